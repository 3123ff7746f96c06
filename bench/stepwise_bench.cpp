// Google Benchmark: ns per particle-step of every integrator at 1e4, 1e5
// and 1e6 particles, with gravity + drag and with a spring chain; a stream
// copy of the same bytes as the memory-bandwidth peer; RK4 against
// Boost.Odeint's runge_kutta4 on the same problem and force code; and the
// state-layout measurement (interleaved x,y per body vs split x[], y[]);
// Barnes–Hut against exact pairwise attraction (and the size where the tree
// starts to pay); dopri5 against Odeint's controlled runge_kutta_dopri5.
// Not part of ctest: compare ratios from one run, the machine is shared.
//
//   build/bench/stepwise_bench --benchmark_filter=... --benchmark_min_time=0.2

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/world.hpp"
#include "world/world_internals.hpp"
#include "report/scenes.hpp"
#include "generated_scenes.hpp"

#include <benchmark/benchmark.h>
#include <boost/numeric/odeint/stepper/generation.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>
#include <boost/numeric/odeint/stepper/runge_kutta_dopri5.hpp>

#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

using namespace stepwise;

namespace {

enum class Problem { GravityDrag, Springs };

// "p<i>" (built with append: GCC 12 warns falsely on "literal" + std::string).
std::string particleName(std::size_t i) {
    std::string s = "p";
    s += std::to_string(i);
    return s;
}

// Gravity + drag: n free particles. Springs: a chain of n particles (n-1
// springs, k = 100 N/m, 1 kg, damped) anchored at one end, under gravity.
Scene makeScene(Problem p, std::size_t n) {
    Scene s;
    s.world.dt = p == Problem::Springs ? 1e-3 : 1.0 / 60.0;
    s.world.sleep = false;  // the integrators' cost per particle-step, whatever the chain does
    s.registry.reserve(2 * n + 1);
    for (std::size_t i = 0; i < n; ++i) {
        Entity e = s.registry.create();
        s.registry.emplace<Name>(e, {particleName(i)});
        s.registry.emplace<Position>(e, {{0.1 * double(i % 1000), 0.1 * double(i / 1000)}});
        s.registry.emplace<Velocity>(e, {{1.0, 0.5}});
        if (p == Problem::GravityDrag) s.registry.emplace<Drag>(e, {0.1});
    }
    if (p == Problem::Springs) {
        const std::vector<Entity> particles = s.registry.entities();  // the n particles, in order
        for (std::size_t i = 0; i < n; ++i) {
            Entity e = s.registry.create();
            Spring sp;
            sp.a = particles[i];
            if (i == 0)
                sp.anchor = Vec2{0.0, 0.0};
            else
                sp.b = particles[i - 1];
            sp.k = 100.0;
            sp.damping = 0.5;
            sp.restLength = 0.1;
            s.registry.emplace<Spring>(e, sp);
        }
    }
    return s;
}

// Worlds are built once per (problem, n) and shared: building 1e6 bodies
// through the scene registry costs seconds.
World& sharedWorld(Problem p, std::size_t n) {
    static std::map<std::pair<int, std::size_t>, std::unique_ptr<World>> worlds;
    auto& slot = worlds[{int(p), n}];
    if (!slot) {
        Result<World> w = World::build(makeScene(p, n));
        if (!w) throw std::runtime_error(w.error());
        slot = std::make_unique<World>(std::move(w.value()));
        slot->setProfiling(false);
    }
    return *slot;
}

void perParticle(benchmark::State& state, std::size_t n) {
    // Seconds per particle-step (shown with an SI prefix, "n" = ns).
    state.counters["per_particle_step"] =
        benchmark::Counter(double(state.iterations()) * double(n), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_Step(benchmark::State& state, Problem p, std::string integrator) {
    const std::size_t n = std::size_t(state.range(0));
    World& w = sharedWorld(p, n);
    if (!w.setIntegrator(integrator).ok()) {
        state.SkipWithError("unknown integrator");
        return;
    }
    for (auto _ : state) {
        Result<void> r = w.step();
        if (!r) {
            state.SkipWithError(r.error().c_str());
            break;
        }
    }
    perParticle(state, n);
}

// Memory-bandwidth peer: copy the state's bytes (positions + velocities,
// 32 bytes per particle) from one buffer to another, as a step that reads
// the state and writes the next one must.
void BM_StreamCopy(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    std::vector<double> a(4 * n, 1.0), b(4 * n, 0.0);
    for (auto _ : state) {
        std::memcpy(b.data(), a.data(), a.size() * sizeof(double));
        benchmark::DoNotOptimize(b.data());
        benchmark::ClobberMemory();
        std::swap(a, b);
    }
    perParticle(state, n);
}

// Odeint's runge_kutta4 on y = [x; v], y' = [v; a(x, v)], with the world's
// own force model: the same problem and force code as BM_Step rk4.
void BM_OdeintRk4(benchmark::State& state, Problem p) {
    namespace odeint = boost::numeric::odeint;
    const std::size_t n = std::size_t(state.range(0));
    World& w = sharedWorld(p, n);
    const detail::ForceModel& model = internals(w).model;
    const std::size_t m = 2 * model.n;
    std::vector<double> y(2 * m);
    std::copy(internals(w).xs(), internals(w).xs() + m, y.begin());
    std::copy(internals(w).vs(), internals(w).vs() + m, y.begin() + long(m));
    odeint::runge_kutta4<std::vector<double>> stepper;
    auto sys = [&model, m](const std::vector<double>& s, std::vector<double>& dsdt, double) {
        std::copy(s.begin() + long(m), s.end(), dsdt.begin());
        model.accelerations(s.data(), s.data() + m, dsdt.data() + m);
    };
    const double dt = w.settings().dt;
    double t = 0.0;
    for (auto _ : state) {
        stepper.do_step(sys, y, t, dt);
        t += dt;
        benchmark::DoNotOptimize(y.data());
    }
    perParticle(state, n);
}

// Layout: semi-implicit Euler with gravity + drag over interleaved (x0 y0
// x1 y1 ...) and split (x0 x1 ... / y0 y1 ...) arrays, and a spring-chain
// force pass over both.
void BM_LayoutEulerInterleaved(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    std::vector<double> x(2 * n, 1.0), v(2 * n, 0.5), rate(n, 0.1);
    const double h = 1.0 / 60, gx = 0.0, gy = -9.81;
    for (auto _ : state) {
        for (std::size_t b = 0; b < n; ++b) {
            const double vx = v[2 * b] + h * (gx - rate[b] * v[2 * b]);
            const double vy = v[2 * b + 1] + h * (gy - rate[b] * v[2 * b + 1]);
            v[2 * b] = vx;
            v[2 * b + 1] = vy;
            x[2 * b] += h * vx;
            x[2 * b + 1] += h * vy;
        }
        benchmark::DoNotOptimize(x.data());
        benchmark::ClobberMemory();
    }
    perParticle(state, n);
}

void BM_LayoutEulerSplit(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    std::vector<double> x(n, 1.0), y(n, 1.0), vx(n, 0.5), vy(n, 0.5), rate(n, 0.1);
    const double h = 1.0 / 60, gx = 0.0, gy = -9.81;
    for (auto _ : state) {
        for (std::size_t b = 0; b < n; ++b) {
            vx[b] += h * (gx - rate[b] * vx[b]);
            vy[b] += h * (gy - rate[b] * vy[b]);
            x[b] += h * vx[b];
            y[b] += h * vy[b];
        }
        benchmark::DoNotOptimize(x.data());
        benchmark::ClobberMemory();
    }
    perParticle(state, n);
}

struct ChainSpring {
    std::uint32_t a, b;
    double k, rest;
};

std::vector<ChainSpring> shuffledChain(std::size_t n) {
    // Cloth-like locality: neighbours are near in memory but not adjacent.
    std::vector<ChainSpring> s;
    for (std::size_t i = 1; i < n; ++i) s.push_back({std::uint32_t(i), std::uint32_t(i - 1), 100.0, 0.1});
    for (std::size_t i = 100; i < n; ++i) s.push_back({std::uint32_t(i), std::uint32_t(i - 100), 100.0, 0.1});
    return s;
}

void BM_LayoutSpringsInterleaved(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    const std::vector<ChainSpring> springs = shuffledChain(n);
    std::vector<double> x(2 * n), a(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
        x[2 * i] = 0.1 * double(i % 100);
        x[2 * i + 1] = 0.1 * double(i / 100);
    }
    for (auto _ : state) {
        std::fill(a.begin(), a.end(), 0.0);
        for (const ChainSpring& s : springs) {
            const double dx = x[2 * s.a] - x[2 * s.b], dy = x[2 * s.a + 1] - x[2 * s.b + 1];
            const double l = std::sqrt(dx * dx + dy * dy);
            const double f = -s.k * (l - s.rest) / l;
            a[2 * s.a] += f * dx;
            a[2 * s.a + 1] += f * dy;
            a[2 * s.b] -= f * dx;
            a[2 * s.b + 1] -= f * dy;
        }
        benchmark::DoNotOptimize(a.data());
        benchmark::ClobberMemory();
    }
    state.counters["per_spring"] = benchmark::Counter(double(state.iterations()) * double(springs.size()),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_LayoutSpringsSplit(benchmark::State& state) {
    const std::size_t n = std::size_t(state.range(0));
    const std::vector<ChainSpring> springs = shuffledChain(n);
    std::vector<double> x(n), y(n), ax(n), ay(n);
    for (std::size_t i = 0; i < n; ++i) {
        x[i] = 0.1 * double(i % 100);
        y[i] = 0.1 * double(i / 100);
    }
    for (auto _ : state) {
        std::fill(ax.begin(), ax.end(), 0.0);
        std::fill(ay.begin(), ay.end(), 0.0);
        for (const ChainSpring& s : springs) {
            const double dx = x[s.a] - x[s.b], dy = y[s.a] - y[s.b];
            const double l = std::sqrt(dx * dx + dy * dy);
            const double f = -s.k * (l - s.rest) / l;
            ax[s.a] += f * dx;
            ay[s.a] += f * dy;
            ax[s.b] -= f * dx;
            ay[s.b] -= f * dy;
        }
        benchmark::DoNotOptimize(ax.data());
        benchmark::ClobberMemory();
    }
    state.counters["per_spring"] = benchmark::Counter(double(state.iterations()) * double(springs.size()),
                                                      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

// --- Barnes–Hut ---------------------------------------------------------------

// One attractor force evaluation: exact (theta 0) or through the tree
// (theta 0.5, the default), the tree forced on at every size so that the
// crossover with exact summation shows (kTreeMinAttractors).
void BM_Attractors(benchmark::State& state, double theta) {
    const std::size_t n = std::size_t(state.range(0));
    Result<World> built = World::build(report::attractorDisc(n, theta));
    if (!built) {
        state.SkipWithError(built.error().c_str());
        return;
    }
    detail::ForceModel& model = internals(*built).model;
    model.treeMinAttractors = 0;
    std::vector<double> a(2 * n);
    for (auto _ : state) {
        model.accelerations(internals(*built).xs(), internals(*built).vs(), a.data());
        benchmark::DoNotOptimize(a.data());
    }
    perParticle(state, n);
}

// A whole step, with and without World::energy() after it (what
// `stepwise run --trace` does): the trace must not double the cost.
void BM_AttractorStep(benchmark::State& state, double theta, bool traced) {
    const std::size_t n = std::size_t(state.range(0));
    Result<World> built = World::build(report::attractorDisc(n, theta));
    if (!built) {
        state.SkipWithError(built.error().c_str());
        return;
    }
    built->setProfiling(false);
    // A trace starts with the energy of step 0 (stepwise run --trace writes
    // that row before the first step); without it the first timed step
    // would pay for a force pass the trace saves on every later one.
    double sink = traced ? built->energy().attractors : 0.0;
    for (auto _ : state) {
        if (!built->step().ok()) {
            state.SkipWithError("diverged");
            break;
        }
        if (traced) sink += built->energy().attractors;
    }
    benchmark::DoNotOptimize(sink);
}

// --- dopri5 against Odeint ----------------------------------------------------

// One period of Kepler e = 0.9 (60 frames) at tolerance state.range(0) = -log10.
Scene keplerScene(double tolerance) {
    Scene s;
    s.world.gravity = {0.0, 0.0};
    s.world.integrator = "dopri5";
    s.world.tolerance = tolerance;
    s.world.dt = 2.0 * M_PI / 60.0;
    Entity sun = s.registry.create();
    s.registry.emplace<Position>(sun, {{0.0, 0.0}});
    s.registry.emplace<Static>(sun, {true});
    s.registry.emplace<Attractor>(sun, {0.0});
    Entity planet = s.registry.create();
    s.registry.emplace<Position>(planet, {{0.1, 0.0}});
    s.registry.emplace<Velocity>(planet, {{0.0, std::sqrt(1.9 / 0.1)}});
    return s;
}

void BM_Dopri5Kepler(benchmark::State& state) {
    const double tolerance = std::pow(10.0, -double(state.range(0)));
    double error = 0.0;
    for (auto _ : state) {
        Result<World> w = World::build(keplerScene(tolerance));
        w->setProfiling(false);
        for (int f = 0; f < 60; ++f)
            if (!w->step().ok()) state.SkipWithError("dopri5 failed");
        error = std::hypot(w->bodyPosition(0).x - 0.1, w->bodyPosition(0).y);
    }
    state.counters["error_m"] = error;
}

void BM_OdeintDopri5Kepler(benchmark::State& state) {
    namespace odeint = boost::numeric::odeint;
    const double tolerance = std::pow(10.0, -double(state.range(0)));
    Result<World> w = World::build(keplerScene(tolerance));
    const detail::ForceModel& model = internals(*w).model;
    auto sys = [&model](const std::vector<double>& s, std::vector<double>& dsdt, double) {
        dsdt[0] = s[2];
        dsdt[1] = s[3];
        model.accelerations(s.data(), s.data() + 2, dsdt.data() + 2);
    };
    const double frame = w->settings().dt;
    double error = 0.0;
    for (auto _ : state) {
        std::vector<double> y{0.1, 0.0, 0.0, std::sqrt(1.9 / 0.1)};
        auto stepper = odeint::make_controlled(tolerance, tolerance, odeint::runge_kutta_dopri5<std::vector<double>>());
        double t = 0.0, dt = frame;
        for (int f = 0; f < 60; ++f) {
            const double end = double(f + 1) * frame;
            while (t < end) {
                double h = std::min(dt, end - t);
                const bool landing = h == end - t;
                double tt = t;
                if (stepper.try_step(sys, y, tt, h) == odeint::success) {
                    t = landing ? end : tt;
                    if (!landing || h > dt) dt = h;
                } else {
                    dt = h;
                }
            }
        }
        error = std::hypot(y[0] - 0.1, y[1]);
    }
    state.counters["error_m"] = error;
}

const std::vector<std::int64_t> kSizes{10'000, 100'000, 1'000'000};

int registerAll() {
    for (std::string_view name : integratorNames()) {
        // Sparse Newton and dopri5's error-controlled steps on a
        // million-body chain take seconds per step: those rows stop at 1e5.
        const bool implicit = name.rfind("implicit_", 0) == 0 || name == "dopri5";
        for (std::int64_t n : kSizes) {
            benchmark::RegisterBenchmark(("Step/gravity_drag/" + std::string(name)).c_str(), BM_Step,
                                         Problem::GravityDrag, std::string(name))
                ->Arg(n)
                ->Unit(benchmark::kMicrosecond);
            // Sparse Newton on a million-body chain takes seconds per
            // step; the implicit spring rows stop at 1e5.
            if (!(implicit && n > 100'000))
                benchmark::RegisterBenchmark(("Step/springs/" + std::string(name)).c_str(), BM_Step, Problem::Springs,
                                             std::string(name))
                    ->Arg(n)
                    ->Unit(benchmark::kMicrosecond);
        }
    }
    for (std::int64_t n : kSizes) {
        benchmark::RegisterBenchmark("StreamCopy", BM_StreamCopy)->Arg(n)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("OdeintRk4/gravity_drag", BM_OdeintRk4, Problem::GravityDrag)
            ->Arg(n)
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("OdeintRk4/springs", BM_OdeintRk4, Problem::Springs)
            ->Arg(n)
            ->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("Layout/euler_interleaved", BM_LayoutEulerInterleaved)->Arg(n)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("Layout/euler_split", BM_LayoutEulerSplit)->Arg(n)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("Layout/springs_interleaved", BM_LayoutSpringsInterleaved)->Arg(n)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("Layout/springs_split", BM_LayoutSpringsSplit)->Arg(n)->Unit(benchmark::kMicrosecond);
    }
    for (std::int64_t n : {64, 128, 256, 512, 1024, 10'000}) {
        benchmark::RegisterBenchmark("BarnesHut/exact", BM_Attractors, 0.0)->Arg(n)->Unit(benchmark::kMillisecond);
        benchmark::RegisterBenchmark("BarnesHut/tree_theta0.5", BM_Attractors, 0.5)->Arg(n)->Unit(benchmark::kMillisecond);
    }
    for (bool traced : {false, true})
        for (double theta : {0.0, 0.5})
            benchmark::RegisterBenchmark(("BarnesHut/step_theta" + std::string(theta > 0 ? "0.5" : "0") +
                                          (traced ? "_traced" : "")).c_str(),
                                         BM_AttractorStep, theta, traced)
                ->Arg(10'000)
                ->Unit(benchmark::kMillisecond);
    for (std::int64_t digits : {6, 8, 10}) {
        benchmark::RegisterBenchmark("Dopri5/kepler_e0.9", BM_Dopri5Kepler)->Arg(digits)->Unit(benchmark::kMicrosecond);
        benchmark::RegisterBenchmark("OdeintDopri5/kepler_e0.9", BM_OdeintDopri5Kepler)
            ->Arg(digits)
            ->Unit(benchmark::kMicrosecond);
    }
    return 0;
}
const int kRegistered = registerAll();

// Sleeping: the 2,000-circle pile of bench/collision
// (circlesInBox, levels/pile.json) while it falls (its first 2 s), and
// settled (after range(1) steps) with sleeping on and off. Goal: settled
// with sleep under 15% of falling. Counter "asleep": the fraction of bodies
// asleep during the timed steps.
enum class PilePhase { Falling, SettledSleep, SettledAwake };
void BM_CirclePile(benchmark::State& state, PilePhase phase) {
    Scene scene = scenes::circlesInBox(2000);
    scene.world.sleep = phase != PilePhase::SettledAwake;
    const auto fresh = [&] {
        Result<World> w = World::build(scene);
        if (!w) throw std::runtime_error(w.error());
        w->setProfiling(false);
        return std::move(*w);
    };
    World w = fresh();
    const std::uint64_t settle = std::uint64_t(state.range(0));
    if (phase != PilePhase::Falling) advance(w, settle);
    double asleep = 0.0;
    std::uint64_t taken = 0;
    for (auto _ : state) {
        if (phase == PilePhase::Falling && taken == 120) {
            state.PauseTiming();
            w = fresh();
            taken = 0;
            state.ResumeTiming();
        }
        if (!w.step().ok()) {
            state.SkipWithError("diverged");
            return;
        }
        ++taken;
        asleep += double(w.sleepingBodyCount()) / double(w.bodyCount());
    }
    state.counters["asleep"] = asleep / double(state.iterations());
}
const int kPileRegistered = [] {
    benchmark::RegisterBenchmark("SleepPile/falling", BM_CirclePile, PilePhase::Falling)->Arg(0)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("SleepPile/settled_sleep", BM_CirclePile, PilePhase::SettledSleep)
        ->Arg(900)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark("SleepPile/settled_awake", BM_CirclePile, PilePhase::SettledAwake)
        ->Arg(900)
        ->Unit(benchmark::kMillisecond);
    return 0;
}();

} // namespace

BENCHMARK_MAIN();
