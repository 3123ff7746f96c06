// Instanced discs: bodies with a radius, point masses, attractor glows.
layout(location = 0) in vec2 aCenter;   // pixels
layout(location = 1) in float aRadius;  // pixels (glow: glow radius)
layout(location = 2) in float aAngle;   // radians, counter-clockwise
layout(location = 3) in vec4 aColor;
layout(location = 4) in float aFlags;   // see disc.frag
out vec2 vLocal;                        // pixels from the centre
flat out float vRadius;
flat out vec2 vTick;                    // unit direction of the rotation tick
flat out vec4 vColor;
flat out float vFlags;
void main() {
    // Room for the anti-aliased edge, and for the ring when selected: tight
    // quads matter when thousands of small bodies are drawn on llvmpipe.
    float pad = (int(aFlags) & 1) != 0 ? 7.0 : 1.5;
    bool glow = (int(aFlags) & 8) != 0;
    vLocal = quadCorner() * (glow ? 1.6 * aRadius : aRadius + pad);
    vRadius = aRadius;
    vTick = vec2(cos(aAngle), sin(aAngle));
    vColor = aColor;
    vFlags = aFlags;
    gl_Position = pixelToClip(aCenter + vLocal);
}
