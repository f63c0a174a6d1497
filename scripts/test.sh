#!/usr/bin/env bash
# Set up and build (scripts/setup.sh), then run the whole test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
ctest --test-dir build --output-on-failure -j"$(nproc)" --timeout 600
# Smoke fuzz of the parsers (libFuzzer + ASan + UBSan, 10 s a target; skipped without clang 14).
FUZZ_SECONDS=${FUZZ_SECONDS:-10} bash scripts/fuzz_smoke.sh
