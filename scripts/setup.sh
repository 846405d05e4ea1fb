#!/usr/bin/env bash
# Installs the Debian packages unibeam needs (when missing; needs root or sudo),
# then configures and builds a Release build in ./build.
# Usage: scripts/setup.sh [extra cmake args...]
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  build-essential cmake ninja-build pkg-config git
  libembree-dev libtbb-dev libopenexr-dev libpng-dev zlib1g-dev libjpeg62-turbo-dev libstb-dev
  libopenvdb-dev libnanovdb-dev libboost-iostreams-dev
  ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers pocl-opencl-icd clinfo
  nlohmann-json3-dev libcli11-dev libtinyobjloader-dev libpugixml-dev
  libgtest-dev libgmock-dev libbenchmark-dev clang-format
  python3-matplotlib chromium
)

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "setup: installing ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y --no-install-recommends "${missing[@]}"
fi

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release "$@"
cmake --build build
