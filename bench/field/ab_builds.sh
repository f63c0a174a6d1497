#!/bin/bash
# The voxel build of two programs side by side on one machine, same run, alternating (issue 15:
# the build of before the issue against today's): `field build SCENE --voxel H` with the scene's
# field.refine_tolerance set to T (the old program has neither --refine-tolerance nor --backend)
# and, with --study-scene, field.sample_step 0.5 (the study's samples), REPEATS times, alternating;
# prints every run's "build X s" and the medians.
#   bench/field/ab_builds.sh OLD_FIELDPATH NEW_FIELDPATH SCENE H T REPEATS [NEW_BACKEND] [--study-scene]
# (NEW_BACKEND, default cpu, is passed to the new one)
set -eu
. "$(dirname "$0")/common.sh"
old=$1 new=$2 scene=$3 h=$4 tol=$5 reps=$6 backend=${7:-cpu}
tmp=$(mktemp -d "$(dirname "$scene")/.ab_XXXX")  # beside the scene: its meshes are relative
trap 'rm -rf "$tmp"' EXIT
sed -e "s/refine_tolerance: 0 /refine_tolerance: $tol /" "$scene" > "$tmp/scene.yaml"
[ "${8:-}" = --study-scene ] && sed -i 's/sample_step: 1.0 /sample_step: 0.5 /' "$tmp/scene.yaml"
grep -q "refine_tolerance: $tol " "$tmp/scene.yaml" || { echo "no 'refine_tolerance: 0 ' in $scene"; exit 1; }
scene=$tmp/scene.yaml
build_s() { grep -oE "build [0-9.]+ s" | head -1 | awk '{print $2}'; }
counts() { grep -oE "[0-9]+ samples|active nodes: [0-9]+" | tr '\n' ' '; }
declare -a o n
for ((r = 1; r <= reps; r++)); do
  "$old" field build "$scene" --voxel "$h" --out "$tmp/o.vdb" > "$tmp/o.txt" 2>&1
  "$new" field build "$scene" --voxel "$h" --backend "$backend" --out "$tmp/n.vdb" > "$tmp/n.txt" 2>&1
  o+=("$(build_s < "$tmp/o.txt")")
  n+=("$(build_s < "$tmp/n.txt")")
  echo "rep $r: old ${o[-1]} s, new ($backend) ${n[-1]} s"
done
echo "old: $(counts < "$tmp/o.txt"); new: $(counts < "$tmp/n.txt")"
mo=$(median "${o[@]}") mn=$(median "${n[@]}")
echo "median of $reps: old $mo s, new $mn s, x $(awk -v a="$mo" -v b="$mn" 'BEGIN {printf "%.2f", a / b}')"
