#pragma once
// The collision stages inside the World: which entities become colliders,
// and the hooks the step pipeline calls. Kept apart from world.cpp so the
// force/integrator pipeline reads on its own.

#include "collision/collision_system.hpp"
#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>

namespace stepwise::detail {

/// Builds the collision system for every entity with a shape (radius, box,
/// plane), or returns nullptr when the scene has none: then the step runs no
/// collision stage at all. `bodyOf` maps an entity to its index in the
/// state vector, or kNoBody when it is static.
///
/// Joints are solved with the contacts, so a scene with a joint has a
/// collision system even without shapes; a jointed dynamic body without a
/// shape joins the solver as a shapeless body (kShapelessRadius). A joint
/// the engine cannot simulate (an end that no longer exists, two fixed
/// ends) is an Error ("entity N (\"name\"): joint ..."). Null when the scene
/// has nothing to collide or join. Without `shapes` (contacts switched off)
/// only the joints are compiled.
Result<std::unique_ptr<collision::CollisionSystem>> buildCollisions(
    const Scene& scene, const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody, bool shapes = true);

/// Where the outlines and chain segments of colliders about to be added
/// live: CollisionSystem::add copies them, so they only need to outlast that.
struct ShapeStorage {
    std::deque<collision::ConvexPolygon> polygons;
    std::deque<collision::ChainSegment> segments;
};
/// Appends the colliders of entity `e` as World::build makes them (its
/// shape, body, material, rotation and filter): none without a shape, one
/// per segment of a chain, and for a compound body a hub (when it moves)
/// and one per shape, whose `hub` is the hub's place in `out`
/// (CollisionSystem::addAll).
void collidersFor(const Registry& reg, Entity e, const std::function<std::uint32_t(Entity)>& bodyOf,
                  std::uint32_t noBody, ShapeStorage& storage, std::vector<collision::CollisionSystem::ColliderAdd>& out);
/// A joint's kind, limits, motor, springs and breaking force from its
/// component; false when a slider axis has no length.
bool fillJointParams(const Joint& joint, joints::JointConstraint& j);

/// A dynamic body held by a joint but without a shape turns like a solid
/// disc of this radius (I = m r^2 / 2), metres: a point mass (I = 0) could
/// not be welded or driven by a motor, and a small disc changes nothing for
/// a hinge at its centre.
inline constexpr double kShapelessRadius = 0.1;

/// The fewest whole substeps, from 1 to `most`, that split a step into
/// parts of at most 1 / `perStep` of it: ceil(perStep), with the ratio
/// rounded first so one that sits on a whole number does not ask for one
/// more.
inline int wholeSubsteps(double perStep, double most) {
    return int(std::clamp(std::ceil(perStep * (1.0 - 1e-12)), 1.0, most));
}

/// Views an interleaved (x0, y0, x1, y1, ...) state array as Vec2s. Vec2 is
/// exactly two doubles (asserted), the layout the integrators use.
inline std::span<Vec2> asVec2(double* p, std::size_t bodies) {
    static_assert(sizeof(Vec2) == 2 * sizeof(double) && alignof(Vec2) == alignof(double));
    return {reinterpret_cast<Vec2*>(p), bodies};
}
inline std::span<const Vec2> asVec2(const double* p, std::size_t bodies) {
    return {reinterpret_cast<const Vec2*>(p), bodies};
}

} // namespace stepwise::detail
