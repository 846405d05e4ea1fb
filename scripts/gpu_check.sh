#!/usr/bin/env bash
# Runs the OpenCL checks on a machine with a GPU's OpenCL driver, from a checkout of the
# commit that scripts/gpu_bundle.sh packed (the scenes and test data are read from it):
#   1. `unibeam devices` (after writing an ICD file for NVIDIA's driver when none exists);
#   2. the OpenCL tests (kernel against host twin per query, whole renders of both
#      backends, layout probe, program cache, error paths) on the first device listed;
#   3. the default scene rendered with `--backend host` and `--backend opencl`, compared;
#   4. bench_upbp --replay: each estimator's kernel against its host twin on the same records;
#   5. bench_upbp, host twin against the kernels, for each estimator and `upbp`.
# Each step has its own time limit, and its log is written to LOGDIR as it runs.
#
# Usage: scripts/gpu_check.sh ARCHIVE LOGDIR [BENCH_SECONDS] [BENCH_SCENE ...]
set -u
archive=$1
logs=$2
benchSeconds=${3:-240}
shift $(($# < 3 ? $# : 3))
mkdir -p "$logs"
root=$(mktemp -d)
# Python's tarfile where the machine has no xz.
tar -C "$root" -xJf "$archive" 2>/dev/null ||
    python3 -c 'import sys, tarfile; tarfile.open(sys.argv[1]).extractall(sys.argv[2])' "$archive" "$root" ||
    { echo "gpu_check: cannot unpack $archive" >&2; exit 2; }
export LD_LIBRARY_PATH=$root/lib
if ldd "$root/bin/unibeam" 2>&1 | grep -q 'not found'; then
    export LD_LIBRARY_PATH=$root/lib:$root/lib-fallback  # the target's C++ runtime is older
fi
export XDG_CACHE_HOME=$root/cache
src=$(cat "$root/SOURCE_DIR")
if [[ ! -e $src/tests/data && $(pwd -P) != "$src" ]]; then
    mkdir -p "$(dirname "$src")" && ln -sfn "$(pwd -P)" "$src"
fi
step() { echo "== $*" | tee -a "$logs/summary.txt"; }

{
    echo "commit packed: $(cat "$root/COMMIT" 2>/dev/null)  checkout: $(git rev-parse HEAD 2>/dev/null)"
    nvidia-smi -L 2>&1 | head -4
    nvidia-smi --query-gpu=driver_version,clocks.sm,clocks.mem --format=csv 2>&1 | head -3
    echo "cpus: $(nproc), $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
} 2>&1 | tee "$logs/machine.txt"

cnanovdb=$(cat "$root/CNANOVDB_DIR")
[[ -e $cnanovdb/CNanoVDB.h ]] || { mkdir -p "$cnanovdb" && cp "$root/cnanovdb/CNanoVDB.h" "$cnanovdb/"; }

# NVIDIA's OpenCL library, which its container runtimes mount without an ICD file. Where
# it exists, the loader sees it alone (OCL_ICD_VENDORS), so the tests and the benchmark,
# which take the first device listed, run on the GPU; GPU_CHECK_ALL_ICDS=1 keeps the others.
echo "ICD files: $(ls /etc/OpenCL/vendors 2>/dev/null | tr '\n' ' ')" | tee -a "$logs/machine.txt"
lib=$( (ldconfig -p 2>/dev/null | awk '/libnvidia-opencl\.so\.1/ {print $NF; exit}'
    find /usr/local/nvidia /usr/lib /usr/lib64 /lib /usr/local/cuda* /opt -name 'libnvidia-opencl.so*' 2>/dev/null) | head -1)
if [[ -n $lib ]]; then
    mkdir -p "$root/vendors" && echo "$lib" >"$root/vendors/nvidia.icd"
    [[ ${GPU_CHECK_ALL_ICDS:-0} == 1 ]] && cp /etc/OpenCL/vendors/*.icd "$root/vendors/" 2>/dev/null
    export OCL_ICD_VENDORS=$root/vendors
    echo "ICD: $lib (OCL_ICD_VENDORS=$OCL_ICD_VENDORS: $(ls "$root/vendors" | tr '\n' ' '))" | tee -a "$logs/machine.txt"
else
    echo "ICD: no libnvidia-opencl.so.1 found; nvidia libraries present:" | tee -a "$logs/machine.txt"
    (ldconfig -p | grep -i nvidia; ls /usr/local/nvidia/lib* 2>/dev/null) | head -40 | tee -a "$logs/machine.txt"
fi

step devices
timeout 60 "$root/bin/unibeam" devices 2>&1 | tee "$logs/devices.txt"

step tests
(cd "$src" && timeout 240 "$root/bin/unibeam_tests" --gtest_filter='OpenCl*' 2>&1) |
    tee "$logs/tests.txt" | grep -E '^\[  (PASSED|FAILED)|^\[==========\]|FAILED|Failure' | tee -a "$logs/summary.txt"

step render
for b in host opencl; do
    (cd "$src" && timeout 120 "$root/bin/unibeam" render scenes/cornell-smoke.json -a upbp -i 8 \
        --seed 3 --backend $b -o "$root/smoke-$b.exr" 2>&1) | tee "$logs/render-$b.txt" |
        grep -iE 'device|kernel|backend|s/it|per iteration|error' | tee -a "$logs/summary.txt"
done
timeout 60 "$root/bin/unibeam" compare "$root/smoke-opencl.exr" "$root/smoke-host.exr" 2>&1 |
    tee -a "$logs/summary.txt"

step replay
# Each estimator's kernel against its host twin on the same records, alternately (short).
(cd "$src" && timeout "$benchSeconds" "$root/bin/bench_upbp" --runs 1 --replay 5 \
    --radius-of scene --backends opencl --sets upbp "$@" 2>&1) | tee "$logs/replay.txt" |
    grep -E 'replay|s/it' | tee -a "$logs/summary.txt"

step bench
(cd "$src" && timeout "$benchSeconds" "$root/bin/bench_upbp" --runs 3 --radius-of scene \
    --backends host,opencl --sets upbp:pp3d,upbp:pb2d,upbp:bp2d,upbp:bb1d,upbp:surf,upbp "$@" 2>&1) |
    tee "$logs/bench.txt"
step done
