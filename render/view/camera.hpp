#pragma once
/// \file camera.hpp
/// The world-space camera a frame is drawn with, and the default framing of
/// a level. No GL (see overlay_set.hpp for why this is apart from the renderer).

#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

namespace stepwise::render {

/// World-space camera. `zoom` is pixels per metre in a 720-pixel-tall image
/// (the level file's `view.zoom`); other heights scale it so the same region
/// is shown whatever the resolution.
struct Camera {
    Vec2 center;        ///< metres, shown at the middle of the image
    double zoom = 40.0; ///< pixels per metre at 720 px image height
    double pixelsPerMetre(int heightPx) const { return zoom * double(heightPx) / 720.0; }
};

/// Fits the scene's bounds (shapes, points, spring anchors, the nearest part
/// of each plane) with a margin.
Camera fitCamera(const Scene& scene, int widthPx, int heightPx);
/// The level's `view` when it has one, else fitCamera().
Camera sceneCamera(const Scene& scene, int widthPx, int heightPx);

} // namespace stepwise::render
