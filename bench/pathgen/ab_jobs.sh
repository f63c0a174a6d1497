#!/usr/bin/env bash
# Two builds of fieldpath on the same jobs, as a user runs them: `generate` then `check` of its
# path, ROUNDS rounds alternating the binaries; prints the median CPU seconds (user + system) of
# each, the ratio new / old, and whether path.cl and clearance.csv are byte for byte the same.
# Jobs: both examples, and both with their passes given backwards (each pass's postures in the
# other order: the from-end repair's jobs, faulty steered from their starts). AB_JOBS="..." picks
# them, and offers three more: bodies6 (the mesh example with one STL a blade), bodies96 (each
# blade in 16 closed pieces, one STL each: blade_bodies.py) and bodies96_one (the same 96 pieces
# in one STL: bodies96's peer, the same path).
# Usage: [AB_JOBS="mesh bodies96 bodies96_one"] bench/pathgen/ab_jobs.sh OLD NEW [ROUNDS] [WORKDIR]
set -euo pipefail
here=$(cd "$(dirname "$0")/../.." && pwd)
old=$(realpath "$1"); new=$(realpath "$2")
rounds=${3:-3}
work=${4:-$(mktemp -d)}
mkdir -p "$work"

# Each pass block of a .cl (`# pass` lines start them; `# link` blocks dropped) in reverse order
# (the corpus's helper, bench/reliability/corpus_scenes.py, makes the same reversed jobs).
reverse_cl() { /usr/bin/python3 "$here/bench/reliability/corpus_scenes.py" --reverse "$1" "$2"; }

# The jobs: impeller, impeller_rev, mesh, mesh_rev (each a scene.yaml in its folder).
mkdir -p "$work/impeller" "$work/impeller_rev" "$work/mesh" "$work/mesh_rev"
cp "$here/examples/impeller/scene.yaml" "$work/impeller/"
"$new" --quiet generate "$work/impeller/scene.yaml" --nominal --out "$work/impeller_nominal" \
  > /dev/null 2>&1
reverse_cl "$work/impeller_nominal/path.cl" "$work/impeller_rev/rev.cl"
# (the passes from the file: no guide, the path block replaced)
/usr/bin/python3 - "$here/examples/impeller/scene.yaml" "$work/impeller_rev/scene.yaml" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
text = re.sub(r'^guide:.*\n', '', text, flags=re.M)
text = re.sub(r'^path:\n(  .*\n)*', 'path: { nominal: rev.cl, lead_deg: 0 }\n', text, flags=re.M)
open(sys.argv[2], 'w').write(text)
EOF
cp "$here/examples/mesh_impeller/scene.yaml" "$work/mesh/"
/usr/bin/python3 "$here/examples/mesh_impeller/make_part.py" "$work/mesh" > /dev/null
cp "$work/mesh/"*.stl "$work/mesh/scene.yaml" "$work/mesh_rev/"
reverse_cl "$work/mesh/nominal.cl" "$work/mesh_rev/nominal.cl"

# The many-bodies jobs (only those asked for).
jobs=(${AB_JOBS:-impeller impeller_rev mesh mesh_rev})
for job in "${jobs[@]}"; do
  case $job in
    bodies6) pieces=(1) ;; bodies96) pieces=(16) ;; bodies96_one) pieces=(16 --one-file) ;;
    *) continue ;;
  esac
  mkdir -p "$work/$job"
  cp "$work/mesh/"*.stl "$work/mesh/nominal.cl" "$work/mesh/scene.yaml" "$work/$job/"
  /usr/bin/python3 "$here/bench/pathgen/blade_bodies.py" "$work/$job" "${pieces[@]}" > /dev/null
done

median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2 ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2)}'; }
for r in $(seq "$rounds"); do
  for job in "${jobs[@]}"; do
    for b in old new; do
      bin=${!b}; d="$work/$job"
      /usr/bin/time -f "%U %S" -a -o "$d/$b.generate.cpu" \
        "$bin" --quiet generate "$d/scene.yaml" --out "$d/$b" > /dev/null 2>&1 || true
      /usr/bin/time -f "%U %S" -a -o "$d/$b.check.cpu" \
        "$bin" --quiet check "$d/scene.yaml" --path "$d/$b/path.cl" --out "$d/$b.check" \
        > /dev/null 2>&1 || true
    done
  done
done
echo "machine: $(nproc) cores, $(date -u '+%F %H:%M') UTC, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "| job | generate old s | new s | new / old | check old s | new s | new / old | path.cl | clearance.csv |"
echo "|---|---:|---:|---:|---:|---:|---:|---|---|"
for job in "${jobs[@]}"; do
  d="$work/$job"; row="| $job"
  for step in generate check; do
    o=$(awk '{print $1 + $2}' "$d/old.$step.cpu" | median)
    n=$(awk '{print $1 + $2}' "$d/new.$step.cpu" | median)
    row="$row | $o | $n | $(awk -v o="$o" -v n="$n" 'BEGIN {printf "%.2f", n / o}')"
  done
  same() { cmp -s "$1" "$2" && echo same || echo DIFFERS; }
  row="$row | $(same "$d/old/path.cl" "$d/new/path.cl") | $(same "$d/old.check/clearance.csv" "$d/new.check/clearance.csv") |"
  echo "$row"
done
