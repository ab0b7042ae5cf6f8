#!/usr/bin/env bash
# test_geometric_stiffening.sh: the flexible-body option geometric_stiffening
# (docs/formulation.md 12.1) against independent truth:
#  1. a uniform cantilever spinning at a constant Omega about an axis through
#     its clamped root, bending out of the rotation plane (flapwise): the first
#     frequency from the zero crossings of a free vibration against
#     - Southwell's omega^2 = omega0^2 + alpha Omega^2 at Omega = omega0/3.5:
#       alpha = int N(x) phi'^2 / int phi^2 with N = (1 - xi^2)/2 and the
#       exact cantilever mode phi, computed here by quadrature (1.1933), to 1 %
#       of alpha;
#     - the exact rotating-beam frequency 4.7973 (Hodges and Rutkowski,
#       AIAA J. 19 (1981), Table 1; omega0 = 3.5160) at Omega = 3 in units of
#       sqrt(EI / (rho A L^4)), to 0.5 %;
#     - without the option: no stiffening at all (omega = omega0 to 1e-4),
#     so that a model without it cannot pass the first two;
#  2. the same cantilever loaded axially by gravity along it (tension, and
#     compression with gravity reversed): the slope of omega^2 in g,
#     (omega^2(g) - omega^2(-g)) / 2g (second order cancels), against
#     int (1 - xi) phi'^2 / int phi^2 / L from the exact mode (first-order
#     perturbation, exact in the slope), to 1 %;
#  3. a free spinning and tumbling beam with the option (no gravity, no
#     damping): total energy, linear and angular momentum conserved to 1e-9
#     of their magnitudes (the CSV has 12 digits) on the generic path;
#  4. the flexible slider-crank (models/slider_crank_flexible.yaml) with the
#     option: the peak mid-span deflection drops against the linear model by
#     5 to 10 % (a geometrically exact beam: 7.5 %, issue #25);
#  5. errors: the option on a modal-data-file body, with a chord reference,
#     or not a boolean: file:line:col, exit 2.
# The generated code against the generic path, and the stiffening's terms
# against Lagrange's equations: tests/test_fd.c (model free_flexible_stiff).
set -u
cd "$(dirname "$0")/.."
. tests/shell_setup.sh
command -v python3 >/dev/null || { echo "FAIL: python3 is missing (scripts/install-deps.sh installs it)"; exit 1; }

# the cantilever: L = 1 m, EI_flap = 700 N m^2, rho A = 1.08 kg/m; in-plane
# bending 4 times as stiff, so that mode 1 is the first flapwise mode
cantilever() { # name stiffening omega gravity_x -> name.yaml
  cat > "$1.yaml" <<EOF
name: $1
gravity: [$4, 0, 0]
bodies:
  beam:
    type: flexible
    line: {from: [0, 0, 0], to: [1.0, 0, 0], elements: 12}
    section: {area: 4.0e-4, Iy: 1.0e-8, Iz: 4.0e-8, J: 2.0e-8}
    material: {E: 7.0e10, nu: 0.3, density: 2700}
    reference: [0]
    modes: {count: 5}
    damping: none
    geometric_stiffening: $2
    initial_modes: [1.0e-3, 0, 0, 0, 0]
joints:
  hub:
    type: revolute
    bodies: [ground, beam]
    node: 0
    axis: [0, 0, 1]
drivers:
  spin:
    joint: hub
    motion: {type: constant_velocity, velocity: $3}
outputs:
  - {name: q1, type: modal, body: beam, mode: 1}
simulation:
  end_time: 0.5
  output_step: 2.0e-4
  integrator: dopri5
  rtol: 1.0e-9
  atol: 1.0e-12
EOF
}
run() { # name -> name.csv (generic path)
  "$MBCC" run "$1.yaml" --path generic -o "$1.csv" --plot none > "$1.log" 2>&1 || { cat "$1.log"; err "$1 did not run"; }
}

scale=$(python3 -c 'import math; print(math.sqrt(700 / 1.08))') # sqrt(EI / (rho A L^4)), 1/s
cantilever spin1 true "$(python3 -c "print(1.0 * $scale)")" 0
cantilever spin3 true "$(python3 -c "print(3.0 * $scale)")" 0
cantilever spin3lin false "$(python3 -c "print(3.0 * $scale)")" 0
cantilever pull true 0 800
cantilever push true 0 -800
for m in spin1 spin3 spin3lin pull push; do run $m; done
f0=$("$MBCC" modes spin1.yaml --body beam | awk '$1 == "1" {print $2}')

python3 - "$scale" "$f0" <<'EOF' || fail=1
import csv, math, sys
scale, f0 = float(sys.argv[1]), float(sys.argv[2])
def freq(name):  # Hz, from the upward zero crossings of q1
    r = list(csv.DictReader(open(name + ".csv")))
    t = [float(x["t"]) for x in r]; y = [float(x["q1"]) for x in r]
    up = [t[i - 1] + (t[i] - t[i - 1]) * -y[i - 1] / (y[i] - y[i - 1])
          for i in range(1, len(y)) if y[i - 1] < 0 <= y[i]]
    if len(up) < 4: sys.exit("FAIL: %s: %d zero crossings" % (name, len(up)))
    return (len(up) - 1) / (up[-1] - up[0])
# the exact first cantilever mode and its Rayleigh integrals (midpoint rule)
b = 1.875104068711961
s = (math.cosh(b) + math.cos(b)) / (math.sinh(b) + math.sin(b))
phi = lambda x: math.cosh(b * x) - math.cos(b * x) - s * (math.sinh(b * x) - math.sin(b * x))
dphi = lambda x: b * (math.sinh(b * x) + math.sin(b * x) - s * (math.cosh(b * x) - math.cos(b * x)))
n = 20000
xs = [(i + 0.5) / n for i in range(n)]
den = sum(phi(x) ** 2 for x in xs)
alpha = sum(0.5 * (1 - x * x) * dphi(x) ** 2 for x in xs) / den  # Southwell, centrifugal N
cg = sum((1 - x) * dphi(x) ** 2 for x in xs) / den               # N = rho A g (L - x)
bad = False
def check(label, got, want, tol):
    global bad
    ok = abs(got - want) <= tol * abs(want)
    print("%s: %s %.6g, expected %.6g (%.2g %%)" % ("ok" if ok else "FAIL", label, got, want,
                                                   100 * (got - want) / want))
    bad |= not ok
w0 = 2 * math.pi * f0
# 1. Southwell at Omega = 1 (units of scale): alpha from the measured shift
Om = 1.0 * scale
check("spin Omega=1: Southwell coefficient", ((2 * math.pi * freq("spin1")) ** 2 - w0 ** 2) / Om ** 2, alpha, 0.01)
check("spin Omega=3: omega/omega0", freq("spin3") / f0, 4.7973 / 3.5160, 0.005)
check("spin Omega=3 without the option: omega/omega0", freq("spin3lin") / f0, 1.0, 1e-4)
# 2. axial load: slope of omega^2 in g (L = 1 m)
slope = ((2 * math.pi * freq("pull")) ** 2 - (2 * math.pi * freq("push")) ** 2) / (2 * 800)
check("gravity along the beam: d omega^2 / d g", slope, cg, 0.01)
sys.exit(1 if bad else 0)
EOF

# --- 3. conservation of a free spinning beam with the option ------------------
"$MBCC" run "$root/tests/models/free_flexible_stiff.yaml" --path generic -o free.csv --plot none > free.log 2>&1 ||
  { cat free.log; err "free_flexible_stiff did not run"; }
python3 - <<'EOF' || fail=1
import csv, sys
r = list(csv.DictReader(open("free.csv")))
bad = False
col = lambda k: [float(x[k]) for x in r]
h = [(a * a + b * b + c * c) ** 0.5 for a, b, c in zip(col("momentum.hx"), col("momentum.hy"), col("momentum.hz"))]
p = [(a * a + b * b + c * c) ** 0.5 for a, b, c in zip(col("momentum.px"), col("momentum.py"), col("momentum.pz"))]
for k, scale in [("energy", max(col("energy"))), ("momentum.px", max(p)), ("momentum.py", max(p)),
                 ("momentum.pz", max(p)), ("momentum.hx", max(h)), ("momentum.hy", max(h)), ("momentum.hz", max(h))]:
    v = col(k)
    drift = max(abs(a - v[0]) for a in v) / scale
    print("%s: free beam %s drift %.2g of %.6g" % ("ok" if drift < 1e-9 else "FAIL", k, drift, scale))
    bad |= drift >= 1e-9
sys.exit(1 if bad else 0)
EOF

# --- 4. the flexible slider-crank ------------------------------------------------
sed 's/^  end_time: 0.1$/  end_time: 0.065/' "$root/models/slider_crank_flexible.yaml" > sc_lin.yaml
sed 's/^    damping: none /    geometric_stiffening: true\n    damping: none /' sc_lin.yaml > sc_stiff.yaml
grep -q 'geometric_stiffening: true' sc_stiff.yaml || err "the slider-crank variant lacks the option"
for m in sc_lin sc_stiff; do run $m; done
python3 - <<'EOF' || fail=1
import csv, sys
def peak(name):
    r = list(csv.DictReader(open(name + ".csv")))
    return max(abs(float(x["midspan"])) for x in r)
lin, st = peak("sc_lin"), peak("sc_stiff")
drop = 100 * (1 - st / lin)
ok = 5 <= drop <= 10
print("%s: slider-crank peak mid-span deflection / L: linear %.6g, stiffened %.6g (%.2f %% lower; "
      "geometrically exact beam 7.5 %%)" % ("ok" if ok else "FAIL", lin, st, drop))
sys.exit(0 if ok else 1)
EOF

# --- 5. errors ------------------------------------------------------------------
expect_error() { # file pattern
  "$MBCC" check "$1" > "$1.out" 2>&1
  local rc=$?
  [ $rc -eq 2 ] || err "$1: exit $rc, expected 2"
  grep -q "$2" "$1.out" || { cat "$1.out"; err "$1: no '$2'"; }
}
cantilever e_chord true 0 0
sed -i 's/^    reference: \[0\]/    reference: {chord: [0, 12]}/' e_chord.yaml
expect_error e_chord.yaml "e_chord.yaml:[0-9]*:[0-9]*: error: .*'geometric_stiffening' needs a clamped reference"
cantilever e_bool maybe 0 0
expect_error e_bool.yaml "e_bool.yaml:12:27: error: .*geometric_stiffening"
"$MBCC" modes spin1.yaml --body beam --write-modal beam.modal.yaml > /dev/null 2>&1 || err "modes --write-modal failed"
cat > e_modal.yaml <<'EOF'
name: e_modal
bodies:
  beam:
    type: flexible
    modal_file: beam.modal.yaml
    geometric_stiffening: true
EOF
expect_error e_modal.yaml "e_modal.yaml:6:27: error: .*'geometric_stiffening' needs an FE model of beams"
exit $fail
