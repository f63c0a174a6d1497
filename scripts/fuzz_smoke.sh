#!/usr/bin/env bash
# CI smoke fuzz: each parser target for a short time (FUZZ_SECONDS, default 10) on its seed
# corpus, two at a time; fails on any crash, hang, leak or sanitizer report. Skipped (exit 0,
# with a line) where clang 14 or libFuzzer is missing. fuzz_scene is left to scripts/fuzz.sh (it needs the whole
# project built with sanitizers: too slow for CI); FUZZ_SCENE=1 adds it.
set -euo pipefail
cd "$(dirname "$0")/.."
export LSAN_OPTIONS="suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0${LSAN_OPTIONS:+:$LSAN_OPTIONS}"
seconds=${FUZZ_SECONDS:-10}
if ! command -v clang++-14 >/dev/null || ! ls /usr/lib/llvm-14/lib/clang/14*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "fuzz_smoke: skipped (no clang++-14 with libFuzzer)"
  exit 0
fi
targets=(fuzz_cl fuzz_apt fuzz_npy fuzz_mesh fuzz_tool)
[ -f app/cli_parse.cpp ] && targets+=(fuzz_cli)  # the CLI parsers, once in their own file
[ "${FUZZ_SCENE:-0}" = 1 ] && targets+=(fuzz_scene)
bash scripts/fuzz_build.sh "${targets[@]}"
# One target: a fresh working corpus (CI runs are independent of earlier ones); prints its line,
# or its log's tail on a finding (exit 1).
smoke_one() {
  local t=$1 scratch
  scratch=$(mktemp -d)
  if ! "build-fuzz/bin/$t" "$scratch" "tests/fuzz/corpus/$t" -max_total_time="$seconds" \
      -timeout=10 -rss_limit_mb=2048 -max_len=8192 -artifact_prefix="$scratch/" \
      -print_final_stats=1 >"$scratch/log" 2>&1; then
    echo "fuzz_smoke: $t FAILED; its log:" >&2
    tail -40 "$scratch/log" >&2
    return 1
  fi
  local runs
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$scratch/log" | grep -o '[0-9]*$' || echo '?')
  echo "fuzz_smoke: $t ok ($runs inputs in ${seconds} s)"
  rm -rf "$scratch"
}
# FUZZ_PARALLEL targets at a time (default: the cores, at most 2: CI's machine has 2).
parallel=${FUZZ_PARALLEL:-$(($(nproc) > 1 ? 2 : 1))}
failed=0
for ((i = 0; i < ${#targets[@]}; i += parallel)); do
  pids=()
  for t in "${targets[@]:i:parallel}"; do
    smoke_one "$t" &
    pids+=($!)
  done
  for pid in "${pids[@]}"; do wait "$pid" || failed=1; done
done
exit "$failed"
