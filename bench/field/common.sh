# Sourced by the field's bench scripts (gpu_run.sh, gpu_trace.sh, ab_gpu.sh, ab_builds.sh).

# scene NAME SAMPLE_STEP TOLERANCE: examples/impeller/scene.yaml with field.sample_step and
# field.refine_tolerance set, written beside it (its meshes are relative) as
# examples/impeller/.bench_NAME.yaml; prints the path (remove them with remove_scenes).
scene() {
  local out="examples/impeller/.bench_$1.yaml"
  sed -e "s/sample_step: 1.0 /sample_step: $2 /" -e "s/refine_tolerance: 0 /refine_tolerance: $3 /" \
    examples/impeller/scene.yaml > "$out"
  grep -q "refine_tolerance: $3 " "$out" || echo "WARNING: scene $1 not made" >&2
  echo "$out"
}
remove_scenes() { rm -f examples/impeller/.bench_*.yaml; }

# median X...: the median of the numbers
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
