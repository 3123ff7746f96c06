// A plane is drawn over the bounding rectangle (pixels) of its solid side
// clipped to the viewport; the fragment shader keeps the solid side.
layout(location = 0) in vec2 aNormal;   // unit, pixel space = world space (uniform scale)
layout(location = 1) in float aOffset;  // dot(normal, p) of the surface, pixels
layout(location = 2) in vec4 aColor;
layout(location = 3) in float aFlags;   // bit 0: selected
layout(location = 4) in vec4 aRect;     // x0, y0, x1, y1, pixels
flat out vec2 vNormal;
flat out float vOffset;
flat out vec4 vColor;
flat out float vFlags;
void main() {
    vNormal = aNormal;
    vOffset = aOffset;
    vColor = aColor;
    vFlags = aFlags;
    vec2 t = quadCorner() * 0.5 + 0.5;
    gl_Position = pixelToClip(mix(aRect.xy, aRect.zw, t));
}
