#!/usr/bin/env bash
# test_bench.sh: `mbcc bench` end to end (exit 0 = pass), on a short run of
# the slider-crank (0.01 s, one repetition):
#   - the CSV has the columns path,n,nnz_K,nnz_L,step_median_s,run_s,ratio,
#     steps,max_rel_diff (then step_ratio,status) and one row per path;
#   - every path that ran (ldl may be absent: "skipped") reports steps and
#     times, the fastest run has ratio 1, the paths with the same integrator
#     agree to 1e-9 of each output's range and IDA to 1e-5;
#   - at rtol 1e-12 (both integrators' own errors far below 1e-9), IDA and the
#     Dormand-Prince path agree to 1e-9 on the position outputs
#     (max_rel_diff_positions) over 0.05 s;
#   - IDA at rtol 1e-13 converges on the flexible slider-crank and agrees there;
#   - --paths selects paths; bad options exit with status 2.
# Runs mbcc from a scratch directory, so that nothing lands in the source tree.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

model="$root/models/slider_crank.yaml"
if "$MBCC" bench "$model" --end 0.01 --reps 1 --csv b.csv --quiet > bench.txt 2> bench.log; then
  head -1 b.csv | grep -q '^path,n,nnz_K,nnz_L,step_median_s,run_s,ratio,steps,max_rel_diff' ||
    err "CSV header: $(head -1 b.csv)"
  rows=$(($(wc -l < b.csv) - 1))
  [ "$rows" = 7 ] || err "CSV has $rows rows, expected 7"
  for p in generated+ldl generated+klu generated+dense generic+klu generic+dense ida ida+klu; do
    grep -q "^$p," b.csv || err "no row for path $p"
  done
  awk -F, 'NR > 1 {
      if ($11 == "skipped") { if ($1 != "generated+ldl") { print "path " $1 " skipped"; bad = 1 } next }
      if ($11 != "ok") { print "path " $1 ": " $11; bad = 1; next }
      if (!($8 > 0) || !($5 > 0) || !($6 > 0)) { print "path " $1 ": no steps or times"; bad = 1 }
      if ($7 < 0.999) { print "path " $1 ": ratio " $7 " below 1"; bad = 1 }
      if ($7 < 1.0001) one = 1
      tol = ($1 ~ /^ida/) ? 1e-5 : 1e-9
      if (!($9 <= tol)) { print "path " $1 ": max_rel_diff " $9 " above " tol; bad = 1 }
      if ($2 != (($1 ~ /^ida/) ? 57 : 36)) { print "path " $1 ": n = " $2; bad = 1 }
    }
    END { if (!one) { print "no path with ratio 1"; bad = 1 } exit bad }' b.csv > check.log ||
    err "$(cat check.log)"
  grep -q '^generated+klu ' bench.txt || err "no table on stdout: $(head -5 bench.txt)"
else
  err "mbcc bench failed: $(tail -5 bench.log)"
fi

# --paths
if "$MBCC" bench "$model" --end 0.005 --reps 1 --paths generated+klu,ida --csv p.csv --quiet > /dev/null 2>&1; then
  [ "$(cut -d, -f1 p.csv | tr '\n' ' ')" = "path generated+klu ida " ] || err "--paths: $(cut -d, -f1 p.csv | tr '\n' ' ')"
else
  err "mbcc bench --paths failed"
fi

# agreement on positions at tight tolerances, and --ida-rtol
if "$MBCC" bench "$model" --end 0.05 --reps 1 --paths generated+klu,ida --rtol 1e-12 --atol 1e-14 \
    --csv t.csv --quiet > tight.txt 2>&1; then
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; if (!c["max_rel_diff_positions"]) { print "no positions column"; exit 1 } next }
    $c["path"] == "ida" { seen = 1; if (!($c["max_rel_diff_positions"] <= 1e-9)) { print "ida positions " $c["max_rel_diff_positions"]; exit 1 } }
    END { if (!seen) { print "no ida row"; exit 1 } }' t.csv > tight.log || err "tight tolerances: $(cat tight.log)"
else
  err "mbcc bench at rtol 1e-12 failed: $(tail -5 tight.txt)"
fi
# IDA at rtol 1e-13 on the flexible slider-crank: its multipliers' Newton weights
# (runtime/hosted/ida.c, set_tolerances) let it converge where atol alone made it fail at
# t = 0.0024; it agrees on positions, and the CSV names the worst position output
flex="$root/models/slider_crank_flexible.yaml"
if "$MBCC" bench "$flex" --end 0.01 --reps 1 --paths generated+ldl,ida --rtol 1e-12 --atol 1e-14 \
    --ida-rtol 1e-13 --csv f.csv --quiet > flex.txt 2>&1; then
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    $c["path"] == "ida" { seen = 1
      if ($c["status"] != "ok") { print "ida " $c["status"]; exit 1 }
      if (!($c["max_rel_diff_positions"] <= 1e-9)) { print "ida positions " $c["max_rel_diff_positions"]; exit 1 }
      if ($c["worst_output_positions"] !~ /^(crank_angle|slider_x|midspan)$/) { print "worst position output \"" $c["worst_output_positions"] "\""; exit 1 } }
    END { if (!seen) { print "no ida row"; exit 1 } }' f.csv > flex.log || err "ida at rtol 1e-13: $(cat flex.log) $(cat flex.txt)"
else
  err "mbcc bench with --ida-rtol 1e-13 failed: $(tail -5 flex.txt)"
fi
"$MBCC" bench "$model" --end 0.005 --reps 1 --paths ida --ida-rtol 1e-10 --quiet > ir.txt 2>&1 &&
  grep -q '^ida: rtol 1e-10, atol 1e-12' ir.txt || err "--ida-rtol: $(head -3 ir.txt)"

# bad options
"$MBCC" bench "$model" --reps 0 --quiet > /dev/null 2>&1
[ $? = 2 ] || err "--reps 0 did not exit with status 2"
"$MBCC" bench "$model" --paths generated+foo --quiet > /dev/null 2>&1
[ $? = 2 ] || err "--paths generated+foo did not exit with status 2"
"$MBCC" bench "$model" --ida-rtol 0 --quiet > /dev/null 2>&1
[ $? = 2 ] || err "--ida-rtol 0 did not exit with status 2"
exit $fail
