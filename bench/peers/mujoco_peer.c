/* mujoco_peer.c: mbcc's emitted evaluation (eval, then the emitted LDL^T
 * factor and solve) against MuJoCo's mj_forward and mj_step on the same
 * mechanism, at the same state, measured interleaved (make bench; see
 * bench/peers/README.md).
 *
 * Built by scripts/peers.sh with the model's generated code and a one-line
 * file defining peer_model; the MJCF comes from scripts/mjcf_from_yaml.py
 * (same bodies, joints split into a tree and loop-closing 'connect's).
 *
 * The state: mbcc's assembled design configuration q0 with random velocities
 * projected onto the velocity constraints (so that the velocity terms count).
 * MuJoCo's joint coordinates follow from it: at the design configuration
 * every body frame is parallel to the global axes in both codes, so qpos is
 * MuJoCo's qpos0 and qvel the joints' relative velocities.  Forces: mbcc's
 * force elements, evaluated by mbcc at that state (mb_force_wrench), are given
 * to MuJoCo as qfrc_applied (mj_applyFT), so that both integrate the same loads;
 * MuJoCo's timed calls therefore do not evaluate any force element, while
 * mbcc's eval does (the comparison favours MuJoCo).
 *
 * Checks (exit 1 when one fails): MuJoCo's body velocities equal mbcc's (the
 * state mapping) and, at rest (v = 0: gravity and the element forces), every
 * body's linear and angular acceleration agrees with mbcc's within --tol
 * (default 5e-3: MuJoCo's constraints are soft, impedance at most 0.9999; the
 * car's difference, 2.6e-3, scales with 1 - impedance) of the largest.  Then the timing: ROUNDS rounds, each
 * timing REPS calls of mbcc's evaluation, of mj_forward and of mj_step (state
 * restored before each), in turn; medians of the per-call times and of the
 * per-round ratios.  Then where the time goes, in a pass of its own: mbcc's
 * eval alone against eval + factor + solve (interleaved rounds), and MuJoCo's
 * stage timers (mjcb_time) over as many mj_forward calls.  With --only mbcc|eval|forward N it runs N calls of one of
 * them (eval: mbcc's evaluation without the factor and solve) and nothing else (for valgrind --tool=cachegrind's instruction counts). */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <mujoco/mujoco.h>

#include "mb_kernels.h"
#include "mb_sim.h"

extern const mb_model *const peer_model;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* MuJoCo's timer callback: microseconds (its timers' unit is the callback's) */
static mjtNum mj_clock_us(void) { return 1e6 * now(); }

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *a, int n) {
  qsort(a, (size_t)n, sizeof *a, cmp_double);
  return n % 2 ? a[n / 2] : 0.5 * (a[n / 2 - 1] + a[n / 2]);
}

/* the body's global velocity of its centre of mass and angular velocity */
static void body_velocity(const mb_model *m, int b, const double *q, const double *v, double lin[3],
                          double ang[3]) {
  const mb_body *B = &m->body[b];
  double A[9];
  mb_euler_to_A(q + B->qadr + 3, A);
  for (int i = 0; i < 3; i++) lin[i] = v[B->vadr + i];
  mb_mul3(A, v + B->vadr + 3, ang);
}

static int mbcc_body(const mb_model *m, const char *name) {
  for (int b = 0; b < m->nbody; b++)
    if (!strcmp(m->body[b].name, name)) return b;
  return -1;
}

typedef struct {
  const mb_model *m;
  double *Kx, *rhs, *phi, *phid, *x, *lw;
  void *work;
} mbcc_eval;

/* one evaluation as the emitted path does it per step: eval, factor, solve */
static int mbcc_accel(mbcc_eval *e, const double *q, const double *v) {
  const mb_model *m = e->m;
  m->eval(m, 0, q, v, e->Kx, e->rhs, e->phi, e->phid, e->work);
  if (m->ldl_factor(m, e->Kx, e->lw)) return 1;
  memcpy(e->x, e->rhs, sizeof(double) * (size_t)m->n);
  return m->ldl_solve(m, e->Kx, e->lw, e->x, NULL);
}

/* MuJoCo's state from mbcc's (q at the design configuration, v), mbcc's element
 * forces as qfrc_applied, mj_forward; the largest differences of the body
 * velocities (*vrel) and accelerations (*arel, at body *aworst) relative to the
 * largest of each (*amax) */
static void compare_state(const mb_model *m, mjModel *mj, mjData *d, const int *bmap, const double *q,
                          const double *v, void *work, double *vrel, double *arel, double *amax_out,
                          int *aworst_out) {
  double *vd = malloc(sizeof(double) * (size_t)m->nv), *lam = malloc(sizeof(double) * ((size_t)m->nc + 1));
  mb_settings set;
  mb_settings_default(&set);
  mb_solver *ls = mb_solver_new("ldl", m);
  mb_sim sim;
  if (!vd || !lam || !ls || mb_sim_init(&sim, m, ls, &set) || mb_sim_accel(&sim, 0, q, v, vd, lam)) {
    fprintf(stderr, "mujoco_peer: error: mbcc accelerations failed\n");
    exit(2);
  }
  mju_copy(d->qpos, mj->qpos0, mj->nq);
  for (int j = 0; j < mj->njnt; j++) {
    int c = mj->jnt_bodyid[j], p = mj->body_parentid[c], da = mj->jnt_dofadr[j];
    double lc[3], ac[3], lp[3] = {0, 0, 0}, ap[3] = {0, 0, 0}, rel[3];
    body_velocity(m, bmap[c], q, v, lc, ac);
    if (p) body_velocity(m, bmap[p], q, v, lp, ap);
    const double *axis = mj->jnt_axis + 3 * j; /* local = global at the design configuration */
    switch (mj->jnt_type[j]) {
    case mjJNT_FREE:
      for (int i = 0; i < 3; i++) d->qvel[da + i] = lc[i];
      for (int i = 0; i < 3; i++) d->qvel[da + 3 + i] = v[m->body[bmap[c]].vadr + 3 + i];
      break;
    case mjJNT_BALL:
      for (int i = 0; i < 3; i++) d->qvel[da + i] = ac[i] - ap[i];
      break;
    case mjJNT_HINGE:
      d->qvel[da] = mju_dot3(axis, ac) - mju_dot3(axis, ap);
      break;
    case mjJNT_SLIDE: {
      const double *xc = q + m->body[bmap[c]].qadr, *xp = p ? q + m->body[bmap[p]].qadr : NULL;
      double r[3] = {0, 0, 0};
      if (xp) mju_sub3(r, xc, xp);
      mju_cross(rel, ap, r);
      double dv[3] = {lc[0] - lp[0] - rel[0], lc[1] - lp[1] - rel[1], lc[2] - lp[2] - rel[2]};
      d->qvel[da] = mju_dot3(axis, dv);
      break;
    }
    }
  }

  /* mbcc's force elements as MuJoCo applied forces: the wrench on body 1 about its
     point, and its reaction on body 0 about the same point */
  mju_zero(d->qfrc_applied, mj->nv);
  mj_forward(mj, d); /* mj_applyFT needs the bodies' positions and centres of mass */
  for (int k = 0; k < m->nforce; k++) {
    const mb_forcedef *fd = &m->force[k];
    double F[3], T[3], A[9], x[3], nF[3], nT[3];
    mb_force_wrench(m, k, 0, q, v, F, T, work);
    int mk = fd->m1 >= 0 ? fd->m1 : fd->m0;
    const mb_markerdef *md = &m->marker[mk];
    if (md->body >= 0) {
      const double *r = q + m->body[md->body].qadr;
      mb_euler_to_A(r + 3, A);
      mb_mul3(A, md->s, x);
      for (int i = 0; i < 3; i++) x[i] += r[i];
    } else {
      for (int i = 0; i < 3; i++) x[i] = md->s[i];
    }
    for (int i = 0; i < 3; i++) { nF[i] = -F[i]; nT[i] = -T[i]; }
    for (int side = 0; side < 2; side++) {
      int mkb = side ? mk : (fd->m1 >= 0 ? fd->m0 : -1);
      if (mkb < 0 || m->marker[mkb].body < 0) continue;
      int bid = -1;
      for (int i = 1; i < mj->nbody; i++)
        if (bmap[i] == m->marker[mkb].body) bid = i;
      mj_applyFT(mj, d, side ? F : nF, side ? T : nT, x, bid, d->qfrc_applied);
    }
  }

  /* the mapping check: MuJoCo's body velocities against mbcc's */
  mj_forward(mj, d);
  mj_rnePostConstraint(mj, d);
  double vmax = 0, verr = 0, amax = 0, aerr = 0;
  int aworst = 0;
  for (int i = 1; i < mj->nbody; i++) {
    double res[6], lin[3], ang[3], al[3], aa[3], A[9];
    mj_objectVelocity(mj, d, mjOBJ_BODY, i, res, 0);
    body_velocity(m, bmap[i], q, v, lin, ang);
    for (int k = 0; k < 3; k++) {
      vmax = fmax(vmax, fmax(fabs(lin[k]), fabs(ang[k])));
      verr = fmax(verr, fmax(fabs(res[3 + k] - lin[k]), fabs(res[k] - ang[k])));
    }
    /* accelerations: MuJoCo's cacc starts from -gravity at the world (an
       accelerometer's reading), so gravity is added back */
    mj_objectAcceleration(mj, d, mjOBJ_BODY, i, res, 0);
    const mb_body *B = &m->body[bmap[i]];
    mb_euler_to_A(q + B->qadr + 3, A);
    mb_mul3(A, vd + B->vadr + 3, aa);
    for (int k = 0; k < 3; k++) al[k] = vd[B->vadr + k];
    for (int k = 0; k < 3; k++) {
      double el = fabs(res[3 + k] + mj->opt.gravity[k] - al[k]), ea = fabs(res[k] - aa[k]);
      amax = fmax(amax, fmax(fabs(al[k]), fabs(aa[k])));
      if (fmax(el, ea) > aerr) { aerr = fmax(el, ea); aworst = i; }
      if (getenv("PEER_DEBUG"))
        fprintf(stderr, "%-20s %d lin mbcc %10.4g mj %10.4g  ang mbcc %10.4g mj %10.4g\n",
                mj_id2name(mj, mjOBJ_BODY, i), k, al[k], res[3 + k] + mj->opt.gravity[k], aa[k], res[k]);
    }
  }
  *vrel = verr / fmax(vmax, 1e-300);
  *arel = aerr / fmax(amax, 1e-300);
  *amax_out = amax;
  *aworst_out = aworst;
  mb_sim_free(&sim);
  ls->destroy(ls);
  free(vd);
  free(lam);
}


int main(int argc, char **argv) {
  const char *xml = NULL, *only = NULL, *csv = NULL;
  int reps = 200, rounds = 31, only_n = 0;
  unsigned seed = 1;
  double tol = 5e-3, vscale = 1.0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i];
    if (a[0] != '-') { xml = a; continue; }
    if (i + 1 >= argc) { fprintf(stderr, "mujoco_peer: error: '%s' needs a value\n", a); return 2; }
    if (!strcmp(a, "--reps")) reps = atoi(argv[++i]);
    else if (!strcmp(a, "--rounds")) rounds = atoi(argv[++i]);
    else if (!strcmp(a, "--seed")) seed = (unsigned)atoi(argv[++i]);
    else if (!strcmp(a, "--tol")) tol = atof(argv[++i]);
    else if (!strcmp(a, "--vscale")) vscale = atof(argv[++i]);
    else if (!strcmp(a, "--csv")) csv = argv[++i];
    else if (!strcmp(a, "--only")) {
      only = argv[++i];
      if (i + 1 >= argc) { fprintf(stderr, "mujoco_peer: error: '--only' needs a count\n"); return 2; }
      only_n = atoi(argv[++i]);
    } else { fprintf(stderr, "mujoco_peer: error: unknown option '%s'\n", a); return 2; }
  }
  if (!xml || reps < 1 || rounds < 1) {
    fprintf(stderr, "usage: mujoco_peer MODEL.xml [--reps N] [--rounds R] [--seed S] [--tol T] "
                    "[--vscale V] [--csv FILE] [--only mbcc|eval|forward N]\n");
    return 2;
  }
  const mb_model *m = peer_model;
  if (!m->ldl_factor || !m->ldl_solve) { fprintf(stderr, "mujoco_peer: error: no emitted LDL^T\n"); return 2; }
  char err[1000] = "";
  mjModel *mj = mj_loadXML(xml, NULL, err, sizeof err);
  if (!mj) { fprintf(stderr, "mujoco_peer: error: %s: %s\n", xml, err); return 2; }
  mjData *d = mj_makeData(mj);

  /* mbcc's state: q0, random velocities projected onto D v = nu */
  mb_settings set;
  mb_settings_default(&set);
  mb_solver *ls = mb_solver_new("ldl", m);
  mb_sim sim;
  if (!ls || mb_sim_init(&sim, m, ls, &set)) { fprintf(stderr, "mujoco_peer: error: mbcc set-up\n"); return 2; }
  double *q = malloc(sizeof(double) * (size_t)m->nq), *v = malloc(sizeof(double) * (size_t)m->nv);
  double *vd = malloc(sizeof(double) * (size_t)m->nv), *lam = malloc(sizeof(double) * ((size_t)m->nc + 1));
  memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
  srand(seed);
  for (int i = 0; i < m->nv; i++) v[i] = vscale * (2.0 * rand() / RAND_MAX - 1.0);
  if (mb_sim_project(&sim, 0, q, v) || mb_sim_accel(&sim, 0, q, v, vd, lam)) {
    fprintf(stderr, "mujoco_peer: error: mbcc projection or accelerations failed\n");
    return 2;
  }

  /* MuJoCo's joint velocities from mbcc's body velocities (design configuration) */
  int *bmap = malloc(sizeof(int) * (size_t)mj->nbody); /* MuJoCo body -> mbcc body (-1: world) */
  for (int i = 0; i < mj->nbody; i++) {
    bmap[i] = i ? mbcc_body(m, mj_id2name(mj, mjOBJ_BODY, i)) : -1;
    if (i && bmap[i] < 0) { fprintf(stderr, "mujoco_peer: error: body %s not in the mbcc model\n", mj_id2name(mj, mjOBJ_BODY, i)); return 2; }
  }
  if (mj->nbody - 1 != m->nbody) { fprintf(stderr, "mujoco_peer: error: %d bodies in MuJoCo, %d in mbcc\n", mj->nbody - 1, m->nbody); return 2; }
  void *work = malloc(mb_model_worksize(m) + 16);
  /* at rest, the only difference is the constraints' softness; in motion MuJoCo's
     constraint rows also leave out the term dJ/dt qdot of the exact acceleration
     constraint (its reference acceleration acts on the position and velocity
     errors only), which grows with the square of the velocities */
  double *v0 = calloc((size_t)m->nv, sizeof(double));
  double vrel0, arel0, amax0, vrel, arel, amax;
  int aworst0, aworst;
  compare_state(m, mj, d, bmap, q, v0, work, &vrel0, &arel0, &amax0, &aworst0);
  compare_state(m, mj, d, bmap, q, v, work, &vrel, &arel, &amax, &aworst);
  int ok = vrel < 1e-12 && arel0 < tol;

  mbcc_eval e = {m, NULL, NULL, NULL, NULL, NULL, NULL, work};
  e.Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  e.rhs = calloc((size_t)m->n, sizeof(double));
  e.x = calloc((size_t)m->n, sizeof(double));
  e.phi = calloc((size_t)m->nc + 1, sizeof(double));
  e.phid = calloc((size_t)m->nc + 1, sizeof(double));
  e.lw = calloc(m->ldl_worksize + 1, sizeof(double));
  m->init(m, e.Kx);
  double *qpos0 = malloc(sizeof(double) * (size_t)mj->nq), *qvel0 = malloc(sizeof(double) * (size_t)mj->nv);
  mju_copy(qpos0, d->qpos, mj->nq);
  mju_copy(qvel0, d->qvel, mj->nv);
  /* what the set-up allocated, released at the end (a leak check of make sanitize runs this program) */
  void *owned[] = {q, v, vd, lam, bmap, work, v0, e.Kx, e.rhs, e.x, e.phi, e.phid, e.lw, qpos0, qvel0};
  int status = ok ? 0 : 1;

  if (only) { /* N calls of one side, for cachegrind */
    for (int k = 0; k < only_n; k++) {
      if (!strcmp(only, "mbcc")) mbcc_accel(&e, q, v);
      else if (!strcmp(only, "eval")) m->eval(m, 0, q, v, e.Kx, e.rhs, e.phi, e.phid, e.work);
      else mj_forward(mj, d);
    }
    status = 0;
    goto release;
  }

  printf("model %s: mbcc n = %d (nq %d, nv %d, nc %d), nnz(K) %d, LDL^T %s; MuJoCo nq %d, nv %d, "
         "%d equality constraints (%d rows)\n", m->name, m->n, m->nq, m->nv, m->nc, m->nnz,
         m->ldl_straight ? "straight-line" : "looped", mj->nq, mj->nv, mj->neq, d->nefc);
  printf("state mapping: body velocities agree to %.1e of the largest\n", vrel);
  printf("accelerations at rest: largest difference %.2e of the largest (%.3g), at %s; tolerance %.0e: %s\n",
         arel0, amax0, mj_id2name(mj, mjOBJ_BODY, aworst0), tol, ok ? "agree" : "DISAGREE");
  printf("accelerations in motion (the timed state): largest difference %.2e of the largest (%.3g), at %s "
         "(MuJoCo's constraints omit dJ/dt qdot)\n", arel, amax, mj_id2name(mj, mjOBJ_BODY, aworst));

  /* timing, interleaved: per round REPS calls of each */
  double *tm = malloc(sizeof(double) * (size_t)rounds), *tf = malloc(sizeof(double) * (size_t)rounds);
  double *ts = malloc(sizeof(double) * (size_t)rounds), *rf = malloc(sizeof(double) * (size_t)rounds);
  double *rs = malloc(sizeof(double) * (size_t)rounds);
  for (int r = 0; r < rounds; r++) {
    double t0 = now();
    for (int k = 0; k < reps; k++) mbcc_accel(&e, q, v);
    double t1 = now();
    for (int k = 0; k < reps; k++) mj_forward(mj, d);
    double t2 = now();
    for (int k = 0; k < reps; k++) {
      mju_copy(d->qpos, qpos0, mj->nq);
      mju_copy(d->qvel, qvel0, mj->nv);
      d->time = 0;
      mj_step(mj, d);
    }
    double t3 = now();
    tm[r] = (t1 - t0) / reps;
    tf[r] = (t2 - t1) / reps;
    ts[r] = (t3 - t2) / reps;
    rf[r] = tm[r] / tf[r];
    rs[r] = tm[r] / ts[r];
  }
  double mm = median(tm, rounds), mf = median(tf, rounds), ms = median(ts, rounds);
  double fastest = tm[0] / tf[0]; /* after the sorts: the fastest mbcc call over the fastest mj_forward */
  double mrf = median(rf, rounds), mrs = median(rs, rounds);
  printf("per call, medians of %d interleaved rounds of %d calls: mbcc eval+factor+solve %.3g us, "
         "mj_forward %.3g us, mj_step %.3g us\n", rounds, reps, 1e6 * mm, 1e6 * mf, 1e6 * ms);
  printf("ratio mbcc / mj_forward %.3f (per-round range %.3f-%.3f; fastest rounds %.3f), mbcc / mj_step %.3f\n",
         mrf, rf[0], rf[rounds - 1], fastest, mrs);

  /* where the time goes, apart from the interleaved timing above (the timer
     callback costs MuJoCo a clock read per stage): mbcc's eval alone against
     its eval + factor + solve, in turn; MuJoCo's own stage timers over the
     same number of mj_forward calls */
  double *te = malloc(sizeof(double) * (size_t)rounds), *ta = malloc(sizeof(double) * (size_t)rounds);
  for (int r = 0; r < rounds; r++) {
    double t0 = now();
    for (int k = 0; k < reps; k++) m->eval(m, 0, q, v, e.Kx, e.rhs, e.phi, e.phid, e.work);
    double t1 = now();
    for (int k = 0; k < reps; k++) mbcc_accel(&e, q, v);
    double t2 = now();
    te[r] = (t1 - t0) / reps;
    ta[r] = (t2 - t1) / reps;
  }
  double me = median(te, rounds), ma = median(ta, rounds);
  mjcb_time = mj_clock_us;
  for (int k = 0; k < mjNTIMER; k++) d->timer[k].duration = 0, d->timer[k].number = 0;
  for (int k = 0; k < rounds * reps; k++) mj_forward(mj, d);
  mjcb_time = NULL;
#define MJ_US(t) (d->timer[t].number ? d->timer[t].duration / d->timer[t].number : 0.0)
  /* smooth dynamics: the position stage less making the constraints, velocity, actuation, acceleration;
     constraints: making their rows and the solver */
  double mj_make = MJ_US(mjTIMER_POS_MAKE) + MJ_US(mjTIMER_POS_PROJECT);
  double mj_smooth = MJ_US(mjTIMER_POSITION) - mj_make + MJ_US(mjTIMER_VELOCITY) + MJ_US(mjTIMER_ACTUATION) +
                     MJ_US(mjTIMER_ACCELERATION);
  double mj_cons = mj_make + MJ_US(mjTIMER_CONSTRAINT);
  printf("where the time goes (medians of %d rounds, apart from the timing above): mbcc eval %.3g us, "
         "factor + solve %.3g us; MuJoCo's stage timers (clock reads included: %.3g us a call in all): "
         "smooth dynamics %.3g us (kinematics %.3g, inertia and its factorization %.3g, velocity %.3g, "
         "acceleration %.3g), constraints %.3g us (making the %d rows %.3g, solving %.3g)\n",
         rounds, 1e6 * me, 1e6 * (ma - me), MJ_US(mjTIMER_FORWARD), mj_smooth, MJ_US(mjTIMER_POS_KINEMATICS),
         MJ_US(mjTIMER_POS_INERTIA), MJ_US(mjTIMER_VELOCITY), MJ_US(mjTIMER_ACCELERATION), mj_cons, d->nefc, mj_make,
         MJ_US(mjTIMER_CONSTRAINT));
  if (csv) {
    FILE *f = fopen(csv, "w");
    if (!f) { fprintf(stderr, "mujoco_peer: error: cannot write %s\n", csv); return 2; }
    fprintf(f, "model,n,mj_nv,mj_nefc,vel_map_rel,acc_rel_diff_rest,acc_rel_diff,acc_max,mbcc_us,forward_us,step_us,"
               "ratio_forward,ratio_forward_lo,ratio_forward_hi,ratio_step,rounds,reps,ratio_fastest,mbcc_eval_us,"
               "mbcc_factor_solve_us,mj_smooth_us,mj_constraint_us\n");
    fprintf(f, "%s,%d,%d,%d,%.2g,%.3g,%.3g,%.4g,%.4g,%.4g,%.4g,%.4f,%.4f,%.4f,%.4f,%d,%d,%.4f,%.4g,%.4g,%.4g,%.4g\n",
            m->name, m->n, mj->nv, d->nefc, vrel, arel0, arel, amax, 1e6 * mm, 1e6 * mf, 1e6 * ms, mrf, rf[0],
            rf[rounds - 1], mrs, rounds, reps, fastest, 1e6 * me, 1e6 * (ma - me), mj_smooth, mj_cons);
    fclose(f);
  }
  free(tm); free(tf); free(ts); free(rf); free(rs); free(te); free(ta);
release:
  for (size_t i = 0; i < sizeof owned / sizeof *owned; i++) free(owned[i]);
  mb_sim_free(&sim);
  ls->destroy(ls);
  mj_deleteData(d);
  mj_deleteModel(mj);
  return status;
}
