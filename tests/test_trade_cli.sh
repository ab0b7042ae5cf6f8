#!/usr/bin/env bash
# test_trade_cli.sh: `mbcc trade` on the command line (exit 0 = pass):
#   - bad input (unknown output, unknown scene, bad numbers, unknown values,
#     unknown option) is an "error:" with exit status 2 and leaves no CSV;
#   - an integrator the simulator does not know (as genalpha before it is
#     merged) gives runs reported failed (failed = 1, empty errors, a reason,
#     never on the front) while the study completes with exit 0; so does a
#     single-precision build while there is none;
#   - the CSV has one row per run with the documented columns, at least one
#     run on the front, and the plot is written;
#   - by default only outputs that vary are compared: on the pendulum the
#     constants (bob_position.z, the out-of-plane reaction) and the conserved
#     total energy are left out with the reason, and the reference's own
#     error is then small (it was 0.93 with the energy in); --outputs energy
#     still compares it when asked.
# Runs in a scratch directory.  Environment: MBCC (default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
pend="$root/models/pendulum.yaml"

# 1. bad input: exit 2, an error message, no CSV
bad() {
  "$MBCC" trade "$@" --csv "$tmp/bad.csv" --workdir "$tmp/w" --quiet >out.txt 2>err.txt
  st=$?
  [ $st = 2 ] || err "mbcc trade $* exited $st, expected 2"
  grep -q "error:" err.txt || err "mbcc trade $*: no 'error:' message ($(cat err.txt))"
  [ ! -e "$tmp/bad.csv" ] || err "mbcc trade $*: wrote a CSV"
  rm -f "$tmp/bad.csv"
}
bad "$pend" --outputs angle,nosuch
bad "$pend" --scene nosuch
bad "$pend" --reps 0
bad "$pend" --reps 2.5
bad "$pend" --end -1
bad "$pend" --max-error abc
bad "$pend" --integrators dopri5
bad "$pend" --integrators dopri5@x
bad "$pend" --solvers ldl,lu
bad "$pend" --couplings stiff
bad "$pend" --modes two
bad "$pend" --frobnicate 1
bad "$root/models/nosuch.yaml"

# 2. failures are rows, not aborts
if "$MBCC" trade "$pend" --outputs angle,omega --end 1 --reps 1 --integrators rk4@0.01,dopri5@1e-6,nosuch@1e-6 \
    --solvers ldl --reals double,float --csv "$tmp/t.csv" --workdir "$tmp/w" --max-error 1e-3 --quiet >out.txt 2>err.txt; then
  head -1 t.csv | grep -q '^run,variant,modes,coupling,joints,real,integrator,step,rtol,solver,cpu_s,max_err,rms_err,failed,pareto,note$' \
    || err "CSV header: $(head -1 t.csv)"
  rows=$(($(wc -l <t.csv) - 1))
  [ "$rows" = 6 ] || err "expected 6 runs (3 integrators x double, float), got $rows"
  awk -F, 'NR > 1 && $7 == "nosuch" && !($14 == 1 && $12 == "" && $15 == 0) { bad = 1 } END { exit bad }' t.csv \
    || err "the unknown integrator's runs are not failed rows without errors"
  # float runs fail while there is no single-precision build, and succeed after: either way
  # a failed row has no errors, a reason, and is not on the front
  awk -F, 'NR > 1 && $14 == 1 && !($11 == "" && $12 == "" && $13 == "" && $15 == 0 && $16 != "") { bad = 1 }
           NR > 1 && $14 == 0 && !($11 > 0 && $12 != "" && $13 != "") { bad = 1 } END { exit bad }' t.csv \
    || err "a failed row with errors or without a reason, or a successful row without errors"
  awk -F, 'NR > 1 && $6 == "double" && $7 != "nosuch" && !($14 == 0 && $12 != "" && $11 > 0) { bad = 1 } END { exit bad }' t.csv \
    || err "the rk4 and dopri5 runs did not succeed"
  [ "$(awk -F, 'NR > 1 && $15 == 1' t.csv | wc -l)" -ge 1 ] || err "no run on the Pareto front"
  grep -q '^reference error: max_err ' out.txt || err "no reference error line"
  grep -q '^max_err <= 0.001: cheapest is run ' out.txt || err "no cheapest run for 1e-3: $(cat out.txt)"
  [ -s t.png ] || err "no plot t.png"
else
  err "mbcc trade with failing runs exited $?: $(tail -5 err.txt)"
fi
# 3. only outputs that vary, by default
if "$MBCC" trade "$pend" --end 0.5 --reps 1 --integrators rk4@1e-3 --solvers ldl --reals double --plot none \
    --workdir "$tmp/w3" > out3.txt 2> err3.txt; then
  for o in bob_position.z pivot_force.fz pivot_force.tz; do
    grep -q "^  $o (constant)" out3.txt || err "the constant $o is not reported left out: $(head -12 out3.txt)"
  done
  grep -q '^  energy (conserved: ' out3.txt || err "the conserved energy is not reported left out: $(head -12 out3.txt)"
  grep -q '^  angle ' out3.txt && err "the angle (it varies) was left out"
  grep -q '^model pendulum: 8 outputs compared' out3.txt || err "expected 8 outputs compared: $(grep '^model' out3.txt)"
  awk '/^reference error: max_err/ { found = 1; if (!($4 + 0 < 1e-6)) bad = 1 } END { exit !(found && !bad) }' out3.txt ||
    err "the reference's own error without the flat outputs: $(grep '^reference error' out3.txt)"
else
  err "mbcc trade (default outputs) exited $?: $(tail -5 err3.txt)"
fi
"$MBCC" trade "$pend" --outputs angle,energy --end 0.5 --reps 1 --integrators rk4@1e-3 --solvers ldl --reals double \
  --plot none --workdir "$tmp/w4" > out4.txt 2> err4.txt || err "mbcc trade --outputs angle,energy exited $?"
grep -q '^model pendulum: 2 outputs compared' out4.txt || err "--outputs angle,energy: $(grep '^model' out4.txt)"
grep -q 'left out' out4.txt && err "--outputs named explicitly, yet some were left out"
exit $fail
