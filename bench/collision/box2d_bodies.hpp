#pragma once
// One Box2D 2.4.1 body from one Stepwise body, for the comparisons
// (collision_vs_box2d, joints_vs_box2d): the same pose, velocity, spin,
// material, drag, shape and mass, so both engines start from the same state.

#include "stepwise/components.hpp"
#include "stepwise/registry.hpp"

#include <box2d/box2d.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <string>
#include <unordered_map>
#include <unordered_set>
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

/// The template `e` is part of (a prefab that emitters copy, never a body
/// of its own), or nullptr: its own `template`, or for a joint or spring the
/// template of its first end (the loader keeps a template's joints within it).
inline const std::string* templateOf(const Registry& r, Entity e) {
    if (const Template* t = r.tryGet<Template>(e)) return &t->value;
    Entity end;
    if (const Joint* j = r.tryGet<Joint>(e)) end = j->a;
    else if (const Spring* s = r.tryGet<Spring>(e)) end = s->a;
    if (end.isNull() || !r.alive(end)) return nullptr;
    const Template* t = r.tryGet<Template>(end);
    return t ? &t->value : nullptr;
}

inline bool inTemplate(const Registry& r, Entity e) { return templateOf(r, e) != nullptr; }

/// Whether `e` is an emitter's copy saved with a run ("TEMPLATE#N" or
/// "TEMPLATE#N/..." with TEMPLATE a template of the scene).
inline bool isEmittedCopy(const Registry& r, Entity e, const std::unordered_set<std::string>& templates) {
    const Name* n = r.tryGet<Name>(e);
    if (!n) return false;
    const std::size_t hash = n->value.find('#');
    return hash != std::string::npos && templates.count(n->value.substr(0, hash)) > 0;
}

/// The template names of a scene.
inline std::unordered_set<std::string> templateNames(const Registry& r) {
    std::unordered_set<std::string> out;
    for (const Entity e : r.entities())
        if (const Template* t = r.tryGet<Template>(e)) out.insert(t->value);
    return out;
}

/// A scene's emitters in a Box2D 2.4.1 world, on Stepwise's clock: before
/// each step, the copies whose lifetime is over leave, then every copy
/// due (the first step that starts within half a step of `next`) is added,
/// the oldest leaving first when `count` are alive; `next` advances by
/// `interval`, times summed as World::step sums them, so copies come and go
/// at the same steps in both engines. A copy is the template's bodies
/// (createBox2dBody) moved so that its first body lands on the emitter
/// (the emitter body's position when it has a shape), each with the
/// emitter's velocity, and its hinges (createBox2dHinge). Not mirrored,
/// and refused by start(): a `spread` (the engine's random turn), a run
/// resumed with copies alive, and joints other than hinges; springs are
/// left out as the harness leaves out every spring.
class Box2dEmitters {
public:
    struct Copy {
        std::vector<b2Body*> bodies;
        std::vector<b2Joint*> joints;
    };

    /// Reads the emitters of `r` (world time `time`, step `dt`); an empty
    /// string, or why the peer cannot mirror them.
    std::string start(const Registry& r, double time, double dt) {
        registry_ = &r;
        time_ = time;
        dt_ = dt;
        for (const Entity e : r.entities()) {
            const Emitter* em = r.tryGet<Emitter>(e);
            if (!em) continue;
            Run run;
            run.entity = e;
            run.params = *em;
            if (!run.params.next) run.params.next = time;
            if (em->spread != 0.0) return "the Box2D peer does not turn copies by an emitter's spread";
            if (em->alive > 0) return "the Box2D peer does not resume an emitter with copies alive";
            if (const Position* p = r.tryGet<Position>(e)) run.position = p->value;
            for (const Entity m : r.entities()) {
                const std::string* t = templateOf(r, m);
                if (!t || *t != em->templateName) continue;
                if (const Joint* j = r.tryGet<Joint>(m)) {
                    if (j->type != "hinge") return "Box2D port builds hinges only, not " + j->type;
                    run.joints.push_back(m);
                } else if (r.has<Position>(m) && !r.has<Spring>(m)) {
                    run.bodies.push_back(m);
                }
            }
            if (run.bodies.empty()) return "emitter template \"" + em->templateName + "\" has no body";
            runs_.push_back(std::move(run));
        }
        return {};
    }

    /// Before a step: removes and adds the copies due. `bodyOf` maps the
    /// level's entities (by index) to their bodies, for an emitter that is
    /// a body.
    void beforeStep(b2World& world, b2Body* ground, const std::unordered_map<std::uint32_t, b2Body*>& bodyOf) {
        const Registry& r = *registry_;
        const double now = time_ + 0.5 * dt_;
        for (Run& run : runs_) {
            Emitter& p = run.params;
            const auto removeOldest = [&] {
                Copy& gone = run.copies.front();
                for (b2Joint* j : gone.joints) world.DestroyJoint(j);
                for (b2Body* b : gone.bodies) world.DestroyBody(b);
                run.copies.pop_front();
                --p.alive;
                if (p.alive > 0) p.oldest = *p.oldest + p.interval;
                else p.oldest.reset();
            };
            while (p.lifetime && p.alive > 0 && now >= *p.oldest + *p.lifetime) removeOldest();
            for (int made = 0; now >= *p.next && made < kMaxEmissionsPerStep; ++made) {
                if (p.alive >= p.count) removeOldest();
                Vec2 at = run.position;
                if (const auto it = bodyOf.find(run.entity.index); it != bodyOf.end())
                    at = {it->second->GetPosition().x, it->second->GetPosition().y};
                const Vec2 offset = at - r.tryGet<Position>(run.bodies.front())->value;
                Copy copy;
                std::unordered_map<std::uint32_t, b2Body*> copyOf;
                for (const Entity m : run.bodies) {
                    b2Body* b = createBox2dBody(world, r, m);
                    const Vec2 q = r.tryGet<Position>(m)->value + offset;
                    b->SetTransform(b2Vec2(float(q.x), float(q.y)), b->GetAngle());
                    b->SetLinearVelocity(b2Vec2(float(p.velocity.x), float(p.velocity.y)));
                    copyOf.emplace(m.index, b);
                    copy.bodies.push_back(b);
                }
                for (const Entity m : run.joints) {
                    Joint j = *r.tryGet<Joint>(m);
                    if (j.b.isNull()) j.localB += offset;
                    copy.joints.push_back(
                        createBox2dHinge(world, j, copyOf.at(j.a.index), j.b.isNull() ? ground : copyOf.at(j.b.index)));
                }
                run.copies.push_back(std::move(copy));
                if (p.alive == 0) p.oldest = *p.next;
                ++p.alive;
                ++p.emitted;
                p.next = *p.next + p.interval;
            }
        }
    }

    /// After a step: the clock moves on as World::step moves it.
    void afterStep() { time_ += dt_; }

    /// Every copy alive, each emitter's oldest first.
    template <class F> void forEachCopy(F&& f) const {
        for (const Run& run : runs_)
            for (const Copy& c : run.copies) f(c);
    }

private:
    /// As the engine's cap: the rest wait for the next step.
    static constexpr int kMaxEmissionsPerStep = 1000;
    struct Run {
        Entity entity;
        Emitter params;
        Vec2 position;
        std::vector<Entity> bodies, joints;  ///< the template's, in scene order
        std::deque<Copy> copies;             ///< alive, oldest first
    };
    const Registry* registry_ = nullptr;
    double time_ = 0.0, dt_ = 0.0;
    std::vector<Run> runs_;
};

} // namespace stepwise::bench
