// EXPERIMENT (issue 13, kept only in history): build with
//   g++ -std=c++20 -O2 -Iengine/include -Iengine/src bench/collision/experiment_one_substep.cpp build/engine/libstepwise_engine.a -o /tmp/pile
// and run /tmp/pile 1 with the STEPWISE_* variables read in collision_system.cpp.
// Experiment: 30-row pile at 1 substep, heavy box 100:1, 20-row pyramid.
#include "stepwise/components.hpp"
#include "stepwise/world.hpp"
#include <cstdio>
#include <cmath>
#include <algorithm>
#include <cstdlib>
using namespace stepwise;
static Entity body(Scene& s, Vec2 p, double mass, double fr) {
    const Entity e = s.registry.create();
    s.registry.emplace<Position>(e, Position{p});
    s.registry.emplace<Velocity>(e, Velocity{});
    s.registry.emplace<Mass>(e, Mass{mass});
    s.registry.emplace<Friction>(e, Friction{fr});
    return e;
}
static void staticBox(Scene& s, Vec2 p, double w, double h) {
    const Entity e = s.registry.create();
    s.registry.emplace<Position>(e, Position{p});
    s.registry.emplace<Static>(e, Static{true});
    s.registry.emplace<Box>(e, Box{w, h});
    s.registry.emplace<Friction>(e, Friction{0.6});
}
static Scene base(int substeps, int iters) {
    Scene s; s.world.gravity = {0.0, -10.0}; s.world.dt = 1.0 / 60.0; s.world.substeps = substeps; s.world.solverIterations = iters; return s;
}
int main(int argc, char** argv) {
    const int substeps = argc > 1 ? std::atoi(argv[1]) : 1;
    const int iters = argc > 2 ? std::atoi(argv[2]) : 0;
    { // pile
        Scene s = base(substeps, iters);
        staticBox(s, {0.0, -0.5}, 8.0, 1.0); staticBox(s, {-3.1, 10.0}, 1.0, 22.0); staticBox(s, {3.1, 10.0}, 1.0, 22.0);
        for (int i = 0; i < 300; ++i) {
            const double jitter = 0.01 * double((i * 7919) % 11 - 5) / 5.0;
            const Entity e = body(s, {-2.3 + 0.51 * (i % 10) + jitter, 0.3 + 0.52 * (i / 10)}, 1.0, 0.6);
            s.registry.emplace<Radius>(e, Radius{0.25});
        }
        Result<World> w = World::build(s);
        if (!w) { std::printf("%s\n", w.error().c_str()); return 1; }
        double deepest = 0.0, floorDepth = 0.0, ke = 0.0;
        for (int i = 0; i < 600; ++i) {
            if (!w->step()) { std::printf("pile step failed\n"); return 1; }
            if (i >= 540) for (const ContactRecord& c : w->contacts()) deepest = std::max(deepest, c.depth);
        }
        for (std::size_t b = 0; b < w->bodyCount(); ++b) {
            floorDepth = std::max(floorDepth, 0.25 - w->bodyPosition(b).y);
            ke += 0.5 * std::pow(length(w->bodyVelocity(b)), 2);
        }
        std::printf("pile (%dx%d): deepest overlap %.1f mm, into floor %.1f mm, KE %.3g J\n", w->settings().substeps,
                    w->settings().solverIterations, 1e3 * deepest, 1e3 * floorDepth, ke);
    }
    { // heavy box 100:1 on two light boxes on a floor
        Scene s = base(substeps, iters);
        staticBox(s, {0.0, -0.5}, 20.0, 1.0);
        Entity a = body(s, {-1.0, 0.25}, 1.0, 0.6); s.registry.emplace<Box>(a, Box{0.5, 0.5});
        Entity b = body(s, {1.0, 0.25}, 1.0, 0.6); s.registry.emplace<Box>(b, Box{0.5, 0.5});
        Entity h = body(s, {0.0, 0.75}, 100.0, 0.6); s.registry.emplace<Box>(h, Box{3.0, 0.5});
        Result<World> w = World::build(s);
        double ke = 0.0;
        for (int i = 0; i < 600; ++i) if (!w->step()) { std::printf("heavy failed\n"); return 1; }
        for (std::size_t k = 0; k < w->bodyCount(); ++k) ke += 0.5 * (k == 2 ? 100.0 : 1.0) * std::pow(length(w->bodyVelocity(k)), 2);
        for (std::size_t k = 0; k < 3; ++k) std::printf("  body %zu: p (%.4f, %.4f) v (%.4f, %.4f)\n", k, w->bodyPosition(k).x, w->bodyPosition(k).y, w->bodyVelocity(k).x, w->bodyVelocity(k).y);
        std::printf("heavy 100:1: heavy y %.4f (0.75 expected), x %.4f, KE %.3g J\n", w->bodyPosition(2).y, w->bodyPosition(2).x, ke);
    }
    { // 20-row pyramid of 1 m boxes
        Scene s = base(substeps, iters);
        staticBox(s, {0.0, -0.5}, 60.0, 1.0);
        const int rows = 20; const double size = 1.0;
        for (int row = 0; row < rows; ++row)
            for (int i = 0; i < rows - row; ++i) {
                const double x = (i - (rows - row - 1) * 0.5) * size * 1.05;
                Entity e = body(s, {x, 0.5 * size + row * size}, 1.0, 0.6); s.registry.emplace<Box>(e, Box{size, size});
            }
        Result<World> w = World::build(s);
        const std::size_t top = w->bodyCount() - 1;
        const Vec2 start = w->bodyPosition(top); Vec2 settled; double deepest = 0.0, ke = 0.0;
        for (int i = 0; i < 600; ++i) {
            if (!w->step()) { std::printf("pyramid failed\n"); return 1; }
            if (i == 119) settled = w->bodyPosition(top);
            if (i >= 540) for (const ContactRecord& c : w->contacts()) deepest = std::max(deepest, c.depth);
        }
        for (std::size_t k = 0; k < w->bodyCount(); ++k) ke += 0.5 * std::pow(length(w->bodyVelocity(k)), 2);
        std::printf("pyramid 20 rows: top drift %.2f mm, creep 2-10 s %.3f mm, deepest %.2f mm, KE %.3g J\n",
                    1e3 * length(w->bodyPosition(top) - start), 1e3 * length(w->bodyPosition(top) - settled), 1e3 * deepest, ke);
    }
}
