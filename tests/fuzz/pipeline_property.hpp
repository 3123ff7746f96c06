#pragma once
// The property the pipeline fuzzer checks on every input, shared with the
// regression test that replays tests/fuzz/corpus/ through it.
//
// Whatever loads either builds a World or is refused with a message; a World
// steps, or stops with a message naming why; and what a run that did not
// stop saves (state and solver state, as `stepwise run --out` writes it)
// loads again: a level's ranges are ones the engine can step, and a run
// never leaves them (docs/format.md, "Ranges").

#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <string>
#include <string_view>

namespace stepwise::fuzz {

/// Inputs with more bodies are only loaded: the per-input time limit is for
/// paths that grow faster than their input, and stepping a large level is
/// linear but slow under the sanitizers.
inline constexpr std::size_t kPipelineMaxEntities = 256;
inline constexpr int kPipelineSteps = 3;

/// "" when `text` behaves, else what went wrong (with the texts involved).
inline std::string checkPipelineProperty(std::string_view text) {
    Result<Scene> scene = parseScene(text, "fuzz.json");
    if (!scene || scene->registry.entities().size() > kPipelineMaxEntities) return {};
    Result<World> world = World::build(*scene);
    if (!world) return world.error().empty() ? "World::build refused a loaded level without a message" : "";
    for (int step = 0; step < kPipelineSteps; ++step) {
        const Result<void> stepped = world->step();
        if (!stepped) return stepped.error().empty() ? "a step failed without a message" : "";
    }
    world->writeBack(*scene);
    scene->solverState.reset();
    SolverState solver = world->solverState();
    if (!solver.empty()) scene->solverState = std::move(solver);
    const std::string saved = sceneToJsonText(*scene);
    Result<Scene> again = parseScene(saved, "saved.json");
    if (!again) return "a run saved a level that does not load: " + again.error() + "\n--- saved text:\n" + saved;
    return {};
}

} // namespace stepwise::fuzz
