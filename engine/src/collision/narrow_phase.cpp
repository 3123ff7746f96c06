// Contact manifolds. Box-box uses the separating axis test on the four face
// normals, then clips the incident edge against the reference face's side
// planes (Sutherland-Hodgman on a segment), which gives up to two points
// with stable feature ids for warm starting.

#include "collision/narrow_phase.hpp"

#include <algorithm>
#include <array>

namespace stepwise::collision {

namespace {

/// Box corners and outward face normals in the box frame. Edge i runs from
/// corner i to corner i+1; normal i is its outward normal.
struct BoxPolygon {
    std::array<Vec2, 4> vertices;
    std::array<Vec2, 4> normals;  ///< normals 1 and 2 are the box's x and y axes
    Vec2 centre, half;
};

BoxPolygon worldBox(Vec2 h, Vec2 p, Rot q) {
    BoxPolygon out;
    const Vec2 ax{q.c, q.s}, ay{-q.s, q.c};  // the box's axes in the world
    const Vec2 ex = h.x * ax, ey = h.y * ay;
    out.vertices = {p - ex - ey, p + ex - ey, p + ex + ey, p - ex + ey};
    out.normals = {-ay, ax, ay, -ax};
    out.centre = p;
    out.half = h;
    return out;
}

/// Largest separation of B from A's face planes, and that face. B's deepest
/// corner along -n is its support point, so its depth below face i is
/// dot(n, centreB - centreA) - |dot(n, xB)| hB.x - |dot(n, yB)| hB.y - hA
/// (hA: A's half extent along face i): 4 projections instead of 16 corner
/// tests.
std::pair<int, double> maxSeparation(const BoxPolygon& a, const BoxPolygon& b) {
    const Vec2 d = b.centre - a.centre;
    const Vec2 xA = a.normals[1], yA = a.normals[2], xB = b.normals[1], yB = b.normals[2];
    const double dx = dot(d, xA), dy = dot(d, yA);
    const double reachX = std::abs(dot(xA, xB)) * b.half.x + std::abs(dot(xA, yB)) * b.half.y;
    const double reachY = std::abs(dot(yA, xB)) * b.half.x + std::abs(dot(yA, yB)) * b.half.y;
    // Faces in edge order: -y, +x, +y, -x.
    const double s[4] = {-dy - reachY - a.half.y, dx - reachX - a.half.x, dy - reachY - a.half.y,
                         -dx - reachX - a.half.x};
    int bestEdge = 0;
    for (int i = 1; i < 4; ++i)
        if (s[i] > s[bestEdge]) bestEdge = i;
    return {bestEdge, s[bestEdge]};
}

struct ClipVertex {
    Vec2 v;
    std::uint32_t id;
};

/// Keeps the part of segment `in` where dot(n, v) <= offset.
int clipSegment(const ClipVertex in[2], ClipVertex out[2], Vec2 n, double offset, std::uint32_t clipId) {
    const double d0 = dot(n, in[0].v) - offset;
    const double d1 = dot(n, in[1].v) - offset;
    int count = 0;
    if (d0 <= 0.0) out[count++] = in[0];
    if (d1 <= 0.0) out[count++] = in[1];
    if (d0 * d1 < 0.0) {
        const double t = d0 / (d0 - d1);
        out[count++] = ClipVertex{in[0].v + t * (in[1].v - in[0].v), clipId};
    }
    return count;
}

} // namespace

Manifold collideCircles(double rA, Vec2 pA, double rB, Vec2 pB, double margin) {
    Manifold m;
    const Vec2 d = pB - pA;
    const double reach = rA + rB + margin;
    const double dist2 = lengthSquared(d);
    if (dist2 > reach * reach) return m;
    const double dist = std::sqrt(dist2);
    m.normal = dist > 1e-12 ? d / dist : Vec2{0.0, 1.0};
    m.pointCount = 1;
    m.points[0].separation = dist - rA - rB;
    m.points[0].point = 0.5 * ((pA + rA * m.normal) + (pB - rB * m.normal));
    return m;
}

Manifold collideBoxCircle(Vec2 h, Vec2 pA, Rot qA, double r, Vec2 pB, double margin) {
    Manifold m;
    const Vec2 c = invRotate(qA, pB - pA);  // circle centre in the box frame
    Vec2 surface, localNormal;
    double separation;
    const double dx = h.x - std::abs(c.x), dy = h.y - std::abs(c.y);
    if (dx >= 0.0 && dy >= 0.0) {
        // Centre inside the box: push out through the nearest face.
        if (dx < dy) {
            localNormal = {c.x >= 0.0 ? 1.0 : -1.0, 0.0};
            surface = {localNormal.x * h.x, c.y};
            separation = -dx - r;
        } else {
            localNormal = {0.0, c.y >= 0.0 ? 1.0 : -1.0};
            surface = {c.x, localNormal.y * h.y};
            separation = -dy - r;
        }
    } else {
        surface = {std::clamp(c.x, -h.x, h.x), std::clamp(c.y, -h.y, h.y)};
        const Vec2 d = c - surface;
        const double dist = length(d);
        separation = dist - r;
        if (separation > margin) return m;
        localNormal = d / dist;
    }
    if (separation > margin) return m;
    m.normal = rotate(qA, localNormal);
    const Vec2 worldSurface = pA + rotate(qA, surface);
    m.pointCount = 1;
    m.points[0].separation = separation;
    m.points[0].point = 0.5 * (worldSurface + (pB - r * m.normal));
    return m;
}

Manifold collideBoxes(Vec2 hA, Vec2 pA, Rot qA, Vec2 hB, Vec2 pB, Rot qB, double margin) {
    Manifold m;
    const BoxPolygon a = worldBox(hA, pA, qA), b = worldBox(hB, pB, qB);
    const auto [edgeA, separationA] = maxSeparation(a, b);
    if (separationA > margin) return m;
    const auto [edgeB, separationB] = maxSeparation(b, a);
    if (separationB > margin) return m;

    // Prefer A's face unless B's is clearly better: keeps the reference face
    // from flickering between steps when the two are nearly equal.
    const bool flip = separationB > 0.98 * separationA + 0.0005;
    const BoxPolygon& ref = flip ? b : a;
    const BoxPolygon& inc = flip ? a : b;
    const int refEdge = flip ? edgeB : edgeA;
    const Vec2 n = ref.normals[refEdge];

    int incEdge = 0;
    double minDot = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 4; ++i) {
        const double d = dot(n, inc.normals[i]);
        if (d < minDot) {
            minDot = d;
            incEdge = i;
        }
    }
    const ClipVertex incident[2] = {
        {inc.vertices[incEdge], std::uint32_t(incEdge)},
        {inc.vertices[(incEdge + 1) % 4], std::uint32_t((incEdge + 1) % 4)},
    };
    const Vec2 v1 = ref.vertices[refEdge], v2 = ref.vertices[(refEdge + 1) % 4];
    const Vec2 t = (v2 - v1) / length(v2 - v1);
    ClipVertex clipped1[2], clipped2[2];
    if (clipSegment(incident, clipped1, -t, -dot(t, v1), 8 + std::uint32_t(refEdge)) < 2) return m;
    if (clipSegment(clipped1, clipped2, t, dot(t, v2), 12 + std::uint32_t(refEdge)) < 2) return m;

    m.normal = flip ? -n : n;
    for (const ClipVertex& cv : clipped2) {
        const double separation = dot(n, cv.v - v1);
        if (separation > margin) continue;
        ManifoldPoint& p = m.points[m.pointCount++];
        p.separation = separation;
        p.point = cv.v - 0.5 * separation * n;
        p.id = (std::uint32_t(flip) << 16) | (std::uint32_t(refEdge) << 8) | cv.id;
    }
    return m;
}

Manifold collidePlaneCircle(Vec2 n, double offset, double r, Vec2 pB, double margin) {
    Manifold m;
    const double separation = dot(n, pB) - offset - r;
    if (separation > margin) return m;
    m.normal = n;
    m.pointCount = 1;
    m.points[0].separation = separation;
    m.points[0].point = pB - (r + 0.5 * separation) * n;
    return m;
}

Manifold collidePlaneBox(Vec2 n, double offset, Vec2 h, Vec2 pB, Rot qB, double margin) {
    Manifold m;
    const BoxPolygon box = worldBox(h, pB, qB);
    // The two deepest corners within the margin.
    int first = -1, second = -1;
    double s[4];
    for (int i = 0; i < 4; ++i) {
        s[i] = dot(n, box.vertices[i]) - offset;
        if (s[i] > margin) continue;
        if (first < 0 || s[i] < s[first]) {
            second = first;
            first = i;
        } else if (second < 0 || s[i] < s[second]) {
            second = i;
        }
    }
    m.normal = n;
    for (int i : {first, second}) {
        if (i < 0) continue;
        ManifoldPoint& p = m.points[m.pointCount++];
        p.separation = s[i];
        p.point = box.vertices[i] - 0.5 * s[i] * n;
        p.id = std::uint32_t(i);
    }
    // Keep a stable order (by corner id) so warm starting matches points.
    if (m.pointCount == 2 && m.points[0].id > m.points[1].id) std::swap(m.points[0], m.points[1]);
    return m;
}

Manifold collide(const Shape& a, Vec2 pA, Rot qA, const Shape& b, Vec2 pB, Rot qB, double margin) {
    auto flipped = [](Manifold m) {
        m.normal = -m.normal;
        return m;
    };
    switch (a.kind) {
    case ShapeKind::Circle:
        if (b.kind == ShapeKind::Circle) return collideCircles(a.radius, pA, b.radius, pB, margin);
        if (b.kind == ShapeKind::Box) return flipped(collideBoxCircle(b.halfExtents, pB, qB, a.radius, pA, margin));
        return flipped(collidePlaneCircle(b.normal, b.offset, a.radius, pA, margin));
    case ShapeKind::Box:
        if (b.kind == ShapeKind::Circle) return collideBoxCircle(a.halfExtents, pA, qA, b.radius, pB, margin);
        if (b.kind == ShapeKind::Box) return collideBoxes(a.halfExtents, pA, qA, b.halfExtents, pB, qB, margin);
        return flipped(collidePlaneBox(b.normal, b.offset, a.halfExtents, pA, qA, margin));
    case ShapeKind::Plane:
        if (b.kind == ShapeKind::Circle) return collidePlaneCircle(a.normal, a.offset, b.radius, pB, margin);
        if (b.kind == ShapeKind::Box) return collidePlaneBox(a.normal, a.offset, b.halfExtents, pB, qB, margin);
        return Manifold{};  // two infinite walls never collide
    }
    return Manifold{};
}

Aabb computeAabb(const Shape& shape, Vec2 p, Rot q) {
    if (shape.kind == ShapeKind::Circle) return {p - Vec2{shape.radius, shape.radius}, p + Vec2{shape.radius, shape.radius}};
    const Vec2 h = shape.halfExtents;
    const Vec2 e{std::abs(q.c) * h.x + std::abs(q.s) * h.y, std::abs(q.s) * h.x + std::abs(q.c) * h.y};
    return {p - e, p + e};
}

} // namespace stepwise::collision
