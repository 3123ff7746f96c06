#include "world/islands.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace stepwise::detail {

void SleepIslands::resize(std::size_t bodies) {
    timer.assign(bodies, 0.0);
    anchor.assign(kAnchorStride * bodies, 0.0);
    anchored.assign(bodies, 0);
    island.assign(bodies, -1);
    asleep.assign(bodies, 0);
    extent.assign(bodies, 0.0);
    restless.assign(bodies, 0);
    sleeping.clear();
}

void SleepIslands::refresh() {
    sleeping.clear();
    for (std::size_t b = 0; b < island.size(); ++b) {
        asleep[b] = island[b] >= 0 ? 1 : 0;
        if (asleep[b]) sleeping.push_back(std::uint32_t(b));
    }
    changed = true;
}

bool SleepIslands::wake(std::uint32_t body) {
    if (body >= island.size() || island[body] < 0) return false;
    const std::int32_t label = island[body];
    // One pass over the sleeping bodies: wakes are rare events (a touch, an
    // edit), and an island has no member list to keep in step.
    for (const std::uint32_t b : sleeping)
        if (island[b] == label) {
            island[b] = -1;
            restart(b);
        }
    refresh();
    return true;
}

void SleepIslands::wakeAll() {
    if (sleeping.empty()) return;
    for (const std::uint32_t b : sleeping) {
        island[b] = -1;
        restart(b);
    }
    refresh();
}


namespace {
std::uint32_t findRoot(std::vector<std::uint32_t>& parent, std::uint32_t b) {
    while (parent[b] != b) {
        parent[b] = parent[parent[b]];  // path halving
        b = parent[b];
    }
    return b;
}
} // namespace

bool SleepIslands::advanceTimers(std::span<const double> speed, const double* x, const double* v,
                                 std::span<const double> angle, double dt,
                                 const std::function<double(std::size_t)>& fieldAccel) {
    if (!enabled) return false;
    bool ready = false;
    const double limit = driftLimit();
    // At least two steps past the window's start as well: with a frame
    // longer than sleep_time (implicit Euler at dt = 100 s), one step's
    // motion is no evidence that a body has come to rest.
    readyAt = std::max(time, 2.0 * dt);
    for (std::size_t b = 0; b < timer.size(); ++b) {
        if (island[b] >= 0) continue;
        if (restless[b] || !(speed[b] <= velocity)) {  // NaN speed counts as moving
            restart(b);
            continue;
        }
        const double* a = &anchor[kAnchorStride * b];
        const double px = x[2 * b], py = x[2 * b + 1], pa = angle[b];
        // The window counts the time between still observations, so one
        // still step never sleeps a body, however long dt is.
        if (anchored[b]) {
            const double drift = std::max(std::hypot(px - a[0], py - a[1]), extent[b] * std::abs(pa - a[2]));
            if (drift <= limit) {
                timer[b] += dt;
                // The acceleration is judged over the window's second half:
                // the first half lets a transient pass (a wake, an
                // integrator switched at rest).
                if (timer[b] < 0.5 * readyAt) {
                    double* av = &anchor[kAnchorStride * b];
                    av[3] = v[2 * b];
                    av[4] = v[2 * b + 1];
                }
                if (timer[b] >= readyAt && speedingUp(b, v, fieldAccel)) {
                    restartHere(b, px, py, pa, &v[2 * b]);
                    continue;
                }
                ready = ready || timer[b] >= readyAt;
                continue;
            }
        }
        restartHere(b, px, py, pa, &v[2 * b]);
    }
    return ready;
}

void SleepIslands::restartHere(std::size_t b, double px, double py, double pa, const double* v) {
    double* a = &anchor[kAnchorStride * b];
    a[0] = px;
    a[1] = py;
    a[2] = pa;
    a[3] = v[0];
    a[4] = v[1];
    anchored[b] = 1;
    timer[b] = 0.0;
}

bool SleepIslands::speedingUp(std::size_t b, const double* v,
                              const std::function<double(std::size_t)>& fieldAccel) const {
    // The mean acceleration over the window's second half: the velocity's
    // change since its middle (anchor[3..4], kept up to then), over about
    // half a window. A resting body's jitter averages out (and a velocity
    // an integrator reports off by a constant, as velocity Verlet's half
    // kick at rest, cancels), while a box on a gentle frictionless slope
    // shows g sin(theta).
    const double T = timer[b] - 0.5 * readyAt;
    if (!(T > 0.0)) return false;
    const double* a0 = &anchor[kAnchorStride * b];
    const double vx = v[2 * b], vy = v[2 * b + 1];
    const double ax = (vx - a0[3]) / T, ay = (vy - a0[4]) / T;
    // Slowing down is coming to rest (friction, drag): only an acceleration
    // along the motion, or from rest, keeps a body from sleeping.
    if (ax * vx + ay * vy < 0.0) return false;
    const double accel = std::hypot(ax, ay);
    if (accel > accelerationLimit()) return true;
    if (!(accel > 0.0)) return false;
    // Under a weak field (a far attractor) every acceleration is small: a
    // body is held only when its net acceleration is small next to the
    // field's pull, as it is for a body resting on the ground.
    return accel > 0.5 * fieldAccel(b);
}

std::vector<std::uint32_t> SleepIslands::fallAsleep(std::span<const std::pair<std::uint32_t, std::uint32_t>> edges,
                                                    const std::function<bool(std::span<const std::uint32_t>)>& couldRest) {
    std::vector<std::uint32_t> fell;
    const std::size_t n = timer.size();
    // Union-find over the awake bodies; the root is always the lowest
    // index, which then labels the island (deterministic, scene order).
    std::vector<std::uint32_t> parent(n);
    std::iota(parent.begin(), parent.end(), 0u);
    std::vector<std::uint32_t> touchesSleeper;  // awake ends of edges into a sleeping island
    for (const auto& [a, b] : edges) {
        if (asleep[a] || asleep[b]) {
            // Only an edit makes such an edge, and it wakes the sleeper; until
            // then the awake side must not take a label of its own.
            touchesSleeper.push_back(asleep[a] ? b : a);
            continue;
        }
        const std::uint32_t ra = findRoot(parent, a), rb = findRoot(parent, b);
        if (ra == rb) continue;
        if (ra < rb) parent[rb] = ra;
        else parent[ra] = rb;
    }
    // An island sleeps when its slowest-to-settle body has waited long enough.
    std::vector<std::uint8_t> blocked(n, 0);
    for (std::size_t b = 0; b < n; ++b)
        if (island[b] < 0 && !(timer[b] >= readyAt)) blocked[findRoot(parent, std::uint32_t(b))] = 1;
    for (const std::uint32_t b : touchesSleeper) blocked[findRoot(parent, b)] = 1;
    // The islands ready to sleep, each one's bodies together (ascending
    // within an island): a counting sort by root.
    std::vector<std::uint32_t> start(n + 1, 0u), members;
    for (std::size_t b = 0; b < n; ++b) parent[b] = findRoot(parent, std::uint32_t(b));
    for (std::size_t b = 0; b < n; ++b)
        if (island[b] < 0 && !blocked[parent[b]]) ++start[parent[b] + 1];
    for (std::size_t r = 0; r < n; ++r) start[r + 1] += start[r];
    members.resize(start[n]);
    std::vector<std::uint32_t> at(start.begin(), start.end() - 1);
    for (std::size_t b = 0; b < n; ++b)
        if (island[b] < 0 && !blocked[parent[b]]) members[at[parent[b]]++] = std::uint32_t(b);
    for (std::size_t root = 0; root < n; ++root) {
        const std::span<const std::uint32_t> bodies(members.data() + start[root], start[root + 1] - start[root]);
        if (bodies.empty()) continue;
        if (!couldRest(bodies)) {
            for (const std::uint32_t b : bodies) restart(b);
            continue;
        }
        for (const std::uint32_t b : bodies) {
            island[b] = std::int32_t(root);
            fell.push_back(b);
        }
    }
    std::sort(fell.begin(), fell.end());
    if (!fell.empty()) refresh();
    return fell;
}

} // namespace stepwise::detail
