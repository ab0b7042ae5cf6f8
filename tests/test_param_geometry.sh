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
#   3. geometry still fixed at compile time (a body's orientation, a joint
#      axis) as a run-time parameter: a located error naming what is
#      supported, exit 2, nothing written;
#   4. run-time joint points, re-assembled at start (runtime/hosted/
#      reassemble.c): a four-bar whose ground pivot is run-time and whose
#      crank a driver turns to 1.5 rad at t = 0.  --set against the model
#      recompiled with the value, the generic path and the simulator's own
#      --set; the assembled coupler pin against the loop closure (circle
#      intersection); a pivot for which the loop cannot close stops with the
#      parameter and the cause, exit 2, no CSV; a sweep over the pivot merges
#      the same values as single runs;
#   5. a run-time body position (with a force and an output on the body)
#      against the recompiled model and the generic path;
#   6. a run-time point that makes a compile-time redundant row independent
#      (a door on two coaxial hinges, one moved off the axis): the generated
#      simulator stops with the cause (the generic path, reading the model
#      again, shows the door then locked);
#   7. a --set or sweep value beyond the reader's bound on a number (1e30):
#      an error, exit 2, on mbcc run, the simulator and mbcc sweep.
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
model 1.2 1.2 "  turn: {value: 0.4, runtime: true}" | sed 's/angle: 0.4/angle: turn/' > turn.yaml
expect_error "turn.yaml:4:3: error: body 'arm': run-time parameter 'turn' turns its initial orientation" run turn.yaml -o e.csv
model 1.2 1.2 "  tilt: {value: 1, runtime: true}" | sed 's/axis: \[0, 1, 0\]/axis: [0, tilt, 0]/' > axis.yaml
expect_error "axis.yaml:15:15: error: this value depends on run-time parameter 'tilt'" run axis.yaml -o e.csv
expect_error "not orientations, axes, masses" run axis.yaml -o e.csv
model 1.2 1.2 "  hinge_x: {value: 0, input: true}" | sed 's/point: \[0, 0, 0\]/point: [hinge_x, 0, 0]/' > input.yaml
expect_error "error: input parameter 'hinge_x' moves joint points or body positions" run input.yaml -o e.csv
[ -e e.csv ] && err "a refused model wrote e.csv"

# 4. a run-time joint point: the four-bar of models/four_bar.yaml with its
#    rocker pivot at (ground_x, 0, 0) and the crank driven from 1.5 rad
fourbar() { # name, the pivot's x (a number or ground_x), parameter lines
  cat <<YAML
name: $1
gravity: [0, -9.81, 0]
bodies:
  crank: {type: rigid, mass: 0.5, inertia: [1.0e-4, 4.2e-4, 4.2e-4], position: [0.05, 0.0, 0]}
  coupler: {type: rigid, mass: 1.0, inertia: [1.0e-4, 7.5e-3, 7.5e-3], position: [0.184375, 0.12401959270615269, 0]}
  rocker: {type: rigid, mass: 0.8, inertia: [1.0e-4, 4.2e-3, 4.2e-3], position: [0.284375, 0.12401959270615269, 0]}
joints:
  crank_pivot: {type: revolute, bodies: [ground, crank], point: [0, 0, 0], axis: [0, 0, 1]}
  crank_pin: {type: spherical, bodies: [crank, coupler], point: [0.1, 0.0, 0]}
  rocker_pin: {type: universal, bodies: [coupler, rocker], point: [0.26875, 0.24803918541230538, 0], axes: [[0, 0, 1], [-0.9921567416492215, -0.125, 0]]}
  rocker_pivot: {type: revolute, bodies: [rocker, ground], point: [$2, 0.0, 0], axis: [0, 0, 1]}
drivers:
  motor: {joint: crank_pivot, motion: {type: constant_velocity, velocity: 6.283185307179586, initial: 1.5}}
outputs:
  - {name: pin, type: position, body: coupler, point: [0.26875, 0.24803918541230538, 0]}
  - {name: torque, type: effort, driver: motor}
simulation: {end_time: 0.3, output_step: 0.01, integrator: dopri5, rtol: 1.0e-9, atol: 1.0e-11}
YAML
  [ $# -gt 2 ] && printf 'parameters:\n%s\n' "$3"
}
near() { # a.csv b.csv: every value equal to 1e-7 relative (the integration tolerance)
  paste -d, "$1" "$2" | awk -F, 'NR > 1 { n = NF / 2; for (j = 2; j <= n; j++) { d = $j - $(j + n); if (d < 0) d = -d
      s = $j < 0 ? -$j : $j; if (d > 1e-7 * (s + 1e-3)) bad = 1 } } END { exit bad }'
}
fourbar fb_rt ground_x "  ground_x: {value: 0.3, runtime: true, min: -1, max: 10}" > fb_rt.yaml
fourbar fb_fixed 0.32 > fb_fixed.yaml
if run fb_rt.yaml -o fset.csv --set ground_x=0.32 > fset.log 2>&1; then
  run fb_fixed.yaml -o ffixed.csv > /dev/null 2>&1 || err "the four-bar with the pivot in the file failed"
  near fset.csv ffixed.csv || err "four-bar: --set ground_x and the value written in the file give different CSVs"
  run fb_rt.yaml -o fgeneric.csv --set ground_x=0.32 --path generic > /dev/null 2>&1 || err "four-bar: generic --set failed"
  near fset.csv fgeneric.csv || err "four-bar: the generic path with --set differs from the generated one"
  generated/fb_rt/fb_rt_sim -o fdirect.csv --set ground_x=0.32 --quiet > /dev/null 2>&1 ||
    err "four-bar: the simulator's own --set failed"
  near fset.csv fdirect.csv || err "four-bar: the simulator's own --set differs from mbcc run --set"
  run fb_rt.yaml -o fdefault.csv > /dev/null 2>&1 || err "four-bar: the default run failed"
  near fset.csv fdefault.csv && err "four-bar: --set ground_x changed nothing"
  # loop closure at t = 0: crank pin B = 0.1 (cos 1.5, sin 1.5); the coupler
  # (0.3 from B) meets the rocker, whose length from the pivot D = (g, 0)
  # follows the moved pivot: l = |(0.26875, 0.248...) - D|; C is the upper
  # intersection of the circles about B and D
  awk -F, -v g=0.32 'NR == 2 { bx = 0.1 * cos(1.5); by = 0.1 * sin(1.5); lc = 0.3
      l = sqrt((0.26875 - g)^2 + 0.24803918541230538^2)
      dx = g - bx; dy = -by; d = sqrt(dx * dx + dy * dy)
      a = (lc * lc - l * l + d * d) / (2 * d); h = sqrt(lc * lc - a * a)
      mx = bx + a * dx / d; my = by + a * dy / d
      cx = mx - h * dy / d; cy = my + h * dx / d
      if (cy < 0) { cx = mx + h * dy / d; cy = my - h * dx / d }
      e = sqrt(($2 - cx)^2 + ($3 - cy)^2); if (e > 1e-9) { printf "C (%g, %g), want (%g, %g)\n", $2, $3, cx, cy; exit 1 } }' fset.csv ||
    err "four-bar: the re-assembled coupler pin is not the loop closure's"
else
  err "four-bar: mbcc run --set ground_x=0.32 failed: $(cat fset.log)"
fi
# a pivot for which the loop cannot close at the crank's 1.5 rad
run fb_rt.yaml -o fbad.csv --set ground_x=-0.17 > fbad.log 2>&1; st=$?
[ $st = 2 ] || err "four-bar, a loop that cannot close: exit $st, expected 2"
grep -q "error: --set ground_x=-0.17 moves the assembly: the joints cannot be assembled" fbad.log ||
  err "four-bar, a loop that cannot close: no cause naming the parameter: $(cat fbad.log)"
[ -e fbad.csv ] && err "four-bar, a loop that cannot close: a CSV was written"
# a sweep over the pivot: its merged values are the single runs'
"$MBCC" sweep fb_rt.yaml --vary ground_x=0.3,0.32 --metric pin.x:final --metric torque:max --dir fsw \
  --csv fsweep.csv --jobs 1 --quiet > /dev/null 2> fsweep.log || err "four-bar sweep failed: $(cat fsweep.log)"
want=$(awk -F, 'NR == 1 { for (j = 1; j <= NF; j++) if ($j == "pin.x") c = j; next } { x = $c } END { printf "%.9g", x }' fset.csv)
got=$(awk -F, '$2 == "0.32" { printf "%.9g", $3 == "ok" ? $4 : "nan" }' fsweep.csv)
[ "$want" = "$got" ] || err "four-bar sweep: pin.x final $got at ground_x=0.32, the single run's $want: $(cat fsweep.csv)"

# 5. a run-time body position: the arm of section 1 at (arm_x, 0, 0), its
#    spring point and tip output on the arm following it
model 1.2 1.2 "  arm_x: {value: 0.6, runtime: true, min: 0.1, max: 2}" | sed 's/position: \[0.6, 0, 0\]/position: [arm_x, 0, 0]/' > body.yaml
model 1.2 1.2 | sed 's/position: \[0.6, 0, 0\]/position: [0.9, 0, 0]/; s/^name: param_geometry/name: body_fixed/' > body_fixed.yaml
if run body.yaml -o bpset.csv --set arm_x=0.9 > bp.log 2>&1 && run body_fixed.yaml -o bpfixed.csv > /dev/null 2>&1 &&
   run body.yaml -o bpgeneric.csv --set arm_x=0.9 --path generic > /dev/null 2>&1 &&
   run body.yaml -o bpdefault.csv > /dev/null 2>&1; then
  near bpset.csv bpfixed.csv || err "body position: --set and the recompiled model differ"
  near bpset.csv bpgeneric.csv || err "body position: the generic path differs"
  near bpset.csv bpdefault.csv && err "body position: --set arm_x changed nothing"
else
  err "the run-time body position failed: $(cat bp.log)"
fi

# 6. a door on two coaxial hinges; the upper one moved off the axis locks it,
#    which makes rows the compiler removed as redundant independent
cat > door.yaml <<YAML
name: door_rt
gravity: [0, -9.81, 0]
parameters:
  hinge_y: {value: 0, runtime: true}
bodies:
  door: {type: rigid, mass: 10, inertia: [1, 1, 1], position: [0.4, 0, 0.5]}
joints:
  lower: {type: revolute, bodies: [ground, door], point: [0, 0, 0], axis: [0, 0, 1]}
  upper: {type: revolute, bodies: [ground, door], point: [0, hinge_y, 1], axis: [0, 0, 1]}
outputs:
  - {name: door_x, type: position, body: door, component: x}
simulation: {end_time: 0.1, output_step: 0.01}
YAML
run door.yaml -o dset.csv --set hinge_y=0.1 > dset.log 2>&1; st=$?
[ $st = 2 ] || err "door: exit $st, expected 2"
grep -q "error: --set hinge_y=0.1 moves the assembly: .*removed as redundant at compile time, is no longer redundant" dset.log ||
  err "door: no cause naming the redundant row: $(cat dset.log)"
[ -e dset.csv ] && err "door: a CSV was written"
run door.yaml -o dgeneric.csv --set hinge_y=0.1 --path generic > /dev/null 2>&1 || err "door: the generic path failed"
awk -F, 'NR > 1 && ($2 < 0.4 - 1e-9 || $2 > 0.4 + 1e-9) { bad = 1 } END { exit bad }' dgeneric.csv ||
  err "door: the generic path does not show the door locked"
run door.yaml -o dzero.csv --set hinge_y=0 > /dev/null 2>&1 || err "door: --set hinge_y=0 (on the axis) failed"
awk -F, 'END { exit !($2 < 0.4 - 1e-4) }' dzero.csv || err "door: on the axis, the door does not swing"

# 7. values beyond the bound on numbers in the file (no ranges given: rt.yaml, door.yaml)
expect_error "error: --set anchor_x=1e200: 1e+200 is beyond the limit 1e+30" run rt.yaml -o e.csv --set anchor_x=1e200
expect_error "error: --set hinge_y=-2e30: -2e+30 is beyond the limit 1e+30" generated/door_rt/door_rt_sim -o e.csv --set hinge_y=-2e30
expect_error "error: '--vary anchor_x=1,1e40': 1e+40 is beyond the limit 1e+30" "$MBCC" sweep rt.yaml --vary anchor_x=1,1e40 --dir big
[ -e e.csv ] || [ -e big/jobs.txt ] && err "a value beyond the bound wrote results or jobs"
exit $fail
