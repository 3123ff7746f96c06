// Implicit integrators: backward Euler and the implicit midpoint rule, both
// solved for the end-of-step velocity v1 by Newton's method.
//
//   backward Euler:  v1 = v0 + h a(x0 + h v1, v1),          x1 = x0 + h v1
//   implicit midpt:  v1 = v0 + h a(x0 + h/4 (v0+v1), (v0+v1)/2),
//                    x1 = x0 + h/2 (v0 + v1)
//
// Both are G(v1) = M (v1 - v0) - h F(x_e(v1), v_e(v1)) = 0 with
// x_e = x0 + cx0 v0 + cx1 v1 and v_e = cv0 v0 + cv1 v1, so
//   dG/dv1 = M - h cv1 dF/dv - h cx1 dF/dx     (2n x 2n, sparse).
// The Jacobian blocks are analytic (springs, drag, attractors; boids are
// explicit inside the iteration). Its pattern is fixed by the scene, so the
// sparse matrix, the symbolic factorisation and the address of every block
// entry are computed once; an iteration only overwrites values.
// Newton uses the chord variant: the factorisation is reused while the
// update shrinks by at least 4x per iteration (a linear force converges in
// one factorisation), and refreshed otherwise.

#include "integrators/integrator.hpp"

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseLU>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

namespace stepwise::detail {

namespace {

using SparseMatrix = Eigen::SparseMatrix<double>;

class ImplicitIntegrator final : public Integrator, private JacobianSink {
public:
    ImplicitIntegrator(bool midpoint, const ForceModel& model)
        : midpoint_(midpoint), n_(model.n), a_(2 * n_), xe_(2 * n_), ve_(2 * n_), rhs_(2 * n_), delta_(2 * n_),
          residual_(2 * n_) {
        buildPattern(model);
    }

    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double h) override {
        const std::size_t m = 2 * n_;
        const double cx0 = midpoint_ ? 0.25 * h : 0.0, cx1 = midpoint_ ? 0.25 * h : h;
        const double cv0 = midpoint_ ? 0.5 : 0.0, cv1 = midpoint_ ? 0.5 : 1.0;
        alpha_ = h * cv1;  // weight of dF/dv in dG/dv1
        beta_ = h * cx1;   // weight of dF/dx
        std::copy(v0, v0 + m, v1);  // initial guess: v1 = v0
        evaluations_ = 0;
        failed_ = false;
        bool factored = false;
        double previous = 0.0;
        for (int iteration = 0; iteration < kNewtonMaxIterations; ++iteration) {
            for (std::size_t i = 0; i < m; ++i) {
                xe_[i] = x0[i] + cx0 * v0[i] + cx1 * v1[i];
                ve_[i] = cv0 * v0[i] + cv1 * v1[i];
            }
            f.accelerations(xe_.data(), ve_.data(), a_.data());
            ++evaluations_;
            // rhs = -G(v1) = M (v0 - v1 + h a), newtons*s.
            for (std::size_t i = 0; i < m; ++i) rhs_[Eigen::Index(i)] = f.mass[i / 2] * (v0[i] - v1[i] + h * a_[i]);
            if (!factored) {
                if (!factorize(f)) {
                    // Singular in doubles: the masses on the diagonal are
                    // lost to rounding next to h^2 k (k >= ~1e20 for 1 kg at
                    // 60 Hz). Keeping v1 = v0 froze every body, the free
                    // ones too: refuse the step instead.
                    fail("the linear system is singular in double precision (the factorisation failed)",
                         Failure::Factorisation);
                    break;
                }
                factored = true;
            }
            solve();
            if (!solveAccurate()) break;
            // Converged when the update is below kNewtonRelativeTolerance of
            // the velocities or of what moves a position by one step's worth
            // of its own magnitude (|x|/h): below that, the update only
            // changes positions at rounding level, and rounding in the
            // stiff forces (k |x| eps) keeps it from shrinking further.
            double size = 0.0, scale = 0.0;
            for (std::size_t i = 0; i < m; ++i) {
                v1[i] += delta_[Eigen::Index(i)];
                size = std::max(size, std::abs(delta_[Eigen::Index(i)]));
                scale = std::max({scale, std::abs(v1[i]), std::abs(x0[i]) / h});
            }
            if (!(size > kNewtonRelativeTolerance * scale)) break;  // converged (or NaN: stop)
            // Chord Newton: refactor when the update stopped shrinking fast.
            if (iteration > 0 && size > 0.25 * previous) factored = false;
            previous = size;
        }
        if (midpoint_) {
            for (std::size_t i = 0; i < m; ++i) x1[i] = x0[i] + 0.5 * h * (v0[i] + v1[i]);
        } else {
            for (std::size_t i = 0; i < m; ++i) x1[i] = x0[i] + h * v1[i];
        }
    }
    int lastEvaluations() const override { return evaluations_; }
    const SolveFailure* lastFailure() const override { return failed_ ? &failure_ : nullptr; }

private:
    // --- JacobianSink: A = M - alpha dF/dv - beta dF/dx, block by block.
    void addBlock(int slot, double sign, const std::array<double, 4>& block) {
        if (slot < 0) return;
        double* values = A_.valuePtr();
        for (int e = 0; e < 4; ++e) values[blockSlots_[std::size_t(slot) * 4 + std::size_t(e)]] += sign * block[e];
    }
    void spring(std::size_t s, const std::array<double, 4>& dFdx, const std::array<double, 4>& dFdv) override {
        std::array<double, 4> b;
        for (int e = 0; e < 4; ++e) b[e] = -(alpha_ * dFdv[e] + beta_ * dFdx[e]);
        const SpringSlots& slots = springSlots_[s];
        // F_b = -F_a, so the (b,b) block equals (a,a) and the cross blocks
        // are its negative.
        addBlock(slots.aa, 1.0, b);
        addBlock(slots.bb, 1.0, b);
        addBlock(slots.ab, -1.0, b);
        addBlock(slots.ba, -1.0, b);
    }
    void drag(std::size_t body, double minusB) override {
        double* values = A_.valuePtr();
        values[blockSlots_[diagSlot(body) * 4 + 0]] -= alpha_ * minusB;
        values[blockSlots_[diagSlot(body) * 4 + 3]] -= alpha_ * minusB;
    }
    void attraction(std::size_t attractor, std::size_t body, const std::array<double, 4>& dFdx) override {
        std::array<double, 4> b;
        for (int e = 0; e < 4; ++e) b[e] = -beta_ * dFdx[e];
        addBlock(int(diagSlot(body)), 1.0, b);
        // dF_body/dp_attractor = -dF_body/dp_body.
        addBlock(attractionCross_[attractor * n_ + body], -1.0, b);
    }

    struct SpringSlots {
        int aa = -1, bb = -1, ab = -1, ba = -1;
    };
    std::size_t diagSlot(std::size_t body) const { return body; }

    void buildPattern(const ForceModel& model) {
        // Blocks: one per body on the diagonal (slot = body index), then the
        // off-diagonal blocks of springs and dynamic attractors.
        std::vector<std::pair<std::size_t, std::size_t>> blocks;
        for (std::size_t i = 0; i < n_; ++i) blocks.emplace_back(i, i);
        auto addPair = [&](std::size_t r, std::size_t c) {
            blocks.emplace_back(r, c);
            return int(blocks.size() - 1);
        };
        springSlots_.resize(model.springs.size());
        for (std::size_t s = 0; s < model.springs.size(); ++s) {
            const SpringData& sp = model.springs[s];
            SpringSlots& slots = springSlots_[s];
            slots.aa = int(sp.a);
            if (sp.b != kNoBody) {
                slots.bb = int(sp.b);
                slots.ab = addPair(sp.a, sp.b);
                slots.ba = addPair(sp.b, sp.a);
            }
        }
        attractionCross_.assign(model.attractors.size() * n_, -1);
        symmetric_ = true;
        for (std::size_t k = 0; k < model.attractors.size(); ++k) {
            const AttractorData& at = model.attractors[k];
            if (at.body == kNoBody) continue;
            // A dynamic attractor pulls body i but a plain body does not pull
            // back: dF_i/dp_a without its transpose. LU instead of LDLT.
            symmetric_ = false;
            for (std::size_t i = 0; i < n_; ++i)
                if (i != at.body) attractionCross_[k * n_ + i] = addPair(i, at.body);
        }
        std::vector<Eigen::Triplet<double>> triplets;
        triplets.reserve(blocks.size() * 4);
        for (const auto& [r, c] : blocks)
            for (int e = 0; e < 4; ++e)
                triplets.emplace_back(Eigen::Index(2 * r + std::size_t(e / 2)), Eigen::Index(2 * c + std::size_t(e % 2)),
                                      0.0);
        A_.resize(Eigen::Index(2 * n_), Eigen::Index(2 * n_));
        A_.setFromTriplets(triplets.begin(), triplets.end());
        A_.makeCompressed();
        blockSlots_.resize(blocks.size() * 4);
        for (std::size_t b = 0; b < blocks.size(); ++b)
            for (int e = 0; e < 4; ++e)
                blockSlots_[b * 4 + std::size_t(e)] =
                    std::size_t(&A_.coeffRef(Eigen::Index(2 * blocks[b].first + std::size_t(e / 2)),
                                             Eigen::Index(2 * blocks[b].second + std::size_t(e % 2))) -
                                A_.valuePtr());
        if (symmetric_)
            ldlt_.analyzePattern(A_);
        else
            lu_.analyzePattern(A_);
        luAnalyzed_ = !symmetric_;
    }

    bool factorize(const ForceModel& f) {
        std::fill(A_.valuePtr(), A_.valuePtr() + A_.nonZeros(), 0.0);
        double* values = A_.valuePtr();
        massOf_.assign(f.mass.begin(), f.mass.begin() + std::ptrdiff_t(n_));
        residual_.setZero();
        for (std::size_t i = 0; i < n_; ++i) {
            values[blockSlots_[i * 4 + 0]] = f.mass[i];
            values[blockSlots_[i * 4 + 3]] = f.mass[i];
        }
        f.jacobian(xe_.data(), ve_.data(), *this);
        useLu_ = !symmetric_;
        if (symmetric_) {
            ldlt_.factorize(A_);
            if (ldlt_.info() == Eigen::Success) return true;
            useLu_ = true;  // a zero pivot (indefinite, compressed springs): fall back to LU
        }
        if (!luAnalyzed_) {
            lu_.analyzePattern(A_);
            luAnalyzed_ = true;
        }
        lu_.factorize(A_);
        return lu_.info() == Eigen::Success;
    }

    /// The residual of the last solve against the matrix it factored: a
    /// solve that "succeeds" on a nearly singular matrix (k = 1e100) gives
    /// velocities off by orders of magnitude, a 96 km spring. The bodies
    /// named are those whose rows the solve got wrong; bodies of other,
    /// well-conditioned blocks (a free body) have residual ~0.
    bool solveAccurate() {
        residual_.noalias() = A_ * delta_;
        residual_ -= rhs_;
        const double rhsSize = rhs_.lpNorm<Eigen::Infinity>();
        const double size = residual_.lpNorm<Eigen::Infinity>();
        if (size <= kSolveRelativeResidual * rhsSize) return true;
        if (!std::isfinite(rhsSize)) return true;  // non-finite forces: the world's check names them
        char text[160];
        std::snprintf(text, sizeof text,
                      "the linear solve lost its accuracy (residual %.2g of the right-hand side; the system is too "
                      "stiff for doubles at this dt)",
                      rhsSize > 0.0 ? size / rhsSize : size);
        fail(text, Failure::Solve);
        return false;
    }

    /// Which part of the Newton step failed: the factorisation of the
    /// system, or the solve that followed it (then the residual names the
    /// bodies whose rows went wrong).
    enum class Failure { Factorisation, Solve };
    void fail(const std::string& what, Failure where) {
        failed_ = true;
        failure_.what = what;
        failure_.bodies.clear();
        const double rhsSize = rhs_.lpNorm<Eigen::Infinity>();
        const bool solved = residual_.size() == rhs_.size() && residual_.allFinite();
        for (std::size_t b = 0; b < n_; ++b) {
            bool bad;
            if (solved && where == Failure::Solve) {
                const double r = std::max(std::abs(residual_[Eigen::Index(2 * b)]),
                                          std::abs(residual_[Eigen::Index(2 * b + 1)]));
                bad = !(r <= kSolveRelativeResidual * rhsSize);
            } else {
                // Factorisation failed: the bodies whose mass is lost next to
                // the stiffness on their diagonal.
                const double* values = A_.valuePtr();
                const double diag = std::max(std::abs(values[blockSlots_[b * 4 + 0]]),
                                             std::abs(values[blockSlots_[b * 4 + 3]]));
                bad = !(diag * std::numeric_limits<double>::epsilon() < massOf_[b]);
            }
            if (bad) failure_.bodies.push_back(b);
        }
    }

    void solve() {
        if (useLu_)
            delta_ = lu_.solve(rhs_);
        else
            delta_ = ldlt_.solve(rhs_);
    }

    bool midpoint_;
    std::size_t n_;
    std::vector<double> a_, xe_, ve_;
    Eigen::VectorXd rhs_, delta_, residual_;
    std::vector<double> massOf_;  ///< the masses of the last factorisation (naming failing bodies)
    bool failed_ = false;
    SolveFailure failure_;
    SparseMatrix A_;
    std::vector<std::size_t> blockSlots_;  ///< per block, 4 offsets into A_'s values (row-major in the block)
    std::vector<SpringSlots> springSlots_;
    std::vector<int> attractionCross_;     ///< [attractor * n + body] -> block of dF_body/dp_attractor
    Eigen::SimplicialLDLT<SparseMatrix> ldlt_;
    Eigen::SparseLU<SparseMatrix> lu_;
    bool symmetric_ = true, useLu_ = false, luAnalyzed_ = false;
    double alpha_ = 0.0, beta_ = 0.0;
    int evaluations_ = 0;
};

} // namespace

std::unique_ptr<Integrator> makeImplicitIntegrator(bool midpointRule, const ForceModel& model) {
    return std::make_unique<ImplicitIntegrator>(midpointRule, model);
}

// --- Stability limits ------------------------------------------------------

namespace {

struct Scalar {
    double x, v;
};

// One step of `kind` on x'' = -x - 2 zeta x' (omega = 1, so h = h*omega).
Scalar scalarStep(IntegratorKind kind, Scalar s, double h, double zeta) {
    auto f = [zeta](double x, double v) { return -x - 2.0 * zeta * v; };
    switch (kind) {
        case IntegratorKind::ExplicitEuler: return {s.x + h * s.v, s.v + h * f(s.x, s.v)};
        case IntegratorKind::SemiImplicitEuler: {
            const double v = s.v + h * f(s.x, s.v);
            return {s.x + h * v, v};
        }
        case IntegratorKind::Midpoint: {
            const double xm = s.x + 0.5 * h * s.v, vm = s.v + 0.5 * h * f(s.x, s.v);
            return {s.x + h * vm, s.v + h * f(xm, vm)};
        }
        case IntegratorKind::Trapezoid: {
            const double xa = s.x + h * s.v, va = s.v + h * f(s.x, s.v);
            const double xb = s.x + h * va, vb = s.v + h * f(xa, va);
            return {0.5 * (xa + xb), 0.5 * (va + vb)};
        }
        case IntegratorKind::Rk4: {
            const double k1x = s.v, k1v = f(s.x, s.v);
            const double k2x = s.v + 0.5 * h * k1v, k2v = f(s.x + 0.5 * h * k1x, s.v + 0.5 * h * k1v);
            const double k3x = s.v + 0.5 * h * k2v, k3v = f(s.x + 0.5 * h * k2x, s.v + 0.5 * h * k2v);
            const double k4x = s.v + h * k3v, k4v = f(s.x + h * k3x, s.v + h * k3v);
            return {s.x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x), s.v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)};
        }
        case IntegratorKind::VelocityVerlet: {
            const double a0 = f(s.x, s.v);
            const double vh = s.v + 0.5 * h * a0, x1 = s.x + h * vh, vp = s.v + h * a0;
            return {x1, vh + 0.5 * h * f(x1, vp)};
        }
        case IntegratorKind::ImplicitEuler:
        case IntegratorKind::ImplicitMidpoint:
        case IntegratorKind::Dopri5: break;
    }
    return s;
}

double spectralRadius(IntegratorKind kind, double h, double zeta) {
    const Scalar c0 = scalarStep(kind, {1.0, 0.0}, h, zeta);
    const Scalar c1 = scalarStep(kind, {0.0, 1.0}, h, zeta);
    const double tr = c0.x + c1.v, det = c0.x * c1.v - c1.x * c0.v;
    const double disc = 0.25 * tr * tr - det;
    if (disc >= 0.0) return std::max(std::abs(0.5 * tr + std::sqrt(disc)), std::abs(0.5 * tr - std::sqrt(disc)));
    return std::sqrt(det);  // complex pair: |lambda|^2 = det
}

} // namespace

double stabilityLimit(IntegratorKind kind, double zeta) {
    // dopri5 cannot spiral out: its controller shrinks the internal step
    // until the error (and so the growth) is within tolerance. Stiffness
    // costs it steps, not stability.
    if (isImplicit(kind) || kind == IntegratorKind::Dopri5) return std::numeric_limits<double>::infinity();
    constexpr double kStep = 0.005, kMax = 50.0, kSlack = 1e-12;
    for (double y = kStep; y <= kMax; y += kStep) {
        if (spectralRadius(kind, y, zeta) <= 1.0 + kSlack) continue;
        if (y == kStep) return 0.0;  // unstable at every practical h*omega (undamped Euler, RK2)
        double lo = y - kStep, hi = y;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (spectralRadius(kind, mid, zeta) <= 1.0 + kSlack ? lo : hi) = mid;
        }
        return lo;
    }
    return kMax;
}

} // namespace stepwise::detail
