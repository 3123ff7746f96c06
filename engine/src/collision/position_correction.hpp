#pragma once
// Position correction after the soft step: a rigid pass over positions that
// takes out overlap beyond the slop, moving bodies without changing their
// velocities (non-linear Gauss-Seidel on positions, Box2D 2.4.1's
// SolvePositionConstraints; Catto, "Solver2D", the NGS solver).
//
// Contacts with the static world are rigid in the velocity solve
// (Softness::rigidDepth), which holds any load the step can resolve; this
// pass is the backstop for the rest: the overlap with static geometry ends
// each step at the slop whatever the load, the substeps or the iterations.
// Between moving bodies it acts only on crowds (bodies started deep in one
// another): a fifth of the excess a step, as 2.4.1's Baumgarte factor, so
// the crowd unfolds through positions and is not flung. Other moving pairs
// are left to the soft contacts: a second rule fighting their equilibrium
// made piles jitter.

#include "collision/contact_solver.hpp"

#include <span>
#include <vector>

namespace stepwise::collision {

struct PositionCorrectionSettings {
    double slop = 0.005;             ///< m: overlap left alone (the soft contacts' working range)
    double movingFraction = 0.2;     ///< of the excess between two moving bodies, per pass
    double maxCorrection = 0.2;      ///< m: the largest move of one point between moving bodies in one pass
    /// m: past this, a static contact's correction moves the body without
    /// turning it (the turn is linearised: a metre of correction through a
    /// corner would spin a box round).
    double maxTurningCorrection = 0.05;
    int maxPasses = 16;              ///< at most, over the static contacts per step
};

/// What the pass moved: per solver body, the change of its angle (rad); its
/// displacement is added to SolverBody::dp and its rotation to dq.
struct PositionCorrectionScratch {
    std::vector<std::uint32_t> deepMoving;      ///< moving pairs with a point past the slop
    std::vector<std::uint32_t> touchingStatic;  ///< contacts with the static world that overlap
    std::vector<double> turned;       ///< rad, per solver body
    std::vector<std::uint8_t> moved;  ///< per solver body: 1 when the pass moved it
};

/// Corrects the positions of the bodies of `contacts` (their dp and dq):
/// every contact with the static world, and between moving bodies those
/// with a body marked in `crowd` (per solver body; an empty span marks all).
/// Returns false, having touched nothing, when no point is deeper than the
/// slop: the common case costs one look at each contact's separations.
/// `measured` (empty, or one entry per contact) holds the deepestSeparation
/// of every contact between moving bodies at the bodies' present poses, as
/// the solve's last pass measured it: those contacts are then not read
/// unless they are too deep.
bool correctPositions(std::span<const ContactConstraint> contacts, std::span<SolverBody> bodies,
                      std::span<const std::uint8_t> crowd, const PositionCorrectionSettings& settings,
                      PositionCorrectionScratch& scratch, std::span<const double> measured = {});

/// Where a body, at its pose once the passes above have run, meets a static
/// shape: a point of a manifold found afresh by the narrow phase.
struct PresentContact {
    Vec2 normal;              ///< unit, from the static shape into the body
    Vec2 arm;                 ///< the point minus the body's centre of mass now, metres
    double separation = 0.0;  ///< metres (< 0: overlap)
};

/// One pass of correctPositions' static rule over one body's contacts found
/// at its present pose: each point deeper than the slop is moved back to
/// it, the later points' depths following the earlier moves (linearised).
/// The move is added to body.dp and body.dq and its turn (rad) to `turned`;
/// returns the deepest excess past the slop it found (<= 0, metres).
double pushOutOfStatic(SolverBody& body, std::span<const PresentContact> points,
                       const PositionCorrectionSettings& settings, double& turned);

} // namespace stepwise::collision
