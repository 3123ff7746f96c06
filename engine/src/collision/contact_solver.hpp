#pragma once
// Soft-step contact solver (the scheme of Box2D v3's "soft step" and Erin
// Catto's Solver2D notes): per substep, warm start, solve with a soft
// position bias, integrate positions, relax without bias. Restitution is
// applied from the approach speed measured before the solve, as impact
// propagation, so a Newton's cradle passes one ball's momentum down the row.

#include "collision/collision_types.hpp"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

namespace stepwise::collision {

/// Velocity state of one collider during the solve. Static colliders share
/// entry 0, which has zero inverse mass and never moves.
/// What the contact iterations read of a body, (v, w, invMass) and (dp, dq),
/// fills the first cache line (64-byte aligned): one line a body, where 72
/// bytes in a row spread a body over two lines half the time.
struct alignas(64) SolverBody {
    Vec2 v;              ///< m/s
    double w = 0.0;      ///< rad/s
    double invMass = 0.0;    ///< 1/kg
    Vec2 dp;             ///< displacement since the step began, metres
    Rot dq;              ///< rotation since the step began
    double invInertia = 0.0; ///< 1/(kg m^2)
};

/// Soft constraint coefficients for a stiffness (Hz) and damping ratio at a
/// time step h (Box2D v3's b2MakeSoft).
struct Softness {
    double biasRate = 0.0;    ///< 1/s
    double massScale = 1.0;
    double impulseScale = 0.0;
    /// Overlap (m) that the contact may reach softly: a point whose approach
    /// would carry it past this depth within the substep, or that is past
    /// it, is solved rigidly (no mass scaling, no impulse leak), closing at
    /// most to this depth and pushing out only what lies past it. A soft
    /// contact under a steady load settles at load / (m omega^2), however
    /// deep; this bounds it. Infinite: always soft.
    double rigidDepth = std::numeric_limits<double>::infinity();
    static Softness make(double hertz, double dampingRatio, double h);
};

/// Solver data of one contact point: only what the iterations read and
/// write, so a pass over thousands of contacts streams as few bytes as
/// possible (the solve is memory-bound; see ContactDetail for the rest).
struct ContactPoint {
    /// The anchors r (contact point minus body centre at step start, metres)
    /// enter every formula only through two projections on the normal n:
    /// rn = cross(r, n) and dn = dot(r, n). The tangent t = (n.y, -n.x) needs
    /// no more, since cross(r, t) = -dot(r, n). So four doubles replace the
    /// two anchor vectors and no iteration rotates a vector.
    double rnA = 0.0, rnB = 0.0, dnA = 0.0, dnB = 0.0;
    double adjustedSeparation = 0.0;  ///< separation minus (dnB - dnA), metres
    double normalMass = 0.0, tangentMass = 0.0;        ///< kg
    double normalImpulse = 0.0, tangentImpulse = 0.0;  ///< accumulated, N*s
};

/// The 2x2 normal system of a two-point manifold, for the block solve.
/// K maps the two normal impulses (N*s) to the two normal velocity changes
/// (m/s): K = [k11 k12; k12 k22], 1/kg; inv is its inverse, kg.
struct BlockMass {
    double k11 = 0.0, k12 = 0.0, k22 = 0.0;
    double i11 = 0.0, i12 = 0.0, i22 = 0.0;
};

struct ContactConstraint {
    std::uint32_t bodyA = 0, bodyB = 0;  ///< SolverBody indices (0 = static)
    Vec2 normal;                         ///< from A to B
    double friction = 0.0;
    std::int32_t pointCount = 0;
    bool touchesStatic = false;
    /// A side whose surface is round about its centre (a circle): turning
    /// it slides the contact point along the surface and leaves the gap as
    /// it was, so the current separation ignores that side's rotation. With
    /// the rotated step-start anchor instead, a disc spinning at 20 rad/s
    /// would lift its contact 2.7 cm off the floor within one 1/60 s step,
    /// read as a gap: no normal impulse, so no friction.
    bool roundA = false, roundB = false;
    /// Two points whose normal impulses are solved together (K well
    /// conditioned); otherwise the points are solved one after the other.
    bool block = false;
    ContactPoint points[2];
    BlockMass blockMass;
};

/// Everything about a contact that the solver iterations do not touch:
/// identity, geometry at step start, restitution. Parallel to the constraints.
struct ContactDetail {
    std::uint32_t colliderA = 0, colliderB = 0;  ///< collider indices (records, warm starting)
    double restitution = 0.0;
    Vec2 point[2];                    ///< world points at step start, metres
    double separation[2] = {0.0, 0.0};   ///< at step start, metres
    double restitutionImpulse[2] = {0.0, 0.0};  ///< from impact propagation, N*s
    std::uint32_t id[2] = {0, 0};     ///< feature ids
};

struct SolverSettings {
    /// The default contact stiffness, Hz: Box2D v3's default is 30 Hz; 60
    /// gives 4x less overlap in a 25-deep circle pile at the same cost.
    static constexpr double kDefaultHertz = 60.0;
    /// Contact stiffness, Hz, capped at a quarter of the substep rate (so 60
    /// Hz needs 4 substeps at 60 steps/s; Box2D v3.0's cap, v3.1 uses an
    /// eighth). Raised past kDefaultHertz under strong loads.
    double contactHertz = kDefaultHertz;
    /// The cap on contactHertz, as a fraction of the substep rate: a quarter
    /// (Box2D v3.0's), or an eighth (v3.1's) for a scene with a column of
    /// boxes deeper than kDeepColumn, where at a quarter (h omega = pi/2)
    /// the soft contacts keep a tall pyramid in motion and it slides apart
    /// (world.hpp, docs/collisions.md "Deep columns").
    double hertzFraction = 0.25;
    /// Every pass in the same colour order (Box2D v3's), instead of
    /// alternating forward and reverse from pass to pass. Alternating lets
    /// resting piles and stacks come to rest and sleep sooner; in a column
    /// deeper than kDeepColumn the two orders pull it sideways by turns: the
    /// top of a 100-row pyramid drifts 44 mm in 5 s at 8 substeps (6.5 mm in
    /// one order).
    bool oneColourOrder = false;
    double dampingRatio = 10.0;        ///< heavily over-damped: pushes out without bounce
    /// m/s: caps the speed of overlap recovery at kDefaultHertz (Box2D's
    /// 3 m/s). Stiffer contacts push proportionally faster (pushCap): the
    /// push that holds an overlap at a given depth grows with the
    /// stiffness, and held at 3 m/s it could not make up what a strong load
    /// adds in a substep (two boxes under 10^6 m/s^2 sank 27 cm into each
    /// other, five flew apart).
    double pushMaxVelocity = 3.0;
    double restitutionThreshold = 1.0; ///< m/s; slower impacts do not bounce (resting contact stays put)
    int iterations = 2;                ///< biased solve iterations per substep (world.solver_iterations)
    int relaxIterations = 1;           ///< unbiased iterations per substep
    bool warmStart = true;
    /// Solve the coloured bundles in SIMD lanes (contact_bundles.hpp). Off:
    /// the same contacts in the same coloured order, one at a time through
    /// solveContacts below; both give the same bits (tests compare them).
    bool simd = true;
    /// The push cap (m/s) at a stiffness of `hertz` (the one a substep
    /// applies, or any bound on it).
    double pushCap(double hertz) const { return pushMaxVelocity * std::max(1.0, hertz / kDefaultHertz); }
};

/// The separation of point `p` of contact `c` at the bodies' current dp, dq
/// (metres, negative when overlapping).
double currentSeparation(const SolverBody& a, const SolverBody& b, const ContactConstraint& c, const ContactPoint& p);
/// The least currentSeparation of contact c's points (metres).
double deepestSeparation(const SolverBody& a, const SolverBody& b, const ContactConstraint& c);

/// Velocity bias (m/s) and soft scaling of one contact point.
struct PointTarget {
    double bias = 0.0, massScale = 1.0, impulseScale = 0.0;
};
/// The target of a point at `separation` (m): a speculative point may close
/// its gap this substep; an overlapping one is pushed out softly (biased
/// passes only), or rigidly past the softness's rigidDepth. `normalSpeed()`
/// gives the point's current approach (m/s), read only when needed.
template <class Speed>
inline PointTarget pointTarget(double separation, Speed&& normalSpeed, const Softness& s, double invH,
                               double pushMaxVelocity, bool useBias) {
    PointTarget t;
    if (separation > 0.0) {
        t.bias = separation * invH;
    } else if (useBias && (!(separation > -s.rigidDepth) ||
                           !((separation + normalSpeed() / invH) > -(s.rigidDepth + s.rigidDepth)))) {
        // Past rigidDepth, or an approach that would carry the point past
        // twice that within this substep: a soft contact lets a few percent
        // of the approach through (8 m in one substep at 10^6 m/s^2), so it
        // turns rigid, closing at most to that depth and pushing out only
        // what lies past it. (Twice: a resting point near the depth,
        // approaching at g h, would otherwise switch between soft and rigid
        // every substep and never sleep.)
        const double toDepth = separation + s.rigidDepth;
        t.bias = toDepth > 0.0 ? toDepth * invH : std::max(s.biasRate * toDepth, -pushMaxVelocity);
    } else if (useBias) {
        t.bias = std::max(s.biasRate * separation, -pushMaxVelocity);
        t.massScale = s.massScale;
        t.impulseScale = s.impulseScale;
    }
    return t;
}

/// Block solve of a two-point manifold's normal rows, both at one massScale:
/// the new accumulated impulses y >= 0 make the normal velocities
/// w = K (y - a) + vn + bias non-negative with y_i w_i = 0 (a 2x2 linear
/// complementarity problem, solved by trying its four cases: both points
/// pushing, only the first, only the second, neither). The soft rule
/// new = massScale * (a - K^-1 (vn + bias)) of the one-point solve becomes
/// new = massScale * y (massScale + impulseScale = 1). Returns the new
/// accumulated impulses; `vn1`, `vn2` are the points' normal speeds (m/s),
/// `a1`, `a2` their impulses so far (N*s).
struct BlockImpulses {
    double x1, x2;
};
inline BlockImpulses solveNormalBlock(const BlockMass& bm, double vn1, double vn2, const PointTarget& t0,
                                      const PointTarget& t1, double a1, double a2) {
    const double q1 = vn1 + t0.bias - (bm.k11 * a1 + bm.k12 * a2);
    const double q2 = vn2 + t1.bias - (bm.k12 * a1 + bm.k22 * a2);
    double y1 = -(bm.i11 * q1 + bm.i12 * q2);
    double y2 = -(bm.i12 * q1 + bm.i22 * q2);
    if (!(y1 >= 0.0 && y2 >= 0.0)) {
        y1 = -q1 / bm.k11;
        y2 = 0.0;
        if (!(y1 >= 0.0 && bm.k12 * y1 + q2 >= 0.0)) {
            y1 = 0.0;
            y2 = -q2 / bm.k22;
            if (!(y2 >= 0.0 && bm.k12 * y2 + q1 >= 0.0)) {
                // Neither point pushes; q >= 0 then, for K positive definite
                // (anything else is rounding: keep a).
                y2 = 0.0;
                if (!(q1 >= 0.0 && q2 >= 0.0)) {
                    y1 = a1 / t0.massScale;
                    y2 = a2 / t0.massScale;
                }
            }
        }
    }
    return {t0.massScale * y1, t0.massScale * y2};
}

/// What the colouring and the impact passes read of every contact, packed
/// side by side. A ContactConstraint is 232 bytes: a pass that streamed the
/// whole array for its bodies and point count read it from memory again
/// (on Box2D's many pyramids, 13 MB for 0.5 MB of pairs).
struct ContactPairs {
    /// What the impact passes need to tell whether a contact approaches:
    /// its normal and its points' lever arms about it (rn of
    /// ContactPoint; a one-point contact repeats its point). Most contacts
    /// of a churned pile do not approach, and a row is a quarter of the
    /// constraint the passes would otherwise stream twice a substep.
    struct ApproachRow {
        Vec2 normal;
        double rnA[2] = {0.0, 0.0}, rnB[2] = {0.0, 0.0};
    };
    std::vector<std::uint32_t> bodies;    ///< contact k's bodyA, bodyB at 2k, 2k + 1
    std::vector<std::uint8_t> twoPoints;  ///< 1 when contact k has two points
    std::vector<ApproachRow> approach;    ///< contact k's normal and lever arms
    /// Per solver body: the largest |rn| of its contact points this step (m).
    std::vector<double> reach;

    /// Empties the pairs for a step of `bodyCount` solver bodies.
    void clear(std::size_t bodyCount);
    /// Appends contact `c` (the next one) and raises its bodies' reach. The
    /// narrow phase packs each manifold as it makes it, where its values are
    /// at hand: a pass of its own read the 232-byte contacts again.
    void add(const ContactConstraint& c);
};

/// Prepares one contact's masses, the block solve's 2x2 system and its
/// adjusted separations, once a step, from its bodies' masses as the step
/// solves with them. ColouredContacts::build prepares each contact as it
/// reaches it.
void prepareContact(ContactConstraint& c, const ContactDetail& detail, const SolverBody& a, const SolverBody& b);
/// Keeps a warm start the step can use: normal impulses in [0, most] (N*s)
/// and tangent impulses within the friction cone (see
/// CollisionSystem::warmStartBound).
void boundWarmStart(ContactConstraint& c, double most);

/// Impact propagation, run at the start of each substep on the
/// unconstrained velocities: repeatedly applies a pairwise impact
/// impulse at every manifold that approaches faster than `threshold` (m/s)
/// and touches within the substep `h`, until none does (or `maxPasses`).
/// Exact for two-body impacts; passes a cradle's impulse down the row, which
/// accumulated-impulse restitution cannot do.
///
/// A pass looks only at the contacts whose bodies changed velocity since the
/// contact was last looked at (or that fired then): the others would find
/// what they found before and do nothing, so the result is that of passes
/// over every contact, at the cost of the contacts that move. `scratch` holds
/// which contacts touch which body; startStep resets it once a step, and
/// the first impulse of the step lists them (most steps of a resting scene
/// have none). The impulses each contact received are kept packed in the
/// scratch and go to the details in storeImpacts, once a step. The
/// contacts' bodies and the bodies' reaches come from ContactPairs.
struct ImpactScratch {
    /// Full passes over every contact, no contact passed over: the result
    /// the marks and bounds must reproduce bit for bit (tests compare the two).
    bool lookAtEveryContact = false;
    /// How many contacts the passes read this step, and how many impulses
    /// they applied (statistics: tests check that a pile moving together is
    /// passed over).
    std::size_t looked = 0, fired = 0;
    bool pairsReady = false;              ///< restitution and impulse hold this step's contacts
    bool incidentReady = false;           ///< start and incident list this step's contacts
    std::vector<std::uint32_t> start;     ///< solver body b's contacts: incident[start[b], start[b + 1])
    std::vector<std::uint32_t> incident;  ///< contact indices, ascending per body
    std::vector<std::uint64_t> now, next;  ///< contacts to look at in this pass and the next (bit sets)
    std::vector<std::uint32_t> now32;      ///< the listing's cursor per body
    /// Per solver body: the pass (a count over all calls) in which it last
    /// changed velocity, and the contact of its last change in that pass.
    std::vector<std::uint64_t> changedInPass;
    std::vector<std::uint32_t> lastChange;
    std::vector<std::uint32_t> changed;  ///< the bodies changed in this pass
    std::uint64_t passCount = 0;
    /// Per solver body, at the start of a substep: a bound on the normal
    /// speed any of its points can have, |v.x - u.x| + |v.y - u.y| + |w|
    /// reach (m/s).
    std::vector<double> bound;
    /// Each contact's restitution (ContactDetail::restitution), packed: a
    /// crowd's approaching contacts all read it, and a detail is 88 bytes.
    std::vector<double> restitution;
    /// The impulse each point of a contact has received this step, N*s: the
    /// same for all its points. Summed here rather than in the 88-byte
    /// details, whose scattered writes were half the passes' cost in a
    /// churned pile.
    std::vector<double> impulse;
    /// Forgets the last step's contacts (once a step, after detection).
    void startStep() {
        looked = fired = 0;
        pairsReady = incidentReady = false;
    }
};
/// Writes this step's propagated impulses to details[k].restitutionImpulse,
/// once.
void storeImpacts(std::span<const ContactConstraint> contacts, std::span<ContactDetail> details,
                  ImpactScratch& scratch);
void propagateImpacts(std::span<ContactConstraint> contacts, std::span<ContactDetail> details,
                      std::span<SolverBody> bodies, const ContactPairs& pairs, double h, double threshold,
                      int maxPasses, ImpactScratch& scratch);

/// Applies the accumulated impulses of contacts[order[0]], contacts[order[1]], ...
void warmStart(std::span<ContactConstraint> contacts, std::span<const std::uint32_t> order,
               std::span<SolverBody> bodies);
/// One Gauss-Seidel pass: normal (soft when useBias) then friction, over
/// contacts[order[k]] for k forwards or (reverse) backwards. Alternating the
/// direction between passes cancels the drift a fixed order feeds into stacks.
void solveContacts(std::span<ContactConstraint> contacts, std::span<const std::uint32_t> order,
                   std::span<SolverBody> bodies, double h, const Softness& soft, const Softness& staticSoft,
                   double pushMaxVelocity, bool useBias, bool reverse);

} // namespace stepwise::collision
