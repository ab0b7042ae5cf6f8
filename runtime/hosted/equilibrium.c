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
 * free direction with load is either a turning point of the potential (a
 * pendulum released horizontally: zero curvature there), passed by damped
 * steps of pseudo-transient continuation (the tangent less sigma M, as a step
 * of damped motion), or no equilibrium (a body free under gravity: no such
 * step lowers the residual), reported with the body and direction.  A
 * backtracking line search on the residual norm damps the Newton steps.  The
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
#define EQ_RANK_TOL 1e-4    /* pivots below this fraction of the largest: a free direction */
#define EQ_NOISE 1e-3       /* tangent columns below this (force scale per unit): round-off */
#else
#define EQ_FORCE_TOL 1e-10
#define EQ_FD_STEP 1e-6
#define EQ_RANK_TOL 1e-9
#define EQ_NOISE 1e-7
#endif
#define EQ_MAX_ITERATIONS 200
#define EQ_MAX_UNKNOWNS 4000 /* the dense tangent: n^2 reals */

typedef struct {
  mb_sim *s;
  const mb_model *m;
  int nv, nc, n;
  double scale;          /* force scale F (N): force rows are divided by it, mu = lambda / F */
  mb_real *vzero, *qt, *dv;
  double *R, *Rp, *Rm, *J, *x, *mu, *mut, *colscale, *mass;
  int *dslot;
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

/* At rest at q: the multipliers of K [a; lambda] = [f; 0] (v = 0) into mu
 * (lambda / F), and R(q, mu) into R; MB_OK or the solver's status */
static int rest_solve(eq_work *e, const mb_real *q, double *mu, double *R) {
  mb_sim *s = e->s;
  int nv = e->nv;
  residual(e, q, mu, R);
  int st = s->ls->factor(s->ls, s->Kx);
  s->factored_valid = 0;
  if (st) return st;
  for (int i = 0; i < nv; i++) s->x[i] = s->rhs[i];
  for (int r = 0; r < e->nc; r++) s->x[nv + r] = 0;
  st = s->ls->solve(s->ls, s->x);
  if (st) return st;
  for (int i = 0; i < nv + e->nc; i++)
    if (!isfinite((double)s->x[i])) return MB_ERR_NONFINITE;
  for (int r = 0; r < e->nc; r++) mu[r] = (double)s->x[nv + r] / e->scale;
  residual(e, q, mu, R);
  return MB_OK;
}

/* The multipliers that fit the load best at q, min |f/F - D^T mu| (normal
 * equations D D^T mu = D f / F, slightly regularized for redundant rows),
 * into mu, and R(q, mu) into R: what is left is the load the constraints
 * cannot take.  Uses e->J as scratch.  MB_OK or MB_ERR_SINGULAR. */
static int fitted_residual(eq_work *e, const mb_real *q, double *mu, double *R) {
  const mb_model *m = e->m;
  int nv = e->nv, nc = e->nc;
  for (int r = 0; r < nc; r++) mu[r] = 0;
  residual(e, q, mu, R); /* R = f / F, Kx holds D(q) */
  if (nc == 0) return MB_OK;
  double *D = e->J, *G = e->J + (size_t)nc * (size_t)nv; /* nc x nv and nc x nc, column-major */
  memset(D, 0, sizeof(double) * (size_t)nc * (size_t)nv);
  for (int j = 0; j < nv; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] >= nv) D[(m->Ki[p] - nv) + (size_t)nc * j] = (double)e->s->Kx[p];
  double gmax = 0;
  for (int a = 0; a < nc; a++) {
    double b = 0;
    for (int j = 0; j < nv; j++) b += D[a + (size_t)nc * j] * R[j];
    mu[a] = b;
    for (int c = 0; c <= a; c++) {
      double g = 0;
      for (int j = 0; j < nv; j++) g += D[a + (size_t)nc * j] * D[c + (size_t)nc * j];
      G[a + (size_t)nc * c] = G[c + (size_t)nc * a] = g;
    }
    gmax = fmax(gmax, G[a + (size_t)nc * a]);
  }
  for (int a = 0; a < nc; a++) G[a + (size_t)nc * a] += 1e-12 * gmax;
  /* Cholesky G = L L^T in the lower triangle, then the two solves */
  for (int c = 0; c < nc; c++) {
    double d = G[c + (size_t)nc * c];
    for (int k = 0; k < c; k++) d -= G[c + (size_t)nc * k] * G[c + (size_t)nc * k];
    if (!(d > 0)) return MB_ERR_SINGULAR;
    d = sqrt(d);
    G[c + (size_t)nc * c] = d;
    for (int a = c + 1; a < nc; a++) {
      double v = G[a + (size_t)nc * c];
      for (int k = 0; k < c; k++) v -= G[a + (size_t)nc * k] * G[c + (size_t)nc * k];
      G[a + (size_t)nc * c] = v / d;
    }
  }
  for (int a = 0; a < nc; a++) {
    for (int k = 0; k < a; k++) mu[a] -= G[a + (size_t)nc * k] * mu[k];
    mu[a] /= G[a + (size_t)nc * a];
  }
  for (int a = nc - 1; a >= 0; a--) {
    for (int k = a + 1; k < nc; k++) mu[a] -= G[k + (size_t)nc * a] * mu[k];
    mu[a] /= G[a + (size_t)nc * a];
  }
  residual(e, q, mu, R);
  return MB_OK;
}

static void eq_free(eq_work *e) {
  free(e->vzero); free(e->qt); free(e->dv); free(e->R); free(e->Rp); free(e->Rm); free(e->J);
  free(e->x); free(e->mu); free(e->mut); free(e->rowp); free(e->colp); free(e->colscale);
  free(e->mass); free(e->dslot);
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
  e.colscale = calloc((size_t)n + 1, sizeof(double));
  e.mass = calloc((size_t)nv + 1, sizeof(double));
  e.dslot = calloc((size_t)nv + 1, sizeof(int));
  if (!e.colscale || !e.mass || !e.dslot || !e.vzero || !e.qt || !e.dv || !e.R || !e.Rp || !e.Rm ||
      !e.J || !e.x || !e.mu || !e.mut ||
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
  if (e.nc > 0 && rest_solve(&e, q, e.mu, e.R))
    for (int r = 0; r < e.nc; r++) e.mu[r] = 0;

  /* the mass diagonal's slots in K (0 mass: a virtual body) */
  for (int j = 0; j < nv; j++) {
    e.dslot[j] = -1;
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] == j) e.dslot[j] = p;
  }
  int status = MB_OK;
  /* Pseudo-transient continuation where the tangent is singular along a
     loaded direction: a turning point of the potential (a pendulum or a
     hinged chain released horizontally, zero curvature there) or no
     equilibrium at all (a body free under gravity).  The tangent gets
     -sigma M on its diagonal, as a step of damped motion would, so the step
     follows the load; sigma shrinks with the residual (switched evolution
     relaxation) until it is plain Newton again, and grows when no step
     lowers the residual.  sigma0 moves the most loaded coordinate 0.1 m or
     rad. */
  double sigma = 0, sigma0 = 0;
  int damped_steps = 0;
  char free_cause[sizeof info->why] = "";
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
      if (free_cause[0] && damped_steps > 0)
        snprintf(info->why, sizeof info->why, "Newton found the static tangent singular along a loaded "
                 "direction (a turning point, e.g. a mechanism released horizontally), and %d damped "
                 "steps from there did not converge in %d iterations (force residual %.3g of the force "
                 "scale %.4g N, constraint residual %.3g): start the model nearer its rest position",
                 damped_steps, it, fres, e.scale, cres);
      else
        snprintf(info->why, sizeof info->why, "Newton did not converge in %d iterations: force "
                 "residual %.3g of the force scale %.4g N, constraint residual %.3g", it, fres, e.scale, cres);
      status = MB_ERR_NEWTON;
      break;
    }
    /* in damped motion the multipliers are fitted to the load: a turning
       point's progress shows in the residual only with them (the load turns,
       its size stays, until the constraints take the part along them) */
    if (sigma > 0 && fitted_residual(&e, q, e.mu, e.R)) residual(&e, q, e.mu, e.R);
    /* the tangent: constraint rows D and multiplier columns -D^T from K's pattern */
    double *J = e.J;
    memset(J, 0, sizeof(double) * (size_t)n * (size_t)n);
    for (int j = 0; j < nv; j++)
      for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
        if (m->Ki[p] >= nv) {
          J[m->Ki[p] + (size_t)n * j] = (double)s->Kx[p];
          J[j + (size_t)n * m->Ki[p]] = -(double)s->Kx[p];
        }
    for (int j = 0; j < nv; j++) e.mass[j] = e.dslot[j] >= 0 ? (double)s->Kx[e.dslot[j]] / e.scale : 0;
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
      J[j + (size_t)n * j] -= sigma * e.mass[j];
    }
    /* columns scaled to a largest entry of 1, so that a stiff mode (omega^2 of
       1e8) does not make the constraint columns look like round-off; a column
       of round-off only (a direction without stiffness) becomes exactly 0 */
    for (int j = 0; j < n; j++) {
      double cmax = max_abs_range(J + (size_t)n * j, 0, n);
      e.colscale[j] = cmax > EQ_NOISE ? 1 / cmax : 0;
      for (int i = 0; i < n; i++) J[i + (size_t)n * j] *= e.colscale[j];
    }
    for (int i = 0; i < n; i++) e.Rm[i] = -e.R[i];
    double left;
    int left_row;
    int rank = solve_complete(n, J, e.Rm, e.x, e.rowp, e.colp, EQ_RANK_TOL, &left, &left_row);
    for (int j = 0; j < n; j++) e.x[j] *= e.colscale[j];
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
      if (left_row < nv && sigma == 0) {
        /* a turning point or no equilibrium: continue as damped motion */
        snprintf(free_cause, sizeof free_cause, "%s", info->why);
        double amax = 0;
        for (int j = 0; j < nv; j++)
          if (e.mass[j] > 0) amax = fmax(amax, fabs(e.R[j]) / e.mass[j]);
        sigma = sigma0 = amax / 0.1;
        if (sigma > 0) continue;
      }
      if (free_cause[0]) snprintf(info->why, sizeof info->why, "%s", free_cause);
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
      if (sigma > 0) {
        if (fitted_residual(&e, e.qt, e.mut, e.Rp)) continue;
        if (half_square_norm(e.Rp, n) < (1 - 1e-10) * merit0) { accepted = 1; break; }
        continue;
      }
      residual(&e, e.qt, e.mut, e.Rp);
      double merit = half_square_norm(e.Rp, n);
      if (merit <= (1 - 1e-4 * alpha) * merit0) { accepted = 1; break; }
    }
    for (int i = 0; i < nv; i++) e.dv[i] = 0;
    if (!accepted && sigma > 0 && sigma < 1e8 * sigma0) {
      sigma *= 10; /* shorter, more motion-like steps */
      residual(&e, q, e.mu, e.R);
      continue;
    }
    if (!accepted) {
      if (free_cause[0])
        snprintf(info->why, sizeof info->why, "%s", free_cause);
      else
        snprintf(info->why, sizeof info->why, "the line search found no step that lowers the residual "
                 "after %d iterations (force residual %.3g of the force scale %.4g N, constraint residual "
                 "%.3g): no equilibrium reachable from the start", it, fres, e.scale, cres);
      status = free_cause[0] ? MB_ERR_SINGULAR : MB_ERR_NEWTON;
      break;
    }
    memcpy(q, e.qt, sizeof(mb_real) * (size_t)m->nq);
    memcpy(e.mu, e.mut, sizeof(double) * (size_t)e.nc);
    memcpy(e.R, e.Rp, sizeof(double) * (size_t)n);
    if (sigma > 0) {
      damped_steps++;
      info->damped_steps = damped_steps;
      sigma *= sqrt(half_square_norm(e.R, n) / merit0);
      if (sigma < 1e-10 * sigma0) sigma = 0;
    }
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
