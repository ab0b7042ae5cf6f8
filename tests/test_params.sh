#!/usr/bin/env bash
# test_params.sh: parameters and expressions (docs/model-format.md, Parameters).
#   1. expression values: precedence, associativity, unary minus, functions,
#      parameters defined through later ones, against hand-computed numbers
#      (mbcc check lists each parameter's value);
#   2. a model written with expressions emits the same C as the same model
#      written with the numbers (only the input hash in the header differs);
#   3. run-time parameters: `mbcc run --set k=900` (the simulator sets it, no
#      recompilation: the emitted code is the same as without --set) gives
#      the same CSV, byte for byte, as the model recompiled with k: 900 in the
#      file; the generic path with --set agrees with the generated one; the
#      motion matches the closed form x0 + pull cos(sqrt(k/m) t);
#   4. errors: --set of an unknown or compile-time parameter, of a value
#      outside its range, on mbcc run and on the generated simulator: exit 2;
#   5. a --set value that breaks the rule of the field it sets (a negative
#      stiffness or free length): exit 2 from mbcc run and from the generated
#      simulator, with the field's file:line:col and rule; the bound 0 passes.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

# 1. values
cat > values.yaml <<'YAML'
name: values
parameters:
  p7: p1 * p5                       # defined before the parameters it uses
  p1: 2 + 3 * 4 ^ 2 / 8 - -1        # 2 + 48/8 + 1 = 9
  p2: -2^2                          # -(2^2) = -4
  p3: 2^3^2                         # 2^(3^2) = 512
  p4: sqrt(16) + atan2(1, 1) * 4 / pi + abs(-3) + min(2, 5) + max(2, 5) + exp(0) + log(exp(2))  # 4+1+3+2+5+1+2 = 18
  p5: (1 + 2) * 3                   # 9
  p6: "cos(0) + sin(0) + tan(0) - 10 / 4 / 5"   # 1 - 0.5 = 0.5
  p8: {value: "2 * p2", unit: m}    # -8
bodies:
  b: {type: rigid, mass: p6 * 4, inertia: [1, 1, 1]}
YAML
if "$MBCC" check values.yaml > values.out 2>&1; then
  for expect in "p7 81" "p1 9" "p2 -4" "p3 512" "p4 18" "p5 9" "p6 0.5" "p8 -8 m"; do
    name=${expect%% *}
    got=$(awk -v n="$name" '$1 == n { v = $2; if ($3 == "m") v = v " m"; print n " " v }' values.out)
    [ "$got" = "$expect" ] || err "parameter $name: got '$got', expected '$expect'"
  done
else
  err "mbcc check values.yaml failed: $(cat values.out)"
fi

# 2. expressions emit what the numbers emit (the parameters block last, so
#    that every element keeps its line)
cat > numbers.yaml <<'YAML'
name: twin
gravity: [0, 0, -9.81]
bodies:
  arm:
    type: rigid
    mass: 3.0
    inertia: [0.02, 0.5, 0.5]
    position: [0.6, 0, 0]
joints:
  hinge:
    type: revolute
    bodies: [ground, arm]
    point: [0, 0, 0]
    axis: [0, 1, 0]
forces:
  holder:
    type: spring_damper
    bodies: [ground, arm]
    points: [[1.2, 0, 0.8], [1.2, 0, 0]]
    stiffness: 1500
    damping: 12
outputs:
  - {name: tip_z, type: position, body: arm, point: [1.2, 0, 0], component: z}
YAML
cat > expressions.yaml <<'YAML'
name: twin
gravity: [0, 0, -g]
bodies:
  arm:
    type: rigid
    mass: rho * length * area
    inertia: [0.02, mass_arm * length^2 / 12 + 0.14, "mass_arm * length ^ 2 / 12 + 0.14"]
    position: [length / 2, 0, 0]
joints:
  hinge:
    type: revolute
    bodies: [ground, arm]
    point: [0, 0, 0]
    axis: [0, 1, 0]
forces:
  holder:
    type: spring_damper
    bodies: [ground, arm]
    points: [[length, 0, 2 * 0.4], [length, 0, 0]]
    stiffness: 3 * k_half
    damping: max(12, sqrt(4))
outputs:
  - {name: tip_z, type: position, body: arm, point: [length, 0, 0], component: z}
parameters:
  g: 9.81
  length: 1.2
  area: 2.5e-3
  rho: 1000
  mass_arm: rho * length * area
  k_half: 500
YAML
if "$MBCC" compile numbers.yaml -o gen_numbers > /dev/null 2>&1 && "$MBCC" compile expressions.yaml -o gen_expr > /dev/null 2>&1; then
  # the only differences allowed: the file's name and the input hash
  for f in twin.c twin.h; do
    sed 's/numbers\.yaml/MODEL/; /input hash/d' "gen_numbers/$f" > a.txt
    sed 's/expressions\.yaml/MODEL/; /input hash/d' "gen_expr/$f" > b.txt
    cmp -s a.txt b.txt || err "expressions emit other code than numbers in $f: $(diff a.txt b.txt | head -5)"
  done
else
  err "compiling numbers.yaml / expressions.yaml failed"
fi

# 3. run-time parameters
model="$root/tests/models/param_oscillator.yaml"
run() { "$MBCC" run "$@" --plot none --quiet; }
if run "$model" -o set.csv --set k=900 > set.log 2>&1; then
  sed 's/k: {value: 400, runtime: true/k: {value: 900, runtime: false/' "$model" > fixed.yaml
  run fixed.yaml -o fixed.csv > fixed.log 2>&1 || err "the model with k = 900 in the file failed: $(cat fixed.log)"
  cmp -s set.csv fixed.csv || err "--set k=900 and k: 900 in the file give different CSVs"
  run "$model" -o generic.csv --set k=900 --path generic > generic.log 2>&1 || err "generic --set failed: $(cat generic.log)"
  paste -d, set.csv generic.csv | awk -F, 'NR > 1 { d = $2 - $4; if (d < 0) d = -d; if (d > m) m = d }
      END { exit !(m < 1e-9) }' || err "the generic path with --set differs from the generated one"
  # closed form: x = free_length + pull cos(sqrt(k / m) t)
  awk -F, 'NR > 1 { w = sqrt(900 / 2.5); e = $2 - (0.5 + 0.05 * cos(w * $1)); if (e < 0) e = -e; if (e > m) m = e }
      END { exit !(m < 1e-8) }' set.csv || err "--set k=900: the motion is not x0 + pull cos(sqrt(k/m) t)"
  # the default differs (the setting took effect), and the damping derived from k and zeta
  run "$model" -o default.csv > /dev/null 2>&1 || err "the default run failed"
  cmp -s default.csv set.csv && err "--set k=900 changed nothing"
  run "$model" -o damped.csv --set zeta=0.1 --set k=900 > /dev/null 2>&1 || err "--set zeta failed"
  awk -F, 'NR > 1 { w = sqrt(900 / 2.5); z = 0.1; wd = w * sqrt(1 - z * z)
      x = 0.5 + 0.05 * exp(-z * w * $1) * (cos(wd * $1) + z / sqrt(1 - z * z) * sin(wd * $1))
      e = $2 - x; if (e < 0) e = -e; if (e > m) m = e } END { exit !(m < 1e-8) }' damped.csv ||
    err "--set zeta=0.1: not the damped closed form"
else
  err "mbcc run --set k=900 failed: $(cat set.log)"
fi

# 4. errors, exit 2
expect_error() { # expected-substring, command...
  local want=$1; shift
  "$@" > out.log 2>&1; local rc=$?
  [ $rc = 2 ] || err "$*: exit $rc, expected 2"
  grep -qF -- "$want" out.log || err "$*: no '$want' in: $(cat out.log)"
}
expect_error "no parameter 'kk' (did you mean 'k'?)" run "$model" -o e.csv --set kk=3
expect_error "is compile-time" run "$model" -o e.csv --set mass=3
expect_error "outside the range" run "$model" -o e.csv --set k=-5
expect_error "NAME=VALUE" run "$model" -o e.csv --set k=abc
expect_error "no parameter 'kk'" run "$model" -o e.csv --set kk=3 --path generic
expect_error "--set is an option of mbcc run" "$MBCC" check "$model" --set k=3
sim=$(ls generated/param_oscillator/param_oscillator_sim 2>/dev/null)
if [ -x "$sim" ]; then
  "$sim" -o direct.csv --set k=900 --quiet > /dev/null 2>&1 || err "the simulator's own --set k=900 failed"
  cmp -s direct.csv set.csv || err "the simulator's --set differs from mbcc run --set"
  expect_error "no run-time parameter 'kk'" "$sim" -o e.csv --set kk=3
  expect_error "outside the parameter's range" "$sim" -o e.csv --set k=0
  expect_error "finite number" "$sim" -o e.csv --set k=1e999
else
  err "no simulator in generated/param_oscillator"
fi
[ -e e.csv ] && err "a refused run wrote e.csv"

# 5. a --set value is checked against the rule of the field it sets, not only
#    the parameter's range: sweep_oscillator's k (no min) is its spring's
#    stiffness (>= 0), L0 its free length (>= 0); mbcc refuses before running,
#    the generated simulator's set_params too (and writes nothing)
osc="$root/tests/models/sweep_oscillator.yaml"
expect_error "sweep_oscillator.yaml:19:16: error: --set k=-5: 'stiffness' of force 'spring' would be -5, but it must be >= 0 (it depends on run-time parameter 'k')" run "$osc" -o e.csv --set k=-5
expect_error "sweep_oscillator.yaml:18:18: error: --set L0=-0.25: 'free_length' of force 'spring' would be -0.25, but it must be >= 0" run "$osc" -o e.csv --set L0=-0.25
run "$osc" -o osc.csv --set k=0 > /dev/null 2>&1 || err "--set k=0 (the rule's bound) refused"
sim=$(ls generated/sweep_oscillator/sweep_oscillator_sim 2>/dev/null)
if [ -x "$sim" ]; then
  expect_error "error: --set k=-5: force 'spring': 'stiffness' at sweep_oscillator.yaml:19:16 must be >= 0" "$sim" -o e.csv --set k=-5
  expect_error "'free_length' at sweep_oscillator.yaml:18:18 must be >= 0" "$sim" -o e.csv --set k=5 --set L0=-1e-9
  "$sim" -o osc2.csv --set k=0 --quiet > /dev/null 2>&1 || err "the simulator refuses --set k=0"
else
  err "no simulator in generated/sweep_oscillator"
fi
[ -e e.csv ] && err "a run refused by a field's rule wrote e.csv"
exit $fail
