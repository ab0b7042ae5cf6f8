/* ida.c: the model's DAE F(t, y, y') = 0, y = [q; v; lambda], integrated by
 * SUNDIALS IDA, either with dense LU and a difference-quotient Jacobian or
 * with KLU on a sparse Jacobian assembled from the model's analytic pieces
 * (mb_ida.h). */
#define _POSIX_C_SOURCE 199309L
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <ida/ida.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunlinsol/sunlinsol_klu.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunmatrix/sunmatrix_sparse.h>

#include "mb_ida.h"
#include "mb_kernels.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
  const mb_model *m;
  double *Kx;        /* nnz: K, constant entries from m->init */
  double *rhs;       /* n: [f; gamma] */
  double *phi, *phid; /* nc: constraint violations (unused) */
  double *x, *Kxv;   /* n: [vdot; lambda] and K times it */
  double *qd;        /* nq: G(q) v */
  double *qn;        /* nq: normalized positions for the outputs */
  void *work;        /* mb_model_worksize */
  mb_solver *ls;     /* dense: consistent initial values and output accelerations */
  double t_eval;
  /* MB_IDA_KLU: the Jacobian's CSC pattern over y (N + 1, nnz) and where K's
     slots land in it (m->nnz) */
  int jN, jnnz;
  int *Jp, *Ji, *kpos;
  double *Jx;        /* jnnz: the values (mb_ida_jacobian_dense) */
} ida_ctx;

int mb_ida_size(const mb_model *m) { return m->nq + m->nv + m->nc; }

/* F = [qdot - G(q) v; K [vdot; lambda] - [f; gamma]] */
static int residual(sunrealtype t, N_Vector yy, N_Vector yp, N_Vector rr, void *user) {
  ida_ctx *c = user;
  const mb_model *m = c->m;
  const double *y = N_VGetArrayPointer(yy), *d = N_VGetArrayPointer(yp);
  double *r = N_VGetArrayPointer(rr);
  int nq = m->nq, nv = m->nv, n = m->n;
  const double *q = y, *v = y + nq, *lam = y + nq + nv;
  double t0 = now();
  m->eval(m, t, q, v, c->Kx, c->rhs, c->phi, c->phid, c->work);
  c->t_eval += now() - t0;
  mb_model_qdot(m, q, v, c->qd);
  for (int i = 0; i < nq; i++) r[i] = d[i] - c->qd[i];
  memcpy(c->x, d + nq, sizeof(double) * (size_t)nv);
  memcpy(c->x + nv, lam, sizeof(double) * (size_t)m->nc);
  for (int i = 0; i < n; i++) c->Kxv[i] = 0;
  for (int j = 0; j < n; j++) {
    double xj = c->x[j];
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) c->Kxv[m->Ki[p]] += c->Kx[p] * xj;
  }
  for (int i = 0; i < n; i++) r[nq + i] = c->Kxv[i] - c->rhs[i];
  for (int i = 0; i < nq + n; i++)
    if (!isfinite(r[i])) return 1; /* recoverable: IDA retries with a smaller step */
  return 0;
}

/* ---- the analytic sparse Jacobian J = dF/dy + cj dF/dy' (MB_IDA_KLU) ----
 * Over y = [q; v; lambda], with F_q = q' - G(q) v and F_K = K(q) [v'; lambda] - [f; gamma]:
 *   q rows:  cj I - d(G v)/dq (exact: Euler-parameter rates are bilinear in p and omega),
 *            -G(q) in the v columns (exact);
 *   K rows:  cj K in the v columns and K in the lambda columns (exact: the emitted K),
 *            the flexible bodies' modal stiffness (q columns) and damping (v columns) (exact);
 *            the q and v derivatives of the remaining terms (gyroscopic, D(q)^T lambda, forces,
 *            gamma) are not emitted by mbcc and are left out.
 * IDA's modified Newton converges with this matrix (the residual is exact, so the
 * accuracy is the tolerance's); tests/test_ida.c checks the exact parts against
 * difference quotients of the residual. */
typedef struct { int col, row; } jentry;

static int cmp_jentry(const void *a, const void *b) {
  const jentry *x = a, *y = b;
  if (x->col != y->col) return (x->col > y->col) - (x->col < y->col);
  return (x->row > y->row) - (x->row < y->row);
}

/* the index of (row, col) in the pattern, or -1 */
static int jpos(const ida_ctx *c, int row, int col) {
  int lo = c->Jp[col], hi = c->Jp[col + 1] - 1;
  while (lo <= hi) {
    int mid = (lo + hi) / 2;
    if (c->Ji[mid] == row) return mid;
    if (c->Ji[mid] < row) lo = mid + 1;
    else hi = mid - 1;
  }
  return -1;
}

/* the pattern's entries into e (when not NULL; they may repeat); returns their count */
static int jac_entries(const mb_model *m, jentry *e) {
  int k = 0, nq = m->nq;
#define ADD(r, cc) do { if (e) { e[k].row = (r); e[k].col = (cc); } k++; } while (0)
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    int qa = B->qadr, va = nq + B->vadr;
    for (int i = 0; i < 3; i++) { ADD(qa + i, qa + i); ADD(qa + i, va + i); }
    for (int r = 0; r < 4; r++) {
      for (int i = 0; i < 4; i++) ADD(qa + 3 + r, qa + 3 + i);
      for (int i = 0; i < 3; i++) ADD(qa + 3 + r, va + 3 + i);
    }
    for (int j = 0; j < B->nm; j++) {
      ADD(qa + 7 + j, qa + 7 + j);
      ADD(qa + 7 + j, va + 6 + j);
      ADD(va + 6 + j, qa + 7 + j);
      ADD(va + 6 + j, va + 6 + j);
    }
  }
  for (int j = 0; j < m->n; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) ADD(nq + m->Ki[p], nq + j);
#undef ADD
  return k;
}

static int jac_pattern(ida_ctx *c) {
  const mb_model *m = c->m;
  int ne = jac_entries(m, NULL), N = m->nq + m->n;
  jentry *e = malloc(sizeof *e * (size_t)ne);
  c->Jp = calloc((size_t)N + 1, sizeof(int));
  c->Ji = malloc(sizeof(int) * (size_t)ne);
  c->Jx = malloc(sizeof(double) * (size_t)ne);
  c->kpos = malloc(sizeof(int) * ((size_t)m->nnz + 1));
  if (!e || !c->Jp || !c->Ji || !c->Jx || !c->kpos) { free(e); return MB_ERR_NOMEM; }
  jac_entries(m, e);
  qsort(e, (size_t)ne, sizeof *e, cmp_jentry);
  int nnz = 0;
  for (int i = 0; i < ne; i++) {
    if (nnz && e[i].col == e[nnz - 1].col && e[i].row == e[nnz - 1].row) continue;
    e[nnz++] = e[i];
  }
  for (int i = 0; i < nnz; i++) {
    c->Ji[i] = e[i].row;
    c->Jp[e[i].col + 1]++;
  }
  for (int j = 0; j < N; j++) c->Jp[j + 1] += c->Jp[j];
  free(e);
  c->jN = N;
  c->jnnz = nnz;
  for (int j = 0; j < m->n; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) c->kpos[p] = jpos(c, m->nq + m->Ki[p], m->nq + j);
  return MB_OK;
}

/* the values of J at (t, y) for cj into c->Jx (on c->Jp, c->Ji) */
static void jac_values(ida_ctx *c, double t, const double *y, double cj) {
  const mb_model *m = c->m;
  int nq = m->nq, nv = m->nv;
  const double *q = y, *v = y + nq;
  double t0 = now();
  m->eval(m, t, q, v, c->Kx, c->rhs, c->phi, c->phid, c->work);
  c->t_eval += now() - t0;
  double *J = c->Jx;
  memset(J, 0, sizeof(double) * (size_t)c->jnnz);
  for (int j = 0; j < m->n; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++) J[c->kpos[p]] += (j < nv ? cj : 1.0) * c->Kx[p];
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    int qa = B->qadr, va = nq + B->vadr;
    for (int i = 0; i < 3; i++) {
      J[jpos(c, qa + i, qa + i)] += cj;
      J[jpos(c, qa + i, va + i)] -= 1;
    }
    const double *p = q + qa + 3, *w = v + B->vadr + 3;
    for (int i = 0; i < 4; i++) { /* d(pdot)/dp_i: the rates of the unit vector e_i */
      double e[4] = {0, 0, 0, 0}, col[4];
      e[i] = 1;
      mb_euler_rates(e, w, col);
      for (int r = 0; r < 4; r++) J[jpos(c, qa + 3 + r, qa + 3 + i)] += (r == i ? cj : 0.0) - col[r];
    }
    for (int i = 0; i < 3; i++) { /* d(pdot)/domega_i */
      double e[3] = {0, 0, 0}, col[4];
      e[i] = 1;
      mb_euler_rates(p, e, col);
      for (int r = 0; r < 4; r++) J[jpos(c, qa + 3 + r, va + 3 + i)] -= col[r];
    }
    for (int j = 0; j < B->nm; j++) {
      J[jpos(c, qa + 7 + j, qa + 7 + j)] += cj;
      J[jpos(c, qa + 7 + j, va + 6 + j)] -= 1;
      if (B->flex) {
        J[jpos(c, va + 6 + j, qa + 7 + j)] += B->flex->stiffness[j];
        J[jpos(c, va + 6 + j, va + 6 + j)] += B->flex->damping[j];
      }
    }
  }
}

static int jac_klu(sunrealtype t, sunrealtype cj, N_Vector yy, N_Vector yp, N_Vector rr, SUNMatrix A,
                   void *user, N_Vector t1, N_Vector t2, N_Vector t3) {
  (void)yp; (void)rr; (void)t1; (void)t2; (void)t3;
  ida_ctx *c = user;
  jac_values(c, t, N_VGetArrayPointer(yy), cj);
  sunindextype *Ap = SUNSparseMatrix_IndexPointers(A), *Ai = SUNSparseMatrix_IndexValues(A);
  double *Ax = SUNSparseMatrix_Data(A);
  for (int j = 0; j <= c->jN; j++) Ap[j] = c->Jp[j];
  for (int k = 0; k < c->jnnz; k++) {
    Ai[k] = c->Ji[k];
    Ax[k] = c->Jx[k];
  }
  for (int k = 0; k < c->jnnz; k++)
    if (!isfinite(Ax[k])) return 1;
  return 0;
}

/* IDA reports errors through this hook; the runtime never prints */
static void silent(int code, const char *module, const char *function, char *msg, void *user) {
  (void)code; (void)module; (void)function; (void)msg; (void)user;
}

/* vdot and lambda at (t, q, v): eval, factor, solve (into c->x) */
static int accel(ida_ctx *c, double t, const double *q, const double *v) {
  const mb_model *m = c->m;
  double t0 = now();
  m->eval(m, t, q, v, c->Kx, c->rhs, c->phi, c->phid, c->work);
  c->t_eval += now() - t0;
  int st = c->ls->factor(c->ls, c->Kx);
  if (st) return st;
  memcpy(c->x, c->rhs, sizeof(double) * (size_t)m->n);
  st = c->ls->solve(c->ls, c->x);
  if (st) return st;
  for (int i = 0; i < m->n; i++)
    if (!isfinite(c->x[i])) return MB_ERR_NONFINITE;
  return MB_OK;
}

/* the output at t: positions with normalized Euler parameters */
static int emit(ida_ctx *c, double t, const double *y, mb_output_fn out, void *user, int *stop) {
  const mb_model *m = c->m;
  memcpy(c->qn, y, sizeof(double) * (size_t)m->nq);
  mb_model_normalize(m, c->qn);
  const double *v = y + m->nq;
  int st = accel(c, t, c->qn, v);
  if (st) return st;
  if (out && out(user, t, c->qn, v, c->x, c->x + m->nv)) *stop = 1;
  return MB_OK;
}

static int map_flag(int flag) {
  switch (flag) {
  case IDA_MEM_FAIL: return MB_ERR_NOMEM;
  case IDA_ILL_INPUT: return MB_ERR_INVALID;
  case IDA_LSETUP_FAIL: case IDA_LSOLVE_FAIL: case IDA_LINIT_FAIL: return MB_ERR_SINGULAR;
  case IDA_RES_FAIL: case IDA_REP_RES_ERR: case IDA_FIRST_RES_FAIL: return MB_ERR_NONFINITE;
  default: return MB_ERR_STEP_TOO_SMALL; /* too much work, error test or convergence failures */
  }
}

/* Tolerances: rtol and atol on q and v.  The multipliers are out of the error test
 * (IDASetSuppressAlg) but IDA's Newton test still weighs them; with atol alone, a
 * multiplier that vanishes would have to converge to atol in absolute terms, below the
 * round-off that the large multipliers leave in it (about eps * cond(K) * max|lambda|),
 * and at rtol 1e-13 Newton never converges.  They get an absolute tolerance of
 * sqrt(eps) times the largest initial multiplier (at least 1) instead. */
static int set_tolerances(void *mem, const mb_settings *s, int ndiff, int nc, const double *lam0,
                          SUNContext ctx) {
  double big = 1;
  for (int i = 0; i < nc; i++) big = fmax(big, fabs(lam0[i]));
  N_Vector av = N_VNew_Serial(ndiff + nc, ctx);
  if (!av) return IDA_MEM_FAIL;
  double *a = N_VGetArrayPointer(av);
  for (int i = 0; i < ndiff + nc; i++) a[i] = i < ndiff ? s->atol : fmax(s->atol, sqrt(DBL_EPSILON) * big);
  int flag = IDASVtolerances(mem, s->rtol, av);
  N_VDestroy(av);
  return flag;
}

int mb_ida_simulate(const mb_model *m, const mb_settings *s, mb_output_fn out, void *user,
                    mb_stats *stats, double *fail_time) {
  return mb_ida_run(m, s, MB_IDA_DENSE, out, user, stats, fail_time);
}

int mb_ida_run(const mb_model *m, const mb_settings *s, int linsol, mb_output_fn out, void *user,
               mb_stats *stats, double *fail_time) {
  double wall0 = now();
  if (stats) memset(stats, 0, sizeof *stats);
  if (fail_time) *fail_time = 0;
  if (!(s->end_time > 0) || !(s->output_step > 0) || !(s->rtol > 0) || !(s->atol > 0) ||
      (linsol != MB_IDA_DENSE && linsol != MB_IDA_KLU))
    return MB_ERR_INVALID;
  int nq = m->nq, nv = m->nv, nc = m->nc, n = m->n, N = nq + nv + nc;
  ida_ctx c = {0};
  c.m = m;
  c.Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  c.rhs = calloc((size_t)n + 1, sizeof(double));
  c.phi = calloc((size_t)nc + 1, sizeof(double));
  c.phid = calloc((size_t)nc + 1, sizeof(double));
  c.x = calloc((size_t)n + 1, sizeof(double));
  c.Kxv = calloc((size_t)n + 1, sizeof(double));
  c.qd = calloc((size_t)nq + 1, sizeof(double));
  c.qn = calloc((size_t)nq + 1, sizeof(double));
  c.work = malloc(mb_model_worksize(m) + 16);
  c.ls = mb_solver_new("dense", m);
  SUNContext ctx = NULL;
  N_Vector yy = NULL, yp = NULL, id = NULL;
  SUNMatrix A = NULL;
  SUNLinearSolver LS = NULL;
  void *mem = NULL;
  int st = MB_OK, stop = 0, flag = 0;
  double t = 0, *y, *d, *idv;
  long nout = (long)floor(s->end_time / s->output_step + 1e-9);
  long nsteps = 0, nres = 0, nlres = 0, netf = 0, ncf = 0, nni = 0, nset = 0, nje = 0;

  if (!c.Kx || !c.rhs || !c.phi || !c.phid || !c.x || !c.Kxv || !c.qd || !c.qn || !c.work || !c.ls) {
    st = MB_ERR_NOMEM;
    goto done;
  }
  m->init(m, c.Kx);
  if (SUNContext_Create(NULL, &ctx)) { ctx = NULL; st = MB_ERR_NOMEM; goto done; }
  yy = N_VNew_Serial(N, ctx);
  yp = N_VNew_Serial(N, ctx);
  id = N_VNew_Serial(N, ctx);
  if (!yy || !yp || !id) { st = MB_ERR_NOMEM; goto done; }

  /* consistent initial values: q0, v0 and one solve of K for vdot, lambda */
  y = N_VGetArrayPointer(yy);
  d = N_VGetArrayPointer(yp);
  idv = N_VGetArrayPointer(id);
  memcpy(y, m->q0, sizeof(double) * (size_t)nq);
  memcpy(y + nq, m->v0, sizeof(double) * (size_t)nv);
  if ((st = accel(&c, 0, y, y + nq))) goto done;
  memcpy(y + nq + nv, c.x + nv, sizeof(double) * (size_t)nc);
  mb_model_qdot(m, y, y + nq, d);
  memcpy(d + nq, c.x, sizeof(double) * (size_t)nv);
  for (int i = 0; i < nc; i++) d[nq + nv + i] = 0;
  for (int i = 0; i < N; i++) idv[i] = i < nq + nv ? 1.0 : 0.0;

  mem = IDACreate(ctx);
  if (!mem) { st = MB_ERR_NOMEM; goto done; }
  flag = IDASetErrHandlerFn(mem, silent, NULL);
  if (!flag) flag = IDAInit(mem, residual, 0.0, yy, yp);
  if (!flag) flag = set_tolerances(mem, s, nq + nv, nc, y + nq + nv, ctx);
  if (!flag) flag = IDASetUserData(mem, &c);
  if (!flag) flag = IDASetId(mem, id);
  /* lambda out of the error test: multipliers that vanish (e.g. reactions
     across the plane of a planar mechanism) carry the round-off of the large
     ones and would fail any absolute tolerance; they follow from q and v */
  if (!flag) flag = IDASetSuppressAlg(mem, SUNTRUE);
  if (!flag) flag = IDASetMaxNumSteps(mem, 10000000L);
  /* up to 8 Newton iterations per step (IDA's default is 4): at rtol 1e-12
     (make bench's agreement runs) the difference-quotient Jacobian, kept over
     many steps, needs more than 4, and IDA would otherwise cut the step
     until it gives up (the flexible slider-crank at t = 0.071) */
  if (!flag) flag = IDASetMaxNonlinIters(mem, 8);
  if (!flag && s->max_step > 0) flag = IDASetMaxStep(mem, s->max_step);
  if (!flag && s->min_step > 0) flag = IDASetMinStep(mem, s->min_step);
  if (!flag) flag = IDASetStopTime(mem, (double)nout * s->output_step);
  if (flag) { st = map_flag(flag); goto done; }
  if (linsol == MB_IDA_KLU) {
    if ((st = jac_pattern(&c))) goto done;
    A = SUNSparseMatrix(N, N, c.jnnz, CSC_MAT, ctx);
    LS = A ? SUNLinSol_KLU(yy, A, ctx) : NULL;
  } else {
    A = SUNDenseMatrix(N, N, ctx);
    LS = A ? SUNLinSol_Dense(yy, A, ctx) : NULL;
  }
  if (!A || !LS) { st = MB_ERR_NOMEM; goto done; }
  if ((flag = IDASetLinearSolver(mem, LS, A))) { st = map_flag(flag); goto done; }
  if (linsol == MB_IDA_KLU && (flag = IDASetJacFn(mem, jac_klu))) { st = map_flag(flag); goto done; }

  if (stats) stats->t_setup = now() - wall0;
  if ((st = emit(&c, 0, y, out, user, &stop)) || stop) goto done;
  for (long k = 1; k <= nout; k++) {
    double tout = (double)k * s->output_step, tret = t;
    flag = IDASolve(mem, tout, &tret, yy, yp, IDA_NORMAL);
    if (flag < 0) {
      IDAGetCurrentTime(mem, &t);
      st = map_flag(flag);
      goto done;
    }
    t = tout;
    y = N_VGetArrayPointer(yy);
    if ((st = emit(&c, tout, y, out, user, &stop)) || stop) goto done;
  }

done:
  if (mem) {
    IDAGetNumSteps(mem, &nsteps);
    IDAGetNumResEvals(mem, &nres);
    IDAGetNumLinResEvals(mem, &nlres);
    IDAGetNumErrTestFails(mem, &netf);
    IDAGetNumNonlinSolvConvFails(mem, &ncf);
    IDAGetNumNonlinSolvIters(mem, &nni);
    IDAGetNumLinSolvSetups(mem, &nset);
    IDAGetNumJacEvals(mem, &nje);
  }
  if (stats) {
    stats->steps = nsteps;
    stats->rejected = netf + ncf;
    stats->evals = nres + nlres;
    stats->solves = nni;
    stats->factorizations = nset;
    stats->full_factorizations = nje;
    stats->t_assembly = c.t_eval;
  }
  if (st && fail_time) *fail_time = t;
  IDAFree(&mem);
  if (LS) SUNLinSolFree(LS);
  if (A) SUNMatDestroy(A);
  if (yy) N_VDestroy(yy);
  if (yp) N_VDestroy(yp);
  if (id) N_VDestroy(id);
  if (ctx) SUNContext_Free(&ctx);
  if (c.ls) c.ls->destroy(c.ls);
  free(c.Kx); free(c.rhs); free(c.phi); free(c.phid); free(c.x); free(c.Kxv); free(c.qd);
  free(c.qn); free(c.work);
  free(c.Jp); free(c.Ji); free(c.Jx); free(c.kpos);
  if (stats) stats->t_total = now() - wall0;
  return st;
}

/* ---- for tests: the residual and the analytic Jacobian at one point ---- */
static int ctx_open(ida_ctx *c, const mb_model *m) {
  memset(c, 0, sizeof *c);
  c->m = m;
  c->Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  c->rhs = calloc((size_t)m->n + 1, sizeof(double));
  c->phi = calloc((size_t)m->nc + 1, sizeof(double));
  c->phid = calloc((size_t)m->nc + 1, sizeof(double));
  c->x = calloc((size_t)m->n + 1, sizeof(double));
  c->Kxv = calloc((size_t)m->n + 1, sizeof(double));
  c->qd = calloc((size_t)m->nq + 1, sizeof(double));
  c->work = malloc(mb_model_worksize(m) + 16);
  if (!c->Kx || !c->rhs || !c->phi || !c->phid || !c->x || !c->Kxv || !c->qd || !c->work) return MB_ERR_NOMEM;
  m->init(m, c->Kx);
  return jac_pattern(c);
}

static void ctx_close(ida_ctx *c) {
  free(c->Kx); free(c->rhs); free(c->phi); free(c->phid); free(c->x); free(c->Kxv); free(c->qd);
  free(c->work); free(c->Jp); free(c->Ji); free(c->Jx); free(c->kpos);
}

int mb_ida_residual(const mb_model *m, double t, const double *y, const double *yp, double *r) {
  ida_ctx c;
  int st = ctx_open(&c, m), N = m->nq + m->n;
  if (!st) {
    SUNContext ctx = NULL;
    N_Vector yy = NULL, pp = NULL, rr = NULL;
    if (SUNContext_Create(NULL, &ctx)) ctx = NULL;
    if (ctx) { yy = N_VMake_Serial(N, (double *)y, ctx); pp = N_VMake_Serial(N, (double *)yp, ctx);
               rr = N_VMake_Serial(N, r, ctx); }
    if (!yy || !pp || !rr) st = MB_ERR_NOMEM;
    else if (residual(t, yy, pp, rr, &c)) st = MB_ERR_NONFINITE;
    if (yy) N_VDestroy(yy);
    if (pp) N_VDestroy(pp);
    if (rr) N_VDestroy(rr);
    if (ctx) SUNContext_Free(&ctx);
  }
  ctx_close(&c);
  return st;
}

int mb_ida_klu_nnz(const mb_model *m) {
  ida_ctx c;
  memset(&c, 0, sizeof c);
  c.m = m;
  int nnz = jac_pattern(&c) ? 0 : c.jnnz;
  free(c.Jp); free(c.Ji); free(c.Jx); free(c.kpos);
  return nnz;
}

int mb_ida_jacobian_dense(const mb_model *m, double t, const double *y, double cj, double *J,
                          int *nnz) {
  ida_ctx c;
  int st = ctx_open(&c, m), N = m->nq + m->n;
  if (!st) {
    jac_values(&c, t, y, cj);
    memset(J, 0, sizeof(double) * (size_t)N * (size_t)N);
    for (int j = 0; j < N; j++)
      for (int k = c.Jp[j]; k < c.Jp[j + 1]; k++) J[(size_t)j * (size_t)N + (size_t)c.Ji[k]] = c.Jx[k];
    if (nnz) *nnz = c.jnnz;
  }
  ctx_close(&c);
  return st;
}
