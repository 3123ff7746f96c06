// The speed-against-error report. See accuracy.hpp.
//
// Fairness: Stepwise's integrators run through World::step (the real
// pipeline, profiling off); the Odeint peers integrate the same ODE
// y = [x; v], y' = [v; a(x, v)] with a(x, v) computed by the SAME force
// model (forces/force_model.hpp), so the comparison is integrator against
// integrator, not force code against force code.

#include "report/accuracy.hpp"
#include "report/odeint_implicit.hpp"
#include "report/cpu_clock.hpp"
#include "report/scenes.hpp"

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/scene.hpp"
#include "stepwise/scene_io.hpp"
#include "stepwise/world.hpp"
#include "world/world_internals.hpp"

#include <boost/numeric/odeint/stepper/euler.hpp>
#include <boost/numeric/odeint/stepper/modified_midpoint.hpp>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>
#include <boost/numeric/odeint/stepper/symplectic_euler.hpp>
#include <boost/numeric/odeint/stepper/velocity_verlet.hpp>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cstdint>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <ostream>
#include <sstream>

namespace stepwise::report {

namespace odeint = boost::numeric::odeint;
using Clock = ThreadCpuClock;  // CPU time: see cpu_clock.hpp
using State = std::vector<double>;

namespace {

struct Problem {
    std::string name;
    std::string title;
    Scene scene;
    double T = 1.0;                  ///< s, simulated horizon
    std::vector<long> stepCounts;    ///< dt = T / N
    bool positionOnlyForces = false; ///< odeint symplectic_euler applies
    bool smallForDense = false;      ///< odeint implicit_euler (dense ublas LU) applies
    std::vector<double> reference;   ///< final positions, 2n
    std::string referenceName;
};

Entity body(Scene& s, const std::string& name, Vec2 p, Vec2 v, double m) {
    Entity e = s.registry.create();
    s.registry.emplace<Name>(e, {name});
    s.registry.emplace<Position>(e, {p});
    s.registry.emplace<Velocity>(e, {v});
    s.registry.emplace<Mass>(e, {m});
    return e;
}
void spring(Scene& s, const std::string& a, const std::string& b, std::optional<Vec2> anchor, double k, double c,
            double rest) {
    // Springs hold handles: look the ends up by name ("" = none).
    const auto named = [&](const std::string& name) {
        for (Entity x : s.registry.entities())
            if (const Name* n = s.registry.tryGet<Name>(x); n && !name.empty() && n->value == name) return x;
        return Entity{};
    };
    Spring sp;
    sp.a = named(a);
    sp.b = named(b);
    Entity e = s.registry.create();
    sp.anchor = anchor;
    sp.k = k;
    sp.damping = c;
    sp.restLength = rest;
    s.registry.emplace<Spring>(e, sp);
}

// x'' = -w^2 x - g x' per coordinate, exact solution.
Vec2 oscillatorExact(double k, double m, double b, Vec2 p0, Vec2 v0, double t) {
    const double w2 = k / m, g = b / m, wd = std::sqrt(w2 - 0.25 * g * g);
    auto x = [&](double x0, double u0) {
        return std::exp(-0.5 * g * t) * (x0 * std::cos(wd * t) + (u0 + 0.5 * g * x0) / wd * std::sin(wd * t));
    };
    return {x(p0.x, v0.x), x(p0.y, v0.y)};
}

Problem oscillator(bool damped, bool quick) {
    Problem p;
    const double k = 4.0, m = 1.0, b = damped ? 0.4 : 0.0;
    const Vec2 p0{1.0, 0.0}, v0{0.0, 1.0};
    p.name = damped ? "damped_oscillator" : "harmonic_oscillator";
    p.title = damped ? "damped oscillator (w=2, drag 0.4)" : "harmonic oscillator (w=2)";
    p.scene.world.gravity = {0.0, 0.0};
    Entity e = body(p.scene, "bob", p0, v0, m);
    if (damped) p.scene.registry.emplace<Drag>(e, {b});
    spring(p.scene, "bob", "", Vec2{0.0, 0.0}, k, 0.0, 0.0);
    p.T = 10.0;
    p.stepCounts = quick ? std::vector<long>{50, 200, 800, 3200} : std::vector<long>{50, 100, 200, 400, 800, 1600, 3200, 6400};
    p.positionOnlyForces = !damped;
    p.smallForDense = true;
    const Vec2 e1 = oscillatorExact(k, m, b, p0, v0, p.T);
    p.reference = {e1.x, e1.y};
    p.referenceName = "analytic";
    return p;
}

Problem kepler(bool quick) {
    Problem p;
    const double e = 0.6, a = 1.0, M = 1.0;
    p.name = "kepler_e0.6";
    p.title = "Kepler e=0.6, one period";
    p.scene.world.gravity = {0.0, 0.0};
    Entity sun = p.scene.registry.create();
    p.scene.registry.emplace<Name>(sun, {"sun"});
    p.scene.registry.emplace<Position>(sun, {{0.0, 0.0}});
    p.scene.registry.emplace<Static>(sun, {true});
    p.scene.registry.emplace<Mass>(sun, {M});
    p.scene.registry.emplace<Attractor>(sun, {0.0});
    const Vec2 p0{a * (1 - e), 0.0};
    body(p.scene, "planet", p0, {0.0, std::sqrt(M * (1 + e) / (a * (1 - e)))}, 1.0);
    p.T = 2.0 * std::numbers::pi * std::sqrt(a * a * a / M);
    p.stepCounts = quick ? std::vector<long>{100, 400, 1600, 6400} : std::vector<long>{100, 200, 400, 800, 1600, 3200, 6400, 12800};
    p.positionOnlyForces = true;
    p.smallForDense = true;
    p.reference = {p0.x, p0.y};  // a closed orbit returns to perihelion after one period
    p.referenceName = "analytic";
    return p;
}

// Stiff chain: 10 beads of 10 g on k = 1e5 N/m springs, released
// horizontally under gravity (dt*sqrt(k/m) = 53 at dt = 1/60).
Problem stiffChain(bool quick) {
    Problem p;
    p.name = "stiff_chain";
    p.title = "stiff chain (k=1e5, m=0.01, 10 beads)";
    const int n = 10;
    const double L = 0.3;
    for (int i = 0; i < n; ++i) body(p.scene, "b" + std::to_string(i), {(i + 1) * L, 0.0}, {0.0, 0.0}, 0.01);
    spring(p.scene, "b0", "", Vec2{0.0, 0.0}, 1e5, 0.0, L);
    for (int i = 1; i < n; ++i) spring(p.scene, "b" + std::to_string(i - 1), "b" + std::to_string(i), {}, 1e5, 0.0, L);
    p.T = 0.5;
    p.stepCounts = quick ? std::vector<long>{30, 120, 480, 1920} : std::vector<long>{30, 60, 120, 240, 480, 960, 1920, 3840};
    p.positionOnlyForces = true;
    p.smallForDense = true;
    return p;
}

// 1000-particle cloth: 40 x 25 grid, structural and shear springs, top
// corners held by anchor springs, drag.
Problem cloth(bool quick) {
    Problem p;
    p.name = "cloth_1000";
    p.title = "cloth, 1000 particles, 3847 springs";
    const int W = 40, H = 25;
    const double s = 0.1;
    auto nm = [](int i, int j) { return "p" + std::to_string(i) + "_" + std::to_string(j); };
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            Entity e = body(p.scene, nm(i, j), {i * s, -j * s}, {0.0, 0.0}, 0.01);
            p.scene.registry.emplace<Drag>(e, {0.001});
        }
    for (int j = 0; j < H; ++j)
        for (int i = 0; i < W; ++i) {
            if (i + 1 < W) spring(p.scene, nm(i, j), nm(i + 1, j), {}, 200.0, 0.01, s);
            if (j + 1 < H) spring(p.scene, nm(i, j), nm(i, j + 1), {}, 200.0, 0.01, s);
            if (i + 1 < W && j + 1 < H) spring(p.scene, nm(i, j), nm(i + 1, j + 1), {}, 100.0, 0.01, s * std::sqrt(2.0));
        }
    spring(p.scene, nm(0, 0), "", Vec2{0.0, 0.0}, 2000.0, 0.1, 0.0);
    spring(p.scene, nm(W - 1, 0), "", Vec2{(W - 1) * s, 0.0}, 2000.0, 0.1, 0.0);
    p.T = 0.25;
    p.stepCounts = quick ? std::vector<long>{25, 100, 400} : std::vector<long>{25, 50, 100, 200, 400, 800};
    p.positionOnlyForces = false;
    p.smallForDense = false;
    return p;
}

std::vector<double> finalPositions(const World& w) {
    std::vector<double> x(2 * w.bodyCount());
    for (std::size_t b = 0; b < w.bodyCount(); ++b) {
        x[2 * b] = w.bodyPosition(b).x;
        x[2 * b + 1] = w.bodyPosition(b).y;
    }
    return x;
}

double positionError(const double* x, const std::vector<double>& ref) {
    double worst = 0.0;
    for (std::size_t b = 0; b < ref.size() / 2; ++b) {
        const double d = std::hypot(x[2 * b] - ref[2 * b], x[2 * b + 1] - ref[2 * b + 1]);
        if (!std::isfinite(d)) return std::numeric_limits<double>::infinity();
        worst = std::max(worst, d);
    }
    return worst;
}

World buildWorld(const Scene& base, const std::string& integrator, double dt) {
    Scene s = base;
    s.world.integrator = integrator;
    s.world.dt = dt;
    s.world.substeps = 1;
    Result<World> w = World::build(s);
    if (!w) throw std::runtime_error("bench problem does not build: " + w.error());
    w->setProfiling(false);
    return std::move(w.value());
}

// Runs `once` (returns seconds for `steps` steps, or -1 on divergence)
// until at least `minSeconds` have been measured; the fastest repeat wins
// (the least disturbed by the shared machine).
double bestSecondsPerStep(const std::function<double()>& once, long steps, double minSeconds, int maxRepeats) {
    double best = std::numeric_limits<double>::infinity(), total = 0.0;
    for (int r = 0; r < maxRepeats && (r == 0 || total < minSeconds); ++r) {
        const double s = once();
        if (s < 0) return -1.0;
        best = std::min(best, s);
        total += s;
    }
    return best / double(steps);
}

// --- Odeint peers -----------------------------------------------------------

struct OdeSystem {
    const detail::ForceModel* model;
    std::size_t m;  // 2n
    void operator()(const State& y, State& dydt, double) const {
        std::copy(y.begin() + long(m), y.end(), dydt.begin());
        model->accelerations(y.data(), y.data() + m, dydt.data() + m);
    }
};

template <class Stepper>
double runOdeintFirstOrderSystem(const detail::ForceModel& model, const std::vector<double>& x0,
                                 const std::vector<double>& v0, double dt, long steps, std::vector<double>& xOut) {
    const std::size_t m = x0.size();
    State y(2 * m);
    std::copy(x0.begin(), x0.end(), y.begin());
    std::copy(v0.begin(), v0.end(), y.begin() + long(m));
    Stepper stepper;
    OdeSystem sys{&model, m};
    const double seconds = timedFixedSteps(stepper, sys, y, dt, steps);
    xOut.assign(y.begin(), y.begin() + long(m));
    return seconds;
}

double runOdeintVerlet(const detail::ForceModel& model, const std::vector<double>& x0, const std::vector<double>& v0,
                       double dt, long steps, std::vector<double>& xOut) {
    // odeint's velocity_verlet evaluates a(x1, v0): the textbook form,
    // first order once forces depend on velocity.
    std::pair<State, State> y{x0, v0};
    odeint::velocity_verlet<State> stepper;
    auto sys = [&model](const State& x, const State& v, State& a, double) {
        model.accelerations(x.data(), v.data(), a.data());
    };
    const double seconds = timedFixedSteps(stepper, sys, y, dt, steps);
    xOut = y.first;
    return seconds;
}

double runOdeintSymplecticEuler(const detail::ForceModel& model, const std::vector<double>& x0,
                                const std::vector<double>& v0, double dt, long steps, std::vector<double>& xOut) {
    // Position-only forces: p = v (per unit mass), dp/dt = a(q).
    std::pair<State, State> y{x0, v0};
    odeint::symplectic_euler<State> stepper;
    State zero(x0.size(), 0.0);
    auto coor = [](const State& p, State& dqdt) { dqdt = p; };
    auto momentum = [&model, &zero](const State& q, State& dpdt) {
        model.accelerations(q.data(), zero.data(), dpdt.data());
    };
    const double seconds = timedFixedSteps(stepper, std::make_pair(coor, momentum), y, dt, steps);
    xOut = y.first;
    return seconds;
}

// Dense Jacobian of y' = [v; a(x, v)] for odeint's implicit_euler:
// [[0, I], [M^-1 dF/dx, M^-1 dF/dv]], row-major (2m)^2.
struct DenseJacobian final : detail::JacobianSink {
    const detail::ForceModel& f;
    double* J;
    std::size_t m;
    DenseJacobian(const detail::ForceModel& model, double* j) : f(model), J(j), m(2 * model.n) {}
    void block(std::size_t r, std::size_t c, double sign, const std::array<double, 4>& b, bool velocity) {
        const std::size_t col = velocity ? m : 0;
        for (int e = 0; e < 4; ++e)
            J[(m + 2 * r + std::size_t(e / 2)) * 2 * m + col + 2 * c + std::size_t(e % 2)] +=
                sign * b[std::size_t(e)] * f.invMass[r];
    }
    void spring(std::size_t s, const std::array<double, 4>& dFdx, const std::array<double, 4>& dFdv) override {
        const auto& sp = f.springs[s];
        for (bool vel : {false, true}) {
            const auto& b = vel ? dFdv : dFdx;
            block(sp.a, sp.a, 1, b, vel);
            if (sp.b != detail::kNoBody) {
                block(sp.b, sp.b, 1, b, vel);
                block(sp.a, sp.b, -1, b, vel);
                block(sp.b, sp.a, -1, b, vel);
            }
        }
    }
    void drag(std::size_t body, double minusB) override { block(body, body, 1, {minusB, 0, 0, minusB}, true); }
    void attraction(std::size_t k, std::size_t body, const std::array<double, 4>& dFdx) override {
        block(body, body, 1, dFdx, false);
        if (f.attractors[k].body != detail::kNoBody) block(body, f.attractors[k].body, -1, dFdx, false);
    }
};

double runOdeintImplicitEuler(const detail::ForceModel& model, const std::vector<double>& x0,
                              const std::vector<double>& v0, double dt, long steps, std::vector<double>& xOut) {
    const std::size_t m = x0.size();
    xOut.assign(m, 0.0);
    auto accel = [&model](const double* x, const double* v, double* a) { model.accelerations(x, v, a); };
    auto jacobian = [&model, m](const double* x, const double* v, double* J) {
        for (std::size_t i = 0; i < m; ++i) J[i * 2 * m + m + i] = 1.0;  // dx'/dv = I
        DenseJacobian sink(model, J);
        model.jacobian(x, v, sink);
    };
    return runOdeintImplicitEulerDense(m, x0.data(), v0.data(), dt, steps, accel, jacobian, xOut.data());
}

// Odeint's controlled runge_kutta_dopri5 over the same frames as the
// engine's dopri5: each frame is covered by try_step calls, the last one
// shortened to land on the frame's end, and the step size is carried from
// frame to frame (as integrate_adaptive does within one call).
double runOdeintDopri5(const detail::ForceModel& model, const std::vector<double>& x0, const std::vector<double>& v0,
                       double frame, long frames, double tolerance, std::vector<double>& xOut) {
    const std::size_t m = x0.size();
    State y(2 * m);
    std::copy(x0.begin(), x0.end(), y.begin());
    std::copy(v0.begin(), v0.end(), y.begin() + long(m));
    auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<State>());
    OdeSystem sys{&model, m};
    const auto t0 = Clock::now();
    double t = 0.0, dt = frame;
    for (long f = 0; f < frames; ++f) {
        const double end = double(f + 1) * frame;
        long tries = 0;
        while (t < end) {
            if (++tries > 10000000) return -1.0;
            double h = std::min(dt, end - t);
            const bool landing = h == end - t;
            double tt = t;
            if (stepper.try_step(sys, y, tt, h) == odeint::success) {
                t = landing ? end : tt;
                if (!landing || h > dt) dt = h;  // a landing step does not shrink the proposal
            } else {
                dt = h;
            }
        }
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
    xOut.assign(y.begin(), y.begin() + long(m));
    return seconds;
}

// --- Barnes–Hut ---------------------------------------------------------------

struct BarnesHutSummary {
    std::size_t n = 0;
    double exactSecondsPerEvaluation = 0.0;
    // Five steps of semi-implicit Euler from rest, tree at theta 0.5 against exact.
    double exactFiveSteps = 0.0, treeFiveSteps = 0.0, rmsError = 0.0, rmsMoved = 0.0;
    double exactTraced = 0.0, treeTraced = 0.0;  // the same five steps with energy() after each
};

// One force evaluation per theta against exact summation: relative RMS
// force error and seconds per evaluation.
BarnesHutSummary barnesHut(bool quick, std::vector<AccuracyRow>& rows, std::ostream& log) {
    BarnesHutSummary out;
    out.n = 10000;
    log << "bench accuracy: barnes_hut (" << out.n << " attractors)\n" << std::flush;
    const Scene exactScene = attractorDisc(out.n, 0.0);
    World exact = buildWorld(exactScene, "semi_implicit_euler", 0.01);
    const detail::ForceModel& exactModel = internals(exact).model;
    const std::size_t m = 2 * out.n;
    const double* x = internals(exact).xs();
    const double* v = internals(exact).vs();
    std::vector<double> reference(m), a(m);
    auto timeEvaluation = [&](const detail::ForceModel& model, std::vector<double>& acc, int repeats) {
        double best = std::numeric_limits<double>::infinity();
        for (int r = 0; r < repeats; ++r) {
            const auto t0 = Clock::now();
            model.accelerations(x, v, acc.data());
            best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
        }
        return best;
    };
    out.exactSecondsPerEvaluation = timeEvaluation(exactModel, reference, quick ? 1 : 2);
    double ref2 = 0.0;
    for (double r : reference) ref2 += r * r;
    for (double theta : {0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 1.0}) {
        detail::ForceModel model = exactModel;
        model.theta = theta;
        const double seconds = timeEvaluation(model, a, quick ? 3 : 10);
        double err2 = 0.0;
        for (std::size_t i = 0; i < m; ++i) err2 += (a[i] - reference[i]) * (a[i] - reference[i]);
        AccuracyRow row{"barnes_hut", "barnes_hut", 0.0, 1, std::sqrt(err2 / ref2), seconds, "exact pairwise sum"};
        row.parameter = theta;
        rows.push_back(row);
    }
    // The goal: five steps at theta 0.5 against exact, error against the
    // distance moved; and the same with an energy trace.
    auto fiveSteps = [&](double theta, bool traced, std::vector<double>& xEnd) {
        World w = buildWorld(attractorDisc(out.n, theta), "semi_implicit_euler", 0.01);
        if (traced) (void)w.energy();  // a trace's row for step 0, as `stepwise run --trace` writes it
        const auto t0 = Clock::now();
        for (int i = 0; i < 5; ++i) {
            if (!w.step().ok()) throw std::runtime_error("barnes_hut run diverged");
            if (traced) (void)w.energy();
        }
        const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
        xEnd = finalPositions(w);
        return seconds;
    };
    std::vector<double> xExact, xTree, xStart = finalPositions(exact);
    out.exactFiveSteps = fiveSteps(0.0, false, xExact);
    out.treeFiveSteps = fiveSteps(0.5, false, xTree);
    out.exactTraced = fiveSteps(0.0, true, xExact);
    out.treeTraced = fiveSteps(0.5, true, xTree);
    double e2 = 0.0, d2 = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
        e2 += (xTree[i] - xExact[i]) * (xTree[i] - xExact[i]);
        d2 += (xExact[i] - xStart[i]) * (xExact[i] - xStart[i]);
    }
    out.rmsError = std::sqrt(2.0 * e2 / double(m));
    out.rmsMoved = std::sqrt(2.0 * d2 / double(m));
    return out;
}

// --- Output -----------------------------------------------------------------

std::string num(double v, int digits = 6) {
    if (std::isinf(v)) return "diverged";
    char b[40];
    std::snprintf(b, sizeof b, "%.*g", digits, v);
    return b;
}

std::string writeGnuplot(const std::vector<Problem>& problems, const std::vector<AccuracyRow>& rows,
                         const std::filesystem::path& dir, double exactSecondsPerEvaluation) {
    // One data file per problem, one block (index) per method.
    std::ostringstream script;
    script << "set terminal pngcairo size 1800,1150 font 'DejaVu Sans,10' noenhanced\n"
           << "set output '" << (dir / "accuracy.png").string() << "'\n"
           << "set multiplot layout 2,3 title 'Work-precision: final position error vs CPU time for the whole "
              "horizon (= time per step x steps; Stepwise solid, Boost.Odeint dashed; one point per dt)'\n"
           << "set logscale xy\nset format x '1e%L'\nset format y '1e%L'\nset grid\n"
           << "set xlabel 'CPU time for the horizon (s)'\nset ylabel 'max position error (m)'\n"
           << "set key outside right top font ',8' spacing 0.9\n";
    std::vector<std::string> methods;
    for (const AccuracyRow& r : rows)
        if (std::find(methods.begin(), methods.end(), r.method) == methods.end()) methods.push_back(r.method);
    for (const Problem& p : problems) {
        const std::filesystem::path data = dir / ("accuracy_" + p.name + ".dat");
        std::ofstream out(data);
        std::vector<std::string> plotted;
        for (const std::string& method : methods) {
            std::vector<const AccuracyRow*> pts;
            for (const AccuracyRow& r : rows)
                if (r.problem == p.name && r.method == method && std::isfinite(r.error) && r.error > 0 &&
                    r.error < 1e3 && r.secondsPerStep > 0)
                    pts.push_back(&r);
            if (pts.empty()) continue;
            if (!plotted.empty()) out << "\n\n";
            out << "# " << method << "\n";
            // x: CPU seconds to cover the horizon (per step x steps), as in
            // SciML's work-precision diagrams: per-step cost alone is flat
            // per method and would draw vertical lines. Per-step cost is in
            // the CSV and the markdown.
            for (const AccuracyRow* r : pts)
                out << r->secondsPerStep * double(r->steps) << " " << r->error << " " << r->dt << " "
                    << r->secondsPerStep << "\n";
            plotted.push_back(method);
        }
        script << "set title '" << p.title << "'\n";
        if (plotted.empty()) {
            script << "unset key\nplot 1/0 notitle\nset key\n";
            continue;
        }
        script << "plot ";
        for (std::size_t i = 0; i < plotted.size(); ++i) {
            const std::size_t colour = std::size_t(std::find(methods.begin(), methods.end(), plotted[i]) - methods.begin());
            const bool peer = plotted[i].rfind("odeint_", 0) == 0;
            script << (i ? ", " : "") << "'" << data.string() << "' index " << i << " using 1:2 with linespoints lc "
                   << (colour % 8 + 1) << " dt " << (peer ? 2 : 1) << " pt " << (peer ? 6 : 7) << " ps 0.8 lw 1.5 title '"
                   << plotted[i] << "'";
        }
        script << "\n";
    }
    // Sixth panel: Barnes–Hut force error against the time of one
    // evaluation, labelled by theta; exact summation is the vertical line.
    {
        const std::filesystem::path data = dir / "accuracy_barnes_hut.dat";
        std::ofstream out(data);
        for (const AccuracyRow& r : rows)
            if (r.problem == "barnes_hut") out << r.secondsPerStep << " " << r.error << " " << r.parameter << "\n";
        script << "set title 'Barnes-Hut, 10,000 attractors: force error vs time per evaluation'\n"
               << "set xlabel 'CPU time per force evaluation (s)'\nset ylabel 'relative RMS force error'\n"
               << "set arrow 1 from " << exactSecondsPerEvaluation << ", graph 0 to " << exactSecondsPerEvaluation
               << ", graph 1 nohead dt 2 lc rgb 'black'\n"
               << "set label 1 'exact pairwise' at " << exactSecondsPerEvaluation << ", graph 0.5 right offset -0.5,0\n"
               << "set xrange [" << exactSecondsPerEvaluation / 1000.0 << ":" << exactSecondsPerEvaluation * 3.0 << "]\n"
               << "plot '" << data.string() << "' using 1:2 with linespoints lc 1 pt 7 lw 1.5 title 'tree (theta)', '' "
               << "using 1:2:(sprintf('%.1f', $3)) with labels offset 0,1 font ',8' notitle\n"
               << "unset arrow 1\nunset label 1\nset xrange [*:*]\n";
    }
    script << "unset multiplot\n";
    const std::filesystem::path scriptPath = dir / "accuracy.gp";
    std::ofstream(scriptPath) << script.str();
    const std::string command = "gnuplot '" + scriptPath.string() + "' 2>'" + (dir / "gnuplot.log").string() + "'";
    if (std::system(command.c_str()) != 0) {
        // The staging folder goes away: the message carries the log's start.
        std::ifstream logFile(dir / "gnuplot.log");
        std::string first(400, '\0');
        logFile.read(first.data(), std::streamsize(first.size()));
        first.resize(std::size_t(logFile.gcount()));
        return "gnuplot failed (is gnuplot-nox installed?): " + first;
    }
    return {};
}

} // namespace

Result<void> runAccuracyReport(const AccuracyOptions& options, std::ostream& log, std::vector<AccuracyRow>* rowsOut) {
    std::error_code ec;
    std::filesystem::create_directories(options.out, ec);
    if (ec) return Error{"cannot create " + options.out.string() + ": " + ec.message(), "", ErrorKind::Io};
    const bool quick = options.quick;
    const double minSeconds = quick ? 0.002 : 0.02;
    const int maxRepeats = quick ? 3 : 10;

    std::vector<Problem> problems;
    problems.push_back(oscillator(false, quick));
    problems.push_back(oscillator(true, quick));
    problems.push_back(kepler(quick));
    problems.push_back(stiffChain(quick));
    problems.push_back(cloth(quick));

    std::vector<AccuracyRow> rows;
    for (Problem& p : problems) {
        if (p.reference.empty()) {
            // Converged reference: RK4 at a step far below every tested dt
            // (h*omega_max ~ 0.06 on the stiff chain), checked against half
            // that step.
            const long refSteps = p.name == "stiff_chain" ? 50000 : 8000;
            auto refRun = [&](long steps) {
                World w = buildWorld(p.scene, "rk4", p.T / double(steps));
                if (!advance(w, std::uint64_t(steps)).ok()) throw std::runtime_error("reference run diverged: " + p.name);
                return finalPositions(w);
            };
            p.reference = refRun(refSteps);
            const std::vector<double> coarser = refRun(refSteps / 2);
            p.referenceName = "rk4 dt=" + num(p.T / double(refSteps), 3) + " (vs dt*2: " +
                              num(positionError(coarser.data(), p.reference), 2) + " m)";
        }
        log << "bench accuracy: " << p.name << " (reference: " << p.referenceName << ")\n" << std::flush;

        // dopri5 chooses its own steps within each frame: it runs in 10
        // frames over the horizon (at 60 frames per second every frame of
        // the smooth problems is one step and the tolerance would not
        // matter), and the tolerance is swept.
        const long frames = 10;
        const double frame = p.T / double(frames);
        const std::vector<double> tolerances =
            quick ? std::vector<double>{1e-3, 1e-5, 1e-7, 1e-9}
                  : std::vector<double>{1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11};
        // One row: `scene` under `integrator` for `steps` steps of dt.
        auto measure = [&](const Scene& scene, const std::string& integrator, double dt, long steps, double parameter) {
            AccuracyRow row{p.name, integrator, dt, steps, 0.0, 0.0, p.referenceName, parameter};
            std::vector<double> x;
            auto once = [&]() -> double {
                World w = buildWorld(scene, integrator, dt);
                const auto t0 = Clock::now();
                if (!advance(w, std::uint64_t(steps)).ok()) return -1.0;
                const double s = std::chrono::duration<double>(Clock::now() - t0).count();
                x = finalPositions(w);
                return s;
            };
            row.secondsPerStep = bestSecondsPerStep(once, steps, minSeconds, maxRepeats);
            row.error = row.secondsPerStep < 0 ? std::numeric_limits<double>::infinity()
                                               : positionError(x.data(), p.reference);
            rows.push_back(row);
        };
        for (std::string_view integrator : integratorNames()) {
            if (integrator == "dopri5") {
                for (double tolerance : tolerances) {
                    Scene scene = p.scene;
                    scene.world.tolerance = tolerance;
                    measure(scene, "dopri5", frame, frames, tolerance);
                }
                continue;
            }
            for (long steps : p.stepCounts) measure(p.scene, std::string(integrator), p.T / double(steps), steps, 0.0);
        }

        // Peers: same model, same initial state.
        World proto = buildWorld(p.scene, "rk4", 1.0);
        const detail::ForceModel model = internals(proto).model;
        const std::vector<double> x0(internals(proto).xs(), internals(proto).xs() + 2 * model.n);
        const std::vector<double> v0(internals(proto).vs(), internals(proto).vs() + 2 * model.n);
        using Runner = std::function<double(double, long, std::vector<double>&)>;
        std::vector<std::pair<std::string, Runner>> peers = {
            {"odeint_euler",
             [&](double dt, long n, std::vector<double>& x) {
                 return runOdeintFirstOrderSystem<odeint::euler<State>>(model, x0, v0, dt, n, x);
             }},
            {"odeint_modified_midpoint",
             [&](double dt, long n, std::vector<double>& x) {
                 return runOdeintFirstOrderSystem<odeint::modified_midpoint<State>>(model, x0, v0, dt, n, x);
             }},
            {"odeint_runge_kutta4",
             [&](double dt, long n, std::vector<double>& x) {
                 return runOdeintFirstOrderSystem<odeint::runge_kutta4<State>>(model, x0, v0, dt, n, x);
             }},
            {"odeint_velocity_verlet",
             [&](double dt, long n, std::vector<double>& x) { return runOdeintVerlet(model, x0, v0, dt, n, x); }},
        };
        if (p.positionOnlyForces)
            peers.emplace_back("odeint_symplectic_euler", [&](double dt, long n, std::vector<double>& x) {
                return runOdeintSymplecticEuler(model, x0, v0, dt, n, x);
            });
        if (p.smallForDense)
            peers.emplace_back("odeint_implicit_euler", [&](double dt, long n, std::vector<double>& x) {
                return runOdeintImplicitEuler(model, x0, v0, dt, n, x);
            });
        for (double tolerance : tolerances) {
            AccuracyRow row{p.name, "odeint_dopri5", frame, frames, 0.0, 0.0, p.referenceName, tolerance};
            std::vector<double> x;
            auto once = [&]() { return runOdeintDopri5(model, x0, v0, frame, frames, tolerance, x); };
            row.secondsPerStep = bestSecondsPerStep(once, frames, minSeconds, maxRepeats);
            row.error = row.secondsPerStep < 0 ? std::numeric_limits<double>::infinity()
                                               : positionError(x.data(), p.reference);
            rows.push_back(row);
        }
        for (const auto& [name, runner] : peers) {
            for (long steps : p.stepCounts) {
                const double dt = p.T / double(steps);
                AccuracyRow row{p.name, name, dt, steps, 0.0, 0.0, p.referenceName};
                std::vector<double> x;
                auto once = [&]() { return runner(dt, steps, x); };
                row.secondsPerStep = bestSecondsPerStep(once, steps, minSeconds, maxRepeats);
                row.error = positionError(x.data(), p.reference);
                if (!std::isfinite(row.error)) row.error = std::numeric_limits<double>::infinity();
                rows.push_back(row);
            }
        }
    }

    const BarnesHutSummary tree = barnesHut(quick, rows, log);

    // Nothing is written until everything is ready: the CSV and the
    // Markdown are built in memory, the plot is drawn in a private staging
    // folder, and then each output replaces its file atomically. A run that
    // fails (or is killed) leaves the previous report whole.
    std::ostringstream csv;
    std::ostringstream md;
    {
        csv << "problem,method,dt,steps,error_m,seconds_per_step,reference,parameter\n";
        for (const AccuracyRow& r : rows)
            csv << r.problem << "," << r.method << "," << num(r.dt, 17) << "," << r.steps << ","
                << (std::isfinite(r.error) ? num(r.error, 6) : "inf") << ","
                << (r.secondsPerStep > 0 ? num(r.secondsPerStep, 6) : "") << ",\""
                << r.reference << "\"," << num(r.parameter, 6) << "\n";
    }

    // Markdown: per problem, each method's observed order (slope between
    // the two finest dt), and the CPU cost to reach 1e-3 m and 1e-6 m.
    {
        md << "# Speed against error\n\n"
           << "Error: largest final position error over the bodies, metres, against the reference. Cost: CPU "
              "seconds per step (best of repeats, one thread). `odeint_*` rows: Boost.Odeint steppers on the "
              "same ODE and the same force code. "
           << (quick ? "Quick run (`--quick`): fewer dt and repeats.\n\n" : "\n\n");
        md << "`dopri5` and `odeint_dopri5` (Odeint's controlled runge_kutta_dopri5, the same frames, the step "
              "carried across them) run in 10 frames over each horizon and sweep the tolerance instead of dt: "
              "their \"error at each dt\" columns are at each tolerance (";
        for (std::size_t i = 0; i < rows.size(); ++i)
            if (rows[i].method == "dopri5" && rows[i].problem == problems.front().name)
                md << num(rows[i].parameter, 2) << " ";
        md << ").\n\n";
        for (const Problem& p : problems) {
            md << "## " << p.title << "\n\nHorizon " << num(p.T, 4) << " s; reference: " << p.referenceName
               << ".\n\n| method | order (finest dt) | cost to 1e-3 m (s) | cost to 1e-6 m (s) | error at each dt (";
            for (std::size_t i = 0; i < p.stepCounts.size(); ++i) md << (i ? ", " : "") << num(p.T / double(p.stepCounts[i]), 3);
            md << " s) | us/step at each dt |\n|---|---|---|---|---|---|\n";
            std::vector<std::string> methods;
            for (const AccuracyRow& r : rows)
                if (r.problem == p.name && std::find(methods.begin(), methods.end(), r.method) == methods.end())
                    methods.push_back(r.method);
            for (const std::string& method : methods) {
                std::vector<const AccuracyRow*> rs;
                for (const AccuracyRow& r : rows)
                    if (r.problem == p.name && r.method == method) rs.push_back(&r);
                std::string order = "-";
                if (rs.size() >= 2) {
                    const AccuracyRow& a = *rs[rs.size() - 2];
                    const AccuracyRow& b = *rs.back();
                    if (std::isfinite(a.error) && std::isfinite(b.error) && a.error > 0 && b.error > 0 && a.dt != b.dt)
                        order = num(std::log(a.error / b.error) / std::log(a.dt / b.dt), 3);
                }
                auto cost = [&](double tol) {
                    double best = std::numeric_limits<double>::infinity();
                    for (const AccuracyRow* r : rs)
                        if (r->error <= tol) best = std::min(best, r->secondsPerStep * double(r->steps));
                    return std::isfinite(best) ? num(best, 3) : std::string("not reached");
                };
                md << "| " << method << " | " << order << " | " << cost(1e-3) << " | " << cost(1e-6) << " | ";
                for (std::size_t i = 0; i < rs.size(); ++i) md << (i ? ", " : "") << num(rs[i]->error, 2);
                md << " | ";
                for (std::size_t i = 0; i < rs.size(); ++i)
                    md << (i ? ", " : "") << (rs[i]->secondsPerStep > 0 ? num(1e6 * rs[i]->secondsPerStep, 3) : "-");
                md << " |\n";
            }
            md << "\n";
        }
        md << "## Barnes–Hut: force error against time\n\n" << tree.n
           << " attractors of total mass 1 at rest in the unit disc (softening 0.01 m). One force evaluation per "
              "theta; error: RMS over bodies of the acceleration error over RMS acceleration, against exact "
              "pairwise summation (theta 0), which took "
           << num(tree.exactSecondsPerEvaluation, 3) << " s.\n\n| theta | relative force error | s per evaluation | "
              "fraction of exact |\n|---|---|---|---|\n";
        for (const AccuracyRow& r : rows)
            if (r.problem == "barnes_hut")
                md << "| " << num(r.parameter, 2) << " | " << num(r.error, 3) << " | " << num(r.secondsPerStep, 3) << " | "
                   << num(r.secondsPerStep / tree.exactSecondsPerEvaluation, 3) << " |\n";
        md << "\nFive steps of semi_implicit_euler (dt 0.01 s) from rest, theta 0.5 against exact: "
           << num(tree.treeFiveSteps, 3) << " s against " << num(tree.exactFiveSteps, 3) << " s ("
           << num(100.0 * tree.treeFiveSteps / tree.exactFiveSteps, 3) << "% of the exact time); RMS position error "
           << num(tree.rmsError, 3) << " m = " << num(100.0 * tree.rmsError / tree.rmsMoved, 3)
           << "% of the RMS distance moved (" << num(tree.rmsMoved, 3) << " m). With World::energy() after every step "
           << "(what --trace does): exact " << num(tree.exactTraced, 3) << " s (" << num(tree.exactTraced / tree.exactFiveSteps, 3)
           << "x untraced), tree " << num(tree.treeTraced, 3) << " s (" << num(tree.treeTraced / tree.treeFiveSteps, 3)
           << "x).\n\n";
        md << "![work-precision](accuracy.png)\n";
    }
    std::string staging = (options.out / ".accuracy-XXXXXX").string();
    if (!::mkdtemp(staging.data()))
        return Error{"cannot write in " + options.out.string() + ": " + std::strerror(errno), "", ErrorKind::Io};
    const std::filesystem::path stagingDir(staging);
    std::string problem = writeGnuplot(problems, rows, stagingDir, tree.exactSecondsPerEvaluation);
    const ErrorKind kind = problem.empty() ? ErrorKind::Io : ErrorKind::Environment;  // gnuplot failed, or a write
    if (problem.empty()) {
        if (Result<void> w = writeFileAtomically(options.out / "accuracy.csv", csv.str()); !w) problem = w.error();
    }
    if (problem.empty()) {
        if (Result<void> w = writeFileAtomically(options.out / "accuracy.md", md.str()); !w) problem = w.error();
    }
    if (problem.empty()) {
        // Same folder, same filesystem: rename() replaces the old plot whole.
        std::filesystem::rename(stagingDir / "accuracy.png", options.out / "accuracy.png", ec);
        if (ec) problem = (options.out / "accuracy.png").string() + ": error: cannot write: " + ec.message();
    }
    std::filesystem::remove_all(stagingDir, ec);
    if (!problem.empty()) return Error{problem, "", kind};
    if (rowsOut) *rowsOut = std::move(rows);
    return {};
}

} // namespace stepwise::report
