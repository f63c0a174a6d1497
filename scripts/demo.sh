#!/usr/bin/env bash
# Set up and build (scripts/setup.sh), then run both examples end to end: the parametric impeller
# into out/impeller/ and the impeller given as meshes (STL blades and hub, a nominal .cl path, as
# a CAM system hands them over) into out/mesh_impeller/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash examples/impeller/run.sh build/bin/fieldpath out/impeller
bash examples/mesh_impeller/run.sh build/bin/fieldpath out/mesh_impeller
