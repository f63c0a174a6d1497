#!/usr/bin/env bash
# Where the time goes (device tool): build the Z-buffer only, then run the chosen cases once each
# with FIELDPATH_ZB_TRACE=1 (device time per stage, lines visited / lowered, host stages).
#   bash bench/zbuffer/gpu_trace.sh 1,2,4,5,8 [extra bench args]
set -uo pipefail
OUT=${OUT:-/tmp/zbuffer-gpu}
mkdir -p "$OUT"
B=/tmp/zb-build
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader > "$OUT/device.txt" 2>&1
cmake -S . -B $B -DFIELDPATH_ZBUFFER_ONLY=ON -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_BUILD_TYPE=Release \
  > "$OUT/build.txt" 2>&1 && cmake --build $B -j16 >> "$OUT/build.txt" 2>&1 || { tail -40 "$OUT/build.txt"; exit 1; }
CASES=${1:-1,2,4,5,8}
shift || true
FIELDPATH_ZB_TRACE=1 timeout ${TRACE_TIMEOUT:-300} $B/bin/bench_zbuffer --backend cuda --reps 2 --peer-limit 1 \
  --no-exact --cases "$CASES" "$@" > "$OUT/trace.md" 2> "$OUT/trace.txt"
echo "trace rc=$?"
cat "$OUT/device.txt"
grep -v "^|---" "$OUT/trace.md" | cut -d'|' -f2,6 
cat "$OUT/trace.txt"
