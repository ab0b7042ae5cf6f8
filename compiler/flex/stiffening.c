/* stiffening.c: geometric stiffening of a flexible body (the option
 * geometric_stiffening: true).  docs/formulation.md section 12.1 derives it;
 * in short:
 *
 * A node's position gains a second-order part d_k = 1/2 sum_ij w_i w_j D_kij
 * (the foreshortening of the bent beams), and the kinetic energy the products
 * of the rigid velocities with it.  What the equations of motion need are two
 * mass-weighted sums over the nodes,
 *   P_ij = sum_k m_k D_kij            (3-vector),
 *   R_ij = sum_k m_k D_kij x_k^T      (3x3),
 * and these follow without D_k from the geometric stiffness of the beams
 * (Wallrapp and Schwertassek, "Representation of geometric stiffening in
 * multibody system simulation", IJNME 32 (1991); Schwertassek and Wallrapp,
 * "Dynamik flexibler Mehrkoerpersysteme" (1999), ch. 6): for loads f_k held by
 * the reference nodes, the work of the loads on the second-order
 * displacement is minus the geometric-stiffness energy of the axial forces
 * N_e(f) they cause,
 *   sum_k f_k . D_kij = -Phi_i^T K_G(N(f)) Phi_j.
 * So each component of P and R is one static load case:
 *   P_ij[c]    with f_k = m_k e_c            (3 cases),
 *   R_ij[c][l] with f_k = m_k x_k[l] e_c     (9 cases),
 * solved on the FE model with the reference nodes clamped; N_e from the
 * elongation of each beam, and K_G of a beam element from the cubic (Hermite)
 * interpolation of its transverse displacement (Przemieniecki, "Theory of
 * Matrix Structural Analysis" (1968), ch. 15; Shabana, "Dynamics of
 * Multibody Systems", 3rd ed., sec. 6.10):
 *   Phi_i^T K_G Phi_j = N_e int_0^L v_i' . v_j' dx,
 * v the displacement perpendicular to the element (a 3-vector: the two
 * bending planes at once; slopes theta x e at the ends). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "flex.h"

void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info);
void dpotrs_(const char *uplo, const int *n, const int *nrhs, const double *a, const int *lda,
             double *b, const int *ldb, int *info);

enum { STIFF_CASES = 12, STIFF_MAX_FREE = 6000 };

/* the load of case c at node k: cases 0..2 m_k e_c; 3 + 3 c + l: m_k x_k[l] e_c */
static void case_load(int c, double mk, const double *x, double f[3]) {
  f[0] = f[1] = f[2] = 0;
  if (c < 3) f[c] = mk;
  else f[(c - 3) / 3] = mk * x[(c - 3) % 3];
}

/* int_0^L a'(x) . b'(x) dx of two cubic (Hermite) fields given by their end
 * values (a0, a1) and end slopes (s0, s1), 3-vectors: the consistent
 * geometric stiffness of a beam per unit axial force, 1/(30 L) [36 3L -36 3L;
 * 3L 4L^2 -3L -L^2; -36 -3L 36 -3L; 3L -L^2 -3L 4L^2] on (v0, s0, v1, s1) */
static double slope_product(double L, const double *a[4], const double *b[4]) {
  const double G[16] = {36,     3 * L,  -36,    3 * L,  3 * L,  4 * L * L, -3 * L, -L * L,
                        -36,    -3 * L, 36,     -3 * L, 3 * L,  -L * L,    -3 * L, 4 * L * L};
  double s = 0;
  for (int p = 0; p < 4; p++)
    for (int q = 0; q < 4; q++)
      s += G[4 * p + q] * (a[p][0] * b[q][0] + a[p][1] * b[q][1] + a[p][2] * b[q][2]);
  return s / (30 * L);
}

/* mode j's displacement perpendicular to unit e at node k (body axes) and its
 * slope theta x e there */
static void transverse(const flex_data *d, int nm, int k, int j, const double e[3], double v[3],
                       double s[3]) {
  const double *X = d->node_X + 3 * ((size_t)k * nm + j), *Psi = d->node_Psi + 3 * ((size_t)k * nm + j);
  double ax = X[0] * e[0] + X[1] * e[1] + X[2] * e[2];
  for (int i = 0; i < 3; i++) v[i] = X[i] - ax * e[i];
  s[0] = Psi[1] * e[2] - Psi[2] * e[1];
  s[1] = Psi[2] * e[0] - Psi[0] * e[2];
  s[2] = Psi[0] * e[1] - Psi[1] * e[0];
}

/* entries below 1e-10 of the table's largest become exact zeros, as the
 * other invariants' (flex.c): structurally zero products of different shape
 * families leave a rounding residue */
static void clean(double *t, size_t n) {
  double mx = 0;
  for (size_t i = 0; i < n; i++) mx = fmax(mx, fabs(t[i]));
  for (size_t i = 0; i < n; i++)
    if (fabs(t[i]) <= 1e-10 * mx) t[i] = 0;
}

int flex_stiffening_build(const ir_flex *fx, const fe_modes *fm, flex_data *out, char *err, size_t nerr) {
  int nm = out->flex.nm, nn = fm->nnodes;
  if (fx->modal_file || fx->K_given || fx->nbeams == 0) {
    snprintf(err, nerr, "'geometric_stiffening' needs an FE model of beams (not a modal data file or matrices)");
    return -1;
  }
  if (fx->reference_kind != REFERENCE_CLAMPED || fx->nreference < 1) {
    snprintf(err, nerr, "'geometric_stiffening' needs a clamped reference node (reference: [node]); "
                        "chord and free reference conditions are not supported");
    return -1;
  }
  if (fx->nlinks > 0) {
    snprintf(err, nerr, "'geometric_stiffening' does not support RBE2 rigid links");
    return -1;
  }
  if (fx->coupling == COUPLING_CONSTANT || fx->coupling == COUPLING_RIGID) {
    snprintf(err, nerr, "'geometric_stiffening' needs coupling full or partial (its terms move the mass matrix)");
    return -1;
  }
  if (nm == 0) return 0;
  int ndof = 6 * nn;
  int *freeidx = malloc(sizeof(int) * (size_t)ndof);
  if (!freeidx) { snprintf(err, nerr, "out of memory"); return -1; }
  for (int i = 0; i < ndof; i++) freeidx[i] = 0;
  for (int r = 0; r < fx->nreference; r++)
    for (int i = 0; i < 6; i++) freeidx[6 * fx->reference[r] + i] = -1;
  if (fx->fixed)
    for (int i = 0; i < ndof; i++)
      if (fx->fixed[i]) freeidx[i] = -1;
  int nf = 0;
  for (int i = 0; i < ndof; i++)
    if (freeidx[i] == 0) freeidx[i] = nf++;
  if (nf > STIFF_MAX_FREE) {
    snprintf(err, nerr, "'geometric_stiffening': %d free FE DOFs; the dense static solve takes at most %d",
             nf, STIFF_MAX_FREE);
    free(freeidx);
    return -1;
  }
  fe_system sys = {0};
  double *Kf = NULL, *U = NULL, *N = NULL;
  int st = -1;
  if (fe_assemble(fx, &sys, err, nerr)) goto done;
  Kf = calloc((size_t)nf * (size_t)nf + 1, sizeof(double));
  U = calloc((size_t)nf * STIFF_CASES + 1, sizeof(double));
  N = calloc((size_t)fx->nbeams * STIFF_CASES + 1, sizeof(double));
  out->stiff_P = calloc(3 * (size_t)nm * (size_t)nm + 1, sizeof(double));
  out->stiff_R = calloc(9 * (size_t)nm * (size_t)nm + 1, sizeof(double));
  if (!Kf || !U || !N || !out->stiff_P || !out->stiff_R) { snprintf(err, nerr, "out of memory"); goto done; }
  for (int j = 0; j < ndof; j++)
    for (int i = 0; i < ndof; i++)
      if (freeidx[i] >= 0 && freeidx[j] >= 0)
        Kf[(size_t)freeidx[j] * nf + freeidx[i]] = sys.K[(size_t)j * ndof + i];
  /* the unit inertia loads on the lumped node masses (translations only) */
  for (int k = 0; k < nn; k++)
    for (int c = 0; c < STIFF_CASES; c++) {
      double f[3];
      case_load(c, fm->node_mass[k], fm->x + 3 * k, f);
      for (int i = 0; i < 3; i++)
        if (freeidx[6 * k + i] >= 0) U[(size_t)c * nf + freeidx[6 * k + i]] = f[i];
    }
  int info = 0, ncase = STIFF_CASES;
  dpotrf_("L", &nf, Kf, &nf, &info);
  if (info != 0) {
    snprintf(err, nerr, "'geometric_stiffening': the FE stiffness with the reference node clamped is singular "
                        "(a mechanism or a DOF without stiffness)");
    goto done;
  }
  dpotrs_("L", &nf, &ncase, Kf, &nf, U, &nf, &info);
  /* axial force of each beam in each case: EA/L times its elongation */
  for (int e = 0; e < fx->nbeams; e++) {
    const ir_beam *b = &fx->beams[e];
    int a = b->node[0], c1 = b->node[1];
    double d[3], L = 0;
    for (int i = 0; i < 3; i++) { d[i] = fm->x[3 * c1 + i] - fm->x[3 * a + i]; L += d[i] * d[i]; }
    L = sqrt(L);
    for (int i = 0; i < 3; i++) d[i] /= L;
    for (int c = 0; c < STIFF_CASES; c++) {
      double el = 0;
      for (int i = 0; i < 3; i++) {
        int ia = freeidx[6 * a + i], ib = freeidx[6 * c1 + i];
        double ua = ia >= 0 ? U[(size_t)c * nf + ia] : 0, ub = ib >= 0 ? U[(size_t)c * nf + ib] : 0;
        el += (ub - ua) * d[i];
      }
      N[(size_t)e * STIFF_CASES + c] = b->E * b->A / L * el;
    }
  }
  /* P_ij[c] = -sum_e N_e(c) int v_i' . v_j',  R_ij[c][l] likewise with case 3 + 3 c + l */
  for (int e = 0; e < fx->nbeams; e++) {
    const ir_beam *b = &fx->beams[e];
    int n0 = b->node[0], n1 = b->node[1];
    double d[3], L = 0;
    for (int i = 0; i < 3; i++) { d[i] = fm->x[3 * n1 + i] - fm->x[3 * n0 + i]; L += d[i] * d[i]; }
    L = sqrt(L);
    for (int i = 0; i < 3; i++) d[i] /= L;
    for (int i = 0; i < nm; i++) {
      double vi0[3], si0[3], vi1[3], si1[3];
      transverse(out, nm, n0, i, d, vi0, si0);
      transverse(out, nm, n1, i, d, vi1, si1);
      const double *ai[4] = {vi0, si0, vi1, si1};
      for (int j = 0; j < nm; j++) {
        double vj0[3], sj0[3], vj1[3], sj1[3];
        transverse(out, nm, n0, j, d, vj0, sj0);
        transverse(out, nm, n1, j, d, vj1, sj1);
        const double *aj[4] = {vj0, sj0, vj1, sj1};
        double g = slope_product(L, ai, aj);
        if (g == 0) continue;
        const double *Ne = N + (size_t)e * STIFF_CASES;
        double *P = out->stiff_P + 3 * ((size_t)i * nm + j), *R = out->stiff_R + 9 * ((size_t)i * nm + j);
        for (int c = 0; c < 3; c++) P[c] -= Ne[c] * g;
        for (int c = 0; c < 9; c++) R[c] -= Ne[3 + c] * g;
      }
    }
  }
  clean(out->stiff_P, 3 * (size_t)nm * (size_t)nm);
  clean(out->stiff_R, 9 * (size_t)nm * (size_t)nm);
  out->stiff.P = out->stiff_P;
  out->stiff.R = out->stiff_R;
  out->stiff.body = mb_flex_body_stiff;
  st = 0;
done:
  free(freeidx);
  free(Kf);
  free(U);
  free(N);
  fe_system_free(&sys);
  return st;
}
