#!/usr/bin/env bash
# Builds fuzz targets (default: all but fuzz_scene, which needs the whole project instrumented)
# in build-fuzz with clang 14, libFuzzer, ASan and UBSan. Usage: scripts/fuzz_build.sh [TARGET...]
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang++-14 >/dev/null; then
  echo "fuzz_build: clang++-14 not found (apt-get install clang-14 libclang-rt-14-dev)" >&2
  exit 3
fi
if [ ! -f build-fuzz/CMakeCache.txt ]; then
  launcher=()
  command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++-14 \
    -DCMAKE_C_COMPILER=clang-14 "${launcher[@]}" -DFIELDPATH_FUZZ=ON -DBUILD_TESTING=OFF \
    -DFIELDPATH_BUILD_BENCH=OFF -DFIELDPATH_WITH_CUDA=OFF >/dev/null
fi
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(fuzz_cl fuzz_apt fuzz_npy fuzz_mesh fuzz_tool)
  [ -f app/cli_parse.cpp ] && targets+=(fuzz_cli)  # the CLI parsers, once in their own file
fi
cmake --build build-fuzz -j"${FIELDPATH_JOBS:-2}" --target "${targets[@]}"
