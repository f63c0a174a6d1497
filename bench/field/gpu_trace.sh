#!/bin/bash
# The build's phases on the GPU machine (FIELDPATH_TRACE_BUILD=1): where the time of a CUDA
# build goes beside the kernel, for the uniform example and the study scene refined to 0.5 % and
# 1 %, each with glibc's malloc as is and with transparent huge pages (GLIBC_TUNABLES
# glibc.malloc.hugetlb=1: the host refinement is page-fault bound).
#   bench/field/gpu_trace.sh DIR/fp.tar.xz OUTDIR [REPS]   (bundle: gpu_bundle.sh)
set -u
. "$(dirname "$0")/common.sh"
bundle=$1 out=${2:-/tmp/gpu_out} reps=${3:-3}
mkdir -p "$out"
tar -C /tmp -xJf "$bundle"
export LD_LIBRARY_PATH=/tmp/B/lib
fp=/tmp/B/fieldpath
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
echo "cores: $(nproc); THP: $(cat /sys/kernel/mm/transparent_hugepage/enabled); $(ldd --version | head -1)"
ex_u=$(scene ex_u 1.0 0) st_r=$(scene st_r 0.5 0.005) st_r1=$(scene st_r1 0.5 0.01)
for sc in "$ex_u" "$st_r" "$st_r1"; do
  for b in cuda cpu; do
    for thp in "" "glibc.malloc.hugetlb=1"; do
      for ((rep = 1; rep <= reps; rep++)); do
        log="$out/trace_$(basename "$sc" .yaml)_${b}_${thp:+thp}_$rep.log"
        GLIBC_TUNABLES=$thp FIELDPATH_TRACE_BUILD=1 timeout 120 "$fp" --quiet field build "$sc" \
          --backend $b --voxel 0.5 --out /tmp/f.vdb > "$log" 2>&1
        echo "== $(basename "$sc") $b ${thp:+thp} rep $rep: $(grep -oE 'build [0-9.]+ s.*' "$log")"
      done
    done
  done
  # the phases of the last run of each backend
  for b in cuda cpu; do
    echo "-- phases $(basename "$sc") $b thp:"; grep "build trace" "$out/trace_$(basename "$sc" .yaml)_${b}_thp_$reps.log"
  done
done
remove_scenes
