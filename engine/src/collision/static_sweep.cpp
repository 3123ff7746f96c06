#include "collision/static_sweep.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::collision {

namespace {

/// A convex static shape as a signed distance-like function of a point:
/// negative inside, zero on the outline, convex in the point (so along a
/// line it has one minimum), with the outward normal where it is evaluated.
struct Outline {
    const Shape& shape;
    Vec2 centre;
    Rot q;

    struct Value {
        double f;
        Vec2 normal;
    };

    Value operator()(Vec2 p) const {
        switch (shape.kind) {
        case ShapeKind::Plane: return {dot(shape.normal, p) - shape.offset, shape.normal};
        case ShapeKind::Circle: {
            const Vec2 d = p - centre;
            const double r = length(d);
            return {r - shape.radius, r > 0.0 ? d / r : Vec2{0.0, 1.0}};
        }
        case ShapeKind::Box: {
            const Vec2 l = invRotate(q, p - centre);
            const double fx = std::abs(l.x) - shape.halfExtents.x, fy = std::abs(l.y) - shape.halfExtents.y;
            if (fx >= fy) return {fx, rotate(q, Vec2{l.x >= 0.0 ? 1.0 : -1.0, 0.0})};
            return {fy, rotate(q, Vec2{0.0, l.y >= 0.0 ? 1.0 : -1.0})};
        }
        case ShapeKind::Polygon: {
            // The faces' planes pushed out by the corner radius: the rounded
            // corners are taken as sharp, a little more solid than they are.
            const ConvexPolygon& poly = *shape.polygon;
            const Vec2 l = invRotate(q, p - centre);
            int best = 0;
            double f = dot(l - poly.vertices[0], poly.normals[0]);
            for (int i = 1; i < poly.count; ++i) {
                const double fi = dot(l - poly.vertices[i], poly.normals[i]);
                if (fi > f) f = fi, best = i;
            }
            return {f - poly.cornerRadius, rotate(q, poly.normals[best])};
        }
        case ShapeKind::Capsule: {
            const Vec2 l = invRotate(q, p - centre);
            const Vec2 h = shape.halfExtents;
            const double hh = dot(h, h);
            const double u = hh > 0.0 ? std::clamp(dot(l, h) / hh, -1.0, 1.0) : 0.0;
            const Vec2 d = l - u * h;
            const double r = length(d);
            return {r - shape.radius, rotate(q, r > 0.0 ? d / r : perp(h) / std::sqrt(std::max(hh, 1e-300)))};
        }
        case ShapeKind::ChainSegment: break;
        }
        return {1.0, Vec2{0.0, 1.0}};
    }
};

/// Where the path p0 -> p1 first enters the static shape: the fraction,
/// the point on the outline and the outward normal there. False when it
/// starts inside (or behind a chain segment) or never enters.
struct Entry {
    double t = 1.0;
    Vec2 point, normal;
};

bool chainEntry(const Shape& shape, Vec2 centre, Rot q, Vec2 p0, Vec2 p1, Entry& entry) {
    const Vec2 a = centre + rotate(q, shape.segment->p1), b = centre + rotate(q, shape.segment->p2);
    const Vec2 e = b - a;
    const double ee = dot(e, e);
    if (!(ee > 0.0)) return false;
    // The solid side is on the right of the segment's direction.
    const Vec2 n = Vec2{e.y, -e.x} / std::sqrt(ee);
    const double f0 = dot(p0 - a, n), f1 = dot(p1 - a, n);
    if (!(f0 >= 0.0) || !(f1 < 0.0)) return false;
    const double t = f0 / (f0 - f1);
    const Vec2 x = p0 + t * (p1 - p0);
    const double u = dot(x - a, e) / ee;
    if (u < 0.0 || u > 1.0) return false;  // past an end: the neighbour's, or open
    entry = {t, x, n};
    return true;
}

bool convexEntry(const Outline& outline, Vec2 p0, Vec2 p1, Entry& entry) {
    const auto at = [&](double t) { return p0 + t * (p1 - p0); };
    if (!(outline(p0).f > 0.0)) return false;
    // The path's deepest point: f along a line is convex, so a ternary
    // search finds its minimum; the path enters only if that is inside.
    double lo = 0.0, hi = 1.0;
    if (!(outline(p1).f < 0.0)) {
        for (int k = 0; k < 60 && hi - lo > 1e-9; ++k) {
            const double m1 = lo + (hi - lo) / 3.0, m2 = hi - (hi - lo) / 3.0;
            if (outline(at(m1)).f < outline(at(m2)).f) hi = m2;
            else lo = m1;
        }
        if (!(outline(at(0.5 * (lo + hi))).f < 0.0)) return false;
        hi = 0.5 * (lo + hi);
    }
    // The first crossing of the outline, in [0, hi].
    lo = 0.0;
    for (int k = 0; k < 60 && hi - lo > 1e-12; ++k) {
        const double m = 0.5 * (lo + hi);
        if (outline(at(m)).f > 0.0) lo = m;
        else hi = m;
    }
    // The normal is read just outside, where the face that is crossed is
    // the nearest one.
    entry = {lo, at(lo), outline(at(lo)).normal};
    return true;
}

} // namespace

double smallestReach(const Shape& shape) {
    switch (shape.kind) {
    case ShapeKind::Circle:
    case ShapeKind::Capsule: return shape.radius;
    case ShapeKind::Box: return std::min(shape.halfExtents.x, shape.halfExtents.y);
    case ShapeKind::Polygon: {
        const ConvexPolygon& poly = *shape.polygon;
        double reach = -dot(poly.vertices[0], poly.normals[0]);
        for (int i = 1; i < poly.count; ++i) reach = std::min(reach, -dot(poly.vertices[i], poly.normals[i]));
        return std::max(reach, 0.0) + poly.cornerRadius;
    }
    default: return 0.0;
    }
}

double supportAlong(const Shape& shape, Rot q, Vec2 d) {
    switch (shape.kind) {
    case ShapeKind::Circle: return shape.radius;
    case ShapeKind::Box:
        return std::abs(dot(rotate(q, Vec2{1.0, 0.0}), d)) * shape.halfExtents.x +
               std::abs(dot(rotate(q, Vec2{0.0, 1.0}), d)) * shape.halfExtents.y;
    case ShapeKind::Polygon: {
        const ConvexPolygon& poly = *shape.polygon;
        const Vec2 l = invRotate(q, d);
        double most = dot(poly.vertices[0], l);
        for (int i = 1; i < poly.count; ++i) most = std::max(most, dot(poly.vertices[i], l));
        return most + poly.cornerRadius;
    }
    case ShapeKind::Capsule: return std::abs(dot(rotate(q, shape.halfExtents), d)) + shape.radius;
    default: return 0.0;
    }
}

double sweepFraction(const BodySweep& sweep, const SweptShape& moving, const PlacedShape& fixed, double target) {
    const auto centreAt = [&](double t) {
        return sweep.centreAt(t) + rotate(Rot::fromAngle(sweep.angleAt(t)), moving.offset);
    };
    // The shape's centroid is taken along the chord between its two ends:
    // within one step the turn is small.
    const Vec2 p0 = centreAt(0.0), p1 = centreAt(1.0);
    Entry entry;
    const bool enters = fixed.shape->kind == ShapeKind::ChainSegment
                            ? chainEntry(*fixed.shape, fixed.centre, fixed.q, p0, p1, entry)
                            : convexEntry(Outline{*fixed.shape, fixed.centre, fixed.q}, p0, p1, entry);
    if (!enters) return 1.0;
    // The surface crossed, as a plane through the entry point: the body's
    // gap to it at time t, from its outline or from its core.
    const Vec2 n = entry.normal;
    const auto gap = [&](double t, double reach) { return dot(centreAt(t) - entry.point, n) - reach; };
    const auto outlineGap = [&](double t) {
        return gap(t, supportAlong(*moving.shape, Rot::fromAngle(sweep.angleAt(t)), -n));
    };
    const double core = 0.25 * smallestReach(*moving.shape);
    const bool outlineClear = outlineGap(0.0) > target;
    if (!outlineClear && !(gap(0.0, core) > target)) return 0.0;  // held where it started
    const auto g = [&](double t) { return outlineClear ? outlineGap(t) : gap(t, core); };
    double lo = 0.0, hi = entry.t;
    if (!(g(hi) <= target)) {
        hi = 1.0;
        if (!(g(hi) <= target)) return 1.0;
    }
    for (int k = 0; k < 50 && hi - lo > 1e-12; ++k) {
        const double m = 0.5 * (lo + hi);
        if (g(m) > target) lo = m;
        else hi = m;
    }
    return lo;
}

} // namespace stepwise::collision
