// Plain coloured triangles in pixels: text and axis-aligned HUD pieces.
layout(location = 0) in vec2 aPosition;
layout(location = 1) in vec4 aColor;
out vec4 vColor;
void main() {
    vColor = aColor;
    gl_Position = pixelToClip(aPosition);
}
