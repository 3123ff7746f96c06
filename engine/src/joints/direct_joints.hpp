#pragma once
// Exact solve of the rigid joints whose bodies form a tree (Baraff, "Linear-
// time dynamics using Lagrange multipliers", 1996), inside the soft step.
//
// Gauss-Seidel passes a joint's impulse on to its neighbours one joint per
// pass. Along a chain with a heavy end that takes far more passes than a
// substep has: the light links cannot carry the heavy body's pull in two
// passes and the chain opens. A group of joints whose dynamic bodies form a
// tree (no loop among dynamic bodies; joints to static bodies or the world
// never make a loop) is solved here instead, all its rows at once:
//
//   (J M^-1 J^T + gamma D) dlambda = -(J v + bias + gamma D lambda)
//
// J the rows' Jacobian at the current rotation, D the block diagonal of
// J M^-1 J^T (each joint's own effective mass), lambda the accumulated
// impulses. With gamma = impulseScale / massScale and bias = biasRate * C
// of the soft step this is the point the soft Gauss-Seidel iteration
// converges to (each joint's row: J v + bias + (1/c) K lambda = 0), reached
// in one solve; the relax pass (gamma = 0, no bias) is the rigid solve.
// The matrix of a tree factors without fill when eliminated leaves first:
// a block LDL^T over the joints (3x3 blocks) in that order costs time
// linear in the joints. The order and pattern are found once; each pass
// factors the values (twice a substep: biased and relax) and each
// iteration solves.
// After the relax pass, project() moves each group's positions back onto
// its joints by the part of each error past a slop (see the .cpp).
// Groups, their order and every factorisation depend only on the joints'
// order and the state, so the same input gives the same bits, and a saved
// and reloaded world (its impulses in solver_state) continues exactly.
//
// Rows solved here: a hinge's point (2 rows) and a rigid weld's angle and
// point (3 rows). Limits, motors, sliders, distances, ropes, springs and
// every joint of a group with a loop (a grid, a closed linkage) stay in the
// Gauss-Seidel passes (joint_solver.hpp), which run first in each iteration.

#include "joints/joint_solver.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace stepwise::joints {

class DirectJoints {
public:
    DirectJoints();
    ~DirectJoints();
    DirectJoints(DirectJoints&&) noexcept;
    DirectJoints& operator=(DirectJoints&&) noexcept;

    /// Groups the joints (once per set of joints), marks the joints it
    /// solves (`JointConstraint::direct`) and factors each awake group at the
    /// bodies' current rotation. `soft`: the rigid joints' softness; `biased`:
    /// the biased passes (soft) or the relax pass (rigid).
    void factor(std::span<JointConstraint> joints, std::span<const collision::SolverBody> bodies,
                const collision::Softness& soft, bool biased);
    /// One exact solve of every awake group's rows against the current
    /// velocities, after factor() in the same pass.
    void solve(std::span<JointConstraint> joints, std::span<collision::SolverBody> bodies);
    /// After the relax pass (factor(..., false) at the substep's end pose):
    /// one exact projection of the groups' positions onto their joints,
    /// x += M^-1 J^T dl with (J M^-1 J^T) dl = -C', C' each joint's error
    /// beyond the slop (0.5 mm; 0.002 rad for a weld's angle). Velocities
    /// are left alone (a split impulse), so the correction adds no momentum
    /// and no kinetic energy. Writes each moved solver body's displacement (m) and
    /// turn (rad) into `moves` (sized to the bodies, zeroed here) and lists
    /// the moved bodies in `moved`; the caller moves its state.
    struct Move {
        Vec2 dp;
        double dq = 0.0;
    };
    void project(std::span<const JointConstraint> joints, std::span<const collision::SolverBody> bodies,
                 std::vector<Move>& moves, std::vector<std::uint32_t>& moved);
    /// The response of a group to an impulse on one of its bodies, for the
    /// contacts solved with the group (tree_contacts.hpp): with it, an
    /// impulse on one body moves the whole group at once as its rows allow.
    /// The group (an index) holding solver body `body`, or -1.
    int groupOf(std::uint32_t body) const {
        return body < bodyGroup_.size() ? bodyGroup_[body] : -1;
    }
    /// The group was factored in this pass (it is awake and its rows solve).
    bool factored(int group) const;
    /// Counts the factor() calls: responses are the same between two.
    std::uint64_t factorCount() const { return factorCount_; }
    /// Doubles in one response of `group`: (dvx, dvy, dw) of each of its
    /// bodies, in the order of their places, then the change (x, y, angle)
    /// of each of its joints' impulses.
    std::size_t responseSize(int group) const;
    /// A body's place in its group: its velocity change in a response is
    /// at 3 * place.
    std::uint32_t placeOf(std::uint32_t body) const { return bodyPlace_[body]; }
    /// Writes to `out` the response of `group` to a unit impulse along `dir`
    /// on solver body `body` whose angular part is `arm` (cross(r, dir), r
    /// from the body's centre): the body's own change, plus what the
    /// group's rows then do, solved exactly with this pass's factor.
    void respond(int group, std::uint32_t body, Vec2 dir, double arm, std::span<const collision::SolverBody> bodies,
                 std::span<double> out);
    /// Adds `scale` times a response of `group` to its bodies' velocities
    /// and its joints' impulses.
    void applyResponse(int group, std::span<const double> response, double scale, std::span<JointConstraint> joints,
                       std::span<collision::SolverBody> bodies) const;

    /// Forgets the grouping (the joints changed).
    void reset() { built_ = false; }
    /// Groups the joints now if they changed since the last grouping, which
    /// marks the ones it solves (JointConstraint::direct); factor() does it
    /// too, but the joint bundles need the marks before the warm start.
    void ensureBuilt(std::span<JointConstraint> joints, std::span<const collision::SolverBody> bodies) {
        if (!built_ || builtFor_ != joints.size()) build(joints, bodies);
    }
    /// Joints solved here, for tests and the docs' measurements.
    std::size_t directJointCount() const { return directCount_; }

private:
    struct Group;  // Eigen's types stay in the .cpp (the engine links Eigen privately)
    void build(std::span<JointConstraint> joints, std::span<const collision::SolverBody> bodies);
    /// The group's joints in elimination order and the factor's pattern.
    static void order(Group& g, std::span<const JointConstraint> joints);

    bool built_ = false;
    std::size_t builtFor_ = 0;
    std::size_t directCount_ = 0;
    std::vector<std::unique_ptr<Group>> groups_;
    std::vector<std::int32_t> bodyGroup_;   // per solver body: its group, or -1
    std::vector<std::uint32_t> bodyPlace_;  // per solver body in a group: its place there
    double gamma_ = 0.0, biasRate_ = 0.0;
    std::uint64_t factorCount_ = 0;
    bool biased_ = false;
};

} // namespace stepwise::joints
