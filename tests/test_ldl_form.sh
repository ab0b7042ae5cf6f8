#!/usr/bin/env bash
# test_ldl_form.sh: the emitted LDL^T's straight-line / looped choice by its
# measured compile-time limit (compiler/back/order.h, docs/architecture.md):
#   - mbcc check reports the straight-line code's estimated gcc CPU and the
#     limit; the form is straight-line exactly when the estimate is within it
#     (the slider-crank, the rigid and flexible cars: straight-line; the
#     flexible_virtual car, whose block pivots add code: looped);
#   - the estimate is gcc's actual time within a factor of 4 (CPU time grows with the load): the
#     straight-line LDL^T files of a 10-link chain compiled with cc -O2 (CPU,
#     user + system);
#   - MBCC_LDL_BUDGET still forces a form (0: loops, 1e12: straight-line).
# Environment: MBCC (set by tests/run_tests.sh; default build/mbcc), CC.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

# form and estimate of "LDL^T code" in mbcc check's report
form_of() { "$MBCC" check "$@" 2>/dev/null | sed -n 's/^  LDL^T code *\([a-z-]*\) (straight-line: about \([0-9.]*\) s of gcc CPU, limit \([0-9.]*\) s.*/\1 \2 \3/p'; }

for spec in "models/slider_crank.yaml:straight-line" "models/sports_car.yaml --scene rigid:straight-line" \
  "models/sports_car.yaml --scene flexible:straight-line" "models/sports_car.yaml --scene flexible_virtual:looped"; do
  args=${spec%%:*}
  want=${spec##*:}
  # shellcheck disable=SC2086
  read -r form est lim <<< "$(cd "$root" && form_of $args)"
  [ -n "${lim:-}" ] || { err "$args: no estimate in mbcc check"; continue; }
  rule=$(awk -v e="$est" -v l="$lim" 'BEGIN { print (e <= l) ? "straight-line" : "looped" }')
  [ "$form" = "$rule" ] || err "$args: $form, but the estimate $est s against the limit $lim s says $rule"
  [ "$form" = "$want" ] || err "$args: $form (estimate $est s), expected $want"
done

# the estimate against gcc's time on a 10-link chain, straight-line
m=hinged_chain10_rigid
read -r form est lim <<< "$(form_of "$root/tests/models/$m.yaml")"
MBCC_LDL_BUDGET=1e12 "$MBCC" compile "$root/tests/models/$m.yaml" -o s > c.log 2>&1 || err "compile: $(cat c.log)"
grep -q "_LDL_STRAIGHT 1" "s/$m.h" || err "MBCC_LDL_BUDGET=1e12 did not give straight-line code"
: > t
for c in s/"$m"_ldl*.c; do
  /usr/bin/time -a -o t -f "%U %S" "${CC:-cc}" -std=c11 -O2 -I"$root/runtime/core" -I"$root/runtime/hosted" -Is -c "$c" -o x.o ||
    err "$c does not compile"
done
cpu=$(awk '{ s += $1 + $2 } END { print s }' t)
awk -v c="$cpu" -v e="$est" 'BEGIN { exit !(c > e / 4 && c < 4 * e) }' ||
  err "gcc took $cpu s of CPU on the straight-line LDL^T files, the estimate is $est s"
MBCC_LDL_BUDGET=0 "$MBCC" compile "$root/tests/models/$m.yaml" -o l > c.log 2>&1 || err "compile: $(cat c.log)"
grep -q "_LDL_STRAIGHT 0" "l/$m.h" || err "MBCC_LDL_BUDGET=0 did not give loops"
[ $fail = 0 ] && echo "forms by the compile-time limit; chain's straight-line LDL^T: estimate $est s, gcc $cpu s CPU"
exit $fail
