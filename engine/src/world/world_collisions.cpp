#include "world/world_collisions.hpp"

#include "stepwise/components.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace stepwise::detail {

std::unique_ptr<collision::CollisionSystem> buildCollisions(
    const Scene& scene, const std::function<std::uint32_t(Entity)>& bodyOf, std::uint32_t noBody) {
    const Registry& reg = scene.registry;
    std::unique_ptr<collision::CollisionSystem> system;
    for (const Entity e : reg.entities()) {
        collision::Collider c;
        if (const Radius* r = reg.tryGet<Radius>(e)) {
            c.shape.kind = collision::ShapeKind::Circle;
            c.shape.radius = r->value;
        } else if (const Box* b = reg.tryGet<Box>(e)) {
            c.shape.kind = collision::ShapeKind::Box;
            c.shape.halfExtents = {0.5 * b->width, 0.5 * b->height};
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
        }
        system->add(c, angle, spin);
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
