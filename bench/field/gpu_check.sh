#!/bin/bash
# A short check of the voxel builds on the GPU machine after a change of the node rules: the
# build tests (CUDA against the CPU block build, the block build against the reference), then
# `field build` cpu and cuda, 3 runs each, on the example uniform and refined 0.5 % and the
# study's scene refined 0.5 %, and generate's path.cl CUDA against CPU on the study's scene.
#   here:  bench/field/gpu_bundle.sh build .gpu
#   there: bench/field/gpu_check.sh .gpu/fp.tar.xz OUTDIR
set -u
. "$(dirname "$0")/common.sh"
out=${2:-/tmp/gpu_out}
mkdir -p "$out"
tar -C /tmp -xJf "$1"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
nvidia-smi --query-gpu=name --format=csv,noheader
echo "cores $(nproc)"
timeout 200 /tmp/B/test_field --gtest_filter='VoxelBuild.*:Voxel.*' 2>&1 |
  grep -E "OK|FAILED|PASSED|SKIPPED|Failure|Expected|actual" | tee "$out/tests.log"
ex_u=$(scene ex_u 1.0 0) ex_r=$(scene ex_r 1.0 0.005) st_r=$(scene st_r 0.5 0.005)
for c in "$ex_u" "$ex_r" "$st_r"; do
  for rep in 1 2 3; do
    for b in cpu cuda; do
      echo -n "== $(basename "$c") $b rep $rep: "
      timeout 120 "$fp" --quiet field build "$c" --backend $b --voxel 0.5 --out /tmp/f_$b.vdb 2>&1 |
        grep -E "active|time|start-up" | tr '\n' ' '
      echo
    done
  done
done 2>&1 | tee "$out/builds.log"
for b in cpu cuda; do
  timeout 120 "$fp" --quiet generate "$st_r" --backend $b --out /tmp/g_$b > /dev/null 2>&1
done
echo -n "path.cl cuda vs cpu (study scene refined 0.5 %): "
python3 "$(dirname "$0")/compare_cl.py" /tmp/g_cpu/path.cl /tmp/g_cuda/path.cl | tail -1
remove_scenes
