#!/usr/bin/env bash
# `fieldpath simulate` timed as a user runs it: a process per run, the path read from a file, the
# outputs written (issue 13). For each seed-000 case asked for, bench_zbuffer --write-cases writes
# the postures as .cl (shortest float text) and .npy (float32); each file is simulated --reps
# times (wall clock of the whole process: median, min and max; peak memory, and the read /
# prepare / cut / write split, from its simulate.json); beside it, the in-process warm kernel time
# of the same case from bench_zbuffer (the analytic tool's column, same backend), the peer. The
# heights of the .cl and the .npy runs must be the same bit for bit (checked, cmp).
#
# usage: bench/zbuffer/process.sh [--bin DIR] [--cases 4,5,6,7,8] [--backend auto|cpu|cuda]
#                                 [--reps 3] [--work DIR] [--outputs npy] [--no-kernel]
#                                 [--taskset CPUS]
#   --bin      where fieldpath and bench_zbuffer are (default build/bin)
#   --work     scratch folder for the path files and outputs (default /tmp/fieldpath-process);
#              the files are written once and kept (case 7 is 928 MB of text)
#   --outputs  simulate's --outputs (default npy: the heights; the STL of a 10000² grid is 10 GB)
#   --taskset  run the processes on these CPUs only (e.g. 0,1: a 2-core machine)
# Prints a markdown table on stdout; logs under WORK/logs.
set -euo pipefail

bin=build/bin cases=4,5,6,7,8 backend=auto reps=3 work=/tmp/fieldpath-process outputs=npy
kernel=1 cpus=
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bin) bin=$2; shift 2 ;;
    --cases) cases=$2; shift 2 ;;
    --backend) backend=$2; shift 2 ;;
    --reps) reps=$2; shift 2 ;;
    --work) work=$2; shift 2 ;;
    --outputs) outputs=$2; shift 2 ;;
    --no-kernel) kernel=0; shift ;;
    --taskset) cpus=$2; shift 2 ;;
    *) echo "process.sh: unknown option '$1' (see the comment at the top)" >&2; exit 1 ;;
  esac
done
fieldpath=$(realpath "$bin/fieldpath")
bench=$(realpath "$bin/bench_zbuffer")
mkdir -p "$work/logs"
pin=()
[[ -n "$cpus" ]] && pin=(taskset -c "$cpus")

# The path files, once.
missing=
for id in ${cases//,/ }; do
  grep -q "^$id " "$work/cases.txt" 2>/dev/null || missing+="${missing:+,}$id"
done
if [[ -n "$missing" ]]; then
  "$bench" --write-cases "$work/new" --cases "$missing" 2>>"$work/logs/write.log"
  mv -f "$work"/new/case*.cl "$work"/new/case*.npy "$work"/
  grep -v '^#' "$work/new/cases.txt" >>"$work/cases.txt"
  rm -rf "$work/new"
fi

# The in-process warm kernel times (bench_zbuffer's "analytic tool ms" column) of the cases.
declare -A kernel_ms
if [[ $kernel == 1 ]]; then
  kb=$backend
  [[ $kb == auto ]] && kb=
  "${pin[@]}" "$bench" ${kb:+--backend $kb} --cases "$cases" --reps "$reps" --peer-limit 2000 >"$work/logs/kernel.md" 2>"$work/logs/kernel.err"
  while IFS='|' read -r _ id _ _ _ _ _ _ _ _ _ _ _ _ _ _ analytic _; do
    id=$(echo $id | cut -d' ' -f1)
    [[ -n "$id" ]] && kernel_ms[$id]=${analytic// /}
  done < <(grep '^| [0-9]' "$work/logs/kernel.md")
fi

# A number from simulate.json: "key": value (the keys asked for are unique in the file).
json_number() { sed -n "s/.*\"$1\": \([0-9.eE+-]*\).*/\1/p" "$2" | head -1; }
median() { sort -g | awk '{v[NR]=$1} END {print v[int((NR+1)/2)]}'; }
range() { sort -g | awk 'NR==1{lo=$1} {hi=$1} END {printf "%s–%s", lo, hi}'; }

echo "| case | postures | grid | input | size MB | process wall s (median of $reps) | min–max s | peak MiB | read s | prepare s | cut s | write s | kernel in process ms | heights .cl = .npy |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
for id in ${cases//,/ }; do
  read -r _ tool region grid postures stock stem < <(grep "^$id " "$work/cases.txt")
  for format in cl npy; do
    file="$work/$stem.$format"
    walls=()
    for ((r = 1; r <= reps; ++r)); do
      out="$work/out-$id-$format"
      rm -rf "$out"
      t0=$(date +%s.%N)
      "${pin[@]}" "$fieldpath" --quiet simulate --tool "$tool" --path "$file" --grid "$grid" \
        --region "$region" --stock "$stock" --backend "$backend" --outputs "$outputs" \
        --out "$out" >"$work/logs/run-$id-$format-$r.txt" 2>&1
      t1=$(date +%s.%N)
      walls+=("$(awk "BEGIN {print $t1 - $t0}")")
    done
    json="$out/simulate.json"
    wall=$(printf '%s\n' "${walls[@]}" | median)
    span=$(printf '%s\n' "${walls[@]}" | range)
    same=
    if [[ $format == npy ]]; then
      cmp -s "$work/out-$id-cl/heights.npy" "$out/heights.npy" && same=yes || same=NO
    fi
    printf '| %s | %s | %s | .%s | %.1f | %.3f | %s | %.0f | %.3f | %.3f | %.3f | %.3f | %s | %s |\n' \
      "$id" "$postures" "$grid" "$format" "$(awk "BEGIN {print $(stat -c %s "$file") / 1e6}")" \
      "$wall" "$span" "$(json_number peak_memory_mib "$json")" "$(json_number read "$json")" \
      "$(json_number prepare "$json")" "$(json_number cut "$json")" \
      "$(json_number write "$json")" "${kernel_ms[$id]:-}" "$same"
  done
done
