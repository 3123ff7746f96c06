#pragma once
// Internals of World (world.hpp). Tests and benchmarks reach them through
// the stepwise_engine_internal include path.

#include "collision/collision_system.hpp"
#include "forces/force_model.hpp"
#include "integrators/integrator.hpp"
#include "world/islands.hpp"
#include "stepwise/world.hpp"

#include <chrono>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace stepwise {

namespace detail {
/// "entity 3", or "entity 3 (\"ball\")" when it has a name: how the World's
/// messages name an entity, by its place in the scene's order.
std::string entityLabel(std::size_t index, const std::string* name);
/// What World::build refuses in the shapes of the scene's entity number
/// `index` (a capsule without a segment, a bad outline, a chain on a
/// dynamic body, an empty compound), naming it; nothing when they are fine.
std::optional<Error> shapeProblem(const Registry& reg, std::size_t index);
} // namespace detail

/// How many Worlds World::build has made in this process: the tests check
/// that emitting and removing copies builds none.
std::uint64_t worldBuildCount();

class WorldImpl;
/// The emitters of `scene` into `w` (after its bodies and collisions): their
/// templates, run state and the run's registry. Nothing without emitters.
std::optional<Error> compileEmitters(const Scene& scene, WorldImpl& w);

/// One emitter as the run has it (docs/format.md, "Templates and emitters").
struct EmitterRun {
    Entity entity;
    std::uint32_t body = 0xFFFFFFFFu;  ///< state index when the emitter is a dynamic body (it has a shape)
    Vec2 position;                     ///< where it is when it is not a dynamic body
    Emitter params;                    ///< the component; its run state (next, emitted, alive, oldest) kept current
    std::vector<Entity> members;       ///< the template's entities in the run's registry, scene order
    std::uint64_t key = 0;             ///< detail::emitterKey
    std::deque<std::vector<Entity>> copies;  ///< the copies alive, oldest first, each its entities in scene order
    std::deque<int> numbers;                 ///< their numbers N (named TEMPLATE#N), oldest first
};

class WorldImpl {
public:
    WorldSettings settings;
    detail::IntegratorKind kind = detail::IntegratorKind::SemiImplicitEuler;
    std::unique_ptr<detail::Integrator> integrator;
    detail::ForceModel model;

    // Double-buffered state: buffers[current] is the state; a step writes
    // the other one and flips `current` only if it stayed finite.
    detail::AlignedDoubles x[2], v[2];
    int current = 0;
    // Start-of-step copy, only needed with substeps > 1 (the intermediate
    // substeps overwrite both buffers).
    std::vector<double> backupX, backupV;
    /// The last step succeeded and the velocities it started from are still
    /// there (the other buffer with one substep, backupV with several): what
    /// netForces() needs. Cleared by a failed step; a restore or reload
    /// starts a World without it.
    bool stepStartKnown = false;
    const double* stepStartV() const { return settings.substeps > 1 ? backupV.data() : v[1 - current].data(); }

    /// Kinematic bodies (state vector indices, ascending) and their
    /// velocities (interleaved, m/s): each substep sets their state to
    /// x + h v, v, whatever the forces did, so nothing but their own
    /// velocity moves them. Empty in a level without one.
    std::vector<std::uint32_t> kinematicBody;
    std::vector<double> kinematicVelocity;
    /// 1 for a kinematic body, by state index; empty when there is none.
    std::vector<std::uint8_t> isKinematic;
    void holdKinematic(const double* xFrom, double* xTo, double* vTo, double h) const {
        for (std::size_t k = 0; k < kinematicBody.size(); ++k) {
            const std::size_t i = 2 * std::size_t(kinematicBody[k]);
            vTo[i] = kinematicVelocity[2 * k];
            vTo[i + 1] = kinematicVelocity[2 * k + 1];
            xTo[i] = xFrom[i] + h * vTo[i];
            xTo[i + 1] = xFrom[i + 1] + h * vTo[i + 1];
        }
    }

    // Bodies with angle and angular_velocity (angle += h * omega).
    std::vector<std::uint32_t> spinBody;  ///< dynamic body index
    std::vector<double> angle, angularVelocity, angleBackup;

    std::vector<Entity> bodyEntity;
    std::vector<std::uint32_t> bodySceneIndex;  ///< place in the scene order (messages, "entity N")
    std::vector<std::string> bodyName;
    std::vector<std::string> springName;         ///< per model spring: name or "entity N"

    std::vector<std::string_view> active;
    StepStats stats;
    /// Broad phase, narrow phase and contact solve; null when the scene has
    /// no shapes (then the step has no collision stages). It owns the
    /// rotation of the bodies that have shapes: only contacts make torque.
    std::unique_ptr<collision::CollisionSystem> collision;
    std::optional<DroppedImpulses> dropped;  ///< by the last setSolverState
    std::vector<JointBreak> breaks;          ///< joints broken so far (World::jointBreaks)
    std::vector<std::pair<std::uint32_t, double>> breakScratch;  ///< CollisionSystem::breakJoints' output
    ContactSettingsChoice contactChoice;  ///< the scene's deepest pile (pileHint) and the engine's choice
    World::SettingsSource settingsSource = World::SettingsSource::Given;  ///< where substeps came from
    bool hertzFractionRecorded = false;  ///< contactChoice.hertzFraction came from solver_state.chosen
    bool substepsGiven = false, iterationsGiven = false;  ///< by the level's world object
    /// An edit taken in place has not yet been checked against the
    /// settings a reload would choose (World::settleChoice); step refuses.
    bool choiceUnsettled = false;
    std::vector<double> collisionAngleBackup, collisionSpinBackup;  ///< undo after a divergence
    bool profiling = true;
    /// Entities of the state arrays (saveState/restoreState); set by build.
    std::shared_ptr<const WorldLayout> layout;

    /// Emitters (empty in a level without one) and the run's own registry:
    /// the scene as built plus the copies the emitters made, minus those
    /// they removed, with the same entity handles (writeBack creates and
    /// destroys the copies in the scene under them). Shared with the
    /// snapshots that hold it; cloned before a change while one does.
    std::vector<EmitterRun> emitters;
    std::vector<EmitterEvent> emitterEvents;  ///< of the last step
    std::shared_ptr<Registry> registry;
    SystemSwitches switches;  ///< what build left out; copies are compiled the same way
    WorldSettings sceneWorld;
    std::uint64_t run = 0;  ///< WorldLayout::run  ///< the world settings of the scene built from (restoreState's rebuild)
    /// Entity index -> state index of every dynamic body, kNoBody for the
    /// other slots (a slot's entity may since be another generation).
    std::vector<std::uint32_t> bodyOfSlot;
    /// The state index of dynamic body `e`; kNoBody when it is none of this World's.
    std::uint32_t bodyIndexOf(Entity e) const {
        const std::uint32_t b = e.index < bodyOfSlot.size() ? bodyOfSlot[e.index] : detail::kNoBody;
        return b != detail::kNoBody && bodyEntity[b] == e ? b : detail::kNoBody;
    }
    /// Emissions and removals due at the start of a step (time + dt/2 past
    /// their time), applied in place: changeBodies.
    void runEmitters();
    /// The number the next copy of template `templateName` takes (as
    /// wide as a sum of counts, so an emitter can stop short of int's end).
    long long nextCopyNumber(const std::string& templateName) const;
    /// Takes the bodies of `removed` (with their shapes, joints and springs)
    /// out of every array in place and puts those of `added` (entities of
    /// `reg`, the scene as it now is, in its order) at their places in the
    /// scene order, so the arrays are
    /// what World::build would make of that scene; every other body's state
    /// and warm start stay. An added entity is a dynamic body with a shape,
    /// or a joint or spring among such bodies (a spring may also hold one to
    /// a body already here): emitters' copies and the editor's additions.
    void changeBodies(const Registry& reg, std::span<const Entity> removed, std::span<const Entity> added);
    /// After an edit of a level with emitters (not of an emitter, a
    /// template or a copy) and changeBodies: each emitter's body and key
    /// renumbered from the edited scene, as compileEmitters makes them.
    void renumberEmitters(const Registry& reg);
    /// The layout of the arrays as they are now.
    std::shared_ptr<const WorldLayout> makeLayout() const;
    /// The names activeSystems() reports, in pipeline order.
    void listActiveSystems();

    /// Sleeping islands (world/islands.hpp) and, per body, its collider
    /// (-1: none).
    detail::SleepIslands sleep;
    std::vector<std::int32_t> colliderOfBody;
    std::vector<double> sleepSpeed;  ///< scratch: each awake body's fastest point, m/s
    std::vector<double> sleepAngle;  ///< scratch: each body's angle, rad
    /// The world settings the sleeping islands were last stepped under. A
    /// step under other settings (gravity turned, dt changed ...) wakes them
    /// all first. Checked at the step, not at the edit, so that an edit
    /// undone before any step (a system switched off and on) wakes nothing;
    /// a restore or a resume sets it to the settings it is stepped under.
    WorldSettings sleptUnder;
    /// Wakes every island when `settings` differ from sleptUnder.
    void wakeForChangedSettings();

    const double* xs() const { return x[current].data(); }
    const double* vs() const { return v[current].data(); }
    double* xs() { return x[current].data(); }
    double* vs() { return v[current].data(); }

    /// "step 42: entity 3 (\"ball\"): velocity.x became inf" (or a value
    /// past kMaxMagnitude, which a level could not hold), or "" if every
    /// position, velocity, angle and spin is within it.
    std::string findOutOfRange(std::uint64_t stepNumber) const;
    /// "step 42: implicit_euler: the linear ...; bodies of the failing
    /// system: entity 0 (\"a\"), entity 1 (\"b\")".
    std::string describeSolveFailure(const detail::SolveFailure& failure, std::uint64_t stepNumber) const;
    void setIntegratorKind(detail::IntegratorKind k);
    /// The sleeping set changed: the collision system takes it again.
    void sleepChanged();
    /// End of a successful step: sleeping bodies go back to their frozen
    /// state (`startX`, `startV`: the step's start), the awake bodies'
    /// timers advance, and still islands fall asleep.
    void updateSleep(const double* startX, const double* startV);
    /// Pairs of dynamic bodies that share an island: springs, joints and
    /// touching contacts.
    void islandEdges(std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges) const;
    /// After reload(): wakes the islands whose bodies, springs or joints
    /// differ from `before` (the World this one replaces), all of them when
    /// the world settings differ, and those that touched a removed body.
    void wakeEdited(const WorldImpl& before);
    /// For an edit taken in place (world_edits.cpp): whether a reload from
    /// `scene` would run these settings; if so, its choice becomes this one.
    std::optional<Error> keepChoiceFor(const Scene& scene, const SystemSwitches& switches);
};

namespace detail {
/// World::build's refusal of a body that the springs or attractors pull
/// past what one step holds, at the state `w` holds now; the in-place adds
/// run it as a rebuild would.
std::optional<Error> checkFirstStepForces(const WorldImpl& w, IntegratorKind kind);
} // namespace detail

} // namespace stepwise
