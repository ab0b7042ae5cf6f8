#!/usr/bin/env bash
# test_loop_form.sh: the loop form of the evaluation (compiler/back/emit_loops.c)
# on a 50-link pendulum chain (scripts/chain.sh 50):
#   - by default (its 50 bodies and 49 hinges are groups of at least G
#     members) the evaluation is in the loop form: one function, the groups'
#     tables, no evaluation part files; MBCC_LOOP_MIN=1000000000 writes it
#     straight-line (in parts, several files);
#   - the two forms' simulations (--precision 17) agree to round-off (every
#     value within 1e-12 of the column's range), and both agree with the
#     generic path (--path generic) to the integrator's tolerance;
#   - the loop form's run conserves the chain's total energy (no damping) to
#     1e-6 J while its tip falls by more than 4 cm (free fall: 4.9 cm);
#   - its LDL^T is straight-line: its parts are in files of their own
#     (chain50_ldl.c, chain50_ldl<k>.c, listed in chain50.sources after
#     chain50.c, no evaluation part files), compiled in parallel, and the
#     simulation is byte-identical (--precision 17) to the model written as
#     one file (MBCC_EVAL_FILE_BYTES=0);
#   - the loop form's C files compile as C++11 (g++, clang++ when installed)
#     and, in single precision, freestanding.
# And a mixed model: a 40-link chain with a flexible beam (10 elements, 4
# modes) hinged at its tip.  The rods and hinges are loops, the beam, its
# hinge and its node markers straight-line in the same function; its
# simulation equals the straight-line form's to 17 digits (1e-15 of each
# column's range) and the generic path's to the integrator's tolerance, and
# its C file compiles as C++11 and, in single precision, freestanding.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
bash "$root/scripts/chain.sh" 50 > chain50.yaml
mkdir straight generic onefile
cp chain50.yaml straight/ && cp chain50.yaml generic/ && cp chain50.yaml onefile/
run() { "$MBCC" run chain50.yaml --end 0.1 --precision 17 --plot none -o out.csv "$@"; }
# the C files of generated model DIR/NAME: those NAME.sources lists, or NAME.c
sources() { if [ -f "$1/$2.sources" ]; then sed "s|^|$1/|" "$1/$2.sources"; else echo "$1/$2.c"; fi; }

run > loop.log 2>&1 || err "run (loop form): $(tail -5 loop.log)"
g=generated/chain50
grep -q "static const loop_joint1 loop_joints1\[49\]" "$g/chain50.c" || err "the 49 hinges are not one group of the loop form"
grep -q "static const loop_body loop_bodies0\[50\]" "$g/chain50.c" || err "the 50 rods are not one group of the loop form"
ls "$g"/chain50_eval*.c > /dev/null 2>&1 && err "the loop form's evaluation was split into part files: $(ls "$g")"
[ "$(grep -c '^void chain50_eval' "$g/chain50.c")" = 1 ] || err "the loop form's evaluation is not one function"
# its straight-line LDL^T in files of its own, the evaluation in chain50.c
grep -q "straight-line code" "$g/chain50_ldl.c" 2> /dev/null || err "the loop form's straight-line LDL^T is not in chain50_ldl.c: $(ls "$g")"
[ "$(head -2 "$g/chain50.sources" 2> /dev/null | tr '\n' ' ')" = "chain50.c chain50_ldl.c " ] ||
  err "chain50.sources does not list chain50.c, then chain50_ldl.c: $(cat "$g/chain50.sources" 2> /dev/null)"
grep -qx "chain50_ldl1.c" "$g/chain50.sources" 2> /dev/null || err "the LDL^T's parts are not in several files: $(ls "$g")"
for f in $(cat "$g/chain50.sources" 2> /dev/null); do [ -s "$g/$f" ] || err "chain50.sources lists $f, which is missing"; done
[ -e "$g/chain50_parts.h" ] && err "a loop-form model wrote the evaluation parts' header"
grep -q "ldl_factor_part0(" "$g/chain50.c" && err "the LDL^T's parts are still in chain50.c"
(cd onefile && MBCC_EVAL_FILE_BYTES=0 run > log 2>&1) || err "run (one file): $(tail -5 onefile/log)"
[ -e onefile/$g/chain50.sources ] && err "MBCC_EVAL_FILE_BYTES=0 still wrote several files: $(ls onefile/$g)"
grep -q "ldl_factor_part0(" onefile/$g/chain50.c || err "the one-file loop form has no LDL^T parts in chain50.c"
cmp -s out.csv onefile/out.csv || err "the LDL^T in files of its own changes the results: $(diff out.csv onefile/out.csv | head -4)"
(cd straight && MBCC_LOOP_MIN=1000000000 run > log 2>&1) || err "run (straight-line): $(tail -5 straight/log)"
grep -q "loop_joints" straight/$g/chain50*.c && err "MBCC_LOOP_MIN=1000000000 still wrote the loop form"
[ -s straight/$g/chain50.sources ] || err "the straight-line 50-link chain is not in parts and files"
(cd generic && run --path generic > log 2>&1) || err "run (generic): $(tail -5 generic/log)"

# largest difference of two runs relative to each column's range (a column
# that hardly moves: against 1)
compare() {
  awk -F, 'NR == FNR { if (FNR > 1) for (i = 2; i <= NF; i++) { a[FNR, i] = $i; lo[i] = (FNR == 2 || $i < lo[i]) ? $i : lo[i];
                                                                 hi[i] = (FNR == 2 || $i > hi[i]) ? $i : hi[i] }
                       rows = FNR; next }
           FNR > 1 { for (i = 2; i <= NF; i++) { r = hi[i] - lo[i]; if (r < 1) r = 1; d = $i - a[FNR, i]; if (d < 0) d = -d;
                                                  if (d / r > w) w = d / r } n = FNR }
           END { if (n != rows || n < 10) { print "rows differ: " rows " against " n; exit 1 } printf "%.3g\n", w }' "$1" "$2"
}
d=$(compare out.csv straight/out.csv) || err "loop form against straight-line: $d"
awk -v d="$d" 'BEGIN { exit !(d <= 1e-12) }' || err "loop form against straight-line: largest relative difference $d > 1e-12"
e=$(compare out.csv generic/out.csv) || err "loop form against generic: $e"
awk -v d="$e" 'BEGIN { exit !(d <= 1e-6) }' || err "loop form against the generic path: largest relative difference $e > 1e-6"
# total energy (the last column; 0 at the start) and the tip's fall (y, the third column)
awk -F, 'NR == 2 { e0 = $NF } NR > 1 { d = $NF - e0; if (d < 0) d = -d; if (d > w) w = d; y = $3 }
  END { if (NR < 10 || !(w < 1e-6) || !(y < -0.04)) { printf "energy drift %g J, tip y %g\n", w, y; exit 1 } }' out.csv ||
  err "the loop form does not conserve energy"

for cxx in g++ clang++; do
  command -v $cxx > /dev/null || continue
  $cxx -x c++ -std=c++11 -fsyntax-only -Wall -Wextra -Werror -Wno-missing-field-initializers \
    -I"$root/runtime/core" -I"$root/runtime/hosted" $(sources "$g" chain50) > cxx.log 2>&1 || err "$cxx rejects the loop form: $(head -5 cxx.log)"
done
MBCC_LOOP_MIN=0 "$MBCC" compile chain50.yaml --real float -o gen_float > /dev/null || err "compile --real float"
grep -q "loop_joints" gen_float/chain50.c || err "the float model is not in the loop form"
for f in $(sources gen_float chain50); do
  cc -std=c11 -ffreestanding -fno-math-errno -Wall -Wextra -Wdouble-promotion -Wconversion -Werror -DMB_REAL_FLOAT \
    -I"$root/runtime/core" -Igen_float -c "$f" -o /dev/null || err "freestanding float build of the loop form: $f"
done
[ $fail = 0 ] && echo "50-link chain: loop form = straight-line to $d, = generic to $e, = one file exactly; energy conserved; C++ and freestanding"

# the mixed model: chain.sh's 40 rods, the beam after them, its hinge after theirs
mkdir mixed mixed/straight mixed/generic && cd mixed
bash "$root/scripts/chain.sh" 40 chain40flex | awk '
  $0 == "joints:" { print "  beam:"
    print "    type: flexible"
    print "    line: {from: [20, 0, 0], to: [21, 0, 0], elements: 10}"
    print "    section: {area: 0.0002, Iy: 6.666666666666668e-09, Iz: 1.666666666666667e-09, J: 4.577604166666668e-09}"
    print "    material: {E: 70000000000.0, nu: 0.33, density: 2700.0}"
    print "    reference: [0]"
    print "    modes: {count: 4}"
    print "    damping: none" }
  $0 == "outputs:" { print "  hinge_beam: {type: revolute, bodies: [rod40, beam], node: 0, axis: [0, 0, 1]}" }
  { print }
  $0 == "outputs:" { print "  - {name: beam_tip, type: position, body: beam, node: 10}" }' > chain40flex.yaml
cp chain40flex.yaml straight/ && cp chain40flex.yaml generic/
runm() { "$MBCC" run chain40flex.yaml --end 0.1 --precision 17 --plot none -o out.csv "$@"; }
runm > loop.log 2>&1 || err "run (mixed loop form): $(tail -5 loop.log)"
g=generated/chain40flex
grep -q "static const loop_body loop_bodies0\[40\]" "$g/chain40flex.c" || err "the mixed model's 40 rods are not one group"
grep -q "the elements without a loop form, straight-line" "$g/chain40flex.c" || err "the mixed model is not in the mixed loop form"
grep -q "mb_flex_forces(&flex40" "$g/chain40flex.c" || err "the mixed model's beam is not written straight-line"
[ "$(grep -c '^void chain40flex_eval' "$g/chain40flex.c")" = 1 ] || err "the mixed loop form's evaluation is not one function"
(cd straight && MBCC_LOOP_MIN=1000000000 runm > log 2>&1) || err "run (mixed, straight-line): $(tail -5 straight/log)"
grep -q "loop_bodies" straight/$g/chain40flex*.c && err "MBCC_LOOP_MIN=1000000000 still wrote the mixed loop form"
(cd generic && runm --path generic > log 2>&1) || err "run (mixed, generic): $(tail -5 generic/log)"
dm=$(compare out.csv straight/out.csv) || err "mixed loop form against straight-line: $dm"
awk -v d="$dm" 'BEGIN { exit !(d <= 1e-15) }' || err "mixed loop form against straight-line: largest relative difference $dm > 1e-15"
em=$(compare out.csv generic/out.csv) || err "mixed loop form against generic: $em"
awk -v d="$em" 'BEGIN { exit !(d <= 1e-6) }' || err "mixed loop form against the generic path: largest relative difference $em > 1e-6"
# the beam's tip (columns 2-4) fell: the flexible body took part
awk -F, 'NR == 2 { y0 = $3 } NR > 1 { y = $3 } END { if (!(y0 - y > 0.04)) { printf "beam tip fell %g m\n", y0 - y; exit 1 } }' out.csv ||
  err "the mixed model's beam did not fall"
for cxx in g++ clang++; do
  command -v $cxx > /dev/null || continue
  $cxx -x c++ -std=c++11 -fsyntax-only -Wall -Wextra -Werror -Wno-missing-field-initializers \
    -I"$root/runtime/core" -I"$root/runtime/hosted" $(sources "$g" chain40flex) > cxx.log 2>&1 || err "$cxx rejects the mixed loop form: $(head -5 cxx.log)"
done
MBCC_LOOP_MIN=0 "$MBCC" compile chain40flex.yaml --real float -o gen_float > /dev/null || err "compile --real float (mixed)"
grep -q "the elements without a loop form" gen_float/chain40flex.c || err "the float mixed model is not in the mixed loop form"
for f in $(sources gen_float chain40flex); do
  cc -std=c11 -ffreestanding -fno-math-errno -Wall -Wextra -Wdouble-promotion -Wconversion -Werror -DMB_REAL_FLOAT \
    -I"$root/runtime/core" -Igen_float -c "$f" -o /dev/null || err "freestanding float build of the mixed loop form: $f"
done
# a model mostly without a loop form stays straight-line (in parts) unless
# MBCC_LOOP_MIN forces it: a fleet of 8 cars (32 tyres: a group of 32), whose
# chassis, its node markers and the joints on them have none
bash "$root/scripts/fleet.sh" 8 > fleet8.yaml
"$MBCC" compile fleet8.yaml -o gen_fleet > /dev/null || err "compile fleet8"
grep -q "loop_forces" gen_fleet/fleet8*.c && err "the 8-car fleet took the mixed loop form by default"
[ -f gen_fleet/fleet8.sources ] || err "the 8-car fleet is not written in parts"
MBCC_LOOP_MIN=32 "$MBCC" compile fleet8.yaml -o gen_fleet_loops > /dev/null || err "compile fleet8 (MBCC_LOOP_MIN=32)"
grep -q "loop_forces" gen_fleet_loops/fleet8.c || err "MBCC_LOOP_MIN=32 did not force the 8-car fleet's loop form"
[ $fail = 0 ] && echo "40-link chain + flexible beam: mixed loop form = straight-line to $dm, = generic to $em; C++ and freestanding; the fleet stays straight-line"
exit $fail
