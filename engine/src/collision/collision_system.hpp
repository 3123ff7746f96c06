#pragma once
// The collision stages of a step: broad phase, narrow phase (with
// speculative margins for continuous collision), impact propagation, and the
// soft contact solve in each substep. The World owns the translational state
// of dynamic bodies (one state vector for the integrators); this system owns
// the rotational state of the bodies that have shapes, since only contacts
// create torque.

#include "collision/broad_phase.hpp"
#include "collision/contact_solver.hpp"
#include "collision/narrow_phase.hpp"

#include "stepwise/entity.hpp"
#include "stepwise/world.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace stepwise::collision {

/// One shape in the world.
struct Collider {
    Shape shape;
    std::int32_t body = -1;      ///< index in the World's state vector; -1 = static or plane
    Vec2 staticPosition;         ///< centre of a static shape, metres
    double mass = 0.0;           ///< kg; 0 for static
    double restitution = 0.0;
    double friction = 0.2;
    Entity entity;
};

/// Solid-shape moment of inertia about the centre, kg m^2.
double momentOfInertia(const Shape& shape, double mass);

struct CollisionTimings {
    double broadPhaseMs = 0.0, narrowPhaseMs = 0.0, solveMs = 0.0;
};

class CollisionSystem {
public:
    /// Adds a collider with its initial orientation (rad) and spin (rad/s).
    void add(const Collider& collider, double angle, double angularVelocity);
    bool empty() const { return colliders_.empty(); }
    std::size_t colliderCount() const { return colliders_.size(); }
    const Collider& collider(std::size_t i) const { return colliders_[i]; }
    double angle(std::size_t i) const { return angles_[i]; }
    double angularVelocity(std::size_t i) const { return angularVelocities_[i]; }

    SolverSettings& settings() { return settings_; }
    const SolverSettings& settings() const { return settings_; }
    /// Fixes the broad-phase strategy (tests, benchmarks); by default it is
    /// chosen per step from the number of shapes.
    void setBroadPhase(BroadPhaseKind kind) {
        autoBroadPhase_ = false;
        broadPhase_.setKind(kind);
    }
    const BroadPhase& broadPhase() const { return broadPhase_; }

    /// Records the step-start state. Detection for the whole step runs in
    /// the first solveSubstep, once the forces of the step are known: margins
    /// cover the motion of `dt`, so contacts exist before fast bodies reach a
    /// surface.
    void beginStep(std::span<const Vec2> x, std::span<const Vec2> v, double dt, int substeps);
    /// Contact solve for one substep of length h. On entry `x`, `v` hold the
    /// integrator's unconstrained end-of-substep state; on exit, the
    /// constrained one (positions move by h times the contact velocity change).
    /// The first call of a step also runs the broad and narrow phases.
    void solveSubstep(std::span<Vec2> x, std::span<Vec2> v, double h);
    /// Stores impulses for warm starting and builds the contact records.
    void endStep();

    std::span<const ContactRecord> contacts() const { return records_; }
    std::size_t contactPointCount() const { return records_.size(); }
    /// Broad-phase pairs and narrow-phase manifolds of the last detection.
    std::size_t candidatePairCount() const { return pairs_.size(); }
    std::size_t manifoldCount() const { return constraints_.size(); }
    const CollisionTimings& timings() const { return timings_; }

    /// Undoes a step's rotational change (after a divergence).
    void restoreRotation(std::span<const double> angles, std::span<const double> angularVelocities) {
        angles_.assign(angles.begin(), angles.end());
        angularVelocities_.assign(angularVelocities.begin(), angularVelocities.end());
    }
    std::span<const double> angles() const { return angles_; }
    std::span<const double> angularVelocities() const { return angularVelocities_; }

private:
    struct CachedImpulse {
        std::uint64_t key;  // (colliderA << 40) | (colliderB << 16) | point id
        double normal, tangent;
        friend bool operator<(const CachedImpulse& l, const CachedImpulse& r) { return l.key < r.key; }
    };

    void addManifold(std::uint32_t a, std::uint32_t b, const Manifold& m, std::span<const Vec2> centres);
    /// Broad and narrow phase at the step-start positions; `firstSubstepV`
    /// is the unconstrained velocity after the first substep's forces.
    void detect(std::span<const Vec2> firstSubstepV);
    static Vec2 coincidentNormal(std::uint32_t a, std::uint32_t b);

    std::vector<Collider> colliders_;
    std::vector<double> angles_, angularVelocities_;
    std::vector<double> invMass_, invInertia_, maxExtent_;
    std::vector<std::uint32_t> finite_;  // colliders that are not planes (broad-phase proxies)
    std::vector<std::uint32_t> planes_;
    std::vector<std::uint32_t> solverIndex_;  // collider -> SolverBody (0 = static)

    SolverSettings settings_;
    BroadPhase broadPhase_;
    bool autoBroadPhase_ = true;
    std::vector<Aabb> boxes_;
    std::vector<std::uint8_t> movable_;
    std::vector<ProxyPair> pairs_;
    std::vector<Vec2> centres_, stepStart_;
    std::vector<double> stepStartAngle_, margins_, spin_;
    std::vector<Vec2> startV_, endV_;  // per collider: velocity at step start, predicted at step end (m/s)
    bool detected_ = false;
    struct SavedVelocity {
        Vec2 v;
        double w = 0.0;
    };
    std::vector<std::uint32_t> crowdBodies_;  // solver bodies in a crowded grid cell this step
    std::vector<SavedVelocity> crowdSaved_;
    std::vector<SolverBody> bodies_;
    std::vector<ContactConstraint> constraints_;
    std::vector<ContactDetail> details_;  // parallel to constraints_
    std::vector<CachedImpulse> cache_;
    std::size_t cacheCursor_ = 0;  // where the previous manifold's cache search ended
    std::vector<Vec2> unconstrainedV_;
    std::vector<ContactRecord> records_;
    std::vector<Rot> rotScratch_;
    CollisionTimings timings_;
    double dt_ = 0.0;
    int substeps_ = 1;
};

} // namespace stepwise::collision
