#!/usr/bin/env bash
# A regression corpus: two builds of fieldpath on the same jobs, outputs compared. The jobs are
# written by corpus_scenes.py beside this script (deterministic; its docstring lists them): single
# passes with corners of 30-150 deg turning away from a wall, into a pocket's inner corner and round
# a boss's apex (sharp, R 2, filleted), 3-D corners on slopes, ramps; CAM finishing jobs (pockets
# 30 deep with corner radii 0 / 3 / 6 by closed offset loops, a boss in a pocket, an L pocket, 5 deg
# draft, a zig-zag raster, a pocket's --nominal path, a corner with --direct); two scenes with
# `on_limit: fail` that must exit 1; both examples with their passes given forwards and reversed
# (as bench/pathgen/ab_jobs.sh); and 4 nominal paths in the other formats path.nominal reads,
# converted from corpus .cl paths by corpus_scenes.py: APT CLDATA as a CAM system posts it (.apt
# with 3-value GOTOs, .cls with 6-value GOTOs over `$` continuations; RAPID between passes, FEDRAT,
# records read past) and .npy (float32 N x 6, float64 N x 7). Each job: `generate` with OLD and
# with NEW (the same flags, each in its own folder), then `check` of each generated path.
# Compared: exit codes; path.cl, path.apt, angles.csv, clearance.csv and deviation.npy byte for
# byte where written; report.json and check.json without their timing keys (names with "time",
# "seconds" or ending "_s"); stdout and stderr with times ("1.6 s") masked and progress lines left
# out. Both binaries run from a folder of the same name (WORKDIR/runs/JOB/{old,new}/ with --out out
# and check's --out check), so file names in messages compare equal.
# Then the other commands, 9 jobs in a second table (inputs the same for both: "the other
# commands" below): `simulate` (--backend cpu, 256 x 256) of the mesh example's and pocket_r6's
# generated paths from --part and from --stock, of the CAM-style APT and of the float64 .npy with
# a flat end; `check` of paths fieldpath did not write (a corner pushed into its wall with
# --fail-unsafe: exit 3; the mesh example's nominal path as CAM-style APT: colliding, exit 0);
# `view` of a simulated surface and of that check; a `study` (--voxels 1,0.5, no brute force) of
# the impeller cut to 3 short passes. Compared: exit codes; heights.npy, heights.json,
# surface.stl, heights.png, clearance.csv, deviation.npy, view.html, lines.csv, tilt.csv and the
# study's error and tilt plots byte for byte; simulate.json and check.json without timing keys
# (nor simulate's speeds and peak memory); study.csv without its time and speedup columns
# (study.md and speed_vs_error.png hold times and the load: not compared); stdout and stderr as
# above, less simulate's time and memory lines and the study table's times.
# Prints a markdown table (one row a job: generate exit codes, check exit codes, each file's
# same / DIFF / - (written by neither), CPU seconds user + system of generate + check), the other
# commands' table (the exit codes of a job's commands, e.g. 3/0 for check then view), and a last
# line `corpus: N jobs, D differ`. Logs and outputs stay in WORKDIR (default: a new mktemp -d);
# WORKDIR/diffs.txt gives the first differing lines of each DIFF.
# 88 jobs: both binaries in 13 min wall, 11 min CPU on the 2-core VM shared at load 6 (2026-12-01),
# the 13 added jobs 1.3 min CPU of it (the 75 before: 6 min wall, 8.5 min CPU idle): about 7 min idle.
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
# The other formats path.nominal reads (DESIGN.md: .cl, APT CLDATA, .npy): a job's nominal.cl
# converted by corpus_scenes.py, the scene otherwise the same. `convert JOB NEW FILE ARGS...`:
# scenes/NEW is scenes/JOB with its path.nominal FILE, corpus_scenes.py ARGS... IN OUT [...] from
# JOB's nominal.cl. The .cl and the APT carry the same values (6 decimals), so NEW's path.cl should
# be JOB's; the .npy in float32 rounds the tips (about 1 um), so not there.
convert() {
  local src=$1 dst=$2 file=$3 how=$4; shift 4
  mkdir -p "$scenes/$dst"
  cp "$scenes/$src/"*.stl "$scenes/$dst/"
  sed "s/nominal: nominal\.cl/nominal: $file/" "$scenes/$src/scene.yaml" > "$scenes/$dst/scene.yaml"
  grep -q "nominal: $file" "$scenes/$dst/scene.yaml" || { echo "corpus.sh: $src/scene.yaml has no nominal.cl" >&2; exit 100; }
  "$py" "$here/corpus_scenes.py" "$how" "$scenes/$src/nominal.cl" "$scenes/$dst/$file" "$@"
  echo "$dst ok" >> "$scenes/jobs.txt"
}
convert pocket_r6 pocket_r6_apt nominal.apt --apt                          # 3-value GOTOs (the axis kept)
convert climb_20_down_90_normal climb_20_down_90_normal_cls nominal.cls --apt  # 6-value GOTOs over $
convert corner_boss_90_round corner_boss_90_round_npy32 nominal.npy --npy f4 6
convert lpocket lpocket_npy64 nominal.npy --npy f8 7                       # 3 passes split by the gaps
# Inputs of the other commands (below), not generate jobs: a path with a deliberate collision (the
# corner's pass pushed 2 mm into the wall's clearance over x -20..-10), the mesh example's nominal
# path as a CAM system posts it (APT, 6 decimals, RAPID between passes; it collides: README), and
# the impeller cut down to a study of seconds.
mkdir -p "$scenes/collide" "$scenes/impeller_small"
# (its nominal.cl too: view, unlike check, refuses a scene whose path.nominal is missing, --path or not)
cp "$scenes/corner_away_90_r0/"*.stl "$scenes/corner_away_90_r0/"{scene.yaml,nominal.cl} "$scenes/collide/"
"$py" "$here/corpus_scenes.py" --shift "$scenes/corner_away_90_r0/nominal.cl" "$scenes/collide/collide.cl" -20 -10 2
"$py" "$here/corpus_scenes.py" --apt "$scenes/mesh/nominal.cl" "$scenes/mesh/nominal_cam.apt"
"$py" "$here/corpus_scenes.py" --small-impeller "$root/examples/impeller/scene.yaml" "$scenes/impeller_small/scene.yaml"

# ---- normalisers ------------------------------------------------------------------------------
# norm_json IN OUT [RE]: the JSON without timing keys (and keys matching RE), sorted, one value a
# line (diff-able).
norm_json() {
  "$py" - "$1" "$2" "${3:-}" <<'EOF'
import json, re, sys
timing = re.compile(r'time|seconds|_s$' + ('|' + sys.argv[3] if sys.argv[3] else ''))
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

# norm_csv IN OUT: the CSV without its timing columns (study.csv: field_s .. total_s, and the
# speedups, ratios of those times).
norm_csv() {
  "$py" - "$1" "$2" <<'EOF'
import csv, re, sys
timing = re.compile(r'time|seconds|_s$|speedup')
rows = list(csv.reader(open(sys.argv[1], newline='')))
keep = [i for i, h in enumerate(rows[0]) if not timing.search(h)] if rows else []
with open(sys.argv[2], 'w', newline='') as f:
    csv.writer(f, lineterminator='\n').writerows([[r[i] for i in keep if i < len(r)] for r in rows])
EOF
}
# norm_other IN OUT: norm_log, and simulate's `time` and `memory` lines (speeds, peak memory) left
# out, its count of culled postures masked (the live tiles' culls depend on the threads' timing,
# the heights do not: 143 against 124 under load, the same binary), study's table with its
# total_s and x_direct columns (times) masked.
norm_other() {
  norm_log "$1" "$2.tmp"
  sed -E -e '/^(time|memory) {2,}/d' -e 's/^(postures +[0-9]+ )\([0-9]+ culled/\1(<N> culled/' \
         -e 's/^((brute force|direct|voxel .*[a-z]) +[0-9]+) +[0-9.]+ +[0-9.]+ /\1 <T> <T> /' "$2.tmp" > "$2"
  rm -f "$2.tmp"
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
      if LC_ALL=C grep -qI . "$a" 2>/dev/null; then diff "$a" "$b" | head -12 | cut -c1-300 || true
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

# ---- the other commands: simulate, check of paths fieldpath did not write, view, study ----------
# Each job: one or more commands run by OLD and by NEW in WORKDIR/runs/JOB/{old,new}/ (outputs in
# sim/, check/, study/, view.html). Their inputs are the same for both: the scenes above and, where
# a generated path is needed, OLD's (runs/JOB/old/out/path.cl of the generate job; generated into
# WORKDIR/inputs/ when CORPUS_JOBS left that job out), so a difference in these rows is the
# command's own, not generate's. simulate runs on --backend cpu (the reference; the GPU's auto
# choice would differ between machines) on a 256 x 256 grid (0.2 s).
# gen_path JOB: OLD's path.cl of the generate job JOB.
gen_path() {
  local p="$work/runs/$1/old/out/path.cl"
  if [ ! -f "$p" ]; then
    p="$work/inputs/$1/path.cl"
    [ -f "$p" ] || "$old" --quiet generate "$scenes/$1/scene.yaml" --out "$work/inputs/$1" \
      > "$work/inputs.$1.log" 2>&1 || true
  fi
  echo "$p"
}
# cmd N ARGS...: $bin ARGS... in the current folder; its exit code appended to `rc`, its output in
# N.stdout / N.stderr, its CPU seconds in N.time.
cmd() {
  local label=$1 rc=0; shift
  /usr/bin/time -f "%U %S" -o "$label.time" timeout "$limit" "$bin" "$@" > "$label.stdout" 2> "$label.stderr" || rc=$?
  printf '%s' "${rc_sep:-}$rc" >> rc; rc_sep=/
}
# other_job JOB: its commands (run in DIR by $bin); the expected exit codes are in other_expect.
declare -A other_expect=(
  [sim_mesh_part]=0 [sim_mesh_stock]=0 [sim_pocket_part]=0 [sim_pocket_stock]=0/0
  [sim_apt]=0 [sim_npy_flat]=0 [check_collide]=3/0 [check_mesh_apt]=0 [study_small]=0)
other_jobs="sim_mesh_part sim_mesh_stock sim_pocket_part sim_pocket_stock sim_apt sim_npy_flat
            check_collide check_mesh_apt study_small"
other_job() {
  local s=$scenes z="--grid 256x256 --backend cpu"
  # shellcheck disable=SC2086
  case $1 in
    # the mesh example's path: from the hub's top (only gouges show) and from a stock plane at 20
    # (above the hub's 18: every pass's cusps)
    sim_mesh_part)  cmd 1 simulate --tool ball:3:40 --path "$mesh_path" --part "$s/mesh/hub.stl" $z --out sim ;;
    sim_mesh_stock) cmd 1 simulate --tool ball:3:40 --path "$mesh_path" --stock 20 $z --out sim ;;
    # pocket_r6's path (links included): from the floor's top, and from 1 mm of stock, then that
    # surface in view (the clearance computed by view itself)
    sim_pocket_part) cmd 1 simulate --tool ball:3:35 --path "$pocket_path" --part "$s/pocket_r6/floor.stl" $z --out sim ;;
    sim_pocket_stock)
      cmd 1 simulate --tool ball:3:35 --path "$pocket_path" --stock 1 $z --out sim
      cmd 2 view "$s/pocket_r6/scene.yaml" --path "$pocket_path" --surface sim --out view.html ;;
    # simulate's own readers: the CAM-style APT, and the float64 N x 7 .npy cut with a flat end
    sim_apt)      cmd 1 simulate --tool ball:3:35 --path "$s/pocket_r6_apt/nominal.apt" --stock 1 $z --out sim ;;
    sim_npy_flat) cmd 1 simulate --tool flat:3:35 --path "$s/lpocket_npy64/nominal.npy" --stock 1 $z --out sim ;;
    # check of a path fieldpath did not write: the deliberate collision (--fail-unsafe: exit 3), in
    # view with that check; the mesh example's nominal path as APT (collides; exit 0, reported)
    check_collide)
      cmd 1 check "$s/collide/scene.yaml" --path "$s/collide/collide.cl" --fail-unsafe --out check
      cmd 2 view "$s/collide/scene.yaml" --path "$s/collide/collide.cl" --check check --out view.html ;;
    check_mesh_apt) cmd 1 check "$s/mesh/scene.yaml" --path "$s/mesh/nominal_cam.apt" --out check ;;
    # study on the cut-down impeller, without the every-point sum (minutes): direct + 2 voxel sizes
    study_small) cmd 1 study "$s/impeller_small/scene.yaml" --voxels 1,0.5 --interp trilinear \
                   --stored force --no-brute-force --out study ;;
  esac
}
others=()
for j in $other_jobs; do
  [ -z "${CORPUS_JOBS:-}" ] || [[ " $CORPUS_JOBS " == *" $j "* ]] && others+=("$j")
done
if [ ${#others[@]} -gt 0 ]; then
  mesh_path=$(gen_path mesh) pocket_path=$(gen_path pocket_r6)
  echo
  echo "| job | rc old | new | heights.npy | heights.json | surface.stl | heights.png | simulate.json | check.json | clearance.csv | deviation.npy | view.html | study.csv | lines.csv | tilt.csv | study png | stdout | stderr | CPU s old | new |"
  echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
fi
for job in "${others[@]+"${others[@]}"}"; do
  n=$((n + 1))
  d="$work/runs/$job"
  for b in old new; do
    mkdir -p "$d/$b"
    bin=$old; [ $b = new ] && bin=$new
    ( cd "$d/$b"; rc_sep=; : > rc; other_job "$job"
      [ -f sim/simulate.json ] && norm_json sim/simulate.json simulate.norm 'per_second|memory|culled'
      [ -f check/check.json ] && norm_json check/check.json check.norm
      [ -f study/study.csv ] && norm_csv study/study.csv study.norm
      # the study's plots of errors and tilts (its speed_vs_error.png plots times: left out)
      [ -f study/tilt_along_path.png ] && cat study/force_error_lines.png study/tilt_along_path.png > study_png.cat
      for x in stdout stderr; do
        for f in [0-9].$x; do norm_other "$f" "$f.norm"; done
        cat [0-9].$x.norm > "$x.norm"
      done )
  done
  o=$d/old n_=$d/new
  ro=$(cat "$o/rc") rn=$(cat "$n_/rc")
  row="| $job | $ro | $rn"
  diff_here=0
  [ "$ro" = "$rn" ] || diff_here=1
  for pair in "heights.npy:sim/heights.npy" "heights.json:sim/heights.json" "surface.stl:sim/surface.stl" \
              "heights.png:sim/heights.png" "simulate.json:simulate.norm" "check.json:check.norm" \
              "clearance.csv:check/clearance.csv" "deviation.npy:check/deviation.npy" "view.html:view.html" \
              "study.csv:study.norm" "lines.csv:study/lines.csv" "tilt.csv:study/tilt.csv" \
              "study png:study_png.cat" "stdout:stdout.norm" "stderr:stderr.norm"; do
    r=$(same "${pair%%:*}" "$o/${pair#*:}" "$n_/${pair#*:}")
    [ "$r" = DIFF ] && diff_here=1
    row="$row | $r"
  done
  co=$(cat "$o"/[0-9].time | awk '{t += $1 + $2} END {printf "%.2f", t}')
  cn=$(cat "$n_"/[0-9].time | awk '{t += $1 + $2} END {printf "%.2f", t}')
  tot_old=$(awk -v a="$tot_old" -v b="$co" 'BEGIN {print a + b}')
  tot_new=$(awk -v a="$tot_new" -v b="$cn" 'BEGIN {print a + b}')
  echo "$row | $co | $cn |"
  differ=$((differ + diff_here))
  for b in old new; do
    rc=$(cat "$d/$b/rc")
    [ "$rc" = "${other_expect[$job]}" ] || unexpected+=("$job: $b exit $rc (expected ${other_expect[$job]}): $(cat "$d/$b"/[0-9].stderr | grep -m1 -v '%' | head -c 200)")
  done
done
end_wall=$(date +%s.%N)
echo
for u in "${unexpected[@]+"${unexpected[@]}"}"; do echo "unexpected: $u"; done
awk -v o="$tot_old" -v n="$tot_new" -v s="$start_wall" -v e="$end_wall" \
  'BEGIN {printf "CPU s (user + system, all commands): old %.1f, new %.1f (new / old %.2f); wall %.0f s in all\n", o, n, (o > 0 ? n / o : 0), e - s}'
[ -s "$work/diffs.txt" ] && echo "first differing lines: $work/diffs.txt"
echo "corpus: $n jobs, $differ differ"
exit "$differ"
