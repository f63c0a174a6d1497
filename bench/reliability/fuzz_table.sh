#!/usr/bin/env bash
# Markdown rows from logs of scripts/fuzz.sh runs: bench/reliability/fuzz_table.sh LOG...
# (one log per target, named TARGET.log): inputs run, coverage (libFuzzer's edge counter `cov`),
# features, corpus size, time, peak RSS and findings (crash-/leak-/timeout-/oom- lines).
echo "| target | inputs | cov (edges) | ft | corpus | time s | exec/s | peak RSS MB | findings |"
echo "|---|---|---|---|---|---|---|---|---|"
for log in "$@"; do
  t=$(basename "$log" .log)
  stat() { grep -o "stat::$1: *[0-9]*" "$log" | tail -1 | grep -o '[0-9]*$'; }
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  cov=$(echo "$last" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*')
  ft=$(echo "$last" | grep -o 'ft: [0-9]*' | grep -o '[0-9]*')
  corp=$(echo "$last" | grep -o 'corp: [0-9]*/[0-9]*[a-zA-Z]*' | sed 's/corp: //')
  runs=$(stat number_of_executed_units)
  secs=$(grep -o 'Done [0-9]* runs in [0-9]* second' "$log" | grep -o 'in [0-9]*' | grep -o '[0-9]*')
  findings=$(grep -cE 'Test unit written|ERROR: (AddressSanitizer|LeakSanitizer|UndefinedBehaviorSanitizer|libFuzzer)|runtime error:' "$log")
  echo "| $t | ${runs:-?} | ${cov:-?} | ${ft:-?} | ${corp:-?} | ${secs:-?} | $(stat average_exec_per_sec) | $(stat peak_rss_mb) | $findings |"
done
