#!/usr/bin/env bash
# Long fuzz run of one target: scripts/fuzz.sh TARGET SECONDS [libFuzzer options...]
#   TARGET: fuzz_cl fuzz_apt fuzz_npy fuzz_mesh fuzz_tool fuzz_cli fuzz_scene
# Builds it with clang 14 + libFuzzer + ASan + UBSan in build-fuzz (FIELDPATH_FUZZ=ON), then runs
# it on its seed corpus tests/fuzz/corpus/TARGET (read only) and a working corpus
# build-fuzz/corpus/TARGET (new inputs go there). Crashes, leaks, timeouts and out-of-memory
# inputs are written to build-fuzz/crashes/TARGET/; make each a unit test with its input.
# Exit status: libFuzzer's (0: no finding). The last lines are libFuzzer's final stats.
set -euo pipefail
cd "$(dirname "$0")/.."
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
target=${1:?usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options]}
seconds=${2:?usage: scripts/fuzz.sh TARGET SECONDS [libFuzzer options]}
shift 2
bash scripts/fuzz_build.sh "$target"
mkdir -p "build-fuzz/corpus/$target" "build-fuzz/crashes/$target"
# -timeout: one input over 10 s is a hang; -rss_limit_mb: over 2 GB is memory exhaustion;
# -max_len: scenes and meshes are small text files.
exec "build-fuzz/bin/$target" "build-fuzz/corpus/$target" "tests/fuzz/corpus/$target" \
  -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
  -artifact_prefix="build-fuzz/crashes/$target/" -print_final_stats=1 "$@"
