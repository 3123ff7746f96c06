// stepwise bench accuracy [--quick] --out DIR: the speed-against-error
// report (bench/accuracy): accuracy.csv, accuracy.md and the work-precision
// plot accuracy.png.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "accuracy/accuracy.hpp"

#include <iostream>
#include <memory>

namespace stepwise::cli {

void addBenchCommand(CLI::App& app, int& exitCode) {
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks and reports");
    bench->require_subcommand(1);
    auto options = std::make_shared<bench::AccuracyOptions>();
    auto out = std::make_shared<std::string>();
    CLI::App* accuracy = bench->add_subcommand(
        "accuracy", "Speed against error of every integrator (and Boost.Odeint's) on five problems");
    accuracy->add_flag("--quick", options->quick, "Fewer dt and repeats (finishes in under a minute)");
    accuracy->add_option("--out", *out, "Directory for accuracy.csv, accuracy.md and accuracy.png")->required();
    accuracy->callback([options, out, &exitCode] {
        options->out = *out;
        try {
            const std::string problem = bench::runAccuracyReport(*options, std::cerr);
            if (!problem.empty()) {
                reportError(problem);
                exitCode = kExitBadInput;
                return;
            }
        } catch (const std::exception& e) {
            reportError(std::string("bench accuracy: ") + e.what());
            exitCode = kExitFailure;
            return;
        }
        std::cout << "wrote " << (options->out / "accuracy.csv").string() << ", "
                  << (options->out / "accuracy.md").string() << ", " << (options->out / "accuracy.png").string()
                  << "\n";
        exitCode = kExitOk;
    });
}

} // namespace stepwise::cli
