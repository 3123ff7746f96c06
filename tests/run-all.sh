#!/usr/bin/env bash
# The whole test suite from a fresh clone: install what is missing,
# configure, build, run every test. `.ci/run` calls exactly this.
#
# Stages (each timed; the times are printed at the end):
#   release  build/ (Release): every test with ctest
#   asan     build-asan/ (-DSTEPWISE_SANITIZE=ON: AddressSanitizer +
#            UndefinedBehaviorSanitizer, LeakSanitizer included, and assert()
#            on): every test again; any report or failed assert fails the
#            test that caused it
#   fuzz     build-fuzz/ (clang, libFuzzer): 60 s on the level loader and
#            45 s on the whole pipeline (tests/fuzz/run.sh), seeded from
#            levels/ and tests/fuzz/corpus/
# STEPWISE_STAGES="release" (or any subset, space-separated) runs fewer.
# Extra arguments go to both ctest runs, e.g. `-L unit` or `-R Scene`.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
stages=${STEPWISE_STAGES:-release asan fuzz}
jobs=$(nproc)
timings=()
timed() {  # timed NAME COMMAND...: runs it, records the wall time
  local name=$1 start=$SECONDS
  shift
  echo "==== $name"
  "$@"
  timings+=("$(printf '%-22s %5d s' "$name" $((SECONDS - start)))")
}
report() {
  echo "==== stage times"
  printf '  %s\n' "${timings[@]}"
}
trap report EXIT
has() { [[ " $stages " == *" $1 "* ]]; }

timed setup bash tests/setup-debian.sh

if has release; then
  timed release-configure cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
  timed release-build cmake --build build -j "$jobs"
  timed release-ctest ctest --test-dir build --output-on-failure -j "$jobs" "$@"
fi

if has asan; then
  # -O1 -g1: line tables are enough for file:line in sanitizer reports, and
  # against -O2 -g the build is about 40% shorter (313 s against 475 on 2
  # cores) for a test run about a minute longer. No
  # -DNDEBUG: this is the one stage that runs the suite with assert() on,
  # so a broken invariant aborts here instead of passing silently in Release.
  # The benchmarks are not tests, so this stage does not build them, and with
  # Box2D and Google Benchmark hidden from find_package it also proves that a
  # build with -DSTEPWISE_BUILD_BENCH=OFF needs neither.
  timed asan-configure cmake -S . -B build-asan -DSTEPWISE_SANITIZE=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    "-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=-O1 -g1" -DSTEPWISE_BUILD_BENCH=OFF \
    -DCMAKE_DISABLE_FIND_PACKAGE_box2d=ON -DCMAKE_DISABLE_FIND_PACKAGE_benchmark=ON
  timed asan-build cmake --build build-asan -j "$jobs"
  # halt_on_error / abort: a report must fail the test, not scroll past.
  # detect_leaks: LeakSanitizer at exit. The suppressions file lists leaks
  # inside system libraries we cannot fix, each with its reason.
  export ASAN_OPTIONS="halt_on_error=1:abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
  export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
  export LSAN_OPTIONS="suppressions=$root/tests/sanitizer-suppressions/lsan.supp:print_suppressions=0"
  # ctest starts the tests it knows to be long first (its cost data, written
  # by each run); the asan build has none yet, so it borrows the release
  # run's: same test names, and the long ones are long in both. Without it
  # the longest tests start last and run alone at the end.
  if [[ -f build/Testing/Temporary/CTestCostData.txt && ! -f build-asan/Testing/Temporary/CTestCostData.txt ]]; then
    mkdir -p build-asan/Testing/Temporary
    cp build/Testing/Temporary/CTestCostData.txt build-asan/Testing/Temporary/
  fi
  timed asan-ctest ctest --test-dir build-asan --output-on-failure -j "$jobs" --timeout 900 "$@"
  unset ASAN_OPTIONS UBSAN_OPTIONS LSAN_OPTIONS
fi

if has fuzz; then
  timed fuzz-60s bash tests/fuzz/run.sh 60
  timed fuzz-pipeline-45s bash tests/fuzz/run.sh 45 fuzz_pipeline
fi
