#!/usr/bin/env bash
# The whole test suite under AddressSanitizer + UndefinedBehaviorSanitizer (every report fatal),
# in build-asan (gcc, FIELDPATH_SANITIZE=ON, no CUDA): scripts/sanitize.sh [ctest -R pattern]
# `scripts/sanitize.sh tsan` instead builds build-tsan with ThreadSanitizer and runs the tests of
# the parallel parts where TSan works (the chunked path readers; OpenMP's libgomp is not
# TSan-instrumented, so the Z-buffer's CPU engine would only give false reports).
# Slow: a full instrumented build (≈ 20-30 min on 2 cores); FIELDPATH_JOBS sets -j.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${FIELDPATH_JOBS:-2}
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
if [ "${1:-}" = tsan ]; then
  cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -g" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread" \
    -DFIELDPATH_WITH_CUDA=OFF -DFIELDPATH_BUILD_BENCH=OFF >/dev/null
  cmake --build build-tsan -j"$jobs" --target test_geometry
  # oneTBB is not TSan-instrumented: its own task objects are suppressed (tests/fuzz/tsan.supp).
  TSAN_OPTIONS="halt_on_error=1:suppressions=$PWD/tests/fuzz/tsan.supp" ctest --test-dir build-tsan -R "${2:-ClFile|PathRead|Npy|Apt}" \
    --output-on-failure --timeout 600
  exit
fi
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo "${launcher[@]}" -DFIELDPATH_SANITIZE=ON \
  -DFIELDPATH_WITH_CUDA=OFF -DFIELDPATH_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$jobs"
# detect_leaks: leaks are bugs too; the tests run the built fieldpath, which inherits these.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1
# assimp's own leaks on malformed files (Debian's library, not ours): tests/fuzz/lsan.supp.
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0"
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-asan --output-on-failure -j"$jobs" --timeout 1800 ${1:+-R "$1"}
