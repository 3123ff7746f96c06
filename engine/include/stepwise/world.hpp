#pragma once
/// \file world.hpp
/// The simulation. A World is compiled from a Scene: the dynamic bodies'
/// state is packed into one state vector and each force system gets the
/// arrays it needs, so a scene with no springs never visits the spring
/// system and bodies without a shape cost the collision stages nothing.
/// `step()` runs a named pipeline of timed stages (Box2D's b2World_Step
/// shape); `writeBack()` copies the results into the Scene.

#include "stepwise/entity.hpp"
#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/vec2.hpp"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise {

/// Wall time of one pipeline stage in the last step, milliseconds.
struct StageTime {
    std::string_view name;  ///< "forces", "integrate", "broad_phase", ...
    double milliseconds = 0.0;
};

/// What the last step did.
struct StepStats {
    std::uint64_t step = 0;            ///< steps taken since build
    std::vector<StageTime> stages;     ///< in pipeline order
    std::size_t contactCount = 0;
    /// Time of each active force system inside "forces" (addition): their
    /// sum is the "forces" stage. With gravity and drag only, semi-implicit
    /// Euler fuses them into its update and their time is in "integrate".
    std::vector<StageTime> systems;
    int forceEvaluations = 0;          ///< force evaluations in the last step (addition)
};

/// Energy and momentum of the dynamic bodies, joules and kg*m/s.
struct EnergyReport {
    double kinetic = 0.0;
    double gravity = 0.0;     ///< potential of uniform gravity, zero at y = 0
    double springs = 0.0;     ///< 1/2 k (len - rest)^2 summed
    double attractors = 0.0;  ///< -G m_i m_a / sqrt(r^2 + eps^2) summed over pairs
    Vec2 momentum;
    double potential() const { return gravity + springs + attractors; }
    double total() const { return kinetic + potential(); }
};

/// One contact of the last step, for the debugging views.
struct ContactRecord {
    Entity a, b;               ///< b is a plane or static body when one side is
    Vec2 point;                ///< world point, metres
    Vec2 normal;               ///< unit, from a to b
    double depth = 0.0;        ///< penetration, metres (negative: speculative gap)
    double normalImpulse = 0.0;   ///< N*s
    double tangentImpulse = 0.0;  ///< N*s
};

/// A stiffness warning: a spring whose dt*sqrt(k/m) is past the chosen
/// integrator's stability limit.
struct StiffnessHint {
    Entity spring;
    std::string springName;   ///< entity name, or "entity N"
    double hOmega = 0.0;      ///< dt*sqrt(k/m_reduced) per substep
    double limit = 0.0;       ///< the integrator's stable h*omega
    double largestStableDt = 0.0;  ///< seconds per step (whole step, substeps included)
    std::string integrator;   ///< the integrator whose limit it is (addition)
    std::string message() const;
};

/// What the engine runs when a level gives no `substeps` (and no
/// `solver_iterations`): enough substeps for the deepest pile the scene can
/// build to rest with its deepest overlap under 1% of a body's diameter
/// (expectedPileOverlap), at most 16. See docs (collide.md).
struct ContactSettingsChoice {
    int substeps = 1;
    int iterations = 8;        ///< 8 at 1 substep (the old default), else 2
    int stackDepth = 0;        ///< bodies in the deepest column the scene can pile up
    double diameter = 0.0;     ///< metres, the median dynamic shape's size
    double gravity = 0.0;      ///< m/s^2, |world.gravity|
};
ContactSettingsChoice chooseContactSettings(const Scene& scene);
/// Expected deepest resting overlap (metres) in a pile `depth` bodies deep
/// under `gravity` (m/s^2) with substeps of `h` seconds: the soft contact
/// compresses by load / (m_n omega^2), omega = 2 pi min(60 Hz, 1 / (4 h)),
/// with a factor measured on the 30-row pile (docs: collide.md).
double expectedPileOverlap(int depth, double gravity, double h);
/// world.restitution_threshold when the level gives none: four times the
/// speed gravity adds in one substep (m/s), so resting contacts never bounce
/// and, with zero gravity, every approach does.
double derivedRestitutionThreshold(double gravity, double h);

/// A warning before playing: the level's own substeps let its deepest pile
/// sink into itself by more than 2% of a diameter.
struct PileHint {
    int stackDepth = 0;
    double expectedOverlap = 0.0;  ///< metres
    double diameter = 0.0;         ///< metres
    int substeps = 1;              ///< the level's
    int substepsNeeded = 1;        ///< the fewest that keep it under 2% (16 at most)
    std::string message() const;
};

class WorldImpl;

class World {
public:
    /// Compiles `scene` into a world. Fails (with a message naming the entity
    /// and component) when the scene asks for something the engine cannot
    /// simulate.
    static Result<World> build(const Scene& scene);

    World(World&&) noexcept;
    World& operator=(World&&) noexcept;
    ~World();

    /// Advances one step of settings().dt (split into settings().substeps).
    /// On a non-finite value, stops and returns a message naming the step,
    /// the entity and the quantity ("step 42: entity 3 (\"ball\"): velocity.x
    /// became inf"); the world is then left as it was before that step.
    Result<void> step();

    /// Copies positions, velocities, angles and time into `scene`, whose
    /// entities must be the ones the world was built from.
    void writeBack(Scene& scene) const;

    const WorldSettings& settings() const;
    /// Changes the integrator by name (one of integratorNames()).
    Result<void> setIntegrator(std::string_view name);
    /// Moves the fixed end of a spring whose second end is fixed (an
    /// `anchor`, or a static body), metres: the editor's mouse spring follows the
    /// cursor this way without rebuilding the world (which would also drop
    /// the contacts' warm start). Fails when `spring` is not such a spring.
    Result<void> setSpringAnchor(Entity spring, Vec2 anchor);
    double time() const;

    /// Systems this scene needs, in pipeline order: "gravity", "drag",
    /// "springs", "attractors", "boids", "collisions" ...
    std::vector<std::string_view> activeSystems() const;
    const StepStats& lastStats() const;
    EnergyReport energy() const;
    /// Contacts of the last step (empty when the scene has no shapes).
    std::span<const ContactRecord> contacts() const;

    /// Springs past the integrator's stability limit at the current dt.
    std::vector<StiffnessHint> stiffnessHints() const;
    /// Set when the scene's deepest pile would sink more than 2% of a
    /// diameter at the running substeps (see PileHint).
    std::optional<PileHint> pileHint() const;

    /// Net force a unit-mass probe at `point` moving at `velocity` would feel
    /// from the scene's force model (gravity, attractors, drag-free). Uses the
    /// same force code the step uses. Newtons (= m/s^2 for 1 kg).
    Vec2 probeForce(Vec2 point, Vec2 velocity = {}) const;

    /// Dynamic bodies, in the order of the state vector.
    std::size_t bodyCount() const;
    Entity bodyEntity(std::size_t body) const;
    Vec2 bodyPosition(std::size_t body) const;
    Vec2 bodyVelocity(std::size_t body) const;
    /// Net force on each dynamic body at the current state, newtons.
    std::vector<Vec2> bodyForces() const;

    /// Per-stage timing on (default) or off. Off, a step reads no clock at
    /// all; the benchmarks use this to time the integrators alone. (Addition.)
    void setProfiling(bool on);

    WorldImpl& impl() { return *impl_; }
    const WorldImpl& impl() const { return *impl_; }

private:
    explicit World(std::unique_ptr<WorldImpl> impl);
    std::unique_ptr<WorldImpl> impl_;
};

} // namespace stepwise
