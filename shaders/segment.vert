// Instanced line segments with round caps (springs, trails, scale bar) and
// arrows (same layout; the fragment shader adds the head). One quad (4
// vertices) per segment or arrow; an arrow's quad is as wide as its head.
// (A thin quad for the shaft and another for the head shade fewer pixels,
// but on llvmpipe the extra triangles cost more: 19.5 -> 18.7 ms a frame
// for 2,000 bodies with every overlay, and the two overlapped at the join,
// blending it twice.)
uniform bool uArrow;
layout(location = 0) in vec2 aFrom;     // pixels
layout(location = 1) in vec2 aTo;       // pixels
layout(location = 2) in float aWidth;   // pixels
layout(location = 3) in vec4 aColor;
out vec2 vLocal;                        // x along the segment from aFrom, y across, pixels
flat out float vLength;
flat out float vWidth;
flat out vec4 vColor;
void main() {
    vec2 delta = aTo - aFrom;
    float len = length(delta);
    vec2 axis = len > 1e-6 ? delta / len : vec2(1.0, 0.0);
    vec2 side = vec2(-axis.y, axis.x);
    vec2 c = quadCorner();
    float halfW = aWidth * 0.5 + 1.0;  // half the line plus a pixel of anti-aliasing
    float u;
    float v;
    if (!uArrow) {
        u = c.x < 0.0 ? -halfW : len + halfW;
        v = c.y * halfW;
    } else {
        // Same head size as arrow.frag. The quad holds every pixel the
        // shader covers: the shaft (halfW), and the head, at most 0.9 px
        // outside its triangle, so 1.5 px of margin around the head's back
        // corners and its tip. A long arrow's quad is a trapezoid, narrow at
        // the tail and wide enough at the head's back: about 28% fewer
        // pixels than the rectangle as wide as the head, which llvmpipe
        // shades and blends just the same when they are transparent.
        float headLen = min(4.5 + 3.0 * aWidth, 0.6 * len);
        float headHalf = max(halfW, 0.55 * headLen + 1.5);
        float headBack = len - headLen - 0.5 + halfW;  // from the quad's tail edge
        float far = len + 1.5 + halfW;
        float wide = headBack > 0.0 ? halfW + (headHalf - halfW) * far / headBack : headHalf;
        bool trapezoid = wide + halfW < 2.0 * headHalf;  // else a short arrow: the rectangle is smaller
        u = c.x < 0.0 ? -halfW : len + 1.5;
        v = c.y * (!trapezoid ? headHalf : (c.x < 0.0 ? halfW : wide));
    }
    vLocal = vec2(u, v);
    vLength = len;
    vWidth = aWidth;
    vColor = aColor;
    gl_Position = pixelToClip(aFrom + axis * u + side * v);
}
