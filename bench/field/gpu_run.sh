#!/bin/bash
# The voxel field's builds on the GPU machine (issue 15): the CUDA build against the CPU block
# build and the per-node reference, same run, same scenes. The machine has no OpenVDB: the
# program travels as a bundle (BUILD-NOTES.md "The whole program on the GPU machine"):
#   here:  bench/field/gpu_bundle.sh DIR      (fieldpath + test_field + their libraries, DIR/fp.tar.xz)
#   there: bench/field/gpu_run.sh DIR/fp.tar.xz OUTDIR
set -u
bundle=$1
out=${2:-/tmp/gpu_out}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
nproc
# 1. the CUDA build equals the CPU build (the test skips without a GPU)
/tmp/B/test_field --gtest_filter='VoxelBuild.*' 2>&1 | tail -15
# 2. scenes: the example (blades every 1 mm) and the study's (every 0.5 mm)
sed 's/sample_step: 1.0 /sample_step: 0.5 /' examples/impeller/scene.yaml > /tmp/study_scene.yaml
run() {  # backend, scene, voxel, tolerance
  "$fp" --quiet field build "$2" --backend "$1" --voxel "$3" --refine-tolerance "$4" \
    --out /tmp/f.vdb 2>&1 | grep -E "samples|active|levels|time" | tr '\n' ' '
  echo
}
for rep in 1 2 3; do
  for b in cuda cpu; do
    echo "== $b example 0.5 uniform (rep $rep)"; run $b examples/impeller/scene.yaml 0.5 0
  done
done
for b in cuda cpu reference; do
  echo "== $b example 0.5 refined 0.5 %"; run $b examples/impeller/scene.yaml 0.5 0.005
done
for rep in 1 2; do
  for b in cuda cpu; do
    echo "== $b study 0.5 refined 0.5 % (rep $rep)"; run $b /tmp/study_scene.yaml 0.5 0.005
  done
done
echo "== reference study 0.5 refined 0.5 %"; run reference /tmp/study_scene.yaml 0.5 0.005
# 3. generate end to end: voxel (refined 0.5 mm to 0.5 %) against the indexed direct sum
for mode in "--backend cuda" "--backend cpu" "--direct"; do
  echo "== generate $mode"
  sed 's/refine_tolerance: 0 /refine_tolerance: 0.005 /' /tmp/study_scene.yaml > /tmp/gen_scene.yaml
  d=$out/gen_${mode//[- ]/}
  /usr/bin/time -f "wall %e s" "$fp" --quiet generate /tmp/gen_scene.yaml $mode --out "$d" 2>&1 | tail -2
  python3 -c "import json,sys; r=json.load(open('$d/report.json')); print(r['times_s'], r.get('voxel_nodes'))"
done
# path.cl of the CUDA build against the CPU build's
python3 "$(dirname "$0")/compare_cl.py" "$out/gen_backendcpu/path.cl" "$out/gen_backendcuda/path.cl"
