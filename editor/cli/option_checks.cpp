#include "cli/option_checks.hpp"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace stepwise::cli {

CLI::Validator wholeNumberAtLeastZero() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            errno = 0;
            char* end = nullptr;
            const long long value = std::strtoll(text.c_str(), &end, 10);
            if (text.empty() || *end != '\0' || errno == ERANGE || value < 0)
                return "expected a whole number >= 0, got \"" + text + "\"";
            return {};
        },
        "INT>=0");
}

CLI::Validator outputFileName() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            if (text.empty()) return "expected a file name, got \"\"";
            return {};
        },
        "FILE");
}

CLI::Validator secondsPerStep() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            char* end = nullptr;
            const double value = std::strtod(text.c_str(), &end);
            // strtod sets ERANGE for a subnormal result too (1e-320): that
            // is still a number > 0, so only the value decides.
            if (text.empty() || *end != '\0' || !std::isfinite(value) || !(value > 0.0) || value > 10.0)
                return "expected seconds per step, a number in (0, 10], got \"" + text + "\"";
            return {};
        },
        "SECONDS");
}

} // namespace stepwise::cli
