#include "stepwise/integrators.hpp"

#include <algorithm>
#include <array>

namespace stepwise {

namespace {
// The scene format's names (docs/format.md), in the editor's order.
constexpr std::array<std::string_view, 9> kNames{
    "explicit_euler", "semi_implicit_euler", "midpoint",          "trapezoid", "rk4",
    "velocity_verlet", "implicit_euler",     "implicit_midpoint", "dopri5",
};
} // namespace

std::span<const std::string_view> integratorNames() { return kNames; }

bool isIntegratorName(std::string_view name) {
    return std::find(kNames.begin(), kNames.end(), name) != kNames.end();
}

} // namespace stepwise
