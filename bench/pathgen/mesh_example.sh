#!/usr/bin/env bash
# The mesh example end to end as a user runs it (issue: generate ≤ 3 s, check with motions ≤ 3 s,
# peak memory ≤ 500 MB on 2 cores): makes the part (examples/mesh_impeller/make_part.py), then
# times `fieldpath generate` and `fieldpath check` as processes, REPEATS runs each, and prints
# the median wall time and peak RSS of each, with the key results of the last run.
# Usage: bench/pathgen/mesh_example.sh [FIELDPATH] [REPEATS] [WORKDIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
bin=$(realpath "${1:-$here/build/bin/fieldpath}")
repeats=${2:-5}
work=${3:-$(mktemp -d)}
mkdir -p "$work/part"
cp "$here/examples/mesh_impeller/scene.yaml" "$work/part/"
/usr/bin/python3 "$here/examples/mesh_impeller/make_part.py" "$work/part" > /dev/null

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2 ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2)}'; }
run() {  # name, command...: appends "wall_s peak_kb" per run to $work/$name.times
  local name=$1; shift
  : > "$work/$name.times"
  for _ in $(seq "$repeats"); do
    /usr/bin/time -f "%e %M" -o "$work/$name.one" "$@" > "$work/$name.out"
    cat "$work/$name.one" >> "$work/$name.times"
  done
  printf '| `%s` | %s | %s |\n' "$name" "$(cut -d' ' -f1 < "$work/$name.times" | median)" \
    "$(cut -d' ' -f2 < "$work/$name.times" | median | awk '{printf "%.0f", $1 / 1024}')"
}
echo "machine: $(nproc) cores, $(date -u +%F), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "| command | median wall s | median peak RSS MiB |"
echo "|---|---:|---:|"
run generate "$bin" --quiet generate "$work/part/scene.yaml" --out "$work/field"
run check "$bin" --quiet check "$work/part/scene.yaml" --path "$work/field/path.cl" --out "$work/field"
run "generate --nominal" "$bin" --quiet generate "$work/part/scene.yaml" --nominal --out "$work/nominal"
run "check (nominal)" "$bin" --quiet check "$work/part/scene.yaml" --path "$work/nominal/path.cl" --out "$work/nominal"
echo
cat "$work/generate.out" "$work/check.out" "$work/generate --nominal.out" "$work/check (nominal).out"
