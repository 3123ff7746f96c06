#pragma once
// The contact solve in SIMD lanes (the design of Box2D v3, from Erin Catto's
// "Solver2D" and "SIMD Matters" notes; the code is ours): the contacts of a
// step are coloured so that no two contacts of one colour share a dynamic
// body, and each colour is cut into bundles of kContactLanes contacts whose
// data sit side by side (one array per quantity). A bundle is solved as one
// contact in vector registers: its lanes touch different bodies, so solving
// them together gives what solving them one after another gives.
//
// Bit-identical on every instruction set: a bundle holds eight contacts
// whatever the machine (AVX-512 solves them in one register, AVX2 four at a
// time, SSE2 two), each lane does the scalar solver's operations in the
// scalar solver's order (selects replace its branches), and the engine is
// built without fused multiply-add. The same coloured order,
// solved one contact at a time by solveContacts (SolverSettings::simd off),
// gives the same bits; the tests check both.

#include "collision/contact_solver.hpp"

#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

namespace stepwise::collision {

/// Contacts in one bundle: fixed (not the machine's vector width) so the
/// bundles are the same everywhere. Eight fill an AVX-512 register, which
/// takes half the instructions of two fours (the passes' arithmetic, not
/// memory, bounds a pile of boxes: perf).
constexpr int kContactLanes = 8;
/// Colours tried before a contact goes to the overflow, which is solved one
/// contact at a time after the colours (a crowd at one point overflows).
constexpr int kContactColours = 24;

/// One contact point of kContactLanes contacts (see ContactPoint).
struct PointLanes {
    alignas(64) double rnA[kContactLanes], rnB[kContactLanes], dnA[kContactLanes], dnB[kContactLanes];
    alignas(64) double adjustedSeparation[kContactLanes];
    alignas(64) double normalMass[kContactLanes], tangentMass[kContactLanes];
    alignas(64) double normalImpulse[kContactLanes], tangentImpulse[kContactLanes];
};

/// The block solve's K (BlockMass) of kContactLanes two-point contacts; its
/// inverse is formed in the pass (the same operations as prepareContact's,
/// so the same bits), which costs a division a bundle against 96 bytes more
/// to stream through every pass.
struct BlockLanes {
    alignas(64) double k11[kContactLanes], k12[kContactLanes], k22[kContactLanes];
};
struct NoBlockLanes {};

/// ContactBundle::flags bits: ContactConstraint's touchesStatic, block,
/// roundA and roundB.
constexpr std::int64_t kTouchesStatic = 1, kBlock = 2, kRoundA = 4, kRoundB = 8;

/// kContactLanes contacts of `Points` points each, one array per quantity.
/// Unused lanes join static body 0 to itself with zero masses: they compute
/// zeros and write nothing that matters. Only what the passes cannot take
/// from the bodies they gather is here (the inverse masses come with the
/// velocities): the passes stream every bundle a dozen times a step.
template <int Points>
struct ContactBundle : std::conditional_t<Points == 2, BlockLanes, NoBlockLanes> {
    /// Leaves the lanes unset: the bundles are rebuilt every step, every
    /// field of a used lane is set, and only a colour's last bundle (which
    /// may have unused lanes) is zeroed first. A value-initialising resize
    /// wrote each bundle twice (a sixth of the build's time, perf).
    ContactBundle() noexcept {}
    std::uint32_t bodyA[kContactLanes], bodyB[kContactLanes];
    std::uint32_t source[kContactLanes];  ///< index in the step's contacts; ~0u for an unused lane
    alignas(64) double nx[kContactLanes], ny[kContactLanes], friction[kContactLanes];
    alignas(64) double invInertiaA[kContactLanes], invInertiaB[kContactLanes];  ///< 1/(kg m^2)
    alignas(64) std::int64_t flags[kContactLanes];  ///< kTouchesStatic, kBlock, kRoundA, kRoundB
    PointLanes points[Points];
};

/// The step's contacts in colours and bundles. Built once a step, after
/// the narrow phase; the impulses live in the bundles until storeImpulses.
class ColouredContacts {
public:
    /// What build() does to every contact (held out ones too) before any
    /// pass reads it: prepareContact with the step's bodies, then
    /// boundWarmStart when `warmStartBound` is set. A bundled contact is
    /// prepared as it is copied into its lane, in the one pass over the
    /// 232-byte contacts that bundling makes anyway.
    struct Preparation {
        std::span<const ContactDetail> details;
        std::optional<double> warmStartBound;  ///< N*s
    };
    /// Colours the contacts greedily in their (deterministic) order: each
    /// takes the first colour that neither of its dynamic bodies has yet;
    /// static body 0 never blocks a colour. `simd` picks the path for the
    /// whole step (SolverSettings::simd). The contacts marked in `heldOut`
    /// (empty: none) are left out: another solve takes them
    /// (joints/tree_contacts.hpp), and their impulses stay in the contacts.
    void build(std::span<ContactConstraint> contacts, const Preparation& preparation, const ContactPairs& pairs,
               std::span<const SolverBody> bodies, bool simd, std::span<const std::uint8_t> heldOut = {});
    void warmStart(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies);
    /// One pass over the colours (then the overflow), or backwards. A relax
    /// pass (useBias off) given `deepest` (one entry per contact) writes
    /// there each bundled contact's deepest point's separation at the
    /// bodies' present positions (correctPositions' reading, the same bits);
    /// the other entries are left alone.
    void solve(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies, double h, const Softness& soft,
               const Softness& staticSoft, double pushMaxVelocity, bool useBias, bool reverse,
               std::span<double> deepest = {});
    /// Copies the bundles' impulses back to the contacts (warm starting, records).
    void storeImpulses(std::span<ContactConstraint> contacts) const;
    /// The accumulated (normal, tangent) impulses of every contact that has
    /// a body with `marked[body]` set, in the order forEachHeld visits them.
    void saveImpulses(std::span<const ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                      std::vector<double>& out) const;
    /// Puts back what saveImpulses saved with the same `marked`. What the
    /// passes added to a contact from a marked body to one with
    /// `takeBack[body]` set is taken back from that body's velocity too.
    void restoreImpulses(std::span<ContactConstraint> contacts, std::span<const std::uint8_t> marked,
                         std::span<const double> saved, std::span<SolverBody> bodies,
                         std::span<const std::uint8_t> takeBack);

    /// Contact indices colour by colour, then the overflow: the order both
    /// paths solve in.
    std::span<const std::uint32_t> order() const { return order_; }
    int colourCount() const { return colourCount_; }
    std::size_t overflowCount() const { return order_.size() - colourStart_[std::size_t(colourCount_)]; }

private:
    /// Calls visit(bodyA, bodyB, contact, point, normal, tangent), the last
    /// two references to the impulses where the solve keeps them: the
    /// bundles' lanes and then the overflow's contacts (SIMD), or every
    /// contact (scalar); `contact` indexes `contacts`. A bundled
    /// contact's own impulses are left alone by the passes until
    /// storeImpulses, so they are not visited.
    /// (`self` is *this, const or not: restoring writes through it.)
    template <class Self, class Contacts, class Visit>
    static void forEachHeld(Self& self, Contacts& contacts, Visit&& visit);
    /// restoreImpulses' scratch: a point (2 contact + point) and what the
    /// passes added to its impulses.
    struct TakenBack {
        std::uint32_t point;
        double normal, tangent;
    };
    std::vector<TakenBack> takenBack_;
    bool simd_ = true;
    int colourCount_ = 0;
    std::vector<std::uint32_t> order_;
    std::vector<std::uint32_t> colourStart_;  ///< colourCount_ + 1 offsets into order_
    std::vector<std::uint32_t> colourMask_;   ///< per solver body: colours it is in
    std::vector<std::uint8_t> colourOf_;      ///< per contact; kContactColours = overflow
    static constexpr std::uint8_t kHeldOut = kContactColours + 1;  ///< colourOf_ of a contact left out
    std::vector<ContactBundle<1>> one_;
    std::vector<ContactBundle<2>> two_;
    /// Per colour: its one-point bundles one_[oneStart_[c], oneStart_[c+1]) and
    /// two-point bundles two_[twoStart_[c], twoStart_[c+1]).
    std::vector<std::uint32_t> oneStart_, twoStart_;
};

} // namespace stepwise::collision
