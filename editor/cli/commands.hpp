#pragma once
// Each subcommand lives in its own file and registers itself on the app.
// `exitCode` is written by the subcommand's callback.

namespace CLI {
class App;
}
namespace stepwise::ui {
struct EditOptions;
}

namespace stepwise::cli {

/// Process exit codes (README.md, "Exit codes").
enum ExitCode : int {
    kExitOk = 0,
    kExitFailure = 1,    ///< an unexpected internal failure
    kExitBadInput = 2,   ///< bad file, bad argument, unwritable output
    kExitDiverged = 3,   ///< the simulation produced a non-finite value
};

void addValidateCommand(CLI::App& app, int& exitCode);
void addRunCommand(CLI::App& app, int& exitCode);
/// `stepwise bench`: the speed-against-error report (bench/report) and the
/// hard-cases report (bench/hard_cases).
void addBenchCommand(CLI::App& app, int& exitCode);
void addRenderCommand(CLI::App& app, int& exitCode);
void addSchemaCommand(CLI::App& app, int& exitCode);
/// `stepwise edit [LEVEL]`: the editor (SDL2 window, or headless with --script/--screenshot).
void addEditCommand(CLI::App& app, int& exitCode);
/// `stepwise edit` headless (OSMesa): replays --script, then --bench-frames,
/// then writes --screenshot. Returns the process exit code.
int runScripted(const ui::EditOptions& o, int width, int height);

} // namespace stepwise::cli
