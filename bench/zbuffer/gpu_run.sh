#!/usr/bin/env bash
# One batched call on the GPU machine (device tool): build the Z-buffer only, run the tests
# (CPU vs CUDA bit-identity included), then the benchmark; everything is logged under $OUT.
#   bash bench/zbuffer/gpu_run.sh [bench args...]     (default: all cases)
set -uo pipefail
OUT=${OUT:-/tmp/zbuffer-gpu}
mkdir -p "$OUT"
B=/tmp/zb-build
{
  nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
  nproc
  date -u
} > "$OUT/device.txt" 2>&1
cmake -S . -B $B -DFIELDPATH_ZBUFFER_ONLY=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_BUILD_TYPE=Release \
  > "$OUT/build.txt" 2>&1 && cmake --build $B -j16 >> "$OUT/build.txt" 2>&1 || { tail -40 "$OUT/build.txt"; exit 1; }
$B/bin/test_zbuffer_cuda > "$OUT/test_cuda.txt" 2>&1; echo "test_zbuffer_cuda rc=$?"
grep -E "OK|FAILED|SKIPPED|Failure|differ" "$OUT/test_cuda.txt" | head -20
$B/bin/test_zbuffer > "$OUT/test_cpu.txt" 2>&1; echo "test_zbuffer rc=$?"; tail -1 "$OUT/test_cpu.txt"
ARGS=("$@")
[ ${#ARGS[@]} -eq 0 ] && ARGS=(--backend cuda --reps 3 --peer-limit 3000000)
timeout ${BENCH_TIMEOUT:-420} $B/bin/bench_zbuffer "${ARGS[@]}" | tee "$OUT/bench.md"
cat "$OUT/device.txt"
