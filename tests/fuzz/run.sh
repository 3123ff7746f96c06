#!/usr/bin/env bash
# Builds a libFuzzer target with clang and runs it.
#   bash tests/fuzz/run.sh [SECONDS] [TARGET]   (default 60 and
#   fuzz_scene_loader; CI runs the loader 60 s and fuzz_pipeline 45 s)
# fuzz_scene_loader: the level loader alone (scene_loader_property.hpp).
# fuzz_pipeline: load, build, step 3 times, save, load the save
# (pipeline_property.hpp); each input must finish in the same 2 s.
# Seeds: every levels/*.json plus tests/fuzz/corpus/ (kept findings and inputs
# worth keeping). New inputs the fuzzer finds go to build-fuzz/corpus/, so
# the repository's corpus only grows by hand. A crash, leak, sanitizer
# report, timeout (2 s: a 64 KiB input loads in milliseconds, so a slower
# one means a path that grows faster than its input) or out-of-memory
# (2 GiB) leaves build-fuzz/crash-* (or timeout-*/oom-*) and makes this
# script exit non-zero; replay one with
#   build-fuzz/tests/fuzz/TARGET build-fuzz/crash-...
# Set FUZZ_EXTRA for more libFuzzer flags (e.g. FUZZ_EXTRA=-jobs=2).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
cd "$root"
seconds=${1:-60}
target=${2:-fuzz_scene_loader}
build=build-fuzz
# -O2 as RelWithDebInfo has it (the executions a second are the point), but
# line tables instead of full debug info: a report's stack still names file
# and line, and the build costs less (world.cpp 16-18 CPU s against 19-24
# with full debug info).
cmake -S . -B "$build" -DSTEPWISE_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O2 -gline-tables-only -DNDEBUG" \
  -DSTEPWISE_BUILD_TESTS=OFF -DSTEPWISE_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" --target "$target" -j "$(nproc)"
mkdir -p "$build/corpus-$target" "$build/seeds"
# Levels up to 64 KiB are seeds as they are; the big benchmark levels
# (pile, rain, cloth: 250-380 KB) would make every execution slow, and their
# structure is in the small ones. -max_len keeps mutations small as well.
find levels -name '*.json' ! -name scene.schema.json -size -65537c -exec cp {} "$build/seeds/" \;
# shellcheck disable=SC2086
exec "$build/tests/fuzz/$target" "$build/corpus-$target" "$build/seeds" tests/fuzz/corpus \
  -dict=tests/fuzz/scene.dict -max_len=65536 -max_total_time="$seconds" -timeout=2 -rss_limit_mb=2048 \
  -artifact_prefix="$build/" -print_final_stats=1 ${FUZZ_EXTRA:-}
