#pragma once
// The speed-against-error report (`stepwise bench accuracy`): every
// integrator, and Boost.Odeint's matching steppers as the peer, on a set of
// problems with analytic or converged reference answers, at several dt.
// Writes accuracy.csv, accuracy.md and a work-precision plot accuracy.png
// (SciML style: error against CPU time per step, log-log, one panel per
// problem, one line per method), plus a panel of the Barnes–Hut force error
// against time for a range of theta, with exact summation as the peer.

#include "stepwise/result.hpp"

#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace stepwise::report {

struct AccuracyOptions {
    bool quick = false;              ///< fewer dt and timing repeats: under a minute
    std::filesystem::path out;       ///< directory, created if missing
};

struct AccuracyRow {
    std::string problem;
    std::string method;              ///< integrator name or odeint_<stepper>
    double dt = 0.0;                 ///< s
    long steps = 0;
    double error = 0.0;              ///< max position error over bodies at the end, m (inf: diverged)
    double secondsPerStep = 0.0;     ///< CPU (wall, single thread) seconds per step; -1: World::step stopped on divergence
    std::string reference;           ///< "analytic" or "rk4 dt=..."
    /// dopri5 rows: world.tolerance (dt is then the frame interval);
    /// Barnes–Hut rows: theta (error is the relative force error and
    /// secondsPerStep the time of one force evaluation). 0 otherwise.
    double parameter = 0.0;
};

/// Runs the report. Progress goes to `log`. Fails when the directory cannot
/// be written (kind Io) or gnuplot fails (kind Environment).
Result<void> runAccuracyReport(const AccuracyOptions& options, std::ostream& log,
                              std::vector<AccuracyRow>* rowsOut = nullptr);

} // namespace stepwise::report
