// Polygon shapes: the one validity check (loader, world, editor) and the
// mass properties the engine derives from the outline; and the capsule's
// mass properties, which the collision system and the tests share.

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace stepwise {

namespace {

std::string pointText(Vec2 p) {
    std::ostringstream s;
    s << "{\"x\": " << p.x << ", \"y\": " << p.y << "}";
    return s.str();
}

} // namespace

std::optional<Error> polygonProblem(const std::vector<Vec2>& v) {
    const std::size_t n = v.size();
    if (n < 3 || n > 8) return Error{"expected 3 to 8 vertices, got " + std::to_string(n)};
    for (std::size_t i = 0; i < n; ++i)
        if (!(std::abs(v[i].x) <= kMaxMagnitude && std::abs(v[i].y) <= kMaxMagnitude))
            return Error{"vertex " + std::to_string(i) + " " + pointText(v[i]) + " is not within " +
                             formatNumber(kMaxMagnitude) + " m of the body's position on each axis",
                         std::to_string(i)};
    // Tolerances are relative to the polygon's size, so a 1 mm triangle and a
    // 1 km one are judged alike. extent: the largest coordinate span, metres.
    Vec2 lo = v[0], hi = v[0];
    for (const Vec2& p : v) {
        lo = {std::min(lo.x, p.x), std::min(lo.y, p.y)};
        hi = {std::max(hi.x, p.x), std::max(hi.y, p.y)};
    }
    const double extent = std::max(hi.x - lo.x, hi.y - lo.y);
    // Below it the area (extent^2) and second moment (extent^4) leave the
    // normal doubles, and the checks below would misjudge rounding as shape.
    if (!(extent >= kMinSize))
        return Error{"the polygon is " + formatNumber(extent) + " m across; the smallest shape is " +
                     formatNumber(kMinSize) + " m"};
    // Closer than a billionth of the size: the edge between them has no
    // usable direction (its normal would be rounding noise).
    const double samePoint = 1e-9 * extent;
    for (std::size_t j = 1; j < n; ++j)
        for (std::size_t i = 0; i < j; ++i)
            if (length(v[j] - v[i]) <= samePoint)
                return Error{"vertex " + std::to_string(j) + " " + pointText(v[j]) + " is the same point as vertex " +
                                 std::to_string(i) + "; a polygon needs distinct vertices",
                             std::to_string(j)};
    // All on one line: no area, so no mass distribution and no inside.
    std::size_t far = 1;
    for (std::size_t k = 2; k < n; ++k)
        if (lengthSquared(v[k] - v[0]) > lengthSquared(v[far] - v[0])) far = k;
    const Vec2 axis = v[far] - v[0];
    double offLine = 0.0;
    for (const Vec2& p : v) offLine = std::max(offLine, std::abs(cross(axis, p - v[0])) / length(axis));
    if (offLine <= 1e-9 * extent) return Error{"the vertices lie on one line, so the polygon has no area"};
    double twiceArea = 0.0;
    for (std::size_t i = 1; i + 1 < n; ++i) twiceArea += cross(v[i] - v[0], v[i + 1] - v[0]);
    if (twiceArea < 0.0)
        return Error{"the vertices run clockwise; list them counter-clockwise (reverse the list)"};
    // Each corner must turn left: sin of the turn below 1e-9 is a straight
    // corner (a vertex on the line between its neighbours), negative a dent.
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 before = v[i] - v[(i + n - 1) % n], after = v[(i + 1) % n] - v[i];
        const double turn = cross(before, after);
        if (std::abs(turn) <= 1e-9 * length(before) * length(after))
            return Error{"vertex " + std::to_string(i) + " " + pointText(v[i]) +
                             " lies on the straight line between its neighbours; remove it",
                         std::to_string(i)};
        if (turn < 0.0)
            return Error{"not convex: the outline turns clockwise at vertex " + std::to_string(i) + " " +
                             pointText(v[i]) + "; a polygon shape must be convex (split the shape into convex pieces)",
                         std::to_string(i)};
    }
    // Left turns everywhere but wound round more than once (a star drawn
    // without lifting the pen): some vertex lies outside some edge.
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = v[i], edge = v[(i + 1) % n] - a;
        for (std::size_t k = 0; k < n; ++k) {
            if (k == i || k == (i + 1) % n) continue;
            if (cross(edge, v[k] - a) <= 0.0)
                return Error{"not convex: the outline crosses itself (vertex " + std::to_string(k) +
                                 " is not inside edge " + std::to_string(i) + "-" + std::to_string((i + 1) % n) + ")",
                             std::to_string(k)};
        }
    }
    return {};
}

PolygonMassProperties polygonMassProperties(const std::vector<Vec2>& v) {
    // Fan of triangles (v0, vi, vi+1), measured from v0 so that vertices far
    // from the origin lose no digits. A triangle (0, e1, e2) has area
    // cross(e1, e2)/2, centroid (e1 + e2)/3 and polar second moment about 0
    // of area/6 * (e1.e1 + e1.e2 + e2.e2).
    PolygonMassProperties out;
    if (v.size() < 3) return out;
    Vec2 firstMoment;
    double polarAboutV0 = 0.0;
    for (std::size_t i = 1; i + 1 < v.size(); ++i) {
        const Vec2 e1 = v[i] - v[0], e2 = v[i + 1] - v[0];
        const double area = 0.5 * cross(e1, e2);
        out.area += area;
        firstMoment += (area / 3.0) * (e1 + e2);
        polarAboutV0 += area / 6.0 * (dot(e1, e1) + dot(e1, e2) + dot(e2, e2));
    }
    const Vec2 c = firstMoment / out.area;  // centroid relative to v0
    out.centroid = v[0] + c;
    // Parallel axis theorem: J_v0 = J_centroid + A |c|^2.
    out.secondMoment = polarAboutV0 - out.area * lengthSquared(c);
    return out;
}

PolygonMassProperties polygonMassProperties(const std::vector<Vec2>& v, double r) {
    PolygonMassProperties core = polygonMassProperties(v);
    if (!(r > 0.0) || v.size() < 3) return core;
    // Moments about the core's centroid c (so large coordinates lose no
    // digits): area, first moment and polar second moment of each piece.
    const Vec2 c = core.centroid;
    double area = core.area, polar = core.secondMoment;
    Vec2 first;
    const std::size_t n = v.size();
    for (std::size_t i = 0; i < n; ++i) {
        const Vec2 a = v[i] - c, b = v[(i + 1) % n] - c, e = b - a;
        const double len = length(e);
        const Vec2 normal{e.y / len, -e.x / len};  // outward (counter-clockwise outline)
        // The rectangle on edge i: len by r, centred at the edge's middle
        // pushed out by r/2; about its centre len r (len^2 + r^2) / 12.
        const double rect = len * r;
        const Vec2 centre = 0.5 * (a + b) + (0.5 * r) * normal;
        area += rect;
        first += rect * centre;
        polar += rect * (len * len + r * r) / 12.0 + rect * lengthSquared(centre);
        // The sector at vertex b, between edge i's normal and edge i+1's:
        // angle theta, area theta r^2 / 2, polar moment about its apex
        // theta r^4 / 4, first moment about the apex (2/3) r^3 sin(theta/2)
        // along the bisector.
        const Vec2 f = v[(i + 2) % n] - v[(i + 1) % n];
        const Vec2 nextNormal = Vec2{f.y, -f.x} / length(f);
        const double theta = std::atan2(cross(normal, nextNormal), dot(normal, nextNormal));
        const Vec2 bisector = (normal + nextNormal) / length(normal + nextNormal);
        const double sector = 0.5 * theta * r * r;
        const Vec2 apexMoment = (2.0 / 3.0) * r * r * r * std::sin(0.5 * theta) * bisector;
        area += sector;
        first += sector * b + apexMoment;
        polar += 0.25 * theta * r * r * r * r + 2.0 * dot(b, apexMoment) + sector * lengthSquared(b);
    }
    PolygonMassProperties out;
    out.area = area;
    const Vec2 shift = first / area;  // centroid relative to the core's
    out.centroid = c + shift;
    out.secondMoment = polar - area * lengthSquared(shift);
    return out;
}

} // namespace stepwise

namespace stepwise {

CapsuleMassProperties capsuleMassProperties(double length, double radius) {
    // A rectangle 2r by L and two half discs, mass shared by area. A half
    // disc's centroid is lc = 4r / (3 pi) beyond its flat side, which sits
    // h = L/2 from the centre; about its centroid it has m (r^2/2 - lc^2),
    // so by parallel axes m (r^2/2 + h^2 + 2 h lc) about the centre.
    constexpr double kPi = 3.14159265358979323846;
    const double r = radius, h = 0.5 * length;
    const double rectangle = 2.0 * r * length, discs = kPi * r * r;
    CapsuleMassProperties out;
    out.area = rectangle + discs;
    const double lc = 4.0 * r / (3.0 * kPi);
    out.inertiaPerMass = (rectangle * (length * length + 4.0 * r * r) / 12.0 +
                          discs * (0.5 * r * r + h * h + 2.0 * h * lc)) /
                         out.area;
    return out;
}

} // namespace stepwise

namespace stepwise {

std::optional<Error> chainProblem(const std::vector<Vec2>& p, bool loop) {
    const std::size_t n = p.size();
    const std::size_t least = loop ? 3 : 2;
    if (n < least || n > kMaxChainPoints)
        return Error{"expected " + std::to_string(least) + " to " + std::to_string(kMaxChainPoints) + " points" +
                     (loop ? " in a loop" : "") + ", got " + std::to_string(n)};
    for (std::size_t i = 0; i < n; ++i)
        if (!(std::abs(p[i].x) <= kMaxMagnitude && std::abs(p[i].y) <= kMaxMagnitude))
            return Error{"point " + std::to_string(i) + " " + pointText(p[i]) + " is not within " +
                             formatNumber(kMaxMagnitude) + " m of the body's position on each axis",
                         std::to_string(i)};
    // A segment needs a direction: its normal decides which side is solid.
    // Relative to the chain's size, like a polygon's vertices.
    Vec2 lo = p[0], hi = p[0];
    for (const Vec2& q : p) {
        lo = {std::min(lo.x, q.x), std::min(lo.y, q.y)};
        hi = {std::max(hi.x, q.x), std::max(hi.y, q.y)};
    }
    const double samePoint = 1e-9 * std::max(hi.x - lo.x, hi.y - lo.y);
    const std::size_t segments = loop ? n : n - 1;
    for (std::size_t i = 0; i < segments; ++i) {
        const std::size_t j = (i + 1) % n;
        if (length(p[j] - p[i]) <= samePoint || p[j] == p[i])
            return Error{"point " + std::to_string(j) + " " + pointText(p[j]) + " is the same point as point " +
                             std::to_string(i) + (j == 0 ? " (the loop closes from the last point to the first)" : "") +
                             "; each segment of a chain needs a length",
                         std::to_string(j)};
    }
    return {};
}

std::optional<Error> compoundShapeProblem(const CompoundShape& shape) {
    using Kind = CompoundShape::Kind;
    if (shape.kind == Kind::Polygon) {
        if (std::optional<Error> problem = polygonProblem(shape.vertices)) return problem->within("polygon/vertices");
    } else if (shape.kind == Kind::Capsule && shape.a == shape.b) {
        return Error{"a and b are the same point {\"x\": " + formatNumber(shape.a.x) + ", \"y\": " +
                         formatNumber(shape.a.y) + "}; a capsule needs a segment of non-zero length (a circle is "
                         "the shape without one)",
                     "capsule/b"};
    }
    return {};
}

ShapeAreaProperties compoundShapeArea(const CompoundShape& shape) {
    constexpr double kPi = 3.14159265358979323846;
    ShapeAreaProperties out;
    switch (shape.kind) {
    case CompoundShape::Kind::Circle:
        out.area = kPi * shape.radius * shape.radius;
        out.centroid = shape.center;
        out.secondMoment = 0.5 * out.area * shape.radius * shape.radius;
        break;
    case CompoundShape::Kind::Box:
        out.area = shape.width * shape.height;
        out.centroid = shape.center;
        out.secondMoment = out.area * (shape.width * shape.width + shape.height * shape.height) / 12.0;
        break;
    case CompoundShape::Kind::Polygon: {
        const PolygonMassProperties p = polygonMassProperties(shape.vertices, shape.cornerRadius.value_or(0.0));
        out.area = p.area;
        out.centroid = p.centroid;
        out.secondMoment = p.secondMoment;
        break;
    }
    case CompoundShape::Kind::Capsule: {
        const CapsuleMassProperties c = capsuleMassProperties(length(shape.b - shape.a), shape.radius);
        out.area = c.area;
        out.centroid = 0.5 * (shape.a + shape.b);
        out.secondMoment = c.area * c.inertiaPerMass;
        break;
    }
    }
    return out;
}

CompoundMassProperties compoundMassProperties(const Shapes& shapes, std::optional<double> mass) {
    CompoundMassProperties out;
    std::vector<ShapeAreaProperties> parts;
    Vec2 moment;
    for (const CompoundShape& s : shapes.items) {
        parts.push_back(compoundShapeArea(s));
        const double m = s.density.value_or(1.0) * parts.back().area;
        out.shapeMass.push_back(m);
        out.mass += m;
        moment += m * parts.back().centroid;
    }
    if (!(out.mass > 0.0)) return out;
    out.centre = moment / out.mass;
    // Parallel axes: each shape's own inertia (m J / A) plus m d^2 to the
    // common centre.
    for (std::size_t i = 0; i < parts.size(); ++i) {
        const double m = out.shapeMass[i];
        out.inertia += m * parts[i].secondMoment / parts[i].area + m * lengthSquared(parts[i].centroid - out.centre);
    }
    if (mass) {
        const double scale = *mass / out.mass;
        for (double& m : out.shapeMass) m *= scale;
        out.inertia *= scale;
        out.mass = *mass;
    }
    return out;
}

} // namespace stepwise

namespace stepwise {

ShapeOutline compoundShapeOutline(const CompoundShape& s) {
    ShapeOutline out;
    switch (s.kind) {
    case CompoundShape::Kind::Circle:
        out.points = {s.center};
        out.radius = s.radius;
        break;
    case CompoundShape::Kind::Box: {
        const double c = std::cos(s.angle), sn = std::sin(s.angle), hx = 0.5 * s.width, hy = 0.5 * s.height;
        for (const Vec2 k : {Vec2{-hx, -hy}, Vec2{hx, -hy}, Vec2{hx, hy}, Vec2{-hx, hy}})
            out.points.push_back(s.center + Vec2{c * k.x - sn * k.y, sn * k.x + c * k.y});
        break;
    }
    case CompoundShape::Kind::Polygon:
        out.points = s.vertices;
        out.radius = s.cornerRadius.value_or(0.0);
        break;
    case CompoundShape::Kind::Capsule:
        out.points = {s.a, s.b};
        out.radius = s.radius;
        break;
    }
    return out;
}

bool compoundShapeContains(const CompoundShape& s, Vec2 local) {
    switch (s.kind) {
    case CompoundShape::Kind::Circle: return length(local - s.center) <= s.radius;
    case CompoundShape::Kind::Capsule: {
        const Vec2 ab = s.b - s.a;
        const double t = std::clamp(dot(local - s.a, ab) / dot(ab, ab), 0.0, 1.0);
        return length(local - (s.a + t * ab)) <= s.radius;
    }
    case CompoundShape::Kind::Box:
    case CompoundShape::Kind::Polygon: {
        // Inside a counter-clockwise convex outline (left of every edge), or
        // within its rounding of an edge.
        const ShapeOutline outline = compoundShapeOutline(s);
        const std::vector<Vec2>& v = outline.points;
        if (v.size() < 3) return false;
        bool inside = true;
        double nearest = std::numeric_limits<double>::infinity();
        for (std::size_t i = 0; i < v.size(); ++i) {
            const Vec2 p = v[i], edge = v[(i + 1) % v.size()] - p;
            inside = inside && cross(edge, local - p) >= 0.0;
            const double t = std::clamp(dot(local - p, edge) / dot(edge, edge), 0.0, 1.0);
            nearest = std::min(nearest, length(local - (p + t * edge)));
        }
        return inside || nearest <= outline.radius;
    }
    }
    return false;
}

} // namespace stepwise
