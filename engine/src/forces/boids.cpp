// Boids (Reynolds 1987) as proxy forces: separation, alignment, cohesion,
// goal seeking and a soft speed limit. Every steering term is made
// dimensionless and multiplied by its weight (m/s^2):
//   separation  sum over neighbours closer than r_s of unit(p_i - p_j) (1 - d/r_s)
//   alignment   (mean neighbour velocity - v_i) / maxSpeed
//   cohesion    (mean neighbour position - p_i) / neighbourRadius
//   goal        (maxSpeed unit(goal - p_i) - v_i) / maxSpeed
//   speed limit -kBoidSpeedLimitRate (|v| - maxSpeed) v/|v|   when |v| > maxSpeed
// Neighbours come from a uniform hash grid (cell = largest neighbour
// radius): O(n) per evaluation for a flock of bounded density, not O(n^2).

#include "forces/force_model.hpp"

#include <algorithm>
#include <cmath>

namespace stepwise::detail {

namespace {
// Cell coordinate of a coordinate, clamped so huge or non-finite values
// (a diverging run, caught after the step) never overflow the integer.
std::int64_t cellCoord(double value, double cell) {
    double q = std::floor(value / cell);
    if (!(q > -1e15)) q = -1e15;
    if (!(q < 1e15)) q = 1e15;
    return std::int64_t(q);
}
} // namespace

void BoidSystem::prepare() {
    double r = 0.0;
    for (const BoidParams& p : params) r = std::max(r, p.neighborRadius);
    cellSize = r > 0.0 ? r : 1.0;
    std::size_t table = 16;
    while (table < 2 * body.size()) table *= 2;
    mask_ = table - 1;
    bucketStart_.assign(table + 1, 0);
    sorted_.assign(body.size(), 0);
    gather_.clear();
    gather_.reserve(body.size());  // worst case: the whole flock in 9 cells; never reallocates
    bucketOfBoid_.assign(body.size(), 0);
}

std::size_t BoidSystem::bucketOf(double px, double py, int dx, int dy) const {
    const std::uint64_t cx = std::uint64_t(cellCoord(px, cellSize) + dx);
    const std::uint64_t cy = std::uint64_t(cellCoord(py, cellSize) + dy);
    // Spatial hash (Teschner et al. 2003 primes); collisions only add
    // candidates that fail the distance test.
    return std::size_t((cx * 73856093ull) ^ (cy * 19349663ull)) & mask_;
}

void BoidSystem::steer(std::size_t i, const double* x, const double* v, double* a,
                       const std::uint32_t* candidates, std::size_t count) const {
    const BoidParams& p = params[i];
    const std::size_t bi = 2 * std::size_t(body[i]);
    const double px = x[bi], py = x[bi + 1], vx = v[bi], vy = v[bi + 1];
    double sepX = 0, sepY = 0, sumPX = 0, sumPY = 0, sumVX = 0, sumVY = 0;
    std::size_t neighbours = 0;
    for (std::size_t c = 0; c < count; ++c) {
        const std::uint32_t j = candidates[c];
        if (j == i) continue;
        const std::size_t bj = 2 * std::size_t(body[j]);
        const double dx = x[bj] - px, dy = x[bj + 1] - py;
        const double d2 = dx * dx + dy * dy;
        if (!(d2 < p.neighborRadius2)) continue;
        ++neighbours;
        sumPX += x[bj];
        sumPY += x[bj + 1];
        sumVX += v[bj];
        sumVY += v[bj + 1];
        const double d = std::sqrt(d2);
        if (d < p.separationRadius && d > 1e-12) {
            const double w = (1.0 - d / p.separationRadius) / d;
            sepX -= w * dx;
            sepY -= w * dy;
        }
    }
    double ax = p.separation * sepX, ay = p.separation * sepY;
    if (neighbours) {
        const double inv = 1.0 / double(neighbours);
        ax += p.alignment * (sumVX * inv - vx) / p.maxSpeed;
        ay += p.alignment * (sumVY * inv - vy) / p.maxSpeed;
        ax += p.cohesion * (sumPX * inv - px) / p.neighborRadius;
        ay += p.cohesion * (sumPY * inv - py) / p.neighborRadius;
    }
    if (p.goalWeight > 0.0) {
        const double gx = p.goalX - px, gy = p.goalY - py;
        const double gl = std::sqrt(gx * gx + gy * gy);
        const double desiredX = gl > 1e-12 ? p.maxSpeed * gx / gl : 0.0;
        const double desiredY = gl > 1e-12 ? p.maxSpeed * gy / gl : 0.0;
        ax += p.goalWeight * (desiredX - vx) / p.maxSpeed;
        ay += p.goalWeight * (desiredY - vy) / p.maxSpeed;
    }
    const double speed = std::sqrt(vx * vx + vy * vy);
    if (speed > p.maxSpeed) {
        const double s = kBoidSpeedLimitRate * (speed - p.maxSpeed) / speed;
        ax -= s * vx;
        ay -= s * vy;
    }
    a[bi] += ax;
    a[bi + 1] += ay;
}

void BoidSystem::accumulate(const double* x, const double* v, double* a) const {
    const std::size_t nb = body.size();
    // Counting sort of the boids by bucket.
    std::fill(bucketStart_.begin(), bucketStart_.end(), 0u);
    for (std::size_t i = 0; i < nb; ++i) {
        const std::size_t b = bucketOf(x[2 * body[i]], x[2 * body[i] + 1], 0, 0);
        bucketOfBoid_[i] = std::uint32_t(b);
        ++bucketStart_[b + 1];
    }
    for (std::size_t b = 1; b < bucketStart_.size(); ++b) bucketStart_[b] += bucketStart_[b - 1];
    // Fill from the bucket end downwards, so the order inside a bucket is
    // the boid order: deterministic, and the same every run.
    std::vector<std::uint32_t>& sorted = sorted_;
    {
        // bucketStart_[b+1] is the end of bucket b; walk the boids backwards
        // decrementing it as a cursor.
        for (std::size_t i = nb; i-- > 0;) {
            const std::size_t b = bucketOfBoid_[i];
            sorted[--bucketStart_[b + 1]] = std::uint32_t(i);
        }
        // bucketStart_[b+1] now holds the start of bucket b; shift back.
        for (std::size_t b = 0; b + 1 < bucketStart_.size(); ++b) bucketStart_[b] = bucketStart_[b + 1];
        bucketStart_.back() = std::uint32_t(nb);
    }
    for (std::size_t i = 0; i < nb; ++i) {
        const double px = x[2 * body[i]], py = x[2 * body[i] + 1];
        std::size_t seen[9];
        std::size_t seenCount = 0;
        // Steer once over the 3x3 neighbourhood; a bucket met twice (hash
        // collision between neighbouring cells) is visited once.
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const std::size_t b = bucketOf(px, py, dx, dy);
                if (std::find(seen, seen + seenCount, b) != seen + seenCount) continue;
                seen[seenCount++] = b;
            }
        gather_.clear();
        for (std::size_t s = 0; s < seenCount; ++s)
            for (std::uint32_t k = bucketStart_[seen[s]]; k < bucketStart_[seen[s] + 1]; ++k)
                gather_.push_back(sorted[k]);
        steer(i, x, v, a, gather_.data(), gather_.size());
    }
}

void BoidSystem::accumulateBruteForce(const double* x, const double* v, double* a) const {
    std::vector<std::uint32_t> all(body.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = std::uint32_t(i);
    for (std::size_t i = 0; i < body.size(); ++i) steer(i, x, v, a, all.data(), all.size());
}

} // namespace stepwise::detail
