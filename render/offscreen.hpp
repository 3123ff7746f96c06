#pragma once
/// \file offscreen.hpp
/// Headless rendering: an OSMesa OpenGL core context (llvmpipe, no display,
/// no X server) with a Renderer on it. The Renderer is the same class the
/// editor window uses; only the context differs.

#include "renderer.hpp"

#include <memory>
#include <optional>

namespace stepwise::render {

class OffscreenRenderer {
public:
    /// Largest image: 8K UHD (7680 x 4320). Each side may reach 16384 on its
    /// own, but llvmpipe keeps several buffers of this size, so the product
    /// is what bounds memory (about 0.5 GB here) and time.
    static constexpr long long kMaxSidePx = 16384;
    static constexpr long long kMaxPixels = 7680LL * 4320LL;
    /// Why widthPx x heightPx cannot be rendered, or nothing when it can.
    static std::optional<Error> sizeProblem(int widthPx, int heightPx);

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
