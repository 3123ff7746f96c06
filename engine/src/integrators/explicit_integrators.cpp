// The explicit integrators. Each loop runs over the 2n doubles of a state
// array; a force evaluation writes the acceleration array `a_` (m/s^2).

#include "integrators/integrator.hpp"

#include <vector>

namespace stepwise::detail {

namespace {

using Vec = std::vector<double>;

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
        const std::size_t m = a_.size();
        if (f.localOnly()) {
            fusedLocal(f, x0, v0, x1, v1, h, m);
            return;
        }
        f.accelerations(x0, v0, a_.data());
        const double* a = a_.data();
        for (std::size_t i = 0; i < m; ++i) {
            const double vn = v0[i] + h * a[i];
            v1[i] = vn;
            x1[i] = x0[i] + h * vn;
        }
    }
    int lastEvaluations() const override { return 1; }

private:
    // Outputs never alias inputs (Integrator::step contract): __restrict
    // lets the compiler vectorise without runtime overlap checks.
    static void fusedLocal(const ForceModel& f, const double* __restrict x0, const double* __restrict v0,
                           double* __restrict x1, double* __restrict v1, double h, std::size_t m) {
        {
            // Gravity and drag only: the force is a function of the body's
            // own velocity, so it is fused into the update. One pass over
            // the state instead of three (memory-bound at 1e5+ bodies).
            const double gx = f.gravityOn ? f.gx : 0.0, gy = f.gravityOn ? f.gy : 0.0;
            if (f.dragOn) {
                const double* rate = f.dragRate.data();
                for (std::size_t b = 0; b < m / 2; ++b) {
                    const double vx = v0[2 * b] + h * (gx - rate[b] * v0[2 * b]);
                    const double vy = v0[2 * b + 1] + h * (gy - rate[b] * v0[2 * b + 1]);
                    v1[2 * b] = vx;
                    v1[2 * b + 1] = vy;
                    x1[2 * b] = x0[2 * b] + h * vx;
                    x1[2 * b + 1] = x0[2 * b + 1] + h * vy;
                }
            } else {
                for (std::size_t b = 0; b < m / 2; ++b) {
                    const double vx = v0[2 * b] + h * gx, vy = v0[2 * b + 1] + h * gy;
                    v1[2 * b] = vx;
                    v1[2 * b + 1] = vy;
                    x1[2 * b] = x0[2 * b] + h * vx;
                    x1[2 * b + 1] = x0[2 * b + 1] + h * vy;
                }
            }
        }
    }
    Vec a_;
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

private:
    Vec a_, xs_, vs_;
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
    }
    return nullptr;
}

std::optional<IntegratorKind> integratorKind(std::string_view name) {
    for (int k = 0; k <= int(IntegratorKind::ImplicitMidpoint); ++k)
        if (integratorName(IntegratorKind(k)) == name) return IntegratorKind(k);
    return std::nullopt;
}

std::string_view integratorName(IntegratorKind kind) {
    switch (kind) {
        case IntegratorKind::ExplicitEuler: return "explicit_euler";
        case IntegratorKind::SemiImplicitEuler: return "semi_implicit_euler";
        case IntegratorKind::Midpoint: return "midpoint";
        case IntegratorKind::Trapezoid: return "trapezoid";
        case IntegratorKind::Rk4: return "rk4";
        case IntegratorKind::VelocityVerlet: return "velocity_verlet";
        case IntegratorKind::ImplicitEuler: return "implicit_euler";
        case IntegratorKind::ImplicitMidpoint: return "implicit_midpoint";
    }
    return "?";
}

bool isImplicit(IntegratorKind kind) {
    return kind == IntegratorKind::ImplicitEuler || kind == IntegratorKind::ImplicitMidpoint;
}

} // namespace stepwise::detail
