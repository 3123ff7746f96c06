#pragma once
// Boost.Odeint's implicit_euler needs uBLAS, which does not compile as
// C++20 in Boost 1.74 (std::allocator::construct is gone). This wrapper is
// compiled as C++17 in its own object library and sees only plain arrays.

#include <cstddef>
#include <functional>

namespace stepwise::report {

/// a(x, v) into `a` (m doubles each).
using AccelerationFn = std::function<void(const double* x, const double* v, double* a)>;
/// Dense Jacobian of y' = [v; a(x, v)] at y = [x; v]: (2m)^2 doubles,
/// row-major, zeroed by the caller.
using JacobianFn = std::function<void(const double* x, const double* v, double* J)>;

/// Runs `steps` steps of odeint::implicit_euler<double>; writes the final
/// positions to xOut (m doubles) and returns the wall seconds of the loop.
double runOdeintImplicitEulerDense(std::size_t m, const double* x0, const double* v0, double dt, long steps,
                                   const AccelerationFn& accel, const JacobianFn& jacobian, double* xOut);

} // namespace stepwise::report
