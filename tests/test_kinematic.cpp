// Kinematic bodies: moved only by their own velocity and spin, never by
// forces or contacts, while they push and carry the dynamic bodies they meet.
#include "test_support.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

using namespace stepwise;
using namespace stepwise::test;

namespace {

constexpr double kG = 9.81;

Entity named(const Registry& reg, std::string_view name) {
    for (const Entity e : reg.entities())
        if (const Name* n = reg.tryGet<Name>(e); n && n->value == name) return e;
    throw std::runtime_error("no entity named " + std::string(name));
}

std::string vec(Vec2 v) { return R"({"x": )" + exactNumber(v.x) + R"(, "y": )" + exactNumber(v.y) + "}"; }

/// Position and angle of every named body after `steps` steps.
struct Pose {
    Vec2 p;
    double angle = 0.0;
};
std::map<std::string, Pose> posesAfter(World& world, Scene& scene, int steps) {
    for (int i = 0; i < steps; ++i) {
        Result<void> stepped = world.step();
        if (!stepped) throw std::runtime_error(stepped.error());
    }
    world.writeBack(scene);
    std::map<std::string, Pose> out;
    for (const Entity e : scene.registry.entities()) {
        const Name* name = scene.registry.tryGet<Name>(e);
        const Position* p = scene.registry.tryGet<Position>(e);
        if (!name || !p) continue;
        const Angle* a = scene.registry.tryGet<Angle>(e);
        out[name->value] = {p->value, a ? a->value : 0.0};
    }
    return out;
}

/// A 4 m x 0.4 m kinematic platform at the origin moving at `velocity`,
/// carrying a 0.5 m crate (friction 0.6 on both) that starts at rest or
/// moving with it, under gravity.
std::string platformLevel(Vec2 velocity, bool crateMovesWithIt, const std::string& settings) {
    return R"({"world": {"gravity": {"x": 0, "y": -9.81})" + settings + R"(},
      "entities": [
        {"name": "platform", "position": {"x": 0, "y": 0}, "kinematic": true, "velocity": )" + vec(velocity) +
           R"(, "box": {"width": 4, "height": 0.4}, "friction": 0.6},
        {"name": "crate", "position": {"x": -1, "y": 0.45}, "mass": 2, "box": {"width": 0.5, "height": 0.5},
         "friction": 0.6, "velocity": )" + vec(crateMovesWithIt ? velocity : Vec2{}) + "}]}";
}

} // namespace

TEST(Kinematic, AMovingPlatformCarriesACrateInPlaceAtEverySpeedAndSubstepCount) {
    // The crate starts moving with the platform: static friction holds it
    // where it was on the platform, within a millimetre, across speeds,
    // directions and the substep settings a designer may give.
    for (const Vec2 velocity : {Vec2{0.5, 0.0}, Vec2{2.0, 0.0}, Vec2{8.0, 0.0}, Vec2{30.0, 0.0}, Vec2{-5.0, 0.0},
                                Vec2{0.0, 1.0}, Vec2{0.0, 4.0}, Vec2{0.0, -3.0}, Vec2{3.0, 2.0}})
        for (const std::string settings : {std::string(), std::string(R"(, "substeps": 1)"),
                                           std::string(R"(, "substeps": 8, "solver_iterations": 8)")}) {
            Scene scene = parseLevel(platformLevel(velocity, true, settings));
            World world = buildWorld(scene);
            const auto poses = posesAfter(world, scene, 180);
            const Vec2 platform = poses.at("platform").p, crate = poses.at("crate").p;
            const std::string where = "v {" + exactNumber(velocity.x) + ", " + exactNumber(velocity.y) + "}" + settings;
            // The platform went exactly where its velocity took it.
            EXPECT_NEAR(platform.x, 3.0 * velocity.x, 1e-9 * (1.0 + std::abs(velocity.x))) << where;
            EXPECT_NEAR(platform.y, 3.0 * velocity.y, 1e-9 * (1.0 + std::abs(velocity.y))) << where;
            EXPECT_EQ(poses.at("platform").angle, 0.0) << where;
            // The crate sits where it started on it: 1 m left of centre, on top.
            EXPECT_NEAR(crate.x - platform.x, -1.0, 1e-3) << where;
            EXPECT_NEAR(crate.y - platform.y, 0.45, 6e-3) << where;
            EXPECT_NEAR(poses.at("crate").angle, 0.0, 1e-3) << where;
        }
}

TEST(Kinematic, ACrateSetDownOnAMovingPlatformSlipsByTheCoulombDistance) {
    // From rest, kinetic friction mu g accelerates the crate until it moves
    // with the platform: it slips v^2 / (2 mu g) backwards relative to it
    // (mu = 0.6 on both sides, so the pair's sqrt(0.6 * 0.6) = 0.6).
    for (const double speed : {0.5, 1.0, 2.0, 4.0}) {
        Scene scene = parseLevel(platformLevel({speed, 0.0}, false, R"(, "substeps": 4)"));
        scene.registry.tryGet<Box>(named(scene.registry, "platform"))->width = 40.0;
        World world = buildWorld(scene);
        const int steps = int(60.0 * (speed / (0.6 * kG) + 1.0));
        const auto poses = posesAfter(world, scene, steps);
        const double slip = -1.0 - (poses.at("crate").p.x - poses.at("platform").p.x);
        const double expected = speed * speed / (2.0 * 0.6 * kG);
        EXPECT_NEAR(slip, expected, 0.1 * expected + 0.01) << "speed " << speed;
    }
}

TEST(Kinematic, NoForceOrContactMovesItUnderEveryIntegrator) {
    // Gravity, a spring, drag, an attractor and crates dropped on it: a
    // resting kinematic body stays bit for bit where it is, and a moving
    // one follows its velocity and spin, under every integrator.
    for (const std::string_view integrator : integratorNames())
        for (const bool moving : {false, true}) {
            const Vec2 v = moving ? Vec2{0.75, -0.25} : Vec2{};
            const double w = moving ? 0.5 : 0.0;
            const std::string text = R"({"world": {"gravity": {"x": 0, "y": -9.81}, "integrator": ")" +
                                     std::string(integrator) + R"("},
              "entities": [
                {"name": "slab", "position": {"x": 0.125, "y": 0.5}, "kinematic": true, "velocity": )" + vec(v) +
                                     R"(, "angular_velocity": )" + exactNumber(w) + R"(, "box": {"width": 3, "height": 0.5},
                 "drag": 5, "mass": 3},
                {"name": "crate", "position": {"x": 0, "y": 2}, "mass": 50, "box": {"width": 1, "height": 1}},
                {"name": "sun", "position": {"x": 5, "y": 5}, "mass": 1000, "attractor": {"softening": 0.1}},
                {"name": "rope", "spring": {"a": "slab", "b": "crate", "k": 500, "damping": 2}}]})";
            Scene scene = parseLevel(text);
            World world = buildWorld(scene);
            const auto poses = posesAfter(world, scene, 90);
            const Pose slab = poses.at("slab");
            const std::string where = std::string(integrator) + (moving ? " moving" : " resting");
            if (!moving) {
                EXPECT_EQ(slab.p, (Vec2{0.125, 0.5})) << where;
                EXPECT_EQ(slab.angle, 0.0) << where;
            } else {
                EXPECT_NEAR(slab.p.x, 0.125 + 1.5 * v.x, 1e-9) << where;
                EXPECT_NEAR(slab.p.y, 0.5 + 1.5 * v.y, 1e-9) << where;
                EXPECT_NEAR(slab.angle, 1.5 * w, 1e-9) << where;
            }
            // Its velocity in the saved level is still its own.
            const Velocity* saved = scene.registry.tryGet<Velocity>(named(scene.registry, "slab"));
            EXPECT_EQ(saved->value, v) << where;
        }
}

TEST(Kinematic, ASpinningPaddlePushesEveryBallItReachesAndNoneCrossesIt) {
    // A 3 m paddle spins about its centre among twelve balls at rest, no
    // gravity. At every spin up to 4 rad/s (6 m/s at the tips) it turns at
    // exactly that rate, every ball within its reach is pushed away, and
    // none sinks into it by more than the bound below.
    for (const double spin : {0.5, 1.0, 2.0, 4.0}) {
        std::string balls;
        for (int i = 0; i < 12; ++i) {
            // Inner balls at 30, 90, ... degrees: clear of the paddle, which lies along 0.
            const double a = i * 3.14159265358979 / 6.0, r = i % 2 ? 0.9 : 2.2;
            balls += R"(, {"name": "ball )" + std::to_string(i) + R"(", "position": )" +
                     vec({r * std::cos(a), r * std::sin(a)}) + R"(, "radius": 0.15, "mass": 0.5})";
        }
        Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": 0}},
          "entities": [{"name": "paddle", "position": {"x": 0, "y": 0}, "kinematic": true, "angular_velocity": )" +
                                 exactNumber(spin) + R"(, "box": {"width": 3, "height": 0.2}})" + balls + "]}");
        World world = buildWorld(scene);
        const double seconds = 4.0 * 3.14159265358979 / spin;  // two turns
        const int steps = int(std::ceil(seconds * 60.0));
        double closest = 1e9;
        for (int s = 0; s < steps; ++s) {
            ASSERT_TRUE(world.step()) << "spin " << spin;
            world.writeBack(scene);
            const double angle = scene.registry.tryGet<Angle>(named(scene.registry, "paddle"))->value;
            const Vec2 axis{std::cos(angle), std::sin(angle)};
            for (int i = 0; i < 12; ++i) {
                const Vec2 p = scene.registry.tryGet<Position>(named(scene.registry, "ball " + std::to_string(i)))->value;
                const double along = dot(p, axis), across = std::abs(cross(axis, p));
                if (std::abs(along) < 1.5) closest = std::min(closest, across);
            }
        }
        world.writeBack(scene);
        EXPECT_NEAR(scene.registry.tryGet<Angle>(named(scene.registry, "paddle"))->value, steps * spin / 60.0,
                    1e-9 * steps * spin)
            << "spin " << spin;
        // A ball centre never came closer to the paddle's axis than its
        // radius plus the paddle's half-thickness, less what the turn within
        // one step costs: contacts take their normal once a step, so a face
        // turning w dt in it lets a ball sink by about 2.5 mm per rad/s here
        // (docs/collisions.md, "Kinematic bodies").
        EXPECT_GT(closest, 0.15 + 0.1 - (0.002 + 0.0025 * spin)) << "spin " << spin;
        // The inner ring (0.9 m, inside the 1.5 m reach) was all pushed out.
        for (int i = 1; i < 12; i += 2) {
            const Vec2 p = scene.registry.tryGet<Position>(named(scene.registry, "ball " + std::to_string(i)))->value;
            EXPECT_GT(length(p), 1.0) << "spin " << spin << " ball " << i;
        }
    }
}

TEST(Kinematic, SaveLoadAndContinueEqualsRunningOn) {
    const std::string text = platformLevel({1.5, 0.5}, false, "");
    Scene scene = parseLevel(text);
    World straight = buildWorld(scene);
    for (int i = 0; i < 60; ++i) ASSERT_TRUE(straight.step());
    const std::string expected = savedRunText(straight, scene);

    Scene first = parseLevel(text);
    World world = buildWorld(first);
    for (int i = 0; i < 25; ++i) ASSERT_TRUE(world.step());
    Scene resumed = parseLevel(savedRunText(world, first));
    World again = buildWorld(resumed);
    for (int i = 0; i < 35; ++i) ASSERT_TRUE(again.step());
    EXPECT_EQ(savedRunText(again, resumed), expected);
}

TEST(Kinematic, ACrateOnAStillPlatformSleepsAndOnAMovingOneNever) {
    for (const double speed : {0.0, 0.05, 1.0}) {
        Scene scene = parseLevel(platformLevel({speed, 0.0}, true, ""));
        World world = buildWorld(scene);
        bool crateSlept = false;
        for (int i = 0; i < 300; ++i) {
            ASSERT_TRUE(world.step());
            crateSlept = crateSlept || world.asleep(1);
        }
        EXPECT_EQ(crateSlept, speed == 0.0) << "speed " << speed;
    }
}

TEST(Kinematic, APlatformMovingIntoASleepingCrateWakesAndPushesIt) {
    // The crate sleeps on a floor; a kinematic wall sweeps in from the left
    // at 1 m/s and pushes it along: the crate's left face stays on the
    // wall's right face.
    Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}},
        {"name": "crate", "position": {"x": 0, "y": 0.25}, "box": {"width": 0.5, "height": 0.5}},
        {"name": "pusher", "position": {"x": -5, "y": 0.6}, "kinematic": true, "box": {"width": 0.2, "height": 1}}]})");
    World world = buildWorld(scene);
    for (int i = 0; i < 120; ++i) ASSERT_TRUE(world.step());
    ASSERT_TRUE(world.asleep(0));
    // Set it moving, as an editor edit would.
    world.writeBack(scene);
    scene.registry.emplace(named(scene.registry, "pusher"), Velocity{{1.0, 0.0}});
    ASSERT_TRUE(world.reload(scene));
    const auto poses = posesAfter(world, scene, 360);
    const double pusherRight = poses.at("pusher").p.x + 0.1, crateLeft = poses.at("crate").p.x - 0.25;
    EXPECT_NEAR(poses.at("pusher").p.x, 1.0, 1e-9);
    EXPECT_NEAR(crateLeft, pusherRight, 0.01);
    EXPECT_FALSE(world.asleep(0));
}

TEST(Kinematic, ItsMotionIsNotInTheEnergyBalance) {
    // A level of one moving kinematic body has no energy to report.
    Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": -9.81}},
      "entities": [{"name": "lift", "position": {"x": 0, "y": 0}, "kinematic": true, "velocity": {"x": 0, "y": 3},
                    "angular_velocity": 2, "box": {"width": 2, "height": 0.2}, "mass": 10}]})");
    World world = buildWorld(scene);
    for (int i = 0; i < 30; ++i) ASSERT_TRUE(world.step());
    const EnergyReport e = world.energy();
    EXPECT_EQ(e.kinetic, 0.0);
    EXPECT_EQ(e.gravity, 0.0);
}

TEST(Kinematic, StaticAndKinematicTogetherAreRefused) {
    Result<Scene> s = parseScene(R"({"entities": [{"name": "lift", "position": {"x": 0, "y": 0}, "static": true,
        "kinematic": true, "radius": 1}]})",
                                 "t.json");
    ASSERT_FALSE(s);
    EXPECT_EQ(s.error(), "t.json: error: /entities/0/kinematic: a body is static or kinematic, not both");
}

TEST(Kinematic, AJointHangsABodyFromAMovingKinematicBody) {
    // A trolley moving at constant speed carries a pendulum on a hinge. In
    // the trolley's frame (inertial: it does not accelerate) the bob hangs
    // straight down once it has settled, so it travels with the trolley,
    // and the hinge holds together. Swept over speed and hinge length.
    for (const double speed : {0.5, 2.0, 8.0})
        for (const double arm : {0.5, 2.0}) {
            Scene scene = parseLevel(R"({"world": {"gravity": {"x": 0, "y": -9.81}},
              "entities": [
                {"name": "trolley", "position": {"x": 0, "y": 0}, "kinematic": true, "velocity": {"x": )" +
                                     exactNumber(speed) + R"(, "y": 0}, "box": {"width": 1, "height": 0.3}},
                {"name": "bob", "position": {"x": 0, "y": )" + exactNumber(-arm) + R"(}, "velocity": {"x": )" +
                                     exactNumber(speed) + R"(, "y": 0}, "radius": 0.1, "mass": 2},
                {"name": "pin", "joint": {"type": "hinge", "a": "trolley", "b": "bob", "anchor": {"x": 0, "y": 0}}}]})");
            World world = buildWorld(scene);
            const auto poses = posesAfter(world, scene, 240);
            const Vec2 trolley = poses.at("trolley").p, bob = poses.at("bob").p;
            const std::string where = "speed " + exactNumber(speed) + " arm " + exactNumber(arm);
            EXPECT_NEAR(trolley.x, 4.0 * speed, 1e-9 * speed) << where;
            EXPECT_NEAR(bob.x, trolley.x, 1e-3) << where;
            EXPECT_NEAR(bob.y, -arm, 1e-3) << where;
        }
}
