// A one-colour coverage layer (PixelLayer): the texel is the alpha to draw
// uColour with, blended like every other batch.
in vec2 vUv;
uniform sampler2D uImage;
uniform vec3 uColour;
out vec4 fragColor;
void main() { fragColor = vec4(uColour, texture(uImage, vUv).r); }
