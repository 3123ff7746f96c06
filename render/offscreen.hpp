#pragma once
/// \file offscreen.hpp
/// Headless rendering: an OSMesa OpenGL core context (llvmpipe, no display,
/// no X server) with a Renderer on it. The Renderer is the same class the
/// editor window uses; only the context differs.

#include "renderer.hpp"

#include <memory>

namespace stepwise::render {

class OffscreenRenderer {
public:
    /// Creates a 3.3 core context drawing into a widthPx x heightPx buffer.
    static Result<std::unique_ptr<OffscreenRenderer>> create(int widthPx, int heightPx);
    ~OffscreenRenderer();
    OffscreenRenderer(const OffscreenRenderer&) = delete;
    OffscreenRenderer& operator=(const OffscreenRenderer&) = delete;

    /// Renders the frame and reads it back (top-down RGB). `drawn`, when
    /// given, receives the batches (for statistics).
    Image capture(const FrameInput& input, DrawData* drawn = nullptr);

    Renderer& renderer() { return *renderer_; }
    int width() const { return width_; }
    int height() const { return height_; }

private:
    OffscreenRenderer() = default;
    struct Context;
    std::unique_ptr<Context> context_;
    std::unique_ptr<Renderer> renderer_;
    int width_ = 0, height_ = 0;
};

} // namespace stepwise::render
