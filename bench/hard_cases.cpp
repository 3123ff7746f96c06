// Hard cases: error against ms/step for Stepwise at its defaults and at
// fixed settings (substeps 1, 2, 4, 8 with one iteration each, sleeping
// off), with Box2D 2.4.1 (Debian libbox2d-dev; substeps 1, 2, 4, 8 of 8
// velocity and 3 position iterations, sleeping off) run in the same process
// on the same scenes. Times are the median of the per-step times of a run.
//
//   hard_cases [--quick] [--steps N] [--budget S] [--out DIR] [--only NAME] [--levels DIR] [--write-levels DIR]
//
// --out writes hard_cases.md, hard_cases.csv and the plot hard_cases.png
// (gnuplot, as the other reports). --only runs the cases whose name holds
// NAME. --levels reads Box2D's benchmark scenes from DIR (default
// bench/levels); --write-levels writes them there from bench/box2d_scenes.cpp
// and stops. --quick runs a fifth of the steps and leaves out the largest
// crowd: a check that the harness works, not figures to quote. --steps runs
// every case for N steps (while tuning one scene). --budget caps each run's
// wall-clock time (default 90 s); a run that reaches it, or whose joints
// open by more than 1 km, stops and says so.

#include "box2d_scenes.hpp"
#include "generated_scenes.hpp"

#include "collision/box2d_bodies.hpp"
#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

using namespace stepwise;
namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------- bodies

/// The scene's dynamic bodies in registry order, with what the measures
/// need (both engines report their state in this order). Templates and
/// emitters' copies are not among them: copies come and go during a run
/// (each engine adds and removes them itself), so the per-body measures
/// follow the level's own bodies, while contacts and joints count the
/// copies alive.
struct Bodies {
    std::vector<Entity> entities;
    std::vector<std::string> names;
    std::vector<double> mass, inertia, radius;  ///< radius: circles, else 0
    std::vector<Vec2> start;                    ///< initial positions
};

bool isStatic(const Registry& r, Entity e) { return r.has<Static>(e) && r.tryGet<Static>(e)->value; }

bool hasShape(const Registry& r, Entity e) {
    return r.has<Radius>(e) || r.has<Box>(e) || r.has<Polygon>(e) || r.has<Capsule>(e) || r.has<Chain>(e) ||
           r.has<Shapes>(e);
}

Bodies bodiesOf(const Scene& scene) {
    Bodies b;
    const Registry& r = scene.registry;
    const std::unordered_set<std::string> templates = bench::templateNames(r);
    for (Entity e : r.entities()) {
        if (!r.has<Position>(e) || isStatic(r, e) || !hasShape(r, e)) continue;
        if (bench::inTemplate(r, e) || bench::isEmittedCopy(r, e, templates)) continue;
        double m = r.has<Mass>(e) ? r.tryGet<Mass>(e)->value : 1.0;
        double inertia = 0.0, radius = 0.0;
        if (const Shapes* shapes = r.tryGet<Shapes>(e)) {
            const Mass* given = r.tryGet<Mass>(e);
            const CompoundMassProperties props =
                compoundMassProperties(*shapes, given ? std::optional<double>(given->value) : std::nullopt);
            m = props.mass;
            inertia = props.inertia;
        }
        if (const Radius* c = r.tryGet<Radius>(e)) {
            inertia = 0.5 * m * c->value * c->value;
            radius = c->value;
        } else if (const Box* x = r.tryGet<Box>(e)) {
            inertia = m * (x->width * x->width + x->height * x->height) / 12.0;
        } else if (const Polygon* p = r.tryGet<Polygon>(e)) {
            const PolygonMassProperties mp = polygonMassProperties(p->vertices);
            inertia = m * mp.secondMoment / mp.area;
        }
        b.entities.push_back(e);
        b.names.push_back(r.has<Name>(e) ? r.tryGet<Name>(e)->value : std::string());
        b.mass.push_back(m);
        b.inertia.push_back(inertia);
        b.radius.push_back(radius);
        b.start.push_back(r.tryGet<Position>(e)->value);
    }
    return b;
}

// ---------------------------------------------------------------- runs

/// Wall-clock seconds a run may take (--budget): a scene that blows up can
/// make each step cost seconds (its bounding boxes span kilometres), and
/// the report must finish. A run stopped by it says so in its figures.
double g_budgetSeconds = 90.0;
/// Metres: a joint open this wide has blown up; the run stops there.
constexpr double kBlownUp = 1000.0;

/// What the per-step measures follow (each costs a pass over the bodies or
/// joints after every step, outside the timed step).
struct Track {
    bool speed = false;   ///< fastest body and translational energy
    bool joints = false;  ///< widest joint opening
    /// With `speed`: while every body's centre is above this height (m),
    /// the crowd is in flight and its speed relative to free fall from rest
    /// is what the push-out gave it (pushOut). NaN: not measured.
    double inFlightAbove = std::numeric_limits<double>::quiet_NaN();
    bool lastStep = false;  ///< every body's position before the last step (Run::beforeLast)
};

struct BodyState {
    Vec2 p, v;
    double angle = 0.0, w = 0.0;
};

struct Run {
    double msPerStep = 0.0;  ///< median of the steps' times
    int steps = 0;           ///< completed
    std::string diverged;    ///< the engine's message when a step failed
    std::string stopped;     ///< why the run stopped early without failing (budget, blown up)
    double maxSpeed = 0.0;   ///< m/s, fastest body over the run
    double maxSideways = 0.0;  ///< m/s, fastest horizontal speed over the run (gravity adds none)
    double energyGain = 0.0; ///< J, largest rise of translational kinetic + potential energy over the start
    double pushOut = 0.0;    ///< m/s, fastest speed relative to free fall while in flight (Track::inFlightAbove)
    double maxJointOpening = 0.0;   ///< m, over every joint and step
    double finalJointOpening = 0.0; ///< m, widest at the end
    double deepestContact = 0.0;    ///< m, the engine's own deepest contact at the end
    std::vector<BodyState> final;   ///< Bodies order
    std::vector<Vec2> beforeLast;   ///< Bodies order, before the last step (Track::lastStep)
};

std::string stopReason(std::chrono::steady_clock::time_point runStart, const Run& run) {
    if (run.maxJointOpening > kBlownUp) return "blew up: a joint opened over 1 km";
    if (std::chrono::duration<double>(std::chrono::steady_clock::now() - runStart).count() > g_budgetSeconds)
        return "stopped by the " + std::to_string(int(g_budgetSeconds)) + " s budget";
    return {};
}

double median(std::vector<double> v) {
    if (v.empty()) return kNaN;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

/// Translational kinetic + potential energy (J) of `p`, `v` under `g`.
double translationalEnergy(const Bodies& b, const std::vector<Vec2>& p, const std::vector<Vec2>& v, Vec2 g) {
    double e = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i) e += b.mass[i] * (0.5 * lengthSquared(v[i]) - dot(g, p[i]));
    return e;
}

/// The settings a run uses: the engine's choice (substeps 0: as the
/// level's defaults, sleeping as the engine's default), or fixed.
/// The run's fastest body, fastest sideways speed and largest energy gain
/// so far, updated from one step's positions `p` and velocities `v`.
/// `fall` is the velocity free fall from rest has reached; `inFlightAbove`
/// as Track's.
void recordMotion(Run& out, const Bodies& bodies, const std::vector<Vec2>& p, const std::vector<Vec2>& v, Vec2 g,
                  double startEnergy, Vec2 fall, double inFlightAbove) {
    for (const Vec2& x : v) {
        out.maxSpeed = std::max(out.maxSpeed, length(x));
        out.maxSideways = std::max(out.maxSideways, std::abs(x.x));
    }
    out.energyGain = std::max(out.energyGain, translationalEnergy(bodies, p, v, g) - startEnergy);
    bool inFlight = !std::isnan(inFlightAbove);
    for (const Vec2& x : p) inFlight = inFlight && x.y > inFlightAbove;
    if (inFlight)
        for (const Vec2& x : v) out.pushOut = std::max(out.pushOut, length(x - fall));
}

struct Setting {
    std::string label;  ///< "default", "1", "2", "4", "8"
    int substeps = 0;   ///< 0: the engine's choice
};

Run runStepwise(const Scene& level, const Bodies& bodies, int steps, const Setting& setting, Track track) {
    Scene scene = level;
    if (setting.substeps == 0) {
        // The level with the step left to the engine: no substeps, no
        // iterations, sleeping as the engine's default.
        const WorldSettings defaults;
        scene.world.substeps = 0;
        scene.world.solverIterations = 0;
        scene.world.sleep = defaults.sleep;
    } else {
        scene.world.substeps = setting.substeps;
        scene.world.solverIterations = 1;
        scene.world.sleep = false;
    }
    Run out;
    Result<World> built = World::build(scene);
    if (!built) {
        out.diverged = "cannot build: " + built.error();
        return out;
    }
    World& world = *built;
    world.setProfiling(false);
    std::unordered_map<std::uint32_t, std::size_t> order;  // entity index -> Bodies index
    for (std::size_t i = 0; i < bodies.entities.size(); ++i) order.emplace(bodies.entities[i].index, i);
    // World body k -> Bodies index; emitters add and remove bodies (and
    // renumber the rest), so it is made again after every step that did.
    std::vector<std::size_t> slot;
    const auto mapBodies = [&] {
        slot.assign(world.bodyCount(), std::size_t(-1));
        for (std::size_t k = 0; k < world.bodyCount(); ++k)
            if (auto it = order.find(world.bodyEntity(k).index); it != order.end()) slot[k] = it->second;
    };
    mapBodies();
    const Vec2 g = scene.world.gravity;
    std::vector<Vec2> p(bodies.entities.size()), v(bodies.entities.size());
    double startEnergy = 0.0;
    const auto sample = [&] {
        for (std::size_t k = 0; k < slot.size(); ++k)
            if (slot[k] != std::size_t(-1)) {
                p[slot[k]] = world.bodyPosition(k);
                v[slot[k]] = world.bodyVelocity(k);
            }
    };
    if (track.speed) {
        sample();
        startEnergy = translationalEnergy(bodies, p, v, g);
    }
    std::vector<double> times;
    times.reserve(std::size_t(steps));
    const auto runStart = std::chrono::steady_clock::now();
    for (int i = 0; i < steps; ++i) {
        if (track.lastStep && i + 1 == steps) {
            out.beforeLast.assign(bodies.entities.size(), Vec2{});
            for (std::size_t k = 0; k < slot.size(); ++k)
                if (slot[k] != std::size_t(-1)) out.beforeLast[slot[k]] = world.bodyPosition(k);
        }
        const auto start = std::chrono::steady_clock::now();
        const Result<void> r = world.step();
        times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        if (!r) {
            out.diverged = "step " + std::to_string(i + 1) + ": " + r.error();
            break;
        }
        ++out.steps;
        if (!world.emitterEvents().empty()) mapBodies();
        if (const std::string why = stopReason(runStart, out); !why.empty()) {
            out.stopped = why;
            break;
        }
        if (track.speed) {
            sample();
            recordMotion(out, bodies, p, v, g, startEnergy, g * (double(i + 1) * scene.world.dt), track.inFlightAbove);
        }
        if (track.joints) {
            double widest = 0.0;
            for (const JointRecord& j : world.joints()) widest = std::max(widest, j.separation);
            out.maxJointOpening = std::max(out.maxJointOpening, widest);
            out.finalJointOpening = widest;
        }
    }
    out.msPerStep = median(times);
    for (const ContactRecord& c : world.contacts()) out.deepestContact = std::max(out.deepestContact, c.depth);
    world.writeBack(scene);
    const Registry& r = scene.registry;
    for (Entity e : bodies.entities) {
        BodyState s;
        s.p = r.tryGet<Position>(e)->value;
        if (const Velocity* x = r.tryGet<Velocity>(e)) s.v = x->value;
        if (const Angle* x = r.tryGet<Angle>(e)) s.angle = x->value;
        if (const AngularVelocity* x = r.tryGet<AngularVelocity>(e)) s.w = x->value;
        out.final.push_back(s);
    }
    return out;
}

/// Box2D 2.4.1 on the same scene: `substeps` calls of Step(dt / substeps,
/// 8, 3) per step, sleeping off. Empty `diverged` unless the scene has
/// something it cannot build (a joint other than a hinge).
Run runBox2d(const Scene& scene, const Bodies& bodies, int steps, int substeps, Track track) {
    Run out;
    const Registry& r = scene.registry;
    b2World world(b2Vec2(float(scene.world.gravity.x), float(scene.world.gravity.y)));
    world.SetAllowSleeping(false);
    b2BodyDef groundDef;
    b2Body* ground = world.CreateBody(&groundDef);
    std::unordered_map<std::uint32_t, b2Body*> bodyOf;
    for (Entity e : r.entities())
        if (r.has<Position>(e) && (hasShape(r, e) || isStatic(r, e)) && !bench::inTemplate(r, e))
            bodyOf.emplace(e.index, bench::createBox2dBody(world, r, e));
    // Templates are copied by the emitters, at the steps Stepwise copies them.
    bench::Box2dEmitters emitters;
    if (std::string why = emitters.start(r, scene.world.time, scene.world.dt); !why.empty()) {
        out.diverged = why;
        return out;
    }
    std::vector<b2Joint*> joints;
    for (Entity e : r.entities()) {
        const Joint* j = r.tryGet<Joint>(e);
        if (!j || bench::inTemplate(r, e)) continue;
        if (j->type != "hinge") {
            out.diverged = "Box2D port builds hinges only, not " + j->type;
            return out;
        }
        joints.push_back(bench::createBox2dHinge(world, *j, bodyOf.at(j->a.index),
                                                 j->b.isNull() ? ground : bodyOf.at(j->b.index)));
    }
    std::vector<b2Body*> mine;
    for (Entity e : bodies.entities) mine.push_back(bodyOf.at(e.index));
    const Vec2 g = scene.world.gravity;
    std::vector<Vec2> p(mine.size()), v(mine.size());
    const auto sample = [&] {
        for (std::size_t k = 0; k < mine.size(); ++k) {
            p[k] = {mine[k]->GetPosition().x, mine[k]->GetPosition().y};
            v[k] = {mine[k]->GetLinearVelocity().x, mine[k]->GetLinearVelocity().y};
        }
    };
    double startEnergy = 0.0;
    if (track.speed) {
        sample();
        startEnergy = translationalEnergy(bodies, p, v, g);
    }
    const float h = float(scene.world.dt) / float(substeps);
    std::vector<double> times;
    times.reserve(std::size_t(steps));
    const auto runStart = std::chrono::steady_clock::now();
    for (int i = 0; i < steps; ++i) {
        if (track.lastStep && i + 1 == steps)
            for (const b2Body* b : mine) out.beforeLast.push_back({b->GetPosition().x, b->GetPosition().y});
        const auto start = std::chrono::steady_clock::now();
        emitters.beforeStep(world, ground, bodyOf);  // timed, as World::step times its own
        for (int s = 0; s < substeps; ++s) world.Step(h, 8, 3);
        emitters.afterStep();
        times.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
        ++out.steps;
        if (const std::string why = stopReason(runStart, out); !why.empty()) {
            out.stopped = why;
            break;
        }
        if (track.speed) {
            sample();
            recordMotion(out, bodies, p, v, g, startEnergy, g * (double(i + 1) * scene.world.dt), track.inFlightAbove);
        }
        if (track.joints) {
            double widest = 0.0;
            const auto opening = [](const b2Joint* j) { return double((j->GetAnchorB() - j->GetAnchorA()).Length()); };
            for (b2Joint* j : joints) widest = std::max(widest, opening(j));
            emitters.forEachCopy([&](const bench::Box2dEmitters::Copy& c) {
                for (const b2Joint* j : c.joints) widest = std::max(widest, opening(j));
            });
            out.maxJointOpening = std::max(out.maxJointOpening, widest);
            out.finalJointOpening = widest;
        }
    }
    out.msPerStep = median(times);
    for (b2Contact* c = world.GetContactList(); c; c = c->GetNext()) {
        if (!c->IsTouching()) continue;
        b2WorldManifold m;
        c->GetWorldManifold(&m);
        for (int i = 0; i < c->GetManifold()->pointCount; ++i)
            out.deepestContact = std::max(out.deepestContact, double(-m.separations[i]));
    }
    for (b2Body* b : mine)
        out.final.push_back({{b->GetPosition().x, b->GetPosition().y},
                             {b->GetLinearVelocity().x, b->GetLinearVelocity().y},
                             b->GetAngle(),
                             b->GetAngularVelocity()});
    return out;
}

// ---------------------------------------------------------------- cases

/// A case's figures: the error plotted, and what else the table shows.
struct Figures {
    double error = kNaN;
    std::string detail;
};

struct Case {
    std::string panel;       ///< plot panel
    std::string name;        ///< table row
    std::string errorLabel;  ///< the error's meaning and unit
    Scene scene;
    int steps = 0;
    Track track;
    bool box2dSweep = true;  ///< Box2D at substeps 1, 2, 4, 8 (else 1 only)
    bool box2d = true;       ///< Box2D 2.4.1 can run it
    bool logError = true;    ///< the panel's error axis is logarithmic
    std::function<Figures(const Bodies&, const Run&)> measure;
};

std::string fmt(const char* format, double a, double b = 0.0, double c = 0.0) {
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, format, a, b, c);
    return buffer;
}

double kineticEnergy(const Bodies& b, const Run& run) {
    double e = 0.0;
    for (std::size_t i = 0; i < run.final.size(); ++i)
        e += 0.5 * b.mass[i] * lengthSquared(run.final[i].v) + 0.5 * b.inertia[i] * run.final[i].w * run.final[i].w;
    return e;
}

Entity add(Scene& s, Vec2 p) {
    const Entity e = s.registry.create();
    s.registry.emplace<Position>(e, Position{p});
    return e;
}

Entity addStatic(Scene& s, Vec2 p, double w, double h, double friction) {
    const Entity e = add(s, p);
    s.registry.emplace<Static>(e, Static{true});
    s.registry.emplace<Box>(e, Box{w, h});
    s.registry.emplace<Friction>(e, Friction{friction});
    return e;
}

void addHinge(Scene& s, Entity a, Entity b, Vec2 localA, Vec2 localB) {
    const Entity e = s.registry.create();
    Joint j;
    j.type = "hinge";
    j.a = a;
    j.b = b;  // null: the world, localB a world point
    j.localA = localA;
    j.localB = localB;
    j.referenceAngle = 0.0;
    s.registry.emplace<Joint>(e, j);
}

Scene baseWorld(double g = 10.0) {
    Scene s;
    s.world.gravity = {0.0, -g};
    s.world.dt = 1.0 / 60.0;
    return s;
}

/// Solid disc (r 0.5 m, friction 0.9 on a friction 0.9 floor) set down
/// spinning at w0: sliding friction turns spin into rolling until
/// v = -w0 r / 3, the rolling speed that conserves the angular momentum
/// about the contact point (I w0 = (I + m r^2) v / r, I = m r^2 / 2).
Case spinningDisc(double w0) {
    Case c;
    c.panel = "disc spun onto the floor";
    c.name = "disc w0 " + fmt("%g", w0) + " rad/s";
    c.errorLabel = "|rolling speed - (-w0 r/3)|, m/s";
    Scene& s = c.scene = baseWorld();
    addStatic(s, {0.0, -0.5}, 4000.0, 1.0, 0.9);
    const Entity disc = add(s, {0.0, 0.5});
    s.registry.emplace<Radius>(disc, Radius{0.5});
    s.registry.emplace<Friction>(disc, Friction{0.9});
    s.registry.emplace<AngularVelocity>(disc, AngularVelocity{w0});
    c.steps = 420;  // 7 s: the slip of w0 = -200 ends after 3.7 s
    const double expected = -w0 * 0.5 / 3.0;
    c.measure = [expected](const Bodies&, const Run& r) {
        const double v = r.final[0].v.x;
        return Figures{std::abs(v - expected), fmt("v %.4g m/s (expected %.4g), spin %.4g rad/s", v, expected, r.final[0].w) + fmt(", y %.4g m", r.final[0].p.y)};
    };
    return c;
}

/// One ball (r 0.25 m) resting on a 2 cm static box under gravity g.
Case ballOnThinBox(double g) {
    Case c;
    c.panel = "ball on a 2 cm box";
    c.name = "ball on 2 cm box, g " + fmt("%g", g);
    c.errorLabel = "sinkage below the box top, m";
    Scene& s = c.scene = baseWorld(g);
    addStatic(s, {0.0, -0.01}, 4.0, 0.02, 0.6);
    const Entity ball = add(s, {0.0, 0.25});
    s.registry.emplace<Radius>(ball, Radius{0.25});
    s.registry.emplace<Friction>(ball, Friction{0.6});
    c.steps = 120;
    c.measure = [](const Bodies&, const Run& r) {
        const double sink = std::max(0.0, -(r.final[0].p.y - 0.25));
        return Figures{sink, sink > 0.02 + 0.5 ? std::string("fell through") : fmt("%.3g mm", 1e3 * sink)};
    };
    return c;
}

/// A 1000 kg box hanging from ten 1 kg links (0.5 m, hinged) whose top is
/// hinged to the world, released horizontally: the mass ratio 1000 that
/// a Gauss-Seidel joint solver leaves stretched.
Case heavyOnChain() {
    Case c;
    c.panel = c.name = "1000 kg on ten 1 kg links";
    c.errorLabel = "widest joint opening, m";
    Scene& s = c.scene = baseWorld();
    Entity previous;
    for (int k = 0; k < 10; ++k) {
        const Entity link = add(s, {0.25 + 0.5 * k, 10.0});
        s.registry.emplace<Box>(link, Box{0.5, 0.1});
        if (k == 0) addHinge(s, link, Entity{}, {-0.25, 0.0}, {0.0, 10.0});
        else addHinge(s, previous, link, {0.25, 0.0}, {-0.25, 0.0});
        previous = link;
    }
    const Entity heavy = add(s, {5.5, 10.0});
    s.registry.emplace<Box>(heavy, Box{1.0, 1.0});
    s.registry.emplace<Mass>(heavy, Mass{1000.0});
    addHinge(s, previous, heavy, {0.25, 0.0}, {-0.5, 0.0});
    c.steps = 240;
    c.track.joints = true;
    c.measure = [](const Bodies&, const Run& r) {
        return Figures{r.maxJointOpening, fmt("widest %.3g mm, at the end %.3g mm", 1e3 * r.maxJointOpening,
                                              1e3 * r.finalJointOpening)};
    };
    return c;
}

/// Twenty 1 m boxes hinged end to end, the first to the world, released
/// horizontally.
Case chainOf20() {
    Case c;
    c.panel = c.name = "chain of 20 links";
    c.errorLabel = "widest joint opening / link length";
    Scene& s = c.scene = baseWorld();
    Entity previous;
    for (int k = 0; k < 20; ++k) {
        const Entity link = add(s, {0.5 + k, 0.0});
        s.registry.emplace<Box>(link, Box{1.0, 0.25});
        if (k == 0) addHinge(s, link, Entity{}, {-0.5, 0.0}, {0.0, 0.0});
        else addHinge(s, previous, link, {0.5, 0.0}, {-0.5, 0.0});
        previous = link;
    }
    c.steps = 240;
    c.track.joints = true;
    c.measure = [](const Bodies&, const Run& r) {
        return Figures{r.maxJointOpening / 1.0, fmt("widest %.3g mm, at the end %.3g mm", 1e3 * r.maxJointOpening,
                                                    1e3 * r.finalJointOpening)};
    };
    return c;
}

/// A crate (1.2 m, `mass` kg) dropped onto a bridge of twelve 2 kg planks
/// (1 m x 0.2 m) hinged end to end, its ends pinned to the world 12 m
/// apart, and left 10 s to settle. The error is how far the crate's
/// velocity is from its motion over the last step: what the solve leaves
/// it moving into the planks that the joints' correction takes back as
/// position (a body's velocity should say how it moves).
Case crateOnBridge(double mass) {
    Case c;
    c.panel = "crate on a bridge: velocity against motion";
    c.name = "crate " + fmt("%g", mass) + " kg on a bridge";
    c.errorLabel = "|crate velocity - its motion over the last step / dt|, m/s";
    Scene& s = c.scene = baseWorld();
    const Entity crate = add(s, {0.5, 2.5});
    s.registry.emplace<Box>(crate, Box{1.2, 1.2});
    s.registry.emplace<Mass>(crate, Mass{mass});
    s.registry.emplace<Friction>(crate, Friction{0.6});
    Entity previous;
    for (int k = 0; k < 12; ++k) {
        const Entity plank = add(s, {-5.5 + k, 0.0});
        s.registry.emplace<Box>(plank, Box{1.0, 0.2});
        s.registry.emplace<Mass>(plank, Mass{2.0});
        s.registry.emplace<Friction>(plank, Friction{0.6});
        if (k == 0) addHinge(s, plank, Entity{}, {-0.5, 0.0}, {-6.0, 0.0});
        else addHinge(s, previous, plank, {0.5, 0.0}, {-0.5, 0.0});
        previous = plank;
    }
    addHinge(s, previous, Entity{}, {0.5, 0.0}, {6.0, 0.0});
    c.steps = 600;
    c.track.joints = true;
    c.track.lastStep = true;
    const double dt = s.world.dt;
    c.measure = [dt](const Bodies&, const Run& r) {
        if (r.beforeLast.empty()) return Figures{kNaN, "did not reach its last step"};
        const Vec2 motion = (1.0 / dt) * (r.final[0].p - r.beforeLast[0]);
        const double ghost = length(r.final[0].v - motion);
        return Figures{ghost, fmt("velocity %.3g m/s, motion %.3g m/s; crate sags %.3g m", length(r.final[0].v),
                                  length(motion), -(r.final[0].p.y - 0.7)) +
                                  fmt("; deepest contact %.3g mm, widest pin %.3g mm", 1e3 * r.deepestContact,
                                      1e3 * r.maxJointOpening)};
    };
    return c;
}

/// Ten 1 m boxes stacked edge to edge from y = 0 up, on ground below.
void addTenBoxes(Scene& s) {
    for (int k = 0; k < 10; ++k) {
        const Entity box = add(s, {0.0, 0.5 + k});
        s.registry.emplace<Box>(box, Box{1.0, 1.0});
        s.registry.emplace<Friction>(box, Friction{0.6});
    }
}

/// How far a body placed at `start` and ending at `at` sank, and how far
/// it moved sideways.
Figures sinkage(Vec2 start, Vec2 at) {
    return Figures{std::max(0.0, start.y - at.y),
                   fmt("sank %.3g mm, sideways %.3g mm", 1e3 * (start.y - at.y), 1e3 * std::abs(at.x - start.x))};
}

/// How far the top box (the last body) sank, and how far it moved sideways.
Figures topBoxSinkage(const Bodies& b, const Run& r) { return sinkage(b.start.back(), r.final.back().p); }

/// Ten 1 m boxes stacked edge to edge on the ground, under gravity g.
Case stackOf10(double g) {
    Case c;
    c.panel = c.name = "stack of 10 boxes";
    if (g != 10.0) c.name += ", g " + fmt("%g", g);
    c.errorLabel = "sinkage of the top box, m";
    Scene& s = c.scene = baseWorld(g);
    addStatic(s, {0.0, -0.5}, 20.0, 1.0, 0.6);
    addTenBoxes(s);
    c.steps = 180;
    c.measure = topBoxSinkage;
    return c;
}

/// The same stack standing on a planet: an attractor of radius 100 m, no
/// gravity, pulling `pull` m/s^2 at its surface, static or (`dynamic`)
/// left free to move, when the sinkage is read from the planet. Box2D has
/// no attractors.
Case stackOnAPlanet(double pull, bool dynamic = false) {
    Case c = stackOf10(10.0);
    c.name = std::string("stack of 10 boxes on a ") + (dynamic ? "dynamic " : "") + "planet, pull " + fmt("%g", pull);
    Scene& s = c.scene = baseWorld(0.0);
    const double radius = 100.0;
    const Entity planet = add(s, {0.0, -radius});
    if (!dynamic) s.registry.emplace<Static>(planet, Static{true});
    s.registry.emplace<Radius>(planet, Radius{radius});
    s.registry.emplace<Mass>(planet, Mass{pull * radius * radius});  // G = 1
    s.registry.emplace<Attractor>(planet, Attractor{0.0});
    s.registry.emplace<Friction>(planet, Friction{0.6});
    addTenBoxes(s);
    if (dynamic)
        c.measure = [](const Bodies& b, const Run& r) {
            // The planet is the first body.
            return sinkage(b.start.back() - b.start.front(), r.final.back().p - r.final.front().p);
        };
    c.box2d = false;
    return c;
}

/// Ten 1 m boxes in a column on a 2 cm static box under gravity `g`, for a
/// case to add what presses them. Box2D 2.4.1 is not run: the harness gives
/// it neither springs nor motors.
Case stackOnThinFloor(std::string name, double g) {
    Case c = stackOf10(10.0);
    c.name = std::move(name);
    Scene& s = c.scene = baseWorld(g);
    addStatic(s, {0.0, -0.01}, 20.0, 0.02, 0.6);
    addTenBoxes(s);
    c.box2d = false;
    return c;
}

/// Ten 1 m boxes in a column on a 2 cm static box, no gravity, the top one
/// pulled down by a spring anchored 100 m below with `force` N as placed.
Case stackPressedBySpring(double force) {
    Case c = stackOnThinFloor("stack of 10 boxes pressed by a spring, " + fmt("%g", force) + " N", 0.0);
    Scene& s = c.scene;
    Entity top;
    for (const Entity e : s.registry.entities())
        if (s.registry.has<Box>(e) && !s.registry.has<Static>(e)) top = e;
    const Entity spring = s.registry.create();
    const double anchorAt = -100.0, stretch = 9.5 - anchorAt;
    s.registry.emplace<Spring>(spring, Spring{top, Entity{}, Vec2{0.0, anchorAt}, force / stretch, 0.0, 0.0});
    return c;
}

/// Ten 1 m boxes in a column on a 2 cm static box under gravity 10, a 10 m
/// bar lying on them hinged to the world at its left end and turned down
/// onto the top box by a motor of `torque` N*m (about torque / 4.5 m on
/// the stack).
Case stackPressedByHingedBar(double torque) {
    Case c = stackOnThinFloor("stack of 10 boxes pressed by a hinged bar, " + fmt("%g", torque) + " N m", 10.0);
    Scene& s = c.scene;
    const Entity bar = add(s, {0.0, 10.1});
    s.registry.emplace<Box>(bar, Box{10.0, 0.2});
    s.registry.emplace<Friction>(bar, Friction{0.6});
    addHinge(s, bar, Entity{}, {-5.0, 0.0}, {-5.0, 10.1});
    for (const Entity e : s.registry.entities())
        if (Joint* j = s.registry.tryGet<Joint>(e)) {
            j->motorSpeed = 1.0;
            j->maxMotorTorque = torque;
        }
    // The top box is the last but one body, before the bar.
    c.measure = [](const Bodies& b, const Run& r) {
        const std::size_t top = r.final.size() - 2;
        return sinkage(b.start[top], r.final[top].p);
    };
    return c;
}

/// N balls (r 0.25 m) started at one point 5 m above a floor: how fast the
/// overlap pushes them apart (Box2D v3 caps the push-out at 3 m/s) and the
/// energy that adds.
Case crowd(int n) {
    Case c;
    c.panel = c.name = "crowd of " + std::to_string(n) + " at one point";
    // Sideways: the fall alone reaches 9.7 m/s at the floor, so the
    // horizontal speed is what the push-out gives.
    c.errorLabel = "push-out: fastest speed relative to free fall in flight, m/s";
    Scene& s = c.scene = baseWorld();
    addStatic(s, {0.0, -0.5}, 400.0, 1.0, 0.6);
    for (int i = 0; i < n; ++i) {
        const Entity ball = add(s, {0.0, 5.0});
        s.registry.emplace<Radius>(ball, Radius{0.25});
        s.registry.emplace<Friction>(ball, Friction{0.6});
    }
    c.steps = 60;
    c.track.speed = true;
    // In flight until a ball comes within a radius of the floor's top (y = 0).
    c.track.inFlightAbove = 0.5;
    // Box2D 2.4.1 makes a contact for every overlapping pair: n^2/2 of them
    // (5e7 at 10,000, tens of gigabytes).
    c.box2d = n <= 1000;
    c.box2dSweep = n <= 64;
    c.measure = [](const Bodies&, const Run& r) {
        return Figures{r.pushOut, fmt("push-out %.3g m/s in flight; on the floor sideways %.3g m/s, fastest %.3g m/s",
                                      r.pushOut, r.maxSideways, r.maxSpeed) +
                                      fmt(", energy gained %.3g J", r.energyGain)};
    };
    return c;
}

/// scenes::tallPile: 300 balls in a 6 m wide well, 30 rows deep. Box2D's
/// answer to this pile is its substeps; this is the one substep.
Case pile300() {
    Case c;
    c.panel = c.name = "300-ball pile";
    c.errorLabel = "deepest floor sinkage, m";
    c.scene = scenes::tallPile();
    c.steps = 300;
    c.measure = [](const Bodies& b, const Run& r) {
        double floor = 0.0, neighbour = 0.0;
        for (std::size_t i = 0; i < r.final.size(); ++i) {
            floor = std::max(floor, b.radius[i] - r.final[i].p.y);  // the floor's top is y = 0
            for (std::size_t j = i + 1; j < r.final.size(); ++j)
                neighbour = std::max(neighbour, b.radius[i] + b.radius[j] - length(r.final[i].p - r.final[j].p));
        }
        return Figures{std::max(0.0, floor), fmt("floor %.3g mm, neighbours %.3g mm", 1e3 * floor, 1e3 * neighbour)};
    };
    return c;
}

/// Reference figures the report prints next to its own (one thread, median
/// ms/step, taken in one sitting on the 2-core VM): Box2D v3.1.1's for its
/// benchmark scenes (v3 is not linked here), and Stepwise's at v3's settings
/// from a build without the hard-case rules, as a baseline.
struct Reference {
    const char* scene;
    double v3Ms;
    double stepwiseMs;
};
const Reference kReferences[] = {{"joint_grid", 7.05, 9.61},     {"large_pyramid", 5.76, 7.19}, {"many_pyramids", 24.4, 28.7},
                                 {"rain", kNaN, kNaN},           {"smash", 11.9, 17.9},         {"spinner", 5.47, 5.64},
                                 {"tumbler", 3.83, 3.73}};

std::vector<Case> box2dScenes(const fs::path& levels, int steps) {
    std::vector<Case> cases;
    for (const bench::Box2dScene& port : bench::box2dBenchmarkScenes()) {
        Case c;
        c.panel = c.name = "box2d " + port.name;
        const fs::path file = levels / ("box2d_" + port.name + ".json");
        Result<Scene> loaded = loadSceneFile(file);
        if (!loaded) {
            std::cerr << "hard_cases: " << loaded.error() << " (hard_cases --write-levels " << levels.string()
                      << " makes them)\n";
            std::exit(2);
        }
        c.scene = std::move(*loaded);
        c.steps = steps;
        c.box2dSweep = false;
        const std::string name = port.name;
        if (name == "joint_grid") {
            c.errorLabel = "widest joint opening, m";
            c.track.joints = true;
            c.measure = [](const Bodies&, const Run& r) {
                return Figures{r.maxJointOpening, fmt("widest %.3g m, at the end %.3g m", r.maxJointOpening,
                                                      r.finalJointOpening)};
            };
        } else if (name == "large_pyramid" || name == "many_pyramids") {
            c.errorLabel = "top box sideways drift, m";
            c.measure = [](const Bodies& b, const Run& r) {
                // The top box of each pyramid: "box 99.99" or "... box 9.9".
                double drift = 0.0;
                for (std::size_t i = 0; i < b.names.size(); ++i) {
                    const std::string& n = b.names[i];
                    if (n == "box 99.99" || (n.starts_with("pyramid ") && n.ends_with(" box 9.9")))
                        drift = std::max(drift, std::abs(r.final[i].p.x - b.start[i].x));
                }
                return Figures{drift, fmt("top drift %.3g mm, kinetic %.3g J", 1e3 * drift, kineticEnergy(b, r))};
            };
        } else if (name == "rain") {
            c.errorLabel = "deepest contact overlap, m";
            c.track.joints = true;
            c.measure = [](const Bodies&, const Run& r) {
                return Figures{r.deepestContact, fmt("overlap %.3g mm, widest joint opening %.3g mm",
                                                     1e3 * r.deepestContact, 1e3 * r.maxJointOpening)};
            };
        } else if (name == "smash") {
            c.errorLabel = "deepest contact overlap, m";
            c.measure = [](const Bodies& b, const Run& r) {
                const double start = 0.5 * 512.0 * 40.0 * 40.0;  // the ram's kinetic energy
                return Figures{r.deepestContact, fmt("overlap %.3g mm, kinetic energy %.3g of the start",
                                                     1e3 * r.deepestContact, kineticEnergy(b, r) / start)};
            };
        } else if (name == "spinner") {
            c.errorLabel = "deepest contact overlap, m";
            // Box2D 2.4.1 takes over a second a step here (100 steps in more
            // than three minutes on the 2-core VM): left out.
            c.box2d = false;
            c.measure = [](const Bodies& b, const Run& r) {
                int escaped = 0;
                for (std::size_t i = 0; i < r.final.size(); ++i)
                    escaped += length(r.final[i].p - Vec2{0.0, 32.0}) > 40.5 && b.names[i] != "spinner";
                return Figures{r.deepestContact,
                               fmt("overlap %.3g mm, %.0f escaped the drum", 1e3 * r.deepestContact, escaped)};
            };
        } else if (name == "tumbler") {
            c.errorLabel = "bodies escaped";
            c.logError = false;
            c.measure = [](const Bodies& b, const Run& r) {
                // Outside the circle through the box's outer corners: out.
                int escaped = 0;
                for (std::size_t i = 0; i < r.final.size(); ++i)
                    escaped += !b.names[i].starts_with("wall") && length(r.final[i].p - Vec2{0.0, 10.0}) > 15.0;
                return Figures{double(escaped), fmt("%.0f escaped, overlap %.3g mm", escaped, 1e3 * r.deepestContact)};
            };
        }
        cases.push_back(std::move(c));
    }
    return cases;
}

// ---------------------------------------------------------------- report

struct Row {
    std::string panel, name, engine, setting, errorLabel;
    double ms = kNaN, error = kNaN;
    std::string detail;
};

std::string measuredOn(int argc, char** argv) {
    const std::time_t now = std::time(nullptr);
    char when[32];
    std::strftime(when, sizeof when, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    std::string cpu = "unknown CPU";
    std::ifstream cpuinfo("/proc/cpuinfo");
    for (std::string line; std::getline(cpuinfo, line);)
        if (line.rfind("model name", 0) == 0 && line.find(':') != std::string::npos) {
            cpu = line.substr(line.find(':') + 2);
            break;
        }
    // `stepwise bench hard-cases` starts this program; the table names that.
    std::string command = "stepwise bench hard-cases";
    for (int i = 1; i < argc; ++i) command.append(" ").append(argv[i]);
    return "Measured " + std::string(when) + " on " + cpu + " (" + std::to_string(std::thread::hardware_concurrency()) +
           " hardware threads) by `" + command + "`.";
}

/// Text for a Markdown table cell: a '|' (as in "|v - w|") would end the cell.
std::string cell(const std::string& text) {
    std::string out;
    for (const char ch : text) {
        if (ch == '|') out += '\\';
        out += ch;
    }
    return out;
}

std::string num(double x) {
    if (std::isnan(x)) return "NaN";
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", x);
    return b;
}

/// hard_cases.png: one panel per case, error against ms/step; a panel
/// with several cases (a sweep) shows for each setting the worst error and
/// the slowest step over them.
bool writePlot(const fs::path& dir, const std::vector<Row>& rows, const std::vector<Case>& cases) {
    std::vector<std::string> panels;
    std::map<std::string, bool> logOf;
    std::map<std::string, std::string> labelOf;
    for (const Case& c : cases)
        if (std::find(panels.begin(), panels.end(), c.panel) == panels.end()) {
            panels.push_back(c.panel);
            logOf[c.panel] = c.logError;
            labelOf[c.panel] = c.errorLabel;
        }
    std::ostringstream data;
    int block = 0;
    std::map<std::string, int> firstBlock;
    const char* series[] = {"Stepwise", "Stepwise default", "Box2D 2.4.1"};
    for (const std::string& panel : panels) {
        firstBlock[panel] = block;
        for (const char* engine : series) {
            if (block > 0) data << "\n\n";
            data << "# " << panel << " / " << engine << "\n";
            ++block;
            std::vector<std::string> settings;
            for (const Row& r : rows)
                if (r.panel == panel && r.engine == engine &&
                    std::find(settings.begin(), settings.end(), r.setting) == settings.end())
                    settings.push_back(r.setting);
            bool any = false;
            for (const std::string& setting : settings) {
                double ms = 0.0, error = 0.0;
                bool failed = false;
                for (const Row& r : rows)
                    if (r.panel == panel && r.engine == engine && r.setting == setting) {
                        ms = std::max(ms, r.ms);
                        if (std::isnan(r.error)) failed = true;
                        else error = std::max(error, r.error);
                    }
                if (failed || std::isnan(ms)) continue;  // diverged: the table says so
                // A log axis has no zero: errors below 1e-6 sit on 1e-6.
                if (logOf[panel]) error = std::max(error, 1e-6);
                data << ms << " " << error << " \"" << setting << "\"\n";
                any = true;
            }
            if (!any) data << "NaN NaN \"\"\n";
        }
    }
    if (Result<void> r = writeFileAtomically(dir / "hard_cases.dat", data.str()); !r) {
        std::cerr << r.error() << "\n";
        return false;
    }
    const int columns = 4, rowsOfPanels = int((panels.size() + columns - 1) / columns);
    std::ostringstream gp;
    gp << "set terminal pngcairo size 1800," << 380 * rowsOfPanels << " font 'DejaVu Sans,10' noenhanced\n"
       << "set output '" << (dir / "hard_cases.png").string() << "'\n"
       << "set multiplot layout " << rowsOfPanels << "," << columns
       << " title 'Hard cases: error against median ms/step (Stepwise fixed substeps x 1 iteration: solid, labels = "
          "substeps; Stepwise defaults: square; Box2D 2.4.1, 8+3 iterations: dashed). Sweeps: worst error, slowest step'\n"
       << "set grid\nset logscale x\nset format x '%g'\nset format y '%g'\nset xlabel 'ms per step'\n"
       << "set key top right font ',8'\n";
    for (const std::string& panel : panels) {
        const int b = firstBlock[panel];
        const std::string file = (dir / "hard_cases.dat").string();
        gp << (logOf[panel] ? "set logscale y\n" : "unset logscale y\n") << "set ylabel '" << labelOf[panel]
           << "'\nset title '" << panel << "'\nplot '" << file << "' index " << b
           << " using 1:2 with linespoints lc 1 pt 7 title 'Stepwise', '' index " << b
           << " using 1:2:3 with labels offset 0,0.8 font ',7' notitle, '' index " << b + 1
           << " using 1:2 with points lc 3 pt 5 ps 1.5 title 'Stepwise defaults', '' index " << b + 2
           << " using 1:2 with linespoints lc 2 dt 2 pt 6 title 'Box2D 2.4.1', '' index " << b + 2
           << " using 1:2:3 with labels offset 0,-0.8 font ',7' tc lt 2 notitle\n";
    }
    gp << "unset multiplot\n";
    const fs::path script = dir / "hard_cases.gp";
    std::ofstream(script) << gp.str();
    const std::string command = "gnuplot '" + script.string() + "' 2>'" + (dir / "gnuplot.log").string() + "'";
    if (std::system(command.c_str()) != 0) {
        std::cerr << "hard_cases: gnuplot failed (is gnuplot-nox installed?); see " << (dir / "gnuplot.log").string()
                  << "\n";
        return false;
    }
    return true;
}

} // namespace

int main(int argc, char** argv) {
    bool quick = false;
    std::string out, only, writeLevels;
    int stepsOverride = 0;
    fs::path levels = fs::path(STEPWISE_SOURCE_DIR) / "bench" / "levels";
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (arg == "--quick") quick = true;
        else if (arg == "--out" && i + 1 < argc) out = argv[++i];
        else if (arg == "--only" && i + 1 < argc) only = argv[++i];
        else if (arg == "--budget" && i + 1 < argc && std::atof(argv[i + 1]) > 0) g_budgetSeconds = std::atof(argv[++i]);
        else if (arg == "--steps" && i + 1 < argc && std::atoi(argv[i + 1]) > 0) stepsOverride = std::atoi(argv[++i]);
        else if (arg == "--levels" && i + 1 < argc) levels = argv[++i];
        else if (arg == "--write-levels" && i + 1 < argc) writeLevels = argv[++i];
        else {
            std::cerr << "hard_cases: unknown argument \"" << arg
                      << "\"; usage: hard_cases [--quick] [--steps N] [--budget S] [--out DIR] [--only NAME] [--levels DIR] [--write-levels DIR]\n";
            return 2;
        }
    }
    if (!writeLevels.empty()) {
        fs::create_directories(writeLevels);
        for (const bench::Box2dScene& b : bench::box2dBenchmarkScenes()) {
            const fs::path file = fs::path(writeLevels) / ("box2d_" + b.name + ".json");
            if (Result<void> r = saveSceneFile(b.scene, file); !r) {
                std::cerr << r.error() << "\n";
                return 2;
            }
            std::cout << "wrote " << file.string() << "\n";
        }
        return 0;
    }

    std::vector<Case> cases;
    for (double w0 : {-5.0, -20.0, -50.0, -200.0}) cases.push_back(spinningDisc(w0));
    for (double g : {10.0, 100.0, 1000.0, 2e4}) cases.push_back(ballOnThinBox(g));
    cases.push_back(heavyOnChain());
    cases.push_back(chainOf20());
    for (double mass : {4.0, 100.0}) cases.push_back(crateOnBridge(mass));
    for (double g : {10.0, 1e4}) cases.push_back(stackOf10(g));
    cases.push_back(stackOnAPlanet(1000.0));
    cases.push_back(stackOnAPlanet(1000.0, true));
    cases.push_back(stackPressedBySpring(1000.0));
    cases.push_back(stackPressedByHingedBar(1e4));
    for (int n : {64, 1000, 10000})
        if (!(quick && n > 1000)) cases.push_back(crowd(n));
    cases.push_back(pile300());
    // 500 steps: the pyramids' quality is read after 500 steps.
    for (Case& c : box2dScenes(levels, 500)) cases.push_back(std::move(c));
    if (!only.empty())
        std::erase_if(cases, [&](const Case& c) { return c.name.find(only) == std::string::npos; });
    if (quick)
        for (Case& c : cases) c.steps = std::max(1, c.steps / 5);
    if (stepsOverride > 0)
        for (Case& c : cases) c.steps = stepsOverride;

    const std::vector<Setting> settings{{"default", 0}, {"1", 1}, {"2", 2}, {"4", 4}, {"8", 8}};
    std::vector<Row> rows;
    const auto record = [&](const Case& c, const std::string& engine, const std::string& setting, const Bodies& b,
                            const Run& run) {
        Row row{c.panel, c.name, engine, setting, c.errorLabel, run.msPerStep, kNaN, ""};
        if (run.diverged.empty() || run.steps > 0) {
            const Figures f = c.measure(b, run);
            row.error = run.diverged.empty() ? f.error : kNaN;
            row.detail = f.detail;
        }
        if (!run.stopped.empty()) {
            row.detail = run.stopped + " after " + std::to_string(run.steps) + " steps; " + row.detail;
            if (run.stopped.starts_with("blew")) row.error = kNaN;
        }
        if (!run.diverged.empty())
            row.detail = "failed after " + std::to_string(run.steps) + " steps (" + run.diverged.substr(0, 120) +
                         ")" + (row.detail.empty() ? "" : "; then " + row.detail);
        // The figures go into Markdown and CSV cells: an engine's message
        // may hold neither a line break, a cell separator nor a quote.
        for (char& ch : row.detail)
            if (ch == '\n' || ch == '|' || ch == '"') ch = ch == '|' ? '/' : ch == '"' ? '\'' : ' ';
        std::printf("| %s | %s | %s | %.4g | %s | %s |\n", c.name.c_str(), engine.c_str(), setting.c_str(), row.ms,
                    num(row.error).c_str(), row.detail.c_str());
        std::fflush(stdout);
        rows.push_back(std::move(row));
    };
    std::printf("| case | engine | substeps | ms/step | error | figures |\n|---|---|---|---|---|---|\n");
    for (const Case& c : cases) {
        const Bodies bodies = bodiesOf(c.scene);
        for (const Setting& s : settings)
            record(c, s.substeps == 0 ? "Stepwise default" : "Stepwise", s.label, bodies,
                   runStepwise(c.scene, bodies, c.steps, s, c.track));
        if (!c.box2d) continue;
        for (int n : {1, 2, 4, 8}) {
            if (n > 1 && !c.box2dSweep) break;
            record(c, "Box2D 2.4.1", std::to_string(n), bodies, runBox2d(c.scene, bodies, c.steps, n, c.track));
        }
    }
    if (out.empty()) return 0;

    const fs::path dir(out);
    fs::create_directories(dir);
    std::ostringstream csv, md;
    csv << "case,panel,engine,substeps,ms_per_step,error,error_meaning,figures\n";
    for (const Row& r : rows)
        csv << '"' << r.name << "\",\"" << r.panel << "\",\"" << r.engine << "\"," << r.setting << "," << num(r.ms)
            << "," << num(r.error) << ",\"" << r.errorLabel << "\",\"" << r.detail << "\"\n";
    md << "# Hard cases: error against time\n\n" << measuredOn(argc, argv) << "\n\n"
       << "Written by `stepwise bench hard-cases --out docs/measured` (see docs/performance.md, \"Hard cases\"). "
          "Stepwise runs each case at its defaults (the level's own step settings removed: the engine chooses "
          "substeps and iterations, and sleeping is on) and at substeps 1, 2, 4 and 8 of one iteration each with "
          "sleeping off; Box2D 2.4.1 runs in the same process with 8 velocity and 3 position iterations per call and "
          "sleeping off, at 1, 2, 4 and 8 calls per step (at 1 only for its benchmark scenes and the 1,000 crowd; "
          "not at all for the 10,000 crowd, where it would make a contact for each of 5e7 overlapping pairs, nor "
          "for the spinner, where it takes over a second a step). ms/step is the median of a run's per-step times; "
          "one run each. A run stops early, and says so, when it reaches the wall-clock budget or a joint opens "
          "by more than 1 km.\n\n"
       << "![hard cases](hard_cases.png)\n\n";
    // Box2D's benchmark scenes side by side, with the reference figures.
    md << "## Box2D's benchmark scenes\n\n"
       << "| scene | Stepwise at v3's settings (4 substeps, 1 iteration), ms | Stepwise defaults, ms | Box2D 2.4.1 "
          "(1 x 8+3 iterations), ms | Box2D v3.1.1, ms (reference) | Stepwise at v3's settings, ms (reference) | "
          "Stepwise at v3's settings | Stepwise defaults | Box2D 2.4.1 |\n|---|---|---|---|---|---|---|---|---|\n";
    for (const Reference& ref : kReferences) {
        const std::string name = std::string("box2d ") + ref.scene;
        const Row *v3 = nullptr, *def = nullptr, *peer = nullptr;
        for (const Row& r : rows) {
            if (r.name != name) continue;
            if (r.engine == "Stepwise" && r.setting == "4") v3 = &r;
            if (r.engine == "Stepwise default") def = &r;
            if (r.engine == "Box2D 2.4.1" && r.setting == "1") peer = &r;
        }
        if (!v3 && !def && !peer) continue;
        const auto ms = [](const Row* r) { return r ? fmt("%.3g", r->ms) : std::string("–"); };
        const auto what = [](const Row* r) { return r ? cell(r->detail) : std::string("–"); };
        md << "| " << ref.scene << " | " << ms(v3) << " | " << ms(def) << " | " << ms(peer) << " | "
           << (std::isnan(ref.v3Ms) ? std::string("–") : fmt("%.3g", ref.v3Ms)) << " | "
           << (std::isnan(ref.stepwiseMs) ? std::string("–") : fmt("%.3g", ref.stepwiseMs)) << " | " << what(v3)
           << " | " << what(def) << " | " << what(peer) << " |\n";
    }
    md << "\nBox2D v3.1.1 on the large pyramid: the top box drifts 4 mm sideways and 1e-4 J of kinetic energy are "
          "left after 500 steps.\n\n## Every run\n\n"
       << "| case | engine | substeps | ms/step | error | error is | figures |\n|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows)
        md << "| " << cell(r.name) << " | " << r.engine << " | " << r.setting << " | " << fmt("%.3g", r.ms) << " | "
           << num(r.error) << " | " << cell(r.errorLabel) << " | " << cell(r.detail) << " |\n";
    for (const auto& [name, text] :
         {std::pair<std::string, std::string>{"hard_cases.csv", csv.str()}, {"hard_cases.md", md.str()}})
        if (Result<void> r = writeFileAtomically(dir / name, text); !r) {
            std::cerr << r.error() << "\n";
            return 2;
        }
    if (!writePlot(dir, rows, cases)) return 2;
    std::cout << "wrote " << (dir / "hard_cases.md").string() << ", " << (dir / "hard_cases.csv").string() << ", "
              << (dir / "hard_cases.png").string() << "\n";
    return 0;
}
