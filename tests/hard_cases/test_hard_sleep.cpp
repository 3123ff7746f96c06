// Sleep only at rest: a body whose forces do not balance (a gentle
// frictionless slope, a weak attractor) keeps moving at the analytic
// acceleration, bodies at rest still sleep, and a saved sleeping body moved or
// pushed by hand in the file wakes on load.

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"

#include "../test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

using namespace stepwise;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kG = 9.81;
constexpr double kDt = 1.0 / 60.0;

constexpr auto num = &test::exactNumber;

constexpr auto parse = &test::parseLevel;

constexpr auto build = &test::buildWorld;

Entity named(const Scene& s, const std::string& name) {
    for (const Entity e : s.registry.entities())
        if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == name) return e;
    throw std::runtime_error("no entity " + name);
}

/// A plane through the origin tilted by `degrees` (normal (-sin, cos)) and
/// one body `name` resting on it from rest, its centre `lift` above the
/// plane; `shape` is the body's shape members. Both have `friction`.
std::string onSlope(double degrees, double friction, const std::string& name, double lift, const std::string& shape) {
    const double t = degrees * kPi / 180.0;
    const double nx = -std::sin(t), ny = std::cos(t);
    return R"({"entities": [
        {"name": "ground", "plane": {"normal": {"x": )" + num(nx) + R"(, "y": )" + num(ny) + R"(}, "offset": 0},
         "friction": )" + num(friction) + R"(},
        {"name": ")" + name + R"(", "position": {"x": )" + num(lift * nx) + R"(, "y": )" + num(lift * ny) + R"(},
         )" + shape + R"(, "friction": )" + num(friction) + "}]}";
}

/// A 1 x 0.5 m box lying on the plane of onSlope().
std::string slope(double degrees, double friction) {
    return onSlope(degrees, friction, "box", 0.25,
                   R"("angle": )" + num(degrees * kPi / 180.0) + R"(, "box": {"width": 1, "height": 0.5})");
}

/// A disc of radius 0.5 m resting on the plane of onSlope().
std::string ballOnSlope(double degrees, double friction) {
    return onSlope(degrees, friction, "ball", 0.5, R"("radius": 0.5)");
}

} // namespace

TEST(HardSleep, FrictionlessSlopeOfAnyGentleAngleKeepsAcceleratingAtGSinTheta) {
    // Under 0.1 degrees the drift rule alone let the box sleep at its first
    // window (0.05 degrees: 1.1 mm in half a second). Under 0.006 degrees
    // (1 mm/s^2) the timers' velocity rule cannot tell the slide from a
    // settling pile's jitter either: there the forces' balance keeps it
    // awake, down to a millionth of a degree.
    for (const double degrees : {1e-6, 1e-5, 1e-4, 1e-3, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0, 5.0, 10.0}) {
        const Scene scene = parse(slope(degrees, 0.0));
        World w = build(scene);
        const int steps = 180;  // 3 s
        int asleepSteps = 0;
        for (int i = 0; i < steps; ++i) {
            ASSERT_TRUE(w.step());
            asleepSteps += w.sleepingBodyCount() > 0 ? 1 : 0;
        }
        EXPECT_EQ(asleepSteps, 0) << degrees << " deg: a body that speeds up never sleeps";
        Scene now = scene;
        w.writeBack(now);
        const Entity box = named(now, "box");
        const double t = degrees * kPi / 180.0;
        const Vec2 downhill{-std::cos(t), -std::sin(t)};
        const double a = kG * std::sin(t), T = steps * kDt;
        // Semi-implicit Euler gains a dt each step exactly: v = a T; its
        // position is a dt^2 N (N + 1) / 2, a T^2 / 2 (1 + 1/N).
        const double v = dot(now.registry.tryGet<Velocity>(box)->value, downhill);
        EXPECT_NEAR(v, a * T, 0.005 * a * T) << degrees << " deg";
        const Vec2 start{-0.25 * std::sin(t), 0.25 * std::cos(t)};
        const double travelled = dot(now.registry.tryGet<Position>(box)->value - start, downhill);
        EXPECT_NEAR(travelled, 0.5 * a * T * T * (1.0 + 1.0 / steps), 0.01 * 0.5 * a * T * T) << degrees << " deg";
    }
}

namespace {

/// How far body `name` of `scene` has moved down the slope of `degrees`
/// from where the scene places it, m, and its speed that way, m/s, after
/// `steps`; `asleepSteps` counts the steps any body slept.
struct Slide {
    double travelled = 0.0, speed = 0.0;
    int asleepSteps = 0;
};
Slide slideDown(const Scene& scene, const std::string& name, double degrees, int steps) {
    World w = build(scene);
    Slide out;
    for (int i = 0; i < steps; ++i) {
        if (!w.step()) throw std::runtime_error("step failed");
        out.asleepSteps += w.sleepingBodyCount() > 0 ? 1 : 0;
    }
    Scene now = scene;
    w.writeBack(now);
    const double t = degrees * kPi / 180.0;
    const Vec2 downhill{-std::cos(t), -std::sin(t)};
    const Entity body = named(now, name);
    out.speed = dot(now.registry.tryGet<Velocity>(body)->value, downhill);
    out.travelled = dot(now.registry.tryGet<Position>(body)->value - scene.registry.tryGet<Position>(named(scene, name))->value,
                        downhill);
    return out;
}

} // namespace

TEST(HardSleep, ABallOnAGentleSlopeWithFrictionRollsAtTwoThirdsGSinTheta) {
    // A rolling disc accelerates at g sin t / (1 + I / (m r^2)) = 2/3 g sin t
    // however small t is: with friction the slide test holds it, but the
    // pull's line misses its one contact point, so it turns. Without the
    // torque test it slept at its first window below 0.006 degrees (a
    // hundredth of the distance at 0.001 degrees).
    for (const double degrees : {1e-6, 1e-4, 1e-3, 0.01, 0.1, 1.0, 5.0, 10.0}) {
        const int steps = 180;
        const Slide s = slideDown(parse(ballOnSlope(degrees, 0.5)), "ball", degrees, steps);
        const double a = 2.0 / 3.0 * kG * std::sin(degrees * kPi / 180.0), T = steps * kDt;
        EXPECT_EQ(s.asleepSteps, 0) << degrees << " deg";
        EXPECT_NEAR(s.speed, a * T, 0.01 * a * T) << degrees << " deg";
        EXPECT_NEAR(s.travelled, 0.5 * a * T * T * (1.0 + 1.0 / steps), 0.01 * 0.5 * a * T * T) << degrees << " deg";
    }
}

TEST(HardSleep, AStackOnAFrictionlessSlopeSlidesTogetherAtGSinTheta) {
    // Two boxes held together by friction (0.5) on a frictionless plane: the
    // island as a whole cannot rest, though each box's own contacts with the
    // other could hold it.
    for (const double degrees : {1e-5, 1e-3, 0.01, 0.1, 1.0, 5.0}) {
        const double t = degrees * kPi / 180.0;
        const double nx = -std::sin(t), ny = std::cos(t);
        const auto box = [&](const char* name, double height) {
            return R"({"name": ")" + std::string(name) + R"(", "position": {"x": )" + num(height * nx) + R"(, "y": )" +
                   num(height * ny) + R"(}, "angle": )" + num(t) + R"(, "box": {"width": 1, "height": 0.5}, "friction": 0.5})";
        };
        const Scene scene = parse(R"({"entities": [
            {"name": "ground", "plane": {"normal": {"x": )" + num(nx) + R"(, "y": )" + num(ny) + R"(}, "offset": 0}, "friction": 0},
            )" + box("lower", 0.25) + ",\n" + box("upper", 0.75) + "]}");
        const int steps = 180;
        const double a = kG * std::sin(t), T = steps * kDt;
        for (const char* name : {"lower", "upper"}) {
            const Slide s = slideDown(scene, name, degrees, steps);
            EXPECT_EQ(s.asleepSteps, 0) << degrees << " deg, " << name;
            EXPECT_NEAR(s.speed, a * T, 0.01 * a * T) << degrees << " deg, " << name;
        }
    }
}

TEST(HardSleep, BodiesAtRestStillSleepOnFlatGroundAndOnSlopesFrictionHolds) {
    // friction 0.5 holds up to atan(0.5) = 26.6 degrees: the forces balance.
    for (const double degrees : {0.0, 1e-6, 1e-3, 1.0, 5.0, 10.0, 20.0}) {
        World w = build(parse(slope(degrees, 0.5)));
        int fellAsleepAt = -1;
        for (int i = 0; i < 120 && fellAsleepAt < 0; ++i) {
            ASSERT_TRUE(w.step());
            if (w.sleepingBodyCount() == 1) fellAsleepAt = i + 1;
        }
        // Measured: asleep after sleep_time (0.5 s = 30 steps) and a step or two.
        EXPECT_GE(fellAsleepAt, 30) << degrees << " deg";
        EXPECT_LE(fellAsleepAt, 40) << degrees << " deg";
    }
}

TEST(HardSleep, BodyUnderAWeakAttractorNeverSleepsAndFallsAtTheFieldsAcceleration) {
    // A static attractor 100 m away pulling with a: a body from rest moves
    // a T^2 / 2 in T (the field changes by under 1% over the way).
    for (const double a : {1e-4, 1e-3, 5e-3, 2e-2, 1e-1}) {
        const double r = 100.0, mass = a * r * r;
        const Scene scene = parse(R"({"world": {"gravity": {"x": 0, "y": 0}, "theta": 0}, "entities": [
            {"name": "sun", "position": {"x": 0, "y": 0}, "static": true, "mass": )" + num(mass) + R"(, "attractor": {}},
            {"name": "probe", "position": {"x": )" + num(r) + R"(, "y": 0}, "radius": 0.5}]})");
        World w = build(scene);
        const int steps = 180;
        int asleepSteps = 0;
        for (int i = 0; i < steps; ++i) {
            ASSERT_TRUE(w.step());
            asleepSteps += w.sleepingBodyCount() > 0 ? 1 : 0;
        }
        EXPECT_EQ(asleepSteps, 0) << "a = " << a;
        Scene now = scene;
        w.writeBack(now);
        const double moved = r - now.registry.tryGet<Position>(named(now, "probe"))->value.x;
        const double T = steps * kDt;
        EXPECT_NEAR(moved, 0.5 * a * T * T * (1.0 + 1.0 / steps), 0.02 * 0.5 * a * T * T) << "a = " << a;
    }
}

TEST(HardSleep, ASleepingBodyMovedOrPushedInTheFileWakesOnLoad) {
    const Scene level = parse(R"({"entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}},
        {"name": "crate_a", "position": {"x": -3, "y": 0.5}, "box": {"width": 1, "height": 1}, "friction": 0.5},
        {"name": "crate_b", "position": {"x": 0, "y": 0.5}, "box": {"width": 1, "height": 1}, "friction": 0.5},
        {"name": "ball", "position": {"x": 6, "y": 0.5}, "radius": 0.5, "friction": 0.5}]})");
    World first = build(level);
    for (int i = 0; i < 600 && first.sleepingBodyCount() < 3; ++i) ASSERT_TRUE(first.step());
    ASSERT_EQ(first.sleepingBodyCount(), 3u);
    Scene saved = level;
    first.writeBack(saved);
    saved.solverState = first.solverState();

    struct Edit {
        const char* what;
        bool moveBall, pushBall, pushCrate;
    };
    for (const Edit edit : {Edit{"untouched", false, false, false}, Edit{"ball moved", true, false, false},
                            Edit{"ball pushed", false, true, false}, Edit{"ball moved and pushed, crate pushed", true, true, true},
                            Edit{"crate pushed", false, false, true}}) {
        Scene file = saved;
        Registry& reg = file.registry;
        const Entity ball = named(file, "ball"), crateA = named(file, "crate_a"), crateB = named(file, "crate_b");
        if (edit.moveBall) reg.tryGet<Position>(ball)->value.y = 5.0;
        if (edit.pushBall) reg.emplace<Velocity>(ball, Velocity{{0.0, 3.0}});
        if (edit.pushCrate) reg.emplace<Velocity>(crateB, Velocity{{4.0, 0.0}});
        // Through the file's text, as a hand edit would go.
        const Scene loaded = parse(sceneToJsonText(file));
        World w = build(loaded);
        const bool ballEdited = edit.moveBall || edit.pushBall;
        EXPECT_EQ(w.asleep(2), !ballEdited) << edit.what;
        EXPECT_EQ(w.asleep(1), !edit.pushCrate) << edit.what;
        EXPECT_TRUE(w.asleep(0)) << edit.what << ": an island nobody edited stays asleep";
        Scene after = loaded;
        double highest = loaded.registry.tryGet<Position>(ball)->value.y, halfSecond = 0.0;
        for (int i = 0; i < 60; ++i) {
            ASSERT_TRUE(w.step());
            w.writeBack(after);
            highest = std::max(highest, after.registry.tryGet<Position>(ball)->value.y);
            if (i == 29) halfSecond = after.registry.tryGet<Position>(ball)->value.y;
        }
        const auto pos = [&](Entity e) { return after.registry.tryGet<Position>(e)->value; };
        const auto was = [&](Entity e) { return loaded.registry.tryGet<Position>(e)->value; };
        // Untouched islands: exactly where they were.
        EXPECT_EQ(pos(crateA).x, was(crateA).x) << edit.what;
        EXPECT_EQ(pos(crateA).y, was(crateA).y) << edit.what;
        if (edit.moveBall) {
            // In free flight for half a second: semi-implicit Euler's
            // y = y0 + v0 T - g dt^2 N (N + 1) / 2.
            const double v0 = edit.pushBall ? 3.0 : 0.0;
            const double expected = 5.0 + v0 * 0.5 - kG * kDt * kDt * 30.0 * 31.0 / 2.0;
            EXPECT_NEAR(halfSecond, expected, 1e-9) << edit.what;
        } else if (edit.pushBall) {
            // Thrown up at 3 m/s: it rises 3^2 / (2 g) = 0.46 m.
            EXPECT_NEAR(highest - was(ball).y, 9.0 / (2.0 * kG), 0.03) << edit.what;
        } else {
            EXPECT_EQ(pos(ball).y, was(ball).y) << edit.what;
        }
        if (edit.pushCrate) EXPECT_GT(pos(crateB).x - was(crateB).x, 0.5) << edit.what;
        else EXPECT_EQ(pos(crateB).x, was(crateB).x) << edit.what;
    }
}

