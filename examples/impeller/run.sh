#!/usr/bin/env bash
# Runs the impeller example end to end. Usage: run.sh FIELDPATH_BINARY OUT_DIR
set -euo pipefail
bin=$(realpath "$1"); out=$2
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$out"
"$bin" tool --shape ball:3:12 --tol 0.001 --out "$out/tool.stl"
echo "impeller: outputs in $out"
