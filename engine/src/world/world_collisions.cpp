#include "world/world_collisions.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <cmath>
#include <unordered_map>

#include <algorithm>
#include <cmath>
#include <map>

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
            // The file's anchor is measured from the body's position (the
            // frame of a polygon's vertices); the solver turns a dynamic
            // body about its centre of mass, so the anchor is taken from
            // there. (A fixed end stays about its position: fixedCentre.)
            je.local = je.local - system->collider(std::size_t(filter[k])).centreOfMass;
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

namespace stepwise {

double expectedPileOverlap(int depth, double gravity, double h) {
    // A resting soft contact compresses by load / (m_n omega^2). In a pile
    // `depth` bodies deep the lowest contacts between bodies carry about
    // depth * m g with m_n = m / 2. kMeasured folds in what the model leaves
    // out (contacts share the load unevenly, a few iterations do not fully
    // converge); measured on the 30-row, 300-circle pile (docs: collide.md).
    constexpr double kMeasured = 1.0;
    constexpr double kPi = 3.14159265358979323846;
    if (depth < 2 || !(gravity > 0.0) || !(h > 0.0)) return 0.0;
    const double hertz = std::min(collision::SolverSettings{}.contactHertz, 0.25 / h);
    const double omega = 2.0 * kPi * hertz;
    return kMeasured * 2.0 * double(depth - 1) * gravity / (omega * omega);
}

double derivedRestitutionThreshold(double gravity, double h) { return 4.0 * gravity * h; }

ContactSettingsChoice chooseContactSettings(const Scene& scene) {
    ContactSettingsChoice choice;
    const Registry& reg = scene.registry;
    choice.gravity = length(scene.world.gravity);
    // The deepest pile: dynamic shapes binned into columns one median
    // diameter wide across the direction of gravity; the fullest column is
    // how deep they can pile if they all come to rest.
    std::vector<std::pair<double, double>> shapes;  // (position across gravity, size) in metres
    const Vec2 down = choice.gravity > 0.0 ? scene.world.gravity / choice.gravity : Vec2{0.0, -1.0};
    const Vec2 across{-down.y, down.x};
    for (const Entity e : reg.entities()) {
        const Static* st = reg.tryGet<Static>(e);
        const Position* p = reg.tryGet<Position>(e);
        if ((st && st->value) || !p) continue;
        double size = 0.0;
        if (const Radius* r = reg.tryGet<Radius>(e)) size = 2.0 * r->value;
        else if (const Box* b = reg.tryGet<Box>(e)) size = std::max(b->width, b->height);
        else continue;
        shapes.emplace_back(dot(p->value, across), size);
    }
    if (shapes.empty()) return choice;
    std::vector<double> sizes;
    for (const auto& s : shapes) sizes.push_back(s.second);
    std::nth_element(sizes.begin(), sizes.begin() + std::ptrdiff_t(sizes.size() / 2), sizes.end());
    choice.diameter = sizes[sizes.size() / 2];
    std::map<long long, int> columns;
    for (const auto& s : shapes) ++columns[(long long)std::floor(s.first / choice.diameter)];
    for (const auto& [column, count] : columns) choice.stackDepth = std::max(choice.stackDepth, count);
    // The fewest substeps (up to 16) that keep the pile's overlap under 1%
    // of a diameter; beyond 4 substeps at 60 Hz the contact stiffness stops
    // growing (SolverSettings::contactHertz), so more would only cost.
    const double dt = scene.world.dt;
    for (int s = 1; s <= 16; s *= 2) {
        choice.substeps = s;
        if (expectedPileOverlap(choice.stackDepth, choice.gravity, dt / double(s)) <= 0.01 * choice.diameter) break;
        if (s > 1 && expectedPileOverlap(choice.stackDepth, choice.gravity, dt / double(s)) ==
                         expectedPileOverlap(choice.stackDepth, choice.gravity, dt / double(2 * s)))
            break;
    }
    choice.iterations = choice.substeps == 1 ? 8 : 2;
    return choice;
}

} // namespace stepwise
