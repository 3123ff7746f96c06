#pragma once
/// \file renderer.hpp
/// Submits DrawData to the current OpenGL 3.3 core context: one draw call
/// per batch (instanced quads), so 10,000 bodies cost one call, not 10,000.
/// The caller owns the context (OsmesaContext headless, SDL2 in the editor)
/// and makes it current before create(), draw() and readPixels().

#include "frame.hpp"
#include "gl_api.hpp"
#include "image.hpp"

#include "stepwise/result.hpp"

#include <memory>

namespace stepwise::render {

class Renderer {
public:
    /// Loads GL entry points through `getProc` and compiles the shaders.
    /// Fails with the missing entry point or the compiler's log.
    static Result<std::unique_ptr<Renderer>> create(GetProcAddress getProc);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    /// Draws into the currently bound framebuffer, in the w x h rectangle
    /// (w, h from `data`) whose bottom-left pixel is (originX, originY) in
    /// GL's y-up framebuffer coordinates; nothing outside it is touched (the
    /// editor draws its viewport straight into the window, under ImGui).
    void draw(const DrawData& data, int originX = 0, int originY = 0);

    /// buildDrawData + draw.
    DrawData render(const FrameInput& input, int widthPx, int heightPx, int originX = 0, int originY = 0);

    /// Waits until the GPU (llvmpipe: the rasteriser threads) has finished.
    void finish();
    /// Hands everything drawn so far to the GPU without waiting (llvmpipe:
    /// its rasteriser threads start on it now instead of at the swap).
    void flush();

    /// Reads the bound framebuffer back as top-down RGB8 (waits for the GPU).
    Image readPixels(int widthPx, int heightPx);

    /// "OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)".
    std::string describeContext() const;

    /// Number of draw calls issued by the last draw().
    int lastDrawCalls() const { return drawCalls_; }

private:
    Renderer() = default;
    struct Impl;
    std::unique_ptr<Impl> impl_;
    int drawCalls_ = 0;
};

} // namespace stepwise::render
