#!/usr/bin/env bash
# test_loads_export.sh: mbcc run --body B --loads FILE.csv writes the loads
# on a flexible body's joint nodes over a run (force and moment on the body,
# body axes).  A Nastran cantilever (4 CBARs, 1 m along x, 20 x 10 mm steel,
# clamped at GRID 1 by a fixed joint) under gravity, started in static
# equilibrium: the clamp carries the weight, Fy = m g, and its moment,
# Mz = m g L / 2, at every time; node ids are the deck's; errors exit 2.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

cp "$root"/tests/models/fe/beam.bdf "$root"/tests/models/fe/beam_elements.bdf .
sed 's/^bodies:/gravity: [0, -9.81, 0]\nsimulation: {end_time: 0.01, output_step: 0.001, equilibrium: true}\nbodies:/' \
  "$root"/tests/models/fe/beam_bdf.yaml > hang.yaml
"$MBCC" run hang.yaml --body beam --loads loads.csv > run.log 2>&1 || { cat run.log; err "run --loads failed"; }
head -1 loads.csv | grep -q '^t,clamp@1.Fx,clamp@1.Fy,clamp@1.Fz,clamp@1.Mx,clamp@1.My,clamp@1.Mz$' ||
  { head -1 loads.csv; err "the header"; }
# m = rho A L = 7850 * 2e-4 * 1
awk -F, -v W="$(awk 'BEGIN { printf "%.17g", 7850 * 2e-4 * 1 * 9.81 }')" 'NR == 1 { next }
  { n++; dy = ($3 - W) / W; dm = ($7 - W / 2) / (W / 2); if (dy < 0) dy = -dy; if (dm < 0) dm = -dm
    if (dy > wy) wy = dy; if (dm > wm) wm = dm; o = ($2 < 0 ? -$2 : $2) + ($4 < 0 ? -$4 : $4); if (o > wo) wo = o }
  END { printf "clamp load over %d times: Fy vs m g %.2e, Mz vs m g L/2 %.2e, other force components %.2e N\n", n, wy, wm, wo
        exit !(n >= 10 && wy < 1e-5 && wm < 1e-5 && wo < 1e-6 * W) }' loads.csv || err "the clamp's load"

"$MBCC" run hang.yaml --loads x.csv > e1.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q -- "--loads needs --body" e1.log || { cat e1.log; err "--loads without --body: exit $rc"; }
"$MBCC" run hang.yaml --body ground --loads x.csv > e2.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "'ground' is not a flexible body" e2.log || { cat e2.log; err "--loads on a rigid body: exit $rc"; }
exit $fail
