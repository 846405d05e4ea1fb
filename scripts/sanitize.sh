#!/usr/bin/env bash
# AddressSanitizer + UndefinedBehaviorSanitizer build and test run, part of .ci/run.
# Configures ./build-asan (UNIBEAM_SANITIZE=ON, -O1 -g1, every UB finding fatal), builds the CLI
# and the test binary, then runs the tests under the sanitizers with leak checking; any finding
# or failing test exits non-zero. Measured on 2 shared cores (docs/fuzzing.md, "Time in CI"):
# the build from clean 10.8 minutes, the whole suite 12.1 minutes, so CI runs all of it.
#
# Usage: scripts/sanitize.sh [GTEST_FILTER]     (default: every test)
#   scripts/sanitize.sh '-*MitsubaReference*:*Bidir*:*Vpt*:Pt.*:*Upbp*:*Vcm*'  skips renders.
# Environment: JOBS (parallel compile jobs, default 2).
set -euo pipefail
cd "$(dirname "$0")/.."

FILTER="${1:-*}"
JOBS="${JOBS:-2}"

# -O1 -g1: about half the compile time of -O2 -g, still line numbers in every report.
cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DUNIBEAM_SANITIZE=ON \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DCMAKE_CXX_FLAGS="-fno-sanitize-recover=undefined" \
  -DCMAKE_C_FLAGS="-fno-sanitize-recover=undefined" -DUNIBEAM_BUILD_BENCH=OFF
ninja -C build-asan -j"$JOBS" unibeam unibeam_tests

# Leak reports from third-party library internals are suppressed in scripts/lsan.supp (each
# entry says why); a leak in unibeam's own code still fails the run.
# No strict_string_checks: with it ASan's strtol/strtof interceptors take strlen of the whole
# rest of the buffer at every number, which makes the SmallUPBP OBJ parser quadratic (the 8 MB
# mirrorballs.obj took over 5 minutes instead of seconds).
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0:halt_on_error=1"
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
cd build-asan
tests/unibeam_tests --gtest_filter="$FILTER"
