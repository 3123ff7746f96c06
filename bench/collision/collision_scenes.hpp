#pragma once
// The contact-heavy scenes of the collision benchmark, built as ordinary
// Scenes so the same builders write the shipped levels (levels/pile.json,
// levels/pyramid.json, levels/rain.json): the levels a designer opens are the
// ones the benchmark times.

#include "stepwise/scene.hpp"

#include <string>
#include <vector>

namespace stepwise::bench {

/// 2,000 circles (radius 0.25 m) in a grid, falling into a 30 m wide box.
Scene circlesInBox(int count = 2000);
/// A pyramid of unit boxes, `rows` at the base, on a static ground box.
Scene boxPyramid(int rows = 20);
/// 1,000 circles raining from a tall sparse column into a container.
Scene circleRain(int count = 1000);

struct NamedScene {
    std::string name;   ///< file stem and report row
    Scene scene;
    double seconds;     ///< simulated time the benchmark runs
};
std::vector<NamedScene> benchmarkScenes();

} // namespace stepwise::bench
