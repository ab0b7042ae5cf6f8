#!/usr/bin/env bash
# test_precision.sh: single and double precision builds of the generated code
# (mbcc run --real float|double), and the integrator options of the simulator.
#   - the rigid slider-crank in float against the closed form
#     x = r cos(theta) + sqrt(L^2 - r^2 sin^2 theta), r = 0.1524 m, L = 0.3048 m:
#     within 2e-5 of the stroke with DOPRI5 and with genalpha (double: 1e-9;
#     the crank is driven, so the positions come from the constraints);
#   - the float build tightens nothing it cannot meet: rtol 1e-8 is raised to
#     1e-5 with a warning;
#   - integrator auto names its choice and the reason; bad option values exit 2;
#   - a fixed step the run cannot afford (RK4, 1e-12 s) stops at once with
#     exit 1, the step count in the message, and no CSV.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

# max |x - closed form| / stroke (2 r) over the run, from columns t, crank_angle, slider_x
closed_form_error() {
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "crank_angle") a = i; if ($i == "slider_x") x = i }; next }
    { r = 0.1524; L = 0.3048; th = $a; s = sin(th)
      e = $x - (r * cos(th) + sqrt(L * L - r * r * s * s)); if (e < 0) e = -e; if (e > m) m = e }
    END { printf "%.3e\n", m / (2 * 0.1524) }' "$1"
}

for real in double float; do
  for integ in dopri5 genalpha; do
    csv=$tmp/sc_${real}_$integ.csv
    if ! "$MBCC" run "$root/models/slider_crank.yaml" --real $real --integrator $integ --rtol 1e-6 \
        -o "$csv" --plot none > "$tmp/run.log" 2>&1; then
      cat "$tmp/run.log"; err "$real $integ run failed"; continue
    fi
    e=$(closed_form_error "$csv")
    echo "  slider-crank, $real, $integ: max |x - closed form| / stroke = $e"
    tol=1e-9; [ $real = float ] && tol=2e-5
    awk -v e="$e" -v t="$tol" 'BEGIN { exit !(e <= t) }' || err "$real $integ: error $e above $tol"
  done
done
grep -q "solver ldl" "$tmp/run.log" || err "the float build did not use the emitted LDL"

"$MBCC" run "$root/models/slider_crank.yaml" --real float --rtol 1e-8 -o "$tmp/f.csv" --plot none > "$tmp/f.log" 2>&1 ||
  err "float run at rtol 1e-8 failed"
grep -q "warning: rtol 1e-08 is below what single precision resolves; using 1e-5" "$tmp/f.log" ||
  err "no warning for rtol 1e-8 in single precision: $(cat "$tmp/f.log")"

"$MBCC" run "$root/tests/models/hinged_flexible_stiff.yaml" --integrator auto --end 0.01 -o "$tmp/a.csv" \
  --plot none > "$tmp/a.log" 2>&1 || err "auto run failed"
grep -q "integrator auto: genalpha: the highest mode (beam, 9652 Hz)" "$tmp/a.log" || err "auto: $(grep auto "$tmp/a.log")"
grep -q "^integrator genalpha" "$tmp/a.log" || err "auto did not run genalpha"
"$MBCC" run "$root/models/pendulum.yaml" --integrator auto --end 0.1 -o "$tmp/p.csv" --plot none > "$tmp/p.log" 2>&1 ||
  err "auto run failed"
grep -q "integrator auto: dopri5: the model has no flexible modes" "$tmp/p.log" || err "auto: $(cat "$tmp/p.log")"

for bad in "--integrator euler" "--rho-inf 1.5" "--real half" "--max-steps -3"; do
  # shellcheck disable=SC2086  # split the option and its value on purpose
  "$MBCC" run "$root/models/pendulum.yaml" $bad -o "$tmp/bad.csv" --plot none > "$tmp/bad.log" 2>&1
  rc=$?
  [ $rc = 2 ] || err "'$bad' exit $rc, expected 2"
  grep -q "error:" "$tmp/bad.log" || err "'$bad': no error message"
  [ -e "$tmp/bad.csv" ] && err "'$bad' wrote a CSV"
done

"$MBCC" run "$root/models/pendulum.yaml" --integrator rk4 --step 1e-12 -o "$tmp/r.csv" --plot none > "$tmp/r.log" 2>&1
rc=$?
[ $rc = 1 ] || err "RK4 at 1e-12: exit $rc, expected 1"
grep -q "error: at t = 0: RK4 with step 1e-12 s needs 5e+12 steps to reach 5 s, more than max_steps 1e+07" "$tmp/r.log" ||
  err "RK4 at 1e-12: $(cat "$tmp/r.log")"
[ -e "$tmp/r.csv" ] && err "RK4 at 1e-12 wrote a CSV"
exit $fail
