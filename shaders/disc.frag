// Signed-distance disc with a one-pixel anti-aliased edge.
// Flags: 1 selected, 2 static (hatched), 4 rotation tick, 8 glow, 16 flat.
// Compiled twice: with PLAIN defined, for batches with no selected, static
// or glowing instance (Batch::plain), those features are left out.
in vec2 vLocal;
flat in float vRadius;
flat in vec2 vTick;
flat in vec4 vColor;
flat in float vFlags;
uniform vec3 uHighlight;
out vec4 fragColor;

void main() {
    int flags = int(vFlags);
    float rho = length(vLocal);
#ifndef PLAIN
    if ((flags & 8) != 0) {
        // Attractor glow: soft Gaussian falloff of width vRadius (the quad
        // is 1.6 radii; the dashed ring is drawn as segments by the CPU).
        float x = rho / vRadius;
        float a = exp(-x * x * 2.0) * 0.5 * clamp(1.6 - x, 0.0, 1.0);
        fragColor = vec4(vColor.rgb, a * vColor.a);
        return;
    }
#endif
    float d = rho - vRadius;                      // pixels, < 0 inside
    float inside = clamp(0.5 - d, 0.0, 1.0);
    vec3 base = vColor.rgb;
    vec3 c;
    if ((flags & 16) != 0) {
        c = base;
    } else {
        // Gentle light from the upper left so discs read as solid objects.
        vec2 n = vLocal / max(vRadius, 1.0);
        float shade = 0.86 + 0.14 * dot(n, vec2(-0.6, 0.8));
        c = base * shade;
#ifndef PLAIN
        if ((flags & 2) != 0) {
            float stripe = abs(mod(vLocal.x + vLocal.y, 8.0) - 4.0);
            c *= 1.0 - 0.25 * clamp(1.5 - stripe, 0.0, 1.0);
        }
#endif
        float rimWidth = min(1.6, vRadius * 0.25);
        float rim = clamp(d + rimWidth + 0.5, 0.0, 1.0);
        c = mix(c, mix(base, vec3(1.0), 0.4), rim);
        if ((flags & 4) != 0 && vRadius > 4.0) {
            // Tick from the centre to the edge along the body's angle.
            float along = clamp(dot(vLocal, vTick), 0.0, vRadius - rimWidth);
            float tickD = length(vLocal - along * vTick);
            float tick = clamp(1.25 - tickD, 0.0, 1.0);
            c = mix(c, base * 0.28, tick);
        }
    }
    float alpha = inside * vColor.a;
#ifndef PLAIN
    if ((flags & 1) != 0) {
        float ringD = abs(rho - (vRadius + 3.5)) - 1.0;
        float ring = clamp(0.5 - ringD, 0.0, 1.0);
        // Disc and ring never overlap, so "over" reduces to a sum.
        c = (c * alpha + uHighlight * ring) / max(alpha + ring, 1e-4);
        alpha = max(alpha, ring);
    }
#endif
    fragColor = vec4(c, alpha);
}
