#include "collision/contact_solver.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::collision {

namespace {
constexpr double kPi = 3.14159265358979323846;

/// Velocity of the material point at offset r of body b.
inline Vec2 pointVelocity(const SolverBody& b, Vec2 r) { return b.v + crossSV(b.w, r); }

inline void applyImpulse(SolverBody& a, SolverBody& b, Vec2 rA, Vec2 rB, Vec2 impulse) {
    a.v -= a.invMass * impulse;
    a.w -= a.invInertia * cross(rA, impulse);
    b.v += b.invMass * impulse;
    b.w += b.invInertia * cross(rB, impulse);
}

inline double effectiveMass(const SolverBody& a, const SolverBody& b, Vec2 rA, Vec2 rB, Vec2 dir) {
    const double rnA = cross(rA, dir), rnB = cross(rB, dir);
    const double k = a.invMass + b.invMass + a.invInertia * rnA * rnA + b.invInertia * rnB * rnB;
    return k > 0.0 ? 1.0 / k : 0.0;
}

/// Tangent direction: the normal turned clockwise, as Box2D.
inline Vec2 tangentOf(Vec2 n) { return {n.y, -n.x}; }
} // namespace

Softness Softness::make(double hertz, double dampingRatio, double h) {
    if (hertz == 0.0) return {0.0, 1.0, 0.0};
    const double omega = 2.0 * kPi * hertz;
    const double a1 = 2.0 * dampingRatio + h * omega;
    const double a2 = h * omega * a1;
    const double a3 = 1.0 / (1.0 + a2);
    return {omega / a1, a2 * a3, a3};
}

void prepareContacts(std::span<ContactConstraint> contacts, std::span<const ContactDetail> details,
                     std::span<const SolverBody> bodies) {
    for (std::size_t k = 0; k < contacts.size(); ++k) {
        ContactConstraint& c = contacts[k];
        const SolverBody& a = bodies[c.bodyA];
        const SolverBody& b = bodies[c.bodyB];
        const Vec2 t = tangentOf(c.normal);
        for (int i = 0; i < c.pointCount; ++i) {
            ContactPoint& p = c.points[i];
            p.normalMass = effectiveMass(a, b, p.anchorA, p.anchorB, c.normal);
            p.tangentMass = effectiveMass(a, b, p.anchorA, p.anchorB, t);
            // Separation later is this plus the change in the anchors' gap.
            p.adjustedSeparation = details[k].separation[i] - dot(p.anchorB - p.anchorA, c.normal);
        }
    }
}

void propagateImpacts(std::span<ContactConstraint> contacts, std::span<ContactDetail> details,
                      std::span<SolverBody> bodies, double h, double threshold, int maxPasses) {
    // Touching within this many metres counts as an impact (Box2D's linear
    // slop): without it a pair that closes its gap exactly at the end of a
    // substep would be stopped by the speculative constraint instead.
    constexpr double kSlop = 0.005;
    for (int pass = 0; pass < maxPasses; ++pass) {
        bool any = false;
        for (std::size_t k = 0; k < contacts.size(); ++k) {
            ContactConstraint& c = contacts[k];
            ContactDetail& detail = details[k];
            SolverBody& a = bodies[c.bodyA];
            SolverBody& b = bodies[c.bodyB];
            // The approaching points that touch within this substep; the
            // impulse acts at their centroid so a flat landing box does not
            // pick up spin from the order of its two corners.
            Vec2 rA{}, rB{};
            double gap = 0.0;
            int count = 0;
            for (int i = 0; i < c.pointCount; ++i) {
                const ContactPoint& p = c.points[i];
                const Vec2 pA = rotate(a.dq, p.anchorA), pB = rotate(b.dq, p.anchorB);
                const double separation = dot((b.dp - a.dp) + (pB - pA), c.normal) + p.adjustedSeparation;
                const double vn = dot(c.normal, pointVelocity(b, pB) - pointVelocity(a, pA));
                if (vn < -threshold && separation + vn * h < kSlop) {
                    rA += pA;
                    rB += pB;
                    gap += separation;
                    ++count;
                }
            }
            if (count == 0) continue;
            rA = rA / double(count);
            rB = rB / double(count);
            gap = std::max(gap / double(count), 0.0);
            const double vn = dot(c.normal, pointVelocity(b, rB) - pointVelocity(a, rA));
            // Bouncy pairs leave at e times the approach speed. Inelastic ones
            // close exactly the remaining gap this substep, so a fast body
            // stopped by a speculative contact ends up touching, not hovering.
            const double target = detail.restitution > 0.0 ? -detail.restitution * vn : -gap / h;
            if (vn >= target) continue;
            const double mass = effectiveMass(a, b, rA, rB, c.normal);
            const double impulse = (target - vn) * mass;
            applyImpulse(a, b, rA, rB, impulse * c.normal);
            for (int i = 0; i < c.pointCount; ++i) detail.restitutionImpulse[i] += impulse / double(c.pointCount);
            any = true;
        }
        if (!any) break;
    }
}

void warmStart(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies) {
    for (ContactConstraint& c : contacts) {
        SolverBody& a = bodies[c.bodyA];
        SolverBody& b = bodies[c.bodyB];
        const Vec2 t = tangentOf(c.normal);
        for (int i = 0; i < c.pointCount; ++i) {
            const ContactPoint& p = c.points[i];
            const Vec2 rA = rotate(a.dq, p.anchorA), rB = rotate(b.dq, p.anchorB);
            applyImpulse(a, b, rA, rB, p.normalImpulse * c.normal + p.tangentImpulse * t);
        }
    }
}

void solveContacts(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies, double h,
                   const Softness& soft, const Softness& staticSoft, double pushMaxVelocity, bool useBias) {
    const double invH = 1.0 / h;
    for (ContactConstraint& c : contacts) {
        SolverBody& a = bodies[c.bodyA];
        SolverBody& b = bodies[c.bodyB];
        const Softness& s = c.touchesStatic ? staticSoft : soft;
        const Vec2 n = c.normal;
        for (int i = 0; i < c.pointCount; ++i) {
            ContactPoint& p = c.points[i];
            const Vec2 rA = rotate(a.dq, p.anchorA), rB = rotate(b.dq, p.anchorB);
            // Current separation from the step-start value and the motion since.
            const Vec2 d = (b.dp - a.dp) + (rB - rA);
            const double separation = dot(d, n) + p.adjustedSeparation;
            double bias = 0.0, massScale = 1.0, impulseScale = 0.0;
            if (separation > 0.0) {
                bias = separation * invH;  // speculative: close at most the gap this substep
            } else if (useBias) {
                bias = std::max(s.biasRate * separation, -pushMaxVelocity);
                massScale = s.massScale;
                impulseScale = s.impulseScale;
            }
            const double vn = dot(pointVelocity(b, rB) - pointVelocity(a, rA), n);
            double impulse = -p.normalMass * massScale * (vn + bias) - impulseScale * p.normalImpulse;
            const double total = std::max(p.normalImpulse + impulse, 0.0);
            impulse = total - p.normalImpulse;
            p.normalImpulse = total;
            applyImpulse(a, b, rA, rB, impulse * n);
        }
        const Vec2 t = tangentOf(n);
        for (int i = 0; i < c.pointCount; ++i) {
            ContactPoint& p = c.points[i];
            const Vec2 rA = rotate(a.dq, p.anchorA), rB = rotate(b.dq, p.anchorB);
            const double vt = dot(pointVelocity(b, rB) - pointVelocity(a, rA), t);
            const double maxFriction = c.friction * p.normalImpulse;
            double impulse = -p.tangentMass * vt;
            const double total = std::clamp(p.tangentImpulse + impulse, -maxFriction, maxFriction);
            impulse = total - p.tangentImpulse;
            p.tangentImpulse = total;
            applyImpulse(a, b, rA, rB, impulse * t);
        }
    }
}

} // namespace stepwise::collision
