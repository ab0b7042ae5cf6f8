#!/usr/bin/env bash
# test_chassis.sh: the sports car's chassis (models/sports_car_chassis.fe.yaml)
# against the vehicle spec's checks (section 12, item 4):
#  1. the committed FE file is what scripts/sports_car_chassis.py writes;
#  2. 303 nodes, 487 beams, 10 sections, 42 point masses, the named nodes
#     of section 10.4 at their coordinates;
#  3. mass 834.0 kg and centre of mass (-1.240, 0, 0.440), from mbcc check
#     (the compiler's lumped masses) and from the generator (sum of rho A L
#     + non-structural + items: an independent sum);
#  4. the 10 lowest constrained modes (CM node clamped) within +-1 % of the
#     spec's 7.72 9.05 18.15 21.22 22.87 24.83 27.57 29.09 33.75 38.79 Hz, by
#     the sparse (the model's) and the dense eigensolver.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
M="$root/models/sports_car_chassis.yaml"
FE="$root/models/sports_car_chassis.fe.yaml"

# --- 1. the committed file is current ------------------------------------------
if command -v python3 >/dev/null; then
  python3 "$root/scripts/sports_car_chassis.py" fresh.fe.yaml || err "the generator failed"
  cmp -s fresh.fe.yaml "$FE" || err "models/sports_car_chassis.fe.yaml is not what the generator writes (make chassis)"
else
  err "python3 is missing (scripts/install-deps.sh installs it)"
fi

# --- 2. counts and named nodes -----------------------------------------------------
count() { awk -v s="$1" '/^[a-z_]+:/ { on = ($1 == s) } on && /^  - / { n++ } END { print n + 0 }' "$FE"; }
[ "$(count nodes:)" = 303 ] || err "nodes: $(count nodes:), expected 303"
[ "$(count beams:)" = 487 ] || err "beams: $(count beams:), expected 487"
[ "$(count point_masses:)" = 42 ] || err "point masses: $(count point_masses:), expected 42 (16 items)"
nsec=$(awk '/^sections:/ { on = 1; next } /^[a-z_]+:/ { on = 0 } on && /^  [A-Z]+:/ { n++ } END { print n + 0 }' "$FE")
[ "$nsec" = 10 ] || err "sections: $nsec, expected 10"
# spec section 10.4: name, 1-based id, coordinates
while read -r name id x y z; do
  k=$(awk -v s="$name" '$1 == s ":" { print $2 }' "$FE")
  [ "$k" = $((id - 1)) ] || { err "node $name is $k, expected $((id - 1)) (the spec's id $id less 1)"; continue; }
  awk -v k="$k" -v x="$x" -v y="$y" -v z="$z" -v name="$name" '
    /^nodes:/ { on = 1; next } /^[a-z_]+:/ { on = 0 }
    on && /^  - / { if (i++ == k) { gsub(/[][,]/, " "); d = ($2 - x)^2 + ($3 - y)^2 + ($4 - z)^2
      if (d > 1e-12) { print "FAIL: node " name " at " $2 " " $3 " " $4; exit 1 } } }' "$FE" || fail=1
done <<'EOF'
J1 17 0.000 0.300 0.150
J2 18 0.000 0.380 0.440
J5 19 0.000 -0.300 0.150
J6 20 0.000 -0.380 0.440
J9 217 -2.180 0.600 0.700
J10 216 -2.180 0.300 0.150
J13 218 -2.180 -0.300 0.150
J14 219 -2.180 -0.600 0.700
SD_TOP_FL 64 0 0.480 0.565
SD_TOP_FR 67 0 -0.480 0.565
TIEROD_IN_FL 66 0.130 0.318 0.193
TIEROD_IN_FR 69 0.130 -0.318 0.193
CM 190 -1.240 0 0.440
ENGINE 303 -1.953 0 0.4832
EOF

# --- 3. mass and centre of mass ----------------------------------------------------
"$MBCC" check "$M" > check.txt 2>&1 || { cat check.txt; err "mbcc check failed"; }
grep -q "303 nodes, 10 modes" check.txt || err "mbcc check: expected 303 nodes and 10 modes"
awk '/mass .* kg, centre of mass/ { gsub(/[][,]/, " "); m = $2; x = $7; y = $8; z = $9; found = 1
       if ((m - 834.0)^2 > 0.05^2) { print "FAIL: mass " m " kg, expected 834.0"; bad = 1 }
       if ((x + 1.240)^2 + y^2 + (z - 0.440)^2 > 0.0005^2) { print "FAIL: centre of mass " x " " y " " z; bad = 1 } }
     END { if (!found) print "FAIL: no mass line in mbcc check"; exit !found || bad }' check.txt || fail=1
head -5 "$FE" | grep -q "= 834.0 kg" || err "the generator's own mass sum is not 834.0 kg"

# --- 4. frequencies -------------------------------------------------------------------
spec="7.72 9.05 18.15 21.22 22.87 24.83 27.57 29.09 33.75 38.79"
within() { # label, then 10 frequencies
  local label=$1; shift
  echo "$spec | $*" | awk -v label="$label" '{ for (i = 1; i <= 10; i++) { s = $i; f = $(i + 11)
      d = (f - s) / s; if (d < 0) d = -d; if (d > w) w = d; if (d > 0.01) { printf "FAIL: %s mode %d: %g Hz, spec %g\n", label, i, f, s; bad = 1 } }
      if (NF != 21) { print "FAIL: " label ": expected 10 frequencies"; bad = 1 }
      printf "%s: 10 frequencies within %.2g%% of the spec\n", label, 100 * w; exit bad }' || fail=1
}
within "sparse" $(awk '/frequencies \(Hz\):/ { for (i = 3; i <= NF; i++) printf "%s ", $i }' check.txt)
sed 's/^    eigensolver: sparse.*/    eigensolver: dense/' "$M" > dense.yaml
sed -i "s|fe_file: sports_car_chassis.fe.yaml|fe_file: $FE|" dense.yaml
"$MBCC" modes dense.yaml --body chassis > dense.txt 2>&1 || { cat dense.txt; err "mbcc modes (dense) failed"; }
grep -q "dense LAPACK" dense.txt || err "the dense variant did not use the dense eigensolver"
within "dense" $(awk '/^ +[0-9]+ +[0-9.e+]+$/ { printf "%s ", $2 }' dense.txt)

[ "$fail" = 0 ] && echo "test_chassis: ok"
exit "$fail"
