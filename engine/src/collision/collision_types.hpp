#pragma once
// Collision data shared by the broad phase, the narrow phase and the contact
// solver. Internal to the engine.

#include "stepwise/vec2.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace stepwise::collision {

enum class ShapeKind : std::uint8_t { Circle, Box, Plane, Polygon, Capsule, ChainSegment };

/// Rotation as cosine/sine, so rotating a vector is 4 multiplies.
struct Rot {
    double c = 1.0;
    double s = 0.0;
    static Rot fromAngle(double angle) { return {std::cos(angle), std::sin(angle)}; }
};
/// The rotation by an angle x (rad) that is usually small: a body's turn
/// since the step began, which the solver needs every substep (sincos would
/// be 8% of a 20-row pyramid's step). Below 1/16 rad, Taylor series through x^9
/// (sine) and x^8 (cosine): the first terms left out are under 2.5e-19, so
/// only rounding separates it from libm's (within two units in the last
/// place, tests/test_collision.cpp); no libm call, so also the same on every
/// C library. Larger angles take std::cos and std::sin.
inline Rot rotationBy(double x) {
    if (!(std::abs(x) < 0.0625)) return Rot::fromAngle(x);
    const double x2 = x * x;
    constexpr double k2 = 1.0 / 2.0, k3 = 1.0 / 6.0, k4 = 1.0 / 12.0, k5 = 1.0 / 20.0, k6 = 1.0 / 30.0,
                     k7 = 1.0 / 42.0, k8 = 1.0 / 56.0, k9 = 1.0 / 72.0;
    const double s = x * (1.0 - x2 * k3 * (1.0 - x2 * k5 * (1.0 - x2 * k7 * (1.0 - x2 * k9))));
    const double c = 1.0 - x2 * k2 * (1.0 - x2 * k4 * (1.0 - x2 * k6 * (1.0 - x2 * k8)));
    return {c, s};
}
inline Vec2 rotate(Rot q, Vec2 v) { return {q.c * v.x - q.s * v.y, q.s * v.x + q.c * v.y}; }
inline Vec2 invRotate(Rot q, Vec2 v) { return {q.c * v.x + q.s * v.y, -q.s * v.x + q.c * v.y}; }
/// Perpendicular (counter-clockwise) and the 2D cross products used by
/// impulse maths: w x r = (-w r.y, w r.x).
inline Vec2 perp(Vec2 v) { return {-v.y, v.x}; }
inline Vec2 crossSV(double w, Vec2 r) { return {-w * r.y, w * r.x}; }

/// Most vertices a polygon shape may have (the scene format's limit).
inline constexpr int kMaxPolygonVertices = 8;

/// A convex polygon in its body's frame, centred on its centre of mass:
/// counter-clockwise vertices, and normal i the outward unit normal of the
/// edge from vertex i to vertex i+1.
struct ConvexPolygon {
    int count = 0;
    Vec2 vertices[kMaxPolygonVertices];
    Vec2 normals[kMaxPolygonVertices];
    double radius = 0.0;  ///< farthest vertex from the centre of mass, metres
    /// The corners rounded by this radius (the outline grown by a disc),
    /// metres; 0 for a sharp polygon.
    double cornerRadius = 0.0;
    /// Builds from vertices already relative to the centre of mass (valid:
    /// convex, counter-clockwise, 3..8).
    static ConvexPolygon fromVertices(const Vec2* v, int n) {
        ConvexPolygon p;
        p.count = n;
        for (int i = 0; i < n; ++i) {
            p.vertices[i] = v[i];
            const Vec2 edge = v[(i + 1) % n] - v[i];
            p.normals[i] = Vec2{edge.y, -edge.x} / std::sqrt(edge.x * edge.x + edge.y * edge.y);
            p.radius = std::max(p.radius, std::sqrt(v[i].x * v[i].x + v[i].y * v[i].y));
        }
        return p;
    }
};

/// One segment of a chain, in its body's frame (relative to the position):
/// from p1 to p2, solid on the right (the normal is (d.y, -d.x) / |d|).
/// The ghosts are the neighbouring segments' far points, which tell the
/// narrow phase which contact normals belong to the neighbour instead (so a
/// body crossing a joint feels no bump). An open end gets a ghost that
/// makes it a square corner: a wall down behind the segment.
struct ChainSegment {
    Vec2 p1, p2;
    Vec2 ghost1, ghost2;
    bool open1 = false, open2 = false;  ///< p1 / p2 is an end of an open chain
    std::uint32_t index = 0;            ///< the segment's number in its chain (feature ids)
};

/// A chain contact's feature id holds the segment's number above its low
/// 6 bits, so an entity-keyed warm start (a saved level) finds the segment
/// again: 10 bits of a 16-bit id, hence at most 1024 segments.
inline constexpr int kChainFeatureShift = 6;

/// Geometry of one collider in its body's frame.
struct Shape {
    ShapeKind kind = ShapeKind::Circle;
    double radius = 0.0;      ///< circles and capsules, metres
    /// Boxes: half extents, metres. Capsules: the half segment, from the
    /// centre of mass (the segment's midpoint) to end b in the body frame;
    /// end a is its negative. Shared, so a capsule costs a Shape no bytes.
    Vec2 halfExtents;
    Vec2 normal{0.0, 1.0};    ///< planes: unit normal, world frame
    double offset = 0.0;      ///< planes: dot(normal, p) >= offset is outside
    /// Polygons: the outline about the centre of mass. Owned by whoever made
    /// the shape (the collision system keeps its polygons at fixed addresses).
    const ConvexPolygon* polygon = nullptr;
    /// Chain segments: the segment, owned like the polygons' outlines.
    const ChainSegment* segment = nullptr;
};

/// One contact point of a manifold.
struct ManifoldPoint {
    Vec2 point;               ///< world point midway between the surfaces, metres
    double separation = 0.0;  ///< signed gap along the normal, metres (< 0: overlap)
    std::uint32_t id = 0;     ///< feature key for matching across steps (warm start)
};

/// Contact manifold between shapes A and B; the normal points from A to B.
struct Manifold {
    Vec2 normal;
    ManifoldPoint points[2];
    int pointCount = 0;
};

/// Axis-aligned bounding box, metres.
struct Aabb {
    Vec2 lower;
    Vec2 upper;
};
inline bool overlaps(const Aabb& a, const Aabb& b) {
    return a.lower.x <= b.upper.x && b.lower.x <= a.upper.x && a.lower.y <= b.upper.y && b.lower.y <= a.upper.y;
}

} // namespace stepwise::collision
