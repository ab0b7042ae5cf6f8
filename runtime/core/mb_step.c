/* mb_step.c: fixed-step RK4 and generalized-alpha on one data block (see
 * mb_step.h).  The algorithms are those of the hosted integrators
 * (runtime/hosted/integrate.c, genalpha.c) with their adaptive parts taken
 * out: the step is the caller's, generalized-alpha runs a fixed number of
 * modified-Newton iterations (one factorization per step), and the
 * projection stops after a fixed number of iterations. */
#include "mb_step.h"

void mb_step_defaults(mb_step_settings *set) {
  set->integrator = MB_STEP_RK4;
  set->newton_iterations = 3;
  set->projection = 1;
  set->projection_iterations = 8;
#ifdef MB_REAL_FLOAT
  set->projection_tol = MB_R(1e-5); /* about 100 ulp of unit coordinates */
#else
  set->projection_tol = MB_R(1e-10);
#endif
  set->rho_inf = MB_R(0.8);
}

static void copy(mb_real *dst, const mb_real *src, int n) {
  for (int i = 0; i < n; i++) dst[i] = src[i];
}

static int all_finite(const mb_real *a, int n) {
  int finite = 1; /* x - x is 0 for a finite x, NaN otherwise */
  for (int i = 0; i < n; i++) finite &= a[i] - a[i] == 0;
  return finite;
}

void mb_ga_method_init(mb_ga_method *g, mb_real rho_inf) {
  g->am = (2 * rho_inf - 1) / (rho_inf + 1);
  g->af = rho_inf / (rho_inf + 1);
  g->gamma = MB_R(0.5) - g->am + g->af;
  g->beta = MB_R(0.25) * (g->gamma + MB_R(0.5)) * (g->gamma + MB_R(0.5));
}

/* evaluate at (t, q, v) and factor K */
static int eval_factor(mb_stepper *s, mb_real t, const mb_real *q, const mb_real *v) {
  const mb_model *m = s->m;
  m->eval(m, t, q, v, s->Kx, s->rhs, s->phi, s->nu, s->u);
  return m->ldl_factor(m, s->Kx, s->ldl) ? MB_ERR_SINGULAR : MB_OK;
}

/* K b = b in place with the factors of the last eval_factor */
static int solve(mb_stepper *s, const mb_real *K, mb_real *b) {
  const mb_model *m = s->m;
  int st = m->ldl_solve(m, K, s->ldl, b, 0);
  if (st) return st;
  return all_finite(b, m->n) ? MB_OK : MB_ERR_NONFINITE;
}

/* accelerations and multipliers into s->x */
static int accel(mb_stepper *s, mb_real t, const mb_real *q, const mb_real *v) {
  int st = eval_factor(s, t, q, v);
  if (st) return st;
  copy(s->x, s->rhs, s->m->n);
  return solve(s, s->Kx, s->x);
}

static mb_real max_abs(const mb_real *a, int n) {
  mb_real mx = 0;
  for (int i = 0; i < n; i++) {
    mb_real z = MB_FABS(a[i]);
    if (!(z <= mx)) mx = z; /* NaN wins */
  }
  return mx;
}

/* (q, v) onto phi = 0 and D v = nu: Newton with the mass-weighted least
 * correction K [dq; mu] = [0; -phi], then K [dv; mu] = [0; -phid] */
static int project(mb_stepper *s) {
  const mb_model *m = s->m;
  int nv = m->nv;
  mb_model_normalize(m, s->q);
  for (int it = 0;; it++) {
    int st = eval_factor(s, s->t, s->q, s->v);
    if (st) return st;
    s->projection_iterations_last = it;
    mb_real mx = max_abs(s->phi, m->nc);
    if (mx <= s->set.projection_tol) break;
    if (it >= s->set.projection_iterations) return MB_ERR_PROJECTION;
    for (int i = 0; i < nv; i++) s->dv[i] = 0;
    for (int r = 0; r < m->nc; r++) s->dv[nv + r] = -s->phi[r];
    if ((st = solve(s, s->Kx, s->dv))) return st;
    mb_model_qincrement(m, s->q, s->dv);
    mb_model_normalize(m, s->q);
  }
  for (int i = 0; i < nv; i++) s->dv[i] = 0;
  for (int r = 0; r < m->nc; r++) s->dv[nv + r] = -s->nu[r];
  int st = solve(s, s->Kx, s->dv);
  if (st) return st;
  for (int i = 0; i < nv; i++) s->v[i] += s->dv[i];
  return MB_OK;
}

/* take n mb_real from the block */
static mb_real *take(mb_real **p, long n) {
  mb_real *a = *p;
  *p += n + 1; /* the spare element */
  return a;
}

int mb_step_init(mb_stepper **sp, void *mem, unsigned long bytes, const mb_model *m, int nin,
                 unsigned long frames, const mb_step_settings *set) {
  *sp = 0;
  int ga = MB_STEP_HAS(MB_STEP_GENALPHA) && set->integrator == MB_STEP_GENALPHA;
  unsigned long need = MB_STEP_BYTES((unsigned long)m->nq, (unsigned long)m->nv, (unsigned long)m->nc,
                                     (unsigned long)m->n, (unsigned long)m->nnz, m->ldl_worksize,
                                     (unsigned long)nin, frames, ga);
  if (!mem || ((unsigned long)mem & 7u) || bytes < need || !m->ldl_factor || !m->ldl_solve)
    return MB_ERR_INVALID;
  if (!ga && !(MB_STEP_HAS(MB_STEP_RK4) && set->integrator == MB_STEP_RK4)) return MB_ERR_INVALID;
  if (ga && (set->newton_iterations < 1 || !(set->rho_inf >= 0 && set->rho_inf <= 1)))
    return MB_ERR_INVALID;
  if (set->projection_iterations < 0) return MB_ERR_INVALID;
  mb_stepper *s = (mb_stepper *)mem;
  mb_real *p = (mb_real *)((unsigned char *)mem + (sizeof(mb_stepper) + 7) / 8 * 8);
  for (mb_real *z = p; z < (mb_real *)((unsigned char *)mem + need); z++) *z = 0;
  s->m = m;
  s->set = *set;
  s->t = 0;
  s->nin = nin;
  s->steps = 0;
  int ny = m->nq + m->nv;
  s->q = take(&p, m->nq);
  s->v = take(&p, m->nv);
  s->Kx = take(&p, m->nnz);
  s->rhs = take(&p, m->n);
  s->x = take(&p, m->n);
  s->dv = take(&p, m->n);
  s->phi = take(&p, m->nc);
  s->nu = take(&p, m->nc);
  s->ldl = s->frames = take(&p, (long)(m->ldl_worksize > frames ? m->ldl_worksize : frames));
  s->u = take(&p, nin);
  if (ga) {
    s->vd = take(&p, m->nv);
    s->a = take(&p, m->nv);
    s->a1 = take(&p, m->nv);
    s->dq = take(&p, m->nv);
    s->v1 = take(&p, m->nv);
    s->lam = take(&p, m->nc);
    s->q1 = take(&p, m->nq);
    s->Kmod = take(&p, m->nnz);
    mb_ga_method_init(&s->ga, set->rho_inf);
  } else {
    s->y0 = take(&p, ny);
    s->ytmp = take(&p, ny);
    s->ksum = take(&p, ny);
    s->kst = take(&p, ny);
  }
  copy(s->q, m->q0, m->nq);
  copy(s->v, m->v0, m->nv);
  m->init(m, s->Kx);
  if (ga) m->init(m, s->Kmod);
  *sp = s;
  int st = s->set.projection ? project(s) : MB_OK;
  if (st) return st;
  if (ga) { /* consistent accelerations start the recurrence: a_0 = vd_0 */
    if ((st = accel(s, 0, s->q, s->v))) return st;
    copy(s->vd, s->x, m->nv);
    copy(s->a, s->x, m->nv);
    copy(s->lam, s->x + m->nv, m->nc);
  }
  return MB_OK;
}

/* dy = [G(q) v; vd] at (t, y) */
static int deriv(mb_stepper *s, mb_real t, const mb_real *y, mb_real *dy) {
  const mb_model *m = s->m;
  int st = accel(s, t, y, y + m->nq);
  if (st) return st;
  copy(dy + m->nq, s->x, m->nv);
  mb_model_qdot(m, y, y + m->nq, dy);
  return MB_OK;
}

int mb_rk4_step(int ny, mb_real h, const mb_real *y0, const mb_real *k1, mb_rk4_deriv deriv, void *ctx,
                mb_real *ytmp, mb_real *k, mb_real *ksum, mb_real *y1) {
  static const mb_real c[4] = {0, MB_R(0.5), MB_R(0.5), 1};
  static const mb_real b[4] = {MB_R(1.0) / 6, MB_R(1.0) / 3, MB_R(1.0) / 3, MB_R(1.0) / 6};
  for (int i = 0; i < ny; i++) ksum[i] = b[0] * k1[i];
  for (int j = 1; j < 4; j++) {
    const mb_real *kp = j == 1 ? k1 : k; /* read before deriv writes k: k1 may be k */
    for (int i = 0; i < ny; i++) ytmp[i] = y0[i] + h * (c[j] * kp[i]);
    int st = deriv(ctx, c[j], ytmp, k);
    if (st) return st;
    for (int i = 0; i < ny; i++) ksum[i] = ksum[i] + b[j] * k[i];
  }
  for (int i = 0; i < ny; i++) y1[i] = y0[i] + h * ksum[i];
  return MB_OK;
}

/* the stepper's stage derivative at s->t + c h (mb_rk4_step's callback) */
typedef struct {
  mb_stepper *s;
  mb_real h;
} rk4_ctx;

static int rk4_deriv(void *ctx, mb_real c, const mb_real *y, mb_real *dy) {
  rk4_ctx *r = (rk4_ctx *)ctx;
  return deriv(r->s, r->s->t + c * r->h, y, dy);
}

static int step_rk4(mb_stepper *s, mb_real h) {
  const mb_model *m = s->m;
  int nq = m->nq, ny = m->nq + m->nv;
  rk4_ctx ctx = {s, h};
  copy(s->y0, s->q, nq);
  copy(s->y0 + nq, s->v, m->nv);
  int st = deriv(s, s->t, s->y0, s->kst);
  if (st) return st;
  if ((st = mb_rk4_step(ny, h, s->y0, s->kst, rk4_deriv, &ctx, s->ytmp, s->kst, s->ksum, s->ytmp))) return st;
  copy(s->q, s->ytmp, nq);
  copy(s->v, s->ytmp + nq, m->nv);
  return MB_OK;
}

void mb_ga_predict(const mb_model *m, const mb_ga_method *g, mb_real h, const mb_real *q, const mb_real *v,
                   const mb_real *vd, const mb_real *a, const mb_real *x, mb_real *q1, mb_real *v1,
                   mb_real *a1, mb_real *dq) {
  for (int i = 0; i < m->nv; i++) {
    mb_real ai = ((1 - g->af) * x[i] + g->af * vd[i] - g->am * a[i]) / (1 - g->am);
    a1[i] = ai;
    dq[i] = h * v[i] + h * h * ((MB_R(0.5) - g->beta) * a[i] + g->beta * ai);
    v1[i] = v[i] + h * ((1 - g->gamma) * a[i] + g->gamma * ai);
  }
  copy(q1, q, m->nq);
  mb_model_qincrement(m, q1, dq);
  mb_model_normalize(m, q1);
}

void mb_ga_iteration_matrix(const mb_model *m, const mb_real *Kx, mb_real kfac, mb_real cfac, mb_real *Kmod,
                            mb_real t, const mb_real *q, const mb_real *v, void *work) {
  copy(Kmod, Kx, m->nnz);
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (B->kind != MB_BODY_FLEXIBLE || !B->flex || !B->mslotf) continue;
    int nb = 6 + B->nm;
    for (int j = 0; j < B->nm; j++) {
      int slot = B->mslotf[(6 + j) * nb + 6 + j];
      if (slot >= 0) Kmod[slot] += kfac * B->flex->stiffness[j] + cfac * B->flex->damping[j];
    }
  }
  mb_model_force_tangent(m, t, q, v, kfac, cfac, Kmod, work);
}

/* q1, v1, a1 from the iterate vd1 = x[0..nv) */
static void ga_predict(mb_stepper *s, mb_real h) {
  mb_ga_predict(s->m, &s->ga, h, s->q, s->v, s->vd, s->a, s->x, s->q1, s->v1, s->a1, s->dq);
}

/* generalized-alpha (as genalpha.c) with newton_iterations modified-Newton
 * iterations on the iteration matrix of the first iterate */
static int step_genalpha(mb_stepper *s, mb_real h) {
  const mb_model *m = s->m;
  int nv = m->nv, nc = m->nc, n = m->n;
  mb_real bp = (1 - s->ga.am) / (h * h * s->ga.beta * (1 - s->ga.af)); /* beta' */
  mb_real gp = s->ga.gamma / (h * s->ga.beta);                         /* gamma' */
  copy(s->x, s->vd, nv);
  copy(s->x + nv, s->lam, nc);
  for (int it = 0; it < s->set.newton_iterations; it++) {
    ga_predict(s, h);
    m->eval(m, s->t + h, s->q1, s->v1, s->Kx, s->rhs, s->phi, s->nu, s->u);
    /* r = [f - (M vd + D^T lambda); -beta' phi] */
    for (int i = 0; i < nv; i++) s->dv[i] = s->rhs[i];
    for (int j = 0; j < n; j++)
      for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
        if (m->Ki[p] < nv) s->dv[m->Ki[p]] -= s->Kx[p] * s->x[j];
    for (int r = 0; r < nc; r++) s->dv[nv + r] = -bp * s->phi[r];
    if (it == 0) { /* modified Newton: the iteration matrix of the first iterate */
      mb_ga_iteration_matrix(m, s->Kx, 1 / bp, gp / bp, s->Kmod, s->t + h, s->q1, s->v1, s->frames);
      if (m->ldl_factor(m, s->Kmod, s->ldl)) return MB_ERR_SINGULAR;
    }
    int st = solve(s, s->Kmod, s->dv);
    if (st) return st;
    for (int i = 0; i < n; i++) s->x[i] += s->dv[i];
  }
  ga_predict(s, h);
  copy(s->q, s->q1, m->nq);
  copy(s->v, s->v1, nv);
  copy(s->vd, s->x, nv);
  copy(s->lam, s->x + nv, nc);
  copy(s->a, s->a1, nv);
  return MB_OK;
}

int mb_step(mb_stepper *s, mb_real h) {
  const mb_model *m = s->m;
  if (!(h > 0)) return MB_ERR_INVALID;
  int st = MB_STEP_HAS(MB_STEP_GENALPHA) && (!MB_STEP_HAS(MB_STEP_RK4) || s->set.integrator == MB_STEP_GENALPHA)
               ? step_genalpha(s, h)
               : step_rk4(s, h);
  if (st) return st;
  s->t += h;
  s->steps++;
  if (s->set.projection) {
    if ((st = project(s))) return st;
  } else {
    mb_model_normalize(m, s->q);
  }
  if (!all_finite(s->q, m->nq) || !all_finite(s->v, m->nv)) return MB_ERR_NONFINITE;
  return MB_OK;
}

int mb_step_outputs(mb_stepper *s, mb_real *y) {
  const mb_model *m = s->m;
  int st = accel(s, s->t, s->q, s->v);
  if (st) return st;
  mb_model_outputs(m, s->t, s->q, s->v, s->x, s->x + m->nv, 0, y, s->frames);
  return MB_OK;
}
