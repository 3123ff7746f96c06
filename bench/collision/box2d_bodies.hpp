#pragma once
// One Box2D 2.4.1 body from one Stepwise body, for the comparisons
// (collision_vs_box2d, joints_vs_box2d): the same pose, velocity, spin,
// material, drag, shape and mass, so both engines start from the same state.

#include "stepwise/components.hpp"
#include "stepwise/registry.hpp"

#include <box2d/box2d.h>

#include <cmath>
#include <cstdint>
#include <vector>

namespace stepwise::bench {

inline bool isStaticBody(const Registry& r, Entity e) { return r.has<Static>(e) && r.tryGet<Static>(e)->value; }

/// Box2D 2.4.1 has no capsule: the same outline as the union of a box along
/// the segment and a disc at each end, three fixtures of equal density
/// whose areas sum to `mass` (the overlaps make the inertia a little high).
inline void addBox2dCapsule(b2Body* body, b2FixtureDef fd, Vec2 a, Vec2 b, double radius, double mass) {
    const Vec2 d = b - a;
    const double length = std::sqrt(d.x * d.x + d.y * d.y);
    const double area = 2.0 * radius * length + 2.0 * M_PI * radius * radius;
    fd.density = float(mass / area);
    b2CircleShape ends[2];
    for (int k = 0; k < 2; ++k) {
        const Vec2 c = k == 0 ? a : b;
        ends[k].m_radius = float(radius);
        ends[k].m_p.Set(float(c.x), float(c.y));
        fd.shape = &ends[k];
        body->CreateFixture(&fd);
    }
    if (length > 0.0) {
        b2PolygonShape core;
        core.SetAsBox(float(0.5 * length), float(radius), b2Vec2(float(0.5 * (a.x + b.x)), float(0.5 * (a.y + b.y))),
                      float(std::atan2(d.y, d.x)));
        fd.shape = &core;
        body->CreateFixture(&fd);
    }
}

/// Creates `e`'s body in `world` (static when Static, else dynamic), with a
/// fixture for its radius, box, polygon (rounded too), chain or capsule (see
/// addBox2dCapsule), one per compound shape (none when it has no shape). Mass
/// as Stepwise's: `mass`, else 1 kg, spread over the shape's area; friction
/// and restitution as the components say, else Stepwise's defaults 0.2 and
/// 0. Drag b (force -b v) becomes Box2D's linear damping b/m (dv/dt = -c v).
inline b2Body* createBox2dBody(b2World& world, const Registry& r, Entity e) {
    b2BodyDef def;
    def.type = isStaticBody(r, e) ? b2_staticBody : b2_dynamicBody;
    if (const Position* p = r.tryGet<Position>(e)) def.position.Set(float(p->value.x), float(p->value.y));
    if (const Velocity* v = r.tryGet<Velocity>(e)) def.linearVelocity.Set(float(v->value.x), float(v->value.y));
    if (const Angle* a = r.tryGet<Angle>(e)) def.angle = float(a->value);
    if (const AngularVelocity* w = r.tryGet<AngularVelocity>(e)) def.angularVelocity = float(w->value);
    const Shapes* shapes = r.tryGet<Shapes>(e);
    const double mass = r.has<Mass>(e)  ? r.tryGet<Mass>(e)->value
                        : shapes ? compoundMassProperties(*shapes, std::nullopt).mass
                                 : 1.0;
    if (const Drag* d = r.tryGet<Drag>(e)) def.linearDamping = float(d->value / mass);
    b2Body* body = world.CreateBody(&def);
    b2FixtureDef fd;
    fd.friction = float(r.has<Friction>(e) ? r.tryGet<Friction>(e)->value : 0.2);
    fd.restitution = float(r.has<Restitution>(e) ? r.tryGet<Restitution>(e)->value : 0.0);
    // 2.4.1's filter has 16-bit categories and masks and a 16-bit group.
    const auto box2dFilter = [](const Filter& f) {
        b2Filter out;
        out.categoryBits = std::uint16_t(f.category & 0xFFFFu);
        out.maskBits = std::uint16_t(f.mask & 0xFFFFu);
        out.groupIndex = std::int16_t(f.group);
        return out;
    };
    if (const Filter* f = r.tryGet<Filter>(e)) fd.filter = box2dFilter(*f);
    b2CircleShape circle;
    b2PolygonShape polygon;
    if (const Radius* c = r.tryGet<Radius>(e)) {
        circle.m_radius = float(c->value);
        fd.shape = &circle;
        fd.density = float(mass / (M_PI * c->value * c->value));
    } else if (const Box* b = r.tryGet<Box>(e)) {
        polygon.SetAsBox(float(b->width / 2), float(b->height / 2));
        fd.shape = &polygon;
        fd.density = float(mass / (b->width * b->height));
    } else if (const Polygon* poly = r.tryGet<Polygon>(e)) {
        b2Vec2 v[b2_maxPolygonVertices];
        for (std::size_t k = 0; k < poly->vertices.size(); ++k)
            v[k].Set(float(poly->vertices[k].x), float(poly->vertices[k].y));
        polygon.Set(v, int(poly->vertices.size()));
        // 2.4.1's polygon skin is the same Minkowski rounding.
        if (poly->radius) polygon.m_radius = float(*poly->radius);
        fd.shape = &polygon;
        fd.density = float(mass / polygonMassProperties(poly->vertices, poly->radius.value_or(0.0)).area);
    }
    b2ChainShape chainShape;
    if (const Chain* chain = r.tryGet<Chain>(e)) {
        // One-sided with the solid side on the right of the direction, as
        // Stepwise's; an open end's ghost continues the end segment straight.
        std::vector<b2Vec2> v;
        for (const Vec2 q : chain->points) v.emplace_back(float(q.x), float(q.y));
        if (chain->loop) {
            chainShape.CreateLoop(v.data(), int(v.size()));
        } else {
            const b2Vec2 prev = v.front() + (v.front() - v[1]), next = v.back() + (v.back() - v[v.size() - 2]);
            chainShape.CreateChain(v.data(), int(v.size()), prev, next);
        }
        fd.shape = &chainShape;
    }
    if (fd.shape) body->CreateFixture(&fd);
    if (const Capsule* cap = r.tryGet<Capsule>(e)) addBox2dCapsule(body, fd, cap->a, cap->b, cap->radius, mass);
    if (shapes) {
        // A fixture per shape; densities scaled as Stepwise scales them to `mass`.
        const double scale = mass / compoundMassProperties(*shapes, std::nullopt).mass;
        for (const CompoundShape& s : shapes->items) {
            b2FixtureDef part = fd;
            part.friction = float(s.friction.value_or(fd.friction));
            part.restitution = float(s.restitution.value_or(fd.restitution));
            part.isSensor = s.sensor.value_or(false);
            if (s.filter) part.filter = box2dFilter(*s.filter);
            part.density = float(s.density.value_or(1.0) * scale);
            b2CircleShape c;
            b2PolygonShape p;
            if (s.kind == CompoundShape::Kind::Circle) {
                c.m_radius = float(s.radius);
                c.m_p.Set(float(s.center.x), float(s.center.y));
                part.shape = &c;
            } else if (s.kind == CompoundShape::Kind::Box) {
                p.SetAsBox(float(s.width / 2), float(s.height / 2), b2Vec2(float(s.center.x), float(s.center.y)),
                           float(s.angle));
                part.shape = &p;
            } else if (s.kind == CompoundShape::Kind::Polygon) {
                b2Vec2 v[b2_maxPolygonVertices];
                for (std::size_t k = 0; k < s.vertices.size(); ++k)
                    v[k].Set(float(s.vertices[k].x), float(s.vertices[k].y));
                p.Set(v, int(s.vertices.size()));
                if (s.cornerRadius) p.m_radius = float(*s.cornerRadius);
                part.shape = &p;
            } else {
                const double area = capsuleMassProperties(length(s.b - s.a), s.radius).area;
                addBox2dCapsule(body, part, s.a, s.b, s.radius, part.density * area);
                continue;
            }
            body->CreateFixture(&part);
        }
    }
    return body;
}

/// A b2RevoluteJoint for Stepwise hinge `j` (the same anchors, reference
/// angle, limits and motor) between the bodies made for its ends;
/// `worldBody` stands for the world when `j.b` is null.
inline b2Joint* createBox2dHinge(b2World& world, const Joint& j, b2Body* a, b2Body* b) {
    b2RevoluteJointDef def;
    def.bodyA = a;
    def.bodyB = b;
    def.localAnchorA.Set(float(j.localA.x), float(j.localA.y));
    def.localAnchorB.Set(float(j.localB.x), float(j.localB.y));
    def.referenceAngle = float(j.referenceAngle.value_or(0.0));
    def.collideConnected = j.collideConnected;
    if (j.lower || j.upper) {
        def.enableLimit = true;
        def.lowerAngle = float(j.lower.value_or(-1e9));
        def.upperAngle = float(j.upper.value_or(1e9));
    }
    if (j.maxMotorTorque) {
        def.enableMotor = true;
        def.motorSpeed = float(j.motorSpeed.value_or(0.0));
        def.maxMotorTorque = float(*j.maxMotorTorque);
    }
    return world.CreateJoint(&def);
}

} // namespace stepwise::bench
