#!/bin/bash
# The voxel field's builds on the GPU machine (issue 15): the CUDA build against the CPU block
# build and the build of before the issue (`fieldpath_old`, built from 1512102^ without CUDA),
# same run, same scenes. The machine has no OpenVDB: the program travels as a bundle
# (BUILD-NOTES.md "The whole program on the GPU machine"):
#   here:  OLD=/path/to/old/fieldpath bench/field/gpu_bundle.sh BUILD_DIR DIR   (DIR/fp.tar.xz)
#   there: bench/field/gpu_run.sh DIR/fp.tar.xz OUTDIR [study | study-only | generate-only]
# Prints one line per run: "== case backend rep" then the build's own times ("build X s (B nodes
# Y s, refinement Z s)"; the CUDA start-up, made before the build, printed apart); then
# `generate` end to end (voxel refined to 1 % against the indexed direct sum).
set -u
. "$(dirname "$0")/common.sh"
bundle=$1
out=${2:-/tmp/gpu_out}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
old=/tmp/B/fieldpath_old
here=$(dirname "$0")
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "cores: $(nproc)"
# The study at 16 cores / GPU (study or study-only): reference, cpu and cuda builds side by side,
# uniform and refined 0.5 % and 1 % (the 2-core run: bench/results/study/builds/).
study() {
  timeout 300 "$fp" --quiet study examples/impeller/scene.yaml --sample-step 0.5 --voxels 0.5,0.5 \
    --interp trilinear --stored plane_ratio --refine 0.5,1 --refine-levels 2 \
    --backend reference,cpu,cuda --no-brute-force --line-step 0.2 --out /tmp/study 2>&1 | tail -12
  cp /tmp/study/study.md "$out/study_gpu.md" 2>/dev/null
  cp /tmp/study/study.csv "$out/study_gpu.csv" 2>/dev/null
}
# generate end to end on the study scene (step 3 below), as separate processes
generate_runs() {
  local st_r st_r1
  st_r=$(scene st_r 0.5 0.005) st_r1=$(scene st_r1 0.5 0.01)
  for sc in "$st_r1" "$st_r"; do
    for mode in "--backend cuda" "--backend cpu" "--direct"; do
      for rep in 1 2 3; do
        d=/tmp/gen_${mode//[- ]/}
        echo -n "== generate $(basename "$sc") $mode rep $rep: "
        timeout 120 "$fp" --quiet generate "$sc" $mode --out "$d" >/dev/null 2>&1
        python3 -c "import json; r=json.load(open('$d/report.json')); print(r.get('times_s'))"
      done
    done
    echo -n "path.cl cuda vs cpu: "; python3 "$here/compare_cl.py" /tmp/gen_backendcpu/path.cl /tmp/gen_backendcuda/path.cl
    echo -n "path.cl cpu vs direct: "; python3 "$here/compare_cl.py" /tmp/gen_direct/path.cl /tmp/gen_backendcpu/path.cl
  done
  remove_scenes
}
if [ "${3:-}" = study-only ]; then study; exit 0; fi
if [ "${3:-}" = generate-only ]; then generate_runs; exit 0; fi
# 1. the CUDA build equals the CPU build (the test skips without a GPU)
timeout 90 /tmp/B/test_field --gtest_filter='VoxelBuild.*' 2>&1 | grep -E "OK|FAILED|PASSED|SKIPPED|Failure|Expected|actual"
# 2. scenes: the example (blades every 1 mm, 5100 samples) and the study's (every 0.5 mm, 25000),
# each uniform and with field.refine_tolerance T (the old program has no --refine-tolerance)
ex_u=$(scene ex_u 1.0 0) ex_r=$(scene ex_r 1.0 0.005) st_r=$(scene st_r 0.5 0.005) st_r1=$(scene st_r1 0.5 0.01)
run() {  # case backend scene rep
  echo -n "== $1 $2 rep $4: "
  if [ "$2" = old ]; then
    timeout 200 "$old" --quiet field build "$3" --voxel 0.5 --out /tmp/f_old.vdb 2>&1
  else
    timeout 120 "$fp" --quiet field build "$3" --backend "$2" --voxel 0.5 --out /tmp/f_$2.vdb 2>&1
  fi | grep -E "samples|active|levels|time|start-up" | tr '\n' ' '
  echo
}
for rep in 1 2 3 4 5; do for b in old cpu cuda; do run uniform0.5-example $b "$ex_u" $rep; done; done
for rep in 1 2 3; do for b in old cpu cuda; do run refined0.5pct-example $b "$ex_r" $rep; done; done
run refined0.5pct-study old "$st_r" 1
for rep in 1 2 3; do for b in cpu cuda; do run refined0.5pct-study $b "$st_r" $rep; done; done
for rep in 1 2 3; do for b in cpu cuda; do run refined1pct-study $b "$st_r1" $rep; done; done
# 3. generate end to end on the study scene, voxel refined 0.5 mm to 1 % and to 0.5 %, against the
# indexed direct sum; path.cl of CUDA against CPU
generate_runs
[ "${3:-}" = study ] && study
