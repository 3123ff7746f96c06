// Chain shapes: the format's checks with their exact messages, the narrow
// phase's smoothness and one-sidedness, and whole-world runs with analytic
// answers: a ball rolling and a box sliding across many joints keep what
// they would on one flat floor (swept over speeds, segment lengths and
// substeps), bodies pass a chain from its open side, loops keep bodies
// outside (counter-clockwise) or inside (clockwise), rest heights of every
// kind on a chain, one proxy per segment, and exact save/resume.

#include "collision/narrow_phase.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
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
using namespace stepwise::collision;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;
std::string level(const std::string& entities, const std::string& world = "") {
    return test::levelUnderGravity(entities, world);
}

std::string chainJson(const std::vector<Vec2>& points, bool loop) {
    std::string out = "\"chain\": {\"points\": [";
    for (std::size_t i = 0; i < points.size(); ++i) out += (i ? ", " : "") + vectorJson(points[i].x, points[i].y);
    return out + "], \"loop\": " + (loop ? "true" : "false") + "}";
}

/// A static chain entity named `name` at the origin.
std::string chainEntity(const std::string& name, const std::vector<Vec2>& points, bool loop,
                        const std::string& extra = "") {
    return "{\"name\": \"" + name + "\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, " +
           (extra.empty() ? "" : extra + ", ") + chainJson(points, loop) + "}";
}

/// A flat floor at y = 0 from x = `from` to `to` (from > to: drawn right to
/// left, so its solid side is up), in segments of `segment` metres.
std::vector<Vec2> flatFloor(double from, double to, double segment) {
    std::vector<Vec2> points;
    const int n = int(std::llround((from - to) / segment));
    for (int i = 0; i <= n; ++i) points.push_back({from - (from - to) * i / n, 0.0});
    return points;
}

/// A circle of `count` points, radius R, centred on the origin, turned by
/// half a step so its top is a flat segment; counter-clockwise unless `cw`.
std::vector<Vec2> circlePoints(double R, int count, bool cw) {
    std::vector<Vec2> points;
    for (int i = 0; i < count; ++i) {
        const double a = 2.0 * kPi * (i + 0.5) / count;
        points.push_back({R * std::cos(cw ? -a : a), R * std::sin(cw ? -a : a)});
    }
    return points;
}

Shape segmentShape(const ChainSegment& s) {
    Shape shape;
    shape.kind = ShapeKind::ChainSegment;
    shape.segment = &s;
    return shape;
}

} // namespace

// ------------------------------------------------------------ format

TEST(ChainFormat, BadChainsAreRefusedNamingTheEntityAndPoint) {
    const auto chainOn = [](const std::string& points, const std::string& more = "\"static\": true, ") {
        return level("{\"name\": \"ground\", " + more + "\"position\": {\"x\": 0, \"y\": 0}, \"chain\": " + points +
                     "}");
    };
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}]}")),
              "t.json: error: /entities/0/chain/points: entity 0 (\"ground\"): expected 2 to 1024 points, got 1");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}], \"loop\": true}")),
              "t.json: error: /entities/0/chain/points: entity 0 (\"ground\"): expected 3 to 1024 points in a loop, "
              "got 2");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 1, \"y\": 0}]}")),
              "t.json: error: /entities/0/chain/points/2: entity 0 (\"ground\"): point 2 {\"x\": 1, \"y\": 0} is "
              "the same point as point 1; each segment of a chain needs a length");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 1, \"y\": 1}, "
                                "{\"x\": 0, \"y\": 0}], \"loop\": true}")),
              "t.json: error: /entities/0/chain/points/0: entity 0 (\"ground\"): point 0 {\"x\": 0, \"y\": 0} is "
              "the same point as point 3 (the loop closes from the last point to the first); each segment of a "
              "chain needs a length");
    // The same four points open are a valid chain that ends where it began.
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 1, \"y\": 1}, "
                                "{\"x\": 0, \"y\": 0}]}")),
              "loaded");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": \"far\", \"y\": 0}]}")),
              "t.json: error: /entities/0/chain/points/1/x: expected a number in [-1e+30, 1e+30], got \"far\"");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}], \"loop\": 1}")),
              "t.json: error: /entities/0/chain/loop: expected true or false, got 1");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}]}", "")),
              "t.json: error: /entities/0/chain: entity 0 (\"ground\"): a chain must be on a static or kinematic "
              "body (\"static\": true or \"kinematic\": true); a chain has no area, so it gives a dynamic body no "
              "mass or inertia to move by");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}]}", "\"kinematic\": true, ")),
              "loaded");
    EXPECT_EQ(loadError(chainOn("{\"points\": [{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}]}",
                                "\"static\": true, \"radius\": 1, ")),
              "t.json: error: /entities/0: an entity has at most one shape (radius, box, polygon, capsule, chain or "
              "plane), got 2");
    std::string many = "{\"points\": [";
    for (int i = 0; i < 1025; ++i) many += (i ? ", " : "") + vectorJson(i, 0);
    EXPECT_EQ(loadError(chainOn(many + "]}")),
              "t.json: error: /entities/0/chain/points: entity 0 (\"ground\"): expected 2 to 1024 points, got 1025");
}

TEST(ChainFormat, TheWorldRefusesBadChainsMadeInCode) {
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {"rail"});
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    s.registry.emplace<Chain>(e, {{{0.0, 0.0}, {1.0, 0.0}}, false});
    Result<World> dynamic = World::build(s);
    ASSERT_FALSE(dynamic);
    EXPECT_EQ(dynamic.error(), "entity 0 (\"rail\"): chain: a chain must be on a static or kinematic body "
                               "(\"static\": true or \"kinematic\": true); a chain has no area, so it gives a "
                               "dynamic body no mass or inertia to move by");
    s.registry.emplace<Static>(e, {true});
    s.registry.emplace<Chain>(e, {{{0.0, 0.0}, {1.0, 0.0}, {1.0, 0.0}}, false});
    Result<World> repeated = World::build(s);
    ASSERT_FALSE(repeated);
    EXPECT_EQ(repeated.error(), "entity 0 (\"rail\"): chain.points[2]: point 2 {\"x\": 1, \"y\": 0} is the same point "
                                "as point 1; each segment of a chain needs a length");
}

TEST(ChainFormat, RoundTripsByteForByte) {
    const std::string text = level(
        chainEntity("hills", {{3.0, 0.1}, {0.3333333333333333, 1e-300}, {-2.0, 0.123456789012345678}}, false,
                    "\"angle\": 0.25, \"friction\": 0.7") +
        ", " + chainEntity("bowl", circlePoints(2.0, 7, true), true));
    Result<Scene> first = parseScene(text, "t.json");
    ASSERT_TRUE(first) << first.error();
    const std::string saved = sceneToJsonText(*first);
    Result<Scene> second = parseScene(saved, "saved.json");
    ASSERT_TRUE(second) << second.error();
    EXPECT_EQ(sceneToJsonText(*second), saved);
    const Chain* hills = second->registry.tryGet<Chain>(named(*second, "hills"));
    ASSERT_NE(hills, nullptr);
    EXPECT_FALSE(hills->loop);
    ASSERT_EQ(hills->points.size(), 3u);
    EXPECT_EQ(hills->points[1], (Vec2{0.3333333333333333, 1e-300}));
    EXPECT_EQ(hills->points[2], (Vec2{-2.0, 0.123456789012345678}));
    EXPECT_TRUE(second->registry.tryGet<Chain>(named(*second, "bowl"))->loop);
}

TEST(ChainFormat, EachSegmentIsAColliderOfItsOwn) {
    // A 360-point loop is 360 broad-phase proxies, not one box round it.
    Sim sim(level(chainEntity("ring", circlePoints(10.0, 360, false), true) + ", " +
                  chainEntity("rail", flatFloor(5.0, -5.0, 1.0), false)));
    ASSERT_TRUE(sim.world);
    const WorldState state = sim.world->saveState();
    ASSERT_EQ(state.layout->colliders.size(), 370u);
    for (std::size_t c = 0; c < 360; ++c) EXPECT_EQ(state.layout->colliders[c], named(sim.scene, "ring"));
    for (std::size_t c = 360; c < 370; ++c) EXPECT_EQ(state.layout->colliders[c], named(sim.scene, "rail"));
}

// ------------------------------------------------------------ narrow phase

TEST(ChainNarrowPhase, AtAJointOnlyTheFaceNormalIsEverSeen) {
    // Three collinear segments; shapes straddling or near the joints at
    // x = 0 and x = 1 get normals straight up from the chain, never the
    // joint's corner normal that would bump them.
    const std::vector<Vec2> pts{{2.0, 0.0}, {1.0, 0.0}, {0.0, 0.0}, {-1.0, 0.0}};
    std::vector<ChainSegment> segs(3);
    for (std::size_t k = 0; k < 3; ++k) {
        segs[k].index = std::uint32_t(k);
        segs[k].p1 = pts[k];
        segs[k].p2 = pts[k + 1];
        const Vec2 behind{0.0, -1.0};
        segs[k].open1 = k == 0;
        segs[k].open2 = k == 2;
        segs[k].ghost1 = k == 0 ? pts[0] + behind : pts[k - 1];
        segs[k].ghost2 = k == 2 ? pts[3] + behind : pts[k + 2];
    }
    static const Vec2 square[4] = {{-0.2, -0.2}, {0.2, -0.2}, {0.2, 0.2}, {-0.2, 0.2}};
    const ConvexPolygon poly = ConvexPolygon::fromVertices(square, 4);
    int manifolds = 0;
    for (double x = -0.3; x <= 1.3; x += 0.01) {
        for (const double gap : {-0.004, -0.001, 0.0, 0.002}) {
            for (const double tilt : {0.0, 0.05, -0.05}) {
                Shape circle;
                circle.kind = ShapeKind::Circle;
                circle.radius = 0.2;
                Shape box;
                box.kind = ShapeKind::Box;
                box.halfExtents = {0.2, 0.2};
                Shape polygon;
                polygon.kind = ShapeKind::Polygon;
                polygon.polygon = &poly;
                Shape capsule;
                capsule.kind = ShapeKind::Capsule;
                capsule.halfExtents = {0.3, 0.0};
                capsule.radius = 0.2;
                for (const Shape* other : {&circle, &box, &polygon, &capsule}) {
                    // A tilted flat shape's lowest corner sits at the gap.
                    const double half = other->kind == ShapeKind::Circle ? 0.2
                                        : other->kind == ShapeKind::Capsule
                                            ? 0.2 + 0.3 * std::abs(std::sin(tilt))
                                            : 0.2 * (std::abs(std::cos(tilt)) + std::abs(std::sin(tilt)));
                    const Vec2 p{x, half + gap};
                    double deepest = 1e9;
                    for (const ChainSegment& s : segs) {
                        const Manifold m = collide(segmentShape(s), {}, {}, *other, p, Rot::fromAngle(tilt), 0.02);
                        const Manifold flipped =
                            collide(*other, p, Rot::fromAngle(tilt), segmentShape(s), {}, {}, 0.02);
                        ASSERT_EQ(m.pointCount, flipped.pointCount);
                        if (m.pointCount == 0) continue;
                        ++manifolds;
                        EXPECT_NEAR(m.normal.x, 0.0, 1e-12) << "x " << x << " segment " << s.index;
                        EXPECT_NEAR(m.normal.y, 1.0, 1e-12);
                        EXPECT_EQ(flipped.normal, -m.normal);
                        for (int i = 0; i < m.pointCount; ++i) {
                            EXPECT_EQ(m.points[i].id >> kChainFeatureShift, s.index);
                            deepest = std::min(deepest, m.points[i].separation);
                        }
                    }
                    // The lowest point of the shape is seen at its true gap.
                    EXPECT_NEAR(deepest, gap, 1e-9) << "x " << x << " tilt " << tilt;
                }
            }
        }
    }
    EXPECT_GT(manifolds, 1000);
}

TEST(ChainNarrowPhase, OneSidedAndOpenEndsAreSquareCorners) {
    ChainSegment s;
    s.p1 = {1.0, 0.0};
    s.p2 = {-1.0, 0.0};  // solid side up
    s.open1 = s.open2 = true;
    s.ghost1 = s.p1 + Vec2{0.0, -2.0};
    s.ghost2 = s.p2 + Vec2{0.0, -2.0};
    Shape circle;
    circle.kind = ShapeKind::Circle;
    circle.radius = 0.25;
    Shape box;
    box.kind = ShapeKind::Box;
    box.halfExtents = {0.25, 0.25};
    for (const Shape* other : {&circle, &box}) {
        // From below (its centre behind): nothing, even overlapping.
        for (const double y : {-0.3, -0.2, -0.01})
            EXPECT_EQ(collide(segmentShape(s), {}, {}, *other, {0.0, y}, {}, 0.1).pointCount, 0) << y;
        // From above: the face.
        const Manifold above = collide(segmentShape(s), {}, {}, *other, {0.0, 0.24}, {}, 0.1);
        ASSERT_GT(above.pointCount, 0);
        EXPECT_EQ(above.normal, (Vec2{0.0, 1.0}));
    }
    // Past an open end, beside and above it: the corner pushes outward
    // along the line from the end point.
    const Manifold corner = collide(segmentShape(s), {}, {}, circle, {1.2, 0.1}, {}, 0.1);
    ASSERT_EQ(corner.pointCount, 1);
    EXPECT_NEAR(corner.normal.x, 2.0 / std::sqrt(5.0), 1e-12);
    EXPECT_NEAR(corner.normal.y, 1.0 / std::sqrt(5.0), 1e-12);
    EXPECT_NEAR(corner.points[0].separation, std::sqrt(0.05) - 0.25, 1e-12);
}

// ------------------------------------------------------------ world runs

TEST(ChainWorld, ABallRollsAcrossJointsWithoutABump) {
    // A ball rolling (v = -w r) along a flat chain: every joint it crosses
    // must leave its speed and height as one long segment would (the same
    // floor in one piece, run beside it): no hop, no loss. Swept over
    // speeds, segment lengths and substeps.
    double worstSpeed = 0.0, worstVy = 0.0, worstHeight = 0.0, worstLoss = 0.0;
    int cases = 0;
    for (const double segment : {0.1, 0.3, 1.0}) {
        for (const double v0 : {0.5, 3.0, 12.0}) {
            for (const int substeps : {1, 2, 4, 8}) {
                const double r = 0.25;
                const double end = 2.0 * v0 * 2.0 + 4.0;
                const auto text = [&](const std::vector<Vec2>& floor) {
                    return level(chainEntity("floor", floor, false, "\"friction\": 0.6") +
                                     ", {\"name\": \"ball\", \"position\": " + vectorJson(0.0, r) + ", \"velocity\": " +
                                     vectorJson(v0, 0.0) + ", \"angular_velocity\": " + exactNumber(-v0 / r) +
                                     ", \"radius\": " + exactNumber(r) + ", \"friction\": 0.6}",
                                 "\"substeps\": " + std::to_string(substeps));
                };
                Sim sim(text(flatFloor(end, -2.0, segment)));
                Sim one(text({{end, 0.0}, {-2.0, 0.0}}));
                ASSERT_TRUE(sim.world && one.world);
                for (int i = 0; i < 120; ++i) {  // 2 s
                    ASSERT_TRUE(sim.step());
                    ASSERT_TRUE(one.step());
                    const Vec2 v = sim.velocity("ball"), vOne = one.velocity("ball");
                    const double y = sim.position("ball").y;
                    const std::string what = "segment " + exactNumber(segment) + " v0 " + exactNumber(v0) + " substeps " +
                                             std::to_string(substeps) + " step " + std::to_string(i);
                    ASSERT_NEAR(v.x, vOne.x, 1e-9 * v0) << what;
                    ASSERT_NEAR(v.y, vOne.y, 1e-9) << what;
                    ASSERT_NEAR(y, one.position("ball").y, 1e-9) << what;
                    // And the one long segment itself rolls on: the soft
                    // contact settles by micrometres, the speed stays.
                    ASSERT_NEAR(v.x, v0, 1e-3 * v0) << what;
                    ASSERT_NEAR(y, r, 1.5e-3) << what;
                    worstSpeed = std::max(worstSpeed, std::abs(v.x - vOne.x) / v0);
                    worstVy = std::max(worstVy, std::abs(v.y - vOne.y));
                    worstHeight = std::max(worstHeight, std::abs(y - one.position("ball").y));
                    worstLoss = std::max(worstLoss, std::abs(v.x - v0) / v0);
                }
                EXPECT_NEAR(sim.position("ball").x, 2.0 * v0, 2e-3 * v0);
                ++cases;
            }
        }
    }
    std::printf("rolling ball: %d cases; against one long segment: worst relative speed difference %.3g, "
                "|vy| difference %.3g m/s, height difference %.3g m; worst relative change from v0 %.3g\n",
                cases, worstSpeed, worstVy, worstHeight, worstLoss);
}

TEST(ChainWorld, ABoxSlidesAcrossJointsDeceleratingByFrictionOnly) {
    // A box sliding on a chain of segments as short as a sixth of it
    // straddles a joint at every moment: it must not catch or hop, and its
    // speed must follow v^2 = v0^2 - 2 mu g d. Beside it the same floor in
    // one segment: the joints must change nothing.
    double worstVy = 0.0, worstSpin = 0.0, worstV2 = 0.0, worstApart = 0.0, worstOneSpin = 0.0;
    int cases = 0;
    for (const double segment : {0.1, 0.35, 1.0}) {
        for (const double v0 : {2.0, 5.0, 9.0}) {
            for (const int substeps : {1, 2, 4, 8}) {
                const double mu = 0.3, w = 0.6, h = 0.3;
                const auto text = [&](const std::vector<Vec2>& floor) {
                    return level(chainEntity("floor", floor, false, "\"friction\": 0.3") +
                                     ", {\"name\": \"box\", \"position\": " + vectorJson(0.0, 0.5 * h) +
                                     ", \"velocity\": " + vectorJson(v0, 0.0) + ", \"box\": {\"width\": " + exactNumber(w) +
                                     ", \"height\": " + exactNumber(h) + "}, \"friction\": 0.3}",
                                 "\"substeps\": " + std::to_string(substeps));
                };
                Sim sim(text(flatFloor(16.0, -2.0, segment)));
                Sim one(text({{16.0, 0.0}, {-2.0, 0.0}}));
                ASSERT_TRUE(sim.world && one.world);
                const double stop = v0 * v0 / (2.0 * mu * kG);
                const int steps = int(60.0 * 0.8 * v0 / (mu * kG));  // until 80% of the stopping time
                for (int i = 0; i < steps; ++i) {
                    ASSERT_TRUE(sim.step());
                    ASSERT_TRUE(one.step());
                    const Vec2 v = sim.velocity("box");
                    const double d = sim.position("box").x;
                    const std::string what = "segment " + exactNumber(segment) + " v0 " + exactNumber(v0) + " substeps " +
                                             std::to_string(substeps) + " step " + std::to_string(i);
                    // Several manifolds share the load where one long
                    // segment has one, so the iterations converge a little
                    // differently: close, not equal.
                    ASSERT_NEAR(v.x, one.velocity("box").x, 0.06) << what;
                    ASSERT_NEAR(sim.position("box").y, one.position("box").y, 1e-3) << what;
                    ASSERT_NEAR(v.y, 0.0, 0.01) << what;
                    ASSERT_NEAR(sim.angularVelocity("box"), 0.0, 0.06) << what;
                    worstOneSpin = std::max(worstOneSpin, std::abs(one.angularVelocity("box")));
                    const double expected = v0 * v0 - 2.0 * mu * kG * d;
                    // A step of friction's deceleration is the resolution of
                    // the discrete slide: |dv^2| <= 2 v mu g dt.
                    ASSERT_NEAR(v.x * v.x, expected, 0.6 * 2.0 * v0 * mu * kG / 60.0) << what;
                    worstApart = std::max({worstApart, std::abs(v.x - one.velocity("box").x),
                                           std::abs(v.y - one.velocity("box").y),
                                           std::abs(sim.angularVelocity("box") - one.angularVelocity("box"))});
                    worstVy = std::max(worstVy, std::abs(v.y));
                    worstSpin = std::max(worstSpin, std::abs(sim.angularVelocity("box")));
                    worstV2 = std::max(worstV2, std::abs(v.x * v.x - expected) / (2.0 * v0 * mu * kG / 60.0));
                }
                EXPECT_LT(sim.position("box").x, stop);
                ++cases;
            }
        }
    }
    std::printf("sliding box: %d cases; against one long segment: worst difference %.3g (m/s, rad/s); worst |vy| "
                "%.3g m/s, |w| %.3g rad/s (one segment: %.3g), |v^2 - (v0^2 - 2 mu g d)| %.3g of a step's 2 v0 mu g "
                "dt\n",
                cases, worstApart, worstVy, worstSpin, worstOneSpin, worstV2);
}

TEST(ChainWorld, BodiesPassFromTheOpenSideAndLandOnTheSolidOne) {
    // A floor solid on top; each kind thrown up from below passes through
    // it, then falls back and rests on it.
    const std::vector<std::string> shapes = {"\"radius\": 0.25", "\"box\": {\"width\": 0.6, \"height\": 0.5}",
                                             "\"capsule\": {\"a\": {\"x\": -0.3, \"y\": 0}, \"b\": {\"x\": 0.3, \"y\": "
                                             "0}, \"radius\": 0.25}",
                                             "\"polygon\": {\"vertices\": [{\"x\": -0.25, \"y\": -0.25}, {\"x\": 0.25, "
                                             "\"y\": -0.25}, {\"x\": 0.25, \"y\": 0.25}, {\"x\": -0.25, \"y\": 0.25}]}"};
    for (const std::string& shape : shapes) {
        for (const double up : {5.0, 8.0}) {
            Sim sim(level(chainEntity("floor", flatFloor(3.0, -3.0, 0.5), false) +
                          ", {\"name\": \"body\", \"position\": {\"x\": 0.1, \"y\": -0.6}, \"velocity\": " +
                          vectorJson(0.0, up) + ", " + shape + "}"));
            ASSERT_TRUE(sim.world);
            double highest = -1.0;
            for (int i = 0; i < 300; ++i) {
                ASSERT_TRUE(sim.step());
                highest = std::max(highest, sim.position("body").y);
            }
            // Free flight from -0.6 at `up` reaches -0.6 + up^2 / 2g: the
            // chain never held it back (once its centre is past the line
            // the solid side pushes it on out, so it may go higher).
            EXPECT_GE(highest, -0.6 + up * up / (2.0 * kG) - 1e-3) << shape;
            EXPECT_LE(highest, -0.6 + up * up / (2.0 * kG) + 0.15) << shape;
            EXPECT_NEAR(sim.position("body").y, 0.25, 2e-3) << shape << " up " << up;
        }
    }
}

TEST(ChainWorld, ACounterClockwiseLoopKeepsBodiesOutsideAClockwiseOneInside) {
    // Outside: a ball dropped on a counter-clockwise ring rests on its flat
    // top at R cos(pi / n) + r.
    {
        const int n = 48;
        const double R = 2.0, r = 0.3;
        Sim sim(level(chainEntity("ring", circlePoints(R, n, false), true) +
                      ", {\"name\": \"ball\", \"position\": {\"x\": 0, \"y\": 4}, \"radius\": 0.3}"));
        ASSERT_TRUE(sim.world);
        ASSERT_TRUE(sim.step(240));
        EXPECT_NEAR(sim.position("ball").x, 0.0, 1e-6);
        EXPECT_NEAR(sim.position("ball").y, R * std::cos(kPi / n) + r, 2e-3);
    }
    // Inside: balls thrown about a clockwise ring at any speed stay inside
    // it; the same ring counter-clockwise lets them out.
    double closest = 1e9;
    for (const double speed : {1.0, 10.0, 30.0, 80.0}) {
        for (const double direction : {0.3, 1.9, 4.0}) {
            for (const bool cw : {true, false}) {
                const double R = 3.0, r = 0.2;
                Sim sim(level(chainEntity("ring", circlePoints(R, 64, cw), true, "\"restitution\": 0.8") +
                              ", {\"name\": \"ball\", \"position\": {\"x\": 0.5, \"y\": 0}, \"velocity\": " +
                              vectorJson(speed * std::cos(direction), speed * std::sin(direction)) +
                              ", \"radius\": 0.2, \"restitution\": 0.8}"));
                ASSERT_TRUE(sim.world);
                double farthest = 0.0;
                for (int i = 0; i < 180; ++i) {
                    ASSERT_TRUE(sim.step());
                    farthest = std::max(farthest, length(sim.position("ball")));
                }
                if (cw) {
                    // The centre never reaches the ring (the ball may sink
                    // into it for a step at the highest speeds), and ends
                    // within R - r of the centre plus the contacts' slop.
                    EXPECT_LT(farthest, R * std::cos(kPi / 64) - 0.1) << "speed " << speed << " direction " << direction;
                    EXPECT_LE(length(sim.position("ball")), R - r + 0.01) << "speed " << speed;
                    closest = std::min(closest, R - r - farthest);
                } else {
                    EXPECT_GT(farthest, R + 1.0) << "speed " << speed << " direction " << direction;
                }
            }
        }
    }
    std::printf("clockwise ring: the ball's centre went at most %.3g m past R - r\n", -closest);
}

TEST(ChainWorld, RestHeightsOfEveryKindOnAFlatChain) {
    // Each kind dropped onto a chain of short segments at several places
    // (on a joint, mid-segment): rests at its analytic height.
    struct Piece {
        std::string json;
        double height;  ///< of its position above the floor at rest
    };
    const std::vector<Piece> pieces = {
        {"\"radius\": 0.3", 0.3},
        {"\"box\": {\"width\": 0.8, \"height\": 0.4}", 0.2},
        {"\"capsule\": {\"a\": {\"x\": -0.4, \"y\": 0.1}, \"b\": {\"x\": 0.4, \"y\": 0.1}, \"radius\": 0.15}", 0.05},
        {"\"polygon\": {\"vertices\": [{\"x\": -0.4, \"y\": -0.2}, {\"x\": 0.4, \"y\": -0.2}, {\"x\": 0.2, \"y\": "
         "0.3}, {\"x\": -0.3, \"y\": 0.2}]}",
         0.2},
    };
    double worst = 0.0, worstShift = 0.0, worstTilt = 0.0;
    for (const Piece& piece : pieces) {
        for (const double x : {0.0, 0.125, 0.37}) {
            for (const double segment : {0.25, 1.0}) {
                Sim sim(level(chainEntity("floor", flatFloor(4.0, -4.0, segment), false) +
                              ", {\"name\": \"body\", \"position\": " + vectorJson(x, piece.height + 0.3) + ", " + piece.json +
                              "}"));
                ASSERT_TRUE(sim.world);
                ASSERT_TRUE(sim.step(180));
                const double error = sim.position("body").y - piece.height;
                EXPECT_NEAR(error, 0.0, 1.5e-3) << piece.json << " at " << x << " segment " << segment;
                // Landing on several segments' manifolds at once, solved
                // one after another, shifts and tilts a flat body a little.
                EXPECT_NEAR(sim.position("body").x, x, 0.02) << piece.json;
                EXPECT_NEAR(sim.angle("body"), 0.0, 2e-3) << piece.json;
                worst = std::max(worst, std::abs(error));
                worstShift = std::max(worstShift, std::abs(sim.position("body").x - x));
                worstTilt = std::max(worstTilt, std::abs(sim.angle("body")));
            }
        }
    }
    std::printf("rest heights on a chain: worst error %.3g m, sideways shift %.3g m, tilt %.3g rad\n", worst,
                worstShift, worstTilt);
}

TEST(ChainWorld, ResumesBitForBitFromAMidRunSave) {
    // Bodies rolling and sliding over a hilly chain into a clockwise bowl:
    // 150 steps, save, load, 150 steps == 300 steps, byte for byte. The
    // warm start of each segment's contacts comes back to that segment.
    std::vector<Vec2> hills;
    for (int i = 0; i <= 40; ++i) {
        const double x = 8.0 - 0.4 * i;
        hills.push_back({x, 0.4 * std::sin(0.9 * x)});
    }
    const std::string text = level(
        chainEntity("hills", hills, false, "\"friction\": 0.5") + ", " +
        "{\"name\": \"bowl\", \"static\": true, \"position\": {\"x\": -10, \"y\": 0}, " +
        chainJson(circlePoints(2.0, 40, true), true) + "}, " +
        "{\"name\": \"ball\", \"position\": {\"x\": 6, \"y\": 2}, \"velocity\": {\"x\": -3, \"y\": 0}, \"radius\": "
        "0.3}, "
        "{\"name\": \"crate\", \"position\": {\"x\": 4, \"y\": 1.5}, \"velocity\": {\"x\": -2, \"y\": 0}, \"box\": "
        "{\"width\": 0.5, \"height\": 0.4}}, "
        "{\"name\": \"pill\", \"position\": {\"x\": 2, \"y\": 1.5}, \"angle\": 0.4, \"capsule\": {\"a\": {\"x\": "
        "-0.3, \"y\": 0}, \"b\": {\"x\": 0.3, \"y\": 0}, \"radius\": 0.15}}, "
        "{\"name\": \"pebble\", \"position\": {\"x\": -10.5, \"y\": 0.5}, \"radius\": 0.2}, "
        "{\"name\": \"brick\", \"position\": {\"x\": -9.5, \"y\": 0}, \"box\": {\"width\": 0.6, \"height\": 0.3}}");
    Sim whole(text);
    ASSERT_TRUE(whole.step(300));
    Sim first(text);
    ASSERT_TRUE(first.step(150));
    ASSERT_TRUE(first.scene.solverState.has_value());
    bool segmentBeyondFirst = false;
    for (const ContactImpulse& c : first.scene.solverState->contacts)
        segmentBeyondFirst = segmentBeyondFirst || (c.feature >> kChainFeatureShift) > 0;
    EXPECT_TRUE(segmentBeyondFirst);
    Sim second(sceneToJsonText(first.scene));
    ASSERT_TRUE(second.step(150));
    EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene));
    EXPECT_FALSE(whole.world->contacts().empty());
}

TEST(ChainWorld, AJointToAChainLeavesOutEverySegmentUnlessCollideConnected) {
    // A ball tied to the chain's body by a slack rope, above the chain's
    // second segment: with collide_connected false it meets no segment of
    // the chain (not only the first) and falls through; with true it rests.
    for (const bool connected : {false, true}) {
        Sim sim(level(chainEntity("ground", flatFloor(4.0, -4.0, 1.0), false) +
                      ", {\"name\": \"ball\", \"position\": {\"x\": 2.5, \"y\": 0.5}, \"radius\": 0.25}, "
                      "{\"name\": \"tether\", \"joint\": {\"type\": \"rope\", \"a\": \"ball\", \"b\": \"ground\", "
                      "\"length\": 5, \"collide_connected\": " +
                      std::string(connected ? "true" : "false") + "}}"));
        ASSERT_TRUE(sim.world);
        ASSERT_TRUE(sim.step(40));
        if (connected) EXPECT_NEAR(sim.position("ball").y, 0.25, 2e-3);
        else EXPECT_LT(sim.position("ball").y, -0.5);
    }
}

TEST(ChainWorld, ABallRollsOverBentJointsKeepingItsEnergy) {
    // A ball rolling down a valley and over a hump, each a smooth curve cut
    // into short segments (bent joints, concave and convex): it stays on
    // the surface (no hop at a joint) and its energy, m g y + m v^2/2 +
    // I w^2/2, stays what it started with.
    double worstLoss = 0.0, worstGap = 0.0;
    for (const double segment : {0.1, 0.25}) {
        for (const int substeps : {1, 4}) {
            // y(x) = 0.3 cos(pi x / 4) + x^2 / 16 for x in [-5, 5]: a hump
            // in the middle of a valley, drawn right to left; the ball
            // starts at rest on the left slope, 0.23 m above the hump's top.
            std::vector<Vec2> points;
            const int n = int(std::llround(10.0 / segment));
            for (int i = 0; i <= n; ++i) {
                const double x = 5.0 - 10.0 * i / n;
                points.push_back({x, 0.3 * std::cos(kPi * x / 4.0) + x * x / 16.0});
            }
            const double r = 0.2;
            const auto surface = [&](double x) { return 0.3 * std::cos(kPi * x / 4.0) + x * x / 16.0; };
            const double x0 = -3.6;
            // Start 2 mm off the slope along its normal: it settles in a step.
            const double slope = -0.3 * kPi / 4.0 * std::sin(kPi * x0 / 4.0) + x0 / 8.0;
            const Vec2 normal = Vec2{-slope, 1.0} / std::sqrt(1.0 + slope * slope);
            const Vec2 start = Vec2{x0, surface(x0)} + (r + 0.002) * normal;
            Sim sim(level(chainEntity("valley", points, false, "\"friction\": 1") +
                              ", {\"name\": \"ball\", \"position\": " + vectorJson(start.x, start.y) +
                              ", \"radius\": 0.2, \"friction\": 1}",
                          "\"substeps\": " + std::to_string(substeps)));
            ASSERT_TRUE(sim.world);
            const double m = 1.0, inertia = 0.5 * m * r * r;
            const auto energy = [&] {
                const Vec2 v = sim.velocity("ball");
                const double w = sim.angularVelocity("ball");
                return m * kG * sim.position("ball").y + 0.5 * m * lengthSquared(v) + 0.5 * inertia * w * w;
            };
            ASSERT_TRUE(sim.step(2));
            const double e0 = energy();
            double lowest = e0, farthest = x0;
            for (int i = 0; i < 240; ++i) {
                ASSERT_TRUE(sim.step());
                lowest = std::min(lowest, energy());
                farthest = std::max(farthest, sim.position("ball").x);
                // Distance from the centre to the polyline: r, give or take
                // the contact's softness.
                const Vec2 p = sim.position("ball");
                double d = 1e9;
                for (std::size_t k = 0; k + 1 < points.size(); ++k) {
                    const Vec2 a = points[k], e = points[k + 1] - a;
                    const double u = std::clamp(dot(p - a, e) / lengthSquared(e), 0.0, 1.0);
                    d = std::min(d, length(p - (a + u * e)));
                }
                worstGap = std::max(worstGap, std::abs(d - r));
                ASSERT_NEAR(d, r, 3e-3) << "segment " << segment << " substeps " << substeps << " step " << i;
            }
            // It went over the hump: its energy was enough and stayed.
            worstLoss = std::max(worstLoss, (e0 - lowest) / (e0 - m * kG * (surface(0.0) + r)));
            // What a polyline must take: crossing a concave joint turns the
            // velocity by the joint's angle a, an inelastic turn that keeps
            // cos(a) of the speed along the new segment (a convex joint is
            // rolled round, losing nothing).
            EXPECT_LT(e0 - lowest, 0.04 * (e0 - m * kG * (surface(0.0) + r)))
                << "segment " << segment << " substeps " << substeps;
            EXPECT_GT(farthest, 2.0) << "over the hump and up the far slope";
            std::printf("segment %g substeps %d: lost %.3g J of %.3g J above the hump's top\n", segment, substeps,
                        e0 - lowest, e0 - m * kG * (surface(0.0) + r));
        }
    }
    std::printf("rolling over bent joints: worst energy lost %.3g of the energy above the hump's top, worst gap "
                "from r %.3g m\n",
                worstLoss, worstGap);
}

// ---- chains on kinematic bodies: moving terrain ----------------------------

/// A kinematic chain entity named `name` at `at`, moving with `velocity`
/// and spinning at `spin`.
std::string movingChain(const std::string& name, const std::vector<Vec2>& points, bool loop, Vec2 velocity,
                        double spin, const std::string& extra = "", Vec2 at = {}) {
    return "{\"name\": \"" + name + "\", \"kinematic\": true, \"position\": " + vectorJson(at.x, at.y) +
           ", \"velocity\": " +
           vectorJson(velocity.x, velocity.y) + ", \"angular_velocity\": " + exactNumber(spin) + ", " +
           (extra.empty() ? "" : extra + ", ") + chainJson(points, loop) + "}";
}

// A conveyor: a flat kinematic chain moving at u carries a crate set on it
// at rest. Friction (mu g) brings it to u after slipping u^2 / (2 mu g)
// behind the belt, and a disc set on it ends rolling at u / 3 (its contact
// point moving with the belt). Swept over belt speeds and substeps.
TEST(ChainKinematic, AConveyorCarriesACrateAndRollsADisc) {
    for (const double u : {0.5, 2.0, 6.0})
        for (const std::string substeps : {"1", "2", "4", "8", ""}) {
            SCOPED_TRACE("belt " + exactNumber(u) + " m/s, substeps " + (substeps.empty() ? "default" : substeps));
            const std::string world = substeps.empty() ? "" : "\"substeps\": " + substeps;
            const std::string text =
                level(movingChain("belt", flatFloor(40.0, -40.0, 2.0), false, {u, 0.0}, 0.0, "\"friction\": 0.8") +
                          ", {\"name\": \"crate\", \"position\": {\"x\": 0, \"y\": 0.5}, \"box\": {\"width\": 1, "
                          "\"height\": 1}, \"friction\": 0.8}, {\"name\": \"disc\", \"position\": {\"x\": -4, \"y\": "
                          "0.3}, \"radius\": 0.3, \"friction\": 0.8}",
                      world);
            Sim sim(text);
            ASSERT_TRUE(sim.step(120));  // 2 s: both settle well within it
            const Registry& reg = sim.scene.registry;
            const Entity crate = named(sim.scene, "crate"), disc = named(sim.scene, "disc"), belt = named(sim.scene, "belt");
            const double beltX = reg.tryGet<Position>(belt)->value.x;
            EXPECT_NEAR(beltX, 2.0 * u, 1e-9) << "contacts never move a kinematic body";
            EXPECT_NEAR(reg.tryGet<Velocity>(crate)->value.x, u, 1e-3 * u);
            const double slip = u * u / (2.0 * 0.8 * kG);
            EXPECT_NEAR(beltX - reg.tryGet<Position>(crate)->value.x, slip, 0.1 * slip + 0.01);
            EXPECT_NEAR(reg.tryGet<Position>(crate)->value.y, 0.5, 0.005) << "resting on the belt";
            EXPECT_NEAR(reg.tryGet<Velocity>(disc)->value.x, u / 3.0, 0.01 * u);
            EXPECT_NEAR(reg.tryGet<Position>(disc)->value.y, 0.3, 0.005);
        }
}

// A drum: a clockwise loop chain on a kinematic body spinning about its
// centre keeps a disc and a box inside (one-sided, turning with the body)
// at every speed, and the chain carries them up the rising side.
TEST(ChainKinematic, ASpinningDrumKeepsItsLoadInside) {
    const double R = 3.0;
    for (const double spin : {0.5, 2.0, 6.0, -3.0}) {
        SCOPED_TRACE("spin " + exactNumber(spin) + " rad/s");
        const std::string text =
            level(movingChain("drum", circlePoints(R, 48, true), true, {0.0, 0.0}, spin, "\"friction\": 0.9") +
                  ", {\"name\": \"disc\", \"position\": {\"x\": 0, \"y\": -2.4}, \"radius\": 0.5, \"friction\": "
                  "0.9}, {\"name\": \"crate\", \"position\": {\"x\": 1, \"y\": -2.3}, \"box\": {\"width\": 0.6, "
                  "\"height\": 0.6}, \"friction\": 0.9}");
        Sim sim(text);
        double farthest = 0.0, sideways = 0.0;
        ASSERT_TRUE(sim.step(600, [&] {
            sim.world->writeBack(sim.scene);
            for (const char* name : {"disc", "crate"}) {
                const Vec2 p = sim.scene.registry.tryGet<Position>(named(sim.scene, name))->value;
                farthest = std::max(farthest, length(p));
                if (std::string(name) == "disc") sideways = std::max(sideways, std::abs(p.x));
            }
        }));
        // The disc's centre stays 0.5 m in from the 48-gon's flats (2.995 m
        // from the centre), the box's corners in too (its centre within
        // R - 0.3 and a little for the soft contact).
        EXPECT_LT(farthest, R - 0.29);
        EXPECT_NEAR(sim.scene.registry.tryGet<Angle>(named(sim.scene, "drum"))->value, spin * 10.0, 1e-9);
        EXPECT_GT(sideways, 0.3) << "the turning drum carries the disc up its side";
    }
}

// A run with bodies on a moving chain resumes bit for bit from a save.
TEST(ChainKinematic, ResumesBitForBitFromAMidRunSave) {
    const std::string text = level(
        movingChain("belt", flatFloor(20.0, -20.0, 1.0), false, {1.5, 0.0}, 0.0, "\"friction\": 0.6") + ", " +
        movingChain("drum", circlePoints(2.0, 40, true), true, {0.0, 0.0}, 1.5, "\"friction\": 0.6", {-30.0, 5.0}) +
        ", {\"name\": \"crate\", \"position\": {\"x\": 3, \"y\": 0.3}, \"box\": {\"width\": 0.6, \"height\": 0.6}}"
        ", {\"name\": \"ball\", \"position\": {\"x\": -30, \"y\": 3.5}, \"radius\": 0.3}");
    Sim whole(text);
    ASSERT_TRUE(whole.step(200));
    Sim first(text);
    ASSERT_TRUE(first.step(100));
    ASSERT_TRUE(first.scene.solverState.has_value());
    Sim second(sceneToJsonText(first.scene));
    ASSERT_TRUE(second.step(100));
    EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene));
}

