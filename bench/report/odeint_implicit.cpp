// Compiled as C++17: see odeint_implicit.hpp.

#include "report/odeint_implicit.hpp"
#include "report/cpu_clock.hpp"

#include <boost/numeric/odeint/stepper/implicit_euler.hpp>
#include <boost/numeric/odeint/util/ublas_wrapper.hpp>

#include <chrono>
#include <utility>
#include <vector>

namespace stepwise::report {

double runOdeintImplicitEulerDense(std::size_t m, const double* x0, const double* v0, double dt, long steps,
                                   const AccelerationFn& accel, const JacobianFn& jacobian, double* xOut) {
    namespace ublas = boost::numeric::ublas;
    namespace odeint = boost::numeric::odeint;
    ublas::vector<double> y(2 * m);
    for (std::size_t i = 0; i < m; ++i) {
        y[i] = x0[i];
        y[m + i] = v0[i];
    }
    std::vector<double> xs(m), vs(m), a(m), J(4 * m * m);
    auto split = [&](const ublas::vector<double>& s) {
        for (std::size_t i = 0; i < m; ++i) {
            xs[i] = s[i];
            vs[i] = s[m + i];
        }
    };
    auto deriv = [&](const ublas::vector<double>& s, ublas::vector<double>& dsdt, double) {
        split(s);
        accel(xs.data(), vs.data(), a.data());
        for (std::size_t i = 0; i < m; ++i) {
            dsdt[i] = vs[i];
            dsdt[m + i] = a[i];
        }
    };
    auto jacobi = [&](const ublas::vector<double>& s, ublas::matrix<double>& out, double) {
        split(s);
        std::fill(J.begin(), J.end(), 0.0);
        jacobian(xs.data(), vs.data(), J.data());
        for (std::size_t r = 0; r < 2 * m; ++r)
            for (std::size_t c = 0; c < 2 * m; ++c) out(r, c) = J[r * 2 * m + c];
    };
    odeint::implicit_euler<double> stepper;
    const double seconds = timedFixedSteps(stepper, std::make_pair(deriv, jacobi), y, dt, steps);
    for (std::size_t i = 0; i < m; ++i) xOut[i] = y[i];
    return seconds;
}

} // namespace stepwise::report
