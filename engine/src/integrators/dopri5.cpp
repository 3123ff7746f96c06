// dopri5: Dormand–Prince 5(4) (Dormand & Prince, J. Comput. Appl. Math. 6,
// 1980; Hairer, Nørsett & Wanner, Solving ODEs I, II.4-5) with step-size
// control. A call to step() covers one frame of h seconds (dt / substeps)
// with as many internal steps as the error needs.
//
// The state is y = (x, v), y' = (v, a(x, v)). Seven stages, the seventh at
// the new point (FSAL: its acceleration is the first stage of the next
// internal step). The embedded 4th-order solution gives the error estimate
//   err = sqrt(mean_i (e_i / (tol (1 + max(|y0_i|, |y1_i|))))^2)
// over every position and velocity component (Hairer's norm with absolute
// and relative tolerance both `tol`, world.tolerance). A step is accepted
// when err <= 1; the next step is h * clamp(0.9 err^(-1/5), 0.2, 5) (no
// growth right after a rejection).
//
// Frames: the last internal step of a frame is shortened to land exactly
// on the frame's end (the frame's dense output is then the step's own end
// point, no interpolation error). The controller's proposal for the next
// step is kept across frames and is part of the saved state
// (world.adaptive_step), so that a saved and reloaded run continues bit
// for bit. A frame's first acceleration is evaluated afresh: a contact
// solve may have changed the velocities since the last one.

#include "integrators/integrator.hpp"
#include "stepwise/world_fields.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace stepwise::detail {

namespace {

// Butcher tableau. kA[j] are the weights of stages 0..j-1 for stage j.
constexpr double kA21 = 1.0 / 5.0;
constexpr double kA31 = 3.0 / 40.0, kA32 = 9.0 / 40.0;
constexpr double kA41 = 44.0 / 45.0, kA42 = -56.0 / 15.0, kA43 = 32.0 / 9.0;
constexpr double kA51 = 19372.0 / 6561.0, kA52 = -25360.0 / 2187.0, kA53 = 64448.0 / 6561.0, kA54 = -212.0 / 729.0;
constexpr double kA61 = 9017.0 / 3168.0, kA62 = -355.0 / 33.0, kA63 = 46732.0 / 5247.0, kA64 = 49.0 / 176.0,
                 kA65 = -5103.0 / 18656.0;
// 5th-order weights (= stage 7's row).
constexpr double kB1 = 35.0 / 384.0, kB3 = 500.0 / 1113.0, kB4 = 125.0 / 192.0, kB5 = -2187.0 / 6784.0,
                 kB6 = 11.0 / 84.0;
// b - b*: the difference to the embedded 4th-order solution.
constexpr double kE1 = 71.0 / 57600.0, kE3 = -71.0 / 16695.0, kE4 = 71.0 / 1920.0, kE5 = -17253.0 / 339200.0,
                 kE6 = 22.0 / 525.0, kE7 = -1.0 / 40.0;

constexpr double kSafety = 0.9, kMinFactor = 0.2, kMaxFactor = 5.0;
/// A frame needing more internal steps than this is reported as a failure
/// (a tolerance the problem cannot meet in reasonable time).
constexpr long kMaxStepsPerFrame = 1000000;

using Vec = std::vector<double>;

class Dopri5 final : public Integrator {
public:
    explicit Dopri5(std::size_t n) : m_(2 * n), xs_(2 * n), xn_(2 * n) {
        for (Vec& k : vk_) k.assign(2 * n, 0.0);
        for (Vec& k : ak_) k.assign(2 * n, 0.0);
    }

    void setTolerance(double tolerance) override { tol_ = tolerance; }
    double proposedStep() const override { return proposal_; }
    void setProposedStep(double h) override { proposal_ = h; }
    int lastEvaluations() const override { return evaluations_; }
    int lastAcceptedSteps() const override { return accepted_; }
    int lastRejectedSteps() const override { return rejected_; }
    const std::string& lastToleranceFailure() const override { return failure_; }

    void step(const ForceModel& f, const double* x0, const double* v0, double* x1, double* v1, double H) override {
        evaluations_ = accepted_ = rejected_ = 0;
        failure_.clear();
        const std::size_t m = m_;
        std::copy(x0, x0 + m, x1);
        std::copy(v0, v0 + m, v1);
        if (m == 0) return;
        // Stage 1 at the frame's start.
        std::copy(v0, v0 + m, vk_[0].begin());
        f.accelerations(x1, v1, ak_[0].data());
        ++evaluations_;
        double t = 0.0;
        double h = proposal_ > 0.0 ? proposal_ : H;
        bool rejectedLast = false;
        long steps = 0;
        while (t < H) {
            const double remaining = H - t;
            // Shorten the step to land on the frame's end (and do not leave
            // a sliver of less than 1e-10 of the frame for a last step).
            const bool clipped = h >= remaining - 1e-10 * H;
            const double hs = clipped ? remaining : h;
            if (!(hs > kSmallestAdaptiveStep * H) || ++steps > kMaxStepsPerFrame) {
                char text[200];
                std::snprintf(text, sizeof text,
                              "dopri5: cannot meet tolerance %.3g: step size %.3g s after %ld internal steps "
                              "(%.3g s into a %.3g s frame)",
                              tol_, hs, steps, t, H);
                failure_ = text;
                return;
            }
            const double err = attempt(f, x1, v1, hs);
            evaluations_ += 6;
            double factor;
            if (err <= 1.0) {
                factor = err == 0.0 ? kMaxFactor : std::clamp(kSafety * std::pow(err, -0.2), kMinFactor, kMaxFactor);
                if (rejectedLast) factor = std::min(factor, 1.0);
                // Accept: the seventh stage is the new state and the next
                // step's first stage (FSAL).
                std::copy(xn_.begin(), xn_.end(), x1);
                std::copy(vk_[6].begin(), vk_[6].end(), v1);
                std::swap(vk_[0], vk_[6]);
                std::swap(ak_[0], ak_[6]);
                t = clipped ? H : t + hs;
                ++accepted_;
                rejectedLast = false;
                // A step shortened only to land on the frame's end says
                // nothing against the longer step the controller wanted.
                h = (clipped && factor >= 1.0) ? std::max(h, hs * factor) : hs * factor;
            } else {
                // Too large (or not finite: shrink as far as allowed).
                factor = std::isfinite(err) ? std::max(kMinFactor, kSafety * std::pow(err, -0.2)) : kMinFactor;
                h = hs * factor;
                ++rejected_;
                rejectedLast = true;
            }
        }
        // Capped at the frame: a longer proposal is clipped to the frame's
        // end anyway, and while h >= H every attempt is H whatever h is, so
        // the cap changes no step. It keeps the saved adaptive_step within
        // dt, which the loader accepts.
        proposal_ = std::min(h, H);
    }

private:
    // One internal step of hs from (x, v) with stage 1 in vk_[0], ak_[0].
    // Writes the new state into xn_ and vk_[6] (its acceleration into
    // ak_[6]); returns the scaled error norm.
    double attempt(const ForceModel& f, const double* x, const double* v, double hs) {
        const std::size_t m = m_;
        const double* V1 = vk_[0].data();
        const double* A1 = ak_[0].data();
        double* V2 = vk_[1].data();
        double* A2 = ak_[1].data();
        double* V3 = vk_[2].data();
        double* A3 = ak_[2].data();
        double* V4 = vk_[3].data();
        double* A4 = ak_[3].data();
        double* V5 = vk_[4].data();
        double* A5 = ak_[4].data();
        double* V6 = vk_[5].data();
        double* A6 = ak_[5].data();
        double* V7 = vk_[6].data();
        double* A7 = ak_[6].data();
        double* X = xs_.data();
        for (std::size_t i = 0; i < m; ++i) {
            X[i] = x[i] + hs * (kA21 * V1[i]);
            V2[i] = v[i] + hs * (kA21 * A1[i]);
        }
        f.accelerations(X, V2, A2);
        for (std::size_t i = 0; i < m; ++i) {
            X[i] = x[i] + hs * (kA31 * V1[i] + kA32 * V2[i]);
            V3[i] = v[i] + hs * (kA31 * A1[i] + kA32 * A2[i]);
        }
        f.accelerations(X, V3, A3);
        for (std::size_t i = 0; i < m; ++i) {
            X[i] = x[i] + hs * (kA41 * V1[i] + kA42 * V2[i] + kA43 * V3[i]);
            V4[i] = v[i] + hs * (kA41 * A1[i] + kA42 * A2[i] + kA43 * A3[i]);
        }
        f.accelerations(X, V4, A4);
        for (std::size_t i = 0; i < m; ++i) {
            X[i] = x[i] + hs * (kA51 * V1[i] + kA52 * V2[i] + kA53 * V3[i] + kA54 * V4[i]);
            V5[i] = v[i] + hs * (kA51 * A1[i] + kA52 * A2[i] + kA53 * A3[i] + kA54 * A4[i]);
        }
        f.accelerations(X, V5, A5);
        for (std::size_t i = 0; i < m; ++i) {
            X[i] = x[i] + hs * (kA61 * V1[i] + kA62 * V2[i] + kA63 * V3[i] + kA64 * V4[i] + kA65 * V5[i]);
            V6[i] = v[i] + hs * (kA61 * A1[i] + kA62 * A2[i] + kA63 * A3[i] + kA64 * A4[i] + kA65 * A5[i]);
        }
        f.accelerations(X, V6, A6);
        double* XN = xn_.data();
        for (std::size_t i = 0; i < m; ++i) {
            XN[i] = x[i] + hs * (kB1 * V1[i] + kB3 * V3[i] + kB4 * V4[i] + kB5 * V5[i] + kB6 * V6[i]);
            V7[i] = v[i] + hs * (kB1 * A1[i] + kB3 * A3[i] + kB4 * A4[i] + kB5 * A5[i] + kB6 * A6[i]);
        }
        f.accelerations(XN, V7, A7);
        // Error of the embedded pair, scaled per component.
        double sum = 0.0;
        for (std::size_t i = 0; i < m; ++i) {
            const double ex = hs * (kE1 * V1[i] + kE3 * V3[i] + kE4 * V4[i] + kE5 * V5[i] + kE6 * V6[i] + kE7 * V7[i]);
            const double ev = hs * (kE1 * A1[i] + kE3 * A3[i] + kE4 * A4[i] + kE5 * A5[i] + kE6 * A6[i] + kE7 * A7[i]);
            const double sx = tol_ * (1.0 + std::max(std::fabs(x[i]), std::fabs(XN[i])));
            const double sv = tol_ * (1.0 + std::max(std::fabs(v[i]), std::fabs(V7[i])));
            sum += (ex / sx) * (ex / sx) + (ev / sv) * (ev / sv);
        }
        return std::sqrt(sum / double(2 * m));
    }

    std::size_t m_;
    std::array<Vec, 7> vk_, ak_;  ///< stage velocities (x') and accelerations (v')
    Vec xs_, xn_;                 ///< stage position, new position
    double tol_ = 1e-6;
    double proposal_ = 0.0;
    int evaluations_ = 0, accepted_ = 0, rejected_ = 0;
    std::string failure_;
};

} // namespace

std::unique_ptr<Integrator> makeDopri5(const ForceModel& model) { return std::make_unique<Dopri5>(model.n); }

} // namespace stepwise::detail
