#!/usr/bin/env bash
# test_fe_sections.sh: FE beam models with several sections and materials
# (docs/model-format.md, "Flexible bodies"), against independent truth:
#  1. box and tube sections by 'shape': the same cantilever with A, Iy, Iz, J
#     written out from the closed forms (computed here in another form:
#     Bredt's J = 4 Am^2 t / (mid-line perimeter), a tube's J = polar moment
#     pi (d^4 - di^4) / 32): all frequencies to 1e-9, and the mass rho A L;
#  2. a stepped cantilever (two sections, two materials, named in 'sections'
#     and 'materials'): its first two bending frequencies against the roots of
#     the exact characteristic equation (transfer matrices of the two
#     Euler-Bernoulli segments, solved here), to 1e-5 (consistent mass);
#  3. non-structural mass mu on a uniform beam: the bending frequencies scale
#     by sqrt(rho A / (rho A + mu)) (to 1e-9), the mass grows by mu L;
#  4. the same FE model inline and in a YAML FE file (fe_file), joints on
#     named nodes against node numbers: identical frequencies;
#  5. errors: an unknown node name (in a joint and in 'reference'), an
#     unknown section name, YAML and FE errors in an FE file: each at its
#     file:line:col (the FE file's own), exit 2.
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
command -v python3 >/dev/null || { echo "FAIL: python3 is missing (scripts/install-deps.sh installs it)"; exit 1; }

freqs() { # model body -> the selected modes' frequencies (full precision: the modal file), one line
  "$MBCC" modes "$1" --body "$2" --write-modal "$1.modal" > "$1.modes" 2>&1 || { cat "$1.modes"; return 1; }
  grep -o 'frequency: [0-9.e+-]*' "$1.modal" | cut -d' ' -f2 | tr '\n' ' '
}
same() { # label tol "f1 f2 ..." "g1 g2 ..." [scale]: g = scale f for every pair
  python3 - "$@" <<'EOF' || fail=1
import sys
label, tol, a, b = sys.argv[1], float(sys.argv[2]), sys.argv[3].split(), sys.argv[4].split()
scale = float(sys.argv[5]) if len(sys.argv) > 5 else 1.0
n = int(sys.argv[6]) if len(sys.argv) > 6 else len(a)
if (len(sys.argv) <= 6 and len(a) != len(b)) or len(a) < n or len(b) < n or not a:
    sys.exit("FAIL: %s: %d against %d frequencies" % (label, len(a), len(b)))
worst = max(abs(float(y) - scale * float(x)) / (scale * float(x)) for x, y in list(zip(a, b))[:n])
if worst > tol: sys.exit("FAIL: %s: relative difference %.3g > %g" % (label, worst, tol))
EOF
}
mass_of() { "$MBCC" check "$1" | sed -n 's/^ *mass \([0-9.e+-]*\) kg.*/\1/p'; }

# --- 1. shapes against their closed forms -------------------------------------
cat > shape.yaml <<'EOF'
name: shape
bodies:
  bar:
    type: flexible
    line: {from: [0, 0, 0], to: [1.2, 0, 0], elements: 6}
    modes: 20
    sections:
      BOX:  {shape: box, h: 0.080, b: 0.050, t: 0.002}
      TUBE: {shape: tube, d: 0.040, t: 0.003}
    section: BOX
    material: {E: 2.1e11, G: 8.08e10, density: 7850}
EOF
python3 - > explicit.yaml <<'EOF'
import math
h, b, t = 0.080, 0.050, 0.002
A = 2 * t * (h + b) - 4 * t * t                        # the wall as four strips, corners once
Iy = b * h**3 / 12 - (b - 2 * t) * (h - 2 * t)**3 / 12
Iz = h * b**3 / 12 - (h - 2 * t) * (b - 2 * t)**3 / 12
Am, s = (h - t) * (b - t), 2 * ((h - t) + (b - t))     # Bredt: enclosed mid-line area and perimeter
J = 4 * Am**2 * t / s
print("name: explicit\nbodies:\n  bar:\n    type: flexible\n"
      "    line: {from: [0, 0, 0], to: [1.2, 0, 0], elements: 6}\n    modes: 20\n"
      "    section: {area: %.17g, Iy: %.17g, Iz: %.17g, J: %.17g}\n"
      "    material: {E: 2.1e11, G: 8.08e10, density: 7850}" % (A, Iy, Iz, J))
print("# mass %.17g" % (7850 * A * 1.2))
EOF
same "box by shape" 1e-9 "$(freqs explicit.yaml bar)" "$(freqs shape.yaml bar)"
want=$(sed -n 's/^# mass //p' explicit.yaml)
same "box mass" 1e-9 "$want" "$(mass_of shape.yaml)"
sed 's/section: BOX/section: TUBE/' shape.yaml > shape_tube.yaml
python3 - > explicit_tube.yaml <<'EOF'
import math
d, t = 0.040, 0.003
di = d - 2 * t
A = math.pi * (d * d - di * di) / 4
I = math.pi * (d**4 - di**4) / 64
J = math.pi * (d**4 - di**4) / 32                       # the polar moment of a ring
print("name: explicit_tube\nbodies:\n  bar:\n    type: flexible\n"
      "    line: {from: [0, 0, 0], to: [1.2, 0, 0], elements: 6}\n    modes: 20\n"
      "    section: {area: %.17g, Iy: %.17g, Iz: %.17g, J: %.17g}\n"
      "    material: {E: 2.1e11, G: 8.08e10, density: 7850}" % (A, I, I, J))
EOF
same "tube by shape" 1e-9 "$(freqs explicit_tube.yaml bar)" "$(freqs shape_tube.yaml bar)"

# --- 2. a stepped cantilever against its characteristic equation --------------------
# segment 1 (clamped at x = 0): steel box, L1 = 0.6 m; segment 2 (free end):
# aluminium tube, L2 = 0.4 m; 40 elements each, consistent mass
python3 - > step.yaml <<'EOF'
n1, n2, L1, L2 = 40, 40, 0.6, 0.4
xs = [L1 * k / n1 for k in range(n1)] + [L1 + L2 * k / n2 for k in range(n2 + 1)]
print("name: step\nbodies:\n  beam:\n    type: flexible\n    mass: consistent\n    reference: [ROOT]\n    modes: 10")
print("    node_names: {ROOT: 0, STEP: %d, TIP: %d}" % (n1, n1 + n2))
print("    sections:\n      THICK: {shape: box, h: 0.060, b: 0.040, t: 0.003}\n"
      "      THIN: {shape: tube, d: 0.030, t: 0.002}")
print("    materials:\n      steel: {E: 2.1e11, nu: 0.3, density: 7850}\n"
      "      aluminium: {E: 7.0e10, nu: 0.33, density: 2700}")
print("    nodes:")
for x in xs: print("      - [%.17g, 0, 0]" % x)
print("    beams:")
for e in range(n1 + n2):
    a = "STEP" if e == n1 else e
    b = "STEP" if e + 1 == n1 else ("TIP" if e + 1 == n1 + n2 else e + 1)
    sec, mat = ("THICK", "steel") if e < n1 else ("THIN", "aluminium")
    print("      - {nodes: [%s, %s], section: %s, material: %s}" % (a, b, sec, mat))
EOF
python3 - > step_exact.txt <<'EOF'
import math
def box(h, b, t): return h * b - (h - 2*t) * (b - 2*t), (b * h**3 - (b - 2*t) * (h - 2*t)**3) / 12, (h * b**3 - (h - 2*t) * (b - 2*t)**3) / 12
def tube(d, t): di = d - 2*t; I = math.pi * (d**4 - di**4) / 64; return math.pi * (d*d - di*di) / 4, I, I
A1, Iy1, Iz1 = box(0.060, 0.040, 0.003); A2, Iy2, Iz2 = tube(0.030, 0.002)
seg = lambda E, rho, A, I, L: (E * I, rho * A, L)
def transfer(EI, m, L, w):
    """4x4 map of [v, v', EI v'', EI v'''] across a uniform Euler-Bernoulli segment at circular frequency w"""
    beta = (m * w * w / EI) ** 0.25
    def basis(x):  # rows: v, v', EI v'', EI v''' of cosh, sinh, cos, sin (beta x)
        c, s, C, S, b = math.cosh(beta*x), math.sinh(beta*x), math.cos(beta*x), math.sin(beta*x), beta
        return [[c, s, C, S], [b*s, b*c, -b*S, b*C], [EI*b*b*c, EI*b*b*s, -EI*b*b*C, -EI*b*b*S],
                [EI*b**3*s, EI*b**3*c, EI*b**3*S, -EI*b**3*C]]
    P0, PL = basis(0.0), basis(L)
    # T = PL inv(P0): solve P0^T X^T = PL^T column by column (Gauss-Jordan, partial pivoting)
    n = 4; aug = [P0[i][:] + [1.0 if i == j else 0.0 for j in range(n)] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(aug[r][c])); aug[c], aug[p] = aug[p], aug[c]
        for r in range(n):
            if r != c:
                f = aug[r][c] / aug[c][c]; aug[r] = [x - f * y for x, y in zip(aug[r], aug[c])]
    inv = [[aug[i][n + j] / aug[i][i] for j in range(n)] for i in range(n)]
    return [[sum(PL[i][k] * inv[k][j] for k in range(n)) for j in range(n)] for i in range(n)]
def det_free(w, plane):
    I1, I2 = (Iz1, Iz2) if plane == 'y' else (Iy1, Iy2)
    T1 = transfer(2.1e11 * I1, 7850 * A1, 0.6, w); T2 = transfer(7.0e10 * I2, 2700 * A2, 0.4, w)
    T = [[sum(T2[i][k] * T1[k][j] for k in range(4)) for j in range(4)] for i in range(4)]
    return T[2][2] * T[3][3] - T[2][3] * T[3][2]   # clamped root: [0, 0, M, V]; free tip: M = V = 0
roots = []
for plane in 'yz':
    w, step, d0, found = 1.0, 1.0, det_free(1.0, plane), 0
    while found < 2:
        d1 = det_free(w + step, plane)
        if (d0 > 0) != (d1 > 0):
            a, b = w, w + step
            for _ in range(100):
                mid = 0.5 * (a + b)
                if (det_free(mid, plane) > 0) == (det_free(a, plane) > 0): a = mid
                else: b = mid
            roots.append(0.5 * (a + b) / (2 * math.pi)); found += 1
        w, d0 = w + step, d1
print(" ".join("%.12g" % f for f in sorted(roots)))
EOF
fe=$(freqs step.yaml beam) || err "mbcc modes step.yaml failed"
# the four lowest FE modes are the first two bending modes of each plane
same "stepped cantilever (first 4 bending modes)" 1e-5 "$(cat step_exact.txt)" "$fe" 1 4

# --- 3. non-structural mass on a uniform beam -------------------------------------------
cat > plain.yaml <<'EOF'
name: plain
bodies:
  rod:
    type: flexible
    line: {from: [0, 0, 0], to: [1, 0, 0], elements: 12}
    modes: 6
    section: {area: 3.0e-4, Iy: 2.0e-8, Iz: 1.2e-8, J: 3.0e-8}
    material: {E: 2.1e11, nu: 0.3, density: 7850}
EOF
sed 's/^    line:/    nonstructural_mass: 1.5\n    line:/; s/^name: plain/name: trimmed/' plain.yaml > trimmed.yaml
ratio=$(python3 -c 'import math; r = 7850 * 3.0e-4; print(repr(math.sqrt(r / (r + 1.5))))')
# slender: the 6 lowest modes are bending (torsion and axial are far higher)
same "non-structural mass: bending frequencies" 1e-9 "$(freqs plain.yaml rod)" "$(freqs trimmed.yaml rod)" "$ratio" 6
same "non-structural mass: mass" 1e-12 "$(python3 -c 'print(7850 * 3.0e-4 + 1.5)')" "$(mass_of trimmed.yaml)"

# --- 4. YAML FE file = inline; named nodes = numbers ------------------------------------
awk '/^    [a-z_]+:/ && !/^    (type|reference|modes):/ { sub(/^    /, ""); print; on = 1; next } on && /^      / { sub(/^    /, ""); print; next } { on = 0 }' \
  step.yaml > step.fe.yaml
cat > step_file.yaml <<'EOF'
name: step_file
bodies:
  beam:
    type: flexible
    fe_file: step.fe.yaml
    reference: [ROOT]
    modes: 10
  tip_mass: {type: rigid, mass: 0.3, inertia: [1e-4, 1e-4, 1e-4], position: [1.0, 0, 0]}
joints:
  weld: {type: fixed, bodies: [beam, tip_mass], node: TIP}
outputs:
  - {name: tip_y, type: position, body: beam, node: TIP, component: y}
EOF
same "YAML FE file = inline" 1e-13 "$(freqs step.yaml beam)" "$(freqs step_file.yaml beam)"
"$MBCC" check step_file.yaml > file_check.txt 2>&1 || err "mbcc check of a model with fe_file and named nodes: $(tail -3 file_check.txt)"
sed 's/node: TIP/node: 80/g' step_file.yaml > step_numbers.yaml
"$MBCC" check step_numbers.yaml > numbers_check.txt 2>&1 || err "the numbered variant failed"
diff <(grep -v '^model' file_check.txt) <(grep -v '^model' numbers_check.txt) > /dev/null ||
  err "named nodes and node numbers give different systems"

# --- 5. errors, located ------------------------------------------------------------------
expect_error() { # model file:line:col message
  "$MBCC" check "$1" > err.txt 2>&1
  local rc=$?
  [ $rc = 2 ] || err "$1: exit $rc, expected 2"
  grep -qF "$2: error: " err.txt && grep -qF "$3" err.txt ||
    err "$1: expected '$2: error: ...$3...', got: $(head -3 err.txt)"
}
sed 's/node: TIP/node: TOP/' step_file.yaml > bad_joint.yaml
expect_error bad_joint.yaml "bad_joint.yaml:10:55" "no node is named 'TOP' (named nodes: ROOT, STEP, TIP)"
sed 's/reference: \[ROOT\]/reference: [ROOT, RUT]/' step_file.yaml > bad_ref.yaml
expect_error bad_ref.yaml "bad_ref.yaml:6:23" "no node is named 'RUT'"
sed '0,/section: THIN/s//section: THN/' step.fe.yaml > bad_section.fe.yaml
sed 's/step.fe.yaml/bad_section.fe.yaml/' step_file.yaml > bad_section.yaml
line=$(grep -n 'section: THN' bad_section.fe.yaml | cut -d: -f1)
col=$(grep 'section: THN' bad_section.fe.yaml | awk '{ print index($0, "THN") }')
expect_error bad_section.yaml "bad_section.fe.yaml:$line:$col" "no section is named 'THN' (expected one of: THICK, THIN)"
grep -qF "bad_section.yaml:5:14: note: in the FE file of flexible body 'beam'" err.txt || err "no note at the body's fe_file"
printf 'nodes: [[0, 0, 0], [1, 0, 0]\nbeams: [[0, 1]]\n' > broken.fe.yaml
sed 's/step.fe.yaml/broken.fe.yaml/; s/reference: \[ROOT\]/reference: [0]/; s/node: TIP/node: 1/g' step_file.yaml > broken.yaml
expect_error broken.yaml "broken.fe.yaml:2:1" "invalid YAML"
# a zero-length beam: found by the FE stage, still located in the FE file
awk '/^  - \[/ && ++k == 2 { print "  - [0, 0, 0]"; next } { print }' step.fe.yaml > zero.fe.yaml
sed 's/step.fe.yaml/zero.fe.yaml/' step_file.yaml > zero.yaml
line=$(grep -n 'nodes: \[0, 1\]' zero.fe.yaml | cut -d: -f1)
expect_error zero.yaml "zero.fe.yaml:$line:5" "zero-length element"

[ "$fail" = 0 ] && echo "test_fe_sections: ok"
exit "$fail"
