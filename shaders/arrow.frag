// Arrow: a shaft of width vWidth ending in a triangular head at the tip.
// Distances are in pixels; the head scales with the line width and shrinks
// on short arrows so it never overshoots the tail.
in vec2 vLocal;
flat in float vLength;
flat in float vWidth;
flat in vec4 vColor;
out vec4 fragColor;
void main() {
    float headLen = min(4.5 + 3.0 * vWidth, 0.6 * vLength);
    float headHalf = headLen * 0.55;
    float shaftEnd = vLength - headLen;
    float du = max(max(-vLocal.x, vLocal.x - shaftEnd), 0.0);
    float shaft = length(vec2(du, vLocal.y)) - 0.5 * vWidth;
    // Head: triangle (L,0), (L-h, +-w). Outward normal of the slanted side
    // is normalize(w, h); the back edge is x = L - h.
    vec2 q = vec2(vLocal.x - vLength, abs(vLocal.y));
    float side = dot(q, normalize(vec2(headHalf, headLen)));
    float head = max(side, shaftEnd - vLocal.x);
    float d = min(shaft, head);
    float a = clamp(0.5 - d, 0.0, 1.0) * vColor.a;
    if (a <= 0.0) discard;
    fragColor = vec4(vColor.rgb, a);
}
