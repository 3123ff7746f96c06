#pragma once
// Scenes with analytic answers, built in code, shared by test_forces,
// test_integrators and test_world.

#include "stepwise/components.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/world.hpp"

#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>
#include <string>

namespace stepwise::testing {

inline Scene emptyScene(std::string integrator, double dt, Vec2 gravity = {0.0, 0.0}) {
    Scene s;
    s.world.integrator = std::move(integrator);
    s.world.dt = dt;
    s.world.gravity = gravity;
    return s;
}

inline Entity addBody(Scene& s, const std::string& name, Vec2 p, Vec2 v, double mass = 1.0) {
    Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {name});
    s.registry.emplace<Position>(e, {p});
    s.registry.emplace<Velocity>(e, {v});
    s.registry.emplace<Mass>(e, {mass});
    return e;
}

inline Entity addStatic(Scene& s, const std::string& name, Vec2 p, double mass = 1.0) {
    Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {name});
    s.registry.emplace<Position>(e, {p});
    s.registry.emplace<Static>(e, {true});
    s.registry.emplace<Mass>(e, {mass});
    return e;
}

/// The entity called `name` (springs hold handles; these builders take names
/// for readability). A null handle when there is none.
inline Entity entityNamed(const Scene& s, const std::string& name) {
    for (Entity e : s.registry.entities())
        if (const Name* n = s.registry.tryGet<Name>(e); n && n->value == name) return e;
    return {};
}

inline Entity addSpring(Scene& s, const std::string& name, const std::string& a, const std::string& b, double k,
                        double damping, double rest) {
    Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {name});
    Spring sp;
    sp.a = entityNamed(s, a);
    sp.b = entityNamed(s, b);
    sp.k = k;
    sp.damping = damping;
    sp.restLength = rest;
    s.registry.emplace<Spring>(e, sp);
    return e;
}

inline Entity addAnchoredSpring(Scene& s, const std::string& name, const std::string& a, Vec2 anchor, double k,
                                double damping, double rest) {
    Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {name});
    Spring sp;
    sp.a = entityNamed(s, a);
    sp.anchor = anchor;
    sp.k = k;
    sp.damping = damping;
    sp.restLength = rest;
    s.registry.emplace<Spring>(e, sp);
    return e;
}

/// x'' = -omega^2 x - gamma x' in both coordinates: a 1 kg-scale bob on a
/// zero-rest-length spring to the origin (F = -k p exactly, isotropic) with
/// drag b (gamma = b/m).
struct Oscillator {
    double k = 4.0, m = 1.0, b = 0.0;
    Vec2 p0{1.0, 0.0}, v0{0.0, 0.5};

    Scene scene(const std::string& integrator, double dt) const {
        Scene s = emptyScene(integrator, dt);
        // One substep: the tests measure the integrator at step dt, not the
        // substeps the engine would choose for the spring.
        s.world.substeps = 1;
        const Entity bob = addBody(s, "bob", p0, v0, m);
        if (b > 0.0) s.registry.emplace<Drag>(bob, {b});
        addAnchoredSpring(s, "spring", "bob", {0.0, 0.0}, k, 0.0, 0.0);
        return s;
    }
    /// Exact position and velocity at time t (underdamped).
    void exact(double t, Vec2& p, Vec2& v) const {
        const double w2 = k / m, g = b / m;
        const double wd = std::sqrt(w2 - 0.25 * g * g);
        const double decay = std::exp(-0.5 * g * t), c = std::cos(wd * t), s = std::sin(wd * t);
        auto component = [&](double x0, double u0, double& x, double& u) {
            const double A = x0, B = (u0 + 0.5 * g * x0) / wd;
            x = decay * (A * c + B * s);
            u = decay * (-0.5 * g * (A * c + B * s) + (-A * wd * s + B * wd * c));
        };
        component(p0.x, v0.x, p.x, v.x);
        component(p0.y, v0.y, p.y, v.y);
    }
};

/// Kepler problem: a static attractor of mass M (G = 1) at the origin and a
/// light body at perihelion of an orbit with semi-major axis a and
/// eccentricity e. Period 2 pi sqrt(a^3 / M).
struct Kepler {
    double M = 1.0, a = 1.0, e = 0.5;
    double softening = 0.0;  ///< m; the orbit formulas are exact only at 0
    double period() const { return 2.0 * std::numbers::pi * std::sqrt(a * a * a / M); }
    Vec2 p0() const { return {a * (1.0 - e), 0.0}; }
    Vec2 v0() const { return {0.0, std::sqrt(M * (1.0 + e) / (a * (1.0 - e)))}; }
    double energy() const { return -M / (2.0 * a); }  // per unit mass of the body
    Scene scene(const std::string& integrator, double dt) const {
        Scene s = emptyScene(integrator, dt);
        const Entity sun = addStatic(s, "sun", {0.0, 0.0}, M);
        s.registry.emplace<Attractor>(sun, {softening});
        addBody(s, "planet", p0(), v0(), 1.0);
        return s;
    }
};

inline World buildOrDie(const Scene& s) {
    Result<World> w = World::build(s);
    if (!w) throw std::runtime_error("World::build failed: " + w.error());
    return std::move(w.value());
}

} // namespace stepwise::testing
