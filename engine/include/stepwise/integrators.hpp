#pragma once
/// \file integrators.hpp
/// The names of the time integrators a level can choose (`world.integrator`).
/// The strategies themselves are engine internals (src/integrators/).

#include <span>
#include <string_view>

namespace stepwise {

/// Every integrator name, in the order the editor lists them.
std::span<const std::string_view> integratorNames();

/// True when `name` is one of integratorNames().
bool isIntegratorName(std::string_view name);

} // namespace stepwise
