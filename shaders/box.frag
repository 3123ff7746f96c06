// Signed-distance rounded rectangle.
// Flags: 1 selected, 2 static (hatched), 4 outline only, 16 flat.
// Compiled twice: with PLAIN defined, for batches of flat or outline boxes
// that are neither selected nor static (Batch::plain), only those two.
in vec2 vLocal;
flat in vec2 vHalf;
flat in vec4 vColor;
flat in vec2 vStyle;
uniform vec3 uHighlight;
out vec4 fragColor;

float boxDistance(vec2 p, vec2 halfSize, float r) {
    vec2 q = abs(p) - halfSize + r;
    return length(max(q, 0.0)) + min(max(q.x, q.y), 0.0) - r;
}

void main() {
    int flags = int(vStyle.x);
    float r = min(vStyle.y, min(vHalf.x, vHalf.y));
    float d = boxDistance(vLocal, vHalf, r);
#ifdef PLAIN
    float cover = (flags & 4) != 0 ? clamp(1.1 - abs(d), 0.0, 1.0) : clamp(0.5 - d, 0.0, 1.0);
    fragColor = vec4(vColor.rgb, cover * vColor.a);
#else
    vec3 base = vColor.rgb;
    vec3 c = base;
    float alpha;
    if ((flags & 4) != 0) {
        alpha = clamp(1.1 - abs(d), 0.0, 1.0) * vColor.a;
    } else {
        alpha = clamp(0.5 - d, 0.0, 1.0) * vColor.a;
        if ((flags & 16) == 0) {
            vec2 n = vLocal / max(vHalf, vec2(1.0));
            c = base * (0.88 + 0.12 * dot(n, vec2(-0.45, 0.6)));
            if ((flags & 2) != 0) {
                float stripe = abs(mod(vLocal.x + vLocal.y, 8.0) - 4.0);
                c *= 1.0 - 0.25 * clamp(1.5 - stripe, 0.0, 1.0);
            }
            float rimWidth = min(1.6, min(vHalf.x, vHalf.y) * 0.25);
            c = mix(c, mix(base, vec3(1.0), 0.4), clamp(d + rimWidth + 0.5, 0.0, 1.0));
        }
    }
    if ((flags & 1) != 0) {
        float ringD = abs(d - 3.5) - 1.0;
        float ring = clamp(0.5 - ringD, 0.0, 1.0);
        c = (c * alpha + uHighlight * ring) / max(alpha + ring, 1e-4);
        alpha = max(alpha, ring);
    }
    fragColor = vec4(c, alpha);
#endif
}
