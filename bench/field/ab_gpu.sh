#!/bin/bash
# Two builds of the program with --backend, alternating on the GPU machine, same run (the
# machine's instances differ by up to 30 % from call to call: compare only within one run):
# `field build --voxel 0.5 --backend B` on the example (uniform) and the study scene (blades every
# 0.5 mm) refined to 0.5 % and 1 %; prints each run's build time and the medians.
#   here:  OLD=/path/to/the/other/fieldpath bench/field/gpu_bundle.sh BUILD_DIR DIR
#   there: bench/field/ab_gpu.sh DIR/fp.tar.xz OUTDIR [REPS] [BACKEND]
set -u
. "$(dirname "$0")/common.sh"
bundle=$1 out=${2:-/tmp/gpu_out} reps=${3:-5} backend=${4:-cuda}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "cores: $(nproc)"
for sc in "$(scene u 1.0 0)" "$(scene r 0.5 0.005)" "$(scene r1 0.5 0.01)"; do
  o=() n=()
  for ((rep = 1; rep <= reps; rep++)); do
    for which in old new; do
      fp=/tmp/B/fieldpath; [ $which = old ] && fp=/tmp/B/fieldpath_old
      t=$(timeout 120 "$fp" --quiet field build "$sc" --backend "$backend" --voxel 0.5 --out /tmp/ab.vdb 2>&1 |
          grep -oE "build [0-9.]+ s" | awk '{print $2}')
      [ $which = old ] && o+=("$t") || n+=("$t")
    done
  done
  echo "$(basename "$sc") $backend: old ${o[*]} | new ${n[*]} | medians old $(median "${o[@]}") new $(median "${n[@]}")"
done | tee "$out/ab_gpu.log"
remove_scenes
