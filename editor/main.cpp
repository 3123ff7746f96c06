// stepwise: one executable, subcommands in the manner of `blender -b` and
// `godot --headless`. Each subcommand lives in editor/cli/.

#include "cli/commands.hpp"

#include <exception>
#include <iostream>

int main(int argc, char** argv) {
    using namespace stepwise::cli;
    CLI::App app{"Stepwise: a 2D physics level editor and sandbox", "stepwise"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "stepwise 0.1.0");
    int exitCode = kExitOk;
    addValidateCommand(app, exitCode);
    addRunCommand(app, exitCode);
    addSchemaCommand(app, exitCode);
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return app.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return app.exit(e);
    } catch (const CLI::ParseError& e) {
        // Bad arguments: CLI11's message names the argument; exit 2.
        app.exit(e);
        return kExitBadInput;
    } catch (const std::exception& e) {
        std::cerr << "stepwise: internal error: " << e.what() << "\n";
        return kExitFailure;
    }
    return exitCode;
}
