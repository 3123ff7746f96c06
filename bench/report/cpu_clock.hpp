#pragma once
// The report's clock: CPU time of the calling thread (CLOCK_THREAD_CPUTIME_ID).
// The machines this runs on are shared; wall time then measures the other
// jobs as much as the method, while a thread's CPU time does not (it still
// includes cache and memory effects of the neighbours).

#include <chrono>
#include <ctime>

namespace stepwise::report {

struct ThreadCpuClock {
    using duration = std::chrono::nanoseconds;
    using rep = duration::rep;
    using period = duration::period;
    using time_point = std::chrono::time_point<ThreadCpuClock>;
    static constexpr bool is_steady = true;
    static time_point now() {
        timespec ts{};
        clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
        return time_point(duration(rep(ts.tv_sec) * 1000000000 + rep(ts.tv_nsec)));
    }
};

/// Takes `steps` fixed odeint steps of `dt` with `stepper` on `system` from
/// t = 0, updating `y`; returns the thread CPU seconds they took. The one
/// timing loop of the report's odeint peers.
template <class Stepper, class System, class State>
double timedFixedSteps(Stepper& stepper, System&& system, State& y, double dt, long steps) {
    const auto t0 = ThreadCpuClock::now();
    double t = 0.0;
    for (long i = 0; i < steps; ++i) {
        stepper.do_step(system, y, t, dt);
        t += dt;
    }
    return std::chrono::duration<double>(ThreadCpuClock::now() - t0).count();
}

} // namespace stepwise::report
