#pragma once
// Sleeping, Box2D style. An island is a set of dynamic bodies joined by
// touching contacts (a point within the slop or one that carried load; a
// speculative point across a gap does not join), springs and joints; static bodies, planes, anchors and the world do not
// join islands, so two piles on one floor are two islands. Each awake body
// keeps a timer of how long its fastest point has moved slower than
// world.sleep_velocity; an island whose every timer has reached
// world.sleep_time goes to sleep as a whole: its state is frozen as it is
// (velocities included, all under the threshold: a wake resumes it exactly
// where it paused) and, until it wakes, its bodies are not integrated
// (their state is put back after each step), not solved, and neither the broad phase nor the narrow
// phase looks at their pairs with each other or with static shapes (the
// collision system keeps their warm start and contact records aside).
//
// An island wakes as a whole when an awake body comes within reach of one
// of its bodies (a manifold at the gap the two can close in the step plus
// the slop, so it is in the solver before the touch), when an edit or a World setter changes one of
// its bodies, springs or joints, or when the world settings change.
//
// Timers and islands are state: a snapshot (WorldState) and a saved file
// (`solver_state.bodies`) carry them, so resume and step back stay exact.

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <utility>
#include <vector>

namespace stepwise::detail {

/// Doubles per body in SleepIslands::anchor: x, y, angle, vx, vy.
inline constexpr std::size_t kAnchorStride = 5;

struct SleepIslands {
    bool enabled = false;
    double velocity = 0.05;  ///< m/s, world.sleep_velocity
    double time = 0.5;       ///< s, world.sleep_time

    // Per dynamic body (state-vector order).
    std::vector<double> timer;          ///< s spent still since `anchor` (frozen while asleep)
    /// Where the body was when its still window began: x, y (m), angle
    /// (rad), and its velocity x, y (m/s) at the window's middle (the
    /// latest until then), kAnchorStride per body; valid while anchored[b]. A body that drifts
    /// further than driftLimit() from it starts its window again, so a body
    /// gliding slowly through space (or rolling along a floor) never sleeps.
    std::vector<double> anchor;
    std::vector<std::uint8_t> anchored;
    std::vector<std::int32_t> island;   ///< -1 awake; else the island's label, its lowest body index
    std::vector<std::uint8_t> asleep;   ///< 1 while asleep (island >= 0): what the collision system reads
    std::vector<double> extent;         ///< m, the lever arm of the angular speed (farthest point)
    std::vector<std::uint8_t> restless; ///< 1: never sleeps (boids steer; dynamic attractors move the field)

    std::vector<std::uint32_t> sleeping;  ///< bodies asleep, ascending (rebuilt by refresh())
    bool changed = false;                 ///< the sleeping set changed since the collision system last looked
    double readyAt = 0.5;                 ///< s a timer must reach: max(time, 2 dt) (advanceTimers)

    void resize(std::size_t bodies);
    bool anyAsleep() const { return !sleeping.empty(); }
    /// Wakes the whole island of `body` (nothing if it is awake); true if it slept.
    bool wake(std::uint32_t body);
    void wakeAll();
    /// Rebuilds `asleep` and `sleeping` from `island`.
    void refresh();

    /// After a step: the timers of the awake bodies (speed[b] = |v| +
    /// extent |omega|, m/s; read for awake bodies only) advance by dt or
    /// reset. True when some timer reached `time`: then fallAsleep() is due.
    /// `x`, `v`: positions and velocities (x0, y0, x1, ...), `angle`: per
    /// body, rad. `fieldAccel(b)`: the magnitude of the field forces'
    /// acceleration on body b (gravity, attractors), m/s^2, asked only of a
    /// body whose window is long enough to sleep and that still speeds up.
    bool advanceTimers(std::span<const double> speed, const double* x, const double* v, std::span<const double> angle,
                       double dt, const std::function<double(std::size_t)>& fieldAccel);
    /// m/s^2: a still body whose net acceleration over its window (its
    /// velocity's change since the window began over the window's length:
    /// forces and contact impulses together) exceeds this is not at rest, however
    /// slowly it moves yet: a hundredth of sleep_velocity gained per
    /// sleep_time (1 mm/s^2 by default, a frictionless slope of 0.006
    /// degrees; a settled pile's bodies change speed far less).
    double accelerationLimit() const { return 0.01 * velocity / std::max(time, 1e-300); }
    /// m: how far a still body may drift from its anchor, a tenth of what
    /// sleep_velocity covers in sleep_time (2.5 mm by default); a body
    /// creeping slower than a tenth of sleep_velocity may still sleep.
    double driftLimit() const { return 0.1 * velocity * time; }
    /// Forgets body b's still window (it moved, was edited or woke).
    void restart(std::size_t b) {
        timer[b] = 0.0;
        anchored[b] = 0;
    }
    /// Starts body b's still window at position (px, py), angle pa and
    /// velocity `v` (the body's pair).
    void restartHere(std::size_t b, double px, double py, double pa, const double* v);
    /// Whether body b, still for a whole window, still gains speed: its net
    /// acceleration does not balance (see advanceTimers).
    bool speedingUp(std::size_t b, const double* v,
                    const std::function<double(std::size_t)>& fieldAccel) const;
    /// Builds the islands of the awake bodies from `edges` (pairs of
    /// bodies) and puts to sleep every island whose bodies have all been
    /// still for `time`, unless `couldRest(bodies)` (the island's bodies,
    /// ascending) says its forces do not balance: then its timers start
    /// again. Returns the bodies that fell asleep, ascending.
    std::vector<std::uint32_t> fallAsleep(std::span<const std::pair<std::uint32_t, std::uint32_t>> edges,
                                          const std::function<bool(std::span<const std::uint32_t>)>& couldRest);
};

} // namespace stepwise::detail
