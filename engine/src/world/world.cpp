// World: runs the step pipeline over the packed arrays World::build
// compiles from a Scene (world_build.cpp).
//
// Pipeline of one step (each stage timed into StepStats):
//   for each substep of h = dt / substeps:
//     forces + integrate     the integrator calls the force systems
//                            (gravity, drag, springs, attractors, boids) as
//                            often as its method needs
//     [impact propagation, contact solve]   only when the scene has shapes:
//                            after the integrator has produced the
//                            end-of-substep velocities and before positions
//                            are final (the broad and narrow phases run once
//                            per step, in the first substep, after its
//                            forces, so their margins cover the step's
//                            motion). A contact solver changes
//                            velocities by dv; positions then take x += h dv,
//                            the semi-implicit Euler position update applied
//                            to the impulse, which is exact for semi-implicit
//                            Euler and first order for the others (as in
//                            every impulse-based engine).
//     rotation               angle += h * angular_velocity
//   check                    every state value finite, else undo the step
//                            (x and v: done inside the integrator's pass
//                            when its kernel is fused and no contact solve
//                            ran after it)
//
// Determinism: a step reads the bodies' state, the time and, with contacts
// and joints, the warm-start cache and the joints' accumulated impulses (the
// impulses the previous step ended with). Nothing
// else is carried: no cached accelerations (Verlet recomputes a(x0, v0)),
// the boid grid is rebuilt per evaluation, the broad phase returns sorted
// pairs whatever its kept sweep order, and no summation depends on addresses
// or threads. The state goes to a file through writeBack (shortest
// round-trip numbers) and the cache through solverState() (the file's
// `solver_state`), so 200 steps equal 100 steps, save, load, 100 steps, bit
// for bit; saveState/restoreState do the same in memory.

#include "world/world_impl.hpp"
#include "world/world_collisions.hpp"

#include "templates.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/world_fields.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <unordered_map>

namespace stepwise {

std::string detail::entityLabel(std::size_t index, const std::string* name) {
    std::string s = "entity " + std::to_string(index);
    if (name && !name->empty()) s += " (\"" + *name + "\")";
    return s;
}

using detail::entityLabel;
using detail::kNoBody;

namespace {

using Clock = std::chrono::steady_clock;

std::string describeValue(double v) {
    if (std::isnan(v)) return "nan";
    return v > 0 ? "inf" : "-inf";
}

// True when every value times `scale` (kQuickRangeScale or
// kQuickSpeedScale) stays finite: x * scale * 0 is 0 then and NaN otherwise,
// and NaN survives addition, so one sum answers for the whole array. Four
// partial sums break the dependency chain (0.14 ns per value against 0.43 for
// an exponent-bit test, which GCC 12 does not vectorise). Relies on IEEE
// semantics: no -ffast-math (CMakeLists).
bool allInQuickRange(const double* p, std::size_t m, double scale) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    std::size_t i = 0;
    for (; i + 4 <= m; i += 4) {
        a0 += p[i] * scale * 0.0;
        a1 += p[i + 1] * scale * 0.0;
        a2 += p[i + 2] * scale * 0.0;
        a3 += p[i + 3] * scale * 0.0;
    }
    for (; i < m; ++i) a0 += p[i] * scale * 0.0;
    const double sum = (a0 + a1) + (a2 + a3);
    return sum == sum;
}

std::string format(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", v);
    return buffer;
}

} // namespace

std::string WorldImpl::findOutOfRange(std::uint64_t stepNumber) const {
    // One entry per quantity: its name, its value and the bound a level
    // file holds it to.
    struct Quantity {
        const char* what;
        double value, limit;
    };
    const auto problem = [&](std::size_t body, std::initializer_list<Quantity> quantities) -> std::string {
        for (const Quantity& q : quantities) {
            if (std::abs(q.value) <= q.limit) continue;
            std::string text = "step " + std::to_string(stepNumber) + ": " +
                               entityLabel(bodySceneIndex[body], &bodyName[body]) + ": " + q.what + " became ";
            if (!std::isfinite(q.value)) return text + describeValue(q.value);
            return text + formatNumber(q.value) + ", beyond the +-" + formatNumber(q.limit) + " a level can hold";
        }
        return {};
    };
    const double* px = xs();
    const double* pv = vs();
    for (std::size_t b = 0; b < bodyEntity.size(); ++b) {
        // Velocity before position: in a blow-up the velocity overflows
        // first and the position follows from it.
        std::string found = problem(b, {{"velocity.x", pv[2 * b], kMaxSpeed},
                                        {"velocity.y", pv[2 * b + 1], kMaxSpeed},
                                        {"position.x", px[2 * b], kMaxMagnitude},
                                        {"position.y", px[2 * b + 1], kMaxMagnitude}});
        if (!found.empty()) return found;
    }
    for (std::size_t s = 0; s < spinBody.size(); ++s) {
        std::string found = problem(spinBody[s], {{"angular_velocity", angularVelocity[s], kMaxSpeed},
                                                  {"angle", angle[s], kMaxMagnitude}});
        if (!found.empty()) return found;
    }
    if (collision)
        for (std::size_t c = 0; c < collision->colliderCount(); ++c) {
            const std::int32_t b = collision->collider(c).body;
            if (b < 0) continue;
            std::string found = problem(std::size_t(b), {{"angular_velocity", collision->angularVelocity(c), kMaxSpeed},
                                                         {"angle", collision->angle(c), kMaxMagnitude}});
            if (!found.empty()) return found;
        }
    return {};
}

std::string WorldImpl::describeSolveFailure(const detail::SolveFailure& failure, std::uint64_t stepNumber) const {
    std::string who;
    const std::size_t shown = std::min<std::size_t>(failure.bodies.size(), 6);
    for (std::size_t i = 0; i < shown; ++i) {
        const std::size_t b = failure.bodies[i];
        who += (i ? ", " : "") + entityLabel(bodySceneIndex[b], &bodyName[b]);
    }
    if (failure.bodies.size() > shown) who += " and " + std::to_string(failure.bodies.size() - shown) + " more";
    return "step " + std::to_string(stepNumber) + ": " + settings.integrator + ": " + failure.what +
           (who.empty() ? std::string() : "; bodies of the failing system: " + who) +
           ". Lower the stiffness or dt (stepwise validate estimates the conditioning)";
}

void WorldImpl::setIntegratorKind(detail::IntegratorKind k) {
    kind = k;
    integrator = detail::makeIntegrator(k, model);
    integrator->setTolerance(settings.tolerance);
    integrator->setProposedStep(settings.adaptiveStep);
    settings.integrator = std::string(detail::integratorName(k));
}

// ---------------------------------------------------------------------------

std::string StiffnessHint::message() const {
    char dtText[32];
    std::snprintf(dtText, sizeof dtText, "%.3g", largestStableDt);
    std::string text = "spring \"" + springName + "\": dt*sqrt(k/m) = " + format(hOmega) + " per substep ";
    if (integrator.rfind("implicit_", 0) == 0)
        return text + "makes " + integrator + "'s linear system ill-conditioned (condition number about " +
               format(hOmega * hOmega) + ", past " + format(limit * limit) +
               "): the solve in doubles loses up to that many of its 1e16 parts, and a step whose residual passes " +
               "1e-6 is refused; largest dt for this spring is " +
               dtText + " s (or add substeps, or lower k)";
    if (limit <= 0.0)
        return text + "and " + integrator +
               " is unstable on this spring at any dt (it spirals out); use semi_implicit_euler, velocity_verlet, "
               "rk4 or an implicit integrator";
    return text + "is past " + integrator + "'s stability limit " + format(limit) + "; largest stable dt is " +
           dtText + " s (or add substeps, or use implicit_euler / implicit_midpoint)";
}

World::World(std::unique_ptr<WorldImpl> impl) : impl_(std::move(impl)) {}
World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

Result<void> World::step() {
    WorldImpl& w = *impl_;
    // An edit in place leaves the settings as they were: a step under them
    // could differ from the reload's the edit stands for.
    if (w.choiceUnsettled)
        return Error{"an edit in place is not yet checked against the engine's choice of settings: call settleChoice"};
    w.runEmitters();  // copies due now appear (or leave) before the step reads the arrays
    detail::ForceModel& f = w.model;
    const bool timed = w.profiling;
    f.profiling = timed;
    f.resetTimers();
    const Clock::time_point t0 = timed ? Clock::now() : Clock::time_point{};
    const std::size_t m = 2 * f.n;
    w.wakeForChangedSettings();  // a settings edit since the last step wakes every island
    const int substeps = w.settings.substeps;
    const double h = w.settings.dt / double(substeps);
    w.stepStartKnown = false;  // set again once this step succeeds
    if (substeps > 1) {
        std::copy(w.x[w.current].begin(), w.x[w.current].end(), w.backupX.begin());
        std::copy(w.v[w.current].begin(), w.v[w.current].end(), w.backupV.begin());
    }
    std::copy(w.angle.begin(), w.angle.end(), w.angleBackup.begin());
    int evaluations = 0, internalSteps = 0, rejectedSteps = 0;
    const std::string* failure = nullptr;  // the integrator could not meet its tolerance
    bool verifiedInRange = false;  // the last substep's integrator pass checked x, v
    double rotationSeconds = 0.0, contactSeconds = 0.0;
    collision::CollisionSystem* contacts = w.collision.get();
    if (contacts) {
        // --- broad phase, narrow phase: once per step, with speculative
        // margins that cover the whole step's motion.
        w.collisionAngleBackup.assign(contacts->angles().begin(), contacts->angles().end());
        w.collisionSpinBackup.assign(contacts->angularVelocities().begin(), contacts->angularVelocities().end());
        contacts->beginStep(detail::asVec2(w.xs(), f.n), detail::asVec2(w.vs(), f.n), w.settings.dt, substeps);
    }
    for (int s = 0; s < substeps; ++s) {
        const int next = 1 - w.current;
        // --- forces + integrate
        w.integrator->step(f, w.x[w.current].data(), w.v[w.current].data(), w.x[next].data(), w.v[next].data(), h);
        evaluations += w.integrator->lastEvaluations();
        internalSteps += w.integrator->lastAcceptedSteps();
        rejectedSteps += w.integrator->lastRejectedSteps();
        verifiedInRange = w.integrator->lastStepVerifiedInRange();
        if (const detail::SolveFailure* failed = w.integrator->lastFailure()) {
            // Refused like a non-finite value: the state stays at the start
            // of the step (no buffer was flipped; with substeps, the backup).
            if (substeps > 1) {
                std::copy(w.backupX.begin(), w.backupX.end(), w.x[w.current].begin());
                std::copy(w.backupV.begin(), w.backupV.end(), w.v[w.current].begin());
            }
            std::copy(w.angleBackup.begin(), w.angleBackup.end(), w.angle.begin());
            if (contacts) {
                contacts->endStep();
                contacts->restoreRotation(w.collisionAngleBackup, w.collisionSpinBackup);
                contacts->undoSolverState();
            }
            return Error{w.describeSolveFailure(*failed, w.stats.step + 1), "", ErrorKind::Diverged};
        }
        if (!w.integrator->lastToleranceFailure().empty()) {
            failure = &w.integrator->lastToleranceFailure();
            w.current = next;  // the undo below expects the output buffer current
            break;
        }
        if (!w.kinematicBody.empty()) {
            w.holdKinematic(w.x[w.current].data(), w.x[next].data(), w.v[next].data(), h);
            verifiedInRange = false;  // the integrator's check saw other values
        }
        // --- contact solve on the integrator's end-of-substep state
        if (contacts) {
            contacts->solveSubstep(detail::asVec2(w.x[next].data(), f.n), detail::asVec2(w.v[next].data(), f.n), h);
            contactSeconds += contacts->timings().solveMs * 1e-3;
        }
        w.current = next;
        // --- rotation
        if (!w.spinBody.empty()) {
            const Clock::time_point r0 = timed ? Clock::now() : Clock::time_point{};
            for (std::size_t k = 0; k < w.angle.size(); ++k) w.angle[k] += h * w.angularVelocity[k];
            if (timed) rotationSeconds += std::chrono::duration<double>(Clock::now() - r0).count();
        }
    }
    if (contacts) contacts->endStep();
    const Clock::time_point t1 = timed ? Clock::now() : Clock::time_point{};
    // --- check. The integrator may have checked x and v in its writing
    // pass (fused kernels): then only if nothing changed them since (no
    // contact solve) is a second pass over the state skipped.
    const bool stateChecked = verifiedInRange && !contacts;
    constexpr double lengths = detail::kQuickRangeScale, speeds = detail::kQuickSpeedScale;
    const bool inQuickRange =
        (stateChecked || (allInQuickRange(w.xs(), m, lengths) && allInQuickRange(w.vs(), m, speeds))) &&
        allInQuickRange(w.angle.data(), w.angle.size(), lengths) &&
        allInQuickRange(w.angularVelocity.data(), w.angularVelocity.size(), speeds) &&
        (!contacts ||
         (allInQuickRange(contacts->angles().data(), contacts->angles().size(), lengths) &&
          allInQuickRange(contacts->angularVelocities().data(), contacts->angularVelocities().size(), speeds)));
    const Clock::time_point t2 = timed ? Clock::now() : Clock::time_point{};
    // The quick test flags from 2^99 on; only what is non-finite or past
    // kMaxMagnitude stops the run, so a state that saves also loads.
    const std::string outOfRange =
        failure ? "step " + std::to_string(w.stats.step + 1) + ": " + *failure
                : inQuickRange ? std::string() : w.findOutOfRange(w.stats.step + 1);
    if (!outOfRange.empty()) {
        std::string message = outOfRange;
        // Undo: the step's input is still in the other buffer (one
        // substep) or in the backup (several).
        if (substeps == 1) {
            w.current = 1 - w.current;
        } else {
            std::copy(w.backupX.begin(), w.backupX.end(), w.x[w.current].begin());
            std::copy(w.backupV.begin(), w.backupV.end(), w.v[w.current].begin());
        }
        std::copy(w.angleBackup.begin(), w.angleBackup.end(), w.angle.begin());
        if (contacts) {
            contacts->restoreRotation(w.collisionAngleBackup, w.collisionSpinBackup);
            contacts->undoSolverState();
        }
        w.integrator->setProposedStep(w.settings.adaptiveStep);
        return Error{message, "", ErrorKind::Diverged};
    }
    w.settings.time += w.settings.dt;
    w.stepStartKnown = true;
    // Breaks after the step is known good (a failed step breaks nothing)
    // and before the islands are updated, which then no longer join the
    // broken joint's bodies.
    if (contacts && contacts->hasBreakableJoints()) {
        w.breakScratch.clear();
        contacts->breakJoints(w.breakScratch);
        for (const auto& [k, force] : w.breakScratch) {
            const joints::JointConstraint& j = contacts->jointConstraints()[k];
            w.breaks.push_back({j.entity, j.entityA, j.entityB, w.stats.step + 1, force, j.maxForce});
        }
    }
    w.updateSleep(substeps > 1 ? w.backupX.data() : w.x[1 - w.current].data(),
                  substeps > 1 ? w.backupV.data() : w.v[1 - w.current].data());
    if (w.kind == detail::IntegratorKind::Dopri5) w.settings.adaptiveStep = w.integrator->proposedStep();
    ++w.stats.step;
    w.stats.forceEvaluations = evaluations;
    w.stats.internalSteps = internalSteps;
    w.stats.rejectedSteps = rejectedSteps;
    w.stats.contactCount = contacts ? contacts->contactPointCount() : 0;
    w.stats.stages.clear();
    w.stats.systems.clear();
    if (timed) {
        double forceSeconds = 0.0;
        for (std::size_t s = 0; s < f.systemSeconds.size(); ++s) {
            const auto system = detail::ForceSystem(s);
            const bool on = (system == detail::ForceSystem::Gravity && f.gravityOn) ||
                            (system == detail::ForceSystem::Drag && f.dragOn) ||
                            (system == detail::ForceSystem::Springs && f.springsOn()) ||
                            (system == detail::ForceSystem::Attractors && f.attractorsOn()) ||
                            (system == detail::ForceSystem::Boids && f.boidsOn);
            if (!on) continue;
            forceSeconds += f.systemSeconds[s];
            w.stats.systems.push_back({detail::forceSystemName(system), 1e3 * f.systemSeconds[s]});
        }
        const double total = std::chrono::duration<double>(t1 - t0).count();
        w.stats.stages.push_back({"forces", 1e3 * forceSeconds});
        const double collisionSeconds =
            contacts ? 1e-3 * (contacts->timings().broadPhaseMs + contacts->timings().narrowPhaseMs) + contactSeconds
                     : 0.0;
        w.stats.stages.push_back(
            {"integrate", 1e3 * std::max(0.0, total - forceSeconds - rotationSeconds - collisionSeconds)});
        if (contacts) {
            w.stats.stages.push_back({"broad_phase", contacts->timings().broadPhaseMs});
            w.stats.stages.push_back({"narrow_phase", contacts->timings().narrowPhaseMs});
            w.stats.stages.push_back({"contact_solve", 1e3 * contactSeconds});
        }
        if (!w.spinBody.empty()) w.stats.stages.push_back({"rotation", 1e3 * rotationSeconds});
        w.stats.stages.push_back({"check", 1e3 * std::chrono::duration<double>(t2 - t1).count()});
    }
    return {};
}

namespace {

/// With emitters: the copies the run has alive are in the scene under the
/// run's handles, with their components, after the scene's other entities
/// in the order they appeared; the copies it removed are not; each
/// emitter's run state is the run's.
void syncCopies(const WorldLayout& layout, Scene& scene) {
    if (!layout.registry) return;
    Registry& reg = scene.registry;
    const Registry& run = *layout.registry;
    std::vector<std::string> prefixes;
    for (const auto& [e, em] : layout.emitters) {
        prefixes.push_back(em.templateName + "#");
        if (Emitter* own = reg.tryGet<Emitter>(e)) {
            own->next = em.next;
            own->emitted = em.emitted;
            own->alive = em.alive;
            own->oldest = em.oldest;
            own->copies = em.copies;
        }
    }
    const auto isCopy = [&](const Registry& r, Entity e) {
        const Name* name = r.tryGet<Name>(e);
        if (!name) return false;
        for (const std::string& prefix : prefixes)
            if (name->value.compare(0, prefix.size(), prefix) == 0) return true;
        return false;
    };
    for (const Entity e : std::vector<Entity>(reg.entities()))
        if (!run.alive(e) && isCopy(reg, e)) reg.destroy(e);
    for (const Entity e : run.entities())
        if (!reg.alive(e) && isCopy(run, e) && reg.createAt(e)) copyComponents(run, e, reg, e);
}

/// World::writeBack and WorldState::writeBack: the arrays of one layout into
/// the scene's components. `colliderAngle`/`colliderSpin` may be empty (no
/// shapes).
void writeStateBack(const WorldLayout& layout, const double* x, const double* v, std::span<const double> spinAngle,
                    std::span<const double> colliderAngle, std::span<const double> colliderSpin, double time,
                    double adaptiveStep, Scene& scene) {
    syncCopies(layout, scene);
    Registry& reg = scene.registry;
    for (std::size_t b = 0; b < layout.bodies.size(); ++b) {
        const Entity e = layout.bodies[b];
        if (!reg.alive(e)) continue;  // stale: the scene is not the one built from
        const Vec2 position{x[2 * b], x[2 * b + 1]};
        bool moved = false;
        if (Position* p = reg.tryGet<Position>(e)) {
            moved = !(p->value == position);
            p->value = position;
        } else {
            reg.emplace<Position>(e, Position{position});
        }
        const Vec2 vel{v[2 * b], v[2 * b + 1]};
        // A body that had no velocity component gets one once it moves,
        // whatever its velocity then: a body that fell and came to rest
        // (asleep, v exactly 0) is written with one, as it is when a run
        // saved while it fell is resumed. So a run saved at any step and
        // resumed writes the bytes one long run does.
        if (reg.has<Velocity>(e) || vel.x != 0.0 || vel.y != 0.0 || moved) reg.emplace<Velocity>(e, Velocity{vel});
    }
    for (std::size_t s = 0; s < layout.spinBodies.size(); ++s) {
        const Entity e = layout.spinBodies[s];
        if (reg.alive(e)) reg.emplace<Angle>(e, Angle{spinAngle[s]});
    }
    for (std::size_t c = 0; c < colliderAngle.size(); ++c) {
        const Entity e = layout.colliders[c];
        if (!layout.colliderMoves[c] || !reg.alive(e)) continue;
        // Like velocity: written once the body turns, so a resumed run
        // starts from the same rotation.
        const double angle = colliderAngle[c], spin = colliderSpin[c];
        const Angle* before = reg.tryGet<Angle>(e);
        const bool turned = (before ? before->value : 0.0) != angle;
        if (reg.has<Angle>(e) || angle != 0.0) reg.emplace<Angle>(e, Angle{angle});
        if (reg.has<AngularVelocity>(e) || spin != 0.0 || turned)
            reg.emplace<AngularVelocity>(e, AngularVelocity{spin});
    }
    scene.world.time = time;
    scene.world.adaptiveStep = adaptiveStep;
}

/// A broken joint is out of the run: out of the scene too, so a save holds
/// what the run simulates and a resume builds the same world.
void removeBrokenJoints(std::span<const JointBreak> breaks, Scene& scene) {
    for (const JointBreak& b : breaks)
        if (scene.registry.has<Joint>(b.joint)) scene.registry.destroy(b.joint);
}

} // namespace

void World::writeBack(Scene& scene) const {
    const WorldImpl& w = *impl_;
    std::span<const double> angles, spins;
    if (w.collision) {
        angles = w.collision->angles();
        spins = w.collision->angularVelocities();
    }
    writeStateBack(*w.layout, w.xs(), w.vs(), w.angle, angles, spins, w.settings.time, w.settings.adaptiveStep, scene);
    removeBrokenJoints(w.breaks, scene);
}

void WorldState::writeBack(Scene& scene) const {
    writeStateBack(*layout, x.data(), v.data(), spinAngle, colliderAngle, colliderSpin, time, adaptiveStep, scene);
    removeBrokenJoints(breaks, scene);
}

namespace {
/// Bitwise +0 (not -0): a joint whose impulses are all this needs no entry.
bool isPlusZero(double v) { return v == 0.0 && !std::signbit(v); }
bool carriesNothing(const JointImpulse& j) {
    return isPlusZero(j.linear.x) && isPlusZero(j.linear.y) && isPlusZero(j.angular) && isPlusZero(j.axial) &&
           isPlusZero(j.motor) && isPlusZero(j.lower) && isPlusZero(j.upper);
}

/// The bodies' sleep state, one array of each (WorldState's or the live one's).
struct SleepArrays {
    std::span<const double> timer;
    std::span<const std::int32_t> island;
    std::span<const double> anchor;
    std::span<const std::uint8_t> anchored;
};

SolverState entityKeyed(const WorldLayout& layout, std::span<const CachedImpulse> cache,
                        std::span<const JointImpulse> jointImpulses, const SleepArrays& sleep) {
    SolverState state;
    // An awake body with no still window carries nothing: no entry.
    for (std::size_t b = 0; b < sleep.timer.size(); ++b) {
        if (sleep.island[b] < 0 && !sleep.anchored[b] && isPlusZero(sleep.timer[b])) continue;
        BodySleep entry{layout.bodies[b], sleep.timer[b], std::nullopt, 0.0,
                        sleep.island[b] >= 0 ? layout.bodies[std::size_t(sleep.island[b])] : Entity{}};
        if (sleep.anchored[b]) {
            const double* a = &sleep.anchor[detail::kAnchorStride * b];
            entry.stillAt = Vec2{a[0], a[1]};
            entry.stillAngle = a[2];
            entry.stillVelocity = Vec2{a[3], a[4]};
        }
        state.bodies.push_back(entry);
    }
    state.contacts.reserve(cache.size());
    for (const CachedImpulse& c : cache)
        state.contacts.push_back({layout.colliders[c.colliderA()], layout.colliders[c.colliderB()], c.feature(),
                                  c.normal, c.tangent, layout.colliderParts[c.colliderA()],
                                  layout.colliderParts[c.colliderB()]});
    // A joint that carries nothing is left out: absent means all +0.
    for (const JointImpulse& j : jointImpulses)
        if (!carriesNothing(j)) state.joints.push_back(j);
    return state;
}

std::vector<JointImpulse> jointImpulsesOf(const collision::CollisionSystem& system) {
    std::vector<JointImpulse> out;
    out.reserve(system.jointConstraints().size());
    for (const joints::JointConstraint& j : system.jointConstraints()) out.push_back(joints::impulsesOf(j));
    return out;
}

/// What the engine chose is part of the run: a resume must not choose
/// again. The substeps and iterations when the level left either out; the
/// contacts' stiffness cap once the run has moved on from the structure it
/// was chosen from (or a record carried it), since a fresh load would choose
/// it from the structure the bodies have then.
std::optional<ChosenSettings> chosenSettings(const WorldImpl& w) {
    const bool counts = w.settingsSource != World::SettingsSource::Given;
    const bool stiffness =
        w.collision && (counts || w.hertzFractionRecorded || w.stats.step > 0);
    if (!counts && !stiffness) return std::nullopt;
    ChosenSettings chosen{w.settings.substeps, w.settings.solverIterations, std::nullopt};
    if (stiffness) {
        chosen.contactHertzFraction = w.contactChoice.hertzFraction;
        if (w.contactChoice.contactHertz != kContactHertz) chosen.contactHertz = w.contactChoice.contactHertz;
    }
    return chosen;
}
} // namespace

SolverState WorldState::solverState() const {
    return entityKeyed(*layout, contacts, joints, {sleepTimer, sleepIsland, sleepAnchor, sleepAnchored});
}

SolverState World::solverState() const {
    const WorldImpl& w = *impl_;
    const SleepArrays sleep{w.sleep.timer, w.sleep.island, w.sleep.anchor, w.sleep.anchored};
    SolverState state = w.collision ? entityKeyed(*w.layout, w.collision->warmStartCache(), jointImpulsesOf(*w.collision), sleep)
                                    : entityKeyed(*w.layout, {}, {}, sleep);
    state.chosen = chosenSettings(w);
    return state;
}

World::SettingsSource World::settingsSource() const { return impl_->settingsSource; }
const ContactSettingsChoice& World::settingsChoice() const { return impl_->contactChoice; }

std::string World::settingsSummary() const {
    const WorldImpl& w = *impl_;
    std::string line = "substeps " + std::to_string(w.settings.substeps) + " (";
    if (w.substepsGiven) line += "given by the level";
    else if (w.settingsSource == SettingsSource::Recorded)
        line += "recorded by the run that saved this file; chosen afresh: " + std::to_string(w.contactChoice.substeps) +
                ", " + w.contactChoice.reason();
    else line += "chosen: " + w.contactChoice.reason();
    line += "), solver_iterations " + std::to_string(w.settings.solverIterations);
    if (w.iterationsGiven) line += " (given by the level)";
    return line;
}

void World::setSolverState(const SolverState& state) {
    WorldImpl& w = *impl_;
    // Sleep first: the contacts' cache is split by it.
    {
        std::unordered_map<Entity, std::uint32_t> bodyOf;
        for (std::size_t b = 0; b < w.bodyEntity.size(); ++b) bodyOf.emplace(w.bodyEntity[b], std::uint32_t(b));
        std::fill(w.sleep.timer.begin(), w.sleep.timer.end(), 0.0);
        std::fill(w.sleep.island.begin(), w.sleep.island.end(), -1);
        std::fill(w.sleep.anchored.begin(), w.sleep.anchored.end(), 0);
        for (const BodySleep& s : state.bodies) {
            const auto body = bodyOf.find(s.body);
            if (body == bodyOf.end()) continue;  // no longer a dynamic body
            w.sleep.timer[body->second] = s.sleepTime;
            if (s.stillAt) {
                double* a = &w.sleep.anchor[detail::kAnchorStride * body->second];
                a[0] = s.stillAt->x;
                a[1] = s.stillAt->y;
                a[2] = s.stillAngle;
                const double* v = w.vs() + 2 * body->second;
                a[3] = s.stillVelocity ? s.stillVelocity->x : v[0];
                a[4] = s.stillVelocity ? s.stillVelocity->y : v[1];
                w.sleep.anchored[body->second] = 1;
            }
            const auto label = s.island.isNull() ? bodyOf.end() : bodyOf.find(s.island);
            // Asleep only where sleeping is on, and a body that may sleep.
            if (label != bodyOf.end() && w.sleep.enabled && !w.sleep.restless[body->second])
                w.sleep.island[body->second] = std::int32_t(label->second);
        }
        w.sleep.refresh();
        // Saved state reproduces a run; it never holds a body the sleep rule
        // would not have put to sleep. A body moved or pushed by hand in the
        // file (faster than sleep_velocity, or further than the drift limit
        // from where its still window began) wakes its island.
        const double* px = w.xs();
        const double* pv = w.vs();
        for (const std::uint32_t b : std::vector<std::uint32_t>(w.sleep.sleeping)) {
            if (w.sleep.island[b] < 0) continue;  // woken with an earlier body of its island
            const std::int32_t c = w.colliderOfBody[b];
            const double spin = c >= 0 ? w.collision->angularVelocity(std::size_t(c)) : 0.0;
            const double angle = c >= 0 ? w.collision->angle(std::size_t(c)) : 0.0;
            const double speed = std::hypot(pv[2 * b], pv[2 * b + 1]) + w.sleep.extent[b] * std::abs(spin);
            const double* a = &w.sleep.anchor[detail::kAnchorStride * b];
            const double drift = w.sleep.anchored[b]
                                     ? std::max(std::hypot(px[2 * b] - a[0], px[2 * b + 1] - a[1]),
                                                w.sleep.extent[b] * std::abs(angle - a[2]))
                                     : std::numeric_limits<double>::infinity();
            if (!(speed <= w.sleep.velocity) || !(drift <= w.sleep.driftLimit())) w.sleep.wake(b);
        }
        // Nor half of a connected group: a joint, spring or touching contact
        // between a sleeping body and one outside its island (awake, or in
        // another island the file names) wakes both islands, as the run that
        // saved it would have kept them one.
        if (!w.sleep.sleeping.empty()) {
            std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
            w.islandEdges(edges);
            for (const auto& [a, b] : edges)
                if (w.sleep.island[a] != w.sleep.island[b]) {
                    w.sleep.wake(a);
                    w.sleep.wake(b);
                }
        }
        w.sleepChanged();
        w.sleptUnder = w.settings;  // a resume steps on under the settings it is given
    }
    w.dropped.reset();
    if (!w.collision) return;
    // Keyed by entity and shape: a compound body has a collider per shape.
    std::unordered_map<Entity, std::uint32_t> colliderOf;  // an entity's first collider
    const std::vector<Entity>& colliders = w.layout->colliders;
    const std::vector<std::uint32_t>& parts = w.layout->colliderParts;
    for (std::size_t c = 0; c < colliders.size(); ++c) colliderOf.emplace(colliders[c], std::uint32_t(c));
    // A compound body's colliders follow each other: its hub, then shape k at k + 1.
    const auto colliderFor = [&](Entity e, std::uint32_t shape) -> std::optional<std::uint32_t> {
        const auto it = colliderOf.find(e);
        if (it == colliderOf.end()) return std::nullopt;
        std::uint32_t c = it->second;
        if (parts[c] == collision::Collider::kHubPart) ++c;
        if (shape != 0) {
            if (parts[c] != 0 || std::size_t(c) + shape >= colliders.size() || colliders[c + shape] != e) return std::nullopt;
            c += shape;
        }
        return parts[c] == shape ? std::optional<std::uint32_t>(c) : std::nullopt;
    };
    // The most impulse a run can leave on one contact, when contacts,
    // gravity and drag are all that act (springs, attractors, boids and
    // joints can press with any force, so no bound is claimed for them). A
    // contact's impulse over a substep passes through the bodies it holds up
    // or stops: at most every dynamic body's mass times what the substep
    // can change of its velocity, from the fastest a level holds to the
    // fastest the other way, plus a step of gravity; four times that. A
    // saved impulse past it is no run's, so it is dropped with a warning;
    // what is kept the engine bounds again at each step's start, from the
    // bodies' motion then (CollisionSystem::warmStartBound).
    const detail::ForceModel& f = w.model;
    const bool bounded = f.springs.empty() && f.attractors.empty() && f.boids.body.empty() &&
                         w.collision->jointConstraints().empty();
    double totalMass = 0.0;
    for (const double m : f.mass) totalMass += m;
    const double bound = 4.0 * totalMass * (2.0 * kMaxSpeed + length(w.settings.gravity) * w.settings.dt);
    std::vector<CachedImpulse> cache;
    cache.reserve(state.contacts.size());
    for (const ContactImpulse& c : state.contacts) {
        const std::optional<std::uint32_t> a = colliderFor(c.a, c.shapeA), b = colliderFor(c.b, c.shapeB);
        if (!a || !b) continue;  // no longer collides: nothing to warm
        // A chain's segments follow its first collider; the feature id
        // holds the segment's number.
        const auto segmentOf = [&](std::uint32_t first) -> std::int64_t {
            if (w.collision->collider(first).shape.kind != collision::ShapeKind::ChainSegment) return first;
            const std::size_t k = first + (c.feature >> collision::kChainFeatureShift);
            if (k >= colliders.size() || colliders[k] != colliders[first]) return -1;
            return std::int64_t(k);
        };
        const std::int64_t ca = segmentOf(*a), cb = segmentOf(*b);
        if (ca < 0 || cb < 0) continue;  // a segment the chain no longer has
        const double largest = std::max(std::abs(c.normalImpulse), std::abs(c.tangentImpulse));
        if (bounded && !(largest <= bound)) {
            if (!w.dropped) w.dropped = DroppedImpulses{.bound = bound};
            ++w.dropped->count;
            w.dropped->largest = std::max(w.dropped->largest, largest);
            continue;
        }
        cache.push_back({CachedImpulse::makeKey(std::uint32_t(ca), std::uint32_t(cb), c.feature), c.normalImpulse,
                         c.tangentImpulse});
    }
    // Kept in the given order when it is sorted (always, for a state this
    // engine wrote): entries with equal keys then stay in the order the
    // warm start reads them.
    w.collision->setWarmStartCache(std::move(cache));
    // Joints: an entry sets its joint's impulses, a joint without one
    // starts from zero (as a state that carried nothing was written).
    std::unordered_map<Entity, const JointImpulse*> given;
    for (const JointImpulse& j : state.joints) given[j.joint] = &j;
    for (joints::JointConstraint& j : w.collision->jointConstraints()) {
        const auto it = given.find(j.entity);
        joints::setImpulses(j, it != given.end() ? *it->second : JointImpulse{j.entity});
    }
}

std::size_t WorldState::bytes() const {
    return sizeof(double) * (x.capacity() + v.capacity() + spinAngle.capacity() + colliderAngle.capacity() +
                             colliderSpin.capacity() + sleepTimer.capacity() + sleepAnchor.capacity()) +
           sizeof(std::int32_t) * sleepIsland.capacity() + sleepAnchored.capacity() +
           sizeof(CachedImpulse) * contacts.capacity() + sizeof(JointImpulse) * joints.capacity() +
           sizeof(JointBreak) * breaks.capacity();
}

WorldState World::saveState() const {
    const WorldImpl& w = *impl_;
    WorldState s;
    s.layout = w.layout;
    s.time = w.settings.time;
    s.adaptiveStep = w.settings.adaptiveStep;
    s.steps = w.stats.step;
    s.x.assign(w.x[w.current].begin(), w.x[w.current].end());
    s.v.assign(w.v[w.current].begin(), w.v[w.current].end());
    s.spinAngle = w.angle;
    s.sleepTimer = w.sleep.timer;
    s.sleepIsland = w.sleep.island;
    s.sleepAnchor = w.sleep.anchor;
    s.sleepAnchored = w.sleep.anchored;
    if (w.collision) {
        s.colliderAngle.assign(w.collision->angles().begin(), w.collision->angles().end());
        s.colliderSpin.assign(w.collision->angularVelocities().begin(), w.collision->angularVelocities().end());
        s.contacts = w.collision->warmStartCache();
        s.joints = jointImpulsesOf(*w.collision);
    }
    s.breaks = w.breaks;
    return s;
}

namespace {
/// Whether snapshot `s` comes from this World's run with other copies
/// alive: both have emitters, the same ones.
bool sameEmitters(const WorldState& s, const WorldImpl& w) {
    if (!s.layout || !s.layout->registry || !w.registry || s.layout->run != w.run ||
        s.layout->emitters.size() != w.emitters.size())
        return false;
    for (std::size_t k = 0; k < w.emitters.size(); ++k)
        if (s.layout->emitters[k].first != w.emitters[k].entity) return false;
    return true;
}
} // namespace

Result<void> World::restoreState(const WorldState& s) {
    WorldImpl& w = *impl_;
    if (!s.layout || (s.layout != w.layout && *s.layout != *w.layout) || s.joints.size() != w.layout->joints.size() ||
        s.sleepTimer.size() != w.bodyEntity.size() || s.sleepIsland.size() != w.bodyEntity.size() ||
        s.sleepAnchor.size() != detail::kAnchorStride * w.bodyEntity.size() || s.sleepAnchored.size() != w.bodyEntity.size()) {
        if (!sameEmitters(s, w)) return Error{"the snapshot was taken from a world with other bodies or shapes"};
        return restoreOtherCopies(s);
    }
    std::copy(s.x.begin(), s.x.end(), w.x[w.current].begin());
    std::copy(s.v.begin(), s.v.end(), w.v[w.current].begin());
    w.angle = s.spinAngle;
    if (w.collision) w.collision->restoreRotation(s.colliderAngle, s.colliderSpin);
    // Joints broken as of the snapshot (before the sleep state, which sets
    // the others' flags); one that broke later is whole again.
    w.breaks = s.breaks;
    if (w.collision && w.collision->hasBreakableJoints()) {
        std::vector<Entity> broken;
        for (const JointBreak& b : w.breaks) broken.push_back(b.joint);
        w.collision->setBrokenJoints(broken);
    }
    // Sleep after the rotations (the frozen shapes' boxes use them) and
    // before the cache (it is split by it).
    w.sleep.timer = s.sleepTimer;
    w.sleep.island = s.sleepIsland;
    w.sleep.anchor = s.sleepAnchor;
    w.sleep.anchored = s.sleepAnchored;
    if (!w.sleep.enabled) std::fill(w.sleep.island.begin(), w.sleep.island.end(), -1);
    w.sleep.refresh();
    w.sleepChanged();
    w.sleptUnder = w.settings;
    if (w.collision) {
        w.collision->setWarmStartCache(s.contacts);
        const std::span<joints::JointConstraint> joints = w.collision->jointConstraints();
        for (std::size_t k = 0; k < joints.size(); ++k) joints::setImpulses(joints[k], s.joints[k]);
        w.collision->clearContactRecords();  // they described the step this state replaces
        if (w.collision->hasSensors()) w.collision->initSensors(detail::asVec2(w.xs(), w.model.n));
    }
    w.stats.contactCount = 0;
    w.stepStartKnown = false;  // the other buffer holds no step's start
    w.settings.time = s.time;
    w.settings.adaptiveStep = s.adaptiveStep;
    w.integrator->setProposedStep(s.adaptiveStep);
    w.stats.step = s.steps;
    return {};
}

Result<void> World::restoreOtherCopies(const WorldState& s) {
    // The snapshot's own scene: the run's registry as it was then (its
    // copies alive, broken joints kept, so that the joints line up with the
    // snapshot's), its state written back, built and restored. Only a World
    // whose emitters added or removed copies since the snapshot comes here.
    const WorldImpl& w = *impl_;
    Scene scene;
    scene.world = w.sceneWorld;
    scene.world.integrator = w.settings.integrator;
    scene.registry = *s.layout->registry;
    writeStateBack(*s.layout, s.x.data(), s.v.data(), s.spinAngle, s.colliderAngle, s.colliderSpin, s.time,
                   s.adaptiveStep, scene);
    scene.solverState = s.solverState();
    scene.solverState->chosen = chosenSettings(w);
    Result<World> next = build(scene, w.switches);
    if (!next) return Error{next.error()};
    next->impl_->profiling = w.profiling;
    next->impl_->run = w.run;  // the same run: its snapshots restore here too
    next->impl_->choiceUnsettled = w.choiceUnsettled;
    next->impl_->layout = next->impl_->makeLayout();
    if (Result<void> restored = next->restoreState(s); !restored) return restored;
    impl_ = std::move(next->impl_);
    return {};
}

Result<void> World::reload(const Scene& scene, const SystemSwitches& switches) {
    Result<World> next = build(scene, switches);
    if (!next) return Error{next.error()};
    if (!scene.solverState) {
        next->setSolverState(solverState());
        next->impl_->wakeEdited(*impl_);  // an edit wakes the islands it touches
    }
    next->impl_->stats.step = impl_->stats.step;
    next->impl_->profiling = impl_->profiling;
    impl_ = std::move(next->impl_);
    return {};
}

AdvanceResult advance(World& world, std::uint64_t steps, const AdvanceHooks& hooks) {
    AdvanceResult result;
    while (result.taken < steps) {
        if (hooks.beforeStep && !hooks.beforeStep(result.taken + 1)) {
            result.stopped = true;
            break;
        }
        if (Result<void> stepped = world.step(); !stepped) {
            result.divergence = stepped.failure();
            break;
        }
        ++result.taken;
        if (hooks.afterStep && !hooks.afterStep(result.taken)) {
            result.stopped = true;
            break;
        }
    }
    return result;
}

const WorldSettings& World::settings() const { return impl_->settings; }

Result<void> World::setIntegrator(std::string_view name) {
    const auto kind = detail::integratorKind(name);
    if (!kind) return Error{"unknown integrator \"" + std::string(name) + "\""};
    impl_->setIntegratorKind(*kind);  // another integrator: the next step wakes every island (sleptUnder)
    return {};
}

Result<void> World::setSpringAnchor(Entity spring, Vec2 anchor) {
    for (detail::SpringData& s : impl_->model.springs)
        if (s.entity == spring && s.b == detail::kNoBody) {
            if (s.fx != anchor.x || s.fy != anchor.y) {
                impl_->sleep.wake(s.a);  // the mouse spring pulls its body out of its island's sleep
                impl_->sleepChanged();
            }
            s.fx = anchor.x;
            s.fy = anchor.y;
            return {};
        }
    return Error{"no anchored spring with that entity in this world"};
}

Result<void> World::moveBody(Entity body, Vec2 position, Vec2 velocity) {
    if (!isFinite(position) || !isFinite(velocity)) return Error{"a position and velocity must be finite"};
    const std::uint32_t found = impl_->bodyIndexOf(body);
    if (found == detail::kNoBody) return Error{"not a dynamic body of this world"};
    const std::size_t b = found;
    double* x = impl_->xs();
    double* v = impl_->vs();
    x[2 * b] = position.x;
    x[2 * b + 1] = position.y;
    v[2 * b] = velocity.x;
    v[2 * b + 1] = velocity.y;
    // A kinematic body moves at its own velocity, which each substep sets
    // again (WorldImpl::kinematicVelocity): the edit goes there too.
    for (std::size_t k = 0; k < impl_->kinematicBody.size(); ++k)
        if (impl_->kinematicBody[k] == b) {
            impl_->kinematicVelocity[2 * k] = velocity.x;
            impl_->kinematicVelocity[2 * k + 1] = velocity.y;
        }
    impl_->sleep.wake(std::uint32_t(b));
    impl_->sleepChanged();
    return {};
}

double World::time() const { return impl_->settings.time; }

std::vector<std::string_view> World::activeSystems() const { return impl_->active; }

const StepStats& World::lastStats() const { return impl_->stats; }

void World::setProfiling(bool on) { impl_->profiling = on; }

EnergyReport World::energy() const {
    const WorldImpl& w = *impl_;
    const detail::ForceModel& f = w.model;
    const double* x = w.xs();
    const double* v = w.vs();
    EnergyReport e;
    for (std::size_t b = 0; b < f.n; ++b) {
        if (!w.isKinematic.empty() && w.isKinematic[b]) continue;  // infinite mass: outside the balance
        const double m = f.mass[b];
        e.kinetic += 0.5 * m * (v[2 * b] * v[2 * b] + v[2 * b + 1] * v[2 * b + 1]);
        // -m g.p: zero at the origin, so that kinetic + gravity is conserved.
        e.gravity -= m * (w.settings.gravity.x * x[2 * b] + w.settings.gravity.y * x[2 * b + 1]);
        e.momentum.x += m * v[2 * b];
        e.momentum.y += m * v[2 * b + 1];
    }
    if (const collision::CollisionSystem* contacts = w.collision.get()) {
        for (std::size_t c = 0; c < contacts->colliderCount(); ++c) {
            const collision::Collider& col = contacts->collider(c);
            if (col.body < 0 || col.kinematic) continue;
            const double spin = contacts->angularVelocity(c);
            e.kinetic += 0.5 * col.inertia * spin * spin;
            // Gravity acts at the centre of mass, which the state's position
            // is not for an off-centre polygon.
            const Vec2 offset = contacts->centreOfMass(c, detail::asVec2(x, f.n)) - detail::asVec2(x, f.n)[std::size_t(col.body)];
            e.gravity -= col.mass * (w.settings.gravity.x * offset.x + w.settings.gravity.y * offset.y);
        }
    }
    e.springs = f.springEnergy(x);
    e.attractors = f.attractorEnergy(x);
    return e;
}

std::string World::nonFiniteEnergyTerm() const {
    const WorldImpl& w = *impl_;
    const detail::ForceModel& f = w.model;
    const double* x = w.xs();
    const double* v = w.vs();
    const auto bodyLabel = [&](std::size_t b) { return entityLabel(w.bodySceneIndex[b], &w.bodyName[b]); };
    const Vec2 g = w.settings.gravity;
    for (std::size_t b = 0; b < f.n; ++b) {
        const double m = f.mass[b];
        const double speed = std::hypot(v[2 * b], v[2 * b + 1]);
        const double kinetic = 0.5 * m * (v[2 * b] * v[2 * b] + v[2 * b + 1] * v[2 * b + 1]);
        if (!std::isfinite(kinetic))
            return bodyLabel(b) + ": kinetic energy m*v^2/2 became " + formatNumber(kinetic) + " J (mass " +
                   formatNumber(m) + " kg, speed " + formatNumber(speed) + " m/s)";
        const double potential = -m * (g.x * x[2 * b] + g.y * x[2 * b + 1]);
        if (!std::isfinite(potential))
            return bodyLabel(b) + ": gravity's potential energy -m*g.x became " + formatNumber(potential) +
                   " J (mass " + formatNumber(m) + " kg at {" + formatNumber(x[2 * b]) + ", " +
                   formatNumber(x[2 * b + 1]) + "} m)";
    }
    if (const collision::CollisionSystem* contacts = w.collision.get())
        for (std::size_t c = 0; c < contacts->colliderCount(); ++c) {
            const collision::Collider& col = contacts->collider(c);
            if (col.body < 0) continue;
            const double spin = contacts->angularVelocity(c);
            const double turning = 0.5 * col.inertia * spin * spin;
            if (!std::isfinite(turning))
                return bodyLabel(std::size_t(col.body)) + ": rotational energy I*w^2/2 became " + formatNumber(turning) +
                       " J (inertia " + formatNumber(col.inertia) + " kg m^2, spin " + formatNumber(spin) + " rad/s)";
        }
    for (std::size_t k = 0; k < f.springs.size(); ++k) {
        const detail::SpringData& s = f.springs[k];
        const double ax = x[2 * s.a], ay = x[2 * s.a + 1];
        const double bx = s.b == detail::kNoBody ? s.fx : x[2 * s.b], by = s.b == detail::kNoBody ? s.fy : x[2 * s.b + 1];
        const double stretch = std::hypot(bx - ax, by - ay) - s.rest;
        const double elastic = 0.5 * s.k * stretch * stretch;
        if (!std::isfinite(elastic))
            return "spring " + w.springName[k] + ": energy k*stretch^2/2 became " + formatNumber(elastic) +
                   " J (k " + formatNumber(s.k) + " N/m, stretch " + formatNumber(stretch) + " m)";
    }
    return {};
}

std::span<const ContactRecord> World::contacts() const {
    return impl_->collision ? impl_->collision->contacts() : std::span<const ContactRecord>{};
}

std::span<const SensorEvent> World::sensorEvents() const {
    return impl_->collision ? impl_->collision->sensorEvents() : std::span<const SensorEvent>{};
}

std::vector<std::pair<Entity, Entity>> World::sensorOverlaps() const {
    return impl_->collision ? impl_->collision->sensorOverlaps() : std::vector<std::pair<Entity, Entity>>{};
}

std::span<const JointRecord> World::joints() const {
    return impl_->collision ? impl_->collision->jointRecords() : std::span<const JointRecord>{};
}

std::span<const JointBreak> World::jointBreaks() const { return impl_->breaks; }

std::vector<StiffnessHint> World::stiffnessHints() const {
    const WorldImpl& w = *impl_;
    const detail::ForceModel& f = w.model;
    std::vector<StiffnessHint> hints;
    const bool implicitMethod = detail::isImplicit(w.kind);
    if (w.kind == detail::IntegratorKind::Dopri5) return hints;  // error-controlled: no fixed-step limit
    const int substeps = w.settings.substeps;
    const double h = w.settings.dt / double(substeps);
    std::map<double, double> limitByZeta;  // cloth and chains share a few damping ratios
    for (std::size_t s = 0; s < f.springs.size(); ++s) {
        const detail::SpringData& sp = f.springs[s];
        if (!(sp.k > 0.0)) continue;
        // Reduced mass: two bodies oscillate against each other with
        // m_a m_b / (m_a + m_b); against a fixed end with m_a.
        const double ma = f.mass[sp.a];
        const double mr = sp.b == kNoBody ? ma : ma * f.mass[sp.b] / (ma + f.mass[sp.b]);
        const double omega = std::sqrt(sp.k / mr);
        const double zeta = sp.c / (2.0 * std::sqrt(sp.k * mr));
        // The implicit methods are stable at any dt, but their linear system
        // M + h^2 K has condition number about (h omega)^2: past
        // kImplicitConditioningLimit the solve in doubles loses its accuracy
        // and the step is refused.
        auto it = limitByZeta.find(zeta);
        if (it == limitByZeta.end())
            it = limitByZeta
                     .emplace(zeta, implicitMethod ? detail::kImplicitConditioningLimit
                                                   : detail::stabilityLimit(w.kind, zeta))
                     .first;
        const double limit = it->second;
        const double hOmega = h * omega;
        if (!(hOmega > limit)) continue;
        StiffnessHint hint;
        hint.spring = sp.entity;
        hint.springName = w.springName[s];
        hint.hOmega = hOmega;
        hint.limit = limit;
        hint.largestStableDt = limit / omega * double(substeps);
        hint.integrator = w.settings.integrator;
        hints.push_back(std::move(hint));
    }
    return hints;
}

std::optional<DroppedImpulses> World::droppedImpulses() const { return impl_->dropped; }

std::string DroppedImpulses::message() const {
    return "solver_state: " + std::to_string(count) + " saved contact impulse" + (count == 1 ? "" : "s") +
           " up to " + formatNumber(largest) + " N*s dropped: no run of this scene can leave more than " +
           formatNumber(bound) + " N*s on a contact (4 x its dynamic mass x (2 x 1e9 m/s + g dt)); those contacts "
           "start cold, so the run does not resume exactly";
}

std::optional<PileHint> World::pileHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    // Only a setting the level gave can be at fault: the engine's own
    // choice (fresh or recorded) is what the rule allows.
    if (w.settingsSource != SettingsSource::Given && w.settings.substeps >= c.substeps) return std::nullopt;
    if (!w.collision || c.stackDepth < 2 || !(c.diameter > 0.0)) return std::nullopt;
    const double limit = 0.02 * c.diameter;  // the pile goal: overlap under 2% of a diameter
    const int substeps = w.settings.substeps;
    // Equal bodies: the warning's model is the one measured on the 30-row
    // pile; the choice also weighs the mass ratio (a heavy body on a light
    // one), so it never gets less than this asks for.
    const double overlap = expectedPileOverlap(c.stackDepth, c.gravity, w.settings.dt / double(substeps), 1.0,
                                               c.hertzFraction, c.contactHertz);
    if (!(overlap > limit)) return std::nullopt;
    PileHint hint;
    hint.stackDepth = c.stackDepth;
    hint.expectedOverlap = overlap;
    hint.diameter = c.diameter;
    hint.substeps = substeps;
    // None up to kMaxContactSubsteps may hold it (a load past what the
    // chosen stiffness carries): then the warning says what those leave.
    hint.substepsNeeded = 0;
    for (int s = substeps + 1; s <= kMaxContactSubsteps; ++s)
        if (expectedPileOverlap(c.stackDepth, c.gravity, w.settings.dt / double(s), 1.0, c.hertzFraction,
                                c.contactHertz) <= limit) {
            hint.substepsNeeded = s;
            break;
        }
    if (hint.substepsNeeded == 0)
        hint.overlapAtMost =
            expectedPileOverlap(c.stackDepth, c.gravity, w.settings.dt / double(kMaxContactSubsteps), 1.0,
                                c.hertzFraction, c.contactHertz);
    return hint;
}

// The engine takes up to what a level may give (a run records its choice,
// which a reload reads as a count in the level's range).
static_assert(kMaxContactSubsteps == kMaxLevelSubsteps);

std::optional<ContactStiffnessHint> World::contactStiffnessHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    // At kContactHertz a rule that fails is the pile's or the column's,
    // whose own hint (pileHint) names the substeps; only a strong load
    // raises the stiffness. Bodies that cannot rest on one another meet
    // only static supports, whose contacts turn rigid before the slop
    // (Softness::rigidDepth) whatever the stiffness.
    if (!w.collision || !(c.contactHertz > kContactHertz)) return std::nullopt;
    if (c.stackDepth < 2 && c.columnHeight < 2) return std::nullopt;
    const double dt = w.settings.dt;
    const double carried = c.hertzFraction * double(w.settings.substeps) / dt;
    if (!(c.contactHertz > carried * (1.0 + 1e-12))) return std::nullopt;
    ContactStiffnessHint hint;
    hint.gravity = c.gravity;
    hint.hertzNeeded = c.contactHertz;
    hint.hertzCarried = carried;
    hint.substeps = w.settings.substeps;
    const int needed = detail::wholeSubsteps(c.contactHertz * dt / c.hertzFraction, 1e6);
    hint.substepsNeeded = needed <= kMaxLevelSubsteps ? needed : 0;
    return hint;
}

std::optional<ImpactHint> World::impactHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    if (!w.substepsGiven || !w.collision || !(c.impactSize > 0.0) || !(c.impactDriven > 0.0)) return std::nullopt;
    const double dt = w.settings.dt;
    const int substeps = w.settings.substeps;
    const double travel = c.impactDriven * dt / double(substeps);
    if (!(travel > kImpactTravel * c.impactSize)) return std::nullopt;
    ImpactHint hint;
    hint.speed = c.impactSpeed;
    hint.size = c.impactSize;
    hint.driven = c.impactDriven;
    hint.travel = travel;
    hint.substeps = substeps;
    // Any whole number of substeps (the engine's own choice takes 1, 2, 4
    // or 8).
    hint.substepsNeeded = detail::wholeSubsteps(c.impactDriven * dt / (kImpactTravel * c.impactSize), 1e6);
    return hint;
}

std::optional<JointLoopHint> World::jointLoopHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    if (!w.substepsGiven || c.jointLoops == 0 || !(c.jointLoopHertz > 0.0)) return std::nullopt;
    const double perStep = w.settings.dt * c.jointLoopHertz / kLoopJointHertzFraction;
    if (!(perStep > double(w.settings.substeps) * (1.0 + 1e-12))) return std::nullopt;
    JointLoopHint hint;
    hint.loops = c.jointLoops;
    hint.hertz = c.jointLoopHertz;
    hint.substeps = w.settings.substeps;
    hint.substepsNeeded = detail::wholeSubsteps(perStep, 1e6);
    return hint;
}

std::optional<JointSupportHint> World::jointSupportHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    const double s = double(w.settings.substeps);
    if (!w.substepsGiven || !(c.jointSupportRatio > kJointSupportRatio * s * s * (1.0 + 1e-12))) return std::nullopt;
    JointSupportHint hint;
    hint.ratio = c.jointSupportRatio;
    hint.substeps = w.settings.substeps;
    hint.substepsNeeded = detail::wholeSubsteps(std::sqrt(c.jointSupportRatio / kJointSupportRatio), 1e6);
    return hint;
}

std::string JointSupportHint::message() const {
    char text[360];
    std::snprintf(text, sizeof text,
                  "bodies %.3g times as heavy as jointed bodies they can rest on: at %d substep%s a load over "
                  "%.3g times can spring on the joints and fall through them; substeps %d would hold it",
                  ratio, substeps, substeps == 1 ? "" : "s", kJointSupportRatio * substeps * substeps, substepsNeeded);
    return text;
}

std::string JointLoopHint::message() const {
    char text[360];
    std::snprintf(text, sizeof text,
                  "%d %s among moving bodies, corrected at %.3g Hz: past a quarter of the substep rate at %d "
                  "substep%s, where a net of joints can swing open or diverge; substeps %d would hold it",
                  loops, loops == 1 ? "joint closes a loop" : "joints close loops", hertz, substeps,
                  substeps == 1 ? "" : "s", substepsNeeded);
    return text;
}

std::string ContactStiffnessHint::message() const {
    char text[400];
    const int written = std::snprintf(
        text, sizeof text,
        "a load of %.3g m/s^2 needs contacts of %.0f Hz, and %d substep%s carry %.0f Hz: stacks and piles sink into "
        "themselves and a tall one can collapse; ",
        gravity, hertzNeeded, substeps, substeps == 1 ? "" : "s", hertzCarried);
    const std::size_t at = std::size_t(std::max(written, 0));
    if (substepsNeeded > 0)
        std::snprintf(text + at, sizeof text - at, "substeps %d would carry them", substepsNeeded);
    else
        std::snprintf(text + at, sizeof text - at, "no substep count up to %d carries them: lower the load",
                      kMaxLevelSubsteps);
    return text;
}

std::string ImpactHint::message() const {
    char text[320];
    std::snprintf(text, sizeof text,
                  "a body at %.3g m/s strikes %.2g m bodies and drives them %.0f mm per substep (%.0f%% of their "
                  "size) at %d substep%s; substeps %d would keep it under %.0f%%",
                  speed, size, 1e3 * travel, 100.0 * travel / size, substeps, substeps == 1 ? "" : "s",
                  substepsNeeded, 100.0 * kImpactTravel);
    return text;
}

std::string PileHint::message() const {
    char text[400];
    const int written = std::snprintf(
        text, sizeof text, "piles up to %d bodies deep: expected sinkage %.0f mm (%.1f%% of a %.2g m diameter) at %d substep%s; ",
        stackDepth, 1e3 * expectedOverlap, 100.0 * expectedOverlap / diameter, diameter, substeps,
        substeps == 1 ? "" : "s");
    const std::size_t at = std::size_t(std::max(written, 0));
    if (substepsNeeded > 0)
        std::snprintf(text + at, sizeof text - at, "%d substeps would hold it under 2%%", substepsNeeded);
    else
        std::snprintf(text + at, sizeof text - at,
                      "no substep count up to %d holds it under 2%% (%d leave %.0f mm): lower the load or the pile",
                      kMaxContactSubsteps, kMaxContactSubsteps, 1e3 * overlapAtMost);
    return text;
}

Vec2 World::probeForce(Vec2 point, Vec2) const {
    // A 1 kg probe: force in newtons equals acceleration in m/s^2. The same
    // fieldAt() the attractor system runs per body.
    return impl_->model.fieldAt(point.x, point.y, kNoBody, impl_->xs());
}

std::size_t World::bodyCount() const { return impl_->bodyEntity.size(); }

std::size_t World::kinematicCount() const { return impl_->kinematicBody.size(); }
Entity World::bodyEntity(std::size_t body) const { return impl_->bodyEntity.at(body); }
Vec2 World::bodyPosition(std::size_t body) const {
    const double* x = impl_->xs();
    return {x[2 * body], x[2 * body + 1]};
}
Vec2 World::bodyVelocity(std::size_t body) const {
    const double* v = impl_->vs();
    return {v[2 * body], v[2 * body + 1]};
}

std::vector<Vec2> World::bodyForces() const {
    const WorldImpl& w = *impl_;
    const detail::ForceModel& f = w.model;
    std::vector<double> a(2 * f.n);
    const bool wasProfiling = f.profiling;
    f.profiling = false;  // do not disturb the last step's timings
    f.accelerations(w.xs(), w.vs(), a.data());
    f.profiling = wasProfiling;
    std::vector<Vec2> forces(f.n);
    for (std::size_t b = 0; b < f.n; ++b) forces[b] = {f.mass[b] * a[2 * b], f.mass[b] * a[2 * b + 1]};
    return forces;
}

std::vector<Vec2> World::netForces() const {
    const WorldImpl& w = *impl_;
    if (!w.stepStartKnown) return {};
    const detail::ForceModel& f = w.model;
    const double* v = w.vs();
    const double* v0 = w.stepStartV();
    const double dt = w.settings.dt;
    std::vector<Vec2> forces(f.n);
    for (std::size_t b = 0; b < f.n; ++b)
        forces[b] = {f.mass[b] * (v[2 * b] - v0[2 * b]) / dt, f.mass[b] * (v[2 * b + 1] - v0[2 * b + 1]) / dt};
    return forces;
}

} // namespace stepwise
