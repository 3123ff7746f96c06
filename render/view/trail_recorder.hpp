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
        /// How many of the newest points equal the point before them. At
        /// points.size() - 1 the trail is one point (a body asleep all that
        /// time): nothing to draw, and no need to walk it.
        std::size_t repeats = 0;
        bool isPoint() const { return points.empty() || repeats + 1 >= points.size(); }
    };
    const std::vector<Trail>& trails() const { return trails_; }
    std::size_t capacity() const { return capacity_; }

private:
    Trail& trailFor(Entity e);
    void append(Trail& t, Vec2 p) const;
    std::size_t capacity_;
    std::vector<Trail> trails_;
    std::vector<std::uint32_t> slotOfIndex_;  // entity index -> trails_ slot + 1 (0: none)
};

} // namespace stepwise::render
