// World: compiles a Scene into packed arrays and runs the step pipeline.
//
// Pipeline of one step (each stage timed into StepStats):
//   for each substep of h = dt / substeps:
//     forces + integrate     the integrator calls the force systems
//                            (gravity, drag, springs, attractors, boids) as
//                            often as its method needs
//     [broad phase, narrow phase, contact solve]   -- collisions, another
//                            issue: they go here, after the integrator has
//                            produced the end-of-substep velocities and
//                            before positions are final. A contact solver
//                            changes velocities by dv; positions then take
//                            x += h dv, the semi-implicit Euler position
//                            update applied to the impulse, which is exact
//                            for semi-implicit Euler and first order for
//                            the others (as in every impulse-based engine).
//     rotation               angle += h * angular_velocity
//   check                    every state value finite, else undo the step
//                            (x and v: done inside the integrator's pass
//                            when its kernel is fused and no contact solve
//                            ran after it)
//
// Determinism: nothing is carried between steps except the state and the
// time, both of which a saved file holds exactly (shortest round-trip
// numbers). No cached accelerations (Verlet recomputes a(x0, v0)), the boid
// grid is rebuilt per evaluation, and no summation depends on addresses or
// threads. So 200 steps equal 100 steps, save, load, 100 steps, bit for bit.

#include "world/world_impl.hpp"
#include "world/world_collisions.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <unordered_map>

namespace stepwise {

using detail::kNoBody;

namespace {

using Clock = std::chrono::steady_clock;

std::string entityLabel(std::size_t index, const std::string* name) {
    std::string s = "entity " + std::to_string(index);
    if (name && !name->empty()) s += " (\"" + *name + "\")";
    return s;
}

std::string describeValue(double v) {
    if (std::isnan(v)) return "nan";
    return v > 0 ? "inf" : "-inf";
}

// True when every value is finite. x * 0 is 0 for a finite x and NaN for
// inf or NaN, and NaN survives addition, so one sum answers for the whole
// array. Four partial sums break the dependency chain (measured 0.14 ns
// per value against 0.43 for an exponent-bit test, which GCC 12 does not
// vectorise). Relies on IEEE semantics: no -ffast-math (CMakeLists).
bool allFinite(const double* p, std::size_t m) {
    double a0 = 0.0, a1 = 0.0, a2 = 0.0, a3 = 0.0;
    std::size_t i = 0;
    for (; i + 4 <= m; i += 4) {
        a0 += p[i] * 0.0;
        a1 += p[i + 1] * 0.0;
        a2 += p[i + 2] * 0.0;
        a3 += p[i + 3] * 0.0;
    }
    for (; i < m; ++i) a0 += p[i] * 0.0;
    const double sum = (a0 + a1) + (a2 + a3);
    return sum == sum;
}

std::string format(double v) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.3g", v);
    return buffer;
}

} // namespace

std::string WorldImpl::findNonFinite(std::uint64_t stepNumber) const {
    const double* px = xs();
    const double* pv = vs();
    const std::size_t n = bodyEntity.size();
    for (std::size_t b = 0; b < n; ++b) {
        // Velocity before position: in a blow-up the velocity overflows
        // first and the position follows from it.
        const std::pair<const char*, double> quantities[] = {
            {"velocity.x", pv[2 * b]}, {"velocity.y", pv[2 * b + 1]},
            {"position.x", px[2 * b]}, {"position.y", px[2 * b + 1]}};
        for (const auto& [what, value] : quantities)
            if (!std::isfinite(value))
                return "step " + std::to_string(stepNumber) + ": " + entityLabel(bodySceneIndex[b], &bodyName[b]) +
                       ": " + what + " became " + describeValue(value);
    }
    for (std::size_t s = 0; s < spinBody.size(); ++s)
        if (!std::isfinite(angle[s]))
            return "step " + std::to_string(stepNumber) + ": " +
                   entityLabel(bodySceneIndex[spinBody[s]], &bodyName[spinBody[s]]) + ": angle became " +
                   describeValue(angle[s]);
    return {};
}

void WorldImpl::setIntegratorKind(detail::IntegratorKind k) {
    kind = k;
    integrator = detail::makeIntegrator(k, model);
    settings.integrator = std::string(detail::integratorName(k));
}

// ---------------------------------------------------------------------------

std::string StiffnessHint::message() const {
    char dtText[32];
    std::snprintf(dtText, sizeof dtText, "%.3g", largestStableDt);
    std::string text = "spring \"" + springName + "\": dt*sqrt(k/m) = " + format(hOmega) + " per substep ";
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

Result<World> World::build(const Scene& scene) {
    auto impl = std::make_unique<WorldImpl>();
    WorldImpl& w = *impl;
    w.settings = scene.world;
    const WorldSettings& ws = scene.world;
    const auto kind = detail::integratorKind(ws.integrator);
    if (!kind) {
        std::string known;
        for (std::string_view name : integratorNames()) known += (known.empty() ? "" : ", ") + std::string(name);
        return Error{"world.integrator: unknown integrator \"" + ws.integrator + "\"; known: " + known};
    }
    if (!(ws.dt > 0.0) || !std::isfinite(ws.dt)) return Error{"world.dt: expected a finite number > 0, got " + format(ws.dt)};
    if (ws.substeps < 0) return Error{"world.substeps: expected an integer >= 1, got " + std::to_string(ws.substeps)};
    if (ws.solverIterations < 0)
        return Error{"world.solver_iterations: expected an integer >= 1, got " + std::to_string(ws.solverIterations)};
    if (ws.restitutionThreshold && !(*ws.restitutionThreshold >= 0.0 && std::isfinite(*ws.restitutionThreshold)))
        return Error{"world.restitution_threshold: expected a finite number >= 0, got " + format(*ws.restitutionThreshold)};
    if (!isFinite(ws.gravity) || !std::isfinite(ws.G) || !std::isfinite(ws.time))
        return Error{"world: gravity, G and time must be finite"};

    const Registry& reg = scene.registry;
    const std::vector<Entity>& order = reg.entities();

    // Dynamic bodies, in scene order (the state vector's order: stable
    // across save and load).
    std::unordered_map<std::uint32_t, std::uint32_t> bodyOfSlot;  // entity index -> body
    std::unordered_map<std::string, std::size_t> sceneIndexOfName;
    std::vector<double> x0, v0, mass;
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Name* name = reg.tryGet<Name>(e);
        if (name && !name->value.empty()) sceneIndexOfName.emplace(name->value, i);
        const Position* p = reg.tryGet<Position>(e);
        if (!p) continue;
        const Static* st = reg.tryGet<Static>(e);
        if (st && st->value) continue;
        const Velocity* vel = reg.tryGet<Velocity>(e);
        const Mass* m = reg.tryGet<Mass>(e);
        const double mv = m ? m->value : 1.0;
        if (!(mv > 0.0) || !std::isfinite(mv))
            return Error{entityLabel(i, name ? &name->value : nullptr) + ": mass must be a finite number > 0"};
        bodyOfSlot.emplace(e.index, std::uint32_t(w.bodyEntity.size()));
        w.bodyEntity.push_back(e);
        w.bodySceneIndex.push_back(std::uint32_t(i));
        w.bodyName.push_back(name ? name->value : std::string());
        x0.push_back(p->value.x);
        x0.push_back(p->value.y);
        v0.push_back(vel ? vel->value.x : 0.0);
        v0.push_back(vel ? vel->value.y : 0.0);
        mass.push_back(mv);
    }
    const std::size_t n = w.bodyEntity.size();
    detail::ForceModel& f = w.model;
    f.n = n;
    f.mass = mass;
    f.invMass.resize(n);
    for (std::size_t b = 0; b < n; ++b) f.invMass[b] = 1.0 / mass[b];
    auto bodyOf = [&](Entity e) -> std::uint32_t {
        const auto it = bodyOfSlot.find(e.index);
        return it == bodyOfSlot.end() ? kNoBody : it->second;
    };

    // Gravity: only when there is something for it to pull.
    f.gravityOn = n > 0 && (ws.gravity.x != 0.0 || ws.gravity.y != 0.0);
    f.gx = ws.gravity.x;
    f.gy = ws.gravity.y;
    f.G = ws.G;

    // Drag: dense per-body rates, only if some body has b > 0.
    f.dragB.assign(n, 0.0);
    for (std::size_t b = 0; b < n; ++b)
        if (const Drag* d = reg.tryGet<Drag>(w.bodyEntity[b]); d && d->value > 0.0) {
            f.dragB[b] = d->value;
            f.dragOn = true;
        }
    if (f.dragOn) {
        f.dragRate.resize(n);
        for (std::size_t b = 0; b < n; ++b) f.dragRate[b] = f.dragB[b] * f.invMass[b];
    } else {
        f.dragB.clear();
    }

    // Springs, in scene order. A static or anchored end is a fixed point.
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Spring* s = reg.tryGet<Spring>(e);
        if (!s) continue;
        const Name* sname = reg.tryGet<Name>(e);
        const std::string label = entityLabel(i, sname ? &sname->value : nullptr);
        struct End {
            std::uint32_t body = kNoBody;
            Vec2 point;
        };
        auto resolve = [&](const std::string& endName, const char* key, End& end) -> std::string {
            const auto it = sceneIndexOfName.find(endName);
            if (it == sceneIndexOfName.end())
                return label + ": spring " + key + ": no entity is named \"" + endName + "\"";
            const Entity other = order[it->second];
            const Position* p = reg.tryGet<Position>(other);
            if (!p) return label + ": spring " + key + ": entity \"" + endName + "\" has no position";
            end.body = bodyOf(other);
            end.point = p->value;
            return {};
        };
        End a, b;
        if (std::string problem = resolve(s->a, "a", a); !problem.empty()) return Error{problem};
        if (!s->b.empty()) {
            if (std::string problem = resolve(s->b, "b", b); !problem.empty()) return Error{problem};
        } else if (s->anchor) {
            b.point = *s->anchor;
        } else {
            return Error{label + ": spring needs \"b\" or \"anchor\""};
        }
        if (a.body == kNoBody) std::swap(a, b);
        if (a.body == kNoBody) continue;  // both ends fixed: no dynamics, nothing to simulate
        detail::SpringData d;
        d.a = a.body;
        d.b = b.body;
        d.fx = b.point.x;
        d.fy = b.point.y;
        d.k = s->k;
        d.c = s->damping;
        // A file always has rest_length after loading; a scene built in code
        // may not: then it rests at its built length, as the loader does.
        const Vec2 pa = a.point, pb = b.point;
        d.rest = s->restLength ? *s->restLength : length(pa - pb);
        d.sceneIndex = std::uint32_t(i);
        d.entity = e;
        f.springs.push_back(d);
        w.springName.push_back(sname && !sname->value.empty() ? sname->value : "entity " + std::to_string(i));
    }

    // Attractors: dynamic ones are n-body participants, static ones fixed.
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Attractor* at = reg.tryGet<Attractor>(e);
        const Position* p = reg.tryGet<Position>(e);
        if (!at || !p) continue;
        const Mass* m = reg.tryGet<Mass>(e);
        detail::AttractorData d;
        d.body = bodyOf(e);
        d.px = p->value.x;
        d.py = p->value.y;
        d.mass = m ? m->value : 1.0;
        d.gm = ws.G * d.mass;
        d.eps2 = at->softening * at->softening;
        f.attractors.push_back(d);
    }

    // Boids: dynamic bodies with a boid component.
    for (std::size_t b = 0; b < n; ++b) {
        const Boid* boid = reg.tryGet<Boid>(w.bodyEntity[b]);
        if (!boid) continue;
        detail::BoidParams p;
        p.neighborRadius = boid->neighborRadius;
        p.neighborRadius2 = boid->neighborRadius * boid->neighborRadius;
        p.separationRadius = boid->separationRadius;
        p.separation = boid->separation;
        p.alignment = boid->alignment;
        p.cohesion = boid->cohesion;
        if (boid->goal) {
            p.goalX = boid->goal->x;
            p.goalY = boid->goal->y;
            p.goalWeight = boid->goalWeight;
        }
        p.maxSpeed = boid->maxSpeed;
        f.boids.body.push_back(std::uint32_t(b));
        f.boids.params.push_back(p);
    }
    f.boidsOn = !f.boids.body.empty();
    if (f.boidsOn) f.boids.prepare();

    // Shapes: the collision stages, only when some entity has one.
    w.collision = detail::buildCollisions(scene, bodyOf, kNoBody);
    // Settings the level left to the engine (world.hpp: chooseContactSettings,
    // derivedRestitutionThreshold); settings() reports what runs.
    const ContactSettingsChoice choice = chooseContactSettings(scene);
    w.contactChoice = choice;
    if (ws.substeps == 0) w.settings.substeps = choice.substeps;
    if (ws.solverIterations == 0) w.settings.solverIterations = ws.substeps == 0 ? choice.iterations : 8;
    const double substepLength = ws.dt / double(w.settings.substeps);
    if (w.collision) {
        w.collision->settings().iterations = w.settings.solverIterations;
        w.collision->settings().restitutionThreshold =
            ws.restitutionThreshold ? *ws.restitutionThreshold
                                    : derivedRestitutionThreshold(length(ws.gravity), substepLength);
    }

    // Spin: angle += h * angular velocity for dynamic bodies with both
    // (bodies with shapes turn in the contact solver instead).
    for (std::size_t b = 0; b < n; ++b) {
        const Entity be = w.bodyEntity[b];
        if (reg.has<Radius>(be) || reg.has<Box>(be)) continue;
        const Angle* an = reg.tryGet<Angle>(w.bodyEntity[b]);
        const AngularVelocity* av = reg.tryGet<AngularVelocity>(w.bodyEntity[b]);
        if (!an || !av) continue;
        w.spinBody.push_back(std::uint32_t(b));
        w.angle.push_back(an->value);
        w.angularVelocity.push_back(av->value);
    }
    w.angleBackup.resize(w.angle.size());

    if (f.gravityOn) w.active.push_back("gravity");
    if (f.dragOn) w.active.push_back("drag");
    if (f.springsOn()) w.active.push_back("springs");
    if (f.attractorsOn()) w.active.push_back("attractors");
    if (f.boidsOn) w.active.push_back("boids");
    if (!w.spinBody.empty()) w.active.push_back("rotation");
    if (w.collision) w.active.push_back("collisions");

    w.x[0].assign(x0.begin(), x0.end());
    w.v[0].assign(v0.begin(), v0.end());
    w.x[1].assign(2 * n, 0.0);
    w.v[1].assign(2 * n, 0.0);
    if (w.settings.substeps > 1) {
        w.backupX.assign(2 * n, 0.0);
        w.backupV.assign(2 * n, 0.0);
    }
    w.setIntegratorKind(*kind);
    w.stats.stages.reserve(8);
    w.stats.systems.reserve(std::size_t(detail::ForceSystem::Count));
    return World(std::move(impl));
}

Result<void> World::step() {
    WorldImpl& w = *impl_;
    detail::ForceModel& f = w.model;
    const bool timed = w.profiling;
    f.profiling = timed;
    f.resetTimers();
    const Clock::time_point t0 = timed ? Clock::now() : Clock::time_point{};
    const std::size_t m = 2 * f.n;
    const int substeps = w.settings.substeps;
    const double h = w.settings.dt / double(substeps);
    if (substeps > 1) {
        std::copy(w.x[w.current].begin(), w.x[w.current].end(), w.backupX.begin());
        std::copy(w.v[w.current].begin(), w.v[w.current].end(), w.backupV.begin());
    }
    std::copy(w.angle.begin(), w.angle.end(), w.angleBackup.begin());
    int evaluations = 0;
    bool verifiedFinite = false;  // the last substep's integrator pass checked x, v
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
        verifiedFinite = w.integrator->lastStepVerifiedFinite();
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
    const bool stateChecked = verifiedFinite && !contacts;
    const bool finite = (stateChecked || (allFinite(w.xs(), m) && allFinite(w.vs(), m))) &&
                        allFinite(w.angle.data(), w.angle.size()) &&
                        (!contacts || (allFinite(contacts->angles().data(), contacts->angles().size()) &&
                                       allFinite(contacts->angularVelocities().data(),
                                                 contacts->angularVelocities().size())));
    const Clock::time_point t2 = timed ? Clock::now() : Clock::time_point{};
    if (!finite) {
        std::string message = w.findNonFinite(w.stats.step + 1);
        // Undo: the step's input is still in the other buffer (one
        // substep) or in the backup (several).
        if (substeps == 1) {
            w.current = 1 - w.current;
        } else {
            std::copy(w.backupX.begin(), w.backupX.end(), w.x[w.current].begin());
            std::copy(w.backupV.begin(), w.backupV.end(), w.v[w.current].begin());
        }
        std::copy(w.angleBackup.begin(), w.angleBackup.end(), w.angle.begin());
        if (contacts) contacts->restoreRotation(w.collisionAngleBackup, w.collisionSpinBackup);
        return Error{message};
    }
    w.settings.time += w.settings.dt;
    ++w.stats.step;
    w.stats.forceEvaluations = evaluations;
    w.stats.contactCount = contacts ? contacts->contacts().size() : 0;
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

void World::writeBack(Scene& scene) const {
    const WorldImpl& w = *impl_;
    Registry& reg = scene.registry;
    const double* x = w.xs();
    const double* v = w.vs();
    for (std::size_t b = 0; b < w.bodyEntity.size(); ++b) {
        const Entity e = w.bodyEntity[b];
        if (!reg.alive(e)) continue;  // stale: the scene is not the one built from
        reg.emplace<Position>(e, Position{{x[2 * b], x[2 * b + 1]}});
        const Vec2 vel{v[2 * b], v[2 * b + 1]};
        // A body that had no velocity component gets one only once it moves.
        if (reg.has<Velocity>(e) || vel.x != 0.0 || vel.y != 0.0) reg.emplace<Velocity>(e, Velocity{vel});
    }
    for (std::size_t s = 0; s < w.spinBody.size(); ++s) {
        const Entity e = w.bodyEntity[w.spinBody[s]];
        if (reg.alive(e)) reg.emplace<Angle>(e, Angle{w.angle[s]});
    }
    if (const collision::CollisionSystem* contacts = w.collision.get()) {
        for (std::size_t c = 0; c < contacts->colliderCount(); ++c) {
            const Entity e = contacts->collider(c).entity;
            if (contacts->collider(c).body < 0 || !reg.alive(e)) continue;
            // Like velocity: written once the body turns, so a resumed run
            // starts from the same rotation.
            const double angle = contacts->angle(c), spin = contacts->angularVelocity(c);
            if (reg.has<Angle>(e) || angle != 0.0) reg.emplace<Angle>(e, Angle{angle});
            if (reg.has<AngularVelocity>(e) || spin != 0.0) reg.emplace<AngularVelocity>(e, AngularVelocity{spin});
        }
    }
    scene.world.time = w.settings.time;
}

const WorldSettings& World::settings() const { return impl_->settings; }

Result<void> World::setIntegrator(std::string_view name) {
    const auto kind = detail::integratorKind(name);
    if (!kind) return Error{"unknown integrator \"" + std::string(name) + "\""};
    impl_->setIntegratorKind(*kind);
    return {};
}

Result<void> World::setSpringAnchor(Entity spring, Vec2 anchor) {
    for (detail::SpringData& s : impl_->model.springs)
        if (s.entity == spring && s.b == detail::kNoBody) {
            s.fx = anchor.x;
            s.fy = anchor.y;
            return {};
        }
    return Error{"no anchored spring with that entity in this world"};
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
            if (col.body < 0) continue;
            const double spin = contacts->angularVelocity(c);
            e.kinetic += 0.5 * collision::momentOfInertia(col.shape, col.mass) * spin * spin;
        }
    }
    e.springs = f.springEnergy(x);
    e.attractors = f.attractorEnergy(x);
    return e;
}

std::span<const ContactRecord> World::contacts() const {
    return impl_->collision ? impl_->collision->contacts() : std::span<const ContactRecord>{};
}

std::vector<StiffnessHint> World::stiffnessHints() const {
    const WorldImpl& w = *impl_;
    const detail::ForceModel& f = w.model;
    std::vector<StiffnessHint> hints;
    if (detail::isImplicit(w.kind)) return hints;
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
        auto it = limitByZeta.find(zeta);
        if (it == limitByZeta.end()) it = limitByZeta.emplace(zeta, detail::stabilityLimit(w.kind, zeta)).first;
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

std::optional<PileHint> World::pileHint() const {
    const WorldImpl& w = *impl_;
    const ContactSettingsChoice& c = w.contactChoice;
    if (!w.collision || c.stackDepth < 2 || !(c.diameter > 0.0)) return std::nullopt;
    const double limit = 0.02 * c.diameter;  // the pile goal: overlap under 2% of a diameter
    const int substeps = w.settings.substeps;
    const double overlap = expectedPileOverlap(c.stackDepth, c.gravity, w.settings.dt / double(substeps));
    if (!(overlap > limit)) return std::nullopt;
    PileHint hint;
    hint.stackDepth = c.stackDepth;
    hint.expectedOverlap = overlap;
    hint.diameter = c.diameter;
    hint.substeps = substeps;
    hint.substepsNeeded = 16;
    for (int s = substeps + 1; s <= 16; ++s)
        if (expectedPileOverlap(c.stackDepth, c.gravity, w.settings.dt / double(s)) <= limit) {
            hint.substepsNeeded = s;
            break;
        }
    return hint;
}

std::string PileHint::message() const {
    char text[320];
    std::snprintf(text, sizeof text,
                  "piles up to %d bodies deep: expected sinkage %.0f mm (%.1f%% of a %.2g m diameter) at %d substep%s; "
                  "%d substeps would hold it under 2%%",
                  stackDepth, 1e3 * expectedOverlap, 100.0 * expectedOverlap / diameter, diameter, substeps,
                  substeps == 1 ? "" : "s", substepsNeeded);
    return text;
}

Vec2 World::probeForce(Vec2 point, Vec2) const {
    // A 1 kg probe: force in newtons equals acceleration in m/s^2. The same
    // fieldAt() the attractor system runs per body.
    return impl_->model.fieldAt(point.x, point.y, kNoBody, impl_->xs());
}

std::size_t World::bodyCount() const { return impl_->bodyEntity.size(); }
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

} // namespace stepwise
