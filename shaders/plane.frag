// Half-plane wall: a dark fill on the solid side (dot(n, p) < offset), a
// hatched band along the surface fading with depth, and a crisp edge line.
flat in vec2 vNormal;
flat in float vOffset;
flat in vec4 vColor;
flat in float vFlags;
uniform vec3 uHighlight;
// Bottom-left of the drawing rectangle in window pixels: gl_FragCoord is
// relative to the window, the plane's offset to the rectangle (the editor
// draws its viewport inside a larger window).
uniform vec2 uOrigin;
out vec4 fragColor;

void main() {
    vec2 p = gl_FragCoord.xy - uOrigin;                 // pixels in the drawing rectangle
    float s = dot(vNormal, p) - vOffset;  // pixels, > 0 on the free side
    if (s > 1.5) discard;
    bool selected = (int(vFlags) & 1) != 0;
    vec3 edgeColor = selected ? uHighlight : mix(vColor.rgb, vec3(1.0), 0.15);
    // Hatch lines at 45 degrees to the surface, 9 px apart, ~1.3 px wide.
    vec2 t = vec2(-vNormal.y, vNormal.x);
    float k = dot(p, normalize(vNormal + t));
    float dist = abs(mod(k, 9.0) - 4.5);
    float hatch = clamp(1.15 - dist, 0.0, 1.0) * (1.0 - smoothstep(4.0, 26.0, -s));
    vec3 fill = vColor.rgb * 0.16;
    vec3 c = mix(fill, vColor.rgb * 0.75, hatch * 0.8);
    float inside = clamp(0.5 - s, 0.0, 1.0);
    float edge = clamp(1.6 - abs(s + 1.0), 0.0, 1.0);
    c = mix(c, edgeColor, edge);
    float alpha = max(inside * 0.92, edge);
    fragColor = vec4(c, alpha);
}
