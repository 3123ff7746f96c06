#pragma once

#include <cstdint>

#include "stepwise/vec2.hpp"

namespace stepwise::collision {

/// One touching contact between a dynamic body and a static (or kinematic)
/// shape, as the body feels it.
struct Support {
    std::uint32_t body = 0;  ///< state-vector index
    Vec2 normal;             ///< unit: the direction the support pushes the body
    double friction = 0.0;   ///< the pair's friction coefficient
    int points = 0;
    /// Each point's place relative to the body's centre of mass, metres:
    /// `along` the tangent (normal.y, -normal.x) and `up` the normal (below
    /// the centre, as a resting body's points are, is negative).
    double along[2] = {0.0, 0.0};
    double up[2] = {0.0, 0.0};
};

} // namespace stepwise::collision
