#!/usr/bin/env bash
# Installs what is missing (Debian 12 packages only), configures and builds fieldpath in build/.
# Used by scripts/demo.sh and scripts/test.sh; safe to run again (it only installs what is missing).
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(
  build-essential cmake git pkg-config
  libeigen3-dev libopenvdb-dev libboost-iostreams-dev libnanovdb-dev libfcl-dev libassimp-dev
  libsundials-dev libtbb-dev libcli11-dev libyaml-cpp-dev nlohmann-json3-dev zlib1g-dev
  libgtest-dev googletest libbenchmark-dev
  python3-matplotlib python3-numpy
  chromium libjs-three
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  echo "setup: installing ${missing[*]}" >&2
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# CUDA is used when /usr/local/cuda exists (CMake's FIELDPATH_WITH_CUDA=AUTO finds nvcc there).
jobs=$(nproc)
mkdir -p build
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release ${FIELDPATH_CMAKE_ARGS:-} >build/configure.log 2>&1 \
  || { cat build/configure.log >&2; exit 1; }
grep -E "fieldpath: CUDA" build/configure.log >&2 || true
cmake --build build -j"$jobs"
