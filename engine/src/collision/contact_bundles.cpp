#include "collision/contact_bundles.hpp"

#include "collision/simd_lanes.hpp"

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstring>

namespace stepwise::collision {

namespace {

using namespace simd;

static_assert(kContactLanes == kLanes, "a bundle fills the vector types of simd_lanes.hpp");

struct PassArgs {
    SolverBody* bodies;
    ContactBundle<1>* one;
    std::size_t oneCount;
    ContactBundle<2>* two;
    std::size_t twoCount;
    Softness soft, staticSoft;
    double invH, pushMaxVelocity;
};

// The velocity state of a bundle's two sides while it is solved.
struct Velocities {
    D4 vAx, vAy, wA, vBx, vBy, wB;
};

// Each formula below is solveContacts' (contact_solver.cpp), with the same
// operations in the same order; comments there say why.

/// The inverse masses (1/kg) and inertias (1/(kg m^2)) of a bundle's two sides.
struct Masses {
    D4 mA, iA, mB, iB;
};

/// Impulse j (N*s) along (dx, dy) with lever arms armA, armB: applyImpulse
/// of contact_solver.cpp. Friction passes the arms -dnA, -dnB, where
/// solveContacts writes wA + iA dnA j: negation is exact, so the bits agree.
[[gnu::always_inline]] inline void applyLanes(Velocities& v, const Masses& m, D4 dx, D4 dy, D4 armA, D4 armB, D4 j) {
    v.vAx = v.vAx - (m.mA * j) * dx;
    v.vAy = v.vAy - (m.mA * j) * dy;
    v.wA = v.wA - (m.iA * armA) * j;
    v.vBx = v.vBx + (m.mB * j) * dx;
    v.vBy = v.vBy + (m.mB * j) * dy;
    v.wB = v.wB + (m.iB * armB) * j;
}

template <int Points>
[[gnu::always_inline]] inline void warmStartBundle(ContactBundle<Points>& c, SolverBody* bodies) {
    const BodyLanes a = gather(bodies, c.bodyA), b = gather(bodies, c.bodyB);
    Velocities v{a.vx, a.vy, a.w, b.vx, b.vy, b.w};
    const Masses m{a.invMass, load(c.invInertiaA), b.invMass, load(c.invInertiaB)};
    const D4 nx = load(c.nx), ny = load(c.ny);
    const D4 tx = ny, ty = -nx;
    for (int i = 0; i < Points; ++i) {
        const PointLanes& p = c.points[i];
        const D4 ni = load(p.normalImpulse), ti = load(p.tangentImpulse);
        const D4 rnA = load(p.rnA), rnB = load(p.rnB), dnA = load(p.dnA), dnB = load(p.dnB);
        applyLanes(v, m, nx, ny, rnA, rnB, ni);
        applyLanes(v, m, tx, ty, -dnA, -dnB, ti);
    }
    scatter(bodies, c.bodyA, v.vAx, v.vAy, v.wA, a.invMass);
    scatter(bodies, c.bodyB, v.vBx, v.vBy, v.wB, b.invMass);
}

/// Bias and soft scaling of one point (solveContacts' targetOf).
struct Target {
    D4 bias, massScale, impulseScale;
};

/// One point's sequential normal update (solveContacts' else branch).
[[gnu::always_inline]] inline void normalPoint(Velocities& v, PointLanes& p, const Target& t, D4 nx, D4 ny,
                                               const Masses& m) {
    const D4 rnA = load(p.rnA), rnB = load(p.rnB);
    const D4 ni = load(p.normalImpulse);
    const D4 vn = (((v.vBx - v.vAx) * nx + (v.vBy - v.vAy) * ny) + v.wB * rnB) - v.wA * rnA;
    D4 impulse = ((-load(p.normalMass)) * t.massScale) * (vn + t.bias) - t.impulseScale * ni;
    const D4 total = maxOf(ni + impulse, splat(0.0));
    impulse = total - ni;
    store(p.normalImpulse, total);
    applyLanes(v, m, nx, ny, rnA, rnB, impulse);
}

template <int Points, bool UseBias>
[[gnu::always_inline]] inline void solveBundle(ContactBundle<Points>& c, const PassArgs& args) {
    SolverBody* bodies = args.bodies;
    const BodyLanes a = gather(bodies, c.bodyA), b = gather(bodies, c.bodyB);
    Velocities v{a.vx, a.vy, a.w, b.vx, b.vy, b.w};
    const Masses m{a.invMass, load(c.invInertiaA), b.invMass, load(c.invInertiaB)};
    const D4 mA = m.mA, iA = m.iA, mB = m.mB, iB = m.iB;
    const D4 nx = load(c.nx), ny = load(c.ny);
    const M4 flags = loadMask(c.flags);
    const M4 isStatic = (flags & kTouchesStatic) != 0;
    const D4 biasRate = isStatic ? splat(args.staticSoft.biasRate) : splat(args.soft.biasRate);
    const D4 massScale = isStatic ? splat(args.staticSoft.massScale) : splat(args.soft.massScale);
    const D4 impulseScale = isStatic ? splat(args.staticSoft.impulseScale) : splat(args.soft.impulseScale);
    const D4 rigidDepth = isStatic ? splat(args.staticSoft.rigidDepth) : splat(args.soft.rigidDepth);
    const D4 baseGap = (b.dpx - a.dpx) * nx + (b.dpy - a.dpy) * ny;
    const D4 zero = splat(0.0), one = splat(1.0);
    const M4 roundA = (flags & kRoundA) != 0, roundB = (flags & kRoundB) != 0;
    const D4 qcA = roundA ? one : a.qc, qsA = roundA ? zero : a.qs;
    const D4 qcB = roundB ? one : b.qc, qsB = roundB ? zero : b.qs;
    Target t[2];
    for (int i = 0; i < Points; ++i) {
        const PointLanes& p = c.points[i];
        const D4 separation = ((baseGap + (qcB * load(p.dnB) + qsB * load(p.rnB))) -
                               (qcA * load(p.dnA) + qsA * load(p.rnA))) +
                              load(p.adjustedSeparation);
        const M4 apart = separation > zero;
        const D4 speculative = separation * splat(args.invH);
        if constexpr (UseBias) {
            // Rigid past rigidDepth, or when the approach would carry the
            // point past twice that within this substep (solveContacts says
            // why).
            const D4 vn = (((v.vBx - v.vAx) * nx + (v.vBy - v.vAy) * ny) + v.wB * load(p.rnB)) - v.wA * load(p.rnA);
            const M4 rigid =
                (!(separation > -rigidDepth)) | (!((separation + vn / splat(args.invH)) > -(rigidDepth + rigidDepth)));
            const D4 toDepth = separation + rigidDepth;
            const D4 rigidBias = toDepth > zero ? toDepth * splat(args.invH)
                                                : maxOf(biasRate * toDepth, splat(-args.pushMaxVelocity));
            const D4 push = maxOf(biasRate * separation, splat(-args.pushMaxVelocity));
            t[i] = {apart ? speculative : (rigid ? rigidBias : push), apart ? one : (rigid ? one : massScale),
                    apart ? zero : (rigid ? zero : impulseScale)};
        } else {
            t[i] = {apart ? speculative : zero, one, zero};
        }
    }
    if constexpr (Points == 1) {
        normalPoint(v, c.points[0], t[0], nx, ny, m);
    } else {
        const M4 block = (flags & kBlock) != 0;
        const M4 useBlock = block & (t[0].massScale == t[1].massScale);
        Velocities blockV = v;
        D4 blockX1 = zero, blockX2 = zero;
        if (anyLane(useBlock)) {
            PointLanes& p1 = c.points[0];
            PointLanes& p2 = c.points[1];
            const D4 k11 = load(c.k11), k12 = load(c.k12), k22 = load(c.k22);
            // K^-1 as prepareContacts forms it; zero in the lanes without a
            // block (as BlockMass leaves it there).
            const D4 invDet = one / (k11 * k22 - k12 * k12);
            const D4 i11 = block ? k22 * invDet : zero, i12 = block ? -k12 * invDet : zero,
                     i22 = block ? k11 * invDet : zero;
            const D4 rnA1 = load(p1.rnA), rnB1 = load(p1.rnB), rnA2 = load(p2.rnA), rnB2 = load(p2.rnB);
            const D4 dvx = v.vBx - v.vAx, dvy = v.vBy - v.vAy;
            const D4 a1 = load(p1.normalImpulse), a2 = load(p2.normalImpulse);
            const D4 vn1 = ((dvx * nx + dvy * ny) + v.wB * rnB1) - v.wA * rnA1;
            const D4 vn2 = ((dvx * nx + dvy * ny) + v.wB * rnB2) - v.wA * rnA2;
            const D4 q1 = (vn1 + t[0].bias) - (k11 * a1 + k12 * a2);
            const D4 q2 = (vn2 + t[1].bias) - (k12 * a1 + k22 * a2);
            // The four cases of the 2x2 complementarity problem, taken in
            // solveContacts' order: both push, only the first, only the
            // second, neither.
            const D4 both1 = -(i11 * q1 + i12 * q2);
            const D4 both2 = -(i12 * q1 + i22 * q2);
            const M4 bothOk = (both1 >= zero) & (both2 >= zero);
            D4 y1 = both1, y2 = both2;
            if (!allLanes(bothOk)) {
                // Only lanes where both points cannot push need the other
                // cases (and their divisions): settled stacks rarely do.
                const D4 first1 = -q1 / k11;
                const M4 firstOk = (first1 >= zero) & (k12 * first1 + q2 >= zero);
                const D4 second2 = -q2 / k22;
                const M4 secondOk = (second2 >= zero) & (k12 * second2 + q1 >= zero);
                const M4 noneOk = (q1 >= zero) & (q2 >= zero);
                const D4 none1 = noneOk ? zero : a1 / t[0].massScale;
                const D4 none2 = noneOk ? zero : a2 / t[0].massScale;
                y1 = bothOk ? both1 : firstOk ? first1 : secondOk ? zero : none1;
                y2 = bothOk ? both2 : firstOk ? zero : secondOk ? second2 : none2;
            }
            blockX1 = t[0].massScale * y1;
            blockX2 = t[0].massScale * y2;
            const D4 d1 = blockX1 - a1, d2 = blockX2 - a2;
            const D4 d = d1 + d2;
            blockV.vAx = v.vAx - (mA * d) * nx;
            blockV.vAy = v.vAy - (mA * d) * ny;
            blockV.wA = v.wA - iA * (rnA1 * d1 + rnA2 * d2);
            blockV.vBx = v.vBx + (mB * d) * nx;
            blockV.vBy = v.vBy + (mB * d) * ny;
            blockV.wB = v.wB + iB * (rnB1 * d1 + rnB2 * d2);
        }
        if (allLanes(useBlock)) {
            v = blockV;
            store(c.points[0].normalImpulse, blockX1);
            store(c.points[1].normalImpulse, blockX2);
        } else {
            // Some lanes solve the points one after the other; the block
            // lanes keep their block result.
            normalPoint(v, c.points[0], t[0], nx, ny, m);
            normalPoint(v, c.points[1], t[1], nx, ny, m);
            if (anyLane(useBlock)) {
                v.vAx = useBlock ? blockV.vAx : v.vAx;
                v.vAy = useBlock ? blockV.vAy : v.vAy;
                v.wA = useBlock ? blockV.wA : v.wA;
                v.vBx = useBlock ? blockV.vBx : v.vBx;
                v.vBy = useBlock ? blockV.vBy : v.vBy;
                v.wB = useBlock ? blockV.wB : v.wB;
                store(c.points[0].normalImpulse, useBlock ? blockX1 : load(c.points[0].normalImpulse));
                store(c.points[1].normalImpulse, useBlock ? blockX2 : load(c.points[1].normalImpulse));
            }
        }
    }
    // Friction: t = (n.y, -n.x), cross(r, t) = -dot(r, n).
    const D4 tx = ny, ty = -nx;
    const D4 friction = load(c.friction);
    for (int i = 0; i < Points; ++i) {
        PointLanes& p = c.points[i];
        const D4 dnA = load(p.dnA), dnB = load(p.dnB);
        const D4 ti = load(p.tangentImpulse);
        const D4 vt = (((v.vBx - v.vAx) * tx + (v.vBy - v.vAy) * ty) - v.wB * dnB) + v.wA * dnA;
        const D4 maxFriction = friction * load(p.normalImpulse);
        D4 impulse = (-load(p.tangentMass)) * vt;
        const D4 total = minOf(maxOf(ti + impulse, -maxFriction), maxFriction);  // std::clamp
        impulse = total - ti;
        store(p.tangentImpulse, total);
        applyLanes(v, m, tx, ty, -dnA, -dnB, impulse);
    }
    scatter(bodies, c.bodyA, v.vAx, v.vAy, v.wA, a.invMass);
    scatter(bodies, c.bodyB, v.vBx, v.vBy, v.wB, b.invMass);
}

// One colour: its one-point bundles, then its two-point bundles (any order
// gives the same bits, since no two of its contacts share a dynamic body).
template <int Mode>  // 0 warm start, 1 biased solve, 2 relax
[[gnu::always_inline]] inline void colourPass(const PassArgs& args) {
    for (std::size_t k = 0; k < args.oneCount; ++k) {
        if constexpr (Mode == 0)
            warmStartBundle(args.one[k], args.bodies);
        else
            solveBundle<1, Mode == 1>(args.one[k], args);
    }
    for (std::size_t k = 0; k < args.twoCount; ++k) {
        if constexpr (Mode == 0)
            warmStartBundle(args.two[k], args.bodies);
        else
            solveBundle<2, Mode == 1>(args.two[k], args);
    }
}

using PassKernel = void (*)(const PassArgs&);

template <int Mode>
PassKernel passKernel() {
    return kernelFor<PassArgs, colourPass<Mode>>();
}

template <int Points>
void fillLane(ContactBundle<Points>& bundle, int lane, const ContactConstraint& c, std::uint32_t source,
              std::span<const SolverBody> bodies) {
    const SolverBody& a = bodies[c.bodyA];
    const SolverBody& b = bodies[c.bodyB];
    bundle.bodyA[lane] = c.bodyA;
    bundle.bodyB[lane] = c.bodyB;
    bundle.source[lane] = source;
    bundle.nx[lane] = c.normal.x;
    bundle.ny[lane] = c.normal.y;
    bundle.friction[lane] = c.friction;
    bundle.invInertiaA[lane] = a.invInertia;
    bundle.invInertiaB[lane] = b.invInertia;
    bundle.flags[lane] = (c.touchesStatic ? kTouchesStatic : 0) | (c.block ? kBlock : 0) | (c.roundA ? kRoundA : 0) |
                         (c.roundB ? kRoundB : 0);
    if constexpr (Points == 2) {
        bundle.k11[lane] = c.blockMass.k11;
        bundle.k12[lane] = c.blockMass.k12;
        bundle.k22[lane] = c.blockMass.k22;
    }
    for (int i = 0; i < Points; ++i) {
        const ContactPoint& p = c.points[i];
        PointLanes& q = bundle.points[i];
        q.rnA[lane] = p.rnA;
        q.rnB[lane] = p.rnB;
        q.dnA[lane] = p.dnA;
        q.dnB[lane] = p.dnB;
        q.adjustedSeparation[lane] = p.adjustedSeparation;
        q.normalMass[lane] = p.normalMass;
        q.tangentMass[lane] = p.tangentMass;
        q.normalImpulse[lane] = p.normalImpulse;
        q.tangentImpulse[lane] = p.tangentImpulse;
    }
}

/// Bundles the contacts `order` (all with `Points` points) at the end of
/// `out`; lanes left over stay unused (all zero: static body 0 against itself).
template <int Points>
void bundle(std::vector<ContactBundle<Points>>& out, std::span<const std::uint32_t> order,
            std::span<const ContactConstraint> contacts, std::span<const std::uint32_t> pairBodies,
            std::span<const SolverBody> bodies) {
    const std::size_t first = out.size(), count = (order.size() + kContactLanes - 1) / kContactLanes;
    out.resize(first + count);
    // fillLane sets every field of a used lane; only the last bundle can
    // have unused lanes, which must be all zero.
    if (count > 0) std::memset(static_cast<void*>(&out.back()), 0, sizeof(ContactBundle<Points>));
    // A colour's contacts are scattered through `contacts` (about 240 bytes
    // each) and their bodies through `bodies`: the copy waits on memory, not
    // arithmetic. Fetch the contacts a few lanes ahead, and the bodies a few
    // lanes ahead too, named by the packed pairs (reading them from a contact
    // fetched only lanes before waited on that contact).
    constexpr std::size_t kContactAhead = 8, kBodiesAhead = 4;
    for (std::size_t k = 0; k < order.size(); ++k) {
        if (k + kContactAhead < order.size()) {
            const char* line = reinterpret_cast<const char*>(&contacts[order[k + kContactAhead]]);
            for (std::size_t at = 0; at < sizeof(ContactConstraint); at += 64) __builtin_prefetch(line + at);
        }
        if (k + kBodiesAhead < order.size()) {
            // Both lines of each body: the inverse inertia sits on the
            // second (the iterations' fields fill the first).
            const std::size_t ahead = order[k + kBodiesAhead];
            const SolverBody& a = bodies[pairBodies[2 * ahead]];
            const SolverBody& b = bodies[pairBodies[2 * ahead + 1]];
            __builtin_prefetch(&a);
            __builtin_prefetch(&a.invInertia);
            __builtin_prefetch(&b);
            __builtin_prefetch(&b.invInertia);
        }
        fillLane(out[first + k / kContactLanes], int(k % kContactLanes), contacts[order[k]], order[k], bodies);
    }
    for (std::size_t k = order.size(); k < count * kContactLanes; ++k)
        out[first + k / kContactLanes].source[k % kContactLanes] = ~0u;
}

/// Visits each used lane's impulses as (bodyA, bodyB, normal, tangent).
template <int Points, typename Bundles, typename Visit>
void forEachLane(Bundles& bundles, Visit&& visit) {
    for (auto& b : bundles)
        for (int l = 0; l < kContactLanes; ++l) {
            if (b.source[l] == ~0u) continue;
            for (int i = 0; i < Points; ++i)
                visit(b.bodyA[l], b.bodyB[l], b.source[l], i, b.points[i].normalImpulse[l],
                      b.points[i].tangentImpulse[l]);
        }
}

template <int Points>
void storeLanes(std::span<const ContactBundle<Points>> bundles, std::span<ContactConstraint> contacts) {
    for (const ContactBundle<Points>& b : bundles) {
        for (int l = 0; l < kContactLanes; ++l) {
            if (b.source[l] == ~0u) continue;
            ContactConstraint& c = contacts[b.source[l]];
            for (int i = 0; i < Points; ++i) {
                c.points[i].normalImpulse = b.points[i].normalImpulse[l];
                c.points[i].tangentImpulse = b.points[i].tangentImpulse[l];
            }
        }
    }
}

} // namespace

void ColouredContacts::build(std::span<const ContactConstraint> contacts, const ContactPairs& pairs,
                             std::span<const SolverBody> bodies, bool simd, std::span<const std::uint8_t> heldOut) {
    simd_ = simd;
    const std::size_t n = contacts.size();
    colourMask_.assign(bodies.size(), 0u);
    colourOf_.resize(n);
    // Counts per (colour, point count); the overflow is colour kContactColours.
    std::uint32_t counts[kContactColours + 1][2] = {};
    constexpr std::uint32_t kAllColours = (1u << kContactColours) - 1u;
    // From the packed pairs, not the 232-byte contacts (ContactPairs).
    std::size_t held = 0;
    for (std::size_t k = 0; k < n; ++k) {
        if (!heldOut.empty() && heldOut[k]) {
            colourOf_[k] = kHeldOut;
            ++held;
            continue;
        }
        const std::uint32_t bodyA = pairs.bodies[2 * k], bodyB = pairs.bodies[2 * k + 1];
        const bool two = pairs.twoPoints[k] != 0;
        // Static body 0 is in no colour: any number of contacts of one colour
        // may touch it (it never moves, so they do not interact through it).
        const std::uint32_t used = (bodyA != 0 ? colourMask_[bodyA] : 0u) | (bodyB != 0 ? colourMask_[bodyB] : 0u);
        std::uint32_t free = ~used & kAllColours;
        if (two && used != 0) {
            // Two-point manifolds (boxes, polygons: stacks) take the first
            // colour above every colour their bodies already have, wrapping
            // only when none is left. The contacts come roughly bottom-up
            // (sorted pairs), so a forward pass then runs up a stack in one
            // sweep, as a one-at-a-time pass does; first-free colours
            // alternate layers (red-black) and carry the load up two layers
            // a colour pass. On a 20-row pyramid at 1 iteration, first-free
            // creeps 6.2 mm between t = 2 s and 10 s, this 0.08 mm.
            // Circles keep first-free: on tests/test_collision's 400-circle
            // pile this rule leaves 13.1 mm of overlap (first-free: under the
            // test's 12.5) and flings a 20,000-circle crowd at 6.3 m/s (over 5).
            const int above = 32 - std::countl_zero(used);  // one past the highest colour either body has
            const std::uint32_t higher = above >= 32 ? 0u : ~((1u << above) - 1u);
            if ((free & higher) != 0) free &= higher;
        }
        int colour = kContactColours;
        if (free != 0) {
            colour = std::countr_zero(free);
            if (bodyA != 0) colourMask_[bodyA] |= 1u << colour;
            if (bodyB != 0) colourMask_[bodyB] |= 1u << colour;
        }
        colourOf_[k] = std::uint8_t(colour);
        ++counts[colour][two ? 1 : 0];
    }
    colourCount_ = 0;
    for (int colour = 0; colour < kContactColours; ++colour)
        if (counts[colour][0] + counts[colour][1] > 0) colourCount_ = colour + 1;
    // Order: colour by colour, one-point contacts before two-point ones, each
    // in contact order; the overflow last. A stable counting sort.
    std::uint32_t start[kContactColours + 1][2];
    std::uint32_t at = 0;
    for (int colour = 0; colour <= kContactColours; ++colour) {
        for (int kind = 0; kind < 2; ++kind) {
            start[colour][kind] = at;
            at += counts[colour][kind];
        }
    }
    // Colours past colourCount_ are empty, so the overflow starts where colourCount_ would.
    colourStart_.resize(std::size_t(colourCount_) + 1);
    for (int colour = 0; colour < colourCount_; ++colour) colourStart_[std::size_t(colour)] = start[colour][0];
    colourStart_[std::size_t(colourCount_)] = start[kContactColours][0];
    order_.resize(n - held);
    {
        std::uint32_t cursor[kContactColours + 1][2];
        std::memcpy(cursor, start, sizeof cursor);
        for (std::size_t k = 0; k < n; ++k)
            if (colourOf_[k] != kHeldOut) order_[cursor[colourOf_[k]][pairs.twoPoints[k]]++] = std::uint32_t(k);
    }
    one_.clear();
    two_.clear();
    oneStart_.assign(std::size_t(colourCount_) + 1, 0u);
    twoStart_.assign(std::size_t(colourCount_) + 1, 0u);
    if (!simd_) return;
    for (int colour = 0; colour < colourCount_; ++colour) {
        oneStart_[std::size_t(colour)] = std::uint32_t(one_.size());
        twoStart_[std::size_t(colour)] = std::uint32_t(two_.size());
        const std::span<const std::uint32_t> all(order_);
        bundle<1>(one_, all.subspan(start[colour][0], counts[colour][0]), contacts, pairs.bodies, bodies);
        bundle<2>(two_, all.subspan(start[colour][1], counts[colour][1]), contacts, pairs.bodies, bodies);
    }
    oneStart_[std::size_t(colourCount_)] = std::uint32_t(one_.size());
    twoStart_[std::size_t(colourCount_)] = std::uint32_t(two_.size());
}

void ColouredContacts::warmStart(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies) {
    if (!simd_) {
        collision::warmStart(contacts, order_, bodies);
        return;
    }
    const PassKernel kernel = passKernel<0>();
    for (int colour = 0; colour < colourCount_; ++colour) {
        const std::size_t c = std::size_t(colour);
        PassArgs args{bodies.data(), one_.data() + oneStart_[c], oneStart_[c + 1] - oneStart_[c],
                      two_.data() + twoStart_[c], twoStart_[c + 1] - twoStart_[c], {}, {}, 0.0, 0.0};
        kernel(args);
    }
    const std::span<const std::uint32_t> overflow = std::span<const std::uint32_t>(order_).subspan(colourStart_[std::size_t(colourCount_)]);
    if (!overflow.empty()) collision::warmStart(contacts, overflow, bodies);
}

void ColouredContacts::solve(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies, double h,
                             const Softness& soft, const Softness& staticSoft, double pushMaxVelocity, bool useBias,
                             bool reverse) {
    if (!simd_) {
        solveContacts(contacts, order_, bodies, h, soft, staticSoft, pushMaxVelocity, useBias, reverse);
        return;
    }
    const std::span<const std::uint32_t> overflow = std::span<const std::uint32_t>(order_).subspan(colourStart_[std::size_t(colourCount_)]);
    const auto solveOverflow = [&] {
        if (!overflow.empty())
            solveContacts(contacts, overflow, bodies, h, soft, staticSoft, pushMaxVelocity, useBias, reverse);
    };
    if (reverse) solveOverflow();
    const PassKernel kernel = useBias ? passKernel<1>() : passKernel<2>();
    for (int k = 0; k < colourCount_; ++k) {
        const std::size_t c = std::size_t(reverse ? colourCount_ - 1 - k : k);
        PassArgs args{bodies.data(), one_.data() + oneStart_[c], oneStart_[c + 1] - oneStart_[c],
                      two_.data() + twoStart_[c], twoStart_[c + 1] - twoStart_[c], soft, staticSoft, 1.0 / h,
                      pushMaxVelocity};
        kernel(args);
    }
    if (!reverse) solveOverflow();
}

template <class Self, class Contacts, class Visit>
void ColouredContacts::forEachHeld(Self& self, Contacts& contacts, Visit&& visit) {
    const auto points = [&](std::uint32_t k) {
        auto& c = contacts[k];
        for (int i = 0; i < c.pointCount; ++i)
            visit(c.bodyA, c.bodyB, k, i, c.points[i].normalImpulse, c.points[i].tangentImpulse);
    };
    if (!self.simd_) {
        for (std::uint32_t k = 0; k < contacts.size(); ++k)
            if (self.colourOf_[k] != kHeldOut) points(k);
        return;
    }
    forEachLane<1>(self.one_, visit);
    forEachLane<2>(self.two_, visit);
    const std::span<const std::uint32_t> order(self.order_);
    for (const std::uint32_t k : order.subspan(self.colourStart_[std::size_t(self.colourCount_)])) points(k);
}

void ColouredContacts::saveImpulses(std::span<const ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                                    std::vector<double>& out) const {
    out.clear();
    const auto save = [&](std::uint32_t a, std::uint32_t b, std::uint32_t, int, double normal, double tangent) {
        if (!marked[a] && !marked[b]) return;
        out.push_back(normal);
        out.push_back(tangent);
    };
    forEachHeld(*this, contacts, save);
}

void ColouredContacts::restoreImpulses(std::span<ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                                       std::span<const double> saved, std::span<SolverBody> bodies,
                                       std::span<const std::uint8_t> takeBack) {
    std::size_t at = 0;
    takenBack_.clear();
    const auto restore = [&](std::uint32_t a, std::uint32_t b, std::uint32_t k, int i, double& normal,
                             double& tangent) {
        if (!marked[a] && !marked[b]) return;
        if (marked[a] != marked[b] && (takeBack[a] || takeBack[b]))
            takenBack_.push_back({2 * k + std::uint32_t(i), normal - saved[at], tangent - saved[at + 1]});
        normal = saved[at];
        tangent = saved[at + 1];
        at += 2;
    };
    forEachHeld(*this, contacts, restore);
    // In contact order, whichever path holds the impulses: a body's
    // velocity then sums the same terms in the same order (the same bits).
    std::sort(takenBack_.begin(), takenBack_.end(),
              [](const TakenBack& x, const TakenBack& y) { return x.point < y.point; });
    for (const TakenBack& e : takenBack_) {
        const ContactConstraint& c = contacts[e.point / 2];
        const ContactPoint& p = c.points[e.point % 2];
        const Vec2 t{c.normal.y, -c.normal.x};
        const Vec2 impulse = e.normal * c.normal + e.tangent * t;
        if (takeBack[c.bodyA]) {
            SolverBody& body = bodies[c.bodyA];
            body.v += body.invMass * impulse;
            body.w += body.invInertia * (p.rnA * e.normal - p.dnA * e.tangent);
        } else {
            SolverBody& body = bodies[c.bodyB];
            body.v -= body.invMass * impulse;
            body.w -= body.invInertia * (p.rnB * e.normal - p.dnB * e.tangent);
        }
    }
}

void ColouredContacts::storeImpulses(std::span<ContactConstraint> contacts) const {
    if (!simd_) return;
    storeLanes<1>(one_, contacts);
    storeLanes<2>(two_, contacts);
}

} // namespace stepwise::collision
