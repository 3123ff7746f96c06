#pragma once
// Helpers shared by the subcommands.

#include "stepwise/scene.hpp"

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

} // namespace stepwise::cli
