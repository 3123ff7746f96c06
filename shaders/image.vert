// A layer of pixels drawn on the CPU (DrawData::images), one quad over its
// rectangle. The rectangle is whole pixels and as large as the image, so
// nearest sampling at the pixel centres reads each texel once, exactly.
layout(location = 0) in vec4 aRect;     // x0, y0, x1, y1, pixels
layout(location = 1) in float aLayer;   // index into DrawData::images (unused here: the texture is bound per quad)
out vec2 vUv;
void main() {
    vec2 t = quadCorner() * 0.5 + 0.5;
    vUv = t;
    gl_Position = pixelToClip(mix(aRect.xy, aRect.zw, t));
}
