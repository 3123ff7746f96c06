#pragma once
// Helpers shared by the subcommands.

#include "stepwise/scene.hpp"

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

namespace stepwise::cli {

/// Loads a level; on failure prints the loader's message to stderr and
/// returns nullopt (the caller exits with kExitBadInput).
std::optional<Scene> loadLevelOrReport(const std::string& path);

/// Prints "stepwise: error: MESSAGE" to stderr.
void reportError(const std::string& message);

/// One-line description of what a scene contains and needs:
/// "12 entities; components: name, position, ...; systems: gravity, springs".
std::string sceneSummary(const Scene& scene);

/// CLI11 check for a step count: a whole number >= 0. The message names the
/// option and what was expected ("--steps: expected a whole number >= 0,
/// got -5"); CLI::NonNegativeNumber printed all 309 digits of DBL_MAX as
/// the range and called "abc" a value out of range.
CLI::Validator wholeNumberAtLeastZero();

} // namespace stepwise::cli
