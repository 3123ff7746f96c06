// libFuzzer target for the level loader: parseScene on any bytes,
// then save -> load -> save on whatever loads (scene_loader_property.hpp).
// A crash, a sanitizer report, a hang or a broken property is a finding: the
// target aborts with the reason on stderr so libFuzzer keeps the input.
//
// Build and run: bash fuzz/run.sh [SECONDS] (clang-14, -DSTEPWISE_FUZZ=ON,
// build-fuzz/). Keep each finding in tests/fuzz/corpus/ and as an exact-message
// test in tests/test_loader_regressions.cpp.

#include "scene_loader_property.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string problem =
        stepwise::fuzz::checkLoaderProperty(std::string_view(reinterpret_cast<const char*>(data), size));
    if (!problem.empty()) {
        std::fprintf(stderr, "FINDING: %s\n", problem.c_str());
        std::abort();
    }
    return 0;
}
