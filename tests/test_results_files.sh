#!/usr/bin/env bash
# test_results_files.sh: what `mbcc run` writes (exit 0 = pass).
#   - --precision 17: the pendulum's bob stays on its unit circle,
#     |x^2 + y^2 - 1| < 1e-13 in the CSV itself (12 digits, the default, only
#     resolve ~1e-12: the check fails there), on both paths, with steps small
#     enough (--max-step) that the projected rows are exact to round-off; the default still
#     prints at most 12 significant digits; --precision 0 and 18 are errors;
#   - the units file CSV.units has a row per CSV column, in order, with the
#     unit of the output's kind (s, rad, m, rad/s, J, N, N m; a beam
#     section's forces N, moments N m, a fiber's stress Pa), and a scaled
#     output (scale 1000 on a position) in 0.001 m;
#   - --results DIR puts the CSV, its units and the plot in DIR;
#   - each warning and note is printed once (the four-bar's redundant rows).
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

circle() { awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
  { d = $c["bob_position.x"] ^ 2 + $c["bob_position.y"] ^ 2 - 1; if (d < 0) d = -d; if (d > m) m = d } END { print m + 0 }' "$1"; }
for p in generated generic; do
  "$MBCC" run "$root/models/pendulum.yaml" --path $p --end 0.2 --max-step 1e-3 --precision 17 -o "p17_$p.csv" --plot none --quiet > "$p.log" 2>&1 \
    || { err "--precision 17 ($p) failed: $(tail -3 "$p.log")"; continue; }
  m=$(circle "p17_$p.csv")
  awk -v m="$m" 'BEGIN { exit !(m < 1e-13) }' || err "--precision 17 ($p): |x^2 + y^2 - 1| reaches $m in the CSV"
done
"$MBCC" run "$root/models/pendulum.yaml" --end 0.2 -o p12.csv --plot none --quiet > p12.log 2>&1 || err "default run failed: $(tail -3 p12.log)"
digits=$(tail -n +2 p12.csv | tr ',' '\n' | sed 's/e.*//; s/[-.]//g; s/^0*//' | awk '{ if (length($0) > m) m = length($0) } END { print m }')
[ "$digits" -le 12 ] || err "the default CSV has $digits significant digits, expected at most 12"
for bad in 0 18 x; do
  "$MBCC" run "$root/models/pendulum.yaml" --end 0.2 --precision $bad -o bad.csv --plot none --quiet > bad.log 2>&1
  [ $? = 2 ] || err "--precision $bad was accepted"
  [ -e bad.csv ] && err "--precision $bad wrote a CSV"
done

# units: beside the CSV, a row per column, by kind
if [ -s p12.csv.units ]; then
  cmp -s <(head -1 p12.csv | tr ',' '\n') <(tail -n +2 p12.csv.units | cut -d, -f1) ||
    err "p12.csv.units does not list the CSV's columns in order"
  head -1 p12.csv.units | grep -qx 'column,unit' || err "units header: $(head -1 p12.csv.units)"
  for want in t,s angle,rad bob_position.y,m omega,rad/s energy,J pivot_force.fx,N "pivot_force.tz,N m"; do
    grep -qx "$want" p12.csv.units || err "p12.csv.units lacks '$want'"
  done
else
  err "no units file p12.csv.units"
fi
"$MBCC" run "$root/tests/models/fe/cantilever_section.yaml" --end 0.001 -o cs.csv --plot none --quiet > cs.log 2>&1 ||
  err "cantilever_section run failed: $(tail -3 cs.log)"
for want in root.N,N root.Vz,N "root.T,N m" "root.Mz,N m" "mid_Mz,N m" root_top,Pa; do
  grep -qx "$want" cs.csv.units || err "cs.csv.units lacks '$want'"
done
sed 's/{name: bob_position, type: position, body: bob}/{name: bob_position, type: position, body: bob, scale: 1000}/' \
  "$root/models/pendulum.yaml" > mm.yaml
"$MBCC" run mm.yaml --end 0.1 -o mm.csv --plot none --quiet > mm.log 2>&1 || err "scaled run failed: $(tail -3 mm.log)"
grep -qx 'bob_position.x,0.001 m' mm.csv.units || err "scale 1000 on a position: $(grep bob_position.x mm.csv.units)"

# --results DIR
"$MBCC" run "$root/models/pendulum.yaml" --end 0.1 --results out --quiet > r.log 2>&1 || err "--results failed: $(tail -3 r.log)"
for f in out/pendulum.csv out/pendulum.csv.units out/pendulum.png; do [ -s "$f" ] || err "--results out: no $f"; done
[ -e results ] && err "--results out also wrote results/"

# each warning once
"$MBCC" run "$root/tests/models/four_bar_revolutes.yaml" --end 0.01 -o fb.csv --plot none > fb.log 2>&1 || err "four_bar_revolutes failed: $(tail -3 fb.log)"
grep -q 'warning: redundant' fb.log || err "no redundant-constraint warning for four_bar_revolutes"
dup=$(grep -E 'warning|note' fb.log | sort | uniq -d)
[ -z "$dup" ] || err "printed more than once: $dup"

exit $fail
