#!/usr/bin/env bash
# test_solver_choice.sh: the linear solver, from the model file and the
# command line (exit 0 = pass).
#   - `simulation: {solver: S}` is accepted for every solver the command line
#     knows (ldl, klu, dense), and the generated simulator uses it (its
#     closing statistics name it); the three give the same pendulum to 1e-9;
#   - with no solver named, the generated path uses the emitted LDL^T;
#   - messages do not contradict themselves: the generic path (no emitted
#     LDL^T) refuses `--solver ldl` without listing ldl as a choice, and an
#     unknown solver in the model file lists all three.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

model_with() { # model_with SOLVER-LINE > file: the pendulum with that simulation line added
  sed "s/^simulation:\$/simulation:\\n$1/" "$root/models/pendulum.yaml"
}

for s in ldl klu dense; do
  model_with "  solver: $s" > "p_$s.yaml"
  "$MBCC" run "p_$s.yaml" --end 0.2 -o "$s.csv" --plot none > "$s.log" 2>&1 \
    || { err "solver: $s in the model file: run failed: $(tail -3 "$s.log")"; continue; }
  grep -q "solver $s," "$s.log" || err "solver: $s in the model file, but the run says: $(grep -m1 '^integrator' "$s.log")"
done
for s in klu dense; do
  [ -s ldl.csv ] && [ -s "$s.csv" ] || continue
  out=$(awk -F, 'NR == FNR { a[FNR] = $0; next }
    FNR > 1 { split(a[FNR], x, ","); for (i = 1; i <= NF; i++) { d = x[i] - $i; if (d < 0) d = -d
      if (d > 1e-9 * (1 + (x[i] < 0 ? -x[i] : x[i]))) { print "row " FNR " column " i ": " x[i] " vs " $i; exit } } }' \
    ldl.csv "$s.csv")
  [ -z "$out" ] || err "ldl and $s disagree: $out"
done

# the default: the emitted LDL^T
"$MBCC" run "$root/models/pendulum.yaml" --end 0.2 -o d.csv --plot none > d.log 2>&1 || err "default run failed: $(tail -3 d.log)"
grep -q "solver ldl," d.log || err "the default solver is not ldl: $(grep -m1 '^integrator' d.log)"

# the generic path has no emitted LDL^T: said once, without contradiction
"$MBCC" run "$root/models/pendulum.yaml" --path generic --solver ldl -o g.csv --plot none > g.log 2>&1
rc=$?
[ $rc = 2 ] || err "run --path generic --solver ldl exited $rc, expected 2"
grep -q "expected ldl" g.log && err "the generic path lists ldl as a choice: $(cat g.log)"
grep -q "klu or dense" g.log || err "the generic path's refusal names no alternative: $(cat g.log)"
# ... and a model that asks for ldl (or nothing) still runs there, with KLU
"$MBCC" run p_ldl.yaml --path generic --end 0.2 -o gl.csv --plot none > gl.log 2>&1 || err "generic run of a model with solver: ldl failed: $(tail -3 gl.log)"
grep -q "solver klu," gl.log || err "generic run of solver: ldl: $(grep -m1 '^integrator' gl.log)"

# an unknown solver in the model file lists every one the command line knows
model_with "  solver: lu" > bad.yaml
"$MBCC" check bad.yaml > bad.log 2>&1
rc=$?
[ $rc = 2 ] || err "solver: lu exited $rc, expected 2"
for s in ldl klu dense; do grep -q "$s" bad.log || err "the unknown-solver message does not list $s: $(cat bad.log)"; done
grep -q '^bad.yaml:[0-9]*:[0-9]*: error:' bad.log || err "the unknown-solver message has no file:line:col: $(cat bad.log)"

exit $fail
