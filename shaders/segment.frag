// Capsule of width vWidth around the segment, anti-aliased over one pixel.
in vec2 vLocal;
flat in float vLength;
flat in float vWidth;
flat in vec4 vColor;
out vec4 fragColor;
void main() {
    float du = max(max(-vLocal.x, vLocal.x - vLength), 0.0);
    float d = length(vec2(du, vLocal.y)) - 0.5 * vWidth;
    float a = clamp(0.5 - d, 0.0, 1.0) * vColor.a;
    if (a <= 0.0) discard;
    fragColor = vec4(vColor.rgb, a);
}
