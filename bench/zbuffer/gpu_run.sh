#!/usr/bin/env bash
# One batched call on the GPU machine (device tool): build the Z-buffer only, run the tests
# (CPU vs CUDA bit-identity included), the benchmark, then the tuning variants; everything is
# logged under $OUT and a short table is printed last.
#   bash bench/zbuffer/gpu_run.sh [bench args...]     (default: all cases)
#   VARIANT_CASES=1,3,7 (default below; empty: none) VARIANT_TIMEOUT, BENCH_TIMEOUT in seconds
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
timeout ${BENCH_TIMEOUT:-330} $B/bin/bench_zbuffer "${ARGS[@]}" > "$OUT/bench.md" 2>&1
echo "bench rc=$?"
VC=${VARIANT_CASES-1,2,3,4,5,6,7,R,S,C,Fz}
if [ -n "$VC" ]; then
  timeout ${VARIANT_TIMEOUT:-200} $B/bin/bench_zbuffer --backend cuda --variants --reps ${VARIANT_REPS:-3} \
    --cases "$VC" > "$OUT/variants.md" 2>&1
  echo "variants rc=$?"; cat "$OUT/variants.md"
fi
cat "$OUT/device.txt"
# short table: case | ours ms | peer ms | best published | best/ours | peer/ours
awk -F'|' 'NR>2 && NF>10 {printf "%-28s %9s %11s %22s %8s %8s\n",$2,$6,$7,$8,$9,$10}' "$OUT/bench.md"
