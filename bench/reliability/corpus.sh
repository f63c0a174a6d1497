#!/usr/bin/env bash
# A regression corpus: two builds of fieldpath on the same jobs, outputs compared. The jobs are
# written by corpus_scenes.py beside this script (deterministic; its docstring lists them): single
# passes with corners of 30-150 deg turning away from a wall, into a pocket's inner corner and round
# a boss's apex (sharp, R 2, filleted), 3-D corners on slopes, ramps; CAM finishing jobs (pockets
# 30 deep with corner radii 0 / 3 / 6 by closed offset loops, a boss in a pocket, an L pocket, 5 deg
# draft, a zig-zag raster, a pocket's --nominal path, a corner with --direct); two scenes with
# `on_limit: fail` that must exit 1; and both examples with their passes given forwards and
# reversed (as bench/pathgen/ab_jobs.sh). Each job: `generate` with OLD and with NEW (the same
# flags, each in its own folder), then `check` of each generated path.
# Compared: exit codes; path.cl, path.apt, angles.csv, clearance.csv and deviation.npy byte for
# byte where written; report.json and check.json without their timing keys (names with "time",
# "seconds" or ending "_s"); stdout and stderr with times ("1.6 s") masked and progress lines left
# out. Both binaries run from a folder of the same name (WORKDIR/runs/JOB/{old,new}/ with --out out
# and check's --out check), so file names in messages compare equal.
# Prints a markdown table (one row a job: generate exit codes, check exit codes, each file's
# same / DIFF / - (written by neither), CPU seconds user + system of generate + check) and a last
# line `corpus: N jobs, D differ`. Logs and outputs stay in WORKDIR (default: a new mktemp -d);
# WORKDIR/diffs.txt gives the first differing lines of each DIFF.
# 75 jobs: both binaries in about 6 min wall, 8.5 min CPU on the 2-core VM (2026-12-01, idle).
# Usage: bench/reliability/corpus.sh OLD NEW [WORKDIR]   (CORPUS_JOBS="a b": those jobs only;
#        CORPUS_TIMEOUT=S: a command's limit, default 600 s, a hang then reads as exit 124)
# Exit status: the number of jobs that differ (0: all the same); 100 on bad arguments.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
py=/usr/bin/python3
[ $# -ge 2 ] || { sed -n '2,/^set -euo/p' "$0" | sed '$d'; exit 100; }
old=$(realpath "$1"); new=$(realpath "$2")
if [ ! -x "$old" ] || [ ! -x "$new" ]; then echo "corpus.sh: $1 or $2 is not an executable" >&2; exit 100; fi
work=${3:-$(mktemp -d)}
mkdir -p "$work"
work=$(realpath "$work")
limit=${CORPUS_TIMEOUT:-600}      # seconds a command may run (a hang reads as exit 124)
start_wall=$(date +%s.%N)

# ---- the jobs ---------------------------------------------------------------------------------
scenes="$work/scenes"
rm -rf "$scenes" "$work/runs" "$work/diffs.txt"
"$py" "$here/corpus_scenes.py" "$scenes" > /dev/null
# The examples: impeller (parametric), impeller_rev (its nominal passes, by OLD, each reversed,
# read as a nominal path), mesh (make_part.py's part and path), mesh_rev (that path reversed).
mkdir -p "$scenes/impeller" "$scenes/impeller_rev" "$scenes/mesh" "$scenes/mesh_rev"
cp "$root/examples/impeller/scene.yaml" "$scenes/impeller/"
"$old" --quiet generate "$scenes/impeller/scene.yaml" --nominal --out "$work/impeller_nominal" \
  > "$work/impeller_nominal.log" 2>&1
"$py" "$here/corpus_scenes.py" --reverse "$work/impeller_nominal/path.cl" "$scenes/impeller_rev/rev.cl"
"$py" "$here/corpus_scenes.py" --unguide "$root/examples/impeller/scene.yaml" "$scenes/impeller_rev/scene.yaml"
cp "$root/examples/mesh_impeller/scene.yaml" "$scenes/mesh/"
"$py" "$root/examples/mesh_impeller/make_part.py" "$scenes/mesh" --no-check > /dev/null
cp "$scenes/mesh/"*.stl "$scenes/mesh/scene.yaml" "$scenes/mesh_rev/"
"$py" "$here/corpus_scenes.py" --reverse "$scenes/mesh/nominal.cl" "$scenes/mesh_rev/nominal.cl"
printf '%s ok\n' impeller impeller_rev mesh mesh_rev >> "$scenes/jobs.txt"

# ---- normalisers ------------------------------------------------------------------------------
# norm_json IN OUT: the JSON without timing keys, sorted, one value a line (diff-able).
norm_json() {
  "$py" - "$1" "$2" <<'EOF'
import json, re, sys
timing = re.compile(r'time|seconds|_s$')
def strip(o):
    if isinstance(o, dict):
        return {k: strip(v) for k, v in o.items() if not timing.search(k)}
    if isinstance(o, list):
        return [strip(v) for v in o]
    return o
with open(sys.argv[2], 'w') as f:
    json.dump(strip(json.load(open(sys.argv[1]))), f, indent=1, sort_keys=True)
    f.write('\n')
EOF
}
# norm_log IN OUT: progress lines (`stage  42.0%  1.6 s`) left out, times masked.
norm_log() {
  sed -E -e '/^[^ ].*[0-9]%[[:space:]]+[0-9.]+ *(ms|s|min)?[[:space:]]*$/d' \
         -e 's/[0-9]+(\.[0-9]+)? ?(ms|s|min)\b/<T> \2/g' "$1" > "$2"
}

# ---- the runs ---------------------------------------------------------------------------------
# run_one BIN DIR SCENE FLAGS...: generate (+ check of its path) in DIR, as DIR/out and DIR/check.
run_one() {
  local bin=$1 d=$2 scene=$3; shift 3
  mkdir -p "$d"
  ( cd "$d"
    local rc=0
    /usr/bin/time -f "%U %S" -o gen.time timeout "$limit" "$bin" generate "$scene" "$@" --out out \
      > gen.stdout 2> gen.stderr || rc=$?
    echo "$rc" > gen.rc
    if [ -f out/path.cl ]; then
      rc=0
      /usr/bin/time -f "%U %S" -o check.time timeout "$limit" "$bin" check "$scene" --path out/path.cl \
        --out check > check.stdout 2> check.stderr || rc=$?
      echo "$rc" > check.rc
    fi )
}
cpu() { [ -f "$1" ] && tail -1 "$1" | awk '{print $1 + $2}' || echo 0; }

# same NAME A B: "same", "DIFF" (its first differing lines to diffs.txt) or "-" (neither has it).
same() {
  local name=$1 a=$2 b=$3
  if [ ! -e "$a" ] && [ ! -e "$b" ]; then echo "-"; return; fi
  if [ -e "$a" ] && [ -e "$b" ] && cmp -s "$a" "$b"; then echo same; return; fi
  { echo "== $job $name"
    if [ -e "$a" ] && [ -e "$b" ]; then
      if LC_ALL=C grep -qI . "$a" 2>/dev/null; then diff "$a" "$b" | head -12 || true
      else cmp "$a" "$b" || true; fi
    else echo "only in $([ -e "$a" ] && echo old || echo new)"; fi
  } >> "$work/diffs.txt"
  echo DIFF
}

mapfile -t lines < "$scenes/jobs.txt"
if [ -n "${CORPUS_JOBS:-}" ]; then
  keep=" $CORPUS_JOBS "; sel=()
  for l in "${lines[@]}"; do [[ $keep == *" ${l%% *} "* ]] && sel+=("$l"); done
  lines=("${sel[@]}")
fi
echo "corpus: $(nproc) cores, $(date -u '+%F %H:%M') UTC, load $(cut -d' ' -f1-3 /proc/loadavg)"
echo "workdir: $work"
echo "old: $old ($("$old" --version 2>&1 | head -1)); new: $new ($("$new" --version 2>&1 | head -1))"
echo
echo "| job | gen rc old | new | check rc old | new | path.cl | path.apt | angles.csv | report.json | stdout | stderr | clearance.csv | deviation.npy | check.json | check stdout | check stderr | CPU s old | new |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
n=0 differ=0 unexpected=()
tot_old=0 tot_new=0
for l in "${lines[@]}"; do
  read -r job expect flags <<< "$l"
  n=$((n + 1))
  d="$work/runs/$job"
  # shellcheck disable=SC2086
  run_one "$old" "$d/old" "$scenes/$job/scene.yaml" $flags
  # shellcheck disable=SC2086
  run_one "$new" "$d/new" "$scenes/$job/scene.yaml" $flags
  for b in old new; do
    [ -f "$d/$b/out/report.json" ] && norm_json "$d/$b/out/report.json" "$d/$b/report.norm"
    [ -f "$d/$b/check/check.json" ] && norm_json "$d/$b/check/check.json" "$d/$b/check.norm"
    for s in gen.stdout gen.stderr check.stdout check.stderr; do
      [ -f "$d/$b/$s" ] && norm_log "$d/$b/$s" "$d/$b/$s.norm"
    done
  done
  o=$d/old n_=$d/new
  gro=$(cat "$o/gen.rc") grn=$(cat "$n_/gen.rc")
  cro=$(cat "$o/check.rc" 2>/dev/null || echo -) crn=$(cat "$n_/check.rc" 2>/dev/null || echo -)
  row="| $job | $gro | $grn | $cro | $crn"
  diff_here=0
  [ "$gro" = "$grn" ] && [ "$cro" = "$crn" ] || diff_here=1
  for pair in "path.cl:out/path.cl" "path.apt:out/path.apt" "angles.csv:out/angles.csv" \
              "report.json:report.norm" "stdout:gen.stdout.norm" "stderr:gen.stderr.norm" \
              "clearance.csv:check/clearance.csv" "deviation.npy:check/deviation.npy" \
              "check.json:check.norm" "check stdout:check.stdout.norm" "check stderr:check.stderr.norm"; do
    r=$(same "${pair%%:*}" "$o/${pair#*:}" "$n_/${pair#*:}")
    [ "$r" = DIFF ] && diff_here=1
    row="$row | $r"
  done
  co=$(awk -v a="$(cpu "$o/gen.time")" -v b="$(cpu "$o/check.time")" 'BEGIN {printf "%.2f", a + b}')
  cn=$(awk -v a="$(cpu "$n_/gen.time")" -v b="$(cpu "$n_/check.time")" 'BEGIN {printf "%.2f", a + b}')
  tot_old=$(awk -v a="$tot_old" -v b="$co" 'BEGIN {print a + b}')
  tot_new=$(awk -v a="$tot_new" -v b="$cn" 'BEGIN {print a + b}')
  echo "$row | $co | $cn |"
  differ=$((differ + diff_here))
  want=0; [ "$expect" = fail ] && want=1
  for b in old new; do
    rc=$(cat "$d/$b/gen.rc")
    [ "$rc" = "$want" ] || unexpected+=("$job: $b generate exit $rc (expected $want): $(head -c 200 "$d/$b/gen.stderr" | head -1)")
    c=$(cat "$d/$b/check.rc" 2>/dev/null || echo 0)
    [ "$c" = 0 ] || unexpected+=("$job: $b check exit $c: $(head -c 200 "$d/$b/check.stderr" | head -1)")
  done
done
end_wall=$(date +%s.%N)
echo
for u in "${unexpected[@]+"${unexpected[@]}"}"; do echo "unexpected: $u"; done
awk -v o="$tot_old" -v n="$tot_new" -v s="$start_wall" -v e="$end_wall" \
  'BEGIN {printf "CPU s (user + system, generate + check): old %.1f, new %.1f (new / old %.2f); wall %.0f s in all\n", o, n, (o > 0 ? n / o : 0), e - s}'
[ -s "$work/diffs.txt" ] && echo "first differing lines: $work/diffs.txt"
echo "corpus: $n jobs, $differ differ"
exit "$differ"
