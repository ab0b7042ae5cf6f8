#!/usr/bin/env bash
# test_superelement.sh: a massless flexible body (force type superelement):
# a Nastran cantilever of 8 CBARs statically condensed to its end nodes,
# clamped to the ground, carrying a rigid tip mass under gravity (damped to
# rest).  The tip's rest deflection against the closed forms
#  1. along x: P L^3 / (3 E I);
#  2. the deck turned 30 degrees about z: the bending part P cos(a) L^3/(3EI)
#     and the axial part P sin(a) L/(EA) projected on y (the condensed K is
#     in global axes);
#  3. generated and generic paths agree;
#  4. three interface nodes (a beam held at one end, two bodies on it): the
#     rest deflections against beam theory, generated = generic;
#  5. bad input: an interface node that is not a GRID, one node only, fewer
#     bodies than nodes, interface nodes tied by an RBE2 (singular).
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

deck() { # angle-degrees file
  awk -v a="$1" 'BEGIN {
    pi = atan2(0, -1); c = cos(a * pi / 180); s = sin(a * pi / 180)
    print "BEGIN BULK"
    for (k = 1; k <= 9; k++) printf "GRID,%d,,%.17g,%.17g,0.\n", k, (k - 1) * 0.0625 * c, (k - 1) * 0.0625 * s
    for (e = 1; e <= 8; e++) printf "CBAR,%d,1,%d,%d,0.,0.,1.\n", e, e, e + 1
    print "PBAR,1,1,1.e-4,8.3333333333e-10,8.3333333333e-10,1.406e-9"
    print "MAT1,1,2.1e11,,.3,7850."
    print "ENDDATA" }' > "$2"
}
model() { # deck tip-x tip-y interface file
  cat > "$5" <<YAML
name: superelement_cantilever
gravity: [0, -9.81, 0]
bodies:
  tip: {type: rigid, mass: 1.0, inertia: [1.0e-4, 1.0e-4, 1.0e-4], position: [$2, $3, 0]}
forces:
  bracket:
    type: superelement
    bodies: [ground, tip]
    fe_file: $1
    interface: $4
    damping_ratio: 0.01
outputs:
  - {name: tip_y, type: position, body: tip, component: y}
simulation: {end_time: 1.0, output_step: 0.01}
YAML
}
check() { # csv expected-y what undeformed-y: the deflection's relative error
  awk -F, -v want="$2" -v what="$3" -v y0="$4" 'END { d = ($2 - want) / (want - y0); if (d < 0) d = -d
      printf "%s: tip y %.12g, closed form %.12g (deflection relative error %.2e)\n", what, $2, want, d; exit !(d < 1e-6) }' "$1" ||
    err "$3: the rest deflection differs from the closed form"
}
P=9.81; L=0.5; E=2.1e11; I=8.3333333333e-10; A=1.0e-4

deck 0 straight.bdf
model straight.bdf 0.5 0 "[1, 9]" straight.yaml
"$MBCC" run straight.yaml -o straight.csv --plot none --quiet > run1.log 2>&1 || { cat run1.log; err "run straight"; }
check straight.csv "$(awk -v P=$P -v L=$L -v E=$E -v I=$I 'BEGIN { printf "%.17g", -P * L^3 / (3 * E * I) }')" "along x" 0
"$MBCC" run straight.yaml --path generic -o generic.csv --plot none --quiet > run2.log 2>&1 || { cat run2.log; err "run generic"; }
cmp -s <(tail -1 straight.csv | cut -c1-14) <(tail -1 generic.csv | cut -c1-14) ||
  err "generated and generic paths differ: $(tail -1 straight.csv) vs $(tail -1 generic.csv)"

deck 30 turned.bdf
c=$(awk 'BEGIN { print cos(atan2(0, -1) / 6) }'); s=0.5
model turned.bdf "$(awk -v c=$c 'BEGIN { printf "%.17g", 0.5 * c }')" 0.25 "[1, 9]" turned.yaml
"$MBCC" run turned.yaml -o turned.csv --plot none --quiet > run3.log 2>&1 || { cat run3.log; err "run turned"; }
check turned.csv "$(awk -v P=$P -v L=$L -v E=$E -v I=$I -v A=$A -v c=$c -v s=$s \
  'BEGIN { printf "%.17g", 0.25 - P * c * L^3 / (3 * E * I) * c - P * s * L / (E * A) * s }')" "turned 30 degrees" 0.25

# --- three interface nodes: the same cantilever, 1 m of 8 CBARs with I ten
# times larger, held at GRID 1 by the ground, carrying a 2 kg body at GRID 5
# (x = 0.5) and a 1 kg body at GRID 9 (x = 1): the rest deflections against
# beam theory's superposition of two point loads (P at a: y(x) = P x^2
# (3a - x) / 6EI for x <= a, P a^2 (3x - a) / 6EI beyond), which the
# coupling between the two loaded nodes (the condensed K's off-diagonal
# blocks) decides
awk 'BEGIN {
  print "BEGIN BULK"
  for (k = 1; k <= 9; k++) printf "GRID,%d,,%.17g,0.,0.\n", k, (k - 1) * 0.125
  for (e = 1; e <= 8; e++) printf "CBAR,%d,1,%d,%d,0.,0.,1.\n", e, e, e + 1
  print "PBAR,1,1,1.e-4,8.3333333333e-9,8.3333333333e-9,1.406e-8"
  print "MAT1,1,2.1e11,,.3,7850."
  print "ENDDATA" }' > three.bdf
three() { # interface bodies file
  cat > "$3" <<YAML
name: superelement_three_nodes
gravity: [0, -9.81, 0]
bodies:
  mid: {type: rigid, mass: 2.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3], position: [0.5, 0, 0]}
  tip: {type: rigid, mass: 1.0, inertia: [1.0e-3, 1.0e-3, 1.0e-3], position: [1.0, 0, 0]}
forces:
  bracket:
    type: superelement
    bodies: $2
    fe_file: three.bdf
    interface: $1
    damping_ratio: 0.002
outputs:
  - {name: mid_y, type: position, body: mid, component: y}
  - {name: tip_y, type: position, body: tip, component: y}
simulation: {end_time: 4.0, output_step: 0.01}
YAML
}
three "[1, 5, 9]" "[ground, mid, tip]" three.yaml
"$MBCC" run three.yaml -o three.csv --plot none --quiet > run4.log 2>&1 || { cat run4.log; err "run three nodes"; }
"$MBCC" run three.yaml --path generic -o three_generic.csv --plot none --quiet > run5.log 2>&1 ||
  { cat run5.log; err "run three nodes, generic"; }
awk -F, 'END { E = 2.1e11; I = 8.3333333333e-9; g = 9.81; P1 = 2 * g; P2 = g; a = 0.5; L = 1
    want[2] = -(P1 * a^3 / (3 * E * I) + P2 * a^2 * (3 * L - a) / (6 * E * I))
    want[3] = -(P1 * a^2 * (3 * L - a) / (6 * E * I) + P2 * L^3 / (3 * E * I))
    for (c = 2; c <= 3; c++) { d = ($c - want[c]) / want[c]; if (d < 0) d = -d
      printf "three nodes: %s y %.12g, beam theory %.12g (relative error %.2e)\n", c == 2 ? "mid" : "tip", $c, want[c], d
      if (!(d < 1e-6)) bad = 1 }
    exit bad }' three.csv || err "three nodes: the rest deflections differ from beam theory"
cmp -s <(tail -1 three.csv | cut -c1-14) <(tail -1 three_generic.csv | cut -c1-14) ||
  err "three nodes: generated and generic paths differ: $(tail -1 three.csv) vs $(tail -1 three_generic.csv)"

# bad input
three "[1, 5, 9]" "[ground, mid]" bad3.yaml
"$MBCC" check bad3.yaml > bad3.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "bad3.yaml:[0-9]*:[0-9]*: error: 'bodies': a superelement with 3 interface nodes takes a list of 3 bodies" bad3.log ||
  { cat bad3.log; err "three nodes, two bodies: exit $rc"; }
# GRIDs 4 and 6 tied to GRID 5 by one RBE2: as interface nodes they cannot move apart
awk '/^ENDDATA/ { print "RBE2,20,5,123456,4,6" } { print }' three.bdf > tied.bdf
three "[1, 4, 6]" "[ground, mid, tip]" bad4.yaml
sed -i 's/fe_file: three.bdf/fe_file: tied.bdf/' bad4.yaml
"$MBCC" check bad4.yaml > bad4.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "bad4.yaml:[0-9]*:[0-9]*: error: superelement 'bracket': .*flexibility is singular" bad4.log ||
  { cat bad4.log; err "interface nodes tied by an RBE2: exit $rc"; }
model straight.bdf 0.5 0 "[1, 12]" bad1.yaml
"$MBCC" check bad1.yaml > bad1.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "bad1.yaml:[0-9]*:[0-9]*: error: 'interface': node 12 is not a node id" bad1.log ||
  { cat bad1.log; err "an interface node that is not a GRID: exit $rc"; }
model straight.bdf 0.5 0 "[9]" bad2.yaml
"$MBCC" check bad2.yaml > bad2.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "bad2.yaml:[0-9]*:[0-9]*: error: 'interface': a superelement takes 2 nodes" bad2.log ||
  { cat bad2.log; err "one interface node: exit $rc"; }
exit $fail
