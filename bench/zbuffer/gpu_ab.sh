#!/usr/bin/env bash
# A/B timing on the GPU machine (device tool): the GPU machine changes between calls, and case 8's
# time moved by ±10 % from one machine to the next, so a change is timed against the previous
# commit in the same call, the two binaries alternating.
#   here:   rm -rf ab-prev && mkdir ab-prev && git archive <ref> | tar -x -C ab-prev
#           (untracked and not ignored, so that it travels with the working tree)
#   there:  bash bench/zbuffer/gpu_ab.sh [cases] [reps] [rounds]      (default 8,3,5 5 2)
#   then:   rm -rf ab-prev
set -uo pipefail
CASES=${1:-8,3,5}; REPS=${2:-5}; ROUNDS=${3:-2}
[ -d ab-prev ] || { echo "gpu_ab.sh: no ab-prev/ (see the comment at the top)"; exit 1; }
declare -A SRC=([prev]=ab-prev [cur]=.)
for k in prev cur; do
  (cmake -S "${SRC[$k]}" -B /tmp/ab-$k -DFIELDPATH_ZBUFFER_ONLY=ON -DCMAKE_CUDA_ARCHITECTURES=90 \
     -DCMAKE_BUILD_TYPE=Release > /tmp/ab-$k.log 2>&1 &&
   cmake --build /tmp/ab-$k -j8 >> /tmp/ab-$k.log 2>&1 || { echo "build $k failed"; tail -20 /tmp/ab-$k.log; }) &
done
wait
/tmp/ab-cur/bin/test_zbuffer_cuda 2>&1 | grep -E "OK \]|FAILED|differ" | head
for r in $(seq "$ROUNDS"); do
  for k in prev cur; do
    /tmp/ab-$k/bin/bench_zbuffer --backend cuda --reps "$REPS" --peer-limit 1 --no-exact --cases "$CASES" |
      grep "^| [0-9A-Z]" | cut -d'|' -f2,6 | sed "s/^/$k r$r /"
  done
done
