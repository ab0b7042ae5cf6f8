/* test_fe.c: the beam finite elements and the modal reduction (compiler/flex/fe.c):
 * Euler-Bernoulli convergence to the clamped-free closed form (h^4 with the
 * consistent mass, h^2 lumped), Timoshenko against Euler-Bernoulli and against
 * the simply supported Timoshenko closed form, Craig-Bampton against the full
 * FE model, mass normalization, lumped masses, axial modes, invariance under a
 * rotation of the model, the mode selection among a modal data file's modes,
 * static condensation (superelement, two and more nodes), residual attachment modes (static correction, free-interface + residual
 * against the full FE model, inertia relief on a free-free body), and the
 * errors for bad FE data. */
#include "../compiler/flex/fe.c"
#include "../compiler/flex/fe_sparse.c"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "support.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* --- model builders ---------------------------------------------------------- */

typedef struct {
  double E, G, rho, A, Iy, Iz, J, sy, sz;
} section;

/* steel, square h x h (J of a square: 0.1406 h^4) */
static section square(double h) {
  section s;
  s.E = 2.1e11;
  s.G = s.E / (2 * 1.3);
  s.rho = 7850;
  s.A = h * h;
  s.Iy = s.Iz = h * h * h * h / 12;
  s.J = 0.140577 * h * h * h * h;
  s.sy = s.sz = 5.0 / 6;
  return s;
}

static void free_flex(ir_flex *fx) {
  free(fx->nodes);
  free(fx->node_loc);
  free(fx->beams);
  free(fx->point_masses);
  free(fx->reference);
  free(fx->interface);
  free(fx->residual);
  free(fx->list);
  memset(fx, 0, sizeof *fx);
}

static void set_beam(ir_beam *b, int n0, int n1, const section *s, ir_beam_theory th, const double yaxis[3]) {
  memset(b, 0, sizeof *b);
  b->node[0] = n0;
  b->node[1] = n1;
  b->theory = th;
  b->E = s->E; b->G = s->G; b->rho = s->rho;
  b->A = s->A; b->Iy = s->Iy; b->Iz = s->Iz; b->J = s->J;
  if (th == BEAM_TIMOSHENKO) { b->shear_y = s->sy; b->shear_z = s->sz; }
  memcpy(b->yaxis, yaxis, sizeof b->yaxis);
  b->loc.line = 10 + n0;
  b->loc.col = 7;
}

static void set_reference(ir_flex *fx, int node) {
  fx->reference = malloc(sizeof(int));
  fx->reference[0] = node;
  fx->nreference = 1;
}

/* nel elements along unit direction dir from the origin, length L, clamped at node 0 */
static void line_beam(ir_flex *fx, int nel, double L, const double dir[3], const double yaxis[3],
                      const section *s, ir_beam_theory th, ir_mass_kind mk) {
  memset(fx, 0, sizeof *fx);
  fx->nnodes = nel + 1;
  fx->nodes = calloc(3 * (size_t)(nel + 1), sizeof(double));
  fx->node_loc = calloc((size_t)(nel + 1), sizeof(ir_loc));
  for (int k = 0; k <= nel; k++) {
    for (int d = 0; d < 3; d++) fx->nodes[3 * k + d] = L * k / nel * dir[d];
    fx->node_loc[k].line = 100 + k;
    fx->node_loc[k].col = 3;
  }
  fx->nbeams = nel;
  fx->beams = calloc((size_t)nel, sizeof(ir_beam));
  for (int e = 0; e < nel; e++) set_beam(&fx->beams[e], e, e + 1, s, th, yaxis);
  fx->mass = mk;
  set_reference(fx, 0);
  fx->select = MODES_ALL;
  fx->loc.line = 5;
  fx->loc.col = 3;
}

static const double ex[3] = {1, 0, 0}, ey[3] = {0, 1, 0};

/* a 3D frame: a column up z (0..1), an arm along x (0..0.8), a bent tip
 * going along y and down, with point masses; clamped at the column foot */
static void frame3d(ir_flex *fx, int per, ir_mass_kind mk, ir_beam_theory th) {
  const double corners[4][3] = {{0, 0, 0}, {0, 0, 1}, {0.8, 0, 1}, {0.8, 0.5, 0.7}};
  const double yax[3][3] = {{1, 0, 0}, {0, 0.6, 0.8}, {0.3, 0.2, 0.9}};
  int nn = 3 * per + 1;
  memset(fx, 0, sizeof *fx);
  fx->nnodes = nn;
  fx->nodes = calloc(3 * (size_t)nn, sizeof(double));
  fx->node_loc = calloc((size_t)nn, sizeof(ir_loc));
  for (int seg = 0; seg < 3; seg++)
    for (int k = 0; k <= per; k++)
      for (int d = 0; d < 3; d++)
        fx->nodes[3 * (seg * per + k) + d] =
            corners[seg][d] + (corners[seg + 1][d] - corners[seg][d]) * k / per;
  fx->nbeams = 3 * per;
  fx->beams = calloc((size_t)fx->nbeams, sizeof(ir_beam));
  section s = square(0.03);
  s.Iz *= 2; /* a rectangular-ish section: no degenerate pairs */
  s.J *= 1.4;
  for (int e = 0; e < fx->nbeams; e++) set_beam(&fx->beams[e], e, e + 1, &s, th, yax[e / per]);
  fx->npoint_masses = 2;
  fx->point_masses = calloc(2, sizeof(ir_point_mass));
  fx->point_masses[0].node = 2 * per;
  fx->point_masses[0].mass = 1.5;
  double I0[9] = {0.02, 0.001, 0, 0.001, 0.03, 0.002, 0, 0.002, 0.01};
  memcpy(fx->point_masses[0].inertia, I0, sizeof I0);
  fx->point_masses[1].node = nn - 1;
  fx->point_masses[1].mass = 0.7;
  fx->mass = mk;
  set_reference(fx, 0);
  fx->select = MODES_ALL;
}

/* --- helpers ------------------------------------------------------------------- */

static int compute(const ir_flex *fx, fe_modes *m) {
  char err[1024];
  int rc = fe_compute_modes(fx, m, err, sizeof err);
  if (rc) print_error("fe_compute_modes: %s\n", err);
  return rc;
}

/* mass-weighted fraction of mode j's kinetic energy in the DOFs flagged in mask[6] */
static double fraction(const fe_modes *m, const fe_system *s, int j, const int mask[6]) {
  int n = s->ndof;
  const double *x = m->shapes + (size_t)j * n;
  double part = 0, all = 0;
  for (int c = 0; c < n; c++)
    for (int r = 0; r < n; r++) {
      double v = x[r] * s->M[(size_t)c * n + r] * x[c];
      all += v;
      if (mask[r % 6] && mask[c % 6]) part += v;
    }
  return part / all;
}

/* the first nwant frequencies of modes with > 99 % of their energy in mask;
 * pairs: the section is square, so bending modes come in equal pairs: take one of each */
static int modes_of_kind(const fe_modes *m, const fe_system *s, const int mask[6], int pairs,
                         double *f, int nwant) {
  int k = 0, seen = 0;
  double prev = 0;
  for (int j = 0; j < m->nmodes && k < nwant; j++) {
    if (fraction(m, s, j, mask) < 0.99) continue;
    if (pairs && (seen++ % 2 == 1)) {
      assert_true(fabs(m->freq_hz[j] - prev) <= 1e-7 * prev);
      continue;
    }
    prev = f[k++] = m->freq_hz[j];
  }
  return k;
}

static const int bend_mask[6] = {0, 1, 1, 0, 1, 1};
static const int axial_mask[6] = {1, 0, 0, 0, 0, 0};

/* roots of cos x cosh x = -1, by Newton on cos x + 1/cosh x */
static double clamped_free_root(int n) {
  double x = (n - 0.5) * M_PI + (n == 1 ? 0.3 : 0);
  for (int it = 0; it < 100; it++) {
    double g = cos(x) + 1 / cosh(x), dg = -sin(x) - sinh(x) / (cosh(x) * cosh(x));
    double dx = -g / dg;
    x += dx;
    if (fabs(dx) < 1e-15 * x) break;
  }
  return x;
}

/* max |X^T M X - I| over the selected modes */
static double orthonormality(const fe_modes *m, const fe_system *s) {
  int n = s->ndof;
  double worst = 0;
  double *Mx = malloc(sizeof(double) * (size_t)n);
  for (int b = 0; b < m->nmodes; b++) {
    const double *xb = m->shapes + (size_t)b * n;
    for (int r = 0; r < n; r++) {
      double v = 0;
      for (int c = 0; c < n; c++) v += s->M[(size_t)c * n + r] * xb[c];
      Mx[r] = v;
    }
    for (int a = 0; a < m->nmodes; a++) {
      const double *xa = m->shapes + (size_t)a * n;
      double g = 0;
      for (int r = 0; r < n; r++) g += xa[r] * Mx[r];
      worst = fmax(worst, fabs(g - (a == b)));
    }
  }
  free(Mx);
  return worst;
}

/* --- 1. clamped-free Euler-Bernoulli convergence -------------------------------------- */

static void test_eb_convergence(void **state) {
  (void)state;
  const int nmesh = 5, meshes[5] = {2, 4, 8, 16, 32};
  section s = square(0.02);
  double L = 1, beta[4], exact[4];
  const double published[4] = {1.8751, 4.6941, 7.8548, 10.9955};
  for (int n = 0; n < 4; n++) {
    beta[n] = clamped_free_root(n + 1);
    assert_close(beta[n], published[n], 6e-5);
    assert_true(fabs(cos(beta[n]) * cosh(beta[n]) + 1) < 1e-9 * cosh(beta[n]));
    exact[n] = beta[n] * beta[n] / (2 * M_PI * L * L) * sqrt(s.E * s.Iz / (s.rho * s.A));
  }
  printf("clamped-free Euler-Bernoulli beam, steel, L = 1 m, 20 mm square: exact f = %.6f %.5f %.4f %.4f Hz\n",
         exact[0], exact[1], exact[2], exact[3]);
  for (int mk = 0; mk < 2; mk++) {
    ir_mass_kind kind = mk == 0 ? MASS_CONSISTENT : MASS_LUMPED;
    double err[5][4];
    printf("%s mass: relative error of f_n\n  elements        mode 1        mode 2        mode 3        mode 4\n",
           kind == MASS_CONSISTENT ? "consistent" : "lumped (HRZ)");
    for (int i = 0; i < nmesh; i++) {
      ir_flex fx;
      line_beam(&fx, meshes[i], L, ex, ey, &s, BEAM_EULER_BERNOULLI, kind);
      fe_modes m;
      fe_system sys;
      char e[512];
      assert_int_equal(compute(&fx, &m), 0);
      assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
      double f[4];
      assert_int_equal(modes_of_kind(&m, &sys, bend_mask, 1, f, 4), 4);
      printf("  %8d", meshes[i]);
      for (int n = 0; n < 4; n++) {
        err[i][n] = (f[n] - exact[n]) / exact[n];
        printf("  %12.4e", err[i][n]);
        /* consistent: Rayleigh-Ritz upper bound; lumped: from below */
        if (kind == MASS_CONSISTENT) assert_true(err[i][n] > 0);
        else assert_true(err[i][n] < 0);
        /* from the first mesh with at least n + 1 elements (mode n + 1 resolved) */
        if (i > 0 && meshes[i - 1] > n) assert_true(fabs(err[i][n]) < fabs(err[i - 1][n]));
      }
      printf("\n");
      fe_system_free(&sys);
      fe_modes_free(&m);
      free_flex(&fx);
    }
    printf("  observed order (log2 of successive error ratios), mode 1:");
    for (int i = 1; i < nmesh; i++) printf(" %.3f", log2(fabs(err[i - 1][0] / err[i][0])));
    printf("\n  observed order, mode 2:");
    for (int i = 1; i < nmesh; i++) printf(" %.3f", log2(fabs(err[i - 1][1] / err[i][1])));
    printf("\n");
    double p = log2(fabs(err[nmesh - 2][0] / err[nmesh - 1][0]));
    double p2 = log2(fabs(err[nmesh - 3][0] / err[nmesh - 2][0]));
    if (kind == MASS_CONSISTENT) {
      assert_true(p > 3.5 && p < 4.5);
      assert_true(p2 > 3.5 && p2 < 4.5);
      assert_true(fabs(err[nmesh - 1][3]) < 1e-4);
    } else {
      assert_true(p > 1.5 && p < 2.5);
      assert_true(p2 > 1.5 && p2 < 2.5);
      assert_true(fabs(err[nmesh - 1][3]) < 2e-2);
    }
  }
}

/* --- 2. Timoshenko ---------------------------------------------------------------------- */

static double first_bending(double slenderness, ir_beam_theory th, ir_mass_kind mk, double *f4) {
  double L = 1;
  section s = square(L / slenderness);
  ir_flex fx;
  line_beam(&fx, 24, L, ex, ey, &s, th, mk);
  fe_modes m;
  fe_system sys;
  char e[512];
  assert_int_equal(compute(&fx, &m), 0);
  assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
  assert_int_equal(modes_of_kind(&m, &sys, bend_mask, 1, f4, 4), 4);
  fe_system_free(&sys);
  fe_modes_free(&m);
  free_flex(&fx);
  return f4[0];
}

static void test_timoshenko_vs_eb(void **state) {
  (void)state;
  for (int mk = 0; mk < 2; mk++) {
    ir_mass_kind kind = mk ? MASS_LUMPED : MASS_CONSISTENT;
    double fe[4], ft[4];
    first_bending(5, BEAM_EULER_BERNOULLI, kind, fe);
    first_bending(5, BEAM_TIMOSHENKO, kind, ft);
    printf("%s, L/h = 5:   f_T/f_EB - 1 =", kind == MASS_LUMPED ? "lumped    " : "consistent");
    for (int n = 0; n < 4; n++) {
      printf(" %.4f", ft[n] / fe[n] - 1);
      assert_true(ft[n] < fe[n]);
    }
    assert_true(ft[0] / fe[0] - 1 < -0.005);
    first_bending(100, BEAM_EULER_BERNOULLI, kind, fe);
    first_bending(100, BEAM_TIMOSHENKO, kind, ft);
    printf("\n%s, L/h = 100: f_T/f_EB - 1 =", kind == MASS_LUMPED ? "lumped    " : "consistent");
    for (int n = 0; n < 4; n++) printf(" %.2e", ft[n] / fe[n] - 1);
    printf("\n");
    assert_true(ft[0] < fe[0]);
    assert_true(fabs(ft[0] / fe[0] - 1) < 1e-3);
  }
}

/* the first nwant bending frequencies of a simply supported beam (pinned at
 * node 0: ux uy uz rx fixed; roller at the last node: uy uz fixed), from
 * fe_assemble and the eigensolver directly */
static void simply_supported(int nel, double L, const section *s, ir_beam_theory th, double *fb, int nwant) {
  ir_flex fx;
  line_beam(&fx, nel, L, ex, ey, s, th, MASS_CONSISTENT);
  fe_system sys;
  char e[512];
  assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
  int n = sys.ndof, *fr = malloc(sizeof(int) * (size_t)n), nf = 0;
  for (int d = 0; d < n; d++) {
    int node = d / 6, c = d % 6;
    if (node == 0 && c < 4) continue;
    if (node == nel && (c == 1 || c == 2)) continue;
    fr[nf++] = d;
  }
  double *K = malloc(sizeof(double) * (size_t)nf * nf), *M = malloc(sizeof(double) * (size_t)nf * nf);
  double *X = malloc(sizeof(double) * (size_t)nf * nf), *w = malloc(sizeof(double) * (size_t)nf);
  gather(sys.K, n, fr, nf, fr, nf, K);
  gather(sys.M, n, fr, nf, fr, nf, M);
  int bad = 0;
  assert_int_equal(gen_eig(nf, K, M, w, X, &bad), 0);
  /* bending modes: energy in (uy, uz, ry, rz); square section: pairs */
  int k = 0, seen = 0;
  for (int j = 0; j < nf && k < nwant; j++) {
    double part = 0, all = 0;
    for (int c = 0; c < nf; c++)
      for (int r = 0; r < nf; r++) {
        double v = X[(size_t)j * nf + r] * M[(size_t)c * nf + r] * X[(size_t)j * nf + c];
        all += v;
        if (bend_mask[fr[r] % 6] && bend_mask[fr[c] % 6]) part += v;
      }
    if (part / all < 0.99) continue;
    if (seen++ % 2) continue;
    fb[k++] = sqrt(w[j]) / (2 * M_PI);
  }
  assert_int_equal(k, nwant);
  free(fr); free(K); free(M); free(X); free(w);
  fe_system_free(&sys);
  free_flex(&fx);
}

/* simply supported stubby Timoshenko beam against the closed form
 * rho^2 I/(k G) w^4 - (rho A + rho I k_n^2 (1 + E/(k G))) w^2 + E I k_n^4 = 0:
 * upper bounds converging like h^2 (the element's shear strain is constant,
 * the mode's is not), to 1e-4 with 40 elements */
static void test_timoshenko_simply_supported(void **state) {
  (void)state;
  double L = 1;
  section s = square(0.2);
  double f20[3], f40[3];
  simply_supported(20, L, &s, BEAM_TIMOSHENKO, f20, 3);
  simply_supported(40, L, &s, BEAM_TIMOSHENKO, f40, 3);
  double kG = s.G * s.sy;
  printf("simply supported Timoshenko beam, L/h = 5, consistent mass:\n"
         "  n  f_exact (Hz)  error, 20 el.  error, 40 el.  order   f_EB/f_exact - 1\n");
  for (int i = 0; i < 3; i++) {
    double kn = (i + 1) * M_PI / L;
    double a = s.rho * s.rho * s.Iz / kG, b = s.rho * s.A + s.rho * s.Iz * kn * kn * (1 + s.E / kG),
           c = s.E * s.Iz * kn * kn * kn * kn;
    double w2 = (b - sqrt(b * b - 4 * a * c)) / (2 * a), fex = sqrt(w2) / (2 * M_PI);
    double feb = kn * kn / (2 * M_PI) * sqrt(s.E * s.Iz / (s.rho * s.A));
    double e20 = f20[i] / fex - 1, e40 = f40[i] / fex - 1, p = log2(e20 / e40);
    printf("  %d  %12.5f  %12.3e  %12.3e  %6.3f  %8.4f\n", i + 1, fex, e20, e40, p, feb / fex - 1);
    assert_true(e40 > 0 && e20 > e40);
    assert_true(p > 1.8 && p < 2.2);
    assert_true(e40 < 1e-3);
    if (i == 0) assert_true(e40 < 1e-4);
  }
}

/* --- 3. Craig-Bampton --------------------------------------------------------------------- */

static void test_craig_bampton(void **state) {
  (void)state;
  for (int mk = 0; mk < 2; mk++) {
    ir_flex fx;
    frame3d(&fx, 4, mk ? MASS_LUMPED : MASS_CONSISTENT, mk ? BEAM_TIMOSHENKO : BEAM_EULER_BERNOULLI);
    fe_modes full;
    assert_int_equal(compute(&fx, &full), 0);
    int nf = 6 * (fx.nnodes - 1);
    assert_int_equal(full.nmodes, nf);
    fx.ninterface = 3;
    fx.interface = malloc(3 * sizeof(int));
    fx.interface[0] = 4;
    fx.interface[1] = fx.nnodes - 1;
    fx.interface[2] = 0; /* a reference node: ignored */
    int nb = 12, ni = nf - nb;
    /* all fixed-interface modes: the full FE frequencies */
    fe_modes cb;
    assert_int_equal(compute(&fx, &cb), 0);
    assert_int_equal(cb.nmodes, nf);
    assert_int_equal(cb.nall, ni);
    for (int j = 0; j < nf; j++) assert_true(fabs(cb.freq_hz[j] / full.freq_hz[j] - 1) < 1e-8);
    fe_system sys;
    char e[512];
    assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
    assert_true(orthonormality(&cb, &sys) < 1e-10);
    fe_modes_free(&cb);
    /* truncated: from above, decreasing as fixed-interface modes are added */
    double *prev = calloc((size_t)nf, sizeof(double));
    fx.select = MODES_COUNT;
    printf("Craig-Bampton (%s), 12 interface DOFs: f_1..f_4 against fixed-interface modes kept\n",
           mk ? "lumped, Timoshenko" : "consistent, Euler-Bernoulli");
    for (int k = 0; k <= ni; k++) {
      fx.count = k;
      assert_int_equal(compute(&fx, &cb), 0);
      assert_int_equal(cb.nmodes, nb + k);
      if (k % 8 == 0 || k == ni) printf("  %3d: %.6f %.6f %.6f %.6f Hz\n", k, cb.freq_hz[0], cb.freq_hz[1],
                                        cb.freq_hz[2], cb.freq_hz[3]);
      for (int j = 0; j < cb.nmodes; j++) {
        assert_true(cb.freq_hz[j] >= full.freq_hz[j] * (1 - 1e-10));
        if (k > 0 && j < nb + k - 1) assert_true(cb.freq_hz[j] <= prev[j] * (1 + 1e-10));
        prev[j] = cb.freq_hz[j];
      }
      if (k == 6) assert_true(orthonormality(&cb, &sys) < 1e-10);
      fe_modes_free(&cb);
    }
    printf("  full FE:    %.6f %.6f %.6f %.6f Hz\n", full.freq_hz[0], full.freq_hz[1], full.freq_hz[2],
           full.freq_hz[3]);
    /* max frequency and list select fixed-interface modes */
    fx.select = MODES_MAX_FREQUENCY;
    fe_modes cbf;
    assert_int_equal(compute(&fx, &cbf), 0);
    fx.max_frequency = cbf.all_freq_hz[4] * 1.0000001;
    fe_modes_free(&cbf);
    assert_int_equal(compute(&fx, &cbf), 0);
    assert_int_equal(cbf.nmodes, nb + 5);
    fe_modes_free(&cbf);
    free(prev);
    fe_system_free(&sys);
    fe_modes_free(&full);
    free_flex(&fx);
  }
}

/* --- 4. normalization, lumped masses, axial modes, rotation invariance ------------------------ */

static void test_normalization_and_masses(void **state) {
  (void)state;
  for (int mk = 0; mk < 2; mk++)
    for (int th = 0; th < 2; th++) {
      ir_flex fx;
      frame3d(&fx, 5, mk ? MASS_LUMPED : MASS_CONSISTENT, th ? BEAM_TIMOSHENKO : BEAM_EULER_BERNOULLI);
      fe_modes m;
      fe_system sys;
      char e[512];
      assert_int_equal(compute(&fx, &m), 0);
      assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
      assert_true(orthonormality(&m, &sys) < 1e-10);
      for (int j = 1; j < m.nmodes; j++) assert_true(m.freq_hz[j] >= m.freq_hz[j - 1]);
      assert_true(m.freq_hz[0] > 0);
      /* X^T K X = diag(omega^2) */
      int n = sys.ndof;
      for (int j = 0; j < 5; j++) {
        const double *x = m.shapes + (size_t)j * n;
        double q = 0;
        for (int c = 0; c < n; c++)
          for (int r = 0; r < n; r++) q += x[r] * sys.K[(size_t)c * n + r] * x[c];
        double om = 2 * M_PI * m.freq_hz[j];
        assert_true(fabs(q / (om * om) - 1) < 1e-9);
      }
      /* reference node rows are zero; sign convention */
      for (int j = 0; j < m.nmodes; j++) {
        const double *x = m.shapes + (size_t)j * n;
        double big = 0;
        int at = 0;
        for (int d = 0; d < 6; d++) assert_true(x[d] == 0);
        for (int r = 0; r < n; r++)
          if (fabs(x[r]) > big * (1 + 1e-8)) { big = fabs(x[r]); at = r; }
        assert_true(x[at] > 0);
      }
      /* lumped masses: beams + point masses; positions copied */
      double total = 0, want = 1.5 + 0.7;
      for (int b = 0; b < fx.nbeams; b++) {
        const ir_beam *bm = &fx.beams[b];
        const double *p0 = fx.nodes + 3 * bm->node[0], *p1 = fx.nodes + 3 * bm->node[1];
        double L = sqrt((p1[0] - p0[0]) * (p1[0] - p0[0]) + (p1[1] - p0[1]) * (p1[1] - p0[1]) +
                        (p1[2] - p0[2]) * (p1[2] - p0[2]));
        want += bm->rho * bm->A * L;
      }
      for (int k = 0; k < m.nnodes; k++) {
        total += m.node_mass[k];
        for (int d = 0; d < 3; d++) assert_true(m.x[3 * k + d] == fx.nodes[3 * k + d]);
        const double *J = m.node_inertia + 9 * k;
        assert_true(J[0] > 0 && J[4] > 0 && J[8] > 0);
        assert_true(J[1] == J[3] && J[2] == J[6] && J[5] == J[7]);
      }
      assert_true(fabs(total / want - 1) < 1e-13);
      /* the lumped M is exactly diag(node_mass) + node_inertia blocks */
      if (mk) {
        for (int k = 0; k < m.nnodes; k++)
          for (int i = 0; i < 3; i++) {
            assert_true(sys.M[(size_t)(6 * k + i) * n + 6 * k + i] == m.node_mass[k]);
            for (int j = 0; j < 3; j++)
              assert_true(sys.M[(size_t)(6 * k + 3 + j) * n + 6 * k + 3 + i] == m.node_inertia[9 * k + 3 * i + j]);
          }
      }
      fe_system_free(&sys);
      fe_modes_free(&m);
      free_flex(&fx);
    }
  /* HRZ values of one Euler-Bernoulli element: rho A L / 2, rho A L^3 / 78, rho Ip L / 2 */
  {
    ir_flex fx;
    section s = square(0.05);
    s.Iz = 2 * s.Iy;
    line_beam(&fx, 1, 0.7, ex, ey, &s, BEAM_EULER_BERNOULLI, MASS_LUMPED);
    double nm[2], ni[18];
    char e[256];
    assert_int_equal(fe_lumped_nodes(&fx, nm, ni, e, sizeof e, NULL), 0);
    double m = s.rho * s.A * 0.7;
    assert_close(nm[1], m / 2, 1e-14 * m);
    assert_close(ni[9 + 0], s.rho * (s.Iy + s.Iz) * 0.7 / 2, 1e-14 * m);
    assert_close(ni[9 + 4], m * 0.49 / 78, 1e-14 * m);
    assert_close(ni[9 + 8], m * 0.49 / 78, 1e-14 * m);
    free_flex(&fx);
  }
  /* axial modes of a clamped-free bar: f = (2n-1)/(4L) sqrt(E/rho); consistent
     mass from above, lumped from below */
  double L = 2;
  section s = square(0.05);
  for (int n = 1; n <= 2; n++) {
    double fex = (2 * n - 1) / (4 * L) * sqrt(s.E / s.rho), f[2][2];
    for (int mk = 0; mk < 2; mk++) {
      ir_flex fx;
      line_beam(&fx, 64, L, ex, ey, &s, BEAM_EULER_BERNOULLI, mk ? MASS_LUMPED : MASS_CONSISTENT);
      fe_modes m;
      fe_system sys;
      char e[512];
      assert_int_equal(compute(&fx, &m), 0);
      assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
      assert_int_equal(modes_of_kind(&m, &sys, axial_mask, 0, f[mk], 2), 2);
      fe_system_free(&sys);
      fe_modes_free(&m);
      free_flex(&fx);
    }
    printf("axial mode %d of a clamped-free bar, 64 elements: exact %.4f Hz, consistent %+.2e, lumped %+.2e\n",
           n, fex, f[0][n - 1] / fex - 1, f[1][n - 1] / fex - 1);
    assert_true(f[0][n - 1] > fex && f[1][n - 1] < fex);
    assert_true(fabs(f[0][n - 1] / fex - 1) < 1e-3 && fabs(f[1][n - 1] / fex - 1) < 1e-3);
  }
  /* the same beam along an oblique direction (yaxis rotated with it) has the same frequencies */
  {
    section r = square(0.02);
    r.Iz = 3 * r.Iy;
    double d[3] = {0.48, -0.6, 0.64}; /* unit */
    double y[3] = {0.8, 0.6, 0};      /* perpendicular to d, not unit */
    for (int mk = 0; mk < 2; mk++) {
      ir_flex a, b;
      const double zx[3] = {0, 0, 1};
      double yd[3] = {y[0] * 2, y[1] * 2, y[2] * 2};
      line_beam(&a, 6, 1.3, ex, ey, &r, mk ? BEAM_TIMOSHENKO : BEAM_EULER_BERNOULLI, mk ? MASS_LUMPED : MASS_CONSISTENT);
      line_beam(&b, 6, 1.3, d, yd, &r, mk ? BEAM_TIMOSHENKO : BEAM_EULER_BERNOULLI, mk ? MASS_LUMPED : MASS_CONSISTENT);
      (void)zx;
      /* a yaxis with a component along the element is orthogonalized */
      for (int e = 0; e < b.nbeams; e++)
        for (int k = 0; k < 3; k++) b.beams[e].yaxis[k] += 0.3 * d[k];
      fe_modes ma, mb;
      assert_int_equal(compute(&a, &ma), 0);
      assert_int_equal(compute(&b, &mb), 0);
      assert_int_equal(ma.nmodes, mb.nmodes);
      for (int j = 0; j < ma.nmodes; j++) assert_true(fabs(mb.freq_hz[j] / ma.freq_hz[j] - 1) < 1e-9);
      fe_modes_free(&ma);
      fe_modes_free(&mb);
      free_flex(&a);
      free_flex(&b);
    }
  }
}

/* --- 5. modal data file ------------------------------------------------------------------------ */

/* The front end reads and checks the file (compiler/front/modal_file.c;
 * its errors: tests/bad_models/1NN_modal_NAME.yaml; the written file read back:
 * tests/test_modal_file.sh); fe.c takes its modes as given and selects among
 * them. */
static void test_modal_file(void **state) {
  (void)state;
  ir_flex fx;
  frame3d(&fx, 3, MASS_LUMPED, BEAM_TIMOSHENKO);
  fe_modes m;
  assert_int_equal(compute(&fx, &m), 0);
  ir_modal_data md = {m.nnodes, m.nmodes, m.x, m.node_mass, m.node_inertia, m.freq_hz, m.shapes};
  ir_flex rf;
  memset(&rf, 0, sizeof rf);
  rf.modal_file = "frame.modal";
  rf.modal = &md;
  rf.select = MODES_ALL;
  fe_modes r;
  assert_int_equal(compute(&rf, &r), 0);
  assert_int_equal(r.nnodes, m.nnodes);
  assert_int_equal(r.nmodes, m.nmodes);
  assert_int_equal(r.nall, m.nmodes);
  for (int k = 0; k < m.nnodes; k++) {
    assert_true(r.node_mass[k] == m.node_mass[k]);
    for (int i = 0; i < 3; i++) assert_true(r.x[3 * k + i] == m.x[3 * k + i]);
    for (int i = 0; i < 9; i++) assert_true(r.node_inertia[9 * k + i] == m.node_inertia[9 * k + i]);
  }
  for (int j = 0; j < m.nmodes; j++) {
    assert_true(r.freq_hz[j] == m.freq_hz[j] && r.all_freq_hz[j] == m.freq_hz[j]);
    for (int i = 0; i < 6 * m.nnodes; i++)
      assert_true(r.shapes[(size_t)j * 6 * m.nnodes + i] == m.shapes[(size_t)j * 6 * m.nnodes + i]);
  }
  fe_modes_free(&r);
  /* selection applies to the file's modes */
  rf.select = MODES_LIST;
  int list[3] = {5, 2, 9};
  rf.list = list;
  rf.nlist = 3;
  assert_int_equal(compute(&rf, &r), 0);
  assert_int_equal(r.nmodes, 3);
  assert_true(r.freq_hz[0] == m.freq_hz[1] && r.freq_hz[1] == m.freq_hz[4] && r.freq_hz[2] == m.freq_hz[8]);
  assert_true(r.shapes[6 * m.nnodes - 1] == m.shapes[(size_t)1 * 6 * m.nnodes + 6 * m.nnodes - 1]);
  assert_true(r.shapes[(size_t)3 * 6 * m.nnodes - 1] == m.shapes[(size_t)9 * 6 * m.nnodes - 1]);
  assert_int_equal(r.nall, m.nmodes);
  fe_modes_free(&r);
  rf.select = MODES_MAX_FREQUENCY;
  rf.max_frequency = m.freq_hz[3];
  assert_int_equal(compute(&rf, &r), 0);
  assert_int_equal(r.nmodes, 4);
  fe_modes_free(&r);
  char err[1024];
  rf.select = MODES_COUNT;
  rf.count = m.nmodes + 1;
  assert_int_not_equal(fe_compute_modes(&rf, &r, err, sizeof err), 0);
  assert_non_null(strstr(err, "exceeds"));
  assert_null(r.shapes);
  /* a file named but not read (the front end reports why): no modes */
  rf.modal = NULL;
  rf.select = MODES_ALL;
  assert_int_not_equal(fe_compute_modes(&rf, &r, err, sizeof err), 0);
  assert_non_null(strstr(err, "was not read"));
  fe_modes_free(&m);
  free_flex(&fx);
}

/* --- 6. errors in the FE data ----------------------------------------------------------------------- */

static void expect_fe_error(ir_flex *fx, const char *msg, int line) {
  fe_modes m;
  char err[1024];
  ir_loc where = {0, 0};
  int rc = fe_compute_modes_at(fx, &m, err, sizeof err, &where);
  if (rc == 0 || !strstr(err, msg) || (line && where.line != line)) {
    print_error("rc %d, message: %s, line %d\n(expected '%s' at line %d)\n", rc, rc ? err : "-", where.line, msg, line);
    fail();
  }
  assert_null(m.freq_hz);
}

static void test_errors(void **state) {
  (void)state;
  section s = square(0.02);
  ir_flex fx;
  line_beam(&fx, 4, 1, ex, ey, &s, BEAM_EULER_BERNOULLI, MASS_CONSISTENT);
  fx.beams[2].E = 0;
  expect_fe_error(&fx, "beam 2: Young's modulus E must be positive", 12);
  fx.beams[2].E = s.E;
  fx.beams[1].rho = -1;
  expect_fe_error(&fx, "density rho must be positive", 11);
  fx.beams[1].rho = s.rho;
  fx.beams[3].A = 0;
  expect_fe_error(&fx, "area A must be positive", 13);
  fx.beams[3].A = s.A;
  fx.beams[0].yaxis[0] = 2; fx.beams[0].yaxis[1] = 0;
  expect_fe_error(&fx, "is parallel to the element", 10);
  fx.beams[0].yaxis[0] = 0; fx.beams[0].yaxis[1] = 1;
  fx.beams[1].theory = BEAM_TIMOSHENKO;
  expect_fe_error(&fx, "positive shear area ratios", 11);
  fx.beams[1].theory = BEAM_EULER_BERNOULLI;
  double save = fx.nodes[3 * 2];
  fx.nodes[3 * 2] = fx.nodes[3 * 1];
  expect_fe_error(&fx, "zero-length element", 11);
  fx.nodes[3 * 2] = save;
  fx.nreference = 0;
  expect_fe_error(&fx, "at least one reference node", 5);
  fx.nreference = 1;
  /* a mechanism: the last beam detached (its end nodes held by nothing) */
  fx.beams[3].node[0] = 4; fx.beams[3].node[1] = 3;
  fx.nbeams = 3;
  expect_fe_error(&fx, "node 4 is not connected to any beam", 104);
  fx.nbeams = 4;
  /* a free-floating part: beam 1 from node 1 moved off to connect only 2-3-4 */
  fx.beams[1].node[0] = 2; fx.beams[1].node[1] = 3;
  fx.beams[2].node[0] = 3; fx.beams[2].node[1] = 4;
  fx.beams[3].node[0] = 2; fx.beams[3].node[1] = 4;
  expect_fe_error(&fx, "not connected through beams to any reference node", 102);
  for (int e = 0; e < 4; e++) { fx.beams[e].node[0] = e; fx.beams[e].node[1] = e + 1; }
  /* a point mass with a bad node, a mode count too large, a bad list */
  fx.npoint_masses = 1;
  fx.point_masses = calloc(1, sizeof(ir_point_mass));
  fx.point_masses[0].node = 9;
  fx.point_masses[0].loc.line = 77;
  expect_fe_error(&fx, "point mass 0: node 9 out of range", 77);
  fx.point_masses[0].node = 4;
  fx.select = MODES_COUNT;
  fx.count = 25;
  expect_fe_error(&fx, "mode count 25 exceeds the 24 constrained normal modes", 5);
  fx.count = 0;
  fe_modes m0;
  assert_int_equal(compute(&fx, &m0), 0);
  assert_int_equal(m0.nmodes, 0);
  assert_int_equal(m0.nall, 24);
  fe_modes_free(&m0);
  fx.select = MODES_LIST;
  fx.list = malloc(2 * sizeof(int));
  fx.list[0] = 3; fx.list[1] = 3;
  fx.nlist = 2;
  expect_fe_error(&fx, "mode number 3 is listed twice", 5);
  fx.list[1] = 0;
  expect_fe_error(&fx, "mode number 0 out of range", 5);
  fx.list[1] = 24;
  fe_modes m;
  assert_int_equal(compute(&fx, &m), 0);
  assert_int_equal(m.nmodes, 2);
  assert_int_equal(m.nall, 24);
  assert_true(m.freq_hz[0] == m.all_freq_hz[2] && m.freq_hz[1] == m.all_freq_hz[23]);
  fe_modes_free(&m);
  /* every node a reference node: a rigid body, no modes */
  fx.select = MODES_ALL;
  free(fx.reference);
  fx.reference = malloc(5 * sizeof(int));
  for (int k = 0; k < 5; k++) fx.reference[k] = k;
  fx.nreference = 5;
  assert_int_equal(compute(&fx, &m), 0);
  assert_int_equal(m.nmodes, 0);
  assert_true(m.node_mass[2] > 0);
  fe_modes_free(&m);
  free_flex(&fx);
}

/* --- residual attachment modes ------------------------------------------------------- */

/* sum over the modes of x_j(a) x_j(b) / lambda_j: the modal model's static
 * flexibility between DOFs a and b (full DOF numbering) */
static double modal_flexibility(const fe_modes *m, int a, int b) {
  int n = 6 * m->nnodes;
  double g = 0;
  for (int j = 0; j < m->nmodes; j++) {
    double lam = pow(2 * M_PI * m->freq_hz[j], 2);
    g += m->shapes[(size_t)j * n + a] * m->shapes[(size_t)j * n + b] / lam;
  }
  return g;
}

/* the lowest frequency (Hz) of the modal model with a grounded spring ks on DOF a */
static double spring_frequency(const fe_modes *m, int a, double ks) {
  int n = 6 * m->nnodes, k = m->nmodes, bad = -1;
  double *K = calloc((size_t)k * k, sizeof(double)), *M = calloc((size_t)k * k, sizeof(double));
  double *w = calloc((size_t)k, sizeof(double)), *Y = calloc((size_t)k * k, sizeof(double));
  for (int j = 0; j < k; j++) {
    M[(size_t)j * k + j] = 1;
    K[(size_t)j * k + j] = pow(2 * M_PI * m->freq_hz[j], 2);
    for (int i = 0; i < k; i++)
      K[(size_t)j * k + i] += ks * m->shapes[(size_t)i * n + a] * m->shapes[(size_t)j * n + a];
  }
  assert_int_equal(gen_eig(k, K, M, w, Y, &bad), 0);
  double f = sqrt(w[0]) / (2 * M_PI);
  free(K); free(M); free(w); free(Y);
  return f;
}

static void test_residual_modes(void **state) {
  (void)state;
  const int nel = 16;
  const double L = 1.2;
  section s = square(0.02);
  s.Iy = 100 * s.Iz; /* bending in z far stiffer: the lowest modes bend in y */
  ir_flex fx;
  line_beam(&fx, nel, L, ex, ey, &s, BEAM_EULER_BERNOULLI, MASS_CONSISTENT);
  int tip_y = 6 * nel + 1;
  double exact = L * L * L / (3 * s.E * s.Iz); /* PL^3/3EI per unit tip load */
  /* the reference: every mode of the FE model, with the tip spring */
  double ks = 5 * 3 * s.E * s.Iz / (L * L * L);
  fe_modes full;
  assert_int_equal(compute(&fx, &full), 0);
  double f_exact = spring_frequency(&full, tip_y, ks);
  assert_true(fabs(modal_flexibility(&full, tip_y, tip_y) / exact - 1) < 1e-9);
  fe_modes_free(&full);
  fx.select = MODES_COUNT;
  printf("cantilever, unit tip load: tip deflection error / first frequency error with a tip spring,\n"
         "against the number of normal modes kept (alone | with the 6 residual modes of the tip)\n");
  double prev_alone = INFINITY;
  for (int k = 1; k <= 5; k++) {
    fx.count = k;
    fx.nresidual = 0;
    fe_modes alone, corr;
    assert_int_equal(compute(&fx, &alone), 0);
    fx.residual = realloc(fx.residual, sizeof(int));
    fx.residual[0] = nel;
    fx.nresidual = 1;
    assert_int_equal(compute(&fx, &corr), 0);
    double ea = fabs(modal_flexibility(&alone, tip_y, tip_y) / exact - 1);
    double ec = fabs(modal_flexibility(&corr, tip_y, tip_y) / exact - 1);
    double fa = fabs(spring_frequency(&alone, tip_y, ks) / f_exact - 1);
    double fc = fabs(spring_frequency(&corr, tip_y, ks) / f_exact - 1);
    printf("  %d modes: deflection %.3e | %.3e   frequency %.3e | %.3e\n", k, ea, ec, fa, fc);
    /* static correction: the tip load's deflection is exact whatever k */
    assert_true(ec < 1e-8);
    assert_true(ea > 1e-4 && ea <= prev_alone * (1 + 1e-9));
    prev_alone = ea;
    /* free-interface + residual: the coupled frequency from above, and far closer */
    assert_true(fc < fa / 10);
    assert_true(spring_frequency(&corr, tip_y, ks) >= f_exact * (1 - 1e-10));
    /* the kept modes unchanged, the set mass-orthonormal, frequencies ascending */
    fe_system sys;
    char e[512];
    assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
    assert_true(orthonormality(&corr, &sys) < 1e-9);
    fe_system_free(&sys);
    assert_true(corr.nmodes > k && corr.nmodes <= k + 6);
    for (int j = 1; j < corr.nmodes; j++) assert_true(corr.freq_hz[j] >= corr.freq_hz[j - 1]);
    for (int j = 0; j < k; j++) assert_true(fabs(corr.freq_hz[j] / alone.freq_hz[j] - 1) < 1e-12);
    fe_modes_free(&alone);
    fe_modes_free(&corr);
  }
  /* all modes kept: nothing residual is left */
  fx.select = MODES_ALL;
  fe_modes allm;
  assert_int_equal(compute(&fx, &allm), 0);
  assert_int_equal(allm.nmodes, 6 * nel);
  fe_modes_free(&allm);

  /* inertia relief on a free-free body: the elastic flexibility of a tip load
     equals the sum over every elastic mode; the residual modes stay in mean axes */
  free(fx.reference);
  fx.reference = NULL;
  fx.nreference = 0;
  fx.reference_kind = REFERENCE_FREE;
  fx.nresidual = 0;
  fe_modes ff;
  assert_int_equal(compute(&fx, &ff), 0);
  double ge = modal_flexibility(&ff, tip_y, tip_y), ge_mid = modal_flexibility(&ff, tip_y, 6 * (nel / 2) + 1);
  fe_modes_free(&ff);
  fx.select = MODES_COUNT;
  fx.count = 2;
  fx.nresidual = 1;
  fe_modes fr, fa2;
  assert_int_equal(compute(&fx, &fr), 0);
  fx.nresidual = 0;
  assert_int_equal(compute(&fx, &fa2), 0);
  double er = fabs(modal_flexibility(&fr, tip_y, tip_y) / ge - 1);
  double ea2 = fabs(modal_flexibility(&fa2, tip_y, tip_y) / ge - 1);
  double em = fabs(modal_flexibility(&fr, tip_y, 6 * (nel / 2) + 1) / ge_mid - 1);
  printf("free-free, inertia relief: tip flexibility error with 2 modes %.3e, with residual modes %.3e "
         "(tip to middle %.3e)\n", ea2, er, em);
  assert_true(er < 1e-8 && em < 1e-8 && ea2 > 1e-3);
  fe_system sys;
  char e[512];
  assert_int_equal(fe_assemble(&fx, &sys, e, sizeof e), 0);
  assert_true(orthonormality(&fr, &sys) < 1e-9);
  /* mean axes: no momentum, sum M x = 0 in each translation */
  int n = sys.ndof;
  for (int j = 0; j < fr.nmodes; j++)
    for (int a = 0; a < 3; a++) {
      double p = 0, scale = 0;
      for (int r = 0; r < n; r++)
        for (int cc = 0; cc < n; cc++) {
          double v = sys.M[(size_t)cc * n + r] * fr.shapes[(size_t)j * n + r];
          if (cc % 6 == a) p += v;
          scale += fabs(v);
        }
      assert_true(fabs(p) <= 1e-9 * scale);
    }
  fe_system_free(&sys);
  fe_modes_free(&fr);
  fe_modes_free(&fa2);
  free_flex(&fx);
}

/* --- superelement: static condensation ---------------------------------------------- */

/* fe_condense_nodes with three loaded nodes (listed out of order) against the
 * Schur complement K_BB - K_Bi K_ii^-1 K_iB of the assembled K, node 0
 * clamped, B the loaded nodes' 18 DOFs in their order */
static void test_condense_nodes(void **state) {
  (void)state;
  ir_flex fx;
  frame3d(&fx, 3, MASS_CONSISTENT, BEAM_TIMOSHENKO);
  int nn = fx.nnodes, n = 6 * nn;
  const int loaded[3] = {nn - 1, 3, 6};
  int nb = 18, ni = n - 6 - nb;
  double *Kc = calloc((size_t)nb * nb, sizeof(double));
  char err[512];
  ir_loc where;
  assert_int_equal(fe_condense_nodes(&fx, 0, loaded, 3, Kc, err, sizeof err, &where), 0);
  fe_system sys;
  assert_int_equal(fe_assemble(&fx, &sys, err, sizeof err), 0);
  int *bdof = malloc((size_t)nb * sizeof(int)), *idof = malloc((size_t)ni * sizeof(int)), m = 0;
  for (int a = 0; a < 3; a++)
    for (int d = 0; d < 6; d++) bdof[6 * a + d] = 6 * loaded[a] + d;
  for (int k = 1; k < nn; k++)
    if (k != loaded[0] && k != loaded[1] && k != loaded[2])
      for (int d = 0; d < 6; d++) idof[m++] = 6 * k + d;
  assert_int_equal(m, ni);
  double *Kii = malloc((size_t)ni * ni * sizeof(double)), *KiB = malloc((size_t)ni * nb * sizeof(double));
  for (int j = 0; j < ni; j++)
    for (int i = 0; i < ni; i++) Kii[(size_t)j * ni + i] = sys.K[(size_t)idof[j] * n + idof[i]];
  for (int j = 0; j < nb; j++)
    for (int i = 0; i < ni; i++) KiB[(size_t)j * ni + i] = sys.K[(size_t)bdof[j] * n + idof[i]];
  double *X = malloc((size_t)ni * nb * sizeof(double));
  memcpy(X, KiB, (size_t)ni * nb * sizeof(double));
  int info = 0;
  dpotrf_("U", &ni, Kii, &ni, &info);
  assert_int_equal(info, 0);
  dpotrs_("U", &ni, &nb, Kii, &ni, X, &ni, &info);
  assert_int_equal(info, 0);
  double worst = 0, big = 0;
  for (int a = 0; a < nb; a++)
    for (int b = 0; b < nb; b++) {
      double v = sys.K[(size_t)bdof[b] * n + bdof[a]];
      for (int i = 0; i < ni; i++) v -= KiB[(size_t)a * ni + i] * X[(size_t)b * ni + i];
      worst = fmax(worst, fabs(v - Kc[nb * a + b]));
      big = fmax(big, fabs(v));
    }
  printf("superelement, three loaded nodes: condensed K against the Schur complement: %.2e relative\n",
         worst / big);
  assert_true(worst <= 1e-9 * big);
  /* the same node twice, or the clamped node loaded: errors */
  const int twice[3] = {3, 6, 3}, clamped[2] = {3, 0};
  assert_int_not_equal(fe_condense_nodes(&fx, 0, twice, 3, Kc, err, sizeof err, &where), 0);
  assert_int_not_equal(fe_condense_nodes(&fx, 0, clamped, 2, Kc, err, sizeof err, &where), 0);
  free(Kii); free(KiB); free(X); free(bdof); free(idof); free(Kc);
  fe_system_free(&sys);
  free_flex(&fx);
}

/* fe_condense against the Schur complement K_BB - K_Bi K_ii^-1 K_iB of the
 * assembled K (node 0 clamped, B the last node), on the 3D frame; and a
 * straight cantilever's condensed K against the closed-form beam stiffness */
static void test_condense(void **state) {
  (void)state;
  ir_flex fx;
  frame3d(&fx, 3, MASS_CONSISTENT, BEAM_TIMOSHENKO);
  int nn = fx.nnodes, B = nn - 1, n = 6 * nn;
  double K6[36];
  char err[512];
  ir_loc where;
  assert_int_equal(fe_condense(&fx, 0, B, K6, err, sizeof err, &where), 0);
  fe_system sys;
  assert_int_equal(fe_assemble(&fx, &sys, err, sizeof err), 0);
  /* internal DOFs: nodes 1 .. nn-2 */
  int ni = 6 * (nn - 2);
  double *Kii = calloc((size_t)ni * ni, sizeof(double)), *KiB = calloc((size_t)ni * 6, sizeof(double));
  for (int j = 0; j < ni; j++)
    for (int i = 0; i < ni; i++) Kii[(size_t)j * ni + i] = sys.K[(size_t)(6 + j) * n + 6 + i];
  for (int j = 0; j < 6; j++)
    for (int i = 0; i < ni; i++) KiB[(size_t)j * ni + i] = sys.K[(size_t)(6 * B + j) * n + 6 + i];
  double *X = malloc((size_t)ni * 6 * sizeof(double));
  memcpy(X, KiB, (size_t)ni * 6 * sizeof(double));
  int info = 0, six = 6;
  dpotrf_("U", &ni, Kii, &ni, &info);
  assert_int_equal(info, 0);
  dpotrs_("U", &ni, &six, Kii, &ni, X, &ni, &info);
  assert_int_equal(info, 0);
  double worst = 0, big = 0;
  for (int a = 0; a < 6; a++)
    for (int b = 0; b < 6; b++) {
      double v = sys.K[(size_t)(6 * B + b) * n + 6 * B + a];
      for (int i = 0; i < ni; i++) v -= KiB[(size_t)a * ni + i] * X[(size_t)b * ni + i];
      worst = fmax(worst, fabs(v - K6[6 * a + b]));
      big = fmax(big, fabs(v));
    }
  printf("superelement: condensed K against the Schur complement: %.2e relative\n", worst / big);
  assert_true(worst <= 1e-9 * big);
  free(Kii); free(KiB); free(X);
  fe_system_free(&sys);
  assert_int_not_equal(fe_condense(&fx, 0, 0, K6, err, sizeof err, &where), 0);
  free_flex(&fx);
  /* a straight Euler-Bernoulli cantilever: tip stiffness 3EI/L^3 with the tip
     free to rotate, 12EI/L^3 with it held; EA/L; GJ/L */
  section s = square(0.02);
  s.Iy = 3 * s.Iz;
  const double L = 0.7;
  line_beam(&fx, 6, L, ex, ey, &s, BEAM_EULER_BERNOULLI, MASS_LUMPED);
  assert_int_equal(fe_condense(&fx, 0, 6, K6, err, sizeof err, &where), 0);
  double kyy = K6[6 * 1 + 1], kyr = K6[6 * 1 + 5], krr = K6[6 * 5 + 5];
  double ky_free = kyy - kyr * kyr / krr;
  assert_true(fabs(ky_free / (3 * s.E * s.Iz / (L * L * L)) - 1) < 1e-10);
  assert_true(fabs(kyy / (12 * s.E * s.Iz / (L * L * L)) - 1) < 1e-10);
  double kzz = K6[6 * 2 + 2], kzr = K6[6 * 2 + 4], kr2 = K6[6 * 4 + 4];
  assert_true(fabs((kzz - kzr * kzr / kr2) / (3 * s.E * s.Iy / (L * L * L)) - 1) < 1e-10);
  assert_true(fabs(K6[0] / (s.E * s.A / L) - 1) < 1e-10);
  assert_true(fabs(K6[21] / (s.G * s.J / L) - 1) < 1e-10);
  free_flex(&fx);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_eb_convergence),
      cmocka_unit_test(test_timoshenko_vs_eb),
      cmocka_unit_test(test_timoshenko_simply_supported),
      cmocka_unit_test(test_craig_bampton),
      cmocka_unit_test(test_residual_modes),
      cmocka_unit_test(test_condense),
      cmocka_unit_test(test_condense_nodes),
      cmocka_unit_test(test_normalization_and_masses),
      cmocka_unit_test(test_modal_file),
      cmocka_unit_test(test_errors),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
