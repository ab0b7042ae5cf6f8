#!/usr/bin/env bash
# test_param_geometry.sh: run-time parameters in the geometry
# (docs/model-format.md, Parameters): the attachment points of force
# elements, on the ground and on a turned rigid body, written as run-time
# parameters.
#   1. `mbcc run --set` of both points gives the CSV of the model recompiled
#      with the values written in the file (to 1e-9 relative); the generic
#      path and the generated simulator's own --set agree; the default run
#      differs (the setting took effect);
#   2. the point moves the spring's force by the closed form: at t = 0 the arm
#      hangs at rest along x, so its angular acceleration about the hinge is
#      (torque of gravity + torque of the spring) / J, and tip_z(t) for small
#      t is 1.2 * alpha * t^2 / 2;
#   3. geometry still fixed at compile time (a joint point, a body position)
#      as a run-time parameter: a located error naming what is supported,
#      exit 2, nothing written.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

model() { # anchor_x tip_x (numbers or parameter names), extra parameter lines
  cat <<YAML
name: param_geometry
gravity: [0, 0, -9.81]
bodies:
  arm:
    type: rigid
    mass: 3.0
    inertia: [0.02, 0.5, 0.5]
    position: [0.6, 0, 0]
    orientation: {axis: [1, 0, 0], angle: 0.4}
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
    points: [[$1, 0, 0.8], [$2, 0, 0]]
    stiffness: 1500
    damping: 12
    free_length: 0.7
outputs:
  - {name: tip_z, type: position, body: arm, point: [1.2, 0, 0], component: z}
simulation: {end_time: 0.5, output_step: 0.001}
YAML
  [ $# -gt 2 ] && printf 'parameters:\n%s\n' "$3"
}
run() { "$MBCC" run "$@" --plot none --quiet; }
close() { # a.csv b.csv: every value equal to 1e-9 relative
  paste -d, "$1" "$2" | awk -F, 'NR > 1 { d = $2 - $4; if (d < 0) d = -d; s = $2 < 0 ? -$2 : $2
      if (d > 1e-9 * (s + 1e-3)) bad = 1 } END { exit bad }'
}

# 1. --set against the recompiled model
model anchor_x tip_x "  anchor_x: {value: 1.2, runtime: true}
  tip_x: {value: 1.2, runtime: true, min: 0.1, max: 1.2}" > rt.yaml
model 0.95 0.9 | sed 's/^name: param_geometry/name: param_geometry_fixed/' > fixed.yaml
if run rt.yaml -o set.csv --set anchor_x=0.95 --set tip_x=0.9 > set.log 2>&1; then
  run fixed.yaml -o fixed.csv > fixed.log 2>&1 || err "the model with the points in the file failed: $(cat fixed.log)"
  close set.csv fixed.csv || err "--set of the points and the points written in the file give different CSVs"
  run rt.yaml -o generic.csv --set anchor_x=0.95 --set tip_x=0.9 --path generic > generic.log 2>&1 ||
    err "generic --set failed: $(cat generic.log)"
  close set.csv generic.csv || err "the generic path with --set differs from the generated one"
  sim=generated/param_geometry/param_geometry_sim
  if [ -x "$sim" ]; then
    "$sim" -o direct.csv --set anchor_x=0.95 --set tip_x=0.9 --quiet > /dev/null 2>&1 || err "the simulator's --set failed"
    close set.csv direct.csv || err "the simulator's own --set differs from mbcc run --set"
  else
    err "no simulator in generated/param_geometry"
  fi
  run rt.yaml -o default.csv > /dev/null 2>&1 || err "the default run failed"
  close set.csv default.csv && err "--set of the points changed nothing"
else
  err "mbcc run --set of the attachment points failed: $(cat set.log)"
fi

# 1b. a bushing's point (both its markers, on two bodies, one turned) and a
#     point force's point, against the recompiled model and the generic path
bushing() { # bx fx (numbers or parameter names), name, parameter lines
  cat <<YAML
name: $3
gravity: [0, 0, -9.81]
bodies:
  arm: {type: rigid, mass: 3.0, inertia: [0.02, 0.5, 0.5], position: [0.6, 0, 0], orientation: {axis: [0, 0, 1], angle: 0.3}}
  bob: {type: rigid, mass: 1.0, inertia: [0.01, 0.01, 0.01], position: [1.2, 0, 0]}
joints:
  hinge: {type: revolute, bodies: [ground, arm], point: [0, 0, 0], axis: [0, 1, 0]}
forces:
  bush: {type: bushing, bodies: [arm, bob], point: [$1, 0.1, 0], stiffness: [1e4, 1e4, 1e4, 50, 50, 50], damping: [10, 10, 10, 0.1, 0.1, 0.1]}
  push: {type: force, body: arm, point: [$2, 0, 0], value: [0, 0, 20], frame: global}
outputs:
  - {name: bob_z, type: position, body: bob, point: [1.2, 0, 0], component: z}
simulation: {end_time: 0.3, output_step: 0.01}
YAML
  [ $# -gt 3 ] && printf 'parameters:\n%s\n' "$4"
}
bushing bx fx bush_rt "  bx: {value: 1.2, runtime: true}
  fx: {value: 0.5, runtime: true}" > bush_rt.yaml
bushing 1.1 0.8 bush_fixed > bush_fixed.yaml
if run bush_rt.yaml -o bset.csv --set bx=1.1 --set fx=0.8 > bset.log 2>&1 &&
   run bush_fixed.yaml -o bfixed.csv > bfixed.log 2>&1 &&
   run bush_rt.yaml -o bgeneric.csv --set bx=1.1 --set fx=0.8 --path generic > bgeneric.log 2>&1 &&
   run bush_rt.yaml -o bdefault.csv > bdefault.log 2>&1; then
  close bset.csv bfixed.csv || err "bushing and force points: --set and the recompiled model differ"
  close bset.csv bgeneric.csv || err "bushing and force points: the generic path differs"
  close bset.csv bdefault.csv && err "bushing and force points: --set changed nothing"
else
  err "the bushing model failed: $(cat bset.log bfixed.log bgeneric.log bdefault.log)"
fi

# 2. the closed form at t = 0: spring from (a, 0, 0.8) to (p, 0, 0) on the arm,
#    length l = sqrt((a - p)^2 + 0.8^2), tension T = k (l - 0.7) (no velocity
#    yet), its force on the arm T (a - p, 0, 0.8) / l at (p, 0, 0): torque
#    about +y is z F_x - x F_z = -p T 0.8 / l; gravity's -0.6 m g about +y is
#    +0.6 m g (r x F with r = (0.6,0,0), F = (0,0,-m g): y = -(0.6 * -m g));
#    the arm's inertia about y through the hinge: its own about the global
#    y axis (turned about x by 0.4: cos^2 0.4 * 0.5 + sin^2 0.4 * 0.5 = 0.5)
#    plus m 0.6^2; rotation +y takes +x toward -z: tip_z = -1.2 theta
awk -F, -v a=0.95 -v p=0.9 'NR > 1 && $1 > 0 && $1 <= 0.0101 {
    l = sqrt((a - p)^2 + 0.64); T = 1500 * (l - 0.7); tau = -p * T * 0.8 / l + 0.6 * 3 * 9.81
    J = 0.5 + 3 * 0.36; alpha = tau / J; z = -1.2 * alpha * $1 * $1 / 2
    e = ($2 - z) / z; if (e < 0) e = -e; if (e > m) m = e; n++ }
    END { if (!n || m > 0.05) { printf "n=%d rel=%g\n", n, m; exit 1 } }' set.csv ||
  err "--set of the points: tip_z(t) at small t is not the closed form's 1.2 alpha t^2 / 2"

# 3. what stays compile-time: a located error naming what is supported
expect_error() { # expected-substring, command...
  local want=$1; shift
  "$@" > out.log 2>&1; local rc=$?
  [ $rc = 2 ] || err "$*: exit $rc, expected 2"
  grep -qF -- "$want" out.log || err "$*: no '$want' in: $(cat out.log)"
}
model 1.2 1.2 "  hinge_x: {value: 0, runtime: true}" | sed 's/point: \[0, 0, 0\]/point: [hinge_x, 0, 0]/' > joint.yaml
expect_error "joint.yaml:14:13: error: this value depends on run-time parameter 'hinge_x'" run joint.yaml -o e.csv
expect_error "the attachment points of force elements on rigid bodies" run joint.yaml -o e.csv
model 1.2 1.2 "  arm_x: {value: 0.6, runtime: true}" | sed 's/position: \[0.6, 0, 0\]/position: [arm_x, 0, 0]/' > body.yaml
expect_error "this value depends on run-time parameter 'arm_x'" run body.yaml -o e.csv
[ -e e.csv ] && err "a refused model wrote e.csv"
exit $fail
