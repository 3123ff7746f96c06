#pragma once
// Narrow phase: contact manifolds for every pair of shape kinds. Each
// function returns points whose separation is below `margin` (metres), so
// the solver gets speculative contacts for bodies about to touch (the
// continuous-collision scheme: no tunnelling when margin covers the motion
// of one step).

#include "collision/collision_types.hpp"

namespace stepwise::collision {

/// Manifold of shape A at (pA, qA) against shape B at (pB, qB). Planes
/// ignore their position and rotation (they are in world coordinates).
/// Returns pointCount == 0 when the shapes are farther apart than `margin`.
Manifold collide(const Shape& a, Vec2 pA, Rot qA, const Shape& b, Vec2 pB, Rot qB, double margin);

Manifold collideCircles(double rA, Vec2 pA, double rB, Vec2 pB, double margin);
/// Box A (half extents hA) against circle B.
Manifold collideBoxCircle(Vec2 hA, Vec2 pA, Rot qA, double rB, Vec2 pB, double margin);
Manifold collideBoxes(Vec2 hA, Vec2 pA, Rot qA, Vec2 hB, Vec2 pB, Rot qB, double margin);
/// Plane A against circle B / box B.
Manifold collidePlaneCircle(Vec2 n, double offset, double rB, Vec2 pB, double margin);
Manifold collidePlaneBox(Vec2 n, double offset, Vec2 hB, Vec2 pB, Rot qB, double margin);

/// Polygons (outlines about their centre of mass at pA/pB). Box A and plane
/// A against polygon B; polygon A against circle B.
Manifold collidePolygons(const ConvexPolygon& a, Vec2 pA, Rot qA, const ConvexPolygon& b, Vec2 pB, Rot qB,
                         double margin);
Manifold collideBoxPolygon(Vec2 hA, Vec2 pA, Rot qA, const ConvexPolygon& b, Vec2 pB, Rot qB, double margin);
Manifold collidePolygonCircle(const ConvexPolygon& a, Vec2 pA, Rot qA, double rB, Vec2 pB, double margin);
Manifold collidePlanePolygon(Vec2 n, double offset, const ConvexPolygon& b, Vec2 pB, Rot qB, double margin);

/// Capsules: the segment from c1 to c2 (world points) swept by radius r.
/// Capsule A against circle B, plane A against capsule B, capsule A against
/// capsule B, and capsule A against box B / polygon B.
Manifold collideCapsuleCircle(Vec2 a1, Vec2 a2, double rA, double rB, Vec2 pB, double margin);
Manifold collidePlaneCapsule(Vec2 n, double offset, Vec2 b1, Vec2 b2, double rB, double margin);
Manifold collideCapsules(Vec2 a1, Vec2 a2, double rA, Vec2 b1, Vec2 b2, double rB, double margin);
Manifold collideCapsuleBox(Vec2 a1, Vec2 a2, double rA, Vec2 hB, Vec2 pB, Rot qB, double margin);
Manifold collideCapsulePolygon(Vec2 a1, Vec2 a2, double rA, const ConvexPolygon& b, Vec2 pB, Rot qB,
                               double margin);

/// World-space bounding box of a circle, box, polygon, capsule or chain
/// segment (planes have none).
Aabb computeAabb(const Shape& shape, Vec2 p, Rot q);

} // namespace stepwise::collision
