#pragma once
/// \file view_camera.hpp
/// The viewport camera: pan and zoom about the cursor, conversions between
/// viewport pixels (origin top-left, y down, as the mouse reports them) and
/// world metres (y up). Uses the renderer's Camera so what the tools hit is
/// exactly what the renderer drew.

#include "camera.hpp"
#include "stepwise/vec2.hpp"

namespace stepwise::editor {

struct ViewCamera {
    render::Camera camera;  ///< centre (m) and zoom (px/m at 720 px height)
    int width = 1, height = 1;  ///< viewport size, pixels

    double pixelsPerMetre() const { return camera.pixelsPerMetre(height); }
    /// Viewport pixel (top-left origin) -> world metres.
    Vec2 toWorld(Vec2 px) const;
    /// World metres -> viewport pixel (top-left origin).
    Vec2 toPixels(Vec2 world) const;
    /// Moves the view by a mouse drag of `deltaPx` (the world follows the mouse).
    void pan(Vec2 deltaPx);
    /// Multiplies zoom by 1.15^notches keeping the world point under `atPx` fixed.
    void zoomAt(Vec2 atPx, double notches);
};

} // namespace stepwise::editor
