#!/bin/bash
# The voxel job refined near its path against refined everywhere and the indexed direct sum,
# on the GPU machine (issue 15, fourth session): `generate` end to end as a user runs it, and the
# study at 16 cores / GPU. Bundle made here as for gpu_run.sh:
#   here:  bench/field/gpu_bundle.sh BUILD_DIR .gpu            (.gpu/fp.tar.xz)
#   there: bench/field/gpu_near_path.sh .gpu/fp.tar.xz OUTDIR
# Prints the runs, then a table of medians (seconds, as report.json's times_s) last.
set -u
. "$(dirname "$0")/common.sh"
bundle=$1
out=${2:-/tmp/gpu_out}
reps=${REPS:-5}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
here=$(dirname "$0")
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "cores: $(nproc)"
# 1. the CUDA build equals the CPU build, the mask and the region (tests skip without a GPU)
timeout 120 /tmp/B/test_field --gtest_filter='VoxelBuild.*:CellMask.*:RegionField.*' 2>&1 |
  grep -E "OK \]|FAILED|PASSED|SKIPPED|Failure"
# 2. generate on the study's scene (blades every 0.5 mm): 1 mm refined 1 % to 0.125 mm (0.81 %
# max force error on 2 cores), near the path and everywhere, cuda and cpu, against direct
near_path_scenes
st=examples/impeller/.bench_st1.yaml
declare -A totals wall
for rep in $(seq 1 "$reps"); do
  for c in "path cuda" "reach cuda" "path cpu" "direct -"; do
    set -- $c
    sc=$st; [ "$1" = reach ] && sc=examples/impeller/.bench_st1_reach.yaml
    d=/tmp/gen_$1_$2
    if [ "$1" = direct ]; then args="--direct"; else args="--backend $2"; fi
    t0=$(date +%s.%N)
    timeout 120 "$fp" --quiet generate "$sc" $args --out "$d" > /dev/null 2>&1 || echo "FAILED $c"
    t1=$(date +%s.%N)
    line=$(python3 -c "import json; r=json.load(open('$d/report.json')); t=r['times_s']; c=r['counts']; print(t['field'], t['steering'], t['field']+t['steering'], c['voxel_nodes'], c.get('voxel_outside_points', 0))")
    echo "== $1 $2 rep $rep: field steering field+steering nodes outside = $line; wall $(python3 -c "print(round($t1 - $t0, 3))")"
    totals["$1 $2"]+="$(echo "$line" | awk '{print $3}') "
    wall["$1 $2"]+="$(python3 -c "print(round($t1 - $t0, 3))") "
  done
done
echo -n "path.cl near path vs everywhere (cuda): "; python3 "$here/compare_cl.py" /tmp/gen_reach_cuda/path.cl /tmp/gen_path_cuda/path.cl | tail -1
echo -n "path.cl cuda vs cpu (near path): "; python3 "$here/compare_cl.py" /tmp/gen_path_cpu/path.cl /tmp/gen_path_cuda/path.cl | tail -1
# 3. the study at 16 cores / GPU, near the path and everywhere, cpu and cuda builds: 1 mm refined
# 1 % to 0.125 mm, and 0.5 mm refined 1 % to 0.125 mm
for v in "1 3" "0.5 2"; do
  set -- $v
  timeout 240 "$fp" --quiet study examples/impeller/scene.yaml --sample-step 0.5 --voxels "$1" \
    --interp trilinear --stored plane_ratio --refine 1 --refine-levels "$2" --refine-region path,reach \
    --backend cpu,cuda --no-brute-force --repeat 5 --line-step 0.2 --out "/tmp/study_np_$1" 2>&1 | tail -6
  cp "/tmp/study_np_$1/study.md" "$out/study_near_path_gpu_$1.md" 2>/dev/null
  cp "/tmp/study_np_$1/study.csv" "$out/study_near_path_gpu_$1.csv" 2>/dev/null
  grep "^| voxel\|^| direct" "/tmp/study_np_$1/study.md" | head -5 | cut -d'|' -f2,7-9
done
# 4. the near-path phases of one study build (cuda), FIELDPATH_TRACE_BUILD
FIELDPATH_TRACE_BUILD=1 timeout 120 "$fp" --quiet study examples/impeller/scene.yaml --sample-step 0.5 \
  --voxels 1 --interp trilinear --stored plane_ratio --refine 1 --refine-levels 3 \
  --refine-region path --backend cuda --no-brute-force --repeat 3 --line-step 0.2 \
  --out /tmp/study_trace 2> "$out/near_path_trace.txt" > /dev/null
awk '/near path: uniform/{n++} n==3' "$out/near_path_trace.txt" | head -50
remove_scenes
echo
echo "generate, medians of $reps (field + steering s, from report.json):"
for c in "direct -" "path cuda" "reach cuda" "path cpu"; do
  m=$(median ${totals[$c]})
  echo "  $c: $m"
done
