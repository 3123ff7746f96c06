#include "collision/position_correction.hpp"

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

namespace stepwise::collision {

namespace {
inline Rot turnedBy(Rot q, double angle) {
    const Rot r = Rot::fromAngle(angle);
    return {q.c * r.c - q.s * r.s, q.s * r.c + q.c * r.s};
}

/// A correction of `move` metres at one point, as position impulses (kg m):
/// up to maxTurningCorrection through the point's inverse mass
/// (`inverseMass`, turning included), the rest without turning
/// (`linearMass`), since the turn is linearised.
struct PositionImpulse {
    double turning = 0.0, linear = 0.0;
};
inline PositionImpulse splitCorrection(double move, double inverseMass, double linearMass,
                                       const PositionCorrectionSettings& settings) {
    const double turning = std::min(move, settings.maxTurningCorrection);
    return {turning / inverseMass, (move - turning) / linearMass};
}
} // namespace

bool correctPositions(std::span<const ContactConstraint> contacts, std::span<SolverBody> bodies,
                      std::span<const std::uint8_t> crowd, const PositionCorrectionSettings& settings,
                      PositionCorrectionScratch& scratch, std::span<const double> measured) {
    // A manifold's point lies midway between the two surfaces, half its
    // step-start separation s0 off each side's feature along the normal;
    // turned by t, an anchor there reads the gap (s0 / 2)(1 - cos t) off
    // the gap at the feature. The velocity passes work with that (as Box2D
    // v3: the turn within a step is small); against the static world, where
    // this pass promises the slop at the end of every step, a plank that
    // closed a 31 cm speculative gap while turning 6 mrad ended 2.6
    // micrometres past the slop. The turned sides' terms are added back
    // there (a round side's anchor does not turn).
    const auto separationOf = [&](const SolverBody& a, const SolverBody& b, const ContactConstraint& c,
                                  const ContactPoint& p) {
        const double s = currentSeparation(a, b, c, p);
        if (!c.touchesStatic) return s;
        const double halfStart = 0.5 * (p.adjustedSeparation + (p.dnB - p.dnA));
        return s + halfStart * ((c.roundA ? 0.0 : a.dq.c - 1.0) + (c.roundB ? 0.0 : b.dq.c - 1.0));
    };
    const auto deepest = [&](const ContactConstraint& c) {
        const SolverBody& a = bodies[c.bodyA];
        const SolverBody& b = bodies[c.bodyB];
        double s = separationOf(a, b, c, c.points[0]);
        if (c.pointCount == 2) s = std::min(s, separationOf(a, b, c, c.points[1]));
        return s;
    };
    // Moving pairs past the slop; the static contacts, kept to see which
    // touch once the moving pass has run (it may push a body squeezed
    // against a wall into it).
    scratch.deepMoving.clear();
    scratch.touchingStatic.clear();
    bool any = false;  // a point this pass will move
    for (std::size_t k = 0; k < contacts.size(); ++k) {
        if (contacts[k].touchesStatic) {
            scratch.touchingStatic.push_back(std::uint32_t(k));
            any = any || deepest(contacts[k]) < -settings.slop;
            continue;
        }
        const double s = measured.empty() ? deepest(contacts[k]) : measured[k];
        assert(measured.empty() || std::bit_cast<std::uint64_t>(s) == std::bit_cast<std::uint64_t>(deepest(contacts[k])) ||
               (std::isnan(s) && std::isnan(deepest(contacts[k]))));
        if (s < -settings.slop && (crowd.empty() || crowd[contacts[k].bodyA] || crowd[contacts[k].bodyB])) {
            scratch.deepMoving.push_back(std::uint32_t(k));
            any = true;
        }
    }
    if (!any) return false;

    scratch.turned.assign(bodies.size(), 0.0);
    scratch.moved.assign(bodies.size(), 0);
    // Pushes contact k's points out to `fraction` of their excess past the
    // slop, at most `cap` metres each; returns the deepest excess found.
    const auto correct = [&](const ContactConstraint& c, double fraction, double cap) {
        SolverBody& a = bodies[c.bodyA];
        SolverBody& b = bodies[c.bodyB];
        const Vec2 n = c.normal;
        double worst = 0.0;
        for (int i = 0; i < c.pointCount; ++i) {
            const ContactPoint& p = c.points[i];
            const double excess = separationOf(a, b, c, p) + settings.slop;  // < 0: too deep
            if (excess >= 0.0) continue;
            worst = std::min(worst, excess);
            const double move = std::min(-fraction * excess, cap);
            const double inverseMass =
                a.invMass + b.invMass + a.invInertia * p.rnA * p.rnA + b.invInertia * p.rnB * p.rnB;
            const double linearMass = a.invMass + b.invMass;
            if (inverseMass <= 0.0 || linearMass <= 0.0) continue;
            const auto [impulse, push] = splitCorrection(move, inverseMass, linearMass, settings);
            scratch.moved[c.bodyA] = 1;
            scratch.moved[c.bodyB] = 1;
            a.dp -= (a.invMass * (impulse + push)) * n;
            b.dp += (b.invMass * (impulse + push)) * n;
            const double turnA = -a.invInertia * p.rnA * impulse, turnB = b.invInertia * p.rnB * impulse;
            if (turnA != 0.0) {
                a.dq = turnedBy(a.dq, turnA);
                scratch.turned[c.bodyA] += turnA;
            }
            if (turnB != 0.0) {
                b.dq = turnedBy(b.dq, turnB);
                scratch.turned[c.bodyB] += turnB;
            }
        }
        return worst;
    };
    // Between moving bodies a fraction of the excess, once a step, as a
    // Baumgarte factor: a deep crowd unfolds over a few steps instead of in
    // one jump.
    for (const std::uint32_t k : scratch.deepMoving)
        correct(contacts[k], settings.movingFraction, settings.maxCorrection);
    std::erase_if(scratch.touchingStatic, [&](std::uint32_t k) { return !(deepest(contacts[k]) < 0.0); });
    // Against the static world the whole excess, uncapped, until every
    // point is within a micrometre of the slop: nothing else can carry the
    // load, and a point left past its step-start plane may be on the far
    // side of a thin shape at the next detection.
    for (int pass = 0; pass < settings.maxPasses; ++pass) {
        double worst = 0.0;  // before this pass's moves
        for (const std::uint32_t k : scratch.touchingStatic)
            worst = std::min(worst, correct(contacts[k], 1.0, std::numeric_limits<double>::infinity()));
        if (worst > -1e-6) break;
    }
    return true;
}

double pushOutOfStatic(SolverBody& body, std::span<const PresentContact> points,
                       const PositionCorrectionSettings& settings, double& turned) {
    if (!(body.invMass > 0.0)) return 0.0;
    Vec2 moved;         // this pass's move of the centre of mass, metres
    double turn = 0.0;  // and its turn, rad
    double worst = 0.0;
    for (const PresentContact& p : points) {
        const double rn = cross(p.arm, p.normal);
        // A point turned by a small angle a about the centre moves by
        // a cross(arm, n) along n.
        const double excess = p.separation + dot(moved, p.normal) + turn * rn + settings.slop;
        if (excess >= 0.0) continue;
        worst = std::min(worst, excess);
        const auto [impulse, push] =
            splitCorrection(-excess, body.invMass + body.invInertia * rn * rn, body.invMass, settings);
        moved += (body.invMass * (impulse + push)) * p.normal;
        turn += body.invInertia * rn * impulse;
    }
    body.dp += moved;
    if (turn != 0.0) {
        body.dq = turnedBy(body.dq, turn);
        turned += turn;
    }
    return worst;
}

} // namespace stepwise::collision
