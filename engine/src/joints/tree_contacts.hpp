#pragma once
// Contacts of a loose body on a body of an exactly solved joint group (a
// crate on a bridge's plank), solved together with the group.
//
// Solved as an ordinary contact, the plank's side of the contact has a
// plank's mass. The contact stops a heavy crate only by what it gives a
// 2 kg plank, which the group's exact solve then takes back through the
// pins, and the crate's weight reaches the pins a plank's share per pass.
// At rest the crate kept the velocity the passes never took out (1.2 m/s
// for 500 kg on a taut bridge of 2 kg planks), which the joints'
// projection took back as position every substep; the bridge never slept,
// and with part of the support given as position, friction let a crate on
// a sloping plank creep.
//
// Here the group's side of the contact is the whole group: an impulse on
// the plank moves every body of the group as the group's rows allow
// (DirectJoints::respond), and adds to its joints' impulses what they take
// of it. All the contacts of one loose body with one group (a crate across
// two planks has two, of two points each) are solved at once: their normal
// rows as one small complementarity problem with the exact coupling of
// every row to every other, through the loose body and through the group
// (a block Gauss-Seidel step with the group and the loose body as one
// block). One contact at a time, a crate resting on the kink between two
// planks kept a third of its ghost velocity: neither plank alone holds it.
// The points' targets and the friction clamps are the ordinary contact's
// (contact_solver.hpp).

#include "joints/direct_joints.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace stepwise::joints {

class TreeContacts {
public:
    /// Picks this step's contacts between a body of an exactly solved group
    /// and a moving body in no group, neither in a crowd (`inCrowd`, per
    /// solver body, may be empty), and marks them in `heldOut` (sized to the
    /// contacts) for the coloured solve to leave out. False when none.
    bool select(std::span<const collision::ContactConstraint> contacts, const DirectJoints& direct,
                std::span<const collision::SolverBody> bodies, std::span<const std::uint8_t> inCrowd,
                std::vector<std::uint8_t>& heldOut);
    /// Forgets the picked contacts (a step without groups).
    void clear() { list_.clear(); }
    bool empty() const { return list_.empty(); }
    std::span<const std::uint32_t> contacts() const { return list_; }

    /// Applies the picked contacts' accumulated impulses, before the passes
    /// (the group's solve then spreads them over the group).
    void warmStart(std::span<collision::ContactConstraint> contacts, std::span<collision::SolverBody> bodies) const;
    /// One pass over the picked contacts, each with its group's response by
    /// the factor of this pass (after DirectJoints::factor and solve).
    void solve(std::span<collision::ContactConstraint> contacts, std::span<JointConstraint> joints,
               std::span<collision::SolverBody> bodies, DirectJoints& direct, double h,
               const collision::Softness& soft, const collision::Softness& staticSoft, double pushMaxVelocity,
               bool useBias, bool reverse);

private:
    /// One row of a set: a point's normal or friction direction.
    struct Row {
        std::uint32_t contact = 0;  ///< index into the step's contacts
        int point = 0;
        std::uint32_t member = 0;   ///< the group's body in the contact
        Vec2 dir;
        double armA = 0.0, armB = 0.0;  ///< cross(r, dir) on each side
        double memberSign = 1.0;        ///< +1: the member is the contact's body B
    };
    /// The contacts of one loose body with one group: list_[first, last).
    struct Set {
        std::uint32_t first = 0, last = 0;
        int group = -1;
        std::uint32_t loose = 0;
        std::size_t responseAt = 0;  ///< its rows' responses in responses_
    };
    void solveSet(const Set& set, std::span<collision::ContactConstraint> contacts,
                  std::span<JointConstraint> joints, std::span<collision::SolverBody> bodies, DirectJoints& direct,
                  double invH, const collision::Softness& soft, const collision::Softness& staticSoft,
                  double pushMaxVelocity, bool useBias, bool respond);

    std::vector<std::uint32_t> list_;  ///< sorted by set
    std::vector<std::uint32_t> scratch_;  ///< select's candidates
    std::vector<Set> sets_;
    std::vector<Row> rows_;  ///< scratch: one set's rows, normals first
    /// Each set's rows' responses (DirectJoints::respond), back to back, for
    /// the factor numbered responseFactor_; recomputed after a new factor.
    std::vector<double> responses_;
    std::uint64_t responseFactor_ = ~std::uint64_t(0);
    std::vector<collision::PointTarget> targets_;  ///< scratch: the set's normal rows' targets
    std::vector<double> matrix_;  ///< scratch: the set's row couplings and their solves
};

} // namespace stepwise::joints
