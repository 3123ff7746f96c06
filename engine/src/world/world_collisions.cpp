#include "world/world_collisions.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <cmath>
#include <unordered_map>

namespace stepwise::detail {

namespace {

std::string labelOf(const Registry& reg, std::size_t index) {
    std::string label = "entity " + std::to_string(index);
    const Name* name = reg.tryGet<Name>(reg.entities()[index]);
    if (name && !name->value.empty()) label += " (\"" + name->value + "\")";
    return label;
}

joints::JointKind jointKindOf(const std::string& type) {
    if (type == "slider") return joints::JointKind::Slider;
    if (type == "weld") return joints::JointKind::Weld;
    if (type == "distance") return joints::JointKind::Distance;
    if (type == "rope") return joints::JointKind::Rope;
    return joints::JointKind::Hinge;
}

} // namespace

std::unique_ptr<collision::CollisionSystem> buildCollisions(
    const Scene& scene, const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody,
    std::string* problem) {
    const Registry& reg = scene.registry;
    std::unique_ptr<collision::CollisionSystem> system;
    std::unordered_map<std::uint32_t, std::int32_t> colliderOf;  // entity index -> collider
    const auto makeSystem = [&] {
        if (system) return;
        system = std::make_unique<collision::CollisionSystem>();
        system->settings().iterations = scene.world.solverIterations;
    };
    collision::ConvexPolygon polygon;  // copied by add()
    for (const Entity e : reg.entities()) {
        collision::Collider c;
        if (const Radius* r = reg.tryGet<Radius>(e)) {
            c.shape.kind = collision::ShapeKind::Circle;
            c.shape.radius = r->value;
        } else if (const Box* b = reg.tryGet<Box>(e)) {
            c.shape.kind = collision::ShapeKind::Box;
            c.shape.halfExtents = {0.5 * b->width, 0.5 * b->height};
        } else if (const Polygon* poly = reg.tryGet<Polygon>(e)) {
            // The engine works about the centre of mass: the outline is
            // shifted so the centroid is its origin, and the offset kept.
            const PolygonMassProperties props = polygonMassProperties(poly->vertices);
            Vec2 local[collision::kMaxPolygonVertices];
            const int count = int(poly->vertices.size());
            for (int i = 0; i < count; ++i) local[i] = poly->vertices[std::size_t(i)] - props.centroid;
            polygon = collision::ConvexPolygon::fromVertices(local, count);
            c.shape.kind = collision::ShapeKind::Polygon;
            c.shape.polygon = &polygon;
            c.centreOfMass = props.centroid;
        } else if (const Plane* p = reg.tryGet<Plane>(e)) {
            c.shape.kind = collision::ShapeKind::Plane;
            c.shape.normal = p->normal;
            c.shape.offset = p->offset;
        } else {
            continue;  // no shape: never collides, costs the collision stages nothing
        }
        const std::uint32_t body = c.shape.kind == collision::ShapeKind::Plane ? noBody : bodyOf(e);
        c.body = body == noBody ? -1 : std::int32_t(body);
        if (const Position* p = reg.tryGet<Position>(e)) c.staticPosition = p->value;
        c.mass = c.body >= 0 ? (reg.has<Mass>(e) ? reg.tryGet<Mass>(e)->value : 1.0) : 0.0;
        c.restitution = reg.has<Restitution>(e) ? reg.tryGet<Restitution>(e)->value : Restitution{}.value;
        c.friction = reg.has<Friction>(e) ? reg.tryGet<Friction>(e)->value : Friction{}.value;
        c.entity = e;
        const double angle = reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0;
        const double spin = reg.has<AngularVelocity>(e) ? reg.tryGet<AngularVelocity>(e)->value : 0.0;
        makeSystem();
        colliderOf.emplace(e.index, std::int32_t(system->colliderCount()));
        system->add(c, angle, spin);
    }

    // Joints, in scene order.
    const auto& order = reg.entities();
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Joint* stored = reg.tryGet<Joint>(order[i]);
        if (!stored) continue;
        // A scene built in code may leave anchor, reference_angle or length
        // to their defaults; the loader has already filled them for files.
        Joint completed = *stored;
        completeJoint(reg, completed);
        const Joint* joint = &completed;
        joints::JointConstraint j;
        j.kind = jointKindOf(joint->type);
        j.entity = order[i];
        j.entityA = joint->a;
        j.entityB = joint->b;
        std::int32_t filter[2] = {-1, -1};
        bool fixed[2] = {true, true};
        const Entity ends[2] = {joint->a, joint->b};
        joints::JointEnd* out[2] = {&j.a, &j.b};
        for (int k = 0; k < 2; ++k) {
            const Entity end = ends[k];
            joints::JointEnd& je = *out[k];
            je.local = k == 0 ? joint->localA : joint->localB;
            if (end.isNull() && k == 1) continue;  // the world: a fixed frame at the origin
            if (end.isNull() || !reg.alive(end) || !reg.has<Position>(end)) {
                if (problem)
                    *problem = labelOf(reg, i) + ": joint " + (k == 0 ? "a" : "b") +
                               ": the body it names does not exist or has no position";
                return nullptr;
            }
            const Angle* an = reg.tryGet<Angle>(end);
            je.fixedCentre = reg.tryGet<Position>(end)->value;
            je.fixedAngle = an ? an->value : 0.0;
            const auto it = colliderOf.find(end.index);
            if (it != colliderOf.end()) filter[k] = it->second;
            const std::uint32_t body = bodyOf(end);
            if (body == noBody) continue;  // static: fixed at its pose
            fixed[k] = false;
            if (it == colliderOf.end()) {
                // A shapeless dynamic body: into the solver, never colliding.
                collision::Collider c;
                c.body = std::int32_t(body);
                c.mass = reg.has<Mass>(end) ? reg.tryGet<Mass>(end)->value : 1.0;
                c.entity = end;
                c.solverOnly = true;
                c.inertia = 0.5 * c.mass * kShapelessRadius * kShapelessRadius;
                const AngularVelocity* av = reg.tryGet<AngularVelocity>(end);
                makeSystem();
                filter[k] = std::int32_t(system->colliderCount());
                colliderOf.emplace(end.index, filter[k]);
                system->add(c, je.fixedAngle, av ? av->value : 0.0);
            }
            je.collider = filter[k];
            je.solverBody = system->solverBodyOf(std::size_t(filter[k]));
        }
        if (fixed[0] && fixed[1]) {
            if (problem) *problem = labelOf(reg, i) + ": joint joins two static bodies; at least one end must be dynamic";
            return nullptr;
        }
        if (joint->axis) {
            const double len = std::hypot(joint->axis->x, joint->axis->y);
            if (!(len > 1e-12)) {
                if (problem) *problem = labelOf(reg, i) + ": joint axis: a slider axis needs a non-zero length";
                return nullptr;
            }
            j.localAxis = *joint->axis / len;
        }
        j.referenceAngle = joint->referenceAngle.value_or(0.0);
        j.hasLower = joint->lower.has_value();
        j.hasUpper = joint->upper.has_value();
        j.lower = joint->lower.value_or(0.0);
        j.upper = joint->upper.value_or(0.0);
        const std::optional<double>& maxMotor = j.kind == joints::JointKind::Slider ? joint->maxMotorForce
                                                                                    : joint->maxMotorTorque;
        j.motor = maxMotor.has_value() && (j.kind == joints::JointKind::Hinge || j.kind == joints::JointKind::Slider);
        j.maxMotor = maxMotor.value_or(0.0);
        j.motorSpeed = joint->motorSpeed.value_or(0.0);
        j.length = joint->length.value_or(0.0);
        j.stiffnessHz = joint->stiffnessHz.value_or(0.0);
        j.dampingRatio = joint->dampingRatio.value_or(1.0);
        makeSystem();
        system->addJoint(j, filter[0], filter[1], joint->collideConnected);
    }
    return system;
}

} // namespace stepwise::detail
