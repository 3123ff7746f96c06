#pragma once
// Scenes the report, the benchmarks and the tests share.

#include "stepwise/scene.hpp"

#include <cstddef>
#include <string>

namespace stepwise::report {

/// n dynamic attractors ("s0", "s1", ...) of total mass 1 (G = 1) at rest,
/// scattered uniformly over the unit disc by a fixed generator (the same
/// scene on every run and machine), softening 0.01 m, no gravity: the
/// n-body case Barnes–Hut is for.
Scene attractorDisc(std::size_t n, double theta, const std::string& integrator = "semi_implicit_euler",
                    double dt = 0.01);

} // namespace stepwise::report
