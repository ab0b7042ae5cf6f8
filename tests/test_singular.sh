#!/usr/bin/env bash
# test_singular.sh: singular configurations are handled or reported
# (the quick cases of tests/extremes/run.sh):
#   - the slider-crank with rod = crank passes its dead point (theta = pi/2)
#     on the branch x = 2 r cos(theta), to 1e-8 of the stroke;
#   - an output time on the dead point no longer makes a step end there
#     (dense output): the run passes it with a warning that K's condition
#     estimate collapsed near it, or stops exactly there with the note below;
#   - when a step ends exactly on the dead point, DOPRI5 stops there with
#     exit 1, no CSV, and a note that the constraint Jacobian is singular --
#     or, when K's pivot there is at round-off rather than exactly zero, goes
#     on with a warning that K's condition estimate fell below 1e-12 there;
#   - RK4 with a stage on the dead point stops there, and the note describes
#     the failing stage's state (not the step's start, where D is regular);
#   - RK4 at twice a 10 kHz beam's stability limit stops with a note that
#     the integration blew up, not that the configuration is singular;
#   - the parallelogram four-bar passes its change point (t = 0.25 s) as a
#     parallelogram with KLU and warns that K's condition estimate collapsed
#     there; with the default emitted LDL^T (static pivots) it passes too or
#     stops at 0.25 s with the singular-configuration note.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
X=$root/tests/extremes/models

"$MBCC" run "$X/slider_crank_equal.yaml" -o "$tmp/a.csv" --plot none > "$tmp/a.log" 2>&1 || err "dead point run: $(cat "$tmp/a.log")"
e=$(awk -F, 'NR > 1 { d = $3 - 2 * 0.1524 * cos($2); if (d < 0) d = -d; if (d > m) m = d } END { printf "%.2e", m / 0.3048 }' "$tmp/a.csv")
echo "  slider-crank r = L through the dead point: x vs 2 r cos(theta) $e of the stroke"
awk -v e="$e" 'BEGIN { exit !(e <= 1e-8) }' || err "branch error $e"

h=$(awk 'BEGIN { printf "%.17g", atan2(1, 0) / 124.8 / 100 }')
# an output row exactly on the dead point: its state is projected there, where
# D is singular.  Either the run goes through with the near-singular warning,
# or it stops at the dead point with the singular-configuration note; never a
# silent pass, never a stop elsewhere
if "$MBCC" run "$X/slider_crank_equal.yaml" --output-step "$h" -o "$tmp/g.csv" --plot none > "$tmp/g.log" 2>&1; then
  grep -q "warning: near t = 0.01258650.* the condition estimate of K fell" "$tmp/g.log" ||
    err "output grid on the dead point: no near-singular warning: $(cat "$tmp/g.log")"
else
  grep -q "error: at t = 0.01258650" "$tmp/g.log" &&
    grep -q "note: at t = 0.01258650.* the constraint Jacobian is nearly singular" "$tmp/g.log" ||
    err "output grid on the dead point: stopped without the dead-point error and note: $(cat "$tmp/g.log")"
fi
end=$(awk 'BEGIN { printf "%.17g", atan2(1, 0) / 124.8 }')
"$MBCC" run "$X/slider_crank_equal.yaml" --end "$end" --output-step "$h" -o "$tmp/b.csv" --plot none > "$tmp/b.log" 2>&1
rc=$?
# Whether K's pivot at the dead point comes out exactly zero (a stop) or at
# round-off (the run goes on, warned) depends on the last bits of the
# assembled initial state; either way the dead point must be named.
if [ $rc = 1 ]; then
  [ -e "$tmp/b.csv" ] && err "step on the dead point: a CSV was written"
  grep -q "error: at t = 0.01258650" "$tmp/b.log" || err "no error at the dead point: $(cat "$tmp/b.log")"
  grep -q "note: at t = 0.01258650.* the constraint Jacobian is nearly singular" "$tmp/b.log" ||
    err "no singular-configuration note: $(cat "$tmp/b.log")"
  grep "_sim: \(error\|note\)" "$tmp/b.log" | sed 's/^[^ ]*_sim: /  /'
elif [ $rc = 0 ]; then
  w=$(grep -o "warning: near t = 0.01258650[0-9]* the condition estimate of K fell to [0-9.e+-]*" "$tmp/b.log")
  [ -n "$w" ] || err "step on the dead point: neither a stop nor a near-singular warning there: $(cat "$tmp/b.log")"
  awk -v c="${w##* }" 'BEGIN { exit !(c < 1e-12) }' || err "condition estimate at the dead point only fell to ${w##* }"
  echo "  $w"
else
  err "step on the dead point: exit $rc, expected 1 (stop) or 0 (warned)"
fi

# RK4's steps end on the output grid: a stage at the dead point, whose
# factorization of K fails there.  The note must describe that stage's state,
# not the step's start 1e-5 s earlier, where D is still regular (4.9e-5)
"$MBCC" run "$X/slider_crank_equal.yaml" --integrator rk4 --step 1e-5 --output-step "$h" -o "$tmp/r.csv" --plot none > "$tmp/r.log" 2>&1
rc=$?
if [ $rc = 0 ]; then
  e=$(awk -F, 'NR > 1 { d = $3 - 2 * 0.1524 * cos($2); if (d < 0) d = -d; if (d > m) m = d } END { printf "%.2e", m / 0.3048 }' "$tmp/r.csv")
  awk -v e="$e" 'BEGIN { exit !(e <= 1e-8) }' || err "rk4 through the dead point: branch error $e"
else
  [ $rc = 1 ] || err "rk4 at the dead point: exit $rc, expected 0 or 1"
  grep -q "error: at t = 0.01258650" "$tmp/r.log" &&
    grep -q "note: at t = 0.01258650[0-9]* (the state it failed at) the constraint Jacobian is nearly singular" "$tmp/r.log" ||
    err "rk4 at the dead point: no stop there with the note on the failing stage: $(cat "$tmp/r.log")"
  grep "_sim: note" "$tmp/r.log" | sed 's/^[^ ]*_sim: /  rk4: /'
fi

# an explicit step twice the stability limit of a 10 kHz mode blows up; the
# stop must say so, not blame a singular configuration (the blown-up state's
# D is as singular as a dead point's)
"$MBCC" run "$X/beam_10khz.yaml" --integrator rk4 --step 1e-4 --end 0.05 -o "$tmp/u.csv" --plot none > "$tmp/u.log" 2>&1
rc=$?
[ $rc = 1 ] || err "rk4 above the stability limit: exit $rc, expected 1: $(cat "$tmp/u.log")"
[ -e "$tmp/u.csv" ] && err "rk4 above the stability limit: a CSV was written"
grep -q "note: by t = .* the velocities had grown to .*: the integration blew up" "$tmp/u.log" ||
  err "rk4 above the stability limit: no blow-up note: $(cat "$tmp/u.log")"
grep -q "singular configuration (dead point" "$tmp/u.log" && err "rk4 above the stability limit: blamed on a singular configuration"
grep "_sim: note" "$tmp/u.log" | sed 's/^[^ ]*_sim: /  rk4 1e-4 s on a 10 kHz beam: /' | cut -c1-160

# KLU's run-time pivoting carries the parallelogram through the change point
"$MBCC" run "$X/four_bar_change.yaml" --solver klu -o "$tmp/c.csv" --plot none > "$tmp/c.log" 2>&1 || err "change point run: $(cat "$tmp/c.log")"
e=$(awk -F, 'NR > 1 { d = $3 - $2; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.2e", m }' "$tmp/c.csv")
echo "  parallelogram four-bar through its change point: |rocker - crank| $e rad"
awk -v e="$e" 'BEGIN { exit !(e <= 1e-8) }' || err "parallelogram error $e"
grep -q "warning: near t = 0.25 the condition estimate of K fell" "$tmp/c.log" || err "no near-singular warning: $(cat "$tmp/c.log")"
# the emitted LDL^T (the default) has its pivots fixed at compile time: it
# passes as well, or stops at 0.25 s with the singular-configuration note
"$MBCC" run "$X/four_bar_change.yaml" -o "$tmp/d.csv" --plot none > "$tmp/d.log" 2>&1
rc=$?
if [ $rc = 0 ]; then
  e=$(awk -F, 'NR > 1 { d = $3 - $2; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.2e", m }' "$tmp/d.csv")
  awk -v e="$e" 'BEGIN { exit !(e <= 1e-8) }' || err "ldl through the change point: parallelogram error $e"
else
  [ $rc = 1 ] || err "ldl at the change point: exit $rc, expected 0 or 1"
  [ -e "$tmp/d.csv" ] && err "ldl stopped at the change point but wrote a CSV"
  grep -Eq "error: at t = 0\.(2499|25[;:])" "$tmp/d.log" &&
    grep -Eq "note: at t = 0\.(2499|25 ).* nearly singular" "$tmp/d.log" ||
    err "ldl at the change point: no stop at 0.25 s with the note: $(cat "$tmp/d.log")"
  echo "  the default (emitted ldl) stops at the change point with the note"
fi
exit $fail
