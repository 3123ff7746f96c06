// Google Benchmark: what one step of a drag costs the editor as the level
// grows. Moving one body should cost the same in a level of 2,000, 20,000
// or 200,000 bodies: in the undo stack (BM_DragOneBody; the peer is a copy
// of the whole scene, BM_CopyScene) and, while paused, in the live World
// too (BM_DragOneBodyWhilePaused; the peer is a rebuild of the World from
// the scene, BM_ReloadWorld, which an edit that is not a move still costs).
// A mass edit goes in place as well (BM_SetMassOfOneBody), and so do a
// radius (BM_ReshapeOneBody) and a body added and deleted
// (BM_AddAndDeleteOneBody, two edits an iteration; BM_AddOneBody, the add
// alone, which is appended in place; BM_DeleteAndUndoOneBody, a body
// brought back where it stood). The engine's choice of
// settings, which reads the whole scene, is checked once before the next
// step however many edits came (BM_SetMassAndSettle: one edit and that
// check, the cost a frame that edits and then steps pays).
// Not part of ctest.
//
//   build/bench/editor_bench --benchmark_min_time=0.2

#include "app/command_stack.hpp"
#include "app/editor.hpp"
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

/// One step of a drag in the editor while the run is paused: the undo
/// record and the live World's body, in place.
void BM_DragOneBodyWhilePaused(benchmark::State& state) {
    editor::Editor ed;
    ed.doc.reset(scenes::circlesInBox(int(state.range(0))));
    ed.stepForward();
    const std::vector<Entity> bodies = bodiesOf(ed.doc.scene);
    const Entity dragged = bodies[bodies.size() / 2];
    const std::uint64_t builds = ed.sim.worldBuilds();
    double dx = 0.0;
    for (auto _ : state) {
        dx += 1e-3;
        const bool done = ed.applyEdit("drag", [&](Scene& s) {
            s.registry.tryGet<Position>(dragged)->value.x += dx;
            return true;
        }, 1);
        benchmark::DoNotOptimize(done);
    }
    ed.stepForward();
    if (ed.sim.worldBuilds() != builds) state.SkipWithError("the drag rebuilt the World");
}
BENCHMARK(BM_DragOneBodyWhilePaused)->Arg(2000)->Arg(20000)->Arg(200000)->Unit(benchmark::kMicrosecond);

/// A mass edit in place (World::setMass): one body's mass alternates by a
/// part in a billion, which leaves the engine's choice of settings as it
/// is; with `settle`, each edit is followed by the check of that choice the
/// next step makes first (World::settleChoice).
void setMassOfOneBody(benchmark::State& state, bool settle) {
    Scene scene = scenes::circlesInBox(int(state.range(0)));
    const std::vector<Entity> bodies = bodiesOf(scene);
    const Entity edited = bodies[bodies.size() / 2];
    Result<World> world = World::build(scene);
    bool heavier = false;
    for (auto _ : state) {
        heavier = !heavier;
        scene.registry.emplace<Mass>(edited, Mass{heavier ? 1.0 + 1e-9 : 1.0});
        Result<void> set = world->setMass(scene, edited);
        if (set && settle) set = world->settleChoice(scene);
        if (!set) state.SkipWithError(set.error().c_str());
    }
    state.counters["bodies"] = double(bodies.size());
}
void BM_SetMassOfOneBody(benchmark::State& state) { setMassOfOneBody(state, false); }
BENCHMARK(BM_SetMassOfOneBody)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);
void BM_SetMassAndSettle(benchmark::State& state) { setMassOfOneBody(state, true); }
BENCHMARK(BM_SetMassAndSettle)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);

/// A radius edit in place (World::reshapeBody): one circle alternates
/// between two sizes a part in a billion apart.
void BM_ReshapeOneBody(benchmark::State& state) {
    Scene scene = scenes::circlesInBox(int(state.range(0)));
    const std::vector<Entity> bodies = bodiesOf(scene);
    const Entity edited = bodies[bodies.size() / 2];
    const double radius = scene.registry.tryGet<Radius>(edited)->value;
    Result<World> world = World::build(scene);
    bool larger = false;
    for (auto _ : state) {
        larger = !larger;
        scene.registry.tryGet<Radius>(edited)->value = larger ? radius * (1.0 + 1e-9) : radius;
        Result<void> set = world->reshapeBody(scene, {}, edited);
        if (!set) state.SkipWithError(set.error().c_str());
    }
    state.counters["bodies"] = double(bodies.size());
}
BENCHMARK(BM_ReshapeOneBody)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);

/// A ball added above the box and deleted again, each in place
/// (World::changeEntities): with `addOnly`, only the add is timed (the
/// delete that keeps the level's size is not).
void addAndDeleteOneBody(benchmark::State& state, bool addOnly) {
    Scene scene = scenes::circlesInBox(int(state.range(0)));
    const std::vector<Entity> bodies = bodiesOf(scene);
    Result<World> world = World::build(scene);
    const Vec2 above = scene.registry.tryGet<Position>(bodies.back())->value + Vec2{0.0, 2.0};
    for (auto _ : state) {
        const Entity e = scene.registry.create();
        scene.registry.emplace<Position>(e, Position{above});
        scene.registry.emplace<Radius>(e, Radius{0.1});
        const Result<void> added = world->changeEntities(scene, {}, {}, std::vector<Entity>{e});
        if (addOnly) state.PauseTiming();
        (void)scene.registry.destroy(e);
        const Result<void> removed = world->changeEntities(scene, {}, std::vector<Entity>{e}, {});
        if (!added || !removed) state.SkipWithError((added ? removed : added).error().c_str());
        if (addOnly) state.ResumeTiming();
    }
    state.counters["bodies"] = double(bodies.size());
}
/// Two edits per iteration, against two reloads.
void BM_AddAndDeleteOneBody(benchmark::State& state) { addAndDeleteOneBody(state, false); }
BENCHMARK(BM_AddAndDeleteOneBody)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);
void BM_AddOneBody(benchmark::State& state) { addAndDeleteOneBody(state, true); }
BENCHMARK(BM_AddOneBody)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);

/// A body in the middle of the level deleted and brought back where it
/// stood in the scene order, as an undo of the delete restores it, each
/// in place: two edits per iteration.
void BM_DeleteAndUndoOneBody(benchmark::State& state) {
    Scene scene = scenes::circlesInBox(int(state.range(0)));
    const std::vector<Entity> bodies = bodiesOf(scene);
    Result<World> world = World::build(scene);
    const Entity middle = bodies[bodies.size() / 2];
    Registry aside;
    const Entity copy = aside.create();
    copyComponents(scene.registry, middle, aside, copy);
    for (auto _ : state) {
        const Registry::Slots before = scene.registry.slots();
        (void)scene.registry.destroy(middle);
        const Result<void> removed = world->changeEntities(scene, {}, std::vector<Entity>{middle}, {});
        scene.registry.setSlots(before);
        copyComponents(aside, copy, scene.registry, middle);
        const Result<void> back = world->changeEntities(scene, {}, {}, std::vector<Entity>{middle});
        if (!removed || !back) state.SkipWithError((removed ? back : removed).error().c_str());
    }
}
BENCHMARK(BM_DeleteAndUndoOneBody)->Arg(2'000)->Arg(20'000)->Arg(200'000)->Unit(benchmark::kMicrosecond);

/// The peer: the World rebuilt from the scene (World::reload).
void BM_ReloadWorld(benchmark::State& state) {
    const Scene scene = scenes::circlesInBox(int(state.range(0)));
    Result<World> world = World::build(scene);
    for (auto _ : state) {
        Result<void> reloaded = world->reload(scene);
        benchmark::DoNotOptimize(reloaded.ok());
    }
}
BENCHMARK(BM_ReloadWorld)->Arg(2000)->Arg(20000)->Arg(200000)->Unit(benchmark::kMicrosecond);

} // namespace

BENCHMARK_MAIN();
