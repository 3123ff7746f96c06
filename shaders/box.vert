// Instanced rotated rectangles: box bodies, AABB outlines, HUD panels.
layout(location = 0) in vec2 aCenter;   // pixels
layout(location = 1) in vec2 aHalf;     // half width and height, pixels
layout(location = 2) in float aAngle;   // radians, counter-clockwise
layout(location = 3) in vec4 aColor;
layout(location = 4) in vec2 aStyle;    // x: flags (see box.frag), y: corner radius px
out vec2 vLocal;                        // pixels in the box frame
flat out vec2 vHalf;
flat out vec4 vColor;
flat out vec2 vStyle;
void main() {
    // Room for the anti-aliased edge, and for the ring when selected.
    float pad = (int(aStyle.x) & 1) != 0 ? 7.0 : 1.5;
    vLocal = quadCorner() * (aHalf + pad);
    vHalf = aHalf;
    vColor = aColor;
    vStyle = aStyle;
    vec2 axis = vec2(cos(aAngle), sin(aAngle));
    vec2 p = aCenter + axis * vLocal.x + vec2(-axis.y, axis.x) * vLocal.y;
    gl_Position = pixelToClip(p);
}
