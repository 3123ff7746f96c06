#pragma once
/// \file simulation.hpp
/// Edit / play / pause / step / step back / reset, on top of World.
///
/// * Play from editing keeps a copy of the edited scene; reset() hands it
///   back, so playing never loses the designer's edits.
/// * While running, the document's scene *is* the current state (World::
///   writeBack after every step): the viewport, inspector and overlays show
///   it, and an edit while paused edits that state, deliberately.
/// * One live World. An edit, undo or switched-off system marks it stale and
///   the next use recompiles the scene into it in place (World::reload),
///   which keeps the contacts' warm start and the step count: an edit never
///   resets the solver.
/// * Every step first stores the World's whole evolving state (positions,
///   velocities, angles, warm-start impulses: World::saveState) in a bounded
///   history, with a shared pointer to the scene as of the last edit (its
///   other components). Stepping back restores both, so step back N then
///   step N gives the same bytes as the first pass, contacts included.
/// * System switches: the World is built from a copy of the scene with the
///   components of switched-off systems removed (gravity set to zero), so
///   the engine itself decides what each remaining system costs.

#include "app/command_stack.hpp"

#include "stepwise/scene.hpp"
#include "stepwise/world.hpp"

#include <array>
#include <chrono>
#include <cstddef>
#include <functional>
#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <set>
#include <span>
#include <utility>
#include <string>
#include <vector>

namespace stepwise::editor {

enum class SimState { Editing, Playing, Paused };

/// One sample per step for the plots.
struct SimSample {
    double time = 0.0;
    double kinetic = 0.0, potential = 0.0, total = 0.0;
    double momentum = 0.0;  ///< |p|, kg*m/s
    double contacts = 0.0;
};

/// A contact whose bodies touch (depth >= 0 within round-off), not a
/// speculative one with a gap still open.
bool touches(const ContactRecord& c);
/// What a break on contact says: whether the pair touches (depth >= 0)
/// or is a speculative contact about to touch (its gap), and when.
std::string breakMessage(const Registry& reg, const ContactRecord& c, double time);

class Simulation {
public:
    SimState state() const { return state_; }
    bool running() const { return state_ != SimState::Editing; }

    /// Editing -> Playing (keeps `scene` as the edited scene), Paused -> Playing.
    /// False (and a message) when the World refuses the scene.
    bool play(Scene& scene);
    void pause();
    /// One step. From editing it first enters the paused state.
    bool step(Scene& scene);
    /// Restores the state before the last step. False when there is none.
    bool stepBack(Scene& scene);
    /// The undo position (CommandStack::absoluteCursor) each step records
    /// with its state; the editor sets it before stepping.
    void setCommandCursor(std::uint64_t cursor) { commandCursor_ = cursor; }
    /// The undo position of the state the last stepBack restored: edits
    /// past it are not in the restored scene.
    std::uint64_t restoredCommandCursor() const { return restoredCommandCursor_; }
    /// Back to the edited scene and editing. False when not running.
    bool reset(Scene& scene);
    /// Called once per displayed frame: takes timeScale * frameSeconds / dt
    /// steps (at most maxStepsPerFrame) while playing.
    void advance(Scene& scene, double frameSeconds);

    /// The scene was changed from outside (edit, undo): rebuild before the
    /// next step.
    void sceneChanged() {
        stale_ = true;
        contactsKept_ = false;
    }
    /// After an undoable edit, undo or redo: one that only moved, turned,
    /// re-massed or reshaped bodies (their position, velocity, angle,
    /// angular velocity, mass, shape, friction, restitution or filter), or
    /// added or deleted bodies, goes to the live World in place
    /// (World::moveBody, turnBody, setMass, reshapeBody, changeEntities), so
    /// the rest keeps its warm start and nothing is rebuilt; any other edit,
    /// or one the World declines, makes the World stale.
    void sceneEdited(const Scene& scene, const CommandStack::EditSummary& edit);
    /// Builds the World now if it is stale (for overlays while paused).
    bool ensureWorld(const Scene& scene);
    /// The World ready to step or to save its solver state: built, and the
    /// engine's choice of settings checked once against the edits taken in
    /// place since the last step (World::settleChoice); rebuilt from
    /// `scene` when they change it. Per step, not per frame: a paused
    /// designer's edits cost no pass over the whole scene.
    bool readyToStep(const Scene& scene);

    /// While editing, the same one World compiled from the edited scene
    /// (recompiled in place after each edit) for the panels and force
    /// overlays; null when the engine refuses the scene (editingWorldError()
    /// says why) or while running (use world()).
    const World* editingWorld(const Scene& scene);
    const std::string& editingWorldError() const { return editingError_; }

    /// nullptr when editing or when the World could not be built.
    const World* world() const { return world_ && running() ? &*world_ : nullptr; }
    World* world() { return world_ && running() ? &*world_ : nullptr; }
    const Scene& editedScene() const { return edited_; }

    double timeScale = 1.0;       ///< simulated seconds per real second
    int maxStepsPerFrame = 8;     ///< past this a frame drops time (no spiral of death)
    /// Wall time, ms, a frame may spend on steps beyond its first: half a
    /// 60 Hz frame, so drawing keeps the other half.
    double physicsBudgetMs = 8.0;
    /// The clock advance() holds to physicsBudgetMs: milliseconds on a
    /// monotonic clock (steady_clock). Tests put a fake here so a step count
    /// does not depend on how busy the machine is.
    std::function<double()> clockMs = [] {
        return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
    };
    /// The last frame dropped simulated time (slow motion).
    bool behind() const { return behind_; }
    /// Pause when this body starts touching something (null: off).
    Entity breakOnContact;
    /// Pause at a step where a body enters or leaves a sensor.
    bool breakOnSensor = false;
    /// The run's sensor events, newest last ("t = 1.2000 s: ball entered
    /// goal"), the last kSensorLogLength of them; cleared with the run.
    static constexpr std::size_t kSensorLogLength = 200;
    const std::deque<std::string>& sensorLog() const { return sensorLog_; }
    /// Mouse spring while playing: pulls `dragBody` toward `dragTarget`.
    std::optional<std::pair<Entity, Vec2>> mouseSpring;

    /// Systems switched off by the user ("gravity", "springs", ...).
    std::set<std::string, std::less<>> disabledSystems;
    /// Systems whose switch works: the names the editor knows how to remove.
    static bool canDisable(std::string_view system);
    /// The systems switched off, as the World reads them.
    SystemSwitches switches() const;
    /// While the mouse drags a body during a run, the World is built from a
    /// copy of the scene with a spring from the body to the cursor (its
    /// entity goes to `mouseSpringEntity` when given); otherwise nullopt,
    /// and the World is built from the scene itself.
    std::optional<Scene> withMouseSpring(const Scene& scene, SystemSwitches& switches,
                                         Entity* mouseSpringEntity = nullptr) const;
    /// Times the World was built since the program started (tests: a mouse
    /// drag must not rebuild it every step).
    std::uint64_t worldBuilds() const { return worldBuilds_; }

    /// Last message: divergence, break on contact, refusal. Empty when none.
    const std::string& message() const { return message_; }
    /// One line per joint that broke (max_force) in the steps since the
    /// last call ("joint \"pin 6\" broke at t = 0.267 s: 6683 N past its
    /// max_force 4000 N"); the joint is already gone from the scene.
    std::vector<std::string> takeBreakNotes() { return std::exchange(breakNotes_, {}); }
    bool diverged() const { return diverged_; }
    /// The last build of the World from the scene was refused (message()
    /// says why); false once one succeeds.
    bool cannotSimulate() const { return !refusal_.empty(); }
    /// The contacts the panels and the overlay show: the last step's. An edit
    /// that leaves the contacts as they were (a mass, a colour, a name, a
    /// velocity: not a position, angle, shape, wall or static flag, and no
    /// entity added or removed) keeps them, though the World it recompiles
    /// has none until its next step.
    std::span<const ContactRecord> contacts() const;
    /// Before an edit while the simulation runs (`cursor`: the undo stack's
    /// position before it): keeps the World's state, sleeping islands and
    /// contacts as they are, once per step, so that undoing back to here
    /// restores them (undoneTo) instead of leaving what the edit woke awake.
    void beforeEdit(std::size_t cursor);
    /// After an undo to `cursor`: when no step ran since the state kept at
    /// that cursor, the World (recompiled from `scene`) takes it back. True
    /// when it did.
    bool undoneTo(const Scene& scene, std::size_t cursor);
    /// The pair a break on contact stopped at.
    std::optional<std::pair<Entity, Entity>> contactPair;


    std::size_t historySize() const { return history_.size(); }
    std::size_t historyCapacity() const { return historyCapacity_; }
    /// Memory budget of the step-back history, bytes: the oldest states go
    /// first past it (or past historyCapacity() steps).
    std::size_t historyBudgetBytes = std::size_t(128) << 20;
    /// Heap bytes the history holds now: its states, plus each distinct scene
    /// they point to.
    std::size_t historyBytes() const;

    const std::vector<SimSample>& samples() const { return samples_; }
    /// Energy at the start of the run, joules (the drift reference).
    double initialEnergy() const { return initialEnergy_; }
    /// Steps taken since play started.
    std::uint64_t steps() const { return steps_; }
    /// Wall time of the last frame's steps, ms.
    double lastFrameStepMs() const { return frameStepMs_; }

private:
    std::deque<std::string> sensorLog_;  ///< sensorLog()
    /// One step-back entry: the World's state before a step, and the scene
    /// (as of the last edit) whose other components go with it.
    /// A body that gained a Velocity (1), Angle (2) or AngularVelocity (4)
    /// component since the entry's scene was copied (writeBack adds them
    /// once a body moves or turns, and never removes them).
    struct Gained {
        Entity entity;
        std::uint8_t components = 0;
    };
    struct HistoryEntry {
        std::shared_ptr<const Scene> scene;
        std::shared_ptr<const std::vector<Gained>> gained;  ///< null: none
        WorldState state;
        std::uint64_t commandCursor = 0;  ///< the undo position at this step
        /// The scene this entry stands for: `scene`, the gained components,
        /// then the state written back.
        Scene restore() const;
    };
    /// Restores the entry before `target` into `world` and steps it once:
    /// true when that lands on target's state exactly (then the World also
    /// holds the contacts and joint records of the step that made it).
    bool replayStepInto(World& world, const HistoryEntry& target) const;
    bool rebuild(const Scene& scene);
    /// Recompiles a changed scene into the live World (keeps the warm start).
    bool reload(const Scene& scene);
    bool stepOnce(Scene& scene);
    /// Up to `count` steps through stepwise::advance; `gate` is asked before
    /// each (false: stop). Each step stores its history entry first and
    /// writes the scene back after.
    AdvanceResult runSteps(Scene& scene, int count, const std::function<bool()>& gate);
    bool prepareStep(Scene& scene);  ///< world ready, mouse spring, history entry
    bool finishStep(Scene& scene);   ///< write back, plots, break on contact (false: paused)
    void pushHistory(const Scene& scene);
    void popHistory();
    void record();

    SimState state_ = SimState::Editing;
    Scene edited_;
    std::optional<World> world_;
    bool stale_ = true;
    double accumulator_ = 0.0;
    std::deque<HistoryEntry> history_;
    std::size_t historyStateBytes_ = 0;  ///< sum of history_[i].state.bytes()
    std::size_t historyCapacity_ = 600;
    /// The scene as of the last build or reload, shared by the history
    /// entries taken since (null: not yet taken since the last change).
    std::shared_ptr<const Scene> sceneAtBuild_;
    std::shared_ptr<const std::vector<Gained>> gained_;  ///< since sceneAtBuild_ was copied
    std::array<std::size_t, 3> sceneCounts_{};  ///< Velocity, Angle, AngularVelocity counts when gained_ was taken
    std::string editingError_;
    std::vector<SimSample> samples_;
    double initialEnergy_ = 0.0;
    std::uint64_t steps_ = 0;
    double frameStepMs_ = 0.0;
    std::string message_;
    std::string refusal_;  ///< why the last build or reload was refused; empty after one succeeds
    /// Drops the World that could not be built, keeping why.
    void refuse(std::string why);
    std::vector<std::string> breakNotes_;
    bool diverged_ = false;
    struct BeforeEdits {
        std::size_t cursor = 0;       ///< undo stack position before the first edit since a step
        std::uint64_t steps = 0;      ///< steps_ then
        WorldState state;
        std::vector<ContactRecord> contacts;
    };
    std::optional<BeforeEdits> beforeEdits_;
    std::uint64_t commandCursor_ = 0, restoredCommandCursor_ = 0;
    std::vector<ContactRecord> keptContacts_;  ///< the last step's, while contactsKept_
    bool contactsKept_ = false;
    int contactStageBefore_ = 0;  ///< break on contact: 0 none, 1 speculative, 2 touching, last step
    bool behind_ = false;
    std::uint64_t worldBuilds_ = 0;
    /// The mouse spring the current World was built with: its body and its
    /// spring entity there (null when built without one).
    Entity builtMouseBody_, builtMouseSpring_;
};

} // namespace stepwise::editor
