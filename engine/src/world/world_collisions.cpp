#include "world/world_collisions.hpp"

#include "stepwise/components.hpp"

namespace stepwise::detail {

std::unique_ptr<collision::CollisionSystem> buildCollisions(
    const Scene& scene, const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody) {
    const Registry& reg = scene.registry;
    std::unique_ptr<collision::CollisionSystem> system;
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
        if (!system) {
            system = std::make_unique<collision::CollisionSystem>();
            system->settings().iterations = scene.world.solverIterations;
        }
        system->add(c, angle, spin);
    }
    return system;
}

} // namespace stepwise::detail
