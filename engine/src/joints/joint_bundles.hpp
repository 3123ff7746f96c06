#pragma once
// The joint passes with plain hinges in SIMD lanes, as the contacts are
// (collision/contact_bundles.hpp): within one colour of colourJoints' order
// no two joints share a moving body, so kLanes hinges solved together in
// vector registers give what solving them one after another gives. A hinge
// with no motor, limit or spring, solved by the passes (not in an exactly
// solved tree), is one 2x2 point row: a grid of 20,000 of them spends half
// its step in these passes. Every other joint, and the colours' overflow,
// goes through the scalar passes (joint_solver.hpp) in the same order.
//
// Bit-identical to the scalar passes on every instruction set: each lane
// does solvePoint's operations in solvePoint's order (the tests compare
// every body's state bit for bit with SolverSettings::simd off).

#include "collision/contact_solver.hpp"
#include "collision/simd_lanes.hpp"
#include "joints/joint_solver.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace stepwise::joints {

/// kLanes plain hinges, one array per quantity. Unused lanes join static
/// body 0 to itself with zero anchors: they compute zeros and write body 0's
/// zeros back.
struct HingeBundle {
    static constexpr int kLanes = collision::simd::kLanes;
    alignas(32) double anchorAx[kLanes], anchorAy[kLanes], anchorBx[kLanes], anchorBy[kLanes];
    alignas(32) double deltaX[kLanes], deltaY[kLanes];      ///< centre B - centre A at step start, m
    alignas(32) double impulseX[kLanes], impulseY[kLanes];  ///< accumulated point impulse, N*s
    std::uint32_t bodyA[kLanes], bodyB[kLanes];
    std::uint32_t joint[kLanes];  ///< index in the joints; kNoJoint for an unused lane
    static constexpr std::uint32_t kNoJoint = ~0u;
};

/// A step's joints in colourJoints' order, the plain hinges of each colour
/// in bundles and the rest one at a time. Built once a step, after
/// prepareJoints; the bundled hinges' impulses live in the bundles until
/// storeImpulses.
class JointBundles {
public:
    /// `order` and `colourEnds` as colourJoints gives them. `simd` off: every
    /// joint one at a time (SolverSettings::simd).
    void build(std::span<const JointConstraint> joints, std::span<const std::uint32_t> order,
               std::span<const std::uint32_t> colourEnds, bool simd);
    /// warmStartJoints over every joint, in the order.
    void warmStart(std::span<JointConstraint> joints, std::span<collision::SolverBody> bodies);
    /// solveJoints over every joint, in the order.
    void solve(std::span<JointConstraint> joints, std::span<collision::SolverBody> bodies, double h,
               const collision::Softness& loopSoft, const collision::Softness& directSoft, bool useBias);
    /// Copies the bundles' impulses back to their joints.
    void storeImpulses(std::span<JointConstraint> joints) const;
    /// Copies the joints' impulses into the bundles (after a change to them
    /// mid-step).
    void loadImpulses(std::span<const JointConstraint> joints);
    std::size_t bundledCount() const { return bundled_; }
    std::size_t oneAtATimeCount() const { return rest_.size(); }

private:
    /// One colour (or the overflow): bundles_[.., bundleEnd), then
    /// rest_[.., restEnd).
    struct Segment {
        std::uint32_t bundleEnd, restEnd;
    };
    /// Calls bundles(first, count) for each colour's bundles, then
    /// rest(order) for its joints solved one at a time, colour by colour.
    template <class Bundles, class Rest>
    void forEachSegment(Bundles&& bundles, Rest&& rest) const;
    std::vector<HingeBundle> bundles_;
    std::vector<std::uint32_t> rest_;
    /// Per bundle lane: the axial impulse the warm start applies
    /// (motor + lower - upper, as warmStartJoints forms it).
    std::vector<double> axial_;
    std::vector<Segment> segments_;
    std::size_t bundled_ = 0;
};

} // namespace stepwise::joints
