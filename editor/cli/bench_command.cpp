// stepwise bench accuracy [--quick] --out DIR: the speed-against-error
// report (bench/report): accuracy.csv, accuracy.md and the work-precision
// plot accuracy.png.
// stepwise bench hard-cases [--quick] [--only NAME] [--steps N] --out DIR:
// the hard-cases report, error against ms/step with Box2D 2.4.1 as the peer.
// It is its own program (bench/hard_cases, built beside stepwise) so that the
// editor does not link Box2D; this subcommand checks the arguments and then
// becomes that program.

#include "cli/cli_common.hpp"
#include "cli/commands.hpp"

#include "report/accuracy.hpp"

#include <CLI/CLI.hpp>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <vector>

#include <unistd.h>

namespace stepwise::cli {

namespace {

/// The hard-cases program of this build: bench/hard_cases beside the
/// stepwise executable (the build tree's layout).
std::filesystem::path hardCasesProgram() {
    std::error_code ec;
    const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
    return (ec ? std::filesystem::path(".") : self.parent_path()) / "bench" / "hard_cases";
}

struct HardCasesOptions {
    bool quick = false;
    std::string out, only;
    int steps = 0;
};

void addHardCasesCommand(CLI::App& bench, int& exitCode) {
    auto options = std::make_shared<HardCasesOptions>();
    CLI::App* hard = bench.add_subcommand(
        "hard-cases", "Error against ms/step on the hard cases and Box2D's benchmark scenes, Box2D 2.4.1 in the same run");
    hard->add_flag("--quick", options->quick, "A fifth of the steps, without the 10,000-body crowd");
    hard->add_option("--only", options->only, "Only the cases whose name contains this text");
    hard->add_option("--steps", options->steps, "Steps per case instead of each case's own")->check(CLI::Range(1, 1000000));
    hard->add_option("--out", options->out, "Existing folder for hard_cases.md, hard_cases.csv and hard_cases.png")
        ->required();
    hard->callback([options, &exitCode] {
        std::error_code ec;
        if (!std::filesystem::is_directory(options->out, ec)) {
            reportError("--out: " + options->out + " is not an existing folder");
            exitCode = kExitBadInput;
            return;
        }
        std::vector<OutputFile> outputs;
        for (const char* name : {"hard_cases.csv", "hard_cases.md", "hard_cases.png"})
            outputs.push_back({"--out", (std::filesystem::path(options->out) / name).string()});
        if (Result<void> checked = checkOutputs({}, outputs); !checked) {
            reportOutputProblem(checked.failure());
            exitCode = kExitBadInput;
            return;
        }
        const std::string program = hardCasesProgram().string();
        std::vector<std::string> args{program, "--out", options->out};
        if (options->quick) args.push_back("--quick");
        if (!options->only.empty()) args.insert(args.end(), {"--only", options->only});
        if (options->steps > 0) args.insert(args.end(), {"--steps", std::to_string(options->steps)});
        std::vector<char*> argv;
        for (std::string& a : args) argv.push_back(a.data());
        argv.push_back(nullptr);
        std::cout.flush();
        ::execv(program.c_str(), argv.data());
        // Only reached when the program could not be started.
        reportError("bench hard-cases: cannot start " + program + ": " + std::strerror(errno) +
                    " (build it with: cmake --build build --target hard_cases)");
        exitCode = kExitFailure;
    });
}

} // namespace

void addBenchCommand(CLI::App& app, int& exitCode) {
    CLI::App* bench = app.add_subcommand("bench", "Benchmarks and reports");
    // Not require_subcommand(1): CLI11 then says only "A subcommand is
    // required" for `bench frob`. A positional catches the unknown word so
    // the message can name it (main.cpp does the same one level up).
    auto unknown = std::make_shared<std::string>();
    bench->add_option("REPORT", *unknown, "The report to run: accuracy or hard-cases");
    bench->callback([bench, unknown, &exitCode] {
        // Each report's own callback set exitCode.
        if (bench->got_subcommand("accuracy") || bench->got_subcommand("hard-cases")) return;
        if (unknown->empty())
            reportError("bench: expected a report to run: accuracy or hard-cases (see stepwise bench --help)");
        else reportError("bench: unknown report \"" + *unknown + "\"; expected one of: accuracy, hard-cases");
        exitCode = kExitBadInput;
    });
    auto options = std::make_shared<report::AccuracyOptions>();
    auto out = std::make_shared<std::string>();
    CLI::App* accuracy = bench->add_subcommand(
        "accuracy", "Speed against error of every integrator (and Boost.Odeint's) on five problems");
    accuracy->add_flag("--quick", options->quick, "Fewer dt and repeats (finishes in under a minute)");
    accuracy->add_option("--out", *out, "Existing folder for accuracy.csv, accuracy.md and accuracy.png")->required();
    accuracy->callback([options, out, &exitCode] {
        options->out = *out;
        // Checked before minutes of measuring, and named as the argument.
        // Like every other output, the folder must exist.
        std::error_code ec;
        if (!std::filesystem::is_directory(options->out, ec)) {
            reportError("--out: " + *out + " is not an existing folder");
            exitCode = kExitBadInput;
            return;
        }
        // Each file the report replaces, also before measuring: a read-only
        // accuracy.md is refused now, not after the run.
        std::vector<OutputFile> outputs;
        for (const char* name : {"accuracy.csv", "accuracy.md", "accuracy.png"})
            outputs.push_back({"--out", (options->out / name).string()});
        if (Result<void> checked = checkOutputs({}, outputs); !checked) {
            reportOutputProblem(checked.failure());
            exitCode = kExitBadInput;
            return;
        }
        try {
            if (Result<void> ran = report::runAccuracyReport(*options, std::cerr); !ran) {
                reportError(ran.error());
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
    addHardCasesCommand(*bench, exitCode);
}

} // namespace stepwise::cli
