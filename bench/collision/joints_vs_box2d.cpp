// Joints: Stepwise against Box2D 2.4.1 (Debian libbox2d-dev) on the same
// level files, in the same run: ms per step and the largest joint
// separation (the distance between a hinge's two anchor points, which a
// rigid hinge keeps at zero) over the whole run.
//
//   joints_vs_box2d [--quick] [LEVEL ...]      (default: levels/chain.json levels/bridge.json)
//   joints_vs_box2d --grid [--n N] [--substeps S] [--iterations I] [--steps K]
//                          [--joint-hz HZ] [--joint-damping-ratio Z] [--stepwise-only]
//
// --grid builds Box2D v3's `joint_grid` benchmark scene (shared/benchmarks.c:
// N x N circles of radius 0.4 m, 1 m apart, each hinged to its right and
// lower neighbours at the midpoints, the middle seven of the top row
// static) in both engines and runs it at the given substeps and iterations
// (default 4 and 1, v3's defaults; N 100, 60 steps). Box2D v3.1.1's own
// figures on this machine (1 iteration, 4 substeps): 7.05 ms/step, largest
// separation 0.36 m.
//
// Both engines are built from the parsed level: bodies with circle and box
// shapes, hinge joints (b2RevoluteJoint with the same anchors, limits and
// motor). Box2D runs 8 velocity and 3 position iterations with sleeping off;
// Stepwise runs the level's substeps and iterations. Times are the thread's
// CPU time (both engines, same clock). Each engine runs three
// times, alternating, and its fastest run counts (--quick: once, a fifth of
// the steps).

#include "generated_scenes.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "collision/box2d_bodies.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <iostream>
#include <string>
#include <unordered_map>
#include <vector>

using namespace stepwise;

namespace {

/// This thread's CPU time, s: on the shared machine other processes take
/// turns on the cores, which a wall clock would count against whichever
/// engine was running.
double cpuSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Outcome {
    double msPerStep = 0.0;
    double largestSeparation = 0.0;  ///< metres, over every joint and step
    double finalSeparation = 0.0;    ///< metres, largest at the last step
    int divergedAt = -1;             ///< Stepwise: the step that failed (non-finite state), -1: none
};

/// Box2D v3's joint_grid (see the file comment), as a Stepwise scene.
Scene jointGrid(int n, int substeps, int iterations) {
    Scene scene;
    scene.world.gravity = {0.0, -10.0};
    scene.world.substeps = substeps;
    scene.world.solverIterations = iterations;
    scene.world.sleep = false;
    Registry& r = scene.registry;
    const double radius = 0.4, mass = M_PI * radius * radius;  // density 1
    std::vector<Entity> bodies;
    bodies.reserve(std::size_t(n) * std::size_t(n));
    for (int k = 0; k < n; ++k)
        for (int i = 0; i < n; ++i) {
            const Entity e = r.create();
            r.emplace<Name>(e, Name{"c" + std::to_string(k) + "_" + std::to_string(i)});
            r.emplace<Position>(e, Position{{double(k), -double(i)}});
            r.emplace<Radius>(e, Radius{radius});
            if (k >= n / 2 - 3 && k <= n / 2 + 3 && i == 0) r.emplace<Static>(e, Static{true});
            else r.emplace<Mass>(e, Mass{mass});
            const auto hinge = [&](Entity a, Vec2 localA, Vec2 localB) {
                // Box2D keeps a joint between two static anchors and never
                // solves it; Stepwise refuses one, so it is left out.
                if (r.has<Static>(a) && r.has<Static>(e)) return;
                scenes::addHinge(r, a, e, localA, localB);
            };
            if (i > 0) hinge(bodies.back(), {0.0, -0.5}, {0.0, 0.5});
            if (k > 0) hinge(bodies[bodies.size() - std::size_t(n)], {0.5, 0.0}, {-0.5, 0.0});
            bodies.push_back(e);
        }
    return scene;
}


Outcome runStepwise(const Scene& level, int steps) {
    Scene scene = level;
    scene.world.sleep = false;  // Box2D runs with sleeping off too
    Result<World> built = World::build(scene);
    if (!built) {
        std::cerr << "stepwise cannot build the level: " << built.error() << "\n";
        std::exit(1);
    }
    World& world = *built;
    world.setProfiling(false);
    Outcome out;
    double seconds = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double start = cpuSeconds();
        if (Result<void> r = world.step(); !r) {
            std::cerr << "stepwise diverged at step " << i << ": " << r.error() << "\n";
            out.divergedAt = i;
            out.msPerStep = 1e3 * seconds / std::max(i, 1);
            return out;
        }
        seconds += cpuSeconds() - start;
        double worst = 0.0;
        for (const JointRecord& j : world.joints()) worst = std::max(worst, j.separation);
        out.largestSeparation = std::max(out.largestSeparation, worst);
        out.finalSeparation = worst;
    }
    out.msPerStep = 1e3 * seconds / steps;
    return out;
}

Outcome runBox2d(const Scene& scene, int steps) {
    const Registry& r = scene.registry;
    b2World world(b2Vec2(float(scene.world.gravity.x), float(scene.world.gravity.y)));
    world.SetAllowSleeping(false);
    std::unordered_map<std::uint32_t, b2Body*> bodyOf;
    b2BodyDef groundDef;
    b2Body* worldBody = world.CreateBody(&groundDef);
    for (Entity e : r.entities()) {
        const Position* p = r.tryGet<Position>(e);
        if (!p) continue;
        b2Body* body = bench::createBox2dBody(world, r, e);
        bodyOf.emplace(e.index, body);
    }
    std::vector<b2Joint*> joints;
    for (Entity e : r.entities()) {
        const Joint* j = r.tryGet<Joint>(e);
        if (!j) continue;
        if (j->type != "hinge") {
            std::cerr << "joints_vs_box2d compares hinges only; skipping a " << j->type << "\n";
            continue;
        }
        b2RevoluteJointDef def;
        def.bodyA = bodyOf.at(j->a.index);
        def.bodyB = j->b.isNull() ? worldBody : bodyOf.at(j->b.index);
        def.localAnchorA.Set(float(j->localA.x), float(j->localA.y));
        def.localAnchorB.Set(float(j->localB.x), float(j->localB.y));
        def.referenceAngle = float(j->referenceAngle.value_or(0.0));
        def.collideConnected = j->collideConnected;
        if (j->lower || j->upper) {
            def.enableLimit = true;
            def.lowerAngle = float(j->lower.value_or(-1e9));
            def.upperAngle = float(j->upper.value_or(1e9));
        }
        if (j->maxMotorTorque) {
            def.enableMotor = true;
            def.motorSpeed = float(j->motorSpeed.value_or(0.0));
            def.maxMotorTorque = float(*j->maxMotorTorque);
        }
        joints.push_back(world.CreateJoint(&def));
    }
    const float dt = float(scene.world.dt);
    Outcome out;
    double seconds = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double start = cpuSeconds();
        world.Step(dt, 8, 3);
        seconds += cpuSeconds() - start;
        double worst = 0.0;
        for (b2Joint* joint : joints) {
            const b2Vec2 d = joint->GetAnchorB() - joint->GetAnchorA();
            worst = std::max(worst, double(d.Length()));
        }
        out.largestSeparation = std::max(out.largestSeparation, worst);
        out.finalSeparation = worst;
    }
    out.msPerStep = 1e3 * seconds / steps;
    return out;
}

} // namespace

int runGrid(int n, int substeps, int iterations, int steps, double hz, double zeta, bool stepwiseOnly) {
    Scene scene = jointGrid(n, substeps, iterations);
    if (hz > 0.0) scene.world.jointHz = hz;
    if (zeta >= 0.0) scene.world.jointDampingRatio = zeta;
    const Outcome s = runStepwise(scene, steps);
    const Outcome b = stepwiseOnly ? Outcome{} : runBox2d(scene, steps);
    std::printf("joint_grid %dx%d, %d steps; Stepwise %d substeps x %d iterations, Box2D 2.4.1 8+3 iterations\n", n, n,
                steps, substeps, iterations);
    std::printf("| engine | ms/step | largest separation, m | at the end, m | diverged at step |\n|---|---|---|---|---|\n");
    std::printf("| Stepwise | %.3f | %.4f | %.4f | %d |\n", s.msPerStep, s.largestSeparation, s.finalSeparation,
                s.divergedAt);
    std::printf("| Box2D 2.4.1 | %.3f | %.4f | %.4f | - |\n", b.msPerStep, b.largestSeparation, b.finalSeparation);
    std::printf("speed ratio (Box2D ms / Stepwise ms): %.2fx\n", b.msPerStep / s.msPerStep);
    return s.divergedAt >= 0 ? 1 : 0;
}

int main(int argc, char** argv) {
    bool quick = false, grid = false, stepwiseOnly = false;
    int n = 100, substeps = 4, iterations = 1, steps = 60;
    double hz = 0.0, zeta = -1.0;  // joint_hz, joint_damping_ratio; unset: the engine's choice
    std::vector<std::string> levels;
    for (int i = 1; i < argc; ++i) {
        const auto next = [&] { return i + 1 < argc ? std::atoi(argv[++i]) : 0; };
        if (std::strcmp(argv[i], "--quick") == 0) quick = true;
        else if (std::strcmp(argv[i], "--grid") == 0) grid = true;
        else if (std::strcmp(argv[i], "--stepwise-only") == 0) stepwiseOnly = true;  // for profiling
        else if (std::strcmp(argv[i], "--n") == 0) n = next();
        else if (std::strcmp(argv[i], "--substeps") == 0) substeps = next();
        else if (std::strcmp(argv[i], "--iterations") == 0) iterations = next();
        else if (std::strcmp(argv[i], "--steps") == 0) steps = next();
        else if (std::strcmp(argv[i], "--joint-hz") == 0 && i + 1 < argc) hz = std::atof(argv[++i]);
        else if (std::strcmp(argv[i], "--joint-damping-ratio") == 0 && i + 1 < argc) zeta = std::atof(argv[++i]);
        else levels.push_back(argv[i]);
    }
    if (grid) return runGrid(n, substeps, iterations, steps, hz, zeta, stepwiseOnly);
    if (levels.empty()) levels = {STEPWISE_SOURCE_DIR "/levels/chain.json", STEPWISE_SOURCE_DIR "/levels/bridge.json"};
    const int runs = quick ? 1 : 3;
    std::printf("| level | joints | speed (Box2D ms / Stepwise ms) | largest joint separation, mm (Stepwise / Box2D) | "
                "at the end, mm (Stepwise / Box2D) |\n|---|---|---|---|---|\n");
    for (const std::string& path : levels) {
        Result<Scene> scene = loadSceneFile(path);
        if (!scene) {
            std::cerr << scene.error() << "\n";
            return 2;
        }
        const int steps = quick ? 120 : 600;  // 10 s at 60 Hz
        Outcome best[2];
        for (int run = 0; run < runs; ++run) {
            const Outcome s = runStepwise(*scene, steps);
            const Outcome b = runBox2d(*scene, steps);
            if (run == 0 || s.msPerStep < best[0].msPerStep) best[0] = s;
            if (run == 0 || b.msPerStep < best[1].msPerStep) best[1] = b;
        }
        std::size_t jointCount = 0;
        for (Entity e : scene->registry.entities()) jointCount += scene->registry.has<Joint>(e);
        std::printf("| %s | %zu | %.2fx (%.3f vs %.3f ms) | %.3f / %.3f | %.3f / %.3f |\n",
                    path.substr(path.find_last_of('/') + 1).c_str(), jointCount, best[1].msPerStep / best[0].msPerStep,
                    best[1].msPerStep, best[0].msPerStep, 1e3 * best[0].largestSeparation,
                    1e3 * best[1].largestSeparation, 1e3 * best[0].finalSeparation, 1e3 * best[1].finalSeparation);
    }
    return 0;
}
