#!/usr/bin/env bash
# test_fe_import.sh: flexible bodies from FE files (fe_file).
#  1. a Nastran deck (small-field, free-field, continuation, INCLUDE) and the
#     same beam written inline in mbcc: frequencies and mode shapes to 1e-8;
#     the deck in large-field format (GRID*, fixed and free) reads the same;
#  2. a Matrix Market export of a beam (K and M written here from the textbook
#     12 x 12 Euler-Bernoulli matrices, global DOF map with names) against the
#     inline beam with the consistent mass: to 1e-8;
#  3. a fine Nastran beam (generated) against the closed-form Euler-Bernoulli
#     frequencies: cantilever (clamped GRID), pinned-pinned (chord frame),
#     free-free (mean axes; the 6 rigid-body modes removed);
#  4. RBE2: a spider of dependent GRIDs moves rigidly with its centre;
#  5. bad input: file:line:col errors in the FE files, exit 2.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
T=${KEEP:-$tmp}
fail() { echo "FAIL: $*"; exit 1; }

# max difference of two shape CSVs (relative to each mode's largest entry) and of the frequencies
compare() { # a.csv b.csv a.modal b.modal tol what
  awk -F, -v tol="$5" -v what="$6" '
    FNR == 1 { next }
    NR == FNR { for (i = 5; i <= NF; i++) { a[FNR, i] = $i; m = int((i - 5) / 6); if ($i + 0 > s[m]) s[m] = $i + 0; if (-$i > s[m]) s[m] = -$i }; nf = NF; next }
    { if (NF != nf) { print what ": column counts differ"; bad = 1; exit 1 }
      for (i = 5; i <= NF; i++) { d = $i - a[FNR, i]; if (d < 0) d = -d; d /= s[int((i - 5) / 6)] + 1e-300; if (d > worst) worst = d } }
    END { if (bad) exit 1; if (worst > tol) { printf "%s: shapes differ by %.3g relative\n", what, worst; exit 1 } }' "$1" "$2" || return 1
  paste <(grep -o 'frequency: [0-9.e+-]*' "$3" | cut -d' ' -f2) <(grep -o 'frequency: [0-9.e+-]*' "$4" | cut -d' ' -f2) |
    awk -v tol="$5" -v what="$6" '{ d = ($1 - $2) / $2; if (d < 0) d = -d; if (d > w) w = d; n++ }
      END { if (n == 0 || w > tol) { printf "%s: frequencies differ by %.3g relative (%d modes)\n", what, w, n; exit 1 } }'
}
modes() { # model body out-prefix
  "$MBCC" modes "$1" --body "$2" --shapes "$3.csv" --write-modal "$3.modal" > "$3.log" 2>&1 || { cat "$3.log"; fail "mbcc modes $1"; }
}

# --- 1. Nastran deck = inline beam ---------------------------------------------
modes "$root"/tests/models/fe/beam_bdf.yaml beam "$T/bdf"
modes "$root"/tests/models/fe/beam_inline.yaml beam "$T/inl"
compare "$T/bdf.csv" "$T/inl.csv" "$T/bdf.modal" "$T/inl.modal" 1e-8 "Nastran vs inline" || fail "Nastran import"

# --- 1b. the same deck in large-field format (GRID* with '*' continuations,
#         fixed 16-column and free-field), against the small-field deck
{ echo 'BEGIN BULK'
  printf '%-8s%16s%16s%16s%16s%s\n' 'GRID*' 1 '' 0.0 0.0 '*G1'
  printf '%-8s%16s\n' '*G1' 0.0
  printf '%-8s%16s%16s%16s%16s\n' 'GRID*' 2 '' 2.5000000000D-01 0.0
  printf '%-8s%16s%16s\n' '*' 0.0 ''
  echo 'GRID*,3,,0.5,0.,*'
  echo '*,0.'
  echo 'GRID*,4,,.75,0.'
  echo '*,0.'
  echo 'GRID           5              1.      0.      0.'
  echo "INCLUDE '$root/tests/models/fe/beam_elements.bdf'"
  echo 'MAT1,7,2.1+11,,0.3,7850.'
  echo 'ENDDATA'; } > "$T/large.bdf"
sed "s|fe_file: beam.bdf|fe_file: $T/large.bdf|" "$root"/tests/models/fe/beam_bdf.yaml > "$T/large.yaml"
modes "$T/large.yaml" beam "$T/large"
compare "$T/large.csv" "$T/bdf.csv" "$T/large.modal" "$T/bdf.modal" 1e-12 "large-field vs small-field" ||
  fail "Nastran large-field import"

# --- 2. Matrix Market export = inline beam (consistent mass) -----------------------
E=2.1e11; G=8.0769230769230769e10; RHO=7850; A=2.0e-4; IY=1.6667e-9; IZ=6.6667e-9; J=4.57e-9; L=0.25; NE=4
awk -v E=$E -v G=$G -v rho=$RHO -v A=$A -v Iy=$IY -v Iz=$IZ -v J=$J -v L=$L -v ne=$NE -v dir="$T" '
  function add(i, j, v, which) { if (which == "K") K[i, j] += v; else M[i, j] += v }
  function plane(v0, t0, v1, t1, EI, s,   k, m, c, idx, i, j, sg) {
    c = EI / (L * L * L); m = rho * A * L / 420
    idx[1] = v0; idx[2] = t0; idx[3] = v1; idx[4] = t1; sg[1] = 1; sg[2] = s; sg[3] = 1; sg[4] = s
    split("12 6 -12 6 6 4 -6 2 -12 -6 12 -6 6 2 -6 4", k, " "); split("156 22 54 -13 22 4 13 -3 54 13 156 -22 -13 -3 -22 4", mm, " ")
    split("0 1 0 1 1 2 1 2 0 1 0 1 1 2 1 2", pk, " ")
    for (i = 1; i <= 4; i++) for (j = 1; j <= 4; j++) {
      add(idx[i], idx[j], sg[i] * sg[j] * c * k[4 * (i - 1) + j] * L ^ pk[4 * (i - 1) + j], "K")
      add(idx[i], idx[j], sg[i] * sg[j] * m * mm[4 * (i - 1) + j] * L ^ pk[4 * (i - 1) + j], "M") } }
  BEGIN {
    n = 6 * (ne + 1)
    for (e = 0; e < ne; e++) {
      a = 6 * e; b = 6 * (e + 1)   # 0-based DOF offsets: ux uy uz rx ry rz
      ka = E * A / L; kt = G * J / L; ma = rho * A * L / 6; mt = rho * (Iy + Iz) * L / 6
      add(a, a, ka, "K"); add(b, b, ka, "K"); add(a, b, -ka, "K"); add(b, a, -ka, "K")
      add(a + 3, a + 3, kt, "K"); add(b + 3, b + 3, kt, "K"); add(a + 3, b + 3, -kt, "K"); add(b + 3, a + 3, -kt, "K")
      add(a, a, 2 * ma, "M"); add(b, b, 2 * ma, "M"); add(a, b, ma, "M"); add(b, a, ma, "M")
      add(a + 3, a + 3, 2 * mt, "M"); add(b + 3, b + 3, 2 * mt, "M"); add(a + 3, b + 3, mt, "M"); add(b + 3, a + 3, mt, "M")
      plane(a + 1, a + 5, b + 1, b + 5, E * Iz, 1)     # x-y plane: uy, rz
      plane(a + 2, a + 4, b + 2, b + 4, E * Iy, -1)    # x-z plane: uz, -ry
    }
    # the export lists the DOFs node by node, rotations first (a different order than mbcc)
    split("3 4 5 0 1 2", order, " "); split("UX UY UZ ROTX ROTY ROTZ", name, " ")
    for (k = 0; k <= ne; k++) for (d = 1; d <= 6; d++) { r = 6 * k + d - 1; perm[r] = 6 * k + order[d]; }
    print "Matrix Eqn, Node, DOF" > dir "/map.csv"
    for (r = 0; r < n; r++) printf "%d, %d, %s\n", r + 1, 100 + int(perm[r] / 6), name[perm[r] % 6 + 1] > dir "/map.csv"
    print "# id, x, y, z" > dir "/nodes.csv"
    for (k = 0; k <= ne; k++) printf "%d, %.17g, 0, 0\n", 100 + k, k * L > dir "/nodes.csv"
    for (w = 0; w < 2; w++) {
      f = dir (w ? "/M.mtx" : "/K.mtx"); cnt = 0
      for (r = 0; r < n; r++) for (c = 0; c <= r; c++) { v = w ? M[perm[r], perm[c]] : K[perm[r], perm[c]]; if (v != 0) cnt++ }
      print "%%MatrixMarket matrix coordinate real symmetric" > f
      print "% written by tests/test_fe_import.sh" > f
      print n, n, cnt > f
      for (r = 0; r < n; r++) for (c = 0; c <= r; c++) { v = w ? M[perm[r], perm[c]] : K[perm[r], perm[c]]; if (v != 0) printf "%d %d %.17g\n", r + 1, c + 1, v > f }
    }
  }'
cat > "$T/mtx.yaml" <<YAML
name: fe_beam_mtx
bodies:
  beam:
    type: flexible
    fe_file: {stiffness: K.mtx, mass: M.mtx, dofs: map.csv, nodes: nodes.csv}
    reference: [100]
YAML
sed 's/reference: \[0\]/reference: [0]\n    mass: consistent/' "$root"/tests/models/fe/beam_inline.yaml > "$T/inl_cons.yaml"
modes "$T/mtx.yaml" beam "$T/mtx"
modes "$T/inl_cons.yaml" beam "$T/inc"
compare "$T/mtx.csv" "$T/inc.csv" "$T/mtx.modal" "$T/inc.modal" 1e-8 "Matrix Market vs inline" || fail "Matrix Market import"

# --- 3. a fine beam against closed forms ------------------------------------------
# steel tube (PBARL TUBE), L = 2 m along a tilted line in a CORD2R system, 60 CBEAMs
N=60
{
  echo 'CORD2R,9,,1.,2.,3.,1.,2.,4.'
  echo ',1.,3.,3.'                          # z = global z, C in the x-z plane: x = global y
  for k in $(seq 0 $N); do printf 'GRID,%d,9,%.17g,0.,0.\n' $((k + 1)) "$(awk -v k=$k -v n=$N 'BEGIN{print 2 * k / n}')"; done
  for k in $(seq 1 $N); do printf 'CBEAM,%d,5,%d,%d,0.,0.,1.\n' $k $k $((k + 1)); done
  echo 'PBEAM,5,8,1.,2.,2.,,3.,,'; echo ',,,,,,,,'; echo ',0.,0.'   # K1 = K2 = 0: Euler-Bernoulli
  echo 'MAT1,8,7.e10,,.33,2700.'
} > "$T/fine.bdf"
sed -i 's/^PBEAM.*$/PBEAM,5,8,1.e-4,2.e-9,2.e-9,,4.e-9/' "$T/fine.bdf"
for ref in '[1]' "{chord: [1, $((N + 1))]}" free; do
  cat > "$T/fine.yaml" <<YAML
name: fine
bodies:
  beam: {type: flexible, fe_file: fine.bdf, mass: consistent, reference: $ref, modes: 6}
YAML
  "$MBCC" modes "$T/fine.yaml" --body beam > "$T/fine.log" 2>&1 || { cat "$T/fine.log"; fail "fine beam $ref"; }
  awk -v ref="$ref" '
    BEGIN { E = 7e10; I = 2e-9; rho = 2700; A = 1e-4; L = 2; pi = 3.14159265358979; c = sqrt(E * I / (rho * A)) / (2 * pi * L * L)
            if (ref == "[1]") { b[1] = 1.8751040687; b[2] = 4.6940911330; want = 2 }
            else if (ref == "free") { b[1] = 4.7300407449; b[2] = 7.8532046241; want = 2 }
            else { b[1] = pi; b[2] = 2 * pi; want = 2 } }
    /^ +[0-9]+ +[0-9.e+-]+$/ { f[++n] = $2 }
    END { # bending modes come in equal pairs (a round section): modes 1,2 and 3,4
      for (k = 1; k <= want; k++) for (p = 0; p < 2; p++) {
        ex = b[k] * b[k] * c; got = f[2 * k - 1 + p]; err = (got - ex) / ex; if (err < 0) err = -err
        if (err > 2e-5) { printf "%s: bending mode %d: %.8g Hz, closed form %.8g Hz (%.2g)\n", ref, k, got, ex, err; bad = 1 } }
      exit bad }' "$T/fine.log" || fail "fine beam against the closed form ($ref)"
done

# --- 4. RBE2 spider ------------------------------------------------------------------
cat > "$T/spider.bdf" <<'BDF'
GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.
GRID,3,,1.,.2,0.
GRID,4,,1.,0.,.3
CBAR,1,1,1,2,0.,1.,0.
PBAR,1,1,1.e-4,1.e-9,2.e-9,3.e-9
MAT1,1,2.e11,,.3,8000.
CONM2,7,2,,1.5,,,,
,1.e-3,,1.e-3,,,1.e-3
RBE2,5,2,123456,3,4
BDF
cat > "$T/spider.yaml" <<'YAML'
name: spider
bodies:
  beam: {type: flexible, fe_file: spider.bdf, reference: [1]}
YAML
"$MBCC" modes "$T/spider.yaml" --body beam --shapes "$T/sp.csv" > "$T/sp.log" 2>&1 || { cat "$T/sp.log"; fail "RBE2 spider"; }
# node rows 2 (GRID 3) and 3 (GRID 4) = row 1 (GRID 2) moved rigidly: u_d = u_2 + theta_2 x r
awk -F, 'NR == 1 { next } { for (i = 1; i <= NF; i++) v[$1, i] = $i; nf = NF }
  END { worst = 0; big = 0
    for (m = 0; 5 + 6 * m + 5 <= nf; m++) {
      c = 5 + 6 * m
      for (d = 2; d <= 3; d++) {
        rx = v[d, 2] - v[1, 2]; ry = v[d, 3] - v[1, 3]; rz = v[d, 4] - v[1, 4]
        tx = v[1, c + 3]; ty = v[1, c + 4]; tz = v[1, c + 5]
        e[0] = v[d, c] - (v[1, c] + ty * rz - tz * ry); e[1] = v[d, c + 1] - (v[1, c + 1] + tz * rx - tx * rz)
        e[2] = v[d, c + 2] - (v[1, c + 2] + tx * ry - ty * rx)
        e[3] = v[d, c + 3] - tx; e[4] = v[d, c + 4] - ty; e[5] = v[d, c + 5] - tz
        for (i = 0; i < 6; i++) { if (e[i] < 0) e[i] = -e[i]; if (e[i] > worst) worst = e[i] }
        for (i = 0; i < 6; i++) { a = v[1, c + i]; if (a < 0) a = -a; if (a > big) big = a } } }
    if (!(big > 0) || worst > 1e-12 * big) { printf "RBE2: dependent nodes off the rigid motion by %.3g (scale %.3g)\n", worst, big; exit 1 } }' "$T/sp.csv" || fail "RBE2 spider"

# --- 6. initial modal state: free vibration in mode 1 -----------------------------------
M1="$root"/tests/models/fe/cantilever_mode1.yaml
modes "$M1" beam "$T/c1"
"$MBCC" run "$M1" -o "$T/c1run.csv" --plot none --quiet > "$T/c1run.log" 2>&1 || { cat "$T/c1run.log"; fail "run $M1"; }
f1=$(awk '$1 == 1 && NF == 2 { print $2; exit }' "$T/c1.log")
tip0=$(awk -F, '$1 == 10 { printf "%.17g", 0.01 * $7 }' "$T/c1.csv")   # node 10, mode 1 uz, times w0 = 0.01
awk -F, -v f1="$f1" -v tip0="$tip0" '
  NR == 2 { if ((($2 - tip0) < 0 ? tip0 - $2 : $2 - tip0) > 1e-9 * (tip0 < 0 ? -tip0 : tip0)) { printf "initial tip %.10g, expected %.10g\n", $2, tip0; bad = 1 } }
  NR > 2 && (py < 0) != ($2 < 0) { z[++n] = pt + (0 - py) * ($1 - pt) / ($2 - py) }
  NR > 1 { pt = $1; py = $2 }
  END { if (bad) exit 1
    if (n < 5) { print "too few zero crossings: " n; exit 1 }
    T = 2 * (z[n] - z[1]) / (n - 1); err = (1 / T - f1) / f1; if (err < 0) err = -err
    # the lumped 10-element model is 0.5 % below the Euler-Bernoulli cantilever: 7.615 Hz
    eb = 1.8751040687 ^ 2 / (2 * 3.14159265358979) * sqrt(2e10 * 1e-8 / (2700 * 4e-4))
    if (err > 1e-4) { printf "free vibration at %.8g Hz, the first mode is %.8g Hz\n", 1 / T, f1; exit 1 }
    if ((1 / T - eb) / eb > 0.01 || (eb - 1 / T) / eb > 0.01) { printf "free vibration at %.6g Hz, Euler-Bernoulli %.6g Hz\n", 1 / T, eb; exit 1 } }' "$T/c1run.csv" || fail "initial modal state"

# --- 7. the sparse eigensolver (CHOLMOD + ARPACK) against dense LAPACK ---------------------
# the fine beam with unequal bending stiffnesses (no repeated frequencies), 366 DOFs
sed 's/^PBEAM.*$/PBEAM,5,8,1.e-4,2.e-9,3.e-9,,4.e-9/' "$T/fine.bdf" > "$T/mid.bdf"
# the spider with a beam on from a dependent GRID: RBE2 folding in both assemblies
sed 's/^CBAR,1,1,1,2,0.,1.,0.$/CBAR,1,1,1,2,0.,1.,0.\nGRID,5,,1.5,0.,.3\nCBAR,2,1,4,5,0.,1.,0./' "$T/spider.bdf" > "$T/spider2.bdf"
for ref in '[1]' '{chord: [1, 61]}' free spider; do
  for es in dense sparse; do
    if [ "$ref" = spider ]; then
      printf 'name: sp\nbodies:\n  beam: {type: flexible, fe_file: spider2.bdf, reference: [1], modes: 8, mass: consistent, eigensolver: %s}\n' $es > "$T/mid_$es.yaml"
    else
      printf 'name: mid\nbodies:\n  beam: {type: flexible, fe_file: mid.bdf, reference: %s, modes: 12, eigensolver: %s}\n' "$ref" $es > "$T/mid_$es.yaml"
    fi
    modes "$T/mid_$es.yaml" beam "$T/mid_$es"
  done
  grep -q 'sparse: CHOLMOD' "$T/mid_sparse.log" || fail "the sparse eigensolver was not used ($ref)"
  compare "$T/mid_dense.csv" "$T/mid_sparse.csv" "$T/mid_dense.modal" "$T/mid_sparse.modal" 1e-8 "sparse vs dense ($ref)" ||
    fail "sparse eigensolver ($ref)"
done

# --- 8. a free body in mean axes simulated: energy and momentum conserved ----------------
sed 's/    reference: \[0\]/    reference: free/' "$root"/tests/models/free_flexible.yaml > "$T/ff.yaml"
"$MBCC" run "$T/ff.yaml" -o "$T/ff.csv" --plot none --quiet > "$T/ff.log" 2>&1 || { cat "$T/ff.log"; fail "run free-free"; }
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
  NR == 2 { e0 = $col["energy"]; for (i = col["momentum.px"]; i <= col["momentum.hz"]; i++) p0[i] = $i; next }
  { d = $col["energy"] - e0; if (d < 0) d = -d; if (d > de) de = d
    for (i = col["momentum.px"]; i <= col["momentum.hz"]; i++) { x = $i - p0[i]; if (x < 0) x = -x; if (x > dp) dp = x }
    x = $col["tip.y"]; if (x < 0) x = -x; if (x > tip) tip = x }
  END { if (de > 1e-8 * e0 || dp > 1e-10 || !(tip > 0)) { printf "free-free run: energy drift %.3g, momentum drift %.3g, tip %.3g\n", de / e0, dp, tip; exit 1 } }' "$T/ff.csv" ||
  fail "free-free body in mean axes"

# --- 9. stress recovery: a cantilever under a tip load settles on beam theory -------------
CS="$root"/tests/models/fe/cantilever_section.yaml
"$MBCC" run "$CS" -o "$T/cs.csv" --plot none --quiet > "$T/cs.log" 2>&1 || { cat "$T/cs.log"; fail "run $CS"; }
awk -F, 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next } { for (k in col) last[k] = $col[k] }
  END { P = 2; L = 1; c = 0.01; Iz = 3e-8
    n = split("root.N 0 root.Vy -2 root.Vz 0 root.T 0 root.My 0 root.Mz -2 mid_Mz -1", w, " ")
    for (i = 1; i < n; i += 2) { d = last[w[i]] - w[i + 1]; if (d < 0) d = -d
      if (d > 2e-4 * P * L) { printf "%s = %.8g, beam theory %g\n", w[i], last[w[i]], w[i + 1]; bad = 1 } }
    s = P * L * c / Iz; d = (last["root_top"] - s) / s; if (d < 0) d = -d
    if (d > 1e-4) { printf "root top fiber stress %.8g, beam theory %.8g\n", last["root_top"], s; bad = 1 }
    exit bad }' "$T/cs.csv" || fail "stress recovery"

# all 60 modes with the load on a node: the node's modal sums are longer than
# the emitter's expression buffers (they were cut there, and the C did not
# compile); the emitted C must be whole (a syntax check keeps this fast)
sed 's/^\( *modes:\).*/\1 all/' "$CS" > "$T/cs_all.yaml"
"$MBCC" compile "$T/cs_all.yaml" -o "$T/cs_all" > "$T/cs_all.log" 2>&1 || { cat "$T/cs_all.log"; fail "compile with all modes"; }
${CC:-cc} -std=c99 -fsyntax-only -I"$root"/runtime/core "$T/cs_all/cantilever_section.c" > "$T/cs_all.log" 2>&1 ||
  { head -5 "$T/cs_all.log"; fail "the emitted C of 60 modes with a node load does not compile"; }
grep -q "flexible body 'beam': 60 modes" "$T/cs_all/cantilever_section.c" ||
  fail "the all-modes variant does not have 60 modes"

# --- 5. bad input ---------------------------------------------------------------------
bad() { # deck-text expected-message-regex
  printf '%s\n' "$1" > "$T/bad.bdf"
  printf 'name: bad\nbodies:\n  beam: {type: flexible, fe_file: bad.bdf, reference: [1]}\n' > "$T/bad.yaml"
  "$MBCC" check "$T/bad.yaml" > "$T/bad.log" 2>&1; rc=$?
  [ $rc = 2 ] || { cat "$T/bad.log"; fail "bad deck: exit $rc (expected 2): $1"; }
  grep -Eq "$2" "$T/bad.log" || { cat "$T/bad.log"; fail "bad deck: expected /$2/"; }
}
OK='GRID,1,,0.,0.,0.
GRID,2,,1.,0.,0.
MAT1,1,2.e11,,.3,8000.'
bad "$OK
CBAR,1,1,1,3,0.,1.,0.
PBAR,1,1,1.e-4,1.e-9,1.e-9,1.e-9" 'bad\.bdf:4:12: error: CBAR: GB 3 is not a GRID'
bad "$OK
CBAR,1,1,1,2,1.,0.,0.
PBAR,1,1,1.e-4,1.e-9,1.e-9,1.e-9" 'bad\.bdf:4:14: error: CBAR 1: the orientation vector is zero or along'
bad "$OK
CQUAD4,1,1,1,2,3,4" 'bad\.bdf:4:1: error: card .CQUAD4. is not supported'
bad "GRID,1,,0.,0.,x
GRID,2,,1.,0.,0." 'bad\.bdf:1:15: error: GRID: X3 must be a real number'
bad "$OK
CBAR,1,1,1,2,0.,1.,0.
PBAR,1,1,1.e-4,1.e-9,1.e-9,1.e-9
INCLUDE 'missing.bdf'" 'bad\.bdf:6:1: error: cannot open included file'
bad "$OK
CBAR,1,1,1,2,0.,1.,0.
PBARL,1,1,,HEXA
,1.,2." 'bad\.bdf:5:.*section type .HEXA. is not supported'
printf '%%%%MatrixMarket matrix coordinate real symmetric\n2 2 2\n1 1 1.0\n1 2 3.0\n' > "$T/bad.mtx"
printf 'name: bad\nbodies:\n  b: {type: flexible, fe_file: {stiffness: bad.mtx, mass: bad.mtx, dofs: map.csv, nodes: nodes.csv}}\n' > "$T/badm.yaml"
"$MBCC" check "$T/badm.yaml" > "$T/bad.log" 2>&1; rc=$?
[ $rc = 2 ] && grep -q 'bad\.mtx:4:1: error: a symmetric Matrix Market file holds the lower triangle' "$T/bad.log" || { cat "$T/bad.log"; fail "bad Matrix Market (exit $rc)"; }
printf '%%%%MatrixMarket matrix coordinate real general\n2 2 3\n1 1 1.0\n1 2 3.0\n2 1 2.0\n' > "$T/bad.mtx"
"$MBCC" check "$T/badm.yaml" > "$T/bad.log" 2>&1; rc=$?
[ $rc = 2 ] && grep -q 'bad\.mtx: error: the matrix is not symmetric: entries (1, 2) and (2, 1) differ' "$T/bad.log" || { cat "$T/bad.log"; fail "unsymmetric Matrix Market (exit $rc)"; }
# model errors: the count of initial_modes, a chord of one node, a free body's position
badm() { # yaml-body-line expected-regex
  printf 'name: bad\nbodies:\n  beam:\n    type: flexible\n    line: {from: [0, 0, 0], to: [1, 0, 0], elements: 4}\n    section: {area: 1.0e-4}\n    material: {E: 2.0e11, density: 7800}\n    modes: 2\n%s\n' "$1" > "$T/badm.yaml"
  "$MBCC" compile "$T/badm.yaml" -o "$T/badm" > "$T/bad.log" 2>&1; rc=$?
  [ $rc = 2 ] && grep -Eq "$2" "$T/bad.log" || { cat "$T/bad.log"; fail "bad model (exit $rc): expected /$2/"; }
}
badm '    initial_modes: [0.1, 0, 0]' "badm\.yaml:9:20: error: flexible body 'beam': 'initial_modes' has 3 values, the body has 2 selected modes"
badm '    reference: {chord: [1, 1]}' "badm\.yaml:9:24: error: 'chord': expected two different nodes"
badm 'outputs:
  - {name: s, type: section, body: beam, element: 4}' "badm\\.yaml:10:51: error: body 'beam' has no beam 4 \\(beams are numbered from 0\\)"
badm '    reference: free
    position: [0, 0, 0]' "badm\.yaml:10:15: error: flexible body 'beam': a free-free body's frame is at its centre of mass"
exit 0
