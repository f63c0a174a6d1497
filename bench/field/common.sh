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

# near_path_scenes: the study's scene (blades every 0.5 mm) at 1 mm refined 1 % to 0.125 mm, as
# examples/impeller/.bench_st1.yaml (field.refine_region: path, the default) and
# .bench_st1_reach.yaml (reach); remove them with remove_scenes.
near_path_scenes() {
  local st
  st=$(scene st1 0.5 0.01)
  sed -i -e "s/voxel_size: 0.5 /voxel_size: 1.0 /" -e "s/refine_levels: 2 /refine_levels: 3 /" "$st"
  sed -e "/refine_levels:/a\\  refine_region: reach" "$st" > examples/impeller/.bench_st1_reach.yaml
}

# median X...: the median of the numbers
median() { printf '%s\n' "$@" | sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
