#pragma once
/// \file imgui_gl.hpp
/// Draws Dear ImGui's draw lists with OpenGL 3.3 core. Written for the editor instead of using
/// libimgui's imgui_impl_opengl3 because that backend loads GL through
/// libGL/GLX itself, which does not reach an OSMesa context; this one loads
/// its entry points through the context's own GetProcAddress (as the scene
/// renderer does), so the window and the headless screenshot share one path.

#include "gl_api.hpp"
#include "stepwise/result.hpp"

#include <cstdint>
#include <memory>

struct ImDrawData;
struct ImVec4;

namespace stepwise::ui {

class ImGuiGl {
public:
    /// Loads GL entry points, compiles the shader and uploads the font atlas
    /// of the current ImGui context.
    static Result<std::unique_ptr<ImGuiGl>> create(render::GetProcAddress getProc);
    ~ImGuiGl();

    /// Clears the default framebuffer (0) of size fbWidth x fbHeight to
    /// `colour`, the panels' background. A frame is: clear, the scene renderer draws the
    /// viewport's rectangle, then render() draws the panels over it. (No
    /// offscreen target: on llvmpipe sampling one would make the rasteriser
    /// finish the scene before ImGui's triangles could even be binned.)
    void clear(int fbWidth, int fbHeight, const ImVec4& colour);
    /// Draws `data` over the default framebuffer of size fbWidth x fbHeight.
    void render(const ImDrawData* data, int fbWidth, int fbHeight);
    /// Rebuilds the font texture (after a font size change).
    void rebuildFonts();

private:
    ImGuiGl() = default;
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace stepwise::ui
