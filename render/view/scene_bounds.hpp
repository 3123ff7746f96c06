#pragma once
/// \file scene_bounds.hpp
/// Axis-aligned extents of a scene's shapes, shared by the camera framing
/// (camera.cpp) and the renderer's frame builder. No GL.

#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <algorithm>
#include <optional>

namespace stepwise::render {

struct Bounds {
    Vec2 lo{1e300, 1e300};
    Vec2 hi{-1e300, -1e300};
    bool empty() const { return lo.x > hi.x; }
    void add(Vec2 p, double r = 0.0) {
        lo = {std::min(lo.x, p.x - r), std::min(lo.y, p.y - r)};
        hi = {std::max(hi.x, p.x + r), std::max(hi.y, p.y + r)};
    }
};

/// The axis-aligned box around an entity's shape, metres: its centre and
/// half extents (the centre is the position except for a polygon, whose
/// outline need not be centred on it).
struct ShapeBox {
    Vec2 centre, half;
};
std::optional<ShapeBox> shapeBox(const Scene& scene, Entity e);

/// True when the entity has a Static component set to true.
bool isStatic(const Scene& scene, Entity e);

} // namespace stepwise::render
