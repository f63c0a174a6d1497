#!/usr/bin/env bash
# Runs on the GPU machine (the `run` tool, carrying .gpu/fp.tar.xz from gpu_bundle.sh): CPU vs CUDA
# correctness, then fieldpath simulate as a process (process.sh) on cases 4-8 with the backend a
# user gets (auto) and with cuda for case 4, and case 6 on 2 cores; tables and logs under $OUT.
# usage: bash bench/zbuffer/gpu_process_run.sh [CASES] [READ_BENCH=1: bench_path_read too]
set -uo pipefail
cases=${1:-4,5,6,7,8}
out=${OUT:-/tmp/out}
tar -C /tmp -xJf .gpu/fp.tar.xz
export LD_LIBRARY_PATH=/tmp/B/lib
B=/tmp/B
W=${W:-/var/tmp/fp-w}  # kept between calls of a warm machine (not under a carried folder)
mkdir -p "$W"
{ nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv; nproc; uname -r; } \
  >"$out/device.txt" 2>&1
cat "$out/device.txt"
# correctness: the CUDA engine against the CPU engine, bit for bit (the suite's CpuVsCuda tests)
timeout 120 "$B/test_zbuffer_cuda" >"$out/cpu_vs_cuda.txt" 2>&1
tail -1 "$out/cpu_vs_cuda.txt"
timeout 400 bash bench/zbuffer/process.sh --bin "$B" --cases "$cases" --backend auto --reps 3 \
  --work "$W" >"$out/process_auto.md" 2>"$out/process_auto.err"
timeout 100 bash bench/zbuffer/process.sh --bin "$B" --cases 4 --backend cuda --reps 3 \
  --work "$W" --no-kernel >"$out/process_cuda4.md" 2>&1
# whole program: CUDA vs CPU heights, bit for bit, as processes
for id in 4 5 6; do
  read -r _ tool region grid _ stock stem < <(grep "^$id " "$W/cases.txt")
  for b in cpu cuda; do
    "$B/fieldpath" --quiet simulate --tool "$tool" --path "$W/$stem.npy" --grid "$grid" \
      --region "$region" --stock "$stock" --backend $b --outputs npy --out "$W/$b-$id" >/dev/null
  done
  cmp -s "$W/cpu-$id/heights.npy" "$W/cuda-$id/heights.npy" && same=yes || same=NO
  echo "case $id: fieldpath --backend cpu heights = --backend cuda heights: $same" | tee -a "$out/cpu_vs_cuda.txt"
done
# the 2-core machine's question on 2 of these cores: reading .cl and .npy of case 6
timeout 120 bash bench/zbuffer/process.sh --bin "$B" --cases 6 --backend auto --reps 3 --work "$W" \
  --taskset 0,1 --no-kernel >"$out/process_2cores.md" 2>&1
if [[ ${2:-0} == 1 ]]; then
  taskset -c 0,1 "$B/bench_path_read" --reps 3 "$W/case6.cl" "$W/case6.npy" >"$out/path_read_2cores.txt" 2>&1
  "$B/bench_path_read" --reps 3 "$W/case7.cl" "$W/case7.npy" >"$out/path_read_16cores.txt" 2>&1
fi
cp "$W/logs/kernel.md" "$W/cases.txt" "$out/" 2>/dev/null
echo "== all cores, --backend auto"; cat "$out/process_auto.md"
echo "== case 4, --backend cuda"; cat "$out/process_cuda4.md"
echo "== 2 cores (taskset 0,1), --backend auto"; cat "$out/process_2cores.md"
