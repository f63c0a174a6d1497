#!/usr/bin/env bash
# First frame of `fieldpath view` pages in headless Chromium (software WebGL, SwiftShader), as the
# page measures it: performance.now() when its first frame is drawn (readPixels waits for it),
# counted from the navigation's start; written into the page's #fp-state, read with --dump-dom.
# Usage: first_frame.sh RUNS PAGE.html...   (prints one markdown row per page: size, then the
# first frame's median / min / max in ms over RUNS cold starts of chromium, and the WebGL
# context's creation alone, median).
set -euo pipefail
runs=$1; shift
chromium=${FIELDPATH_CHROMIUM:-chromium}
for page in "$@"; do
  page=$(realpath "$page")
  frames=(); contexts=()
  for ((i = 0; i < runs; ++i)); do
    profile=$(mktemp -d)
    dom=$("$chromium" --headless --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader --disable-dev-shm-usage \
      --window-size=800,650 --virtual-time-budget=5000 --user-data-dir="$profile" --dump-dom \
      "file://$page" 2>/dev/null)
    rm -rf "$profile"
    frames+=("$(grep -o '"first_frame_ms":[0-9]*' <<<"$dom" | cut -d: -f2)")
    contexts+=("$(grep -o '"context_ms":[0-9]*' <<<"$dom" | cut -d: -f2)")
  done
  stats() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {printf "%d / %d / %d", a[int((NR+1)/2)], a[1], a[NR]}'; }
  median() { printf '%s\n' "$@" | sort -n | awk '{a[NR]=$1} END {print a[int((NR+1)/2)]}'; }
  printf '| %s | %.2f MB | %s | %s |\n' "$page" "$(stat -c %s "$page" | awk '{print $1 / 1e6}')" \
    "$(stats "${frames[@]}")" "$(median "${contexts[@]}")"
done
