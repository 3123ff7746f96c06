#include "generated_scenes.hpp"

#include "stepwise/components.hpp"

#include <cmath>
#include <cstdint>

namespace stepwise::scenes {

namespace {

Entity body(Scene& s, const std::string& name, Vec2 p, Rgb color) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{name});
    r.emplace<Position>(e, Position{p});
    r.emplace<Color>(e, Color{color});
    return e;
}

/// A named grey static box with friction 0.6: the benchmark scenes' walls.
void wall(Scene& s, const std::string& name, Vec2 p, double w, double h) {
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

void contactWorld(Scene& s, int substeps, int iterations) {
    s.world.gravity = {0.0, -10.0};
    s.world.dt = 1.0 / 60.0;
    s.world.substeps = substeps;
    s.world.solverIterations = iterations;
    s.world.integrator = "semi_implicit_euler";
}

/// prefix + number, built by appending (GCC 12 warns falsely, -Wrestrict,
/// on "literal" + std::string temporaries).
std::string label(const std::string& prefix, int i) {
    std::string s = prefix;
    s += std::to_string(i);
    return s;
}

} // namespace

double hashJitter(int i) {
    const std::uint32_t h = std::uint32_t(i) * 2654435761u;
    return double(h >> 8) / double(1u << 24) * 2.0 - 1.0;
}

void addCircleGrid(Scene& s, const CircleGrid& g) {
    Registry& r = s.registry;
    std::uint32_t lcg = 7u;  // Jitter::Lcg's state, advanced once per circle
    for (int i = 0; i < g.count; ++i) {
        const int column = i % g.columns, row = i / g.columns;
        // Each written so the product with the amplitude rounds as the
        // scenes were first measured with.
        double offset = 0.0;
        switch (g.jitter) {
        case Jitter::None: break;
        case Jitter::Hash: offset = g.jitterAmplitude * hashJitter(i); break;
        case Jitter::Lcg:
            lcg = lcg * 1664525u + 1013904223u;
            offset = g.jitterAmplitude * ((double(lcg >> 8) / double(1u << 24) - 0.5) * 2.0);
            break;
        case Jitter::Mod11: offset = g.jitterAmplitude * double((i * 7919) % 11 - 5) / 5.0; break;
        }
        const Vec2 centre{g.first.x + g.pitch.x * column + offset + g.centring, g.first.y + g.pitch.y * row};
        const Entity e = r.create();
        if (!g.namePrefix.empty()) r.emplace<Name>(e, Name{label(g.namePrefix, i)});
        r.emplace<Position>(e, Position{centre});
        if (g.velocityPerJitter)  // a zero factor gives +0, not -0 for a negative offset
            r.emplace<Velocity>(e, Velocity{{*g.velocityPerJitter == 0.0 ? 0.0 : offset * *g.velocityPerJitter, 0.0}});
        if (g.mass) r.emplace<Mass>(e, Mass{*g.mass});
        r.emplace<Radius>(e, Radius{g.radius});
        if (g.friction) r.emplace<Friction>(e, Friction{*g.friction});
        switch (g.colours) {
        case CircleColours::None: break;
        case CircleColours::Palette: r.emplace<Color>(e, Color{palette(i)}); break;
        case CircleColours::Gradient:
            r.emplace<Color>(e, Color{Rgb{0.3 + 0.6 * double(column) / g.columns, 0.5,
                                          0.9 - 0.5 * double(row % 20) / 20.0}});
            break;
        }
    }
}

Entity addStaticBox(Scene& s, Vec2 centre, double width, double height) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Position>(e, Position{centre});
    r.emplace<Static>(e, Static{true});
    r.emplace<Box>(e, Box{width, height});
    return e;
}

Entity addHinge(Registry& r, Entity a, Entity b, Vec2 localA, Vec2 localB) {
    Joint joint;
    joint.type = "hinge";
    joint.a = a;
    joint.b = b;
    joint.localA = localA;
    joint.localB = localB;
    joint.referenceAngle = 0.0;
    const Entity j = r.create();
    r.emplace<Joint>(j, joint);
    return j;
}

Scene circlesInBox(int count) {
    Scene s;
    contactWorld(s, 4, 2);
    wall(s, "floor", {0.0, -0.5}, 32.0, 1.0);
    wall(s, "left wall", {-15.5, 15.0}, 1.0, 30.0);
    wall(s, "right wall", {15.5, 15.0}, 1.0, 30.0);
    CircleGrid grid;
    grid.count = count;
    grid.columns = 50;
    grid.first = {-14.0, 1.0};
    grid.pitch = {0.57, 0.57};
    grid.jitter = Jitter::Hash;
    grid.jitterAmplitude = 0.02;
    grid.friction = 0.6;
    grid.namePrefix = "c";
    grid.colours = CircleColours::Palette;
    addCircleGrid(s, grid);
    s.view = View{{0.0, 12.0}, 22.0};
    return s;
}

Scene boxPyramid(int rows) {
    Scene s;
    // One biased iteration per substep (and one relax): the two-point block
    // solve settles a box stack in one pass (levels/pyramid.json, the same).
    contactWorld(s, 4, 1);
    wall(s, "ground", {0.0, -0.5}, 60.0, 1.0);
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
    wall(s, "basin floor", {0.0, -0.5}, 22.0, 1.0);
    wall(s, "basin left", {-10.5, 5.0}, 1.0, 10.0);
    wall(s, "basin right", {10.5, 5.0}, 1.0, 10.0);
    for (int i = 0; i < count; ++i) {
        // A sparse column 8 m wide and ~100 m tall: drops arrive over ~4 s.
        const double x = -4.0 + 8.0 * (0.5 + 0.5 * hashJitter(i));
        const double y = 10.0 + 0.1 * i + 0.05 * hashJitter(i + 7919);
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
    // The smaller pile of the solver benchmark (900 steps): the same box, 300 circles.
    scenes.push_back({"pile300", circlesInBox(300), 15.0});
    scenes.push_back({"pyramid", boxPyramid(), 10.0});
    scenes.push_back({"rain", circleRain(), 20.0});  // the last drops land after ~12 s
    return scenes;
}

Scene tallPile() {
    Scene s;
    s.world.gravity = {0.0, -10.0};
    s.world.dt = 1.0 / 60.0;
    addStaticBox(s, {0.0, -0.5}, 8.0, 1.0);
    addStaticBox(s, {-3.1, 10.0}, 1.0, 22.0);
    addStaticBox(s, {3.1, 10.0}, 1.0, 22.0);
    CircleGrid grid;
    grid.count = 300;
    grid.columns = 10;
    grid.first = {-2.3, 0.3};
    grid.pitch = {0.51, 0.52};
    grid.jitter = Jitter::Mod11;
    grid.jitterAmplitude = 0.01;
    grid.velocityPerJitter = 0.0;
    grid.mass = 1.0;
    grid.friction = 0.6;
    addCircleGrid(s, grid);
    return s;
}

} // namespace stepwise::scenes
