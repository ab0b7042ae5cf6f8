#!/usr/bin/env bash
# test_scaling_parts.sh: a large model's generated functions stay bounded in
# what they cost the C compiler (counted, not timed: docs/architecture.md,
# "The evaluation in parts"), and the bounded form computes what one function
# computes:
#   - mbcc compile of a 200-link chain (scripts/chain.sh 200): every
#     evaluation part's text plus 300 bytes per inlined kernel call (the cost
#     the parts are cut by) stays under two parts' budget (48 000), init is in
#     parts of at most 500 statement lines (+ one element), <m>_eval calls its
#     parts in a loop over a table, and no function of any listed file exceeds
#     2 000 lines (the single 2 600-line init and the 200-frame part of
#     before both fail this);
#   - an 8-link chain written with tiny parts (MBCC_EVAL_PART_BYTES=600,
#     MBCC_INIT_PART_LINES=20: split init, looped part calls) gives, to all
#     17 digits, the results of the same chain written as one function in
#     one file, and conserves its total energy as it falls.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

bash "$root/scripts/chain.sh" 200 > chain200.yaml
# straight-line: by default a chain this long takes the loop form (emit_loops.c)
MBCC_LOOP_MIN=1000000000 "$MBCC" compile chain200.yaml -o g200 > c.log 2>&1 || err "mbcc compile chain200: $(cat c.log)"
[ -s g200/chain200.sources ] || err "the 200-link chain is not in several files: $(ls g200)"
nfiles=$(wc -l < g200/chain200.sources)
# each evaluation part: bytes + 300 per kernel call (not the small vector helpers)
worst=$(cat g200/chain200_eval*.c | awk '
  /^EVAL_NOINLINE void .*_eval_part[0-9]+\(/ { inpart = 1; cost = 0; name = $3; sub(/\(.*/, "", name) }
  inpart {
    cost += length($0) + 1
    line = $0
    while (match(line, /mb_[a-z0-9_]+\(/)) {
      f = substr(line, RSTART, RLENGTH - 1)
      if (f != "mb_cross3" && f != "mb_dot3" && f != "mb_mul3" && f != "mb_mul3t" && f != "mb_col3") cost += 300
      line = substr(line, RSTART + RLENGTH)
    }
  }
  inpart && /^}/ { inpart = 0; n++; if (cost > max) { max = cost; at = name } }
  END { printf "%d %d %s\n", n, max, at }')
read -r nparts maxcost maxpart <<< "$worst"
[ "${nparts:-0}" -gt 32 ] || err "only ${nparts:-0} evaluation parts"
[ "${maxcost:-99999999}" -le 48000 ] || err "evaluation part $maxpart costs $maxcost (bound 48000)"
grep -q "for (int i = 0; i < $nparts; i++) part\[i\](&W" g200/chain200.c || err "chain200_eval does not call its $nparts parts in a loop"
# init in parts; each part's statements, and every function of every file, bounded
ninit=$(grep -c "^static INIT_NOINLINE void chain200_init_part[0-9]*(mb_real \*Kx) {" g200/chain200.c)
[ "$ninit" -ge 4 ] || err "init is not in parts ($ninit)"
while read -r f; do
  awk -v f="$f" '
    /^[a-zA-Z].*\) \{$/ || /^[a-zA-Z].*\($/ { name = $0; start = NR; init = /_init_part[0-9]+\(/ }
    /^}/ && start {
      n = NR - start - 1
      if (n > 2000) { printf "%s: a function of %d lines: %s\n", f, n, substr(name, 1, 60); bad = 1 }
      if (init && n > 520) { printf "%s: an init part of %d lines\n", f, n; bad = 1 }
      start = 0
    }
    END { exit bad }' "g200/$f" || err "a function over its bound"
done < g200/chain200.sources

# tiny parts against one function, run to 17 digits
bash "$root/scripts/chain.sh" 8 > chain8.yaml
mkdir split one && cp chain8.yaml split/ && cp chain8.yaml one/
(cd split && MBCC_EVAL_PART_BYTES=600 MBCC_INIT_PART_LINES=20 "$MBCC" run chain8.yaml --end 0.2 --precision 17 --plot none -o s.csv > r.log 2>&1) ||
  err "run (tiny parts): $(cat split/r.log)"
(cd one && MBCC_EVAL_PART_BYTES=0 MBCC_EVAL_FILE_BYTES=0 MBCC_INIT_PART_LINES=0 "$MBCC" run chain8.yaml --end 0.2 --precision 17 --plot none -o o.csv > r.log 2>&1) ||
  err "run (one function): $(cat one/r.log)"
g=split/generated/chain8
grep -q "^static INIT_NOINLINE void chain8_init_part1(" $g/chain8.c || err "the tiny parts' init is not split"
grep -q "part\[i\](&W" $g/chain8.c || err "the tiny parts are not called in a loop"
grep -q "_init_part\|_eval_part" one/generated/chain8/chain8.c && err "the one-function build has parts"
cmp -s split/s.csv one/o.csv || err "tiny parts and one function differ: $(diff split/s.csv one/o.csv | head -4)"
# total energy (the last column) conserved to 1e-6 J while the tip falls
awk -F, 'NR == 2 { e0 = $NF } NR > 1 { d = $NF - e0; if (d < 0) d = -d; if (d > w) w = d; y = $3 }
  END { if (NR < 10 || !(w < 1e-6) || !(y < -0.1)) { printf "energy drift %g J, tip y %g\n", w, y; exit 1 } }' split/s.csv ||
  err "the split build does not conserve energy"
[ $fail = 0 ] && echo "200 links: $nfiles files, $nparts evaluation parts (costliest $maxcost), init in $ninit parts; tiny parts equal one function"
exit $fail
