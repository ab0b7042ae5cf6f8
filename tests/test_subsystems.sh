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
#      written out by hand, rigid and flexible chassis;
#   5. moved instances ('position'): tests/compose/subsystem_moved.yaml (the
#      corner moved, and mirrored and moved; a mirrored, moved rack holding a
#      moved link and a mirrored, moved link: nested placements compose; a
#      run-time point moved) emits the same C as subsystem_moved_by_hand.yaml,
#      the same written out at the moved places; so does a flexible body of
#      an FE model of its own ('line', global nodes) in a moved instance
#      against the same written by hand; 'position: [0, 0, 0]' emits the
#      same C as no 'position';
#   6. errors at the instance's 'position' (file:line:col, exit status 2): not
#      a list of 3 numbers or expressions, a run-time parameter in it, a
#      flexible body of an FE file (global nodes) in a moved instance, also
#      nested; an unknown instance key lists 'position'.
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
same_code() { # same_code A.yaml B.yaml WHAT: A and B emit the same C (apart from origin and locations)
  local a=gen_${1##*/} b=gen_${2##*/}
  a=${a%.yaml} b=${b%.yaml}
  "$MBCC" compile "$1" -o "$a" > log 2>&1 || { err "compile $1: $(head -5 log)"; return; }
  "$MBCC" compile "$2" -o "$b" > log 2>&1 || { err "compile $2: $(head -5 log)"; return; }
  strip_origin "$a"
  strip_origin "$b"
  [ "$(ls "$a.stripped" | wc -l)" -ge 3 ] || err "$1 emitted fewer than 3 files"
  [ "$(cd "$a.stripped" && sha256sum -- * | sha256sum)" = "$(cd "$b.stripped" && sha256sum -- * | sha256sum)" ] ||
    err "$3: $(diff -r "$a.stripped" "$b.stripped" | head -20)"
}
same_code "$root/tests/compose/subsystem_pair.yaml" "$root/tests/compose/subsystem_pair_by_hand.yaml" \
  "the instantiated subsystems emit other code than the same written by hand"

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

# 5. moved instances: the same C as written out by hand
same_code "$root/tests/compose/subsystem_moved.yaml" "$root/tests/compose/subsystem_moved_by_hand.yaml" \
  "the moved (and nested, mirrored) instances emit other code than the same written out at the moved places"
# a position of all zeros moves nothing: the code of subsystem_pair.yaml
mkdir -p zero/subsystems
cp "$root/tests/compose/subsystems/corner.yaml" zero/subsystems/
cp "$root/tests/compose/subsystem_pair.yaml" zero/
sed 's|^  left:  {file: subsystems/corner.yaml, |  left:  {file: subsystems/corner.yaml, position: [0, 0.0, -0], |' \
  "$root/tests/compose/subsystem_pair.yaml" > zero/pair_at_zero.yaml
grep -q 'position: \[0, 0.0, -0\]' zero/pair_at_zero.yaml || err "could not add 'position' to subsystem_pair.yaml"
same_code zero/pair_at_zero.yaml zero/subsystem_pair.yaml "'position: [0, 0, 0]' changes the emitted code"
# a flexible body of a line of beams (global nodes) moves with its instance
mkdir -p flex/parts
cat > flex/parts/blade.yaml <<'YAML'
subsystem:
  attachments: [hub]
bodies:
  blade:
    type: flexible
    line: {from: [0.1, 0, 0], to: [1.1, 0.2, 0], elements: 4}
    section: {area: 2.0e-4, Iy: 1.6667e-9, Iz: 6.6667e-9, J: 4.57e-9}
    material: {E: 2.1e11, nu: 0.3, density: 7850}
    reference: [0]
joints:
  root: {type: fixed, bodies: [hub, blade], node: 0, point: [0.1, 0, 0]}
outputs:
  - {name: tip, type: position, body: blade, node: 4}
YAML
cat > flex/moved.yaml <<'YAML'
name: blade_moved
gravity: [0, 0, -9.81]
bodies:
  hub: {type: rigid, mass: 5, inertia: [0.1, 0.1, 0.1], position: [0.5, 0.25, 1]}
joints:
  spin: {type: revolute, bodies: [ground, hub], point: [0.5, 0.25, 1], axis: [1, 0, 0]}
subsystems:
  b: {file: parts/blade.yaml, position: [0.5, 0.25, 1], attach: {hub: hub}}
YAML
cat > flex/by_hand.yaml <<'YAML'
name: blade_moved
gravity: [0, 0, -9.81]
bodies:
  hub: {type: rigid, mass: 5, inertia: [0.1, 0.1, 0.1], position: [0.5, 0.25, 1]}
  b_blade:
    type: flexible
    line: {from: [0.1 + 0.5, 0 + 0.25, 0 + 1], to: [1.1 + 0.5, 0.2 + 0.25, 0 + 1], elements: 4}
    section: {area: 2.0e-4, Iy: 1.6667e-9, Iz: 6.6667e-9, J: 4.57e-9}
    material: {E: 2.1e11, nu: 0.3, density: 7850}
    reference: [0]
joints:
  spin: {type: revolute, bodies: [ground, hub], point: [0.5, 0.25, 1], axis: [1, 0, 0]}
  b_root: {type: fixed, bodies: [hub, b_blade], node: 0, point: [0.1 + 0.5, 0 + 0.25, 0 + 1]}
outputs:
  - {name: b_tip, type: position, body: b_blade, node: 4}
YAML
same_code flex/moved.yaml flex/by_hand.yaml "a flexible body of a line of beams in a moved instance emits other code than written by hand"

# 6. errors at 'position'
mkdir -p moved/parts
cp "$root/tests/compose/subsystems/link.yaml" moved/parts/
printf 'GRID,1,,0.,0.,0.\n' > moved/parts/beam.bdf
cat > moved/parts/beam.yaml <<'YAML'
subsystem:
  attachments: [base]
bodies:
  beam: {type: flexible, fe_file: beam.bdf, reference: [1]}
joints:
  clamp: {type: fixed, bodies: [base, beam], node: 1}
YAML
cat > moved/parts/holder.yaml <<'YAML'
subsystem:
  attachments: [base]
subsystems:
  inner: {file: beam.yaml, attach: {base: base}}
YAML
bad_position() { # bad_position 'INSTANCE KEYS' FILE:LINE:COL MESSAGE
  cat > moved/m.yaml <<YAML
name: m
parameters:
  w: {value: 0.1, runtime: true}
bodies:
  rack: {type: rigid, mass: 1, inertia: [1, 1, 1]}
joints:
  fix: {type: fixed, bodies: [ground, rack], point: [0, 0, 0]}
subsystems:
  a: {file: parts/link.yaml, $1, attach: {rack: rack}}
YAML
  "$MBCC" check moved/m.yaml > bad.out 2>&1
  local rc=$?
  [ $rc -eq 2 ] && grep -qF "$2: error: $3" bad.out || err "instance {$1}: exit $rc, expected 2 and '$2: error: $3...': $(cat bad.out)"
}
bad_position "position: [1, 2]" moved/m.yaml:9:40 "'position' of subsystem instance 'a' must be a list of 3 numbers or expressions"
bad_position "position: 0.5" moved/m.yaml:9:40 "'position' of subsystem instance 'a' must be a list of 3 numbers or expressions"
bad_position "position: [1, [2], 3]" moved/m.yaml:9:40 "'position' of subsystem instance 'a' must be a list of 3"
bad_position "position: [1, q, 3]" moved/m.yaml:9:44 "unknown parameter 'q'"
bad_position "position: [1, 2 * w, 3]" moved/m.yaml:9:44 "the 'position' of a subsystem instance cannot use a run-time parameter"
bad_position "positon: [1, 2, 3]" moved/m.yaml:9:30 "unknown key in subsystem instance 'a' (expected file, prefix, mirror, position, attach, parameters)"
fe_message="this subsystem instance cannot be moved ('position'): its flexible body"
sed -i 's|^  a: {.*|  a: {file: parts/beam.yaml, position: [0, lane, 0], attach: {base: rack}}|; s|^  w: .*|  lane: 3.5|' moved/m.yaml
"$MBCC" check moved/m.yaml > bad.out 2>&1
rc=$?
[ $rc -eq 2 ] && grep -qF "moved/m.yaml:9:40: error: $fe_message 'a_beam' reads an FE file" bad.out &&
  grep -qF "moved/parts/beam.yaml:4:35: note: the FE file of 'a_beam' is named here" bad.out &&
  grep -qF "modal_file" bad.out || err "an FE-file body in a moved instance: exit $rc: $(cat bad.out)"
sed -i 's|^  a: {.*|  a: {file: parts/holder.yaml, position: [1, 0, 0], attach: {base: rack}}|' moved/m.yaml
"$MBCC" check moved/m.yaml > bad.out 2>&1
rc=$?
[ $rc -eq 2 ] && grep -qF "moved/m.yaml:9:42: error: $fe_message 'a_inner_beam' reads an FE file" bad.out ||
  err "an FE-file body nested in a moved instance: exit $rc: $(cat bad.out)"
# not moved (every component 0): the FE file is read as usual
sed -i 's|position: \[1, 0, 0\]|position: [0, 0, 0]|' moved/m.yaml
"$MBCC" check moved/m.yaml > bad.out 2>&1
grep -qF "$fe_message" bad.out && err "an instance at 'position: [0, 0, 0]' is taken as moved: $(cat bad.out)"

[ -n "${KEEP:-}" ] && cp -r . "$KEEP"
exit $fail
