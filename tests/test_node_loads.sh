#!/usr/bin/env bash
# test_node_loads.sh: `mbcc run --loads` and `mbcc modes --suggest` count the
# force elements on a flexible body's nodes, not only the joints.  The
# Nastran cantilever of tests/models/fe (1 m along x, clamped at GRID 1;
# its x-z bending, I2, is softer than its x-y bending, I1), started in
# static equilibrium:
#  1. a point force of 50 N along y at GRID 5: the export's push@5 is the
#     applied force (0, 50, 0) and no moment; the clamp carries -50 N and
#     -50 N m about z (the force times the 1 m arm: linear theory moves the
#     tip across, not along);
#  2. --suggest ranks first the first x-y bending mode (mode 2: the force
#     excites it; mode 1 bends in x-z) and gives every mode whose shape at
#     the tip has no y part a vanishing amplitude;
#  3. a massless beam element from GRID 5 to a ground point 0.5 m further
#     (its first side on the node: its reaction acts at the other end):
#     the loads on the body balance, forces and moments about the origin
#     with the tip where a normal run puts it; the reaction's lever (0.5 m)
#     is in the tip's moment;
#  4. no joint or force on a node: an error.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

cp "$root"/tests/models/fe/beam.bdf "$root"/tests/models/fe/beam_elements.bdf .
cat > tip.yaml <<'YAML'
name: tip_loaded
bodies:
  beam: {type: flexible, fe_file: beam.bdf, reference: [1], modes: 6}
joints:
  clamp: {type: fixed, bodies: [ground, beam], node: 1}
forces:
  push: {type: force, body: beam, node: 5, value: [0, 50, 0]}
simulation: {end_time: 0.01, output_step: 0.001, equilibrium: true}
YAML
"$MBCC" run tip.yaml --body beam --loads loads.csv > run1.log 2>&1 || { cat run1.log; err "run --loads"; }
head -1 loads.csv | grep -q '^t,clamp@1.Fx,clamp@1.Fy,clamp@1.Fz,clamp@1.Mx,clamp@1.My,clamp@1.Mz,push@5.Fx,push@5.Fy,push@5.Fz,push@5.Mx,push@5.My,push@5.Mz$' ||
  { head -1 loads.csv; err "the header"; }
awk -F, 'NR == 1 { next }
  { n++
    split("0 50 0 0 0 0", push, " "); split("0 -50 0 0 0 -50", clamp, " ")
    for (c = 1; c <= 6; c++) { d = $(7 + c) - push[c]; if (d < 0) d = -d; if (d > wp) wp = d
                                e = $(1 + c) - clamp[c]; if (e < 0) e = -e; if (e > wc) wc = e } }
  END { printf "point force at GRID 5 over %d times: off the applied force by %.2e, the clamp off -50 N, -50 N m by %.2e\n", n, wp, wc
        exit !(n >= 10 && wp <= 1e-9 && wc <= 1e-6) }' loads.csv || err "the point force's load"

"$MBCC" modes tip.yaml --body beam --shapes shapes.csv --suggest > suggest.log 2>&1 || { cat suggest.log; err "modes --suggest"; }
# each mode's tip (node row 4, GRID 5) motion: y or z
awk -F, 'NR == 6 { for (j = 0; 5 + 6 * j + 5 <= NF; j++) { y = $(6 + 6 * j); z = $(7 + 6 * j)
    if (y < 0) y = -y; if (z < 0) z = -z; print j + 1, (y > 1e3 * z ? "y" : z > 1e3 * y ? "z" : "other") } }' shapes.csv > planes.txt
awk 'NR == FNR { plane[$1] = $2; next }
  /^ *[0-9]+ +[0-9]+ +[0-9.e+-]+ +[0-9.e+-]+ +[0-9.e+-]+$/ { amp[$2] = $4; if ($4 > top) top = $4; if ($1 == 1) first = $2 }
  END { low = 0; for (m in plane) if (plane[m] == "y" && (low == 0 || m + 0 < low)) low = m + 0
    if (!(low > 1) || first != low) { printf "rank 1 is mode %d, the first y-bending mode is %d\n", first, low; bad = 1 }
    for (m in plane) if (plane[m] == "z" && !(amp[m] <= 1e-9 * top)) { printf "mode %d (z) amplitude %g of %g\n", m, amp[m], top; bad = 1 }
    printf "suggest: rank 1 mode %d (first y-bending; mode 1 bends in z)\n", first
    exit bad }' planes.txt suggest.log || { cat suggest.log planes.txt; err "the ranking by the point force"; }

# --- a beam element from the tip to the ground: its reaction's lever ------------
sed 's|^  push: .*|&\n  stay: {type: beam, bodies: [ground, beam], nodes: [~, 5], points: [[1.5, 0, 0], [1, 0, 0]], section: {area: 1.0e-4, Iy: 1.0e-9, Iz: 1.0e-9, J: 2.0e-9}, material: {E: 2.1e11, nu: 0.3, density: 7850}}|' \
  tip.yaml > stay.yaml
sed 's|^simulation:|outputs:\n  - {name: tip, type: position, body: beam, node: 5}\n&|' stay.yaml > stay_tip.yaml
"$MBCC" run stay.yaml --body beam --loads stay.csv > run2.log 2>&1 || { cat run2.log; err "run --loads with the stay"; }
"$MBCC" run stay_tip.yaml --path generic -o tip.csv --plot none --quiet > run3.log 2>&1 || { cat run3.log; err "run the stay"; }
paste -d, <(tail -1 stay.csv) <(tail -1 tip.csv) | awk -F, '{
    # clamp at the origin (2..7), push (8..13) and stay (14..19) at the tip; tip x, y at 21, 22
    x = $21; y = $22
    for (c = 0; c < 3; c++) { f[c] = $(2 + c) + $(8 + c) + $(14 + c); a = $(14 + c) < 0 ? -$(14 + c) : $(14 + c); if (a > big) big = a }
    mz = $7 + $13 + $19 + x * ($9 + $15) - y * ($8 + $14)
    worst = 0; for (c = 0; c < 3; c++) { a = f[c] < 0 ? -f[c] : f[c]; if (a > worst) worst = a }
    printf "stay on the tip: force sum %.2e N, moment sum about z %.2e N m (forces up to %.4g N, the lever 0.5 m x %.4g N)\n", worst, mz, big, $15
    exit !(big > 0 && worst <= 1e-9 * big && (mz < 0 ? -mz : mz) <= 1e-6 * big) }' || err "the loads with the stay do not balance"

# --- no joint or force on a node ---------------------------------------------------
sed 's/node: 1}/point: [0, 0, 0]}/; /^forces:/d; /push:/d' tip.yaml > none.yaml
"$MBCC" run none.yaml --body beam --loads none.csv > none.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "no joint or force element on a node of body 'beam'" none.log || { cat none.log; err "nothing on a node: exit $rc"; }
exit $fail
