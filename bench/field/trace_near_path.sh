# Phases of the voxel build (FIELDPATH_TRACE_BUILD) and report.json times, refined near the path
# against everywhere, CUDA, on the GPU machine: bash bench/field/trace_near_path.sh (bundle in
# .gpu/fp.tar.xz, made by gpu_bundle.sh). Log of record: results/field_builds/gpu_near_path_trace_*.
set -u
. bench/field/common.sh
tar -C /tmp -xJf .gpu/fp.tar.xz; export LD_LIBRARY_PATH=/tmp/B/lib; fp=/tmp/B/fieldpath
near_path_scenes
st=examples/impeller/.bench_st1.yaml
for rep in 1 2 3; do for c in path reach; do
  sc=$st; [ $c = reach ] && sc=examples/impeller/.bench_st1_reach.yaml
  FIELDPATH_TRACE_BUILD=1 $fp --quiet generate $sc --backend cuda --out /tmp/g_$c 2>/tmp/trace_$c.txt >/dev/null
  echo "$c rep $rep: $(python3 -c "import json; print(json.load(open('/tmp/g_$c/report.json'))['times_s'])")"
done; done
for c in path reach; do echo "--- trace $c (last rep)"; cat /tmp/trace_$c.txt; done
remove_scenes
