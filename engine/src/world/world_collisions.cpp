#include "world/world_collisions.hpp"

#include "templates.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <optional>
#include <tuple>
#include <utility>
#include <unordered_map>
#include <unordered_set>

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
    if (type == "wheel") return joints::JointKind::Wheel;
    return joints::JointKind::Hinge;
}

/// One shape of a compound body as the engine holds it: the geometry about
/// its own centre, and that centre in the body frame (Collider::centreOfMass).
/// A turned box becomes the polygon of its corners, so every shape of a body
/// turns with the body's one angle.
void compoundGeometry(const CompoundShape& s, collision::Collider& c, collision::ConvexPolygon& polygon) {
    switch (s.kind) {
    case CompoundShape::Kind::Circle:
        c.shape.kind = collision::ShapeKind::Circle;
        c.shape.radius = s.radius;
        c.centreOfMass = s.center;
        return;
    case CompoundShape::Kind::Box:
        c.centreOfMass = s.center;
        if (s.angle == 0.0) {
            c.shape.kind = collision::ShapeKind::Box;
            c.shape.halfExtents = {0.5 * s.width, 0.5 * s.height};
            return;
        } else {
            const collision::Rot q = collision::Rot::fromAngle(s.angle);
            const double hx = 0.5 * s.width, hy = 0.5 * s.height;
            const Vec2 corners[4] = {collision::rotate(q, {-hx, -hy}), collision::rotate(q, {hx, -hy}),
                                     collision::rotate(q, {hx, hy}), collision::rotate(q, {-hx, hy})};
            polygon = collision::ConvexPolygon::fromVertices(corners, 4);
            c.shape.kind = collision::ShapeKind::Polygon;
            c.shape.polygon = &polygon;
            return;
        }
    case CompoundShape::Kind::Polygon: {
        const double rounding = s.cornerRadius.value_or(0.0);
        const PolygonMassProperties props =
            rounding > 0.0 ? polygonMassProperties(s.vertices, rounding) : polygonMassProperties(s.vertices);
        Vec2 local[collision::kMaxPolygonVertices];
        const int count = int(s.vertices.size());
        for (int i = 0; i < count; ++i) local[i] = s.vertices[std::size_t(i)] - props.centroid;
        polygon = collision::ConvexPolygon::fromVertices(local, count);
        polygon.cornerRadius = rounding;
        c.shape.kind = collision::ShapeKind::Polygon;
        c.shape.polygon = &polygon;
        c.centreOfMass = props.centroid;
        return;
    }
    case CompoundShape::Kind::Capsule:
        c.shape.kind = collision::ShapeKind::Capsule;
        c.shape.radius = s.radius;
        c.shape.halfExtents = 0.5 * (s.b - s.a);
        c.centreOfMass = 0.5 * (s.a + s.b);
        return;
    }
}

/// A compound body: for a moving one, a hub (the rigid body: summed mass,
/// inertia about the common centre of mass, the one angle and spin, the
/// solver body) and then each shape pointing at it (by its place in `out`);
/// for a static one, each shape as a static collider at its place in the
/// body frame.
void appendCompound(const Registry& reg, Entity e, const Shapes& compound,
                    const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody, ShapeStorage& storage,
                    std::vector<collision::CollisionSystem::ColliderAdd>& out) {
    const std::uint32_t body = bodyOf(e);
    const bool moving = body != noBody;
    const bool kinematic = moving && reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value;
    const Vec2 position = reg.tryGet<Position>(e)->value;
    const double angle = reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0;
    const double spin = reg.has<AngularVelocity>(e) ? reg.tryGet<AngularVelocity>(e)->value : 0.0;
    const Mass* given = reg.tryGet<Mass>(e);
    const CompoundMassProperties props =
        compoundMassProperties(compound, given ? std::optional<double>(given->value) : std::nullopt);
    const double restitution = reg.has<Restitution>(e) ? reg.tryGet<Restitution>(e)->value : Restitution{}.value;
    const double friction = reg.has<Friction>(e) ? reg.tryGet<Friction>(e)->value : Friction{}.value;
    const bool sensor = reg.has<Sensor>(e) && reg.tryGet<Sensor>(e)->value;
    const Filter* filter = reg.tryGet<Filter>(e);
    std::int32_t hub = -1;
    if (moving) {
        collision::CollisionSystem::ColliderAdd h;
        h.collider.body = std::int32_t(body);
        h.collider.part = collision::Collider::kHubPart;
        h.collider.kinematic = kinematic;
        h.collider.mass = kinematic ? 0.0 : props.mass;
        h.collider.inertia = props.inertia;
        h.collider.centreOfMass = props.centre;
        h.collider.entity = e;
        h.collider.solverOnly = true;
        h.angle = angle;
        h.angularVelocity = spin;
        hub = std::int32_t(out.size());
        out.push_back(h);
    }
    for (std::size_t k = 0; k < compound.items.size(); ++k) {
        const CompoundShape& s = compound.items[k];
        collision::CollisionSystem::ColliderAdd add;
        collision::Collider& c = add.collider;
        compoundGeometry(s, c, storage.polygons.emplace_back());
        c.body = moving ? std::int32_t(body) : -1;
        c.hub = hub;
        c.part = std::uint32_t(k);
        c.staticPosition = position;
        c.kinematic = kinematic;
        c.restitution = s.restitution.value_or(restitution);
        c.friction = s.friction.value_or(friction);
        c.sensor = s.sensor.value_or(sensor);
        c.entity = e;
        add.angle = angle;
        add.filter = s.filter ? *s.filter : filter ? *filter : Filter{};
        out.push_back(add);
    }
}

} // namespace

void collidersFor(const Registry& reg, Entity e, const std::function<std::uint32_t(Entity)>& bodyOf,
                  std::uint32_t noBody, ShapeStorage& storage, std::vector<collision::CollisionSystem::ColliderAdd>& out) {
    if (const Shapes* compound = reg.tryGet<Shapes>(e)) {
        appendCompound(reg, e, *compound, bodyOf, noBody, storage, out);
        return;
    }
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
        const double rounding = poly->radius.value_or(0.0);
        const PolygonMassProperties props = rounding > 0.0 ? polygonMassProperties(poly->vertices, rounding)
                                                           : polygonMassProperties(poly->vertices);
        Vec2 local[collision::kMaxPolygonVertices];
        const int count = int(poly->vertices.size());
        for (int i = 0; i < count; ++i) local[i] = poly->vertices[std::size_t(i)] - props.centroid;
        collision::ConvexPolygon& polygon = storage.polygons.emplace_back(collision::ConvexPolygon::fromVertices(local, count));
        polygon.cornerRadius = rounding;
        c.shape.kind = collision::ShapeKind::Polygon;
        c.shape.polygon = &polygon;
        c.centreOfMass = props.centroid;
    } else if (const Capsule* cap = reg.tryGet<Capsule>(e)) {
        // About the centre of mass, like polygons: the segment's
        // midpoint, kept as the offset (exactly zero for a capsule
        // centred on its position, which then takes the plain path).
        const Vec2 mid = 0.5 * (cap->a + cap->b);
        c.shape.kind = collision::ShapeKind::Capsule;
        c.shape.radius = cap->radius;
        c.shape.halfExtents = 0.5 * (cap->b - cap->a);
        c.centreOfMass = mid;
    } else if (reg.has<Chain>(e)) {
        c.shape.kind = collision::ShapeKind::ChainSegment;  // one collider per segment, below
    } else if (const Plane* p = reg.tryGet<Plane>(e)) {
        c.shape.kind = collision::ShapeKind::Plane;
        c.shape.normal = p->normal;
        c.shape.offset = p->offset;
    } else {
        return;  // no shape: never collides
    }
    const std::uint32_t body = c.shape.kind == collision::ShapeKind::Plane ? noBody : bodyOf(e);
    c.body = body == noBody ? -1 : std::int32_t(body);
    if (const Position* p = reg.tryGet<Position>(e)) c.staticPosition = p->value;
    c.kinematic = c.body >= 0 && reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value;
    c.mass = c.body >= 0 && !c.kinematic ? (reg.has<Mass>(e) ? reg.tryGet<Mass>(e)->value : 1.0) : 0.0;
    c.restitution = reg.has<Restitution>(e) ? reg.tryGet<Restitution>(e)->value : Restitution{}.value;
    c.friction = reg.has<Friction>(e) ? reg.tryGet<Friction>(e)->value : Friction{}.value;
    c.sensor = reg.has<Sensor>(e) && reg.tryGet<Sensor>(e)->value;
    c.entity = e;
    collision::CollisionSystem::ColliderAdd add;
    add.angle = reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0;
    add.angularVelocity = reg.has<AngularVelocity>(e) ? reg.tryGet<AngularVelocity>(e)->value : 0.0;
    const Filter* filter = reg.tryGet<Filter>(e);
    add.filter = filter ? *filter : Filter{};
    if (c.shape.kind != collision::ShapeKind::ChainSegment) {
        add.collider = c;
        out.push_back(add);
        return;
    }
    // Each segment is a collider and a broad-phase proxy of its own (a long
    // terrain is not one huge box), in order, so segment k is the chain's
    // first collider plus k. On a kinematic body the segments are shapes of
    // one moving body, as a compound body's are: a hub (the solver body,
    // with the body's angle and spin) comes first and they follow it.
    if (c.body >= 0) {
        collision::CollisionSystem::ColliderAdd h;
        h.collider.body = c.body;
        h.collider.part = collision::Collider::kHubPart;
        h.collider.kinematic = c.kinematic;
        h.collider.entity = e;
        h.collider.solverOnly = true;
        h.angle = add.angle;
        h.angularVelocity = add.angularVelocity;
        c.hub = std::int32_t(out.size());
        out.push_back(h);
    }
    const Chain& chain = *reg.tryGet<Chain>(e);
    const std::vector<Vec2>& pts = chain.points;
    const std::size_t n = pts.size(), segments = chain.loop ? n : n - 1;
    for (std::size_t k = 0; k < segments; ++k) {
        collision::ChainSegment& seg = storage.segments.emplace_back();
        seg.index = std::uint32_t(k);
        seg.p1 = pts[k];
        seg.p2 = pts[(k + 1) % n];
        // An open end's ghost lies straight behind the segment: the end is
        // a square corner.
        const Vec2 d = seg.p2 - seg.p1;
        const Vec2 behind{-d.y, d.x};  // the left of the segment, as long as it
        seg.open1 = !chain.loop && k == 0;
        seg.open2 = !chain.loop && k + 1 == segments;
        seg.ghost1 = seg.open1 ? seg.p1 + behind : pts[(k + n - 1) % n];
        seg.ghost2 = seg.open2 ? seg.p2 + behind : pts[(k + 2) % n];
        add.collider = c;
        add.collider.shape.segment = &seg;
        out.push_back(add);
    }
}

bool fillJointParams(const Joint& joint, joints::JointConstraint& j) {
    j.kind = jointKindOf(joint.type);
    if (joint.axis) {
        const double len = std::hypot(joint.axis->x, joint.axis->y);
        if (!(len > 1e-12)) return false;
        j.localAxis = *joint.axis / len;
    }
    j.referenceAngle = joint.referenceAngle.value_or(0.0);
    j.hasLower = joint.lower.has_value();
    j.hasUpper = joint.upper.has_value();
    j.lower = joint.lower.value_or(0.0);
    j.upper = joint.upper.value_or(0.0);
    const std::optional<double>& maxMotor = j.kind == joints::JointKind::Slider ? joint.maxMotorForce
                                                                                : joint.maxMotorTorque;
    j.motor = maxMotor.has_value() && (j.kind == joints::JointKind::Hinge || j.kind == joints::JointKind::Slider ||
                                       j.kind == joints::JointKind::Wheel);
    j.maxMotor = maxMotor.value_or(0.0);
    j.motorSpeed = joint.motorSpeed.value_or(0.0);
    j.length = joint.length.value_or(0.0);
    j.stiffnessHz = joint.stiffnessHz.value_or(0.0);
    j.dampingRatio = joint.dampingRatio.value_or(1.0);
    if (j.kind == joints::JointKind::Hinge) {
        j.springHz = joint.springHz.value_or(0.0);
        j.springDampingRatio = joint.springDampingRatio.value_or(1.0);
    }
    j.spring = (j.kind == joints::JointKind::Hinge && j.springHz > 0.0) ||
               (j.kind == joints::JointKind::Wheel && j.stiffnessHz > 0.0);
    j.maxForce = joint.maxForce.value_or(0.0);
    return true;
}

Result<std::unique_ptr<collision::CollisionSystem>> buildCollisions(
    const Scene& scene, const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody, bool shapes) {
    const Registry& reg = scene.registry;
    std::unique_ptr<collision::CollisionSystem> system;
    std::unordered_map<std::uint32_t, std::int32_t> colliderOf;  // entity index -> collider
    const auto makeSystem = [&] {
        if (system) return;
        system = std::make_unique<collision::CollisionSystem>();
        system->settings().iterations = scene.world.solverIterations;
    };
    ShapeStorage storage;
    std::vector<collision::CollisionSystem::ColliderAdd> adds;
    static const std::vector<Entity> kNoEntities;
    for (const Entity e : shapes ? reg.entities() : kNoEntities) {
        if (inTemplate(reg, e)) continue;  // a prefab: never collides
        adds.clear();
        collidersFor(reg, e, bodyOf, noBody, storage, adds);
        if (adds.empty()) continue;  // no shape: never collides, costs the collision stages nothing
        makeSystem();
        colliderOf.emplace(e.index, std::int32_t(system->addAll(adds)));
    }

    // Joints, in scene order.
    const auto& order = reg.entities();
    for (std::size_t i = 0; i < order.size(); ++i) {
        const Joint* stored = reg.tryGet<Joint>(order[i]);
        if (!stored || inTemplate(reg, order[i])) continue;
        // A scene built in code may leave anchor, reference_angle or length
        // to their defaults; the loader has already filled them for files
        // and refused what cannot be filled, so a refusal here leaves the
        // defaults.
        Joint completed = *stored;
        (void)completeJoint(reg, completed);
        const Joint* joint = &completed;
        joints::JointConstraint j;
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
                return Error{labelOf(reg, i) + ": joint " + (k == 0 ? "a" : "b") +
                             ": the body it names does not exist or has no position"};
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
                c.kinematic = reg.has<Kinematic>(end) && reg.tryGet<Kinematic>(end)->value;
                c.mass = c.kinematic ? 0.0 : reg.has<Mass>(end) ? reg.tryGet<Mass>(end)->value : 1.0;
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
        if (fixed[0] && fixed[1])
            return Error{labelOf(reg, i) + ": joint joins two static bodies; at least one end must be dynamic"};
        if (!fillJointParams(*joint, j))
            return Error{labelOf(reg, i) + ": joint axis: a slider axis needs a non-zero length"};
        makeSystem();
        system->addJoint(j, filter[0], filter[1], joint->collideConnected);
    }
    return system;
}

} // namespace stepwise::detail

namespace stepwise {

namespace {

constexpr double kPi = 3.14159265358979323846;
static_assert(kContactHertz == collision::SolverSettings{}.contactHertz, "one default contact stiffness");

/// omega^2 of the resting soft contact at substeps of h seconds: `hertz`,
/// capped at `fraction` of the substep rate.
double contactOmega2(double h, double fraction, double contactHertz) {
    const double hertz = std::min(contactHertz, fraction / h);
    const double omega = 2.0 * kPi * hertz;
    return omega * omega;
}

/// A shape's extent along `dir` (unit): its half-width there, metres.
double halfExtentAlong(const Registry& reg, Entity e, Vec2 dir) {
    const double angle = reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0;
    const double c = std::cos(angle), s = std::sin(angle);
    // dir in the body's frame
    const Vec2 local{c * dir.x + s * dir.y, -s * dir.x + c * dir.y};
    if (const Radius* r = reg.tryGet<Radius>(e)) return r->value;
    if (const Box* b = reg.tryGet<Box>(e)) return 0.5 * (b->width * std::abs(local.x) + b->height * std::abs(local.y));
    if (const Polygon* p = reg.tryGet<Polygon>(e)) {
        double lo = 0.0, hi = 0.0;
        bool first = true;
        for (const Vec2& v : p->vertices) {
            const double d = dot(v, local);
            lo = first ? d : std::min(lo, d);
            hi = first ? d : std::max(hi, d);
            first = false;
        }
        return 0.5 * (hi - lo) + p->radius.value_or(0.0);
    }
    if (const Capsule* cap = reg.tryGet<Capsule>(e)) return 0.5 * std::abs(dot(cap->b - cap->a, local)) + cap->radius;
    if (const Shapes* shapes = reg.tryGet<Shapes>(e)) {
        // The whole body's extent: over every shape's outline.
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const CompoundShape& shape : shapes->items) {
            const ShapeOutline outline = compoundShapeOutline(shape);
            for (const Vec2 v : outline.points) {
                lo = std::min(lo, dot(v, local) - outline.radius);
                hi = std::max(hi, dot(v, local) + outline.radius);
            }
        }
        return hi >= lo ? 0.5 * (hi - lo) : 0.0;
    }
    return 0.0;
}

/// A shape's centre offset along `dir` from its position (polygons and
/// capsules need not be centred on it), metres.
double centreAlong(const Registry& reg, Entity e, Vec2 dir) {
    const Polygon* p = reg.tryGet<Polygon>(e);
    const Capsule* cap = p ? nullptr : reg.tryGet<Capsule>(e);
    const Shapes* shapes = p || cap ? nullptr : reg.tryGet<Shapes>(e);
    if ((!p || p->vertices.empty()) && !cap && !shapes) return 0.0;
    const double angle = reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0;
    const double c = std::cos(angle), s = std::sin(angle);
    const Vec2 local{c * dir.x + s * dir.y, -s * dir.x + c * dir.y};
    if (cap) return 0.5 * dot(cap->a + cap->b, local);
    if (shapes) {
        double lo = std::numeric_limits<double>::infinity(), hi = -lo;
        for (const CompoundShape& item : shapes->items) {
            const ShapeOutline outline = compoundShapeOutline(item);
            for (const Vec2 v : outline.points) {
                lo = std::min(lo, dot(v, local) - outline.radius);
                hi = std::max(hi, dot(v, local) + outline.radius);
            }
        }
        return hi >= lo ? 0.5 * (lo + hi) : 0.0;
    }
    double lo = dot(p->vertices[0], local), hi = lo;
    for (const Vec2& v : p->vertices) {
        lo = std::min(lo, dot(v, local));
        hi = std::max(hi, dot(v, local));
    }
    return 0.5 * (lo + hi);
}

std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t b) {
    while (parent[b] != b) {
        parent[b] = parent[parent[b]];
        b = parent[b];
    }
    return b;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
    return v[v.size() / 2];
}

std::string number(double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return text;
}

/// Springs' rule (ContactSettingsChoice::springRate). Semi-implicit Euler
/// and Verlet are stable while h omega < 2 and RK4 while < 2.8; explicit
/// Euler and the midpoint method gain energy at any h, less at smaller h.
/// h omega <= 1 keeps every explicit method well inside its bound, with
/// semi-implicit Euler's frequency about 4% off at the bound. A damper is
/// a rate c / m: h c / m <= 1 likewise. Rows of M^-1/2 K M^-1/2: a spring
/// k between dynamic bodies i and j adds k / m_i to row i's diagonal and
/// k / sqrt(m_i m_j) off it; an anchor, or a static or absent partner, only
/// the diagonal.
double springRate(const Scene& scene, const SystemSwitches& switches) {
    const std::string& integrator = scene.world.integrator;
    if (!switches.springs || integrator == "implicit_euler" || integrator == "implicit_midpoint" ||
        integrator == "dopri5")
        return 0.0;
    const Registry& reg = scene.registry;
    const auto dynamicMass = [&](Entity e) -> double {
        if (e.isNull() || !reg.alive(e) || !reg.has<Position>(e) || detail::outsideTheChoice(reg, e)) return 0.0;
        if (const Static* st = reg.tryGet<Static>(e); st && st->value) return 0.0;
        if (const Kinematic* k = reg.tryGet<Kinematic>(e); k && k->value) return 0.0;
        if (reg.has<Mass>(e)) return reg.tryGet<Mass>(e)->value;
        const Shapes* shapes = reg.tryGet<Shapes>(e);
        return shapes ? compoundMassProperties(*shapes, std::nullopt).mass : 1.0;
    };
    std::unordered_map<std::uint32_t, std::pair<double, double>> rows;  // entity index -> (stiffness, damping)
    for (const Entity e : reg.entities()) {
        const Spring* spring = reg.tryGet<Spring>(e);
        if (!spring) continue;
        const double ma = dynamicMass(spring->a), mb = spring->anchor ? 0.0 : dynamicMass(spring->b);
        const auto add = [&](Entity self, double mSelf, double mOther) {
            if (!(mSelf > 0.0)) return;
            const double scale = 1.0 / mSelf + (mOther > 0.0 ? 1.0 / std::sqrt(mSelf * mOther) : 0.0);
            auto& row = rows[self.index];
            row.first += spring->k * scale;
            row.second += spring->damping * scale;
        };
        add(spring->a, ma, mb);
        if (!spring->anchor) add(spring->b, mb, ma);
    }
    double rate = 0.0;
    for (const auto& [index, row] : rows) rate = std::max({rate, std::sqrt(row.first), row.second});
    return rate;
}

/// Calls touch(i, j) for each pair of the boxes (lo, hi, size) that touch
/// as placed: a gap under a quarter of the smaller one's size. Sweeps
/// along x.
template <class PlacedBox, class Touch>
void forEachTouchingPair(const std::vector<PlacedBox>& boxes, const Touch& touch) {
    std::vector<std::uint32_t> byLeft(boxes.size());
    for (std::uint32_t i = 0; i < byLeft.size(); ++i) byLeft[i] = i;
    std::sort(byLeft.begin(), byLeft.end(), [&](std::uint32_t a, std::uint32_t b) {
        return boxes[a].lo.x != boxes[b].lo.x ? boxes[a].lo.x < boxes[b].lo.x : a < b;
    });
    for (std::size_t i = 0; i < byLeft.size(); ++i) {
        const PlacedBox& a = boxes[byLeft[i]];
        for (std::size_t k = i + 1; k < byLeft.size(); ++k) {
            const PlacedBox& b = boxes[byLeft[k]];
            if (b.lo.x - a.hi.x > 0.25 * a.size) break;  // and every later one
            const double gap = 0.25 * std::min(a.size, b.size);
            if (b.lo.x - a.hi.x > gap || b.lo.y - a.hi.y > gap || a.lo.y - b.hi.y > gap) continue;
            touch(byLeft[i], byLeft[k]);
        }
    }
}

/// Marks the boxes (lo, hi, size, touching) that touch another as placed.
template <class PlacedBox>
void markTouching(std::vector<PlacedBox>& boxes) {
    forEachTouchingPair(boxes, [&](std::uint32_t i, std::uint32_t j) { boxes[i].touching = boxes[j].touching = true; });
}

/// The impact rule (ContactSettingsChoice::impactSubsteps). A body moving
/// at v (its centre's speed plus its spin times its reach) with mass M and
/// restitution e_a strikes a body of mass m, size d and restitution e_b:
/// the struck body leaves at up to u = (1 + max(e_a, e_b)) M / (M + m) v
/// (u = (1 + e) v when the striker is kinematic). Driven into its
/// neighbours faster than the contacts can follow, it passes into them:
/// u h must stay under kImpactTravel d. Only a body placed touching another
/// moving body (a gap under a quarter of the smaller one's size) counts as
/// struck: a lone body driven fast just moves, and meets the next one as a
/// striker of its own. Only the velocities the level gives count: what
/// gravity adds within a fall is the load rule's and the contacts'
/// speculative margins' (a body falling from the top of a level 10 m tall
/// reaches 14 m/s, well inside both).
void impactRule(const Scene& scene, const SystemSwitches& switches, double dt, ContactSettingsChoice& choice) {
    if (!switches.collisions || !(dt > 0.0)) return;
    const Registry& reg = scene.registry;
    const auto hasShape = [&](Entity e) {
        return reg.has<Radius>(e) || reg.has<Box>(e) || reg.has<Polygon>(e) || reg.has<Capsule>(e) ||
               reg.has<Shapes>(e);
    };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    struct Body {
        std::uint32_t entity;  // a body does not strike itself
        double size, mass;     // mass: infinite for a kinematic body
        double restitution, speed;
        Vec2 lo, hi;           // its box as placed
        bool touching;
    };
    std::vector<Body> bodies;
    double smallest = kInf, bounciest = 0.0, fastest = 0.0;
    const Vec2 xAxis{1.0, 0.0}, yAxis{0.0, 1.0};
    for (const Entity e : reg.entities()) {
        if (!reg.alive(e) || !reg.has<Position>(e) || !hasShape(e) || detail::outsideTheChoice(reg, e)) continue;
        if (const Static* st = reg.tryGet<Static>(e); st && st->value) continue;
        if (const Sensor* se = reg.tryGet<Sensor>(e); se && se->value) continue;
        Body b{};
        b.entity = e.index;
        const bool kinematic = reg.has<Kinematic>(e) && reg.tryGet<Kinematic>(e)->value;
        b.restitution = reg.has<Restitution>(e) ? reg.tryGet<Restitution>(e)->value : Restitution{}.value;
        const Vec2 half{halfExtentAlong(reg, e, xAxis), halfExtentAlong(reg, e, yAxis)};
        const Vec2 centre = reg.tryGet<Position>(e)->value + Vec2{centreAlong(reg, e, xAxis), centreAlong(reg, e, yAxis)};
        b.lo = centre - half;
        b.hi = centre + half;
        b.size = 2.0 * std::max(half.x, half.y);
        b.mass = kInf;
        if (!kinematic) {
            const Shapes* shapes = reg.tryGet<Shapes>(e);
            b.mass = reg.has<Mass>(e) ? reg.tryGet<Mass>(e)->value
                     : shapes         ? compoundMassProperties(*shapes, std::nullopt).mass
                                      : 1.0;
            if (b.size > 0.0 && b.mass > 0.0) {
                smallest = std::min(smallest, b.size);
                bounciest = std::max(bounciest, b.restitution);
            }
        }
        // The fastest point: the centre's speed and the spin times the
        // corner's reach (a circle's spin moves no surface into anything).
        const Velocity* v = reg.tryGet<Velocity>(e);
        const AngularVelocity* w = reg.tryGet<AngularVelocity>(e);
        const double reach = reg.has<Radius>(e) ? 0.0 : length(half);
        b.speed = (v ? length(v->value) : 0.0) + (w ? std::abs(w->value) * reach : 0.0);
        if (!std::isfinite(b.speed)) b.speed = 0.0;
        fastest = std::max(fastest, b.speed);
        bodies.push_back(b);
    }
    // Nothing fast enough, even doubled by the bounciest restitution, to
    // drive the smallest body past the bound: slow scenes stop here, after
    // one pass over the bodies.
    if (!(fastest * (1.0 + bounciest) * dt > kImpactTravel * smallest)) return;

    markTouching(bodies);

    struct Struck {
        double size, mass, restitution;
        std::uint32_t entity;
    };
    struct Striker {
        double speed, mass, restitution;
        std::uint32_t entity;
    };
    std::vector<Struck> struck;
    std::vector<Striker> strikers;
    for (const Body& b : bodies) {
        if (b.touching && std::isfinite(b.mass) && b.size > 0.0 && b.mass > 0.0)
            struck.push_back({b.size, b.mass, b.restitution, b.entity});
        if (b.speed > 0.0) strikers.push_back({b.speed, b.mass, b.restitution, b.entity});
    }
    if (struck.empty() || strikers.empty()) return;
    // Struck bodies that no other is smaller and lighter than (with a
    // restitution no lower): the only ones that can ask the most.
    std::sort(struck.begin(), struck.end(), [](const Struck& a, const Struck& b) {
        return a.size != b.size           ? a.size < b.size
               : a.mass != b.mass         ? a.mass < b.mass
               : a.restitution != b.restitution ? a.restitution > b.restitution
                                          : a.entity < b.entity;
    });
    std::vector<Struck> front;
    for (const Struck& s : struck) {
        const bool dominated = std::any_of(front.begin(), front.end(), [&](const Struck& f) {
            return f.mass <= s.mass && f.restitution >= s.restitution;
        });
        if (!dominated) front.push_back(s);
    }
    // A striker on the front is weighed against every other body instead.
    std::unordered_set<std::uint32_t> frontEntities;
    for (const Struck& f : front) frontEntities.insert(f.entity);
    const auto onFront = [&](std::uint32_t entity) { return frontEntities.count(entity) != 0; };
    std::sort(strikers.begin(), strikers.end(), [](const Striker& a, const Striker& b) {
        return a.speed != b.speed           ? a.speed > b.speed
               : a.mass != b.mass           ? a.mass > b.mass
               : a.restitution != b.restitution ? a.restitution > b.restitution
                                            : a.entity < b.entity;
    });
    double worst = 0.0;  // the driven travel per step over the bound
    std::vector<Striker> kept;  // strikers no faster one outweighs and outbounces
    for (const Striker& a : strikers) {
        const bool dominated = std::any_of(kept.begin(), kept.end(), [&](const Striker& k) {
            return k.mass >= a.mass && k.restitution >= a.restitution && !onFront(k.entity);
        });
        if (dominated) continue;
        kept.push_back(a);
        for (const Struck& b : onFront(a.entity) ? struck : front) {
            if (b.entity == a.entity) continue;
            const double share = std::isinf(a.mass) ? 1.0 : a.mass / (a.mass + b.mass);
            const double driven = (1.0 + std::max(a.restitution, b.restitution)) * share * a.speed;
            const double ask = driven * dt / (kImpactTravel * b.size);
            if (ask > worst) {
                worst = ask;
                choice.impactSpeed = a.speed;
                choice.impactSize = b.size;
                choice.impactMassRatio = a.mass / b.mass;
                choice.impactDriven = driven;
            }
        }
    }
    int s = 1;
    while (s < kImpactMaxSubsteps && double(s) < worst * (1.0 - 1e-12)) s *= 2;
    choice.impactSubsteps = s;
}

/// The steady load the contact rules read as gravity (m/s^2): the world's
/// gravity, plus the field of the static or kinematic attractors (a
/// planet under a level) and the dynamic ones with a shape (a planet left
/// dynamic), less the acceleration of what the body rests on (scaled up
/// by 1 + m / M where that is an attractor of mass M under what rests on
/// it, m, which pushes it away), where that is strongest on a dynamic
/// body resting with another: in a group placed touching that meets
/// static geometry (a shape, a chain or a plane) or an attractor with a
/// shape, as placed or along its members' paths, or alone, coming to rest
/// beside another. A stack on a planet bears the field as it would bear
/// gravity; a body in orbit bears none of it, however strong the pull. A
/// shapeless dynamic attractor's pull moves with it and is left to the
/// impacts it causes.
///
/// Springs and motors press too: a group placed resting on a support
/// bears the sum of their forces on its members as placed (a motor's is
/// its largest force, which it gives when the group stalls it; those
/// between two members cancel), spread over its mass. Its deepest contact
/// then bears what it bears under that force, as under gravity of that
/// much: a stack pulled onto its floor by a spring on its top box, or
/// pressed by a ram, is read as heavy. A motor's body placed apart presses
/// the first resting group it meets along its drive, and a hinge motor's
/// body, turned about its pivot, the first it meets turning, with the
/// torque over the lever.
struct SteadyLoad {
    Vec2 load;               ///< m/s^2
    bool attractors = false; ///< the strongest includes attractors' pull
    bool springs = false;    ///< the strongest includes springs' force
    bool motors = false;     ///< the strongest includes motors' force
};
template <class IsStatic, class Dynamic, class MassOf, class HasShape>
SteadyLoad steadyLoad(const Scene& scene, const SystemSwitches& switches, const IsStatic& isStatic,
                      const Dynamic& dynamic, const MassOf& massOf, const HasShape& hasShape) {
    const Registry& reg = scene.registry;
    const Vec2 gravity = switches.gravity ? scene.world.gravity : Vec2{};
    if (!switches.collisions) return {gravity};
    // The springs and motors that push or pull a dynamic body with a shape
    // as placed.
    struct Pull {
        Entity body;
        Vec2 force;  // N
        bool motor;
        /// A hinge motor's: the hinge's world point, its torque on `body`
        /// (N*m, counter-clockwise positive) and the body it turns against,
        /// which it does not press; `force` is unused.
        std::optional<Vec2> pivot = std::nullopt;
        double torque = 0.0;
        Entity partner{};
    };
    std::vector<Pull> pulls;
    if (switches.springs) {
        for (const Entity e : reg.entities()) {
            const Spring* spring = reg.alive(e) ? reg.tryGet<Spring>(e) : nullptr;
            if (!spring || !reg.alive(spring->a) || !reg.has<Position>(spring->a)) continue;
            const Vec2 pa = reg.tryGet<Position>(spring->a)->value;
            std::optional<Vec2> pb = spring->anchor;
            if (!pb && reg.alive(spring->b) && reg.has<Position>(spring->b))
                pb = reg.tryGet<Position>(spring->b)->value;
            if (!pb) continue;
            const Vec2 d = *pb - pa;
            const double len = length(d);
            const double stretch = len - spring->restLength.value_or(len);
            if (!(len > 0.0) || stretch == 0.0) continue;
            const Vec2 onA = (spring->k * stretch / len) * d;  // toward b when stretched
            if (hasShape(spring->a) && dynamic(spring->a)) pulls.push_back({spring->a, onA, false});
            if (!spring->anchor && hasShape(spring->b) && dynamic(spring->b))
                pulls.push_back({spring->b, -1.0 * onA, false});
        }
    }
    // A motor drives b against a at its speed; held still, it gives its
    // largest force or torque (joints/joint_solver.cpp): a slider's pushes
    // b along +axis (in a's frame) and a along -axis, a hinge's turns b by
    // +torque and a by -torque, for a positive speed.
    for (const Entity e : reg.entities()) {
        const Joint* joint = reg.alive(e) ? reg.tryGet<Joint>(e) : nullptr;
        if (!joint || joint->motorSpeed.value_or(0.0) == 0.0 || !reg.alive(joint->a)) continue;
        const bool slider = joint->type == "slider", hinge = joint->type == "hinge";
        const std::optional<double>& most = slider ? joint->maxMotorForce : joint->maxMotorTorque;
        if (!(slider || hinge) || !most || !(*most > 0.0) || (hinge && !reg.has<Position>(joint->a))) continue;
        const double angle = reg.has<Angle>(joint->a) ? reg.tryGet<Angle>(joint->a)->value : 0.0;
        const collision::Rot turn = collision::Rot::fromAngle(angle);
        const double signedMost = std::copysign(*most, *joint->motorSpeed);
        const bool onA = hasShape(joint->a) && dynamic(joint->a);
        const bool onB = reg.alive(joint->b) && hasShape(joint->b) && dynamic(joint->b);
        if (slider) {
            const Vec2 axis = collision::rotate(turn, joint->axis.value_or(Vec2{1.0, 0.0}));
            const double len = length(axis);
            if (!(len > 0.0)) continue;
            const Vec2 force = (signedMost / len) * axis;
            if (onA) pulls.push_back({joint->a, -1.0 * force, true});
            if (onB) pulls.push_back({joint->b, force, true});
        } else {
            const Vec2 pivot = reg.tryGet<Position>(joint->a)->value + collision::rotate(turn, joint->localA);
            if (onA) pulls.push_back({joint->a, Vec2{}, true, pivot, -signedMost, joint->b});
            if (onB) pulls.push_back({joint->b, Vec2{}, true, pivot, signedMost, joint->a});
        }
    }
    if (!switches.attractors && pulls.empty()) return {gravity};
    struct Source {
        Vec2 at;
        double gm, eps2;
    };
    std::vector<Source> sources;
    // A dynamic attractor with a shape is ground to what rests on it: what
    // rests there bears the field less the attractor's own acceleration
    // (under gravity both fall), and more as the attractor is lighter, for
    // the push of what rests on it drives it away (a planet left dynamic
    // barely moves; a light one does).
    const auto attractorSupport = [&](Entity e) {
        return switches.attractors && reg.has<Attractor>(e) && hasShape(e) && dynamic(e);
    };
    if (switches.attractors)
        for (const Entity e : reg.entities())
            if (const Attractor* a = reg.tryGet<Attractor>(e);
                a && reg.alive(e) && (isStatic(e) || attractorSupport(e)) && reg.has<Position>(e))
                sources.push_back(
                    {reg.tryGet<Position>(e)->value, scene.world.G * massOf(e), a->softening * a->softening});
    if (sources.empty() && pulls.empty()) return {gravity};

    // Every shape as placed, static ones and chain segments included; only
    // a dynamic one's field is read.
    struct Placed {
        Vec2 lo, hi;
        double size;
        bool touching;
        Entity body;         // null for static shapes
        double radius = 0.0;  // a static circle's (a round planet), tested exactly
    };
    std::vector<Placed> placed;
    struct Halfspace {
        Vec2 normal;
        double offset;
    };
    std::vector<Halfspace> planes;
    const Vec2 xAxis{1.0, 0.0}, yAxis{0.0, 1.0};
    for (const Entity e : reg.entities()) {
        if (!reg.alive(e)) continue;
        if (const Plane* p = reg.tryGet<Plane>(e)) {
            if (const double len = length(p->normal); len > 0.0) planes.push_back({p->normal / len, p->offset});
            continue;
        }
        if (!reg.has<Position>(e)) continue;
        const Vec2 pos = reg.tryGet<Position>(e)->value;
        if (const Chain* chain = reg.tryGet<Chain>(e); chain && isStatic(e)) {
            const collision::Rot q = collision::Rot::fromAngle(reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0);
            const std::size_t n = chain->points.size(), segments = chain->loop ? n : n - 1;
            for (std::size_t k = 0; k < segments && n >= 2; ++k) {
                const Vec2 a = pos + collision::rotate(q, chain->points[k]);
                const Vec2 b = pos + collision::rotate(q, chain->points[(k + 1) % n]);
                const Vec2 lo{std::min(a.x, b.x), std::min(a.y, b.y)}, hi{std::max(a.x, b.x), std::max(a.y, b.y)};
                placed.push_back({lo, hi, length(b - a), false, Entity{}});
            }
            continue;
        }
        if (!hasShape(e) || !(isStatic(e) || dynamic(e))) continue;
        if (const Sensor* se = reg.tryGet<Sensor>(e); se && se->value) continue;  // holds nothing up
        const Vec2 half{halfExtentAlong(reg, e, xAxis), halfExtentAlong(reg, e, yAxis)};
        const Vec2 centre = pos + Vec2{centreAlong(reg, e, xAxis), centreAlong(reg, e, yAxis)};
        const bool circle = reg.has<Radius>(e) && !reg.has<Box>(e) && !reg.has<Polygon>(e) && !reg.has<Capsule>(e) &&
                            !reg.has<Shapes>(e);
        placed.push_back({centre - half, centre + half, 2.0 * std::max(half.x, half.y), false,
                          isStatic(e) ? Entity{} : e, (isStatic(e) || attractorSupport(e)) && circle ? half.x : 0.0});
    }

    const auto fieldAt = [&](Vec2 p) {
        Vec2 field = gravity;
        for (const Source& s : sources) {
            const Vec2 r = s.at - p;
            const double d2 = lengthSquared(r) + s.eps2;
            if (d2 > 0.0) field += (s.gm / (d2 * std::sqrt(d2))) * r;
        }
        return field;
    };
    // Whether a box (lo, hi) comes within `gap` of the shape `o` (a circle
    // exactly, any other shape by its bounding box).
    const auto meetsShape = [](const Placed& o, Vec2 lo, Vec2 hi, double gap) {
        if (!(o.lo.x - hi.x <= gap && lo.x - o.hi.x <= gap && o.lo.y - hi.y <= gap && lo.y - o.hi.y <= gap))
            return false;
        if (o.radius == 0.0) return true;
        // A circle: the box's nearest point to its centre.
        const Vec2 c = 0.5 * (o.lo + o.hi);
        const Vec2 nearest{std::clamp(c.x, lo.x, hi.x), std::clamp(c.y, lo.y, hi.y)};
        return length(nearest - c) - o.radius <= gap;
    };
    std::vector<const Placed*> statics;
    std::size_t dynamicCount = 0;
    for (const Placed& b : placed) {
        if (b.body.isNull()) statics.push_back(&b);
        else ++dynamicCount;
    }
    // A box (lo, hi) of a shape `size` across within a quarter of its size
    // of static geometry.
    const auto meetsStatic = [&](Vec2 lo, Vec2 hi, double size) {
        const double gap = 0.25 * size;
        for (const Placed* o : statics)
            if (meetsShape(*o, lo, hi, gap)) return true;
        const Vec2 centre = 0.5 * (lo + hi), half = 0.5 * (hi - lo);
        return std::any_of(planes.begin(), planes.end(), [&](const Halfspace& h) {
            const double reach = std::abs(h.normal.x) * half.x + std::abs(h.normal.y) * half.y;
            return dot(h.normal, centre) - h.offset - reach <= gap;
        });
    };
    // What a body rests on: its acceleration as placed, and its mass
    // (infinite for static geometry and for an attractor held on it).
    struct Under {
        Vec2 acceleration;
        double mass = std::numeric_limits<double>::infinity();
    };
    // The dynamic attractors with a shape, each with its velocity.
    struct Support {
        const Placed* shape;
        Vec2 at, velocity;
        Under under;
    };
    std::vector<Support> supports;
    for (const Placed& b : placed) {
        if (b.body.isNull() || !attractorSupport(b.body)) continue;
        const Vec2 at = reg.tryGet<Position>(b.body)->value;
        const Velocity* given = reg.tryGet<Velocity>(b.body);
        supports.push_back({&b, at, given ? given->value : Vec2{},
                            meetsStatic(b.lo, b.hi, b.size) ? Under{} : Under{fieldAt(at), massOf(b.body)}});
    }
    // The attractors by their left edge, to visit only those within reach
    // of a box (a field of stars among dust has thousands).
    std::vector<std::uint32_t> byLeft(supports.size());
    double widest = 0.0;
    for (std::uint32_t k = 0; k < byLeft.size(); ++k) {
        byLeft[k] = k;
        widest = std::max(widest, supports[k].shape->hi.x - supports[k].shape->lo.x);
    }
    std::sort(byLeft.begin(), byLeft.end(), [&](std::uint32_t a, std::uint32_t b) {
        return supports[a].shape->lo.x != supports[b].shape->lo.x ? supports[a].shape->lo.x < supports[b].shape->lo.x
                                                                  : a < b;
    });
    // Where a body rests, and on what.
    struct Rest {
        Vec2 at;
        Under under;
    };
    // The first support (static geometry, then the attractors in the
    // level's order) that the box (lo, hi) of `self` meets as placed.
    const auto restsAsPlaced = [&](const Placed& self, Vec2 lo, Vec2 hi) -> std::optional<Under> {
        if (meetsStatic(lo, hi, self.size)) return Under{};
        const double gap = 0.25 * self.size;
        auto it = std::lower_bound(byLeft.begin(), byLeft.end(), lo.x - gap - widest,
                                   [&](std::uint32_t k, double x) { return supports[k].shape->lo.x < x; });
        std::uint32_t first = ~0u;
        for (; it != byLeft.end() && supports[*it].shape->lo.x - hi.x <= gap; ++it)
            if (*it < first && supports[*it].shape->body != self.body && meetsShape(*supports[*it].shape, lo, hi, gap))
                first = *it;
        if (first != ~0u) return supports[first].under;
        return std::nullopt;
    };
    // A body placed apart lands when its path under the steady fields (a
    // point's, from its velocity as placed) meets static geometry within
    // kHorizon, or an attractor (the path then taken relative to it):
    // boxes dropped onto a planet bear its pull where they land. One in
    // orbit never meets any. Each step of the path is swept, so a fast body
    // does not skip a thin support. Past kMostPathWork box and field tests
    // the paths are not followed, and only the groups placed on a support
    // count.
    constexpr double kHorizon = 2.0;  // s
    constexpr int kPathSteps = 256;
    constexpr double kMostPathWork = 5e7;
    const double perStep = double(statics.size() + planes.size() + 1) +
                           double(supports.size()) * double(sources.size() + 1);
    const bool followPaths = !sources.empty() && double(dynamicCount) * kPathSteps * perStep <= kMostPathWork;
    // The path of `b` relative to a frame at `origin`, moving at `frameVelocity`
    // and accelerating at `frameAcceleration`; `meets` tests a swept box in
    // that frame. Where it first meets, in the frame.
    const auto followPath = [&](const Placed& b, Vec2 origin, Vec2 frameVelocity, Vec2 frameAcceleration,
                                const auto& meets) -> std::optional<Vec2> {
        const Vec2 at = reg.tryGet<Position>(b.body)->value;
        const Velocity* given = reg.tryGet<Velocity>(b.body);
        Vec2 x = at - origin, v = (given ? given->value : Vec2{}) - frameVelocity;
        const Vec2 half = 0.5 * (b.hi - b.lo), offset = 0.5 * (b.lo + b.hi) - at;
        const double h = kHorizon / kPathSteps;
        for (int i = 0; i < kPathSteps; ++i) {
            v += h * (fieldAt(origin + x) - frameAcceleration);
            const Vec2 next = x + h * v;
            if (!std::isfinite(next.x) || !std::isfinite(next.y)) return std::nullopt;
            const Vec2 lo{std::min(x.x, next.x), std::min(x.y, next.y)}, hi{std::max(x.x, next.x), std::max(x.y, next.y)};
            if (meets(lo + offset - half, hi + offset + half)) return next;
            x = next;
        }
        return std::nullopt;
    };
    // Where a body comes to rest, as placed or along its path, if it does.
    const auto landing = [&](const Placed& b) -> std::optional<Rest> {
        const Vec2 at = reg.tryGet<Position>(b.body)->value;
        if (const std::optional<Under> under = restsAsPlaced(b, b.lo, b.hi)) return Rest{at, *under};
        if (!followPaths) return std::nullopt;
        const auto onStatic = [&](Vec2 lo, Vec2 hi) { return meetsStatic(lo, hi, b.size); };
        if (const std::optional<Vec2> x = followPath(b, Vec2{}, Vec2{}, Vec2{}, onStatic)) return Rest{*x, Under{}};
        for (const Support& s : supports) {
            if (s.shape->body == b.body) continue;
            // In the support's frame, where its shape stays as placed.
            const auto onSupport = [&](Vec2 lo, Vec2 hi) {
                return meetsShape(*s.shape, lo + s.at, hi + s.at, 0.25 * b.size);
            };
            if (const std::optional<Vec2> x = followPath(b, s.at, s.velocity, s.under.acceleration, onSupport))
                return Rest{s.at + *x, s.under};
        }
        return std::nullopt;
    };
    // Only bodies that rest on or under another bear a load the contact
    // rules need: a lone body on static ground holds at any load (its
    // contacts turn rigid before the slop), so a planet that lands alone
    // on its sun does not make the level heavy. Moving bodies placed
    // touching make groups (union-find); an attractor with a shape is
    // ground, not a member. A group in the air (falling together, or in
    // orbit) bears nothing from within itself: it rests where it meets a
    // support, as placed or along its members' paths. A body placed alone
    // counts where it rests beside another.
    std::vector<Placed> moving;
    for (const Placed& b : placed)
        if (!b.body.isNull() && !attractorSupport(b.body)) moving.push_back(b);
    std::vector<std::uint32_t> group(moving.size());
    for (std::uint32_t i = 0; i < group.size(); ++i) group[i] = i;
    forEachTouchingPair(moving, [&](std::uint32_t i, std::uint32_t j) {
        moving[i].touching = moving[j].touching = true;
        const std::uint32_t ri = findRoot(group, i), rj = findRoot(group, j);
        if (ri != rj) group[std::max(ri, rj)] = std::min(ri, rj);
    });
    // What each group (by its root) rests on as placed.
    std::vector<std::optional<Under>> groupUnder(moving.size());
    for (std::uint32_t i = 0; i < moving.size(); ++i) {
        const std::uint32_t root = findRoot(group, i);
        if (moving[i].touching && !groupUnder[root])
            groupUnder[root] = restsAsPlaced(moving[i], moving[i].lo, moving[i].hi);
    }
    std::unordered_map<std::uint32_t, std::uint32_t> movingOf;  // entity index -> index in `moving`
    for (std::uint32_t i = 0; i < moving.size(); ++i) movingOf.emplace(moving[i].body.index, i);
    // Each group's mass and centre, and all of theirs: what can rest on
    // one attractor (for a body placed apart, which lands with others
    // unknown).
    std::vector<double> groupMass(moving.size(), 0.0);
    std::vector<Vec2> groupMoment(moving.size());
    double movingMass = 0.0;
    for (std::uint32_t i = 0; i < moving.size(); ++i) {
        const double m = massOf(moving[i].body);
        const std::uint32_t root = findRoot(group, i);
        groupMass[root] += m;
        groupMoment[root] += m * reg.tryGet<Position>(moving[i].body)->value;
        movingMass += m;
    }
    // The force of springs and motors on each group resting as placed.
    std::vector<Vec2> groupForce(moving.size());
    std::vector<std::uint8_t> pressed(moving.size(), 0);  // bit 1: by a spring, bit 2: by a motor
    constexpr double kInf = std::numeric_limits<double>::infinity();
    // The first body of a group resting as placed that moving[i]'s box
    // meets, swept along `force` (unbounded: a slider's limits are not
    // read).
    const auto drivenInto = [&](std::uint32_t i, Vec2 force) -> std::optional<std::uint32_t> {
        const double len = length(force);
        if (!(len > 0.0)) return std::nullopt;
        const Vec2 d = force / len;
        const Vec2 centre = 0.5 * (moving[i].lo + moving[i].hi), half = 0.5 * (moving[i].hi - moving[i].lo);
        std::optional<std::uint32_t> first;
        double firstAt = kInf;
        for (std::uint32_t j = 0; j < moving.size(); ++j) {
            if (j == i || !groupUnder[findRoot(group, j)]) continue;
            // The ray from the centre against the other box grown by this
            // box's half extents.
            double enter = 0.0, leave = kInf;
            for (const auto& [from, dir, lo, hi] :
                 {std::tuple{centre.x, d.x, moving[j].lo.x - half.x, moving[j].hi.x + half.x},
                  std::tuple{centre.y, d.y, moving[j].lo.y - half.y, moving[j].hi.y + half.y}}) {
                if (dir == 0.0) {
                    if (from < lo || from > hi) leave = -1.0;
                    continue;
                }
                const double t0 = (lo - from) / dir, t1 = (hi - from) / dir;
                enter = std::max(enter, std::min(t0, t1));
                leave = std::min(leave, std::max(t0, t1));
            }
            if (enter <= leave && enter < firstAt) {
                firstAt = enter;
                first = j;
            }
        }
        return first;
    };
    // The first body of a group resting as placed that moving[i] meets
    // turning about `pivot` the way `torque` turns it, within its reach, and
    // the force the torque presses it with: at its nearest point to the
    // pivot (at least half its size away), across the line to it. A body
    // turning about its own centre (a wheel, a rotor) presses nothing.
    const auto turnedInto = [&](std::uint32_t i, Vec2 pivot, double torque,
                                Entity partner) -> std::optional<std::pair<std::uint32_t, Vec2>> {
        const Placed& arm = moving[i];
        const Vec2 along = 0.5 * (arm.lo + arm.hi) - pivot;
        if (!(length(along) >= 0.25 * arm.size) || torque == 0.0) return std::nullopt;
        double reach = 0.0;
        for (const Vec2 corner : {arm.lo, arm.hi, Vec2{arm.lo.x, arm.hi.y}, Vec2{arm.hi.x, arm.lo.y}})
            reach = std::max(reach, length(corner - pivot));
        const double sense = torque > 0.0 ? 1.0 : -1.0;
        std::optional<std::pair<std::uint32_t, Vec2>> first;
        double firstTurn = kInf;
        for (std::uint32_t j = 0; j < moving.size(); ++j) {
            if (j == i || moving[j].body == partner || !groupUnder[findRoot(group, j)]) continue;
            const Vec2 nearest{std::clamp(pivot.x, moving[j].lo.x, moving[j].hi.x),
                               std::clamp(pivot.y, moving[j].lo.y, moving[j].hi.y)};
            const double lever = length(nearest - pivot);
            if (lever > reach) continue;
            const Vec2 to = 0.5 * (moving[j].lo + moving[j].hi) - pivot;
            double turn = sense * std::atan2(cross(along, to), dot(along, to));
            if (turn <= 0.0) turn += 2.0 * kPi;
            if (!(turn < firstTurn) || !(length(to) > 0.0)) continue;
            firstTurn = turn;
            const Vec2 across = (sense / length(to)) * Vec2{-to.y, to.x};
            first = {j, (std::abs(torque) / std::max(lever, 0.5 * moving[j].size)) * across};
        }
        return first;
    };
    const auto press = [&](std::uint32_t root, Vec2 force, bool motor) {
        groupForce[root] += force;
        pressed[root] |= motor ? 2 : 1;
    };
    for (const Pull& pull : pulls) {
        const auto it = movingOf.find(pull.body.index);
        if (it == movingOf.end()) continue;
        const std::uint32_t root = findRoot(group, it->second);
        if (pull.pivot) {
            if (const std::optional<std::pair<std::uint32_t, Vec2>> hit =
                    turnedInto(it->second, *pull.pivot, pull.torque, pull.partner))
                press(findRoot(group, hit->first), hit->second, true);
            continue;
        }
        if (!groupUnder[root]) {
            // A motor keeps its largest force until it stalls, wherever it
            // meets a resting group; a spring's force as placed is not what
            // it presses with once its body has moved.
            if (pull.motor)
                if (const std::optional<std::uint32_t> hit = drivenInto(it->second, pull.force))
                    press(findRoot(group, *hit), pull.force, true);
            continue;
        }
        // A motor gives its largest force only held still: when it drives
        // its body into the rest of the group. Driving it away, it runs free.
        if (pull.motor && !(groupMass[root] > 0.0 &&
                            dot(pull.force, groupMoment[root] / groupMass[root] -
                                                reg.tryGet<Position>(pull.body)->value) > 0.0))
            continue;
        press(root, pull.force, pull.motor);
    }
    std::vector<Placed> resting;         // touching: rests with another
    std::vector<Rest> rests;             // where each of `resting` rests, and on what
    std::vector<std::uint32_t> restingGroup;  // the root of a group resting as placed, or ~0u
    for (std::uint32_t i = 0; i < moving.size(); ++i) {
        const Placed& b = moving[i];
        const Vec2 placedAt = reg.tryGet<Position>(b.body)->value;
        const std::uint32_t root = findRoot(group, i);
        const std::optional<Under>& under = groupUnder[root];
        const std::optional<Rest> rest = under ? std::optional<Rest>(Rest{placedAt, *under}) : landing(b);
        if (!rest) continue;
        const Vec2 move = rest->at - placedAt;
        resting.push_back({b.lo + move, b.hi + move, b.size, b.touching, b.body});
        rests.push_back(*rest);
        restingGroup.push_back(under ? root : ~0u);
    }
    markTouching(resting);
    SteadyLoad strongest{gravity};
    for (std::size_t i = 0; i < resting.size(); ++i) {
        if (!resting[i].touching) continue;
        const Under& under = rests[i].under;
        const std::uint32_t root = restingGroup[i];
        Vec2 pulled = fieldAt(rests[i].at) - under.acceleration;
        // A dynamic support is pushed away by what rests on it.
        if (std::isfinite(under.mass))
            pulled = (1.0 + (root != ~0u ? groupMass[root] : movingMass) / under.mass) * pulled;
        const std::uint8_t by = root != ~0u && groupMass[root] > 0.0 ? pressed[root] : 0;
        const Vec2 field = by ? pulled + groupForce[root] / groupMass[root] : pulled;
        if (std::isfinite(field.x) && std::isfinite(field.y) && lengthSquared(field) > lengthSquared(strongest.load))
            strongest = {field, pulled != gravity, (by & 1) != 0, (by & 2) != 0};
    }
    return strongest;
}

} // namespace

double expectedPileOverlap(int depth, double gravity, double h, double massRatio, double hertzFraction,
                           double contactHertz) {
    // A resting soft contact compresses by load / (m_n omega^2). In a pile
    // `depth` bodies deep the lowest contacts between bodies carry about
    // (depth - 1) heavy bodies on a light one (world.hpp). kMeasured folds in
    // what the model leaves out (contacts share the load unevenly, a few
    // iterations do not fully converge); measured on the 30-row, 300-circle
    // pile (docs/collisions.md, "Substeps when the level gives none").
    constexpr double kMeasured = 1.0;
    if (depth < 2 || !(gravity > 0.0) || !(h > 0.0)) return 0.0;
    const double ratio = std::max(1.0, massRatio);
    return kMeasured * double(depth - 1) * (1.0 + ratio) * gravity / contactOmega2(h, hertzFraction, contactHertz);
}

double expectedSupportOverlap(int depth, double gravity, double h, double massRatio, double hertzFraction,
                              double contactHertz) {
    if (depth < 1 || !(gravity > 0.0) || !(h > 0.0)) return 0.0;
    const double ratio = std::max(1.0, massRatio);
    return (double(depth - 1) * ratio + 1.0) * gravity / contactOmega2(h, hertzFraction, contactHertz);
}

double derivedRestitutionThreshold(double gravity, double h) { return 4.0 * gravity * h; }

double loadSpeedup(double gravity) { return std::sqrt(std::max(1.0, gravity / kReferenceGravity)); }

std::string ContactSettingsChoice::reason() const {
    std::string out;
    const auto add = [&](const std::string& part) { out += (out.empty() ? "" : "; ") + part; };
    // The rules that set the choice, and the pile's depth whenever there is one.
    if (stackDepth >= 2)
        add("pile " + std::to_string(stackDepth) + " deep" +
            (massRatio > 1.0 ? ", mass ratio " + number(massRatio) + ":1" : std::string()));
    if (columnHeight > stackDepth) add("stack " + std::to_string(columnHeight) + " high");
    {
        // What loads resting bodies past gravity: "attractors", "springs and motors", ...
        std::vector<std::string> by;
        if (attractorLoad) by.push_back("attractors");
        if (springLoad) by.push_back("springs");
        if (motorLoad) by.push_back("motors");
        std::string named;
        for (std::size_t k = 0; k < by.size(); ++k)
            named += (k == 0 ? "" : k + 1 == by.size() ? " and " : ", ") + by[k];
        if (!by.empty()) add(named + " load resting bodies at up to " + number(gravity) + " m/s^2");
    }
    if (loadSubsteps > 1 && loadSubsteps == substeps)
        add("load " + number(gravity) + " m/s^2 on " + number(diameter) + " m bodies" +
            (support > 0.0 ? ", supports " + number(support) + " m thick" : std::string()));
    if (contactHertz > kContactHertz) add("contacts stiffened to " + number(contactHertz) + " Hz");
    if (springSubsteps > 1 && springSubsteps == substeps) add("springs up to " + number(springRate) + " rad/s");
    if (impactSubsteps > 1 && impactSubsteps == substeps)
        add("impact " + number(impactSpeed) + " m/s on " + number(impactSize) + " m bodies" +
            (impactMassRatio > 1.0 ? ", mass ratio " + (std::isinf(impactMassRatio) ? std::string("kinematic")
                                                                                    : number(impactMassRatio) + ":1")
                                   : std::string()));
    if (jointSupportSubsteps > 1 && jointSupportSubsteps == substeps)
        add("bodies " + number(jointSupportRatio) + " times as heavy as jointed bodies they can rest on");
    if (jointLoopSubsteps > 1 && jointLoopSubsteps == substeps)
        add(std::to_string(jointLoops) + " joint" + (jointLoops == 1 ? "" : "s") + " in loops at " +
            number(jointLoopHertz) + " Hz");
    if (substeps == 1) add(out.empty() ? "nothing in the scene needs more" : "nothing needs more");
    return out;
}

ContactSettingsChoice chooseContactSettings(const Scene& scene, const SystemSwitches& switches) {
    ContactSettingsChoice choice;
    const Registry& reg = scene.registry;
    const auto& order = reg.entities();
    // A kinematic body carries loads like a static one.
    const auto isStatic = [&](Entity e) {
        const Static* st = reg.tryGet<Static>(e);
        const Kinematic* k = reg.tryGet<Kinematic>(e);
        return (st && st->value) || (k && k->value);
    };
    // With contacts switched off no shape takes part.
    const auto hasShape = [&](Entity e) {
        return switches.collisions && (reg.has<Radius>(e) || reg.has<Box>(e) || reg.has<Polygon>(e) ||
                                       reg.has<Capsule>(e) || reg.has<Shapes>(e));
    };
    // An emitter's copies and shapeless emitters are left out: the choice is
    // the scene's as written, whatever copies a run has made. A template
    // counts for the copies it stands for.
    const auto dynamic = [&](Entity e) {
        return reg.alive(e) && reg.has<Position>(e) && !isStatic(e) && !detail::outsideTheChoice(reg, e);
    };
    const auto massOf = [&](Entity e) {
        if (reg.has<Mass>(e)) return reg.tryGet<Mass>(e)->value;
        const Shapes* shapes = reg.tryGet<Shapes>(e);
        return shapes ? compoundMassProperties(*shapes, std::nullopt).mass : 1.0;
    };
    const SteadyLoad steady = steadyLoad(scene, switches, isStatic, dynamic, massOf, hasShape);
    const Vec2 gravity = steady.load;
    choice.gravity = length(gravity);
    choice.attractorLoad = steady.attractors;
    choice.springLoad = steady.springs;
    choice.motorLoad = steady.motors;
    const Vec2 down = choice.gravity > 0.0 ? gravity / choice.gravity : Vec2{0.0, -1.0};
    const Vec2 across{-down.y, down.x};
    const auto sizeOf = [&](Entity e) {
        return hasShape(e) ? 2.0 * std::max(halfExtentAlong(reg, e, across), halfExtentAlong(reg, e, down))
                           : 2.0 * detail::kShapelessRadius;
    };

    // Joint groups: dynamic bodies joined by joints (union-find in scene
    // order), and whether a group hangs from a static body or the world
    // (such a group does not pile).
    std::unordered_map<std::uint32_t, std::uint32_t> slot;  // entity index -> dense index
    std::vector<Entity> bodies;
    for (const Entity e : order)
        if (dynamic(e)) {
            slot.emplace(e.index, std::uint32_t(bodies.size()));
            bodies.push_back(e);
        }
    std::vector<std::uint32_t> parent(bodies.size());
    for (std::uint32_t i = 0; i < parent.size(); ++i) parent[i] = i;
    std::vector<std::uint8_t> jointed(bodies.size(), 0), anchored(bodies.size(), 0);
    // The rigid joints alone, for the loops they close (a joint with its
    // own stiffness is a spring, not corrected at the loop stiffness).
    std::vector<std::uint32_t> rigidParent = parent;
    for (const Entity e : order) {
        const Joint* j = reg.tryGet<Joint>(e);
        if (!j) continue;
        const bool da = !j->a.isNull() && dynamic(j->a), db = !j->b.isNull() && dynamic(j->b);
        if (da) jointed[slot[j->a.index]] = 1;
        if (db) jointed[slot[j->b.index]] = 1;
        if (da && db) {
            const std::uint32_t ra = findRoot(parent, slot[j->a.index]), rb = findRoot(parent, slot[j->b.index]);
            if (ra != rb) parent[std::max(ra, rb)] = std::min(ra, rb);
            const bool sprung = (j->type == "weld" || j->type == "distance") && j->stiffnessHz.value_or(0.0) > 0.0;
            if (!sprung) {
                const std::uint32_t qa = findRoot(rigidParent, slot[j->a.index]);
                const std::uint32_t qb = findRoot(rigidParent, slot[j->b.index]);
                if (qa == qb) ++choice.jointLoops;
                else rigidParent[std::max(qa, qb)] = std::min(qa, qb);
            }
        } else if (da || db) {
            anchored[slot[da ? j->a.index : j->b.index]] = 1;
        }
    }
    std::vector<std::uint8_t> groupAnchored(bodies.size(), 0);
    for (std::uint32_t i = 0; i < bodies.size(); ++i)
        if (jointed[i]) groupAnchored[findRoot(parent, i)] |= anchored[i];
    // The pile: dynamic shapes that are free to come to rest on each other
    // (a group hanging from the world does not pile).
    std::vector<double> sizes;
    std::vector<Vec2> places;  // each pile body's (across, up) coordinates, m
    double lightest = 0.0, heaviestMass = 0.0;
    for (std::uint32_t i = 0; i < bodies.size(); ++i) {
        if (!hasShape(bodies[i])) continue;
        if (jointed[i] && groupAnchored[findRoot(parent, i)]) continue;
        sizes.push_back(sizeOf(bodies[i]));
        const Vec2 p = reg.tryGet<Position>(bodies[i])->value;
        places.push_back({dot(p, across), -dot(p, down)});
        const double m = massOf(bodies[i]);
        lightest = sizes.size() == 1 ? m : std::min(lightest, m);
        heaviestMass = std::max(heaviestMass, m);
    }
    // Columns: flat-faced bodies (boxes, polygons) stand on one another as
    // placed, where circles roll off into a heap. In bins one median flat
    // body wide across gravity: the fullest bin is how tall a stack the
    // bodies can make (columnHeight, the column rule below), and the
    // tallest run of bodies that touch the one below (a gap under a quarter
    // of a body) is how tall a stack stands as placed (stackHeight, the
    // deep-column contacts); bodies placed apart, such as ragdolls waiting
    // to fall, make the first but not the second. (A resumed run uses its
    // recorded choice, so where the bodies are now only matters for a level
    // as authored.)
    {
        struct Flat {
            double across, bottom, top, size;
        };
        std::vector<Flat> flat;
        for (std::uint32_t i = 0; i < bodies.size(); ++i) {
            const Entity e = bodies[i];
            if (!switches.collisions || !(reg.has<Box>(e) || reg.has<Polygon>(e))) continue;
            if (jointed[i] && groupAnchored[findRoot(parent, i)]) continue;
            const Vec2 p = reg.tryGet<Position>(e)->value;
            // Height against gravity: the centre, then half the extent.
            const double up = -(dot(p, down) + centreAlong(reg, e, down)), half = halfExtentAlong(reg, e, down);
            flat.push_back({dot(p, across), up - half, up + half, sizeOf(e)});
        }
        std::vector<double> flatSizes;
        for (const Flat& f : flat) flatSizes.push_back(f.size);
        const double width = median(flatSizes);
        if (width > 0.0) {
            std::map<long long, std::vector<const Flat*>> columns;
            for (const Flat& f : flat) columns[(long long)std::floor(f.across / width)].push_back(&f);
            for (auto& [column, members] : columns) {
                choice.columnHeight = std::max(choice.columnHeight, int(members.size()));
                std::sort(members.begin(), members.end(), [](const Flat* a, const Flat* b) {
                    return a->bottom != b->bottom ? a->bottom < b->bottom : a->top < b->top;
                });
                int run = 1;
                double reach = members.front()->top;
                choice.stackHeight = std::max(choice.stackHeight, 1);
                for (std::size_t k = 1; k < members.size(); ++k) {
                    run = members[k]->bottom - reach <= 0.25 * width ? run + 1 : 1;
                    reach = run == 1 ? members[k]->top : std::max(reach, members[k]->top);
                    choice.stackHeight = std::max(choice.stackHeight, run);
                }
            }
            choice.columnWidth = width;
        }
    }
    // What holds them up: static shapes and planes. A wide one is a floor,
    // a tall one a wall; walls across the widest floor cut it into bays,
    // and the widest bay a body fits in is the container's width (planes
    // facing each other bound it exactly).
    struct Interval {
        double lo, hi;
    };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    std::optional<Interval> floor;
    std::vector<Interval> walls;
    double left = -kInf, right = kInf;  // plane walls: the side bodies stay on
    double thinnest = kInf;
    struct FloorPiece {
        Interval span;
        double top;  // m, against gravity
    };
    std::vector<FloorPiece> floorPieces;
    static const std::vector<Entity> kNoEntities;
    for (const Entity e : switches.collisions ? order : kNoEntities) {
        if (const Plane* p = reg.tryGet<Plane>(e)) {
            const double len = length(p->normal);
            if (!(len > 0.0)) continue;
            const Vec2 n = p->normal / len;
            const double up = -dot(n, down), side = dot(n, across);
            if (up > 0.7) {
                floor = Interval{-kInf, kInf};
            } else if (std::abs(side) > 0.7) {
                const double at = p->offset / side;  // where the wall crosses the across axis
                if (side > 0.0) left = std::max(left, at);
                else right = std::min(right, at);
            }
            continue;
        }
        if (const Chain* chain = reg.tryGet<Chain>(e); chain && isStatic(e) && reg.has<Position>(e)) {
            // Terrain and containers drawn as chains: one floor as wide as
            // the chain (its sides, steep or curved, bound the pile it
            // holds), resting at its lowest segment flatter than steep. A
            // chain has no thickness to cross, so it sets no support.
            const Vec2 pos = reg.tryGet<Position>(e)->value;
            const collision::Rot q = collision::Rot::fromAngle(reg.has<Angle>(e) ? reg.tryGet<Angle>(e)->value : 0.0);
            const std::size_t n = chain->points.size(), segments = chain->loop ? n : n - 1;
            Interval span{kInf, -kInf};
            double top = kInf;
            for (std::size_t k = 0; k < segments && n >= 2; ++k) {
                const Vec2 a = pos + collision::rotate(q, chain->points[k]);
                const Vec2 b = pos + collision::rotate(q, chain->points[(k + 1) % n]);
                span = {std::min({span.lo, dot(a, across), dot(b, across)}),
                        std::max({span.hi, dot(a, across), dot(b, across)})};
                if (std::abs(dot(b - a, across)) >= std::abs(dot(b - a, down)))
                    top = std::min(top, std::max(-dot(a, down), -dot(b, down)));
            }
            if (std::isfinite(top)) floorPieces.push_back({span, top});
            continue;
        }
        if (!hasShape(e) || !isStatic(e) || !reg.has<Position>(e)) continue;
        const Vec2 pos = reg.tryGet<Position>(e)->value;
        const double halfAcross = halfExtentAlong(reg, e, across), halfDown = halfExtentAlong(reg, e, down);
        const double c = dot(pos, across) + centreAlong(reg, e, across);
        const Interval span{c - halfAcross, c + halfAcross};
        thinnest = std::min(thinnest, 2.0 * halfDown);
        if (halfAcross >= halfDown) {
            const double top = -(dot(pos, down) + centreAlong(reg, e, down)) + halfDown;
            floorPieces.push_back({span, top});
        } else {
            walls.push_back(span);
        }
    }
    // A floor laid as tiles is one floor: pieces side by side whose tops
    // are level within a quarter body and whose gaps no body fits through
    // (under the median body) are joined into runs, and the widest run is
    // the floor. Taken one tile at a time, a floor of 0.5 m tiles would
    // hold one body a row and every body would count as one column.
    std::vector<FloorPiece> runs;
    std::size_t widestRun = std::size_t(-1);  // the run that is `floor`, if one is
    if (!floorPieces.empty()) {
        const double d = median(sizes);
        std::sort(floorPieces.begin(), floorPieces.end(), [](const FloorPiece& a, const FloorPiece& b) {
            return a.top != b.top ? a.top > b.top : a.span.lo < b.span.lo;
        });
        // Level bands from the highest top down; in each, runs by position.
        for (std::size_t i = 0; i < floorPieces.size();) {
            std::size_t j = i + 1;
            while (j < floorPieces.size() && floorPieces[i].top - floorPieces[j].top <= 0.25 * d) ++j;
            std::vector<Interval> band;
            for (std::size_t k = i; k < j; ++k) band.push_back(floorPieces[k].span);
            std::sort(band.begin(), band.end(), [](const Interval& a, const Interval& b) { return a.lo < b.lo; });
            Interval run = band.front();
            for (std::size_t k = 1; k <= band.size(); ++k) {
                if (k < band.size() && band[k].lo - run.hi < d) {
                    run.hi = std::max(run.hi, band[k].hi);
                    continue;
                }
                if (!floor || run.hi - run.lo > floor->hi - floor->lo) {
                    floor = run;
                    widestRun = runs.size();
                }
                runs.push_back({run, floorPieces[i].top});
                if (k < band.size()) run = band[k];
            }
            i = j;
        }
    }
    choice.support = std::isfinite(thinnest) ? thinnest : 0.0;
    // Without gravity nothing piles up, whatever the geometry.
    if (choice.gravity > 0.0 && !sizes.empty() && (floor || !walls.empty())) {
        choice.diameter = median(sizes);
        choice.massRatio = heaviestMass / lightest;
        const double d = choice.diameter;
        std::sort(walls.begin(), walls.end(), [](const Interval& a, const Interval& b) { return a.lo < b.lo; });
        // How deep n bodies heap on `ground`, in its widest bay.
        const auto depthOn = [&](Interval ground, long long n) {
            ground.lo = std::max(ground.lo, left);
            ground.hi = std::min(ground.hi, right);
            double widestBay = 0.0, widestFiniteBay = 0.0, from = ground.lo;
            for (const Interval& w : walls) {
                if (w.hi <= ground.lo || w.lo >= ground.hi) continue;
                const double bay = w.lo - from;
                widestBay = std::max(widestBay, bay);
                if (std::isfinite(bay) && bay >= d) widestFiniteBay = std::max(widestFiniteBay, bay);
                from = std::max(from, w.hi);
            }
            const double last = ground.hi - from;
            widestBay = std::max(widestBay, last);
            if (std::isfinite(last) && last >= d) widestFiniteBay = std::max(widestFiniteBay, last);
            const double width = widestFiniteBay > 0.0 ? widestFiniteBay : widestBay;
            // A heap on open ground: rows of 1, 2, 3 ... bodies, k deep for
            // k (k + 1) / 2 >= n. On ground `width` wide, rows hold at most
            // floor(width / d): the heap is no wider than that, and the
            // bodies fill ceil(n / per row) full rows.
            long long heap = 1;
            while (heap * (heap + 1) / 2 < n) ++heap;
            long long depth = heap;
            if (std::isfinite(width) && d > 0.0) {
                const long long perRow = std::max(1LL, (long long)std::floor(width / d));
                depth = std::max((n + perRow - 1) / perRow, std::min(heap, perRow));
            }
            return depth;
        };
        // Each body heaps on the highest floor run below it (shelves, the
        // levels of a building, many pyramids on their own grounds); a body
        // above none heaps on the widest floor, or the open ground.
        std::vector<long long> onRun(runs.size(), 0);
        long long elsewhere = 0;
        for (const Vec2& place : places) {
            std::size_t best = runs.size();
            for (std::size_t r = 0; r < runs.size(); ++r)
                if (runs[r].top <= place.y && place.x >= runs[r].span.lo - 0.5 * d &&
                    place.x <= runs[r].span.hi + 0.5 * d && (best == runs.size() || runs[r].top > runs[best].top))
                    best = r;
            if (best < runs.size()) ++onRun[best];
            else if (widestRun < runs.size()) ++onRun[widestRun];
            else ++elsewhere;
        }
        long long depth = elsewhere > 0 ? depthOn(floor ? *floor : Interval{-kInf, kInf}, elsewhere) : 0;
        for (std::size_t r = 0; r < runs.size(); ++r)
            if (onRun[r] > 0) depth = std::max(depth, depthOn(runs[r].span, onRun[r]));
        choice.stackDepth = int(std::min<long long>(depth, 1'000'000));
    }

    // A deep column of boxes standing under gravity gets softer contacts
    // (kDeepColumn), and the rules below count with them.
    choice.hertzFraction = choice.gravity > 0.0 && choice.stackHeight > kDeepColumn ? 0.125 : 0.25;
    const double fraction = choice.hertzFraction;

    // The fewest substeps that hold every rule: up to kMaxContactSubsteps
    // for the contact rules, 16 for the joints'.
    const double dt = scene.world.dt;
    // Each contact rule asks that an overlap, load / (m omega^2), stay
    // under a limit: overlap(h, hertz) for substeps of h and stiffness
    // hertz (capped at `fraction` of the substep rate).
    const auto pileOverlap = [&](double h, double hertz) {
        return expectedPileOverlap(choice.stackDepth, choice.gravity, h, choice.massRatio, fraction, hertz);
    };
    const double pileLimit = 0.01 * choice.diameter;
    const auto loadOverlap = [&](double h, double hertz) {
        return choice.stackDepth < 1
                   ? 0.0
                   : expectedSupportOverlap(choice.stackDepth, choice.gravity, h, choice.massRatio, fraction, hertz);
    };
    const double loadLimit = choice.support > 0.0 ? std::min(pileLimit, 0.1 * choice.support) : pileLimit;
    // A column's layers compress in series: the contact k layers down
    // carries k bodies, so the top sinks by the sum, n (n - 1) / 2 times a
    // layer's load overlap; it must stay under 1% of a body.
    const auto columnOverlap = [&](double h, double hertz) {
        if (choice.columnHeight < 2) return 0.0;
        const double n = double(choice.columnHeight);
        return 0.5 * n * (n - 1.0) * expectedPileOverlap(2, choice.gravity, h, 1.0, fraction, hertz);
    };
    const double columnLimit = 0.01 * choice.columnWidth;
    // The stiffness the rules need under a strong load: the default
    // (kContactHertz) unless a rule fails there at any substeps; then the
    // stiffness at which it holds (the overlap falls as 1 / hertz^2),
    // reached with substeps fine enough to carry it. At most the default
    // scaled by sqrt(g / kReferenceGravity), which keeps every overlap where
    // it is at 10 m/s^2: the default was measured there, and a 100-row
    // pyramid, which the rules read as far deeper than it sinks, runs as
    // it did.
    {
        constexpr double kUncapped = 1e-12;  // s: a substep short enough that only the stiffness caps omega
        const double base = kContactHertz;
        const auto needs = [&](const auto& overlap, double limit) {
            const double at = overlap(kUncapped, base);
            return at > limit && limit > 0.0 ? base * std::sqrt(at / limit) : base;
        };
        const double needed = std::max({base, needs(pileOverlap, pileLimit), needs(loadOverlap, loadLimit),
                                        needs(columnOverlap, columnLimit)});
        choice.contactHertz = std::min(needed, base * loadSpeedup(choice.gravity));
    }
    const double hertz = choice.contactHertz;
    const auto pileHolds = [&](int s) { return pileOverlap(dt / s, hertz) <= pileLimit; };
    const auto loadHolds = [&](int s) { return loadOverlap(dt / s, hertz) <= loadLimit; };
    const auto columnHolds = [&](int s) { return columnOverlap(dt / s, hertz) <= columnLimit; };
    // A contact rule that cannot hold stops where more substeps stop
    // stiffening the contacts (the stiffness chosen above).
    const auto contactsSaturated = [&](int s) {
        return contactOmega2(dt / s, fraction, hertz) == contactOmega2(dt / (2 * s), fraction, hertz);
    };
    const auto fewest = [&](const auto& holds, bool contact) {
        int s = 1;
        for (; s < kMaxContactSubsteps; s = std::min(2 * s, kMaxContactSubsteps))
            if (holds(s) || (contact && contactsSaturated(s))) break;
        return s;
    };
    choice.pileSubsteps = std::max(fewest(pileHolds, true), fewest(columnHolds, true));
    choice.loadSubsteps = fewest(loadHolds, true);
    // Chains and other trees of joints add no rule: the joint solver holds
    // them exactly at any substep count (direct_joints.hpp). Joints in loops
    // are iterated at their loop stiffness (kLoopJointHertzFraction).
    if (choice.jointLoops > 0) {
        choice.jointLoopHertz = scene.world.jointHz.value_or(joints::JointSettings::kLoopHertz);
        const double perStep = dt * choice.jointLoopHertz / kLoopJointHertzFraction;
        if (perStep > 0.0) choice.jointLoopSubsteps = detail::wholeSubsteps(perStep, 16.0);
    }
    // A body that can pile onto a joint group hung from the world (a crate
    // on a bridge) against the lightest body of such groups
    // (kJointSupportRatio).
    double lightestHung = 0.0;
    for (std::uint32_t i = 0; i < bodies.size(); ++i)
        if (jointed[i] && groupAnchored[findRoot(parent, i)] && hasShape(bodies[i])) {
            const double m = massOf(bodies[i]);
            if (m > 0.0) lightestHung = lightestHung > 0.0 ? std::min(lightestHung, m) : m;
        }
    if (switches.collisions && choice.gravity > 0.0 && lightestHung > 0.0 && heaviestMass > 0.0) {
        choice.jointSupportRatio = heaviestMass / lightestHung;
        int s = 1;
        while (s < 16 && choice.jointSupportRatio > kJointSupportRatio * double(s) * double(s)) s *= 2;
        choice.jointSupportSubsteps = s;
    }
    choice.springRate = springRate(scene, switches);
    choice.springSubsteps = detail::wholeSubsteps(dt * choice.springRate, 1000.0);
    impactRule(scene, switches, dt, choice);
    choice.substeps =
        std::max({choice.pileSubsteps, choice.loadSubsteps, choice.springSubsteps, choice.impactSubsteps,
                  choice.jointLoopSubsteps, choice.jointSupportSubsteps});
    choice.iterations = choice.substeps == 1 ? 8 : 2;
    return choice;
}

} // namespace stepwise
