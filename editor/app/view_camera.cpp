#include "app/view_camera.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::editor {

Vec2 ViewCamera::toWorld(Vec2 px) const {
    const double s = pixelsPerMetre();
    return {camera.center.x + (px.x - 0.5 * width) / s, camera.center.y - (px.y - 0.5 * height) / s};
}

Vec2 ViewCamera::toPixels(Vec2 world) const {
    const double s = pixelsPerMetre();
    return {0.5 * width + (world.x - camera.center.x) * s, 0.5 * height - (world.y - camera.center.y) * s};
}

void ViewCamera::pan(Vec2 deltaPx) {
    const double s = pixelsPerMetre();
    camera.center.x -= deltaPx.x / s;
    camera.center.y += deltaPx.y / s;
}

void ViewCamera::zoomAt(Vec2 atPx, double notches) {
    const Vec2 before = toWorld(atPx);
    // Clamp: below 1e-3 px/m or above 1e5 px/m the grid and hit tests lose meaning.
    camera.zoom = std::clamp(camera.zoom * std::pow(1.15, notches), 1e-3, 1e5);
    const Vec2 after = toWorld(atPx);
    camera.center += before - after;
}

} // namespace stepwise::editor
