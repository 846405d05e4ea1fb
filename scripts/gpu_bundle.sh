#!/usr/bin/env bash
# Packs the built programs (unibeam, unibeam_tests, bench_upbp) with the shared libraries
# they load, except the C and C++ runtimes, into one archive. The archive lets the OpenCL
# checks run on a machine that has a GPU's OpenCL driver but none of Debian's -dev
# packages (docs/opencl.md, "Running on a GPU's OpenCL driver"); scripts/gpu_check.sh
# unpacks and runs it there, from a checkout of the same commit.
#
# Usage: scripts/gpu_bundle.sh [BUILD_DIR] [ARCHIVE]   (default build, .gpu/unibeam-gpu.tar.xz)
set -euo pipefail
build=${1:-build}
archive=${2:-.gpu/unibeam-gpu.tar.xz}
bins=("$build/unibeam" "$build/tests/unibeam_tests" "$build/bench/bench_upbp")
for b in "${bins[@]}"; do
    [[ -x $b ]] || { echo "gpu_bundle: $b is missing; build first (ninja -C $build)" >&2; exit 2; }
done
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/bin" "$stage/lib" "$stage/lib-fallback"
cp "${bins[@]}" "$stage/bin/"
# Every library ldd resolves; the C runtime and the loader stay the target's own, and the
# C++ runtime goes to lib-fallback, used only where the target's is older than ours.
ldd "${bins[@]}" | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u | while read -r lib; do
    case $(basename "$lib") in
    libc.so.* | libm.so.* | libpthread.so.* | libdl.so.* | librt.so.* | ld-linux*) ;;
    libstdc++.so.* | libgcc_s.so.*) cp -L "$lib" "$stage/lib-fallback/" ;;
    *) cp -L "$lib" "$stage/lib/" ;;
    esac
done
# The tests and the benchmark read scenes through the source folder compiled into them.
src=$(sed -n 's/^CMAKE_HOME_DIRECTORY:INTERNAL=//p' "$build/CMakeCache.txt")
echo "$src" >"$stage/SOURCE_DIR"
# The header test builds kernels/shared/*.h from source, with NanoVDB's C header beside them.
cnanovdb=$(sed -n 's/^UB_CNANOVDB_DIR:PATH=//p' "$build/CMakeCache.txt")
mkdir -p "$stage/cnanovdb" && cp "$cnanovdb/CNanoVDB.h" "$stage/cnanovdb/" && echo "$cnanovdb" >"$stage/CNANOVDB_DIR"
git rev-parse HEAD >"$stage/COMMIT" 2>/dev/null || true
mkdir -p "$(dirname "$archive")"
tar -C "$stage" -cf - . | xz -T0 -6 >"$archive"
echo "gpu_bundle: $archive ($(du -h "$archive" | cut -f1)), built from $src"
