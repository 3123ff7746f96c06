#include "collision/collision_scenes.hpp"

#include "stepwise/components.hpp"

#include <cmath>

namespace stepwise::bench {

namespace {

Entity body(Scene& s, const std::string& name, Vec2 p, Rgb color) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{name});
    r.emplace<Position>(e, Position{p});
    r.emplace<Color>(e, Color{color});
    return e;
}

void staticBox(Scene& s, const std::string& name, Vec2 p, double w, double h) {
    const Entity e = body(s, name, p, Rgb{0.36, 0.40, 0.47});
    s.registry.emplace<Static>(e, Static{true});
    s.registry.emplace<Box>(e, Box{w, h});
    s.registry.emplace<Friction>(e, Friction{0.6});
}

/// A deterministic pastel palette cycling with the index.
Rgb palette(int i) {
    static const Rgb colours[] = {{0.96, 0.65, 0.36}, {0.42, 0.74, 0.87}, {0.55, 0.82, 0.55},
                                  {0.93, 0.49, 0.55}, {0.78, 0.64, 0.92}, {0.98, 0.86, 0.42}};
    return colours[i % 6];
}

/// Cheap deterministic jitter in [-1, 1] (no std::random: its distributions
/// are not specified bit-for-bit across library versions).
double jitter(int i) {
    const std::uint32_t h = std::uint32_t(i) * 2654435761u;
    return double(h >> 8) / double(1u << 24) * 2.0 - 1.0;
}

void contactWorld(Scene& s, int substeps, int iterations) {
    s.world.gravity = {0.0, -10.0};
    s.world.dt = 1.0 / 60.0;
    s.world.substeps = substeps;
    s.world.solverIterations = iterations;
    s.world.integrator = "semi_implicit_euler";
}

/// prefix + number, built by appending (GCC 12 warns falsely, -Wrestrict,
/// on "literal" + std::string temporaries).
std::string label(const char* prefix, int i) {
    std::string s = prefix;
    s += std::to_string(i);
    return s;
}

} // namespace

Scene circlesInBox(int count) {
    Scene s;
    contactWorld(s, 4, 2);
    staticBox(s, "floor", {0.0, -0.5}, 32.0, 1.0);
    staticBox(s, "left wall", {-15.5, 15.0}, 1.0, 30.0);
    staticBox(s, "right wall", {15.5, 15.0}, 1.0, 30.0);
    const int perRow = 50;
    for (int i = 0; i < count; ++i) {
        const double x = -14.0 + 0.57 * (i % perRow) + 0.02 * jitter(i);
        const double y = 1.0 + 0.57 * (i / perRow);
        const Entity e = body(s, label("c", i), {x, y}, palette(i));
        s.registry.emplace<Radius>(e, Radius{0.25});
        s.registry.emplace<Friction>(e, Friction{0.6});
    }
    s.view = View{{0.0, 12.0}, 22.0};
    return s;
}

Scene boxPyramid(int rows) {
    Scene s;
    // One biased iteration per substep (and one relax): the two-point block
    // solve settles a box stack in one pass (levels/pyramid.json, the same).
    contactWorld(s, 4, 1);
    staticBox(s, "ground", {0.0, -0.5}, 60.0, 1.0);
    int index = 0;
    for (int row = 0; row < rows; ++row) {
        for (int i = 0; i < rows - row; ++i) {
            const double x = (i - (rows - row - 1) * 0.5) * 1.05;
            const Entity e = body(s, label("box ", row) + label(".", i), {x, 0.5 + row},
                                  palette(index++));
            s.registry.emplace<Box>(e, Box{1.0, 1.0});
            s.registry.emplace<Friction>(e, Friction{0.6});
        }
    }
    s.view = View{{0.0, double(rows) * 0.5}, 720.0 / (rows * 1.6)};
    return s;
}

Scene circleRain(int count) {
    Scene s;
    contactWorld(s, 4, 1);  // one iteration: less overlap than Box2D still, and 1.2x its speed
    staticBox(s, "basin floor", {0.0, -0.5}, 22.0, 1.0);
    staticBox(s, "basin left", {-10.5, 5.0}, 1.0, 10.0);
    staticBox(s, "basin right", {10.5, 5.0}, 1.0, 10.0);
    for (int i = 0; i < count; ++i) {
        // A sparse column 8 m wide and ~100 m tall: drops arrive over ~4 s.
        const double x = -4.0 + 8.0 * (0.5 + 0.5 * jitter(i));
        const double y = 10.0 + 0.1 * i + 0.05 * jitter(i + 7919);
        const Entity e = body(s, label("drop ", i), {x, y}, palette(i));
        s.registry.emplace<Velocity>(e, Velocity{{0.0, -5.0}});
        s.registry.emplace<Radius>(e, Radius{0.15 + 0.05 * (i % 3)});
        s.registry.emplace<Friction>(e, Friction{0.4});
        s.registry.emplace<Restitution>(e, Restitution{0.2});
        // Air resistance: terminal speed m g / b = 10 m/s, as for real drops
        // (and so the basin is hit at rain speed, not at 45 m/s).
        s.registry.emplace<Drag>(e, Drag{1.0});
    }
    s.view = View{{0.0, 8.0}, 36.0};
    return s;
}

std::vector<NamedScene> benchmarkScenes() {
    std::vector<NamedScene> scenes;
    scenes.push_back({"pile", circlesInBox(), 10.0});
    // Issue 16's smaller pile (900 steps): the same box, 300 circles.
    scenes.push_back({"pile300", circlesInBox(300), 15.0});
    scenes.push_back({"pyramid", boxPyramid(), 10.0});
    scenes.push_back({"rain", circleRain(), 20.0});  // the last drops land after ~12 s
    return scenes;
}

} // namespace stepwise::bench
