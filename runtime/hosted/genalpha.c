/* genalpha.c: the implicit generalized-alpha method (Chung & Hulbert; on the
 * Lie group of the body rotations as Arnold & Bruls 2007) for stiff modal
 * content, on the index-3 equations
 *     M(q) vd + D(q)^T lambda = f(q, v, t),   phi(q) = 0,
 * with adaptive steps.  Newton iterates on the fixed pattern of K: scaled by
 * 1/beta', the iteration matrix is
 *     [ M + (gamma'/beta') C + (1/beta') K_t   D^T ]
 *     [ D                                      0   ]
 * which is K with the modal damping and stiffness added on the modal diagonal
 * (the stiff part of K_t; the remaining, non-stiff tangent terms are left to
 * the Newton iterations).  Velocities are projected onto D v = nu after each
 * step when projection is on (index-3 positions already satisfy phi = 0). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "mb_sim.h"
#include "mb_step.h" /* the generalized-alpha step arithmetic it shares with the core */

typedef struct {
  /* method constants */
  mb_ga_method ga; /* shared with the embedded core (mb_step.h) */
  /* state at t_n: accelerations vd and algorithmic accelerations a */
  mb_real *vd, *a, *lam;
  /* the iterate at t_n+1 */
  mb_real *x;      /* [vd; lambda] */
  mb_real *q1, *v1, *a1, *dq;
  mb_real *Kmod, *r; /* iteration matrix, Newton right side / correction */
  mb_real *sc;       /* error weights of the velocity-space position coordinates */
  mb_real *vd_out, *lam_out;
  const char *why; /* why the last Newton iteration failed */
} ga_work;

static void ga_free(ga_work *g) {
  free(g->vd); free(g->a); free(g->lam); free(g->x); free(g->q1); free(g->v1); free(g->a1);
  free(g->dq); free(g->Kmod); free(g->r); free(g->sc); free(g->vd_out); free(g->lam_out);
}

static int ga_alloc(ga_work *g, const mb_model *m) {
  size_t nv = (size_t)m->nv + 1, n = (size_t)m->n + 1, nc = (size_t)m->nc + 1;
  g->vd = calloc(nv, sizeof(mb_real));
  g->a = calloc(nv, sizeof(mb_real));
  g->lam = calloc(nc, sizeof(mb_real));
  g->x = calloc(n, sizeof(mb_real));
  g->q1 = calloc((size_t)m->nq + 1, sizeof(mb_real));
  g->v1 = calloc(nv, sizeof(mb_real));
  g->a1 = calloc(nv, sizeof(mb_real));
  g->dq = calloc(nv, sizeof(mb_real));
  g->Kmod = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  g->r = calloc(n, sizeof(mb_real));
  g->sc = calloc(nv, sizeof(mb_real));
  g->vd_out = calloc(nv, sizeof(mb_real));
  g->lam_out = calloc(nc, sizeof(mb_real));
  return g->vd && g->a && g->lam && g->x && g->q1 && g->v1 && g->a1 && g->dq && g->Kmod &&
         g->r && g->sc && g->vd_out && g->lam_out;
}

/* error weights atol + rtol |size|, per velocity-space coordinate: translations
 * by their size, rotations by 1 rad, and modal amplitudes by the body's largest
 * modal amplitude: an error in a high mode matters against the deformation of
 * the body, not against that mode's own (tiny) amplitude */
static void error_weights(const mb_model *m, const mb_settings *set, const mb_real *q,
                          const mb_real *q1, mb_real *sc) {
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    for (int j = 0; j < 3; j++)
      sc[B->vadr + j] = (mb_real)(set->atol + set->rtol * fmax(fabs((double)q[B->qadr + j]),
                                                              fabs((double)q1[B->qadr + j])));
    for (int j = 3; j < 6; j++) sc[B->vadr + j] = (mb_real)(set->atol + set->rtol);
    double wmax = 0;
    for (int j = 0; j < B->nm; j++)
      wmax = fmax(wmax, fmax(fabs((double)q[B->qadr + 7 + j]), fabs((double)q1[B->qadr + 7 + j])));
    for (int j = 0; j < B->nm; j++) sc[B->vadr + 6 + j] = (mb_real)(set->atol + set->rtol * wmax);
  }
}

/* q1, v1, a1 from the iterate vd1 = x[0..nv) (generalized-alpha recurrences,
 * runtime/core/mb_step.c: the embedded core's step arithmetic) */
static void ga_predict(const mb_sim *s, const ga_work *g, double h) {
  mb_ga_predict(s->m, &g->ga, (mb_real)h, s->q, s->v, g->vd, g->a, g->x, g->q1, g->v1, g->a1, g->dq);
}

/* the iteration matrix: K with kfac * stiffness + cfac * damping on the modal
 * diagonal, and the force elements' tangents at the iterate (t, q, v) on their
 * coupling blocks (when the model was compiled for an implicit method) */
static void iteration_matrix(const mb_model *m, const mb_real *Kx, double kfac, double cfac,
                             mb_real *Kmod, double t, const mb_real *q, const mb_real *v,
                             void *work) {
  mb_ga_iteration_matrix(m, Kx, (mb_real)kfac, (mb_real)cfac, Kmod, (mb_real)t, q, v, work);
}

/* r_top = K x - f over the dynamic rows (the constraint rows are phi) */
static void dynamic_residual(const mb_model *m, const mb_real *Kx, const mb_real *x,
                             const mb_real *rhs, mb_real *r) {
  for (int i = 0; i < m->nv; i++) r[i] = -rhs[i];
  for (int j = 0; j < m->n; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] < m->nv) r[m->Ki[p]] += Kx[p] * x[j];
}

static double weighted_rms(const mb_real *e, const mb_real *sc, int n, double scale) {
  double sum = 0;
  for (int i = 0; i < n; i++) {
    double z = scale * (double)e[i] / (double)sc[i];
    sum += z * z;
  }
  return n ? sqrt(sum / n) : 0;
}

enum { GA_CONVERGED = 0, GA_DIVERGED = 1, GA_FAILED = 2 };

/* Newton on x = [vd1; lambda1] for a step h from s->t: GA_CONVERGED with q1, v1,
 * a1 and x at the solution; GA_DIVERGED (retry smaller); GA_FAILED (status in *st) */
static int ga_newton(mb_sim *s, ga_work *g, double h, int *st, double *rate_out) {
  const mb_model *m = s->m;
  int nv = m->nv, nc = m->nc, n = m->n;
  double bp = (1 - g->ga.am) / (h * h * g->ga.beta * (1 - g->ga.af)); /* beta' */
  double gp = g->ga.gamma / (h * g->ga.beta);                         /* gamma' */
  double eta_prev = 0;
  int factored = 0;
  /* predictor: the accelerations and multipliers of t_n */
  memcpy(g->x, g->vd, sizeof(mb_real) * (size_t)nv);
  memcpy(g->x + nv, g->lam, sizeof(mb_real) * (size_t)nc);
  for (int it = 0; it < 12; it++) {
    ga_predict(s, g, h);
    double t0 = s->set.timers ? mb_sim_clock() : 0;
    m->eval(m, (mb_real)(s->t + h), g->q1, g->v1, s->Kx, s->rhs, s->phi, s->nu, s->work);
    s->stats.evals++;
    double t1 = s->set.timers ? mb_sim_clock() : 0;
    s->stats.t_assembly += t1 - t0;
    dynamic_residual(m, s->Kx, g->x, s->rhs, g->r);
    for (int i = 0; i < nv; i++) g->r[i] = -g->r[i];
    for (int r = 0; r < nc; r++) g->r[nv + r] = (mb_real)(-bp * s->phi[r]);
    for (int i = 0; i < n; i++)
      if (!isfinite((double)g->r[i])) { g->why = "the residual is not finite"; return GA_DIVERGED; }
    /* a fresh iteration matrix at the first iterate and whenever the
       iterations slow down (modified Newton) */
    if (!factored || (it >= 2 && *rate_out > 0.25)) {
      iteration_matrix(m, s->Kx, 1 / bp, gp / bp, g->Kmod, s->t + h, g->q1, g->v1, s->work);
      s->factored_valid = 0; /* the solver now holds the iteration matrix */
      int fs = s->ls->factor(s->ls, g->Kmod);
      if (fs) { g->why = "the iteration matrix is singular"; return GA_DIVERGED; } /* a smaller step may help */
      factored = 1;
    }
    int ss = s->ls->solve(s->ls, g->r);
    s->stats.solves++;
    s->stats.t_solve += (s->set.timers ? mb_sim_clock() : 0) - t1;
    if (ss) { *st = ss; return GA_FAILED; }
    for (int i = 0; i < n; i++) {
      if (!isfinite((double)g->r[i])) { g->why = "the Newton correction is not finite"; return GA_DIVERGED; }
      g->x[i] += g->r[i];
    }
    s->stats.newton_iterations++;
    /* size of the position correction dq = d(vd) / beta' against the error weights */
    error_weights(m, &s->set, s->q, g->q1, g->sc);
    double eta = weighted_rms(g->r, g->sc, nv, 1 / bp);
    if (it > 0) *rate_out = eta / fmax(eta_prev, 1e-300);
    eta_prev = eta;
    /* converged: the correction is far below the error tolerance, or (single
       precision) it has stopped shrinking at the round-off floor while already
       below the tolerance.  In double precision a stall is not convergence:
       a slowly contracting modified Newton (an iteration matrix without the
       stiffness that dominates, e.g. force elements compiled without their
       tangents) stalls with the error still far above the tolerance, and
       accepting it gave wrong reactions with no warning */
    int stalled = it > 1 && *rate_out > 0.9;
#ifdef MB_REAL_FLOAT
    int floor_ok = stalled && eta <= 1;
#else
    int floor_ok = 0;
#endif
    /* and with a known rate theta, the error left after this correction,
       about eta theta / (1 - theta), is below the same bound: a correction
       that shrinks slowly overstates convergence (theta 0.9: 9 eta left) */
    double theta = it > 0 ? *rate_out : 0;
    int small = eta <= 1e-2 && theta < 1 && eta * theta <= 1e-2 * (1 - theta);
    if (small || floor_ok) {
      ga_predict(s, g, h);
      return GA_CONVERGED;
    }
    if (stalled) { g->why = "the Newton corrections stopped shrinking"; return GA_DIVERGED; }
  }
  g->why = "no convergence in 12 iterations";
  return GA_DIVERGED;
}

/* does force element d do work that is not the change of a potential
 * mb_model_energy counts?  Point forces and torques (applied loads), tyres
 * (slip and rolling losses, and traction), and fields whose stiffness is not
 * symmetric (circulatory) */
static int does_work(const mb_model *m, const mb_forcedef *d) {
  if (d->kind == MB_FORCE_POINT || d->kind == MB_FORCE_TORQUE || d->kind == MB_FORCE_TYRE) return 1;
  if (d->kind == MB_FORCE_FIELD) {
    const mb_real *K = m->force_prm + d->padr + MB_FIELD_K;
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < i; j++)
        if (K[6 * i + j] != K[6 * j + i]) return 1;
  }
  return 0;
}

/* the power the watchdog integrates at the state of s: |lambda . D v| of
 * the constraints (D from K's constraint rows) plus |f_src . v| of the
 * work-doing elements (their generalized forces: the generic evaluation with
 * them minus the one without any element) */
static double input_power(mb_watchdog *w, mb_sim *s, const mb_real *lambda) {
  const mb_model *m = s->m;
  double pc = 0, pf = 0;
  for (int r = 0; r < m->nc; r++) w->phi[r] = 0;
  for (int j = 0; j < m->nv; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] >= m->nv) w->phi[m->Ki[p] - m->nv] += s->Kx[p] * s->v[j];
  for (int r = 0; r < m->nc; r++) pc += (double)lambda[r] * (double)w->phi[r];
  if (w->src.nforce) {
    mb_generic_eval(&w->src, (mb_real)s->t, s->q, s->v, w->Kx, w->r_src, w->phi, w->phid, w->work);
    mb_generic_eval(&w->none, (mb_real)s->t, s->q, s->v, w->Kx, w->r_none, w->phi, w->phid, w->work);
    for (int i = 0; i < m->nv; i++) pf += (double)(w->r_src[i] - w->r_none[i]) * (double)s->v[i];
  }
  return fabs(pc) + fabs(pf);
}


void mb_watchdog_free(mb_watchdog *w) {
  free(w->src_force); free(w->Kx); free(w->r_src); free(w->r_none); free(w->phi); free(w->phid);
  free(w->work);
  memset(w, 0, sizeof *w);
}

int mb_watchdog_start(mb_watchdog *w, mb_sim *s) {
  const mb_model *m = s->m;
  memset(w, 0, sizeof *w);
  w->src_force = malloc(sizeof(mb_forcedef) * ((size_t)m->nforce + 1));
  w->Kx = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  w->r_src = calloc((size_t)m->n + 1, sizeof(mb_real));
  w->r_none = calloc((size_t)m->n + 1, sizeof(mb_real));
  w->phi = calloc((size_t)m->nc + 1, sizeof(mb_real));
  w->phid = calloc((size_t)m->nc + 1, sizeof(mb_real));
  w->work = malloc(mb_model_worksize(m) + 16);
  if (!w->src_force || !w->Kx || !w->r_src || !w->r_none || !w->phi || !w->phid || !w->work) {
    mb_watchdog_free(w);
    return MB_ERR_NOMEM;
  }
  int nsrc = 0;
  for (int e = 0; e < m->nforce; e++)
    if (does_work(m, &m->force[e])) w->src_force[nsrc++] = m->force[e];
  w->src = *m;
  w->src.force = w->src_force;
  w->src.nforce = nsrc;
  w->src.force_tslot = w->src.tangent_slot = NULL;
  w->none = w->src;
  w->none.nforce = 0;
  mb_real T, V;
  mb_model_energy(m, (mb_real)s->t, s->q, s->v, &T, &V, w->work);
  /* L: the model's reach from the origin, over the bodies' frames, their
     markers (joint and element points) and a flexible body's centre of mass
     twice over (its length) */
  double mass = 0, L = 0;
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (B->kind == MB_BODY_VIRTUAL) continue;
    const mb_real *r = s->q + B->qadr;
    double rb = sqrt((double)(r[0] * r[0] + r[1] * r[1] + r[2] * r[2])), reach = 0;
    if (B->kind == MB_BODY_FLEXIBLE && B->flex) {
      const mb_real *S0 = B->flex->S0;
      mass += (double)B->flex->mass;
      if (B->flex->mass > 0)
        reach = 2 * sqrt((double)(S0[0] * S0[0] + S0[1] * S0[1] + S0[2] * S0[2])) / (double)B->flex->mass;
    } else {
      mass += (double)B->mass;
    }
    for (int k = 0; k < m->nmarker; k++)
      if (m->marker[k].body == b) {
        const mb_real *p = m->marker[k].s;
        reach = fmax(reach, sqrt((double)(p[0] * p[0] + p[1] * p[1] + p[2] * p[2])));
      }
    L = fmax(L, rb + reach);
  }
  double g = sqrt((double)(m->gravity[0] * m->gravity[0] + m->gravity[1] * m->gravity[1] +
                           m->gravity[2] * m->gravity[2]));
  w->e0 = (double)T + (double)V;
  w->e_ref = fabs((double)T) + fabs((double)V) + mass * g * L;
  w->t_prev = s->t;
  return MB_OK;
}

int mb_watchdog_check(mb_watchdog *w, mb_sim *s, const mb_real *lambda) {
  double p = input_power(w, s, lambda);
  w->w_in += 0.5 * (s->t - w->t_prev) * (w->p_prev + p);
  w->p_prev = p;
  w->t_prev = s->t;
  mb_real T, V;
  mb_model_energy(s->m, (mb_real)s->t, s->q, s->v, &T, &V, w->work);
  double e = (double)T + (double)V;
  w->rise = e - w->e0 - w->w_in;
  /* allowed: the energy scale, the input work once more (its quadrature
     error) and the round-off of T + V */
  double allowed = w->e_ref + w->w_in + 1e-6 * (fabs((double)T) + fabs((double)V));
  if (isfinite(e) && w->rise <= allowed) return MB_OK;
  s->fail_time = s->t;
  snprintf(s->fail_detail, sizeof s->fail_detail,
           "generalized-alpha: the energy rose to %.4g from %.4g (work in %.3g), more than "
           "the energy scale %.3g: a blow-up", e, w->e0, w->w_in, w->e_ref);
  return MB_ERR_ENERGY;
}

int mb_genalpha_run(mb_sim *s, mb_output_fn out, void *user) {
  const mb_model *m = s->m;
  const mb_settings *set = &s->set;
  int nq = m->nq, nv = m->nv, nc = m->nc;
  ga_work g;
  mb_watchdog wd;
  memset(&g, 0, sizeof g);
  memset(&wd, 0, sizeof wd);
  if (!ga_alloc(&g, m)) { ga_free(&g); return MB_ERR_NOMEM; }
  double rho = set->rho_inf;
  if (!(rho >= 0 && rho <= 1)) { ga_free(&g); return MB_ERR_INVALID; }
  mb_ga_method_init(&g.ga, (mb_real)rho);
  int st = MB_OK;
  s->t = 0;
  long nout = (long)floor(set->end_time / set->output_step + 1e-9), iout = 0;
  double h = fmin(set->step, set->max_step);

  if (set->stabilization == MB_STAB_PROJECTION && (st = mb_sim_project(s, 0, s->q, s->v))) goto done;
  s->angle_hmax = mb_model_angle_step(m, s->q, s->v, s->work);
  /* consistent accelerations at t = 0 start the recurrence: a_0 = vd_0 */
  if ((st = mb_sim_accel(s, 0, s->q, s->v, g.vd, g.lam))) goto done;
  memcpy(g.a, g.vd, sizeof(mb_real) * (size_t)nv);
  if ((st = mb_watchdog_start(&wd, s))) goto done;
  wd.p_prev = input_power(&wd, s, g.lam);
  while (1) {
    double tout = (double)iout * set->output_step;
    if ((st = mb_sim_step_budget(s, h))) goto done;
    if (fabs(s->t - tout) <= 1e-9 * set->output_step) {
      /* outputs from the index-1 accelerations of the (projected) state */
      if ((st = mb_sim_accel(s, s->t, s->q, s->v, g.vd_out, g.lam_out))) goto done;
      double mx = 0;
      for (int r = 0; r < nc; r++) mx = fmax(mx, fabs((double)s->phi[r]));
      if (mx > s->stats.max_phi) s->stats.max_phi = mx;
      if (out && out(user, s->t, s->q, s->v, g.vd_out, g.lam_out)) goto done;
      iout++;
      if (iout > nout) break;
      tout = (double)iout * set->output_step;
    }
    double hmax = tout - s->t;
    for (;;) {
      double hh = fmin(fmin(h, s->angle_hmax), hmax); /* angle_hmax: see mb_model_angle_step */
      if (hmax - hh < 1e-9 * set->output_step) hh = hmax;
      double rate = 0;
      int ns = MB_OK;
      int res = ga_newton(s, &g, hh, &ns, &rate);
      if (res == GA_FAILED) { st = mb_sim_fail_at(s, s->t + hh, g.q1, g.v1, ns, "implicit step"); goto done; }
      if (res == GA_DIVERGED) {
        s->stats.newton_failures++;
        s->stats.rejected++;
        h = hh / 4;
        if (h < set->min_step) {
          s->fail_time = s->t;
          snprintf(s->fail_detail, sizeof s->fail_detail,
                   "generalized-alpha: Newton did not converge even with step %.3g s: %s", hh,
                   g.why ? g.why : "unknown");
          st = MB_ERR_NEWTON;
          goto done;
        }
        continue;
      }
      /* local error of the positions: h^2 (beta - 1/6) (vd1 - vd0) */
      for (int i = 0; i < nv; i++) g.r[i] = g.x[i] - g.vd[i];
      error_weights(m, set, s->q, g.q1, g.sc);
      double err = weighted_rms(g.r, g.sc, nv, hh * hh * fabs((double)g.ga.beta - 1.0 / 6));
      if (!isfinite(err)) err = 1e10;
      double fac = err > 0 ? 0.9 * pow(err, -1.0 / 3) : 2;
      fac = fmin(2, fmax(0.2, fac));
      if (err <= 1) {
        memcpy(s->q, g.q1, sizeof(mb_real) * (size_t)nq);
        memcpy(s->v, g.v1, sizeof(mb_real) * (size_t)nv);
        memcpy(g.vd, g.x, sizeof(mb_real) * (size_t)nv);
        memcpy(g.lam, g.x + nv, sizeof(mb_real) * (size_t)nc);
        memcpy(g.a, g.a1, sizeof(mb_real) * (size_t)nv);
        s->t = (hh == hmax) ? tout : s->t + hh;
        s->stats.steps++;
        h = fmin(hh * fac, set->max_step);
        if (hh == hmax && hh < h) h = fmax(h, hh);
        break;
      }
      s->stats.rejected++;
      h = hh * fac;
      if (h < set->min_step) {
        st = mb_sim_fail(s, s->t, MB_ERR_STEP_TOO_SMALL, "generalized-alpha error control");
        goto done;
      }
    }
    if (set->stabilization == MB_STAB_BAUMGARTE) {
      /* index-3 positions need no Baumgarte terms: plain normalization */
      mb_model_normalize(m, s->q);
    }
    /* before the state can reach an output row: an energy that blew up
       stops the run (the step's K and multipliers are from its Newton) */
    if ((st = mb_watchdog_check(&wd, s, g.lam))) goto done;
    if ((st = mb_sim_finish_step(s, s->t))) goto done;
  }
done:
  mb_watchdog_free(&wd);
  ga_free(&g);
  return st;
}
