/* assemble.c: assembly analysis at t = 0 on the generic path: positions
 * corrected onto the constraints (Newton, minimum-norm steps), redundant
 * constraint rows found (QR with column pivoting of D^T) and removed,
 * velocities made consistent, and K checked for singularity. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "lower.h"

void dgelsd_(const int *m, const int *n, const int *nrhs, double *a, const int *lda, double *b,
             const int *ldb, double *s, const double *rcond, int *rank, double *work,
             const int *lwork, int *iwork, int *info);
void dgeqp3_(const int *m, const int *n, double *a, const int *lda, int *jpvt, double *tau,
             double *work, const int *lwork, int *info);
void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);

typedef struct {
  double *Kx, *rhs, *phi, *nu;
  void *work;
} evalbuf;

static int evalbuf_init(evalbuf *e, const mb_model *m) {
  e->Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  e->rhs = calloc((size_t)m->n + 1, sizeof(double));
  e->phi = calloc((size_t)m->nc + 1, sizeof(double));
  e->nu = calloc((size_t)m->nc + 1, sizeof(double));
  e->work = malloc(mb_model_worksize(m) + 16);
  return e->Kx && e->rhs && e->phi && e->nu && e->work ? 0 : -1;
}

static void evalbuf_free(evalbuf *e) {
  free(e->Kx); free(e->rhs); free(e->phi); free(e->nu); free(e->work);
}

static void evaluate(const mb_model *m, evalbuf *e, const double *q, const double *v) {
  m->init(m, e->Kx);
  m->eval(m, 0, q, v, e->Kx, e->rhs, e->phi, e->nu, e->work);
}

/* D (nc x nv, column-major) from the constraint rows of K */
static void dense_D(const mb_model *m, const double *Kx, double *D) {
  memset(D, 0, sizeof(double) * (size_t)m->nc * (size_t)m->nv);
  for (int c = 0; c < m->nv; c++)
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++)
      if (m->Ki[p] >= m->nv) D[(size_t)c * (size_t)m->nc + (size_t)(m->Ki[p] - m->nv)] = Kx[p];
}

/* zero the modal columns of D: the model is given undeformed and at rest
 * relative to its flexible bodies' frames, so assembly moves only the frames */
static void freeze_modes(const mb_model *m, double *D) {
  for (int b = 0; b < m->nbody; b++)
    for (int j = 0; j < m->body[b].nm; j++)
      memset(D + (size_t)(m->body[b].vadr + 6 + j) * (size_t)m->nc, 0, sizeof(double) * (size_t)m->nc);
}

/* minimum-norm least-squares solution of A x = b, A: mr x nc col-major
 * (destroyed); b has max(mr, nc) entries, x returned in b */
static int min_norm_solve(int mr, int nc, double *A, double *b) {
  if (mr == 0 || nc == 0) {
    for (int i = 0; i < nc; i++) b[i] = 0;
    return 0;
  }
  int nrhs = 1, lda = mr, ldb = mr > nc ? mr : nc, rank = 0, info = 0, lwork = -1;
  int mn = mr < nc ? mr : nc;
  double rcond = 1e-10, wq = 0;
  double *s = malloc(sizeof(double) * (size_t)mn);
  int *iwork = malloc(sizeof(int) * (size_t)(30 * mn + 64) * 4);
  if (!s || !iwork) { free(s); free(iwork); return -1; }
  dgelsd_(&mr, &nc, &nrhs, A, &lda, b, &ldb, s, &rcond, &rank, &wq, &lwork, iwork, &info);
  lwork = (int)wq + 1;
  double *work = malloc(sizeof(double) * (size_t)lwork);
  if (!work) { free(s); free(iwork); return -1; }
  dgelsd_(&mr, &nc, &nrhs, A, &lda, b, &ldb, s, &rcond, &rank, work, &lwork, iwork, &info);
  free(work); free(s); free(iwork);
  return info;
}

static double max_abs(const double *a, int n, int *where) {
  double mx = 0;
  int w = -1;
  for (int i = 0; i < n; i++)
    if (!(fabs(a[i]) <= mx)) { mx = fabs(a[i]); w = i; }
  if (where) *where = w;
  return mx;
}

/* rows on which row r depends: D_dep^T = D_indep^T c, report joints with |c| > 1e-6 */
static void explain_dependency(const lmodel *L, const double *D, const int *keep, int r) {
  const mb_model *m = &L->m;
  int nk = 0;
  for (int k = 0; k < m->nc; k++) nk += keep[k];
  double *A = malloc(sizeof(double) * (size_t)m->nv * (size_t)(nk + 1));
  double *b = malloc(sizeof(double) * (size_t)(m->nv + nk + 1));
  int *idx = malloc(sizeof(int) * (size_t)(nk + 1));
  if (!A || !b || !idx) { free(A); free(b); free(idx); return; }
  int c = 0;
  for (int k = 0; k < m->nc; k++) {
    if (!keep[k]) continue;
    idx[c] = k;
    for (int j = 0; j < m->nv; j++) A[(size_t)c * (size_t)m->nv + (size_t)j] = D[(size_t)j * (size_t)m->nc + (size_t)k];
    c++;
  }
  for (int j = 0; j < m->nv; j++) b[j] = D[(size_t)j * (size_t)m->nc + (size_t)r];
  char list[1024] = "";
  if (!min_norm_solve(m->nv, nk, A, b)) {
    for (int k = 0; k < nk; k++) {
      if (fabs(b[k]) < 1e-6) continue;
      const char *what = L->row_desc[idx[k]];
      /* name each element once: the text before ':' */
      const char *colon = strchr(what, ':');
      int len = colon ? (int)(colon - what) : (int)strlen(what);
      char item[256];
      snprintf(item, sizeof item, "%.*s", len, what);
      if (!strstr(list, item) && strlen(list) + strlen(item) + 4 < sizeof list) {
        if (list[0]) strcat(list, ", ");
        strcat(list, item);
      }
    }
  }
  if (list[0])
    diag_note(L->ir->path, L->row_loc[r], "it is a combination of rows of %s", list);
  free(A); free(b); free(idx);
}

int assemble_model(lmodel *L, int verbose) {
  mb_model *m = &L->m;
  const char *file = L->ir->path;
  evalbuf e = {0};
  int status = 2;
  double *D = NULL, *b = NULL;
  int *keep = NULL;
  if (evalbuf_init(&e, m)) goto out;
  size_t dn = (size_t)(m->nc > 0 ? m->nc : 1) * (size_t)(m->nv > 0 ? m->nv : 1);
  D = malloc(sizeof(double) * dn);
  b = malloc(sizeof(double) * (size_t)(m->nv + m->nc + 1));
  keep = malloc(sizeof(int) * (size_t)(m->nc + 1));
  if (!D || !b || !keep) goto out;

  /* 1. positions: Newton with minimum-norm steps (handles redundant rows) */
  int worst = -1, it;
  double res = 0;
  for (it = 0; it < 50; it++) {
    evaluate(m, &e, L->q0, L->v0);
    res = max_abs(e.phi, m->nc, &worst);
    if (res <= 1e-12) break;
    dense_D(m, e.Kx, D);
    if (it < 25) freeze_modes(m, D); /* then deform the bodies if they must */
    for (int r = 0; r < m->nc; r++) b[r] = -e.phi[r];
    if (min_norm_solve(m->nc, m->nv, D, b)) goto out;
    mb_model_qincrement(m, L->q0, b);
    mb_model_normalize(m, L->q0);
  }
  if (res > 1e-9) {
    diag_error(file, L->row_loc[worst],
               "the constraints cannot be satisfied: %s has residual %.3g after %d Newton "
               "iterations (inconsistent constraints, or a model not given in its assembled "
               "configuration)", L->row_desc[worst], res, it);
    goto out;
  }
  if (verbose && it > 0)
    fprintf(stderr, "%s: note: assembly: positions corrected in %d Newton iteration(s)\n", file, it);

  /* 2. redundant rows: rank of D^T by QR with column pivoting; driver rows first */
  evaluate(m, &e, L->q0, L->v0);
  dense_D(m, e.Kx, D);
  int rank = 0;
  if (m->nc > 0) {
    int nv = m->nv, nc = m->nc, info = 0, lwork = -1;
    double *At = malloc(sizeof(double) * (size_t)nv * (size_t)nc);
    int *jpvt = calloc((size_t)nc, sizeof(int));
    double *tau = malloc(sizeof(double) * (size_t)(nc + nv));
    double wq = 0;
    if (!At || !jpvt || !tau) { free(At); free(jpvt); free(tau); goto out; }
    for (int r = 0; r < nc; r++) {
      for (int j = 0; j < nv; j++) At[(size_t)r * (size_t)nv + (size_t)j] = D[(size_t)j * (size_t)nc + (size_t)r];
      jpvt[r] = L->row[r].driver >= 0 ? 1 : 0; /* keep drivers: they lead */
    }
    dgeqp3_(&nv, &nc, At, &nv, jpvt, tau, &wq, &lwork, &info);
    lwork = (int)wq + 1;
    double *work = malloc(sizeof(double) * (size_t)lwork);
    if (!work) { free(At); free(jpvt); free(tau); goto out; }
    dgeqp3_(&nv, &nc, At, &nv, jpvt, tau, work, &lwork, &info);
    free(work);
    int kmax = nc < nv ? nc : nv;
    double r00 = kmax > 0 ? fabs(At[0]) : 0;
    for (int k = 0; k < kmax; k++)
      if (fabs(At[(size_t)k * (size_t)nv + (size_t)k]) > 1e-9 * (r00 > 1 ? r00 : 1)) rank++;
    for (int r = 0; r < nc; r++) keep[r] = 0;
    for (int k = 0; k < rank; k++) keep[jpvt[k] - 1] = 1;
    free(At); free(jpvt); free(tau);
    if (rank < nc) {
      for (int r = 0; r < nc; r++) {
        if (keep[r]) continue;
        diag_warning(file, L->row_loc[r], "redundant constraint removed: %s", L->row_desc[r]);
        explain_dependency(L, D, keep, r);
      }
      L->nredundant += nc - rank;
      if (lower_remove_rows(L, keep)) goto out;
      evalbuf_free(&e);
      if (evalbuf_init(&e, m)) goto out;
    }
  }
  L->dof = m->nv - rank;

  /* 3. velocities: minimum-norm correction onto D v = nu (e.nu holds phid = D v - nu) */
  evaluate(m, &e, L->q0, L->v0);
  if (m->nc > 0) {
    dense_D(m, e.Kx, D);
    for (int r = 0; r < m->nc; r++) b[r] = -e.nu[r];
    freeze_modes(m, D);
    if (min_norm_solve(m->nc, m->nv, D, b)) goto out;
    for (int j = 0; j < m->nv; j++) L->v0[j] += b[j];
  }

  /* 4. K must be nonsingular: massless bodies fully determined by their joints */
  evaluate(m, &e, L->q0, L->v0);
  {
    int n = m->n, info = 0;
    double *K = calloc((size_t)n * (size_t)n + 1, sizeof(double));
    int *ipiv = malloc(sizeof(int) * (size_t)(n + 1));
    if (!K || !ipiv) { free(K); free(ipiv); goto out; }
    for (int c = 0; c < n; c++)
      for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++) K[(size_t)c * (size_t)n + (size_t)m->Ki[p]] = e.Kx[p];
    if (n > 0) dgetrf_(&n, &n, K, &n, ipiv, &info);
    free(K); free(ipiv);
    if (info > 0) {
      diag_error(file, (ir_loc){1, 1},
                 "the system matrix K = [M D^T; D 0] is singular at t = 0: some motion has "
                 "neither mass nor a constraint");
      for (int b2 = 0; b2 < m->nbody; b2++)
        if (L->body[b2].kind == MB_BODY_VIRTUAL)
          diag_note(file, b2 + 1 < L->ir->nbodies ? L->ir->bodies[b2 + 1].loc : (ir_loc){0, 0},
                    "massless body '%s' must be fully determined by its joints",
                    L->body[b2].name);
      goto out;
    }
  }
  status = 0;
out:
  if (status && diag_errors() == 0) diag_error(file, (ir_loc){0, 0}, "assembly analysis failed (out of memory or LAPACK error)");
  evalbuf_free(&e);
  free(D); free(b); free(keep);
  return status;
}
