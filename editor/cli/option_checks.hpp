#pragma once
// CLI11 checks shared by the subcommands' options. Kept apart from
// cli_common.hpp so that only the files that declare options include CLI11:
// its header alone costs about 7 s of compile per file (14.5 s with
// ASan+UBSan), mostly the validator objects every including file constructs.

#include <CLI/CLI.hpp>

namespace stepwise::cli {

/// CLI11 check for a step count: a whole number >= 0. The message names the
/// option and what was expected ("--steps: expected a whole number >= 0,
/// got -5"); CLI::NonNegativeNumber prints all 309 digits of DBL_MAX as
/// the range and calls "abc" a value out of range.
CLI::Validator wholeNumberAtLeastZero();

/// CLI11 check for an output file option: a non-empty name ("--out:
/// expected a file name, got \"\""; unchecked, an empty name gives
/// ": error: ..." with no name at all).
CLI::Validator outputFileName();

/// CLI11 check for --dt: a number of seconds in (0, 10], the documented
/// range of world.dt; subnormal values (1e-320) included. "nan", "inf" and
/// "0" are refused naming the option, without CLI::PositiveNumber's 309
/// digits of DBL_MAX.
CLI::Validator secondsPerStep();

} // namespace stepwise::cli
