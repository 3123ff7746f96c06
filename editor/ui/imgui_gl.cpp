#include "ui/imgui_gl.hpp"

#include <imgui.h>

#include <GL/glcorearb.h>

#include <string>

namespace stepwise::ui {

namespace {

// The same loaded entry points as the scene renderer (render/gl_api.hpp).
using Gl = render::GlApi;

// Positions in pixels -> clip space by uProjection; colours are straight
// RGBA8 (ImGui's convention). The font atlas is coverage only (R8): its
// sample scales the alpha.
const char* kVertex = R"(#version 330 core
layout (location = 0) in vec2 aPos;
layout (location = 1) in vec2 aUV;
layout (location = 2) in vec4 aColor;
uniform mat4 uProjection;
out vec2 vUV;
out vec4 vColor;
void main() {
    vUV = aUV;
    vColor = aColor;
    gl_Position = uProjection * vec4(aPos, 0.0, 1.0);
}
)";
const char* kFragment = R"(#version 330 core
in vec2 vUV;
in vec4 vColor;
uniform sampler2D uTexture;
out vec4 outColor;
void main() { outColor = vec4(vColor.rgb, vColor.a * texture(uTexture, vUV).r); }
)";

} // namespace

struct ImGuiGl::Impl {
    Gl gl;
    GLuint program = 0, vao = 0, vbo = 0, ebo = 0, font = 0;
    GLint projection = -1, texture = -1;

    void uploadFonts() {
        ImGuiIO& io = ImGui::GetIO();
        unsigned char* pixels = nullptr;
        int w = 0, h = 0;
        // Every pixel of every panel samples the atlas (backgrounds read its
        // white texel), so on llvmpipe the sample is a real share of the
        // frame: one coverage channel and nearest filtering save 1.4 ms of
        // a 13.2 ms frame. Nearest is exact because glyphs are rasterised
        // 1:1 and snapped to whole pixels (Session::loadFonts) and lines are
        // drawn as geometry, not from baked textures (applyTheme).
        io.Fonts->GetTexDataAsAlpha8(&pixels, &w, &h);
        if (!font) gl.GenTextures(1, &font);
        gl.BindTexture(GL_TEXTURE_2D, font);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
        gl.TexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
        gl.PixelStorei(GL_UNPACK_ALIGNMENT, 1);
        gl.TexImage2D(GL_TEXTURE_2D, 0, GL_R8, w, h, 0, GL_RED, GL_UNSIGNED_BYTE, pixels);
        io.Fonts->SetTexID(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(font)));
    }
};

Result<std::unique_ptr<ImGuiGl>> ImGuiGl::create(render::GetProcAddress getProc) {
    std::unique_ptr<ImGuiGl> r(new ImGuiGl());
    r->impl_ = std::make_unique<Impl>();
    Impl& im = *r->impl_;
    if (std::string missing = im.gl.load(getProc); !missing.empty())
        return Error{"OpenGL entry point " + missing + " is missing"};
    Gl& gl = im.gl;
    std::string error;
    im.program = render::linkProgram(gl, kVertex, kFragment, "ImGui", error);
    if (!im.program) return Error{error};
    im.projection = gl.GetUniformLocation(im.program, "uProjection");
    im.texture = gl.GetUniformLocation(im.program, "uTexture");
    gl.GenVertexArrays(1, &im.vao);
    gl.GenBuffers(1, &im.vbo);
    gl.GenBuffers(1, &im.ebo);
    gl.BindVertexArray(im.vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, im.vbo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, im.ebo);
    gl.EnableVertexAttribArray(0);
    gl.EnableVertexAttribArray(1);
    gl.EnableVertexAttribArray(2);
    gl.VertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(ImDrawVert),
                           reinterpret_cast<void*>(offsetof(ImDrawVert, pos)));
    gl.VertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, sizeof(ImDrawVert),
                           reinterpret_cast<void*>(offsetof(ImDrawVert, uv)));
    gl.VertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(ImDrawVert),
                           reinterpret_cast<void*>(offsetof(ImDrawVert, col)));
    gl.BindVertexArray(0);
    im.uploadFonts();
    return r;
}

ImGuiGl::~ImGuiGl() {
    if (!impl_) return;
    Gl& gl = impl_->gl;
    if (impl_->font) gl.DeleteTextures(1, &impl_->font);
    if (impl_->vbo) gl.DeleteBuffers(1, &impl_->vbo);
    if (impl_->ebo) gl.DeleteBuffers(1, &impl_->ebo);
    if (impl_->vao) gl.DeleteVertexArrays(1, &impl_->vao);
    if (impl_->program) gl.DeleteProgram(impl_->program);
}

void ImGuiGl::rebuildFonts() { impl_->uploadFonts(); }

void ImGuiGl::clear(int fbWidth, int fbHeight, const ImVec4& colour) {
    Gl& gl = impl_->gl;
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.Disable(GL_SCISSOR_TEST);
    gl.Viewport(0, 0, fbWidth, fbHeight);
    // The panels' colour: gaps between them look intended, and a panel
    // alone can leave its background out (ui::beginPanel).
    gl.ClearColor(colour.x, colour.y, colour.z, colour.w);
    gl.Clear(GL_COLOR_BUFFER_BIT);
}

void ImGuiGl::render(const ImDrawData* data, int fbWidth, int fbHeight) {
    Impl& im = *impl_;
    Gl& gl = im.gl;
    gl.BindFramebuffer(GL_FRAMEBUFFER, 0);
    gl.Viewport(0, 0, fbWidth, fbHeight);
    if (!data || data->CmdListsCount == 0) return;
    gl.Enable(GL_BLEND);
    gl.BlendEquation(GL_FUNC_ADD);
    gl.BlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    gl.Disable(GL_CULL_FACE);
    gl.Disable(GL_DEPTH_TEST);
    gl.Enable(GL_SCISSOR_TEST);
    const float L = data->DisplayPos.x, R = data->DisplayPos.x + data->DisplaySize.x;
    const float T = data->DisplayPos.y, B = data->DisplayPos.y + data->DisplaySize.y;
    // Orthographic projection, y down (ImGui's pixels) to GL clip space.
    const float ortho[16] = {2.0f / (R - L), 0, 0, 0, 0, 2.0f / (T - B), 0, 0, 0, 0, -1, 0,
                             (R + L) / (L - R), (T + B) / (B - T), 0, 1};
    gl.UseProgram(im.program);
    gl.Uniform1i(im.texture, 0);
    gl.UniformMatrix4fv(im.projection, 1, GL_FALSE, ortho);
    gl.ActiveTexture(GL_TEXTURE0);
    gl.BindVertexArray(im.vao);
    gl.BindBuffer(GL_ARRAY_BUFFER, im.vbo);
    gl.BindBuffer(GL_ELEMENT_ARRAY_BUFFER, im.ebo);
    for (int n = 0; n < data->CmdListsCount; ++n) {
        const ImDrawList* list = data->CmdLists[n];
        gl.BufferData(GL_ARRAY_BUFFER, GLsizeiptr(list->VtxBuffer.Size) * GLsizeiptr(sizeof(ImDrawVert)),
                      list->VtxBuffer.Data, GL_STREAM_DRAW);
        gl.BufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(list->IdxBuffer.Size) * GLsizeiptr(sizeof(ImDrawIdx)),
                      list->IdxBuffer.Data, GL_STREAM_DRAW);
        for (int c = 0; c < list->CmdBuffer.Size; ++c) {
            const ImDrawCmd& cmd = list->CmdBuffer[c];
            if (cmd.UserCallback) {
                cmd.UserCallback(list, &cmd);
                continue;
            }
            const float x0 = cmd.ClipRect.x - L, y0 = cmd.ClipRect.y - T;
            const float x1 = cmd.ClipRect.z - L, y1 = cmd.ClipRect.w - T;
            if (x1 <= x0 || y1 <= y0) continue;
            gl.Scissor(GLint(x0), GLint(float(fbHeight) - y1), GLsizei(x1 - x0), GLsizei(y1 - y0));
            gl.BindTexture(GL_TEXTURE_2D, GLuint(reinterpret_cast<std::uintptr_t>(cmd.GetTexID())));
            gl.DrawElements(GL_TRIANGLES, GLsizei(cmd.ElemCount),
                            sizeof(ImDrawIdx) == 2 ? GL_UNSIGNED_SHORT : GL_UNSIGNED_INT,
                            reinterpret_cast<void*>(std::uintptr_t(cmd.IdxOffset) * sizeof(ImDrawIdx)));
        }
    }
    gl.Disable(GL_SCISSOR_TEST);
    gl.BindVertexArray(0);
}

} // namespace stepwise::ui
