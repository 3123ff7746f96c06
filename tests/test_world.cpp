// World: building, refusal of what this build cannot simulate, divergence
// reports, determinism across save/load, stiffness hints, the stiff chain
// and the CLI's exit code 3.

#include "physics_scenes.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world_fields.hpp"
#include "world/world_internals.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include <array>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <sys/wait.h>

using namespace stepwise;
using namespace stepwise::testing;

namespace {

Scene mixedScene(const std::string& integrator) {
    // Springs, drag, an attractor pair, boids and spin: every system.
    Scene s = emptyScene(integrator, 1.0 / 60.0, {0.0, -9.81});
    s.world.substeps = 2;
    addStatic(s, "post", {0.0, 5.0});
    for (int i = 0; i < 6; ++i) {
        Entity e = addBody(s, "bead" + std::to_string(i), {0.4 * (i + 1), 5.0}, {0.0, 0.1 * i}, 0.2 + 0.05 * i);
        s.registry.emplace<Drag>(e, {0.05});
        addSpring(s, "link" + std::to_string(i), i == 0 ? "post" : "bead" + std::to_string(i - 1),
                  "bead" + std::to_string(i), 50.0, 0.2, 0.4);
    }
    Entity star = addBody(s, "star", {-3.0, 0.0}, {0.0, 0.3}, 5.0);
    s.registry.emplace<Attractor>(star, {0.2});
    s.registry.emplace<Angle>(star, {0.1});
    s.registry.emplace<AngularVelocity>(star, {1.5});
    for (int i = 0; i < 12; ++i) {
        Entity b = addBody(s, "boid" + std::to_string(i), {-6.0 + 0.5 * (i % 4), -2.0 + 0.5 * (i / 4)},
                           {0.3 * (i % 3), -0.2 * (i % 2)});
        Boid boid;
        boid.goal = Vec2{4.0, 4.0};
        s.registry.emplace<Boid>(b, boid);
    }
    return s;
}

TEST(World, ActiveSystemsAreWhatTheSceneContains) {
    {
        Scene s = emptyScene("rk4", 0.01);
        addBody(s, "a", {0, 0}, {1, 0});
        World w = buildOrDie(s);
        EXPECT_TRUE(w.activeSystems().empty());  // zero gravity, nothing else
    }
    {
        Oscillator osc;
        World w = buildOrDie(osc.scene("rk4", 0.01));
        EXPECT_EQ(w.activeSystems(), (std::vector<std::string_view>{"springs"}));
        ASSERT_TRUE(w.step().ok());
        std::vector<std::string_view> stages, systems;
        for (const StageTime& st : w.lastStats().stages) stages.push_back(st.name);
        for (const StageTime& st : w.lastStats().systems) systems.push_back(st.name);
        EXPECT_EQ(stages, (std::vector<std::string_view>{"forces", "integrate", "check"}));
        EXPECT_EQ(systems, (std::vector<std::string_view>{"springs"}));
        EXPECT_EQ(w.lastStats().forceEvaluations, 4);  // RK4
    }
    World w = buildOrDie(mixedScene("midpoint"));
    EXPECT_EQ(w.activeSystems(),
              (std::vector<std::string_view>{"gravity", "drag", "springs", "attractors", "boids", "rotation"}));
    EXPECT_EQ(w.bodyCount(), 6u + 1u + 12u);
}

TEST(World, CollisionStagesRunOnlyWhenTheSceneHasShapes) {
    Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0);
    s.world.gravity = {0.0, -10.0};
    addBody(s, "free", {5, 0}, {0, 0});
    Entity ball = addBody(s, "ball", {0, 0.5}, {0, 0});
    {
        Result<World> shapeless = World::build(s);
        ASSERT_TRUE(shapeless.ok()) << shapeless.error();
        const auto systems = shapeless->activeSystems();
        EXPECT_EQ(std::count(systems.begin(), systems.end(), "collisions"), 0);
        ASSERT_TRUE(shapeless->step().ok());
        for (const StageTime& stage : shapeless->lastStats().stages)
            EXPECT_NE(stage.name, "broad_phase") << "a scene without shapes must not pay for collisions";
        EXPECT_TRUE(shapeless->contacts().empty());
    }
    // A ball resting on a static box: collisions join the pipeline, the ball
    // stays on the box and the contact carries its weight.
    s.registry.emplace<Radius>(ball, {0.5});
    Entity floor = addStatic(s, "floor", {0, -0.5});
    s.registry.emplace<Box>(floor, {10.0, 1.0});
    Result<World> w = World::build(s);
    ASSERT_TRUE(w.ok()) << w.error();
    const auto systems = w->activeSystems();
    EXPECT_EQ(std::count(systems.begin(), systems.end(), "collisions"), 1);
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(w->step().ok());
    ASSERT_EQ(w->contacts().size(), 1u);
    const ContactRecord& c = w->contacts()[0];
    EXPECT_EQ(c.b, floor) << "the static side is b";
    EXPECT_EQ(c.normal, (Vec2{0.0, -1.0})) << "from a (the ball) to b (the floor)";
    // One substep's impulse equals the weight times the substep: m g h.
    EXPECT_NEAR(c.normalImpulse, 1.0 * 10.0 / 60.0, 1e-6);
    Scene after = s;
    w->writeBack(after);
    EXPECT_NEAR(after.registry.tryGet<Position>(ball)->value.y, 0.5, 0.01);
    EXPECT_NEAR(after.registry.tryGet<Position>(ball)->value.x, 0.0, 1e-12);
}

// A scene made in code is held to the settings table's ranges, in the
// words the loader writes after /world/KEY (WorldFields.
// EveryOutOfRangeSettingIsRefusedAtItsPointer): one check, not two. A cap
// that guards input only is not held against it.
TEST(World, EveryOutOfRangeSettingIsRefusedWithTheTablesWords) {
    for (const WorldFieldInfo& info : worldFieldTable()) {
        const NumberRange& r = info.field.range;
        if (!std::isfinite(r.max)) continue;
        const std::string key(info.field.key);
        Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0, {0.0, -9.81});
        void* member = info.field.address(&s.world);
        // One past an integer bound; past 1e30, one part in a million (1e30
        // + 1 is 1e30 again).
        const double outside = r.max + std::max(1.0, r.max * 1e-6);
        std::string expected = r.describe(info.field.kind == FieldKind::Integer) + ", got " + formatNumber(outside);
        switch (info.field.kind) {
        case FieldKind::Number: *static_cast<double*>(member) = outside; break;
        case FieldKind::OptionalNumber: *static_cast<std::optional<double>*>(member) = outside; break;
        case FieldKind::Integer: *static_cast<int*>(member) = int(outside); break;
        case FieldKind::Vector:
            *static_cast<Vec2*>(member) = {outside, 0.0};
            expected = "each axis in [" + formatNumber(r.min) + ", " + formatNumber(r.max) + "], got {\"x\": " +
                       formatNumber(outside) + ", \"y\": 0}";
            break;
        default: FAIL() << key << ": a bounded setting of another kind";
        }
        Result<World> w = World::build(s);
        if (info.maxGuardsInputOnly) {
            EXPECT_TRUE(w) << key << ": " << w.error();
            continue;
        }
        ASSERT_FALSE(w) << key;
        EXPECT_EQ(w.error(), "world." + key + ": expected " + expected);
    }
    Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0, {0.0, -9.81});
    s.world.integrator = "rk5";
    Result<World> w = World::build(s);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error().rfind("world.integrator: expected one of explicit_euler, ", 0), 0u) << w.error();
}

TEST(World, DivergenceNamesStepEntityAndQuantityAndKeepsState) {
    // Gravity of 1e9 m/s^2, the most a level holds, adds 5e8 m/s per step
    // of 0.5 s: step 3 takes the ball past the fastest speed a level holds
    // (1e9 m/s), so its state could not be saved and loaded again.
    Scene s = emptyScene("semi_implicit_euler", 0.5, {0.0, -1e9});
    s.world.substeps = 1;
    addStatic(s, "floor", {0, 0});
    addBody(s, "ball", {0, 0}, {0, 0});
    World w = buildOrDie(s);
    for (int i = 0; i < 2; ++i) ASSERT_TRUE(w.step().ok());
    const Vec2 before = w.bodyPosition(0);
    const double timeBefore = w.time();
    Result<void> r = w.step();
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error(), "step 3: entity 1 (\"ball\"): velocity.y became -1.5e+09, beyond the +-1e+09 a level can "
                         "hold");
    EXPECT_EQ(r.failure().kind, ErrorKind::Diverged);
    const AdvanceResult advanced = advance(w, 5);
    ASSERT_TRUE(advanced.divergence);
    EXPECT_EQ(advanced.taken, 0u);
    EXPECT_EQ(advanced.divergence->kind, ErrorKind::Diverged);
    EXPECT_EQ(advanced.divergence->message, r.error());
    EXPECT_EQ(w.bodyPosition(0), before);
    EXPECT_EQ(w.time(), timeBefore);
    EXPECT_EQ(w.lastStats().step, 2u);

    // With substeps, the state before the whole step comes back. Velocity
    // is reported before position (cause before effect).
    Scene s2 = emptyScene("explicit_euler", 1.0, {0.0, -1e9});
    s2.world.substeps = 3;
    Entity e = s2.registry.create();
    s2.registry.emplace<Position>(e, {{0.0, 0.0}});
    s2.registry.emplace<Velocity>(e, {{0.0, -9e8}});
    World w2 = buildOrDie(s2);
    Result<void> r2 = w2.step();
    ASSERT_FALSE(r2.ok());
    // -9e8 + 3 x (-1e9 / 3) in doubles.
    EXPECT_EQ(r2.error(), "step 1: entity 0: velocity.y became -1899999999.9999998, beyond the +-1e+09 a level can "
                          "hold");
    EXPECT_EQ(w2.bodyVelocity(0), (Vec2{0.0, -9e8}));
    EXPECT_EQ(w2.bodyPosition(0), (Vec2{0.0, 0.0}));
}

// A file cannot hold values whose energy overflows (docs/format.md,
// "Ranges"), but a scene made in code can: the energy check names the first
// entity and term that are not finite, with the numbers behind it.
TEST(World, ANonFiniteEnergyNamesTheEntityAndTheTerm) {
    const auto termOf = [](const std::function<void(Scene&)>& make) {
        Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0, {0.0, -10.0});
        make(s);
        return buildOrDie(s).nonFiniteEnergyTerm();
    };
    // A spin a step can take (its rim under 1e9 m/s) on a body heavy enough
    // that I w^2 / 2 overflows.
    EXPECT_EQ(termOf([](Scene& s) {
                  const Entity e = addBody(s, "spinner", {0, 10}, {0, 0}, 1e300);
                  s.registry.emplace<Radius>(e, {1.0});
                  s.registry.emplace<AngularVelocity>(e, {9e8});
              }),
              "entity 0 (\"spinner\"): rotational energy I*w^2/2 became inf J (inertia 5e+299 kg m^2, spin 9e+08 rad/s)");
    EXPECT_EQ(termOf([](Scene& s) { addBody(s, "heavy", {0, 0.5}, {0, 0}, 1e308); }),
              "entity 0 (\"heavy\"): gravity's potential energy -m*g.x became inf J (mass 1e+308 kg at {0, 0.5} m)");
    EXPECT_EQ(termOf([](Scene& s) { addBody(s, "fast", {0, 0}, {1e200, 0}); }),
              "entity 0 (\"fast\"): kinetic energy m*v^2/2 became inf J (mass 1 kg, speed 1e+200 m/s)");
    EXPECT_EQ(termOf([](Scene& s) { addBody(s, "calm", {0, 0}, {1, 0}); }), "");
}

// Every field within its range, yet the first step would carry a body past
// the 1e9 m/s a run holds: the build refuses it, naming the value, instead
// of a divergence at step 1. Swept across the limit: gravity times dt, and
// a spin times the shape's farthest point.
TEST(World, ValuesNoStepCanTakeAreRefusedAtBuild) {
    const double dt = 1.0 / 60.0;
    for (const double factor : {0.5, 0.999, 1.001, 1e10}) {
        const double g = factor * 1e9 / dt;
        Scene s = emptyScene("semi_implicit_euler", dt, {0.0, -g});
        addBody(s, "ball", {0, 0}, {0, 0});
        Result<World> w = World::build(s);
        EXPECT_EQ(bool(w), factor < 1.0) << factor;
        if (!w)
            EXPECT_EQ(w.error(), "world.gravity: " + formatNumber(g) + " m/s^2 gives a body " + formatNumber(g * dt) +
                                     " m/s in one step of " + formatNumber(dt) +
                                     " s, past the 1e+09 m/s a run holds; at this dt gravity may be at most " +
                                     formatNumber(1e9 / dt) + " m/s^2");
    }
    for (const double factor : {0.5, 0.999, 1.001, 100.0}) {
        Scene s = emptyScene("semi_implicit_euler", dt);
        const Entity e = addBody(s, "wheel", {0, 0}, {0, 0});
        s.registry.emplace<Box>(e, Box{6.0, 8.0});  // farthest corner 5 m from the centre
        s.registry.emplace<AngularVelocity>(e, AngularVelocity{factor * 1e9 / 5.0});
        Result<World> w = World::build(s);
        EXPECT_EQ(bool(w), factor < 1.0) << factor;
        if (!w)
            EXPECT_EQ(w.error(), "entity 0 (\"wheel\"): angular_velocity: " + formatNumber(factor * 2e8) +
                                     " rad/s moves its farthest point (5 m from its centre of mass) at " +
                                     formatNumber(factor * 2e8 * 5.0) + " m/s, past the 1e+09 m/s a run holds");
    }
}

// The same for the pull of attractors and springs at the start: an
// attractor heavy enough (G m / r^2 times dt past 1e9 m/s), or a stiff
// spring stretched, is refused naming the body it pulls; swept across the
// limit.
TEST(World, PullsNoStepCanTakeAreRefusedAtBuild) {
    const double dt = 1.0 / 60.0;
    for (const double factor : {0.5, 0.999, 1.001, 1e10}) {
        // A static sun 2 m from a ball: a = G m / r^2, G = 1.
        Scene s = emptyScene("semi_implicit_euler", dt);
        addBody(s, "ball", {2, 0}, {0, 0});
        const Entity sun = addBody(s, "sun", {0, 0}, {0, 0}, factor * 4e9 / dt);
        s.registry.emplace<Static>(sun, Static{true});
        s.registry.emplace<Attractor>(sun, {0.0});
        Result<World> w = World::build(s);
        EXPECT_EQ(bool(w), factor < 1.0) << factor;
        if (!w) {
            const double pull = factor * 1e9 / dt;
            EXPECT_EQ(w.error(), "entity 0 (\"ball\"): the attractors pull it at " + formatNumber(pull) +
                                     " m/s^2 at the start: " + formatNumber(pull * dt) + " m/s in one step of " +
                                     formatNumber(dt) + " s, past the 1e+09 m/s a run holds");
        }
    }
    for (const double factor : {0.5, 0.999, 1.001, 1e10}) {
        // A 2 kg body on a spring stretched 3 m: a = k 3 / 2.
        Scene s = emptyScene("semi_implicit_euler", dt);
        const Entity e = addBody(s, "bob", {3, 0}, {0, 0}, 2.0);
        const Entity spring = s.registry.create();
        s.registry.emplace<Spring>(spring, Spring{e, Entity{}, Vec2{0.0, 0.0}, factor * 2e9 / (3.0 * dt), 0.0, 0.0});
        Result<World> w = World::build(s);
        EXPECT_EQ(bool(w), factor < 1.0) << factor;
        if (!w) {
            EXPECT_NE(w.error().find("entity 0 (\"bob\"): the springs pull it at "), std::string::npos) << w.error();
        }
    }
    // Two bodies at one point under an attractor with no softening: no
    // direction to pull in, so no pull (and a build, not a refusal).
    Scene s = emptyScene("semi_implicit_euler", dt);
    const Entity a = addBody(s, "a", {1, 1}, {0, 0});
    addBody(s, "b", {1, 1}, {0, 0});
    s.registry.emplace<Attractor>(a, {0.0});
    Result<World> w = World::build(s);
    ASSERT_TRUE(w) << w.error();
    EXPECT_EQ(w->bodyForces()[1], (Vec2{0.0, 0.0}));
}

// A step that diverges leaves the whole carried state as it was, the
// solver's too: the failed step's contact cache and joint impulses must not
// stay in place and warm the next step (a retry after an edit, a reload
// keeping the warm start), or the World is not "as before that step".
TEST(World, DivergenceLeavesTheWarmStartAndJointImpulsesAsTheyWere) {
    // A ball resting on a floor (contact impulses), a swinging pendulum
    // (joint impulses), and a shapeless rocket pulled by a weak spring to a
    // point 1e12 m away: 6e8 m/s^2, so 3e8 m/s more each step of 0.5 s, and
    // past the 1e9 m/s a level holds in its fourth step.
    Result<Scene> scene = parseScene(R"({"world": {"dt": 0.5, "substeps": 2},
        "entities": [{"name": "floor", "position": {"x": 0, "y": -1}, "static": true, "box": {"width": 10, "height": 1}},
                     {"name": "ball", "position": {"x": 0, "y": 0}, "radius": 0.5},
                     {"name": "bob", "position": {"x": 6, "y": 0}, "radius": 0.2},
                     {"name": "pin", "joint": {"type": "hinge", "a": "bob", "anchor": {"x": 5, "y": 0}}},
                     {"name": "rocket", "position": {"x": 0, "y": 50}},
                     {"name": "thrust", "spring": {"a": "rocket", "anchor": {"x": 1e12, "y": 50}, "k": 6e-4,
                                                   "rest_length": 0}}]})",
                                     "diverge.json");
    ASSERT_TRUE(scene) << scene.error();
    World w = buildOrDie(*scene);
    for (int i = 0; i < 3; ++i) ASSERT_TRUE(w.step().ok());
    const WorldState before = w.saveState();
    ASSERT_FALSE(before.contacts.empty());
    ASSERT_EQ(before.joints.size(), 1u);
    Result<void> r = w.step();
    ASSERT_FALSE(r.ok());
    EXPECT_NE(r.error().find("\"rocket\""), std::string::npos) << r.error();
    const WorldState after = w.saveState();
    EXPECT_EQ(after.x, before.x);
    EXPECT_EQ(after.v, before.v);
    EXPECT_EQ(after.colliderAngle, before.colliderAngle);
    EXPECT_EQ(after.colliderSpin, before.colliderSpin);
    EXPECT_EQ(after.contacts, before.contacts);
    EXPECT_EQ(after.joints, before.joints);
}

// The contacts a World lists are those of its last whole step, whether
// they were looked at before a step that diverges or only after it (they
// are made when first asked for).
TEST(World, AfterADivergenceTheContactsAreThoseOfTheLastWholeStep) {
    Result<Scene> scene = parseScene(R"({"world": {"dt": 0.5, "substeps": 2},
        "entities": [{"name": "floor", "position": {"x": 0, "y": -1}, "static": true, "box": {"width": 10, "height": 1}},
                     {"name": "ball", "position": {"x": 0, "y": 0}, "radius": 0.5},
                     {"name": "crate", "position": {"x": 3, "y": 0}, "box": {"width": 1, "height": 1}},
                     {"name": "rocket", "position": {"x": 0, "y": 50}},
                     {"name": "thrust", "spring": {"a": "rocket", "anchor": {"x": 1e12, "y": 50}, "k": 6e-4,
                                                   "rest_length": 0}}]})",
                                     "diverge.json");
    ASSERT_TRUE(scene) << scene.error();
    World looked = buildOrDie(*scene), unlooked = buildOrDie(*scene);
    std::vector<ContactRecord> lastWhole;
    for (int i = 0; i < 3; ++i) {
        ASSERT_TRUE(looked.step().ok());
        ASSERT_TRUE(unlooked.step().ok());
        const std::span<const ContactRecord> now = looked.contacts();
        lastWhole.assign(now.begin(), now.end());
    }
    ASSERT_EQ(lastWhole.size(), 3u) << "the ball's point and the crate's two";
    ASSERT_FALSE(unlooked.step().ok());
    ASSERT_FALSE(looked.step().ok());
    for (const World* w : {&looked, &unlooked}) {
        const std::span<const ContactRecord> after = w->contacts();
        ASSERT_EQ(after.size(), lastWhole.size());
        for (std::size_t k = 0; k < after.size(); ++k) {
            EXPECT_EQ(after[k].a, lastWhole[k].a);
            EXPECT_EQ(after[k].b, lastWhole[k].b);
            EXPECT_EQ(after[k].point.x, lastWhole[k].point.x);
            EXPECT_EQ(after[k].point.y, lastWhole[k].point.y);
            EXPECT_EQ(after[k].depth, lastWhole[k].depth);
            EXPECT_EQ(after[k].normalImpulse, lastWhole[k].normalImpulse);
            EXPECT_EQ(after[k].tangentImpulse, lastWhole[k].tangentImpulse);
        }
        EXPECT_EQ(w->lastStats().contactCount, lastWhole.size());
    }
}

std::string stepAndSave(Scene scene, int steps, int times) {
    // `times` rounds of: build, step `steps`, write back, save, load.
    for (int round = 0; round < times; ++round) {
        World w = buildOrDie(scene);
        for (int i = 0; i < steps; ++i) {
            Result<void> r = w.step();
            if (!r) throw std::runtime_error(r.error());
        }
        w.writeBack(scene);
        const std::string text = sceneToJsonText(scene);
        Result<Scene> loaded = parseScene(text, "roundtrip");
        if (!loaded) throw std::runtime_error(loaded.error());
        scene = std::move(loaded.value());
    }
    return sceneToJsonText(scene);
}

TEST(World, DeterministicAcrossSaveAndLoad) {
    // dopri5 carries its proposed step across frames: saved as
    // world.adaptive_step, so the split run continues bit for bit too.
    for (const char* integrator : {"explicit_euler", "semi_implicit_euler", "midpoint", "trapezoid", "rk4",
                                   "velocity_verlet", "implicit_euler", "implicit_midpoint", "dopri5"}) {
        const Scene scene = mixedScene(integrator);
        const std::string straight = stepAndSave(scene, 200, 1);
        const std::string split = stepAndSave(scene, 100, 2);
        EXPECT_EQ(straight, split) << integrator << ": 200 steps differ from 100 + save/load + 100";
        // And the run did something: the text differs from the start.
        EXPECT_NE(straight, stepAndSave(scene, 0, 1)) << integrator;
    }
}

TEST(World, SetIntegratorAndEnergyAndMomentum) {
    Scene s = emptyScene("rk4", 0.01, {0.0, -10.0});
    addBody(s, "a", {1.0, 2.0}, {3.0, 0.0}, 2.0);
    World w = buildOrDie(s);
    const EnergyReport e = w.energy();
    EXPECT_DOUBLE_EQ(e.kinetic, 9.0);
    EXPECT_DOUBLE_EQ(e.gravity, 40.0);  // -m g.p = -2 * (-10) * 2
    EXPECT_DOUBLE_EQ(e.momentum.x, 6.0);
    EXPECT_FALSE(w.setIntegrator("leapfrog").ok());
    ASSERT_TRUE(w.setIntegrator("implicit_midpoint").ok());
    EXPECT_EQ(w.settings().integrator, "implicit_midpoint");
    for (int i = 0; i < 100; ++i) ASSERT_TRUE(w.step().ok());
    // Free fall conserves kinetic + gravity energy exactly under a
    // second-order method (the trajectory is exact).
    EXPECT_NEAR(w.energy().total(), e.total(), 1e-9);
}

TEST(World, StiffnessHintsNameSpringAndLargestStableDt) {
    Result<Scene> loaded = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/stiff_spring.json");
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    Scene scene = loaded.value();
    EXPECT_TRUE(buildOrDie(scene).stiffnessHints().empty()) << "implicit_euler: no hints";
    scene.world.integrator = "semi_implicit_euler";
    World w = buildOrDie(scene);
    const std::vector<StiffnessHint> hints = w.stiffnessHints();
    ASSERT_EQ(hints.size(), 10u);
    // The anchored spring: m_reduced = 0.01 kg, omega = sqrt(1e5/0.01).
    const double omega = std::sqrt(1e5 / 0.01);
    EXPECT_EQ(hints[0].springName, "stiff0");
    EXPECT_NEAR(hints[0].hOmega, omega / 60.0, 1e-9);
    EXPECT_NEAR(hints[0].limit, 2.0, 1e-9);
    EXPECT_NEAR(hints[0].largestStableDt, 2.0 / omega, 1e-12);
    // Bead to bead: m_reduced = 0.005 kg.
    EXPECT_NEAR(hints[1].largestStableDt, 2.0 / std::sqrt(1e5 / 0.005), 1e-12);
    EXPECT_NE(hints[0].message().find("stiff0"), std::string::npos);
    EXPECT_NE(hints[0].message().find("semi_implicit_euler"), std::string::npos);
    // With enough substeps the hint goes away.
    scene.world.substeps = 40;  // h w = 52.7/40 = 1.3 < 2 (bead pairs: 74.5/40 = 1.9)
    EXPECT_TRUE(buildOrDie(scene).stiffnessHints().empty());
}

// A spring with no name is called by its place in the scene's order; a
// body deleted before it in place moves it up, as a rebuild would count.
TEST(World, AnUnnamedSpringIsCalledByItsNewPlaceAfterADeleteInPlace) {
    Scene s = emptyScene("semi_implicit_euler", 1.0 / 60.0, {0.0, -10.0});
    s.world.substeps = 1;
    const Entity first = addBody(s, "first", {0.0, 5.0}, {0.0, 0.0});
    const Entity second = addBody(s, "second", {3.0, 5.0}, {0.0, 0.0});
    for (const Entity e : {first, second}) s.registry.emplace<Radius>(e, Radius{0.2});
    const Entity spring = s.registry.create();
    Spring sp;
    sp.a = second;
    sp.anchor = Vec2{3.0, 6.0};
    sp.k = 1e6;  // h omega = 1000 / 60, far past 2: a hint names it
    s.registry.emplace<Spring>(spring, std::move(sp));
    World w = buildOrDie(s);
    ASSERT_EQ(w.stiffnessHints().size(), 1u);
    EXPECT_EQ(w.stiffnessHints()[0].springName, "entity 2");
    ASSERT_TRUE(s.registry.destroy(first));
    const Result<void> changed = w.changeEntities(s, {}, std::vector<Entity>{first}, {});
    ASSERT_TRUE(changed.ok()) << changed.error();
    ASSERT_EQ(w.stiffnessHints().size(), 1u);
    EXPECT_EQ(w.stiffnessHints()[0].springName, "entity 1");
    EXPECT_EQ(w.stiffnessHints()[0].springName, buildOrDie(s).stiffnessHints()[0].springName);
}

namespace {

/// Steps `w` (just edited in place, its choice settled) and a World built
/// from `edited` with w's solver state, as a rebuild after the edit would
/// carry it, `steps` times: every body's position the same bits.
void expectStepsAsARebuild(World& w, const Scene& edited, int steps) {
    Scene rebuiltScene = edited;
    rebuiltScene.solverState = w.solverState();
    World rebuilt = buildOrDie(rebuiltScene);
    for (int i = 0; i < steps; ++i) {
        ASSERT_TRUE(w.step().ok());
        ASSERT_TRUE(rebuilt.step().ok());
    }
    ASSERT_EQ(w.bodyCount(), rebuilt.bodyCount());
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        EXPECT_EQ(w.bodyEntity(b), rebuilt.bodyEntity(b)) << b;
        EXPECT_EQ(w.bodyPosition(b).x, rebuilt.bodyPosition(b).x) << b;
        EXPECT_EQ(w.bodyPosition(b).y, rebuilt.bodyPosition(b).y) << b;
    }
    ASSERT_EQ(w.joints().size(), rebuilt.joints().size());
    for (std::size_t k = 0; k < w.joints().size(); ++k) {
        EXPECT_EQ(w.joints()[k].joint, rebuilt.joints()[k].joint) << k;
        EXPECT_EQ(w.joints()[k].force.x, rebuilt.joints()[k].force.x) << k;
    }
}

/// One body of each kind a level can add in place (the fields after its
/// name), placed to land on tests' small pile of two boxes near x = 0.
std::vector<std::pair<std::string, std::string>> kindsOfBody() {
    return {
        {"circle", R"("position": {"x": 0.3, "y": 1.7}, "radius": 0.25)"},
        {"box", R"("position": {"x": 0.3, "y": 1.7}, "angle": 0.4, "box": {"width": 0.6, "height": 0.3})"},
        {"polygon", R"("position": {"x": 0.3, "y": 1.7}, "polygon": {"vertices": [{"x": -0.3, "y": -0.2},
            {"x": 0.3, "y": -0.2}, {"x": 0.1, "y": 0.3}]})"},
        {"capsule", R"("position": {"x": 0.3, "y": 1.7}, "capsule": {"a": {"x": -0.3, "y": 0}, "b": {"x": 0.3, "y": 0},
            "radius": 0.12})"},
        {"compound", R"("position": {"x": 0.3, "y": 1.7}, "shapes": [{"box": {"center": {"x": 0.2, "y": 0}, "width": 0.5,
            "height": 0.2, "angle": 0}}, {"circle": {"center": {"x": -0.3, "y": 0.1}, "radius": 0.15}}])"},
        {"static box", R"("position": {"x": 4, "y": 0.5}, "static": true, "box": {"width": 1, "height": 1})"},
        {"static chain", R"("position": {"x": -4, "y": 0.15}, "static": true, "chain": {"points": [{"x": 1, "y": 0.5},
            {"x": 0, "y": 0}, {"x": -1, "y": 0.5}]})"},
    };
}

} // namespace

// Each kind of body added in place beside a settling pile, a body before
// it deleted (its colliders move up), then it deleted, each in place:
// after each edit the run is that of a World built from the edited scene
// with the same warm start, bit for bit, for a circle, a
// box, a polygon, a capsule, a compound body (its hub and shapes), a
// static box and a static chain (which wake every island).
TEST(World, EachKindOfBodyAddedAndDeletedInPlaceRunsAsARebuilds) {
    for (const auto& [kind, fields] : kindsOfBody()) {
        SCOPED_TRACE(kind);
        Result<Scene> loaded = parseScene(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 2, "sleep": true},
          "entities": [
            {"name": "ground", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 20, "height": 1}},
            {"name": "b1", "position": {"x": 0, "y": 0.3}, "box": {"width": 0.6, "height": 0.6}},
            {"name": "b2", "position": {"x": 0.1, "y": 0.95}, "box": {"width": 0.6, "height": 0.6}},
            {"name": "far", "position": {"x": -4, "y": 1.2}, "radius": 0.2}
          ]})", "pile");
        ASSERT_TRUE(loaded.ok()) << loaded.error();
        Scene s = loaded.value();
        World w = buildOrDie(s);
        for (int i = 0; i < 20; ++i) ASSERT_TRUE(w.step().ok());
        Result<Scene> extra = parseScene(R"({"entities": [{"name": "new", )" + fields + "}]}", "new");
        ASSERT_TRUE(extra.ok()) << extra.error();
        const Entity source = extra.value().registry.entities().front();
        const auto runsAsARebuild = [&](const char* what) {
            SCOPED_TRACE(what);
            ASSERT_TRUE(w.settleChoice(s).ok());
            expectStepsAsARebuild(w, s, 30);
            w.writeBack(s);
        };
        w.writeBack(s);
        const Entity added = s.registry.create();
        copyComponents(extra.value().registry, source, s.registry, added);
        ASSERT_TRUE(w.changeEntities(s, {}, {}, std::vector<Entity>{added}).ok());
        runsAsARebuild("added");
        // The new body landed on the pile (the chain: the ball falling on it).
        const std::span<const ContactRecord> contacts = w.contacts();
        if (kind != "static box")
            EXPECT_TRUE(std::any_of(contacts.begin(), contacts.end(),
                                    [&](const ContactRecord& c) { return c.a == added || c.b == added; }));
        // A body before it goes, so its colliders move up; then it goes.
        Entity far;
        for (const Entity e : s.registry.entities())
            if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == "far") far = e;
        for (const Entity gone : {far, added}) {
            ASSERT_TRUE(s.registry.destroy(gone));
            ASSERT_TRUE(w.changeEntities(s, {}, std::vector<Entity>{gone}, {}).ok());
            runsAsARebuild(gone == far ? "a body before it deleted" : "deleted");
        }
    }
}

// An undone delete brings entities back where they stood in the scene
// order, between kept ones: in place, each kind of body (and a hinged
// pair with its joint) goes back to its place in the World's bodies,
// colliders and joints, and the run is that of a World built from the
// scene, bit for bit, in the same order of bodies and joints, at 1, 2 and
// 8 substeps and the engine's choice. In half the cases the pile sleeps
// meanwhile (a sleeping island's labels are renumbered too) and a kept
// body goes in the same edit.
TEST(World, EachKindOfBodyBroughtBackWhereItStoodRunsAsARebuilds) {
    std::vector<std::pair<std::string, std::string>> kinds = kindsOfBody();
    kinds.push_back({"hinged pair", ""});
    // Substeps 1, 2 and 8, and none given (the engine's choice).
    int inPlace = 0, declined = 0;
    for (const int substeps : {1, 2, 8, 0})
    for (const bool sleeping : {false, true})
        for (const auto& [kind, fields] : kinds) {
            SCOPED_TRACE(kind + (sleeping ? ", the pile asleep" : "") + ", substeps " + std::to_string(substeps));
            const std::string stepping =
                substeps == 0 ? std::string() : R"("substeps": )" + std::to_string(substeps) + ", ";
            const std::string middle =
                kind == "hinged pair"
                    ? R"({"name": "p1", "position": {"x": -2, "y": 2}, "box": {"width": 0.8, "height": 0.2}},
                         {"name": "p2", "position": {"x": -1.2, "y": 2}, "box": {"width": 0.8, "height": 0.2}},
                         {"name": "hinge", "joint": {"type": "hinge", "a": "p1", "b": "p2",
                          "anchor": {"x": -1.6, "y": 2}}},)"
                    : R"({"name": "new", )" + fields + "},";
            Result<Scene> loaded = parseScene(R"({"world": {"gravity": {"x": 0, "y": -9.81}, )" + stepping + R"("sleep": true},
              "entities": [
                {"name": "ground", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 20, "height": 1}},
                {"name": "b1", "position": {"x": 0, "y": 0.3}, "box": {"width": 0.6, "height": 0.6}},
                )" + middle + R"(
                {"name": "b2", "position": {"x": 0.1, "y": 0.95}, "box": {"width": 0.6, "height": 0.6}},
                {"name": "far", "position": {"x": -4, "y": 1.2}, "radius": 0.2},
                {"name": "q1", "position": {"x": 6, "y": 2}, "box": {"width": 0.8, "height": 0.2}},
                {"name": "q2", "position": {"x": 6.8, "y": 2}, "box": {"width": 0.8, "height": 0.2}},
                {"name": "kept hinge", "joint": {"type": "hinge", "a": "q1", "b": "q2", "anchor": {"x": 6.4, "y": 2}}}
              ]})", "pile");
            ASSERT_TRUE(loaded.ok()) << loaded.error();
            Scene s = loaded.value();
            World w = buildOrDie(s);
            for (int i = 0; i < (sleeping ? 400 : 20); ++i) ASSERT_TRUE(w.step().ok());
            w.writeBack(s);
            // The middle entities go, kept aside with their places.
            Registry aside;
            std::vector<std::pair<Entity, Entity>> gone;  // handle, copy aside
            const std::vector<Entity> order = s.registry.entities();
            for (std::size_t i = 0; i < order.size(); ++i) {
                const Name* name = s.registry.tryGet<Name>(order[i]);
                if (!name || (name->value != "new" && name->value != "p1" && name->value != "p2" && name->value != "hinge"))
                    continue;
                const Entity copy = aside.create();
                copyComponents(s.registry, order[i], aside, copy);
                gone.emplace_back(order[i], copy);
            }
            ASSERT_FALSE(gone.empty());
            const Registry::Slots before = s.registry.slots();
            std::vector<Entity> handles;
            for (const auto& [e, copy] : gone) {
                handles.push_back(e);
                ASSERT_TRUE(s.registry.destroy(e));
            }
            ASSERT_TRUE(w.changeEntities(s, {}, handles, {}).ok());
            // With no substeps given, an edit may change what the engine
            // chooses: the World says so, and the caller reloads (as the
            // editor does).
            const auto declines = [&] {
                const Result<void> settled = w.settleChoice(s);
                if (settled) return false;
                EXPECT_EQ(substeps, 0);
                EXPECT_EQ(settled.error(), "the edit changes the settings the engine chooses");
                ++declined;
                return true;
            };
            if (declines()) continue;
            for (int i = 0; i < 10; ++i) ASSERT_TRUE(w.step().ok());
            w.writeBack(s);
            // Back where they stood, as an undo does: the slot table as it
            // was, then the components.
            s.registry.setSlots(before);
            for (const auto& [e, copy] : gone) copyComponents(aside, copy, s.registry, e);
            ASSERT_EQ(s.registry.entities(), order);
            // In half the cases a body goes in the same edit (an undo of
            // an edit that deleted some and added others).
            std::vector<Entity> goneNow;
            if (sleeping) {
                std::size_t asleep = 0;
                for (std::size_t b = 0; b < w.bodyCount(); ++b) asleep += w.asleep(b) ? 1 : 0;
                // (A static shape gone woke every island.)
                if (kind.rfind("static", 0) != 0) ASSERT_GE(asleep, 2u) << "the hinged pair at x = 6 sleeps";
                for (const Entity e : s.registry.entities())
                    if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == "far") goneNow.push_back(e);
                ASSERT_EQ(goneNow.size(), 1u);
                ASSERT_TRUE(s.registry.destroy(goneNow.front()));
            }
            const Result<void> back = w.changeEntities(s, {}, goneNow, handles);
            ASSERT_TRUE(back.ok()) << back.error();
            if (declines()) continue;
            expectStepsAsARebuild(w, s, 30);
            ++inPlace;
        }
    EXPECT_GT(inPlace, 4 * declined) << "most cases went in place";
}

// A static chain deleted in place leaves its segments' storage behind
// until they are half of what is held, then the rest are copied afresh:
// either way the steps that follow are those of a World built from the
// scene without it. Deleted here: a long chain beside a short one (its
// segments freed at once), then a ball (nothing freed).
TEST(World, ADeletedChainsSegmentsAreFreedAndTheRunIsARebuilds) {
    std::string points;
    for (int k = 0; k <= 60; ++k)
        points += std::string(k ? ", " : "") + "{\"x\": " + std::to_string(-15.0 + 0.5 * k) + ", \"y\": " +
                  std::to_string(0.02 * (k % 7)) + "}";
    Result<Scene> loaded = parseScene(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 2},
      "entities": [
        {"name": "long", "position": {"x": 0, "y": 0}, "static": true, "chain": {"points": [)" + points + R"(]}},
        {"name": "short", "position": {"x": 0, "y": -3}, "static": true,
         "chain": {"points": [{"x": -20, "y": 0}, {"x": 0, "y": -0.5}, {"x": 20, "y": 0}]}},
        {"name": "a", "position": {"x": -2, "y": 1}, "radius": 0.3},
        {"name": "b", "position": {"x": 3, "y": 1.5}, "box": {"width": 0.5, "height": 0.4}, "angle": 0.3}
      ]})", "chains");
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    Scene s = loaded.value();
    const auto named = [&s](const std::string& name) {
        for (const Entity e : s.registry.entities())
            if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == name) return e;
        return Entity{};
    };
    World w = buildOrDie(s);
    for (int i = 0; i < 30; ++i) ASSERT_TRUE(w.step().ok());
    const collision::CollisionSystem& contacts = *internals(w).collision;
    for (const char* gone : {"long", "a"}) {
        SCOPED_TRACE(gone);
        w.writeBack(s);
        const Entity e = named(gone);
        ASSERT_TRUE(s.registry.destroy(e));
        ASSERT_TRUE(w.changeEntities(s, {}, std::vector<Entity>{e}, {}).ok());
        ASSERT_TRUE(w.settleChoice(s).ok());
        EXPECT_EQ(contacts.outlinesHeld(), 2u);  // the short chain's two segments
        expectStepsAsARebuild(w, s, 40);
    }
}

// A body deleted in place beside a sleeping jointed chain: the chain
// stays asleep, and what the World reports of its joints after the next
// step (anchors, angles) is where the links rest, as a World built from
// the scene without the body reports it (whose joints never had an awake
// step to take their geometry from).
TEST(World, ASleepingChainsJointsReadAfterADeleteInPlaceAsARebuilds) {
    Result<Scene> loaded = parseScene(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 4, "sleep": true},
      "entities": [
        {"name": "ground", "position": {"x": 0, "y": -0.5}, "static": true, "box": {"width": 40, "height": 1},
         "friction": 0.8},
        {"name": "l0", "position": {"x": -1, "y": 0.1}, "box": {"width": 1, "height": 0.2}, "friction": 0.8},
        {"name": "l1", "position": {"x": 0, "y": 0.1}, "box": {"width": 1, "height": 0.2}, "friction": 0.8},
        {"name": "l2", "position": {"x": 1, "y": 0.1}, "box": {"width": 1, "height": 0.2}, "friction": 0.8},
        {"name": "h0", "joint": {"type": "hinge", "a": "l0", "b": "l1", "anchor": {"x": -0.5, "y": 0.1}}},
        {"name": "h1", "joint": {"type": "hinge", "a": "l1", "b": "l2", "anchor": {"x": 0.5, "y": 0.1}}},
        {"name": "ball", "position": {"x": 10, "y": 0.5}, "radius": 0.3, "friction": 0.8}
      ]})", "sleeping chain");
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    Scene s = loaded.value();
    World w = buildOrDie(s);
    for (int i = 0; i < 600 && w.sleepingBodyCount() < 4; ++i) ASSERT_TRUE(w.step().ok());
    ASSERT_EQ(w.sleepingBodyCount(), 4u);
    w.writeBack(s);
    Entity ball;
    for (const Entity e : s.registry.entities())
        if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == "ball") ball = e;
    ASSERT_TRUE(s.registry.destroy(ball));
    ASSERT_TRUE(w.changeEntities(s, {}, std::vector<Entity>{ball}, {}).ok());
    ASSERT_TRUE(w.settleChoice(s).ok());
    Scene rebuiltScene = s;
    rebuiltScene.solverState = w.solverState();
    World rebuilt = buildOrDie(rebuiltScene);
    ASSERT_TRUE(w.step().ok());
    ASSERT_TRUE(rebuilt.step().ok());
    EXPECT_EQ(w.sleepingBodyCount(), 3u);
    ASSERT_EQ(w.joints().size(), 2u);
    ASSERT_EQ(rebuilt.joints().size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
        // Where the hinges are: between the links, on the ground.
        EXPECT_NEAR(w.joints()[k].anchorA.x, k == 0 ? -0.5 : 0.5, 0.05) << k;
        EXPECT_NEAR(w.joints()[k].anchorA.y, 0.1, 0.02) << k;
        EXPECT_LT(w.joints()[k].separation, 1e-3) << k;
        EXPECT_EQ(w.joints()[k].angle, rebuilt.joints()[k].angle) << k;
        EXPECT_EQ(w.joints()[k].anchorA.x, rebuilt.joints()[k].anchorA.x) << k;
        EXPECT_EQ(w.joints()[k].anchorB.y, rebuilt.joints()[k].anchorB.y) << k;
    }
}

// An edit in place leaves the engine's choice of settings to one check
// before the next step (settleChoice): until then the World refuses to
// step, and the check says when the edit changed what a reload would run.
// A ball of the kinematic level made a thousand times heavier changes the
// choice (its mass ratio); 1.5 times, not: that World then steps as one
// built from the edited scene.
TEST(World, AnEditInPlaceStepsOnlyOnceTheEnginesChoiceIsSettled) {
    Result<Scene> loaded = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/kinematic.json");
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    for (const double factor : {1000.0, 1.5}) {
        SCOPED_TRACE(factor);
        Scene s = loaded.value();
        Entity ball;
        for (const Entity e : s.registry.entities())
            if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == "ball 3") ball = e;
        ASSERT_FALSE(ball.isNull());
        World w = buildOrDie(s);
        s.registry.tryGet<Mass>(ball)->value *= factor;
        ASSERT_TRUE(w.setMass(s, ball).ok());
        const Result<void> early = w.step();
        ASSERT_FALSE(early.ok());
        EXPECT_EQ(early.error(),
                  "an edit in place is not yet checked against the engine's choice of settings: call settleChoice");
        const Result<void> settled = w.settleChoice(s);
        if (factor > 100.0) {
            ASSERT_FALSE(settled.ok());
            EXPECT_EQ(settled.error(), "the edit changes the settings the engine chooses");
            ASSERT_TRUE(w.reload(s).ok());
        } else {
            ASSERT_TRUE(settled.ok()) << settled.error();
        }
        World fresh = buildOrDie(s);
        for (int i = 0; i < 30; ++i) {
            ASSERT_TRUE(w.step().ok());
            ASSERT_TRUE(fresh.step().ok());
        }
        ASSERT_EQ(w.bodyCount(), fresh.bodyCount());
        for (std::size_t b = 0; b < w.bodyCount(); ++b) {
            EXPECT_EQ(w.bodyPosition(b).x, fresh.bodyPosition(b).x) << b;
            EXPECT_EQ(w.bodyPosition(b).y, fresh.bodyPosition(b).y) << b;
        }
    }
}

TEST(World, StiffChainStaysBoundedUnderImplicitEuler) {
    // k = 1e5 N/m, m = 0.01 kg, dt = 1/60: h w = 53 per spring.
    Result<Scene> loaded = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/stiff_spring.json");
    ASSERT_TRUE(loaded.ok()) << loaded.error();
    const Scene& scene = loaded.value();
    ASSERT_EQ(scene.world.integrator, "implicit_euler");
    ASSERT_DOUBLE_EQ(scene.world.dt, 1.0 / 60.0);
    World w = buildOrDie(scene);
    const double e0 = w.energy().total();
    for (int i = 0; i < 600; ++i) {
        Result<void> r = w.step();
        ASSERT_TRUE(r.ok()) << r.error();
        for (std::size_t b = 0; b < w.bodyCount(); ++b)
            ASSERT_LT(length(w.bodyPosition(b)), 3.0 * 1.001) << "bead " << b << " at step " << i;
    }
    // Backward Euler never adds energy to a conservative system.
    EXPECT_LT(w.energy().total(), e0);
    // The chain hangs: links keep their rest length to within 1e-3 (g m / k
    // stretches them by micrometres).
    for (std::size_t b = 1; b < w.bodyCount(); ++b)
        EXPECT_NEAR(length(w.bodyPosition(b) - w.bodyPosition(b - 1)), 0.3, 1e-3);
}

struct CliRun {
    int exitCode = -1;
    std::string output;
};
CliRun runCli(const std::string& args) {
    CliRun r;
    const std::string command = std::string(STEPWISE_BINARY) + " " + args + " 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    if (!pipe) return r;
    std::array<char, 4096> buffer;
    std::size_t got;
    while ((got = fread(buffer.data(), 1, buffer.size(), pipe)) > 0) r.output.append(buffer.data(), got);
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

TEST(WorldCli, ExplicitBlowUpOnStiffChainExitsThree) {
    const std::string level = std::string(STEPWISE_SOURCE_DIR) + "/levels/stiff_spring.json";
    const CliRun bad = runCli("run " + level + " --steps 600 --integrator semi_implicit_euler");
    EXPECT_EQ(bad.exitCode, 3) << bad.output;
    EXPECT_NE(bad.output.find("diverged at step "), std::string::npos) << bad.output;
    EXPECT_NE(bad.output.find("(\"bead"), std::string::npos) << bad.output;
    EXPECT_NE(bad.output.find(" became "), std::string::npos) << bad.output;
    const CliRun good = runCli("run " + level + " --steps 600");
    EXPECT_EQ(good.exitCode, 0) << good.output;
    const CliRun hint = runCli("validate " + level.substr(0, level.size() - 5) + ".json");
    EXPECT_EQ(hint.exitCode, 0) << hint.output;
}

} // namespace

// A spring of k = 1e25 on 1 kg bodies makes M + h^2 K singular in
// doubles (the masses are lost to rounding). The factorisation fails, and
// a step that kept v1 = v0 for every body (a free falling one too) would
// report success. It is refused, like a non-finite value: the state stays
// at the start of the step and the message names the spring's bodies only.
TEST(World, AFailedImplicitSolveIsRefusedAndNamesOnlyItsBodies) {
    for (const char* k : {"1e25", "1e30"})
        for (const char* integrator : {"implicit_euler", "implicit_midpoint"}) {
            Result<Scene> scene = parseScene(std::string(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "integrator": ")") +
                                                 integrator + R"(", "substeps": 2},
              "entities": [{"name": "a", "position": {"x": 0, "y": 0}, "mass": 1},
                           {"name": "b", "position": {"x": 1.5, "y": 0}, "mass": 1},
                           {"name": "s", "spring": {"a": "a", "b": "b", "k": )" + std::string(k) + R"(, "rest_length": 1}},
                           {"name": "free", "position": {"x": 5, "y": 0}, "mass": 1, "velocity": {"x": 1, "y": 0}}]})",
                                             "t.json");
            ASSERT_TRUE(scene) << scene.error();
            World w = buildOrDie(*scene);
            const std::string what = std::string(k) + " " + integrator;
            ASSERT_EQ(w.stiffnessHints().size(), 1u) << what;
            EXPECT_GT(w.stiffnessHints()[0].hOmega, 1e5) << what;
            Result<void> stepped = w.step();
            ASSERT_FALSE(stepped) << what;
            EXPECT_EQ(stepped.error().rfind("step 1: " + std::string(integrator) + ": the linear ", 0), 0u)
                << stepped.error();
            EXPECT_NE(stepped.error().find("; bodies of the failing system: entity 0 (\"a\"), entity 1 (\"b\")."),
                      std::string::npos)
                << stepped.error();
            EXPECT_EQ(w.time(), 0.0) << what;
            EXPECT_EQ(w.bodyPosition(2).x, 5.0) << what;
            EXPECT_EQ(w.bodyVelocity(2).x, 1.0) << what;
            EXPECT_EQ(w.bodyPosition(1).x, 1.5) << what;
        }
}

// Stiff but within doubles (k = 1e12, h omega = 2.4e4): the solve is
// accepted and the spring relaxes to its rest length under implicit Euler
// while the free body falls as in free fall.
TEST(World, AStiffButSolvableImplicitSystemIsAccepted) {
    Result<Scene> scene = parseScene(R"({"world": {"gravity": {"x": 0, "y": -9.81}, "integrator": "implicit_euler"},
      "entities": [{"name": "a", "position": {"x": 0, "y": 0}, "mass": 1},
                   {"name": "b", "position": {"x": 1.5, "y": 0}, "mass": 1},
                   {"name": "s", "spring": {"a": "a", "b": "b", "k": 1e12, "rest_length": 1}},
                   {"name": "free", "position": {"x": 5, "y": 0}, "mass": 1}]})",
                                     "t.json");
    ASSERT_TRUE(scene) << scene.error();
    World w = buildOrDie(*scene);
    EXPECT_TRUE(w.stiffnessHints().empty());
    for (int i = 0; i < 60; ++i) ASSERT_TRUE(w.step());
    EXPECT_NEAR(w.bodyPosition(1).x - w.bodyPosition(0).x, 1.0, 1e-9);
    // Backward Euler under constant g: y_n = -g h^2 n (n + 1) / 2.
    const double h = 1.0 / 60.0;
    EXPECT_NEAR(w.bodyPosition(2).y, -9.81 * h * h * 60 * 61 / 2, 1e-9);
}

// A system switched off (SystemSwitches) runs as if the scene had none of
// its components, bit for bit, while the scene keeps them: checked against
// a copy with them removed, on a level that uses each system. Switching
// contacts off leaves every shape out, polygons included, and joints hold.
TEST(World, ASwitchedOffSystemRunsAsIfItsComponentsWereRemoved) {
    struct Case {
        const char* system;
        const char* level;
        std::function<void(Scene&)> remove;
    };
    const auto removeAll = [](auto tag) {
        return [](Scene& s) {
            using T = typename decltype(tag)::type;
            for (Entity e : s.registry.entities()) (void)s.registry.remove<T>(e);
        };
    };
    const auto removeShapes = [](Scene& s) {
        for (Entity e : s.registry.entities()) {
            (void)s.registry.remove<Radius>(e);
            (void)s.registry.remove<Box>(e);
            (void)s.registry.remove<Polygon>(e);
            (void)s.registry.remove<Plane>(e);
        }
    };
    const std::vector<Case> cases{
        {"gravity", "pile.json", [](Scene& s) { s.world.gravity = {0.0, 0.0}; }},
        {"drag", "pool_break.json", removeAll(std::type_identity<Drag>{})},
        {"springs", "spring_chain.json", removeAll(std::type_identity<Spring>{})},
        {"attractors", "orbit.json", removeAll(std::type_identity<Attractor>{})},
        {"boids", "flock.json", removeAll(std::type_identity<Boid>{})},
        {"collisions", "polygons.json", removeShapes},
        {"collisions", "bridge.json", removeShapes},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(std::string(c.system) + " in " + c.level);
        Result<Scene> loaded = loadSceneFile(std::string(STEPWISE_SOURCE_DIR) + "/levels/" + c.level);
        ASSERT_TRUE(loaded) << loaded.error();
        Scene removed = *loaded;
        c.remove(removed);
        SystemSwitches off;
        ASSERT_TRUE(off.disable(c.system));
        Result<World> switched = World::build(*loaded, off);
        Result<World> without = World::build(removed);
        ASSERT_TRUE(switched) << switched.error();
        ASSERT_TRUE(without) << without.error();
        EXPECT_EQ(switched->activeSystems(), without->activeSystems());
        EXPECT_EQ(switched->settings().substeps, without->settings().substeps);
        for (int i = 0; i < 60; ++i) {
            ASSERT_TRUE(switched->step());
            ASSERT_TRUE(without->step());
        }
        ASSERT_EQ(switched->bodyCount(), without->bodyCount());
        for (std::size_t b = 0; b < switched->bodyCount(); ++b) {
            EXPECT_EQ(switched->bodyPosition(b), without->bodyPosition(b)) << "body " << b;
            EXPECT_EQ(switched->bodyVelocity(b), without->bodyVelocity(b)) << "body " << b;
        }
    }
    SystemSwitches unknown;
    EXPECT_FALSE(unknown.disable("friction"));
}
