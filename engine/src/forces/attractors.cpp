// Newtonian attraction with Plummer softening. Body i feels, towards
// attractor a,
//   a_i = G m_a d / (|d|^2 + eps^2)^(3/2),   d = p_a - p_i,
// the gradient of the potential -G m_i m_a / sqrt(|d|^2 + eps^2). Dynamic
// attractors pull each other (n-body); only attractors pull (the scene
// format: "every other dynamic body i feels ... toward this body"), so a plain
// body does not pull an attractor back. Cost O(bodies * attractors).

#include "forces/force_model.hpp"

#include <cmath>

namespace stepwise::detail {

Vec2 ForceModel::fieldAt(double px, double py, std::uint32_t self, const double* x) const {
    Vec2 acc = gravityOn ? Vec2{gx, gy} : Vec2{};
    for (const AttractorData& at : attractors) {
        if (at.body == self && self != kNoBody) continue;
        const double ax = at.body == kNoBody ? at.px : x[2 * at.body];
        const double ay = at.body == kNoBody ? at.py : x[2 * at.body + 1];
        const double dx = ax - px, dy = ay - py;
        const double q = dx * dx + dy * dy + at.eps2;
        // q == 0 only at the centre of an unsoftened attractor: no direction,
        // no force (the probe sits on the singularity).
        if (!(q > 0.0)) continue;
        const double s = at.gm / (q * std::sqrt(q));
        acc.x += s * dx;
        acc.y += s * dy;
    }
    return acc;
}

void ForceModel::applyAttractors(const double* x, double* a) const {
    // The same per-point code the field probe uses, minus gravity (the
    // gravity system has already written it).
    for (std::size_t i = 0; i < n; ++i) {
        Vec2 f = fieldAt(x[2 * i], x[2 * i + 1], std::uint32_t(i), x);
        if (gravityOn) {
            f.x -= gx;
            f.y -= gy;
        }
        a[2 * i] += f.x;
        a[2 * i + 1] += f.y;
    }
}

double ForceModel::attractorEnergy(const double* x) const {
    // Sum over pairs. A pair of two dynamic attractors appears twice (each
    // pulls the other), so each appearance counts half.
    std::vector<char> isAttractor(n, 0);
    for (const AttractorData& at : attractors)
        if (at.body != kNoBody) isAttractor[at.body] = 1;
    double e = 0.0;
    for (const AttractorData& at : attractors) {
        const double ax = at.body == kNoBody ? at.px : x[2 * at.body];
        const double ay = at.body == kNoBody ? at.py : x[2 * at.body + 1];
        for (std::size_t i = 0; i < n; ++i) {
            if (i == at.body) continue;
            const double dx = ax - x[2 * i], dy = ay - x[2 * i + 1];
            const double q = dx * dx + dy * dy + at.eps2;
            if (!(q > 0.0)) continue;
            const double w = (at.body != kNoBody && isAttractor[i]) ? 0.5 : 1.0;
            e -= w * at.gm * mass[i] / std::sqrt(q);
        }
    }
    return e;
}

} // namespace stepwise::detail
