#include "box2d_scenes.hpp"

#include "stepwise/components.hpp"

#include <cmath>
#include <optional>
#include <tuple>

namespace stepwise::bench {

namespace {

constexpr double kPi = 3.14159265358979323846;

const Rgb kGrey{0.36, 0.40, 0.47};

Rgb palette(int i) {
    static const Rgb colours[] = {{0.96, 0.65, 0.36}, {0.42, 0.74, 0.87}, {0.55, 0.82, 0.55},
                                  {0.93, 0.49, 0.55}, {0.78, 0.64, 0.92}, {0.98, 0.86, 0.42}};
    return colours[i % 6];
}

/// Box2D v3's defaults for a world: gravity -10, and the step its benchmark
/// runs (60 Hz, 4 substeps, one relaxed iteration each, no sleeping).
Scene v3World() {
    Scene s;
    s.world.gravity = {0.0, -10.0};
    s.world.dt = 1.0 / 60.0;
    s.world.substeps = 4;
    s.world.solverIterations = 1;
    s.world.sleep = false;
    return s;
}

Entity body(Scene& s, std::string name, Vec2 p, double friction, Rgb colour) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{std::move(name)});
    r.emplace<Position>(e, Position{p});
    r.emplace<Friction>(e, Friction{friction});
    r.emplace<Color>(e, Color{colour});
    return e;
}

/// A static box (Box2D's ground shapes: boxes, segments and chain links).
Entity staticBox(Scene& s, std::string name, Vec2 p, double w, double h, double friction = 0.6, double angle = 0.0) {
    const Entity e = body(s, std::move(name), p, friction, kGrey);
    s.registry.emplace<Static>(e, Static{true});
    s.registry.emplace<Box>(e, Box{w, h});
    if (angle != 0.0) s.registry.emplace<Angle>(e, Angle{angle});
    return e;
}

/// A dynamic box of Box2D's density (mass = density * area, as b2ShapeDef).
Entity dynamicBox(Scene& s, std::string name, Vec2 p, double w, double h, double density, double friction, Rgb c) {
    const Entity e = body(s, std::move(name), p, friction, c);
    s.registry.emplace<Box>(e, Box{w, h});
    s.registry.emplace<Mass>(e, Mass{density * w * h});
    return e;
}

Entity dynamicCircle(Scene& s, std::string name, Vec2 p, double r, double density, double friction, Rgb c) {
    const Entity e = body(s, std::move(name), p, friction, c);
    s.registry.emplace<Radius>(e, Radius{r});
    s.registry.emplace<Mass>(e, Mass{density * kPi * r * r});
    return e;
}

void hinge(Scene& s, std::string name, Entity a, std::optional<Entity> b, Vec2 localA, Vec2 localB) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{std::move(name)});
    Joint j;
    j.type = "hinge";
    j.a = a;
    if (b) j.b = *b;
    j.localA = localA;
    j.localB = localB;
    j.referenceAngle = 0.0;
    r.emplace<Joint>(e, j);
}

/// A motor hinge from `a` to the world point `pivot`.
void motorToWorld(Scene& s, std::string name, Entity a, Vec2 aPosition, Vec2 pivot, double speed, double torque) {
    Registry& r = s.registry;
    const Entity e = r.create();
    r.emplace<Name>(e, Name{std::move(name)});
    Joint j;
    j.type = "hinge";
    j.a = a;
    j.localA = pivot - aPosition;
    j.localB = pivot;
    j.referenceAngle = 0.0;
    j.motorSpeed = speed;
    j.maxMotorTorque = torque;
    r.emplace<Joint>(e, j);
}

std::string label(const char* prefix, int a, int b) {
    std::string s = prefix;
    s += std::to_string(a);
    s += '.';
    s += std::to_string(b);
    return s;
}

// CreateJointGrid: 100 x 100 circles (r 0.4, density 1) 1 m apart, each
// hinged to its neighbour above and to its left; seven bodies of the top
// row (the middle ones) are static; a filter keeps the circles apart.
Scene jointGrid() {
    Scene s = v3World();
    const int n = 100;
    std::vector<Entity> bodies;
    std::vector<bool> fixed;
    for (int k = 0; k < n; ++k) {
        for (int i = 0; i < n; ++i) {
            const bool isStatic = k >= n / 2 - 3 && k <= n / 2 + 3 && i == 0;
            const Entity e = dynamicCircle(s, label("node ", k, i), {double(k), -double(i)}, 0.4, 1.0, 0.6,
                                           isStatic ? kGrey : palette(k + i));
            // Box2D's filter: category 2, mask ~2, so the circles never
            // collide with one another (only their joints hold them).
            s.registry.emplace<Filter>(e, Filter{2u, ~2u, 0});
            if (isStatic) {
                s.registry.remove<Mass>(e);
                s.registry.emplace<Static>(e, Static{true});
            }
            // Two static ends make no constraint (Box2D keeps such joints
            // and solves nothing; the format refuses them).
            if (i > 0 && !(isStatic && fixed.back()))
                hinge(s, label("v ", k, i), bodies.back(), e, {0.0, -0.5}, {0.0, 0.5});
            if (k > 0 && !(isStatic && fixed[bodies.size() - n]))
                hinge(s, label("h ", k, i), bodies[bodies.size() - n], e, {0.5, 0.0}, {-0.5, 0.0});
            bodies.push_back(e);
            fixed.push_back(isStatic);
        }
    }
    s.view = View{{50.0, -50.0}, 6.0};
    return s;
}

// CreateLargePyramid: 100 boxes at the base, 1 m squares of density 1 set
// edge to edge (no gap) on a 200 x 2 m ground.
Scene largePyramid() {
    Scene s = v3World();
    staticBox(s, "ground", {0.0, -1.0}, 200.0, 2.0);
    const int base = 100;
    int index = 0;
    for (int i = 0; i < base; ++i)
        for (int j = i; j < base; ++j)
            dynamicBox(s, label("box ", i, j), {(i + 1.0) * 0.5 + (j - i) - 0.5 * base, i + 0.5}, 1.0, 1.0, 1.0, 0.6,
                       palette(index++));
    s.view = View{{0.0, 50.0}, 6.5};
    return s;
}

// CreateManyPyramids: 20 x 20 pyramids of base 10 (1 m boxes), each row on
// its own 220 m ground segment, rows 11 m apart.
Scene manyPyramids() {
    Scene s = v3World();
    const int base = 10, rows = 20, columns = 20;
    const double extent = 0.5;
    const double groundDeltaY = 2.0 * extent * (base + 1.0);
    const double groundWidth = 2.0 * extent * columns * (base + 1.0);
    // Box2D's segments are two-sided; each row's ground is a two-point
    // chain, solid on top (drawn right to left), which is all a pyramid meets.
    for (int i = 0; i < rows; ++i) {
        const Entity ground = body(s, "ground " + std::to_string(i), {0.0, i * groundDeltaY}, 0.6, kGrey);
        s.registry.emplace<Static>(ground, Static{true});
        s.registry.emplace<Chain>(ground, Chain{{{0.5 * groundWidth, 0.0}, {-0.5 * groundWidth, 0.0}}, false});
    }
    const double baseWidth = 2.0 * extent * base;
    int index = 0;
    for (int row = 0; row < rows; ++row) {
        const double baseY = row * groundDeltaY;
        for (int column = 0; column < columns; ++column) {
            const double centerX = -0.5 * groundWidth + column * (baseWidth + 2.0 * extent) + 2.0 * extent;
            const std::string prefix = label("pyramid ", row, column);
            for (int i = 0; i < base; ++i)
                for (int j = i; j < base; ++j)
                    dynamicBox(s, prefix + label(" box ", i, j),
                               {(i + 1.0) * extent + 2.0 * (j - i) * extent + centerX - 0.5, (2.0 * i + 1.0) * extent + baseY},
                               1.0, 1.0, 1.0, 0.6, palette(index++));
        }
    }
    s.view = View{{0.0, 110.0}, 3.0};
    return s;
}

/// Box2D's human (shared/human.c at scale 1): eleven capsule bones, the
/// lower legs with a foot, hinged with Box2D's limits; each hinge has joint
/// friction (a motor at rest, torque 0.05 N m times the bone's share) and a
/// 5 Hz spring of damping ratio 0.5. Bones of one human never collide
/// (group -groupIndex); feet meet only the ground (mask 1). Density 1,
/// friction 0.2 (feet 0.05); the foot is rounded by 0.015 m.
void human(Scene& s, const std::string& prefix, Vec2 at, int groupIndex) {
    const Filter bones{2u, 1u | 2u, -groupIndex};
    struct Bone {
        const char* name;
        double y;           // body position above `at`
        double a, b, r;     // capsule from (0, a) to (0, b), radius r
        int parent;         // index into this table; -1 for the hip
        double pivot;       // joint height above `at`
        double lower, upper, reference, frictionScale, damping;
        bool foot;
    };
    constexpr double pi = kPi;
    static const Bone table[] = {
        {"hip", 0.95, -0.02, 0.02, 0.095, -1, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, false},
        {"torso", 1.2, -0.135, 0.135, 0.09, 0, 1.0, -0.25 * pi, 0.0, 0.0, 0.5, 0.0, false},
        {"head", 1.475, -0.038, 0.039, 0.075, 1, 1.4, -0.3 * pi, 0.1 * pi, 0.0, 0.25, 0.1, false},
        {"upper left leg", 0.775, -0.125, 0.125, 0.06, 0, 0.9, -0.05 * pi, 0.4 * pi, 0.0, 1.0, 0.0, false},
        {"lower left leg", 0.475, -0.155, 0.125, 0.045, 3, 0.625, -0.5 * pi, -0.02 * pi, 0.0, 0.5, 0.0, true},
        {"upper right leg", 0.775, -0.125, 0.125, 0.06, 0, 0.9, -0.05 * pi, 0.4 * pi, 0.0, 1.0, 0.0, false},
        {"lower right leg", 0.475, -0.155, 0.125, 0.045, 5, 0.625, -0.5 * pi, -0.02 * pi, 0.0, 0.5, 0.0, true},
        {"upper left arm", 1.225, -0.125, 0.125, 0.035, 1, 1.35, -0.1 * pi, 0.8 * pi, 0.0, 0.5, 0.0, false},
        {"lower left arm", 0.975, -0.125, 0.125, 0.03, 7, 1.1, -0.2 * pi, 0.3 * pi, 0.25 * pi, 0.1, 0.1, false},
        {"upper right arm", 1.225, -0.125, 0.125, 0.035, 1, 1.35, -0.1 * pi, 0.8 * pi, 0.0, 0.5, 0.0, false},
        {"lower right arm", 0.975, -0.125, 0.125, 0.03, 9, 1.1, -0.2 * pi, 0.3 * pi, 0.25 * pi, 0.1, 0.1, false},
    };
    const std::vector<Vec2> footOutline{{-0.03, -0.185}, {0.11, -0.185}, {0.11, -0.16}, {-0.03, -0.14}};
    std::vector<Entity> e;
    Registry& r = s.registry;
    for (const Bone& bone : table) {
        const Entity part = body(s, prefix + bone.name, at + Vec2{0.0, bone.y}, 0.2, palette(int(e.size())));
        const Capsule capsule{{0.0, bone.a}, {0.0, bone.b}, bone.r};
        double mass = capsuleMassProperties(bone.b - bone.a, bone.r).area;
        if (bone.foot) {
            Shapes shapes;
            shapes.items.clear();
            CompoundShape leg;
            leg.kind = CompoundShape::Kind::Capsule;
            leg.a = capsule.a;
            leg.b = capsule.b;
            leg.radius = capsule.radius;
            shapes.items.push_back(leg);
            CompoundShape foot;
            foot.kind = CompoundShape::Kind::Polygon;
            foot.vertices = footOutline;
            foot.cornerRadius = 0.015;
            foot.friction = 0.05;
            foot.filter = Filter{2u, 1u, -groupIndex};
            shapes.items.push_back(foot);
            mass = compoundMassProperties(shapes, std::nullopt).mass;
            r.emplace<Shapes>(part, std::move(shapes));
        } else {
            r.emplace<Capsule>(part, capsule);
            r.emplace<Mass>(part, Mass{mass});
        }
        r.emplace<Filter>(part, bones);
        if (bone.damping > 0.0) r.emplace<Drag>(part, Drag{bone.damping * mass});  // linearDamping c: drag c m
        e.push_back(part);
        if (bone.parent < 0) continue;
        const Bone& parent = table[bone.parent];
        const Entity j = r.create();
        r.emplace<Name>(j, Name{prefix + bone.name + " joint"});
        Joint joint;
        joint.type = "hinge";
        joint.a = e[std::size_t(bone.parent)];
        joint.b = part;
        joint.localA = {0.0, bone.pivot - parent.y};
        joint.localB = {0.0, bone.pivot - bone.y};
        joint.referenceAngle = bone.reference;
        joint.lower = bone.lower;
        joint.upper = bone.upper;
        joint.motorSpeed = 0.0;
        joint.maxMotorTorque = 0.05 * bone.frictionScale;
        joint.springHz = 5.0;
        joint.springDampingRatio = 0.5;
        r.emplace<Joint>(j, joint);
    }
}

// CreateRain: five floors 45 m apart, each a row of 501 static 0.5 m boxes;
// above each floor, 40 columns of groups of five humans 0.5 m apart (the
// k-th human of every group in collision group -k, as Box2D numbers them).
// StepRain adds column j (a group on each floor) before step 8j, and once
// all 40 are there destroys and re-creates one column every 8 steps, oldest
// first: column j is made anew before steps 8j + 320k. Here each column is
// a template (its five groups, at their places) with one emitter on the
// template's first bone: interval 320 steps, one copy alive, the first at
// the time of step 8j. An emitter adds its copy at the start of the step
// that begins at that time, after removing the copy it replaces, as Box2D
// does before b2World_Step. What differs: a copy's bodies and joints join
// the solver's arrays after everything already there (Box2D reuses the
// destroyed ids), and each is named after its copy (`rain column J#K/...`).
Scene rain() {
    Scene s = v3World();
    const int rows = 5, columns = 40, groupSize = 5, gridCount = 500, delay = 8;
    const double grid = 0.5;
    for (int i = 0; i < rows; ++i)
        for (int j = 0; j <= gridCount; ++j)
            staticBox(s, label("floor ", i, j), {-0.5 * gridCount * grid + j * grid, 45.0 * i}, grid, grid);
    const double span = gridCount * grid;
    const double groupDistance = span / columns;
    Registry& r = s.registry;
    for (int column = 0; column < columns; ++column) {
        const std::string name = "rain column " + std::to_string(column);
        const std::size_t first = r.entities().size();
        for (int row = 0; row < rows; ++row) {
            Vec2 at{-0.5 * span + groupDistance * (column + 0.5), 40.0 + 45.0 * row};
            for (int k = 0; k < groupSize; ++k) {
                human(s, label("human ", row, column) + "." + std::to_string(k) + " ", at, k + 1);
                at.x += 0.5;
            }
        }
        // Held by value: creating the emitter below grows the registry's list.
        const std::vector<Entity> members(r.entities().begin() + std::ptrdiff_t(first), r.entities().end());
        for (const Entity e : members)
            if (!r.has<Joint>(e)) r.emplace<Template>(e, Template{name});
        // The emitter sits on the template's first body, so each copy lands
        // where the template is.
        const Entity emitter = r.create();
        r.emplace<Name>(emitter, Name{name + " emitter"});
        r.emplace<Position>(emitter, Position{r.tryGet<Position>(members.front())->value});
        Emitter em;
        em.templateName = name;
        em.interval = columns * delay * s.world.dt;
        em.count = 1;
        em.next = column * delay * s.world.dt;
        r.emplace<Emitter>(emitter, em);
    }
    s.view = View{{0.0, 90.0}, 2.5};
    return s;
}

// CreateSmash: no gravity; an 8 m box of density 8 at 40 m/s into a block
// of 120 x 80 boxes of 0.4 m (density 1), set edge to edge.
Scene smash() {
    Scene s = v3World();
    s.world.gravity = {0.0, 0.0};
    const Entity ram = dynamicBox(s, "ram", {-20.0, 0.0}, 8.0, 8.0, 8.0, 0.6, palette(0));
    s.registry.emplace<Velocity>(ram, Velocity{{40.0, 0.0}});
    const double d = 0.4;
    const int columns = 120, rows = 80;
    for (int i = 0; i < columns; ++i)
        for (int j = 0; j < rows; ++j)
            dynamicBox(s, label("brick ", i, j), {i * d + 30.0, (j - rows / 2.0) * d}, d, d, 1.0, 0.6, palette(i + j + 1));
    s.view = View{{20.0, 0.0}, 9.0};
    return s;
}

// CreateSpinner: a drum of radius 40 m (a 360-point chain loop, friction
// 0.1) with a 0.8 x 40 m bar rounded by 0.2 m (friction 0) turned at 5 rad/s
// by an unlimited motor about (0, 12), and 6,076 bodies (capsules, circles
// and squares in turn, density 0.25, friction 0.1, restitution 0.1). Every
// part is the same shape as Box2D's.
Scene spinner() {
    Scene s = v3World();
    const int points = 360;
    const Vec2 centre{0.0, 32.0};
    const double radius = 40.0;
    // The drum: one clockwise loop (solid inside), as Box2D's chain.
    Chain drum;
    drum.points.clear();
    drum.loop = true;
    for (int i = 0; i < points; ++i) {
        const double a = -2.0 * kPi * i / points;
        drum.points.push_back({radius * std::cos(a), radius * std::sin(a)});
    }
    const Entity ground = body(s, "drum", centre, 0.1, kGrey);
    s.registry.emplace<Static>(ground, Static{true});
    s.registry.emplace<Chain>(ground, std::move(drum));
    const Vec2 pivot{0.0, 12.0};
    // b2MakeRoundedBox(0.4, 20, 0.2): a 0.8 x 40 m box rounded by 0.2 m, of
    // density 1.
    const Entity bar = body(s, "spinner", pivot, 0.0, palette(3));
    Polygon rounded{{{-0.4, -20.0}, {0.4, -20.0}, {0.4, 20.0}, {-0.4, 20.0}}, 0.2};
    s.registry.emplace<Mass>(bar, Mass{polygonMassProperties(rounded.vertices, 0.2).area});
    s.registry.emplace<Polygon>(bar, std::move(rounded));
    // FLT_MAX in Box2D: far beyond any torque the bodies can resist.
    motorToWorld(s, "spinner motor", bar, pivot, pivot, 5.0, 1e10);
    const double density = 0.25;
    const Capsule capsule{{-0.25, 0.0}, {0.25, 0.0}, 0.25};
    const double capsuleArea = capsuleMassProperties(0.5, 0.25).area;
    const int count = 2 * 3038;
    double x = -23.0, y = 2.0;
    for (int i = 0; i < count; ++i) {
        const std::string name = "body " + std::to_string(i);
        switch (i % 3) {
        case 0: {
            const Entity e = body(s, name, {x, y}, 0.1, palette(i));
            s.registry.emplace<Capsule>(e, capsule);
            s.registry.emplace<Mass>(e, Mass{density * capsuleArea});
            s.registry.emplace<Restitution>(e, Restitution{0.1});
            break;
        }
        case 1:
            s.registry.emplace<Restitution>(dynamicCircle(s, name, {x, y}, 0.35, density, 0.1, palette(i)),
                                            Restitution{0.1});
            break;
        default:
            s.registry.emplace<Restitution>(dynamicBox(s, name, {x, y}, 0.7, 0.7, density, 0.1, palette(i)),
                                            Restitution{0.1});
            break;
        }
        x += 0.5;
        if (x >= 23.0) {
            x = -23.0;
            y += 0.5;
        }
    }
    s.view = View{{0.0, 32.0}, 8.0};
    return s;
}

// CreateTumbler: a 20 m square box of four 1 m walls (density 50) turned
// at 25 degrees/s by a motor (1e8 N m) about (0, 10), holding 45 x 45 boxes
// of 0.25 m (density 1) 0.4 m apart.
Scene tumbler() {
    Scene s = v3World();
    const Vec2 pivot{0.0, 10.0};
    const double speed = 25.0 * kPi / 180.0;
    // One compound body as in Box2D: four 1 x 20 m walls at density 50
    // (4,000 kg), overlapping at the corners (shapes of one body never
    // collide), on one motor about its centre.
    const Entity drum = body(s, "walls", pivot, 0.6, kGrey);
    Shapes walls;
    walls.items.clear();  // the default holds one circle
    for (const auto& [offset, w, h] : {std::tuple{Vec2{10.0, 0.0}, 1.0, 20.0}, std::tuple{Vec2{-10.0, 0.0}, 1.0, 20.0},
                                       std::tuple{Vec2{0.0, 10.0}, 20.0, 1.0}, std::tuple{Vec2{0.0, -10.0}, 20.0, 1.0}}) {
        CompoundShape wall;
        wall.kind = CompoundShape::Kind::Box;
        wall.center = offset;
        wall.width = w;
        wall.height = h;
        wall.density = 50.0;
        walls.items.push_back(wall);
    }
    s.registry.emplace<Shapes>(drum, walls);
    motorToWorld(s, "walls motor", drum, pivot, pivot, speed, 1e8);
    const int grid = 45;
    double y = -0.2 * grid + 10.0;
    int index = 0;
    for (int i = 0; i < grid; ++i) {
        double x = -0.2 * grid;
        for (int j = 0; j < grid; ++j) {
            dynamicBox(s, label("box ", i, j), {x, y}, 0.25, 0.25, 1.0, 0.6, palette(index++));
            x += 0.4;
        }
        y += 0.4;
    }
    s.view = View{{0.0, 10.0}, 14.0};
    return s;
}

} // namespace

std::vector<Box2dScene> box2dBenchmarkScenes() {
    std::vector<Box2dScene> out;
    out.push_back({"joint_grid", jointGrid()});
    out.push_back({"large_pyramid", largePyramid()});
    out.push_back({"many_pyramids", manyPyramids()});
    out.push_back({"rain", rain()});
    out.push_back({"smash", smash()});
    out.push_back({"spinner", spinner()});
    out.push_back({"tumbler", tumbler()});
    return out;
}

} // namespace stepwise::bench
