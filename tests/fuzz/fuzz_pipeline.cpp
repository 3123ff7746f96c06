// libFuzzer target for the whole pipeline: load, build the World, step a
// few times, save, load the save (pipeline_property.hpp). A crash, a
// sanitizer report, a hang or a broken property is a finding: the target
// aborts with the reason on stderr so libFuzzer keeps the input.
//
// Build and run: bash tests/fuzz/run.sh [SECONDS] fuzz_pipeline.

#include "pipeline_property.hpp"

#include <cstdint>
#include <cstdio>
#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string problem =
        stepwise::fuzz::checkPipelineProperty(std::string_view(reinterpret_cast<const char*>(data), size));
    if (!problem.empty()) {
        std::fprintf(stderr, "FINDING: %s\n", problem.c_str());
        std::abort();
    }
    return 0;
}
