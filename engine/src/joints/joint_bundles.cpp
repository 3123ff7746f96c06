#include "joints/joint_bundles.hpp"

#include <algorithm>
#include <iterator>

namespace stepwise::joints {

using collision::SolverBody;
using collision::Softness;

namespace {

using namespace collision::simd;

/// A hinge the bundles can take: one point row, nothing axial.
bool isPlainHinge(const JointConstraint& j) {
    return j.kind == JointKind::Hinge && !j.direct && !j.motor && !j.hasLower && !j.hasUpper && !j.spring && !j.asleep;
}

struct Lanes {
    BodyLanes a, b;
    D4 iA, iB;
};
[[gnu::always_inline]] inline D4 invInertiaOf(const SolverBody* bodies, const std::uint32_t* index) {
    return D4{bodies[index[0]].invInertia, bodies[index[1]].invInertia, bodies[index[2]].invInertia,
              bodies[index[3]].invInertia};
}
[[gnu::always_inline]] inline Lanes gatherLanes(const SolverBody* bodies, const HingeBundle& h) {
    return {gather(bodies, h.bodyA), gather(bodies, h.bodyB), invInertiaOf(bodies, h.bodyA),
            invInertiaOf(bodies, h.bodyB)};
}
[[gnu::always_inline]] inline void scatterLanes(SolverBody* bodies, const HingeBundle& h, const Lanes& l) {
    // A's bodies, then B's, as Pair::store writes them.
    scatter(bodies, h.bodyA, l.a.vx, l.a.vy, l.a.w, l.a.invMass);
    scatter(bodies, h.bodyB, l.b.vx, l.b.vy, l.b.w, l.b.invMass);
}

/// The anchors turned by each body's rotation since the step began:
/// rotate(dq, anchor).
struct Arms {
    D4 rAx, rAy, rBx, rBy;
};
[[gnu::always_inline]] inline Arms armsOf(const HingeBundle& h, const Lanes& l) {
    const D4 ax = load(h.anchorAx), ay = load(h.anchorAy), bx = load(h.anchorBx), by = load(h.anchorBy);
    return {l.a.qc * ax - l.a.qs * ay, l.a.qs * ax + l.a.qc * ay, l.b.qc * bx - l.b.qs * by,
            l.b.qs * bx + l.b.qc * by};
}
/// Pair::applyLinear: impulse P at the arms, -P on A, +P on B.
[[gnu::always_inline]] inline void applyLinear(Lanes& l, const Arms& r, D4 px, D4 py) {
    l.a.vx = l.a.vx - l.a.invMass * px;
    l.a.vy = l.a.vy - l.a.invMass * py;
    l.a.w = l.a.w - l.iA * (r.rAx * py - r.rAy * px);
    l.b.vx = l.b.vx + l.b.invMass * px;
    l.b.vy = l.b.vy + l.b.invMass * py;
    l.b.w = l.b.w + l.iB * (r.rBx * py - r.rBy * px);
}

/// warmStartJoints' hinge case: the point impulse, then the axial one
/// (motor + lower - upper, zero for a plain hinge but still applied: adding
/// +0 turns a -0 spin into +0, and the scalar pass adds it).
[[gnu::always_inline]] inline void warmStartBundle(const HingeBundle& h, SolverBody* bodies, const double* axial) {
    Lanes l = gatherLanes(bodies, h);
    const Arms r = armsOf(h, l);
    applyLinear(l, r, load(h.impulseX), load(h.impulseY));
    const D4 ax = load(axial);
    l.a.w = l.a.w - l.iA * ax;
    l.b.w = l.b.w + l.iB * ax;
    scatterLanes(bodies, h, l);
}

/// solvePoint, lane by lane, with the row's scales (equalityRow) given.
struct RowLanes {
    D4 biasRate, massScale, impulseScale;
    bool apply;
};
[[gnu::always_inline]] inline void solveBundle(HingeBundle& h, SolverBody* bodies, const RowLanes& row) {
    Lanes l = gatherLanes(bodies, h);
    const Arms r = armsOf(h, l);
    const D4 cdotX = ((l.b.vx + (-l.b.w) * r.rBy) - l.a.vx) - (-l.a.w) * r.rAy;
    const D4 cdotY = ((l.b.vy + l.b.w * r.rBx) - l.a.vy) - l.a.w * r.rAx;
    D4 biasX = splat(0.0), biasY = splat(0.0);
    if (row.apply) {
        const D4 sepX = ((l.b.dpx - l.a.dpx) + (r.rBx - r.rAx)) + load(h.deltaX);
        const D4 sepY = ((l.b.dpy - l.a.dpy) + (r.rBy - r.rAy)) + load(h.deltaY);
        biasX = row.biasRate * sepX;
        biasY = row.biasRate * sepY;
    }
    const D4 mSum = l.a.invMass + l.b.invMass;
    const D4 k11 = (mSum + (r.rAy * r.rAy) * l.iA) + (r.rBy * r.rBy) * l.iB;
    const D4 k12 = ((-r.rAy) * r.rAx) * l.iA - (r.rBy * r.rBx) * l.iB;
    const D4 k22 = (mSum + (r.rAx * r.rAx) * l.iA) + (r.rBx * r.rBx) * l.iB;
    const D4 bx = cdotX + biasX, by = cdotY + biasY;
    // solve22: a singular K (two fixed ends) gives zero.
    D4 det = k11 * k22 - k12 * k12;
    det = det != 0.0 ? 1.0 / det : det;
    const D4 xx = det * (k22 * bx - k12 * by), xy = det * (k11 * by - k12 * bx);
    const D4 oldX = load(h.impulseX), oldY = load(h.impulseY);
    const D4 minusScale = -row.massScale;
    const D4 px = minusScale * xx - row.impulseScale * oldX;
    const D4 py = minusScale * xy - row.impulseScale * oldY;
    store(h.impulseX, oldX + px);
    store(h.impulseY, oldY + py);
    applyLinear(l, r, px, py);
    scatterLanes(bodies, h, l);
}

struct PassArgs {
    SolverBody* bodies;
    HingeBundle* bundles;
    const double* axial;  ///< warm start: kLanes per bundle
    std::size_t count;
    RowLanes row;
};

template <bool WarmStart>
[[gnu::always_inline]] inline void bundlePass(const PassArgs& args) {
    for (std::size_t k = 0; k < args.count; ++k) {
        if constexpr (WarmStart)
            warmStartBundle(args.bundles[k], args.bodies, args.axial + HingeBundle::kLanes * k);
        else
            solveBundle(args.bundles[k], args.bodies, args.row);
    }
}

using PassKernel = void (*)(const PassArgs&);

template <bool WarmStart>
PassKernel passKernel() {
    return kernelFor<PassArgs, bundlePass<WarmStart>>();
}

} // namespace

void JointBundles::build(std::span<const JointConstraint> joints, std::span<const std::uint32_t> order,
                         std::span<const std::uint32_t> colourEnds, bool simd) {
    bundles_.clear();
    rest_.clear();
    segments_.clear();
    axial_.clear();
    bundled_ = 0;
    std::uint32_t begin = 0;
    for (std::size_t c = 0; c < colourEnds.size(); ++c) {
        const std::uint32_t end = colourEnds[c];
        // The last entry is the overflow, whose joints may share bodies: one
        // at a time, in order.
        const bool bundle = simd && c + 1 < colourEnds.size();
        int lane = HingeBundle::kLanes;
        for (std::uint32_t i = begin; i < end; ++i) {
            const std::uint32_t k = order[i];
            const JointConstraint& j = joints[k];
            if (!bundle || !isPlainHinge(j)) {
                rest_.push_back(k);
                continue;
            }
            if (lane == HingeBundle::kLanes) {
                // Value-initialised: every lane starts as an unused one (body
                // 0 to body 0, zeros), and only its joint needs marking.
                HingeBundle& h = bundles_.emplace_back();
                std::fill(std::begin(h.joint), std::end(h.joint), HingeBundle::kNoJoint);
                axial_.resize(axial_.size() + HingeBundle::kLanes, 0.0);
                lane = 0;
            }
            HingeBundle& h = bundles_.back();
            h.anchorAx[lane] = j.anchorA.x;
            h.anchorAy[lane] = j.anchorA.y;
            h.anchorBx[lane] = j.anchorB.x;
            h.anchorBy[lane] = j.anchorB.y;
            h.deltaX[lane] = j.deltaCenter.x;
            h.deltaY[lane] = j.deltaCenter.y;
            h.impulseX[lane] = j.linearImpulse.x;
            h.impulseY[lane] = j.linearImpulse.y;
            h.bodyA[lane] = j.a.solverBody;
            h.bodyB[lane] = j.b.solverBody;
            h.joint[lane] = k;
            axial_[axial_.size() - HingeBundle::kLanes + std::size_t(lane)] =
                j.motorImpulse + j.lowerImpulse - j.upperImpulse;
            ++lane;
            ++bundled_;
        }
        segments_.push_back({std::uint32_t(bundles_.size()), std::uint32_t(rest_.size())});
        begin = end;
    }
}

template <class Bundles, class Rest>
void JointBundles::forEachSegment(Bundles&& bundles, Rest&& rest) const {
    std::uint32_t bundle = 0, joint = 0;
    for (const Segment& s : segments_) {
        if (s.bundleEnd > bundle) bundles(bundle, s.bundleEnd - bundle);
        if (s.restEnd > joint) rest(std::span<const std::uint32_t>(rest_).subspan(joint, s.restEnd - joint));
        bundle = s.bundleEnd;
        joint = s.restEnd;
    }
}

void JointBundles::warmStart(std::span<JointConstraint> joints, std::span<SolverBody> bodies) {
    const PassKernel kernel = passKernel<true>();
    forEachSegment(
        [&](std::uint32_t first, std::uint32_t count) {
            kernel(PassArgs{bodies.data(), bundles_.data() + first, axial_.data() + HingeBundle::kLanes * first, count, {}});
        },
        [&](std::span<const std::uint32_t> order) { warmStartJoints(joints, order, bodies); });
}

void JointBundles::solve(std::span<JointConstraint> joints, std::span<SolverBody> bodies, double h,
                         const Softness& loopSoft, const Softness& directSoft, bool useBias) {
    const PassKernel kernel = passKernel<false>();
    // equalityRow(0, loopSoft, useBias): the bundled hinges are all in loops.
    const RowLanes row = useBias ? RowLanes{splat(loopSoft.biasRate), splat(loopSoft.massScale),
                                            splat(loopSoft.impulseScale), true}
                                 : RowLanes{splat(0.0), splat(1.0), splat(0.0), false};
    forEachSegment(
        [&](std::uint32_t first, std::uint32_t count) {
            kernel(PassArgs{bodies.data(), bundles_.data() + first, nullptr, count, row});
        },
        [&](std::span<const std::uint32_t> order) {
            solveJoints(joints, order, bodies, h, loopSoft, directSoft, useBias);
        });
}

void JointBundles::storeImpulses(std::span<JointConstraint> joints) const {
    for (const HingeBundle& h : bundles_)
        for (int m = 0; m < HingeBundle::kLanes; ++m)
            if (h.joint[m] != HingeBundle::kNoJoint) joints[h.joint[m]].linearImpulse = {h.impulseX[m], h.impulseY[m]};
}

void JointBundles::loadImpulses(std::span<const JointConstraint> joints) {
    for (HingeBundle& h : bundles_)
        for (int m = 0; m < HingeBundle::kLanes; ++m)
            if (h.joint[m] != HingeBundle::kNoJoint) {
                h.impulseX[m] = joints[h.joint[m]].linearImpulse.x;
                h.impulseY[m] = joints[h.joint[m]].linearImpulse.y;
            }
}

} // namespace stepwise::joints
