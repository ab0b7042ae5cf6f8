#!/usr/bin/env bash
# test_sports_car.sh: models/sports_car.yaml (the Stratos replica of seed 000)
# against the data and the acceptance checks of the vehicle specification
# (/work/shared/reference/vehicle-model-spec.md, "spec §N").  Checks 1-5 take
# the scene 'rigid' (the chassis rigid, spec §12 items 1-6), standing still on
# the flat road; 6 runs the bump study, 7 the flat road at speed.  Exit 0 =
# pass.  Every run takes the generic path (no C compile).
#   1. mbcc check: the design pose closes without a Newton iteration (every
#      joint is one global point shared by its bodies, spec §6.3: that the
#      hardpoints are the spec's is checked by 4.), the two rear lower ball
#      joints' x rows are found redundant (spec §3.3: rank 86 of 88), 16
#      degrees of freedom;
#   2. mass and centre of mass of all 17 bodies from the momentum output of
#      uniform translations (p = M v, h = M r_cg x v): 980 kg, (-1.231, 0,
#      0.420) (spec §4);
#   3. released at design with gravity and the preloads, the car stays put
#      (< 1 mm in 1 s, spec §12); the wheel loads carried by the tyre stand-ins
#      sum to the weight (to 1e-4: the run is dynamic, the preloads rounded to
#      0.1 N) and split by moment balance about the axles: 2092.8 /
#      2714.1 N (spec §4);
#   4. corner kinematics on a rig (chassis fixed, the lower arms driven):
#      camber, spring length and half-track against the tables of spec §6.1,
#      §6.2 at -80, -40, +40, +80 mm of wheel travel (a strong check of the
#      hardpoints);
#   5. ride: undamped free decay of the chassis guided in heave, then in
#      pitch, against the bounce/pitch frequencies of the corner ride rates of
#      spec §7 (1.60 Hz front, 1.75 Hz rear with 179.8 / 237.2 kg of sprung
#      mass per corner), to 1.5 %.  Measured: heave +0.3 %, pitch -0.8 %; the
#      ideal two-mass model leaves out the arms' and strut rods' inertia moving
#      with the chassis and the rear's rising motion ratio under preload;
#   6. the bump at 60 km/h (spec §9), rigid and flexible chassis, each started
#      from its static equilibrium: Newton's residual, the static wheel loads
#      against the weight (to 1e-6) and the moment balance, the whole car's
#      CM acceleration against the tyres' vertical forces (Newton's second
#      law, at every output), the bands of spec §12 (a reduced-model
#      estimate: CM vertical acceleration peaks, peak tyre loads, front-left
#      bump travel; both left tyres leave the road after the crest); the
#      flexible chassis adds to the rigid one's peak acceleration (seed
#      Fig. 12); the flexible chassis stiffened 1e3 times gives the rigid
#      chassis's response; the joints through 8 virtual bodies (scene
#      flexible_virtual) give the motion of the joints on the nodes;
#   7. straight running on the flat road: the speed falls by the rolling
#      resistance only, the course holds.
# The variants (at rest, on a rig, on the flat road, a stiffer chassis)
# include the model's car (models/sports_car/car.yaml) with their own
# parameters, road, joints, outputs and scenes: no edit of the model's text.
# About 15 s of CPU (generic path, no C compile).
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
model="$root/models/sports_car.yaml"

run() { # run MODEL CSV [ARGS]: generic path, quiet; the log beside the CSV
  m=$1 csv=$2; shift 2
  "$MBCC" run "$m" --path generic -o "$csv" --plot none "$@" > "$csv.log" 2>&1 ||
    { err "mbcc run $m $* failed: $(tail -3 "$csv.log")"; return 1; }
}
# the model's car (models/sports_car/car.yaml) with its parameters as given in
# PARAMS (name=value ...; the others as the model has them, read from mbcc
# check), on the road ROAD; the scenes 'rigid' (deactivating DEACTIVATE, a
# comma-separated list) and 'flexible' as the model's.  A variant appends its
# joints, drivers, outputs and simulation settings.
car() { # car PARAMS ROAD [DEACTIVATE]
  local p params=""
  for p in v0 vz0 chassis_vz chassis_wy spin_front spin_rear tyre_slip; do   # the first value given wins
    params="$params $p=$(printf '%s\n' $1 | awk -F= -v p="$p" '$1 == p { print $2; exit }')"
    [ "${params%=}" = "$params" ] ||
      params="$params$(awk -v p="$p" '$1 == p && $3 ~ /^compile-time/ { print $2; exit }' check.log)"
  done
  cat <<EOF
name: sports_car
gravity: [0, 0, -9.81]
parameters: {$(printf '%s\n' $params | sed 's/=/: /' | paste -sd, - | sed 's/,/, /g')}
roads: {bump_road: $2}
include: $root/models/sports_car/car.yaml
scenes:
  rigid: {bodies: {chassis: {coupling: rigid}}, deactivate: [${3:-}]}
  flexible: {simulation: {joints_on_flexible: direct}}
EOF
}
# standing still on the flat road
base() { car "${1:-} v0=0 vz0=0 spin_front=0 spin_rear=0" '{type: flat}' "${2:-}"; }

# 1. assembly and redundancy
if "$MBCC" check "$model" --scene rigid > check.log 2>&1; then
  grep -q 'constraint rows   86 (2 redundant removed)' check.log || err "not 86 rows with 2 redundant removed: $(grep 'constraint rows' check.log)"
  grep -q 'degrees of freedom 16' check.log || err "not 16 DOF: $(grep 'degrees of freedom' check.log)"
  for j in RL_lower_ball RR_lower_ball; do
    grep -q "redundant constraint removed: spherical '$j': coincident points, x" check.log || err "the x row of $j is not reported redundant"
  done
  [ "$(grep -c 'redundant constraint removed' check.log)" = 2 ] || err "other rows reported redundant: $(grep 'redundant' check.log)"
  ! grep -q 'positions corrected' check.log || err "the design pose needed Newton iterations: $(grep 'positions corrected' check.log)"
else
  err "mbcc check failed: $(tail -3 check.log)"
fi
# 2. mass and centre of mass: every body translating at v; momentum p = M v,
#    angular momentum about the origin h = M r_cg x v (no rotation)
mass_run() { # mass_run NAME PARAMS (every body's initial velocity)
  base "$2" > "$1.yaml"
  printf 'outputs:\n  - {name: L, type: momentum}\nsimulation: {end_time: 0.001}\n' >> "$1.yaml"
  run "$1.yaml" "$1.csv" --scene rigid
}
if mass_run up 'vz0=1 chassis_vz=1' && mass_run fwd 'v0=1'; then
  # columns: t, px, py, pz, hx, hy, hz.  v = z: h = M (y, -x, 0); v = x: h = M (0, z, -y)
  read -r M xg yg <<< "$(awk -F, 'NR == 2 { printf "%.9g %.9g %.9g", $4, -$6 / $4, $5 / $4 }' up.csv)"
  zg=$(awk -F, 'NR == 2 { printf "%.9g", $6 / $2 }' fwd.csv)
  echo "mass $M kg, centre of mass ($xg, $yg, $zg) m"
  awk -v M="$M" -v x="$xg" -v y="$yg" -v z="$zg" 'BEGIN {
    if ((M - 980) ^ 2 > 1e-4 || (x + 1.231) ^ 2 > 2.5e-7 || y ^ 2 > 1e-18 || (z - 0.420) ^ 2 > 2.5e-7) exit 1 }' ||
    err "mass $M kg and centre of mass ($xg, $yg, $zg): spec §4 has 980 kg at (-1.231, 0, 0.420)"
else
  M=980 xg=-1.231
fi

# 3. released at design on the flat road: stays put; wheel loads
base > car.yaml
cat >> car.yaml <<'EOF'
outputs:
  - {name: chassis_z, type: position, body: chassis, component: z}
  - {name: chassis_x, type: position, body: chassis, component: x}
  - {name: FL_wheel_z, type: position, body: FL_wheel, component: z}
  - {name: RR_wheel_z, type: position, body: RR_wheel, component: z}
  - {name: pitch, type: angle, body: chassis, axis: [0, 1, 0]}
  - {name: roll, type: angle, body: chassis, axis: [1, 0, 0]}
  - {name: FL_Fz, type: tyre, element: FL_tyre, component: Fz}
  - {name: FR_Fz, type: tyre, element: FR_tyre, component: Fz}
  - {name: RL_Fz, type: tyre, element: RL_tyre, component: Fz}
  - {name: RR_Fz, type: tyre, element: RR_tyre, component: Fz}
simulation: {end_time: 2.0, output_step: 0.005}
EOF
if run car.yaml car.csv --scene rigid; then
  # the largest displacement in the first second (angles times 1.3 m, about half the wheelbase)
  awk -F, 'NR == 1 { next } NR == 2 { for (i = 2; i <= 5; i++) s[i] = $i; next } $1 > 1.0001 { exit }
           { for (i = 2; i <= 5; i++) if ((d = ($i - s[i]) ^ 2) > m) { m = d; w = i }
             for (i = 6; i <= 7; i++) if ((d = ($i * 1.3) ^ 2) > m) { m = d; w = i } }
           END { printf "largest drift in 1 s: %.3g mm (column %d)\n", sqrt(m) * 1000, w; exit m > 1e-6 }' car.csv ||
    err "the car released at design drifts by more than 1 mm in 1 s (spec §12)"
  # the tyres' normal loads at t = 2 (settled: the tyres' free radius puts the
  # design pose 0.4 mm off their equilibrium, spec §5 rounds the wheel heights)
  loads=$(awk -F, 'END { printf "%.6f %.6f %.6f %.6f", $8, $9, $10, $11 }' car.csv)
  echo "wheel loads FL FR RL RR: $loads N"
  # truth: the weight M g, split by moment balance about the contact lines x = 0, -2.18
  awk -v M="$M" -v x="$xg" -v L="$loads" 'BEGIN { split(L, f, " "); W = M * 9.81
    front = W * (x + 2.18) / 2.18 / 2; rear = W / 2 - front
    printf "from the mass distribution: %.2f N front, %.2f N rear per wheel\n", front, rear
    bad = 0
    if (((f[1] + f[2] + f[3] + f[4]) / W - 1) ^ 2 > 1e-8) { print "loads do not sum to the weight"; bad = 1 }
    for (i = 1; i <= 2; i++) if ((f[i] / front - 1) ^ 2 > 1e-6 || (f[i + 2] / rear - 1) ^ 2 > 1e-6) { print "not the moment balance"; bad = 1 }
    if ((front - 2092.8) ^ 2 > 0.04 || (rear - 2714.1) ^ 2 > 0.04) { print "not spec §4 (2092.8 / 2714.1 N)"; bad = 1 }
    exit bad }' || err "static wheel loads: $loads"
fi

# 4. corner kinematics: chassis fixed, FL and RL lower arms turned by 0.26 sin(pi t / 2) rad
# (the road 1 m down: no tyre touches it, so no tyre force steers the driven corners)
car "v0=0 vz0=0 spin_front=0 spin_rear=0" '{type: flat, height: -1.0}' > rig.yaml
cat >> rig.yaml <<'EOF'
joints:
  rig_fix: {type: fixed, bodies: [ground, chassis], point: [-1.24, 0, 0.44]}
drivers:
  FL_travel: {joint: FL_lower_pivot, motion: {type: sine, amplitude: 0.26, frequency: 0.25}}
  RL_travel: {joint: RL_lower_pivot, motion: {type: sine, amplitude: 0.26, frequency: 0.25}}
outputs:   # camber, SAE sign (top outward +): minus the rotation about +x on the left
  - {name: FL_wz, type: position, body: FL_wheel, component: z}
  - {name: FL_camber, type: angle, body: FL_upright, axis: [1, 0, 0], scale: -57.29577951308232}
  - {name: FL_seat, type: position, body: FL_lower_wishbone, point: [0, 0.56, 0.165]}
  - {name: FL_wy, type: position, body: FL_wheel, component: y}
  - {name: RL_wz, type: position, body: RL_wheel, component: z}
  - {name: RL_camber, type: angle, body: RL_strut_tube, axis: [1, 0, 0], scale: -57.29577951308232}
  - {name: RL_top, type: position, body: RL_strut_rod, point: [-2.18, 0.60595, 0.660]}
  - {name: RL_low, type: position, body: RL_strut_tube, point: [-2.18, 0.64162, 0.420]}
  - {name: RL_wy, type: position, body: RL_wheel, component: y}
simulation: {end_time: 3.0, output_step: 0.005}
EOF
if run rig.yaml rig.csv --scene rigid; then
  # bump on the rise (t <= 1), rebound on the fall to -0.26 rad (2 <= t <= 3); the
  # spec's tables: dz, FL camber [deg], spring length [mm], half-track [mm], then RL
  awk -F, '
    function put(k) { n[k]++; j = n[k]
      z[k, j] = ($2 - 0.3108) * 1000; c[k, j, 1] = $3
      c[k, j, 2] = sqrt($4 ^ 2 + ($5 - 0.48) ^ 2 + ($6 - 0.565) ^ 2) * 1000; c[k, j, 3] = $7 * 1000
      zr[k, j] = ($8 - 0.3077) * 1000; r[k, j, 1] = $9
      r[k, j, 2] = sqrt(($10 - $13) ^ 2 + ($11 - $14) ^ 2 + ($12 - $15) ^ 2) * 1000; r[k, j, 3] = $16 * 1000 }
    NR > 1 && $1 <= 1.0 { put(1) }
    NR > 1 && $1 >= 2.0 { put(2) }
    function at(k, front, q, x,   j, a, b, w) {   # interpolate at wheel travel x
      for (j = 1; j < n[k]; j++) {
        a = front ? z[k, j] : zr[k, j]; b = front ? z[k, j + 1] : zr[k, j + 1]
        if ((a - x) * (b - x) <= 0 && a != b) { w = (x - a) / (b - a)
          return front ? c[k, j, q] + w * (c[k, j + 1, q] - c[k, j, q]) : r[k, j, q] + w * (r[k, j + 1, q] - r[k, j, q]) } }
      return "none" }
    BEGIN { tol[1] = 0.03; tol[2] = 0.3; tol[3] = 0.3; what[1] = "camber [deg]"; what[2] = "spring length [mm]"; what[3] = "half-track [mm]"
      #        dz     FL camber, L, half-track   RL camber, L, half-track      (spec §6.1, §6.2)
      T[1] = "-80  1.08 466.8 708.8   1.80 319.3 726.5"
      T[2] = "-40  0.74 437.3 714.8   0.76 281.3 730.0"
      T[3] = " 40 -1.14 378.5 709.6  -0.41 203.1 726.7"
      T[4] = " 80 -2.74 348.9 698.5  -0.37 162.5 720.2" }
    END { bad = 0
      for (i = 1; i <= 4; i++) { split(T[i], e, " "); x = e[1]; k = x > 0 ? 1 : 2
        for (q = 1; q <= 3; q++) {
          f = at(k, 1, q, x); g = at(k, 0, q, x)
          printf "dz %+d mm: FL %s %s (spec %s), RL %s (spec %s)\n", x, what[q], f, e[1 + q], g, e[4 + q]
          if (f == "none" || g == "none" || (f - e[1 + q]) ^ 2 > tol[q] ^ 2 || (g - e[4 + q]) ^ 2 > tol[q] ^ 2) bad = 1 } }
      exit bad }' rig.csv || err "corner kinematics differ from spec §6"
fi

# 5. ride frequencies: dampers removed, chassis guided in heave or in pitch about
#    its CG; the tyres radial springs only (at standstill their slip forces are
#    stiff viscous dampers that hold the contact patches: not part of the ride rate)
ride_run() { # ride_run NAME JOINT-LINE CHASSIS-START (the chassis's initial velocity)
  base "tyre_slip=0 $3" FL_damper,FR_damper,RL_strut_damper,RR_strut_damper > "$1.yaml"
  printf 'joints:\n%s\n' "$2" >> "$1.yaml"
  cat >> "$1.yaml" <<'EOF'
outputs:
  - {name: z, type: position, body: chassis, component: z}
  - {name: pitch, type: angle, body: chassis, axis: [0, 1, 0]}
simulation: {end_time: 4.0, output_step: 0.002, rtol: 1.0e-9, atol: 1.0e-11}
EOF
  run "$1.yaml" "$1.csv" --scene rigid
}
# frequency from the upward zero crossings of a column about its initial value
freq() { awk -F, -v col="$2" 'NR == 2 { y0 = $col } NR > 2 { y = $col - y0
  if (py < 0 && y >= 0) { t = pt - py * ($1 - pt) / (y - py); if (!n) t0 = t; t1 = t; n++ } py = y; pt = $1 }
  END { if (n < 4) print "none"; else printf "%.5f", (n - 1) / (t1 - t0) }' "$1"; }
if ride_run heave '  rig_heave: {type: prismatic, bodies: [ground, chassis], point: [-1.24, 0, 0.44], axis: [0, 0, 1]}' 'chassis_vz=0.05' &&
   ride_run pitch '  rig_pitch: {type: revolute, bodies: [ground, chassis], point: [-1.24, 0, 0.44], axis: [0, 1, 0]}' 'chassis_wy=0.05'; then
  fh=$(freq heave.csv 2); fp=$(freq pitch.csv 3)
  # truth: ride rate per corner k = m_corner (2 pi f)^2; heave 2 (kf + kr) / m, pitch 2 (kf a^2 + kr b^2) / Iyy
  awk -v fh="$fh" -v fp="$fp" 'BEGIN { pi = 3.141592653589793
    kf = 179.8 * (2 * pi * 1.60) ^ 2; kr = 237.2 * (2 * pi * 1.75) ^ 2; a = 1.24; b = 0.94
    eh = sqrt(2 * (kf + kr) / 834) / (2 * pi); ep = sqrt(2 * (kf * a * a + kr * b * b) / 799.6) / (2 * pi)
    printf "ride: heave %s Hz (from 1.60/1.75 Hz corners: %.4f), pitch %s Hz (%.4f)\n", fh, eh, fp, ep
    exit fh == "none" || fp == "none" || (fh / eh - 1) ^ 2 > 2.25e-4 || (fp / ep - 1) ^ 2 > 2.25e-4 }' ||
    err "ride frequencies are not those of 1.60 / 1.75 Hz corners (within 1.5 %)"
fi

# 6. the bump at 60 km/h: the model as it is (static equilibrium first), rigid
#    and flexible chassis.  Columns are looked up by name (col["FL.Fz"]).
HDR='NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }'
for sc in rigid flexible; do
  run "$model" "bump_$sc.csv" --scene "$sc" || continue
  # the equilibrium: Newton's report (force residual relative to the weight)
  eqline=$(grep 'static equilibrium in' "bump_$sc.csv.log")
  echo "$sc: ${eqline#*: }"
  res=$(sed -n 's/.*force residual \([0-9.e+-]*\) of.*/\1/p' <<< "$eqline")
  awk -v r="${res:-1}" 'BEGIN { exit !(r < 1e-9) }' || err "$sc: no static equilibrium to 1e-9 of the weight: $eqline"
  # the static wheel loads (first row: the settled car) against the weight M g
  # of the masses measured in 2. (to 1e-6) and their split by the moment
  # balance about the axles' contact lines (to 1e-3: the contacts sit a few
  # tenths of a millimetre off x = 0, -2.18 by camber and compliance);
  # travel and joint outputs count from the settled state (0 there)
  awk -F, -v sc="$sc" -v M="$M" -v x="$xg" "$HDR"'
    NR == 2 { W = M * 9.81; front = W * (x + 2.18) / 2.18 / 2; rear = W / 2 - front
      fl = $col["FL.Fz"]; fr = $col["FR.Fz"]; rl = $col["RL.Fz"]; rr = $col["RR.Fz"]; s = fl + fr + rl + rr
      printf "%s: static wheel loads FL %.3f FR %.3f RL %.3f RR %.3f N, sum %.4f N = %.2e of the weight off; moment balance %.2f / %.2f N\n",
        sc, fl, fr, rl, rr, s, s / W - 1, front, rear
      bad = 0
      if ((s / W - 1) ^ 2 > 1e-12) { print "wheel loads do not sum to the weight to 1e-6"; bad = 1 }
      if (((fl + fr) / (2 * front) - 1) ^ 2 > 1e-6 || ((rl + rr) / (2 * rear) - 1) ^ 2 > 1e-6) { print "not the moment balance"; bad = 1 }
      if ($col["FL_travel"] != 0 || $col["RL_travel"] != 0 || $col["FL_arm_angle"] != 0) { print "travel or joint angle not 0 at the settled start"; bad = 1 }
      exit bad }' "bump_$sc.csv" || err "$sc: static equilibrium's wheel loads"
  # the whole car: M a_cm,z = the tyres' vertical forces - M g at every output
  # (centre-of-mass acceleration against the tyre force outputs), to 1e-3 N
  awk -F, -v M="$M" "$HDR"'{ s = $col["FL_fz"] + $col["FR_fz"] + $col["RL_fz"] + $col["RR_fz"]
      d = M * $col["cm_az"] - (s - M * 9.81); d = d < 0 ? -d : d; if (d > w) w = d }
    END { printf "M a_cm,z against the tyres'"'"' vertical forces: largest difference %.2g N\n", w; exit !(w < 1e-3) }' "bump_$sc.csv" ||
    err "$sc: the centre of mass's acceleration is not the tyres' vertical force over the mass"
  # spec §12 (L_b = 1 m): the bands of its reduced-model table.  The spec calls
  # them sanity bands of a 7-DOF model, not targets; chosen bands: chassis CM
  # a_z maximum within its cases' spread 7.3..10.5 m/s^2 widened by 10 %
  # (6.6..11.6; the flexible chassis adds vibration on top: seed Fig. 12,
  # checked after the loop), minimum -5.1..-4.9 widened by 10 % (-5.6..-4.4);
  # peak tyre loads 13.7 / 14.8 kN +-15 %; FL bump travel 91..100 mm of its
  # cases widened to 85..115 mm; both left tyres leave the road after the crest
  awk -F, -v sc="$sc" "$HDR"'{ a = $col["chassis_az"]; if (a > amax) amax = a; if (a < amin) amin = a
      if ($col["FL.Fz"] > fl) fl = $col["FL.Fz"]; if ($col["RL.Fz"] > rl) rl = $col["RL.Fz"]
      if ((tr = $col["FL_travel"] * 1000) > trmax) trmax = tr
      if ($1 > 0.63 && $1 < 0.75 && $col["FL.Fz"] == 0) flair = 1; if ($1 > 0.76 && $1 < 0.9 && $col["RL.Fz"] == 0) rlair = 1 }
    END {
      printf "%s: chassis CM a_z %+.2f / %+.2f m/s^2, peak tyre loads FL %.0f N, RL %.0f N, FL bump travel %.1f mm\n", sc, amax, amin, fl, rl, trmax
      bad = 0
      if (sc == "rigid" && (amax < 6.6 || amax > 11.6 || amin < -5.6 || amin > -4.4)) { print "chassis CM acceleration outside 6.6..11.6 / -5.6..-4.4"; bad = 1 }
      if (sc != "rigid" && (amax < 6.6 || amax > 16 || amin < -9 || amin > -4.4)) { print "flexible chassis CM acceleration outside 6.6..16 / -9..-4.4"; bad = 1 }
      if (fl < 11600 || fl > 15800 || rl < 12600 || rl > 17000) { print "peak tyre load outside 13.7 / 14.8 kN +-15 %"; bad = 1 }
      if (trmax < 85 || trmax > 115) { print "FL bump travel outside 85..115 mm"; bad = 1 }
      if (!flair || !rlair) { print "a left tyre does not leave the road after the crest"; bad = 1 }
      exit bad }' "bump_$sc.csv" || err "bump run ($sc) outside the bands of spec §12"
done
peak() { awk -F, -v c="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == c) k = i; next } $k > p { p = $k } END { print p + 0 }' "$1"; }
if [ -s bump_rigid.csv ] && [ -s bump_flexible.csv ]; then
  # seed Fig. 12: the flexible chassis adds high-frequency content to the CM
  # node's acceleration; its peak is larger than the rigid chassis's
  r=$(peak bump_rigid.csv chassis_az) f=$(peak bump_flexible.csv chassis_az)
  echo "peak chassis CM a_z: rigid $r, flexible $f m/s^2"
  awk -v r="$r" -v f="$f" 'BEGIN { exit !(f > 1.1 * r) }' || err "the flexible chassis does not raise the CM acceleration peak (seed Fig. 12)"
fi

# largest difference of each named column between two runs (common times),
# relative to the first run's range, as "column=value ..."
compare() { # compare A.csv B.csv COLUMN...
  local a=$1 b=$2; shift 2
  awk -F, -v cols="$*" 'BEGIN { nc = split(cols, want, " ") }
    FNR == 1 { for (i = 1; i <= NF; i++) idx[FILENAME == ARGV[1], $i] = i; next }
    FILENAME == ARGV[1] { for (j = 1; j <= nc; j++) { v = $idx[1, want[j]]; A[$1, j] = v
        if (!((j) in lo) || v < lo[j]) lo[j] = v; if (!((j) in hi) || v > hi[j]) hi[j] = v }; next }
    { for (j = 1; j <= nc; j++) { if (!(($1, j) in A)) continue; n++
        d = $idx[0, want[j]] - A[$1, j]; d = d < 0 ? -d : d; if (d > dm[j]) dm[j] = d } }
    END { if (!n) { print "none"; exit }
      for (j = 1; j <= nc; j++) printf "%s=%.3g ", want[j], (hi[j] > lo[j] ? dm[j] / (hi[j] - lo[j]) : dm[j]); print "" }' "$a" "$b"
}
cols="chassis_az cm_az FL.Fz FR.Fz RL.Fz RR.Fz FL_travel RL_travel pitch roll"
# the flexible chassis with its stiffness scaled by 1e3 (E and G of its steel;
# modes at 31.6 times the frequencies) agrees with the rigid chassis over the
# bump (first second): its deflections shrink by 1e3, so wheel loads, travel,
# attitude and the whole car's CM acceleration within 1e-3 of their range
# (measured about 2e-5; the flexible chassis differs by 3e-3..9e-2); the CM
# node's acceleration within 2 % (measured 0.3 %: the stiffened modes, now at
# 0.2-1.6 kHz, are still rung by the tyres' landing; flexible: 53 %)
# (the model's files copied as they are into stiff/, beside the stiffer FE file)
mkdir -p stiff/sports_car stiff/subsystems
cp "$model" stiff/ && cp "$root/models/sports_car/car.yaml" stiff/sports_car/ && cp "$root"/models/subsystems/*.yaml stiff/subsystems/
sed 's/steel: {E: 2.1e+11, G: 8.08e+10,/steel: {E: 2.1e+14, G: 8.08e+13,/' "$root/models/sports_car_chassis.fe.yaml" > stiff/sports_car_chassis.fe.yaml
if grep -q 'E: 2.1e+14' stiff/sports_car_chassis.fe.yaml && [ -s bump_rigid.csv ] && run stiff/sports_car.yaml bump_stiff.csv --scene flexible --end 1.0; then
  d=$(compare bump_rigid.csv bump_stiff.csv $cols)
  echo "flexible chassis x 1e3 stiffness against rigid (of the range): $d"
  awk -v d="$d" 'BEGIN { n = split(d, p, " "); if (n < 10) exit 1
    for (i = 1; i <= n; i++) { split(p[i], kv, "="); if (kv[2] > (kv[1] == "chassis_az" ? 0.02 : 1e-3)) exit 1 } }' ||
    err "the flexible chassis stiffened 1e3 times does not agree with the rigid chassis"
  [ -s bump_flexible.csv ] && echo "flexible chassis against rigid (of the range): $(compare bump_rigid.csv bump_flexible.csv $cols)"
else
  err "the stiffened chassis run failed"
fi
# direct and virtual-body joints: the same motion (to the integration error),
# over the front bump, every output column within 2e-3 of its range
if [ -s bump_flexible.csv ] && run "$model" bump_virtual.csv --scene flexible_virtual --end 0.8; then
  d=$(compare bump_flexible.csv bump_virtual.csv $cols FL.Fx FL.Fy FL_spring_force FL_tie_rod_force)
  echo "direct against virtual joints (of the range): $d"
  awk -v d="$d" 'BEGIN { n = split(d, p, " "); if (n < 14) exit 1
    for (i = 1; i <= n; i++) { split(p[i], kv, "="); if (kv[2] > 2e-3) exit 1 } }' ||
    err "joints through virtual bodies do not reproduce the joints on the nodes"
fi

# 7. straight running on the flat road at 60 km/h, settled first, 1 s: the
#    whole car's speed falls by the rolling resistance only (as test_tyre's
#    cart): C_rr Fz_i / R_i summed over the wheels, over the mass plus the
#    wheels' spin inertia I_i / R_i^2, with R_i between the rolling radius
#    R_e = R0 - delta/3 and the contact lever rho = R0 - delta (delta =
#    Fz / K_z), within 0.5 %; the car holds its course (lateral drift below
#    1 mm, yaw below 1e-4 rad: only the FE chassis's small asymmetry steers)
car "" '{type: flat}' > flat.yaml
cat >> flat.yaml <<'EOF'
outputs:
  - {name: vx, type: center_of_mass, quantity: velocity, component: x}
  - {name: y, type: position, body: chassis, component: y}
  - {name: yaw, type: angle, body: chassis, axis: [0, 0, 1]}
  - {name: FL, type: tyre, element: FL_tyre, component: Fz}
  - {name: FR, type: tyre, element: FR_tyre, component: Fz}
  - {name: RL, type: tyre, element: RL_tyre, component: Fz}
  - {name: RR, type: tyre, element: RR_tyre, component: Fz}
simulation: {equilibrium: true, end_time: 1.0, output_step: 0.01}
EOF
for sc in rigid flexible; do
  run flat.yaml "flat_$sc.csv" --scene "$sc" || continue
  awk -F, -v sc="$sc" -v M="$M" 'NR == 2 { v0 = $2; for (i = 5; i <= 8; i++) F[i] = $i }
    NR > 1 { if ($3 ^ 2 > ym) ym = $3 ^ 2; if ($4 ^ 2 > yw) yw = $4 ^ 2; v = $2; T = $1 }
    END { Crr = 0.005; R0 = 0.3213; KZ = 2e5; lo = hi = 0; d1 = d2 = M
      for (i = 5; i <= 8; i++) { d = F[i] / KZ; Re = R0 - d / 3; rho = R0 - d; I = i < 7 ? 1.1 : 1.2
        lo += Crr * F[i] / Re; hi += Crr * F[i] / rho; d1 += I / (Re * Re); d2 += I / (Re * rho) }
      lo = lo / d1 * T; hi = hi / d2 * T
      printf "%s, flat road: speed loss %.5f m/s in %.1f s, rolling resistance predicts %.5f to %.5f; lateral drift %.2g m, yaw %.2g rad\n",
        sc, v0 - v, T, lo, hi, sqrt(ym), sqrt(yw)
      exit !(T > 0.99 && v0 - v > 0.995 * lo && v0 - v < 1.005 * hi && ym < 1e-6 && yw < 1e-8) }' "flat_$sc.csv" ||
    err "$sc: straight running on the flat road does not hold its speed and course within the rolling loss"
done

exit $fail
