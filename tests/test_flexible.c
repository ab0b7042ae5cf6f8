/* test_flexible.c: flexible bodies against physics and against each other.
 *   - the flexible slider-crank of seed 000 (Fig. 6, 7): joints directly on
 *     the FE nodes, through 1 and through 2 massless virtual bodies: the same
 *     midspan deflection history, of the size a quasi-static estimate gives;
 *   - a free spinning, tumbling flexible beam: energy and the 6 momentum
 *     components are conserved while elastic energy comes and goes;
 *   - a clamped cantilever sagging under gravity (damped, settled) against
 *     the closed-form tip deflection, for coupling full, partial and constant;
 *   - modal damping: the logarithmic decrement of a cantilever's response to
 *     a tip force step (undamped and 5 %), and the three-band setting of
 *     seed 001 section 2.6 at the model's frequencies (tables and mbcc check);
 *   - `mbcc modes`: frequencies, the mode-shape CSV, errors.
 * Physical parameters are those written in the YAML files (comments say
 * which), not read back from the compiled tables. */
// models: slider_crank_flexible slider_crank_flexible@virtual1 slider_crank_flexible@virtual2 free_flexible cantilever_gravity cantilever_gravity_partial cantilever_gravity_constant cantilever_step cantilever_bands
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support.h"
#include "slider_crank_flexible.h"
#include "slider_crank_flexible_virtual1.h"
#include "slider_crank_flexible_virtual2.h"
#include "free_flexible.h"
#include "cantilever_gravity.h"
#include "cantilever_gravity_partial.h"
#include "cantilever_gravity_constant.h"
#include "cantilever_step.h"
#include "cantilever_bands.h"

static const char *mbcc(void) {
  const char *m = getenv("MBCC");
  return m && *m ? m : "build/mbcc";
}

static void run_ok(const mb_model *m, const mb_settings *s, trajectory *tr) {
  int st = simulate(m, s, "klu", tr);
  if (st) print_error("%s: simulation failed (status %d) at t = %g\n", m->name, st, tr->fail_time);
  assert_int_equal(st, 0);
}

static int col_or_fail(const mb_model *m, const char *name) {
  int c = column(m, name);
  if (c < 0) print_error("%s has no output column '%s'\n", m->name, name);
  assert_true(c >= 0);
  return c;
}

/* ---------------------------------------------------------------------------
 * 1a. The flexible slider-crank (models/slider_crank_flexible.yaml): crank
 * r = 0.1524 m at 124.8 rad/s; steel rod L = 0.3048 m, E = 2.068e11 Pa,
 * rho = 7820 kg/m^3, A = 3.16e-5 m^2, solid circular (I = A^2 / (4 pi)).
 * ------------------------------------------------------------------------- */
#define SC_R 0.1524
#define SC_OMEGA 124.8
#define SC_L 0.3048
#define SC_E 2.068e11
#define SC_RHO 7820.0
#define SC_A 3.16e-5

static void test_slider_crank_virtual_bodies(void **state) {
  (void)state;
  /* the model's own settings: DOPRI5, rtol 1e-8, atol 1e-10, 0.1 s */
  mb_settings s;
  test_settings(&s, 0.1, 2.0e-4);
  s.rtol = 1e-8;
  s.atol = 1e-10;
  const mb_model *m[3] = {&slider_crank_flexible_model, &slider_crank_flexible_virtual1_model,
                          &slider_crank_flexible_virtual2_model};
  const char *label[3] = {"direct", "1 virtual body", "2 virtual bodies"};
  trajectory tr[3];
  int c[3];
  for (int k = 0; k < 3; k++) {
    run_ok(m[k], &s, &tr[k]);
    c[k] = col_or_fail(m[k], "midspan"); /* transverse deflection at node 4 from the chord 0-8, / L */
  }
  /* the virtual bodies add coordinates and rows, not physics */
  assert_true(m[1]->nv > m[0]->nv && m[2]->nv > m[1]->nv);
  double peak = 0, tpeak = 0;
  for (int i = 0; i < tr[0].nrows; i++)
    if (fabs(at(&tr[0], i, c[0])) > peak) { peak = fabs(at(&tr[0], i, c[0])); tpeak = tr[0].t[i]; }
  for (int k = 1; k < 3; k++) {
    assert_int_equal(tr[k].nrows, tr[0].nrows);
    double worst = 0;
    for (int i = 0; i < tr[0].nrows; i++) {
      assert_close(tr[k].t[i], tr[0].t[i], 1e-12);
      worst = fmax(worst, fabs(at(&tr[k], i, c[k]) - at(&tr[0], i, c[0])));
    }
    print_message("slider_crank_flexible: %s vs direct: max |midspan difference| = %.3g of the peak "
                  "(%d vs %d velocity coordinates)\n", label[k], worst / peak, m[k]->nv, m[0]->nv);
    assert_true(worst < 1e-3 * peak);
  }
  /* Size of the deflection, quasi-static: the rod's transverse acceleration
   * falls about linearly from omega^2 r at the crank pin to ~0 at the slider
   * (whose acceleration is along the rod's line, nearly), so its inertial load
   * is a triangle of peak q0 = rho A omega^2 r on a pinned-pinned beam.  The
   * midspan deflection of a simply supported beam under a triangular load is
   * half that of a uniform load of q0: 5 q0 L^4 / (768 E I); here 0.66 % of L.
   * The dynamic response (the crank starts at full speed at t = 0, the rod's
   * first bending mode is ~ 49 Hz against 19.9 Hz of the crank) may amplify it
   * a little; a factor 0.75..4.5 is a sanity band, not a validation. */
  double I = SC_A * SC_A / (4 * MB_PI);
  double q0 = SC_RHO * SC_A * SC_OMEGA * SC_OMEGA * SC_R;
  double quasi = 5 * q0 * pow(SC_L, 4) / (768 * SC_E * I) / SC_L;
  print_message("slider_crank_flexible: peak |midspan| / L = %.4g %% at t = %.4g s; quasi-static "
                "estimate %.3g %%\n", 100 * peak, tpeak, 100 * quasi);
  assert_true(quasi > 0.0060 && quasi < 0.0070);
  assert_true(peak > 0.005 && peak < 0.03);
  for (int k = 0; k < 3; k++) trajectory_free(&tr[k]);
}

/* ---------------------------------------------------------------------------
 * 1b. tests/models/free_flexible.yaml: a free beam (no gravity, no damping,
 * no joints) spinning and tumbling: centrifugal loading makes it vibrate.
 * ------------------------------------------------------------------------- */
static double norm3v(const double *a) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

static void test_free_flexible_conservation(void **state) {
  (void)state;
  const mb_model *m = &free_flexible_model;
  mb_settings s;
  test_settings(&s, 1.0, 0.005); /* the model's settings: rtol 1e-10, atol 1e-12 */
  s.rtol = 1e-10;
  s.atol = 1e-12;
  trajectory tr;
  run_ok(m, &s, &tr);
  int ce = col_or_fail(m, "energy"), cu = col_or_fail(m, "potential"), cp = col_or_fail(m, "momentum.px");
  int ch = col_or_fail(m, "momentum.hx"), ct = col_or_fail(m, "tip.y");
  double p0[3], h0[3];
  for (int i = 0; i < 3; i++) { p0[i] = at(&tr, 0, cp + i); h0[i] = at(&tr, 0, ch + i); }
  double E0 = at(&tr, 0, ce), sp = norm3v(p0), sh = norm3v(h0);
  double dE = 0, dp = 0, dh = 0, Umax = 0, tipmax = 0;
  for (int k = 0; k < tr.nrows; k++) {
    dE = fmax(dE, fabs(at(&tr, k, ce) - E0));
    for (int i = 0; i < 3; i++) {
      dp = fmax(dp, fabs(at(&tr, k, cp + i) - p0[i]));
      dh = fmax(dh, fabs(at(&tr, k, ch + i) - h0[i]));
    }
    Umax = fmax(Umax, at(&tr, k, cu));
    tipmax = fmax(tipmax, fabs(at(&tr, k, ct)));
  }
  print_message("free_flexible: over %g s, relative drift: energy %.3g (E = %.6g J), linear momentum "
                "%.3g (|p| = %.6g), angular momentum %.3g (|h| = %.6g); largest elastic energy %.3g J "
                "(%.3g of E), tip deflection %.3g m\n", tr.t[tr.nrows - 1], dE / E0, E0, dp / sp, sp,
                dh / sh, sh, Umax, Umax / E0, tipmax);
  assert_close(tr.t[tr.nrows - 1], 1.0, 1e-12);
  assert_true(dE < 1e-8 * E0);
  assert_true(dp < 1e-8 * sp);
  assert_true(dh < 1e-8 * sh);
  /* meaningful: the elastic energy that comes and goes is far above what the
     energy check resolves (1e-8 E), and the beam does deform */
  assert_true(at(&tr, 0, cu) == 0);
  assert_true(Umax > 10 * 1e-8 * E0);
  assert_true(tipmax > 1e-5);
  trajectory_free(&tr);
}

/* ---------------------------------------------------------------------------
 * 1c. tests/models/cantilever_gravity*.yaml: a cantilever L = 1 m, A = 4e-4
 * m^2, Iz = 3e-8 m^4 (bending in the x-y plane), E = 2e10 Pa, rho = 2700
 * kg/m^3 under g = 9.81 m/s^2 along -y, modal damping 0.2, clamped at x = 0.
 * ------------------------------------------------------------------------- */
#define CB_L 1.0
#define CB_A 4.0e-4
#define CB_IZ 3.0e-8
#define CB_E 2.0e10
#define CB_RHO 2700.0
#define CB_G 9.81

static void test_cantilever_gravity(void **state) {
  (void)state;
  const mb_model *m[3] = {&cantilever_gravity_model, &cantilever_gravity_partial_model,
                          &cantilever_gravity_constant_model};
  const char *coupling[3] = {"full", "partial", "constant"};
  mb_settings s;
  test_settings(&s, 2.0, 0.01);
  trajectory tr[3];
  int c[3];
  /* Euler-Bernoulli, uniform load q = rho A g: tip deflection q L^4 / (8 E I).
   * The model differs from it by (a) the lumped masses: the load is applied
   * as nodal forces (half a share at the free end, no nodal moments), and
   * (b) the static response is built from the 3 lowest y-bending modes (the
   * 6 modes alternate between the y and z planes, Iy != Iz), missing the
   * static part of the higher ones.  Together they make the tip sag about
   * 0.35 % more than the closed form. */
  double q = CB_RHO * CB_A * CB_G, exact = q * pow(CB_L, 4) / (8 * CB_E * CB_IZ);
  for (int k = 0; k < 3; k++) {
    run_ok(m[k], &s, &tr[k]);
    c[k] = col_or_fail(m[k], "tip.y");
    int n = tr[k].nrows;
    double tip = -at(&tr[k], n - 1, c[k]);
    /* settled: damping 0.2 on the 13 Hz first y mode decays as exp(-16.5 t) */
    double moving = fabs(at(&tr[k], n - 1, c[k]) - at(&tr[k], n - 11, c[k]));
    print_message("cantilever_gravity (coupling %s): tip deflection after %g s %.6g m, closed form "
                  "q L^4 / (8 E I) = %.6g m, relative difference %+.3g; change over the last 0.1 s %.2g m\n",
                  coupling[k], tr[k].t[n - 1], tip, exact, tip / exact - 1, moving);
    assert_true(moving < 1e-6 * exact);
    assert_true(fabs(tip - exact) < 0.01 * exact);
  }
  /* With the body frame welded to the ground the frame neither moves nor
     turns, so the terms that differ between coupling levels (J(w), M_thf(w)
     and the velocity-quadratic forces) multiply zero; in this nearly static
     case the three levels must agree closely (whole histories). */
  for (int k = 1; k < 3; k++) {
    assert_int_equal(tr[k].nrows, tr[0].nrows);
    double worst = 0;
    for (int i = 0; i < tr[0].nrows; i++) worst = fmax(worst, fabs(at(&tr[k], i, c[k]) - at(&tr[0], i, c[0])));
    print_message("cantilever_gravity: coupling %s vs full: max |tip difference| = %.3g of the deflection\n",
                  coupling[k], worst / exact);
    assert_true(worst < 1e-3 * exact);
  }
  for (int k = 0; k < 3; k++) trajectory_free(&tr[k]);
}

/* ---------------------------------------------------------------------------
 * 1d. modal damping
 * ------------------------------------------------------------------------- */

/* extremes of column c after time t0: times and values by a parabola through
   the three samples around each sampled extreme */
static int extremes(const trajectory *tr, int c, double t0, double *te, double *ye, int max) {
  int n = 0;
  for (int k = 1; k + 1 < tr->nrows && n < max; k++) {
    if (tr->t[k] < t0) continue;
    double a = at(tr, k - 1, c), b = at(tr, k, c), d = at(tr, k + 1, c);
    if (!((b > a && b >= d) || (b < a && b <= d))) continue;
    double den = a - 2 * b + d, u = den != 0 ? 0.5 * (a - d) / den : 0;
    te[n] = tr->t[k] + u * (tr->t[k + 1] - tr->t[k]);
    ye[n++] = b - 0.25 * (a - d) * u;
  }
  return n;
}

/* Damping ratio from the logarithmic decrement of the swings between
 * successive extremes: for y = y_s + a exp(-zeta w t) cos(w_d t + phi), the
 * swing h_i = |y_{i+1} - y_i| shrinks by exp(delta) per period (2 swings),
 * delta = 2 pi zeta / sqrt(1 - zeta^2), independent of the static offset y_s.
 * Averaged over all whole periods after t0.  Also the mean period. */
static double decrement_zeta(const trajectory *tr, int c, double t0, double *period, int *nswings) {
  double te[512], ye[512];
  int n = extremes(tr, c, t0, te, ye, 512);
  assert_true(n >= 8);
  int ns = n - 1, periods = (ns - 1) / 2;
  double h0 = fabs(ye[1] - ye[0]), h1 = fabs(ye[1 + 2 * periods] - ye[2 * periods]);
  double delta = log(h0 / h1) / periods;
  *period = (te[2 * periods] - te[0]) / periods;
  *nswings = ns;
  return delta / sqrt(4 * MB_PI * MB_PI + delta * delta);
}

/* tests/models/cantilever_step.yaml: the beam of 1c (no gravity), a 1 N tip
 * force along -y from t = 0; 'undamped' (damping: none) and 'damped' (0.05). */
static void test_modal_damping_decrement(void **state) {
  (void)state;
  const mb_model *m = &cantilever_step_model;
  mb_settings s;
  test_settings(&s, 0.6, 2.0e-4);
  trajectory tr;
  run_ok(m, &s, &tr);
  int cu = col_or_fail(m, "tip_undamped"), cd = col_or_fail(m, "tip_damped");
  /* The step excites every y-bending mode; the first (13.1 Hz) carries ~97 %
     of the tip's static deflection.  From t0 = 0.1 s the 5 % damping has
     taken the second (81 Hz) mode down by exp(-0.05 * 2 pi 81 * 0.1) = 0.08:
     the damped tip is then a clean single-mode decay. */
  const double t0 = 0.1;
  double Tu, Td;
  int nu, nd;
  double zu = decrement_zeta(&tr, cu, t0, &Tu, &nu), zd = decrement_zeta(&tr, cd, t0, &Td, &nd);
  /* first y-bending frequency of the continuous beam, 1.8751^2 / (2 pi) sqrt(E I / (rho A L^4)) */
  double f1 = 1.87510407 * 1.87510407 / (2 * MB_PI) * sqrt(CB_E * CB_IZ / (CB_RHO * CB_A * pow(CB_L, 4)));
  print_message("cantilever_step: damping ratio from the logarithmic decrement: damped %.5f (model 0.05, "
                "%d swings), undamped %+.2e (%d swings); periods: damped %.5g s, undamped %.5g s\n",
                zd, nd, zu, nu, Td, Tu);
  assert_true(fabs(zd - 0.05) < 0.1 * 0.05);
  assert_true(fabs(zu) < 0.1 * 0.05);
  /* The oscillation is the first y-bending mode, of the model's lowest
     frequency whose tip motion is along y (the lumped 10-element model is
     ~0.5 % below the continuous beam's f1).  Damped, its period is longer by
     1/sqrt(1 - zeta^2) = 1.00125; the undamped extremes are shifted a little
     by the higher modes that never decay, hence a looser bound there. */
  const mb_flex *fx = m->body[1].flex;
  assert_string_equal(m->body[1].name, "damped");
  double fy = 0;
  for (int j = 0; j < fx->nm && fy == 0; j++) {
    const mb_real *X = fx->node_X + 3 * (10 * fx->nm + j); /* node 10, mode j */
    if (fabs(X[1]) > fabs(X[2])) fy = sqrt(fx->stiffness[j]) / (2 * MB_PI);
  }
  print_message("cantilever_step: model's first y-bending mode %.6g Hz (continuous beam %.6g Hz); "
                "damped period x f sqrt(1 - zeta^2) = %.6f\n", fy, f1, Td * fy * sqrt(1 - 0.05 * 0.05));
  assert_true(fabs(fy / f1 - 1) < 0.01);
  assert_true(fabs(Td * fy * sqrt(1 - 0.05 * 0.05) - 1) < 1e-3);
  assert_true(fabs(Tu * fy - 1) < 0.01);
  /* undamped, it swings about the static deflection P L^3 / (3 E I): the
     mean of its extremes (an even number: as many peaks as troughs) */
  double te[512], ye[512], mean = 0;
  int n = extremes(&tr, cu, 0.0, te, ye, 512) & ~1;
  for (int i = 0; i < n; i++) mean += ye[i] / n;
  double stat = 1.0 * pow(CB_L, 3) / (3 * CB_E * CB_IZ);
  print_message("cantilever_step: undamped mean tip deflection %.5g m, static P L^3 / (3 E I) = %.5g m\n",
                -mean, stat);
  assert_true(fabs(-mean / stat - 1) < 0.02);
  trajectory_free(&tr);
}

/* the band ratio of seed 001 section 2.6 for a mode of f Hz */
static double band_ratio(double f) { return f < 100 ? 0.01 : f <= 1000 ? 0.10 : 1.0; }

/* parse the numbers after 'key' on its line of 'text' */
static int numbers_after(const char *text, const char *key, double *v, int max) {
  const char *p = strstr(text, key);
  if (!p) return -1;
  p += strlen(key);
  int n = 0;
  while (n < max) {
    char *end;
    while (*p == ' ') p++;
    if (*p == '\n' || !*p) break;
    v[n] = strtod(p, &end);
    if (end == p) break;
    n++;
    p = end;
  }
  return n;
}

/* tests/models/cantilever_bands.yaml: 'damping: bands', modes up to 2.5 kHz */
static void test_modal_damping_bands(void **state) {
  (void)state;
  const mb_model *m = &cantilever_bands_model;
  const mb_body *B = &m->body[0];
  assert_int_equal(B->kind, MB_BODY_FLEXIBLE);
  const mb_flex *fx = B->flex;
  int nm = fx->nm, inband[3] = {0, 0, 0};
  assert_true(nm >= 3);
  /* compiled tables: stiffness omega^2 (per unit modal mass Mff_jj = 1 of
     mass-normalized modes), damping 2 zeta omega sqrt(Mff_jj) */
  for (int j = 0; j < nm; j++) {
    double mjj = fx->Mff[j * nm + j], om = sqrt(fx->stiffness[j]), f = om / (2 * MB_PI);
    double zeta = fx->damping[j] / (2 * om * sqrt(mjj));
    assert_close(mjj, 1.0, 1e-9);
    assert_close(zeta, band_ratio(f), 1e-12);
    inband[f < 100 ? 0 : f <= 1000 ? 1 : 2]++;
  }
  print_message("cantilever_bands: %d modes, %d below 100 Hz (1 %%), %d to 1 kHz (10 %%), %d above (100 %%)\n",
                nm, inband[0], inband[1], inband[2]);
  assert_true(inband[0] > 0 && inband[1] > 0 && inband[2] > 0);
  /* and as `mbcc check` reports them */
  char cmd[1024], out[16384];
  snprintf(cmd, sizeof cmd, "%s check tests/models/cantilever_bands.yaml", mbcc());
  int rc = run_capture(cmd, out, sizeof out);
  if (rc) print_error("%s", out);
  assert_int_equal(rc, 0);
  double f[MB_MAX_MODES], z[MB_MAX_MODES];
  int nf = numbers_after(out, "frequencies (Hz):", f, MB_MAX_MODES);
  int nz = numbers_after(out, "damping ratios:", z, MB_MAX_MODES);
  assert_int_equal(nf, nm);
  assert_int_equal(nz, nm);
  for (int j = 0; j < nm; j++) {
    assert_close(f[j], sqrt(fx->stiffness[j]) / (2 * MB_PI), 1e-5 * f[j]);
    assert_close(z[j], band_ratio(f[j]), 1e-12);
  }
}

/* ---------------------------------------------------------------------------
 * 1e. mbcc modes
 * ------------------------------------------------------------------------- */
static void test_modes_command(void **state) {
  (void)state;
  char path[512], cmd[2048], out[16384];
  snprintf(path, sizeof path, "%s/mbcc_shapes_%d.csv", getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp",
           (int)getpid());
  remove(path);
  /* the slider-crank's rod: 8 elements (9 nodes), Craig-Bampton: 6 interface
     modes of node 8 and 4 fixed-interface normal modes */
  snprintf(cmd, sizeof cmd, "%s modes models/slider_crank_flexible.yaml --body rod --shapes '%s'", mbcc(), path);
  int rc = run_capture(cmd, out, sizeof out);
  if (rc) print_error("%s", out);
  assert_int_equal(rc, 0);
  assert_non_null(strstr(out, "flexible body 'rod': 9 nodes, 10 modes selected"));
  const char *p = strstr(out, "mode  frequency_hz\n");
  assert_non_null(p);
  p += strlen("mode  frequency_hz\n");
  for (int j = 1; j <= 10; j++) {
    int k;
    double f;
    int used;
    assert_int_equal(sscanf(p, "%d %lf%n", &k, &f, &used), 2);
    assert_int_equal(k, j);
    assert_true(f > 1 && f < 1e6);
    p += used;
  }
  /* the CSV: a header (node, x, y, z, then 6 columns per mode) and one row per node */
  FILE *fp = fopen(path, "r");
  assert_non_null(fp);
  char line[8192];
  int rows = 0, ok = 1;
  assert_non_null(fgets(line, sizeof line, fp));
  assert_true(!strncmp(line, "node,x,y,z,m1_ux,", 17));
  while (fgets(line, sizeof line, fp)) {
    int fields = 1;
    for (const char *q = line; *q; q++) fields += *q == ',';
    if (atoi(line) != rows || fields != 4 + 6 * 10) ok = 0;
    rows++;
  }
  fclose(fp);
  remove(path);
  assert_true(ok);
  assert_int_equal(rows, 9);

  /* frequencies printed agree with the compiled model's */
  snprintf(cmd, sizeof cmd, "%s modes tests/models/cantilever_gravity.yaml --body beam", mbcc());
  rc = run_capture(cmd, out, sizeof out);
  assert_int_equal(rc, 0);
  const mb_flex *fx = cantilever_gravity_model.body[0].flex;
  p = strstr(out, "mode  frequency_hz\n");
  assert_non_null(p);
  p += strlen("mode  frequency_hz\n");
  for (int j = 0; j < fx->nm; j++) {
    int k, used;
    double f;
    assert_int_equal(sscanf(p, "%d %lf%n", &k, &f, &used), 2);
    assert_close(f, sqrt(fx->stiffness[j]) / (2 * MB_PI), 1e-5 * f);
    p += used;
  }

  /* a body that is not there, a rigid body, no --body: exit status 2 */
  const char *bad[] = {"--body nosuchbody", "--body crank", ""};
  for (int i = 0; i < 3; i++) {
    snprintf(cmd, sizeof cmd, "%s modes models/slider_crank_flexible.yaml %s", mbcc(), bad[i]);
    rc = run_capture(cmd, out, sizeof out);
    if (rc != 2) print_error("%s: exit %d, output:\n%s\n", cmd, rc, out);
    assert_int_equal(rc, 2);
    assert_non_null(strstr(out, "error"));
  }
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_slider_crank_virtual_bodies),
      cmocka_unit_test(test_free_flexible_conservation),
      cmocka_unit_test(test_cantilever_gravity),
      cmocka_unit_test(test_modal_damping_decrement),
      cmocka_unit_test(test_modal_damping_bands),
      cmocka_unit_test(test_modes_command),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
