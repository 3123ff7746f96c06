// Gravity, drag and the dispatch over the force systems. Springs,
// attractors and boids live in their own files.

#include "forces/force_model.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::detail {

std::string_view forceSystemName(ForceSystem s) {
    switch (s) {
        case ForceSystem::Gravity: return "gravity";
        case ForceSystem::Drag: return "drag";
        case ForceSystem::Springs: return "springs";
        case ForceSystem::Attractors: return "attractors";
        case ForceSystem::Boids: return "boids";
        case ForceSystem::Count: break;
    }
    return "?";
}

bool ForceModel::velocityDependent() const {
    if (dragOn || boidsOn) return true;
    return std::any_of(springs.begin(), springs.end(), [](const SpringData& s) { return s.c != 0.0; });
}

void ForceModel::accelerations(const double* x, const double* v, double* a) const {
    const std::size_t m = 2 * n;
    {
        // Uniform gravity: a = g for every dynamic body (F = m g). Without
        // gravity the array is only cleared, which is not a system.
        if (gravityOn) {
            SystemTimer timer(*this, ForceSystem::Gravity);
            for (std::size_t i = 0; i < m; i += 2) {
                a[i] = gx;
                a[i + 1] = gy;
            }
        } else {
            std::fill(a, a + m, 0.0);
        }
    }
    if (dragOn) {
        // Viscous damping F = -b v, so a = -(b/m) v. Dense over all bodies
        // (rate 0 for bodies without drag): a branch-free streaming loop.
        SystemTimer timer(*this, ForceSystem::Drag);
        const double* rate = dragRate.data();
        for (std::size_t i = 0; i < n; ++i) {
            a[2 * i] -= rate[i] * v[2 * i];
            a[2 * i + 1] -= rate[i] * v[2 * i + 1];
        }
    }
    if (springsOn()) {
        SystemTimer timer(*this, ForceSystem::Springs);
        applySprings(x, v, a);
    }
    if (attractorsOn()) {
        SystemTimer timer(*this, ForceSystem::Attractors);
        applyAttractors(x, a);
    }
    if (boidsOn) {
        SystemTimer timer(*this, ForceSystem::Boids);
        boids.accumulate(x, v, a);
    }
}

void ForceModel::jacobian(const double* x, const double* v, JacobianSink& sink) const {
    if (dragOn)
        for (std::size_t i = 0; i < n; ++i)
            if (dragB[i] != 0.0) sink.drag(i, -dragB[i]);
    if (springsOn()) {
        for (std::size_t s = 0; s < springs.size(); ++s) {
            const SpringData& sp = springs[s];
            const double bx = sp.b == kNoBody ? sp.fx : x[2 * sp.b];
            const double by = sp.b == kNoBody ? sp.fy : x[2 * sp.b + 1];
            const double dx = x[2 * sp.a] - bx, dy = x[2 * sp.a + 1] - by;
            const double l = std::sqrt(dx * dx + dy * dy);
            std::array<double, 4> dFdx{}, dFdv{};
            if (l > 1e-12) {
                const double ux = dx / l, uy = dy / l;
                const double wx = v[2 * sp.a] - (sp.b == kNoBody ? 0.0 : v[2 * sp.b]);
                const double wy = v[2 * sp.a + 1] - (sp.b == kNoBody ? 0.0 : v[2 * sp.b + 1]);
                const double tension = sp.k * (l - sp.rest) + sp.c * (ux * wx + uy * wy);
                // F_a = -s u. dF_a/dx_a = -k u u^T - (s/l)(I - u u^T)
                //                         - (c/l) u w^T (I - u u^T).
                // The last term is not symmetric; it is dropped so the
                // Newton matrix stays symmetric (LDLT). Newton still
                // converges to the exact backward-Euler answer because the
                // residual is exact; only its rate is affected.
                const double t = tension / l;
                dFdx = {-sp.k * ux * ux - t * (1.0 - ux * ux), -sp.k * ux * uy + t * ux * uy,
                        -sp.k * ux * uy + t * ux * uy, -sp.k * uy * uy - t * (1.0 - uy * uy)};
                dFdv = {-sp.c * ux * ux, -sp.c * ux * uy, -sp.c * ux * uy, -sp.c * uy * uy};
            }
            sink.spring(s, dFdx, dFdv);
        }
    }
    if (attractorsOn()) {
        for (std::size_t k = 0; k < attractors.size(); ++k) {
            const AttractorData& at = attractors[k];
            const double ax = at.body == kNoBody ? at.px : x[2 * at.body];
            const double ay = at.body == kNoBody ? at.py : x[2 * at.body + 1];
            for (std::size_t i = 0; i < n; ++i) {
                if (i == at.body) continue;
                // F_i = m_i G m_a d q^(-3/2), d = p_a - p_i, q = |d|^2 + eps^2.
                // dF_i/dp_i = m_i G m_a (-I q^(-3/2) + 3 d d^T q^(-5/2)).
                const double dx = ax - x[2 * i], dy = ay - x[2 * i + 1];
                const double q = dx * dx + dy * dy + at.eps2;
                const double iq = 1.0 / q;
                const double s3 = mass[i] * at.gm * iq / std::sqrt(q);
                const double s5 = 3.0 * s3 * iq;
                sink.attraction(k, i, {-s3 + s5 * dx * dx, s5 * dx * dy, s5 * dx * dy, -s3 + s5 * dy * dy});
            }
        }
    }
}

} // namespace stepwise::detail
