// Shared by the instanced vertex shaders (prepended by the renderer after
// the #version line). Positions arrive in pixels (origin bottom-left, y up);
// uViewport is the framebuffer size in pixels.
uniform vec2 uViewport;

// Quads are drawn as indexed triangles from 4 consecutive vertices that all
// carry the same record (llvmpipe runs instanced draws one instance at a
// time, so replicating records and drawing once is several times faster).
// Corner k = gl_VertexID % 4 of a unit quad: (-1,-1) .. (1,1).
vec2 quadCorner() {
    return vec2(float(gl_VertexID & 1), float((gl_VertexID >> 1) & 1)) * 2.0 - 1.0;
}

vec4 pixelToClip(vec2 p) {
    return vec4(p / uViewport * 2.0 - 1.0, 0.0, 1.0);
}
