// The explicit integrators. Each loop runs over the 2n doubles of a state
// array; a force evaluation writes the acceleration array `a_` (m/s^2).

#include "integrators/integrator.hpp"

#include <atomic>
#include <bit>
#include <cstdint>
#include <cstring>
#include <vector>

namespace stepwise::detail {

namespace {

using Vec = std::vector<double>;

// ---------------------------------------------------------------------------
// Streaming kernels for local forces (gravity and drag only: each body's
// acceleration is g - (b/m) v of its own velocity). One pass reads x0, v0
// (and the drag rates) and writes x1, v1, checking on the way that every
// value written is finite.
//
// Written with GCC/Clang vector extensions over eight doubles (four bodies
// of the interleaved state) so that one source compiles to SSE2, AVX2 and
// AVX-512 alike; the per-body drag rate is widened to (r0 r0 r1 r1 ...) by a
// shuffle. Per value the operations and their order are exactly those of
// the scalar formulas (and of ForceModel::accelerations followed by the
// integrator's update), the tail runs the scalar formulas, and the engine
// is built with -ffp-contract=off: every instruction set gives the same
// bits.
//
// Finiteness: v - v is +0 (all bits clear) for a finite v and NaN for inf
// or NaN, so OR-ing the bit patterns of x1 - x1 and v1 - v1 over the pass
// is zero exactly when every value is finite. Integer OR reassociates, so
// it vectorises (a floating-point sum would not without -ffast-math).

typedef double V8 __attribute__((vector_size(64)));
typedef double V4 __attribute__((vector_size(32)));
typedef std::uint64_t U8 __attribute__((vector_size(64)));

struct LocalArgs {
    const double* x0;
    const double* v0;
    double* x1;
    double* v1;
    const double* rate;  ///< b/m per body, 1/s (drag only)
    double gx, gy;       ///< m/s^2, 0 without gravity
    double h;            ///< s
    std::size_t n;       ///< bodies
};

// Non-zero when value * scale overflows (|value| at or past the quick bound
// the scale stands for, see integrator.hpp) or value is not finite: inf - inf
// and NaN - NaN are NaN.
inline std::uint64_t outOfQuickRangeBits(double value, double scale) {
    const double scaled = value * scale;
    return std::bit_cast<std::uint64_t>(scaled - scaled);
}

// The per-body updates, for T = V8 (four bodies of the interleaved state)
// or double (one coordinate of the tail): the same code, so the same
// operations in the same order, for both.
//
// Semi-implicit Euler: v1 = v0 + h (g - r v0), x1 = x0 + h v1 (without drag
// v1 = v0 + h g).
template <bool Drag, class T>
[[gnu::always_inline]] inline void eulerBody(const T& x, const T& v, const T& r, const T& g, double h, T& xn, T& vn) {
    if constexpr (Drag)
        vn = v + h * (g - r * v);
    else
        vn = v + h * g;
    xn = x + h * vn;
}

// Classical RK4 (the Rk4 class below) with a = g - r v: the stage
// accelerations depend on the stage velocity only, so the whole step of a
// body runs in registers, one pass instead of four force evaluations and
// four combination passes. Same operations, same order as Rk4::step with
// ForceModel::accelerations (a = g, then a -= r v).
template <bool Drag, class T>
[[gnu::always_inline]] inline void rk4Body(const T& x, const T& v, const T& r, const T& g, double h, T& xn, T& vn) {
    const double h2 = 0.5 * h, h3 = h / 3.0, h6 = h / 6.0;
    T a = Drag ? g - r * v : g;  // k1
    xn = x + h6 * v;
    vn = v + h6 * a;
    T vs = v + h2 * a;
    a = Drag ? g - r * vs : g;  // k2
    xn += h3 * vs;
    vn += h3 * a;
    vs = v + h2 * a;
    a = Drag ? g - r * vs : g;  // k3
    xn += h3 * vs;
    vn += h3 * a;
    vs = v + h * a;
    a = Drag ? g - r * vs : g;  // k4
    xn += h6 * vs;
    vn += h6 * a;
}

// One pass over the state: reads x0, v0 (and the drag rates), writes x1, v1
// with Euler's or RK4's update, and returns true when every value written
// is finite.
template <bool Rk, bool Drag>
[[gnu::always_inline]] inline bool localPass(const LocalArgs& k) {
    const double* __restrict x0 = k.x0;
    const double* __restrict v0 = k.v0;
    double* __restrict x1 = k.x1;
    double* __restrict v1 = k.v1;
    const double* __restrict rate = k.rate;
    const double h = k.h, gx = k.gx, gy = k.gy;
    const std::size_t n = k.n;  // a local: the stores could alias k
    const V8 g = {gx, gy, gx, gy, gx, gy, gx, gy};
    U8 bad8 = {};
    std::size_t b = 0;
    for (; b + 4 <= n; b += 4) {
        V8 v, x;
        std::memcpy(&v, v0 + 2 * b, sizeof v);
        std::memcpy(&x, x0 + 2 * b, sizeof x);
        V8 r = {};
        if constexpr (Drag) {
            V4 r4;
            std::memcpy(&r4, rate + b, sizeof r4);
            r = __builtin_shufflevector(r4, r4, 0, 0, 1, 1, 2, 2, 3, 3);  // (r0 r0 r1 r1 ...)
        }
        V8 xn, vn;
        if constexpr (Rk)
            rk4Body<Drag>(x, v, r, g, h, xn, vn);
        else
            eulerBody<Drag>(x, v, r, g, h, xn, vn);
        std::memcpy(v1 + 2 * b, &vn, sizeof vn);
        std::memcpy(x1 + 2 * b, &xn, sizeof xn);
        const V8 vs = vn * kQuickSpeedScale, xs = xn * kQuickRangeScale;
        bad8 |= (U8)(vs - vs) | (U8)(xs - xs);
    }
    std::uint64_t bad = 0;
    for (int lane = 0; lane < 8; ++lane) bad |= bad8[lane];
    for (std::size_t i = 2 * b; i < 2 * n; ++i) {
        const double r = Drag ? rate[i / 2] : 0.0;
        const double gi = (i & 1) ? gy : gx;
        double xn, vn;
        if constexpr (Rk)
            rk4Body<Drag>(x0[i], v0[i], r, gi, h, xn, vn);
        else
            eulerBody<Drag>(x0[i], v0[i], r, gi, h, xn, vn);
        v1[i] = vn;
        x1[i] = xn;
        bad |= outOfQuickRangeBits(vn, kQuickSpeedScale) | outOfQuickRangeBits(xn, kQuickRangeScale);
    }
    return bad == 0;
}

using LocalKernel = bool (*)(const LocalArgs&);

// One function per (method, drag, instruction set). The always_inline
// kernel is compiled inside each, with that function's instruction set.
template <bool Rk, bool Drag>
bool localBaseline(const LocalArgs& k) {
    return localPass<Rk, Drag>(k);
}
#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define STEPWISE_X86_DISPATCH 1
template <bool Rk, bool Drag>
__attribute__((target("avx2"))) bool localAvx2(const LocalArgs& k) {
    return localPass<Rk, Drag>(k);
}
template <bool Rk, bool Drag>
__attribute__((target("avx512f"))) bool localAvx512(const LocalArgs& k) {
    return localPass<Rk, Drag>(k);
}
#endif

SimdLevel bestSimdLevel() {
#ifdef STEPWISE_X86_DISPATCH
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx512f")) return SimdLevel::Avx512;
    if (__builtin_cpu_supports("avx2")) return SimdLevel::Avx2;
#endif
    return SimdLevel::Baseline;
}

std::atomic<SimdLevel>& simdLevelInUse() {
    static std::atomic<SimdLevel> level{bestSimdLevel()};
    return level;
}

template <bool Rk>
LocalKernel localKernel(bool drag) {
    switch (simdLevelInUse().load(std::memory_order_relaxed)) {
#ifdef STEPWISE_X86_DISPATCH
        case SimdLevel::Avx512: return drag ? localAvx512<Rk, true> : localAvx512<Rk, false>;
        case SimdLevel::Avx2: return drag ? localAvx2<Rk, true> : localAvx2<Rk, false>;
#endif
        default: return drag ? localBaseline<Rk, true> : localBaseline<Rk, false>;
    }
}

LocalArgs localArgs(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) {
    // Without gravity the force model starts from a = 0 (and drag makes it
    // 0 - r v): g = 0 reproduces both.
    return {x0, v0, x1, v1, f.dragOn ? f.dragRate.data() : nullptr, f.gravityOn ? f.gx : 0.0,
            f.gravityOn ? f.gy : 0.0, h, f.n};
}

class ExplicitEuler final : public Integrator {
public:
    explicit ExplicitEuler(std::size_t n) : a_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // Both updates from the old state (the notes' "Explicit Euler: Code").
        f.accelerations(x0, v0, a_.data());
        const double* a = a_.data();
        for (std::size_t i = 0, m = a_.size(); i < m; ++i) {
            x1[i] = x0[i] + h * v0[i];
            v1[i] = v0[i] + h * a[i];
        }
    }
    int lastEvaluations() const override { return 1; }

private:
    Vec a_;
};

class SemiImplicitEuler final : public Integrator {
public:
    explicit SemiImplicitEuler(std::size_t n) : a_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // Velocity first, then position with the new velocity (the notes'
        // "first try" slide, which calls it forward Euler: it is not; it is
        // symplectic Euler).
        if (f.localOnly()) {
            // Gravity and drag only: the force is a function of the body's
            // own velocity, so it is fused into the update, and so is the
            // finiteness check. One pass over the state instead of four
            // (memory-bound at 1e5+ bodies).
            verified_ = localKernel<false>(f.dragOn)(localArgs(f, x0, v0, x1, v1, h));
            return;
        }
        verified_ = false;
        const std::size_t m = a_.size();
        f.accelerations(x0, v0, a_.data());
        const double* a = a_.data();
        for (std::size_t i = 0; i < m; ++i) {
            const double vn = v0[i] + h * a[i];
            v1[i] = vn;
            x1[i] = x0[i] + h * vn;
        }
    }
    int lastEvaluations() const override { return 1; }
    bool lastStepVerifiedInRange() const override { return verified_; }

private:
    Vec a_;
    bool verified_ = false;
};

class Midpoint final : public Integrator {
public:
    explicit Midpoint(std::size_t n) : a_(2 * n), xm_(2 * n), vm_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // 1. half Euler step, 2. evaluate there, 3. full step with it.
        const std::size_t m = a_.size();
        f.accelerations(x0, v0, a_.data());
        for (std::size_t i = 0; i < m; ++i) {
            xm_[i] = x0[i] + 0.5 * h * v0[i];
            vm_[i] = v0[i] + 0.5 * h * a_[i];
        }
        f.accelerations(xm_.data(), vm_.data(), a_.data());
        for (std::size_t i = 0; i < m; ++i) {
            x1[i] = x0[i] + h * vm_[i];
            v1[i] = v0[i] + h * a_[i];
        }
    }
    int lastEvaluations() const override { return 2; }

private:
    Vec a_, xm_, vm_;
};

class Trapezoid final : public Integrator {
public:
    explicit Trapezoid(std::size_t n) : a_(2 * n), xa_(2 * n), va_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // The notes' four steps: 1. full Euler step to X_a; 2. evaluate f at
        // X_a; 3. full step from X_0 with it to X_b; 4. average X_a, X_b.
        const std::size_t m = a_.size();
        f.accelerations(x0, v0, a_.data());
        for (std::size_t i = 0; i < m; ++i) {
            xa_[i] = x0[i] + h * v0[i];
            va_[i] = v0[i] + h * a_[i];
        }
        f.accelerations(xa_.data(), va_.data(), a_.data());
        for (std::size_t i = 0; i < m; ++i) {
            const double xb = x0[i] + h * va_[i];
            const double vb = v0[i] + h * a_[i];
            x1[i] = 0.5 * (xa_[i] + xb);
            v1[i] = 0.5 * (va_[i] + vb);
        }
    }
    int lastEvaluations() const override { return 2; }

private:
    Vec a_, xa_, va_;
};

class Rk4 final : public Integrator {
public:
    explicit Rk4(std::size_t n) : a_(2 * n), xs_(2 * n), vs_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // Classical RK4 with the outputs as running sums: each stage is one
        // force evaluation plus one fused pass (accumulate k_i, form the
        // next stage state), 3 scratch arrays in all.
        if (f.localOnly()) {
            // Gravity and drag only: the four stages of a body need nothing
            // but its own velocity, so the step is one fused pass (and
            // checks finiteness on the way).
            verified_ = localKernel<true>(f.dragOn)(localArgs(f, x0, v0, x1, v1, h));
            return;
        }
        verified_ = false;
        const std::size_t m = a_.size();
        double* a = a_.data();
        double* xs = xs_.data();
        double* vs = vs_.data();
        const double h2 = 0.5 * h, h3 = h / 3.0, h6 = h / 6.0;
        f.accelerations(x0, v0, a);  // k1
        for (std::size_t i = 0; i < m; ++i) {
            x1[i] = x0[i] + h6 * v0[i];
            v1[i] = v0[i] + h6 * a[i];
            xs[i] = x0[i] + h2 * v0[i];
            vs[i] = v0[i] + h2 * a[i];
        }
        f.accelerations(xs, vs, a);  // k2
        for (std::size_t i = 0; i < m; ++i) {
            const double vk = vs[i];
            x1[i] += h3 * vk;
            v1[i] += h3 * a[i];
            xs[i] = x0[i] + h2 * vk;
            vs[i] = v0[i] + h2 * a[i];
        }
        f.accelerations(xs, vs, a);  // k3
        for (std::size_t i = 0; i < m; ++i) {
            const double vk = vs[i];
            x1[i] += h3 * vk;
            v1[i] += h3 * a[i];
            xs[i] = x0[i] + h * vk;
            vs[i] = v0[i] + h * a[i];
        }
        f.accelerations(xs, vs, a);  // k4
        for (std::size_t i = 0; i < m; ++i) {
            x1[i] += h6 * vs[i];
            v1[i] += h6 * a[i];
        }
    }
    int lastEvaluations() const override { return 4; }
    bool lastStepVerifiedInRange() const override { return verified_; }

private:
    Vec a_, xs_, vs_;
    bool verified_ = false;
};

class VelocityVerlet final : public Integrator {
public:
    explicit VelocityVerlet(std::size_t n) : a_(2 * n), vp_(2 * n) {}
    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        // Kick-drift-kick:
        //   v_half = v0 + h/2 a(x0, v0);  x1 = x0 + h v_half;
        //   v1     = v_half + h/2 a(x1, v1).
        // a(x1, v1) needs v1. The textbook shortcut a(x1, v_half) makes the
        // method first order as soon as a force depends on velocity (drag,
        // spring damping, boids): the O(h) error in the velocity argument
        // enters v1 as O(h^2) per step. We pass the Euler prediction
        // v0 + h a0 instead (O(h^2) off, so O(h^3) per step): second order
        // again at no extra force evaluation. With position-only forces the
        // velocity argument is unused and this is exactly velocity Verlet
        // (symplectic). a(x0, v0) is recomputed each step instead of being
        // carried over, so a saved and reloaded world continues bit-identically.
        const std::size_t m = a_.size();
        f.accelerations(x0, v0, a_.data());
        const bool predict = f.velocityDependent();
        for (std::size_t i = 0; i < m; ++i) {
            const double vh = v0[i] + 0.5 * h * a_[i];
            v1[i] = vh;
            x1[i] = x0[i] + h * vh;
            vp_[i] = v0[i] + h * a_[i];
        }
        f.accelerations(x1, predict ? vp_.data() : v1, a_.data());
        for (std::size_t i = 0; i < m; ++i) v1[i] += 0.5 * h * a_[i];
    }
    int lastEvaluations() const override { return 2; }

private:
    Vec a_, vp_;
};

} // namespace

std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const ForceModel& model) {
    const std::size_t n = model.n;
    switch (kind) {
        case IntegratorKind::ExplicitEuler: return std::make_unique<ExplicitEuler>(n);
        case IntegratorKind::SemiImplicitEuler: return std::make_unique<SemiImplicitEuler>(n);
        case IntegratorKind::Midpoint: return std::make_unique<Midpoint>(n);
        case IntegratorKind::Trapezoid: return std::make_unique<Trapezoid>(n);
        case IntegratorKind::Rk4: return std::make_unique<Rk4>(n);
        case IntegratorKind::VelocityVerlet: return std::make_unique<VelocityVerlet>(n);
        case IntegratorKind::ImplicitEuler: return makeImplicitIntegrator(false, model);
        case IntegratorKind::ImplicitMidpoint: return makeImplicitIntegrator(true, model);
        case IntegratorKind::Dopri5: return makeDopri5(model);
    }
    return nullptr;
}

SimdLevel simdLevel() { return simdLevelInUse().load(std::memory_order_relaxed); }

SimdLevel setSimdLevel(SimdLevel level) {
    const SimdLevel best = bestSimdLevel();
    const SimdLevel use = int(level) <= int(best) ? level : best;
    simdLevelInUse().store(use, std::memory_order_relaxed);
    return use;
}

bool isImplicit(IntegratorKind kind) {
    return kind == IntegratorKind::ImplicitEuler || kind == IntegratorKind::ImplicitMidpoint;
}

} // namespace stepwise::detail
