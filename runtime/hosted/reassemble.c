/* reassemble.c: the assembly at start after run-time parameters moved joint
 * points or body positions (the model's set_params wrote its markers' offsets
 * and q_given).  The compiler assembled the model for the file's values
 * (compiler/lower/assemble.c); here the same steps run on the generated code:
 * Newton on the position constraints with minimum-norm steps from the state
 * as given (m->q_given: where the compiler's assembly started, so that the
 * same assembly branch is found as by a recompiled model), then the velocities made consistent, also by a minimum-norm
 * correction.  The compiled pattern fixes which rows are independent: the
 * kept rows must stay independent at the new configuration, and the rows the
 * compiler removed as redundant (m->redundant_row) must stay satisfied and
 * dependent on the kept ones; otherwise the run stops with the cause.
 *
 * Dense (nc x nv) and done once, at start: models with run-time geometry are
 * rarely large, and the rank decisions want an orthogonal factorization. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "mb_model.h"
#include "mb_sim.h"

typedef struct {
  const mb_model *m;
  int nc, nv;
  double *D;      /* nc x nv, row-major: the kept rows' Jacobian */
  double *Q;      /* up to nc orthonormal rows of nv: a basis of D's rows */
  double *T;      /* nc x nc: row order[k] of D = sum_i T[k][i] Q_i (i <= k) */
  int *order;     /* the rows in the compiler's order: drivers first */
  int *live;      /* live[k]: row order[k] independent of those before it */
  mb_real *Kx, *rhs, *phi, *nu;
  void *work;
} reassembly;

static void release(reassembly *a) {
  free(a->D); free(a->Q); free(a->T); free(a->order); free(a->live);
  free(a->Kx); free(a->rhs); free(a->phi); free(a->nu); free(a->work);
}

static int setup(reassembly *a, const mb_model *m) {
  memset(a, 0, sizeof *a);
  a->m = m;
  a->nc = m->nc;
  a->nv = m->nv;
  size_t nc = (size_t)m->nc + 1, nv = (size_t)m->nv + 1;
  a->D = malloc(sizeof(double) * nc * nv);
  a->Q = malloc(sizeof(double) * nc * nv);
  a->T = malloc(sizeof(double) * nc * nc);
  a->order = malloc(sizeof(int) * nc);
  a->live = malloc(sizeof(int) * nc);
  a->Kx = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  a->rhs = calloc((size_t)m->n + 1, sizeof(mb_real));
  a->phi = calloc(nc, sizeof(mb_real));
  a->nu = calloc(nc, sizeof(mb_real));
  a->work = malloc(mb_model_worksize(m) + 16);
  if (!a->D || !a->Q || !a->T || !a->order || !a->live || !a->Kx || !a->rhs || !a->phi || !a->nu || !a->work)
    return -1;
  int k = 0;
  for (int r = 0; r < m->nc; r++)
    if (m->row[r].driver >= 0) a->order[k++] = r;
  for (int r = 0; r < m->nc; r++)
    if (m->row[r].driver < 0) a->order[k++] = r;
  return 0;
}

/* K's entries at (q, v), phi and nu; D from K's constraint rows, with the
 * modal columns left out when 'frozen' (the model is given undeformed) */
static void evaluate(reassembly *a, const mb_real *q, const mb_real *v, int frozen) {
  const mb_model *m = a->m;
  m->init(m, a->Kx);
  m->eval(m, 0, q, v, a->Kx, a->rhs, a->phi, a->nu, a->work);
  memset(a->D, 0, sizeof(double) * (size_t)a->nc * (size_t)a->nv);
  for (int c = 0; c < m->nv; c++)
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++)
      if (m->Ki[p] >= m->nv) a->D[(size_t)(m->Ki[p] - m->nv) * (size_t)m->nv + (size_t)c] = (double)a->Kx[p];
  if (!frozen) return;
  for (int b = 0; b < m->nbody; b++)
    for (int j = 0; j < m->body[b].nm; j++)
      for (int r = 0; r < m->nc; r++) a->D[(size_t)r * (size_t)m->nv + (size_t)(m->body[b].vadr + 6 + j)] = 0;
}

static double dot(const double *x, const double *y, int n) {
  double s = 0;
  for (int i = 0; i < n; i++) s += x[i] * y[i];
  return s;
}

/* the largest row norm of D, at least 1: the scale of the rank tolerance */
static double row_scale(const reassembly *a) {
  double biggest = 1;
  for (int r = 0; r < a->nc; r++) {
    const double *d = a->D + (size_t)r * (size_t)a->nv;
    biggest = fmax(biggest, sqrt(dot(d, d, a->nv)));
  }
  return biggest;
}

/* w minus its part in the span of the first n basis rows (twice, for
 * orthogonality in round-off); coef[i] += the parts taken */
static void orthogonalize(const reassembly *a, int n, double *w, double *coef) {
  for (int pass = 0; pass < 2; pass++)
    for (int i = 0; i < n; i++) {
      const double *qi = a->Q + (size_t)i * (size_t)a->nv;
      double c = dot(qi, w, a->nv);
      if (coef) coef[i] += c;
      for (int j = 0; j < a->nv; j++) w[j] -= c * qi[j];
    }
}

/* what the model's reals resolve: the compiler's rank tolerance (1e-9) in
 * double, a coarser one in single precision, where D carries errors of 1e-7 */
#ifdef MB_REAL_FLOAT
#define RANK_TOL 1e-5
#define ACCEPT_PHI 1e-5
#else
#define RANK_TOL 1e-9
#define ACCEPT_PHI 1e-9
#endif

/* Gram-Schmidt over D's rows in 'order': a row whose part independent of
 * the rows before it is at most RANK_TOL of the largest row norm (the
 * compiler's tolerance) is not live; returns the basis size */
static int factor(reassembly *a) {
  double tol = RANK_TOL * row_scale(a);
  int n = 0;
  for (int k = 0; k < a->nc; k++) {
    double *w = a->Q + (size_t)n * (size_t)a->nv, *coef = a->T + (size_t)k * (size_t)a->nc;
    memcpy(w, a->D + (size_t)a->order[k] * (size_t)a->nv, sizeof(double) * (size_t)a->nv);
    memset(coef, 0, sizeof(double) * (size_t)a->nc);
    orthogonalize(a, n, w, coef);
    double norm = sqrt(dot(w, w, a->nv));
    a->live[k] = norm > tol;
    if (!a->live[k]) continue;
    for (int j = 0; j < a->nv; j++) w[j] /= norm;
    coef[n++] = norm;
  }
  return n;
}

/* x (nv) = the minimum-norm solution of the live rows' D x = b (b: nc values
 * by row): x = sum_i y_i Q_i with T_live y = b_live, forward */
static void min_norm(const reassembly *a, const double *b, double *x) {
  double *y = malloc(sizeof(double) * ((size_t)a->nc + 1));
  memset(x, 0, sizeof(double) * (size_t)a->nv);
  if (!y) return;
  int n = 0;
  for (int k = 0; k < a->nc; k++) {
    if (!a->live[k]) continue;
    const double *coef = a->T + (size_t)k * (size_t)a->nc;
    double s = b[a->order[k]];
    for (int i = 0; i < n; i++) s -= coef[i] * y[i];
    y[n] = s / coef[n];
    n++;
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < a->nv; j++) x[j] += y[i] * a->Q[(size_t)i * (size_t)a->nv + (size_t)j];
  free(y);
}

/* what row r of the model constrains, for messages */
static void row_name(const mb_model *m, const mb_rowdef *R, char *out, size_t n) {
  if (R->joint >= 0 && m->joint_name) snprintf(out, n, "a row of joint '%s'", m->joint_name[R->joint]);
  else if (R->driver >= 0) snprintf(out, n, "a driver's row");
  else snprintf(out, n, "a row of the rigid joint of a virtual body");
}

/* marker k at (q, v) (as the generic path builds it) */
static void marker_at(const mb_model *m, int k, const mb_real *q, const mb_real *v, mb_frame *f, mb_marker *mk) {
  const mb_markerdef *d = &m->marker[k];
  if (d->body < 0) { mb_marker_ground(d->s, d->C, mk); return; }
  const mb_body *B = &m->body[d->body];
  mb_frame_rigid(q + B->qadr, v + B->vadr, f);
  if (d->node >= 0) mb_marker_node(f, B->flex, d->node, q + B->qadr + 7, v + B->vadr + 6, d->C, mk);
  else mb_marker_rigid(f, d->s, d->C, mk);
}

/* a removed row at (q, v): its phi, and its Jacobian row into d (nv) */
static double removed_row(const mb_model *m, const mb_rowdef *R, const mb_real *q, const mb_real *v, double *d) {
  static const mb_real none[3] = {0, 0, 0};
  mb_frame f[2];
  mb_marker mk[2];
  mb_row r;
  mb_real x[3];
  marker_at(m, R->m0, q, v, &f[0], &mk[0]);
  marker_at(m, R->m1, q, v, &f[1], &mk[1]);
  mb_row_zero(&r); /* a kind not below (a corrupt table): a zero row */
  switch (R->kind) {
  case MB_PRIM_SPH: mb_prim_sph(&mk[0], &mk[1], R->a, &r); break;
  case MB_PRIM_DOT1: mb_prim_dot1(&mk[0], &mk[1], R->a, R->b, &r); break;
  case MB_PRIM_DOT2: mb_prim_dot2(&mk[0], &mk[1], R->a, none, &r); break;
  case MB_PRIM_DIST: mb_prim_dist(&mk[0], &mk[1], R->L, &r); break;
  case MB_PRIM_ROT:
    mb_profile_eval(&m->profile[R->profile], 0, x);
    mb_prim_rot(&mk[0], &mk[1], x, &r);
    break;
  case MB_PRIM_TRANS:
    mb_profile_eval(&m->profile[R->profile], 0, x);
    mb_prim_dot2(&mk[0], &mk[1], 2, x, &r);
    break;
  }
  memset(d, 0, sizeof(double) * (size_t)m->nv);
  for (int s = 0; s < 2; s++) {
    const mb_markerdef *md = &m->marker[s ? R->m1 : R->m0];
    if (md->body < 0) continue;
    const mb_body *B = &m->body[md->body];
    mb_real c[6 + 64];
    int nc = 6;
    if (md->node >= 0 && B->nm <= 64) {
      mb_node_cols_mk(&f[s], B->flex, md->node, &mk[s], r.dV[s], r.dW[s], c);
      nc += B->nm;
    } else {
      mb_rigid_cols(&f[s], mk[s].P, r.dV[s], r.dW[s], c);
    }
    for (int j = 0; j < nc; j++) d[B->vadr + j] += (double)c[j];
  }
  return (double)r.phi;
}

int mb_reassemble(const mb_model *m, mb_real *q, mb_real *v, char *why, size_t nwhy) {
  reassembly a;
  int status = 1;
  double *b = malloc(sizeof(double) * ((size_t)m->nc + (size_t)m->nv + 1));
  double *dx = malloc(sizeof(double) * ((size_t)m->nv + 1));
  mb_real *dq = malloc(sizeof(mb_real) * ((size_t)m->nv + 1));
  /* from the state as given, as the compiler's assembly started */
  memcpy(q, m->q_given ? m->q_given : m->q0, sizeof(mb_real) * (size_t)m->nq);
  memcpy(v, m->v_given ? m->v_given : m->v0, sizeof(mb_real) * (size_t)m->nv);
  snprintf(why, nwhy, "out of memory");
  if (setup(&a, m) || !b || !dx || !dq) goto out;
  /* 1. positions: as the compiler, bodies deformed only if they must */
  int it, worst = -1;
  double res = 0;
  for (it = 0; it < 50; it++) {
    evaluate(&a, q, v, it < 25);
    res = 0;
    for (int r = 0; r < m->nc; r++)
      if (!(fabs((double)a.phi[r]) <= res)) { res = fabs((double)a.phi[r]); worst = r; }
    if (res <= 1e-12) break;
    factor(&a);
    for (int r = 0; r < m->nc; r++) b[r] = -(double)a.phi[r];
    min_norm(&a, b, dx);
    for (int j = 0; j < m->nv; j++) dq[j] = (mb_real)dx[j];
    mb_model_qincrement(m, q, dq);
    mb_model_normalize(m, q);
  }
  const double accept = ACCEPT_PHI;
  char row[200];
  if (!(res <= accept)) {
    row_name(m, &m->row[worst >= 0 ? worst : 0], row, sizeof row);
    snprintf(why, nwhy, "the joints cannot be assembled with this geometry: %s has residual %.3g after %d "
             "Newton iterations (a loop that cannot close, or a configuration too far from the compiled one)",
             row, res, it);
    goto out;
  }
  /* 2. the compiled pattern's rank: kept rows independent, removed rows
     satisfied and dependent on them */
  evaluate(&a, q, v, 0);
  int rank = factor(&a);
  if (rank < m->nc) {
    int k = 0;
    while (k < m->nc && a.live[k]) k++;
    row_name(m, &m->row[a.order[k]], row, sizeof row);
    snprintf(why, nwhy, "at the new geometry %s depends on the other constraints (the compiled model has it "
             "independent: the constraint Jacobian lost rank; recompile with the values in the file)", row);
    goto out;
  }
  double scale = row_scale(&a);
  for (int r = 0; r < m->nredundant; r++) {
    double phi = removed_row(m, &m->redundant_row[r], q, v, b);
    double norm = sqrt(dot(b, b, m->nv));
    orthogonalize(&a, rank, b, NULL);
    double off = sqrt(dot(b, b, m->nv));
    if (fabs(phi) > 1e3 * accept || off > 1e2 * RANK_TOL * fmax(scale, norm)) {
      snprintf(why, nwhy, "at the new geometry the constraint '%s', removed as redundant at compile time, is no "
               "longer redundant (%s %.3g): the compiled model would ignore it; recompile with the values in "
               "the file", m->redundant_name ? m->redundant_name[r] : "?",
               fabs(phi) > 1e3 * accept ? "its residual is" : "its independent part is", fabs(phi) > 1e3 * accept ? fabs(phi) : off);
      goto out;
    }
  }
  /* 3. velocities: D v = nu (a.nu holds phid = D v - nu), modal columns frozen */
  evaluate(&a, q, v, 1);
  factor(&a);
  for (int r = 0; r < m->nc; r++) b[r] = -(double)a.nu[r];
  min_norm(&a, b, dx);
  for (int j = 0; j < m->nv; j++) v[j] = (mb_real)((double)v[j] + dx[j]);
  status = 0;
  why[0] = 0;
out:
  release(&a);
  free(b); free(dx); free(dq);
  return status;
}
