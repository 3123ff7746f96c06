#pragma once
// Box2D v3.1.1's benchmark scenes (its shared/benchmarks.c: joint grid,
// large pyramid, many pyramids, rain, smash, spinner, tumbler) built as
// Stepwise scenes, as close as the scene format allows. What the format
// lacks (capsules, chain shapes, collision filters, kinematic and compound
// bodies) is approximated; docs/performance.md, "Box2D's
// benchmark scenes", lists each approximation and why. bench/levels/ holds
// them as level files (hard_cases --write-levels).

#include "stepwise/scene.hpp"

#include <string>
#include <vector>

namespace stepwise::bench {

struct Box2dScene {
    std::string name;  ///< file stem: bench/levels/box2d_NAME.json
    Scene scene;
};

/// The seven scenes at Box2D's release sizes, with v3's step settings
/// (dt 1/60, 4 substeps, 1 iteration, sleeping off) written into the level.
std::vector<Box2dScene> box2dBenchmarkScenes();

} // namespace stepwise::bench
