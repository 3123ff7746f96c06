// Edits the World takes in place, without a rebuild: what they change is
// exactly what a rebuild from the edited scene would (World::reload), and
// nothing else, so every other body keeps its state and warm start.

#include "world/world_collisions.hpp"
#include "world/world_impl.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_set>

namespace stepwise {

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// The state index of `body`, a dynamic, non-kinematic body of the World
/// that is alive in `scene`; else why an edit of it cannot go in place.
Result<std::size_t> editableBody(const WorldImpl& w, const Scene& scene, Entity body) {
    const std::uint32_t b = w.bodyIndexOf(body);
    if (b == detail::kNoBody) return Error{"not a dynamic body of this world"};
    if (!w.isKinematic.empty() && w.isKinematic[b]) return Error{"a kinematic body moves as its level says"};
    if (!scene.registry.alive(body)) return Error{"the body is not in the scene"};
    return std::size_t(b);
}

} // namespace

/// Whether a reload from `scene` (no solver state: chooseSolverCounts) would
/// run the settings this World runs; if so, takes the reload's choice (its
/// reasons and hints) as its own.
std::optional<Error> WorldImpl::keepChoiceFor(const Scene& scene, const SystemSwitches& switches) {
    const WorldSettings& ws = scene.world;
    const ContactSettingsChoice choice = chooseContactSettings(scene, switches);
    const int substeps = ws.substeps != 0 ? ws.substeps : choice.substeps;
    const int iterations = ws.solverIterations != 0 ? ws.solverIterations : ws.substeps == 0 ? choice.iterations : 8;
    // The stiffness the contacts get at these substeps: a heavier body may
    // raise what the rules ask for (contactHertz) past what the substeps
    // carry, and then nothing the solver runs changes.
    const auto stiffness = [&](const ContactSettingsChoice& c) {
        return std::min(c.contactHertz, c.hertzFraction * double(substeps) / settings.dt);
    };
    if (substeps != settings.substeps || iterations != settings.solverIterations ||
        !sameBits(choice.hertzFraction, contactChoice.hertzFraction) ||
        !sameBits(stiffness(choice), stiffness(contactChoice)))
        return Error{"the edit changes the settings the engine chooses"};
    contactChoice = choice;
    if (collision) collision->settings().contactHertz = choice.contactHertz;
    hertzFractionRecorded = false;
    if (settingsSource == World::SettingsSource::Recorded) settingsSource = World::SettingsSource::Chosen;
    return std::nullopt;
}

Result<void> World::settleChoice(const Scene& scene, const SystemSwitches& switches) {
    WorldImpl& w = *impl_;
    if (!w.choiceUnsettled) return {};
    if (std::optional<Error> other = w.keepChoiceFor(scene, switches)) return std::move(*other);
    w.choiceUnsettled = false;
    return {};
}

Result<void> World::setMass(const Scene& scene, Entity body) {
    WorldImpl& w = *impl_;
    const Result<std::size_t> index = editableBody(w, scene, body);
    if (!index) return index.failure();
    const std::size_t b = *index;
    detail::ForceModel& f = w.model;
    if (f.springsOn() || f.attractorsOn()) return Error{"springs and attractors act: a new mass is checked by a rebuild"};
    const Registry& reg = scene.registry;
    // The mass as the build reads it (compileBodies).
    const Mass* given = reg.tryGet<Mass>(body);
    const Shapes* compound = reg.tryGet<Shapes>(body);
    if (compound && compound->items.empty()) compound = nullptr;  // refused by a build (checkPolygons)
    const double mass = given ? given->value : compound ? compoundMassProperties(*compound, std::nullopt).mass : 1.0;
    if (!(std::isfinite(mass) && mass > 0.0)) return Error{"mass must be a finite number > 0"};
    w.choiceUnsettled = true;  // checked once, before the next step (settleChoice)
    if (sameBits(f.mass[b], mass)) return {};

    f.mass[b] = mass;
    f.invMass[b] = 1.0 / mass;
    if (f.dragOn) f.dragRate[b] = f.dragB[b] * f.invMass[b];
    if (const std::int32_t c = w.colliderOfBody[b]; c >= 0 && w.collision) {
        const collision::Collider& col = w.collision->collider(std::size_t(c));
        // Inertia as the colliders were made (world_collisions.cpp): a
        // compound body's from its shapes, a shapeless one's a small disc's,
        // a shape's from the shape (setMass).
        double inertia = 0.0;
        if (col.part == collision::Collider::kHubPart && compound)
            inertia = compoundMassProperties(*compound, given ? std::optional<double>(given->value) : std::nullopt).inertia;
        else if (col.solverOnly)
            inertia = 0.5 * mass * detail::kShapelessRadius * detail::kShapelessRadius;
        w.collision->setMass(std::size_t(c), mass, inertia);
    }
    w.sleep.wake(std::uint32_t(b));  // as reload's wakeEdited: a changed mass wakes its island
    w.sleepChanged();
    return {};
}

Result<void> World::turnBody(const Scene& scene, Entity body) {
    WorldImpl& w = *impl_;
    const Result<std::size_t> index = editableBody(w, scene, body);
    if (!index) return index.failure();
    const std::size_t b = *index;
    const Registry& reg = scene.registry;
    const double angle = reg.has<Angle>(body) ? reg.tryGet<Angle>(body)->value : 0.0;
    const double spin = reg.has<AngularVelocity>(body) ? reg.tryGet<AngularVelocity>(body)->value : 0.0;
    if (!std::isfinite(angle) || !std::isfinite(spin)) return Error{"an angle and a spin must be finite"};
    // Where the build keeps the body's turn: its collider (the contact
    // solver turns it), else the spin list (a shapeless body with both an
    // angle and a spin). A body with neither takes a rebuild.
    const std::int32_t c = w.colliderOfBody[b];
    std::size_t spinSlot = w.spinBody.size();
    if (c < 0) {
        spinSlot = std::size_t(std::find(w.spinBody.begin(), w.spinBody.end(), std::uint32_t(b)) - w.spinBody.begin());
        if (spinSlot == w.spinBody.size() || !reg.has<Angle>(body) || !reg.has<AngularVelocity>(body))
            return Error{"the body has no turn of its own in this world"};
    }
    w.choiceUnsettled = true;  // checked once, before the next step (settleChoice)
    const bool same = c >= 0 ? sameBits(w.collision->angle(std::size_t(c)), angle) &&
                                   sameBits(w.collision->angularVelocity(std::size_t(c)), spin)
                             : sameBits(w.angle[spinSlot], angle) && sameBits(w.angularVelocity[spinSlot], spin);
    if (same) return {};
    if (c >= 0) {
        w.collision->setRotation(std::size_t(c), angle, spin);
    } else {
        w.angle[spinSlot] = angle;
        w.angularVelocity[spinSlot] = spin;
    }
    w.sleep.wake(std::uint32_t(b));  // as reload's wakeEdited: a turned body wakes its island
    w.sleepChanged();
    return {};
}

Result<void> World::reshapeBody(const Scene& scene, const SystemSwitches& switches, Entity body) {
    WorldImpl& w = *impl_;
    const Result<std::size_t> index = editableBody(w, scene, body);
    if (!index) return index.failure();
    const std::size_t b = *index;
    const Registry& reg = scene.registry;
    if (!w.collision || !switches.collisions) return Error{"no contact solver holds the shape"};
    const std::int32_t c = w.colliderOfBody[b];
    if (c < 0 || reg.has<Shapes>(body) || reg.has<Chain>(body)) return Error{"only a body's one shape is reshaped in place"};
    const collision::Collider& old = w.collision->collider(std::size_t(c));
    if (old.solverOnly || old.hub >= 0) return Error{"only a body's one shape is reshaped in place"};
    const std::size_t at = w.bodySceneIndex[b];
    if (at >= reg.entities().size() || reg.entities()[at] != body) return Error{"the scene's order changed"};
    if (std::optional<Error> problem = detail::shapeProblem(reg, at)) return std::move(*problem);
    // The collider as a build would make it now.
    detail::ShapeStorage storage;
    std::vector<collision::CollisionSystem::ColliderAdd> made;
    detail::collidersFor(reg, body, [b](Entity) { return std::uint32_t(b); }, detail::kNoBody, storage, made);
    if (made.size() != 1) return Error{"the body's shape is not one a build gives a collider"};
    const collision::Collider& fresh = made.front().collider;
    // A shape whose centre of mass moved (a polygon's outline, a capsule's
    // ends off centre) moves the body's centre, and a sensor is another
    // kind of shape: a rebuild.
    if (fresh.shape.kind == collision::ShapeKind::Plane || fresh.sensor != old.sensor ||
        !sameBits(fresh.centreOfMass.x, old.centreOfMass.x) || !sameBits(fresh.centreOfMass.y, old.centreOfMass.y))
        return Error{"the edit moves the body's centre of mass or changes its kind of shape"};
    w.choiceUnsettled = true;  // checked once, before the next step (settleChoice)
    w.collision->reshape(std::size_t(c), fresh, made.front().filter);
    w.sleep.extent[b] = w.collision->maxExtent(std::size_t(c));
    w.sleep.wake(std::uint32_t(b));  // as reload's wakeEdited: a changed shape wakes its island
    w.sleepChanged();
    return {};
}

namespace {

bool isOn(const Static* s) { return s && s->value; }
bool isOn(const Kinematic* k) { return k && k->value; }

/// How far a body's shapes reach from its position, metres.
double reachFromPosition(const Registry& reg, Entity e) {
    double reach = 0.0;
    if (const Radius* r = reg.tryGet<Radius>(e)) reach = std::max(reach, r->value);
    if (const Box* b = reg.tryGet<Box>(e)) reach = std::max(reach, 0.5 * std::hypot(b->width, b->height));
    if (const Polygon* p = reg.tryGet<Polygon>(e))
        for (const Vec2& v : p->vertices) reach = std::max(reach, length(v) + p->radius.value_or(0.0));
    if (const Capsule* c = reg.tryGet<Capsule>(e)) reach = std::max(reach, std::max(length(c->a), length(c->b)) + c->radius);
    if (const Shapes* shapes = reg.tryGet<Shapes>(e))
        for (const CompoundShape& item : shapes->items) {
            const ShapeOutline outline = compoundShapeOutline(item);
            for (const Vec2& v : outline.points) reach = std::max(reach, length(v) + outline.radius);
        }
    return reach;
}

/// Why `e`, the scene's entity number `index`, cannot join the World in
/// place (what changeBodies adds: a dynamic or static body with a shape,
/// or a joint whose ends are added with it); nothing when it can.
std::optional<Error> addableProblem(const Registry& reg, std::size_t index, const std::unordered_set<Entity>& added) {
    const Entity e = reg.entities()[index];
    if (const Joint* joint = reg.tryGet<Joint>(e)) {
        for (const Entity end : {joint->a, joint->b}) {
            if (!end.isNull() && !added.count(end)) return Error{"a joint to a body that was already there"};
            if (!end.isNull() && isOn(reg.tryGet<Static>(end))) return Error{"a joint to a static body is added by a rebuild"};
        }
        return std::nullopt;
    }
    if (reg.has<Spring>(e)) return Error{"a spring is checked by a rebuild"};
    if (!reg.has<Position>(e)) return std::nullopt;  // not simulated (World::build skips it too)
    if (isOn(reg.tryGet<Kinematic>(e)) || reg.has<Plane>(e) || reg.has<Attractor>(e) || reg.has<Boid>(e) ||
        reg.has<Emitter>(e) || reg.has<Template>(e))
        return Error{"only dynamic and static bodies are added in place"};
    const bool fixed = isOn(reg.tryGet<Static>(e));
    if (!reg.has<Radius>(e) && !reg.has<Box>(e) && !reg.has<Polygon>(e) && !reg.has<Capsule>(e) && !reg.has<Shapes>(e) &&
        !(fixed && reg.has<Chain>(e)))
        return Error{"a body without a shape is added by a rebuild"};
    if (fixed) return detail::shapeProblem(reg, index);
    // A build refuses a spin that moves a point faster than a run holds.
    // The centre of mass lies within the shapes, so no point is farther
    // from it than twice the reach from the position: a spin under that
    // bound passes the build's check, and one over it is left to a build.
    if (const AngularVelocity* w = reg.tryGet<AngularVelocity>(e);
        w && !(std::abs(w->value) * 2.0 * reachFromPosition(reg, e) <= kMaxSpeed))
        return Error{"a body spinning this fast is checked by a rebuild"};
    const Mass* m = reg.tryGet<Mass>(e);
    if (m && !(std::isfinite(m->value) && m->value > 0.0)) return Error{"mass must be a finite number > 0"};
    return detail::shapeProblem(reg, index);
}

} // namespace

Result<void> World::changeEntities(const Scene& scene, const SystemSwitches& switches, std::span<const Entity> removed,
                                   std::span<const Entity> added) {
    WorldImpl& w = *impl_;
    const Registry& reg = scene.registry;
    // In a level with emitters the run's registry and the emitters follow
    // the scene (below); an emitter, a template or a copy (named
    // TEMPLATE#N) changes what the emitters do: a rebuild.
    if (!w.emitters.empty()) {
        const auto emitterPart = [](const Registry& r, Entity e) {
            const Name* name = r.tryGet<Name>(e);
            return r.has<Emitter>(e) || r.has<Template>(e) || (name && name->value.find('#') != std::string::npos);
        };
        for (const Entity e : removed)
            if (w.registry->alive(e) && emitterPart(*w.registry, e))
                return Error{"an emitter, a template or an emitted copy is removed by a rebuild"};
        for (const Entity e : added)
            if (reg.alive(e) && emitterPart(reg, e))
                return Error{"an emitter, a template or an emitted copy is added by a rebuild"};
    }
    if (!w.collision || !switches.collisions) return Error{"no contact solver to add shapes to"};
    if (w.model.attractorsOn() || w.model.boidsOn)
        return Error{"attractors and boids act on every body: a rebuild checks them"};
    // The removed: dynamic bodies and joints of this World, gone from the
    // scene, that nothing kept holds.
    const std::unordered_set<Entity> gone(removed.begin(), removed.end());
    for (const Entity e : removed)
        if (reg.alive(e)) return Error{"a removed entity is still in the scene"};
    const auto isGone = [&gone](Entity e) { return !e.isNull() && gone.count(e) != 0; };
    for (std::size_t b = 0; b < w.bodyEntity.size() && !gone.empty(); ++b)
        if (isGone(w.bodyEntity[b]) && !w.isKinematic.empty() && w.isKinematic[b])
            return Error{"a kinematic body is removed by a rebuild"};
    if (!gone.empty()) {
        for (std::size_t c = 0; c < w.collision->colliderCount(); ++c)
            if (w.collision->collider(c).shape.kind == collision::ShapeKind::Plane &&
                isGone(w.collision->collider(c).entity))
                return Error{"a plane is removed by a rebuild"};
        for (const joints::JointConstraint& j : w.collision->jointConstraints())
            if (!isGone(j.entity) && (isGone(j.entityA) || isGone(j.entityB)))
                return Error{"a joint stays while a body it holds is removed"};
        const auto bodyGone = [&](std::uint32_t b) { return b != detail::kNoBody && isGone(w.bodyEntity[b]); };
        for (const detail::SpringData& s : w.model.springs)
            if (!isGone(s.entity) && (bodyGone(s.a) || bodyGone(s.b)))
                return Error{"a spring stays while a body it holds is removed"};
    }
    // The added, in scene order: new entities at its end, or entities
    // brought back where they stood (an undone delete).
    const std::unordered_set<Entity> fresh(added.begin(), added.end());
    for (const Entity e : added)
        if (!reg.alive(e)) return Error{"an added entity is not in the scene"};
    std::vector<Entity> inOrder;
    inOrder.reserve(added.size());
    const std::vector<Entity>& order = reg.entities();
    // The new entities are most often the last: look from the end.
    for (std::size_t i = order.size(); i-- > 0 && inOrder.size() < fresh.size();)
        if (fresh.count(order[i])) {
            if (std::optional<Error> problem = addableProblem(reg, i, fresh)) return std::move(*problem);
            inOrder.push_back(order[i]);
        }
    std::reverse(inOrder.begin(), inOrder.end());
    w.choiceUnsettled = true;  // checked once, before the next step (settleChoice)
    // With emitters, the run's registry is the edited scene, as a build
    // takes it (compileEmitters); before changeBodies, whose layout holds it.
    if (!w.emitters.empty()) w.registry = std::make_shared<Registry>(reg);
    w.changeBodies(reg, removed, inOrder);
    if (!w.emitters.empty()) w.renumberEmitters(reg);
    // The springs' pull on the bodies at this state, as a build checks it:
    // refused, the caller's rebuild says why.
    if (std::optional<Error> refused = detail::checkFirstStepForces(w, w.kind)) return std::move(*refused);
    return {};
}

} // namespace stepwise
