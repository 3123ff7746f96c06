#pragma once
// Helpers shared by the subcommands.

#include "stepwise/result.hpp"
#include "stepwise/scene.hpp"

#include <optional>
#include <string>
#include <vector>

namespace stepwise::cli {

/// Loads a level; on failure prints the loader's message to stderr and
/// returns nullopt (the caller exits with kExitBadInput).
std::optional<Scene> loadLevelOrReport(const std::string& path);

/// Prints "stepwise: error: MESSAGE" to stderr.
void reportError(const std::string& message);

/// One-line description of what a scene contains and needs:
/// "12 entities; components: name, position, ...; systems: gravity, springs".
std::string sceneSummary(const Scene& scene);

/// An output named on the command line: the option and the path.
struct OutputFile {
    std::string option;  ///< "--out", "--trace", ...
    std::string path;
};

/// Everything that can be known about the outputs before any work is done,
/// so that a bad one costs nothing and nothing is written: each can be
/// written (checkWritableTarget), none is one of `inputs` and no two are the
/// same file. Files are compared by identity (device and inode; for a file
/// not yet there, its folder's identity and its name), not by spelling:
/// "t.csv", "./t.csv" and a hard link are the same file. A file that cannot
/// be written fails with kind Io; a clash with the input or another output
/// with kind BadInput, `where` the option.
Result<void> checkOutputs(const std::vector<std::string>& inputs, const std::vector<OutputFile>& outputs);

/// Prints a checkOutputs refusal on stderr: a file that cannot be written as
/// a failed save prints it ("PATH: error: cannot write: REASON", kind Io),
/// an output that clashes with another as "stepwise: error: OPTION: ...".
void reportOutputProblem(const Error& problem);

} // namespace stepwise::cli
