#pragma once
// The one door into a World's internals, for code that measures the engine
// from outside it: the tests, the benchmarks (bench/) and the accuracy report
// (bench/report). They time or compare the force model, the state arrays
// and the collision system on their own, which the public World API does not
// expose (and should not: an application has no use for them). Reached
// through the stepwise_engine_internal include path; nothing else includes
// it. World::impl() is private; this is its only friend.

#include "world/world_impl.hpp"

namespace stepwise {

struct WorldInternalAccess {
    static WorldImpl& of(World& world) { return world.impl(); }
    static const WorldImpl& of(const World& world) { return world.impl(); }
};

/// The internals of `world` (force model, xs()/vs(), collision system).
inline WorldImpl& internals(World& world) { return WorldInternalAccess::of(world); }
inline const WorldImpl& internals(const World& world) { return WorldInternalAccess::of(world); }

} // namespace stepwise
