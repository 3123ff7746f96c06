// The one table of integrator names: the scene format's names (docs/format.md),
// indexed by IntegratorKind, in the order the editor lists them. The loader,
// the schema, the World panel, the CLI's --integrator and the accuracy
// report all read integratorNames(); World maps a name to its strategy with
// integratorKind().

#include "stepwise/integrators.hpp"

#include "integrators/integrator.hpp"

#include <algorithm>
#include <array>

namespace stepwise {

namespace {
constexpr std::array<std::string_view, 9> kNames{
    "explicit_euler",  // IntegratorKind::ExplicitEuler
    "semi_implicit_euler",
    "midpoint",
    "trapezoid",
    "rk4",
    "velocity_verlet",
    "implicit_euler",
    "implicit_midpoint",
    "dopri5",  // IntegratorKind::Dopri5
};
static_assert(kNames.size() == std::size_t(detail::IntegratorKind::Dopri5) + 1,
              "one name per IntegratorKind, in the enum's order");
} // namespace

std::span<const std::string_view> integratorNames() { return kNames; }

bool isIntegratorName(std::string_view name) {
    return std::find(kNames.begin(), kNames.end(), name) != kNames.end();
}

namespace detail {

std::optional<IntegratorKind> integratorKind(std::string_view name) {
    const auto it = std::find(kNames.begin(), kNames.end(), name);
    if (it == kNames.end()) return std::nullopt;
    return IntegratorKind(it - kNames.begin());
}

std::string_view integratorName(IntegratorKind kind) {
    const auto index = std::size_t(kind);
    return index < kNames.size() ? kNames[index] : std::string_view("?");
}

} // namespace detail

} // namespace stepwise
