#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/, UNIBEAM_FUZZ=ON, clang with ASan + UBSan) in
# ./build-fuzz and runs each one for a fixed time (docs/fuzzing.md), one after the other.
#   * seeds: made at run time from scenes/ and tests/data/ by scripts/fuzz_corpus.py into
#     build-fuzz/seeds/<target>/; what a run finds is kept in build-fuzz/corpus/<target>/ (so
#     a later run goes on from there);
#   * the minimised inputs of fixed findings, tests/data/fuzz-regressions/<target>/, are
#     replayed first;
#   * a crash, sanitizer report, leak, out-of-memory or hang (-timeout) fails the script; the
#     input is in build-fuzz/artifacts/<target>/, the report in build-fuzz/logs/<target>.log.
# Usage: scripts/fuzz.sh [SECONDS_PER_TARGET]   (default 30)
# Environment: FUZZ_TARGETS (space-separated subset), JOBS (compile jobs, default 2),
#   FUZZ_TIMEOUT (seconds one input may take before it counts as a hang, default 10),
#   FUZZ_SEED (libFuzzer's -seed, default 1: the same inputs in the same order on every run
#   from a fresh corpus, so that what CI's short run finds is found again by the same command;
#   0 draws a new seed per run, for exploratory fuzzing).
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_PER_TARGET="${1:-30}"
JOBS="${JOBS:-2}"
FUZZ_TIMEOUT="${FUZZ_TIMEOUT:-10}"
FUZZ_SEED="${FUZZ_SEED:-1}"
ALL_TARGETS="fuzz_json_scene fuzz_mitsuba_scene fuzz_smallupbp_scene fuzz_vol_grid fuzz_mesh_obj fuzz_mesh_ply fuzz_serialized_mesh fuzz_exr_image fuzz_png_image fuzz_jpeg_image fuzz_stb_image"
TARGETS="${FUZZ_TARGETS:-$ALL_TARGETS}"

# clang and its runtime libraries (libFuzzer, sanitizers) from Debian.
missing=()
for p in clang libclang-rt-dev python3; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "fuzz: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

# -O1 -g1: quick to build, line numbers in reports.
cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DUNIBEAM_FUZZ=ON -DUNIBEAM_BUILD_TESTS=OFF -DUNIBEAM_BUILD_BENCH=OFF >/dev/null
# shellcheck disable=SC2086
ninja -C build-fuzz -j"$JOBS" $TARGETS

python3 scripts/fuzz_corpus.py build-fuzz/seeds

export ASAN_OPTIONS="detect_leaks=1:abort_on_error=0"  # strict_string_checks: see sanitize.sh
export LSAN_OPTIONS="suppressions=$PWD/scripts/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
mkdir -p build-fuzz/logs
failed=()
for t in $TARGETS; do
  bin="build-fuzz/fuzz/$t"
  mkdir -p "build-fuzz/corpus/$t" "build-fuzz/artifacts/$t"
  log="build-fuzz/logs/$t.log"
  : >"$log"
  # Fixed findings first: each must now run cleanly.
  regressions=(tests/data/fuzz-regressions/"$t"/*)
  if [ -e "${regressions[0]}" ]; then
    if ! "$bin" -timeout="$FUZZ_TIMEOUT" -rss_limit_mb=2048 "${regressions[@]}" >>"$log" 2>&1; then
      echo "fuzz: $t: a regression input fails again (see $log)"
      failed+=("$t")
      continue
    fi
  fi
  # Memory: 2 GB for the process and for any one allocation. (The resident-size growth of
  # fuzz_png_image and fuzz_exr_image in earlier runs was libpng and OpenEXR allocating what a
  # chunk or attribute header announced; the readers now check those sizes first,
  # docs/fuzzing.md.)
  rss=2048
  if "$bin" -seed="$FUZZ_SEED" -max_total_time="$SECONDS_PER_TARGET" -timeout="$FUZZ_TIMEOUT" -rss_limit_mb="$rss" \
    -malloc_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="build-fuzz/artifacts/$t/" \
    "build-fuzz/corpus/$t" "build-fuzz/seeds/$t" >>"$log" 2>&1; then
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
    cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1)
    echo "fuzz: $t: ${SECONDS_PER_TARGET} s, ${execs:-?} executions, ${cov:-cov: ?}, no finding"
  else
    echo "fuzz: $t: FINDING (input in build-fuzz/artifacts/$t/):"
    grep -E "ERROR: |SUMMARY: |runtime error|Test unit written" "$log" | head -5 | sed 's/^/  /'
    failed+=("$t")
  fi
done
if [ ${#failed[@]} -gt 0 ]; then
  echo "fuzz: findings in: ${failed[*]}"
  exit 1
fi
echo "fuzz: no findings in $(echo $TARGETS | wc -w) targets"
