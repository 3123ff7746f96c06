#pragma once
// Time integrators: interchangeable strategies over one state vector, the
// course notes' takeStep(ParticleSystem*, h). The state is the positions
// x and velocities v of the dynamic bodies (2n doubles each, interleaved
// per body, see forces/force_model.hpp). A step reads (x0, v0) and writes
// (x1, v1) into other buffers, so the world can drop a step that diverged
// without a copy.

#include "forces/force_model.hpp"

#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise::detail {

/// The state check's quick bounds: x * kQuickRangeScale overflows exactly
/// when |x| >= 2^99 (6.3e29, under kMaxMagnitude), and v * kQuickSpeedScale
/// when |v| >= 2^29 (5.4e8, under kMaxSpeed); a power of two scales without
/// rounding. So one multiply turns a finiteness test into a range test. A
/// value the quick test flags is then held against the limits themselves
/// (WorldImpl::findOutOfRange).
inline constexpr double kQuickRangeScale = 0x1p925;
inline constexpr double kQuickSpeedScale = 0x1p995;

enum class IntegratorKind {
    ExplicitEuler,      ///< x1 = x0 + h v0, v1 = v0 + h a(x0, v0)            order 1
    SemiImplicitEuler,  ///< v1 = v0 + h a(x0, v0), x1 = x0 + h v1 (symplectic) order 1
    Midpoint,           ///< RK2 through the half step (notes' Midpoint Method) order 2
    Trapezoid,          ///< Heun: average of Euler and Euler-from-Euler       order 2
    Rk4,                ///< classical Runge-Kutta                             order 4
    VelocityVerlet,     ///< kick-drift-kick (symplectic)                      order 2
    ImplicitEuler,      ///< backward Euler, Newton on v1 (L-stable)           order 1
    ImplicitMidpoint,   ///< implicit midpoint rule (symplectic, A-stable)     order 2
    Dopri5,             ///< Dormand–Prince 5(4), error-controlled internal steps  order 5
};

std::optional<IntegratorKind> integratorKind(std::string_view name);
std::string_view integratorName(IntegratorKind kind);
bool isImplicit(IntegratorKind kind);

/// Why the last step's solve cannot be trusted, and the bodies of the
/// failing system (dynamic body indices).
struct SolveFailure {
    std::string what;
    std::vector<std::size_t> bodies;
};

class Integrator {
public:
    virtual ~Integrator() = default;
    /// One step of h seconds from (x0, v0) into (x1, v1). Inputs are not
    /// changed; outputs never alias inputs. No heap allocation (scratch is
    /// sized at construction), except inside Eigen's sparse factorisation
    /// for the implicit methods.
    virtual void step(const ForceModel& model, const double* x0, const double* v0, double* x1, double* v1,
                      double h) = 0;
    /// Force evaluations in the last step (implicit: Newton iterations + 1).
    virtual int lastEvaluations() const = 0;
    /// True when the last step() itself checked, in its writing pass, that
    /// every value of (x1, v1) is within the quick bounds (so finite and
    /// within a level's ranges). The world then skips its own pass over
    /// the state (at 1e4 bodies that pass cost a third of the step). False
    /// means "not checked", never "out of range": the world checks.
    virtual bool lastStepVerifiedInRange() const { return false; }
    /// Set when the last step's linear solve failed or lost its accuracy
    /// (implicit methods): the world refuses the step as it refuses a
    /// non-finite value, instead of keeping a frozen or wrong state.
    virtual const SolveFailure* lastFailure() const { return nullptr; }

    // Error-controlled methods (dopri5); fixed-step methods keep the defaults.
    /// Local error per internal step (world.tolerance).
    virtual void setTolerance(double) {}
    /// Internal steps accepted and rejected in the last step() (1 and 0 for
    /// a fixed-step method).
    virtual int lastAcceptedSteps() const { return 1; }
    virtual int lastRejectedSteps() const { return 0; }
    /// Not empty when the last step() could not meet its tolerance; the
    /// world then undoes the step and reports this message.
    virtual const std::string& lastToleranceFailure() const {
        static const std::string none;
        return none;
    }
    /// The controller's proposal for the next internal step, s (0: none);
    /// carried across frames and saved (world.adaptive_step).
    virtual double proposedStep() const { return 0.0; }
    virtual void setProposedStep(double) {}
};

/// Instruction sets the streaming kernels (semi-implicit Euler and RK4 with
/// local forces) and the contact solver's bundles (collision/contact_bundles)
/// are compiled for; the best one the CPU has is picked at run time. Every level performs the same IEEE operations per value in
/// the same order, and no FMA (-ffp-contract=off), so results are
/// bit-identical whichever runs.
enum class SimdLevel { Baseline, Avx2, Avx512 };
/// The level in use.
SimdLevel simdLevel();
/// Tests: use `level`, or the best the CPU has if it lacks it. Returns the
/// level now in use (from the next step on, for every world).
SimdLevel setSimdLevel(SimdLevel level);

/// A strategy for `model`'s body count and structure.
std::unique_ptr<Integrator> makeIntegrator(IntegratorKind kind, const ForceModel& model);

/// Largest h*omega at which `kind` is stable on the damped oscillator
/// x'' = -omega^2 x - 2 zeta omega x' (spectral radius of the one-step
/// amplification matrix <= 1), found numerically from the method's own
/// update formulas. Undamped: explicit Euler, midpoint and trapezoid 0
/// (they spiral out at any dt), semi-implicit Euler and Verlet 2, RK4
/// 2*sqrt(2). Implicit methods: +infinity (A-stable).
double stabilityLimit(IntegratorKind kind, double zeta);

/// Newton tolerance of the implicit solvers: stop when the update is below
/// this fraction of the velocity scale.
inline constexpr double kNewtonRelativeTolerance = 1e-13;
inline constexpr int kNewtonMaxIterations = 30;
/// A linear solve of the implicit methods is refused when its residual
/// |A dv - rhs| exceeds this fraction of |rhs| (infinity norms). A
/// backward-stable solve leaves about eps * cond(A) of |rhs|, so this
/// passes systems up to cond(A) ~ 1e10 (dt*sqrt(k/m) up to ~1e5).
inline constexpr double kSolveRelativeResidual = 1e-6;
/// dt*sqrt(k/m) past which `validate` warns for the implicit methods:
/// cond(A) ~ (dt*sqrt(k/m))^2 reaches 1e10.
inline constexpr double kImplicitConditioningLimit = 1e5;

std::unique_ptr<Integrator> makeImplicitIntegrator(bool midpointRule, const ForceModel& model);
std::unique_ptr<Integrator> makeDopri5(const ForceModel& model);

} // namespace stepwise::detail
