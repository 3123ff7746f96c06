#include "app/simulation.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <functional>
#include <unordered_set>
#include <cmath>

namespace stepwise::editor {

namespace {
constexpr std::size_t kMaxSamples = 4096;  // plots show the last ~68 s at 60 steps/s
}

bool touches(const ContactRecord& c) {
    // Bodies resting on each other meet at a depth of zero give or take the
    // round-off of their positions (4e-16 m on a crate at rest): that is
    // touching, not a gap. A nanometre is far above that round-off and far
    // below any gap a speculative contact is made for.
    return c.depth > -1e-9;
}

/// "ball entered goal at t = 1.2000 s" (or "left").
std::string sensorMessage(const Registry& reg, const SensorEvent& e, double time) {
    char when[48];
    std::snprintf(when, sizeof when, " at t = %.4f s", time);
    return displayName(reg, e.body) + (e.begin ? " entered " : " left ") + displayName(reg, e.sensor) + when;
}

std::string breakMessage(const Registry& reg, const ContactRecord& c, double time) {
    char numbers[96];
    const std::string a = displayName(reg, c.a), b = displayName(reg, c.b);
    if (touches(c)) {
        std::snprintf(numbers, sizeof numbers, " at t = %.4f s (depth %.3g m)", time, c.depth > 0.0 ? c.depth : 0.0);
        return "break on contact: " + a + " touches " + b + numbers;
    }
    std::snprintf(numbers, sizeof numbers, " at t = %.4f s (speculative contact, gap %.3g m)", time, -c.depth);
    return "break on contact: " + a + " is about to touch " + b + numbers;
}

bool Simulation::canDisable(std::string_view system) {
    return system == "gravity" || system == "drag" || system == "springs" || system == "attractors" ||
           system == "boids" || system == "collisions";
}

SystemSwitches Simulation::switches() const {
    SystemSwitches out;
    for (const std::string& name : disabledSystems) (void)out.disable(name);
    return out;
}

std::optional<Scene> Simulation::withMouseSpring(const Scene& scene, SystemSwitches& switches,
                                                 Entity* mouseSpringEntity) const {
    if (!mouseSpring || !scene.registry.alive(mouseSpring->first) || !scene.registry.has<Position>(mouseSpring->first))
        return std::nullopt;
    Scene sim = scene;  // deep copy; the same entity handles, so writeBack lands on `scene`
    Registry& reg = sim.registry;
    // The mouse pulls with springs switched off too: then the level's own
    // springs leave the copy instead.
    if (!switches.springs) {
        for (Entity e : reg.entities()) (void)reg.remove<Spring>(e);
        switches.springs = true;
    }
    // A critically damped zero-length spring to the cursor; stiffness
    // scales with the body's mass so light and heavy bodies follow alike
    // (omega = sqrt(k/m) = 12 rad/s, well inside every explicit
    // integrator's limit at dt = 1/60).
    const Entity body = mouseSpring->first;
    const Mass* m = reg.tryGet<Mass>(body);
    const double mass = m ? m->value : 1.0;
    const double k = 144.0 * mass;
    if (!reg.has<Name>(body) || reg.tryGet<Name>(body)->value.empty())
        reg.emplace(body, Name{uniqueName(reg, "dragged")});
    Spring spring;
    spring.a = body;
    spring.anchor = mouseSpring->second;
    spring.k = k;
    spring.damping = 2.0 * std::sqrt(k * mass);
    spring.restLength = 0.0;
    const Entity e = reg.create();
    reg.emplace(e, Name{uniqueName(reg, "mouse_spring")});
    reg.emplace(e, std::move(spring));
    if (mouseSpringEntity) *mouseSpringEntity = e;
    return sim;
}

bool Simulation::rebuild(const Scene& scene) {
    builtMouseSpring_ = {};
    SystemSwitches on = switches();
    const std::optional<Scene> dragged = withMouseSpring(scene, on, &builtMouseSpring_);
    Result<World> built = World::build(dragged ? *dragged : scene, on);
    ++worldBuilds_;
    builtMouseBody_ = builtMouseSpring_.isNull() ? Entity{} : mouseSpring->first;
    sceneAtBuild_.reset();
    if (!built) {
        refuse(built.error());
        return false;
    }
    world_.emplace(std::move(*built));
    refusal_.clear();
    stale_ = false;
    return true;
}

void Simulation::refuse(std::string why) {
    world_.reset();
    refusal_ = std::move(why);
    message_ = "cannot simulate: " + refusal_;
}

bool Simulation::reload(const Scene& scene) {
    if (!world_) return rebuild(scene);
    Entity springEntity;
    SystemSwitches on = switches();
    std::optional<Scene> sim = withMouseSpring(scene, on, &springEntity);
    // The live World's own warm start carries over; a solver state the
    // scene was loaded with has been used once, at Play.
    if (scene.solverState && !sim) sim = scene;
    if (sim) sim->solverState.reset();
    Result<void> reloaded = world_->reload(sim ? *sim : scene, on);
    ++worldBuilds_;
    sceneAtBuild_.reset();
    if (!reloaded) {
        refuse(reloaded.error());
        return false;
    }
    refusal_.clear();
    builtMouseSpring_ = springEntity;
    builtMouseBody_ = springEntity.isNull() ? Entity{} : mouseSpring->first;
    stale_ = false;
    return true;
}

void Simulation::sceneEdited(const Scene& scene, const CommandStack::EditSummary& edit) {
    const auto bit = [](std::string_view component) {
        return std::uint64_t(1) << std::size_t(findComponent(component) - componentTable().data());
    };
    static const std::uint64_t kPose = bit("position") | bit("velocity");
    // What decides which pairs touch and where: an edit of any of these (or
    // one that adds or removes entities) makes the last step's contacts stale.
    static const std::uint64_t kContactShape = bit("position") | bit("angle") | bit("static") | bit("kinematic") |
                                               bit("radius") | bit("box") | bit("polygon") | bit("capsule") |
                                               bit("shapes") | bit("chain") | bit("plane") | bit("filter") |
                                               bit("sensor");
    const bool cameOrWent = !edit.created.empty() || !edit.destroyed.empty();
    bool keepContacts = world_ && running() && !edit.beyondComponents && !cameOrWent;
    for (const auto& [entity, changed] : edit.entities) keepContacts = keepContacts && (changed & kContactShape) == 0;
    if (keepContacts && !contactsKept_) {
        const std::span<const ContactRecord> shown = world_->contacts();
        keptContacts_.assign(shown.begin(), shown.end());
    }
    contactsKept_ = keepContacts;
    static const std::uint64_t kMass = bit("mass");
    static const std::uint64_t kTurn = bit("angle") | bit("angular_velocity");
    static const std::uint64_t kShape = bit("radius") | bit("box") | bit("polygon") | bit("capsule") |
                                        bit("friction") | bit("restitution") | bit("filter");
    bool inPlace = world_ && !stale_ && !edit.beyondComponents;
    // Bodies added or deleted (with a mouse spring the World was built from
    // a copy of the scene: those rebuild).
    if (inPlace && cameOrWent)
        inPlace = builtMouseSpring_.isNull() && world_->changeEntities(scene, switches(), edit.destroyed, edit.created);
    std::unordered_set<Entity> newOrGone;
    if (cameOrWent) {
        newOrGone.insert(edit.created.begin(), edit.created.end());
        newOrGone.insert(edit.destroyed.begin(), edit.destroyed.end());
    }
    for (const auto& [entity, changed] : edit.entities) {
        if (!inPlace) break;
        if (newOrGone.count(entity) != 0) continue;
        const Position* p = scene.registry.tryGet<Position>(entity);
        const Velocity* v = scene.registry.tryGet<Velocity>(entity);
        if ((changed & ~(kPose | kTurn | kShape | kMass)) != 0 || !p) {
            inPlace = false;
            continue;
        }
        // Mass, shape and turn edits: the World checks the engine's choice
        // against the scene it would be rebuilt from, which with a mouse
        // spring is a copy: those rebuild. (An undo after steps brings back
        // an entity's mass or shape with its pose of the time.)
        if ((changed & kMass) != 0) inPlace = builtMouseSpring_.isNull() && world_->setMass(scene, entity);
        if (inPlace && (changed & kShape) != 0)
            inPlace = builtMouseSpring_.isNull() && world_->reshapeBody(scene, switches(), entity);
        if (inPlace && (changed & kPose) != 0) inPlace = world_->moveBody(entity, p->value, v ? v->value : Vec2{}).ok();
        if (inPlace && (changed & kTurn) != 0)
            inPlace = builtMouseSpring_.isNull() && world_->turnBody(scene, entity);
    }
    // A partly applied edit is rebuilt whole, like any other.
    if (!inPlace) stale_ = true;
    // The steps from here on are taken from the edited scene: those that
    // step back restores it from a copy of it, not of the scene the World
    // was built from. A move or a turn needs none (the state holds it); a
    // mass, a shape or a body that came or went does.
    bool beyondState = cameOrWent;
    for (const auto& [entity, changed] : edit.entities) beyondState = beyondState || (changed & ~(kPose | kTurn)) != 0;
    if (inPlace && beyondState) sceneAtBuild_.reset();
}

void Simulation::beforeEdit(std::size_t cursor) {
    if (!world_ || !running()) return;
    if (beforeEdits_ && beforeEdits_->steps == steps_ && beforeEdits_->cursor <= cursor) return;  // kept already
    // A World an earlier edit left stale still holds the state from before it.
    const std::span<const ContactRecord> shown = contacts();
    beforeEdits_ = BeforeEdits{cursor, steps_, world_->saveState(), {shown.begin(), shown.end()}};
}

bool Simulation::undoneTo(const Scene& scene, std::size_t cursor) {
    if (!beforeEdits_ || beforeEdits_->steps != steps_ || beforeEdits_->cursor != cursor) return false;
    if (!ensureWorld(scene) || !world_->restoreState(beforeEdits_->state)) return false;
    keptContacts_ = beforeEdits_->contacts;
    contactsKept_ = true;
    return true;
}

std::span<const ContactRecord> Simulation::contacts() const {
    if (contactsKept_) return keptContacts_;
    if (const World* w = world()) return w->contacts();
    return {};
}

bool Simulation::ensureWorld(const Scene& scene) {
    if (state_ == SimState::Editing) return false;
    if (!stale_ && world_) return true;
    return reload(scene);
}

bool Simulation::readyToStep(const Scene& scene) {
    if (!ensureWorld(scene)) return false;
    if (world_->settleChoice(scene, switches())) return true;
    stale_ = true;  // the edits change what the engine chooses: as any edit the World declines
    return reload(scene);
}

const World* Simulation::editingWorld(const Scene& scene) {
    if (state_ != SimState::Editing) return nullptr;
    if (stale_ || !world_) {
        const std::string kept = message_;
        editingError_.clear();
        if (!reload(scene)) editingError_ = refusal_;
        message_ = kept;  // a refusal while editing is shown in the panel, not as a run's message
    }
    return world_ ? &*world_ : nullptr;
}

std::size_t Simulation::historyBytes() const {
    std::size_t bytes = historyStateBytes_ + history_.size() * sizeof(HistoryEntry);
    const Scene* last = nullptr;
    const std::vector<Gained>* lastGained = nullptr;
    for (const HistoryEntry& h : history_) {
        if (h.scene.get() != last) {
            last = h.scene.get();
            bytes += 256 + 256 * last->registry.size();  // estimate: a scene's components and pools
        }
        if (h.gained && h.gained.get() != lastGained) {
            lastGained = h.gained.get();
            bytes += lastGained->capacity() * sizeof(Gained);
        }
    }
    return bytes;
}

void Simulation::record() {
    if (!world_) return;
    const EnergyReport e = world_->energy();
    SimSample s;
    s.time = world_->time();
    s.kinetic = e.kinetic;
    s.potential = e.potential();
    s.total = e.total();
    s.momentum = length(e.momentum);
    s.contacts = double(world_->contacts().size());
    if (samples_.size() >= kMaxSamples) samples_.erase(samples_.begin(), samples_.begin() + kMaxSamples / 4);
    samples_.push_back(s);
}

bool Simulation::play(Scene& scene) {
    if (state_ == SimState::Playing) return true;
    if (state_ == SimState::Editing) {
        message_.clear();
        diverged_ = false;
        contactPair.reset();
        // A fresh World: the one kept for the panels while editing has the
        // same scene but may carry a step count from an earlier run.
        if (!rebuild(scene)) return false;
        edited_ = scene;
        state_ = SimState::Paused;
        history_.clear();
        historyStateBytes_ = 0;
        samples_.clear();
        sensorLog_.clear();
        steps_ = 0;
        contactStageBefore_ = 0;
        initialEnergy_ = world_->energy().total();
        record();
    } else if (!ensureWorld(scene)) {
        return false;
    }
    state_ = SimState::Playing;
    accumulator_ = 0.0;
    return true;
}

void Simulation::pause() {
    if (state_ == SimState::Playing) state_ = SimState::Paused;
}

namespace {
std::array<std::size_t, 3> stateComponentCounts(const Registry& reg) {
    return {reg.count<Velocity>(), reg.count<Angle>(), reg.count<AngularVelocity>()};
}
} // namespace

Scene Simulation::HistoryEntry::restore() const {
    Scene out = *scene;
    if (gained) {
        Registry& reg = out.registry;
        for (const Gained& g : *gained) {
            if (!reg.alive(g.entity)) continue;
            if (g.components & 1) reg.emplace<Velocity>(g.entity);
            if (g.components & 2) reg.emplace<Angle>(g.entity);
            if (g.components & 4) reg.emplace<AngularVelocity>(g.entity);
        }
    }
    state.writeBack(out);
    return out;
}

void Simulation::pushHistory(const Scene& scene) {
    // The scene copy holds everything but the state. writeBack only ever
    // adds Velocity, Angle and AngularVelocity components (once a body
    // moves or turns), so one copy serves every state since the last edit,
    // with the list of bodies that gained one since (kept while it is short;
    // past an eighth of the entities a new copy is cheaper to keep). A
    // restored scene then has exactly the components the first pass had.
    const Registry& reg = scene.registry;
    const std::array<std::size_t, 3> counts = stateComponentCounts(reg);
    if (sceneAtBuild_ && counts != sceneCounts_) {
        const Registry& base = sceneAtBuild_->registry;
        std::vector<Gained> gained;
        for (const Entity e : reg.entities()) {
            const std::uint8_t mask = std::uint8_t((reg.has<Velocity>(e) && !base.has<Velocity>(e) ? 1 : 0) |
                                                   (reg.has<Angle>(e) && !base.has<Angle>(e) ? 2 : 0) |
                                                   (reg.has<AngularVelocity>(e) && !base.has<AngularVelocity>(e) ? 4 : 0));
            if (mask) gained.push_back({e, mask});
        }
        if (gained.size() * 8 > reg.size()) sceneAtBuild_.reset();
        else gained_ = std::make_shared<const std::vector<Gained>>(std::move(gained));
        sceneCounts_ = counts;
    }
    if (!sceneAtBuild_) {
        sceneAtBuild_ = std::make_shared<const Scene>(scene);
        gained_.reset();
        sceneCounts_ = counts;
    }
    HistoryEntry entry{sceneAtBuild_, gained_, world_->saveState(), commandCursor_};
    historyStateBytes_ += entry.state.bytes();
    history_.push_back(std::move(entry));
    while (!history_.empty() && (history_.size() > historyCapacity_ ||
                                 (history_.size() > 8 && historyStateBytes_ > historyBudgetBytes))) {
        historyStateBytes_ -= history_.front().state.bytes();
        history_.pop_front();
    }
}

void Simulation::popHistory() {
    historyStateBytes_ -= history_.back().state.bytes();
    history_.pop_back();
}

bool Simulation::prepareStep(Scene& scene) {
    if (!readyToStep(scene)) {
        state_ = SimState::Paused;
        return false;
    }
    if (mouseSpring) {
        // The anchor follows the cursor. The World built with this drag's
        // spring only moves the anchor; a new drag (or none built yet)
        // recompiles it with the spring.
        const bool moved = !builtMouseSpring_.isNull() && builtMouseBody_ == mouseSpring->first &&
                           world_->setSpringAnchor(builtMouseSpring_, mouseSpring->second);
        if (!moved && !reload(scene)) return false;
    }
    pushHistory(scene);
    return true;
}

bool Simulation::finishStep(Scene& scene) {
    contactsKept_ = false;  // the step made contacts of its own
    // Named before writeBack, which removes a broken joint's entity.
    if (!world_->jointBreaks().empty() && world_->jointBreaks().back().step == world_->lastStats().step)
        for (const JointBreak& b : world_->jointBreaks()) {
            if (b.step != world_->lastStats().step) continue;
            char text[160];
            std::snprintf(text, sizeof text, " broke at t = %.3f s: %.0f N past its max_force %.0f N", world_->time(),
                          b.force, b.maxForce);
            breakNotes_.push_back("joint \"" + displayName(scene.registry, b.joint) + "\"" + text);
        }
    world_->writeBack(scene);
    ++steps_;
    record();
    for (const SensorEvent& e : world_->sensorEvents()) {
        sensorLog_.push_back(sensorMessage(scene.registry, e, world_->time()));
        if (sensorLog_.size() > kSensorLogLength) sensorLog_.pop_front();
    }
    if (breakOnSensor && !world_->sensorEvents().empty()) {
        const std::span<const SensorEvent> events = world_->sensorEvents();
        state_ = SimState::Paused;
        message_ = "break on sensor: " + sensorMessage(scene.registry, events.front(), world_->time()) +
                   (events.size() > 1 ? " (and " + std::to_string(events.size() - 1) + " more)" : std::string());
        return false;
    }
    if (!breakOnContact.isNull()) {
        // The deepest contact of the watched body: a pair that touches wins
        // over one that is only speculative (a gap the solver keeps from
        // closing within the step, depth < 0).
        const ContactRecord* deepest = nullptr;
        for (const ContactRecord& c : world_->contacts())
            if ((c.a == breakOnContact || c.b == breakOnContact) && (!deepest || c.depth > deepest->depth))
                deepest = &c;
        // 0 no contact, 1 speculative, 2 touching: the run pauses when the
        // stage rises, so a pair seen about to touch pauses again when it does.
        const int stage = !deepest ? 0 : touches(*deepest) ? 2 : 1;
        const bool rose = stage > contactStageBefore_;
        contactStageBefore_ = stage;
        if (rose) {
            contactPair = std::make_pair(deepest->a, deepest->b);
            state_ = SimState::Paused;
            message_ = breakMessage(scene.registry, *deepest, world_->time());
            return false;
        }
    }
    return true;
}

AdvanceResult Simulation::runSteps(Scene& scene, int count, const std::function<bool()>& gate) {
    if (!readyToStep(scene)) {
        state_ = SimState::Paused;
        return {};
    }
    const AdvanceResult r = stepwise::advance(*world_, std::uint64_t(count),
                                    {.beforeStep = [&](std::uint64_t) { return gate() && prepareStep(scene); },
                                     .afterStep = [&](std::uint64_t) { return finishStep(scene); }});
    if (r.divergence) {
        popHistory();  // the world is left as before the step
        state_ = SimState::Paused;
        diverged_ = true;
        message_ = "diverged: " + r.divergence->message;
    }
    return r;
}

bool Simulation::stepOnce(Scene& scene) {
    const AdvanceResult r = runSteps(scene, 1, [] { return true; });
    return r.taken == 1 && !r.stopped;
}

bool Simulation::step(Scene& scene) {
    if (state_ == SimState::Editing && !play(scene)) return false;
    state_ = SimState::Paused;
    return stepOnce(scene);
}

namespace {
/// Same bytes in every array a step reads (the layout aside).
bool sameState(const WorldState& a, const WorldState& b) {
    return a.time == b.time && a.adaptiveStep == b.adaptiveStep && a.steps == b.steps && a.x == b.x && a.v == b.v &&
           a.spinAngle == b.spinAngle && a.colliderAngle == b.colliderAngle && a.colliderSpin == b.colliderSpin &&
           a.contacts == b.contacts && a.joints == b.joints && a.sleepTimer == b.sleepTimer &&
           a.sleepIsland == b.sleepIsland && a.sleepAnchor == b.sleepAnchor && a.sleepAnchored == b.sleepAnchored;
}
} // namespace

bool Simulation::replayStepInto(World& world, const HistoryEntry& target) const {
    // Only from an entry of the same build (no edit, system switch or new
    // drag in between), and kept only when the replay lands on the target's
    // bytes: a mouse spring whose anchor moved since, for one, would not.
    if (history_.empty() || history_.back().scene != target.scene) return false;
    if (!world.restoreState(history_.back().state) || !world.step()) return false;
    return sameState(world.saveState(), target.state);
}

bool Simulation::stepBack(Scene& scene) {
    if (state_ == SimState::Editing || history_.empty()) return false;
    state_ = SimState::Paused;
    HistoryEntry entry = std::move(history_.back());
    popHistory();
    restoredCommandCursor_ = entry.commandCursor;
    contactsKept_ = false;  // the restored step's contacts are replayed below
    beforeEdits_.reset();
    scene = entry.restore();
    // The live World takes the state in place when it was compiled from
    // that entry's scene; after an edit (or a switched system, or a drag)
    // it is recompiled from the restored scene first, with the entry's warm
    // start. Either way the next step is the one the first pass took.
    // A turn taken in place since is checked against the restored scene.
    const bool sameBuild = world_ && !stale_ && entry.scene == sceneAtBuild_ && world_->settleChoice(scene, switches());
    const auto rebuild = [&] {
        Entity springEntity;
        SystemSwitches on = switches();
        std::optional<Scene> dragged = withMouseSpring(scene, on, &springEntity);
        Scene sim = dragged ? std::move(*dragged) : scene;
        sim.solverState = entry.state.solverState();
        Result<void> r = world_ ? world_->reload(sim, on) : Result<void>(Error{"no world"});
        if (!r) {
            Result<World> built = World::build(sim, on);
            if (!built) {
                refuse(built.error());
            } else {
                world_.emplace(std::move(*built));
                refusal_.clear();
            }
        }
        ++worldBuilds_;
        builtMouseSpring_ = springEntity;
        builtMouseBody_ = springEntity.isNull() ? Entity{} : mouseSpring->first;
        stale_ = !world_;
    };
    if (!sameBuild) rebuild();
    // The restored state came out of the step before it: replay that step
    // from the entry before, so the contacts, joint forces and net forces
    // on screen are that step's (a restore alone carries none, and the
    // contacts table would be empty until the next step). A state from
    // before an emitter added or removed copies has other bodies than the
    // live World: that World is rebuilt from the restored scene, only then.
    if (world_ && !replayStepInto(*world_, entry) && !world_->restoreState(entry.state)) {
        rebuild();
        if (world_ && !replayStepInto(*world_, entry)) (void)world_->restoreState(entry.state);
    }
    sceneAtBuild_ = world_ ? entry.scene : nullptr;
    gained_ = entry.gained;
    sceneCounts_ = stateComponentCounts(scene.registry);
    if (!samples_.empty()) samples_.pop_back();
    if (steps_ > 0) --steps_;
    diverged_ = false;
    contactStageBefore_ = 0;
    return true;
}

bool Simulation::reset(Scene& scene) {
    if (state_ == SimState::Editing) return false;
    scene = edited_;
    state_ = SimState::Editing;
    world_.reset();
    history_.clear();
    historyStateBytes_ = 0;
    sceneAtBuild_.reset();
    steps_ = 0;  // the step counter belongs to the run that ended
    stale_ = true;
    message_.clear();
    refusal_.clear();
    diverged_ = false;
    contactPair.reset();
    mouseSpring.reset();
    sensorLog_.clear();
    contactsKept_ = false;
    beforeEdits_.reset();
    return true;
}

void Simulation::advance(Scene& scene, double frameSeconds) {
    frameStepMs_ = 0.0;
    if (state_ != SimState::Playing) return;
    const double dt = scene.world.dt > 0.0 ? scene.world.dt : 1.0 / 60.0;
    accumulator_ += std::max(0.0, frameSeconds) * timeScale;
    const double t0 = clockMs();
    int taken = 0;
    // A small tolerance so a 1/60 s frame at dt = 1/60 is exactly one step
    // despite rounding in the accumulator.
    behind_ = false;
    runSteps(scene, maxStepsPerFrame + 1, [&] {
        if (!(accumulator_ >= dt * (1.0 - 1e-9) && state_ == SimState::Playing)) return false;
        const double spentMs = clockMs() - t0;
        if (taken == maxStepsPerFrame || (taken > 0 && spentMs > physicsBudgetMs)) {
            // Behind: drop the time rather than fall further behind. A slow
            // frame must not buy more steps for the next one (each step
            // would make the frames slower still); the scene runs in slow
            // motion instead and the UI stays responsive.
            accumulator_ = 0.0;
            behind_ = true;
            return false;
        }
        accumulator_ -= dt;
        ++taken;
        return true;
    });
    frameStepMs_ = clockMs() - t0;
}

} // namespace stepwise::editor
