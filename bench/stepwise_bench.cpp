// Google Benchmark: ns per particle-step of every integrator at 1e4, 1e5
// and 1e6 particles, with gravity + drag and with a spring chain; a stream
// copy of the same bytes as the memory-bandwidth peer; RK4 against
// Boost.Odeint's runge_kutta4 on the same problem and force code; and the
// state-layout measurement (interleaved x,y per body vs split x[], y[]).
// Not part of ctest: compare ratios from one run, the machine is shared.
//
//   build/bench/stepwise_bench --benchmark_filter=... --benchmark_min_time=0.2

#include "stepwise/components.hpp"
#include "stepwise/integrators.hpp"
#include "stepwise/world.hpp"
#include "world/world_impl.hpp"

#include <benchmark/benchmark.h>
#include <boost/numeric/odeint/stepper/runge_kutta4.hpp>

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
    const detail::ForceModel& model = w.impl().model;
    const std::size_t m = 2 * model.n;
    std::vector<double> y(2 * m);
    std::copy(w.impl().xs(), w.impl().xs() + m, y.begin());
    std::copy(w.impl().vs(), w.impl().vs() + m, y.begin() + long(m));
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

const std::vector<std::int64_t> kSizes{10'000, 100'000, 1'000'000};

int registerAll() {
    for (std::string_view name : integratorNames()) {
        const bool implicit = name.rfind("implicit_", 0) == 0;
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
    return 0;
}
const int kRegistered = registerAll();

} // namespace

BENCHMARK_MAIN();
