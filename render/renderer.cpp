#include "renderer.hpp"

#include "shader_sources.hpp"

#include <algorithm>
#include <array>
#include <cstring>

namespace stepwise::render {

namespace {

// Colours shared with frame.cpp's palette (background and selection live
// in GL state and uniforms rather than instances).
constexpr float kBackground[3] = {0.059f, 0.071f, 0.094f};   // #0f1218
constexpr float kHighlight[3] = {1.0f, 0.820f, 0.400f};      // #ffd166

std::string_view findShader(std::string_view name) {
    for (const ShaderSource& s : shaderSources())
        if (s.name == name) return s.text;
    return {};
}

struct Attribute {
    GLuint location;
    GLint components;
};

/// Copies each of `count` records of `Stride` floats four times, one per
/// quad corner. A size fixed at compile time makes each copy a few vector
/// moves; memcpy with a run-time size of a few dozen bytes is a library
/// call per corner (46,000 a frame in the editor's bench), which costs more
/// than the copying.
template <std::size_t Stride>
void expandToCorners(const float* src, float* dst, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i, src += Stride)
        for (int v = 0; v < 4; ++v, dst += Stride) std::memcpy(dst, src, Stride * sizeof(float));
}

/// expandToCorners for each kind's record size (floatsPerInstance).
void expandToCorners(BatchKind kind, const float* src, float* dst, std::size_t count) {
    switch (floatsPerInstance(kind)) {
    case 5: return expandToCorners<5>(src, dst, count);
    case 9: return expandToCorners<9>(src, dst, count);
    case 11: return expandToCorners<11>(src, dst, count);
    case 12: return expandToCorners<12>(src, dst, count);
    default: break;
    }
    const std::size_t stride = floatsPerInstance(kind);
    for (std::size_t i = 0; i < count; ++i, src += stride)
        for (int v = 0; v < 4; ++v, dst += stride) std::memcpy(dst, src, stride * sizeof(float));
}

/// Instance (or vertex) layout of each batch kind, matching frame.cpp's
/// push order and the shaders' `layout(location = N)`.
std::vector<Attribute> layoutOf(BatchKind kind) {
    switch (kind) {
    case BatchKind::Plane: return {{0, 2}, {1, 1}, {2, 4}, {3, 1}, {4, 4}};
    case BatchKind::Disc: return {{0, 2}, {1, 1}, {2, 1}, {3, 4}, {4, 1}};
    case BatchKind::Box: return {{0, 2}, {1, 2}, {2, 1}, {3, 4}, {4, 2}};
    case BatchKind::Segment:
    case BatchKind::Arrow: return {{0, 2}, {1, 2}, {2, 1}, {3, 4}};
    case BatchKind::Solid: return {{0, 2}, {1, 4}};
    case BatchKind::Image: return {{0, 4}, {1, 1}};
    }
    return {};
}

constexpr std::array kKinds = {BatchKind::Plane, BatchKind::Disc, BatchKind::Box,
                               BatchKind::Segment, BatchKind::Arrow, BatchKind::Solid, BatchKind::Image};

} // namespace

struct Renderer::Impl {
    GlApi gl;
    struct KindState {
        GLuint program = 0;
        GLuint plainProgram = 0;  ///< the fragment shader with PLAIN defined (Batch::plain); 0: none
        GLuint vao = 0;
        GLuint vbo = 0;
    };
    std::array<KindState, kKinds.size()> kinds;
    GLuint quadIndices = 0;          // element buffer: quad q -> 4q + {0,1,2, 2,1,3}
    std::size_t indexedQuads = 0;    // quads the element buffer covers
    std::vector<float> expanded;     // scratch: records replicated per vertex

    /// Grows the shared element buffer to cover `quads` quads.
    void ensureQuadIndices(std::size_t quads) {
        if (quads <= indexedQuads) return;
        std::size_t n = std::max<std::size_t>(quads, 2 * indexedQuads);
        std::vector<GLuint> indices(n * 6);
        for (std::size_t q = 0; q < n; ++q) {
            const GLuint base = GLuint(4 * q);
            const GLuint pattern[6] = {0, 1, 2, 2, 1, 3};
            for (int k = 0; k < 6; ++k) indices[6 * q + std::size_t(k)] = base + pattern[k];
        }
        // The element buffer binding is VAO state: bind through each VAO.
        for (KindState& k : kinds) {
            if (k.vao == 0) continue;
            gl.BindVertexArray(k.vao);
            gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, quadIndices);
        }
        gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(GLuint)), indices.data(),
                      GL_STATIC_DRAW);
        gl.BindVertexArray(0);
        indexedQuads = n;
    }

    ~Impl() {
        if (!gl.DeleteProgram) return;
        gl.DeleteBuffers(1, &quadIndices);
        for (KindState& k : kinds) {
            gl.DeleteProgram(k.program);
            if (k.plainProgram) gl.DeleteProgram(k.plainProgram);
            gl.DeleteVertexArrays(1, &k.vao);
            gl.DeleteBuffers(1, &k.vbo);
        }
    }

    /// The embedded shader `name` with the #version line, and for vertex
    /// shaders the shared quad.glsl, in front; empty when not embedded.
    static std::string source(GLenum stage, std::string_view name, bool plain) {
        const std::string_view body = findShader(name);
        if (body.empty()) return {};
        std::string text = "#version 330 core\n";
        if (plain) text += "#define PLAIN\n";
        if (stage == GL_VERTEX_SHADER) text += std::string(findShader("quad.glsl"));
        text += "#line 1\n";
        text += body;
        return text;
    }

    Result<GLuint> link(std::string_view vert, std::string_view frag, bool plain = false) {
        const std::string vs = source(GL_VERTEX_SHADER, vert, plain), fs = source(GL_FRAGMENT_SHADER, frag, plain);
        if (vs.empty()) return Error{"shader " + std::string(vert) + " is not embedded"};
        if (fs.empty()) return Error{"shader " + std::string(frag) + " is not embedded"};
        std::string error;
        const GLuint program = linkProgram(gl, vs, fs, std::string(vert) + " + " + std::string(frag), error);
        if (!program) return Error{error};
        return program;
    }
};

Result<std::unique_ptr<Renderer>> Renderer::create(GetProcAddress getProc) {
    std::unique_ptr<Renderer> r(new Renderer());
    r->impl_ = std::make_unique<Impl>();
    Impl& im = *r->impl_;
    if (std::string missing = im.gl.load(getProc); !missing.empty()) {
        im.gl = GlApi{};
        return Error{"OpenGL entry point " + missing + " is missing (need OpenGL 3.3 core)"};
    }
    for (std::size_t k = 0; k < kKinds.size(); ++k) {
        const BatchKind kind = kKinds[k];
        const char* vert = "segment.vert";
        const char* frag = "segment.frag";
        switch (kind) {
        case BatchKind::Plane: vert = "plane.vert", frag = "plane.frag"; break;
        case BatchKind::Disc: vert = "disc.vert", frag = "disc.frag"; break;
        case BatchKind::Box: vert = "box.vert", frag = "box.frag"; break;
        case BatchKind::Segment: break;
        case BatchKind::Arrow: frag = "arrow.frag"; break;
        case BatchKind::Solid: vert = "solid.vert", frag = "solid.frag"; break;
        case BatchKind::Image: vert = "image.vert", frag = "image.frag"; break;
        }
        Result<GLuint> program = im.link(vert, frag);
        if (!program) return Error{program.error()};
        Impl::KindState& st = im.kinds[k];
        st.program = *program;
        if (kind == BatchKind::Disc || kind == BatchKind::Box) {
            Result<GLuint> plain = im.link(vert, frag, true);
            if (!plain) return Error{plain.error()};
            st.plainProgram = *plain;
        }
        im.gl.GenVertexArrays(1, &st.vao);
        im.gl.GenBuffers(1, &st.vbo);
        im.gl.BindVertexArray(st.vao);
        im.gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
        const GLsizei stride = GLsizei(floatsPerInstance(kind) * sizeof(float));
        std::size_t offset = 0;
        for (const Attribute& a : layoutOf(kind)) {
            im.gl.EnableVertexAttribArray(a.location);
            im.gl.VertexAttribPointer(a.location, a.components, GL_FLOAT, GL_FALSE, stride,
                                      reinterpret_cast<const void*>(offset * sizeof(float)));
            // Records are replicated per vertex (see draw()): no divisor.
            im.gl.VertexAttribDivisor(a.location, 0);
            offset += std::size_t(a.components);
        }
        im.gl.BindVertexArray(0);
    }
    im.gl.GenBuffers(1, &im.quadIndices);
    im.ensureQuadIndices(4096);
    if (GLenum err = im.gl.GetError(); err != GL_NO_ERROR)
        return Error{"OpenGL error " + std::to_string(err) + " while creating the renderer"};
    return r;
}

Renderer::~Renderer() = default;

std::string Renderer::describeContext() const {
    const GlApi& gl = impl_->gl;
    auto str = [&](GLenum name) {
        const GLubyte* s = gl.GetString(name);
        return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
    };
    return "OpenGL " + str(GL_VERSION) + ", " + str(GL_RENDERER);
}

void Renderer::draw(const DrawData& data, int originX, int originY) {
    Impl& im = *impl_;
    const GlApi& gl = im.gl;
    drawCalls_ = 0;
    gl.Viewport(originX, originY, data.width, data.height);
    // The clear (and every draw) stays inside the rectangle.
    gl.Enable(GL_SCISSOR_TEST);
    gl.Scissor(originX, originY, data.width, data.height);
    gl.Disable(GL_DEPTH_TEST);
    gl.Disable(GL_CULL_FACE);
    gl.Enable(GL_BLEND);
    // Straight alpha for colour; alpha channel accumulates coverage.
    gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    const float w = float(data.width), h = float(data.height);

    // Background: a clear is a memset on llvmpipe, far cheaper than a
    // full-screen shader pass; the grid lines are Solid geometry.
    gl.ClearColor(kBackground[0], kBackground[1], kBackground[2], 1.0f);
    gl.Clear(GL_COLOR_BUFFER_BIT);

    for (const Batch& batch : data.batches) {
        const std::size_t count = batch.count();
        if (count == 0) continue;
        const std::size_t k = std::size_t(std::find(kKinds.begin(), kKinds.end(), batch.kind) - kKinds.begin());
        const Impl::KindState& st = im.kinds[k];
        const GLuint program = batch.plain && st.plainProgram ? st.plainProgram : st.program;
        gl.UseProgram(program);
        gl.Uniform2f(gl.GetUniformLocation(program, "uViewport"), w, h);
        if (GLint loc = gl.GetUniformLocation(program, "uArrow"); loc >= 0)
            gl.Uniform1i(loc, batch.kind == BatchKind::Arrow ? 1 : 0);
        if (GLint loc = gl.GetUniformLocation(program, "uOrigin"); loc >= 0)
            gl.Uniform2f(loc, float(originX), float(originY));
        if (GLint loc = gl.GetUniformLocation(program, "uHighlight"); loc >= 0)
            gl.Uniform3f(loc, kHighlight[0], kHighlight[1], kHighlight[2]);
        gl.BindVertexArray(st.vao);
        gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
        // Re-specifying the store each batch lets the driver orphan the old
        // one instead of waiting for the previous draw to finish with it.
        if (batch.kind == BatchKind::Solid) {
            gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(batch.data.size() * sizeof(float)), batch.data.data(),
                          GL_STREAM_DRAW);
            gl.DrawArrays(GL_TRIANGLES, 0, GLsizei(count));
        } else {
            // One record per quad corner, indexed triangles, one call. This
            // is "batched" rather than instanced on purpose: llvmpipe shades
            // instanced draws one instance at a time (~1-6 us each), while a
            // plain indexed draw runs its vertices through SIMD batches.
            const std::size_t stride = floatsPerInstance(batch.kind);
            im.expanded.resize(count * 4 * stride);
            float* dst = im.expanded.data();
            expandToCorners(batch.kind, batch.data.data(), dst, count);
            im.ensureQuadIndices(count);
            gl.BindVertexArray(st.vao);
            gl.BindBuffer(GL_ARRAY_BUFFER, st.vbo);
            gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(im.expanded.size() * sizeof(float)), im.expanded.data(),
                          GL_STREAM_DRAW);
            if (batch.kind != BatchKind::Image) {
                gl.DrawElements(GL_TRIANGLES, GLsizei(count * 6), GL_UNSIGNED_INT, nullptr);
            } else {
                // One texture and quad per layer. A new texture each time:
                // re-specifying one that the previous frame's drawing still
                // reads would make the driver wait for that drawing (the
                // editor overlaps it with the next frame); a deleted texture
                // lives on until the drawing that reads it is done.
                gl.ActiveTexture(GL_TEXTURE0);
                gl.Uniform1i(gl.GetUniformLocation(program, "uImage"), 0);
                gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
                for (std::size_t i = 0; i < count; ++i) {
                    const std::size_t index = std::size_t(batch.data[i * stride + 4]);
                    if (index >= data.images.size()) continue;
                    const PixelLayer& layer = data.images[index];
                    GLuint texture = 0;
                    gl.GenTextures(1, &texture);
                    gl.BindTexture(GL_TEXTURE_2D, texture);
                    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
                    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
                    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
                    gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
                    gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, layer.width, layer.height, 0, GL_RED, GL_UNSIGNED_BYTE,
                                  layer.coverage.data());
                    gl.Uniform3f(gl.GetUniformLocation(program, "uColour"), layer.colour[0], layer.colour[1], layer.colour[2]);
                    gl.DrawElements(GL_TRIANGLES, 6, GL_UNSIGNED_INT,
                                    reinterpret_cast<const void*>(i * 6 * sizeof(GLuint)));
                    gl.BindTexture(GL_TEXTURE_2D, 0);
                    gl.DeleteTextures(1, &texture);
                    if (i + 1 < count) ++drawCalls_;
                }
            }
        }
        ++drawCalls_;
    }
    gl.BindVertexArray(0);
    gl.Disable(GL_SCISSOR_TEST);
}

DrawData Renderer::render(const FrameInput& input, int widthPx, int heightPx, int originX, int originY) {
    DrawData data = buildDrawData(input, widthPx, heightPx);
    draw(data, originX, originY);
    return data;
}

void Renderer::finish() { impl_->gl.Finish(); }

void Renderer::flush() { impl_->gl.Flush(); }

Image Renderer::readPixels(int widthPx, int heightPx) {
    const GlApi& gl = impl_->gl;
    Image image{widthPx, heightPx, std::vector<std::uint8_t>(std::size_t(widthPx) * std::size_t(heightPx) * 3)};
    gl.PixelStorei(GL_PACK_ALIGNMENT, 1);
    gl.ReadPixels(0, 0, widthPx, heightPx, GL_RGB, GL_UNSIGNED_BYTE, image.rgb.data());
    // GL rows run bottom-up; images top-down.
    const std::size_t row = std::size_t(widthPx) * 3;
    std::vector<std::uint8_t> tmp(row);
    for (int y = 0; y < heightPx / 2; ++y) {
        std::uint8_t* a = image.rgb.data() + std::size_t(y) * row;
        std::uint8_t* b = image.rgb.data() + std::size_t(heightPx - 1 - y) * row;
        std::memcpy(tmp.data(), a, row);
        std::memcpy(a, b, row);
        std::memcpy(b, tmp.data(), row);
    }
    return image;
}

} // namespace stepwise::render
