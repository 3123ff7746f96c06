// Google Benchmark: what one undoable edit costs the editor as the level
// grows. Moving one body (one step of a drag) should cost the same in a
// level of 2,000, 20,000 or 200,000 bodies; a copy of the whole scene is
// the peer, measured in the same run, since the cost of an edit that
// copied the scene grows with it. Not part of ctest.
//
//   build/bench/editor_bench --benchmark_min_time=0.2

#include "app/command_stack.hpp"
#include "generated_scenes.hpp"

#include "stepwise/components.hpp"

#include <benchmark/benchmark.h>

#include <vector>

namespace {

using namespace stepwise;

std::vector<Entity> bodiesOf(const Scene& scene) {
    std::vector<Entity> out;
    for (Entity e : scene.registry.entities())
        if (scene.registry.has<Radius>(e)) out.push_back(e);
    return out;
}

/// One step of a drag: a body moved by a little, merged into the drag's
/// one undo step as the editor does while the mouse button is down.
void BM_DragOneBody(benchmark::State& state) {
    Scene scene = scenes::circlesInBox(int(state.range(0)));
    const std::vector<Entity> bodies = bodiesOf(scene);
    const Entity dragged = bodies[bodies.size() / 2];
    editor::CommandStack stack;
    double dx = 0.0;
    for (auto _ : state) {
        dx += 1e-3;
        const bool done = stack.apply(scene, "drag", [&](Scene& s) {
            s.registry.tryGet<Position>(dragged)->value.x += dx;
            return true;
        }, 1);
        benchmark::DoNotOptimize(done);
    }
    state.counters["bodies"] = double(bodies.size());
    state.counters["undo_bytes"] = double(stack.bytes());
}
BENCHMARK(BM_DragOneBody)->Arg(2000)->Arg(20000)->Arg(200000)->Unit(benchmark::kMicrosecond);

/// The peer: one copy of the whole scene.
void BM_CopyScene(benchmark::State& state) {
    const Scene scene = scenes::circlesInBox(int(state.range(0)));
    for (auto _ : state) {
        Scene copy = scene;
        benchmark::DoNotOptimize(copy.registry.size());
    }
}
BENCHMARK(BM_CopyScene)->Arg(2000)->Arg(20000)->Arg(200000)->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
