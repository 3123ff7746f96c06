// stepwise bench accuracy [--quick] --out DIR: the speed-against-error
// report (editor/report): accuracy.csv, accuracy.md and the work-precision
// plot accuracy.png.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "report/accuracy.hpp"

#include <CLI/CLI.hpp>

#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

namespace stepwise::cli {

void addBenchCommand(CLI::App& app, int& exitCode) {
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks and reports");
    // Not require_subcommand(1): CLI11 then says only "A subcommand is
    // required" for `bench frob`. A positional catches the unknown word so
    // the message can name it (main.cpp does the same one level up).
    auto unknown = std::make_shared<std::string>();
    bench->add_option("REPORT", *unknown, "The report to run: accuracy");
    bench->callback([bench, unknown, &exitCode] {
        if (bench->got_subcommand("accuracy")) return;  // its own callback set exitCode
        if (unknown->empty()) reportError("bench: expected a report to run: accuracy (see stepwise bench --help)");
        else reportError("bench: unknown report \"" + *unknown + "\"; expected one of: accuracy");
        exitCode = kExitBadInput;
    });
    auto options = std::make_shared<report::AccuracyOptions>();
    auto out = std::make_shared<std::string>();
    CLI::App* accuracy = bench->add_subcommand(
        "accuracy", "Speed against error of every integrator (and Boost.Odeint's) on five problems");
    accuracy->add_flag("--quick", options->quick, "Fewer dt and repeats (finishes in under a minute)");
    accuracy->add_option("--out", *out, "Directory for accuracy.csv, accuracy.md and accuracy.png")->required();
    accuracy->callback([options, out, &exitCode] {
        options->out = *out;
        // Checked before minutes of measuring, and named as the argument.
        std::error_code ec;
        std::filesystem::create_directories(options->out, ec);
        if (ec || !std::filesystem::is_directory(options->out, ec)) {
            // An existing file of that name is ENOTDIR ("Not a directory").
            reportError("--out: cannot create the folder " + *out + ": " +
                        (ec ? ec.message() : std::string("not a directory")));
            exitCode = kExitBadInput;
            return;
        }
        // Each file the report replaces, also before measuring: a read-only
        // accuracy.md is refused now, not after the run.
        std::vector<OutputFile> outputs;
        for (const char* name : {"accuracy.csv", "accuracy.md", "accuracy.png"})
            outputs.push_back({"--out", (options->out / name).string()});
        if (std::string problem = checkOutputs({}, outputs); !problem.empty()) {
            std::cerr << problem << "\n";
            exitCode = kExitBadInput;
            return;
        }
        try {
            const std::string problem = report::runAccuracyReport(*options, std::cerr);
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
