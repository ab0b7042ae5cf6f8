#!/usr/bin/env bash
# test_assembly_scale.sh: the assembly analysis is sparse.  `mbcc check` of a
# 500-link pendulum chain (scripts/chain.sh; n = 5500) finds the whole chain
# free (500 degrees of freedom, 2500 rows, none redundant) within 5 s of CPU
# (the dense factorizations it replaced took ~3 s at 200 links and grew
# cubically: ~45 s here); and it is near linear: 500 links cost at most
# 8 times as much CPU as 100 links (5x the size; cubic would be 125x), once
# both are above the clock's resolution.  And 100 separate planar four-bars of
# four revolutes in one model: each loop's last joint gives up its 3
# out-of-plane rows (300 redundant rows, 100 degrees of freedom), and each
# dependency note names the three other joints of its own loop, no other.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

cpu_of_check() { # N: user+system CPU seconds of mbcc check on an N-link chain
  bash "$root/scripts/chain.sh" "$1" > "chain$1.yaml"
  local TIMEFORMAT='%3U %3S'
  { time "$MBCC" check "chain$1.yaml" > "check$1.txt" 2> "check$1.err"; } 2> "time$1.txt" ||
    err "mbcc check of the $1-link chain failed: $(cat "check$1.err")"
  awk '{ print $1 + $2 }' "time$1.txt"
}
c100=$(cpu_of_check 100)
c500=$(cpu_of_check 500)
grep -q "constraint rows   2500 (0 redundant removed)" check500.txt || err "rows: $(grep 'constraint rows' check500.txt)"
grep -q "degrees of freedom 500$" check500.txt || err "dof: $(grep 'degrees of freedom' check500.txt)"
echo "  mbcc check CPU: 100 links $c100 s, 500 links $c500 s"
awk -v c="$c500" 'BEGIN { exit !(c < 5) }' || err "500-link chain took $c500 s of CPU (limit 5 s)"
awk -v a="$c100" -v b="$c500" 'BEGIN { exit !(b < 0.2 || b <= 8 * a) }' ||
  err "not near linear: 100 links $c100 s, 500 links $c500 s"

awk -v n=100 'BEGIN {
  print "name: four_bars"; print "gravity: [0, -9.81, 0]"; print "bodies:"
  for (k = 1; k <= n; k++) {
    printf "  crank%d: {type: rigid, mass: 0.5, inertia: [1.0e-4, 4.2e-4, 4.2e-4], position: [0.05, 0, %d], angular_velocity: [0, 0, 2.0], velocity: [0, 0.1, 0]}\n", k, k
    printf "  coupler%d: {type: rigid, mass: 1.0, inertia: [1.0e-4, 7.5e-3, 7.5e-3], position: [0.184375, 0.12401959270615269, %d]}\n", k, k
    printf "  rocker%d: {type: rigid, mass: 0.8, inertia: [1.0e-4, 4.2e-3, 4.2e-3], position: [0.284375, 0.12401959270615269, %d]}\n", k, k
  }
  print "joints:"
  for (k = 1; k <= n; k++) {
    printf "  crank_pivot%d: {type: revolute, bodies: [ground, crank%d], point: [0, 0, %d], axis: [0, 0, 1]}\n", k, k, k
    printf "  crank_pin%d: {type: revolute, bodies: [crank%d, coupler%d], point: [0.1, 0, %d], axis: [0, 0, 1]}\n", k, k, k, k
    printf "  rocker_pin%d: {type: revolute, bodies: [coupler%d, rocker%d], point: [0.26875, 0.24803918541230538, %d], axis: [0, 0, 1]}\n", k, k, k, k
    printf "  rocker_pivot%d: {type: revolute, bodies: [rocker%d, ground], point: [0.3, 0, %d], axis: [0, 0, 1]}\n", k, k, k
  }
  print "simulation: {end_time: 0.1, output_step: 0.01}"
}' > four_bars.yaml
"$MBCC" check four_bars.yaml > bars.txt 2> bars.err || err "mbcc check of 100 four-bars failed: $(head -3 bars.err)"
grep -q "constraint rows   1700 (300 redundant removed)" bars.txt || err "four-bars rows: $(grep 'constraint rows' bars.txt)"
grep -q "degrees of freedom 100$" bars.txt || err "four-bars dof: $(grep 'degrees of freedom' bars.txt)"
removed=$(grep -c "warning: redundant constraint removed: revolute 'rocker_pivot[0-9]*'" bars.err)
[ "$removed" = 300 ] || err "four-bars: $removed rocker_pivot rows removed, expected 300: $(grep -m3 warning bars.err | grep -v rocker_pivot)"
own=$(awk '/warning: redundant constraint removed/ { match($0, /rocker_pivot[0-9]+/); k = substr($0, RSTART + 12, RLENGTH - 12); next }
  /note: it is a combination of rows of/ {
    want = "revolute \x27crank_pivot" k "\x27, revolute \x27crank_pin" k "\x27, revolute \x27rocker_pin" k "\x27"
    if (substr($0, length($0) - length(want) + 1) == want && index($0, "of " want)) ok++ }
  END { print ok + 0 }' bars.err)
# a loop's three removed rows share one note, printed once (diag shows a
# message it has already shown only once): one note per loop
[ "$own" = 100 ] || err "four-bars: $own of 100 dependency notes name exactly their own loop's joints"
echo "  100 four-bars: 300 redundant rows, each from its own loop"
exit $fail
