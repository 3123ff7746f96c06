// Rounded polygons (polygon.radius): the format (absent stays absent, a
// byte-stable round trip, exact refusals), mass properties against a
// numerical integration of the rounded outline, the narrow phase against
// every kind in both orders, and whole-world runs with analytic answers:
// rest heights of rounded boxes on every support, a heavily rounded
// triangle rolling down a slope like a disc, and exact save/resume.

#include "collision/narrow_phase.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <algorithm>
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

std::string polygonJson(const std::vector<Vec2>& v, double radius) {
    std::string out = "\"polygon\": {\"vertices\": [";
    for (std::size_t i = 0; i < v.size(); ++i) out += (i ? ", " : "") + vectorJson(v[i].x, v[i].y);
    return out + "], \"radius\": " + exactNumber(radius) + "}";
}

std::vector<Vec2> rectangle(double w, double h) { return {{-w / 2, -h / 2}, {w / 2, -h / 2}, {w / 2, h / 2}, {-w / 2, h / 2}}; }

/// Distance from p to the outline's core (0 inside it).
double distanceToPolygon(const std::vector<Vec2>& v, Vec2 p) {
    bool inside = true;
    double best = 1e300;
    for (std::size_t i = 0; i < v.size(); ++i) {
        const Vec2 a = v[i], e = v[(i + 1) % v.size()] - a;
        inside = inside && cross(e, p - a) >= 0.0;
        const double u = std::clamp(dot(p - a, e) / lengthSquared(e), 0.0, 1.0);
        best = std::min(best, length(p - (a + u * e)));
    }
    return inside ? 0.0 : best;
}

} // namespace

// ------------------------------------------------------------ format

TEST(RoundedPolygonFormat, RadiusRoundTripsAndStaysAbsentWhenAbsent) {
    const std::string text = level(
        "{\"name\": \"soap\", \"position\": {\"x\": 0, \"y\": 1}, " + polygonJson(rectangle(1, 0.5), 0.1) +
        "}, {\"name\": \"zero\", \"position\": {\"x\": 2, \"y\": 1}, " + polygonJson(rectangle(1, 0.5), 0) +
        "}, {\"name\": \"sharp\", \"position\": {\"x\": 4, \"y\": 1}, \"polygon\": {\"vertices\": [{\"x\": 0, "
        "\"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 0, \"y\": 1}]}}");
    Result<Scene> first = parseScene(text, "t.json");
    ASSERT_TRUE(first) << first.error();
    const std::string saved = sceneToJsonText(*first);
    Result<Scene> second = parseScene(saved, "saved.json");
    ASSERT_TRUE(second) << second.error();
    EXPECT_EQ(sceneToJsonText(*second), saved);
    EXPECT_EQ(second->registry.tryGet<Polygon>(named(*second, "soap"))->radius, 0.1);
    // A radius written as 0 is kept as written; none written stays none.
    EXPECT_EQ(second->registry.tryGet<Polygon>(named(*second, "zero"))->radius, 0.0);
    EXPECT_FALSE(second->registry.tryGet<Polygon>(named(*second, "sharp"))->radius.has_value());
    const std::size_t sharp = saved.find("\"sharp\"");
    ASSERT_NE(sharp, std::string::npos);
    EXPECT_EQ(saved.find("radius", sharp), std::string::npos);
}

TEST(RoundedPolygonFormat, ANegativeOrBadRadiusIsRefused) {
    EXPECT_EQ(loadError(level("{\"name\": \"soap\", \"position\": {\"x\": 0, \"y\": 0}, " +
                              polygonJson(rectangle(1, 1), -0.1) + "}")),
              "t.json: error: /entities/0/polygon/radius: expected a number in [0, 1e+30], got -0.1");
    EXPECT_EQ(loadError(level("{\"name\": \"soap\", \"position\": {\"x\": 0, \"y\": 0}, \"polygon\": {\"vertices\": "
                              "[{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 0, \"y\": 1}], \"radius\": "
                              "\"round\"}}")),
              "t.json: error: /entities/0/polygon/radius: expected a number in [0, 1e+30], got \"round\"");
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {"soap"});
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    Polygon p;
    p.radius = -1.0;
    s.registry.emplace<Polygon>(e, p);
    Result<World> w = World::build(s);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error(), "entity 0 (\"soap\"): polygon.radius: expected a number in [0, 1e+30], got -1");
}

// ------------------------------------------------------------ mass properties

TEST(RoundedPolygonMass, AreaCentroidAndInertiaMatchANumericalIntegration) {
    // Midpoint rule on a fine grid over the rounded outline (inside when
    // within r of the core), against polygonMassProperties(v, r).
    struct Case {
        std::vector<Vec2> v;
        double r;
    };
    const std::vector<Case> cases = {
        {rectangle(1.0, 1.0), 0.2},
        {rectangle(2.0, 0.5), 0.05},
        {{{0.0, 0.0}, {1.5, 0.2}, {0.3, 1.1}}, 0.3},  // off-centre: the rounding moves the centroid
        {{{1.0, 1.0}, {1.4, 1.0}, {1.6, 1.3}, {1.2, 1.7}, {0.9, 1.4}}, 0.5},
    };
    for (const Case& c : cases) {
        Vec2 lo = c.v[0], hi = c.v[0];
        for (const Vec2 p : c.v) {
            lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
            hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
        }
        lo -= Vec2{c.r, c.r};
        hi += Vec2{c.r, c.r};
        const int n = 1500;
        const double dx = (hi.x - lo.x) / n, dy = (hi.y - lo.y) / n;
        double area = 0.0, polar = 0.0;
        Vec2 first;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const Vec2 p{lo.x + (i + 0.5) * dx, lo.y + (j + 0.5) * dy};
                if (distanceToPolygon(c.v, p) > c.r) continue;
                area += dx * dy;
                first += (dx * dy) * p;
                polar += dx * dy * lengthSquared(p);
            }
        const Vec2 centroid = first / area;
        const double second = polar - area * lengthSquared(centroid);
        const PolygonMassProperties props = polygonMassProperties(c.v, c.r);
        // The perimeter term: A + P r + pi r^2 exactly.
        double perimeter = 0.0;
        for (std::size_t i = 0; i < c.v.size(); ++i) perimeter += length(c.v[(i + 1) % c.v.size()] - c.v[i]);
        EXPECT_NEAR(props.area, polygonMassProperties(c.v).area + perimeter * c.r + kPi * c.r * c.r, 1e-12);
        EXPECT_NEAR(props.area, area, 2e-3 * area);
        EXPECT_NEAR(props.centroid.x, centroid.x, 2e-3);
        EXPECT_NEAR(props.centroid.y, centroid.y, 2e-3);
        EXPECT_NEAR(props.secondMoment, second, 3e-3 * second);
    }
    // Radius 0: the sharp polygon's numbers, bit for bit.
    const std::vector<Vec2> tri{{0.0, 0.0}, {1.5, 0.2}, {0.3, 1.1}};
    const PolygonMassProperties sharp = polygonMassProperties(tri), zero = polygonMassProperties(tri, 0.0);
    EXPECT_EQ(sharp.area, zero.area);
    EXPECT_EQ(sharp.centroid, zero.centroid);
    EXPECT_EQ(sharp.secondMoment, zero.secondMoment);
}

TEST(RoundedPolygonMass, ARoundedSquareHasTheKnownSecondMoment) {
    // Square of side s rounded by r, about its centre: the square s^4/6,
    // four strips s r ((s^2 + r^2)/12 + (s/2 + r/2)^2), four quarter discs
    // pi r^2/4 each with r^2/2 about their apex plus the apex's distance
    // s/sqrt(2) and the cross term 2 (s/2,s/2).(4r/3pi)(1,1)/... summed:
    // pi r^4/2 + pi r^2 s^2/2 + (8/3) r^3 s.
    for (const double s : {0.5, 1.0, 3.0})
        for (const double r : {0.01, 0.25, 1.0}) {
            const double expected = std::pow(s, 4) / 6.0 + 4.0 * s * r * ((s * s + r * r) / 12.0 + std::pow(0.5 * (s + r), 2)) +
                                    kPi * std::pow(r, 4) / 2.0 + kPi * r * r * s * s / 2.0 + 8.0 / 3.0 * r * r * r * s;
            const PolygonMassProperties p = polygonMassProperties(rectangle(s, s), r);
            EXPECT_NEAR(p.secondMoment, expected, 1e-12 * expected) << s << " " << r;
            EXPECT_NEAR(p.area, s * s + 4.0 * s * r + kPi * r * r, 1e-12);
            EXPECT_NEAR(p.centroid.x, 0.0, 1e-14);
        }
}

// ------------------------------------------------------------ narrow phase

TEST(RoundedPolygonNarrowPhase, EveryKindInBothOrdersSeesTheRoundedSurface) {
    // A unit square rounded by 0.2 at the origin; each other shape placed
    // with its lowest point a gap above the rounded top face (y = 0.7), and
    // against the rounded corner along the diagonal.
    static const Vec2 square[4] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    ConvexPolygon rounded = ConvexPolygon::fromVertices(square, 4);
    rounded.cornerRadius = 0.2;
    ConvexPolygon sharpSmall = ConvexPolygon::fromVertices(square, 4);
    Shape a;
    a.kind = ShapeKind::Polygon;
    a.polygon = &rounded;
    Shape circle;
    circle.kind = ShapeKind::Circle;
    circle.radius = 0.3;
    Shape box;
    box.kind = ShapeKind::Box;
    box.halfExtents = {0.3, 0.3};
    Shape polygon;
    polygon.kind = ShapeKind::Polygon;
    polygon.polygon = &sharpSmall;  // half extent 0.5
    Shape roundedToo = a;  // half extent 0.5 + 0.2
    Shape capsule;
    capsule.kind = ShapeKind::Capsule;
    capsule.halfExtents = {0.4, 0.0};
    capsule.radius = 0.3;
    struct Other {
        const Shape* shape;
        double below;  ///< from its centre down to its lowest point
    };
    for (const Other& o : {Other{&circle, 0.3}, Other{&box, 0.3}, Other{&polygon, 0.5}, Other{&roundedToo, 0.7},
                           Other{&capsule, 0.3}}) {
        for (const double gap : {-0.01, 0.0, 0.004}) {
            for (const double x : {0.0, 0.3}) {
                const Vec2 pB{x, 0.7 + o.below + gap};
                const Manifold m = collide(a, {}, {}, *o.shape, pB, {}, 0.02);
                const Manifold f = collide(*o.shape, pB, {}, a, {}, {}, 0.02);
                ASSERT_GT(m.pointCount, 0);
                ASSERT_EQ(m.pointCount, f.pointCount);
                EXPECT_NEAR(m.normal.y, 1.0, 1e-12);
                EXPECT_NEAR(f.normal.y, -1.0, 1e-12);
                double deepest = 1e9;
                for (int i = 0; i < m.pointCount; ++i) {
                    deepest = std::min(deepest, m.points[i].separation);
                    // Midway between the surfaces.
                    EXPECT_NEAR(m.points[i].point.y, 0.7 + 0.5 * m.points[i].separation, 1e-9);
                }
                EXPECT_NEAR(deepest, gap, 1e-12);
            }
        }
    }
    // The plane under it: the rounded bottom at -0.7.
    Shape plane;
    plane.kind = ShapeKind::Plane;
    plane.normal = {0.0, 1.0};
    plane.offset = -0.71;
    const Manifold m = collide(plane, {}, {}, a, {}, {}, 0.02);
    ASSERT_EQ(m.pointCount, 2);
    EXPECT_NEAR(m.points[0].separation, 0.01, 1e-12);
    EXPECT_NEAR(m.points[0].point.y, -0.705, 1e-12);
    // A circle off the corner along the diagonal: the corner's arc.
    const Vec2 corner{0.5, 0.5}, diagonal = Vec2{1.0, 1.0} / std::sqrt(2.0);
    const Manifold c = collide(a, {}, {}, circle, corner + (0.2 + 0.3 + 0.003) * diagonal, {}, 0.02);
    ASSERT_EQ(c.pointCount, 1);
    EXPECT_NEAR(c.points[0].separation, 0.003, 1e-12);
    EXPECT_NEAR(c.normal.x, diagonal.x, 1e-12);
    // Two rounded squares corner to corner: one point on the diagonal.
    const Manifold cc = collide(a, {}, {}, roundedToo, Vec2{1.0, 1.0} + (0.4 + 0.003) * diagonal, {}, 0.02);
    ASSERT_EQ(cc.pointCount, 1);
    EXPECT_NEAR(cc.points[0].separation, 0.003, 1e-12);
    EXPECT_NEAR(cc.normal.x, diagonal.x, 1e-12);
}

// ------------------------------------------------------------ world runs

TEST(RoundedPolygonWorld, ARoundedBoxRestsAtHalfHeightPlusRadiusOnEverySupport) {
    double worst = 0.0;
    int cases = 0;
    const std::vector<std::pair<std::string, double>> supports = {
        {"{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}", 0.0},
        {"{\"name\": \"floor\", \"static\": true, \"position\": {\"x\": 0, \"y\": -0.5}, \"box\": {\"width\": 8, "
         "\"height\": 1}}",
         0.0},
        {"{\"name\": \"floor\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, \"chain\": {\"points\": [{\"x\": "
         "4, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 0.2, \"y\": 0}, {\"x\": -4, \"y\": 0}]}}",
         0.0},
        {"{\"name\": \"floor\", \"static\": true, \"position\": {\"x\": 0, \"y\": -0.6}, " +
             polygonJson(rectangle(8, 1), 0.1) + "}",
         0.0},
    };
    for (const auto& [support, top] : supports)
        for (const double r : {0.02, 0.1, 0.3})
            for (const double h : {0.2, 0.6})
                for (const int substeps : {1, 4}) {
                    Sim sim(level(support + ", {\"name\": \"soap\", \"position\": " + vectorJson(0.1, h / 2 + r + 0.2) +
                                      ", " + polygonJson(rectangle(0.8, h), r) + "}",
                                  "\"substeps\": " + std::to_string(substeps)));
                    ASSERT_TRUE(sim.world);
                    ASSERT_TRUE(sim.step(240));
                    const double error = sim.position("soap").y - (top + h / 2 + r);
                    EXPECT_NEAR(error, 0.0, 1.5e-3) << support << " r " << r << " h " << h;
                    EXPECT_NEAR(sim.angle("soap"), 0.0, 1e-3) << support << " r " << r;
                    worst = std::max(worst, std::abs(error));
                    ++cases;
                }
    // Two rounded boxes stacked: their rest heights add.
    for (const double r : {0.05, 0.2}) {
        Sim sim(level("{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}, "
                      "{\"name\": \"low\", \"position\": " +
                      vectorJson(0, 0.2 + r + 0.05) + ", " + polygonJson(rectangle(1.2, 0.4), r) +
                      "}, {\"name\": \"high\", \"position\": " + vectorJson(0, 0.4 + 2 * r + 0.15 + r + 0.1) + ", " +
                      polygonJson(rectangle(0.8, 0.3), r) + "}",
                      "\"substeps\": 4"));
        ASSERT_TRUE(sim.step(300));
        EXPECT_NEAR(sim.position("low").y, 0.2 + r, 1.5e-3);
        EXPECT_NEAR(sim.position("high").y, 0.4 + 2 * r + 0.15 + r, 2e-3);
    }
    std::printf("rounded boxes at rest: %d cases, worst height error %.3g m\n", cases, worst);
}

TEST(RoundedPolygonWorld, AHeavilyRoundedTriangleRollsDownASlopeLikeADisc) {
    // A 5 mm triangle rounded by 0.3 m is nearly a disc of 0.3 m (its
    // inertia too): rolling without slipping down a static slope it gains
    // (2/3) g sin(theta) like a disc, and keeps pace with one (within 5%:
    // its three 5 mm flats each take a little of its speed as they land); a
    // sharp square of the same size does not roll at all.
    for (const double theta : {0.15, 0.3}) {
        const double c = std::cos(theta), s = std::sin(theta);
        const std::string slope = "{\"name\": \"slope\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, "
                                  "\"angle\": " +
                                  exactNumber(-theta) + ", \"box\": {\"width\": 40, \"height\": 1}, \"friction\": 1}";
        // Start where each touches the slope's top face (y = 0.5 in its frame).
        const auto on = [&](double along, double above) {
            return vectorJson(c * along + s * (0.5 + above), -s * along + c * (0.5 + above));
        };
        const double tiny = 0.005;
        const std::vector<Vec2> tri{{-tiny / 2, -tiny / 3}, {tiny / 2, -tiny / 3}, {0, 2 * tiny / 3}};
        Sim sim(level(slope + ", {\"name\": \"pebble\", \"position\": " + on(-5, 0.3 + tiny / 3) +
                          ", \"angle\": " + exactNumber(-theta) + ", " + polygonJson(tri, 0.3) +
                          ", \"friction\": 1}, {\"name\": \"disc\", \"position\": " + on(-9, 0.3) +
                          ", \"radius\": 0.3, \"friction\": 1}, {\"name\": \"sharp\", \"position\": " +
                          on(-1, 0.3) + ", \"angle\": " + exactNumber(-theta) + ", " +
                          polygonJson(rectangle(0.6, 0.6), 0) + ", \"friction\": 1}",
                      "\"substeps\": 4"));
        ASSERT_TRUE(sim.world);
        const Vec2 start = sim.position("pebble"), discStart = sim.position("disc"), sharpStart = sim.position("sharp");
        ASSERT_TRUE(sim.step(60));
        const double t = 1.0, expected = 0.5 * (2.0 / 3.0) * kG * s * t * t;
        const double travelled = length(sim.position("pebble") - start);
        EXPECT_NEAR(travelled, expected, 0.05 * expected) << theta;
        EXPECT_NEAR(travelled, length(sim.position("disc") - discStart), 0.05 * expected) << theta;
        EXPECT_LT(length(sim.position("sharp") - sharpStart), 0.01) << theta;
        std::printf("slope %.2f rad: rounded triangle %.4f m, disc %.4f m, analytic %.4f m, sharp square %.2g m\n",
                    theta, travelled, length(sim.position("disc") - discStart), expected,
                    length(sim.position("sharp") - sharpStart));
    }
}

TEST(RoundedPolygonWorld, ResumesBitForBitFromAMidRunSave) {
    const std::string text = level(
        "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}, "
        "{\"name\": \"hill\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, \"chain\": {\"points\": [{\"x\": "
        "3, \"y\": 0}, {\"x\": 1, \"y\": 0.6}, {\"x\": -1, \"y\": 0.2}, {\"x\": -3, \"y\": 0}]}}, "
        "{\"name\": \"a\", \"position\": {\"x\": 1.5, \"y\": 2}, \"angle\": 0.3, \"angular_velocity\": 2, " +
        polygonJson(rectangle(0.6, 0.3), 0.1) + "}, {\"name\": \"b\", \"position\": {\"x\": 1.2, \"y\": 3}, " +
        polygonJson({{0, 0}, {0.5, 0.1}, {0.2, 0.4}}, 0.05) +
        "}, {\"name\": \"c\", \"position\": {\"x\": -1, \"y\": 2}, \"radius\": 0.2}, "
        "{\"name\": \"d\", \"position\": {\"x\": -0.8, \"y\": 3}, \"box\": {\"width\": 0.4, \"height\": 0.4}}, "
        "{\"name\": \"e\", \"position\": {\"x\": 0.3, \"y\": 2.5}, \"capsule\": {\"a\": {\"x\": -0.3, \"y\": 0}, "
        "\"b\": {\"x\": 0.3, \"y\": 0}, \"radius\": 0.1}}");
    Sim whole(text);
    ASSERT_TRUE(whole.step(300));
    Sim first(text);
    ASSERT_TRUE(first.step(150));
    Sim second(sceneToJsonText(first.scene));
    ASSERT_TRUE(second.step(150));
    EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene));
    EXPECT_FALSE(whole.world->contacts().empty());
}
