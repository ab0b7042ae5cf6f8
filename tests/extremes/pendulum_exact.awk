# pendulum_exact.awk: max |angle - exact| over a pendulum CSV (models/pendulum.yaml:
# released from rest at theta0 = 90 degrees; the 'angle' column is theta - theta0).
# Exact: theta(t) = 2 asin(k sn(K - w0 t, k)), k = sin(theta0 / 2),
# w0 = sqrt(m g l / I_O), m = 1 kg, l = 1 m, g = 9.81, I_O = 1e-4 + 1 kg m^2;
# sn and K by the arithmetic-geometric mean (descending Landen transformation,
# Abramowitz & Stegun 16.4).  Prints the error in rad.
function asin_(x) { return atan2(x, sqrt(1 - x * x)) }
function agm_setup(k,   b, t) {
  A[0] = 1; b = sqrt(1 - k * k); C[0] = k; N = 0
  while (C[N] > 1e-17 && N < 40) {
    A[N + 1] = (A[N] + b) / 2; C[N + 1] = (A[N] - b) / 2
    t = sqrt(A[N] * b); b = t; N++
  }
  KK = atan2(0, -1) / (2 * A[N])
}
function sn(u,   phi, i, s) {
  phi = 2 ^ N * A[N] * u
  for (i = N; i > 0; i--) { s = C[i] / A[i] * sin(phi); phi = (phi + asin_(s)) / 2 }
  return sin(phi)
}
BEGIN { FS = ","; pi = atan2(0, -1); th0 = pi / 2; k = sin(th0 / 2); w0 = sqrt(9.81 / 1.0001); agm_setup(k) }
NR == 1 { for (i = 1; i <= NF; i++) if ($i == "angle") col = i; next }
{
  exact = 2 * asin_(k * sn(KK - w0 * $1)) - th0
  e = $col - exact; if (e < 0) e = -e
  if (e > worst) worst = e
}
END { printf "%.3e\n", worst }
