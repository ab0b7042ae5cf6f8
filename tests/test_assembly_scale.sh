#!/usr/bin/env bash
# test_assembly_scale.sh: the assembly analysis is sparse.  `mbcc check` of a
# 500-link pendulum chain (scripts/chain.sh; n = 5500) finds the whole chain
# free (500 degrees of freedom, 2500 rows, none redundant) within 5 s of CPU
# (the dense factorizations it replaced took ~3 s at 200 links and grew
# cubically: ~45 s here); and it is near linear: 500 links cost at most
# 8 times as much CPU as 100 links (5x the size; cubic would be 125x), once
# both are above the clock's resolution.
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc).
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

cpu_of_check() { # N: user+system CPU seconds of mbcc check on an N-link chain
  bash "$root/scripts/chain.sh" "$1" > "chain$1.yaml"
  local TIMEFORMAT='%3U %3S'
  { time "$MBCC" check "chain$1.yaml" > "check$1.txt" 2> "check$1.err"; } 2> "time$1.txt" ||
    err "mbcc check of the $1-link chain failed: $(cat "check$1.err")"
  awk '{ print $1 + $2 }' "time$1.txt"
}
c100=$(cpu_of_check 100)
c500=$(cpu_of_check 500)
grep -q "constraint rows   2500 (0 redundant removed)" check500.txt || err "rows: $(grep 'constraint rows' check500.txt)"
grep -q "degrees of freedom 500$" check500.txt || err "dof: $(grep 'degrees of freedom' check500.txt)"
echo "  mbcc check CPU: 100 links $c100 s, 500 links $c500 s"
awk -v c="$c500" 'BEGIN { exit !(c < 5) }' || err "500-link chain took $c500 s of CPU (limit 5 s)"
awk -v a="$c100" -v b="$c500" 'BEGIN { exit !(b < 0.2 || b <= 8 * a) }' ||
  err "not near linear: 100 links $c100 s, 500 links $c500 s"
exit $fail
