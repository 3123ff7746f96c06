// Convex polygon shapes: the file format's checks with their
// exact messages, mass properties against the textbook formulas, contact
// manifolds against hand-computed normals and depths, and whole-world runs
// with analytic answers (resting, sliding on a slope, a head-on elastic
// impact), plus the off-centre centre of mass and its exact save/resume.

#include "collision/collision_system.hpp"
#include "collision/narrow_phase.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

using namespace stepwise;
using test::exactNumber;
using test::loadError;
using test::named;
using test::vectorJson;
using namespace stepwise::collision;

namespace {

constexpr double kPi = std::numbers::pi;

/// A level with the given entities (JSON text of the array's elements).
std::string level(const std::string& entities, const std::string& world = "") {
    return "{\"world\": {" + (world.empty() ? std::string("\"gravity\": {\"x\": 0, \"y\": -9.81}") : world) +
           "}, \"entities\": [" + entities + "]}";
}

/// The loader's message for `text`, or "loaded" when it loads.

/// Loads `text`, steps it `steps` times, writes the state back.
struct Stepped {
    Scene scene;
    std::vector<ContactRecord> contacts;
    EnergyReport energyAtStart, energyAtEnd;
    Stepped(const std::string& text, int steps) {
        Result<Scene> loaded = parseScene(text, "t.json");
        EXPECT_TRUE(loaded) << loaded.error();
        if (!loaded) return;
        scene = std::move(*loaded);
        Result<World> world = World::build(scene);
        EXPECT_TRUE(world) << world.error();
        if (!world) return;
        energyAtStart = world->energy();
        for (int i = 0; i < steps; ++i) {
            Result<void> r = world->step();
            EXPECT_TRUE(r) << r.error();
            if (!r) return;
        }
        energyAtEnd = world->energy();
        contacts.assign(world->contacts().begin(), world->contacts().end());
        world->writeBack(scene);
    }
    Vec2 position(const std::string& name) const { return scene.registry.tryGet<Position>(named(scene, name))->value; }
    Vec2 velocity(const std::string& name) const {
        const Velocity* v = scene.registry.tryGet<Velocity>(named(scene, name));
        return v ? v->value : Vec2{};
    }
    double angle(const std::string& name) const {
        const Angle* a = scene.registry.tryGet<Angle>(named(scene, name));
        return a ? a->value : 0.0;
    }
    double spin(const std::string& name) const {
        const AngularVelocity* w = scene.registry.tryGet<AngularVelocity>(named(scene, name));
        return w ? w->value : 0.0;
    }
};



/// Regular n-gon of circumradius r, counter-clockwise, vertex 0 at `phase` rad.
std::vector<Vec2> regular(int n, double r, double phase = 0.0) {
    std::vector<Vec2> v;
    for (int i = 0; i < n; ++i) {
        const double a = phase + 2.0 * kPi * i / n;
        v.push_back({r * std::cos(a), r * std::sin(a)});
    }
    return v;
}

std::string verticesJson(const std::vector<Vec2>& v) {
    std::string s = "{\"vertices\": [";
    for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + vectorJson(v[i].x, v[i].y);
    return s + "]}";
}

/// A collision-side polygon from vertices about its centroid.
ConvexPolygon convex(const std::vector<Vec2>& v) {
    const PolygonMassProperties props = polygonMassProperties(v);
    std::vector<Vec2> local;
    for (const Vec2& p : v) local.push_back(p - props.centroid);
    return ConvexPolygon::fromVertices(local.data(), int(local.size()));
}

} // namespace

// ------------------------------------------------------------ mass properties

TEST(PolygonMass, RightTriangleMatchesTheFormula) {
    // Legs a along x and b along y: area ab/2, centroid (a/3, b/3), polar
    // second moment about the centroid A (a^2 + b^2) / 18.
    const double a = 3.0, b = 1.5;
    const PolygonMassProperties p = polygonMassProperties({{0, 0}, {a, 0}, {0, b}});
    EXPECT_NEAR(p.area, a * b / 2, 1e-15);
    EXPECT_NEAR(p.centroid.x, a / 3, 1e-15);
    EXPECT_NEAR(p.centroid.y, b / 3, 1e-15);
    EXPECT_NEAR(p.secondMoment, p.area * (a * a + b * b) / 18, 1e-14);
    // The engine's inertia, from the outline about its centre of mass.
    Shape s;
    s.kind = ShapeKind::Polygon;
    const ConvexPolygon poly = convex({{0, 0}, {a, 0}, {0, b}});
    s.polygon = &poly;
    const double mass = 2.5;
    EXPECT_NEAR(momentOfInertia(s, mass), mass * (a * a + b * b) / 18, 1e-13);
}

TEST(PolygonMass, RegularPolygonsMatchTheFormulaAndFarFromTheOriginToo) {
    // Regular n-gon of circumradius R: I = m R^2 (1 + 2 cos^2(pi/n)) / 6.
    for (int n = 3; n <= 8; ++n) {
        const double R = 0.7, mass = 3.0;
        const double expected = mass * R * R * (1.0 + 2.0 * std::pow(std::cos(kPi / n), 2)) / 6.0;
        std::vector<Vec2> v = regular(n, R, 0.3);
        Shape s;
        s.kind = ShapeKind::Polygon;
        const ConvexPolygon poly = convex(v);
        s.polygon = &poly;
        EXPECT_NEAR(momentOfInertia(s, mass) / expected, 1.0, 1e-13) << n;
        // The same outline 1000 m away: measured from a vertex, no digits lost.
        for (Vec2& p : v) p += Vec2{1000.0, -1000.0};
        const PolygonMassProperties far = polygonMassProperties(v);
        EXPECT_NEAR(mass * far.secondMoment / far.area / expected, 1.0, 1e-9) << n;
        EXPECT_NEAR(far.centroid.x, 1000.0, 1e-10);
        EXPECT_NEAR(far.centroid.y, -1000.0, 1e-10);
    }
}

// ------------------------------------------------------------ file format

TEST(PolygonFormat, BadOutlinesAreRefusedWithTheEntityAndThePointer) {
    auto one = [](const std::string& vertices) {
        return loadError(level("{\"name\": \"wedge\", \"position\": {\"x\": 0, \"y\": 0}, \"polygon\": {\"vertices\": [" +
                               vertices + "]}}"));
    };
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}"),
              "t.json: error: /entities/0/polygon/vertices: entity 0 (\"wedge\"): expected 3 to 8 vertices, got 2");
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 1, \"y\": 1}, {\"x\": 0.8, \"y\": 1.2}, "
                  "{\"x\": 0.6, \"y\": 1.3}, {\"x\": 0.4, \"y\": 1.3}, {\"x\": 0.2, \"y\": 1.2}, {\"x\": 0, \"y\": 1}, "
                  "{\"x\": -0.1, \"y\": 0.5}"),
              "t.json: error: /entities/0/polygon/vertices: entity 0 (\"wedge\"): expected 3 to 8 vertices, got 9");
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 0, \"y\": 1}, {\"x\": 1, \"y\": 0}"),
              "t.json: error: /entities/0/polygon/vertices: entity 0 (\"wedge\"): the vertices run clockwise; list "
              "them counter-clockwise (reverse the list)");
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 1}, {\"x\": 2, \"y\": 2}"),
              "t.json: error: /entities/0/polygon/vertices: entity 0 (\"wedge\"): the vertices lie on one line, so "
              "the polygon has no area");
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 0, \"y\": 1}"),
              "t.json: error: /entities/0/polygon/vertices/2: entity 0 (\"wedge\"): vertex 2 {\"x\": 1, \"y\": 0} is "
              "the same point as vertex 1; a polygon needs distinct vertices");
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 1, \"y\": 0}, {\"x\": 2, \"y\": 0}, {\"x\": 1, \"y\": 1}"),
              "t.json: error: /entities/0/polygon/vertices/1: entity 0 (\"wedge\"): vertex 1 {\"x\": 1, \"y\": 0} lies "
              "on the straight line between its neighbours; remove it");
    // An arrow head: the dent at vertex 2.
    EXPECT_EQ(one("{\"x\": 0, \"y\": 0}, {\"x\": 2, \"y\": 1}, {\"x\": 0, \"y\": 0.5}, {\"x\": -2, \"y\": 1}"),
              "t.json: error: /entities/0/polygon/vertices/2: entity 0 (\"wedge\"): not convex: the outline turns "
              "clockwise at vertex 2 {\"x\": 0, \"y\": 0.5}; a polygon shape must be convex (split the shape into "
              "convex pieces)");
    // A pentagram: every turn is to the left, but it winds round twice.
    std::string star;
    for (int i = 0; i < 5; ++i) {
        const double a = 2.0 * kPi * (2 * i) / 5.0;
        star += (i ? ", " : "") + vectorJson(std::cos(a), std::sin(a));
    }
    EXPECT_EQ(one(star), "t.json: error: /entities/0/polygon/vertices/3: entity 0 (\"wedge\"): not convex: the "
                         "outline crosses itself (vertex 3 is not inside edge 0-1)");
    // Without a name, the entity is named by its index.
    EXPECT_EQ(loadError(level("{\"position\": {\"x\": 0, \"y\": 0}, \"polygon\": {\"vertices\": []}}")),
              "t.json: error: /entities/0/polygon/vertices: entity 0: expected 3 to 8 vertices, got 0");
    EXPECT_EQ(loadError(level("{\"position\": {\"x\": 0, \"y\": 0}, \"polygon\": {\"vertices\": 3}}")),
              "t.json: error: /entities/0/polygon/vertices: expected an array of vectors, got 3");
    EXPECT_EQ(loadError(level("{\"position\": {\"x\": 0, \"y\": 0}, \"polygon\": {\"vertices\": [{\"x\": 0, \"y\": "
                              "0}, {\"x\": 1, \"y\": \"a\"}, {\"x\": 0, \"y\": 1}]}}")),
              "t.json: error: /entities/0/polygon/vertices/1/y: expected a number in [-1e+30, 1e+30], got \"a\"");
    EXPECT_EQ(loadError(level("{\"position\": {\"x\": 0, \"y\": 0}, \"radius\": 1, \"polygon\": {}}")),
              "t.json: error: /entities/0: an entity has at most one shape (radius, box, polygon, capsule, chain or plane), got 2");
    EXPECT_EQ(loadError(level("{\"polygon\": {}}")),
              "t.json: error: /entities/0: component \"polygon\" on entity 0 needs \"position\", which is missing");
}

TEST(PolygonFormat, TheWorldRefusesABadPolygonMadeInCode) {
    Scene s;
    const Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {"dent"});
    s.registry.emplace<Position>(e, {{0.0, 0.0}});
    s.registry.emplace<Polygon>(e, {{{0, 0}, {2, 1}, {0, 0.5}, {-2, 1}}});
    Result<World> w = World::build(s);
    ASSERT_FALSE(w);
    EXPECT_EQ(w.error(), "entity 0 (\"dent\"): polygon.vertices[2]: not convex: the outline turns clockwise at vertex 2 "
                         "{\"x\": 0, \"y\": 0.5}; a polygon shape must be convex (split the shape into convex pieces)");
}

TEST(PolygonFormat, RoundTripsByteForByteAndTinyAndHugeOutlinesLoad) {
    const std::string text = level(
        "{\"name\": \"tri\", \"position\": {\"x\": 0.1, \"y\": 1e-300}, \"polygon\": " +
        verticesJson({{-0.3333333333333333, -0.1}, {1e-9, -0.2}, {0.7, 0.123456789012345678}}) +
        ", \"angle\": 0.1},"
        "{\"name\": \"hex\", \"position\": {\"x\": 1e6, \"y\": -2}, \"polygon\": " + verticesJson(regular(6, 1e5)) +
        ", \"static\": true},"
        "{\"name\": \"mite\", \"position\": {\"x\": 0, \"y\": 0}, \"polygon\": " +
        verticesJson({{0, 0}, {1e-6, 0}, {0, 1e-6}}) + "}");
    Result<Scene> first = parseScene(text, "t.json");
    ASSERT_TRUE(first) << first.error();
    const std::string saved = sceneToJsonText(*first);
    Result<Scene> second = parseScene(saved, "saved.json");
    ASSERT_TRUE(second) << second.error();
    EXPECT_EQ(sceneToJsonText(*second), saved);
    EXPECT_EQ(second->registry.tryGet<Polygon>(named(*second, "tri"))->vertices,
              first->registry.tryGet<Polygon>(named(*first, "tri"))->vertices);
    // The saved layout: vertices one per line, each a compact vector.
    EXPECT_NE(saved.find("\"polygon\": {\n        \"vertices\": [\n          {\"x\": -0.3333333333333333, \"y\": -0.1},"),
              std::string::npos)
        << saved;
}

// ------------------------------------------------------------ narrow phase

TEST(PolygonNarrowPhase, CircleOnAFaceAndOnAVertex) {
    // Triangle with a horizontal top edge y = 0.5 from x = -1 to 1, apex down.
    const ConvexPolygon tri = convex({{0, -1}, {1, 0.5}, {-1, 0.5}});
    const Vec2 at = polygonMassProperties({{0, -1}, {1, 0.5}, {-1, 0.5}}).centroid;  // (0, 0)
    Manifold face = collidePolygonCircle(tri, at, Rot{}, 0.25, {0.3, 0.7}, 0.0);
    ASSERT_EQ(face.pointCount, 1);
    EXPECT_NEAR(face.normal.x, 0.0, 1e-15);
    EXPECT_NEAR(face.normal.y, 1.0, 1e-15);
    EXPECT_NEAR(face.points[0].separation, -0.05, 1e-12);
    // Below the apex (0, -1): the vertex is nearest, normal straight down.
    Manifold apex = collidePolygonCircle(tri, at, Rot{}, 0.5, {0.0, -1.4}, 0.0);
    ASSERT_EQ(apex.pointCount, 1);
    EXPECT_NEAR(apex.normal.x, 0.0, 1e-12);
    EXPECT_NEAR(apex.normal.y, -1.0, 1e-12);
    EXPECT_NEAR(apex.points[0].separation, -0.1, 1e-12);
    // Beyond a corner (1, 0.5) along (0.6, 0.8): 0.5 away, just touching.
    Manifold corner = collidePolygonCircle(tri, at, Rot{}, 0.25, Vec2{1.0, 0.5} + 0.5 * Vec2{0.6, 0.8}, 0.0);
    EXPECT_EQ(corner.pointCount, 0);
    corner = collidePolygonCircle(tri, at, Rot{}, 0.25, Vec2{1.0, 0.5} + 0.5 * Vec2{0.6, 0.8}, 0.3);
    ASSERT_EQ(corner.pointCount, 1) << "speculative margin";
    EXPECT_NEAR(corner.normal.x, 0.6, 1e-12);
    EXPECT_NEAR(corner.normal.y, 0.8, 1e-12);
    EXPECT_NEAR(corner.points[0].separation, 0.25, 1e-12);
    // Centre inside: pushed out through the nearest face (the top, 0.1 away).
    Manifold inside = collidePolygonCircle(tri, at, Rot{}, 0.2, {0.0, 0.4}, 0.0);
    ASSERT_EQ(inside.pointCount, 1);
    EXPECT_NEAR(inside.normal.y, 1.0, 1e-15);
    EXPECT_NEAR(inside.points[0].separation, -0.3, 1e-12);
    // Through the generic entry, circle first: the normal flips to point circle -> polygon.
    Shape c, p;
    c.kind = ShapeKind::Circle;
    c.radius = 0.25;
    p.kind = ShapeKind::Polygon;
    p.polygon = &tri;
    const Manifold flipped = collide(c, {0.3, 0.7}, Rot{}, p, at, Rot{}, 0.0);
    EXPECT_NEAR(flipped.normal.y, -1.0, 1e-15);
}

TEST(PolygonNarrowPhase, RotatedSquareAgainstABoxAndAPlane) {
    // A unit square as a polygon, turned 45 degrees: its lowest corner is
    // sqrt(1/2) below its centre.
    const ConvexPolygon square = convex({{-0.5, -0.5}, {0.5, -0.5}, {0.5, 0.5}, {-0.5, 0.5}});
    const double halfDiagonal = std::sqrt(0.5);
    const Rot turned = Rot::fromAngle(kPi / 4);
    const Manifold onPlane = collidePlanePolygon({0, 1}, 0.0, square, {0.2, halfDiagonal - 0.03}, turned, 0.0);
    ASSERT_EQ(onPlane.pointCount, 1);
    EXPECT_NEAR(onPlane.points[0].separation, -0.03, 1e-12);
    EXPECT_NEAR(onPlane.points[0].point.x, 0.2, 1e-12);
    EXPECT_EQ(onPlane.normal, (Vec2{0, 1}));
    // The same corner into the top of a 4 x 1 box whose top is y = 0.
    const Manifold onBox = collideBoxPolygon({2.0, 0.5}, {0.0, -0.5}, Rot{}, square, {0.2, halfDiagonal - 0.03},
                                             turned, 0.0);
    ASSERT_GE(onBox.pointCount, 1);
    EXPECT_NEAR(onBox.normal.x, 0.0, 1e-12);
    EXPECT_NEAR(onBox.normal.y, 1.0, 1e-12);
    double deepest = 0.0;
    for (int i = 0; i < onBox.pointCount; ++i) deepest = std::min(deepest, onBox.points[i].separation);
    EXPECT_NEAR(deepest, -0.03, 1e-12);
    // Flat on the box, 0.01 deep: two points, 1 m apart, at the square's corners.
    const Manifold flat = collideBoxPolygon({2.0, 0.5}, {0.0, -0.5}, Rot{}, square, {0.3, 0.49}, Rot{}, 0.0);
    ASSERT_EQ(flat.pointCount, 2);
    EXPECT_NEAR(flat.normal.y, 1.0, 1e-15);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(flat.points[i].separation, -0.01, 1e-12);
    EXPECT_NEAR(std::abs(flat.points[0].point.x - flat.points[1].point.x), 1.0, 1e-12);
    EXPECT_NE(flat.points[0].id, flat.points[1].id);
}

TEST(PolygonNarrowPhase, TrianglesFaceToFaceAndApart) {
    // Two right triangles whose hypotenuses face each other across the line
    // x + y = 1, overlapping by d along the normal (1, 1)/sqrt(2).
    const std::vector<Vec2> lower{{0, 0}, {1, 0}, {0, 1}};
    const std::vector<Vec2> upper{{1, 0}, {1, 1}, {0, 1}};
    const ConvexPolygon a = convex(lower), b = convex(upper);
    const Vec2 ca = polygonMassProperties(lower).centroid, cb = polygonMassProperties(upper).centroid;
    const double d = 0.02;
    const Vec2 n = Vec2{1, 1} / std::sqrt(2.0);
    const Manifold m = collidePolygons(a, ca, Rot{}, b, cb - d * n, Rot{}, 0.0);
    ASSERT_EQ(m.pointCount, 2);
    EXPECT_NEAR(m.normal.x, n.x, 1e-12);
    EXPECT_NEAR(m.normal.y, n.y, 1e-12);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(m.points[i].separation, -d, 1e-12);
    // Moved apart by 0.1: nothing without a margin, a speculative pair with one.
    EXPECT_EQ(collidePolygons(a, ca, Rot{}, b, cb + 0.1 * n, Rot{}, 0.0).pointCount, 0);
    const Manifold speculative = collidePolygons(a, ca, Rot{}, b, cb + 0.1 * n, Rot{}, 0.2);
    ASSERT_EQ(speculative.pointCount, 2);
    EXPECT_NEAR(speculative.points[0].separation, 0.1, 1e-12);
}

// ------------------------------------------------------------ whole worlds

TEST(PolygonWorld, TriangleRestsOnItsBaseOnAPlaneAndOnABox) {
    // Base 1 m from (-0.5, 0) to (0.5, 0), apex (0.1, 0.8): off-centre apex,
    // so the centroid (0.0333, 0.2667) is not the position, and gravity's
    // line still falls inside the base. It must stay put, unturned.
    const std::string tri = "\"polygon\": " + verticesJson({{-0.5, 0.0}, {0.5, 0.0}, {0.1, 0.8}});
    for (const std::string& ground :
         {std::string("{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}}"),
          std::string("{\"name\": \"floor\", \"position\": {\"x\": 0.3, \"y\": -0.5}, \"box\": {\"width\": 4, "
                      "\"height\": 1}, \"static\": true}")}) {
        Stepped r(level(ground + ", {\"name\": \"tri\", \"position\": {\"x\": 0, \"y\": 0.001}, \"mass\": 2, " + tri + "}",
                    "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 4"),
              600);
        EXPECT_NEAR(r.position("tri").x, 0.0, 1e-4) << ground;
        // Resting: the base sits on y = 0 within the solver's slop (5 mm).
        EXPECT_NEAR(r.position("tri").y, 0.0, 5e-3) << ground;
        EXPECT_NEAR(r.angle("tri"), 0.0, 1e-4) << ground;
        EXPECT_LT(length(r.velocity("tri")), 1e-3) << ground;
        EXPECT_LT(std::abs(r.spin("tri")), 1e-3) << ground;
        ASSERT_EQ(r.contacts.size(), 2u) << ground << ": the base's two corners";
        double load = 0.0;
        for (const ContactRecord& c : r.contacts) load += c.normalImpulse;
        // Impulses are the last substep's: weight = impulse / (dt / 4).
        EXPECT_NEAR(load / (1.0 / 240.0), 2.0 * 9.81, 0.02 * 2.0 * 9.81) << ground << ": the floor carries the weight";
    }
}

TEST(PolygonWorld, HeadOnElasticOneToThreeEndsAtMinusOneAndPlusOne) {
    // Hexagons with flat faces towards each other (vertices at 30 + 60k
    // degrees), 1 kg at 2 m/s into 3 kg at rest, e = 1, no gravity:
    // v1 = (m1 - m2)/(m1 + m2) u1 = -1, v2 = 2 m1/(m1 + m2) u1 = +1.
    const std::string hex = verticesJson(regular(6, 0.5, kPi / 6));
    Stepped r(level("{\"name\": \"light\", \"position\": {\"x\": -2, \"y\": 0}, \"velocity\": {\"x\": 2, \"y\": 0}, "
                "\"mass\": 1, \"restitution\": 1, \"friction\": 0, \"polygon\": " + hex +
                "}, {\"name\": \"heavy\", \"position\": {\"x\": 1, \"y\": 0}, \"mass\": 3, \"restitution\": 1, "
                "\"friction\": 0, \"polygon\": " + hex + "}",
                "\"gravity\": {\"x\": 0, \"y\": 0}"),
          120);
    EXPECT_NEAR(r.velocity("light").x, -1.0, 1e-9);
    EXPECT_NEAR(r.velocity("heavy").x, 1.0, 1e-9);
    EXPECT_NEAR(r.velocity("light").y, 0.0, 1e-12);
    EXPECT_NEAR(r.spin("light"), 0.0, 1e-12);
    EXPECT_NEAR(r.spin("heavy"), 0.0, 1e-12);
    EXPECT_NEAR(r.energyAtEnd.kinetic, r.energyAtStart.kinetic, 1e-9 * r.energyAtStart.kinetic);
}

TEST(PolygonWorld, RotatedBlockOnAPolygonRampSticksOrSlidesAsCoulombSays) {
    // A static right-triangle ramp of slope 20 degrees, and a square block
    // (a 4-gon) turned to lie flat on it. tan 20 = 0.364: friction 0.6
    // holds it; friction 0.1 lets it slide at g (sin - mu cos).
    const double slope = 20.0 * kPi / 180.0, g = 9.81;
    const double run = 8.0, rise = run * std::tan(slope);
    const std::string ramp = "{\"name\": \"ramp\", \"position\": {\"x\": 0, \"y\": 0}, \"static\": true, "
                             "\"friction\": 1, \"polygon\": " + verticesJson({{0, 0}, {run, 0}, {0, rise}}) + "}";
    // The block's centre sits 0.25 m above the slope, 2 m down it from the top.
    const Vec2 down{std::cos(slope), -std::sin(slope)}, up{std::sin(slope), std::cos(slope)};
    const Vec2 centre = Vec2{0.0, rise} + 2.0 * down + 0.2501 * up;
    for (const auto& [friction, slides] : {std::pair{0.36, false}, std::pair{0.01, true}}) {
        // The pair's coefficient is sqrt(f_block * f_ramp) = sqrt(friction).
        const double mu = std::sqrt(friction);
        Stepped r(level(ramp + ", {\"name\": \"block\", \"position\": " + vectorJson(centre.x, centre.y) +
                        ", \"angle\": " + exactNumber(-slope) + ", \"friction\": " + exactNumber(friction) +
                        ", \"polygon\": " + verticesJson({{-0.25, -0.25}, {0.25, -0.25}, {0.25, 0.25}, {-0.25, 0.25}}) +
                        "}",
                    "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"substeps\": 4"),
              60);
        const Vec2 v = r.velocity("block");
        EXPECT_NEAR(r.angle("block"), -slope, 1e-3) << mu << ": it lies flat, not tipping";
        if (!slides) {
            EXPECT_LT(length(v), 0.01) << mu;
        } else {
            // After 1 s from rest: speed g (sin - mu cos) t, along the slope.
            const double expected = g * (std::sin(slope) - mu * std::cos(slope)) * 1.0;
            EXPECT_NEAR(dot(v, down), expected, 0.03 * expected) << mu;
            EXPECT_NEAR(dot(v, up), 0.0, 0.01) << mu;
        }
    }
}

TEST(PolygonWorld, OffCentreBodyTurnsAboutItsCentroidAndResumesBitForBit) {
    // Vertices far to one side of the position: the centroid is (2, 0).
    // Spinning in free fall, the centre of mass follows the parabola and
    // the position circles it at 2 m.
    const std::string text = level(
        "{\"name\": \"flag\", \"position\": {\"x\": 0, \"y\": 0}, \"velocity\": {\"x\": 1, \"y\": 3}, "
        "\"angular_velocity\": 2, \"polygon\": " + verticesJson({{1.5, -0.5}, {2.5, -0.5}, {2.5, 0.5}, {1.5, 0.5}}) + "}",
        "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"dt\": 0.01, \"substeps\": 2");
    Stepped r(text, 100);  // t = 1 s
    const double t = 1.0, angle = 2.0 * t;
    const Vec2 com{2.0 + 1.0 * t, 3.0 * t - 0.5 * 9.81 * t * t};
    const Vec2 expected = com - Vec2{2.0 * std::cos(angle), 2.0 * std::sin(angle)};
    EXPECT_NEAR(r.angle("flag"), angle, 1e-12);
    // Semi-implicit Euler's free-fall error: g dt t / 2 = 0.049 m in y.
    EXPECT_NEAR(r.position("flag").x, expected.x, 1e-9);
    EXPECT_NEAR(r.position("flag").y, expected.y, 0.06);
    EXPECT_NEAR(r.velocity("flag").x, 1.0, 1e-12);
    // Gravity's potential is the centre of mass's height, not the position's.
    const Vec2 p = r.position("flag");
    EXPECT_NEAR(r.energyAtEnd.gravity, 9.81 * (p.y + 2.0 * std::sin(r.angle("flag"))), 1e-9);

    // 100 steps, save, load, 100 steps == 200 steps, byte for byte, with a floor to land on.
    const std::string landing =
        level("{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0.1, \"y\": 1}, \"offset\": -3}}, "
              "{\"name\": \"flag\", \"position\": {\"x\": 0, \"y\": 0}, \"velocity\": {\"x\": 1, \"y\": 3}, "
              "\"angular_velocity\": 2, \"polygon\": " +
                  verticesJson({{1.5, -0.5}, {2.5, -0.5}, {2.5, 0.5}, {1.5, 0.5}}) + "}",
              "\"gravity\": {\"x\": 0, \"y\": -9.81}, \"dt\": 0.01, \"substeps\": 2");
    Stepped whole(landing, 200);
    Stepped firstHalf(landing, 100);
    Stepped secondHalf(sceneToJsonText(firstHalf.scene), 100);
    EXPECT_FALSE(whole.contacts.empty()) << "it should have landed";
    EXPECT_EQ(sceneToJsonText(secondHalf.scene), sceneToJsonText(whole.scene));
}

TEST(PolygonWorld, FastTriangleDoesNotTunnelThroughAThinPolygonWall) {
    // 150 m/s at a 5 cm wall: 2.5 m per step at 60 Hz, 50 wall widths.
    const std::string text =
        level("{\"name\": \"wall\", \"position\": {\"x\": 0, \"y\": 0}, \"static\": true, \"polygon\": " +
                  verticesJson({{0, -2}, {0.05, -2}, {0.05, 2}, {0, 2}}) +
                  "}, {\"name\": \"dart\", \"position\": {\"x\": -3, \"y\": 0.1}, \"velocity\": {\"x\": 150, "
                  "\"y\": 0}, \"polygon\": " + verticesJson({{-0.1, -0.1}, {0.2, 0}, {-0.1, 0.1}}) + "}",
              "\"gravity\": {\"x\": 0, \"y\": 0}, \"substeps\": 1");
    Stepped r(text, 30);
    EXPECT_LT(r.position("dart").x, 0.0) << "it passed through the wall";
    EXPECT_LE(r.velocity("dart").x, 1e-9) << "and stopped against it";
}

TEST(PolygonWorld, PolygonsPileOnOneAnotherWithoutBlowingUp) {
    // 24 mixed n-gons dropped in a plane box, 1 substep and 8 iterations, then
    // 4 substeps: all come to rest inside the walls.
    for (const std::string& settings : {std::string("\"substeps\": 1, \"solver_iterations\": 8"),
                                        std::string("\"substeps\": 4")}) {
        std::string entities =
            "{\"name\": \"floor\", \"plane\": {\"normal\": {\"x\": 0, \"y\": 1}, \"offset\": 0}},"
            "{\"name\": \"left\", \"plane\": {\"normal\": {\"x\": 1, \"y\": 0}, \"offset\": -2}},"
            "{\"name\": \"right\", \"plane\": {\"normal\": {\"x\": -1, \"y\": 0}, \"offset\": -2}}";
        for (int i = 0; i < 24; ++i) {
            const int n = 3 + i % 6;
            entities += ", {\"name\": \"p" + std::to_string(i) + "\", \"position\": " +
                        vectorJson(-1.5 + (i % 6) * 0.6 + 0.05 * (i / 6), 0.5 + 0.7 * (i / 6)) +
                        ", \"angle\": " + exactNumber(0.3 * i) + ", \"polygon\": " + verticesJson(regular(n, 0.28)) +
                        "}";
        }
        Stepped r(level(entities, "\"gravity\": {\"x\": 0, \"y\": -9.81}, " + settings), 600);
        for (int i = 0; i < 24; ++i) {
            const std::string name = "p" + std::to_string(i);
            const Vec2 p = r.position(name);
            EXPECT_GT(p.y, 0.1) << settings << " " << name;
            EXPECT_LT(p.y, 3.0) << settings << " " << name;
            EXPECT_LT(std::abs(p.x), 2.0) << settings << " " << name;
            EXPECT_LT(length(r.velocity(name)), 0.05) << settings << " " << name;
        }
    }
}
