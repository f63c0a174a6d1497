#!/bin/bash
# The CUDA backends verified at a commit on the GPU machine: their tests (the Z-buffer's CUDA
# tests, the voxel build's), then the commands as a user runs them, CPU against CUDA on the mesh
# example's field path: `check` (the surface check's Z-buffer in its local frame) and `simulate`
# (heights bit for bit), with their times. CI has no GPU: this is where the CUDA code is run.
#   here:  bench/field/gpu_bundle.sh build .gpu            (fieldpath, test_field, test_zbuffer_cuda)
#          bench/zbuffer/gpu_verify.sh --job OUT .gpu      (the mesh example's part and path, here)
#   there: bench/zbuffer/gpu_verify.sh .gpu OUTDIR         (run(carry: [.gpu]))
set -u
if [ "${1:-}" = "--job" ]; then  # here: the job's files into .gpu/job (the machine has no numpy)
  out=$2 gpu=$3
  rm -rf "$gpu/job" && mkdir -p "$gpu/job"
  cp "$out/part/scene.yaml" "$out/part/hub.stl" "$out/part/blades.stl" "$out/part/nominal.cl" \
    "$gpu/job/"
  cp "$out/field/path.cl" "$gpu/job/path.cl"
  exit 0
fi
gpu=$1 out=${2:-/tmp/gpu_out}
mkdir -p "$out"
tar -C /tmp -xJf "$gpu/fp.tar.xz"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath job=$gpu/job
device=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader)
echo "device: $device, $(nproc) cores, $(date -u +%FT%TZ)" | tee "$out/device.txt"
timeout 300 /tmp/B/test_zbuffer_cuda > "$out/test_zbuffer_cuda.log" 2>&1
zb=$(grep -E "^\[  (PASSED|FAILED|SKIPPED) " "$out/test_zbuffer_cuda.log" | tr '\n' ' ')
timeout 300 /tmp/B/test_field --gtest_filter='VoxelBuild.*' > "$out/test_field.log" 2>&1
vb=$(grep -E "^\[  (PASSED|FAILED|SKIPPED) " "$out/test_field.log" | tr '\n' ' ')
for b in cpu cuda; do
  for rep in 1 2 3; do
    rm -rf /tmp/chk_$b /tmp/sim_$b
    /usr/bin/time -f "%e" -o /tmp/t_chk_${b}_$rep timeout 120 "$fp" --quiet check \
      "$job/scene.yaml" --path "$job/path.cl" --backend $b --out /tmp/chk_$b > "$out/check_$b.txt" 2>&1
    /usr/bin/time -f "%e" -o /tmp/t_sim_${b}_$rep timeout 120 "$fp" --quiet simulate --tool ball:3:40 \
      --path "$job/path.cl" --part "$job/hub.stl" --grid 4096x4096 --backend $b --out /tmp/sim_$b \
      > "$out/simulate_$b.txt" 2>&1
  done
  cp /tmp/chk_$b/check.json "$out/check_$b.json"
  cp /tmp/sim_$b/simulate.json "$out/simulate_$b.json"
done
median() { sort -n "$@" | sed -n 2p; }
same() { cmp -s "$1" "$2" && echo "identical" || echo "DIFFER"; }
figures() {
  python3 -c "import json,sys; s=json.load(open(sys.argv[1]))['surface']; \
print('scallop %.2f um, gouge %.2f um, band %d lines, backend %s' % (s['max_scallop_um'], \
s['max_gouge_um'], s['band_lines'], s['backend']))" "$1" 2>&1
}
{
  echo "== fieldpath on the GPU machine: $device"
  echo "test_zbuffer_cuda: $zb"
  echo "test_field VoxelBuild.*: $vb"
  echo "check (mesh example field path), cpu:  $(figures "$out/check_cpu.json")"
  echo "check (mesh example field path), cuda: $(figures "$out/check_cuda.json")"
  echo "check deviation.npy cpu vs cuda: $(same /tmp/chk_cpu/deviation.npy /tmp/chk_cuda/deviation.npy)"
  echo "simulate 4096x4096 heights.npy cpu vs cuda: $(same /tmp/sim_cpu/heights.npy /tmp/sim_cuda/heights.npy)"
  echo "| command (wall s, median of 3) | cpu | cuda |"
  echo "| --- | ---: | ---: |"
  echo "| check | $(median /tmp/t_chk_cpu_*) | $(median /tmp/t_chk_cuda_*) |"
  echo "| simulate 4096x4096 --part | $(median /tmp/t_sim_cpu_*) | $(median /tmp/t_sim_cuda_*) |"
} | tee "$out/summary.md"
