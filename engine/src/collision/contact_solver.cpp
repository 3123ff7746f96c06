#include "collision/contact_solver.hpp"


#include <algorithm>
#include <bit>
#include <cmath>

namespace stepwise::collision {

namespace {
constexpr double kPi = 3.14159265358979323846;

/// Tangent direction: the normal turned clockwise, as Box2D.
inline Vec2 tangentOf(Vec2 n) { return {n.y, -n.x}; }

/// Relative normal velocity of B against A at a point with projections
/// (rnA, rnB): dot(vB + wB x rB - vA - wA x rA, n), since dot(w x r, n) =
/// w cross(r, n).
inline double normalSpeed(const SolverBody& a, const SolverBody& b, Vec2 n, double rnA, double rnB) {
    return dot(b.v - a.v, n) + b.w * rnB - a.w * rnA;
}
/// Applies impulse magnitude `j` along unit `dir`, whose lever arms are
/// cross(rA, dir) = armA and cross(rB, dir) = armB.
inline void applyImpulse(SolverBody& a, SolverBody& b, Vec2 dir, double armA, double armB, double j) {
    a.v -= (a.invMass * j) * dir;
    a.w -= a.invInertia * armA * j;
    b.v += (b.invMass * j) * dir;
    b.w += b.invInertia * armB * j;
}
inline double effectiveMass(const SolverBody& a, const SolverBody& b, double armA, double armB) {
    const double k = a.invMass + b.invMass + a.invInertia * armA * armA + b.invInertia * armB * armB;
    return k > 0.0 ? 1.0 / k : 0.0;
}
} // namespace

double currentSeparation(const SolverBody& a, const SolverBody& b, const ContactConstraint& c, const ContactPoint& p) {
    // A round side turns under its contact point (ContactConstraint::roundA).
    const Rot qA = c.roundA ? Rot{} : a.dq, qB = c.roundB ? Rot{} : b.dq;
    return dot(b.dp - a.dp, c.normal) + (qB.c * p.dnB + qB.s * p.rnB) - (qA.c * p.dnA + qA.s * p.rnA) +
           p.adjustedSeparation;
}

double deepestSeparation(const SolverBody& a, const SolverBody& b, const ContactConstraint& c) {
    double s = currentSeparation(a, b, c, c.points[0]);
    if (c.pointCount == 2) s = std::min(s, currentSeparation(a, b, c, c.points[1]));
    return s;
}

Softness Softness::make(double hertz, double dampingRatio, double h) {
    if (hertz == 0.0) return {0.0, 1.0, 0.0};
    const double omega = 2.0 * kPi * hertz;
    const double a1 = 2.0 * dampingRatio + h * omega;
    const double a2 = h * omega * a1;
    const double a3 = 1.0 / (1.0 + a2);
    return {omega / a1, a2 * a3, a3};
}

void ContactPairs::clear(std::size_t bodyCount) {
    bodies.clear();
    twoPoints.clear();
    approach.clear();
    reach.assign(bodyCount, 0.0);
}

void ContactPairs::add(const ContactConstraint& c) {
    bodies.push_back(c.bodyA);
    bodies.push_back(c.bodyB);
    twoPoints.push_back(c.pointCount == 2 ? 1 : 0);
    ApproachRow& row = approach.emplace_back();
    row.normal = c.normal;
    for (int i = 0; i < 2; ++i) {
        const ContactPoint& p = c.points[c.pointCount == 2 ? i : 0];
        row.rnA[i] = p.rnA;
        row.rnB[i] = p.rnB;
    }
    for (int i = 0; i < c.pointCount; ++i) {
        reach[c.bodyA] = std::max(reach[c.bodyA], std::abs(c.points[i].rnA));
        reach[c.bodyB] = std::max(reach[c.bodyB], std::abs(c.points[i].rnB));
    }
}

void prepareContact(ContactConstraint& c, const ContactDetail& detail, const SolverBody& a, const SolverBody& b) {
    for (int i = 0; i < c.pointCount; ++i) {
        ContactPoint& p = c.points[i];
        p.normalMass = effectiveMass(a, b, p.rnA, p.rnB);
        p.tangentMass = effectiveMass(a, b, -p.dnA, -p.dnB);
        p.adjustedSeparation = detail.separation[i] - (p.dnB - p.dnA);
    }
    c.block = false;
    if (c.pointCount == 2) {
        // K of the two normal rows. A box resting on a face gives two
        // strongly coupled rows (k12 close to k11): solving them
        // together settles a stack in far fewer passes than one point
        // after the other. Two points nearly on top of each other make K
        // almost singular; those stay sequential (condition number cap
        // 1000, the usual rule for this block solve).
        const ContactPoint& p1 = c.points[0];
        const ContactPoint& p2 = c.points[1];
        BlockMass& bm = c.blockMass;
        bm.k11 = a.invMass + b.invMass + a.invInertia * p1.rnA * p1.rnA + b.invInertia * p1.rnB * p1.rnB;
        bm.k22 = a.invMass + b.invMass + a.invInertia * p2.rnA * p2.rnA + b.invInertia * p2.rnB * p2.rnB;
        bm.k12 = a.invMass + b.invMass + a.invInertia * p1.rnA * p2.rnA + b.invInertia * p1.rnB * p2.rnB;
        const double det = bm.k11 * bm.k22 - bm.k12 * bm.k12;
        constexpr double kMaxCondition = 1000.0;
        if (bm.k11 > 0.0 && bm.k11 * bm.k11 < kMaxCondition * det) {
            const double invDet = 1.0 / det;
            bm.i11 = bm.k22 * invDet;
            bm.i22 = bm.k11 * invDet;
            bm.i12 = -bm.k12 * invDet;
            c.block = true;
        }
    }
}

void boundWarmStart(ContactConstraint& c, double most) {
    for (int i = 0; i < c.pointCount; ++i) {
        ContactPoint& p = c.points[i];
        if (!(p.normalImpulse >= 0.0)) p.normalImpulse = 0.0;
        if (p.normalImpulse > most) p.normalImpulse = most;
        const double friction = c.friction * p.normalImpulse;
        if (p.tangentImpulse > friction) p.tangentImpulse = friction;
        if (p.tangentImpulse < -friction) p.tangentImpulse = -friction;
    }
}

namespace {

/// The contacts' restitutions, packed, and their impulses zeroed; made by
/// the first substep that finds two bodies fast enough to look at contacts
/// (a resting pile never does, and then never reads its details).
void packRestitution(std::span<const ContactDetail> details, ImpactScratch& scratch) {
    scratch.restitution.resize(details.size());
    scratch.impulse.assign(details.size(), 0.0);
    for (std::size_t k = 0; k < details.size(); ++k) scratch.restitution[k] = details[k].restitution;
    scratch.pairsReady = true;
}

/// Which contacts touch which body, from the packed pairs: a counting sort
/// of (body, contact) by body. Static body 0 never changes velocity, so it
/// lists nothing.
void indexIncident(std::span<const std::uint32_t> pairBodies, std::size_t bodyCount, ImpactScratch& scratch) {
    const std::size_t contactCount = pairBodies.size() / 2;
    scratch.start.assign(bodyCount + 1, 0u);
    for (std::size_t k = 0; k < 2 * contactCount; ++k)
        if (const std::uint32_t b = pairBodies[k]; b != 0) ++scratch.start[b + 1];
    for (std::size_t b = 0; b < bodyCount; ++b) scratch.start[b + 1] += scratch.start[b];
    scratch.incident.resize(scratch.start[bodyCount]);
    std::vector<std::uint32_t>& at = scratch.now32;  // next free slot per body
    at.assign(scratch.start.begin(), scratch.start.end() - 1);
    for (std::size_t k = 0; k < 2 * contactCount; ++k)
        if (const std::uint32_t b = pairBodies[k]; b != 0) scratch.incident[at[b]++] = std::uint32_t(k / 2);
    scratch.incidentReady = true;
}

} // namespace

void propagateImpacts(std::span<ContactConstraint> contacts, std::span<ContactDetail> details,
                      std::span<SolverBody> bodies, const ContactPairs& pairs, double h, double threshold,
                      int maxPasses, ImpactScratch& scratch) {
    // Touching within this many metres counts as an impact (Box2D's linear
    // slop): without it a pair that closes its gap exactly at the end of a
    // substep would be stopped by the speculative constraint instead.
    constexpr double kSlop = 0.005;
    // An impulse that would change an approach by less than this moves the
    // pair under 1e-4 of the slop within the substep: the soft solve takes
    // it. Without a floor, a block of boxes pushed together in zero gravity
    // (a zero threshold) spends every pass of every substep chasing
    // approaches of micrometres per second through the block, 80% of its
    // impulses.
    const double negligible = 1e-4 * kSlop / h;
    const std::size_t words = (contacts.size() + 63) / 64;
    std::vector<std::uint64_t>& now = scratch.now;
    std::vector<std::uint64_t>& next = scratch.next;
    // A contact's normal speed is at most |vA - u| + |vB - u| + |wA rnA| +
    // |wB rnB| <= bound[A] + bound[B] for any velocity u, since vB - vA =
    // (vB - u) - (vA - u) (n is a unit vector, so |dot(d, n)| <= |d.x| +
    // |d.y|). One whose bound is under the threshold by more than rounding
    // would find nothing to do, so it is passed over without reading it: the
    // result is that of looking at it. The bounds follow the bodies'
    // velocities (set here, renewed for the two bodies of each impulse). u is
    // the median velocity of up to 63 moving bodies spread through the list
    // (each component's median; over all bodies it would make the bounds'
    // sum least, and cost more than the passes it saves). Every body a
    // substep's gravity has just given g h (a quarter of the default
    // threshold) is measured from that shared velocity, so a resting
    // pyramid, which sways by millimetres a second, passes nearly all its
    // contacts over, where measured from rest the sway plus g h on both
    // bodies put most of them past the threshold. (A mean would follow a few
    // fast strikers and put a resting block in motion.)
    constexpr std::size_t kSample = 63;
    double xs[kSample], ys[kSample];
    std::size_t sampled = 0;
    const std::size_t stride = std::max<std::size_t>(1, bodies.size() / kSample);
    for (std::size_t i = 0; i < bodies.size() && sampled < kSample; i += stride) {
        const SolverBody& b = bodies[i];
        // NaN has no order (the median needs one); any u keeps the bound.
        if (b.invMass > 0.0 && std::isfinite(b.v.x) && std::isfinite(b.v.y)) {
            xs[sampled] = b.v.x;
            ys[sampled] = b.v.y;
            ++sampled;
        }
    }
    const auto median = [sampled](double* values) {
        if (sampled == 0) return 0.0;
        std::nth_element(values, values + sampled / 2, values + sampled);
        return values[sampled / 2];
    };
    const Vec2 u{median(xs), median(ys)};
    std::vector<double>& bound = scratch.bound;
    const auto boundOf = [&](const SolverBody& b) {
        return (std::abs(b.v.x - u.x) + std::abs(b.v.y - u.y)) +
               std::abs(b.w) * pairs.reach[std::size_t(&b - bodies.data())];
    };
    bound.resize(bodies.size());
    double fastest = 0.0;
    for (std::size_t b = 0; b < bodies.size(); ++b) {
        bound[b] = boundOf(bodies[b]);
        fastest = std::max(fastest, bound[b]);
    }
    // Rounding in the normal speed is a few units in the last place of its
    // terms, far under a millionth of the bound; the terms are at most the
    // bounds plus |u| each, so a pile falling fast together keeps a margin
    // for that too.
    const double quiet = threshold * (1.0 - 1e-6) - 1e-12 * (std::abs(u.x) + std::abs(u.y));
    // No two bodies fast enough together (a resting pile): every contact
    // would be passed over.
    const bool every = scratch.lookAtEveryContact;
    if (fastest + fastest < quiet && !every) return;
    if (!scratch.pairsReady) packRestitution(details, scratch);
    const auto passedOver = [&](std::size_t k) {
        return !every && bound[pairs.bodies[2 * k]] + bound[pairs.bodies[2 * k + 1]] < quiet;
    };
    // The first pass: the contacts not passed over at the start velocities.
    now.assign(words, 0);
    for (std::size_t k = 0; k < contacts.size(); ++k)
        if (!passedOver(k)) now[k / 64] |= std::uint64_t(1) << (k % 64);
    // Contact k changed its bodies: every contact on them looks again, later
    // in this pass if it comes after k, else in the next pass (k included).
    // A pile's body changes several times a pass. Its later contacts are
    // marked at its first change (a later change's are among them, not yet
    // looked at), its earlier ones once at the end of the pass, up to its
    // last change: the marks of marking at every change, at a fraction of
    // the writes (a churned pile made a dozen per impulse).
    scratch.changedInPass.resize(bodies.size(), 0);
    scratch.lastChange.resize(bodies.size(), 0);
    const auto touched = [&](std::uint32_t body, std::size_t k) {
        if (body == 0) return;
        scratch.lastChange[body] = std::uint32_t(k);
        if (scratch.changedInPass[body] == scratch.passCount) return;
        scratch.changedInPass[body] = scratch.passCount;
        scratch.changed.push_back(body);
        if (!scratch.incidentReady) indexIncident(pairs.bodies, bodies.size(), scratch);
        for (std::uint32_t i = scratch.start[body + 1]; i > scratch.start[body];) {
            const std::uint32_t m = scratch.incident[--i];
            if (m <= k) break;  // ascending: the rest come before k
            now[m / 64] |= std::uint64_t(1) << (m % 64);
        }
    };
    const auto markEarlierContacts = [&] {
        for (const std::uint32_t body : scratch.changed) {
            const std::uint32_t last = scratch.lastChange[body];
            for (std::uint32_t i = scratch.start[body]; i < scratch.start[body + 1]; ++i) {
                const std::uint32_t m = scratch.incident[i];
                if (m > last) break;
                next[m / 64] |= std::uint64_t(1) << (m % 64);
            }
        }
        scratch.changed.clear();
    };
    for (int pass = 0; pass < maxPasses; ++pass) {
        bool any = false;
        next.assign(words, 0);
        ++scratch.passCount;  // starts above the zeros changedInPass is filled with
        for (std::size_t word = 0; word < words; ++word) {
            while (now[word] != 0) {
                const std::size_t k = word * 64 + std::size_t(std::countr_zero(now[word]));
                now[word] &= now[word] - 1;
                if (passedOver(k)) continue;
                ++scratch.looked;
                SolverBody& a = bodies[pairs.bodies[2 * k]];
                SolverBody& b = bodies[pairs.bodies[2 * k + 1]];
                // The same test as the points' loop below, on the packed row:
                // a contact none of whose points approaches does nothing.
                const ContactPairs::ApproachRow& row = pairs.approach[k];
                if (normalSpeed(a, b, row.normal, row.rnA[0], row.rnB[0]) >= -threshold &&
                    normalSpeed(a, b, row.normal, row.rnA[1], row.rnB[1]) >= -threshold)
                    continue;
                ContactConstraint& c = contacts[k];
                // The approaching points that touch within this substep; the
                // impulse acts at their centroid (the projections are linear in
                // the anchor, so the centroid's are the mean) so a flat landing
                // box does not pick up spin from the order of its two corners.
                double rnA = 0.0, rnB = 0.0, gap = 0.0;
                int count = 0;
                for (int i = 0; i < c.pointCount; ++i) {
                    const ContactPoint& p = c.points[i];
                    const double vn = normalSpeed(a, b, c.normal, p.rnA, p.rnB);
                    if (vn >= -threshold) continue;  // resting contacts leave here
                    const double separation = currentSeparation(a, b, c, p);
                    if (separation + vn * h < kSlop) {
                        rnA += p.rnA;
                        rnB += p.rnB;
                        gap += separation;
                        ++count;
                    }
                }
                if (count == 0) continue;
                rnA /= double(count);
                rnB /= double(count);
                gap = std::max(gap / double(count), 0.0);
                const double vn = normalSpeed(a, b, c.normal, rnA, rnB);
                // Bouncy pairs leave at e times the approach speed. Inelastic ones
                // close exactly the remaining gap this substep, so a fast body
                // stopped by a speculative contact ends up touching, not hovering.
                const double restitution = scratch.restitution[k];
                const double target = restitution > 0.0 ? -restitution * vn : -gap / h;
                if (!(target - vn > negligible)) continue;
                const double impulse = (target - vn) * effectiveMass(a, b, rnA, rnB);
                applyImpulse(a, b, c.normal, rnA, rnB, impulse);
                bound[c.bodyA] = boundOf(a);
                bound[c.bodyB] = boundOf(b);
                scratch.impulse[k] += impulse / double(c.pointCount);
                ++scratch.fired;
                touched(c.bodyA, k);
                touched(c.bodyB, k);
                any = true;
            }
        }
        markEarlierContacts();
        if (!any) break;
        if (every) {
            std::fill(next.begin(), next.end(), ~std::uint64_t(0));
            if (contacts.size() % 64 != 0) next.back() = (std::uint64_t(1) << (contacts.size() % 64)) - 1;
        }
        now.swap(next);
    }
}

void storeImpacts(std::span<const ContactConstraint> contacts, std::span<ContactDetail> details,
                  ImpactScratch& scratch) {
    if (!scratch.pairsReady) return;  // no pass this step: every detail keeps its zeros
    // The details were made with zero impulses, and a sum from +0 is never
    // -0: only the contacts that took an impulse are written.
    for (std::size_t k = 0; k < contacts.size(); ++k)
        if (scratch.impulse[k] != 0.0)
            for (int i = 0; i < contacts[k].pointCount; ++i) details[k].restitutionImpulse[i] = scratch.impulse[k];
    // Stored once: a step cut short before its detection reaches endStep
    // with the last step's contacts, which already hold these.
    scratch.pairsReady = scratch.incidentReady = false;
}

void warmStart(std::span<ContactConstraint> contacts, std::span<const std::uint32_t> order,
               std::span<SolverBody> bodies) {
    for (const std::uint32_t k : order) {
        ContactConstraint& c = contacts[k];
        SolverBody& a = bodies[c.bodyA];
        SolverBody& b = bodies[c.bodyB];
        const Vec2 t = tangentOf(c.normal);
        for (int i = 0; i < c.pointCount; ++i) {
            const ContactPoint& p = c.points[i];
            applyImpulse(a, b, c.normal, p.rnA, p.rnB, p.normalImpulse);
            applyImpulse(a, b, t, -p.dnA, -p.dnB, p.tangentImpulse);
        }
    }
}

void solveContacts(std::span<ContactConstraint> contacts, std::span<const std::uint32_t> order,
                   std::span<SolverBody> bodies, double h, const Softness& soft, const Softness& staticSoft,
                   double pushMaxVelocity, bool useBias, bool reverse) {
    const double invH = 1.0 / h;
    const std::size_t count = order.size();
    for (std::size_t k = 0; k < count; ++k) {
        ContactConstraint& c = contacts[order[reverse ? count - 1 - k : k]];
        SolverBody& a = bodies[c.bodyA];
        SolverBody& b = bodies[c.bodyB];
        // Work on local copies of the two bodies' velocities and store them
        // once per manifold: A and B never alias, but the compiler cannot
        // know, and every point's update would otherwise go through memory
        // before the next point reads it (the solve's critical path, not its
        // instruction count, is its cost).
        Vec2 vA = a.v, vB = b.v;
        double wA = a.w, wB = b.w;
        const double mA = a.invMass, mB = b.invMass, iA = a.invInertia, iB = b.invInertia;
        const Softness& s = c.touchesStatic ? staticSoft : soft;
        const Vec2 n = c.normal;
        // The separation moves with the bodies' displacement and rotation
        // since the step began; the Jacobian keeps the step-start anchors
        // (as Box2D v3): the rotation within one step is small.
        const double baseGap = dot(b.dp - a.dp, n);
        const Rot qA = c.roundA ? Rot{} : a.dq, qB = c.roundB ? Rot{} : b.dq;
        const auto targetOf = [&](const ContactPoint& p) {
            const double separation =
                baseGap + (qB.c * p.dnB + qB.s * p.rnB) - (qA.c * p.dnA + qA.s * p.rnA) + p.adjustedSeparation;
            return pointTarget(
                separation, [&] { return dot(vB - vA, n) + wB * p.rnB - wA * p.rnA; }, s, invH, pushMaxVelocity,
                useBias);
        };
        const PointTarget t0 = targetOf(c.points[0]);
        const PointTarget t1 = c.pointCount == 2 ? targetOf(c.points[1]) : PointTarget{};
        if (c.block && t0.massScale == t1.massScale) {
            ContactPoint& p1 = c.points[0];
            ContactPoint& p2 = c.points[1];
            const Vec2 dv = vB - vA;
            const double a1 = p1.normalImpulse, a2 = p2.normalImpulse;
            const double vn1 = dot(dv, n) + wB * p1.rnB - wA * p1.rnA;
            const double vn2 = dot(dv, n) + wB * p2.rnB - wA * p2.rnA;
            const auto [x1, x2] = solveNormalBlock(c.blockMass, vn1, vn2, t0, t1, a1, a2);
            const double d1 = x1 - a1, d2 = x2 - a2;
            p1.normalImpulse = x1;
            p2.normalImpulse = x2;
            const double d = d1 + d2;
            vA -= (mA * d) * n;
            wA -= iA * (p1.rnA * d1 + p2.rnA * d2);
            vB += (mB * d) * n;
            wB += iB * (p1.rnB * d1 + p2.rnB * d2);
        } else {
            for (int i = 0; i < c.pointCount; ++i) {
                ContactPoint& p = c.points[i];
                const PointTarget& tg = i == 0 ? t0 : t1;
                const double vn = dot(vB - vA, n) + wB * p.rnB - wA * p.rnA;
                double impulse = -p.normalMass * tg.massScale * (vn + tg.bias) - tg.impulseScale * p.normalImpulse;
                const double total = std::max(p.normalImpulse + impulse, 0.0);
                impulse = total - p.normalImpulse;
                p.normalImpulse = total;
                vA -= (mA * impulse) * n;
                wA -= iA * p.rnA * impulse;
                vB += (mB * impulse) * n;
                wB += iB * p.rnB * impulse;
            }
        }
        // Friction: t = (n.y, -n.x), and cross(r, t) = -dot(r, n).
        const Vec2 t = tangentOf(n);
        for (int i = 0; i < c.pointCount; ++i) {
            ContactPoint& p = c.points[i];
            const double vt = dot(vB - vA, t) - wB * p.dnB + wA * p.dnA;
            const double maxFriction = c.friction * p.normalImpulse;
            double impulse = -p.tangentMass * vt;
            const double total = std::clamp(p.tangentImpulse + impulse, -maxFriction, maxFriction);
            impulse = total - p.tangentImpulse;
            p.tangentImpulse = total;
            vA -= (mA * impulse) * t;
            wA += iA * p.dnA * impulse;
            vB += (mB * impulse) * t;
            wB -= iB * p.dnB * impulse;
        }
        a.v = vA;
        a.w = wA;
        b.v = vB;
        b.w = wB;
    }
}

} // namespace stepwise::collision
