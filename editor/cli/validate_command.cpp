// stepwise validate LEVEL: checks a level file and says what it contains and
// which systems it needs.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "stepwise/world.hpp"

#include <iostream>
#include <memory>

namespace stepwise::cli {

void addValidateCommand(CLI::App& app, int& exitCode) {
    auto level = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("validate", "Check a level file; print a one-line summary or the error");
    cmd->add_option("LEVEL", *level, "Level file (JSON)")->required();
    cmd->callback([level, &exitCode] {
        std::optional<Scene> scene = loadLevelOrReport(*level);
        if (!scene) {
            exitCode = kExitBadInput;
            return;
        }
        std::string summary = *level + ": ok: " + sceneSummary(*scene);
        Result<World> world = World::build(*scene);
        if (world) {
            std::string systems;
            for (std::string_view s : world->activeSystems()) {
                if (!systems.empty()) systems += ", ";
                systems += s;
            }
            summary += "; systems: " + (systems.empty() ? std::string("none") : systems) + "; integrator " +
                       scene->world.integrator;
            std::cout << summary << "\n";
            for (const StiffnessHint& hint : world->stiffnessHints())
                std::cerr << *level << ": warning: " << hint.message() << "\n";
        } else {
            // The file is valid but asks for something this build cannot
            // simulate: say so, without failing validation of the format.
            std::cout << summary << "\n";
            std::cerr << *level << ": warning: cannot be simulated by this build: " << world.error() << "\n";
        }
        exitCode = kExitOk;
    });
}

} // namespace stepwise::cli
