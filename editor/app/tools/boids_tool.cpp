#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

// The Boids tool: a brush that lays boids along the drag.

namespace stepwise::editor {

void Editor::pressBoids(const ToolPress& press) {
    const Vec2 world = press.world;
    drag_ = Drag::Boids;
    dragKey_ = newMergeKey();
    lastBoid_ = snapped(world);
    Entity created;
    applyEdit("boid brush", [&](Scene& s) {
        created = addBoid(s, lastBoid_, {1.0, 0.0});
        return true;
    }, dragKey_);
}

void Editor::dragBoids(Vec2 world) {
    const Vec2 at = snapped(world);
    const Vec2 d = at - lastBoid_;
    const double l = length(d);
    if (l < 0.6) return;  // brush spacing, metres
    // Deterministic jitter (LCG) so a brush stroke is not a line.
    boidSeed_ = boidSeed_ * 1664525u + 1013904223u;
    const double jitter = (double(boidSeed_ >> 8) / double(1u << 24) - 0.5) * 0.4;
    const Vec2 dir = d / l;
    const Vec2 pos = at + Vec2{-dir.y, dir.x} * jitter;
    lastBoid_ = at;
    applyEdit("boid brush", [&](Scene& s) {
        addBoid(s, pos, dir * 2.0);
        return true;
    }, dragKey_);
}

} // namespace stepwise::editor
