/* integrate.c: RK4 and Dormand-Prince 5(4) on y = [q; v], with the
 * accelerations from K [vdot; lambda] = [f; gamma] on the fixed pattern. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include "mb_sim.h"
#include "mb_step.h" /* the fixed-step RK4 it shares with the core */

double mb_sim_clock(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* the per-call clock: a system call's worth of time, so only with timers on */
static double sim_clock(const mb_sim *s) { return s->set.timers ? mb_sim_clock() : 0; }

void mb_settings_default(mb_settings *s) {
  s->integrator = MB_DOPRI5;
  s->end_time = 1;
  s->output_step = 0.01;
  s->step = 1e-3;
  s->rtol = 1e-6;
  s->atol = 1e-8;
  s->min_step = 1e-12;
  s->max_step = 0.01;
  s->stabilization = MB_STAB_PROJECTION;
  s->alpha = 10;
  s->beta = 10;
#ifdef MB_REAL_FLOAT
  s->projection_tol = 1e-5; /* single precision: about 100 ulp of unit coordinates */
#else
  s->projection_tol = 1e-10;
#endif
  s->rho_inf = 0.8;
  s->max_steps = 1e7;
  s->timers = 1;
  s->equilibrium = 0;
}

int mb_sim_fail(mb_sim *s, double t, int status, const char *what) {
  s->fail_time = t;
  snprintf(s->fail_detail, sizeof s->fail_detail, "%s: %s", what, mb_status_text(status));
  return status;
}

int mb_sim_fail_at(mb_sim *s, double t, const mb_real *q, const mb_real *v, int status, const char *what) {
  if (s->fail_q && q != s->fail_q) memcpy(s->fail_q, q, sizeof(mb_real) * (size_t)s->m->nq);
  if (s->fail_v && v != s->fail_v) memcpy(s->fail_v, v, sizeof(mb_real) * (size_t)s->m->nv);
  s->fail_state = s->fail_q && s->fail_v;
  s->fail_state_t = t;
  return mb_sim_fail(s, t, status, what);
}

int mb_sim_init(mb_sim *s, const mb_model *m, mb_solver *ls, const mb_settings *set) {
  memset(s, 0, sizeof *s);
  s->m = m;
  s->ls = ls;
  /* every factor() here gets s->Kx (or genalpha's iteration matrix), and
     neither changes before the next factor(): s->Kx is evaluated again only
     at a new q (then factored) or at the factored q (the same values) */
  ls->kx_stable = 1;
  s->set = *set;
  if (s->set.integrator == MB_AUTO) s->set.integrator = mb_integrator_auto(m, set, NULL, 0);
  size_t ny = (size_t)(m->nq + m->nv);
  s->q = calloc((size_t)m->nq + 1, sizeof(mb_real));
  s->v = calloc((size_t)m->nv + 1, sizeof(mb_real));
  s->Kx = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  s->rhs = calloc((size_t)m->n + 1, sizeof(mb_real));
  s->x = calloc((size_t)m->n + 1, sizeof(mb_real));
  s->phi = calloc((size_t)m->nc + 1, sizeof(mb_real));
  s->nu = calloc((size_t)m->nc + 1, sizeof(mb_real));
  s->y = calloc(ny + 1, sizeof(mb_real));
  s->ytmp = calloc(ny + 1, sizeof(mb_real));
  for (int i = 0; i < 7; i++) s->k[i] = calloc(ny + 1, sizeof(mb_real));
  s->qsave = calloc((size_t)m->nq + 1, sizeof(mb_real));
  s->dv = calloc((size_t)m->n + 1, sizeof(mb_real));
  s->work = malloc(mb_model_worksize(m) + 16);
  s->yout = calloc(ny + 1, sizeof(mb_real));
  s->fail_q = calloc((size_t)m->nq + 1, sizeof(mb_real));
  s->fail_v = calloc((size_t)m->nv + 1, sizeof(mb_real));
  s->angle_hmax = INFINITY;
  if (!s->yout || !s->fail_q || !s->fail_v || !s->q || !s->v || !s->Kx || !s->rhs || !s->x || !s->phi || !s->nu || !s->y || !s->ytmp ||
      !s->qsave || !s->dv || !s->work)
    return MB_ERR_NOMEM;
  for (int i = 0; i < 7; i++)
    if (!s->k[i]) return MB_ERR_NOMEM;
  if (ls->bind) ls->bind(ls, s->work);
  memcpy(s->q, m->q0, sizeof(mb_real) * (size_t)m->nq);
  memcpy(s->v, m->v0, sizeof(mb_real) * (size_t)m->nv);
  m->init(m, s->Kx);
  if (set->end_time <= 0 || set->output_step <= 0 || set->step <= 0) return MB_ERR_INVALID;
  return MB_OK;
}

void mb_sim_free(mb_sim *s) {
  free(s->q); free(s->v); free(s->Kx); free(s->rhs); free(s->x); free(s->phi); free(s->nu);
  free(s->y); free(s->ytmp); free(s->qsave); free(s->dv); free(s->work); free(s->yout);
  free(s->fail_q); free(s->fail_v);
  for (int i = 0; i < 7; i++) free(s->k[i]);
  memset(s, 0, sizeof *s);
}

/* evaluate K and the right side at (t, q, v); factor unless q is the one
 * already factored (K depends on q only) */
static int assemble_factor(mb_sim *s, double t, const mb_real *q, const mb_real *v) {
  const mb_model *m = s->m;
  double t0 = sim_clock(s);
  m->eval(m, t, q, v, s->Kx, s->rhs, s->phi, s->nu, s->work);
  s->stats.evals++;
  double t1 = sim_clock(s);
  s->stats.t_assembly += t1 - t0;
  if (s->factored_valid && !memcmp(q, s->qsave, sizeof(mb_real) * (size_t)m->nq)) return MB_OK;
  int st = s->ls->factor(s->ls, s->Kx);
  s->stats.t_solve += sim_clock(s) - t1;
  if (st) { s->factored_valid = 0; return st; }
  if (s->ls->rcond > 0) { /* watch for near-singular configurations */
    if (s->stats.rcond_first == 0) s->stats.rcond_first = s->stats.rcond_min = s->ls->rcond;
    if (s->ls->rcond < s->stats.rcond_min) { s->stats.rcond_min = s->ls->rcond; s->stats.rcond_min_t = t; }
  }
  memcpy(s->qsave, q, sizeof(mb_real) * (size_t)m->nq);
  s->factored_valid = 1;
  return MB_OK;
}

static int solve(mb_sim *s, mb_real *b) {
  double t0 = sim_clock(s);
  int st = s->ls->solve(s->ls, b);
  s->stats.solves++;
  s->stats.t_solve += sim_clock(s) - t0;
  if (st || s->ls->checks_finite) return st;
  int finite = 1; /* x - x is 0 for a finite x, NaN otherwise: no branch per entry */
  for (int i = 0; i < s->m->n; i++) finite &= b[i] - b[i] == 0;
  return finite ? st : MB_ERR_NONFINITE;
}

int mb_sim_accel(mb_sim *s, double t, const mb_real *q, const mb_real *v, mb_real *vd,
                 mb_real *lambda) {
  const mb_model *m = s->m;
  int st = assemble_factor(s, t, q, v);
  if (st) return mb_sim_fail_at(s, t, q, v, st, "factorization of K");
  if (s->set.stabilization == MB_STAB_BAUMGARTE) {
    /* gamma - 2 alpha phidot - beta^2 phi */
    for (int r = 0; r < m->nc; r++)
      s->rhs[m->nv + r] -= 2 * s->set.alpha * s->nu[r] + s->set.beta * s->set.beta * s->phi[r];
  }
  memcpy(s->x, s->rhs, sizeof(mb_real) * (size_t)m->n);
  st = solve(s, s->x);
  if (st) return mb_sim_fail_at(s, t, q, v, st, "solution for the accelerations");
  memcpy(vd, s->x, sizeof(mb_real) * (size_t)m->nv);
  if (lambda) memcpy(lambda, s->x + m->nv, sizeof(mb_real) * (size_t)m->nc);
  return MB_OK;
}

static double max_abs(const mb_real *a, int n) {
  double mx = 0;
  for (int i = 0; i < n; i++)
    if (fabs(a[i]) > mx || a[i] != a[i]) mx = (a[i] != a[i]) ? INFINITY : fabs(a[i]);
  return mx;
}

int mb_sim_project(mb_sim *s, double t, mb_real *q, mb_real *v) {
  const mb_model *m = s->m;
  int n = m->n, nv = m->nv;
  mb_model_normalize(m, q);
  /* positions: Newton on phi(q) = 0 with the mass-weighted least correction,
     K [dq; mu] = [0; -phi] */
  for (int it = 0;; it++) {
    int st = assemble_factor(s, t, q, v);
    if (st) return mb_sim_fail_at(s, t, q, v, st, "projection");
    if (max_abs(s->phi, m->nc) <= s->set.projection_tol) break;
    if (it >= 8) return mb_sim_fail_at(s, t, q, v, MB_ERR_PROJECTION, "position projection");
    for (int i = 0; i < nv; i++) s->dv[i] = 0;
    for (int r = 0; r < m->nc; r++) s->dv[nv + r] = -s->phi[r];
    st = solve(s, s->dv);
    if (st) return mb_sim_fail_at(s, t, q, v, st, "position projection");
    mb_model_qincrement(m, q, s->dv);
    mb_model_normalize(m, q);
    s->stats.projections++;
  }
  /* velocities: K [dv; mu] = [0; -phid] (K is factored at this q; phid = D v - nu) */
  for (int i = 0; i < nv; i++) s->dv[i] = 0;
  for (int r = 0; r < m->nc; r++) s->dv[nv + r] = -s->nu[r];
  int st = solve(s, s->dv);
  if (st) return mb_sim_fail_at(s, t, q, v, st, "velocity projection");
  for (int i = 0; i < nv; i++) v[i] += s->dv[i];
  (void)n;
  return MB_OK;
}

/* dy = f(t, y): y = [q; v], dy = [G(q) v; vdot] */
static int deriv(mb_sim *s, double t, const mb_real *y, mb_real *dy) {
  const mb_model *m = s->m;
  const mb_real *q = y, *v = y + m->nq;
  int st = mb_sim_accel(s, t, q, v, dy + m->nq, NULL);
  if (st) return st;
  mb_model_qdot(m, q, v, dy);
  return MB_OK;
}

/* mb_rk4_step's stage derivative at t + c h (the time in double) */
typedef struct {
  mb_sim *s;
  double t, h;
} rk4_stage_ctx;

static int rk4_stage_deriv(void *ctx, mb_real c, const mb_real *y, mb_real *dy) {
  const rk4_stage_ctx *r = (const rk4_stage_ctx *)ctx;
  return deriv(r->s, r->t + (double)c * r->h, y, dy);
}

/* after a step: stabilize and check the state */
int mb_sim_finish_step(mb_sim *s, double t) {
  const mb_model *m = s->m;
  if (s->set.stabilization == MB_STAB_PROJECTION) {
    int st = mb_sim_project(s, t, s->q, s->v);
    if (st) return st;
  } else {
    mb_model_normalize(m, s->q);
  }
  for (int i = 0; i < m->nq; i++)
    if (!isfinite(s->q[i])) return mb_sim_fail(s, t, MB_ERR_NONFINITE, "positions");
  for (int i = 0; i < m->nv; i++)
    if (!isfinite(s->v[i])) return mb_sim_fail(s, t, MB_ERR_NONFINITE, "velocities");
  s->angle_hmax = mb_model_angle_step(m, s->q, s->v, s->work);
  if (s->on_step) s->on_step(s->on_step_user, t, s->q, s->v);
  return MB_OK;
}

/* Dormand-Prince 5(4) tableau */
static const double DP_C[7] = {0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1, 1};
static const double DP_A[7][6] = {
    {0},
    {1.0 / 5},
    {3.0 / 40, 9.0 / 40},
    {44.0 / 45, -56.0 / 15, 32.0 / 9},
    {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729},
    {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656},
    {35.0 / 384, 0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84}};
/* error weights: b5 - b4 */
static const double DP_E[7] = {71.0 / 57600, 0, -71.0 / 16695, 71.0 / 1920, -17253.0 / 339200,
                               22.0 / 525, -1.0 / 40};

/* Dormand-Prince stage j (1..6): ytmp = y + h sum a_j k_j with the tableau's
 * row as constants and its zeros dropped, summed in the row's order.
 * A loop over the stages for every state costs about three times as many
 * instructions.  The states go in pairs, two like statements that the C
 * compiler turns into one two-wide vector operation each (SLP at -O2); with
 * an odd ny the last pair reads and writes element ny, the spare one every
 * stage array has (mb_sim_init allocates ny + 1; y[ny] and k_j[ny] stay 0,
 * and the model never reads out[ny]). */
#define DP_PAIRS(E)                                                                                \
  for (int i = 0; i < ny; i += 2) {                                                                \
    { const int l = i; out[l] = y[l] + h * (E); }                                                  \
    { const int l = i + 1; out[l] = y[l] + h * (E); }                                              \
  }
static void dp_stage(int ny, const mb_real *restrict y, double h, mb_real *const *k, int j,
                     mb_real *restrict out) {
  const mb_real *k0 = k[0], *k1 = k[1], *k2 = k[2], *k3 = k[3], *k4 = k[4], *k5 = k[5];
  const double *a = DP_A[j];
  switch (j) {
  case 1: DP_PAIRS(a[0] * k0[l]); break;
  case 2: DP_PAIRS(a[0] * k0[l] + a[1] * k1[l]); break;
  case 3: DP_PAIRS(a[0] * k0[l] + a[1] * k1[l] + a[2] * k2[l]); break;
  case 4: DP_PAIRS(a[0] * k0[l] + a[1] * k1[l] + a[2] * k2[l] + a[3] * k3[l]); break;
  case 5: DP_PAIRS(a[0] * k0[l] + a[1] * k1[l] + a[2] * k2[l] + a[3] * k3[l] + a[4] * k4[l]); break;
  default: /* 6: a[1] = 0 */
    DP_PAIRS(a[0] * k0[l] + a[2] * k2[l] + a[3] * k3[l] + a[4] * k4[l] + a[5] * k5[l]);
    break;
  }
}
#undef DP_PAIRS

/* the error estimate's weighted RMS norm (DP_E[1] = 0 dropped) */
static double dp_error(int ny, const mb_real *y, const mb_real *y5, double h, mb_real *const *k,
                       double atol, double rtol) {
  const mb_real *k0 = k[0], *k2 = k[2], *k3 = k[3], *k4 = k[4], *k5 = k[5], *k6 = k[6];
  double err = 0;
  for (int i = 0; i < ny; i++) {
    double e = DP_E[0] * k0[i] + DP_E[2] * k2[i] + DP_E[3] * k3[i] + DP_E[4] * k4[i] + DP_E[5] * k5[i] +
               DP_E[6] * k6[i];
    e *= h;
    double sc = atol + rtol * fmax(fabs(y[i]), fabs(y5[i]));
    err += (e / sc) * (e / sc);
  }
  return sqrt(err / ny);
}

int mb_sim_step_budget(mb_sim *s, double h) {
  s->fail_state = 0; /* a new step: what failed in the last one's attempts no longer matters */
  if ((double)(s->stats.steps + s->stats.rejected) < s->set.max_steps) return MB_OK;
  s->fail_time = s->t;
  snprintf(s->fail_detail, sizeof s->fail_detail,
           "%ld steps (%ld rejected) reached max_steps %.3g at t = %.6g s (last step %.3g s)",
           s->stats.steps, s->stats.rejected, s->set.max_steps, s->t, h);
  return MB_ERR_STEP_BUDGET;
}

const char *mb_integrator_name(int integrator) {
  switch (integrator) {
  case MB_RK4: return "rk4";
  case MB_DOPRI5: return "dopri5";
  case MB_GENALPHA: return "genalpha";
  case MB_AUTO: return "auto";
  default: return "unknown";
  }
}

/* the largest |eigenvalue| of one spring-damper degree of freedom k, c
 * on a mass m: c/2m + sqrt((c/2m)^2 + k/m) (omega when undamped, about c/m
 * when overdamped) */
static double dof_rate(double k, double c, double m) {
  if (!(m > 0)) return 0;
  double a = fmax(c, 0) / (2 * m);
  return a + sqrt(a * a + fmax(k, 0) / m);
}

/* the mass (rot 0) or smallest principal-axis inertia bound (rot 1) a force
 * element's side moves: 0 on the ground or a massless (virtual) body */
static double side_inertia(const mb_model *m, int marker, int rot) {
  int b = marker >= 0 ? m->marker[marker].body : -1;
  if (b < 0) return 0;
  const mb_body *B = &m->body[b];
  if (!rot) return (double)B->mass;
  return fmin((double)B->J[0], fmin((double)B->J[4], (double)B->J[8]));
}

/* the reduced mass of the two sides (one side on the ground: the other's) */
static double reduced(double a, double b) {
  if (a > 0 && b > 0) return a * b / (a + b);
  return a > 0 ? a : b;
}

/* a law's largest slope: linear coefficient or table segment (power laws
 * have no bound: not weighed) */
static double law_slope(const mb_law *l) {
  if (l->kind == MB_LAW_LINEAR) return fabs((double)l->coef);
  if (l->kind != MB_LAW_TABLE) return 0;
  double k = 0;
  for (int i = 0; i + 1 < l->ntable; i++) {
    double dx = (double)(l->table[2 * i + 2] - l->table[2 * i]);
    if (dx > 0) k = fmax(k, fabs((double)(l->table[2 * i + 3] - l->table[2 * i + 1])) / dx);
  }
  return k;
}

/* the fastest rate of force element e, as one degree of freedom per
 * direction: stiffness and damping on the diagonal of the element's
 * matrices against the reduced mass (translations) or the smallest inertia
 * (rotations) of the bodies it joins.  An estimate (lever arms and
 * couplings between directions are left out), like the modes' sqrt(k). */
static double force_rate(const mb_model *m, int e) {
  const mb_forcedef *d = &m->force[e];
  double mt = reduced(side_inertia(m, d->m0, 0), side_inertia(m, d->m1, 0));
  double jr = reduced(side_inertia(m, d->m0, 1), side_inertia(m, d->m1, 1));
  double rate = 0;
  if (d->kind == MB_FORCE_SPRING) {
    double k = law_slope(&m->force_law[d->ladr]);
    double c = d->lnum > 1 ? law_slope(&m->force_law[d->ladr + 1]) : 0;
    rate = dof_rate(k, c, mt);
  } else if (d->kind == MB_FORCE_FIELD) {
    const mb_real *K = m->force_prm + d->padr + MB_FIELD_K, *C = m->force_prm + d->padr + MB_FIELD_C;
    for (int i = 0; i < 6; i++)
      rate = fmax(rate, dof_rate((double)K[7 * i], (double)C[7 * i], i < 3 ? mt : jr));
  } else if (d->kind == MB_FORCE_TYRE) { /* the radial spring-damper on the wheel */
    const mb_real *prm = m->force_prm + d->padr;
    rate = dof_rate((double)prm[MB_TYRE_KZ], (double)prm[MB_TYRE_CZ], mt);
  }
  return rate;
}

/* The stiffness an explicit method must resolve comes from the highest modal
 * frequency and from the stiffest force element (force_rate): Dormand-Prince
 * is stable for |h lambda| up to about 3.3, so a rate |lambda| caps its step
 * at 3.3 / |lambda|.  When that cap is below a tenth of the output step (the
 * step the explicit method could otherwise take), the implicit method is
 * cheaper. */
int mb_integrator_auto(const mb_model *m, const mb_settings *set, char *why, size_t nwhy) {
  double wmax = 0, fmax_rate = 0;
  const char *body = NULL;
  int force = -1;
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (B->kind != MB_BODY_FLEXIBLE || !B->flex) continue;
    for (int j = 0; j < B->nm; j++)
      if (sqrt((double)B->flex->stiffness[j]) > wmax) { wmax = sqrt((double)B->flex->stiffness[j]); body = B->name; }
  }
  for (int e = 0; e < m->nforce; e++) {
    double r = force_rate(m, e);
    if (r > fmax_rate) { fmax_rate = r; force = e; }
  }
  double rate = fmax(wmax, fmax_rate);
  double hstab = rate > 0 ? 3.3 / rate : INFINITY;
  double hwant = fmin(set->output_step, set->max_step);
  int implicit = hstab < 0.1 * hwant;
  if (why && nwhy) {
    if (!body && force < 0) {
      snprintf(why, nwhy, "dopri5: the model has no flexible modes and no stiff force elements, so nothing stiff for an explicit method");
    } else if (force >= 0 && fmax_rate >= wmax) {
      const mb_forcedef *d = &m->force[force];
      int b0 = m->marker[d->m0].body, b1 = d->m1 >= 0 ? m->marker[d->m1].body : -1;
      snprintf(why, nwhy,
               "%s: the stiffest force element (%s %d, between %s and %s, rate %.4g 1/s as "
               "k/m and c/m of the bodies it joins) limits an explicit step to %.3g s for "
               "stability, %s a tenth of the output step %.3g s",
               implicit ? "genalpha" : "dopri5",
               d->kind == MB_FORCE_SPRING ? "spring" : d->kind == MB_FORCE_TYRE ? "tyre" : "field",
               force, b0 >= 0 ? m->body[b0].name : "ground", b1 >= 0 ? m->body[b1].name : "ground",
               fmax_rate, hstab, implicit ? "below" : "above", hwant);
    } else {
      snprintf(why, nwhy,
               "%s: the highest mode (%s, %.4g Hz) limits an explicit step to %.3g s for stability, "
               "%s a tenth of the output step %.3g s",
               implicit ? "genalpha" : "dopri5", body, wmax / (2 * MB_PI), hstab,
               implicit ? "below" : "above", hwant);
    }
  }
  return implicit ? MB_GENALPHA : MB_DOPRI5;
}

/* Dormand-Prince's continuous extension (the dense output of Hairer, Norsett
 * and Wanner, II.6): y(t + theta h) from the step's start y0, its end y1 and
 * its stages, fifth order in the step like the step itself */
static const double DP_D[7] = {-12715105075.0 / 11282082432.0, 0, 87487479700.0 / 32700410799.0,
                               -10690763975.0 / 1880347072.0, 701980252875.0 / 199316789632.0,
                               -1453857185.0 / 822651844.0, 69997945.0 / 29380423.0};
/* written out like dp_stage (DP_D[1] = 0 dropped, the sum in the row's
 * order): a loop over the stages per state cost three times the instructions */
static void dp_dense(int ny, const mb_real *restrict y0, const mb_real *restrict y1, mb_real *const *k,
                     double h, double theta, mb_real *restrict out) {
  const mb_real *k0 = k[0], *k2 = k[2], *k3 = k[3], *k4 = k[4], *k5 = k[5], *k6 = k[6];
  double theta1 = 1 - theta;
  for (int i = 0; i < ny; i++) {
    double ydiff = y1[i] - y0[i];
    double bspl = h * k0[i] - ydiff;
    double r4 = ydiff - h * k6[i] - bspl;
    double r5 = DP_D[0] * k0[i] + DP_D[2] * k2[i] + DP_D[3] * k3[i] + DP_D[4] * k4[i] + DP_D[5] * k5[i] +
                DP_D[6] * k6[i];
    r5 *= h;
    out[i] = y0[i] + theta * (ydiff + theta1 * (bspl + theta * (r4 + theta1 * r5)));
  }
}

/* the accelerations at the step's end (s->q, s->v, already stabilized by
 * mb_sim_finish_step): the next step's first stage k[0], and the output row
 * when one falls there */
static int dp_first_stage(mb_sim *s, mb_real *vd, mb_real *lam) {
  const mb_model *m = s->m;
  int st = mb_sim_accel(s, s->t, s->q, s->v, vd, lam);
  if (st) return st;
  memcpy(s->k[0] + m->nq, vd, sizeof(mb_real) * (size_t)m->nv);
  mb_model_qdot(m, s->q, s->v, s->k[0]);
  return MB_OK;
}

/* hand one row to the caller: (t, q, v) consistent and vd, lam its
 * accelerations and multipliers (s->phi from the same evaluation) */
static void dp_emit(mb_sim *s, double t, const mb_real *q, const mb_real *v, const mb_real *vd,
                    const mb_real *lam, mb_output_fn out, void *user, int *stop) {
  double mx = max_abs(s->phi, s->m->nc);
  if (mx > s->stats.max_phi) s->stats.max_phi = mx;
  *stop = out && out(user, t, q, v, vd, lam);
}

/* one output row at an interpolated (t, q, v): a consistent state, then its
 * accelerations */
static int dp_output(mb_sim *s, double t, mb_real *q, mb_real *v, mb_real *vd, mb_real *lam,
                     mb_output_fn out, void *user, int *stop) {
  const mb_model *m = s->m;
  int st;
  if (s->set.stabilization == MB_STAB_PROJECTION) st = mb_sim_project(s, t, q, v);
  else { mb_model_normalize(m, q); st = MB_OK; }
  if (!st) st = mb_sim_accel(s, t, q, v, vd, lam);
  if (st) {
    /* the failure is at this row's state, not at the last step's: that is
       the state the diagnosis (a singular configuration?) must look at */
    if (q != s->q) memcpy(s->q, q, sizeof(mb_real) * (size_t)m->nq);
    if (v != s->v) memcpy(s->v, v, sizeof(mb_real) * (size_t)m->nv);
    s->t = t;
    return st;
  }
  dp_emit(s, t, q, v, vd, lam, out, user, stop);
  return MB_OK;
}

/* Adaptive Dormand-Prince 5(4).  The steps follow the error control alone:
 * output rows inside a step come from the continuous extension, so the output
 * grid neither caps nor changes the steps (only the last one ends on the last
 * output time).  Per accepted step: the six stages (an evaluation and a
 * factorization each), the projection at the new positions (one of each,
 * then the velocity correction's solve) and the accelerations at the
 * stabilized state (an evaluation, K already factored), which are both the
 * output row at the step's end and the next step's first stage. */
static int dp_run(mb_sim *s, mb_output_fn out, void *user) {
  const mb_model *m = s->m;
  const mb_settings *set = &s->set;
  int nq = m->nq, nv = m->nv, ny = nq + nv;
  mb_real *vd = malloc(sizeof(mb_real) * (size_t)(nv + 1));
  mb_real *lam = malloc(sizeof(mb_real) * (size_t)(m->nc + 1));
  if (!vd || !lam) { free(vd); free(lam); return MB_ERR_NOMEM; }
  int st = MB_OK, stop = 0;
  s->t = 0;
  long nout = (long)floor(set->end_time / set->output_step + 1e-9), iout = 0;
  double t_end = (double)nout * set->output_step, tiny = 1e-9 * set->output_step;
  double h = fmin(set->step, set->max_step);
  if (set->stabilization != MB_STAB_PROJECTION) mb_model_normalize(m, s->q);
  else if ((st = mb_sim_project(s, 0, s->q, s->v))) goto done;
  s->angle_hmax = mb_model_angle_step(m, s->q, s->v, s->work);
  if ((st = dp_first_stage(s, vd, lam))) goto done;
  dp_emit(s, 0, s->q, s->v, vd, lam, out, user, &stop);
  if (stop) goto done;
  iout = 1;
  int first_stage_ready = 1; /* k[0] holds the derivative at (s->t, s->q, s->v) */
  while (iout <= nout) {
    if ((st = mb_sim_step_budget(s, h))) goto done;
    /* the first stage at (t, y) */
    memcpy(s->y, s->q, sizeof(mb_real) * (size_t)nq);
    memcpy(s->y + nq, s->v, sizeof(mb_real) * (size_t)nv);
    if (!first_stage_ready && (st = dp_first_stage(s, vd, lam))) goto done;
    first_stage_ready = 0;
    double hrest = t_end - s->t, hh;
    char stage_failure[160] = ""; /* why a stage failed in this step's attempts */
    double stage_failure_t = 0;
    for (;;) {
      hh = fmin(fmin(h, s->angle_hmax), hrest);
      if (hrest - hh < tiny) hh = hrest;
      for (int j = 1; j < 7; j++) {
        dp_stage(ny, s->y, hh, s->k, j, s->ytmp);
        if ((st = deriv(s, s->t + DP_C[j] * hh, s->ytmp, s->k[j]))) {
          /* a failed stage (e.g. a singular matrix far from the path):
             retry with a smaller step before giving up */
          snprintf(stage_failure, sizeof stage_failure, "%s", s->fail_detail);
          stage_failure_t = s->fail_time;
          if (hh > 4 * set->min_step) { st = MB_OK; h = hh / 4; goto retry; }
          goto done;
        }
      }
      /* ytmp holds the 5th-order solution (FSAL stage); error estimate */
      double err = dp_error(ny, s->y, s->ytmp, hh, s->k, set->atol, set->rtol);
      if (!isfinite(err)) err = 1e10;
      double fac = err > 0 ? 0.9 * pow(err, -0.2) : 5;
      fac = fmin(5, fmax(0.2, fac));
      if (err <= 1) {
        h = fmin(hh * fac, set->max_step);
        if (hh == hrest && hh < h) h = fmax(h, hh);
        break;
      }
      s->stats.rejected++;
      h = hh * fmax(0.2, fac);
    retry:
      if (h < set->min_step) {
        st = mb_sim_fail(s, s->t, MB_ERR_STEP_TOO_SMALL, "adaptive step");
        if (stage_failure[0]) {
          char detail[sizeof s->fail_detail];
          snprintf(detail, sizeof detail, "adaptive step fell below %.3g s; a stage failed: %.80s at t = %.9g",
                   set->min_step, stage_failure, stage_failure_t);
          memcpy(s->fail_detail, detail, sizeof detail);
        }
        goto done;
      }
    }
    double t0 = s->t, t1 = hh == hrest ? t_end : s->t + hh;
    s->stats.steps++;
    /* rows strictly inside the step, from the continuous extension */
    for (; iout <= nout; iout++) {
      double tout = (double)iout * set->output_step;
      if (tout > t1 - tiny) break;
      dp_dense(ny, s->y, s->ytmp, s->k, hh, (tout - t0) / hh, s->yout);
      if ((st = dp_output(s, tout, s->yout, s->yout + nq, vd, lam, out, user, &stop)) || stop) goto done;
    }
    memcpy(s->q, s->ytmp, sizeof(mb_real) * (size_t)nq);
    memcpy(s->v, s->ytmp + nq, sizeof(mb_real) * (size_t)nv);
    s->t = t1;
    if ((st = mb_sim_finish_step(s, s->t))) goto done;
    /* a row at the step's end: the stabilized state itself, with the
       accelerations the next step starts from */
    if (iout <= nout && fabs((double)iout * set->output_step - t1) <= tiny) {
      if ((st = dp_first_stage(s, vd, lam))) goto done;
      first_stage_ready = 1;
      dp_emit(s, (double)iout * set->output_step, s->q, s->v, vd, lam, out, user, &stop);
      if (stop) goto done;
      iout++;
    }
  }
done:
  free(vd);
  free(lam);
  return st;
}

int mb_sim_run(mb_sim *s, mb_output_fn out, void *user) {
  if (s->set.integrator == MB_GENALPHA) {
    double t0 = mb_sim_clock();
    int st = mb_genalpha_run(s, out, user);
    s->stats.factorizations = s->ls->factorizations;
    s->stats.full_factorizations = s->ls->full_factorizations;
    s->stats.t_total = mb_sim_clock() - t0;
    return st;
  }
  if (s->set.integrator == MB_DOPRI5) {
    double t0 = mb_sim_clock();
    int st = dp_run(s, out, user);
    s->stats.factorizations = s->ls->factorizations;
    s->stats.full_factorizations = s->ls->full_factorizations;
    s->stats.t_total = mb_sim_clock() - t0;
    return st;
  }
  const mb_model *m = s->m;
  const mb_settings *set = &s->set;
  int nq = m->nq, nv = m->nv, ny = nq + nv;
  double t0w = mb_sim_clock();
  mb_real *vd = malloc(sizeof(mb_real) * (size_t)(nv + 1));
  mb_real *lam = malloc(sizeof(mb_real) * (size_t)(m->nc + 1));
  if (!vd || !lam) { free(vd); free(lam); return MB_ERR_NOMEM; }
  int st = MB_OK;
  s->t = 0;
  long nout = (long)floor(set->end_time / set->output_step + 1e-9);
  double h = set->integrator == MB_RK4 ? set->step : fmin(set->step, set->max_step);
  long iout = 0;

  if (set->integrator == MB_RK4) {
    /* a fixed step the run cannot afford is refused before it starts, not after hours */
    double need = ceil(set->output_step / set->step - 1e-9) * ceil(set->end_time / set->output_step - 1e-9);
    if (need > set->max_steps) {
      s->fail_time = 0;
      snprintf(s->fail_detail, sizeof s->fail_detail,
               "RK4 with step %.3g s needs %.3g steps to reach %.3g s, more than max_steps %.3g",
               set->step, need, set->end_time, set->max_steps);
      st = MB_ERR_STEP_BUDGET;
      goto done;
    }
  }
  if (set->stabilization == MB_STAB_PROJECTION && (st = mb_sim_project(s, 0, s->q, s->v))) goto done;
  while (1) {
    double tout = (double)iout * set->output_step;
    if ((st = mb_sim_step_budget(s, h))) goto done;
    /* the stage-1 derivative at (t, y): also gives the outputs at output times */
    memcpy(s->y, s->q, sizeof(mb_real) * (size_t)nq);
    memcpy(s->y + nq, s->v, sizeof(mb_real) * (size_t)nv);
    if ((st = mb_sim_accel(s, s->t, s->q, s->v, vd, lam))) goto done;
    memcpy(s->k[0] + nq, vd, sizeof(mb_real) * (size_t)nv);
    mb_model_qdot(m, s->q, s->v, s->k[0]);
    if (fabs(s->t - tout) <= 1e-9 * set->output_step) {
      double mx = max_abs(s->phi, m->nc);
      if (mx > s->stats.max_phi) s->stats.max_phi = mx;
      if (out && out(user, s->t, s->q, s->v, vd, lam)) goto done;
      iout++;
      if (iout > nout) break;
      tout = (double)iout * set->output_step;
    }
    double hmax = tout - s->t;
    if (set->integrator == MB_RK4) {
      /* fixed step that divides the output step */
      double nsub = ceil(set->output_step / set->step - 1e-9);
      double hs = set->output_step / nsub;
      h = hs < hmax * (1 + 1e-12) ? hs : hmax;
      if (hmax - h < 1e-9 * hs) h = hmax;
      /* the step arithmetic is the embedded core's (runtime/core/mb_step.c) */
      rk4_stage_ctx ctx = {s, s->t, h};
      if ((st = mb_rk4_step(ny, (mb_real)h, s->y, s->k[0], rk4_stage_deriv, &ctx, s->ytmp, s->k[1], s->k[2],
                            s->ytmp)))
        goto done;
      memcpy(s->q, s->ytmp, sizeof(mb_real) * (size_t)nq);
      memcpy(s->v, s->ytmp + nq, sizeof(mb_real) * (size_t)nv);
      s->t = (h == hmax) ? tout : s->t + h;
      s->stats.steps++;
      if ((st = mb_sim_finish_step(s, s->t))) goto done;
    }
  }
done:
  s->stats.factorizations = s->ls->factorizations;
  s->stats.full_factorizations = s->ls->full_factorizations;
  s->stats.t_total = mb_sim_clock() - t0w;
  free(vd);
  free(lam);
  return st;
}
