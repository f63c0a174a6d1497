#!/usr/bin/env bash
# The hostile-input table of bench/results/reliability.md: small edits of the impeller example and
# odd files, fed to every command as a new user would. Each row must exit 1 with one line on stderr
# that names the key or the file (and line), in <= 5 s and <= 1 GB peak memory, leaving no file in
# --out. Usage: bench/reliability/hostile.sh [FIELDPATH] > table.md  (default: build/bin/fieldpath)
# Exit status: the number of rows that fail a requirement (0: all pass).
set -uo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
fp=$(realpath "${1:-$root/build/bin/fieldpath}")
w=$(mktemp -d)
trap 'umount "$w/full" 2>/dev/null; rm -rf "$w"' EXIT
cd "$w"

# ---- fixtures ---------------------------------------------------------------------------------
cp "$root/examples/impeller/scene.yaml" base.yaml
edit() { sed "$2" base.yaml > "$1"; cmp -s base.yaml "$1" && { echo "hostile.sh: edit $2 changed nothing" >&2; exit 99; }; }
edit sample_step.yaml 's/sample_step: 1.0 /sample_step: 0.0001 /'
edit chord_tol.yaml 's/chord_tol: 0.01 /chord_tol: 1e-9 /'
edit r0.yaml 's/r0: 5.0 /r0: 500 /'
edit step.yaml 's/step: 0.5 /step: 1e-7 /'
edit length.yaml 's/length: 72 /length: 1e9 /'
edit passes.yaml 's/passes: 7/passes: 1000000/'
edit voxel.yaml 's/voxel_size: 0.5 /voxel_size: 0.0001 /'
edit rmin.yaml 's/r_min: 0.25 /r_min: 8 /'
edit radius.yaml 's/radius: 3, length: 40/radius: 1e300, length: 40/'
edit holder.yaml 's/\[90, 12\]/[1e9, 12]/'
edit unknown.yaml 's/gain: 1.0/gian: 1.0/'
edit yaml.yaml 's/^field:/field: [/'
edit levels.yaml 's/refine_levels: 2 /refine_levels: 7 /'
edit rtol.yaml 's/rtol: 1.0e-6/rtol: -1/'
edit tilt.yaml 's/max_tilt_deg: 35/max_tilt_deg: 95/'
edit lean.yaml 's/lean_left_deg: \[4, 24\]/lean_left_deg: [4, 89]/'
edit width.yaml 's/width_out: 22 /width_out: nan /'
printf 'PLY garbage \x00\x01\x02\x03' > garbage.stl
: > empty.stl
printf 'ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nelement face 4\nproperty list uchar int vertex_indices\ne0\n0 10 0\n10 0 0\n0 0 10\n3 0 1 2\n' > hang.ply
printf 'ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n' > huge.ply
printf 'obstacles:\n  - mesh: garbage.stl\ntool: { shape: ball, radius: 3 }\n' > mesh_garbage.yaml
printf 'obstacles:\n  - mesh: hang.ply\ntool: { shape: ball, radius: 3 }\n' > mesh_hang.yaml
printf 'obstacles:\n  - mesh: missing.stl\n' > mesh_missing.yaml
printf '0 0 10 0 0 1\n1 0 10 0 0 1\n2 0 10 0 0 1\n' > ok.cl
printf '0 0 10 0 0 1\n1e308 0 10 0 0 1\n' > far308.cl
printf '0 0 10 0 0 1\n1e30 0 10 0 0 1\n' > far30.cl
printf '0 0 10 0 0 1\nnan 0 10 0 0 1\n' > nan.cl
printf '0 0 10 0 0 1\n1 2 3\n' > short.cl
printf '0 0 10 0 0 0\n' > zeroaxis.cl
: > empty.cl
printf 'GOTO/1,2\n' > short.apt
/usr/bin/python3 -c "
import struct
h=\"{'descr': '<i4', 'fortran_order': False, 'shape': (1, 6), }\"
h+=' '*((64-(10+len(h)+1)%64)%64)+'\n'
open('int.npy','wb').write(b'\x93NUMPY\x01\x00'+struct.pack('<H',len(h))+h.encode()+b'\0'*24)"
printf '0 0 0\n1 nan 2\n' > nan_points.txt
echo "a file" > afile
mkdir -p out2 emptydir
printf 'obstacles:\n  - impeller:\nguide: { impeller: hub }\npath: { nominal: far30.cl, passes: 2 }\n' > nominal_far.yaml

# ---- rows ---------------------------------------------------------------------------------------
# row "what the user did" "text the message must contain" fieldpath arguments...
n=0 failed=0
echo "| # | input | command | exit | stderr (one line?) | time s | peak MB | files in out | ok |"
echo "|---|---|---|---|---|---|---|---|---|"
row() {
  local what=$1 expect=$2; shift 2
  n=$((n + 1))
  local outdir=${OUTDIR:-out}
  rm -rf out "$outdir"
  local start end
  start=$(date +%s.%N)
  /usr/bin/time -f "%M" -o mem.txt timeout 60 "$fp" --quiet "$@" > stdout.txt 2> stderr.txt
  local code=$?
  end=$(date +%s.%N)
  local secs mem lines files msg ok=yes
  secs=$(echo "$end - $start" | bc)
  mem=$(( $(tail -1 mem.txt) / 1024 ))
  lines=$(wc -l < stderr.txt)
  files=0
  [ -d "$outdir" ] && files=$(find "$outdir" -type f | wc -l)
  msg=$(head -c 220 stderr.txt | head -1 | sed 's/|/\\|/g')
  [ "$code" = 1 ] || ok=no
  [ "$lines" = 1 ] || ok=no
  grep -qF -- "$expect" stderr.txt || ok=no
  [ "$(echo "$secs <= 5" | bc)" = 1 ] || ok=no
  [ "$mem" -le 1024 ] || ok=no
  [ "$files" = 0 ] || ok=no
  [ $ok = yes ] || failed=$((failed + 1))
  printf '| %d | %s | `%s` | %s | %s (%s) | %.2f | %d | %s | %s |\n' "$n" "$what" "fieldpath $*" "$code" "$msg" "$lines" "$secs" "$mem" "$files" "$ok"
}
# The 8 of the issue.
row "field.sample_step: 0.0001" "field.sample_step" generate sample_step.yaml --out out
row "impeller.chord_tol: 1e-9" "chord_tol" generate chord_tol.yaml --out out
row "field.r0: 500" "field.r0" generate r0.yaml --out out
row "path.step: 1e-7" "path.step" generate step.yaml --out out
row "impeller.length: 1e9" "impeller.length" generate length.yaml --out out
row ".cl with a tip at x = 1e308" "far308.cl:2" simulate --tool ball:3 --path far308.cl --out out
row ".cl with one tip at x = 1e30" "far30.cl:2" simulate --tool ball:3 --path far30.cl --out out
row "--out is an existing file" "afile" simulate --tool ball:3 --path ok.cl --out afile
# Scene keys (generate; check and study read the same scene).
row "path.passes: 1000000" "path.passes" generate passes.yaml --out out
row "field.voxel_size: 0.0001" "field.voxel_size" generate voxel.yaml --out out
row "--voxel 1e-5" "--voxel" generate base.yaml --voxel 1e-5 --out out
row "field.r_min above r0" "field.r_min" generate rmin.yaml --out out
row "tool.radius: 1e300" "tool" generate radius.yaml --out out
row "holder station at z = 1e9" "holder" generate holder.yaml --out out
row "misspelt key field.gian" "field.gian" generate unknown.yaml --out out
row "YAML syntax error" "yaml.yaml:" generate yaml.yaml --out out
row "field.refine_levels: 7" "field.refine_levels" generate levels.yaml --out out
row "dynamics.rtol: -1" "dynamics.rtol" generate rtol.yaml --out out
row "dynamics.max_tilt_deg: 95" "dynamics.max_tilt_deg" generate tilt.yaml --out out
row "blades that cross (lean 89 deg)" "lean" generate lean.yaml --out out
row "impeller.width_out: nan" "width_out" generate width.yaml --out out
row "obstacle mesh of garbage bytes" "garbage.stl" generate mesh_garbage.yaml --out out
row "obstacle PLY without end_header (hung assimp)" "hang.ply" generate mesh_hang.yaml --out out
row "obstacle mesh missing" "missing.stl" generate mesh_missing.yaml --out out
row "path.nominal with a tip at 1e30" "far30.cl" generate nominal_far.yaml --out out
row "scene file is a directory" "out2: is a directory" generate out2 --out out
row "--out under a file (afile/x)" "afile" generate base.yaml --out afile/x
row "--out in /proc (cannot be created)" "/proc/fieldpath" generate base.yaml --out /proc/fieldpath/out
row "--max-memory 1 (MiB) on the example" "--max-memory" generate base.yaml --max-memory 1 --out out
row "--max-memory 12Q" "--max-memory" generate base.yaml --max-memory 12Q --out out
# simulate
row "--grid 0x10" "--grid" simulate --tool ball:3 --path ok.cl --grid 0x10 --out out
row "--grid 100000x100000" "grid 100000x100000" simulate --tool ball:3 --path ok.cl --grid 100000x100000 --out out
row "--region 0,0,0,0" "region" simulate --tool ball:3 --path ok.cl --region 0,0,0,0 --out out
row "--region 0,0,1e308,1" "region" simulate --tool ball:3 --path ok.cl --region 0,0,1e308,1 --out out
row "--tool ball:-1" "ball:-1" simulate --tool ball:-1 --path ok.cl --out out
row "--tool torus:1:5" "torus:1:5" simulate --tool torus:1:5 --path ok.cl --out out
row "--tool mesh of garbage bytes" "garbage.stl" simulate --tool garbage.stl --path ok.cl --out out
row "--tool PLY with 4e9 vertices declared" "huge.ply" simulate --tool huge.ply --path ok.cl --out out
row "--path empty file" "empty.cl" simulate --tool ball:3 --path empty.cl --out out
row "--path nan coordinate" "nan.cl:2" simulate --tool ball:3 --path nan.cl --out out
row "--path short line" "short.cl:2" simulate --tool ball:3 --path short.cl --out out
row "--path zero axis" "zeroaxis.cl:1" simulate --tool ball:3 --path zeroaxis.cl --out out
row "--path .npy of int32" "int.npy" simulate --tool ball:3 --path int.npy --out out
row "--path APT GOTO with 2 numbers" "short.apt:1" simulate --tool ball:3 --path short.apt --out out
row "--part empty mesh" "empty.stl" simulate --tool ball:3 --path ok.cl --part empty.stl --out out
row "--out is a file (simulate under a file)" "afile" simulate --tool ball:3 --path ok.cl --out afile/sub
# A full disk: a 1 MiB tmpfs (where this may mount one), a 1000x1000 simulation (4 MB of heights).
mkdir -p full
if mount -t tmpfs -o size=1m tmpfs full 2>/dev/null; then
  OUTDIR=full/out row "full disk (1 MiB tmpfs)" "No space left on device" simulate --tool ball:3 --path ok.cl --grid 1000x1000 --out full/out
fi
# tool, field, check, study
row "tool --tol 1e-12" "tolerance" tool --shape ball:3 --tol 1e-12 --out out/t.stl
row "tool --holder 40:6,30:6 (goes down)" "holder" tool --shape ball:3 --holder 40:6,30:6 --out out/t.stl
row "tool --out under a file" "afile" tool --shape ball:3 --out afile/t.stl
row "field probe points with nan" "nan_points.txt:2" field probe base.yaml --points nan_points.txt
row "field build --voxel 1e-4" "voxel" field build base.yaml --voxel 1e-4 --out out/f.vdb
row "field build --out is a directory" "out2" field build base.yaml --out out2
row "check --path garbage" "garbage.stl" check base.yaml --path garbage.stl --out out
row "check --out is a file" "afile" check base.yaml --path ok.cl --out afile
row "study --voxels 0,-1" "--voxels" study base.yaml --voxels 0,-1 --out out
row "study --voxels 1e-6" "1e-06" study base.yaml --voxels 1e-6 --out out
row "study --sample-step 1e-4" "--sample-step" study base.yaml --sample-step 1e-4 --out out
# convert (path files from one format to another)
row "convert: input missing" "missing.cl" convert missing.cl out/o.cl
row "convert: unknown output extension" "o.txt" convert ok.cl out/o.txt
row "convert: APT output without --tool" "--tool" convert ok.cl out/o.apt
row "convert: nan coordinate" "nan.cl:2" convert nan.cl out/o.npy
row "convert: a tip at x = 1e30" "far30.cl:2" convert far30.cl out/o.npy
row "convert: .npy of int32" "int.npy" convert int.npy out/o.cl
row "convert: APT GOTO with 2 numbers" "short.apt:1" convert short.apt out/o.cl
row "convert: output under a file" "afile" convert ok.cl afile/o.cl
# view (the page is one file: --out names it)
"$fp" --quiet simulate --tool ball:3 --path ok.cl --grid 64x64 --out farsurf > /dev/null 2>&1
echo '{"origin":[1e300,0],"spacing":[0.1,0.1],"shape":[64,64]}' > farsurf/heights.json
row "view --path missing file" "missing.cl" view base.yaml --path missing.cl --out out/v.html
row "view --path nan coordinate" "nan.cl:2" view base.yaml --path nan.cl --out out/v.html
row "view --check folder without check.json" "emptydir" view base.yaml --path ok.cl --check emptydir --out out/v.html
row "view --surface folder without heights/deviation" "emptydir" view base.yaml --path ok.cl --surface emptydir --out out/v.html
row "view --surface heights.json at x = 1e300" "farsurf/heights.json" view base.yaml --path ok.cl --surface farsurf --out out/v.html
row "view --max-mb 0" "--max-mb" view base.yaml --path ok.cl --max-mb 0 --out out/v.html
row "view obstacle mesh of garbage bytes" "garbage.stl" view mesh_garbage.yaml --out out/v.html
row "view --out under a file" "afile" view base.yaml --path ok.cl --out afile/v.html
echo
echo "$n rows, $failed failing a requirement."
exit "$failed"
