#!/usr/bin/env bash
# Runs the impeller example end to end. Usage: run.sh FIELDPATH_BINARY OUT_DIR
#   OUT_DIR/field/    generate (voxel field) + check: path.cl, path.apt, angles.csv, report.json,
#                     check.json, deviation.png; view.html: the job in 3-D (open it in a browser)
#   OUT_DIR/nominal/  the same for the nominal (untilted) path: the collisions the field avoids
#   OUT_DIR/tilt.png  tilt and lead along the path, field vs nominal clearance
set -euo pipefail
bin=$(realpath "$1"); out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out/field" "$out/nominal"
"$bin" generate "$here/scene.yaml" --out "$out/field"
"$bin" check "$here/scene.yaml" --path "$out/field/path.cl" --out "$out/field"
"$bin" generate "$here/scene.yaml" --nominal --out "$out/nominal"
"$bin" check "$here/scene.yaml" --path "$out/nominal/path.cl" --out "$out/nominal"
for p in field nominal; do
  "$bin" view "$here/scene.yaml" --path "$out/$p/path.cl" --check "$out/$p" --out "$out/$p/view.html"
done
/usr/bin/python3 "$here/plot.py" "$out"
echo "impeller: outputs in $out (field/view.html, field/deviation.png, tilt.png)"
