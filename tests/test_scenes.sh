#!/usr/bin/env bash
# test_scenes.sh: scenes that prune (tests/scenes/chain.yaml, a triple
# pendulum with a spring from its lowest rod to the ground), the YAML merge
# key and include: (tests/compose/).
#   - pruning shrinks the system as `check --scene` reports, and the emitted
#     header has that n and nnz(K); removing 'lower' removes the spring that
#     hangs on it and drops the outputs on it with a note (file:line:col);
#     'no_middle' removes 'lower' too (it hangs on the ground only through
#     'middle');
#   - 'no_lower' is the double pendulum: models/double_pendulum.yaml's angles
#     to 1e-9;
#   - 'stiff_elbow' (the elbow as a bushing of 1e6 N/m, 1e4 N m/rad, free
#     about z) follows the jointed double pendulum: the bushing yields by
#     F/k <= 50 N / 1e6 N/m = 5e-5 m, an angle of 1e-4 rad on the 0.5 m rod;
#     the angles agree to 1e-3 rad over 0.5 s (they move by 0.5 rad);
#   - 'rig_lower' (the lowest rod alone, its wrist held by the ground) is a
#     rod hinged at its end released from the horizontal: reaction m g / 4 at
#     t = 0 (2.4525 N), angle -(3 g / 4 L) t^2 at t = 0.01 to 1e-3 relative,
#     energy conserved to 1e-8;
#   - 'rig_driven': the lowest rod on a body driven by the middle rod's
#     motion recorded by the full model (position and orientation columns,
#     0.01 s apart, a natural cubic spline through them) reproduces the full
#     model's lower_angle to 3e-3 rad over 0.5 s (it moves by 0.8 rad): the
#     spline's acceleration error, about h^2/12 |x''''| ~ 1e-4/12 (10/s)^4
#     0.5 m ~ 0.04 m/s^2 (0.4% of g), bounds the angle error near 3e-3
#     (measured 1.5e-5); a CSV without the body's columns is an error;
#   - the flexible slider-crank's rod made rigid by a scene: its modal output
#     is dropped with a note, and the scene runs;
#   - the merge-key and the include versions of the double pendulum give
#     its results bit for bit; errors in an included file point into it;
#     an include cycle and a bad merge are located errors.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
cp -r "$root/tests/scenes" "$root/tests/compose" .
cp "$root/models/double_pendulum.yaml" .

# size NAME OUTPUT-OF-CHECK: the scene's value after "->" of line NAME
after() { awk -v k="$1" '$1 == k && $3 == "->" { print $4 }' "$2"; }

"$MBCC" check scenes/chain.yaml --scene no_lower > check.txt 2> notes.txt || err "check --scene no_lower failed"
grep -q "^    force 'tip_spring'" check.txt || err "the spring hanging on 'lower' is not reported removed"
grep -q "^scenes/chain.yaml:[0-9]*:[0-9]*: note: output 'lower_angle' dropped" notes.txt ||
  err "no located note for the dropped output: $(cat notes.txt)"
n=$(after n check.txt) nnz=$(after 'nnz(K)' check.txt)
[ "$n" = 22 ] && [ "$nnz" = 108 ] || err "no_lower: n $n, nnz $nnz (the double pendulum has 22, 108)"
"$MBCC" compile scenes/chain.yaml --scene no_lower -o gen > /dev/null 2>&1 || err "compile no_lower failed"
grep -q "CHAIN_NO_LOWER_N $n " gen/chain_no_lower.h && grep -q "CHAIN_NO_LOWER_NNZ $nnz " gen/chain_no_lower.h ||
  err "the emitted header's n/nnz differ from check's $n/$nnz"
grep -q "tip_spring\|lower_angle" gen/chain_no_lower.c && err "the emitted code still names pruned parts"
"$MBCC" check scenes/chain.yaml --scene no_middle > check2.txt 2> notes2.txt || err "check no_middle failed"
grep -q "note: body 'lower' removed too" notes2.txt || err "'lower' not removed with 'middle'"
[ "$(after bodies check2.txt)" = 1 ] || err "no_middle: $(after bodies check2.txt) bodies, expected 1"

# max |column a of file 1 - column b of file 2|
maxdiff() { paste -d, "$1" "$2" | awk -F, -v a="$3" -v b="$4" -v nb="$(head -1 "$1" | tr , '\n' | wc -l)" 'NR > 1 {
    d = $a - $(nb + b); if (d < 0) d = -d; if (d > m) m = d } END { printf "%.3g\n", m }'; }
"$MBCC" run double_pendulum.yaml --end 0.5 -o dp.csv > /dev/null 2>&1 || err "double pendulum run failed"
"$MBCC" run scenes/chain.yaml --scene no_lower -o nl.csv > /dev/null 2>&1 || err "no_lower run failed"
"$MBCC" run scenes/chain.yaml --scene stiff_elbow -o se.csv > /dev/null 2>&1 || err "stiff_elbow run failed"
for c in 2 3; do
  d=$(maxdiff nl.csv dp.csv $c $c)
  awk -v d="$d" 'BEGIN { exit !(d < 1e-9) }' || err "no_lower column $c differs from the double pendulum by $d"
  d=$(maxdiff se.csv nl.csv $c $c)
  awk -v d="$d" 'BEGIN { exit !(d < 1e-3) }' || err "stiff_elbow column $c differs from the joint by $d"
done
moved=$(awk -F, 'END { print ($3 < 0 ? -$3 : $3) }' nl.csv)
awk -v m="$moved" 'BEGIN { exit !(m > 0.1) }' || err "the double pendulum hardly moved ($moved): the comparison is void"

"$MBCC" run scenes/chain.yaml --scene rig_lower -o rig.csv > /dev/null 2>&1 || err "rig_lower run failed"
awk -F, 'NR == 2 { if ($4 < 2.4524 || $4 > 2.4526) { print "reaction at t = 0: " $4; bad = 1 } }
  NR == 3 { ref = -0.75 * 9.81 / 0.5 * $1 * $1; e = ($2 - ref) / ref; if (e < 0) e = -e
            if (e > 1e-3) { print "angle at t = 0.01: " $2 " vs " ref; bad = 1 } }
  NR > 1 { e = $9 < 0 ? -$9 : $9; if (e > 1e-8) { print "energy drift " $9; bad = 1 } }
  END { exit bad }' rig.csv || err "rig_lower is not the hinged rod"

# a rig driven by the full model's recorded motion: 'lower' on its wrist,
# held by a body that follows the middle rod's recorded position and
# orientation, reproduces the full model's lower_angle
"$MBCC" run scenes/chain.yaml -o scenes/chain_full.csv > /dev/null 2>&1 || err "the full chain does not run"
"$MBCC" run scenes/chain.yaml --scene rig_driven -o driven.csv > /dev/null 2> e.txt || err "rig_driven failed: $(cat e.txt)"
d=$(paste -d, driven.csv scenes/chain_full.csv | awk -F, 'NR > 1 { d = $2 - $13; if (d < 0) d = -d; if (d > m) m = d }
  END { printf "%.3g\n", m }')
awk -v d="$d" 'BEGIN { exit !(d < 3e-3) }' || err "rig_driven's lower_angle differs from the full model's by $d"
awk -F, 'END { exit !($4 > 0.3 || $4 < -0.3) }' scenes/chain_full.csv || err "the full chain's lower rod hardly moved"
head -1 scenes/chain_full.csv | sed 's/middle_ori.e0/middle_ori.q0/' > scenes/chain_full_bad.csv
sed 's/chain_full.csv/chain_full_bad.csv/' scenes/chain.yaml > scenes/chain_bad.yaml
"$MBCC" check scenes/chain_bad.yaml --scene rig_driven > /dev/null 2> e.txt && err "a motion without the orientation is accepted"
grep -q "lacks body 'middle'" e.txt || err "no error for a recorded motion without the body: $(cat e.txt)"

# a run-time parameter used only by a pruned force: the scene still builds
sed 's/^name: chain/name: chainp\nparameters:\n  k_tip: {value: 50, runtime: true}/; s/    stiffness: 50/    stiffness: k_tip/' \
  scenes/chain.yaml > scenes/chainp.yaml
"$MBCC" check scenes/chainp.yaml --scene no_lower > /dev/null 2> e.txt || err "a run-time parameter of a pruned force breaks the scene: $(cat e.txt)"

# a flexible body made rigid by a scene: its modal output is dropped with a note
"$MBCC" run scenes/flexible_rigid.yaml --scene rigid_rod --end 0.002 -o fr.csv > /dev/null 2> notes3.txt ||
  err "the rigid_rod scene does not run: $(cat notes3.txt)"
grep -q "^scenes/flexible_rigid.yaml:64:5: note: output 'mode1' dropped: the body is rigid" notes3.txt ||
  err "no note for the modal output of the rod made rigid"
head -1 fr.csv | grep -q mode1 && err "the rigid rod still has its modal output"

# merge key and include: the double pendulum's results bit for bit
"$MBCC" run compose/merge_pendulum.yaml --end 0.5 -o m.csv > /dev/null 2>&1 || err "merge run failed"
"$MBCC" run compose/include_pendulum.yaml --end 0.5 -o i.csv > /dev/null 2>&1 || err "include run failed"
cmp -s m.csv dp.csv || err "the merge-key model differs from the double pendulum"
cmp -s i.csv dp.csv || err "the include model differs from the double pendulum"
sed 's/mass: 1.0/mass: heavy/' compose/parts/lower_link.yaml > compose/parts/bad_link.yaml
sed 's#lower_link.yaml#bad_link.yaml#' compose/include_pendulum.yaml > compose/bad.yaml
"$MBCC" check compose/bad.yaml > /dev/null 2> e.txt; st=$?
[ $st = 2 ] && grep -q "^compose/parts/bad_link.yaml:7:11: error: 'mass' must be a number" e.txt ||
  err "an error in an included file is not located there (exit $st): $(cat e.txt)"
printf 'include: [c2.yaml]\n' > compose/c1.yaml
printf 'include: [c1.yaml]\n' > compose/c2.yaml
sed 's#parts/lower_link.yaml#c1.yaml#' compose/include_pendulum.yaml > compose/cycle.yaml
"$MBCC" check compose/cycle.yaml > /dev/null 2> e.txt; st=$?
[ $st = 2 ] && grep -q "^compose/c2.yaml:1:11: error: include cycle" e.txt || err "include cycle (exit $st): $(cat e.txt)"
printf 'name: m\nbodies:\n  b:\n    <<: 5\n    type: rigid\n' > merge_bad.yaml
"$MBCC" check merge_bad.yaml > /dev/null 2> e.txt; st=$?
[ $st = 2 ] && grep -q "^merge_bad.yaml:4:9: error: '<<' merges a mapping" e.txt || err "bad merge (exit $st): $(cat e.txt)"
# outputs that name forces and bodies follow the pruning: after removing
# body a (and its spring ka), fb is kb's tension (the weight of b, 19.62 N, at
# rest) and cm is b's x (1); fa and the relative output from a are dropped
"$MBCC" run scenes/prune_outputs.yaml --scene only_b -o prune.csv --plot none --quiet 2> notes.txt ||
  err "run prune_outputs only_b failed: $(cat notes.txt)"
[ "$(head -1 prune.csv)" = "t,fb,cm" ] || err "pruned outputs: columns $(head -1 prune.csv)"
awk -F, 'NR > 1 { d = $2 - 19.62; if (d < 0) d = -d; if (d > 1e-6 || $3 != 1) bad = 1 } END { exit bad }' prune.csv ||
  err "pruned outputs follow the wrong force or body: $(sed -n 2p prune.csv)"
grep -q "output 'fa' dropped" notes.txt && grep -q "output 'rb' dropped" notes.txt || err "pruned outputs: notes $(cat notes.txt)"
exit $fail
