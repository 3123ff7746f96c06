// Google Benchmark: the contact solver's three scenes (the
// 2,000-circle pile for 600 steps, the 300-circle pile for 900, the 20-row
// box pyramid for 600), ms per step over the whole run:
//   - Stepwise as shipped (coloured contacts in SIMD bundles),
//   - Stepwise solving the same coloured order one contact at a time
//     (SolverSettings::simd off: the same bits, the scalar cost),
//   - Box2D 2.4.1 (8 velocity and 3 position iterations, sleeping off), the
//     peer measured in the same run, as in collision_vs_box2d.
// Each benchmark iteration is one step (its time is ms per step); the
// iteration count is fixed at the scene's step count, so a run is the whole
// scene. Not part of ctest: the machine is shared, compare the ratios of one
// run (the CPU column is steadier than wall time on a loaded machine).
//
//   build/bench/contact_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true

#include "collision/box2d_bodies.hpp"
#include "generated_scenes.hpp"
#include "collision/collision_system.hpp"
#include "stepwise/world.hpp"
#include "world/world_internals.hpp"

#include <benchmark/benchmark.h>
#include <box2d/box2d.h>

#include <string>

using namespace stepwise;

namespace {

struct BenchScene {
    const char* name;  // scenes::benchmarkScenes() name
    int steps;
};
constexpr BenchScene kScenes[] = {{"pile", 600}, {"pile300", 900}, {"pyramid", 600}};

Scene sceneNamed(const std::string& name) {
    for (scenes::NamedScene& s : scenes::benchmarkScenes())
        if (s.name == name) {
            // Sleeping off, as Box2D's: every step does the full work (with
            // sleeping on, the settled pyramid costs a fifth of a step).
            s.scene.world.sleep = false;
            return std::move(s.scene);
        }
    return {};
}

void BM_Stepwise(benchmark::State& state, std::string name, bool simd) {
    const Scene scene = sceneNamed(name);
    Result<World> world = World::build(scene);
    if (!world) {
        state.SkipWithError(world.error().c_str());
        return;
    }
    internals(*world).collision->settings().simd = simd;
    for (auto _ : state) {
        if (Result<void> stepped = world->step(); !stepped) {
            state.SkipWithError(stepped.error().c_str());
            return;
        }
    }
}

void BM_Box2d(benchmark::State& state, std::string name) {
    const Scene scene = sceneNamed(name);
    b2World world(b2Vec2(float(scene.world.gravity.x), float(scene.world.gravity.y)));
    world.SetAllowSleeping(false);
    const Registry& r = scene.registry;
    for (Entity e : r.entities())
        if (r.has<Radius>(e) || r.has<Box>(e)) bench::createBox2dBody(world, r, e);
    const float dt = float(scene.world.dt);
    for (auto _ : state) world.Step(dt, 8, 3);
}

int registerAll() {
    for (const BenchScene& s : kScenes) {
        const std::string scene = s.name;
        benchmark::RegisterBenchmark(("Contacts/" + scene + "/stepwise_simd").c_str(), BM_Stepwise, scene, true)
            ->Iterations(s.steps)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("Contacts/" + scene + "/stepwise_one_at_a_time").c_str(), BM_Stepwise, scene,
                                     false)
            ->Iterations(s.steps)
            ->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark(("Contacts/" + scene + "/box2d_2.4.1").c_str(), BM_Box2d, scene)
            ->Iterations(s.steps)
            ->Unit(benchmark::kMillisecond);
    }
    return 0;
}
const int kRegistered = registerAll();

} // namespace

BENCHMARK_MAIN();
