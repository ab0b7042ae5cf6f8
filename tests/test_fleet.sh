#!/usr/bin/env bash
# test_fleet.sh: the fleet of scripts/fleet.sh (N rigid-chassis sports cars of
# models/sports_car/rigid_car.yaml, side by side in their lanes: the vehicle
# table of make scaling) against the single car, models/sports_car.yaml in
# its scene `rigid`:
#   1. a 2-car fleet's mbcc check counts (bodies, coordinates, constraint
#      rows and redundant ones, system dimension, nnz(K)) are exactly twice
#      the single car's;
#   2. over 0.05 s at 60 km/h each car of the 2-car fleet, the second 3.5 m
#      to the left, moves as the single car (chassis height and x, pitch, the
#      four tyre loads, to 1e-9 relative): the chassis from the modal file
#      is the FE chassis made rigid, and the car moved by its instance's
#      `position` (its corners and tyres, instances inside it, with it) is
#      the same car.  Both start at the design pose, not at a static equilibrium
#      computed first: Newton leaves the free directions (the car's x, the
#      wheels' spin, ...) where its last step put them, which differs
#      between one car and two by ~1e-6, and the tyres' slips then differ by
#      ~1e-5 relative for a few ms.  The single car's bump lies at x >= 10 m:
#      not reached in 0.05 s (checked), so both roads are flat under the cars;
#   3. models/sports_car/rigid_chassis.modal.yaml is what scripts/rigid_chassis.sh
#      writes from the FE model now;
#   4. fleet.sh refuses N that is not a whole number from 1 to 500 (exit 2);
#   5. a fleet of 30 cars (510 bodies, 210 subsystem instances: each one a file
#      of the diagnostics' table) is read whole, its counts 30 times the single
#      car's; a model file of 2^20 lines gets the reader's line limit (exit 2).
# Generic path (no C compile): a few seconds.
set -u
cd "$(dirname "$0")/.."
# shellcheck source=tests/shell_setup.sh
. tests/shell_setup.sh

single="$root/models/sports_car.yaml"
bash "$root/scripts/fleet.sh" 2 > fleet2.yaml || err "scripts/fleet.sh 2 failed"

# 1. counts: the numbers of mbcc check's size lines
counts() { # counts MODEL [ARGS]: one line of numbers
  "$MBCC" check "$@" 2> /dev/null | awk '
    /^  bodies / || /^  coordinates / || /^  constraint rows / || /^  system dimension / || /^  nnz\(K\) / {
      gsub(/\([0-9.]+% dense\)/, ""); gsub(/[^0-9 ]/, " "); printf "%s ", $0 }' | tr -s ' '
}
one=$(counts "$single" --scene rigid)
two=$(counts fleet2.yaml)
[ -n "$one" ] && [ -n "$two" ] || err "mbcc check gave no counts (single: '$one', fleet: '$two')"
doubled=$(echo "$one" | awk '{ for (i = 1; i <= NF; i++) $i = 2 * $i; print }')
one=$(echo "$one" | awk '{ $1 = $1; print }')
two=$(echo "$two" | awk '{ $1 = $1; print }')
echo "single car: $one; 2-car fleet: $two"
[ "$two" = "$doubled" ] || err "the 2-car fleet's counts '$two' are not twice the single car's '$one'"

# 2. the motion, both from the design pose
sed 's/equilibrium: true/equilibrium: false/' fleet2.yaml > fleet2_design.yaml
sed -e 's/equilibrium: true/equilibrium: false/' -e "s|^include: |include: $root/models/|" "$single" > single_design.yaml
grep -q 'equilibrium: false' fleet2_design.yaml && grep -q 'equilibrium: false' single_design.yaml ||
  err "could not switch off the static equilibrium (the models' simulation lines changed?)"
run() { # run MODEL CSV [ARGS]
  m=$1 csv=$2; shift 2
  "$MBCC" run "$m" --path generic --end 0.05 -o "$csv" --plot none "$@" > "$csv.log" 2>&1 ||
    err "mbcc run $m $* failed: $(tail -3 "$csv.log")"
}
run single_design.yaml single.csv --scene rigid
run fleet2_design.yaml fleet.csv
if [ -s single.csv ] && [ -s fleet.csv ]; then
  [ "$(wc -l < single.csv)" = "$(wc -l < fleet.csv)" ] || err "the runs have different numbers of rows"
  for car in 1 2; do
    worst=$(awk -F, -v car="$car" 'BEGIN { n = split("chassis_z chassis_x pitch FL_fz FR_fz RL_fz RR_fz", q, " ") }
      FNR == 1 { f++; for (i = 1; i <= NF; i++) col[f, $i] = i; next }
      f == 1 { single[FNR] = $0; next }
      { split(single[FNR], s, ",")
        for (j = 1; j <= n; j++) {
          a = s[col[1, q[j]]]; b = $col[2, "car" car "_" q[j]]
          if (a == "" || b == "") { print "column " q[j] " missing"; exit }
          d = a - b; d = d < 0 ? -d : d; m = a < 0 ? -a : a
          r = d / (m > 1e-3 ? m : 1e-3) # pitch (rad) starts at 0: relative to 1 mrad
          if (r > worst[j]) worst[j] = r
          if (q[j] == "chassis_x" && a > 5) far = 1 } }
      END { if (far) print "the car reached x = 5 m (the bump at 10 m is near)"
            for (j = 1; j <= n; j++) printf "%s %.2g ", q[j], worst[j] }' single.csv fleet.csv)
    echo "car $car against the single car, largest relative difference: $worst"
    echo "$worst" | awk '{ for (i = 2; i <= NF; i += 2) if ($i + 0 > 1e-9 || $i !~ /^[0-9.e+-]+$/) bad = 1; exit bad }' ||
      err "car $car does not move as the single car: $worst"
  done
fi

# 3. the chassis's modal file is current
bash "$root/scripts/rigid_chassis.sh" > rigid_chassis.modal.yaml 2> rigid_chassis.log || err "scripts/rigid_chassis.sh failed: $(tail -3 rigid_chassis.log)"
cmp -s rigid_chassis.modal.yaml "$root/models/sports_car/rigid_chassis.modal.yaml" ||
  err "models/sports_car/rigid_chassis.modal.yaml is stale: bash scripts/rigid_chassis.sh > models/sports_car/rigid_chassis.modal.yaml"

# 4. bad N
for n in 0 -1 1.5 abc '' 007 501 99999999999999999999; do
  bash "$root/scripts/fleet.sh" "$n" > out.yaml 2> out.err
  rc=$?
  [ "$rc" = 2 ] && grep -q 'error' out.err || err "fleet.sh '$n': exit $rc (expected 2 with an error): $(cat out.err)"
done
bash "$root/scripts/fleet.sh" > /dev/null 2>&1; [ $? = 2 ] || err "fleet.sh without N: not exit 2"

# 5. many instances; the line limit that keeps file:line:col exact
bash "$root/scripts/fleet.sh" 30 > fleet30.yaml || err "scripts/fleet.sh 30 failed"
thirty=$(counts fleet30.yaml | awk '{ $1 = $1; print }')
times30=$(echo "$one" | awk '{ for (i = 1; i <= NF; i++) $i = 30 * $i; print }')
[ "$thirty" = "$times30" ] || err "30-car fleet counts '$thirty', expected 30 x the single car's: '$times30'"
{ head -c 1048576 /dev/zero | tr '\0' '\n'; cat fleet2.yaml; } > long.yaml
"$MBCC" check long.yaml > long.out 2>&1
rc=$?
[ "$rc" = 2 ] && grep -q 'long.yaml: error: more than 1048575 lines' long.out ||
  err "a model of 2^20 lines: exit $rc, expected 2 and the line limit: $(head -3 long.out)"

exit $fail
