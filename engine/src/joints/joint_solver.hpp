#pragma once
// Joints in the soft-step solver (Catto's Solver2D / Box2D v3 design): each
// joint is a velocity constraint solved with the contacts, in the same
// substeps, warm started from the previous substep and step, with a soft
// position bias in the biased iterations and none in the relax pass.
//
//   hinge     point constraint (2x2 solve) + angle limits + motor
//   slider    perpendicular and angular rows (2x2 solve) + travel limits + motor
//   weld      point (2x2) + angle; rigid, or a spring of stiffness_hz
//   distance  anchors `length` apart along their line; rigid or a spring
//   rope      anchors at most `length` apart (one-sided)
//   wheel     b's anchor on a line along a's axis (1 row), a spring along
//             the axis, free rotation with a motor, travel limits
//
// Anchors are taken at step start (rotated by each body's orientation then)
// and turned by each body's rotation since, as the contact solver does, so
// the position error is measured on the current pose in every substep.

#include "collision/contact_solver.hpp"

#include "stepwise/entity.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

namespace stepwise::joints {

enum class JointKind : std::uint8_t { Hinge, Slider, Weld, Distance, Rope, Wheel };

/// A fixed end (a static body or the world) or a body in the solver.
struct JointEnd {
    std::uint32_t solverBody = 0;  ///< SolverBody index; 0 = fixed
    std::int32_t collider = -1;    ///< collider index of a dynamic end (its centre and angle); -1 = fixed
    Vec2 fixedCentre;              ///< fixed end: position, metres (the world: origin)
    double fixedAngle = 0.0;       ///< fixed end: orientation, rad
    Vec2 local;                    ///< anchor in the end's frame, metres
};

/// One joint: its definition (from the scene) and its solver state.
/// What every pass of a hinge reads and writes (kind and flags, the
/// step-start anchors, the centres' offset, the point impulse, both ends'
/// solver bodies) comes first and fits two cache lines of the aligned
/// struct: a grid of 20,000 hinges streams the array three times a substep,
/// and with those fields spread over the struct the passes cost a third
/// more (joint_grid, joints_vs_box2d --grid).
struct alignas(64) JointConstraint {
    JointKind kind = JointKind::Hinge;
    /// Its island sleeps (world/islands.hpp): the solver passes skip it and
    /// its impulses stay as they were, ready for the wake.
    bool asleep = false;
    /// Its point rows (a rigid weld: all its rows) are solved exactly with
    /// the rest of its tree (direct_joints.hpp); the Gauss-Seidel passes
    /// solve only its limits and motor.
    bool direct = false;
    bool motor = false;
    bool hasLower = false, hasUpper = false;
    /// A hinge with a spring (springHz > 0), or a wheel with an axis spring
    /// (stiffnessHz > 0): read here, in the first cache line, so a hinge
    /// without one never touches the spring's fields.
    bool spring = false;

    // Prepared at step start.
    Vec2 anchorA, anchorB;         ///< anchors rotated to world orientation, relative to the centres, m
    Vec2 deltaCenter;              ///< centre B - centre A, m
    // Accumulated impulses (warm started), N*s and N*m*s.
    Vec2 linearImpulse;            ///< hinge/weld point; slider: (perpendicular, angular); wheel: (perpendicular, 0)

    JointEnd a, b;                 ///< solverBody first in each: still in the first two lines

    double angularImpulse = 0.0;   ///< weld angle
    double axialImpulse = 0.0;     ///< distance / rope along the line; slider: unused
    double motorImpulse = 0.0;
    double lowerImpulse = 0.0, upperImpulse = 0.0;

    Vec2 localAxis{1.0, 0.0};      ///< slider: unit axis in a's frame
    double referenceAngle = 0.0;   ///< rad
    double lower = 0.0, upper = 0.0;  ///< rad (hinge) or m (slider)
    double motorSpeed = 0.0;       ///< rad/s or m/s
    double maxMotor = 0.0;         ///< N*m or N
    double length = 0.0;           ///< distance, rope: metres
    double stiffnessHz = 0.0;      ///< weld, distance: 0 = rigid; wheel: the axis spring, 0 = none (free travel)
    double dampingRatio = 1.0;
    /// Hinge: rotational spring toward referenceAngle, Hz (0: none), solved
    /// in both passes as Box2D's revolute spring, on the axial mass.
    double springHz = 0.0;
    double springDampingRatio = 1.0;
    double springImpulse = 0.0;    ///< accumulated, N*m*s (warm started); wheel: its axis spring's, N*s
    /// Breaks after a step whose constraint force |jointForce| exceeds this,
    /// newtons; 0: never (CollisionSystem only looks at joints listed as
    /// breakable, so an unbreakable level pays nothing).
    double maxForce = 0.0;
    /// Broke: out of the run. It stays in the array (snapshots and the
    /// layout keep their shape; a restore before the break brings it back)
    /// with `asleep` set, so every pass skips it as it skips a sleeping one,
    /// and no group, island edge or record includes it.
    bool broken = false;
    /// Its (min collider << 32 | max collider) entry in the no-collide list
    /// (collide_connected false, both ends with a collider); 0: none.
    std::uint64_t noCollideKey = 0;
    Entity entity;                 ///< the joint's own entity
    Entity entityA, entityB;       ///< its ends (entityB null: the world)

    Vec2 centreA, centreB;         ///< centres at step start, m
    double deltaAngle = 0.0;       ///< angle B - angle A - reference, rad
    Vec2 axisA;                    ///< slider and wheel axis in world orientation at step start
    double axialMass = 0.0;        ///< 1 / (iA + iB), kg m^2 (hinge motor/limits, weld angle)
};

struct JointSettings {
    /// The world's joint_hz and joint_damping_ratio: the softness of every
    /// rigid joint's position correction. Absent: the engine's choice, by
    /// how the joint is solved (docs/joints.md, "Softness"):
    ///  * in a tree solved exactly (direct_joints.hpp): half the substep
    ///    rate, damping ratio 1 (stiff: the exact solve has no Gauss-Seidel
    ///    lag to destabilise, and a pendulum keeps its period within 1e-4);
    ///  * in a loop (Gauss-Seidel): 60 Hz, damping ratio 2, Box2D v3's
    ///    jointHertz and jointDampingRatio. At the cap a 100 x 100 hinge grid
    ///    opened 2.06 m in 60 steps at 4 substeps and 1 iteration; at 60 Hz,
    ///    ratio 2, 0.23 m (joints_vs_box2d --grid).
    /// Whatever is given, the stiffness is capped at half the substep rate
    /// (the soft step's stability limit, twice the contacts' cap).
    std::optional<double> hertz;
    std::optional<double> dampingRatio;
    static constexpr double kLoopHertz = 60.0;
    static constexpr double kLoopDampingRatio = 2.0;
    static constexpr double kTreeDampingRatio = 1.0;
};

/// The joint's accumulated impulses (its warm start), keyed by its entity.
JointImpulse impulsesOf(const JointConstraint& joint);
/// Sets them, zeroing the rows the joint does not have (a motor impulse on
/// a hinge without a motor, a limit it lacks, a row of another type), which
/// the warm start would otherwise apply every substep with nothing to undo it.
void setImpulses(JointConstraint& joint, const JointImpulse& impulses);

/// For each joint listed in `marked`: applies to its bodies the opposite of
/// what its impulses gained since `saved` (its impulses then, in the same
/// order), and sets them back to `saved`: what the joint gave since is
/// undone on both ends.
void takeBackJointImpulses(std::span<JointConstraint> joints, std::span<const std::uint32_t> marked,
                           std::span<const JointImpulse> saved, std::span<collision::SolverBody> bodies);

/// Computes the step-start anchors, centres and angles. `centres` and
/// `angles` are per collider (step start).
void prepareJoints(std::span<JointConstraint> joints, std::span<const collision::SolverBody> bodies,
                   std::span<const Vec2> centres, std::span<const double> angles);
/// The same geometry for the sleeping joints (asleep, not broken), from
/// where their bodies rest: what they report (restingAnchors, deltaAngle)
/// after a load or an edit as well as after the step they fell asleep in.
void poseResting(std::span<JointConstraint> joints, std::span<const Vec2> centres, std::span<const double> angles);
/// The order the passes below visit the joints in: coloured as the
/// contacts are (each joint takes the first colour neither of its moving
/// bodies has; the fixed body is in no colour), colour by colour, each in
/// joint order; past 64 colours, the rest last in joint order. Consecutive
/// joints of one colour share no body, so the processor overlaps their
/// solves: in joint order a grid's neighbours wait on each other's
/// velocities, and 100 x 100 hinges took a quarter longer a pass (Box2D v3
/// colours its joints the same way). `colourEnds`, if given, receives
/// where each of the 64 colours ends in `order`, then where the rest ends.
void colourJoints(std::span<const JointConstraint> joints, std::size_t bodyCount, std::vector<std::uint32_t>& order,
                  std::vector<std::uint32_t>* colourEnds = nullptr);
/// Applies the accumulated impulses, in `order` (colourJoints).
void warmStartJoints(std::span<JointConstraint> joints, std::span<const std::uint32_t> order,
                     std::span<collision::SolverBody> bodies);
/// One Gauss-Seidel pass over the joints, in `order` (colourJoints); `soft` is the rigid rows'
/// softness (used in biased passes only), `directSoft` that of the rows
/// (limits) of joints in an exactly solved tree.
void solveJoints(std::span<JointConstraint> joints, std::span<const std::uint32_t> order,
                 std::span<collision::SolverBody> bodies, double h,
                 const collision::Softness& soft, const collision::Softness& directSoft, bool useBias);

/// Implicit geometric stiffness of the point joints (hinge, weld): a joint
/// force F at anchor r turns with its body, so the torque r x F changes by
/// -(r . F) per radian of turn: a body pulled outward at its anchors (a
/// link in a taut chain) has a rotational stiffness k = sum of r . F. A
/// light link under a heavy load then rings at sqrt(k / I), far above what
/// a substep resolves (1000:1 at 240 Hz: sqrt(k/I) h is about 2, the
/// semi-implicit step's limit), and the chain shakes itself apart. Taking
/// that stiffness implicitly (backward Euler: (I + h^2 k) dw = h torque)
/// is the same as giving each such body the inertia I + h^2 k for the
/// substep: it damps only those modes (h^2 k is 0.1% of I for a 1 kg link
/// under its own weight at 240 Hz) and vanishes as h -> 0. F is taken from
/// the accumulated impulses of the last substep (F h = impulse), so
/// h^2 k = h (r . impulse). Compression (k < 0) is left alone: lowering
/// the inertia would destabilise. Sets bodies' invInertia until
/// restoreInertia() (CollisionSystem: for the whole step); `saved` receives
/// (solver body, original invInertia); `scratch` is all zero between calls.
void stiffenRotation(std::span<const JointConstraint> joints, std::span<collision::SolverBody> bodies, double h,
                     std::vector<std::pair<std::uint32_t, double>>& saved, std::vector<double>& scratch);
void restoreInertia(std::span<collision::SolverBody> bodies, std::span<const std::pair<std::uint32_t, double>> saved);

/// The joint's pull on b (newtons) and torque on b (N*m) over the last
/// substep of length h, from the accumulated impulses; a gets the opposite.
Vec2 jointForce(const JointConstraint& joint, double h);
double jointTorque(const JointConstraint& joint, double h);
/// World anchor points now and the distance between them (metres): the
/// error a rigid hinge or weld should keep near zero.
struct JointAnchors {
    Vec2 a, b;
    double separation = 0.0;
};
/// Angle of b relative to a minus the reference angle, now (rad).
double jointAngle(const JointConstraint& joint, std::span<const collision::SolverBody> bodies);
/// The same from each solver body's turn since the step began (`turns`,
/// atan2 of its dq, by solver body): one atan2 a body, not two a joint.
inline double jointAngle(const JointConstraint& joint, std::span<const double> turns) {
    return joint.deltaAngle + turns[joint.b.solverBody] - turns[joint.a.solverBody];
}
JointAnchors jointAnchors(const JointConstraint& joint, std::span<const collision::SolverBody> bodies);
/// A sleeping joint's anchors (poseResting): its bodies do not move.
JointAnchors restingAnchors(const JointConstraint& joint);

} // namespace stepwise::joints
