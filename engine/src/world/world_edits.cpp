// Edits the World takes in place, without a rebuild: what they change is
// exactly what a rebuild from the edited scene would (World::reload), and
// nothing else, so every other body keeps its state and warm start.

#include "world/world_collisions.hpp"
#include "world/world_impl.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

namespace stepwise {

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

/// The state index of `body`, a dynamic, non-kinematic body of the World
/// that is alive in `scene`; else why an edit of it cannot go in place.
Result<std::size_t> editableBody(const WorldImpl& w, const Scene& scene, Entity body) {
    const auto it = std::find(w.bodyEntity.begin(), w.bodyEntity.end(), body);
    if (it == w.bodyEntity.end()) return Error{"not a dynamic body of this world"};
    const std::size_t b = std::size_t(it - w.bodyEntity.begin());
    if (!w.isKinematic.empty() && w.isKinematic[b]) return Error{"a kinematic body moves as its level says"};
    if (!scene.registry.alive(body)) return Error{"the body is not in the scene"};
    return b;
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
    if (substeps != settings.substeps || iterations != settings.solverIterations ||
        !sameBits(choice.hertzFraction, contactChoice.hertzFraction))
        return Error{"the edit changes the settings the engine chooses"};
    contactChoice = choice;
    hertzFractionRecorded = false;
    if (settingsSource == World::SettingsSource::Recorded) settingsSource = World::SettingsSource::Chosen;
    return std::nullopt;
}

Result<void> World::setMass(const Scene& scene, const SystemSwitches& switches, Entity body) {
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
    if (std::optional<Error> other = w.keepChoiceFor(scene, switches)) return std::move(*other);
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

Result<void> World::turnBody(const Scene& scene, const SystemSwitches& switches, Entity body) {
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
    if (std::optional<Error> other = w.keepChoiceFor(scene, switches)) return std::move(*other);
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

} // namespace stepwise
