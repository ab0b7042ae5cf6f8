#!/usr/bin/env bash
# run.sh B SECONDS: runs B/fuzz_front (make fuzz) for SECONDS on a corpus in
# B/corpus seeded with the repository's models, bad models and fuzz
# regressions; prints one line "fuzz: ..." with the executions and findings
# (also written to B/fuzz-summary.txt for docs/reliability.md).  A finding
# (crash, leak, timeout, sanitizer report) is copied to tests/fuzz_regressions/
# to be committed with its fix; the exit status is then 1.
set -u
cd "$(dirname "$0")/../.."
B=${1:?usage: run.sh BUILD_DIR SECONDS}
secs=${2:-60}
mkdir -p "$B/corpus" "$B/artifacts"
log="$B/fuzz.log"
# -close_fd_mask=2: the models' error messages would drown the log
ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
  "$B/fuzz_front" -max_total_time="$secs" -dict=tests/fuzz/yaml.dict -timeout=10 \
  -rss_limit_mb=2048 -max_len=4096 -close_fd_mask=2 -print_final_stats=1 \
  -artifact_prefix="$B/artifacts/" "$B/corpus" models tests/models tests/bad_models \
  tests/fuzz_regressions > "$log" 2>&1
rc=$?
execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
corpus=$(ls "$B/corpus" | wc -l)
cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 | cut -d' ' -f2)
found=0
for a in "$B"/artifacts/*; do
  [ -e "$a" ] || continue
  found=$((found + 1))
  cp "$a" "tests/fuzz_regressions/$(basename "$a").yaml"
done
line="fuzz: ${execs:-0} executions in $secs s, coverage ${cov:-0} edges, corpus $corpus inputs, $found findings"
echo "$line" | tee "$B/fuzz-summary.txt"
if [ "$rc" != 0 ] || [ "$found" != 0 ]; then
  grep -A30 -m1 'ERROR\|==ERROR\|runtime error\|Timeout\|out-of-memory' "$log" | head -40
  echo "fuzz: FAILED (exit $rc); the input is in tests/fuzz_regressions/ (and $B/artifacts/)"
  exit 1
fi
