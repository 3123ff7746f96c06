#include "app/simulation.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace stepwise::editor {

namespace {
constexpr std::size_t kMaxSamples = 4096;  // plots show the last ~68 s at 60 steps/s
}

bool Simulation::canDisable(std::string_view system) {
    return system == "gravity" || system == "drag" || system == "springs" || system == "attractors" ||
           system == "boids" || system == "collisions";
}

Scene Simulation::simulationScene(const Scene& scene, Entity* mouseSpringEntity) const {
    Scene sim = scene;  // deep copy; the same entity handles, so writeBack lands on `scene`
    Registry& reg = sim.registry;
    auto off = [&](std::string_view s) { return disabledSystems.count(s) != 0; };
    if (off("gravity")) sim.world.gravity = {0.0, 0.0};
    for (Entity e : std::vector<Entity>(reg.entities())) {
        if (off("drag")) reg.remove<Drag>(e);
        if (off("springs") && reg.has<Spring>(e)) reg.remove<Spring>(e);
        if (off("attractors")) reg.remove<Attractor>(e);
        if (off("boids")) reg.remove<Boid>(e);
        if (off("collisions")) {
            reg.remove<Radius>(e);
            reg.remove<Box>(e);
            reg.remove<Plane>(e);
            reg.remove<Restitution>(e);
            reg.remove<Friction>(e);
        }
    }
    if (mouseSpring && reg.alive(mouseSpring->first) && reg.has<Position>(mouseSpring->first)) {
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
        Spring s;
        s.a = body;
        s.anchor = mouseSpring->second;
        s.k = k;
        s.damping = 2.0 * std::sqrt(k * mass);
        s.restLength = 0.0;
        const Entity e = reg.create();
        reg.emplace(e, Name{uniqueName(reg, "mouse_spring")});
        reg.emplace(e, std::move(s));
        if (mouseSpringEntity) *mouseSpringEntity = e;
    }
    return sim;
}

bool Simulation::rebuild(const Scene& scene) {
    builtMouseSpring_ = {};
    Result<World> built = World::build(simulationScene(scene, &builtMouseSpring_));
    ++worldBuilds_;
    builtMouseBody_ = builtMouseSpring_.isNull() ? Entity{} : mouseSpring->first;
    if (!built) {
        world_.reset();
        message_ = "cannot simulate: " + built.error();
        return false;
    }
    world_.emplace(std::move(*built));
    stale_ = false;
    return true;
}

bool Simulation::ensureWorld(const Scene& scene) {
    if (state_ == SimState::Editing) return false;
    if (!stale_ && world_) return true;
    return rebuild(scene);
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
        if (!rebuild(scene)) return false;
        edited_ = scene;
        state_ = SimState::Paused;
        history_.clear();
        samples_.clear();
        steps_ = 0;
        touchingBefore_ = false;
        initialEnergy_ = world_->energy().total();
        // Snapshots cost about this much each; stay inside the budget.
        const std::size_t perSnapshot = 256 + 256 * scene.registry.size();
        historyCapacity_ = std::clamp<std::size_t>(historyBudgetBytes / perSnapshot, 8, 600);
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

bool Simulation::stepOnce(Scene& scene) {
    if (!ensureWorld(scene)) {
        state_ = SimState::Paused;
        return false;
    }
    if (mouseSpring) {
        // The anchor follows the cursor. The World built with this drag's
        // spring only moves the anchor; a new drag (or none built yet)
        // rebuilds it with the spring.
        const bool moved = !builtMouseSpring_.isNull() && builtMouseBody_ == mouseSpring->first &&
                           world_->setSpringAnchor(builtMouseSpring_, mouseSpring->second);
        if (!moved && !rebuild(scene)) return false;
    }
    history_.push_back(scene);
    while (history_.size() > historyCapacity_) history_.pop_front();
    Result<void> r = world_->step();
    if (!r) {
        history_.pop_back();  // the world is left as before the step
        state_ = SimState::Paused;
        diverged_ = true;
        message_ = "diverged: " + r.error();
        return false;
    }
    world_->writeBack(scene);
    ++steps_;
    record();
    if (!breakOnContact.isNull()) {
        std::optional<std::pair<Entity, Entity>> pair;
        for (const ContactRecord& c : world_->contacts())
            if (c.a == breakOnContact || c.b == breakOnContact) {
                pair = std::make_pair(c.a, c.b);
                break;
            }
        if (pair && !touchingBefore_) {
            contactPair = pair;
            state_ = SimState::Paused;
            message_ = "break on contact: " + displayName(scene.registry, pair->first) + " touches " +
                       displayName(scene.registry, pair->second) + " at t = " + std::to_string(world_->time()) + " s";
            touchingBefore_ = true;
            return false;
        }
        touchingBefore_ = pair.has_value();
    }
    return true;
}

bool Simulation::step(Scene& scene) {
    if (state_ == SimState::Editing && !play(scene)) return false;
    state_ = SimState::Paused;
    return stepOnce(scene);
}

bool Simulation::stepBack(Scene& scene) {
    if (state_ == SimState::Editing || history_.empty()) return false;
    state_ = SimState::Paused;
    scene = std::move(history_.back());
    history_.pop_back();
    if (!samples_.empty()) samples_.pop_back();
    if (steps_ > 0) --steps_;
    stale_ = true;
    diverged_ = false;
    touchingBefore_ = false;
    return true;
}

bool Simulation::reset(Scene& scene) {
    if (state_ == SimState::Editing) return false;
    scene = edited_;
    state_ = SimState::Editing;
    world_.reset();
    history_.clear();
    steps_ = 0;  // the step counter belongs to the run that ended
    stale_ = true;
    message_.clear();
    diverged_ = false;
    contactPair.reset();
    mouseSpring.reset();
    return true;
}

void Simulation::advance(Scene& scene, double frameSeconds) {
    frameStepMs_ = 0.0;
    if (state_ != SimState::Playing) return;
    const double dt = scene.world.dt > 0.0 ? scene.world.dt : 1.0 / 60.0;
    accumulator_ += std::max(0.0, frameSeconds) * timeScale;
    const auto t0 = std::chrono::steady_clock::now();
    int taken = 0;
    // A small tolerance so a 1/60 s frame at dt = 1/60 is exactly one step
    // despite rounding in the accumulator.
    behind_ = false;
    while (accumulator_ >= dt * (1.0 - 1e-9) && state_ == SimState::Playing) {
        const double spentMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (taken == maxStepsPerFrame || (taken > 0 && spentMs > physicsBudgetMs)) {
            // Behind: drop the time rather than fall further behind. A slow
            // frame must not buy more steps for the next one (each step
            // would make the frames slower still); the scene runs in slow
            // motion instead and the UI stays responsive.
            accumulator_ = 0.0;
            behind_ = true;
            break;
        }
        accumulator_ -= dt;
        ++taken;
        if (!stepOnce(scene)) break;
    }
    frameStepMs_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

} // namespace stepwise::editor
