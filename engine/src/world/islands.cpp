#include "world/islands.hpp"

#include <algorithm>
#include <numeric>

namespace stepwise::detail {

void SleepIslands::resize(std::size_t bodies) {
    timer.assign(bodies, 0.0);
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
            timer[b] = 0.0;
        }
    refresh();
    return true;
}

void SleepIslands::wakeAll() {
    if (sleeping.empty()) return;
    for (const std::uint32_t b : sleeping) {
        island[b] = -1;
        timer[b] = 0.0;
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

bool SleepIslands::advanceTimers(std::span<const double> speed, double dt) {
    if (!enabled) return false;
    bool ready = false;
    for (std::size_t b = 0; b < timer.size(); ++b) {
        if (island[b] >= 0) continue;
        if (restless[b] || !(speed[b] <= velocity)) timer[b] = 0.0;  // NaN speed counts as moving
        else timer[b] += dt;
        ready = ready || timer[b] >= time;
    }
    return ready;
}

std::vector<std::uint32_t> SleepIslands::fallAsleep(std::span<const std::pair<std::uint32_t, std::uint32_t>> edges) {
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
        if (island[b] < 0 && !(timer[b] >= time)) blocked[findRoot(parent, std::uint32_t(b))] = 1;
    for (const std::uint32_t b : touchesSleeper) blocked[findRoot(parent, b)] = 1;
    for (std::size_t b = 0; b < n; ++b) {
        if (island[b] >= 0) continue;
        const std::uint32_t root = findRoot(parent, std::uint32_t(b));
        if (blocked[root]) continue;
        island[b] = std::int32_t(root);
        fell.push_back(std::uint32_t(b));
    }
    if (!fell.empty()) refresh();
    return fell;
}

} // namespace stepwise::detail
