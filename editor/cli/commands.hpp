#pragma once
// Each subcommand lives in its own file and registers itself on the app.
// `exitCode` is written by the subcommand's callback.

namespace CLI {
class App;
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
/// `stepwise bench accuracy`: the speed-against-error report (editor/report).
void addBenchCommand(CLI::App& app, int& exitCode);
void addRenderCommand(CLI::App& app, int& exitCode);
void addSchemaCommand(CLI::App& app, int& exitCode);
/// `stepwise edit [LEVEL]`: the editor (SDL2 window, or headless with --script/--screenshot).
void addEditCommand(CLI::App& app, int& exitCode);

} // namespace stepwise::cli
