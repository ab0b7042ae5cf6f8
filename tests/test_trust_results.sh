#!/usr/bin/env bash
# test_trust_results.sh: results that must not depend on how they are sampled
# (issue 23, silent wrong results).  Exit 0 = pass.
#   - angle outputs are unwrapped at every accepted step, then scaled: a wheel
#     turning at 100 rad/s sampled every 0.05 s (5 rad between rows) reads
#     100 t, in radians, in degrees (scale 180/pi) and with scale -1;
#   - Dormand-Prince's dense output: the output grid neither caps nor changes
#     the steps, so the pendulum at a loose tolerance gives the same values at
#     the times two output grids share, to round-off (the steps alone decide
#     the error, ~1e-5 here: a grid that changed the steps would show it);
#   - finite but absurd time spans (--end 1e308, --output-step 1e-300) are
#     refused with the limit named, exit 2, nothing written.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

# 1. the wheel: angle = 100 t
if "$MBCC" run "$root/tests/trust/wheel.yaml" -o wheel.csv --plot none --quiet > wheel.log 2>&1; then
  awk -F, 'NR > 1 { e = 100 * $1; d = e * 57.29577951308232
             if ((($2 - e) ^ 2) > 1e-12 || (($3 - d) ^ 2) > 1e-8 || (($4 + e) ^ 2) > 1e-12) {
               printf "t = %s: angle %s, degrees %s, minus %s; expected %.12g\n", $1, $2, $3, $4, e; bad = 1 } }
           END { exit bad }' wheel.csv || err "wheel angles are not 100 t"
  [ "$(awk -F, '$1 == 0.5 { print $2 }' wheel.csv)" != "" ] || err "no row at t = 0.5"
else
  err "mbcc run wheel.yaml failed: $(tail -3 wheel.log)"
fi

# 2. two output grids, one solution
for h in 0.01 0.025; do
  "$MBCC" run "$root/models/pendulum.yaml" --rtol 1e-5 --atol 1e-7 --end 1 --output-step $h \
    -o "p$h.csv" --plot none --quiet > "p$h.log" 2>&1 || err "pendulum at output step $h failed: $(tail -3 "p$h.log")"
done
if [ -s p0.01.csv ] && [ -s p0.025.csv ]; then
  awk -F, 'NR == FNR { if (FNR > 1) row[sprintf("%.6f", $1)] = $0; next }
           FNR > 1 { k = sprintf("%.6f", $1); if (!(k in row)) next; n++
             split(row[k], a, ","); for (j = 2; j <= NF; j++) { d = a[j] - $j; if (d < 0) d = -d
               s = ($j < 0 ? -$j : $j) + 1; if (d > 1e-9 * s) { printf "t = %s column %d: %s vs %s\n", $1, j, a[j], $j; bad = 1; next } } }
           END { if (n < 20) { print "only " n " shared rows"; bad = 1 } exit bad }' p0.01.csv p0.025.csv ||
    err "the output grid changed the solution"
fi

# 3. absurd time spans
for args in "--end 1e308" "--end 1e300 --output-step 1e-300" "--end 1e12 --output-step 1e5"; do
  # shellcheck disable=SC2086
  "$MBCC" run "$root/models/pendulum.yaml" $args -o span.csv --plot none --quiet > span.log 2>&1
  rc=$?
  [ $rc = 2 ] || err "'$args': exit $rc, expected 2"
  grep -q 'limit\|at most' span.log || err "'$args': the message names no limit: $(cat span.log)"
  [ -e span.csv ] && err "'$args': a CSV was written"
  ls span.csv.* > /dev/null 2>&1 && err "'$args': a temporary file was left"
done
exit $fail
