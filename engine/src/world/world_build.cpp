// World::build: compiles a Scene into the packed arrays World::step reads
// (world.cpp), one function per system. The parts run in the order a
// refused scene hears of its problems: settings, bodies, springs, polygons,
// joints, then the settings a saved run recorded.

#include "world/world_impl.hpp"
#include "world/world_collisions.hpp"

#include "templates.hpp"

#include "stepwise/components.hpp"
#include "stepwise/world_fields.hpp"

#include <atomic>
#include <cmath>
#include <optional>
#include <unordered_map>

namespace stepwise {

using detail::entityLabel;
using detail::kNoBody;

namespace {

/// Entity -> its place in the state vector, or kNoBody (static, or no
/// position).
struct BodyIndex {
    std::unordered_map<std::uint32_t, std::uint32_t> ofSlot;  ///< entity index -> body

    std::uint32_t of(Entity e) const {
        const auto it = ofSlot.find(e.index);
        return it == ofSlot.end() ? kNoBody : it->second;
    }
};

/// The bodies' starting positions and velocities, interleaved (x0, y0, ...).
struct InitialState {
    std::vector<double> x, v;
};

bool isPointEmitter(const Registry& reg, Entity e) {
    return reg.has<Emitter>(e) && !reg.has<Radius>(e) && !reg.has<Box>(e) && !reg.has<Polygon>(e) &&
           !reg.has<Capsule>(e);
}

std::atomic<std::uint64_t> buildCount{0};
std::atomic<std::uint64_t> runCount{0};  // WorldLayout::run

/// Dynamic bodies (a position and not static), in scene order: the state
/// vector's order, stable across save and load.
std::optional<Error> compileBodies(const Registry& reg, WorldImpl& w, BodyIndex& bodies, InitialState& start) {
    const std::vector<Entity>& order = reg.entities();
    std::vector<double> mass;
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Name* name = reg.tryGet<Name>(e);
        const Position* p = reg.tryGet<Position>(e);
        if (!p) continue;
        // A template is a prefab; an emitter without a shape, a point.
        if (reg.count<Template>() != 0 && (detail::inTemplate(reg, e) || isPointEmitter(reg, e))) continue;
        const Static* st = reg.tryGet<Static>(e);
        if (st && st->value) continue;
        const Velocity* vel = reg.tryGet<Velocity>(e);
        const Mass* m = reg.tryGet<Mass>(e);
        // A compound body without a mass weighs what its shapes' densities
        // and areas give (with one, that sum is scaled to it).
        // (An empty list is refused by checkPolygons, naming the shapes.)
        const Shapes* compound = m ? nullptr : reg.tryGet<Shapes>(e);
        if (compound && compound->items.empty()) compound = nullptr;
        const double mv = m ? m->value : compound ? compoundMassProperties(*compound, std::nullopt).mass : 1.0;
        if (const Kinematic* k = reg.tryGet<Kinematic>(e); k && k->value) {
            w.isKinematic.resize(w.bodyEntity.size() + 1, 0);
            w.isKinematic.back() = 1;
            w.kinematicBody.push_back(std::uint32_t(w.bodyEntity.size()));
            w.kinematicVelocity.push_back(vel ? vel->value.x : 0.0);
            w.kinematicVelocity.push_back(vel ? vel->value.y : 0.0);
        }
        if (!(mv > 0.0) || !std::isfinite(mv))
            return Error{entityLabel(i, name ? &name->value : nullptr) + ": mass must be a finite number > 0"};
        bodies.ofSlot.emplace(e.index, std::uint32_t(w.bodyEntity.size()));
        w.bodyEntity.push_back(e);
        w.bodySceneIndex.push_back(std::uint32_t(i));
        w.bodyName.push_back(name ? name->value : std::string());
        start.x.push_back(p->value.x);
        start.x.push_back(p->value.y);
        start.v.push_back(vel ? vel->value.x : 0.0);
        start.v.push_back(vel ? vel->value.y : 0.0);
        mass.push_back(mv);
    }
    w.bodyOfSlot.assign(reg.slotCount(), detail::kNoBody);
    for (std::size_t b = 0; b < w.bodyEntity.size(); ++b) w.bodyOfSlot[w.bodyEntity[b].index] = std::uint32_t(b);
    detail::ForceModel& f = w.model;
    f.n = w.bodyEntity.size();
    f.mass = std::move(mass);
    f.invMass.resize(f.n);
    for (std::size_t b = 0; b < f.n; ++b) f.invMass[b] = 1.0 / f.mass[b];
    // A kinematic body keeps its mass in the model (the implicit
    // integrators' mass matrix must stay invertible) but takes no force:
    // its inverse mass is 0, and the step sets its state after each substep.
    if (!w.isKinematic.empty()) w.isKinematic.resize(f.n, 0);
    for (const std::uint32_t k : w.kinematicBody) f.invMass[k] = 0.0;
    return std::nullopt;
}

/// Uniform gravity (only when there is something for it to pull), and the
/// constants of the attractors' pull.
void compileGravity(const WorldSettings& ws, detail::ForceModel& f) {
    f.gravityOn = f.n > 0 && (ws.gravity.x != 0.0 || ws.gravity.y != 0.0);
    f.gx = ws.gravity.x;
    f.gy = ws.gravity.y;
    f.G = ws.G;
    f.theta = ws.theta;
}

/// Drag: dense per-body rates, kept only if some body has b > 0.
void compileDrag(const Registry& reg, WorldImpl& w) {
    detail::ForceModel& f = w.model;
    f.dragB.assign(f.n, 0.0);
    for (std::size_t b = 0; b < f.n; ++b)
        if (const Drag* d = reg.tryGet<Drag>(w.bodyEntity[b]); d && d->value > 0.0) {
            f.dragB[b] = d->value;
            f.dragOn = true;
        }
    if (f.dragOn) {
        f.dragRate.resize(f.n);
        for (std::size_t b = 0; b < f.n; ++b) f.dragRate[b] = f.dragB[b] * f.invMass[b];
    } else {
        f.dragB.clear();
    }
}

/// One end of a spring: a dynamic body, or a fixed point (kNoBody).
struct SpringEnd {
    std::uint32_t body = kNoBody;
    Vec2 point;
};

/// The end `other` names (the spring's field `key`), or why it cannot be one.
std::optional<Error> resolveSpringEnd(const Registry& reg, const BodyIndex& bodies, Entity other,
                                      const std::string& label, const char* key, SpringEnd& end) {
    if (!reg.alive(other)) return Error{label + ": spring " + key + ": the entity it named was deleted"};
    const Position* p = reg.tryGet<Position>(other);
    if (!p) {
        const Name* endName = reg.tryGet<Name>(other);
        return Error{label + ": spring " + key + ": entity \"" + (endName ? endName->value : std::string()) +
                     "\" has no position"};
    }
    end.body = bodies.of(other);
    end.point = p->value;
    return std::nullopt;
}

/// Springs, in scene order. A static or anchored end is a fixed point; the
/// model keeps the dynamic end as `a`.
std::optional<Error> compileSprings(const Registry& reg, const BodyIndex& bodies, WorldImpl& w) {
    const std::vector<Entity>& order = reg.entities();
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Entity e = order[i];
        const Spring* s = reg.tryGet<Spring>(e);
        if (!s || detail::inTemplate(reg, e)) continue;
        const Name* name = reg.tryGet<Name>(e);
        const std::string label = entityLabel(i, name ? &name->value : nullptr);
        SpringEnd a, b;
        if (std::optional<Error> refused = resolveSpringEnd(reg, bodies, s->a, label, "a", a)) return refused;
        if (!s->b.isNull()) {
            if (std::optional<Error> refused = resolveSpringEnd(reg, bodies, s->b, label, "b", b)) return refused;
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
        d.rest = s->restLength ? *s->restLength : length(a.point - b.point);
        d.sceneIndex = std::uint32_t(i);
        d.entity = e;
        w.model.springs.push_back(d);
        w.springName.push_back(name && !name->value.empty() ? name->value : "entity " + std::to_string(i));
    }
    return std::nullopt;
}

/// Attractors: dynamic ones are n-body participants, static ones fixed.
void compileAttractors(const Registry& reg, const BodyIndex& bodies, double G, detail::ForceModel& f) {
    for (const Entity e : reg.entities()) {
        const Attractor* at = reg.tryGet<Attractor>(e);
        const Position* p = reg.tryGet<Position>(e);
        if (!at || !p || detail::inTemplate(reg, e)) continue;
        const Mass* m = reg.tryGet<Mass>(e);
        detail::AttractorData d;
        d.body = bodies.of(e);
        d.px = p->value.x;
        d.py = p->value.y;
        d.mass = m ? m->value : 1.0;
        d.gm = G * d.mass;
        d.eps2 = at->softening * at->softening;
        f.attractors.push_back(d);
    }
}

/// Boids: dynamic bodies with a boid component.
void compileBoids(const Registry& reg, WorldImpl& w) {
    detail::ForceModel& f = w.model;
    for (std::size_t b = 0; b < f.n; ++b) {
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
}

/// Values within every field's range can still be ones no step can take:
/// the speed they give a body in one step passes the kMaxSpeed a run holds
/// (World::step's check), so the first step would fail with exit 3. Such a
/// scene is refused here, naming the value: gravity over one step, and a
/// spin at a shape's farthest point.
std::optional<Error> checkFirstStepSpeeds(const WorldImpl& w) {
    const double dt = w.settings.dt;
    const double g = length(w.settings.gravity);
    if (!w.bodyEntity.empty() && g * dt > kMaxSpeed)
        return Error{formatNumber(g) + " m/s^2 gives a body " + formatNumber(g * dt) + " m/s in one step of " +
                         formatNumber(dt) + " s, past the " + formatNumber(kMaxSpeed) +
                         " m/s a run holds; at this dt gravity may be at most " + formatNumber(kMaxSpeed / dt) +
                         " m/s^2",
                     "world.gravity"};
    if (!w.collision) return std::nullopt;
    const collision::CollisionSystem& c = *w.collision;
    for (std::size_t i = 0; i < c.colliderCount(); ++i) {
        const std::int32_t b = c.collider(i).body;
        if (b < 0) continue;
        const double spin = std::abs(c.angularVelocity(i)), reach = c.maxExtent(i);
        if (!(spin * reach > kMaxSpeed)) continue;
        const std::size_t body = std::size_t(b);
        return Error{detail::entityLabel(w.bodySceneIndex[body], &w.bodyName[body]) + ": angular_velocity: " +
                     formatNumber(spin) + " rad/s moves its farthest point (" + formatNumber(reach) +
                     " m from its centre of mass) at " + formatNumber(spin * reach) + " m/s, past the " +
                     formatNumber(kMaxSpeed) + " m/s a run holds"};
    }
    return std::nullopt;
}

/// The loader refuses bad outlines (capsules without a segment, chains
/// with too few or repeated points or on a moving body), but a
/// scene built in code or edited in the editor reaches here unchecked.
std::optional<Error> checkPolygons(const Registry& reg) {
    for (std::size_t i = 0; i < reg.entities().size(); ++i)
        if (std::optional<Error> problem = detail::shapeProblem(reg, i)) return problem;
    return std::nullopt;
}

/// Substeps and solver iterations the level left to the engine
/// (world.hpp: chooseContactSettings); settings() reports what runs. A run
/// that saved its state recorded what it ran (solver_state.chosen): that is
/// kept, so a resume steps exactly as the long run (bodies that came or went
/// since would not change it).
std::optional<Error> chooseSolverCounts(const Scene& scene, const SystemSwitches& switches, WorldImpl& w) {
    const WorldSettings& ws = scene.world;
    const ContactSettingsChoice choice = chooseContactSettings(scene, switches);
    w.contactChoice = choice;
    const std::optional<ChosenSettings> recorded = scene.solverState ? scene.solverState->chosen : std::nullopt;
    // The stiffness cap follows the structure the run started from (a deep
    // column standing); a resume keeps it whatever the bodies have become.
    w.hertzFractionRecorded = recorded && recorded->contactHertzFraction;
    if (w.hertzFractionRecorded) {
        w.contactChoice.hertzFraction = *recorded->contactHertzFraction;
        w.contactChoice.contactHertz = recorded->contactHertz.value_or(kContactHertz);
    }
    if (recorded && (recorded->substeps < 1 || recorded->solverIterations < 1))
        return Error{"solver_state.chosen: substeps and solver_iterations must be integers >= 1"};
    if (ws.substeps == 0) w.settings.substeps = recorded ? recorded->substeps : choice.substeps;
    if (ws.solverIterations == 0)
        w.settings.solverIterations = recorded ? recorded->solverIterations : ws.substeps == 0 ? choice.iterations : 8;
    w.substepsGiven = ws.substeps != 0;
    w.iterationsGiven = ws.solverIterations != 0;
    w.settingsSource = ws.substeps != 0 && ws.solverIterations != 0 ? World::SettingsSource::Given
                       : recorded                                     ? World::SettingsSource::Recorded
                                                                      : World::SettingsSource::Chosen;
    return std::nullopt;
}

/// Shapes and joints: the collision stages, only when some entity has one;
/// then the contact and joint solvers' settings (derivedRestitutionThreshold
/// when the level gives none).
std::optional<Error> compileCollisions(const Scene& scene, const SystemSwitches& switches, const BodyIndex& bodies,
                                       WorldImpl& w) {
    Result<std::unique_ptr<collision::CollisionSystem>> built =
        detail::buildCollisions(scene, [&bodies](Entity e) { return bodies.of(e); }, kNoBody, switches.collisions);
    if (!built) return built.failure();
    w.collision = std::move(*built);
    if (std::optional<Error> refused = chooseSolverCounts(scene, switches, w)) return refused;
    // Copies an emitter adds join the contact solver in place: the system
    // exists from the start, empty until the first copy.
    if (!w.collision && scene.registry.count<Emitter>() != 0 && switches.collisions)
        w.collision = std::make_unique<collision::CollisionSystem>();
    if (!w.collision) return std::nullopt;
    const WorldSettings& ws = w.settings;
    const double substepLength = ws.dt / double(w.settings.substeps);
    w.collision->settings().iterations = w.settings.solverIterations;
    // From the scene's structure, whatever substeps the level gives.
    w.collision->settings().hertzFraction = w.contactChoice.hertzFraction;
    w.collision->settings().contactHertz = w.contactChoice.contactHertz;
    w.collision->settings().oneColourOrder = w.contactChoice.hertzFraction < 0.25;
    if (ws.jointHz) w.collision->jointSettings().hertz = *ws.jointHz;
    if (ws.jointDampingRatio) w.collision->jointSettings().dampingRatio = *ws.jointDampingRatio;
    w.collision->settings().restitutionThreshold =
        ws.restitutionThreshold ? *ws.restitutionThreshold
                                : derivedRestitutionThreshold(length(ws.gravity), substepLength);
    return std::nullopt;
}

/// Spin: angle += h * angular velocity for dynamic bodies with both (bodies
/// with shapes or joints turn in the contact solver instead).
void compileSpin(const Registry& reg, WorldImpl& w) {
    const std::size_t n = w.bodyEntity.size();
    std::vector<bool> turnedBySolver(n, false);
    if (w.collision)
        for (std::size_t c = 0; c < w.collision->colliderCount(); ++c)
            if (w.collision->collider(c).body >= 0) turnedBySolver[std::size_t(w.collision->collider(c).body)] = true;
    for (std::size_t b = 0; b < n; ++b) {
        if (turnedBySolver[b]) continue;
        const Angle* an = reg.tryGet<Angle>(w.bodyEntity[b]);
        const AngularVelocity* av = reg.tryGet<AngularVelocity>(w.bodyEntity[b]);
        if (!an || !av) continue;
        w.spinBody.push_back(std::uint32_t(b));
        w.angle.push_back(an->value);
        w.angularVelocity.push_back(av->value);
    }
    w.angleBackup.resize(w.angle.size());
}

/// Sleeping islands (world/islands.hpp): who may sleep, each collider's
/// extent, and the bodies that must never rest.
void compileSleep(const WorldSettings& ws, WorldImpl& w) {
    const detail::ForceModel& f = w.model;
    const std::size_t n = f.n;
    w.sleep.resize(n);
    // A dynamic attractor moves the field every body feels, so nothing is
    // ever still for long: no sleeping then.
    bool movingField = false;
    for (const detail::AttractorData& a : f.attractors) movingField = movingField || a.body != kNoBody;
    w.sleep.enabled = ws.sleep && !movingField;
    w.sleep.velocity = ws.sleepVelocity;
    w.sleep.time = ws.sleepTime;
    w.colliderOfBody.assign(n, -1);
    if (w.collision)
        for (std::size_t c = 0; c < w.collision->colliderCount(); ++c)
            if (const std::int32_t body = w.collision->collider(c).body; body >= 0) {
                // A compound body's hub stands for the body (its shapes
                // share its rotation).
                if (w.collision->collider(c).hub >= 0) continue;
                w.colliderOfBody[std::size_t(body)] = std::int32_t(c);
                // A shapeless jointed body turns like a disc of kShapelessRadius.
                w.sleep.extent[std::size_t(body)] =
                    w.collision->collider(c).solverOnly && !w.collision->isHub(c) ? detail::kShapelessRadius
                                                                                  : w.collision->maxExtent(c);
            }
    // Boids steer by their neighbours and never rest; a shapeless body that
    // turns (its spin is constant: nothing applies torque) would stop turning.
    for (const std::uint32_t b : f.boids.body) w.sleep.restless[b] = 1;
    for (std::size_t k = 0; k < w.spinBody.size(); ++k)
        if (w.angularVelocity[k] != 0.0) w.sleep.restless[w.spinBody[k]] = 1;
    if (w.collision)
        w.collision->setSleepSource(&w.sleep.asleep, [impl = &w](std::uint32_t body) { impl->sleep.wake(body); });
    w.sleptUnder = w.settings;
}

/// The state buffers (the start in buffer 0), the integrator and the
/// stats' room, so that a step allocates nothing.
void allocateState(WorldImpl& w, const InitialState& start, detail::IntegratorKind kind) {
    const std::size_t n = w.model.n;
    w.x[0].assign(start.x.begin(), start.x.end());
    w.v[0].assign(start.v.begin(), start.v.end());
    w.x[1].assign(2 * n, 0.0);
    w.v[1].assign(2 * n, 0.0);
    if (w.settings.substeps > 1) {
        w.backupX.assign(2 * n, 0.0);
        w.backupV.assign(2 * n, 0.0);
    }
    w.setIntegratorKind(kind);
    w.stats.stages.reserve(8);
    w.stats.systems.reserve(std::size_t(detail::ForceSystem::Count));
}

} // namespace

/// The names activeSystems() reports, in pipeline order.
void WorldImpl::listActiveSystems() {
    WorldImpl& w = *this;
    const detail::ForceModel& f = w.model;
    w.active.clear();
    if (f.gravityOn) w.active.push_back("gravity");
    if (f.dragOn) w.active.push_back("drag");
    if (f.springsOn()) w.active.push_back("springs");
    if (f.attractorsOn()) w.active.push_back("attractors");
    if (f.boidsOn) w.active.push_back("boids");
    if (!w.spinBody.empty()) w.active.push_back("rotation");
    if (w.collision && w.collision->hasShapes()) w.active.push_back("collisions");
    if (w.collision && w.collision->hasJoints()) w.active.push_back("joints");
}

/// The entities behind each state array, for saveState/restoreState.
std::shared_ptr<const WorldLayout> WorldImpl::makeLayout() const {
    const WorldImpl& w = *this;
    auto layout = std::make_shared<WorldLayout>();
    layout->bodies = w.bodyEntity;
    for (const std::uint32_t b : w.spinBody) layout->spinBodies.push_back(w.bodyEntity[b]);
    if (w.collision) {
        for (std::size_t c = 0; c < w.collision->colliderCount(); ++c) {
            layout->colliders.push_back(w.collision->collider(c).entity);
            layout->colliderParts.push_back(w.collision->collider(c).part);
            layout->colliderMoves.push_back(w.collision->collider(c).body >= 0 ? 1 : 0);
        }
        for (const joints::JointConstraint& j : w.collision->jointConstraints()) layout->joints.push_back(j.entity);
    }
    layout->registry = w.registry;
    layout->run = w.run;
    for (const EmitterRun& e : w.emitters) layout->emitters.emplace_back(e.entity, e.params);
    return layout;
}

std::uint64_t worldBuildCount() { return buildCount.load(); }

bool SystemSwitches::disable(std::string_view system) {
    for (auto [name, on] : {std::pair<std::string_view, bool*>{"gravity", &gravity}, {"drag", &drag}, {"springs", &springs},
                            {"attractors", &attractors}, {"boids", &boids}, {"collisions", &collisions}})
        if (name == system) {
            *on = false;
            return true;
        }
    return false;
}

Result<World> World::build(const Scene& scene, const SystemSwitches& switches) {
    // A scene built in code or edited reaches here unchecked by the loader:
    // the settings table checks it, in the words a file would get.
    if (std::optional<Error> refused = worldSettingsProblem(scene.world)) return std::move(*refused);
    const std::optional<detail::IntegratorKind> kind = detail::integratorKind(scene.world.integrator);
    // The table's choices are integratorNames(): only a mismatch between the
    // two lists could get here.
    if (!kind) return Error{"world.integrator: no integrator is named \"" + scene.world.integrator + "\""};

    auto impl = std::make_unique<WorldImpl>();
    WorldImpl& w = *impl;
    w.settings = scene.world;
    w.switches = switches;
    w.sceneWorld = scene.world;
    if (!switches.gravity) w.settings.gravity = {0.0, 0.0};
    const Registry& reg = scene.registry;
    BodyIndex bodies;
    InitialState start;
    if (std::optional<Error> refused = compileBodies(reg, w, bodies, start)) return std::move(*refused);
    compileGravity(w.settings, w.model);
    if (switches.drag) compileDrag(reg, w);
    if (switches.springs)
        if (std::optional<Error> refused = compileSprings(reg, bodies, w)) return std::move(*refused);
    if (switches.attractors) compileAttractors(reg, bodies, scene.world.G, w.model);
    if (switches.boids) compileBoids(reg, w);
    if (std::optional<Error> refused = checkPolygons(reg)) return std::move(*refused);
    if (std::optional<Error> refused = compileCollisions(scene, switches, bodies, w)) return std::move(*refused);
    compileSpin(reg, w);
    if (std::optional<Error> refused = checkFirstStepSpeeds(w)) return std::move(*refused);
    compileSleep(w.settings, w);
    w.listActiveSystems();
    allocateState(w, start, *kind);
    if (std::optional<Error> refused = detail::checkFirstStepForces(w, *kind)) return std::move(*refused);
    if (std::optional<Error> refused = compileEmitters(scene, w)) return std::move(*refused);
    if (w.registry) w.run = ++runCount;
    w.layout = w.makeLayout();
    ++buildCount;
    if (w.collision && w.collision->hasSensors()) w.collision->initSensors(detail::asVec2(w.xs(), w.model.n));

    World world(std::move(impl));
    if (scene.solverState) world.setSolverState(*scene.solverState);
    return world;
}

/// As checkFirstStepSpeeds, for the springs and attractors at the start:
/// a body pulled at a value no step can take (an attractor of 1e300 kg, two
/// bodies at one point under an unsoftened attractor, a spring of 1e300
/// N/m stretched) is refused, naming it. Needs the state allocated; one
/// force evaluation, only when the scene has springs or attractors. Only
/// for fixed explicit steps: an implicit step solves for the velocity the
/// pull leaves (a stiff spring holds its length), and dopri5 shortens its
/// steps to the pull.
std::optional<Error> detail::checkFirstStepForces(const WorldImpl& w, IntegratorKind kind) {
    if (!w.model.springsOn() && !w.model.attractorsOn()) return std::nullopt;
    if (isImplicit(kind) || kind == IntegratorKind::Dopri5) return std::nullopt;
    const std::size_t n = w.model.n;
    std::vector<double> a(2 * n);
    w.model.accelerations(w.xs(), w.vs(), a.data());
    const double dt = w.settings.dt;
    for (std::size_t b = 0; b < n && b < w.bodyName.size(); ++b) {
        const double pull = std::hypot(a[2 * b], a[2 * b + 1]);
        if (pull * dt <= kMaxSpeed) continue;
        const std::string by = w.model.springsOn() && w.model.attractorsOn() ? "springs and attractors"
                               : w.model.springsOn()                         ? "springs"
                                                                             : "attractors";
        return Error{"the " + by + " pull it at " + formatNumber(pull) + " m/s^2 at the start: " +
                         formatNumber(pull * dt) + " m/s in one step of " + formatNumber(dt) + " s, past the " +
                         formatNumber(kMaxSpeed) + " m/s a run holds",
                     entityLabel(w.bodySceneIndex[b], &w.bodyName[b])};
    }
    return std::nullopt;
}


std::optional<Error> detail::shapeProblem(const Registry& reg, std::size_t i) {
    const Entity e = reg.entities()[i];
    const auto label = [&] {
        const Name* name = reg.tryGet<Name>(e);
        return entityLabel(i, name ? &name->value : nullptr);
    };
    if (const Shapes* compound = reg.tryGet<Shapes>(e)) {
        for (std::size_t k = 0; k < compound->items.size(); ++k)
            if (std::optional<Error> problem = compoundShapeProblem(compound->items[k]))
                return Error{problem->message, label() + ": shapes/" + std::to_string(k) + "/" + problem->where};
        if (compound->items.empty() || compound->items.size() > 256)
            return Error{"expected 1 to 256 shapes, got " + std::to_string(compound->items.size()), label() + ": shapes"};
    }
    if (const Capsule* capsule = reg.tryGet<Capsule>(e); capsule && capsule->a == capsule->b)
        return Error{"a and b are the same point; a capsule needs a segment of non-zero length", label() + ": capsule.b"};
    if (const Chain* chain = reg.tryGet<Chain>(e)) {
        if (std::optional<Error> problem = chainProblem(chain->points, chain->loop))
            return Error{problem->message,
                         label() + ": chain.points" + (problem->where.empty() ? "" : "[" + problem->where + "]")};
        if (!(reg.has<Static>(e) && reg.tryGet<Static>(e)->value) &&
            !(reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value))
            return Error{kChainOnDynamicBody, label() + ": chain"};
    }
    const Polygon* poly = reg.tryGet<Polygon>(e);
    if (!poly) return std::nullopt;
    if (poly->radius && !(*poly->radius >= 0.0 && *poly->radius <= kMaxMagnitude))
        return Error{"expected a number in [0, " + formatNumber(kMaxMagnitude) + "], got " + formatNumber(*poly->radius),
                     label() + ": polygon.radius"};
    // Vertex 3 is named "polygon.vertices[3]".
    if (std::optional<Error> problem = polygonProblem(poly->vertices))
        return Error{problem->message,
                     label() + ": polygon.vertices" + (problem->where.empty() ? "" : "[" + problem->where + "]")};
    return std::nullopt;
}

} // namespace stepwise
