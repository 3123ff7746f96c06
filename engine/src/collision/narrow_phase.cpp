// Contact manifolds. Box-box uses the separating axis test on the four face
// normals, then clips the incident edge against the reference face's side
// planes (Sutherland-Hodgman on a segment), which gives up to two points
// with stable feature ids for warm starting.

#include "collision/narrow_phase.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <optional>

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

/// A convex polygon placed in the world: counter-clockwise vertices and
/// outward unit normals (normal i belongs to the edge from vertex i to i+1).
struct WorldPolygon {
    int count = 0;
    Vec2 vertices[kMaxPolygonVertices];
    Vec2 normals[kMaxPolygonVertices];
};

WorldPolygon worldPolygon(const ConvexPolygon& poly, Vec2 p, Rot q) {
    WorldPolygon out;
    out.count = poly.count;
    for (int i = 0; i < poly.count; ++i) {
        out.vertices[i] = p + rotate(q, poly.vertices[i]);
        out.normals[i] = rotate(q, poly.normals[i]);
    }
    return out;
}

/// A box as a 4-gon, with the corner order of worldBox (so its feature ids
/// against polygons read like box-box ones).
WorldPolygon worldPolygon(const BoxPolygon& box) {
    WorldPolygon out;
    out.count = 4;
    for (int i = 0; i < 4; ++i) {
        out.vertices[i] = box.vertices[i];
        out.normals[i] = box.normals[i];
    }
    return out;
}

/// Largest separation of B from A's face planes, and that face: for each
/// face, B's deepest vertex along -n (its support point) measured from the
/// face. Positive: a separating axis.
std::pair<int, double> maxSeparation(const WorldPolygon& a, const WorldPolygon& b) {
    int bestEdge = 0;
    double best = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < a.count; ++i) {
        const Vec2 n = a.normals[i], v = a.vertices[i];
        double deepest = std::numeric_limits<double>::infinity();
        for (int k = 0; k < b.count; ++k) deepest = std::min(deepest, dot(n, b.vertices[k] - v));
        if (deepest > best) {
            best = deepest;
            bestEdge = i;
        }
    }
    return {bestEdge, best};
}

/// The manifold from reference face `refEdge` of `ref` and the edge of
/// `inc` most facing it: the incident edge clipped against the reference
/// face's side planes. Side-plane points get ids sideId + refEdge and
/// sideId + sideStride + refEdge (boxes and polygons keep their own ranges).
/// Boxes go in as they are (four corners, a count known when compiled):
/// copying one into a WorldPolygon writes 264 bytes for 128 (30% of the
/// box-box instructions on a 20-row pyramid); the arithmetic is the same.
inline int cornerCount(const WorldPolygon& p) { return p.count; }
constexpr int cornerCount(const BoxPolygon&) { return 4; }

template <typename Polygon>
Manifold clipIncidentEdge(const Polygon& ref, int refEdge, const Polygon& inc, bool flip, double margin,
                          std::uint32_t sideId, std::uint32_t sideStride) {
    Manifold m;
    const int incCount = cornerCount(inc), refCount = cornerCount(ref);
    const Vec2 n = ref.normals[refEdge];
    int incEdge = 0;
    double minDot = std::numeric_limits<double>::infinity();
    for (int i = 0; i < incCount; ++i) {
        const double d = dot(n, inc.normals[i]);
        if (d < minDot) {
            minDot = d;
            incEdge = i;
        }
    }
    const int incNext = (incEdge + 1) % incCount;
    const ClipVertex incident[2] = {{inc.vertices[incEdge], std::uint32_t(incEdge)},
                                    {inc.vertices[incNext], std::uint32_t(incNext)}};
    const Vec2 v1 = ref.vertices[refEdge], v2 = ref.vertices[(refEdge + 1) % refCount];
    const Vec2 t = (v2 - v1) / length(v2 - v1);
    ClipVertex clipped1[2], clipped2[2];
    if (clipSegment(incident, clipped1, -t, -dot(t, v1), sideId + std::uint32_t(refEdge)) < 2) return m;
    if (clipSegment(clipped1, clipped2, t, dot(t, v2), sideId + sideStride + std::uint32_t(refEdge)) < 2) return m;

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

/// Separating axis test over both polygons' face normals, then the
/// incident edge clipped (clipIncidentEdge): up to two points. Feature ids:
/// (reference edge << 8) | (incident vertex, or 16 + reference edge / 24 +
/// reference edge for a point cut by a side plane), plus bit 16 when B's
/// face is the reference.
Manifold collideWorldPolygons(const WorldPolygon& a, const WorldPolygon& b, double margin) {
    const auto [edgeA, separationA] = maxSeparation(a, b);
    if (separationA > margin) return Manifold{};
    const auto [edgeB, separationB] = maxSeparation(b, a);
    if (separationB > margin) return Manifold{};
    // The boxes' rule: A's face unless B's is clearly better, so the
    // reference face does not flicker between steps.
    const bool flip = separationB > 0.98 * separationA + 0.0005;
    return clipIncidentEdge(flip ? b : a, flip ? edgeB : edgeA, flip ? a : b, flip, margin, 16, kMaxPolygonVertices);
}

/// Polygon A (in the world) against circle B: the exact closest point of
/// the outline, or, with the centre inside, the face it is least deep under.
Manifold collideWorldPolygonCircle(const WorldPolygon& a, double r, Vec2 pB, double margin) {
    Manifold m;
    int face = 0;
    double faceSeparation = -std::numeric_limits<double>::infinity();
    for (int i = 0; i < a.count; ++i) {
        const double s = dot(a.normals[i], pB - a.vertices[i]);
        if (s > faceSeparation) {
            faceSeparation = s;
            face = i;
        }
    }
    if (faceSeparation - r > margin) return m;
    Vec2 surface;
    double separation;
    if (faceSeparation <= 0.0) {
        // Centre inside: out through the nearest face.
        m.normal = a.normals[face];
        surface = pB - faceSeparation * m.normal;
        separation = faceSeparation - r;
    } else {
        // Outside: the nearest point over all edges (at most 8; exact
        // where the best face's own segment test can pick the wrong vertex).
        double best = std::numeric_limits<double>::infinity();
        for (int i = 0; i < a.count; ++i) {
            const Vec2 v1 = a.vertices[i], edge = a.vertices[(i + 1) % a.count] - v1;
            const double u = std::clamp(dot(pB - v1, edge) / lengthSquared(edge), 0.0, 1.0);
            const Vec2 q = v1 + u * edge;
            const double d2 = lengthSquared(pB - q);
            if (d2 < best) {
                best = d2;
                surface = q;
            }
        }
        const double dist = std::sqrt(best);
        separation = dist - r;
        if (separation > margin) return m;
        m.normal = dist > 0.0 ? (pB - surface) / dist : a.normals[face];
    }
    m.pointCount = 1;
    m.points[0].separation = separation;
    m.points[0].point = 0.5 * (surface + (pB - r * m.normal));
    return m;
}

/// Plane A against polygon B: B's two deepest vertices within the margin,
/// ids the vertex numbers (in that order, for warm starting).
Manifold collidePlaneWorldPolygon(Vec2 n, double offset, const WorldPolygon& b, double margin) {
    Manifold m;
    int first = -1, second = -1;
    double s[kMaxPolygonVertices];
    for (int i = 0; i < b.count; ++i) {
        s[i] = dot(n, b.vertices[i]) - offset;
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
        p.point = b.vertices[i] - 0.5 * s[i] * n;
        p.id = std::uint32_t(i);
    }
    if (m.pointCount == 2 && m.points[0].id > m.points[1].id) std::swap(m.points[0], m.points[1]);
    return m;
}

/// Closest points of segments p1-q1 and p2-q2: fractions s along the first
/// and t along the second (Ericson, Real-Time Collision Detection 5.1.9).
struct SegmentClosest {
    double s = 0.0, t = 0.0;
    Vec2 onFirst, onSecond;
};

SegmentClosest closestOnSegments(Vec2 p1, Vec2 q1, Vec2 p2, Vec2 q2) {
    const Vec2 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
    const double a = dot(d1, d1), e = dot(d2, d2), f = dot(d2, r);
    constexpr double kTiny = 1e-300;
    SegmentClosest out;
    if (a <= kTiny && e <= kTiny) {
        // both points
    } else if (a <= kTiny) {
        out.t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = dot(d1, r);
        if (e <= kTiny) {
            out.s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = dot(d1, d2), denom = a * e - b * b;
            // Parallel segments (denom 0) take s = 0: any point is as close.
            out.s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            out.t = (b * out.s + f) / e;
            if (out.t < 0.0) {
                out.t = 0.0;
                out.s = std::clamp(-c / a, 0.0, 1.0);
            } else if (out.t > 1.0) {
                out.t = 1.0;
                out.s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    out.onFirst = p1 + out.s * d1;
    out.onSecond = p2 + out.t * d2;
    return out;
}

/// A capsule's core as a two-sided polygon: vertices a and b, and edge 0
/// (a to b) and edge 1 (b to a) with opposite outward normals.
WorldPolygon worldSegment(Vec2 a, Vec2 b) {
    WorldPolygon out;
    out.count = 2;
    out.vertices[0] = a;
    out.vertices[1] = b;
    const Vec2 d = b - a;
    const double len = length(d);
    out.normals[0] = len > 0.0 ? Vec2{d.y, -d.x} / len : Vec2{0.0, -1.0};
    out.normals[1] = -out.normals[0];
    return out;
}

/// Feature ids of capsule manifolds, in bits 12-13 above the polygons'
/// (reference edge << 8 | vertex or clip id < 32), all within the 16 bits a
/// warm-start key keeps: a face of B is the reference, a face of the
/// capsule A is, or one point between an end of A and a vertex of B.
constexpr std::uint32_t kCapsuleFaceOfB = 0x1000, kCapsuleFaceOfA = 0x2000, kCapsuleCorner = 0x3000;

/// Convex polygon A swept by rA against convex polygon B swept by rB:
/// rounded polygons, and capsules (a capsule is its core as a two-sided
/// polygon with its radius; boxes and sharp polygons have radius 0). The
/// separating axis test over both cores' face normals picks a reference
/// face; the other core's edge is clipped to that face's side planes, which
/// gives two points when a shape lies along a face. When the cores are apart
/// and nearest at a vertex of each (a rounded corner against a corner) one
/// point on the line between them, the distance measured exactly (Box2D
/// v3's b2CollidePolygons does the same with its rounded polygons).
Manifold collideWorldRoundedPolygons(const WorldPolygon& a, double rA, const WorldPolygon& b, double rB,
                                     double margin) {
    const double rSum = rA + rB;
    const auto [edgeB, separationB] = maxSeparation(b, a);
    if (separationB - rSum > margin) return Manifold{};
    const auto [edgeA, separationA] = maxSeparation(a, b);
    if (separationA - rSum > margin) return Manifold{};
    // B's face unless A's is clearly better (the boxes' rule, so the
    // reference does not flicker between steps).
    const bool capsuleReference = separationA > 0.98 * separationB + 0.0005;
    const Vec2 referenceNormal = capsuleReference ? a.normals[edgeA] : -b.normals[edgeB];  // from A to B

    // One point from the exact closest points.
    const auto cornerPoint = [&](const SegmentClosest& c, int vertexA, int vertexB) {
        Manifold m;
        const Vec2 d = c.onSecond - c.onFirst;
        const double dist = length(d);
        const double separation = dist - rSum;
        if (separation > margin || !(dist > 0.0)) return m;
        m.normal = d / dist;
        m.pointCount = 1;
        m.points[0].separation = separation;
        m.points[0].point = 0.5 * ((c.onFirst + rA * m.normal) + (c.onSecond - rB * m.normal));
        m.points[0].id = kCapsuleCorner | (std::uint32_t(vertexA) << 8) | std::uint32_t(vertexB);
        return m;
    };
    std::optional<SegmentClosest> nearest;
    int nearestVertex = 0, nearestVertexA = 0;
    if (std::max(separationA, separationB) > 0.0) {
        // The cores are apart: their distance is the nearest pair of edges.
        double best = std::numeric_limits<double>::infinity();
        const int edges = b.count == 2 ? 1 : b.count;
        const int edgesA = a.count == 2 ? 1 : a.count;
        for (int j = 0; j < edgesA; ++j) {
            const int nextA = (j + 1) % a.count;
            for (int i = 0; i < edges; ++i) {
                const int next = (i + 1) % b.count;
                const SegmentClosest c = closestOnSegments(a.vertices[j], a.vertices[nextA], b.vertices[i], b.vertices[next]);
                const double d2 = lengthSquared(c.onSecond - c.onFirst);
                if (d2 < best) {
                    best = d2;
                    nearest = c;
                    nearestVertex = c.t > 0.5 ? next : i;
                    nearestVertexA = c.s > 0.5 ? nextA : j;
                }
            }
        }
        if (std::sqrt(best) - rSum > margin) return Manifold{};
        const bool cornerToCorner = (nearest->s == 0.0 || nearest->s == 1.0) && (nearest->t == 0.0 || nearest->t == 1.0);
        const double dist = std::sqrt(best);
        // A rounded corner against a corner, unless the line between them is
        // (nearly) the reference face's normal: two parallel capsules
        // stacked end to end are nearest at their ends too, and must rest
        // on two points.
        if (cornerToCorner && dist > 0.0 && dot(nearest->onSecond - nearest->onFirst, referenceNormal) < 0.999 * dist)
            return cornerPoint(*nearest, nearestVertexA, nearestVertex);
    }

    Manifold m;
    const WorldPolygon& ref = capsuleReference ? a : b;
    const WorldPolygon& inc = capsuleReference ? b : a;
    const int refEdge = capsuleReference ? edgeA : edgeB;
    const Vec2 n = ref.normals[refEdge];  // out of the reference core, toward the other
    int incEdge = 0;
    double minDot = std::numeric_limits<double>::infinity();
    for (int i = 0; i < inc.count; ++i) {
        const double d = dot(n, inc.normals[i]);
        if (d < minDot) {
            minDot = d;
            incEdge = i;
        }
    }
    const int incNext = (incEdge + 1) % inc.count;
    const ClipVertex incident[2] = {{inc.vertices[incEdge], std::uint32_t(incEdge)},
                                    {inc.vertices[incNext], std::uint32_t(incNext)}};
    const Vec2 v1 = ref.vertices[refEdge], v2 = ref.vertices[(refEdge + 1) % ref.count];
    const Vec2 t = (v2 - v1) / length(v2 - v1);
    ClipVertex clipped1[2], clipped2[2];
    const bool clipped = clipSegment(incident, clipped1, -t, -dot(t, v1), 16 + std::uint32_t(refEdge)) == 2 &&
                         clipSegment(clipped1, clipped2, t, dot(t, v2), 24 + std::uint32_t(refEdge)) == 2;
    if (!clipped) return nearest ? cornerPoint(*nearest, nearestVertexA, nearestVertex) : m;
    // The reference side's radius and the incident side's.
    const double rRef = capsuleReference ? rA : rB, rInc = capsuleReference ? rB : rA;
    m.normal = capsuleReference ? n : -n;
    for (const ClipVertex& cv : clipped2) {
        const double depth = dot(n, cv.v - v1);  // core to core along n
        const double separation = depth - rSum;
        if (separation > margin) continue;
        ManifoldPoint& p = m.points[m.pointCount++];
        p.separation = separation;
        // Midway between the reference surface (v1 plane + rRef) and the
        // incident one (cv - rInc n).
        p.point = cv.v - 0.5 * (depth - rRef + rInc) * n;
        p.id = (capsuleReference ? kCapsuleFaceOfA : kCapsuleFaceOfB) | (std::uint32_t(refEdge) << 8) | cv.id;
    }
    if (m.pointCount == 0 && nearest) return cornerPoint(*nearest, nearestVertexA, nearestVertex);
    return m;
}

Manifold collideWorldCapsulePolygon(Vec2 a1, Vec2 a2, double rA, const WorldPolygon& b, double rB, double margin) {
    return collideWorldRoundedPolygons(worldSegment(a1, a2), rA, b, rB, margin);
}


// ------------------------------------------------------------ chain segments
// A chain segment is one-sided and smooth: Box2D v3's chain segments (its
// b2CollideChainSegmentAndPolygon and the Gauss-map classification of
// https://box2d.org/posts/2020/06/ghost-collisions/), written for this
// engine's manifolds: world coordinates, speculative margin, no GJK (the
// closest features of a segment and a convex polygon come from the edge
// pairs directly).

/// A chain segment placed in the world, with the quantities its contacts
/// are judged by.
struct WorldChainSegment {
    Vec2 p1, p2;
    Vec2 edge1;            ///< unit direction p1 -> p2
    Vec2 normal1;          ///< right of edge1: the solid side
    Vec2 normal0, normal2; ///< the neighbours' normals
    bool convex1 = false, convex2 = false;  ///< whether each joint bends away from the solid side
    bool open1 = false, open2 = false;
    std::uint32_t index = 0;
};

Vec2 rightPerp(Vec2 v) { return {v.y, -v.x}; }

WorldChainSegment worldChainSegment(const ChainSegment& s, Vec2 p, Rot q) {
    WorldChainSegment w;
    w.p1 = p + rotate(q, s.p1);
    w.p2 = p + rotate(q, s.p2);
    const Vec2 g1 = p + rotate(q, s.ghost1), g2 = p + rotate(q, s.ghost2);
    w.edge1 = (w.p2 - w.p1) / length(w.p2 - w.p1);
    w.normal1 = rightPerp(w.edge1);
    // Box2D's tolerance: a joint bent by less than about half a degree is
    // flat, and its contacts snap to this segment's normal.
    constexpr double kConvexTol = 0.01;
    const Vec2 edge0 = (w.p1 - g1) / length(w.p1 - g1);
    w.normal0 = rightPerp(edge0);
    w.convex1 = cross(edge0, w.edge1) >= kConvexTol;
    const Vec2 edge2 = (g2 - w.p2) / length(g2 - w.p2);
    w.normal2 = rightPerp(edge2);
    w.convex2 = cross(w.edge1, edge2) >= kConvexTol;
    w.open1 = s.open1;
    w.open2 = s.open2;
    w.index = s.index;
    return w;
}

enum class NormalType { Skip, Admit, Snap };

/// Where a contact normal (from the segment toward the body) falls on the
/// segment's Gauss map: past a convex joint it belongs to the neighbour
/// (Skip); toward a concave joint it snaps to the segment's own normal.
NormalType classifyNormal(const WorldChainSegment& s, Vec2 normal) {
    constexpr double kSinTol = 0.01;
    if (dot(normal, s.edge1) <= 0.0) {
        if (!s.convex1) return NormalType::Snap;
        return cross(normal, s.normal0) > kSinTol ? NormalType::Skip : NormalType::Admit;
    }
    if (!s.convex2) return NormalType::Snap;
    return cross(s.normal2, normal) > kSinTol ? NormalType::Skip : NormalType::Admit;
}

/// Local feature ids of chain contacts (6 bits; the segment's number sits
/// above them): the segment is the reference face (0x00 | end << 3 |
/// polygon vertex), a polygon face is (0x10 | end flag << 3 | vertex), one
/// point between a segment end and a polygon vertex (0x20 | end << 3 |
/// vertex), a circle (0x30 | region).
constexpr std::uint32_t kChainSegmentFace = 0x00, kChainPolygonFace = 0x10, kChainCorner = 0x20, kChainCircle = 0x30;
std::uint32_t chainId(const WorldChainSegment& s, std::uint32_t local) { return (s.index << kChainFeatureShift) | local; }

/// Two-point manifold of Box2D's b2ClipSegments: the incident edge b1-b2
/// clipped to the reference edge a1-a2 along its tangent; `normal` is the
/// reference face's outward normal, ra and rb the two sides' radii. Points
/// midway between the surfaces; those farther apart than `margin` dropped.
Manifold clipChainSegments(Vec2 a1, Vec2 a2, Vec2 b1, Vec2 b2, Vec2 normal, double ra, double rb,
                           std::uint32_t id1, std::uint32_t id2, double margin) {
    Manifold m;
    const Vec2 tangent = perp(normal);
    const double lower1 = 0.0, upper1 = dot(a2 - a1, tangent);
    // The incident edge runs against the tangent (counter-clockwise winding).
    const double upper2 = dot(b1 - a1, tangent), lower2 = dot(b2 - a1, tangent);
    if (upper2 < lower1 || upper1 < lower2) return m;
    constexpr double kTiny = 1e-12;
    const Vec2 vLower = lower2 < lower1 && upper2 - lower2 > kTiny
                            ? b2 + ((lower1 - lower2) / (upper2 - lower2)) * (b1 - b2)
                            : b2;
    const Vec2 vUpper = upper2 > upper1 && upper2 - lower2 > kTiny
                            ? b2 + ((upper1 - lower2) / (upper2 - lower2)) * (b1 - b2)
                            : b1;
    const double radius = ra + rb;
    const Vec2 v[2] = {vLower, vUpper};
    const std::uint32_t ids[2] = {id1, id2};
    m.normal = normal;
    for (int i = 0; i < 2; ++i) {
        const double depth = dot(v[i] - a1, normal);
        const double separation = depth - radius;
        if (separation > margin) continue;
        ManifoldPoint& p = m.points[m.pointCount++];
        p.separation = separation;
        p.point = v[i] + (0.5 * (ra - rb - depth)) * normal;
        p.id = ids[i];
    }
    return m;
}

/// The closest features of segment p1-p2 and a convex polygon (or a
/// capsule's two-sided core): what Box2D reads from GJK's simplex.
struct SegmentPolygonDistance {
    double distance = 0.0;
    Vec2 pointA, pointB;
    int indexA = -1;       ///< the segment end that is closest (0 or 1), -1: an inner point
    int ib1 = -1, ib2 = -1;  ///< the polygon's closest vertex (ib1 == ib2) or edge
};

SegmentPolygonDistance segmentPolygonDistance(Vec2 p1, Vec2 p2, const WorldPolygon& b) {
    SegmentPolygonDistance out;
    // An end inside the polygon: they overlap.
    if (b.count >= 3) {
        bool inside = true;
        for (int i = 0; i < b.count && inside; ++i) inside = dot(b.normals[i], p1 - b.vertices[i]) <= 0.0;
        if (inside) return out;
    }
    double best = std::numeric_limits<double>::infinity();
    SegmentClosest nearest;
    int edge = 0;
    const int edges = b.count == 2 ? 1 : b.count;
    for (int i = 0; i < edges; ++i) {
        const SegmentClosest c = closestOnSegments(p1, p2, b.vertices[i], b.vertices[(i + 1) % b.count]);
        const double d2 = lengthSquared(c.onSecond - c.onFirst);
        if (d2 < best) {
            best = d2;
            nearest = c;
            edge = i;
        }
    }
    out.distance = std::sqrt(best);
    out.pointA = nearest.onFirst;
    out.pointB = nearest.onSecond;
    const int next = (edge + 1) % b.count;
    if (nearest.s == 0.0 || nearest.s == 1.0) out.indexA = nearest.s == 1.0 ? 1 : 0;
    if (nearest.t == 0.0 || nearest.t == 1.0 || out.indexA < 0) {
        out.ib1 = out.ib2 = nearest.t > 0.5 ? next : edge;
    } else {
        out.ib1 = edge;
        out.ib2 = next;
    }
    return out;
}

/// Chain segment A against convex polygon B swept by rB (a box or polygon,
/// or a capsule's core with its radius). Normal from the segment to B.
Manifold collideWorldChainPolygon(const WorldChainSegment& s, const WorldPolygon& b, Vec2 centroidB, double rB,
                                  double margin) {
    const Vec2 p1 = s.p1, p2 = s.p2, normal1 = s.normal1;
    // One-sided: a body whose centre is behind this segment and behind the
    // convex neighbours passes.
    const bool behind1 = dot(normal1, centroidB - p1) < 0.0;
    const bool behind0 = !s.convex1 || dot(s.normal0, centroidB - p1) < 0.0;
    const bool behind2 = !s.convex2 || dot(s.normal2, centroidB - p2) < 0.0;
    if (behind1 && behind0 && behind2) return Manifold{};

    const SegmentPolygonDistance output = segmentPolygonDistance(p1, p2, b);
    if (output.distance > rB + margin) return Manifold{};
    const int count = b.count;
    const Vec2 n0 = s.convex1 ? s.normal0 : normal1;  // concave neighbours snap to this segment
    const Vec2 n2 = s.convex2 ? s.normal2 : normal1;
    // Whether the neighbour across the near joint is the one the body meets
    // along face normal n of B (n points out of B).
    const auto neighbourIncident = [&](Vec2 n, Vec2 faceStart) {
        const double dot1 = dot(n, p1 - faceStart), dot2 = dot(n, p2 - faceStart);
        return dot1 < dot2 ? dot(n0, n) < dot(normal1, n) : dot(n2, n) < dot(normal1, n);
    };
    const auto withIds = [&](Manifold m) {
        for (int i = 0; i < m.pointCount; ++i) m.points[i].id = chainId(s, m.points[i].id);
        return m;
    };
    // B's face i as the reference: the normal from the segment is -n.
    const auto polygonFace = [&](int i) {
        const int i2 = (i + 1) % count;
        Manifold m = clipChainSegments(b.vertices[i], b.vertices[i2], p1, p2, b.normals[i], rB, 0.0,
                                       kChainPolygonFace | 0x8 | std::uint32_t(i), kChainPolygonFace | std::uint32_t(i2),
                                       margin);
        m.normal = -b.normals[i];
        return withIds(m);
    };

    constexpr double kTouching = 0.1 * 0.005;  // a tenth of the linear slop, metres
    int incidentIndex = -1, incidentNormal = -1;
    if (!behind1 && output.distance > kTouching) {
        // Apart: the closest features may be two vertices or a vertex and an
        // edge even when the contact should be face to face.
        if (output.indexA >= 0 && output.ib1 == output.ib2) {
            const Vec2 normal = (output.pointB - output.pointA) / output.distance;
            const NormalType type = classifyNormal(s, normal);
            if (type == NormalType::Skip) return Manifold{};
            if (type == NormalType::Admit) {
                Manifold m;
                m.normal = normal;
                m.pointCount = 1;
                m.points[0].separation = output.distance - rB;
                m.points[0].point = output.pointA + (0.5 * (output.distance - rB)) * normal;
                m.points[0].id = chainId(s, kChainCorner | (std::uint32_t(output.indexA) << 3) | std::uint32_t(output.ib1));
                return m;
            }
            incidentIndex = output.ib1;  // snap: the segment's face
        } else if (output.indexA >= 0) {
            // A segment end against an edge of B: B's face most aligned with
            // the line between them.
            const Vec2 toA = output.pointA - output.pointB;
            const int ib = dot(toA, b.normals[output.ib1]) > dot(toA, b.normals[output.ib2]) ? output.ib1 : output.ib2;
            const Vec2 normalB = b.normals[ib];
            const NormalType type = classifyNormal(s, -normalB);
            if (type == NormalType::Skip) return Manifold{};
            if (type == NormalType::Admit) {
                if (neighbourIncident(normalB, b.vertices[ib])) return Manifold{};
                return polygonFace(ib);
            }
            incidentNormal = ib;
        } else {
            // A vertex of B against the inside of the segment.
            incidentIndex = output.ib1;
        }
    } else {
        // Overlapping or touching: separating axes. The segment's own normal
        // and its convex neighbours' ...
        double edgeSeparation = std::numeric_limits<double>::infinity();
        for (int i = 0; i < count; ++i) {
            const double d = dot(normal1, b.vertices[i] - p1);
            if (d < edgeSeparation) {
                edgeSeparation = d;
                incidentIndex = i;
            }
        }
        if (s.convex1) {
            double s0 = std::numeric_limits<double>::infinity();
            for (int i = 0; i < count; ++i) s0 = std::min(s0, dot(s.normal0, b.vertices[i] - p1));
            if (s0 > edgeSeparation) {
                edgeSeparation = s0;
                incidentIndex = -1;  // the neighbour owns this axis
            }
        }
        if (s.convex2) {
            double s2 = std::numeric_limits<double>::infinity();
            for (int i = 0; i < count; ++i) s2 = std::min(s2, dot(s.normal2, b.vertices[i] - p2));
            if (s2 > edgeSeparation) {
                edgeSeparation = s2;
                incidentIndex = -1;
            }
        }
        // ... and B's face normals that this segment admits.
        double polygonSeparation = -std::numeric_limits<double>::infinity();
        int referenceIndex = -1;
        for (int i = 0; i < count; ++i) {
            const Vec2 n = b.normals[i];
            if (classifyNormal(s, -n) != NormalType::Admit) continue;
            const double sep = std::min(dot(n, p2 - b.vertices[i]), dot(n, p1 - b.vertices[i]));
            if (sep > polygonSeparation) {
                polygonSeparation = sep;
                referenceIndex = i;
            }
        }
        if (polygonSeparation > edgeSeparation) {
            if (neighbourIncident(b.normals[referenceIndex], b.vertices[referenceIndex])) return Manifold{};
            return polygonFace(referenceIndex);
        }
        if (incidentIndex == -1) return Manifold{};  // a neighbour's axis separates best
    }

    // The segment's face is the reference: B's incident edge is the one
    // beside the deepest vertex most against the segment's normal.
    int ib1, ib2;
    if (incidentNormal != -1) {
        ib1 = incidentNormal;
        ib2 = (ib1 + 1) % count;
    } else {
        const int i2 = incidentIndex, i1 = i2 > 0 ? i2 - 1 : count - 1;
        if (dot(normal1, b.normals[i1]) < dot(normal1, b.normals[i2])) {
            ib1 = i1;
            ib2 = i2;
        } else {
            ib1 = i2;
            ib2 = (i2 + 1) % count;
        }
    }
    return withIds(clipChainSegments(p1, p2, b.vertices[ib1], b.vertices[ib2], normal1, 0.0, rB,
                                     kChainSegmentFace | std::uint32_t(ib2), kChainSegmentFace | 0x8 | std::uint32_t(ib1),
                                     margin));
}

/// Chain segment A against circle B (centre pB, radius r).
Manifold collideWorldChainCircle(const WorldChainSegment& s, double r, Vec2 pB, double margin) {
    const Vec2 p1 = s.p1, p2 = s.p2, e = p2 - p1;
    // One-sided: a centre behind the segment passes.
    if (dot(rightPerp(e), pB - p1) < 0.0) return Manifold{};
    const double u = dot(e, p2 - pB), v = dot(e, pB - p1);
    Vec2 pA;
    std::uint32_t region = 0;
    if (v <= 0.0) {
        // Before p1: that joint's corner belongs to the previous segment (it
        // meets it past its p2), so only an open end answers here.
        if (!s.open1) return Manifold{};
        pA = p1;
        region = 1;
    } else if (u <= 0.0) {
        // Past p2: in the next segment's Voronoi region (ahead along its
        // direction) the next segment answers; an open end's ghost points
        // straight down behind it, so it answers here.
        if (dot(perp(s.normal2), pB - p2) > 0.0) return Manifold{};
        pA = p2;
        region = 2;
    } else {
        pA = p1 + (v / dot(e, e)) * e;
    }
    const Vec2 d = pB - pA;
    const double dist = length(d);
    const double separation = dist - r;
    if (separation > margin) return Manifold{};
    Manifold m;
    m.normal = dist > 1e-12 ? d / dist : s.normal1;
    m.pointCount = 1;
    m.points[0].separation = separation;
    m.points[0].point = pA + (0.5 * separation) * m.normal;
    m.points[0].id = chainId(s, kChainCircle | region);
    return m;
}
} // namespace

// A rounded polygon (cornerRadius > 0) takes the rounded routines; a sharp
// one the plain ones, as before rounding existed.

Manifold collidePolygons(const ConvexPolygon& a, Vec2 pA, Rot qA, const ConvexPolygon& b, Vec2 pB, Rot qB,
                         double margin) {
    if (a.cornerRadius > 0.0 || b.cornerRadius > 0.0)
        return collideWorldRoundedPolygons(worldPolygon(a, pA, qA), a.cornerRadius, worldPolygon(b, pB, qB),
                                           b.cornerRadius, margin);
    return collideWorldPolygons(worldPolygon(a, pA, qA), worldPolygon(b, pB, qB), margin);
}

Manifold collideBoxPolygon(Vec2 hA, Vec2 pA, Rot qA, const ConvexPolygon& b, Vec2 pB, Rot qB, double margin) {
    if (b.cornerRadius > 0.0)
        return collideWorldRoundedPolygons(worldPolygon(worldBox(hA, pA, qA)), 0.0, worldPolygon(b, pB, qB),
                                           b.cornerRadius, margin);
    return collideWorldPolygons(worldPolygon(worldBox(hA, pA, qA)), worldPolygon(b, pB, qB), margin);
}

Manifold collidePolygonCircle(const ConvexPolygon& a, Vec2 pA, Rot qA, double rB, Vec2 pB, double margin) {
    if (a.cornerRadius > 0.0) {
        // The core against a circle as large as both radii; the point then
        // moves out by the rounding to sit midway between the surfaces.
        Manifold m = collideWorldPolygonCircle(worldPolygon(a, pA, qA), rB + a.cornerRadius, pB, margin);
        for (int i = 0; i < m.pointCount; ++i) m.points[i].point += a.cornerRadius * m.normal;
        return m;
    }
    return collideWorldPolygonCircle(worldPolygon(a, pA, qA), rB, pB, margin);
}

Manifold collidePlanePolygon(Vec2 n, double offset, const ConvexPolygon& b, Vec2 pB, Rot qB, double margin) {
    if (b.cornerRadius > 0.0) {
        // The core against the plane moved out by the rounding; the point
        // then moves back to sit midway between the surfaces.
        Manifold m = collidePlaneWorldPolygon(n, offset + b.cornerRadius, worldPolygon(b, pB, qB), margin);
        for (int i = 0; i < m.pointCount; ++i) m.points[i].point -= b.cornerRadius * n;
        return m;
    }
    return collidePlaneWorldPolygon(n, offset, worldPolygon(b, pB, qB), margin);
}

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
    const BoxPolygon a = worldBox(hA, pA, qA), b = worldBox(hB, pB, qB);
    const auto [edgeA, separationA] = maxSeparation(a, b);
    if (separationA > margin) return Manifold{};
    const auto [edgeB, separationB] = maxSeparation(b, a);
    if (separationB > margin) return Manifold{};

    // Prefer A's face unless B's is clearly better: keeps the reference face
    // from flickering between steps when the two are nearly equal.
    const bool flip = separationB > 0.98 * separationA + 0.0005;
    return clipIncidentEdge(flip ? b : a, flip ? edgeB : edgeA, flip ? a : b, flip, margin, 8, 4);
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
    return collidePlaneWorldPolygon(n, offset, worldPolygon(worldBox(h, pB, qB)), margin);
}

Manifold collideCapsuleCircle(Vec2 a1, Vec2 a2, double rA, double rB, Vec2 pB, double margin) {
    const Vec2 d = a2 - a1;
    const double len2 = lengthSquared(d);
    const double u = len2 > 0.0 ? std::clamp(dot(pB - a1, d) / len2, 0.0, 1.0) : 0.0;
    return collideCircles(rA, a1 + u * d, rB, pB, margin);
}

Manifold collidePlaneCapsule(Vec2 n, double offset, Vec2 b1, Vec2 b2, double rB, double margin) {
    // Each end's cap against the plane: two points when the capsule lies on
    // it, ids the ends' numbers.
    Manifold m;
    m.normal = n;
    const Vec2 ends[2] = {b1, b2};
    for (int i = 0; i < 2; ++i) {
        const double separation = dot(n, ends[i]) - offset - rB;
        if (separation > margin) continue;
        ManifoldPoint& p = m.points[m.pointCount++];
        p.separation = separation;
        p.point = ends[i] - (rB + 0.5 * separation) * n;
        p.id = std::uint32_t(i);
    }
    return m;
}

Manifold collideCapsules(Vec2 a1, Vec2 a2, double rA, Vec2 b1, Vec2 b2, double rB, double margin) {
    return collideWorldCapsulePolygon(a1, a2, rA, worldSegment(b1, b2), rB, margin);
}

Manifold collideCapsuleBox(Vec2 a1, Vec2 a2, double rA, Vec2 hB, Vec2 pB, Rot qB, double margin) {
    return collideWorldCapsulePolygon(a1, a2, rA, worldPolygon(worldBox(hB, pB, qB)), 0.0, margin);
}

Manifold collideCapsulePolygon(Vec2 a1, Vec2 a2, double rA, const ConvexPolygon& b, Vec2 pB, Rot qB,
                               double margin) {
    return collideWorldCapsulePolygon(a1, a2, rA, worldPolygon(b, pB, qB), b.cornerRadius, margin);
}

Manifold collide(const Shape& a, Vec2 pA, Rot qA, const Shape& b, Vec2 pB, Rot qB, double margin) {
    auto flipped = [](Manifold m) {
        m.normal = -m.normal;
        return m;
    };
    if (a.kind == ShapeKind::ChainSegment || b.kind == ShapeKind::ChainSegment) {
        // Chain first: every pair with a chain segment is written as segment
        // A against B, then flipped back. Chains sit on static bodies, so a
        // chain never meets a plane or another chain (neither moves).
        const bool chainA = a.kind == ShapeKind::ChainSegment;
        const Shape& chain = chainA ? a : b;
        const Shape& other = chainA ? b : a;
        const Vec2 pC = chainA ? pA : pB, pO = chainA ? pB : pA;
        const Rot qC = chainA ? qA : qB, qO = chainA ? qB : qA;
        const WorldChainSegment s = worldChainSegment(*chain.segment, pC, qC);
        Manifold m;
        switch (other.kind) {
        case ShapeKind::Circle: m = collideWorldChainCircle(s, other.radius, pO, margin); break;
        case ShapeKind::Box:
            m = collideWorldChainPolygon(s, worldPolygon(worldBox(other.halfExtents, pO, qO)), pO, 0.0, margin);
            break;
        case ShapeKind::Polygon:
            m = collideWorldChainPolygon(s, worldPolygon(*other.polygon, pO, qO), pO, other.polygon->cornerRadius,
                                         margin);
            break;
        case ShapeKind::Capsule: {
            const Vec2 h = rotate(qO, other.halfExtents);
            m = collideWorldChainPolygon(s, worldSegment(pO - h, pO + h), pO, other.radius, margin);
            break;
        }
        case ShapeKind::Plane:
        case ShapeKind::ChainSegment: break;
        }
        return chainA ? m : flipped(m);
    }
    if (a.kind == ShapeKind::Capsule || b.kind == ShapeKind::Capsule) {
        // Capsule first: every pair with a capsule is written as capsule (or
        // plane) A against B, then flipped back.
        const auto ends = [](const Shape& s, Vec2 p, Rot q) {
            const Vec2 h = rotate(q, s.halfExtents);
            return std::pair<Vec2, Vec2>{p - h, p + h};
        };
        if (a.kind == ShapeKind::Capsule) {
            const auto [a1, a2] = ends(a, pA, qA);
            switch (b.kind) {
            case ShapeKind::Circle: return collideCapsuleCircle(a1, a2, a.radius, b.radius, pB, margin);
            case ShapeKind::Box: return collideCapsuleBox(a1, a2, a.radius, b.halfExtents, pB, qB, margin);
            case ShapeKind::Polygon: return collideCapsulePolygon(a1, a2, a.radius, *b.polygon, pB, qB, margin);
            case ShapeKind::Plane: return flipped(collidePlaneCapsule(b.normal, b.offset, a1, a2, a.radius, margin));
            case ShapeKind::Capsule: {
                const auto [b1, b2] = ends(b, pB, qB);
                return collideCapsules(a1, a2, a.radius, b1, b2, b.radius, margin);
            }
            case ShapeKind::ChainSegment: break;  // handled above
            }
            return Manifold{};
        }
        const auto [b1, b2] = ends(b, pB, qB);
        switch (a.kind) {
        case ShapeKind::Circle: return flipped(collideCapsuleCircle(b1, b2, b.radius, a.radius, pA, margin));
        case ShapeKind::Box: return flipped(collideCapsuleBox(b1, b2, b.radius, a.halfExtents, pA, qA, margin));
        case ShapeKind::Polygon: return flipped(collideCapsulePolygon(b1, b2, b.radius, *a.polygon, pA, qA, margin));
        case ShapeKind::Plane: return collidePlaneCapsule(a.normal, a.offset, b1, b2, b.radius, margin);
        case ShapeKind::Capsule:
        case ShapeKind::ChainSegment: break;  // handled above
        }
        return Manifold{};
    }
    if (a.kind == ShapeKind::Polygon || b.kind == ShapeKind::Polygon) {
        // Polygon first: every pair with a polygon is written as polygon (or
        // plane, or box) A against B, then flipped back.
        if (a.kind == ShapeKind::Polygon) {
            switch (b.kind) {
            case ShapeKind::Circle: return collidePolygonCircle(*a.polygon, pA, qA, b.radius, pB, margin);
            case ShapeKind::Box: return flipped(collideBoxPolygon(b.halfExtents, pB, qB, *a.polygon, pA, qA, margin));
            case ShapeKind::Polygon: return collidePolygons(*a.polygon, pA, qA, *b.polygon, pB, qB, margin);
            case ShapeKind::Plane: return flipped(collidePlanePolygon(b.normal, b.offset, *a.polygon, pA, qA, margin));
            case ShapeKind::Capsule:
            case ShapeKind::ChainSegment: break;  // handled above
            }
            return Manifold{};
        }
        switch (a.kind) {
        case ShapeKind::Circle: return flipped(collidePolygonCircle(*b.polygon, pB, qB, a.radius, pA, margin));
        case ShapeKind::Box: return collideBoxPolygon(a.halfExtents, pA, qA, *b.polygon, pB, qB, margin);
        case ShapeKind::Plane: return collidePlanePolygon(a.normal, a.offset, *b.polygon, pB, qB, margin);
        case ShapeKind::Polygon:
        case ShapeKind::Capsule:
        case ShapeKind::ChainSegment: break;
        }
        return Manifold{};
    }
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
    case ShapeKind::Polygon:
    case ShapeKind::Capsule:
    case ShapeKind::ChainSegment: break;  // handled above
    }
    return Manifold{};
}

Aabb computeAabb(const Shape& shape, Vec2 p, Rot q) {
    if (shape.kind == ShapeKind::Circle) return {p - Vec2{shape.radius, shape.radius}, p + Vec2{shape.radius, shape.radius}};
    if (shape.kind == ShapeKind::Polygon) {
        Aabb box{p + rotate(q, shape.polygon->vertices[0]), p + rotate(q, shape.polygon->vertices[0])};
        for (int i = 1; i < shape.polygon->count; ++i) {
            const Vec2 v = p + rotate(q, shape.polygon->vertices[i]);
            box.lower = {std::min(box.lower.x, v.x), std::min(box.lower.y, v.y)};
            box.upper = {std::max(box.upper.x, v.x), std::max(box.upper.y, v.y)};
        }
        if (const double r = shape.polygon->cornerRadius; r > 0.0) {
            box.lower -= Vec2{r, r};
            box.upper += Vec2{r, r};
        }
        return box;
    }
    if (shape.kind == ShapeKind::ChainSegment) {
        const Vec2 p1 = p + rotate(q, shape.segment->p1), p2 = p + rotate(q, shape.segment->p2);
        return {{std::min(p1.x, p2.x), std::min(p1.y, p2.y)}, {std::max(p1.x, p2.x), std::max(p1.y, p2.y)}};
    }
    if (shape.kind == ShapeKind::Capsule) {
        const Vec2 h = rotate(q, shape.halfExtents);
        const Vec2 e{std::abs(h.x) + shape.radius, std::abs(h.y) + shape.radius};
        return {p - e, p + e};
    }
    const Vec2 h = shape.halfExtents;
    const Vec2 e{std::abs(q.c) * h.x + std::abs(q.s) * h.y, std::abs(q.s) * h.x + std::abs(q.c) * h.y};
    return {p - e, p + e};
}

} // namespace stepwise::collision
