// Springs and dampers: Hooke plus damping along the axis.
//   s   = k (len - rest) + c (u . (v_a - v_b))      tension, N
//   F_a = -s u,  F_b = +s u,  u = (p_a - p_b)/len
// Chains and cloth are thousands of these, so the loop reads the spring
// array once and scatters into the acceleration array; the ends'
// inverse masses are read from the model.

#include "forces/force_model.hpp"

#include <cmath>

namespace stepwise::detail {

void ForceModel::applySprings(const double* x, const double* v, double* a) const {
    const double* im = invMass.data();
    for (const SpringData& sp : springs) {
        const std::size_t ia = 2 * std::size_t(sp.a);
        const bool fixed = sp.b == kNoBody;
        const std::size_t ib = fixed ? 0 : 2 * std::size_t(sp.b);
        const double bx = fixed ? sp.fx : x[ib], by = fixed ? sp.fy : x[ib + 1];
        const double dx = x[ia] - bx, dy = x[ia + 1] - by;
        const double l = std::sqrt(dx * dx + dy * dy);
        // Coincident ends have no axis; the force is zero there (a set of
        // measure zero that a moving simulation passes straight through).
        if (!(l > 1e-12)) continue;
        const double ux = dx / l, uy = dy / l;
        const double wx = v[ia] - (fixed ? 0.0 : v[ib]);
        const double wy = v[ia + 1] - (fixed ? 0.0 : v[ib + 1]);
        const double tension = sp.k * (l - sp.rest) + sp.c * (ux * wx + uy * wy);
        const double fx = -tension * ux, fy = -tension * uy;
        a[ia] += fx * im[sp.a];
        a[ia + 1] += fy * im[sp.a];
        if (!fixed) {
            a[ib] -= fx * im[sp.b];
            a[ib + 1] -= fy * im[sp.b];
        }
    }
}

double ForceModel::springEnergy(const double* x) const {
    double e = 0.0;
    for (const SpringData& sp : springs) {
        const double bx = sp.b == kNoBody ? sp.fx : x[2 * sp.b];
        const double by = sp.b == kNoBody ? sp.fy : x[2 * sp.b + 1];
        const double dx = x[2 * sp.a] - bx, dy = x[2 * sp.a + 1] - by;
        const double stretch = std::sqrt(dx * dx + dy * dy) - sp.rest;
        e += 0.5 * sp.k * stretch * stretch;
    }
    return e;
}

} // namespace stepwise::detail
