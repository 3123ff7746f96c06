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

void TrailRecorder::record(const World& world) {
    for (std::size_t i = 0; i < world.bodyCount(); ++i) {
        Trail& t = trailFor(world.bodyEntity(i));
        t.points.push_back(world.bodyPosition(i));
        if (t.points.size() > capacity_) t.points.pop_front();
    }
}

void TrailRecorder::record(const Scene& scene) {
    for (Entity e : scene.registry.entities()) {
        const Position* p = scene.registry.tryGet<Position>(e);
        if (!p || isStatic(scene, e) || scene.registry.has<Spring>(e)) continue;
        Trail& t = trailFor(e);
        t.points.push_back(p->value);
        if (t.points.size() > capacity_) t.points.pop_front();
    }
}

} // namespace stepwise::render
