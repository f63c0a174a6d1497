#!/bin/bash
# The CPU block build with each lane kind the machine has, same binary, same run, alternating
# (node_lanes.cpp: FIELDPATH_LANES=generic | avx2, and the default: AVX-512 where present):
# `field build SCENE --voxel H` REPEATS times each; prints every run's "build X s", the lanes
# the default took (its trace) and the medians.
#   bench/field/ab_lanes.sh FIELDPATH SCENE H REPEATS
set -eu
. "$(dirname "$0")/common.sh"
bin=$1 scene=$2 h=$3 reps=$4
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
build_s() { grep -oE "build [0-9.]+ s" | head -1 | awk '{print $2}'; }
kinds=(generic avx2 default)
declare -A times
for ((r = 1; r <= reps; r++)); do
  line="rep $r:"
  for k in "${kinds[@]}"; do
    if [ "$k" = default ]; then
      "$bin" field build "$scene" --voxel "$h" --backend cpu --out "$tmp/f.vdb" > "$tmp/o.txt" 2>&1
    else
      FIELDPATH_LANES=$k "$bin" field build "$scene" --voxel "$h" --backend cpu --out "$tmp/f.vdb" \
        > "$tmp/o.txt" 2>&1
    fi
    t=$(build_s < "$tmp/o.txt")
    times[$k]="${times[$k]:-} $t"
    line="$line $k $t s"
  done
  echo "$line"
done
grep -m1 -o 'avx512f' /proc/cpuinfo > /dev/null && echo "CPU: AVX-512 (default: avx512)" ||
  echo "CPU: no AVX-512 (default: avx2 where the CPU has it)"
for k in "${kinds[@]}"; do
  # shellcheck disable=SC2086
  echo "median of $reps, $k: $(median ${times[$k]}) s"
done
