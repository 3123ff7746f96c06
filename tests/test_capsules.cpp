// Capsule shapes: the format's checks with their exact messages, mass
// properties against an independent integration, the narrow phase for every
// pair that involves a capsule (both orders), and whole-world runs with
// analytic answers: rest heights over every pair of shape kinds, swept over
// sizes and mass ratios; a capsule on its side lying still; sliding down a
// slope at g (sin - mu cos); and exact save/resume.

#include "collision/collision_system.hpp"
#include "collision/narrow_phase.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
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
    return "{\"world\": {" + (world.empty() ? std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}") : world) +
           "}, \"entities\": [" + entities + "]}";
}




std::string capsuleJson(Vec2 a, Vec2 b, double r) {
    return "\"capsule\": {\"a\": " + vectorJson(a.x, a.y) + ", \"b\": " + vectorJson(b.x, b.y) + ", \"radius\": " + exactNumber(r) + "}";
}

/// The centre of mass: the position, or a capsule's segment midpoint.
Vec2 centre(const test::Sim& sim, const std::string& name) {
    const Entity e = test::named(sim.scene, name);
    const Vec2 p = sim.position(name);
    const Capsule* c = sim.scene.registry.tryGet<Capsule>(e);
    if (!c) return p;
    const Vec2 mid = 0.5 * (c->a + c->b);
    const double th = sim.angle(name);
    return p + Vec2{std::cos(th) * mid.x - std::sin(th) * mid.y, std::sin(th) * mid.x + std::cos(th) * mid.y};
}
Shape capsuleShape(Vec2 halfSegment, double r) {
    Shape s;
    s.kind = ShapeKind::Capsule;
    s.halfExtents = halfSegment;
    s.radius = r;
    return s;
}

} // namespace

// ------------------------------------------------------------ format

TEST(CapsuleFormat, BadCapsulesAreRefusedNamingTheEntityAndField) {
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, " +
                              capsuleJson({1, 2}, {1, 2}, 0.5) + "}")),
              "t.json: error: /entities/0/capsule/b: entity 0 (\"pill\"): a and b are the same point {\"x\": 1, "
              "\"y\": 2}; a capsule needs a segment of non-zero length (a circle is the shape without one)");
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, " +
                              capsuleJson({0, 0}, {1, 0}, 0) + "}")),
              "t.json: error: /entities/0/capsule/radius: expected a number in [1e-30, 1e+30], got 0");
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, " +
                              capsuleJson({0, 0}, {1, 0}, -1) + "}")),
              "t.json: error: /entities/0/capsule/radius: expected a number in [1e-30, 1e+30], got -1");
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, \"radius\": 1, " +
                              capsuleJson({0, 0}, {1, 0}, 0.5) + "}")),
              "t.json: error: /entities/0: an entity has at most one shape (radius, box, polygon, capsule, chain or plane), "
              "got 2");
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", " + capsuleJson({0, 0}, {1, 0}, 0.5) + "}")),
              "t.json: error: /entities/0: component \"capsule\" on entity 0 (\"pill\") needs \"position\", which is "
              "missing");
    EXPECT_EQ(loadError(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, \"capsule\": {\"a\": {\"x\": "
                              "0, \"y\": 0}, \"b\": {\"x\": 1, \"y\": 0}, \"raduis\": 1}}")),
              "t.json: error: /entities/0/capsule/raduis: unknown field \"raduis\" in \"capsule\"; did you mean "
              "\"radius\"? Known fields: a, b, radius");
}

TEST(CapsuleFormat, TheWorldRefusesADegenerateCapsuleMadeInCode) {
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {"dot"});
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    s.registry.emplace<Capsule>(e, {{0.5, 0.5}, {0.5, 0.5}, 0.2});
    Result<World> w = World::build(s);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error(), "entity 0 (\"dot\"): capsule.b: a and b are the same point; a capsule needs a segment of "
                         "non-zero length");
}

TEST(CapsuleFormat, RoundTripsByteForByte) {
    const std::string text =
        level("{\"name\": \"a\", \"position\": {\"x\": 0.1, \"y\": 1e-300}, \"angle\": 0.3, " +
              capsuleJson({-0.3333333333333333, 0.1}, {0.7, 0.123456789012345678}, 0.1) +
              "}, {\"name\": \"b\", \"position\": {\"x\": 1e6, \"y\": -2}, \"static\": true, " +
              capsuleJson({0, 0}, {1e5, 0}, 3e4) + "}, {\"name\": \"c\", \"position\": {\"x\": 0, \"y\": 0}, " +
              capsuleJson({0, 0}, {1e-6, 0}, 1e-7) + "}");
    Result<Scene> first = parseScene(text, "t.json");
    ASSERT_TRUE(first) << first.error();
    const std::string saved = sceneToJsonText(*first);
    Result<Scene> second = parseScene(saved, "saved.json");
    ASSERT_TRUE(second) << second.error();
    EXPECT_EQ(sceneToJsonText(*second), saved);
    const Capsule* c = second->registry.tryGet<Capsule>(named(*second, "a"));
    ASSERT_NE(c, nullptr);
    EXPECT_EQ(c->a, (Vec2{-0.3333333333333333, 0.1}));
    EXPECT_EQ(c->b, (Vec2{0.7, 0.123456789012345678}));
    EXPECT_EQ(c->radius, 0.1);
}

TEST(CapsuleFormat, ValidateCountsACapsuleAsAShape) {
    // Friction and restitution on a capsule act (it collides): validate
    // notes nothing, where the same on a shapeless body is noted.
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "stepwise_capsule_validate";
    std::filesystem::create_directories(dir);
    const std::filesystem::path file = dir / "pill.json", err = dir / "err.txt";
    std::ofstream(file) << level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 1}, \"friction\": 0.5, "
                                 "\"restitution\": 0.3, " + capsuleJson({0, 0}, {1, 0}, 0.2) +
                                 "}, {\"name\": \"dot\", \"position\": {\"x\": 3, \"y\": 1}, \"friction\": 0.5}");
    const std::string command =
        std::string(STEPWISE_BINARY) + " validate " + file.string() + " >/dev/null 2>" + err.string();
    ASSERT_EQ(std::system(command.c_str()), 0);
    std::stringstream text;
    text << std::ifstream(err).rdbuf();
    EXPECT_EQ(text.str(), file.string() + ": warning: entity 1 (\"dot\"): \"friction\" has no effect: the entity has "
                                          "no shape, so it never collides\n");
    std::filesystem::remove_all(dir);
}

// ------------------------------------------------------------ mass properties

TEST(CapsuleMass, InertiaMatchesAnIndependentIntegrationOfTheStadium) {
    // The engine's formula (rectangle plus two half discs) against a
    // midpoint-rule integral of r^2 over the stadium's area, on a grid
    // fine enough for 1e-4 relative.
    for (const auto& [len, r] : {std::pair{1.0, 0.25}, std::pair{2.0, 0.5}, std::pair{0.1, 1.0}, std::pair{5.0, 0.05},
                                 std::pair{1.0, 1.0}}) {
        const double h = 0.5 * len;
        const int n = 1500;
        const double xMax = h + r, cellX = 2.0 * xMax / n, cellY = 2.0 * r / n;
        double area = 0.0, polar = 0.0;
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double x = -xMax + (i + 0.5) * cellX, y = -r + (j + 0.5) * cellY;
                const double dx = std::max(std::abs(x) - h, 0.0);
                if (dx * dx + y * y > r * r) continue;
                area += cellX * cellY;
                polar += cellX * cellY * (x * x + y * y);
            }
        const CapsuleMassProperties props = capsuleMassProperties(len, r);
        EXPECT_NEAR(props.area / (2.0 * r * len + kPi * r * r), 1.0, 1e-14) << len << " " << r;
        EXPECT_NEAR(area / props.area, 1.0, 2e-3) << len << " " << r;
        EXPECT_NEAR((polar / area) / props.inertiaPerMass, 1.0, 2e-3) << len << " " << r;
        // The collision side's inertia, whatever the segment's direction.
        for (const double dir : {0.0, 0.7, 2.0}) {
            const Shape s = capsuleShape({h * std::cos(dir), h * std::sin(dir)}, r);
            EXPECT_NEAR(momentOfInertia(s, 3.0) / (3.0 * props.inertiaPerMass), 1.0, 1e-12) << len << " " << r;
        }
        // Limits: a long thin capsule is a rod (m L^2 / 12), a short one a disc (m r^2 / 2).
    }
    EXPECT_NEAR(capsuleMassProperties(10.0, 1e-4).inertiaPerMass / (100.0 / 12.0), 1.0, 1e-4);
    EXPECT_NEAR(capsuleMassProperties(1e-6, 1.0).inertiaPerMass / 0.5, 1.0, 1e-5);
}

TEST(CapsuleMass, OffCentreCapsuleTurnsAboutItsMidpointAndGravityActsThere) {
    // Segment from (1, 0.5) to (3, 0.5): the centre of mass is (2, 0.5)
    // from the position. Spinning in free fall, the midpoint follows the
    // parabola; the energy's gravity term is the midpoint's height.
    for (const double spin : {2.0, -5.0}) {
        Sim r(level("{\"name\": \"pill\", \"position\": {\"x\": 0, \"y\": 0}, \"velocity\": {\"x\": 1, \"y\": 3}, "
                    "\"angular_velocity\": " + exactNumber(spin) + ", \"mass\": 2, " + capsuleJson({1, 0.5}, {3, 0.5}, 0.3) +
                    "}",
                    "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"dt\": 0.01, \"substeps\": 2"));
        ASSERT_TRUE(r.step(100));
        const double t = 1.0;
        EXPECT_NEAR(r.angle("pill"), spin * t, 1e-12);
        const Vec2 c = centre(r, "pill");
        EXPECT_NEAR(c.x, 2.0 + 1.0 * t, 1e-9) << spin;
        // Semi-implicit Euler's free-fall error: g dt t / 2 = 0.049 m in y.
        EXPECT_NEAR(c.y, 0.5 + 3.0 * t - 0.5 * kG * t * t, 0.06) << spin;
        EXPECT_NEAR(r.velocity("pill").x, 1.0, 1e-12) << spin;
        const EnergyReport e = r.world->energy();
        EXPECT_NEAR(e.gravity, 2.0 * kG * c.y, 1e-9) << spin;
        // Rotational energy: I w^2 / 2 with the capsule's inertia about its midpoint.
        const double inertia = 2.0 * capsuleMassProperties(2.0, 0.3).inertiaPerMass;
        const Vec2 v = r.velocity("pill");
        EXPECT_NEAR(e.kinetic, 0.5 * 2.0 * dot(v, v) + 0.5 * inertia * spin * spin, 1e-9) << spin;
    }
}

// ------------------------------------------------------------ narrow phase

TEST(CapsuleNarrowPhase, EveryPairInBothOrdersAgreesAndLyingFlatGivesTwoPoints) {
    // Every shape kind against a capsule, in both orders: the same points
    // and separations, opposite normals.
    static const Vec2 square[4] = {{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}};
    const ConvexPolygon poly = ConvexPolygon::fromVertices(square, 4);
    Shape circle;
    circle.kind = ShapeKind::Circle;
    circle.radius = 0.4;
    Shape box;
    box.kind = ShapeKind::Box;
    box.halfExtents = {0.5, 0.5};
    Shape polygon;
    polygon.kind = ShapeKind::Polygon;
    polygon.polygon = &poly;
    Shape plane;
    plane.kind = ShapeKind::Plane;
    plane.normal = {0.0, 1.0};
    plane.offset = 0.0;
    const Shape capsule = capsuleShape({0.6, 0.0}, 0.25);
    const Rot flat{};
    for (const Shape* other : std::initializer_list<const Shape*>{&circle, &box, &polygon, &plane, &capsule}) {
        for (const double lift : {-0.02, 0.0, 0.01}) {
            // The capsule lies on top of the other shape, just touching
            // (lift 0) or overlapping or apart.
            const double otherTop = other->kind == ShapeKind::Circle ? 0.4
                                    : other->kind == ShapeKind::Plane ? 0.0
                                    : other->kind == ShapeKind::Capsule ? 0.25
                                                                        : 0.5;
            const Vec2 pOther{0.0, 0.0}, pCap{0.05, otherTop + 0.25 + lift};
            const Manifold ab = collide(*other, pOther, flat, capsule, pCap, flat, 0.05);
            const Manifold ba = collide(capsule, pCap, flat, *other, pOther, flat, 0.05);
            ASSERT_EQ(ab.pointCount, ba.pointCount) << int(other->kind);
            ASSERT_GE(ab.pointCount, 1) << int(other->kind) << " lift " << lift;
            EXPECT_NEAR(ab.normal.x, 0.0, 1e-12) << int(other->kind);
            EXPECT_NEAR(ab.normal.y, 1.0, 1e-12) << int(other->kind) << ": from the other shape up to the capsule";
            EXPECT_NEAR(ba.normal.y, -1.0, 1e-12) << int(other->kind);
            // Flat against flat: two points, one under each end (a circle
            // touches at one).
            EXPECT_EQ(ab.pointCount, other->kind == ShapeKind::Circle ? 1 : 2) << int(other->kind);
            for (int i = 0; i < ab.pointCount; ++i) {
                EXPECT_NEAR(ab.points[i].separation, lift, 1e-12) << int(other->kind) << " point " << i;
                // Midway between the surfaces.
                EXPECT_NEAR(ab.points[i].point.y, otherTop + 0.5 * lift, 1e-12) << int(other->kind);
            }
            for (int i = 0; i < ba.pointCount; ++i) EXPECT_NEAR(ba.points[i].separation, lift, 1e-12);
        }
        // Beyond the margin: nothing.
        const double far = other->kind == ShapeKind::Plane ? 0.36 : 1.5;
        EXPECT_EQ(collide(*other, {0, 0}, flat, capsule, {0.0, far + 0.25}, flat, 0.05).pointCount, 0)
            << int(other->kind);
    }
}

TEST(CapsuleNarrowPhase, FeatureIdsStayTheSameAsTheCapsuleShiftsAndTilts) {
    // Warm starting matches points by id: a capsule resting on a box, a
    // polygon, a capsule and the plane keeps its two ids while it slides a
    // little and tilts by a milliradian, and the two differ.
    static const Vec2 square[4] = {{-1, -0.5}, {1, -0.5}, {1, 0.5}, {-1, 0.5}};
    const ConvexPolygon poly = ConvexPolygon::fromVertices(square, 4);
    Shape box;
    box.kind = ShapeKind::Box;
    box.halfExtents = {1.0, 0.5};
    Shape polygon;
    polygon.kind = ShapeKind::Polygon;
    polygon.polygon = &poly;
    Shape plane;
    plane.kind = ShapeKind::Plane;
    const Shape ground = capsuleShape({1.0, 0.0}, 0.5);
    const Shape capsule = capsuleShape({0.4, 0.0}, 0.2);
    for (const Shape* under : std::initializer_list<const Shape*>{&box, &polygon, &ground, &plane}) {
        const double top = under->kind == ShapeKind::Plane ? 0.0 : 0.5;
        std::uint32_t ids[2] = {0, 0};
        bool first = true;
        for (const double dx : {-0.1, 0.0, 0.07})
            for (const double tilt : {-1e-3, 0.0, 1e-3}) {
                const Manifold m = collide(*under, {0, 0}, Rot{}, capsule, {dx, top + 0.2 - 1e-3}, Rot::fromAngle(tilt), 0.02);
                ASSERT_EQ(m.pointCount, 2) << int(under->kind) << " " << dx << " " << tilt;
                const std::uint32_t lo = std::min(m.points[0].id, m.points[1].id), hi = std::max(m.points[0].id, m.points[1].id);
                EXPECT_NE(lo, hi);
                EXPECT_LT(hi, 0x10000u) << "a warm-start key keeps 16 bits";
                if (first) {
                    ids[0] = lo;
                    ids[1] = hi;
                    first = false;
                }
                EXPECT_EQ(lo, ids[0]) << int(under->kind) << " " << dx << " " << tilt;
                EXPECT_EQ(hi, ids[1]) << int(under->kind) << " " << dx << " " << tilt;
            }
    }
}

TEST(CapsuleNarrowPhase, CapAgainstACornerIsOnePointAlongTheLineBetweenThem) {
    // A capsule end to the upper right of a box's corner: the exact
    // distance, the normal along the line from corner to cap centre.
    Shape box;
    box.kind = ShapeKind::Box;
    box.halfExtents = {0.5, 0.5};
    const double r = 0.2;
    for (const double gap : {-0.01, 0.0, 0.02}) {
        const Vec2 dir = Vec2{1.0, 2.0} / std::sqrt(5.0);
        const Vec2 end = Vec2{0.5, 0.5} + (r + gap) * dir;
        // Segment pointing away from the box along dir's perpendicular-ish.
        const Vec2 half{0.4, 0.1};
        const Shape cap = capsuleShape(half, r);
        const Vec2 centre = end + half;
        const Manifold m = collide(cap, centre, Rot{}, box, {0, 0}, Rot{}, 0.05);
        ASSERT_EQ(m.pointCount, 1) << gap;
        EXPECT_NEAR(m.points[0].separation, gap, 1e-12);
        EXPECT_NEAR(m.normal.x, -dir.x, 1e-12);
        EXPECT_NEAR(m.normal.y, -dir.y, 1e-12);
        const Manifold f = collide(box, {0, 0}, Rot{}, cap, centre, Rot{}, 0.05);
        ASSERT_EQ(f.pointCount, 1);
        EXPECT_NEAR(f.normal.x, dir.x, 1e-12);
        EXPECT_NEAR(f.points[0].separation, gap, 1e-12);
    }
    // Crossed capsules (an X): one point at the crossing, depth r1 + r2.
    const Shape a = capsuleShape({1.0, 1.0}, 0.1), b = capsuleShape({1.0, -1.0}, 0.2);
    const Manifold x = collide(a, {0, 0}, Rot{}, b, {0, 0}, Rot{}, 0.05);
    ASSERT_GE(x.pointCount, 1);
    for (int i = 0; i < x.pointCount; ++i) EXPECT_LE(x.points[i].separation, -0.3 + 1e-12);
}

// ------------------------------------------------------------ rest heights

namespace {

/// A shape for the rest-height table: its JSON (position excluded) and
/// how far its surface reaches below and above its centre of mass when
/// placed as given.
struct Piece {
    std::string label;
    std::string json;   ///< the shape component(s)
    double down, up;    ///< centre of mass to its lowest and highest point, m
    Vec2 comOffset;     ///< centre of mass from the position, m
};

Piece circlePiece(double r) { return {"circle r=" + exactNumber(r), "\"radius\": " + exactNumber(r), r, r, {}}; }
Piece boxPiece(double w, double h) {
    return {"box " + exactNumber(w) + "x" + exactNumber(h),
            "\"box\": {\"width\": " + exactNumber(w) + ", \"height\": " + exactNumber(h) + "}", 0.5 * h, 0.5 * h, {}};
}
Piece hexPiece(double rho) {
    std::string v = "\"polygon\": {\"vertices\": [";
    for (int i = 0; i < 6; ++i) v += (i ? ", " : "") + vectorJson(rho * std::cos(i * kPi / 3), rho * std::sin(i * kPi / 3));
    const double half = rho * std::sqrt(3.0) / 2.0;
    return {"hexagon " + exactNumber(rho), v + "]}", half, half, {}};
}
/// Lying along x; `lift` moves the segment off the position (a centre of
/// mass that is not the position).
Piece lyingCapsule(double len, double r, double lift = 0.0) {
    return {"capsule L=" + exactNumber(len) + " r=" + exactNumber(r) + (lift != 0.0 ? " off-centre" : ""),
            capsuleJson({-0.5 * len + lift, lift}, {0.5 * len + lift, lift}, r), r, r, {lift, lift}};
}
Piece standingCapsule(double len, double r) {
    return {"standing capsule L=" + exactNumber(len) + " r=" + exactNumber(r), capsuleJson({0, -0.5 * len}, {0, 0.5 * len}, r),
            0.5 * len + r, 0.5 * len + r, {}};
}

/// Two dynamic bodies stacked on a plane at y = 0, `top` centred on
/// `bottom`, masses 1 and `ratio`, settled for 3 s: both centres of mass
/// at their analytic heights.
struct StackResult {
    double bottomError = 0.0, topError = 0.0, drift = 0.0, turn = 0.0;
};
StackResult settleStack(const Piece& bottom, const Piece& top, double ratio, const std::string& world) {
    const double yBottom = bottom.down, yTop = bottom.down + bottom.up + top.down;
    const std::string entities =
        "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}, "
        "{\"name\": \"bottom\", \"mass\": 1, \"position\": " +
        vectorJson(-bottom.comOffset.x, yBottom + 0.001 - bottom.comOffset.y) + ", " + bottom.json +
        "}, {\"name\": \"top\", \"mass\": " + exactNumber(ratio) + ", \"position\": " +
        vectorJson(-top.comOffset.x, yTop + 0.002 - top.comOffset.y) + ", " + top.json + "}";
    Sim r(level(entities, world));
    StackResult out;
    if (!r.step(180)) return out;
    out.bottomError = centre(r, "bottom").y - yBottom;
    out.topError = centre(r, "top").y - yTop;
    out.drift = std::max(std::abs(centre(r, "bottom").x), std::abs(centre(r, "top").x));
    out.turn = std::max(std::abs(r.angle("bottom")), std::abs(r.angle("top")));
    return out;
}

} // namespace

TEST(CapsuleWorld, RestHeightsOverEveryPairOfShapeKindsSizesAndMassRatios) {
    // Capsule on each kind, and each kind on a capsule, both bodies
    // dynamic on a plane, at the engine's chosen settings. The analytic
    // height is the sum of the reaches below; the soft contacts sink by
    // (load / m) / omega^2, about 0.3 mm per contact layer at 60 Hz
    // contacts with a 5:1 load; measured at most 0.83 mm.
    const std::string world = "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 4";
    double worst = 0.0, worstDrift = 0.0, worstTurn = 0.0;
    int cases = 0;
    for (const double r : {0.1, 0.3}) {
        for (const double len : {0.5, 1.5}) {
            const Piece capsule = lyingCapsule(len, r);
            const std::vector<Piece> others = {circlePiece(0.3),     boxPiece(0.8, 0.4),           hexPiece(0.35),
                                               lyingCapsule(1.0, 0.2), lyingCapsule(0.8, 0.15, 0.3), boxPiece(2.0, 0.3)};
            for (const Piece& other : others) {
                for (const double ratio : {0.2, 1.0, 5.0}) {
                    // A circle under a capsule would roll away: only on top.
                    std::vector<std::pair<const Piece*, const Piece*>> pairs = {{&capsule, &other}};
                    if (other.label.rfind("circle", 0) != 0) pairs.push_back({&other, &capsule});
                    for (const auto& [bottom, top] : pairs) {
                        const StackResult s = settleStack(*bottom, *top, ratio, world);
                        const std::string what = top->label + " on " + bottom->label + ", mass ratio " + exactNumber(ratio);
                        EXPECT_NEAR(s.bottomError, 0.0, 1.5e-3) << what;
                        EXPECT_NEAR(s.topError, 0.0, 1.5e-3) << what;
                        EXPECT_LT(s.drift, 1e-3) << what;
                        EXPECT_LT(s.turn, 1e-3) << what;
                        worst = std::max({worst, std::abs(s.bottomError), std::abs(s.topError)});
                        worstDrift = std::max(worstDrift, s.drift);
                        worstTurn = std::max(worstTurn, s.turn);
                        ++cases;
                    }
                }
            }
        }
    }
    std::printf("rest heights: %d cases, worst height error %.3g m, drift %.3g m, turn %.3g rad\n", cases, worst,
                worstDrift, worstTurn);
}

TEST(CapsuleWorld, CapsuleOnStaticShapesAndStandingOnItsEnd) {
    // Static supports: a box, a hexagon, a capsule, a pair of circles (a
    // log on two rollers) and the plane; the capsule lying and standing.
    struct Case {
        std::string support;  // entities
        double top;           // the support's top, m
    };
    const std::vector<Case> supports = {
        {"{\"name\": \"s\", \"static\": true, \"position\": {\"x\": 0, \"y\": -0.25}, \"box\": {\"width\": 3, \"height\": 0.5}}", 0.0},
        {"{\"name\": \"s\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, " + hexPiece(1.0).json + "}",
         std::sqrt(3.0) / 2.0},
        {"{\"name\": \"s\", \"static\": true, \"position\": {\"x\": 0, \"y\": 0}, " +
             capsuleJson({-1.5, 0}, {1.5, 0}, 0.4) + "}",
         0.4},
        {"{\"name\": \"s1\", \"static\": true, \"position\": {\"x\": -0.4, \"y\": 0}, \"radius\": 0.3}, {\"name\": "
         "\"s2\", \"static\": true, \"position\": {\"x\": 0.4, \"y\": 0}, \"radius\": 0.3}",
         0.3},
        {"{\"name\": \"s\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}", 0.0},
    };
    for (const Case& support : supports) {
        for (const Piece& piece : {lyingCapsule(1.2, 0.15), lyingCapsule(2.0, 0.4), lyingCapsule(1.0, 0.2, 0.25),
                                   standingCapsule(0.8, 0.2)}) {
            // Standing on its round end balances only on flat ground.
            if (piece.label.rfind("standing", 0) == 0 && support.support.find("radius") != std::string::npos) continue;
            for (const std::string& world : {std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}"),
                                             std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 1")}) {
                const double y = support.top + piece.down;
                Sim r(level(support.support + ", {\"name\": \"p\", \"mass\": 3, \"position\": " +
                                vectorJson(-piece.comOffset.x, y + 0.001 - piece.comOffset.y) + ", " + piece.json + "}",
                            world));
                ASSERT_TRUE(r.step(180));
                const std::string what = piece.label + " on " + support.support + " " + world;
                EXPECT_NEAR(centre(r, "p").y, y, 2e-3) << what;
                // Exactly symmetric cases stay at 0 to rounding; an
                // off-centre body, and two contacts solved one after the
                // other, lean by at most 2.3e-5 rad (measured).
                EXPECT_NEAR(centre(r, "p").x, 0.0, 2e-5) << what;
                EXPECT_NEAR(r.angle("p"), 0.0, 1e-4) << what;
            }
        }
    }
}

TEST(CapsuleWorld, CapsuleOnItsSideLiesStillForFiveSeconds) {
    // After a second to settle, five seconds more: position and angle
    // move less than 1e-4, at the engine's settings and at 1 substep, on
    // the plane, on a box and on another capsule, with an off-centre
    // position too. Sleep is off: the contacts alone hold it.
    const std::vector<std::string> grounds = {
        "{\"name\": \"g\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}",
        "{\"name\": \"g\", \"static\": true, \"position\": {\"x\": 0.3, \"y\": -0.5}, \"box\": {\"width\": 4, "
        "\"height\": 1}}",
        "{\"name\": \"g\", \"static\": true, \"position\": {\"x\": 0, \"y\": -0.5}, " +
            capsuleJson({-2, 0}, {2, 0}, 0.5) + "}"};
    double worst = 0.0;
    for (const std::string& ground : grounds)
        for (const Piece& piece : {lyingCapsule(1.0, 0.25), lyingCapsule(3.0, 0.1), lyingCapsule(0.6, 0.3, 0.4)})
            for (const std::string& world :
                 {std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}, \"sleep\": false"),
                  std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 1, \"sleep\": false")}) {
                Sim r(level(ground + ", {\"name\": \"p\", \"mass\": 2, \"friction\": 0.5, \"position\": " +
                                vectorJson(-piece.comOffset.x, piece.down - piece.comOffset.y) + ", " + piece.json + "}",
                            world));
                ASSERT_TRUE(r.step(60));
                const Vec2 p0 = r.position("p");
                const double a0 = r.angle("p");
                ASSERT_TRUE(r.step(300));
                const std::string what = piece.label + " on " + ground + " " + world;
                const double moved = length(r.position("p") - p0), turned = std::abs(r.angle("p") - a0);
                EXPECT_LT(moved, 1e-4) << what;
                EXPECT_LT(turned, 1e-4) << what;
                EXPECT_EQ(r.world->contacts().size(), 2u) << what << ": two points, one under each end";
                worst = std::max({worst, moved, turned});
            }
    std::printf("lying still: worst drift over 5 s %.3g\n", worst);
}

TEST(CapsuleWorld, SlidesDownASlopeAtGTimesSinMinusMuCos) {
    // A static box turned to slope theta, the capsule lying along it.
    // Below tan theta it slides at g (sin - mu cos); above, it sticks.
    double worst = 0.0;
    for (const double degrees : {15.0, 25.0, 35.0}) {
        const double theta = degrees * kPi / 180.0;
        const Vec2 down{std::cos(theta), -std::sin(theta)}, up{std::sin(theta), std::cos(theta)};
        for (const double mu : {0.05, 0.2, 1.0}) {
            const double r = 0.2;
            // The slope's top face passes through the origin.
            const Vec2 slopeCentre = -0.5 * up;
            const Vec2 c = 0.0 * down + (r + 0.0005) * up;
            // Both have friction mu, so the pair's sqrt(mu mu) is mu.
            Sim run(level("{\"name\": \"slope\", \"static\": true, \"friction\": " + exactNumber(mu) +
                              ", \"position\": " + vectorJson(slopeCentre.x, slopeCentre.y) + ", \"angle\": " +
                              exactNumber(-theta) + ", \"box\": {\"width\": 30, \"height\": 1}}, {\"name\": \"p\", "
                              "\"friction\": " + exactNumber(mu) + ", \"position\": " + vectorJson(c.x, c.y) +
                              ", \"angle\": " + exactNumber(-theta) + ", " + capsuleJson({-0.5, 0}, {0.5, 0}, r) + "}"));
            ASSERT_TRUE(run.step(60));
            const Vec2 v = run.velocity("p");
            const double along = dot(v, down);
            const std::string what = exactNumber(degrees) + " deg, mu " + exactNumber(mu);
            EXPECT_NEAR(run.angle("p"), -theta, 1e-3) << what << ": it slides flat, not tumbling";
            EXPECT_NEAR(dot(v, up), 0.0, 0.01) << what;
            if (mu < std::tan(theta)) {
                const double expected = kG * (std::sin(theta) - mu * std::cos(theta)) * 1.0;
                EXPECT_NEAR(along, expected, 0.005 * expected) << what;
                worst = std::max(worst, std::abs(along / expected - 1.0));
            } else {
                EXPECT_LT(std::abs(along), 0.01) << what << ": friction holds it";
            }
        }
    }
    std::printf("slope: worst relative speed error %.3g\n", worst);
}

TEST(CapsuleWorld, ResumesBitForBitFromAMidRunSave) {
    // Capsules falling onto a ramp, a box and each other, two of them
    // hinged: 150 steps, save, load, 150 steps == 300 steps, byte for byte.
    const std::string text = level(
        "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}, "
        "{\"name\": \"ramp\", \"static\": true, \"position\": {\"x\": -2, \"y\": 1}, \"angle\": -0.4, \"box\": "
        "{\"width\": 3, \"height\": 0.2}}, "
        "{\"name\": \"c1\", \"position\": {\"x\": -2.5, \"y\": 2.5}, \"angle\": 0.3, \"angular_velocity\": 1, " +
        capsuleJson({-0.4, 0}, {0.4, 0}, 0.15) +
        "}, {\"name\": \"c2\", \"position\": {\"x\": 0.5, \"y\": 1}, " + capsuleJson({0, 0.1}, {0.8, 0.3}, 0.2) +
        "}, {\"name\": \"ball\", \"position\": {\"x\": 0.9, \"y\": 2.5}, \"radius\": 0.2}, "
        "{\"name\": \"crate\", \"position\": {\"x\": 2, \"y\": 0.3}, \"box\": {\"width\": 0.6, \"height\": 0.6}}, "
        "{\"name\": \"arm\", \"position\": {\"x\": 2, \"y\": 1.5}, " + capsuleJson({-0.3, 0}, {0.3, 0}, 0.1) +
        "}, {\"name\": \"forearm\", \"position\": {\"x\": 2.6, \"y\": 1.5}, " + capsuleJson({-0.3, 0}, {0.3, 0}, 0.1) +
        "}, {\"name\": \"elbow\", \"joint\": {\"type\": \"hinge\", \"a\": \"arm\", \"b\": \"forearm\", \"anchor\": "
        "{\"x\": 2.3, \"y\": 1.5}}}");
    Sim whole(text);
    ASSERT_TRUE(whole.step(300));
    Sim first(text);
    ASSERT_TRUE(first.step(150));
    Sim second(sceneToJsonText(first.scene));
    ASSERT_TRUE(second.step(150));
    EXPECT_EQ(sceneToJsonText(second.scene), sceneToJsonText(whole.scene));
    EXPECT_FALSE(whole.world->contacts().empty());
}
