#pragma once
// Continuous collision against the static world, after a step's solve.
//
// The speculative margins cover the motion a body was predicted to make
// when the step's contacts were found. A body that the solve sped up within
// the step (struck by a crowd behind it, or by a fast paddle) can travel
// farther than that, toward static geometry it had no contact with, and a
// one-sided chain lets it go once its centre is past a segment. As Box2D
// v3's continuous stage does, such a body is swept from its step-start pose
// to its end pose against the static shapes near its path: where its
// centroid would pass into one (or behind a chain segment), the body is put
// back at the time its shape reaches that surface.

#include "collision/collision_types.hpp"

namespace stepwise::collision {

/// A body's motion over one step: its centre of mass on a line, its angle
/// at a constant rate (Box2D's b2Sweep).
struct BodySweep {
    Vec2 c0, c1;       ///< centre of mass at the start and the end, metres
    double a0 = 0.0, a1 = 0.0;  ///< angle at the start and the end, rad

    Vec2 centreAt(double t) const { return c0 + t * (c1 - c0); }
    double angleAt(double t) const { return a0 + t * (a1 - a0); }
};

/// One shape of the swept body: its geometry and its centre relative to
/// the body's centre of mass, in the body frame (zero for a single shape).
struct SweptShape {
    const Shape* shape = nullptr;
    Vec2 offset;
};

/// A static shape where it sits in the world.
struct PlacedShape {
    const Shape* shape = nullptr;
    Vec2 centre;
    Rot q;
};

/// The fraction of the step, in (0, 1), at which the body must stop so that
/// this shape's centroid does not pass into the static shape (for a chain
/// segment: behind it, within its length): the time its outline comes to
/// `target` metres from the surface the centroid would cross, or, if it
/// started closer than that, the time a core circle of a quarter of its
/// smallest reach does (0, held where it started, if that core started
/// closer too). 1 when the centroid does not pass in, or when it
/// started inside or behind (Box2D's rule: such a body is already past
/// saving, and holding it back would only pin it there).
double sweepFraction(const BodySweep& sweep, const SweptShape& moving, const PlacedShape& fixed, double target);

/// The smallest distance from the centre of `shape` to its outline.
double smallestReach(const Shape& shape);

/// The largest distance from the centre of `shape` to its outline along
/// the unit direction `d` (its support), with the shape turned by `q`.
double supportAlong(const Shape& shape, Rot q, Vec2 d);

} // namespace stepwise::collision
