#!/usr/bin/env bash
# test_virtual_velocity.sh: a virtual body that the compiler inserts for a
# joint on a flexible node starts moving with the node's frame, so the
# initial velocities given in the model survive assembly unchanged.  A free
# flexible beam translating and spinning carries a small ball on its tip node
# (spherical joint, the ball's velocity v + w x r given consistently); the
# momentum at t = 0 must be the same with the joint directly on the node and
# through a virtual body, and equal to the one computed here from the masses
# (before the fix the virtual body started at rest, and the minimum-norm
# velocity correction of the assembly slowed the whole system down).
# Exit 0 = pass.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

cat > beam.yaml <<'EOF'
name: beam_ball
bodies:
  beam:
    type: flexible
    line: {from: [0, 0, 0], to: [1.0, 0, 0], elements: 4}
    section: {area: 4.0e-4, Iy: 1.0e-8, Iz: 3.0e-8, J: 2.0e-8}
    material: {E: 2.0e9, nu: 0.3, density: 2700}
    reference: [0]
    modes: {count: 4}
    velocity: [1.0, -0.5, 0.2]
    angular_velocity: [3.0, 1.5, 20.0]
  ball:                         # at node 4: v = (1, -0.5, 0.2) + (3, 1.5, 20) x (1, 0, 0)
    type: rigid
    mass: 0.1
    inertia: [1.0e-5, 1.0e-5, 1.0e-5]
    position: [1.0, 0, 0]
    velocity: [1.0, 19.5, -1.3]
joints:
  tip: {type: spherical, bodies: [beam, ball], node: 4}
outputs:
  - {name: L, type: momentum}
simulation: {end_time: 0.001}
scenes:
  direct: {simulation: {joints_on_flexible: direct}}
  virtual: {simulation: {joints_on_flexible: virtual}}
EOF
for s in direct virtual; do
  "$MBCC" run beam.yaml --scene $s --path generic -o $s.csv --plot none --quiet > $s.log 2>&1 ||
    err "scene $s failed: $(tail -3 $s.log)"
done
if [ -s direct.csv ] && [ -s virtual.csv ]; then
  # beam: 2700 x 4e-4 x 1 m = 1.08 kg, its centre at (0.5, 0, 0) moving at
  # v + w x (0.5, 0, 0) = (1, 9.5, -0.55); the ball 0.1 kg at (1, 19.5, -1.3)
  awk -F, 'NR == 2 { for (i = 2; i <= 4; i++) p[FNR, i] = $i }
    FNR == 2 && NR > 2 { for (i = 2; i <= 4; i++) q[i] = $i }
    END { e[2] = 1.08 * 1.0 + 0.1 * 1.0; e[3] = 1.08 * 9.5 + 0.1 * 19.5; e[4] = 1.08 * -0.55 + 0.1 * -1.3
      for (i = 2; i <= 4; i++) {
        printf "p%d: direct %.9g, virtual %.9g, expected %.9g\n", i - 1, p[2, i], q[i], e[i]
        if ((p[2, i] - e[i]) ^ 2 > 1e-18 || (q[i] - e[i]) ^ 2 > 1e-18) bad = 1 }
      exit bad }' direct.csv virtual.csv || err "the initial momentum changes with a virtual body"
fi
exit $fail
