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

} // namespace stepwise::report
