#include "stepwise/integrators.hpp"

#include <algorithm>
#include <array>

namespace stepwise {

namespace {
// The scene format's names (docs/format.md) plus implicit_midpoint.
constexpr std::array<std::string_view, 8> kNames{
    "explicit_euler", "semi_implicit_euler", "midpoint",       "trapezoid",
    "rk4",            "velocity_verlet",     "implicit_euler", "implicit_midpoint",
};
} // namespace

std::span<const std::string_view> integratorNames() { return kNames; }

bool isIntegratorName(std::string_view name) {
    return std::find(kNames.begin(), kNames.end(), name) != kNames.end();
}

} // namespace stepwise
