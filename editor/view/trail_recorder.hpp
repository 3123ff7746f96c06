#pragma once
/// \file trail_recorder.hpp
/// Recent positions of each body, for the trails overlay. No GL.

#include "stepwise/entity.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <cstddef>
#include <cstdint>
#include <deque>
#include <vector>

namespace stepwise {
class World;
}

namespace stepwise::render {

/// Positions of each dynamic body over the last `capacity` recorded steps.
class TrailRecorder {
public:
    explicit TrailRecorder(std::size_t capacity = 48) : capacity_(capacity) {}
    /// Appends every dynamic body's current position (World::bodyPosition).
    void record(const World& world);
    /// Appends every positioned, non-static entity's position from the scene
    /// (used when no World could be built).
    void record(const Scene& scene);
    struct Trail {
        Entity entity;
        std::deque<Vec2> points;  ///< oldest first, metres
    };
    const std::vector<Trail>& trails() const { return trails_; }
    std::size_t capacity() const { return capacity_; }

private:
    Trail& trailFor(Entity e);
    std::size_t capacity_;
    std::vector<Trail> trails_;
    std::vector<std::uint32_t> slotOfIndex_;  // entity index -> trails_ slot + 1 (0: none)
};

} // namespace stepwise::render
