#!/usr/bin/env bash
# test_modes_suggest.sh: mbcc modes --suggest ranks a flexible body's modes
# by the loads of a rigid pre-run.  The flexible slider-crank moves in the
# x-y plane, so its joint loads on the rod lie in that plane: with a
# rectangular rod section (no degenerate bending pairs) every out-of-plane
# mode (z bending and torsion, by its shape) must get a vanishing amplitude
# and stay out of the suggestion, the first in-plane bending mode must rank
# first, and a body the pre-run does not load is refused.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh

sed -e 's/    section: {area: 3.16e-5}/    section: {area: 3.16e-5, Iy: 1.6e-10, Iz: 0.8e-10, J: 1.6e-10}/' \
    -e 's/    modes: {count: 4}       # plus 4 fixed-interface normal modes/    modes: {count: 6}/' \
    "$root/models/slider_crank_flexible.yaml" > sc.yaml
grep -q 'Iz: 0.8e-10' sc.yaml && grep -q 'count: 6' sc.yaml || err "the model edit did not apply"
"$MBCC" modes sc.yaml --body rod --shapes shapes.csv --suggest > suggest.log 2>&1 || { cat suggest.log; err "mbcc modes --suggest failed"; }
# out-of-plane modes by shape: z displacement, x and y rotation (times the
# rod length) beyond the x, y displacement and z rotation
awk -F, 'function a(v) { return v < 0 ? -v : v }
  NR == 1 { next } { for (j = 0; 5 + 6 * j + 5 <= NF; j++) { c = 5 + 6 * j
    i = a($c); if (a($(c + 1)) > i) i = a($(c + 1)); if (0.3 * a($(c + 5)) > i) i = 0.3 * a($(c + 5))
    o = a($(c + 2)); if (0.3 * a($(c + 3)) > o) o = 0.3 * a($(c + 3)); if (0.3 * a($(c + 4)) > o) o = 0.3 * a($(c + 4))
    if (i > in_[j]) in_[j] = i; if (o > out[j]) out[j] = o; n = j + 1 } }
  END { for (j = 0; j < n; j++) print j + 1, (out[j] > in_[j] ? "out" : "in") }' shapes.csv > planes.txt
nout=$(grep -c out planes.txt); nin=$(grep -c ' in' planes.txt)
[ "$nout" -ge 3 ] && [ "$nin" -ge 3 ] || { cat planes.txt; err "expected both in-plane and out-of-plane modes ($nin, $nout)"; }
awk 'NR == FNR { plane[$1] = $2; next }
  /^ *[0-9]+ +[0-9]+ +[0-9.e+-]+ +[0-9.e+-]+ +[0-9.e+-]+$/ { amp[$2] = $4; if ($4 > top) top = $4; if ($1 == 1) first = $2 }
  /^suggested/ { s = $0; gsub(/.*\[|\].*/, "", s); ns = split(s, keep, ", ") }
  END {
    bad = 0
    for (m in plane) if (plane[m] == "out" && !(amp[m] <= 1e-9 * top)) { printf "out-of-plane mode %d: amplitude %g of %g\n", m, amp[m], top; bad = 1 }
    for (k = 1; k <= ns; k++) if (plane[keep[k]] != "in") { printf "suggested mode %d is out of plane\n", keep[k]; bad = 1 }
    low = 0; for (m in plane) if (plane[m] == "in" && (low == 0 || m + 0 < low)) low = m + 0
    if (first != low) { printf "rank 1 is mode %d, not the first in-plane mode %d\n", first, low; bad = 1 }
    if (ns < 1) { print "nothing suggested"; bad = 1 }
    exit bad }' planes.txt suggest.log || { cat suggest.log planes.txt; err "the ranking"; }
grep -A30 '^rank' suggest.log | head -14

# a body the pre-run does not load (a clamped beam without gravity): refused
"$MBCC" modes "$root/tests/models/fe/beam_bdf.yaml" --body beam --suggest > none.log 2>&1; rc=$?
[ $rc -eq 2 ] && grep -q "the rigid pre-run puts no load on body 'beam'" none.log || { cat none.log; err "no load: exit $rc"; }
exit $fail
