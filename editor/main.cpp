// stepwise: one executable, subcommands in the manner of `blender -b` and
// `godot --headless`. Each subcommand lives in editor/cli/.

#include "cli/commands.hpp"
#include "cli/interrupts.hpp"

#include <CLI/CLI.hpp>

#include <exception>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
    using namespace stepwise::cli;
    installInterruptHandlers();
    CLI::App app{"Stepwise: a 2D physics level editor and sandbox", "stepwise"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "stepwise 0.1.0");
    int exitCode = kExitOk;
    addValidateCommand(app, exitCode);
    addRunCommand(app, exitCode);
    addBenchCommand(app, exitCode);
    addRenderCommand(app, exitCode);
    addSchemaCommand(app, exitCode);
    addEditCommand(app, exitCode);
    // CLI11 reports an unknown first word only as "A subcommand is
    // required"; name the word and the choices instead.
    if (argc > 1 && argv[1][0] != '-') {
        std::string known;
        bool found = false;
        for (const CLI::App* sub : app.get_subcommands({})) {
            found = found || sub->get_name() == argv[1];
            known += (known.empty() ? "" : ", ") + sub->get_name();
        }
        if (!found) {
            std::cerr << "stepwise: error: unknown subcommand \"" << argv[1] << "\"; expected one of: " << known
                      << " (see stepwise --help)\n";
            return kExitBadInput;
        }
    }
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
