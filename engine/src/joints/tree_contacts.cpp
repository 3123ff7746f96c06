// Contacts solved with an exactly solved joint group. See tree_contacts.hpp.

#include "joints/tree_contacts.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace stepwise::joints {

using collision::ContactConstraint;
using collision::ContactPoint;
using collision::PointTarget;
using collision::Softness;
using collision::SolverBody;

namespace {

/// Sets of up to this many normal rows are solved by active sets (the last
/// pass's first, then every one: 2^n small solves at most); larger ones,
/// and any set no active set fits, by projected Gauss-Seidel sweeps, until
/// no impulse moves by more than kSweepTolerance of the largest.
constexpr int kEnumeratedRows = 4;
/// Rows an active set may hold (the last pass's, tried first at any size).
constexpr int kActiveRows = 8;
constexpr int kSweeps = 100;
constexpr double kSweepTolerance = 1e-9;
/// Rounds of normal then friction solves a pass (fewer once a round leaves
/// every impulse within kSweepTolerance), and friction sweeps a round.
constexpr int kRounds = 4;
constexpr double kRoundTolerance = 1e-3;
constexpr int kFrictionSweeps = 8;
/// Riders lighter than this share of the group's body they touch are left
/// to the ordinary contacts (their ghost velocity stays well under one
/// substep of gravity there).
constexpr double kLightestRider = 0.25;
/// Rows (two a point) a group solves with its contacts in each pass.
constexpr std::uint32_t kRowsPerGroup = 16;

/// Solves K_SS y_S = -q_S for the rows S in `mask` (y zero elsewhere) by
/// Gaussian elimination with partial pivoting; false when a pivot vanishes
/// against the largest diagonal entry (dependent rows).
bool solveActive(int n, const double* k, const double* q, unsigned mask, double* y) {
    int rows[kActiveRows];
    int m = 0;
    for (int r = 0; r < n; ++r)
        if (mask & (1u << r)) rows[m++] = r;
    double a[kActiveRows][kActiveRows + 1];
    double largest = 0.0;
    for (int i = 0; i < m; ++i) {
        for (int j = 0; j < m; ++j) a[i][j] = k[rows[i] * n + rows[j]];
        a[i][m] = -q[rows[i]];
        largest = std::max(largest, std::abs(a[i][i]));
    }
    for (int col = 0; col < m; ++col) {
        int pivot = col;
        for (int i = col + 1; i < m; ++i)
            if (std::abs(a[i][col]) > std::abs(a[pivot][col])) pivot = i;
        if (!(std::abs(a[pivot][col]) > 1e-12 * largest)) return false;
        for (int j = 0; j <= m; ++j) std::swap(a[col][j], a[pivot][j]);
        for (int i = col + 1; i < m; ++i) {
            const double f = a[i][col] / a[col][col];
            for (int j = col; j <= m; ++j) a[i][j] -= f * a[col][j];
        }
    }
    for (int i = 0; i < n; ++i) y[i] = 0.0;
    for (int i = m - 1; i >= 0; --i) {
        double sum = a[i][m];
        for (int j = i + 1; j < m; ++j) sum -= a[i][j] * y[rows[j]];
        y[rows[i]] = sum / a[i][i];
    }
    return true;
}

/// Whether the active set `mask` solves the problem below: its rows push
/// (y >= 0) and the others do not approach (w >= 0, to rounding).
bool activeSetFits(int n, const double* k, const double* q, unsigned mask, double* y) {
    if (!solveActive(n, k, q, mask, y)) return false;
    double scale = 0.0;
    for (int i = 0; i < n; ++i) scale = std::max(scale, std::abs(q[i]));
    for (int i = 0; i < n; ++i) {
        if (mask & (1u << i)) {
            if (!(y[i] >= 0.0)) return false;
            continue;
        }
        double w = q[i];
        for (int j = 0; j < n; ++j) w += k[i * n + j] * y[j];
        if (!(w >= -1e-10 * scale)) return false;
    }
    return true;
}

/// Projected Gauss-Seidel sweeps on y (clamped to [lower, upper] row by
/// row) until no value moves by more than kSweepTolerance of the largest,
/// or `sweeps` sweeps.
void sweep(int n, const double* k, const double* q, const double* lower, const double* upper, double* y,
           int sweeps) {
    for (int s = 0; s < sweeps; ++s) {
        double moved = 0.0, largest = 0.0;
        for (int i = 0; i < n; ++i) {
            double w = q[i];
            for (int j = 0; j < n; ++j) w += k[i * n + j] * y[j];
            const double next = std::clamp(y[i] - w / k[i * n + i], lower[i], upper[i]);
            moved = std::max(moved, std::abs(next - y[i]));
            largest = std::max(largest, std::abs(next));
            y[i] = next;
        }
        if (moved <= kSweepTolerance * largest) return;
    }
}

/// The n x n linear complementarity problem y >= 0, w = K y + q >= 0,
/// y_i w_i = 0 (K symmetric positive definite, so its solution is unique),
/// from `start` (the impulses so far; `lower` and `upper` scratch, n each).
void solveComplementarity(int n, const double* k, const double* q, const double* start, double* lower,
                          double* upper, double* y) {
    if (n <= kActiveRows) {
        unsigned last = 0;
        for (int i = 0; i < n; ++i)
            if (start[i] > 0.0) last |= 1u << i;
        if (activeSetFits(n, k, q, last, y)) return;
        if (n <= kEnumeratedRows)
            // Every point pushing first: a body at rest on its contacts.
            for (unsigned mask = (1u << n) - 1u;; --mask) {
                if (mask != last && activeSetFits(n, k, q, mask, y)) return;
                if (mask == 0) break;
            }
    }
    for (int i = 0; i < n; ++i) {
        y[i] = std::max(start[i], 0.0);
        lower[i] = 0.0;
        upper[i] = std::numeric_limits<double>::infinity();
    }
    sweep(n, k, q, lower, upper, y, kSweeps);
}

} // namespace

bool TreeContacts::select(std::span<const ContactConstraint> contacts, const DirectJoints& direct,
                          std::span<const SolverBody> bodies, std::span<const std::uint8_t> inCrowd,
                          std::vector<std::uint8_t>& heldOut) {
    list_.clear();
    sets_.clear();
    responseFactor_ = ~std::uint64_t(0);
    heldOut.assign(contacts.size(), 0);
    const auto crowded = [&](std::uint32_t b) { return b < inCrowd.size() && inCrowd[b] != 0; };
    const auto looseOf = [&](const ContactConstraint& c) {
        return direct.groupOf(c.bodyA) >= 0 ? c.bodyB : c.bodyA;
    };
    const auto groupOf = [&](const ContactConstraint& c) {
        return std::max(direct.groupOf(c.bodyA), direct.groupOf(c.bodyB));
    };
    std::vector<std::uint32_t>& picked = scratch_;
    picked.clear();
    for (std::uint32_t k = 0; k < contacts.size(); ++k) {
        const ContactConstraint& c = contacts[k];
        const bool groupA = direct.groupOf(c.bodyA) >= 0, groupB = direct.groupOf(c.bodyB) >= 0;
        if (groupA == groupB) continue;  // neither in a group, or both (two groups, or one group's own bodies)
        const std::uint32_t loose = looseOf(c), member = groupA ? c.bodyA : c.bodyB;
        if (loose == 0 || !(bodies[loose].invMass > 0.0)) continue;  // static or kinematic: nothing rides
        if (crowded(c.bodyA) || crowded(c.bodyB)) continue;  // a crowd's contacts take its push-out rule
        // A light rider's weight reaches the pins in the ordinary passes.
        if (bodies[member].invMass < kLightestRider * bodies[loose].invMass) continue;
        picked.push_back(k);
    }
    // Sets: one loose body against one group, its contacts in their order.
    std::stable_sort(picked.begin(), picked.end(), [&](std::uint32_t x, std::uint32_t y) {
        const int gx = groupOf(contacts[x]), gy = groupOf(contacts[y]);
        if (gx != gy) return gx < gy;
        return looseOf(contacts[x]) < looseOf(contacts[y]);
    });
    struct Candidate {
        std::uint32_t first, last, rows;
        double mass;  // the loose body's, kg
    };
    std::vector<Candidate> candidates;
    for (std::uint32_t at = 0; at < picked.size();) {
        const ContactConstraint& c = contacts[picked[at]];
        Candidate candidate{at, at, 0, 1.0 / bodies[looseOf(c)].invMass};
        while (candidate.last < picked.size() && groupOf(contacts[picked[candidate.last]]) == groupOf(c) &&
               looseOf(contacts[picked[candidate.last]]) == looseOf(c))
            candidate.rows += 2 * std::uint32_t(contacts[picked[candidate.last++]].pointCount);
        candidates.push_back(candidate);
        at = candidate.last;
    }
    // Each group takes its heaviest riders' sets, up to kRowsPerGroup rows:
    // every row costs a solve of the whole group in each pass, and the
    // heaviest riders are the ones the ordinary passes hold worst.
    std::vector<std::uint32_t> order(candidates.size());
    std::iota(order.begin(), order.end(), 0u);
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t x, std::uint32_t y) {
        const int gx = groupOf(contacts[picked[candidates[x].first]]), gy = groupOf(contacts[picked[candidates[y].first]]);
        if (gx != gy) return gx < gy;
        return candidates[x].mass > candidates[y].mass;
    });
    std::vector<std::uint8_t> taken(candidates.size(), 0);
    int group = -1;
    std::uint32_t rows = 0;
    for (const std::uint32_t i : order) {
        const int g = groupOf(contacts[picked[candidates[i].first]]);
        if (g != group) {
            group = g;
            rows = 0;
        }
        if (rows + candidates[i].rows > kRowsPerGroup) continue;
        rows += candidates[i].rows;
        taken[i] = 1;
    }
    std::size_t responseAt = 0;
    for (std::size_t i = 0; i < candidates.size(); ++i) {
        if (!taken[i]) continue;
        const ContactConstraint& c = contacts[picked[candidates[i].first]];
        Set set{std::uint32_t(list_.size()), 0, groupOf(c), looseOf(c), responseAt};
        for (std::uint32_t at = candidates[i].first; at < candidates[i].last; ++at) {
            list_.push_back(picked[at]);
            heldOut[picked[at]] = 1;
        }
        set.last = std::uint32_t(list_.size());
        responseAt += candidates[i].rows * direct.responseSize(set.group);
        sets_.push_back(set);
    }
    responses_.resize(responseAt);
    return !list_.empty();
}

void TreeContacts::warmStart(std::span<ContactConstraint> contacts, std::span<SolverBody> bodies) const {
    collision::warmStart(contacts, list_, bodies);
}

void TreeContacts::solve(std::span<ContactConstraint> contacts, std::span<JointConstraint> joints,
                         std::span<SolverBody> bodies, DirectJoints& direct, double h, const Softness& soft,
                         const Softness& staticSoft, double pushMaxVelocity, bool useBias, bool reverse) {
    // The responses hold until the groups are factored again.
    const bool respond = responseFactor_ != direct.factorCount();
    responseFactor_ = direct.factorCount();
    const std::size_t count = sets_.size();
    for (std::size_t q = 0; q < count; ++q) {
        const Set& set = sets_[reverse ? count - 1 - q : q];
        if (direct.factored(set.group)) {
            solveSet(set, contacts, joints, bodies, direct, 1.0 / h, soft, staticSoft, pushMaxVelocity, useBias,
                     respond);
        } else {
            // Not solved exactly in this pass: ordinary contacts.
            const std::span<const std::uint32_t> own(list_.data() + set.first, set.last - set.first);
            collision::solveContacts(contacts, own, bodies, h, soft, staticSoft, pushMaxVelocity, useBias, false);
        }
    }
}

void TreeContacts::solveSet(const Set& set, std::span<ContactConstraint> contacts, std::span<JointConstraint> joints,
                            std::span<SolverBody> bodies, DirectJoints& direct, double invH, const Softness& soft,
                            const Softness& staticSoft, double pushMaxVelocity, bool useBias, bool respond) {
    rows_.clear();
    for (int friction = 0; friction < 2; ++friction)
        for (std::uint32_t at = set.first; at < set.last; ++at) {
            const std::uint32_t k = list_[at];
            const ContactConstraint& c = contacts[k];
            const bool memberIsB = direct.groupOf(c.bodyB) >= 0;
            const Vec2 n = c.normal, t{n.y, -n.x};  // t as the ordinary contact's: cross(r, t) = -dot(r, n)
            for (int i = 0; i < c.pointCount; ++i) {
                const ContactPoint& p = c.points[i];
                Row row{k, i, memberIsB ? c.bodyB : c.bodyA, friction ? t : n,
                        friction ? -p.dnA : p.rnA, friction ? -p.dnB : p.rnB, memberIsB ? 1.0 : -1.0};
                rows_.push_back(row);
            }
        }
    const int rowCount = int(rows_.size()), normals = rowCount / 2;
    const std::size_t size = direct.responseSize(set.group);
    double* const responses = responses_.data() + set.responseAt;
    const auto response = [&](int r) { return std::span<double>(responses + std::size_t(r) * size, size); };
    const auto memberArm = [](const Row& r) { return r.memberSign > 0.0 ? r.armB : r.armA; };
    const auto looseArm = [](const Row& r) { return r.memberSign > 0.0 ? r.armA : r.armB; };
    if (respond)
        for (int r = 0; r < rowCount; ++r)
            direct.respond(set.group, rows_[std::size_t(r)].member, rows_[std::size_t(r)].dir,
                           memberArm(rows_[std::size_t(r)]), bodies, response(r));
    SolverBody& loose = bodies[set.loose];
    // Row r's change of speed per unit impulse of row s: through the loose
    // body, and through the group answering at r's member. Each side
    // enters r's speed with the sign with which it takes r's impulse.
    const auto coupling = [&](int r, int s) {
        const Row& x = rows_[std::size_t(r)];
        const Row& y = rows_[std::size_t(s)];
        const double* m = response(s).data() + 3 * direct.placeOf(x.member);
        const double viaLoose =
            loose.invMass * dot(x.dir, y.dir) + loose.invInertia * looseArm(x) * looseArm(y);
        const double viaGroup = dot(x.dir, Vec2{m[0], m[1]}) + memberArm(x) * m[2];
        return x.memberSign * y.memberSign * (viaLoose + viaGroup);
    };
    const auto speed = [&](int r) {
        const Row& x = rows_[std::size_t(r)];
        const ContactConstraint& c = contacts[x.contact];
        const SolverBody& a = bodies[c.bodyA];
        const SolverBody& b = bodies[c.bodyB];
        return dot(b.v - a.v, x.dir) + b.w * x.armB - a.w * x.armA;
    };
    const auto apply = [&](int r, double j) {
        const Row& x = rows_[std::size_t(r)];
        const double toLoose = -x.memberSign * j;
        loose.v += (loose.invMass * toLoose) * x.dir;
        loose.w += loose.invInertia * looseArm(x) * toLoose;
        direct.applyResponse(set.group, response(r), x.memberSign * j, joints, bodies);
    };
    const auto pointOf = [&](int r) -> ContactPoint& {
        const Row& x = rows_[std::size_t(r)];
        return contacts[x.contact].points[x.point];
    };

    // The points' targets, from the velocities the set's solve starts from.
    targets_.clear();
    bool together = true;  // one softness for every normal row: solved as one block
    for (int r = 0; r < normals; ++r) {
        const Row& x = rows_[std::size_t(r)];
        const ContactConstraint& c = contacts[x.contact];
        targets_.push_back(collision::pointTarget(
            collision::currentSeparation(bodies[c.bodyA], bodies[c.bodyB], c, c.points[x.point]),
            [&] { return speed(r); }, c.touchesStatic ? staticSoft : soft, invH, pushMaxVelocity, useBias));
        together = together && targets_.back().massScale == targets_.front().massScale;
    }
    // The couplings among the normal rows and among the friction rows
    // (symmetric but for rounding: one value for both halves), then the
    // right-hand sides and solutions.
    const std::size_t n = std::size_t(normals), m = std::size_t(rowCount - normals);
    const std::size_t most = std::max(n, m);
    matrix_.resize(n * n + m * m + 5 * most);
    double* const kn = matrix_.data();
    double* const kf = kn + n * n;
    double* const q = kf + m * m;
    double* const start = q + most;
    double* const y = start + most;
    double* const lower = y + most;
    double* const upper = lower + most;
    const auto fill = [&](double* k, std::size_t size, int first) {
        for (std::size_t r = 0; r < size; ++r)
            for (std::size_t c = 0; c < size; ++c) k[r * size + c] = coupling(first + int(r), first + int(c));
        for (std::size_t r = 0; r < size; ++r)
            for (std::size_t c = r + 1; c < size; ++c) k[r * size + c] = k[c * size + r] = 0.5 * (k[r * size + c] + k[c * size + r]);
    };
    fill(kn, n, 0);
    fill(kf, m, normals);
    double roundChange = 0.0, roundLargest = 0.0;
    const auto setTotal = [&](int r, double& impulse, double total) {
        const double change = total - impulse;
        impulse = total;
        roundChange = std::max(roundChange, std::abs(change));
        roundLargest = std::max(roundLargest, std::abs(total));
        if (change != 0.0) apply(r, change);
    };
    // Normal rows as one complementarity problem (the block rule of
    // contact_solver.hpp: new = massScale * y), else one at a time.
    const auto solveNormals = [&] {
        if (together) {
            const double massScale = targets_.front().massScale;
            for (std::size_t r = 0; r < n; ++r) {
                double sum = speed(int(r)) + targets_[r].bias;
                for (std::size_t c = 0; c < n; ++c) sum -= kn[r * n + c] * pointOf(int(c)).normalImpulse;
                q[r] = sum;
                start[r] = pointOf(int(r)).normalImpulse / massScale;
            }
            solveComplementarity(normals, kn, q, start, lower, upper, y);
            for (int r = 0; r < normals; ++r) setTotal(r, pointOf(r).normalImpulse, massScale * y[r]);
            return;
        }
        for (int r = 0; r < normals; ++r) {
            ContactPoint& p = pointOf(r);
            const PointTarget& t = targets_[std::size_t(r)];
            const double impulse =
                -(t.massScale / kn[std::size_t(r) * (n + 1)]) * (speed(r) + t.bias) - t.impulseScale * p.normalImpulse;
            setTotal(r, p.normalImpulse, std::max(p.normalImpulse + impulse, 0.0));
        }
    };
    // Friction rows by projected sweeps, each within its point's clamp.
    const auto solveFriction = [&] {
        for (std::size_t r = 0; r < m; ++r) {
            const ContactPoint& p = pointOf(normals + int(r));
            double sum = speed(normals + int(r));
            for (std::size_t c = 0; c < m; ++c) sum -= kf[r * m + c] * pointOf(normals + int(c)).tangentImpulse;
            q[r] = sum;  // the speed is q + K x
            y[r] = p.tangentImpulse;
        }
        for (std::size_t r = 0; r < m; ++r) {
            upper[r] = contacts[rows_[normals + r].contact].friction * pointOf(normals + int(r)).normalImpulse;
            lower[r] = -upper[r];
        }
        sweep(int(m), kf, q, lower, upper, y, kFrictionSweeps);
        for (std::size_t r = 0; r < m; ++r) setTotal(normals + int(r), pointOf(normals + int(r)).tangentImpulse, y[r]);
    };
    // Rounds of both: friction on a tilted plank changes the normal speeds,
    // and the normal impulses bound the friction.
    for (int round = 0; round < kRounds; ++round) {
        roundChange = roundLargest = 0.0;
        solveNormals();
        solveFriction();
        if (roundChange <= kRoundTolerance * roundLargest) break;
    }
}

} // namespace stepwise::joints
