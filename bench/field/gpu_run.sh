#!/bin/bash
# The voxel field's builds on the GPU machine (issue 15): the CUDA build against the CPU block
# build and the per-node reference, same run, same scenes. The machine has no OpenVDB: the
# program travels as a bundle (BUILD-NOTES.md "The whole program on the GPU machine"):
#   here:  bench/field/gpu_bundle.sh BUILD_DIR DIR   (fieldpath + test_field + libraries: DIR/fp.tar.xz)
#   there: bench/field/gpu_run.sh DIR/fp.tar.xz OUTDIR [study]
# Prints one line per run: "== case backend rep" then the build's own times ("build X s (B nodes
# Y s, refinement Z s)"); the CUDA start-up is inside the first CUDA build of each process.
set -u
bundle=$1
out=${2:-/tmp/gpu_out}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
here=$(dirname "$0")
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "cores: $(nproc)"
# 1. the CUDA build equals the CPU build (the test skips without a GPU)
timeout 90 /tmp/B/test_field --gtest_filter='VoxelBuild.*' 2>&1 | grep -E "OK|FAILED|PASSED|SKIPPED|Failure|Expected|actual"
# 2. scenes: the example (blades every 1 mm, 5100 samples) and the study's (every 0.5 mm, 20400)
sed 's/sample_step: 1.0 /sample_step: 0.5 /' examples/impeller/scene.yaml > /tmp/study_scene.yaml
grep -q 'sample_step: 0.5 ' /tmp/study_scene.yaml || echo "WARNING: study scene not made"
run() {  # case backend scene voxel tolerance rep
  echo -n "== $1 $2 rep $6: "
  timeout 120 "$fp" --quiet field build "$3" --backend "$2" --voxel "$4" --refine-tolerance "$5" \
    --out /tmp/f_$2.vdb 2>&1 | grep -E "samples|active|levels|time|start-up" | tr '\n' ' '
  echo
}
for rep in 1 2 3 4 5; do
  for b in cuda cpu; do run uniform0.5-example $b examples/impeller/scene.yaml 0.5 0 $rep; done
done
run uniform0.5-example reference examples/impeller/scene.yaml 0.5 0 1
for rep in 1 2 3; do
  for b in cuda cpu; do run uniform0.5-study $b /tmp/study_scene.yaml 0.5 0 $rep; done
done
for rep in 1 2 3; do
  for b in cuda cpu; do run refined0.5pct-example $b examples/impeller/scene.yaml 0.5 0.005 $rep; done
done
run refined0.5pct-example reference examples/impeller/scene.yaml 0.5 0.005 1
for rep in 1 2 3; do
  for b in cuda cpu; do run refined0.5pct-study $b /tmp/study_scene.yaml 0.5 0.005 $rep; done
done
run refined0.5pct-study reference /tmp/study_scene.yaml 0.5 0.005 1
# 3. generate end to end on the study scene: voxel refined 0.5 mm to 0.5 % against the indexed
# direct sum; path.cl of the CUDA build against the CPU build's and the reference's
sed 's/refine_tolerance: 0 /refine_tolerance: 0.005 /' /tmp/study_scene.yaml > /tmp/gen_scene.yaml
for mode in "--backend cuda" "--backend cpu" "--backend reference" "--direct"; do
  d=/tmp/gen_${mode//[- ]/}
  echo -n "== generate $mode: "
  timeout 120 "$fp" --quiet generate /tmp/gen_scene.yaml $mode --out "$d" >/dev/null 2>&1
  python3 -c "import json; r=json.load(open('$d/report.json')); print(r.get('times_s'), r.get('voxel_nodes'))"
done
echo -n "path.cl cuda vs cpu: "; python3 "$here/compare_cl.py" /tmp/gen_backendcpu/path.cl /tmp/gen_backendcuda/path.cl
echo -n "path.cl cpu vs reference: "; python3 "$here/compare_cl.py" /tmp/gen_backendreference/path.cl /tmp/gen_backendcpu/path.cl
# 4. the study at 16 cores / GPU: old, CPU block and CUDA builds side by side
if [ "${3:-}" = study ]; then
  timeout 150 "$fp" --quiet study examples/impeller/scene.yaml --sample-step 0.5 --voxels 0.5 \
    --interp trilinear --stored plane_ratio --refine 0.5 --refine-levels 2 \
    --backend reference,cpu,cuda --no-brute-force --line-step 0.2 --out /tmp/study 2>&1 | tail -12
  cp /tmp/study/study.md "$out/study_gpu.md" 2>/dev/null
  cp /tmp/study/study.csv "$out/study_gpu.csv" 2>/dev/null
fi
