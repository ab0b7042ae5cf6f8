#!/usr/bin/env bash
# test_split_files.sh: a large model is written as several translation units
# (compiler/back/emit_files.c) and built by compilers running in parallel
# (compiler/tools/build.c), with the one-file build's results:
#   - mbcc compile of tests/models/hinged_chain10_rigid.yaml writes
#     NAME.sources listing NAME.c, the evaluation's part files, NAME_ldl.c
#     and the straight-line LDL^T's parts NAME_ldl0.c, ..., and NAME_parts.h;
#     NAME.c keeps the model record's LDL^T wrappers and none of its code;
#     every listed file exists and compiles alone;
#   - mbcc run --set k=5 (a run-time spring stiffness) builds it ("N files,
#     2 at a time" with MBCC_JOBS=2); the results equal, to all 17 digits,
#     those of the same model written as one file (MBCC_EVAL_FILE_BYTES=0);
#     the chain conserves its total energy (no damping, no driver) to 1e-6 J
#     as it falls;
#   - a second run reuses the simulator (the stamp covers every file);
#   - with 20 kB a file (MBCC_EVAL_FILE_BYTES=20000) the LDL^T's parts fill
#     several files, and the results are still the one file's to 17 digits;
#   - written again as one file into the same directory, the split's files
#     are gone (nothing stale is built or hashed).
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc), CC.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh
m=hinged_chain10_rigid
# with a spring whose stiffness is a run-time parameter: set_params changes
# the force pools, which the part files then read through <m>_ref_ pointers
cp "$root/tests/models/$m.yaml" chain.yaml
cat >> chain.yaml <<'EOY'
parameters:
  k: {value: 2, runtime: true, min: 0, max: 100, unit: N/m}
forces:
  tip_spring: {type: spring_damper, bodies: [ground, s9], points: [[1.0, 0.5, 0], [1.0, 0, 0]], stiffness: k, free_length: 0.3}
EOY
g=generated/$m

"$MBCC" compile chain.yaml -o "$g" > c.log 2>&1 || err "mbcc compile: $(cat c.log)"
[ -s "$g/$m.sources" ] || err "no $m.sources: $(ls "$g")"
[ -s "$g/${m}_parts.h" ] || err "no ${m}_parts.h"
nfiles=$(wc -l < "$g/$m.sources")
[ "$nfiles" -ge 3 ] || err "only $nfiles files listed: $(cat "$g/$m.sources")"
[ "$(head -1 "$g/$m.sources")" = "$m.c" ] || err "$m.c is not listed first"
grep -q "^#define force_prm ${m}_ref_force_prm" "$g/${m}"_eval*.c || err "the parts do not read the run-time force pool through its pointer"
grep -q "^${m}_ldl.c$" "$g/$m.sources" || err "the LDL^T is not in a file of its own"
grep -q "^${m}_eval0.c$" "$g/$m.sources" || err "no evaluation part file"
grep -q "^${m}_ldl0.c$" "$g/$m.sources" || err "the straight-line LDL^T's parts are not in files of their own"
grep -q "^static int ldl_factor_m(" "$g/$m.c" || err "$m.c lacks the LDL^T wrappers the model record points at"
grep -q "ldl_factor_part\|ldl_forward" "$g/$m.c" && err "LDL^T code left in $m.c"
grep -q "C files (listed in" c.log || err "mbcc compile does not name the list: $(cat c.log)"
while read -r f; do
  [ -s "$g/$f" ] || { err "listed file $f missing"; continue; }
  ${CC:-cc} -std=c99 -Wall -Wextra -Werror -pedantic -fsyntax-only -I"$root/runtime/core" -I"$root/runtime/hosted" \
    "$g/$f" > cc.log 2>&1 || err "$f does not compile alone: $(head -5 cc.log)"
done < "$g/$m.sources"

MBCC_JOBS=2 "$MBCC" run chain.yaml --set k=5 --precision 17 --plot none -o split.csv > r1.log 2>&1 || err "run (split): $(cat r1.log)"
grep -q "files, 2 at a time" r1.log || err "the split model was not compiled file by file: $(cat r1.log)"
ls "$g"/*.objs > /dev/null 2>&1 && err "object directory left behind: $(ls "$g")"
"$MBCC" run chain.yaml --set k=5 --precision 17 --plot none -o split2.csv > r2.log 2>&1 || err "second run: $(cat r2.log)"
grep -q "up to date" r2.log || err "the second run recompiled: $(cat r2.log)"

mkdir one && cp chain.yaml one/
(cd one && MBCC_EVAL_FILE_BYTES=0 "$MBCC" run chain.yaml --set k=5 --precision 17 --plot none -o one.csv > r.log 2>&1) ||
  err "run (one file): $(cat one/r.log)"
[ -e "one/$g/$m.sources" ] && err "MBCC_EVAL_FILE_BYTES=0 still split the model"
cmp -s split.csv one/one.csv || err "the split build's results differ from the one-file build's: $(diff split.csv one/one.csv | head -4)"
mkdir small && cp chain.yaml small/
(cd small && MBCC_EVAL_FILE_BYTES=20000 "$MBCC" run chain.yaml --set k=5 --precision 17 --plot none -o small.csv > r.log 2>&1) ||
  err "run (20 kB files): $(cat small/r.log)"
nldl=$(grep -c "^${m}_ldl[0-9]*\.c$" "small/$g/$m.sources")
[ "$nldl" -ge 2 ] || err "20 kB files: the LDL^T's parts in $nldl files"
cmp -s small/small.csv one/one.csv || err "the 20 kB files' results differ from the one-file build's: $(diff small/small.csv one/one.csv | head -4)"
# total energy (the last column; 0 at the start) conserved to 1e-6 J while
# the chain falls (the tip drops more than 0.1 m: its potential energy
# changes by joules)
awk -F, 'NR == 2 { e0 = $NF } NR > 1 { d = $NF - e0; if (d < 0) d = -d; if (d > w) w = d; y = $3 }
  END { if (NR < 10 || !(w < 1e-6) || !(y < -0.1)) { printf "energy drift %g J, tip y %g\n", w, y; exit 1 } }' split.csv ||
  err "the split build does not conserve energy"

MBCC_EVAL_FILE_BYTES=0 "$MBCC" compile chain.yaml -o "$g" > c2.log 2>&1 || err "compile as one file: $(cat c2.log)"
left=$(cd "$g" && ls "$m.sources" "${m}_parts.h" "${m}"_ldl*.c "${m}"_eval*.c 2>/dev/null)
[ -z "$left" ] && [ -s "$g/$m.c" ] || err "stale split files after writing one file: $left"
[ $fail = 0 ] && echo "split into $nfiles files: built in parallel, results identical to one file, energy conserved"
exit $fail
