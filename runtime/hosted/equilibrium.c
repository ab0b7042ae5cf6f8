/* equilibrium.c: static equilibrium before a dynamic run (simulation:
 * {equilibrium: true}, --equilibrium).  Newton on the constrained static
 * equations at t = 0 with the velocities set to zero (so that dampers and
 * velocity terms do not bias the rest state):
 *
 *     f(q, 0, 0) - D(q)^T lambda = 0,   phi(q, 0) = 0,
 *
 * the unknowns the position increments in velocity space (rigid frames with
 * exact rotation increments, modal coordinates) and the multipliers.  The
 * tangent's force rows are central differences of f - D^T lambda (they hold
 * the force elements' stiffness, the modal stiffness and the constraints'
 * geometric stiffness lambda dD/dq); its constraint rows are D itself.  It is
 * solved densely with complete pivoting, so that a free direction without load
 * (a car's yaw and ground-plane motion on springs) is left where it is, and a
 * free direction with load (a body free under gravity) is reported as such.
 * A backtracking line search on the residual norm damps the steps.  The
 * velocities given for the dynamic run are kept (projected onto the moved
 * constraints). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mb_sim.h"

#ifdef MB_REAL_FLOAT
#define EQ_FORCE_TOL 1e-4   /* relative to the force scale */
#define EQ_FD_STEP 3e-3     /* central differences: about the cube root of float's epsilon */
#define EQ_RANK_TOL 1e-5    /* pivots below this fraction of the largest: a free direction */
#else
#define EQ_FORCE_TOL 1e-10
#define EQ_FD_STEP 1e-6
#define EQ_RANK_TOL 1e-9
#endif
#define EQ_MAX_ITERATIONS 50
#define EQ_MAX_UNKNOWNS 4000 /* the dense tangent: n^2 reals */

typedef struct {
  mb_sim *s;
  const mb_model *m;
  int nv, nc, n;
  double scale;          /* force scale F (N): force rows are divided by it, mu = lambda / F */
  mb_real *vzero, *qt, *dv;
  double *R, *Rp, *Rm, *J, *x, *mu, *mut;
  int *rowp, *colp;
} eq_work;

/* R = [(f - D^T lambda) / F; phi] at q (t = 0, v = 0), lambda = F mu; leaves
   D(q) in s->Kx */
static void residual(eq_work *e, const mb_real *q, const double *mu, double *R) {
  mb_sim *s = e->s;
  const mb_model *m = e->m;
  m->eval(m, 0, q, e->vzero, s->Kx, s->rhs, s->phi, s->nu, s->work);
  s->stats.evals++;
  for (int j = 0; j < e->nv; j++) {
    double r = (double)s->rhs[j];
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] >= e->nv) r -= (double)s->Kx[p] * e->scale * mu[m->Ki[p] - e->nv];
    R[j] = r / e->scale;
  }
  for (int r = 0; r < e->nc; r++) R[e->nv + r] = (double)s->phi[r];
}

static double max_abs_range(const double *a, int from, int to) {
  double mx = 0;
  for (int i = from; i < to; i++) mx = (fabs(a[i]) > mx || a[i] != a[i]) ? (a[i] != a[i] ? INFINITY : fabs(a[i])) : mx;
  return mx;
}

static double half_square_norm(const double *a, int n) {
  double s = 0;
  for (int i = 0; i < n; i++) s += a[i] * a[i];
  return 0.5 * s;
}

/* Gaussian elimination with complete pivoting on A (n x n, column-major) x =
 * b.  Pivots below rtol times the first (largest) one end the elimination:
 * the unknowns left over are free and set to 0 (the basic solution).  Returns
 * the rank; *left is the largest |b| left in the rows beyond the rank (what
 * the basic solution cannot satisfy) and *left_row that row's original index. */
static int solve_complete(int n, double *A, double *b, double *x, int *rowp, int *colp, double rtol,
                          double *left, int *left_row) {
  for (int i = 0; i < n; i++) { rowp[i] = i; colp[i] = i; }
  double first = 0;
  int rank = n;
  for (int k = 0; k < n; k++) {
    int pi = k, pj = k;
    double big = -1;
    for (int j = k; j < n; j++)
      for (int i = k; i < n; i++)
        if (fabs(A[i + (size_t)n * j]) > big) { big = fabs(A[i + (size_t)n * j]); pi = i; pj = j; }
    if (k == 0) first = big;
    if (!(big > rtol * first) || big == 0) { rank = k; break; }
    if (pi != k) {
      for (int j = 0; j < n; j++) {
        double t = A[k + (size_t)n * j]; A[k + (size_t)n * j] = A[pi + (size_t)n * j]; A[pi + (size_t)n * j] = t;
      }
      double t = b[k]; b[k] = b[pi]; b[pi] = t;
      int ti = rowp[k]; rowp[k] = rowp[pi]; rowp[pi] = ti;
    }
    if (pj != k) {
      for (int i = 0; i < n; i++) {
        double t = A[i + (size_t)n * k]; A[i + (size_t)n * k] = A[i + (size_t)n * pj]; A[i + (size_t)n * pj] = t;
      }
      int tj = colp[k]; colp[k] = colp[pj]; colp[pj] = tj;
    }
    double piv = A[k + (size_t)n * k];
    for (int i = k + 1; i < n; i++) {
      double l = A[i + (size_t)n * k] / piv;
      if (l == 0) continue;
      A[i + (size_t)n * k] = 0;
      for (int j = k + 1; j < n; j++) A[i + (size_t)n * j] -= l * A[k + (size_t)n * j];
      b[i] -= l * b[k];
    }
  }
  *left = 0;
  *left_row = -1;
  for (int k = rank; k < n; k++)
    if (fabs(b[k]) > *left) { *left = fabs(b[k]); *left_row = rowp[k]; }
  for (int k = n - 1; k >= 0; k--) {
    double y = 0;
    if (k < rank) {
      y = b[k];
      for (int j = k + 1; j < rank; j++) y -= A[k + (size_t)n * j] * b[j];
      y /= A[k + (size_t)n * k];
    }
    b[k] = y; /* b now holds the permuted solution from k on */
  }
  for (int k = 0; k < n; k++) x[colp[k]] = k < rank ? b[k] : 0;
  return rank;
}

/* "body 'arm', rotation z" for velocity coordinate i, or "constraint row r" */
static void name_unknown(const mb_model *m, int i, char *out, size_t n) {
  if (i >= m->nv) { snprintf(out, n, "constraint row %d", i - m->nv); return; }
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    int k = i - B->vadr;
    if (k < 0 || k >= 6 + B->nm) continue;
    if (k < 6) snprintf(out, n, "body '%s', %s %c", B->name, k < 3 ? "translation" : "rotation", "xyz"[k % 3]);
    else snprintf(out, n, "body '%s', mode %d", B->name, k - 6 + 1);
    return;
  }
  snprintf(out, n, "coordinate %d", i);
}

static void eq_free(eq_work *e) {
  free(e->vzero); free(e->qt); free(e->dv); free(e->R); free(e->Rp); free(e->Rm); free(e->J);
  free(e->x); free(e->mu); free(e->mut); free(e->rowp); free(e->colp);
}

/* the weight of the model (N), the force scale of the residual */
static double model_weight(const mb_model *m) {
  double mass = 0;
  for (int b = 0; b < m->nbody; b++)
    mass += m->body[b].kind == MB_BODY_FLEXIBLE && m->body[b].flex ? (double)m->body[b].flex->mass
                                                                     : (double)m->body[b].mass;
  double g = sqrt((double)(m->gravity[0] * m->gravity[0] + m->gravity[1] * m->gravity[1] +
                           m->gravity[2] * m->gravity[2]));
  return mass * g;
}

static int eq_fail(mb_sim *s, int status) {
  s->fail_time = 0;
  snprintf(s->fail_detail, sizeof s->fail_detail, "static equilibrium: %s", mb_status_text(status));
  s->factored_valid = 0;
  return status;
}

int mb_sim_equilibrium(mb_sim *s, mb_equilibrium_info *info) {
  const mb_model *m = s->m;
  eq_work e = {0};
  memset(info, 0, sizeof *info);
  e.s = s;
  e.m = m;
  e.nv = m->nv;
  e.nc = m->nc;
  e.n = m->nv + m->nc;
  int n = e.n, nv = e.nv;
  if (n > EQ_MAX_UNKNOWNS) {
    snprintf(info->why, sizeof info->why, "the model has %d unknowns, more than the %d the dense "
             "static tangent handles", n, EQ_MAX_UNKNOWNS);
    return eq_fail(s, MB_ERR_INVALID);
  }
  e.vzero = calloc((size_t)nv + 1, sizeof(mb_real));
  e.qt = calloc((size_t)m->nq + 1, sizeof(mb_real));
  e.dv = calloc((size_t)nv + 1, sizeof(mb_real));
  e.R = calloc((size_t)n + 1, sizeof(double));
  e.Rp = calloc((size_t)n + 1, sizeof(double));
  e.Rm = calloc((size_t)n + 1, sizeof(double));
  e.J = calloc((size_t)n * (size_t)n + 1, sizeof(double));
  e.x = calloc((size_t)n + 1, sizeof(double));
  e.mu = calloc((size_t)e.nc + 1, sizeof(double));
  e.mut = calloc((size_t)e.nc + 1, sizeof(double));
  e.rowp = calloc((size_t)n + 1, sizeof(int));
  e.colp = calloc((size_t)n + 1, sizeof(int));
  if (!e.vzero || !e.qt || !e.dv || !e.R || !e.Rp || !e.Rm || !e.J || !e.x || !e.mu || !e.mut ||
      !e.rowp || !e.colp) {
    eq_free(&e);
    snprintf(info->why, sizeof info->why, "out of memory for the static tangent (%d unknowns)", n);
    return eq_fail(s, MB_ERR_NOMEM);
  }
  mb_real *q = s->q;
  mb_model_normalize(m, q);

  /* the force scale: the weight, or the largest applied force at the start */
  e.scale = 1;
  residual(&e, q, e.mu, e.R);
  double largest = max_abs_range(e.R, 0, nv);
  e.scale = fmax(model_weight(m), largest);
  if (!(e.scale > 0) || !isfinite(e.scale)) e.scale = 1;
  info->force_scale = e.scale;

  /* first multipliers: the dynamic ones at rest, K [a; lambda] = [f; 0], so
     that the first tangent has the constraints' geometric stiffness (a
     pendulum's only stiffness) */
  if (e.nc > 0 && s->ls->factor(s->ls, s->Kx) == MB_OK) {
    for (int i = 0; i < nv; i++) s->x[i] = s->rhs[i];
    for (int r = 0; r < e.nc; r++) s->x[nv + r] = 0;
    if (s->ls->solve(s->ls, s->x) == MB_OK)
      for (int r = 0; r < e.nc; r++)
        e.mu[r] = isfinite((double)s->x[nv + r]) ? (double)s->x[nv + r] / e.scale : 0;
  }
  s->factored_valid = 0;

  int status = MB_OK;
  double ctol = s->set.projection_tol;
  residual(&e, q, e.mu, e.R);
  for (int it = 0;; it++) {
    double fres = max_abs_range(e.R, 0, nv), cres = max_abs_range(e.R, nv, n);
    info->iterations = it;
    info->force_residual = fres;
    info->constraint_residual = cres;
    if (!isfinite(fres) || !isfinite(cres)) {
      snprintf(info->why, sizeof info->why, "the static forces or constraints are not finite "
               "after %d iterations", it);
      status = MB_ERR_NONFINITE;
      break;
    }
    if (fres <= EQ_FORCE_TOL && cres <= ctol) break;
    if (it >= EQ_MAX_ITERATIONS) {
      snprintf(info->why, sizeof info->why, "Newton did not converge in %d iterations: force "
               "residual %.3g of the force scale %.4g N, constraint residual %.3g", it, fres, e.scale, cres);
      status = MB_ERR_NEWTON;
      break;
    }
    /* the tangent: constraint rows D and multiplier columns -D^T from K's pattern */
    double *J = e.J;
    memset(J, 0, sizeof(double) * (size_t)n * (size_t)n);
    for (int j = 0; j < nv; j++)
      for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
        if (m->Ki[p] >= nv) {
          J[m->Ki[p] + (size_t)n * j] = (double)s->Kx[p];
          J[j + (size_t)n * m->Ki[p]] = -(double)s->Kx[p];
        }
    /* ... and the force rows' dq columns by central differences */
    for (int j = 0; j < nv; j++) {
      for (int sign = 0; sign < 2; sign++) {
        memcpy(e.qt, q, sizeof(mb_real) * (size_t)m->nq);
        e.dv[j] = (mb_real)(sign ? -EQ_FD_STEP : EQ_FD_STEP);
        mb_model_qincrement(m, e.qt, e.dv);
        e.dv[j] = 0;
        residual(&e, e.qt, e.mu, sign ? e.Rm : e.Rp);
      }
      for (int i = 0; i < nv; i++) J[i + (size_t)n * j] = (e.Rp[i] - e.Rm[i]) / (2 * EQ_FD_STEP);
    }
    for (int i = 0; i < n; i++) e.Rm[i] = -e.R[i];
    double left;
    int left_row;
    int rank = solve_complete(n, J, e.Rm, e.x, e.rowp, e.colp, EQ_RANK_TOL, &left, &left_row);
    info->free_directions = n - rank;
    double rnorm = max_abs_range(e.R, 0, n);
    if (rank < n && left > (left_row < nv ? EQ_FORCE_TOL : ctol) && left > 1e-3 * rnorm) {
      char what[160];
      name_unknown(m, left_row, what, sizeof what);
      if (left_row < nv)
        snprintf(info->why, sizeof info->why, "no equilibrium: the static tangent is singular (rank %d "
                 "of %d) and the applied forces act along a free direction (%s: %.3g of the force "
                 "scale %.4g N unbalanced), e.g. a body free under gravity or a mechanism without a stop",
                 rank, n, what, left, e.scale);
      else
        snprintf(info->why, sizeof info->why, "no equilibrium: the static tangent is singular (rank %d "
                 "of %d) and the constraints cannot be satisfied (%s violated by %.3g)", rank, n,
                 what, left);
      status = MB_ERR_SINGULAR;
      break;
    }
    /* the step [dq; dmu] in e.x, damped until the residual norm decreases */
    double merit0 = half_square_norm(e.R, n), alpha = 1;
    int accepted = 0;
    for (; alpha >= 1.0 / 4096; alpha /= 2) {
      memcpy(e.qt, q, sizeof(mb_real) * (size_t)m->nq);
      for (int i = 0; i < nv; i++) e.dv[i] = (mb_real)(alpha * e.x[i]);
      mb_model_qincrement(m, e.qt, e.dv);
      mb_model_normalize(m, e.qt);
      for (int r = 0; r < e.nc; r++) e.mut[r] = e.mu[r] + alpha * e.x[nv + r];
      residual(&e, e.qt, e.mut, e.Rp);
      double merit = half_square_norm(e.Rp, n);
      if (merit <= (1 - 1e-4 * alpha) * merit0) { accepted = 1; break; }
    }
    for (int i = 0; i < nv; i++) e.dv[i] = 0;
    if (!accepted) {
      snprintf(info->why, sizeof info->why, "the line search found no step that lowers the residual "
               "after %d iterations (force residual %.3g of the force scale %.4g N, constraint residual "
               "%.3g): no equilibrium reachable from the start", it, fres, e.scale, cres);
      status = MB_ERR_NEWTON;
      break;
    }
    memcpy(q, e.qt, sizeof(mb_real) * (size_t)m->nq);
    memcpy(e.mu, e.mut, sizeof(double) * (size_t)e.nc);
    memcpy(e.R, e.Rp, sizeof(double) * (size_t)n);
    info->smallest_damping = it == 0 || alpha < info->smallest_damping ? alpha : info->smallest_damping;
  }
  s->factored_valid = 0;
  eq_free(&e);
  if (status) return eq_fail(s, status);
  /* the given velocities, on the moved velocity constraints */
  int st = mb_sim_project(s, 0, s->q, s->v);
  if (st) {
    snprintf(info->why, sizeof info->why, "the projection of the velocities onto the constraints at "
             "the equilibrium failed (%s)", mb_status_text(st));
    return st;
  }
  return MB_OK;
}
