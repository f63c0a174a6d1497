#!/usr/bin/env bash
# Runs the mesh impeller example end to end. Usage: run.sh FIELDPATH_BINARY OUT_DIR
#   OUT_DIR/part/     scene.yaml (a copy of this folder's) and what make_part.py writes beside it:
#                     hub.stl, blades.stl, nominal.cl, nominal.apt, nominal.npy
#   OUT_DIR/field/    generate (voxel field) + check: path.cl, path.apt, angles.csv, report.json,
#                     check.json, deviation.png; view.html: the job in 3-D (open it in a browser)
#   OUT_DIR/nominal/  the same for the nominal path (axis on the hub normal): the collisions the
#                     field avoids
set -euo pipefail
bin=$(realpath "$1"); out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out/part" "$out/field" "$out/nominal"
cp "$here/scene.yaml" "$out/part/scene.yaml"
/usr/bin/python3 "$here/make_part.py" "$out/part"
scene="$out/part/scene.yaml"
"$bin" generate "$scene" --out "$out/field"
"$bin" check "$scene" --path "$out/field/path.cl" --out "$out/field"
"$bin" generate "$scene" --nominal --out "$out/nominal"
"$bin" check "$scene" --path "$out/nominal/path.cl" --out "$out/nominal"
for p in field nominal; do
  "$bin" view "$scene" --path "$out/$p/path.cl" --check "$out/$p" --out "$out/$p/view.html"
done
echo "mesh_impeller: outputs in $out (part/, field/, nominal/; field/view.html)"
