#include "trail_recorder.hpp"

#include "scene_bounds.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world.hpp"

namespace stepwise::render {

TrailRecorder::Trail& TrailRecorder::trailFor(Entity e) {
    if (e.index >= slotOfIndex_.size()) slotOfIndex_.resize(std::size_t(e.index) + 1, 0);
    std::uint32_t& slot = slotOfIndex_[e.index];
    if (slot == 0 || trails_[slot - 1].entity != e) {
        trails_.push_back({e, {}});
        slot = std::uint32_t(trails_.size());
    }
    return trails_[slot - 1];
}

void TrailRecorder::append(Trail& t, Vec2 p) const {
    t.repeats = !t.points.empty() && t.points.back() == p ? t.repeats + 1 : 0;
    t.points.push_back(p);
    if (t.points.size() > capacity_) t.points.pop_front();
}

void TrailRecorder::record(const World& world) {
    for (std::size_t i = 0; i < world.bodyCount(); ++i) {
        append(trailFor(world.bodyEntity(i)), world.bodyPosition(i));
    }
}

void TrailRecorder::record(const Scene& scene) {
    for (Entity e : scene.registry.entities()) {
        const Position* p = scene.registry.tryGet<Position>(e);
        if (!p || isStatic(scene, e) || scene.registry.has<Spring>(e)) continue;
        append(trailFor(e), p->value);
    }
}

} // namespace stepwise::render
