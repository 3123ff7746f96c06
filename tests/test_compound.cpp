// Compound bodies (the `shapes` component): the format's checks with their
// exact messages and a byte-stable round trip; mass, centre and inertia
// against the parallel-axis sums (with per-shape density and with `mass`
// scaling), seen through the World's energy; an L of two boxes resting at
// its analytic pose when its centre is over its foot and tipping when it is
// not; a dumbbell rolling as one rigid body; no contacts between shapes of
// one body; per-shape friction, sensor and filter; a kinematic drum turning
// its load; exact save/resume; every integrator.

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

using namespace stepwise;
using test::exactNumber;
using test::loadError;
using test::vectorJson;
using test::named;
using test::Sim;

namespace {

constexpr double kPi = std::numbers::pi;


std::string level(const std::string& entities, const std::string& world = "") {
    return "{\"world\": {\"gravity\": {\"x\": 0, \"y\": -9.81}" + world + "}, \"entities\": [" + entities + "]}";
}


std::string boxItem(double cx, double cy, double w, double h, const std::string& extra = "", double angle = 0.0) {
    return "{\"box\": {\"center\": " + vectorJson(cx, cy) + ", \"width\": " + exactNumber(w) + ", \"height\": " + exactNumber(h) +
           ", \"angle\": " + exactNumber(angle) + "}" + extra + "}";
}
std::string circleItem(double cx, double cy, double r, const std::string& extra = "") {
    return "{\"circle\": {\"center\": " + vectorJson(cx, cy) + ", \"radius\": " + exactNumber(r) + "}" + extra + "}";
}
std::string capsuleItem(Vec2 a, Vec2 b, double r, const std::string& extra = "") {
    return "{\"capsule\": {\"a\": " + vectorJson(a.x, a.y) + ", \"b\": " + vectorJson(b.x, b.y) + ", \"radius\": " + exactNumber(r) + "}" +
           extra + "}";
}

const std::string kFloor = "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}";

const int kSubsteps[] = {0, 1, 2, 4, 8};  // 0: the engine's choice
std::string substepsWorld(int s) { return s == 0 ? std::string() : ", \"substeps\": " + std::to_string(s); }

} // namespace

// ------------------------------------------------------------ format

TEST(CompoundFormat, ShapesWithASingleShapeAreRefusedNamingTheEntity) {
    for (const char* single : {"\"radius\": 0.5", "\"box\": {\"width\": 1, \"height\": 1}",
                               "\"capsule\": {\"a\": {\"x\": 0, \"y\": 0}, \"b\": {\"x\": 1, \"y\": 0}, \"radius\": 0.1}"}) {
        EXPECT_EQ(loadError(level("{\"name\": \"ell\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [" +
                                  circleItem(0, 0, 1) + "], " + single + "}")),
                  "t.json: error: /entities/0: entity 0 (\"ell\") has both shapes and a single shape (radius, box, "
                  "polygon, capsule, chain or plane); a compound body lists every shape in shapes")
            << single;
    }
}

TEST(CompoundFormat, BadItemsAreRefusedWithTheirPlace) {
    EXPECT_EQ(loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": []}")),
              "t.json: error: /entities/0/shapes: entity 0 (\"c\"): expected at least one shape, got none");
    std::string many;
    for (int i = 0; i < 257; ++i) many += (i ? ", " : "") + circleItem(i, 0, 0.4);
    EXPECT_EQ(loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [" + many + "]}")),
              "t.json: error: /entities/0/shapes: entity 0 (\"c\"): expected at most 256 shapes, got 257");
    EXPECT_EQ(loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [" + circleItem(0, 0, 1) +
                              ", " + capsuleItem({1, 1}, {1, 1}, 0.2) + "]}")),
              "t.json: error: /entities/0/shapes/1/capsule/b: entity 0 (\"c\"): a and b are the same point {\"x\": 1, "
              "\"y\": 1}; a capsule needs a segment of non-zero length (a circle is the shape without one)");
    EXPECT_EQ(loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [{\"circle\": "
                              "{\"radius\": 1}, \"box\": {\"width\": 1, \"height\": 1}}]}")),
              "t.json: error: /entities/0/shapes/0: expected exactly one of circle, box, polygon, capsule in a "
              "compound shape, got 2");
    EXPECT_EQ(loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [{\"circle\": "
                              "{\"radius\": 1}, \"densty\": 2}]}")),
              "t.json: error: /entities/0/shapes/0/densty: unknown key \"densty\" in a compound shape; did you mean "
              "\"density\"? Known keys: circle, box, polygon, capsule, density, friction, restitution, sensor, filter");
    const std::string polygon = "{\"polygon\": {\"vertices\": [{\"x\": 0, \"y\": 0}, {\"x\": 0, \"y\": 1}, {\"x\": 1, "
                                "\"y\": 0}]}}";
    const std::string refused = loadError(level("{\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [" +
                                                polygon + "]}"));
    EXPECT_EQ(refused.rfind("t.json: error: /entities/0/shapes/0/polygon/vertices", 0), 0u) << refused;
    EXPECT_NE(refused.find("entity 0 (\"c\")"), std::string::npos) << refused;
}

TEST(CompoundFormat, TheWorldRefusesBadShapesMadeInCode) {
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {"c"});
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    Shapes shapes;
    CompoundShape capsule;
    capsule.kind = CompoundShape::Kind::Capsule;
    capsule.a = capsule.b = {1.0, 1.0};
    shapes.items = {capsule};
    s.registry.emplace<Shapes>(e, shapes);
    Result<World> w = World::build(s);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error(), "entity 0 (\"c\"): shapes/0/capsule/b: a and b are the same point {\"x\": 1, \"y\": 1}; a "
                         "capsule needs a segment of non-zero length (a circle is the shape without one)");
    s.registry.tryGet<Shapes>(e)->items.clear();
    Result<World> empty = World::build(s);
    ASSERT_FALSE(empty);
    EXPECT_EQ(empty.error(), "entity 0 (\"c\"): shapes: expected 1 to 256 shapes, got 0");
}

TEST(CompoundFormat, RoundTripsByteForByte) {
    const std::string text = level(
        "{\"name\": \"c\", \"position\": {\"x\": 0.1, \"y\": 0.2}, \"angle\": 0.3, \"shapes\": [" +
        circleItem(0.5, 0.25, 0.3, ", \"density\": 2.5, \"friction\": 0.7") + ", " +
        boxItem(-0.5, 0, 1, 0.5, ", \"restitution\": 0.5, \"sensor\": true", 0.2) + ", " +
        capsuleItem({0, 1}, {1, 1}, 0.1, ", \"filter\": {\"category\": 2, \"mask\": 4294967293, \"group\": -3}") +
        ", {\"polygon\": {\"vertices\": [{\"x\": 0, \"y\": -1}, {\"x\": 1, \"y\": -1}, {\"x\": 0, \"y\": -0.5}]}}]}");
    Result<Scene> a = parseScene(text, "t.json");
    ASSERT_TRUE(a) << a.error();
    const std::string saved = sceneToJsonText(*a);
    Result<Scene> b = parseScene(saved, "t.json");
    ASSERT_TRUE(b) << b.error();
    EXPECT_EQ(sceneToJsonText(*b), saved);
    const Shapes* shapes = b->registry.tryGet<Shapes>(named(*b, "c"));
    ASSERT_TRUE(shapes);
    ASSERT_EQ(shapes->items.size(), 4u);
    EXPECT_EQ(shapes->items[0].density, 2.5);
    EXPECT_EQ(shapes->items[1].sensor, true);
    EXPECT_EQ(shapes->items[2].filter->group, -3);
    EXPECT_EQ(shapes->items[2].filter->mask, 4294967293u);
}

TEST(CompoundFormat, ValidateCountsTheShapesAndTheirMaterialActs) {
    // Friction on a compound body acts (it collides): validate notes
    // nothing, and its summary counts the bodies and their shapes.
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stepwise_compound_validate";
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / "ell.json", out = dir / "out.txt", err = dir / "err.txt";
    std::ofstream(file) << level("{\"name\": \"ell\", \"position\": {\"x\": 0, \"y\": 1}, \"friction\": 0.5, "
                                 "\"shapes\": [" + boxItem(0, 0, 2, 0.5) + ", " + boxItem(0.75, 1, 0.5, 1.5) +
                                 "]}, {\"name\": \"bell\", \"position\": {\"x\": 3, \"y\": 1}, \"shapes\": [" +
                                 circleItem(-1, 0, 0.3) + ", " + circleItem(1, 0, 0.3) + ", " +
                                 capsuleItem({-1, 0}, {1, 0}, 0.1) + "]}");
    const std::string command = std::string(STEPWISE_BINARY) + " validate " + file.string() + " >" + out.string() +
                                " 2>" + err.string();
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::stringstream text, warnings;
    text << std::ifstream(out).rdbuf();
    warnings << std::ifstream(err).rdbuf();
    EXPECT_NE(text.str().find("shapes x2 (5 shapes)"), std::string::npos) << text.str();
    EXPECT_EQ(warnings.str(), "");
    std::filesystem::remove_all(dir);
}

// ------------------------------------------------------------ mass

TEST(CompoundMass, SumsOverShapesByParallelAxes) {
    // Two boxes (an L) and a disc, each a density of its own; swept over sizes.
    for (const double s : {0.5, 1.0, 3.0}) {
        for (const double d2 : {1.0, 2.0, 7.5}) {
            Shapes shapes;
            CompoundShape base;
            base.kind = CompoundShape::Kind::Box;
            base.center = {0.0, 0.0};
            base.width = 2.0 * s;
            base.height = 0.5 * s;
            CompoundShape post = base;
            post.center = {0.75 * s, 0.75 * s};
            post.width = 0.5 * s;
            post.height = s;
            post.density = d2;
            CompoundShape disc;
            disc.kind = CompoundShape::Kind::Circle;
            disc.center = {-s, s};
            disc.radius = 0.25 * s;
            disc.density = 0.5;
            shapes.items = {base, post, disc};
            const double m1 = 2.0 * s * 0.5 * s, m2 = d2 * 0.5 * s * s, m3 = 0.5 * kPi * 0.0625 * s * s;
            const double m = m1 + m2 + m3;
            const Vec2 c = (m1 * base.center + m2 * post.center + m3 * disc.center) / m;
            const double i1 = m1 * (4.0 * s * s + 0.25 * s * s) / 12.0 + m1 * lengthSquared(base.center - c);
            const double i2 = m2 * (0.25 * s * s + s * s) / 12.0 + m2 * lengthSquared(post.center - c);
            const double i3 = 0.5 * m3 * 0.0625 * s * s + m3 * lengthSquared(disc.center - c);
            const CompoundMassProperties p = compoundMassProperties(shapes, std::nullopt);
            EXPECT_NEAR(p.mass, m, 1e-12 * m);
            EXPECT_NEAR(p.centre.x, c.x, 1e-12 * s);
            EXPECT_NEAR(p.centre.y, c.y, 1e-12 * s);
            EXPECT_NEAR(p.inertia, i1 + i2 + i3, 1e-12 * (i1 + i2 + i3));
            // `mass` scales every shape alike: the centre stays, inertia scales.
            const CompoundMassProperties q = compoundMassProperties(shapes, 5.0);
            EXPECT_DOUBLE_EQ(q.mass, 5.0);
            EXPECT_NEAR(q.centre.x, c.x, 1e-12 * s);
            EXPECT_NEAR(q.inertia, (i1 + i2 + i3) * 5.0 / m, 1e-12 * q.inertia);
        }
    }
}

TEST(CompoundMass, TheWorldMovesTheSummedBody) {
    // No gravity, a push and a spin: kinetic energy is M v^2/2 + I w^2/2
    // with the analytic M and I (about the common centre), with and without
    // `mass`; the velocity is the centre of mass's.
    for (const bool givenMass : {false, true}) {
        for (const double w : {0.5, -2.0}) {
            const std::string text = "{\"world\": {\"gravity\": {\"x\": 0, \"y\": 0}}, \"entities\": [{\"name\": "
                                     "\"ell\", \"position\": {\"x\": 0, \"y\": 0}, \"velocity\": {\"x\": 1, \"y\": 0}, "
                                     "\"angular_velocity\": " + exactNumber(w) + (givenMass ? ", \"mass\": 3" : "") +
                                     ", \"shapes\": [" + boxItem(0, 0, 2, 0.5) + ", " +
                                     boxItem(0.75, 0.75, 0.5, 1, ", \"density\": 3") + "]}]}";
            Sim sim(text);
            ASSERT_TRUE(sim.world);
            double m = 1.0 + 1.5;
            const Vec2 c = (1.0 * Vec2{0, 0} + 1.5 * Vec2{0.75, 0.75}) / m;
            double inertia = 1.0 * (4.0 + 0.25) / 12.0 + 1.0 * lengthSquared(c) + 1.5 * (0.25 + 1.0) / 12.0 +
                             1.5 * lengthSquared(Vec2{0.75, 0.75} - c);
            if (givenMass) {
                inertia *= 3.0 / m;
                m = 3.0;
            }
            const double expected = 0.5 * m * 1.0 + 0.5 * inertia * w * w;
            EXPECT_NEAR(sim.world->energy().kinetic, expected, 1e-12 * expected);
            ASSERT_TRUE(sim.step(60));
            // Free motion: energy kept, the spin unchanged.
            EXPECT_NEAR(sim.world->energy().kinetic, expected, 1e-9 * expected);
            EXPECT_NEAR(sim.angularVelocity("ell"), w, 1e-12);
            EXPECT_NEAR(sim.angle("ell"), w * 1.0, 1e-9);
        }
    }
}

// ------------------------------------------------------------ resting and tipping

namespace {
// An L: a foot 2 wide, 0.5 high, and a post 0.5 wide, 1.5 high standing on
// its end at `postX` (centre), resting on the floor with its foot's bottom
// at y = 0 when the position's y is 0.25.
std::string ell(double postX, double postW, const std::string& world, double x = 0.0) {
    return level(kFloor + ", {\"name\": \"ell\", \"position\": " + vectorJson(x, 0.25) + ", \"shapes\": [" +
                     boxItem(0, 0, 2, 0.5) + ", " + boxItem(postX, 1.0, postW, 1.5) + "]}",
                 world);
}
} // namespace

TEST(CompoundWorld, AnLStandsWhenItsCentreIsOverItsFoot) {
    for (const int substeps : kSubsteps) {
        for (const double postX : {-0.75, 0.0, 0.75}) {
            Sim sim(ell(postX, 0.5, substepsWorld(substeps)));
            ASSERT_TRUE(sim.step(240));
            const std::string what = "substeps " + std::to_string(substeps) + ", post at " + exactNumber(postX);
            EXPECT_NEAR(sim.angle("ell"), 0.0, 1e-3) << what;
            EXPECT_NEAR(sim.position("ell").y, 0.25, 0.01) << what;
            EXPECT_NEAR(sim.position("ell").x, 0.0, 0.01) << what;
        }
    }
}

TEST(CompoundWorld, AnLTipsWhenItsCentreIsPastItsFoot) {
    // A foot 0.5 wide and an arm 4 long at the top reaching past its right
    // edge: the centre of mass is beyond the foot, so it turns clockwise
    // about the foot's right corner (0.25, 0) until the arm's far lower
    // corner (4, 0.5) meets the floor: at -atan2(0.5, 3.75), where it rests
    // on the corner and the arm's end.
    const double expected = -std::atan2(0.5, 3.75);
    for (const int substeps : kSubsteps) {
        for (const double density : {1.0, 2.0, 5.0}) {
            const std::string text =
                level(kFloor + ", {\"name\": \"ell\", \"position\": " + vectorJson(0, 0.25) + ", \"shapes\": [" +
                          boxItem(0, 0, 0.5, 0.5) + ", " +
                          boxItem(2.0, 0.5, 4.0, 0.5, ", \"density\": " + exactNumber(density)) + "]}",
                      substepsWorld(substeps));
            Sim sim(text);
            ASSERT_TRUE(sim.step(240));
            EXPECT_NEAR(sim.angle("ell"), expected, 2e-3) << "substeps " << substeps << ", density " << density;
            EXPECT_NEAR(sim.angularVelocity("ell"), 0.0, 1e-3) << "substeps " << substeps << ", density " << density;
        }
    }
}

TEST(CompoundWorld, EveryIntegratorRestsTheL) {
    for (const std::string_view integrator : integratorNames()) {
        Sim sim(ell(0.75, 0.5, ", \"integrator\": \"" + std::string(integrator) + "\""));
        ASSERT_TRUE(sim.step(240)) << integrator;
        EXPECT_NEAR(sim.angle("ell"), 0.0, 1e-3) << integrator;
        EXPECT_NEAR(sim.position("ell").y, 0.25, 0.01) << integrator;
    }
}

// ------------------------------------------------------------ rolling

TEST(CompoundWorld, ADumbbellRollsAsOneBody) {
    // A dumbbell (two heavy discs on a capsule bar) inside a wheel's rim,
    // all one body, rolls down a slope without slipping: along the slope
    // a = g sin(theta) / (1 + I / (M r^2)), with M and I the sums over the
    // four shapes; it turns by distance / r. Swept over the weights' density.
    const double r = 0.5, theta = 0.3, g = 9.81;
    const Vec2 n{-std::sin(theta), std::cos(theta)};
    for (const double weights : {1.0, 5.0, 20.0}) {
        const std::string items = circleItem(0, 0, r) + ", " + circleItem(-0.3, 0, 0.1, ", \"density\": " + exactNumber(weights)) +
                                  ", " + circleItem(0.3, 0, 0.1, ", \"density\": " + exactNumber(weights)) + ", " +
                                  capsuleItem({-0.3, 0}, {0.3, 0}, 0.04);
        const std::string text =
            level("{\"name\": \"slope\", \"plane\": {\"normal\": " + vectorJson(n.x, n.y) + ", \"offset\": 0}}, "
                  "{\"name\": \"bell\", \"position\": " + vectorJson(r * n.x, r * n.y) +
                  ", \"friction\": 1, \"shapes\": [" + items + "]}");
        Sim sim(text);
        ASSERT_TRUE(sim.world);
        Shapes shapes = *sim.scene.registry.tryGet<Shapes>(named(sim.scene, "bell"));
        const CompoundMassProperties props = compoundMassProperties(shapes, std::nullopt);
        const double a = g * std::sin(theta) / (1.0 + props.inertia / (props.mass * r * r));
        ASSERT_TRUE(sim.step(60));
        const Vec2 moved = sim.position("bell") - r * n;
        const double along = -dot(moved, Vec2{n.y, -n.x});  // down the slope is -x along its surface
        EXPECT_NEAR(std::abs(along), 0.5 * a * 1.0, 0.02 * 0.5 * a) << weights;
        EXPECT_NEAR(std::abs(dot(moved, n)), 0.0, 0.005) << weights;  // stays on the slope
        EXPECT_NEAR(sim.angle("bell"), std::abs(along) / r, 0.02 * std::abs(along) / r) << weights;
    }
}

// ------------------------------------------------------------ contacts

namespace {
/// A drum of four walls on one body, turned as a kinematic body, with
/// balls and boxes inside.
std::string drum(double spin, int count, const std::string& world = "") {
    std::string items = boxItem(2.0, 0, 0.2, 4.2) + ", " + boxItem(-2.0, 0, 0.2, 4.2) + ", " + boxItem(0, 2.0, 4.2, 0.2) +
                        ", " + boxItem(0, -2.0, 4.2, 0.2);
    std::string entities = "{\"name\": \"drum\", \"kinematic\": true, \"position\": {\"x\": 0, \"y\": 0}, "
                           "\"angular_velocity\": " + exactNumber(spin) + ", \"shapes\": [" + items + "]}";
    for (int i = 0; i < count; ++i) {
        const double x = -1.5 + 0.4 * (i % 8), y = -1.5 + 0.4 * (i / 8);
        entities += ", {\"name\": \"b" + std::to_string(i) + "\", \"position\": " + vectorJson(x, y) +
                    (i % 2 ? ", \"radius\": 0.15}" : ", \"box\": {\"width\": 0.25, \"height\": 0.25}}");
    }
    return level(entities, world);
}
} // namespace

TEST(CompoundWorld, ShapesOfOneBodyNeverTouchEachOther) {
    // The drum's walls overlap at its corners; a dynamic L's two boxes too.
    Sim sim(level(kFloor + ", {\"name\": \"ell\", \"position\": {\"x\": 0, \"y\": 1}, \"shapes\": [" +
                  boxItem(0, 0, 2, 0.5) + ", " + boxItem(0.8, 0.5, 0.5, 1.5) + ", " + circleItem(-0.8, 0.2, 0.4) + "]}"));
    ASSERT_TRUE(sim.step(60, [&] {
        for (const ContactRecord& c : sim.world->contacts()) EXPECT_FALSE(c.a == c.b);
    }));
    Sim drummed(drum(0.5, 24));
    ASSERT_TRUE(drummed.step(120, [&] {
        for (const ContactRecord& c : drummed.world->contacts()) EXPECT_FALSE(c.a == c.b);
    }));
}

TEST(CompoundWorld, AKinematicDrumTurnsAndKeepsItsLoad) {
    for (const double spin : {0.3, 1.0}) {
        Sim sim(drum(spin, 32));
        ASSERT_TRUE(sim.step(300));
        EXPECT_NEAR(sim.angle("drum"), spin * 5.0, 1e-9);
        EXPECT_EQ(sim.position("drum"), (Vec2{0, 0}));
        for (int i = 0; i < 32; ++i) {
            const Vec2 p = sim.position("b" + std::to_string(i));
            EXPECT_LT(length(p), 2.0 * std::sqrt(2.0)) << i << " escaped at spin " << spin;
        }
    }
}

TEST(CompoundWorld, AMotorTurnsADynamicDrumOnAHinge) {
    // The tumbler as Box2D builds it: a dynamic drum of four walls on one
    // hinge to the world at its centre, driven by a strong motor. It turns
    // at the motor's speed with its load inside, its centre held.
    for (const double speed : {0.25, 0.8}) {
        std::string text = drum(0.0, 24);
        const std::string kinematic = "\"kinematic\": true, ";
        text.replace(text.find(kinematic), kinematic.size(), "");
        text.insert(text.rfind("]}"), ", {\"name\": \"axle\", \"joint\": {\"type\": \"hinge\", \"a\": \"drum\", "
                                      "\"anchor\": {\"x\": 0, \"y\": 0}, \"motor_speed\": " + exactNumber(speed) +
                                      ", \"max_motor_torque\": 1e6}}");
        Sim sim(text);
        ASSERT_TRUE(sim.step(240));
        // The speed as the mean over the last second: the items striking the
        // walls jolt the drum off the motor's speed for a step and the motor
        // brings it back. The jolts are chaotic: moving one item by a
        // micrometre at the start changes the largest in that second from
        // 5% to 9% or 15%, so a reading at one step says which step it is.
        double sum = 0.0;
        ASSERT_TRUE(sim.step(60, [&] {
            sim.world->writeBack(sim.scene);
            sum += sim.angularVelocity("drum");
        }));
        // The motor sets b's speed relative to a: the world (b) against the
        // drum (a) at +speed turns the drum at -speed.
        EXPECT_NEAR(sim.angle("drum"), -speed * 5.0, 0.02 * speed * 5.0) << speed;
        EXPECT_NEAR(sum / 60.0, -speed, 0.01 * speed) << speed;
        EXPECT_LT(length(sim.position("drum")), 1e-3) << speed;
        for (int i = 0; i < 24; ++i)
            EXPECT_LT(length(sim.position("b" + std::to_string(i))), 2.0 * std::sqrt(2.0)) << i << " at " << speed;
    }
}

TEST(CompoundWorld, EachShapeKeepsItsOwnFriction) {
    // On a 0.4 rad slope a shape with friction 0 slides whatever the
    // body's friction says, and one with friction 1 holds.
    const double slope = 0.4;
    const Vec2 n{-std::sin(slope), std::cos(slope)};
    for (const bool slippery : {true, false}) {
        const std::string item = boxItem(0, 0, 1, 0.5, slippery ? ", \"friction\": 0" : ", \"friction\": 1");
        const std::string text =
            level("{\"name\": \"slope\", \"plane\": {\"normal\": " + vectorJson(n.x, n.y) + ", \"offset\": 0}}, "
                  "{\"name\": \"block\", \"position\": " + vectorJson(0.25 * n.x, 0.25 * n.y) + ", \"angle\": " +
                  exactNumber(slope) + ", \"friction\": " + (slippery ? "1" : "0") + ", \"shapes\": [" + item + "]}");
        Sim sim(text);
        ASSERT_TRUE(sim.step(60));
        const double moved = length(sim.position("block") - 0.25 * n);
        if (slippery) EXPECT_NEAR(moved, 0.5 * 9.81 * std::sin(slope) * 1.0, 0.05);
        else EXPECT_LT(moved, 0.01);
    }
}

TEST(CompoundWorld, SensorAndFilterArePerShape) {
    // A static shelf with two boxes: the left one a sensor, the middle one
    // solid, the right one filtered out of category 1. Balls dropped on each:
    // through the sensor (with a begin event naming the shelf), resting on
    // the solid one, through the filtered one.
    const std::string text = level(
        kFloor + ", {\"name\": \"shelf\", \"static\": true, \"position\": {\"x\": 0, \"y\": 2}, \"shapes\": [" +
        boxItem(-2, 0, 1, 0.2, ", \"sensor\": true") + ", " + boxItem(0, 0, 1, 0.2) + ", " +
        boxItem(2, 0, 1, 0.2, ", \"filter\": {\"category\": 2, \"mask\": 2, \"group\": 0}") +
        "]}, {\"name\": \"left\", \"position\": {\"x\": -2, \"y\": 3}, \"radius\": 0.2}, "
        "{\"name\": \"mid\", \"position\": {\"x\": 0, \"y\": 3}, \"radius\": 0.2}, "
        "{\"name\": \"right\", \"position\": {\"x\": 2, \"y\": 3}, \"radius\": 0.2}");
    Sim sim(text);
    int begins = 0;
    ASSERT_TRUE(sim.step(120, [&] {
        for (const SensorEvent& e : sim.world->sensorEvents())
            if (e.begin) {
                ++begins;
                EXPECT_EQ(e.sensor, named(sim.scene, "shelf"));
                EXPECT_EQ(e.body, named(sim.scene, "left"));
            }
    }));
    EXPECT_EQ(begins, 1);
    EXPECT_NEAR(sim.position("left").y, 0.2, 0.01);
    EXPECT_NEAR(sim.position("mid").y, 2.3, 0.01);
    EXPECT_NEAR(sim.position("right").y, 0.2, 0.01);
}

TEST(CompoundWorld, AHingeHoldsACompoundBodyByItsFrame) {
    // A pendulum of two discs hinged to the world at its position: the
    // anchor is in the body frame, and the body swings about it.
    const std::string text = level("{\"name\": \"pend\", \"position\": {\"x\": 0, \"y\": 0}, \"shapes\": [" +
                                   circleItem(1, 0, 0.2) + ", " + circleItem(2, 0, 0.2) +
                                   "]}, {\"name\": \"pin\", \"joint\": {\"type\": \"hinge\", \"a\": \"pend\", \"anchor\": "
                                   "{\"x\": 0, \"y\": 0}}}");
    Sim sim(text);
    ASSERT_TRUE(sim.step(30));
    // The pin stays at the origin: the body's position is its frame's origin.
    EXPECT_LT(length(sim.position("pend")), 1e-3);
    EXPECT_LT(sim.angle("pend"), -0.1);
}

TEST(CompoundWorld, ARestingCompoundBodySleepsAndABallWakesIt) {
    // The L rests and falls asleep as one body; a ball dropped on its post
    // (not on the shape that touches the floor) wakes it, and it settles
    // again with the ball on top.
    const std::string text = level(kFloor + ", {\"name\": \"ell\", \"position\": " + vectorJson(0, 0.25) +
                                       ", \"shapes\": [" + boxItem(0, 0, 2, 0.5) + ", " + boxItem(0.75, 1.0, 0.5, 1.5) +
                                       "]}, {\"name\": \"ball\", \"position\": {\"x\": 0.75, \"y\": 30}, \"radius\": 0.2}",
                                   ", \"sleep\": true");
    Sim sim(text);
    ASSERT_TRUE(sim.step(90));
    const Entity ell = named(sim.scene, "ell");
    const auto sleeping = [&] {
        const std::vector<Entity> asleep = sim.world->sleepingBodies();
        return std::find(asleep.begin(), asleep.end(), ell) != asleep.end();
    };
    EXPECT_TRUE(sleeping()) << "the L rests and sleeps while the ball falls";
    bool woke = false;
    ASSERT_TRUE(sim.step(240, [&] { woke = woke || !sleeping(); }));
    EXPECT_TRUE(woke);
    EXPECT_NEAR(sim.position("ball").y, 0.25 + 1.75 + 0.2, 0.01);  // on the post's top
    EXPECT_NEAR(sim.angle("ell"), 0.0, 1e-3);
}

// ------------------------------------------------------------ resume

TEST(CompoundWorld, ResumesBitForBitUnderEveryIntegrator) {
    // The drum with its load, and a dynamic L and dumbbell beside it,
    // under each integrator: 60 steps, save, load, 60 steps == 120 steps.
    for (const std::string_view integrator : integratorNames()) {
        std::string text = drum(0.6, 16, ", \"integrator\": \"" + std::string(integrator) + "\"");
        text.insert(text.rfind("]}"), ", " + kFloor +
                                          ", {\"name\": \"ell\", \"position\": {\"x\": 5, \"y\": 2}, \"shapes\": [" +
                                          boxItem(0, 0, 2, 0.5) + ", " + boxItem(0.75, 1, 0.5, 1.5) +
                                          "]}, {\"name\": \"bell\", \"position\": {\"x\": -5, \"y\": 2}, "
                                          "\"angle\": 0.4, \"shapes\": [" + circleItem(-1, 0, 0.4) + ", " +
                                          circleItem(1, 0, 0.4) + ", " + capsuleItem({-1, 0}, {1, 0}, 0.1) + "]}");
        Sim whole(text);
        ASSERT_TRUE(whole.step(120)) << integrator;
        Sim first(text);
        ASSERT_TRUE(first.step(60)) << integrator;
        Sim second(sceneToJsonText(first.scene));
        ASSERT_TRUE(second.step(60)) << integrator;
        EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene)) << integrator;
    }
}

TEST(CompoundWorld, ResumesBitForBitFromAMidRunSave) {
    for (const int substeps : {0, 1, 4}) {
        const std::string text = drum(0.6, 24, substepsWorld(substeps));
        Sim whole(text);
        ASSERT_TRUE(whole.step(200));
        Sim first(text);
        ASSERT_TRUE(first.step(100));
        const std::string saved = sceneToJsonText(first.scene);
        // Contacts with the drum's second wall onwards carry its shape.
        EXPECT_TRUE(saved.find("\"shape_a\"") != std::string::npos || saved.find("\"shape_b\"") != std::string::npos);
        Sim second(saved);
        ASSERT_TRUE(second.step(100));
        EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene)) << substeps;
    }
}

// A polygon item may be rounded as the polygon component is: its mass is
// the rounded outline's, it rests on its rounding, it is picked within it,
// and the file keeps the radius byte for byte.
TEST(CompoundWorld, APolygonItemIsRoundedByItsRadius) {
    const std::string level = R"({"world": {"gravity": {"x": 0, "y": -9.81}, "substeps": 4},
      "entities": [
        {"name": "floor", "plane": {"normal": {"x": 0, "y": 1}, "offset": 0}},
        {"name": "pebble", "position": {"x": 0, "y": 0.301},
         "shapes": [{"polygon": {"vertices": [{"x": -0.25, "y": -0.25}, {"x": 0.25, "y": -0.25},
                                              {"x": 0.25, "y": 0.25}, {"x": -0.25, "y": 0.25}], "radius": 0.05}}]}
      ]})";
    Result<Scene> scene = parseScene(level, "t.json");
    ASSERT_TRUE(scene) << scene.error();
    EXPECT_EQ(sceneToJsonText(*parseScene(sceneToJsonText(*scene), "t.json")), sceneToJsonText(*scene));
    const Shapes& shapes = *scene->registry.tryGet<Shapes>(named(*scene, "pebble"));
    ASSERT_EQ(shapes.items[0].cornerRadius, std::optional<double>(0.05));
    const std::vector<Vec2> square{{-0.25, -0.25}, {0.25, -0.25}, {0.25, 0.25}, {-0.25, 0.25}};
    // 0.25 + 4 x 0.5 x 0.05 + pi 0.05^2 at density 1.
    EXPECT_NEAR(compoundMassProperties(shapes, std::nullopt).mass, 0.25 + 0.1 + std::numbers::pi * 0.0025, 1e-12);
    EXPECT_NEAR(compoundMassProperties(shapes, std::nullopt).inertia,
                polygonMassProperties(square, 0.05).secondMoment, 1e-12);
    EXPECT_TRUE(compoundShapeContains(shapes.items[0], {0.28, 0.0}));
    EXPECT_FALSE(compoundShapeContains(shapes.items[0], {0.32, 0.0}));
    EXPECT_TRUE(compoundShapeContains(shapes.items[0], {0.25 + 0.03, 0.25 + 0.03}));
    EXPECT_FALSE(compoundShapeContains(shapes.items[0], {0.25 + 0.04, 0.25 + 0.04}));
    Sim sim(level);
    ASSERT_TRUE(sim.step(120));
    // Half the height plus the rounding, less the 4-substep contact's sag.
    EXPECT_NEAR(sim.position("pebble").y, 0.3, 2e-4);
    EXPECT_NEAR(sim.angle("pebble"), 0.0, 1e-6);
}
