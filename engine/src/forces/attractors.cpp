// Newtonian attraction with Plummer softening. Body i feels, towards
// attractor a,
//   a_i = G m_a d / (|d|^2 + eps^2)^(3/2),   d = p_a - p_i,
// the gradient of the potential -G m_i m_a / sqrt(|d|^2 + eps^2). Dynamic
// attractors pull each other (n-body); only attractors pull (the scene
// format:
// "every other dynamic body i feels ... toward this body"), so a plain
// body does not pull an attractor back. Cost O(bodies * attractors)
// summed exactly, O(bodies log attractors) through the Barnes–Hut tree
// (barnes_hut.hpp) when theta > 0 and there are enough attractors.

#include "forces/force_model.hpp"

#include <cmath>
#include <cstring>

namespace stepwise::detail {

template <bool Potential>
Vec2 ForceModel::exactField(double px, double py, std::uint32_t self, const double* x, double* phiFixed,
                            double* phiDynamic) const {
    Vec2 acc = gravityOn ? Vec2{gx, gy} : Vec2{};
    // Potential sums in locals, stored once at the end: through the
    // pointers each addition would wait on the previous store.
    double fixedSum = 0.0, dynamicSum = 0.0;
    for (const AttractorData& at : attractors) {
        if (at.body == self && self != kNoBody) continue;
        const double ax = at.body == kNoBody ? at.px : x[2 * at.body];
        const double ay = at.body == kNoBody ? at.py : x[2 * at.body + 1];
        const double dx = ax - px, dy = ay - py;
        const double q = dx * dx + dy * dy + at.eps2;
        // q == 0 only at the centre of an unsoftened attractor: no direction,
        // no force (the probe sits on the singularity).
        if (!(q > 0.0)) continue;
        const double r = std::sqrt(q);
        const double s = at.gm / (q * r);
        acc.x += s * dx;
        acc.y += s * dy;
        // G m / r = s q: a multiply instead of a second division (the
        // divider is the bottleneck of this loop), within an ulp.
        if constexpr (Potential) (at.body == kNoBody ? fixedSum : dynamicSum) += s * q;
    }
    if constexpr (Potential) {
        *phiFixed += fixedSum;
        *phiDynamic += dynamicSum;
    }
    return acc;
}

Vec2 ForceModel::fieldAt(double px, double py, std::uint32_t self, const double* x) const {
    return exactField<false>(px, py, self, x, nullptr, nullptr);
}

template <bool Potential>
double ForceModel::attractorPass(const double* x, double* acc) const {
    // Potential: body i feels -m_i G m_a / r from each attractor. A pair of
    // two dynamic attractors appears twice (each pulls the other), so for
    // an attractor body the dynamic part counts half.
    std::vector<char> isAttractor;
    if constexpr (Potential) {
        isAttractor.assign(n, 0);
        for (const AttractorData& at : attractors)
            if (at.body != kNoBody) isAttractor[at.body] = 1;
    }
    double energy = 0.0;
    if (usesTree() && tree_.build(attractors, x, theta)) {
        for (std::size_t i = 0; i < n; ++i) {
            double ax = 0.0, ay = 0.0, phiFixed = 0.0, phiDynamic = 0.0;
            tree_.accumulate<Potential>(x[2 * i], x[2 * i + 1], std::uint32_t(i), ax, ay, &phiFixed, &phiDynamic);
            acc[2 * i] = ax;
            acc[2 * i + 1] = ay;
            if constexpr (Potential) energy -= mass[i] * (phiFixed + (isAttractor[i] ? 0.5 : 1.0) * phiDynamic);
        }
        return energy;
    }
    // Exact: the same per-point code the field probe uses, minus gravity
    // (the gravity system has already written it).
    for (std::size_t i = 0; i < n; ++i) {
        double phiFixed = 0.0, phiDynamic = 0.0;
        Vec2 f = exactField<Potential>(x[2 * i], x[2 * i + 1], std::uint32_t(i), x, &phiFixed, &phiDynamic);
        if (gravityOn) {
            f.x -= gx;
            f.y -= gy;
        }
        acc[2 * i] = f.x;
        acc[2 * i + 1] = f.y;
        if constexpr (Potential) energy -= mass[i] * (phiFixed + (isAttractor[i] ? 0.5 : 1.0) * phiDynamic);
    }
    return energy;
}

void ForceModel::applyAttractors(const double* x, double* a) const {
    const std::size_t m = 2 * n;
    // The accelerations attractorEnergy() kept, when they are for exactly
    // these positions (and this theta): the same bits a new pass gives.
    if (cacheX_.size() != m || cacheTheta_ != theta || std::memcmp(cacheX_.data(), x, m * sizeof(double)) != 0) {
        scratchAcc_.resize(m);
        attractorPass<false>(x, scratchAcc_.data());
        for (std::size_t i = 0; i < m; ++i) a[i] += scratchAcc_[i];
        return;
    }
    for (std::size_t i = 0; i < m; ++i) a[i] += cacheAcc_[i];
}

double ForceModel::attractorEnergy(const double* x) const {
    if (attractors.empty()) return 0.0;
    const std::size_t m = 2 * n;
    cacheAcc_.resize(m);
    const double energy = attractorPass<true>(x, cacheAcc_.data());
    cacheX_.assign(x, x + m);
    cacheTheta_ = theta;
    return energy;
}

} // namespace stepwise::detail
