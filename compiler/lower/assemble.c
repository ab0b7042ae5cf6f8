/* assemble.c: assembly analysis at t = 0 on the generic path: positions
 * corrected onto the constraints (Newton, minimum-norm steps), redundant
 * constraint rows found and removed, velocities made consistent, and K
 * checked for singularity.
 *
 * Everything is sparse, so the analysis grows about linearly with the model:
 * the constraint Jacobian D (nc x nv) is kept by rows, and a row basis is a
 * rank-revealing sparse QR of D^T (SuiteSparseQR) in a fixed column order --
 * drivers first, then the rows in model order -- so a row is redundant when
 * it depends on the rows before it (the later joint of a closed loop gives
 * way).  Minimum-norm solves over the independent rows use the triangular
 * factor only: D_k D_k^T = R^T R (semi-normal equations, one refinement
 * step); K's singularity check is a KLU factorization. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/SuiteSparseQR_C.h>
#include <suitesparse/klu.h>

#include "diag.h"
#include "lower.h"

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

/* D by rows (CSR, nc x nv): row r's velocity columns ascending */
typedef struct {
  int nc, nv;
  int *p, *j;
  double *x;
} rows_matrix;

static void rows_free(rows_matrix *D) {
  free(D->p); free(D->j); free(D->x);
  memset(D, 0, sizeof *D);
}

/* D from the constraint rows of K; frozen columns (modal coordinates, see
 * frozen_modes) are left out */
static int rows_from_K(const mb_model *m, const double *Kx, const char *frozen, rows_matrix *D) {
  rows_free(D);
  D->nc = m->nc;
  D->nv = m->nv;
  D->p = calloc((size_t)m->nc + 1, sizeof(int));
  int nnz = 0;
  for (int c = 0; c < m->nv; c++)
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++) nnz += m->Ki[p] >= m->nv;
  D->j = malloc(sizeof(int) * (size_t)(nnz + 1));
  D->x = malloc(sizeof(double) * (size_t)(nnz + 1));
  if (!D->p || !D->j || !D->x) return -1;
  for (int c = 0; c < m->nv; c++)
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++)
      if (m->Ki[p] >= m->nv && !(frozen && frozen[c])) D->p[m->Ki[p] - m->nv + 1]++;
  for (int r = 0; r < m->nc; r++) D->p[r + 1] += D->p[r];
  int *next = malloc(sizeof(int) * (size_t)(m->nc + 1));
  if (!next) return -1;
  memcpy(next, D->p, sizeof(int) * (size_t)m->nc);
  for (int c = 0; c < m->nv; c++) /* ascending c: each row's columns come sorted */
    for (int p = m->Kp[c]; p < m->Kp[c + 1]; p++)
      if (m->Ki[p] >= m->nv && !(frozen && frozen[c])) {
        int at = next[m->Ki[p] - m->nv]++;
        D->j[at] = c;
        D->x[at] = Kx[p];
      }
  free(next);
  return 0;
}

/* the modal columns of D: the model is given undeformed and at rest relative
 * to its flexible bodies' frames, so assembly moves only the frames */
static char *frozen_modes(const mb_model *m) {
  char *frozen = calloc((size_t)m->nv + 1, 1);
  if (!frozen) return NULL;
  for (int b = 0; b < m->nbody; b++)
    for (int j = 0; j < m->body[b].nm; j++) frozen[m->body[b].vadr + 6 + j] = 1;
  return frozen;
}

static double row_dot(const rows_matrix *D, int r, const double *v) {
  double s = 0;
  for (int p = D->p[r]; p < D->p[r + 1]; p++) s += D->x[p] * v[D->j[p]];
  return s;
}

/* A row basis of D: rank rows ('live', in the factor's column order) that
 * span the rows of D, and the triangular factor R (rank x rank leading block)
 * of QR(D_live^T) */
typedef struct {
  int rank;
  int *live;
  cholmod_sparse *R;
  int *col;        /* R's column of live row k */
  int *diag;       /* position of R(k,k) in that column */
} row_basis;

static void basis_free(row_basis *B, cholmod_common *cc) {
  free(B->live); free(B->col); free(B->diag);
  if (B->R) cholmod_l_free_sparse(&B->R, cc);
  memset(B, 0, sizeof *B);
}

/* Rows are tried in the order 'order' (nc entries); a row whose part
 * independent of the rows before it has 2-norm <= 1e-9 max(largest row norm,
 * 1) is redundant (the tolerance of the dense column-pivoted QR this replaces). */
static int basis_factor(const rows_matrix *D, const int *order, row_basis *B, cholmod_common *cc) {
  memset(B, 0, sizeof *B);
  if (D->nc == 0) return 0;
  int nnz = D->p[D->nc];
  cholmod_sparse *A = cholmod_l_allocate_sparse((size_t)D->nv, (size_t)D->nc, (size_t)(nnz + 1), 1, 1, 0,
                                                CHOLMOD_REAL, cc);
  if (!A) return -1;
  SuiteSparse_long *Ap = A->p, *Ai = A->i;
  double *Ax = A->x, biggest = 0;
  Ap[0] = 0;
  for (int k = 0; k < D->nc; k++) {
    int r = order[k];
    double norm2 = 0;
    SuiteSparse_long at = Ap[k];
    for (int p = D->p[r]; p < D->p[r + 1]; p++, at++) {
      Ai[at] = D->j[p];
      Ax[at] = D->x[p];
      norm2 += D->x[p] * D->x[p];
    }
    Ap[k + 1] = at;
    if (sqrt(norm2) > biggest) biggest = sqrt(norm2);
  }
  double tol = 1e-9 * (biggest > 1 ? biggest : 1);
  SuiteSparse_long *E = NULL;
  SuiteSparse_long rank = SuiteSparseQR_C(SPQR_ORDERING_FIXED, tol, 0, 0, A, NULL, NULL, NULL, NULL,
                                          &B->R, &E, NULL, NULL, NULL, cc);
  cholmod_l_free_sparse(&A, cc);
  if (rank < 0 || !B->R) {
    if (E) cholmod_l_free((size_t)D->nc, sizeof(SuiteSparse_long), E, cc);
    return -1;
  }
  /* R is squeezed: rank rows, one per live column, and its columns in the
   * order tried (permuted by E, if any); a column is live when it reaches the
   * next row, and its entries in the live columns form the triangular block */
  B->rank = (int)rank;
  B->live = malloc(sizeof(int) * (size_t)(rank + 1));
  B->col = malloc(sizeof(int) * (size_t)(rank + 1));
  B->diag = malloc(sizeof(int) * (size_t)(rank + 1));
  int bad = !B->live || !B->col || !B->diag, nlive = 0;
  const SuiteSparse_long *Rp = B->R->p, *Ri = B->R->i;
  const double *Rx = B->R->x;
  for (int k = 0; !bad && k < D->nc; k++) {
    int at = -1;
    for (SuiteSparse_long p = Rp[k]; p < Rp[k + 1]; p++)
      if (Ri[p] == nlive) at = (int)p;
    if (at < 0 || Rx[at] == 0) continue;
    if (nlive == B->rank) { bad = 1; break; }
    B->live[nlive] = order[E ? E[k] : k];
    B->col[nlive] = k;
    B->diag[nlive] = at;
    nlive++;
  }
  if (nlive != B->rank) bad = 1;
  if (E) cholmod_l_free((size_t)D->nc, sizeof(SuiteSparse_long), E, cc);
  if (bad) { basis_free(B, cc); return -1; }
  return 0;
}

/* z = (R^T R)^-1 y over the basis (y overwritten, length rank) */
static void basis_normal_solve(const row_basis *B, double *y) {
  const SuiteSparse_long *Rp = B->R->p, *Ri = B->R->i;
  const double *Rx = B->R->x;
  for (int k = 0; k < B->rank; k++) { /* R^T w = y, forward */
    double s = y[k];
    for (SuiteSparse_long p = Rp[B->col[k]]; p < Rp[B->col[k] + 1]; p++)
      if (Ri[p] < k) s -= Rx[p] * y[Ri[p]];
    y[k] = s / Rx[B->diag[k]];
  }
  for (int k = B->rank - 1; k >= 0; k--) { /* R z = w, backward */
    y[k] /= Rx[B->diag[k]];
    for (SuiteSparse_long p = Rp[B->col[k]]; p < Rp[B->col[k] + 1]; p++)
      if (Ri[p] < k) y[Ri[p]] -= Rx[p] * y[k];
  }
}

/* x (nv) = the minimum-norm solution of D_live x = b_live (b has nc entries):
 * x = D_live^T z with (R^T R) z = b_live, plus one refinement step */
static int basis_min_norm(const row_basis *B, const rows_matrix *D, const double *b, double *x) {
  double *z = malloc(sizeof(double) * (size_t)(B->rank + 1));
  if (!z) return -1;
  memset(x, 0, sizeof(double) * (size_t)D->nv);
  for (int pass = 0; pass < 2; pass++) {
    for (int k = 0; k < B->rank; k++) z[k] = b[B->live[k]] - row_dot(D, B->live[k], x);
    basis_normal_solve(B, z);
    for (int k = 0; k < B->rank; k++)
      for (int p = D->p[B->live[k]]; p < D->p[B->live[k] + 1]; p++) x[D->j[p]] += D->x[p] * z[k];
  }
  free(z);
  return 0;
}

static double max_abs(const double *a, int n, int *where) {
  double mx = 0;
  int w = -1;
  for (int i = 0; i < n; i++)
    if (!(fabs(a[i]) <= mx)) { mx = fabs(a[i]); w = i; }
  if (where) *where = w;
  return mx;
}

/* the constraint rows in the order they enter the basis: drivers lead */
static int *row_order(const lmodel *L) {
  const mb_model *m = &L->m;
  int *order = malloc(sizeof(int) * (size_t)(m->nc + 1)), k = 0;
  if (!order) return NULL;
  for (int r = 0; r < m->nc; r++)
    if (L->row[r].driver >= 0) order[k++] = r;
  for (int r = 0; r < m->nc; r++)
    if (L->row[r].driver < 0) order[k++] = r;
  return order;
}

/* a minimum-norm correction x (nv) with D x = b on a basis of D's rows */
static int min_norm_step(const rows_matrix *D, const int *order, const double *b, double *x, cholmod_common *cc) {
  row_basis B;
  if (basis_factor(D, order, &B, cc)) return -1;
  int rc = basis_min_norm(&B, D, b, x);
  basis_free(&B, cc);
  return rc;
}

/* rows on which row r depends: d_r = D_live^T c in least squares (normal
 * equations on the basis, one refinement step); report joints with |c| > 1e-6 */
static void explain_dependency(const lmodel *L, const rows_matrix *D, const row_basis *B, int r) {
  const mb_model *m = &L->m;
  double *c = calloc((size_t)B->rank + 1, sizeof(double));
  double *g = malloc(sizeof(double) * (size_t)(B->rank + 1));
  double *res = calloc((size_t)m->nv + 1, sizeof(double));
  double *coef = calloc((size_t)m->nc + 1, sizeof(double));
  if (!c || !g || !res || !coef) { free(c); free(g); free(res); free(coef); return; }
  for (int pass = 0; pass < 2; pass++) {
    /* res = d_r - D_live^T c; g = D_live res */
    memset(res, 0, sizeof(double) * (size_t)m->nv);
    for (int p = D->p[r]; p < D->p[r + 1]; p++) res[D->j[p]] += D->x[p];
    for (int k = 0; k < B->rank; k++)
      for (int p = D->p[B->live[k]]; p < D->p[B->live[k] + 1]; p++) res[D->j[p]] -= D->x[p] * c[k];
    for (int k = 0; k < B->rank; k++) g[k] = row_dot(D, B->live[k], res);
    basis_normal_solve(B, g);
    for (int k = 0; k < B->rank; k++) c[k] += g[k];
  }
  for (int k = 0; k < B->rank; k++) coef[B->live[k]] = c[k];
  char list[1024] = "";
  for (int k = 0; k < m->nc; k++) { /* in model order */
    if (fabs(coef[k]) < 1e-6) continue;
    const char *what = L->row_desc[k];
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
  if (list[0])
    diag_note(L->ir->path, L->row_loc[r], "it is a combination of rows of %s", list);
  free(c); free(g); free(res); free(coef);
}

/* K = [M D^T; D 0] nonsingular (KLU finds no zero pivot) */
static int K_singular(const mb_model *m, const double *Kx, int *failed) {
  *failed = 0;
  if (m->n == 0) return 0;
  klu_common common;
  klu_defaults(&common);
  klu_symbolic *sym = klu_analyze(m->n, (int *)m->Kp, (int *)m->Ki, &common);
  if (!sym) { *failed = common.status != KLU_SINGULAR; return common.status == KLU_SINGULAR; }
  klu_numeric *num = klu_factor((int *)m->Kp, (int *)m->Ki, (double *)Kx, sym, &common);
  int singular = common.status == KLU_SINGULAR;
  if (!num && !singular) *failed = 1;
  if (num) klu_free_numeric(&num, &common);
  klu_free_symbolic(&sym, &common);
  return singular;
}

/* the rows about to be removed (keep[r] 0), appended to L->removed_row:
 * the generated code checks at start that run-time geometry leaves them
 * redundant (runtime/hosted/reassemble.c); 0, or -1 when out of memory */
static int keep_removed_rows(lmodel *L, const int *keep) {
  int nremove = 0;
  for (int r = 0; r < L->m.nrow; r++) nremove += !keep[r];
  mb_rowdef *rows = realloc(L->removed_row, sizeof *rows * (size_t)(L->nremoved + nremove + 1));
  if (rows) L->removed_row = rows;
  char **desc = realloc(L->removed_desc, sizeof *desc * (size_t)(L->nremoved + nremove + 1));
  if (desc) L->removed_desc = desc;
  if (!rows || !desc) return -1;
  for (int r = 0; r < L->m.nrow; r++) {
    if (keep[r]) continue;
    size_t n = strlen(L->row_desc[r]) + 1;
    char *d = malloc(n);
    if (!d) return -1;
    memcpy(d, L->row_desc[r], n);
    L->removed_row[L->nremoved] = L->row[r];
    L->removed_desc[L->nremoved++] = d;
  }
  return 0;
}

/* A rotation driver's row is phi = sin(angle - th), zero at th and at th + pi:
 * Newton from the model's configuration finds the second when the profile
 * starts more than 90 degrees from it, and the mechanism would then run half
 * a turn off, its driver effort with the wrong sign.  The row evaluated
 * against th + pi/2 is -cos(angle - th): positive there.  0 or 2 (reported). */
static int check_driver_branches(lmodel *L, evalbuf *e) {
  mb_model *m = &L->m;
  for (int r = 0; r < m->nc; r++) {
    if (L->row[r].kind != MB_PRIM_ROT) continue;
    int p = L->row[r].profile;
    mb_profile given = L->profile[p];
    mb_real th[3];
    mb_profile_eval(&given, 0, th);
    L->profile[p] = (mb_profile){.kind = MB_PROFILE_CONSTANT, .c = {th[0] + 0.5 * acos(-1.0)}, .nc = 1};
    evaluate(m, e, L->q0, L->v0);
    double minus_cos = e->phi[r];
    L->profile[p] = given;
    if (minus_cos > 0) {
      diag_error(L->ir->path, L->row_loc[r],
                 "%s, which starts at %.6g rad; a rotation driver counts from the configuration "
                 "the model gives, and the assembly found the joint half a turn from that, at "
                 "%.6g rad: start the profile at (or near) 0 and give the bodies the angle "
                 "instead", L->row_desc[r], th[0], remainder(th[0] - acos(-1.0), 2 * acos(-1.0)));
      return 2;
    }
  }
  evaluate(m, e, L->q0, L->v0);
  return 0;
}

int assemble_model(lmodel *L, int verbose) {
  mb_model *m = &L->m;
  const char *file = L->ir->path;
  evalbuf e = {0};
  rows_matrix D = {0};
  row_basis B = {0};
  cholmod_common cc;
  cholmod_l_start(&cc);
  int status = 2;
  double *b = NULL, *dx = NULL;
  int *keep = NULL, *order = NULL;
  char *frozen = NULL;
  if (evalbuf_init(&e, m)) goto out;
  b = malloc(sizeof(double) * (size_t)(m->nv + m->nc + 1));
  dx = malloc(sizeof(double) * (size_t)(m->nv + 1));
  keep = malloc(sizeof(int) * (size_t)(m->nc + 1));
  order = row_order(L);
  frozen = frozen_modes(m);
  if (!b || !dx || !keep || !order || !frozen) goto out;
  free(L->q_given);
  free(L->v_given);
  L->q_given = malloc(sizeof(double) * (size_t)(m->nq + 1));
  L->v_given = malloc(sizeof(double) * (size_t)(m->nv + 1));
  if (!L->q_given || !L->v_given) goto out;
  memcpy(L->q_given, L->q0, sizeof(double) * (size_t)m->nq);
  memcpy(L->v_given, L->v0, sizeof(double) * (size_t)m->nv);

  /* 1. positions: Newton with minimum-norm steps over a basis of the rows */
  int worst = -1, it;
  double res = 0;
  for (it = 0; it < 50; it++) {
    evaluate(m, &e, L->q0, L->v0);
    res = max_abs(e.phi, m->nc, &worst);
    if (res <= 1e-12) break;
    /* deform the bodies only if they must */
    if (rows_from_K(m, e.Kx, it < 25 ? frozen : NULL, &D)) goto out;
    for (int r = 0; r < m->nc; r++) b[r] = -e.phi[r];
    if (min_norm_step(&D, order, b, dx, &cc)) goto out;
    mb_model_qincrement(m, L->q0, dx);
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
  if (check_driver_branches(L, &e)) goto out;

  /* 2. redundant rows: those the basis leaves out; driver rows lead */
  evaluate(m, &e, L->q0, L->v0);
  if (rows_from_K(m, e.Kx, NULL, &D)) goto out;
  int rank = 0;
  if (m->nc > 0) {
    if (basis_factor(&D, order, &B, &cc)) goto out;
    rank = B.rank;
    for (int r = 0; r < m->nc; r++) keep[r] = 0;
    for (int k = 0; k < rank; k++) keep[B.live[k]] = 1;
    if (rank < m->nc) {
      for (int r = 0; r < m->nc; r++) {
        if (keep[r]) continue;
        diag_warning(file, L->row_loc[r], "redundant constraint removed: %s", L->row_desc[r]);
        explain_dependency(L, &D, &B, r);
      }
      L->nredundant += m->nc - rank;
      if (keep_removed_rows(L, keep)) goto out;
      if (lower_remove_rows(L, keep)) goto out;
      evalbuf_free(&e);
      if (evalbuf_init(&e, m)) goto out;
      free(order);
      if (!(order = row_order(L))) goto out;
    }
    basis_free(&B, &cc);
  }
  L->dof = m->nv - rank;

  /* 3. velocities: minimum-norm correction onto D v = nu (e.nu holds phid = D v - nu) */
  evaluate(m, &e, L->q0, L->v0);
  if (m->nc > 0) {
    if (rows_from_K(m, e.Kx, frozen, &D)) goto out;
    for (int r = 0; r < m->nc; r++) b[r] = -e.nu[r];
    if (min_norm_step(&D, order, b, dx, &cc)) goto out;
    for (int j = 0; j < m->nv; j++) L->v0[j] += dx[j];
  }

  /* 4. K must be nonsingular: massless bodies fully determined by their joints */
  evaluate(m, &e, L->q0, L->v0);
  int failed = 0;
  if (K_singular(m, e.Kx, &failed)) {
    diag_error(file, (ir_loc){1, 1},
               "the system matrix K = [M D^T; D 0] is singular at t = 0: some motion has "
               "neither mass nor a constraint");
    for (int b2 = 0; b2 < m->nbody; b2++)
      if (L->body[b2].kind == MB_BODY_VIRTUAL)
        diag_note(file, b2 + 1 < L->ir->nbodies ? L->ir->bodies[b2 + 1].loc : (ir_loc){0, 0},
                  "massless body '%s' must be fully determined by its joints", L->body[b2].name);
    goto out;
  }
  if (failed) goto out;
  status = 0;
out:
  if (status && diag_errors() == 0)
    diag_error(file, (ir_loc){0, 0}, "assembly analysis failed (out of memory or a sparse factorization failed)");
  evalbuf_free(&e);
  rows_free(&D);
  basis_free(&B, &cc);
  cholmod_l_finish(&cc);
  free(b); free(dx); free(keep); free(order); free(frozen);
  return status;
}
