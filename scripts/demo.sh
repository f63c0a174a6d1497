#!/usr/bin/env bash
# Set up and build (scripts/setup.sh), then run the impeller example end to end into out/impeller/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
bash examples/impeller/run.sh build/bin/fieldpath out/impeller
