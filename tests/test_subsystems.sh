#!/usr/bin/env bash
# test_subsystems.sh: subsystem instances (docs/model-format.md, Subsystems).
#   1. tests/compose/subsystem_pair.yaml (the corner of subsystems/corner.yaml
#      left as written and right mirrored, with a parameter set per
#      instance) emits the same C as subsystem_pair_by_hand.yaml, the same
#      written out and mirrored by hand (apart from the header with the input
#      hash and the file:line:col comments that say where each element was
#      written);
#   2. mirror symmetry: with the same parameters on both sides, the mirrored
#      corner moves as the mirror image of the left one (wheel heights, hub
#      angles and spring forces equal, wheel y opposite);
#   3. errors inside a subsystem file point into it, with a note at the
#      instance ("instantiated here"), and a nested instance resolves names
#      and parameters through both levels;
#   4. the sports car built from corner and tyre subsystems
#      (models/sports_car.yaml, models/sports_car/car.yaml, models/subsystems/)
#      gives the same CSV as tests/compose/sports_car_flat.yaml, the same car
#      written out by hand, rigid and flexible chassis.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

# 1. identical emitted code
strip_origin() { # DIR -> DIR.stripped: without the origin header and location comments
  mkdir -p "$1.stripped"
  for f in "$1"/*; do
    sed -E -e '1,2d' -e 's/[a-z_]+\.yaml:[0-9]+:[0-9]+/LOC/g' "$f" > "$1.stripped/${f##*/}"
  done
}
"$MBCC" compile "$root/tests/compose/subsystem_pair.yaml" -o gen_sub > log 2>&1 || err "compile subsystem_pair: $(cat log)"
"$MBCC" compile "$root/tests/compose/subsystem_pair_by_hand.yaml" -o gen_hand > log 2>&1 || err "compile by hand: $(cat log)"
strip_origin gen_sub
strip_origin gen_hand
[ "$(ls gen_sub.stripped | wc -l)" -ge 3 ] || err "subsystem_pair emitted fewer than 3 files"
a=$(cd gen_sub.stripped && sha256sum -- * | sha256sum)
b=$(cd gen_hand.stripped && sha256sum -- * | sha256sum)
[ "$a" = "$b" ] || err "the instantiated subsystems emit other code than the same written by hand: $(diff -r gen_sub.stripped gen_hand.stripped | head -20)"

# 2. mirror symmetry of the motion
mkdir -p sym/subsystems
cp "$root/tests/compose/subsystems/corner.yaml" sym/subsystems/
cat > sym/pair.yaml <<'YAML'
name: pair
gravity: [0, 0, -9.81]
bodies:
  chassis: {type: rigid, mass: 300, inertia: [100, 200, 250], position: [0.2, 0, 0.5]}
joints:
  heave: {type: prismatic, bodies: [ground, chassis], point: [0.2, 0, 0.5], axis: [0, 0, 1]}
subsystems:
  left:  {file: subsystems/corner.yaml, prefix: l_, attach: {chassis: chassis}}
  right: {file: subsystems/corner.yaml, prefix: r_, mirror: true, attach: {chassis: chassis}}
outputs:
  - {name: lw, type: position, body: l_wheel}
  - {name: rw, type: position, body: r_wheel}
simulation: {end_time: 0.3, output_step: 0.01}
YAML
if "$MBCC" run sym/pair.yaml -o sym.csv > log 2>&1; then
  # columns: time, (l_) wheel_z hub_angle spring_force, (r_) the same, lw.x y z, rw.x y z
  awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    function chk(a, b, s,   d) { d = a - s * b; if (d < 0) d = -d; if (d > 1e-7 * (1 + (a < 0 ? -a : a))) { bad++; if (bad < 4) print "row " NR ": " a " vs " s * b } }
    { chk($c["l_wheel_z"], $c["r_wheel_z"], 1); chk($c["l_hub_angle"], $c["r_hub_angle"], 1)
      chk($c["l_spring_force"], $c["r_spring_force"], 1); chk($c["lw.x"], $c["rw.x"], 1); chk($c["lw.y"], $c["rw.y"], -1)
      if ($c["l_hub_angle"] * $c["l_hub_angle"] > m) m = $c["l_hub_angle"] * $c["l_hub_angle"] }
    END { if (m < 1e-6) { print "the hub does not turn: nothing tested"; bad++ } exit bad > 0 }' sym.csv > sym.out ||
    err "the mirrored corner does not move as the mirror image of the left one: $(cat sym.out)"
else
  err "run the symmetric pair: $(tail -5 log)"
fi

# 3. errors inside a subsystem, and nesting
mkdir -p nest/parts
cat > nest/parts/wheel.yaml <<'YAML'
subsystem:
  attachments: [carrier]
parameters:
  r: 0.3
  m_wheel: 2 * r ^ 2 * 0 + 15
bodies:
  wheel: {type: rigid, mass: m_wheel, inertia: [0.6, 1.0, 0.6], position: [0, 0.9, r]}
joints:
  hub: {type: revolute, bodies: [carrier, wheel], point: [0, 0.9, r], axis: [0, 1, 0]}
YAML
cat > nest/parts/corner.yaml <<'YAML'
subsystem:
  attachments: [body]
parameters:
  r: 0.25
bodies:
  carrier: {type: rigid, mass: 3, inertia: [0.1, 0.1, 0.1], position: [0, 0.8, r]}
joints:
  slide: {type: prismatic, bodies: [body, carrier], point: [0, 0.8, r], axis: [0, 0, 1]}
subsystems:
  w: {file: wheel.yaml, prefix: w_, attach: {carrier: carrier}, parameters: {r: r}}
forces:
  spring: {type: spring_damper, bodies: [body, w_wheel], points: [[0, 0.8, 0.6], [0, 0.9, r]], stiffness: 1000}
YAML
cat > nest/car.yaml <<'YAML'
name: car
bodies:
  body: {type: rigid, mass: 100, inertia: [10, 10, 10], position: [0, 0, 0.6]}
joints:
  fix: {type: fixed, bodies: [ground, body], point: [0, 0, 0.6]}
subsystems:
  fl: {file: parts/corner.yaml, attach: {body: body}}
  fr: {file: parts/corner.yaml, mirror: true, attach: {body: body}}
outputs:
  - {name: wheel_y, type: position, body: fr_w_wheel, component: y}
YAML
if "$MBCC" check nest/car.yaml > nest.out 2>&1; then
  # the inner wheel's r is the corner's (0.25), not its own default (0.3)
  grep -Eq '^ +fl_w_r +0\.25 ' nest.out || err "nested override: fl_w_r is not 0.25: $(grep _r nest.out)"
  grep -Eq '^ +fr_w_m_wheel +15 ' nest.out || err "nested parameter fr_w_m_wheel missing: $(cat nest.out)"
  "$MBCC" run nest/car.yaml --end 0.01 -o nest.csv > log 2>&1 || err "run nested: $(tail -3 log)"
  y=$(awk -F, 'NR == 2 { print $2 }' nest.csv)
  awk -v y="$y" 'BEGIN { exit !(y + 0.9 < 1e-12 && y + 0.9 > -1e-12) }' || err "mirrored nested wheel at y = $y, expected -0.9"
else
  err "nested subsystems: $(cat nest.out)"
fi
sed -i 's/^  m_wheel: .*/  m_wheel: 2 * q/' nest/parts/wheel.yaml
"$MBCC" check nest/car.yaml > bad.out 2>&1
[ $? -eq 2 ] || err "an unknown parameter in a subsystem file: not exit 2"
grep -q "nest/parts/wheel.yaml:5:16: error: unknown parameter 'q'" bad.out || err "the error does not point into the subsystem file: $(cat bad.out)"
grep -q "nest/parts/corner.yaml:10:3: note: in the subsystem 'w' instantiated here" bad.out || err "no note at the inner instance: $(cat bad.out)"
grep -q "nest/car.yaml:7:3: note: in the subsystem 'fl' instantiated here" bad.out || err "no note at the outer instance: $(cat bad.out)"
# 4. the sports car with its corners and tyres as subsystems (models/sports_car.yaml
#    includes models/sports_car/car.yaml, which instantiates models/subsystems/:
#    the front double wishbone, the rear McPherson strut and the tyre, mirrored
#    for the right side, mounted on the FE chassis's nodes through node
#    attachments) moves exactly as tests/compose/sports_car_flat.yaml, the car
#    written out by hand (the joints there named j01_FL_lower_pivot ..., the
#    tyres tyre_FL ...): the same CSV, rigid and flexible chassis, through the
#    bump (generic path)
for scene in rigid base; do
  args=(--end 0.7 --path generic --plot none --quiet)
  [ $scene = base ] || args+=(--scene $scene)
  "$MBCC" run "$root/models/sports_car.yaml" "${args[@]}" -o car_sub_$scene.csv > log 2>&1 ||
    err "run sports_car ($scene): $(grep error log | head -3)"
  "$MBCC" run "$root/tests/compose/sports_car_flat.yaml" "${args[@]}" -o car_hand_$scene.csv > log 2>&1 ||
    err "run sports_car_flat ($scene): $(grep error log | head -3)"
  [ "$(wc -l < car_sub_$scene.csv)" -gt 600 ] || err "sports_car ($scene): too few rows"
  cmp -s car_sub_$scene.csv car_hand_$scene.csv ||
    err "the car with subsystem corners ($scene) moves otherwise than the car written out: $(diff car_sub_$scene.csv car_hand_$scene.csv | head -4)"
done

[ -n "${KEEP:-}" ] && cp -r . "$KEEP"
exit $fail
