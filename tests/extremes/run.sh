#!/usr/bin/env bash
# run.sh: the extremes suite (`make extremes`).  Every case runs mbcc at an
# extreme of mass, stiffness, configuration, run length, tolerance or
# precision, and either meets the accuracy stated for it or stops with a clear
# diagnostic (what, when, why); never NaN in the output, never a hang.  The
# suite writes docs/stability.md and its figures docs/img/stability_*.png, and
# exits 1 when a case misses its statement.
# Needs: mbcc built (make all), bash, awk, gnuplot.  Work files: build/extremes/.
# Environment: MBCC (default build/mbcc).
# shellcheck disable=SC2016  # awk programs in single quotes
set -u
export LC_ALL=C
cd "$(dirname "$0")/../.."
ROOT=$(pwd)
MBCC=${MBCC:-build/mbcc}
case $MBCC in /*) ;; *) MBCC=$ROOT/$MBCC ;; esac
W=$ROOT/build/extremes
X=tests/extremes/models
OUT=docs/stability.md
IMG=docs/img
[ -x "$MBCC" ] || { echo "extremes: $MBCC not found: run 'make all' first" >&2; exit 1; }
command -v gnuplot > /dev/null || { echo "extremes: gnuplot not found" >&2; exit 1; }
rm -rf "$W"
mkdir -p "$W" "$IMG"
cd "$W" || exit 1
failures=0
body=$W/body.md
: > "$body"
say() { echo "extremes: $*" >&2; }
md() { printf '%s\n' "$*" >> "$body"; }

# run NAME MODEL ARGS...: mbcc run into $W/NAME.csv; sets RC, STEPS, REJ, SECS, ERR (the error
# line without the program name), NOTE, WARN (first warning about the run itself)
run() {
  local name=$1 model=$2
  shift 2
  "$MBCC" run "$ROOT/$model" -o "$W/$name.csv" --plot none "$@" > "$W/$name.log" 2>&1
  RC=$?
  STEPS=$(sed -n 's/^steps \([0-9]*\) (rejected \([0-9]*\)).*/\1/p' "$W/$name.log")
  REJ=$(sed -n 's/^steps \([0-9]*\) (rejected \([0-9]*\)).*/\2/p' "$W/$name.log")
  SECS=$(sed -n 's/^time \([0-9.]*\) s.*/\1/p' "$W/$name.log")
  ERR=$(sed -n 's/^[^ ]*_sim: error: //p' "$W/$name.log" | head -1)
  NOTE=$(sed -n 's/^[^ ]*_sim: note: //p' "$W/$name.log" | head -1)
  WARN=$(sed -n 's/^[^ ]*_sim: warning: //p' "$W/$name.log" | head -1)
  LDLRES=$(sed -n 's/^ldl residual after refinement.*: last [^,]*, largest \([^;]*\);.*/\1/p' "$W/$name.log")
  : "${STEPS:=-}" "${REJ:=-}" "${SECS:=-}"
  if [ -e "$W/$name.csv" ] && grep -qi 'nan\|inf' "$W/$name.csv"; then
    say "$name: NaN or Inf in the output"; ERR="NaN in the output"; RC=99
  fi
}

# relerr A B COLS: max over the columns (comma list) of max |a - b| / range(a)
relerr() {
  awk -F, -v cols="$3" '
    FNR == 1 { if (NR == 1) { n = split(cols, want, ","); for (i = 1; i <= NF; i++) idx[$i] = i
                 for (j = 1; j <= n; j++) if (!(want[j] in idx)) { print "no-column-" want[j]; bad = 1; exit } } ; next }
    NR == FNR { for (j = 1; j <= n; j++) { c = idx[want[j]]; a[FNR, j] = $c
                  if (!(j in lo) || $c < lo[j]) lo[j] = $c; if (!(j in hi) || $c > hi[j]) hi[j] = $c } ; next }
    { for (j = 1; j <= n; j++) { c = idx[want[j]]; d = $c - a[FNR, j]; if (d < 0) d = -d
        r = hi[j] - lo[j]; if (r < 1e-12) r = 1e-12; if (d / r > worst) worst = d / r } }
    END { if (!bad) printf "%.2e\n", worst + 0 }' "$1" "$2" 2> /dev/null || echo "no-file"
}
# le X Y: X <= Y, both numbers (an empty or missing measurement is not)
le() {
  awk -v x="$1" -v y="$2" 'BEGIN { num = "^[-+]?[0-9.]+([eE][-+]?[0-9]+)?$"
    exit !(x ~ num && y ~ num && x + 0 <= y + 0) }'
}
# verdict OK: PASS or FAIL (counted at the end from the table)
verdict() { if [ "$1" = 1 ]; then echo PASS; else echo "**FAIL**"; fi; }
row() { md "| $1 | $2 | $3 | $4 | $5 |"; }
table_head() { md ""; md "| run | steps (rejected) | time s | measured | statement: verdict |"; md "|---|--:|--:|---|---|"; }

md "# Stability at the extremes"
md ""
md "Regenerate with \`make extremes\` (tests/extremes/run.sh, about four minutes; it"
md "exits 1 when a case misses its statement).  Each case states the accuracy it"
md "must meet or the diagnostic it must stop with; *time* is the simulator's own"
md "measurement of the integration (wall clock, one run, on a machine shared with"
md "other work: read it as an order of magnitude).  Errors are relative to the"
md "range of the output over the reference run unless a unit is given."

# ---------------------------------------------------------------------------
say "1. zero-mass bodies and mass ratios"
md ""
md "## 1. Zero-mass virtual bodies, the massless slider, a mass ratio of 1e12"
md ""
md "Massless (virtual) bodies make the mass matrix singular; the emitted LDLᵀ"
md "eliminates them exactly before the factorization (docs/formulation.md §14)"
md "and checks the residual on the exact system on one solve in 64, KLU pivots."
md "Statement: the variants agree with the direct attachment to 1e-6 of each"
md "output's range, the solvers agree to 1e-9, and the LDLᵀ residual stays"
md "below 1e-12."
table_head
M=models/slider_crank_flexible.yaml
run scf_direct $M --solver klu
ref=$W/scf_direct.csv
row "flexible slider-crank, direct (klu)" "$STEPS ($REJ)" "$SECS" "reference" "-"
for v in virtual1 virtual2; do
  for s in klu ldl; do
    run "scf_${v}_$s" $M --scene $v --solver $s
    e=$(relerr "$ref" "$W/scf_${v}_$s.csv" midspan,slider_x)
    ok=0; [ $RC = 0 ] && le "$e" 1e-6 && ok=1
    extra=""
    if [ $s = ldl ]; then extra="; LDLᵀ residual $LDLRES"; le "${LDLRES:-1}" 1e-12 || ok=0; fi
    row "flexible slider-crank, $v ($s)" "$STEPS ($REJ)" "$SECS" "vs direct $e$extra" "≤ 1e-6: $(verdict $ok)"
  done
done
M=$X/beam_virtual8.yaml
run bv8_direct $M
row "hinged beam with 7 bobs, direct" "$STEPS ($REJ)" "$SECS" "reference" "-"
for s in klu ldl; do
  run "bv8_virtual_$s" $M --scene virtual --solver $s
  e=$(relerr "$W/bv8_direct.csv" "$W/bv8_virtual_$s.csv" tip.x,tip.y,mid.x,mid.y)
  ok=0; [ $RC = 0 ] && le "$e" 1e-6 && ok=1
  extra=""
  if [ $s = ldl ]; then extra="; LDLᵀ residual $LDLRES"; le "${LDLRES:-1}" 1e-12 || ok=0; fi
  row "same, 8 virtual bodies ($s)" "$STEPS ($REJ)" "$SECS" "vs direct $e$extra" "≤ 1e-6: $(verdict $ok)"
done
for s in klu ldl dense; do
  run "sc_$s" models/slider_crank.yaml --solver $s
  e=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) { if ($i == "crank_angle") a = i; if ($i == "slider_x") x = i }; next }
    { r = 0.1524; L = 0.3048; th = $a; s = sin(th); d = $x - (r * cos(th) + sqrt(L * L - r * r * s * s))
      if (d < 0) d = -d; if (d > m) m = d } END { printf "%.2e\n", m / (2 * 0.1524) }' "$W/sc_$s.csv")
  ok=0; [ $RC = 0 ] && le "$e" 1e-9 && ok=1
  row "rigid slider-crank, massless slider ($s)" "$STEPS ($REJ)" "$SECS" "slider_x vs closed form $e of the stroke" "≤ 1e-9: $(verdict $ok)"
done
M=$X/mass_ratio.yaml
run mr_heavy $M --scene heavy_only
for s in klu ldl dense; do
  run "mr_$s" $M --solver $s
  e=$(relerr "$W/mr_heavy.csv" "$W/mr_$s.csv" heavy_angle)
  len=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    { dx = $c["light_end.x"] - $c["heavy_tip.x"]; dy = $c["light_end.y"] - $c["heavy_tip.y"]
      d = sqrt(dx * dx + dy * dy) - 0.5; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.1e\n", m }' "$W/mr_$s.csv")
  ok=0; [ $RC = 0 ] && le "$e" 1e-9 && le "$len" 1e-9 && ok=1
  row "1000 kg bar carrying a 1e-9 kg bar ($s)" "$STEPS ($REJ)" "$SECS" \
    "heavy angle vs the heavy bar alone $e; light bar length error $len m" "≤ 1e-9: $(verdict $ok)"
done
e=$(relerr "$W/mr_klu.csv" "$W/mr_ldl.csv" light_angle,light_end.x,light_end.y)
ok=0; le "$e" 1e-9 && ok=1
row "same, the light bar: ldl vs klu" "" "" "$e" "≤ 1e-9: $(verdict $ok)"

# ---------------------------------------------------------------------------
say "2. stiff modal content (this takes a minute)"
md ""
md "## 2. A flexible body with modes up to 10 kHz"
md ""
md "tests/extremes/models/beam_10khz.yaml: the hinged aluminium beam with all 49"
md "constrained modes up to 9.65 kHz, released under gravity, 0.05 s.  DOPRI5"
md "is stable only for steps below about 3.3/ω_max = 5.4e-5 s whatever its"
md "tolerance; the implicit generalized-α method (\`--integrator genalpha\`,"
md "runtime/hosted/genalpha.c) takes the steps the accuracy needs, with the modal"
md "stiffness and damping in its Newton matrix on K's pattern.  The reference"
md "is DOPRI5 at rtol 1e-9.  Statement: genalpha at rtol 1e-5 within 1e-3 of"
md "the tip's range, in at least 10 times fewer steps than DOPRI5."
table_head
M=$X/beam_10khz.yaml
run b10_ref $M --integrator dopri5 --rtol 1e-9 --atol 1e-11
ref=$W/b10_ref.csv
row "dopri5 rtol 1e-9 (reference)" "$STEPS ($REJ)" "$SECS" "-" "-"
run b10_dopri5 $M --integrator dopri5 --rtol 1e-5 --atol 1e-7
dsteps=$STEPS
e=$(relerr "$ref" "$W/b10_dopri5.csv" tip)
row "dopri5 rtol 1e-5" "$STEPS ($REJ)" "$SECS" "tip $e" "-"
for r in 1e-3 1e-4 1e-5 1e-6; do
  run "b10_ga_$r" $M --integrator genalpha --rtol $r --atol 1e-9
  e=$(relerr "$ref" "$W/b10_ga_$r.csv" tip)
  em=$(relerr "$ref" "$W/b10_ga_$r.csv" mid_deflection.y)
  if [ $r = 1e-5 ]; then
    ok=0; [ $RC = 0 ] && le "$e" 1e-3 && le "$((STEPS * 10))" "$dsteps" && ok=1
    row "genalpha rtol $r" "$STEPS ($REJ)" "$SECS" "tip $e, mid deflection $em" "≤ 1e-3, 10× fewer steps: $(verdict $ok)"
  else
    ok=0; [ $RC = 0 ] && ok=1
    row "genalpha rtol $r" "$STEPS ($REJ)" "$SECS" "tip $e, mid deflection $em" "completes: $(verdict $ok)"
  fi
done
for rho in 0.5 1.0; do
  run "b10_rho_$rho" $M --integrator genalpha --rtol 1e-5 --atol 1e-9 --rho-inf $rho
  e=$(relerr "$ref" "$W/b10_rho_$rho.csv" tip)
  ok=0; [ $RC = 0 ] && ok=1
  row "genalpha rtol 1e-5, ρ∞ = $rho" "$STEPS ($REJ)" "$SECS" "tip $e" "completes: $(verdict $ok)"
done
run b10_auto $M --integrator auto
ok=0; [ $RC = 0 ] && grep -q "integrator auto: genalpha: the highest mode (beam, 9652 Hz)" "$W/b10_auto.log" && ok=1
row "auto (model rtol 1e-9)" "$STEPS ($REJ)" "$SECS" "$(sed -n 's/^[^ ]*_sim: integrator auto: //p' "$W/b10_auto.log")" "chooses genalpha: $(verdict $ok)"
md ""
md "The three-band modal damping (the default; seed 001 §2.6) damps the modes"
md "above the band of interest heavily, so that they stop ringing.  What it"
md "costs in accuracy is the difference between the damped and the undamped"
md "beam, each computed by the reference method; what it buys is the number of"
md "steps and the Newton work of the implicit method:"
table_head
run b10u_ref $M --scene undamped --integrator dopri5 --rtol 1e-9 --atol 1e-11
row "undamped, dopri5 rtol 1e-9 (its reference)" "$STEPS ($REJ)" "$SECS" "-" "-"
eb=$(relerr "$W/b10u_ref.csv" "$ref" tip)
ebm=$(relerr "$W/b10u_ref.csv" "$ref" mid_deflection.y)
ok=0; le "$eb" 1e-2 && ok=1
row "three bands vs undamped (both references)" "" "" "tip $eb, mid deflection $ebm" "tip ≤ 1e-2: $(verdict $ok)"
run b10u_ga $M --scene undamped --integrator genalpha --rtol 1e-5 --atol 1e-9
e=$(relerr "$W/b10u_ref.csv" "$W/b10u_ga.csv" tip)
ok=0; [ $RC = 0 ] && ok=1
row "undamped, genalpha rtol 1e-5" "$STEPS ($REJ)" "$SECS" "tip $e vs undamped reference" "completes: $(verdict $ok)"
gnuplot <<EOF
set terminal pngcairo size 1000,380 noenhanced font ',9'
set output '$ROOT/$IMG/stability_beam_10khz.png'
set datafile separator ','
set multiplot layout 1,2
set xlabel 't [s]'
set ylabel 'tip y [m]'
set key bottom left
plot '$ref' every ::1 using 1:2 with lines lw 2 title 'dopri5 1e-9, three bands', \
     '$W/b10u_ref.csv' every ::1 using 1:2 with lines dt 2 title 'dopri5 1e-9, undamped', \
     '$W/b10_ga_1e-3.csv' every ::1 using 1:2 with points pt 7 ps 0.5 title 'genalpha 1e-3, three bands'
set ylabel 'mid-span deflection from the chord, y [m]'
plot '$ref' every ::1 using 1:4 with lines lw 2 title 'dopri5 1e-9, three bands', \
     '$W/b10u_ref.csv' every ::1 using 1:4 with lines dt 2 title 'dopri5 1e-9, undamped', \
     '$W/b10_ga_1e-5.csv' every ::1 using 1:4 with points pt 7 ps 0.5 title 'genalpha 1e-5, three bands'
unset multiplot
EOF
md ""
md "![beam with modes to 10 kHz](img/stability_beam_10khz.png)"

# ---------------------------------------------------------------------------
say "3. singular configurations"
md ""
md "## 3. Singular configurations"
md ""
md "A dead point or a change point makes the constraint Jacobian D lose rank:"
md "K is singular there.  mbcc either passes through on the branch the motion"
md "is on, or stops and says where and why: the note comes from the singular"
md "values of D at the state the failed factorization or projection was at"
md "(else at the last accepted state), and names a singular configuration when"
md "the smallest is below 1e-5 of the largest (generalized-α's Newton stalls a"
md "few microseconds before the point, where D is ill-conditioned but not yet"
md "singular to round-off).  When a run passes close to such a point, KLU's"
md "condition estimate of K drops and the simulator warns."
table_head
M=$X/slider_crank_equal.yaml
for integ in dopri5 genalpha rk4; do
  args=(--integrator "$integ"); [ "$integ" = rk4 ] && args+=(--step 1e-5)
  run "sce_$integ" $M "${args[@]}"
  e=$(awk -F, 'NR > 1 { d = $3 - 2 * 0.1524 * cos($2); if (d < 0) d = -d; if (d > m) m = d } END { printf "%.1e\n", m / 0.3048 }' "$W/sce_$integ.csv" 2> /dev/null)
  ok=0; [ $RC = 0 ] && le "$e" 1e-8 && ok=1
  row "slider-crank r = L through the dead point, $integ" "$STEPS ($REJ)" "$SECS" "x vs 2 r cos θ: $e of the stroke" "passes on the branch, ≤ 1e-8: $(verdict $ok)"
done
tdead=$(awk 'BEGIN { printf "%.17g", atan2(1, 0) / 124.8 }')
hout=$(awk -v t="$tdead" 'BEGIN { printf "%.17g", t / 100 }')
for integ in dopri5 genalpha rk4; do
  args=(--integrator "$integ" --output-step "$hout"); [ "$integ" = rk4 ] && args+=(--step 1e-5)
  run "sce_exact_$integ" $M "${args[@]}"
  if [ $RC = 0 ]; then
    e=$(awk -F, 'NR > 1 { d = $3 - 2 * 0.1524 * cos($2); if (d < 0) d = -d; if (d > m) m = d } END { printf "%.1e\n", m / 0.3048 }' "$W/sce_exact_$integ.csv")
    ok=0; le "$e" 1e-8 && ok=1
    row "same, a step ends on the dead point, $integ" "$STEPS ($REJ)" "$SECS" "passes: x vs 2 r cos θ $e" "passes ≤ 1e-8 or stops there: $(verdict $ok)"
  else
    t=$(printf '%s' "$ERR" | sed -n 's/^at t = \([0-9.e+-]*\):.*/\1/p')
    ok=0; printf '%s' "$NOTE" | grep -q "singular configuration" && awk -v t="$t" -v d="$tdead" 'BEGIN { exit !((t - d) < 1e-6 && (d - t) < 1e-6) }' && ok=1
    row "same, a step ends on the dead point, $integ" "" "" "stops: $ERR. Note: $NOTE" "passes or stops at t = $(printf '%.6g' "$tdead") s with the note: $(verdict $ok)"
  fi
done
M=$X/four_bar_change.yaml
for integ in dopri5 rk4 genalpha; do
  args=(--integrator "$integ"); [ "$integ" = rk4 ] && args+=(--step 2e-4)
  run "fbc_$integ" $M "${args[@]}"
  if [ $RC = 0 ]; then
    e=$(awk -F, 'NR > 1 { d = $3 - $2; if (d < 0) d = -d; if (d > m) m = d } END { printf "%.1e\n", m }' "$W/fbc_$integ.csv")
    ok=0; le "$e" 1e-8 && [ -n "$WARN" ] && ok=1
    row "parallelogram four-bar through its change point, $integ" "$STEPS ($REJ)" "$SECS" "passes as a parallelogram: rocker − crank angle $e rad. Warning: $WARN" "passes ≤ 1e-8 rad with the warning, or stops at 0.25 s: $(verdict $ok)"
  else
    t=$(printf '%s' "$ERR" | sed -n 's/^at t = \([0-9.e+-]*\):.*/\1/p')
    # within 1e-5 s: 6.3e-5 rad of crank at 2 pi rad/s (the slider-crank's 1e-6 s is 1.2e-4 rad)
    ok=0; printf '%s' "$NOTE" | grep -q "singular configuration" && awk -v t="$t" 'BEGIN { exit !(t > 0.25 - 1e-5 && t < 0.25 + 1e-5) }' && ok=1
    row "parallelogram four-bar through its change point, $integ" "" "" "stops: $ERR. Note: $NOTE" "passes, or stops within 1e-5 s of 0.25 s with the note: $(verdict $ok)"
  fi
done
run fb_spatial models/four_bar.yaml
run fb_revolutes tests/models/four_bar_revolutes.yaml
nred=$(grep -c "warning: redundant constraint removed" "$W/fb_revolutes.log")
e=$(relerr "$W/fb_spatial.csv" "$W/fb_revolutes.csv" rocker_angle)
ok=0; [ $RC = 0 ] && [ "$nred" = 3 ] && le "$e" 1e-9 && ok=1
row "planar four-bar of four revolute joints (redundant)" "$STEPS ($REJ)" "$SECS" "$nred redundant rows removed with a warning; rocker angle vs the spatial four-bar $e" "3 rows, ≤ 1e-9: $(verdict $ok)"
M=$X/four_bar_rsur_free.yaml
run rsur $M
rsur_err=$ERR
run rsur_short $M --end 6.3
jump=$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == "energy") c = i; next } NR == 2 { e0 = $c }
  { d = $c - e0; if (d < 0) d = -d; if (d > 1e-6 && !t) t = $1; if (d > m) m = d } END { printf "%.2g J (first above 1e-6 J at t = %s s)", m, t }' "$W/rsur_short.csv")
md ""
md "One case is *not* caught: the revolute-spherical-universal-revolute four-bar"
md "of models/four_bar.yaml, swinging freely ($X/four_bar_rsur_free.yaml)."
md "Its universal joint blocks the coupler's spin about its own axis only while"
md "the transmission angle is not 90°; at 90° the spin is free for an instant."
md "Driven (models/four_bar.yaml) the spin is never excited; free, RK4 at"
md "1e-4 s gains energy there: $jump over 6.3 s, with no warning (the"
md "condition estimate of K does not drop at the sampled states), and the full"
md "10 s run stops with: $rsur_err.  The same free four-bar built from four"
md "revolute joints (section 4) keeps its energy to round-off.  Modelling advice:"
md "a spatial four-bar needs joints that block the coupler's spin everywhere."

# ---------------------------------------------------------------------------
say "4. long runs (1e6 steps each)"
md ""
md "## 4. Long runs: 1e6 steps"
md ""
md "tests/extremes/models/four_bar_free.yaml: a four-bar swinging freely under"
md "gravity (conservative), RK4 at 1e-4 s for 100 s (1e6 steps).  The"
md "constraint drift is the distance between the rocker pin's two points (on the"
md "coupler and on the rocker), the energy drift max |E − E0| (E0 = 2.2 J),"
md "both from the CSV, whose 12 significant digits put a floor of about 1e-12"
md "under either (a zero in the plot is below that floor)."
md "Statements: projection keeps the pins together to 1e-9 m and the energy to"
md "1e-6 J; Baumgarte (α = β = 10) to 1e-6 m and 1e-4 J; without stabilization"
md "the drift is reported (the run must finish with finite numbers or stop with"
md "a diagnostic)."
table_head
M=$X/four_bar_free.yaml
for stab in projection baumgarte none; do
  run "long_$stab" $M --stabilization $stab
  read -r gap edrift <<< "$(awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) c[$i] = i; next }
    NR == 2 { e0 = $c["energy"] }
    { dx = $c["pin_on_coupler.x"] - $c["pin_on_rocker.x"]; dy = $c["pin_on_coupler.y"] - $c["pin_on_rocker.y"]
      dz = $c["pin_on_coupler.z"] - $c["pin_on_rocker.z"]; g = sqrt(dx * dx + dy * dy + dz * dz); if (g > G) G = g
      d = $c["energy"] - e0; if (d < 0) d = -d; if (d > E) E = d
      printf "%s %.6e %.6e\n", $1, g, d > "'"$W/long_$stab.drift"'" }
    END { printf "%.1e %.1e\n", G, E }' "$W/long_$stab.csv" 2> /dev/null)"
  case $stab in
    projection) ok=0; [ $RC = 0 ] && le "$gap" 1e-9 && le "$edrift" 1e-6 && ok=1; st="≤ 1e-9 m, ≤ 1e-6 J" ;;
    baumgarte) ok=0; [ $RC = 0 ] && le "$gap" 1e-6 && le "$edrift" 1e-4 && ok=1; st="≤ 1e-6 m, ≤ 1e-4 J" ;;
    none) ok=0; { [ $RC = 0 ] || [ -n "$ERR" ]; } && ok=1; st="reported" ;;
  esac
  row "RK4 1e-4 s × 1e6, $stab" "$STEPS ($REJ)" "$SECS" "pin gap $gap m, energy drift $edrift J${ERR:+; stops: $ERR}" "$st: $(verdict $ok)"
done
gnuplot <<EOF
set terminal pngcairo size 1000,380 noenhanced font ',9'
set output '$ROOT/$IMG/stability_long_run.png'
set multiplot layout 1,2
set xlabel 't [s]'
set logscale y
set format y '%.0e'
set key top left
set ylabel 'rocker pin gap [m]'
plot for [s in "projection baumgarte none"] '$W/long_'.s.'.drift' using 1:(\$2 > 1e-16 ? \$2 : 1e-16) with lines title s
set ylabel '|E - E0| [J]'
plot for [s in "projection baumgarte none"] '$W/long_'.s.'.drift' using 1:(\$3 > 1e-16 ? \$3 : 1e-16) with lines title s
unset multiplot
EOF
md ""
md "![long run drift](img/stability_long_run.png)"

# ---------------------------------------------------------------------------
say "5. tolerances, steps and precision"
md ""
md "## 5. Tolerances and steps from 1e-12 to 1e-2, double and float"
md ""
md "models/pendulum.yaml released at 90° for 5 s, output every 0.1 s (so that"
md "the tolerance, not the output grid, sets the step), against the exact"
md "solution θ = 2 asin(k sn(K − ω0 t, k)) (tests/extremes/pendulum_exact.awk)."
md "Float runs use the single-precision build of the generated code and runtime"
md "(\`--real float\`, the emitted LDLᵀ).  Statements, from the order of each"
md "method: DOPRI5 error ≤ 100 rtol + 1e-10; generalized-α, second order with"
md "per-step error control, ≤ 30 rtol^(2/3); RK4 ≤ 1e-5 (h / 0.01 s)^4 + 1e-9;"
md "in float, at most 100 × the larger of rtol and 1e-5 (or 1e-4 for RK4, whose"
md "round-off grows with the step count); a tolerance below what float resolves"
md "is raised with a warning; a step the run cannot afford stops at once."
table_head
M=models/pendulum.yaml
: > "$W/sweep_dopri5_double.dat"; : > "$W/sweep_genalpha_double.dat"; : > "$W/sweep_rk4_double.dat"
: > "$W/sweep_dopri5_float.dat"; : > "$W/sweep_genalpha_float.dat"; : > "$W/sweep_rk4_float.dat"
sweep() { # method real value
  local integ=$1 real=$2 v=$3 name="pend_$1_$2_$3" args=(--integrator "$1" --real "$2" --output-step 0.1) what=rtol
  [ "$integ" = rk4 ] && what=step
  if [ "$integ" = rk4 ]; then args+=(--step "$v"); else args+=(--rtol "$v" --atol "$(awk -v r="$v" 'BEGIN { print r / 100 }')"); fi
  run "$name" $M "${args[@]}"
  if [ $RC != 0 ]; then
    ok=0; [ -n "$ERR" ] && ok=1
    row "$integ, $real, $what $v" "" "" "stops: $ERR" "clear diagnostic: $(verdict $ok)"
    return
  fi
  local e bound
  e=$(awk -f "$ROOT/tests/extremes/pendulum_exact.awk" "$W/$name.csv")
  case $integ/$real in
    dopri5/double) bound=$(awk -v r="$v" 'BEGIN { print 100 * r + 1e-10 }') ;;
    genalpha/double) bound=$(awk -v r="$v" 'BEGIN { print 30 * r ^ (2 / 3) }') ;;
    rk4/double) bound=$(awk -v h="$v" 'BEGIN { print 1e-5 * (h / 0.01) ^ 4 + 1e-9 }') ;;
    rk4/float) bound=1e-4 ;;
    genalpha/float) bound=$(awk -v r="$v" 'BEGIN { if (r < 1e-5) r = 1e-5; print 30 * r ^ (2 / 3) }') ;;
    */float) bound=$(awk -v r="$v" 'BEGIN { if (r < 1e-5) r = 1e-5; print 100 * r }') ;;
  esac
  ok=0; le "$e" "$bound" && ok=1
  local w=""; [ -n "$WARN" ] && w=" (warning: $WARN)"
  row "$integ, $real, $what $v" "$STEPS ($REJ)" "$SECS" "max angle error $e rad$w" "≤ $(printf '%.1e' "$bound"): $(verdict $ok)"
  echo "$v $e $SECS" >> "$W/sweep_${integ}_$real.dat"
}
for r in 1e-2 1e-3 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10 1e-11 1e-12; do sweep dopri5 double $r; done
for r in 1e-2 1e-3 1e-4 1e-5 1e-6 1e-7 1e-8; do sweep genalpha double $r; done
for h in 1e-2 1e-3 1e-4 1e-5 1e-12; do sweep rk4 double $h; done
for r in 1e-2 1e-3 1e-4 1e-5 1e-8; do sweep dopri5 float $r; done
for r in 1e-3 1e-4 1e-5; do sweep genalpha float $r; done
for h in 1e-2 1e-3 1e-4; do sweep rk4 float $h; done
gnuplot <<EOF
set terminal pngcairo size 800,450 noenhanced font ',9'
set output '$ROOT/$IMG/stability_tolerance.png'
set logscale xy
set format x '%.0e'
set format y '%.0e'
set xlabel 'rtol (DOPRI5, generalized-alpha) or step in s (RK4)'
set ylabel 'max |angle - exact| [rad]'
set key outside right
plot for [f in "dopri5_double genalpha_double rk4_double dopri5_float genalpha_float rk4_float"] \
  '$W/sweep_'.f.'.dat' using 1:2 with linespoints title f
EOF
md ""
md "![error against tolerance](img/stability_tolerance.png)"

# ---------------------------------------------------------------------------
failures=$(grep -c '\*\*FAIL\*\*' "$body")
{
  cat "$body"
  md_summary="$failures"
  echo ""
  echo "---"
  if [ "$md_summary" = 0 ]; then echo "Every case met its statement."; else echo "$md_summary case(s) missed their statement."; fi
} > "$ROOT/$OUT"
say "wrote $OUT ($failures case(s) missed their statement)"
[ "$failures" = 0 ]
