// stepwise schema [--out FILE]: the level format's JSON Schema, generated
// from the component table.

#include "cli/cli_common.hpp"
#include "cli/option_checks.hpp"
#include "cli/commands.hpp"

#include "stepwise/scene_io.hpp"

#include <iostream>
#include <memory>

namespace stepwise::cli {

void addSchemaCommand(CLI::App& app, int& exitCode) {
    auto out = std::make_shared<std::string>();
    CLI::App* cmd = app.add_subcommand("schema", "Print the level format's JSON Schema (2020-12)");
    cmd->add_option("--out", *out, "Write it to this file (atomic) instead of stdout")->check(outputFileName());
    cmd->callback([out, &exitCode] {
        const std::string schema = sceneJsonSchema();
        if (out->empty()) {
            std::cout << schema;
        } else if (Result<void> written = writeFileAtomically(*out, schema); !written) {
            std::cerr << written.error() << "\n";
            exitCode = kExitBadInput;
            return;
        }
        exitCode = kExitOk;
    });
}

} // namespace stepwise::cli
