/* order.c: the compile-time part of the emitted LDL^T (see order.h):
 * weights for the rows that touch massless unknowns, the pattern of
 * K_aug = [M + D^T W D, D^T; D, 0], the CAMD ordering (body unknowns before
 * constraint rows), the elimination tree, column counts, the pattern of L and
 * the flop count of the numeric factorization that emit_ldl.c emits.
 *
 * The numeric factorization (emit_ldl.c) is up-looking: row k of L is the
 * solution of a sparse triangular system whose pattern is the set of etree
 * nodes reachable from the nonzeros of column k of the upper triangle; for
 * each j of that row (ascending) with t = y_j:
 *     y_i -= L(i,j) t   for the entries of column j of L above row k
 *     L(k,j) = t / d_j,  d_k -= L(k,j) t
 * so it costs, per entry L(k,j), 2 flops per entry of column j above row k
 * plus 3, and one division per pivot: that is the flop count reported. */
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <stdio.h>
#include <suitesparse/camd.h>

#include "order.h"

void ldl_plan_free(ldl_plan *p) {
  free(p->perm); free(p->iperm);
  free(p->wrow); free(p->w); free(p->Dp); free(p->Dj); free(p->Ds);
  free(p->Up); free(p->Ui); free(p->Us);
  free(p->Tp); free(p->Tw); free(p->Ta); free(p->Tb);
  free(p->parent); free(p->Lp); free(p->Li);
  free(p->Rp); free(p->Rj); free(p->Rpos);
  free(p->eb); free(p->eu); free(p->er); free(p->exp_); free(p->ex); free(p->esp); free(p->es);
  free(p->edu); free(p->edx); free(p->eeu); free(p->ekr); free(p->ekrp);
  free(p->Krp); free(p->Kri); free(p->Krmap);
  free(p->mlb); free(p->mlu); free(p->mlrp); free(p->mlR); free(p->mlT); free(p->mlpi0); free(p->mlyp); free(p->mlY);
  free(p->mldu); free(p->mldy); free(p->mldyp); free(p->mlk); free(p->mlkp);
  free(p->K1p); free(p->K1i); free(p->K1map);
  memset(p, 0, sizeof *p);
}

/* Kx slot of K(i, j), or -1 when structurally zero */
static int kslot(const mb_model *m, int i, int j) {
  int lo = m->Kp[j], hi = m->Kp[j + 1] - 1;
  while (lo <= hi) {
    int mid = (lo + hi) / 2;
    if (m->Ki[mid] == i) return mid;
    if (m->Ki[mid] < i) lo = mid + 1;
    else hi = mid - 1;
  }
  return -1;
}

void ldl_unknown_name(const lmodel *L, int u, char *buf, size_t n) {
  const mb_model *m = &L->m;
  static const char *comp[6] = {"translation x", "translation y", "translation z",
                                "rotation x",    "rotation y",    "rotation z"};
  if (u >= m->nv) {
    int r = u - m->nv;
    snprintf(buf, n, "constraint row %d: %s", r, L->row_desc && L->row_desc[r] ? L->row_desc[r] : "");
    return;
  }
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    int nb = 6 + (B->kind == MB_BODY_FLEXIBLE ? B->nm : 0);
    if (u < B->vadr || u >= B->vadr + nb) continue;
    int c = u - B->vadr;
    if (c < 6) snprintf(buf, n, "body '%s' %s", B->name, comp[c]);
    else snprintf(buf, n, "body '%s' mode %d", B->name, c - 6 + 1);
    return;
  }
  snprintf(buf, n, "velocity unknown %d", u);
}

typedef struct { int col, row, i, j, slot; } uentry; /* permuted (col, row), original (i, j) */

static int uentry_cmp(const void *a, const void *b) {
  const uentry *x = a, *y = b;
  if (x->col != y->col) return x->col < y->col ? -1 : 1;
  return x->row < y->row ? -1 : x->row > y->row;
}

static int int_cmp(const void *a, const void *b) {
  int x = *(const int *)a, y = *(const int *)b;
  return x < y ? -1 : x > y;
}

/* Kx at t = 0 (initial state): constant entries, then the varying ones */
static double *kx_at_start(const mb_model *m) {
  double *Kx = calloc((size_t)m->nnz + 1, sizeof(double));
  double *rhs = calloc((size_t)m->n + 1, sizeof(double));
  double *phi = calloc((size_t)m->nc + 1, sizeof(double));
  double *nu = calloc((size_t)m->nc + 1, sizeof(double));
  void *work = malloc(mb_model_worksize(m) + 16);
  if (Kx && rhs && phi && nu && work) {
    m->init(m, Kx);
    m->eval(m, 0.0, m->q0, m->v0, Kx, rhs, phi, nu, work);
  } else {
    free(Kx);
    Kx = NULL;
  }
  free(rhs); free(phi); free(nu); free(work);
  return Kx;
}

/* the body whose velocity columns include column j, or -1 */
static int body_of_column(const mb_model *m, int j) {
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    int nb = 6 + (B->kind == MB_BODY_FLEXIBLE ? B->nm : 0);
    if (j >= B->vadr && j < B->vadr + nb) return b;
  }
  return -1;
}

/* whether every velocity column of body b (-1: the ground) is massive */
static int body_massive(const mb_model *m, int b, const char *massive) {
  if (b < 0) return 1;
  const mb_body *B = &m->body[b];
  int nb = 6 + (B->kind == MB_BODY_FLEXIBLE ? B->nm : 0);
  for (int c = 0; c < nb; c++)
    if (!massive[B->vadr + c]) return 0;
  return 1;
}

/* constraint row r is a row of the rigid joint (weld) of virtual body b to a
 * massive body (lower.c: no source joint or driver, marker 1 on the virtual
 * body): returns b, else -1 */
static int row_weld_body(const mb_model *m, int r, const char *massive) {
  if (m->nrow != m->nc || r >= m->nrow) return -1;
  const mb_rowdef *R = &m->row[r];
  if (R->joint >= 0 || R->driver >= 0) return -1;
  int b1 = m->marker[R->m1].body, b0 = m->marker[R->m0].body;
  if (b1 < 0 || m->body[b1].kind != MB_BODY_VIRTUAL || b0 == b1) return -1;
  if (R->kind != MB_PRIM_SPH && R->kind != MB_PRIM_DOT1) return -1;
  return body_massive(m, b0, massive) ? b1 : -1;
}

/* per body: the number of weld rows when it is a virtual body held by exactly
 * the 6 rows of one rigid joint to a massive body (3 coincidence, 3
 * orientation), else -1 */
static int *welded_rows(const mb_model *m, const char *massive) {
  int *cnt = malloc(sizeof(int) * (size_t)(m->nbody + 1));
  int *sph = calloc((size_t)m->nbody + 1, sizeof(int)), *other = calloc((size_t)m->nbody + 1, sizeof(int));
  if (!cnt || !sph || !other) { free(cnt); free(sph); free(other); return NULL; }
  for (int r = 0; r < m->nc && m->nrow == m->nc; r++) {
    int b = row_weld_body(m, r, massive);
    if (b < 0) continue;
    const mb_rowdef *R = &m->row[r];
    if (R->kind == MB_PRIM_SPH) sph[b] |= 1 << R->a;
    else other[b] |= 1 << R->a;
  }
  for (int b = 0; b < m->nbody; b++) cnt[b] = sph[b] == 7 && other[b] == 7 ? 6 : -1;
  free(sph); free(other);
  return cnt;
}

/* ------------------------------------------------------------ block pivots */

/* 6 x 6 LU with partial pivoting (row-major A, row swaps in piv); -1 when a
 * pivot is below 1e-12 of the largest entry (the same as the emitted one) */
static int lu6(double *A, int *piv) {
  double amax = 0;
  for (int i = 0; i < 36; i++) amax = fmax(amax, fabs(A[i]));
  for (int k = 0; k < 6; k++) {
    int pr = k;
    for (int i = k + 1; i < 6; i++)
      if (fabs(A[6 * i + k]) > fabs(A[6 * pr + k])) pr = i;
    piv[k] = pr;
    if (!(fabs(A[6 * pr + k]) > 1e-12 * amax)) return -1;
    if (pr != k)
      for (int j = 0; j < 6; j++) { double t = A[6 * k + j]; A[6 * k + j] = A[6 * pr + j]; A[6 * pr + j] = t; }
    for (int i = k + 1; i < 6; i++) {
      double l = A[6 * i + k] /= A[6 * k + k];
      for (int j = k + 1; j < 6; j++) A[6 * i + j] -= l * A[6 * k + j];
    }
  }
  return 0;
}

/* b <- A^-T b with the factors of lu6 (A^T = U^T L^T P) */
static void lu6_solve_t(const double *A, const int *piv, double *b) {
  for (int k = 0; k < 6; k++) {
    for (int j = 0; j < k; j++) b[k] -= A[6 * j + k] * b[j];
    b[k] /= A[6 * k + k];
  }
  for (int k = 5; k >= 0; k--)
    for (int j = k + 1; j < 6; j++) b[k] -= A[6 * j + k] * b[j];
  for (int k = 5; k >= 0; k--)
    if (piv[k] != k) { double t = b[k]; b[k] = b[piv[k]]; b[piv[k]] = t; }
}

static int in_list(const int *a, int n, int x) {
  for (int i = 0; i < n; i++)
    if (a[i] == x) return 1;
  return 0;
}

/* the welded virtual bodies to eliminate and their data (order.h); 0 or -1 */
static int find_elims(const mb_model *m, const double *Kx, ldl_plan *p) {
  int nv = m->nv, nc = m->nc, nb = m->nbody;
  char *massive = calloc((size_t)nv + 1, 1);
  int *weld = NULL;
  if (!massive) return -1;
  for (int j = 0; j < nv; j++)
    for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
      if (m->Ki[q] < nv && Kx[q] != 0) massive[j] = 1;
  weld = welded_rows(m, massive);
  p->eb = malloc(sizeof(int) * (size_t)(nb + 1));
  p->eu = malloc(sizeof *p->eu * (size_t)(nb + 1));
  p->er = malloc(sizeof *p->er * (size_t)(nb + 1));
  p->edu = malloc(sizeof *p->edu * (size_t)(nb + 1));
  p->exp_ = calloc((size_t)nb + 1, sizeof(int));
  p->esp = calloc((size_t)nb + 1, sizeof(int));
  p->ekrp = calloc((size_t)nb + 1, sizeof(int));
  int capx = nb * 80 + 1, caps = nc + 1;
  p->ex = malloc(sizeof(int) * (size_t)capx);
  p->es = malloc(sizeof(int) * (size_t)caps * (size_t)(nb + 1));
  if (!weld || !p->eb || !p->eu || !p->er || !p->edu || !p->exp_ || !p->esp || !p->ekrp || !p->ex || !p->es) {
    free(massive); free(weld);
    return -1;
  }
  int ne = 0, nx = 0, ns = 0;
  for (int b = 0; b < nb; b++) {
    if (weld[b] != 6 || m->body[b].kind != MB_BODY_VIRTUAL) continue;
    const mb_body *B = &m->body[b];
    int ok = 1, k = 0, b0 = -2;
    for (int c = 0; c < 6; c++) ok &= !massive[B->vadr + c];
    for (int r = 0; r < nc && ok; r++)
      if (row_weld_body(m, r, massive) == b) {
        if (k < 6) p->er[ne][k] = nv + r;
        k++;
        int o = m->marker[m->row[r].m0].body;
        if (b0 == -2) b0 = o;
        else if (b0 != o) ok = 0;
      }
    if (!ok || k != 6 || b0 < 0) continue;
    for (int c = 0; c < 6; c++) p->eu[ne][c] = B->vadr + c;
    /* X: the columns of the weld rows other than U */
    int x0 = nx, s0 = ns;
    for (int i = 0; i < 6 && ok; i++) {
      int row = p->er[ne][i];
      for (int q = m->Kp[row]; q < m->Kp[row + 1]; q++) {
        int j = m->Ki[q];
        if (j >= nv) { ok = 0; break; }
        if (in_list(p->eu[ne], 6, j) || in_list(p->ex + x0, nx - x0, j)) continue;
        if (nx + 1 >= capx) { ok = 0; break; }
        p->ex[nx++] = j;
      }
    }
    /* S: the other rows on U; U may hold no other entries (massless) */
    for (int c = 0; c < 6 && ok; c++) {
      int u = p->eu[ne][c];
      for (int q = m->Kp[u]; q < m->Kp[u + 1]; q++) {
        int i = m->Ki[q];
        if (i < nv) {
          if (!in_list(p->eu[ne], 6, i) || Kx[q] != 0) ok = 0;
          continue;
        }
        if (in_list(p->er[ne], 6, i) || in_list(p->es + s0, ns - s0, i)) continue;
        p->es[ns++] = i;
      }
    }
    /* the S rows may not be weld rows of another eliminated body, nor X
       columns be eliminated (X is massive, so they are not) */
    for (int e = 0; e < ne && ok; e++)
      for (int i = 0; i < 6; i++)
        if (in_list(p->es + s0, ns - s0, p->er[e][i])) ok = 0;
    if (!ok) { nx = x0; ns = s0; continue; }
    for (int i = 0; i < 6; i++)
      for (int c = 0; c < 6; c++) p->edu[ne][6 * i + c] = kslot(m, p->er[ne][i], p->eu[ne][c]);
    p->eb[ne] = b;
    p->exp_[ne + 1] = nx;
    p->esp[ne + 1] = ns;
    ne++;
  }
  p->nelim = ne;
  /* a weld row of one body may not be an S row of an earlier one either */
  for (int e = 0; e < ne; e++)
    for (int f = 0; f < ne; f++)
      for (int i = 0; i < 6; i++)
        if (in_list(p->es + p->esp[f], p->esp[f + 1] - p->esp[f], p->er[e][i])) p->nelim = 0;
  ne = p->nelim;
  p->edx = malloc(sizeof(int) * (size_t)(6 * p->exp_[ne] + 1));
  p->eeu = malloc(sizeof(int) * (size_t)(6 * p->esp[ne] + 1));
  if (!p->edx || !p->eeu) { free(massive); free(weld); return -1; }
  for (int e = 0; e < ne; e++) {
    for (int xi = p->exp_[e]; xi < p->exp_[e + 1]; xi++)
      for (int i = 0; i < 6; i++) p->edx[6 * xi + i] = kslot(m, p->er[e][i], p->ex[xi]);
    for (int si = p->esp[e]; si < p->esp[e + 1]; si++)
      for (int c = 0; c < 6; c++) p->eeu[6 * si + c] = kslot(m, p->es[si], p->eu[e][c]);
  }
  free(massive); free(weld);
  return 0;
}

/* ------------------------------------------------------- massless bodies */

/* X = A^-1 (6 x 6, row-major), Gauss-Jordan with partial pivoting; -1 when a
 * pivot is below 1e-12 of the largest entry (the emitted ldl_inv6) */
static int inv6(const double *A0, double *X) {
  double A[36], amax = 0;
  for (int i = 0; i < 36; i++) { A[i] = A0[i]; X[i] = i % 7 == 0; amax = fmax(amax, fabs(A[i])); }
  for (int k = 0; k < 6; k++) {
    int pr = k;
    for (int i = k + 1; i < 6; i++) if (fabs(A[6 * i + k]) > fabs(A[6 * pr + k])) pr = i;
    if (!(fabs(A[6 * pr + k]) > 1e-12 * amax)) return -1;
    if (pr != k)
      for (int j = 0; j < 6; j++) {
        double t = A[6 * k + j]; A[6 * k + j] = A[6 * pr + j]; A[6 * pr + j] = t;
        t = X[6 * k + j]; X[6 * k + j] = X[6 * pr + j]; X[6 * pr + j] = t;
      }
    double d = 1 / A[6 * k + k]; /* columns up to k of A are done (unit vectors) */
    for (int j = k + 1; j < 6; j++) A[6 * k + j] *= d;
    for (int j = 0; j < 6; j++) X[6 * k + j] *= d;
    for (int i = 0; i < 6; i++) {
      double l = A[6 * i + k];
      if (i == k || l == 0) continue;
      for (int j = k + 1; j < 6; j++) A[6 * i + j] -= l * A[6 * k + j];
      for (int j = 0; j < 6; j++) X[6 * i + j] -= l * X[6 * k + j];
    }
  }
  return 0;
}

/* The elimination of one massless body (order.h), the same arithmetic as the
 * emitted ldl_ml_factor: A = D_RU (r x 6, row-major), D = D_RY (r x ny).
 * pi: the rows in pivot order (partial pivoting on A: the first 6 are P),
 * Di = Du^-1 (row-major), W = D_SU Du^-1 ((r-6) x 6), V = D_SY - W D_PY.
 * Returns -1 when D_RU has a pivot below 1e-12 of its largest entry. */
static int ml_eliminate(const double *A, const double *D, int r, int ny, int *pi, double *Di,
                        double *W, double *V) {
  double *B = malloc(sizeof(double) * (size_t)(6 * r + 1)), amax = 0, Du[36];
  int rc = -1;
  if (!B) return -1;
  for (int i = 0; i < 6 * r; i++) { B[i] = A[i]; amax = fmax(amax, fabs(A[i])); }
  for (int i = 0; i < r; i++) pi[i] = i;
  for (int k = 0; k < 6; k++) {
    int pr = k;
    for (int i = k + 1; i < r; i++)
      if (fabs(B[6 * i + k]) > fabs(B[6 * pr + k])) pr = i;
    if (!(fabs(B[6 * pr + k]) > 1e-12 * amax)) goto done;
    if (pr != k) {
      for (int j = 0; j < 6; j++) { double t = B[6 * k + j]; B[6 * k + j] = B[6 * pr + j]; B[6 * pr + j] = t; }
      int t = pi[k]; pi[k] = pi[pr]; pi[pr] = t;
    }
    for (int i = k + 1; i < r; i++) {
      double l = B[6 * i + k] / B[6 * k + k];
      for (int j = k; j < 6; j++) B[6 * i + j] -= l * B[6 * k + j];
    }
  }
  /* Di = Du^-1 (rows pi[0..5]), Gauss-Jordan with partial pivoting */
  for (int i = 0; i < 6; i++)
    for (int c = 0; c < 6; c++) Du[6 * i + c] = A[6 * pi[i] + c];
  if (inv6(Du, Di)) goto done;
  for (int i = 0; i < r - 6; i++) {
    for (int c = 0; c < 6; c++) {
      double w = 0;
      for (int k = 0; k < 6; k++) w += A[6 * pi[6 + i] + k] * Di[6 * k + c];
      W[6 * i + c] = w;
    }
    for (int y = 0; y < ny; y++) {
      double v = D[ny * pi[6 + i] + y];
      for (int c = 0; c < 6; c++) v -= W[6 * i + c] * D[ny * pi[c] + y];
      V[ny * i + y] = v;
    }
  }
  rc = 0;
done:
  free(B);
  return rc;
}

/* the non-welded massless bodies to eliminate first (order.h); 0 or -1 */
static int find_massless(const mb_model *m, const double *Kx, ldl_plan *p) {
  int nv = m->nv, n = m->n, nb = m->nbody;
  char *massive = calloc((size_t)nv + 1, 1), *used = calloc((size_t)n + 1, 1);
  int *weld = NULL, *rows = malloc(sizeof(int) * (size_t)(n + 1)), *cols = malloc(sizeof(int) * (size_t)(n + 1));
  const char *env = getenv("MBCC_LDL_MASSLESS");
  int rc = -1;
  if (!massive || !used || !rows || !cols) goto done;
  for (int j = 0; j < nv; j++)
    for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
      if (m->Ki[q] < nv && Kx[q] != 0) massive[j] = 1;
  weld = welded_rows(m, massive);
  p->mlb = malloc(sizeof(int) * (size_t)(nb + 1));
  p->mlu = malloc(sizeof *p->mlu * (size_t)(nb + 1));
  p->mlrp = calloc((size_t)nb + 2, sizeof(int));
  p->mlyp = calloc((size_t)nb + 2, sizeof(int));
  p->mldyp = calloc((size_t)nb + 2, sizeof(int));
  p->mlR = malloc(sizeof(int) * (size_t)(m->nc + 1));
  p->mlT = malloc(sizeof(int) * (size_t)(m->nc + 1));
  p->mlpi0 = malloc(sizeof(int) * (size_t)(m->nc + 1));
  p->mlY = malloc(sizeof(int) * (size_t)(nb * 0 + nv * (nb + 1) + 1));
  if (!weld || !p->mlb || !p->mlu || !p->mlrp || !p->mlyp || !p->mldyp || !p->mlR || !p->mlT || !p->mlpi0 || !p->mlY) goto done;
  int ne = 0, nr = 0, ny = 0, nt = 0;
  for (int b = 0; b < nb && !(env && !strcmp(env, "0")); b++) {
    const mb_body *B = &m->body[b];
    if (B->kind != MB_BODY_VIRTUAL || weld[b] == 6) continue;
    int ok = 1, r = 0, y = 0;
    for (int c = 0; c < 6; c++) ok &= !massive[B->vadr + c] && !used[B->vadr + c];
    /* R: the rows on U; U may hold no other entries */
    for (int c = 0; c < 6 && ok; c++)
      for (int q = m->Kp[B->vadr + c]; q < m->Kp[B->vadr + c + 1]; q++) {
        int i = m->Ki[q];
        if (i < nv) { if (i < B->vadr || i >= B->vadr + 6 || Kx[q] != 0) ok = 0; continue; }
        if (used[i]) { ok = 0; break; }
        int seen = 0;
        for (int k = 0; k < r; k++) seen |= rows[k] == i;
        if (!seen) rows[r++] = i;
      }
    if (!ok || r < 6) continue;
    /* Y: the other columns of R (velocity columns, none of an eliminated body) */
    for (int k = 0; k < r && ok; k++)
      for (int q = m->Kp[rows[k]]; q < m->Kp[rows[k] + 1]; q++) {
        int j = m->Ki[q];
        if (j >= B->vadr && j < B->vadr + 6) continue;
        if (j >= nv || used[j]) { ok = 0; break; }
        int seen = 0;
        for (int t = 0; t < y; t++) seen |= cols[t] == j;
        if (!seen) cols[y++] = j;
      }
    if (!ok) continue;
    qsort(rows, (size_t)r, sizeof(int), int_cmp);
    qsort(cols, (size_t)y, sizeof(int), int_cmp);
    /* rank 6 at t = 0; the slots T: the rows partial pivoting leaves out there */
    double *A = calloc((size_t)(6 * r + 1), sizeof(double)), *D = calloc((size_t)(r * y + 1), sizeof(double));
    double *W = malloc(sizeof(double) * (size_t)(6 * r + 1)), *V = malloc(sizeof(double) * (size_t)(r * y + 1)), Di[36];
    int *pi = malloc(sizeof(int) * (size_t)(r + 1));
    if (!A || !D || !W || !V || !pi) { free(A); free(D); free(W); free(V); free(pi); goto done; }
    for (int k = 0; k < r; k++) {
      for (int c = 0; c < 6; c++) { int s = kslot(m, rows[k], B->vadr + c); A[6 * k + c] = s >= 0 ? Kx[s] : 0; }
      for (int t = 0; t < y; t++) { int s = kslot(m, rows[k], cols[t]); D[y * k + t] = s >= 0 ? Kx[s] : 0; }
    }
    ok = !ml_eliminate(A, D, r, y, pi, Di, W, V);
    if (ok) {
      for (int k = 0; k < r; k++) { p->mlR[nr + k] = rows[k]; p->mlpi0[nr + k] = pi[k]; }
      for (int k = 6; k < r; k++) p->mlT[nt++] = rows[pi[k]];
      qsort(p->mlT + nt - (r - 6), (size_t)(r - 6), sizeof(int), int_cmp);
      for (int t = 0; t < y; t++) p->mlY[ny + t] = cols[t];
      for (int c = 0; c < 6; c++) { p->mlu[ne][c] = B->vadr + c; used[B->vadr + c] = 1; }
      for (int k = 0; k < r; k++) used[rows[k]] = 1;
      for (int t = 0; t < y; t++) used[cols[t]] = 1;
      nr += r;
      ny += y;
      p->mlb[ne] = b;
      p->mlrp[ne + 1] = nr;
      p->mlyp[ne + 1] = ny;
      p->mldyp[ne + 1] = p->mldyp[ne] + r * y;
      ne++;
    }
    free(A); free(D); free(W); free(V); free(pi);
  }
  p->nml = ne;
  p->mldu = malloc(sizeof(int) * (size_t)(6 * nr + 1));
  p->mldy = malloc(sizeof(int) * (size_t)(p->mldyp[ne] + 1));
  if (!p->mldu || !p->mldy) goto done;
  for (int e = 0; e < ne; e++) {
    int y0 = p->mlyp[e], y = p->mlyp[e + 1] - y0;
    for (int k = p->mlrp[e]; k < p->mlrp[e + 1]; k++) {
      for (int c = 0; c < 6; c++) p->mldu[6 * k + c] = kslot(m, p->mlR[k], p->mlu[e][c]);
      for (int t = 0; t < y; t++)
        p->mldy[p->mldyp[e] + y * (k - p->mlrp[e]) + t] = kslot(m, p->mlR[k], p->mlY[y0 + t]);
    }
  }
  rc = 0;
done:
  free(massive); free(used); free(weld); free(rows); free(cols);
  return rc;
}

/* K1 index kinds: 1 eliminated column, 2 decoupled row, 3 slot row (block e in *blk), 0 else */
static int ml_kind(const ldl_plan *p, int i, int *blk) {
  for (int e = 0; e < p->nml; e++) {
    if (in_list(p->mlu[e], 6, i)) return 1;
    int t0 = p->mlrp[e] - 6 * e, nt = p->mlrp[e + 1] - p->mlrp[e] - 6;
    if (in_list(p->mlT + t0, nt, i)) { if (blk) *blk = e; return 3; }
    if (in_list(p->mlR + p->mlrp[e], p->mlrp[e + 1] - p->mlrp[e], i)) return 2;
  }
  return 0;
}

static void add_entry(int i, int j, int *mark, int *rows, int *nz);

/* the pattern of K1 and its gather map; 0 or -1 */
static int ml_pattern(const mb_model *m, ldl_plan *p) {
  int n = m->n, ne = p->nml;
  char *kind = malloc((size_t)n + 1);
  int *blk = malloc(sizeof(int) * (size_t)(n + 1)), *mark = malloc(sizeof(int) * (size_t)(n + 1));
  p->K1p = calloc((size_t)n + 1, sizeof(int));
  if (!kind || !blk || !mark || !p->K1p) { free(kind); free(blk); free(mark); return -1; }
  for (int i = 0; i < n; i++) { blk[i] = -1; kind[i] = (char)ml_kind(p, i, &blk[i]); }
  for (int pass = 0; pass < 2; pass++) {
    int nz = 0;
    for (int i = 0; i < n; i++) mark[i] = -1;
    for (int j = 0; j < n; j++) {
      int start = nz;
#define ADD(ii) add_entry((ii), j, mark, pass ? p->K1i : NULL, &nz)
      if (kind[j] == 1 || kind[j] == 2) {
        ADD(j);
      } else if (kind[j] == 3) {
        int e = blk[j];
        for (int t = p->mlyp[e]; t < p->mlyp[e + 1]; t++) ADD(p->mlY[t]);
      } else {
        for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
          if (!kind[m->Ki[q]]) ADD(m->Ki[q]);
        for (int e = 0; e < ne; e++)
          if (in_list(p->mlY + p->mlyp[e], p->mlyp[e + 1] - p->mlyp[e], j))
            for (int t = p->mlrp[e] - 6 * e; t < p->mlrp[e + 1] - 6 * (e + 1); t++) ADD(p->mlT[t]);
      }
#undef ADD
      if (pass) qsort(p->K1i + start, (size_t)(nz - start), sizeof(int), int_cmp);
      else p->K1p[j + 1] = nz;
    }
    if (!pass) {
      p->nnz1 = nz;
      p->K1i = malloc(sizeof(int) * (size_t)(nz + 1));
      p->K1map = malloc(sizeof(int) * (size_t)(nz + 1));
      if (!p->K1i || !p->K1map) { free(kind); free(blk); free(mark); return -1; }
    }
  }
  for (int j = 0; j < n; j++)
    for (int q = p->K1p[j]; q < p->K1p[j + 1]; q++) {
      int i = p->K1i[q];
      if (kind[j] == 1) p->K1map[q] = -2;
      else if (kind[j] == 2) p->K1map[q] = -3;
      else if (kind[j] == 3 || kind[i] == 3) p->K1map[q] = -4;
      else p->K1map[q] = kslot(m, i, j) >= 0 ? kslot(m, i, j) : -1;
    }
  /* positions of the computed pairs (t, y), (y, t): slot-major */
  int npair = 0;
  for (int e = 0; e < ne; e++) npair += (p->mlrp[e + 1] - p->mlrp[e] - 6) * (p->mlyp[e + 1] - p->mlyp[e]);
  p->mlk = malloc(sizeof(int) * (size_t)(2 * npair + 1));
  p->mlkp = calloc((size_t)ne + 1, sizeof(int));
  if (!p->mlk || !p->mlkp) { free(kind); free(blk); free(mark); return -1; }
  mb_model m1 = *m;
  m1.Kp = p->K1p;
  m1.Ki = p->K1i;
  m1.nnz = p->nnz1;
  int k = 0;
  for (int e = 0; e < ne; e++) {
    p->mlkp[e] = k;
    for (int t = p->mlrp[e] - 6 * e; t < p->mlrp[e + 1] - 6 * (e + 1); t++)
      for (int y = p->mlyp[e]; y < p->mlyp[e + 1]; y++, k++) {
        p->mlk[2 * k] = kslot(&m1, p->mlT[t], p->mlY[y]);
        p->mlk[2 * k + 1] = kslot(&m1, p->mlY[y], p->mlT[t]);
      }
  }
  p->mlkp[ne] = k;
  free(kind); free(blk); free(mark);
  return 0;
}

/* K1 from Kx (what the emitted ldl_massless does); 0 or -1 */
static int ml_values(const ldl_plan *p, const double *Kx, double *K1) {
  for (int q = 0; q < p->nnz1; q++) {
    int s = p->K1map[q];
    K1[q] = s >= 0 ? Kx[s] : s == -2 ? 1 : s == -3 ? -1 : 0;
  }
  for (int e = 0; e < p->nml; e++) {
    int r = p->mlrp[e + 1] - p->mlrp[e], y = p->mlyp[e + 1] - p->mlyp[e], r0 = p->mlrp[e];
    double *A = calloc((size_t)(6 * r + 1), sizeof(double)), *D = calloc((size_t)(r * y + 1), sizeof(double));
    double *W = malloc(sizeof(double) * (size_t)(6 * r + 1)), *V = malloc(sizeof(double) * (size_t)(r * y + 1)), Di[36];
    int *pi = malloc(sizeof(int) * (size_t)(r + 1)), rc = -1;
    if (A && D && W && V && pi) {
      for (int k = 0; k < r; k++) {
        for (int c = 0; c < 6; c++) A[6 * k + c] = p->mldu[6 * (r0 + k) + c] >= 0 ? Kx[p->mldu[6 * (r0 + k) + c]] : 0;
        for (int t = 0; t < y; t++) {
          int s = p->mldy[p->mldyp[e] + y * k + t];
          D[y * k + t] = s >= 0 ? Kx[s] : 0;
        }
      }
      rc = ml_eliminate(A, D, r, y, pi, Di, W, V);
      /* slot i (row T[i] of K1) holds the i-th row of V: which physical
         row it stands for is pi[6 + i], known at run time only */
      if (!rc)
        for (int i = 0; i < r - 6; i++)
          for (int t = 0; t < y; t++) {
            int k = p->mlkp[e] + i * y + t;
            K1[p->mlk[2 * k]] = K1[p->mlk[2 * k + 1]] = V[y * i + t];
          }
    }
    free(A); free(D); free(W); free(V); free(pi);
    if (rc) return -1;
  }
  return 0;
}

/* Row i in column j of a pattern built in two passes (count, then fill):
 * once per column (mark), stored when rows is not NULL. */
static void add_entry(int i, int j, int *mark, int *rows, int *nz) {
  if (mark[i] == j) return;
  mark[i] = j;
  if (rows) rows[*nz] = i;
  (*nz)++;
}

/* The diagonal blocks of a 6 x 6 A whose structure nz[36] is known (1 where
 * A can be nonzero): rows and columns i, j are in one block when A(i, j) or a
 * chain of such entries joins them.  A welded virtual body's D_u is
 * block-diagonal (its three point rows see only the translations, its three
 * angle rows only the rotations), and so is its inverse: comp[i] is i's block,
 * and A^-1(i, j) is zero unless comp[i] == comp[j].  Returns the number of
 * blocks. */
int ldl_inv_blocks(const int *nz, int comp[6]) {
  int par[6], lab[6], nb = 0;
  for (int i = 0; i < 6; i++) par[i] = i, lab[i] = -1;
  for (int i = 0; i < 6; i++)
    for (int j = 0; j < 6; j++)
      if (nz[6 * i + j]) {
        int a = i, b = j;
        while (par[a] != a) a = par[a];
        while (par[b] != b) b = par[b];
        if (a != b) par[a < b ? b : a] = a < b ? a : b;
      }
  for (int i = 0; i < 6; i++) {
    int a = i;
    while (par[a] != a) a = par[a];
    if (lab[a] < 0) lab[a] = nb++;
    comp[i] = lab[a];
  }
  return nb;
}

/* W(s, i) = sum_c Eu(s, c) Du^-1(c, i) can be nonzero (eu: row s's slots in
 * the body's columns, -1 none; dinz: the structure of Du^-1) */
int ldl_w_nonzero(const int *eu, const int *dinz, int i) {
  for (int c = 0; c < 6; c++)
    if (eu[c] >= 0 && dinz[6 * c + i]) return 1;
  return 0;
}

/* the correction (W Dx)(s, x) of block e can be nonzero (si, xi: positions in
 * es and ex): some i with Dx(i, x) and W(s, i) structurally nonzero.  The pattern
 * of K' holds only these pairs, so that a weld's block-diagonal D_u (point rows on
 * the translations, angle rows on the rotations) adds no fill it cannot produce */
void ldl_block_dinz(const ldl_plan *p, int e, int dinz[36]) {
  int nz[36], comp[6];
  for (int i = 0; i < 36; i++) nz[i] = p->edu[e][i] >= 0;
  ldl_inv_blocks(nz, comp);
  for (int i = 0; i < 36; i++) dinz[i] = comp[i / 6] == comp[i % 6];
}

static int elim_pair_nz(const ldl_plan *p, int e, int si, int xi) {
  int dinz[36];
  ldl_block_dinz(p, e, dinz);
  const int *dx = p->edx + 6 * xi, *eu = p->eeu + 6 * si;
  for (int i = 0; i < 6; i++)
    if (dx[i] >= 0 && ldl_w_nonzero(eu, dinz, i)) return 1;
  return 0;
}

/* eliminated unknown (U or weld row): 1 body column, 2 row, else 0 */
static int elim_kind(const ldl_plan *p, int i) {
  for (int e = 0; e < p->nelim; e++) {
    if (in_list(p->eu[e], 6, i)) return 1;
    if (in_list(p->er[e], 6, i)) return 2;
  }
  return 0;
}

/* the pattern of K' (both triangles, rows sorted), its gather map from Kx
 * and the positions of the corrected entries; 0 or -1 */
static int elim_pattern(const mb_model *m, ldl_plan *p) {
  int n = m->n, ne = p->nelim;
  char *kind = malloc((size_t)n + 1);
  int *mark = malloc(sizeof(int) * (size_t)(n + 1));
  p->Krp = calloc((size_t)n + 1, sizeof(int));
  if (!kind || !mark || !p->Krp) { free(kind); free(mark); return -1; }
  for (int i = 0; i < n; i++) { kind[i] = (char)elim_kind(p, i); mark[i] = -1; }
  for (int pass = 0; pass < 2; pass++) {
    int nz = 0;
    for (int i = 0; i < n; i++) mark[i] = -1;
    for (int j = 0; j < n; j++) {
      int start = nz;
#define ADD(ii) add_entry((ii), j, mark, pass ? p->Kri : NULL, &nz)
      if (kind[j]) {
        ADD(j);
      } else {
        for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
          if (!kind[m->Ki[q]]) ADD(m->Ki[q]);
        for (int e = 0; e < ne; e++) {
          int xs = p->exp_[e], xe = p->exp_[e + 1], ss = p->esp[e], se = p->esp[e + 1];
          for (int xi = xs; xi < xe; xi++)
            if (p->ex[xi] == j)
              for (int k = ss; k < se; k++)
                if (elim_pair_nz(p, e, k, xi)) ADD(p->es[k]);
          for (int si = ss; si < se; si++)
            if (p->es[si] == j)
              for (int k = xs; k < xe; k++)
                if (elim_pair_nz(p, e, si, k)) ADD(p->ex[k]);
        }
      }
#undef ADD
      if (pass) qsort(p->Kri + start, (size_t)(nz - start), sizeof(int), int_cmp);
      else p->Krp[j + 1] = nz;
    }
    if (!pass) {
      p->nnzR = nz;
      p->Kri = malloc(sizeof(int) * (size_t)(nz + 1));
      p->Krmap = malloc(sizeof(int) * (size_t)(nz + 1));
      if (!p->Kri || !p->Krmap) { free(kind); free(mark); return -1; }
    }
  }
  for (int j = 0; j < n; j++)
    for (int q = p->Krp[j]; q < p->Krp[j + 1]; q++) {
      int i = p->Kri[q];
      p->Krmap[q] = kind[j] ? (kind[j] == 1 ? -2 : -3) : kslot(m, i, j);
      if (p->Krmap[q] < 0 && !kind[j]) p->Krmap[q] = -1;
    }
  /* the corrected pairs */
  int npair = 0;
  for (int e = 0; e < ne; e++) npair += (p->exp_[e + 1] - p->exp_[e]) * (p->esp[e + 1] - p->esp[e]);
  p->ekr = malloc(sizeof(int) * (size_t)(2 * npair + 1));
  if (!p->ekr) { free(kind); free(mark); return -1; }
  mb_model mr = *m;
  mr.Kp = p->Krp;
  mr.Ki = p->Kri;
  mr.nnz = p->nnzR;
  int k = 0;
  for (int e = 0; e < ne; e++) {
    p->ekrp[e] = k;
    for (int si = p->esp[e]; si < p->esp[e + 1]; si++)
      for (int xi = p->exp_[e]; xi < p->exp_[e + 1]; xi++) {
        int nz = elim_pair_nz(p, e, si, xi); /* else the pair is not corrected: -1 */
        p->ekr[2 * k] = nz ? kslot(&mr, p->es[si], p->ex[xi]) : -1;
        p->ekr[2 * k + 1] = nz ? kslot(&mr, p->ex[xi], p->es[si]) : -1;
        k++;
      }
  }
  p->ekrp[ne] = k;
  free(kind); free(mark);
  return 0;
}

/* Kr = the values of K' from Kx (what the emitted factorization does); 0 or
 * -1 when a Du is singular */
static int elim_values(const ldl_plan *p, const double *Kx, double *Kr) {
  for (int q = 0; q < p->nnzR; q++) {
    int s = p->Krmap[q];
    Kr[q] = s >= 0 ? Kx[s] : s == -2 ? 1 : s == -3 ? -1 : 0;
  }
  for (int e = 0; e < p->nelim; e++) {
    double A[36], w[6];
    int piv[6];
    for (int i = 0; i < 36; i++) A[i] = p->edu[e][i] >= 0 ? Kx[p->edu[e][i]] : 0;
    if (lu6(A, piv)) return -1;
    int nx = p->exp_[e + 1] - p->exp_[e], k = p->ekrp[e];
    for (int si = p->esp[e]; si < p->esp[e + 1]; si++) {
      for (int c = 0; c < 6; c++) w[c] = p->eeu[6 * si + c] >= 0 ? Kx[p->eeu[6 * si + c]] : 0;
      lu6_solve_t(A, piv, w);
      for (int xi = 0; xi < nx; xi++, k++) {
        const int *dx = p->edx + 6 * (p->exp_[e] + xi);
        if (p->ekr[2 * k] < 0) continue; /* structurally zero */
        double v = 0;
        for (int i = 0; i < 6; i++) v += w[i] * (dx[i] >= 0 ? Kx[dx[i]] : 0);
        Kr[p->ekr[2 * k]] -= v;
        if (p->ekr[2 * k + 1] != p->ekr[2 * k]) Kr[p->ekr[2 * k + 1]] -= v;
      }
    }
  }
  return 0;
}

/* weights: rows touching a massless column get w_r = mref / |D_r|^2 with
 * mref the geometric mean of the nonzero M diagonals of the row's other
 * columns (or of all of M when it has none): D_r^T w_r D_r then adds to the
 * massless columns the scale of the masses (inertias) it couples them to.
 * The columns of a virtual body welded to a massive body are covered by the
 * 6 rows of the weld alone (see below). */
static int choose_weights(const mb_model *m, const double *Kx, ldl_plan *p) {
  int nv = m->nv, nc = m->nc;
  char *massive = calloc((size_t)nv + 1, 1), *wmark = calloc((size_t)nc + 1, 1);
  double *mdiag = calloc((size_t)nv + 1, sizeof(double));
  if (!massive || !wmark || !mdiag) { free(massive); free(wmark); free(mdiag); return -1; }
  double glog = 0;
  int gcount = 0;
  for (int j = 0; j < nv; j++) {
    for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
      if (m->Ki[q] < nv && Kx[q] != 0) massive[j] = 1;
    int s = kslot(m, j, j);
    mdiag[j] = s >= 0 ? fabs(Kx[s]) : 0;
    if (massive[j] && mdiag[j] > 0) { glog += log(mdiag[j]); gcount++; }
  }
  double gmean = gcount ? exp(glog / gcount) : 1.0;
  /* a massless body welded to a massive one (a virtual body inserted for a
     joint on a flexible node: the 6 rows of its rigid joint) needs only those
     6 rows weighted: their block on its own 6 columns is nonsingular in every
     configuration the constraints allow, so M + D_W^T W D_W is positive
     definite on its columns without weighting the rows of the joint it
     carries (which would join the bodies on both sides into one dense block) */
  int *weld = welded_rows(m, massive);
  if (!weld) { free(massive); free(wmark); free(mdiag); return -1; }
  p->nmassless = 0;
  for (int j = 0; j < nv; j++) {
    if (massive[j]) continue;
    p->nmassless++;
    int b = body_of_column(m, j);
    if (b >= 0 && weld[b] >= 0) {
      for (int r = 0; r < nc; r++)
        if (row_weld_body(m, r, massive) == b) wmark[r] = 1;
      continue;
    }
    for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++)
      if (m->Ki[q] >= nv) wmark[m->Ki[q] - nv] = 1;
  }
  free(weld);
  p->nw = 0;
  for (int r = 0; r < nc; r++) p->nw += wmark[r];
  p->wrow = malloc(sizeof(int) * (size_t)(p->nw + 1));
  p->w = malloc(sizeof(double) * (size_t)(p->nw + 1));
  p->Dp = calloc((size_t)p->nw + 1, sizeof(int));
  int cap = 0;
  for (int r = 0; r < nc; r++)
    if (wmark[r]) cap += m->Kp[nv + r + 1] - m->Kp[nv + r];
  p->Dj = malloc(sizeof(int) * (size_t)(cap + 1));
  p->Ds = malloc(sizeof(int) * (size_t)(cap + 1));
  if (!p->wrow || !p->w || !p->Dp || !p->Dj || !p->Ds) {
    free(massive); free(wmark); free(mdiag);
    return -1;
  }
  int k = 0, nd = 0;
  for (int r = 0; r < nc; r++) {
    if (!wmark[r]) continue;
    double norm2 = 0, mlog = 0;
    int mcount = 0;
    /* column nv + r holds D^T: its rows below nv are the row's velocity columns */
    for (int q = m->Kp[nv + r]; q < m->Kp[nv + r + 1]; q++) {
      int j = m->Ki[q];
      if (j >= nv) continue;
      int s = kslot(m, nv + r, j);
      if (s < 0) continue; /* (the pattern is symmetric) */
      p->Dj[nd] = j;
      p->Ds[nd++] = s;
      norm2 += Kx[s] * Kx[s];
      if (massive[j] && mdiag[j] > 0) { mlog += log(mdiag[j]); mcount++; }
    }
    double mref = mcount ? exp(mlog / mcount) : gmean;
    p->wrow[k] = r;
    p->w[k] = norm2 > 0 ? mref / norm2 : mref;
    p->Dp[++k] = nd;
  }
  free(massive); free(wmark); free(mdiag);
  return 0;
}

/* the pattern of K_aug (original numbering, both triangles, rows sorted, with
 * every diagonal entry): K's plus, for each weighted row, all pairs of its columns */
static int aug_pattern(const mb_model *m, const ldl_plan *p, int **Apo, int **Aio) {
  int n = m->n, nv = m->nv;
  /* columns -> weighted rows containing them */
  int *cp = calloc((size_t)nv + 1, sizeof(int)), *cw = NULL;
  int *mark = malloc(sizeof(int) * (size_t)(n + 1)), *Ap = calloc((size_t)n + 1, sizeof(int));
  int *Ai = NULL;
  if (!cp || !mark || !Ap) goto fail;
  for (int k = 0; k < p->nw; k++)
    for (int q = p->Dp[k]; q < p->Dp[k + 1]; q++) cp[p->Dj[q] + 1]++;
  for (int j = 0; j < nv; j++) cp[j + 1] += cp[j];
  cw = malloc(sizeof(int) * (size_t)(cp[nv] + 1));
  if (!cw) goto fail;
  {
    int *fill = calloc((size_t)nv + 1, sizeof(int));
    if (!fill) goto fail;
    for (int k = 0; k < p->nw; k++)
      for (int q = p->Dp[k]; q < p->Dp[k + 1]; q++) {
        int j = p->Dj[q];
        cw[cp[j] + fill[j]++] = k;
      }
    free(fill);
  }
  for (int pass = 0; pass < 2; pass++) {
    for (int i = 0; i < n; i++) mark[i] = -1;
    int nz = 0;
    for (int j = 0; j < n; j++) {
      int start = nz;
#define ADD(ii) add_entry((ii), j, mark, pass ? Ai : NULL, &nz)
      ADD(j);
      for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++) ADD(m->Ki[q]);
      if (j < nv)
        for (int c = cp[j]; c < cp[j + 1]; c++) {
          int k = cw[c];
          for (int q = p->Dp[k]; q < p->Dp[k + 1]; q++) ADD(p->Dj[q]);
        }
#undef ADD
      if (pass) qsort(Ai + start, (size_t)(nz - start), sizeof(int), int_cmp);
      else Ap[j + 1] = nz;
    }
    if (!pass) {
      Ai = malloc(sizeof(int) * (size_t)(nz + 1));
      if (!Ai) goto fail;
    }
  }
  free(cp); free(cw); free(mark);
  *Apo = Ap;
  *Aio = Ai;
  return 0;
fail:
  free(cp); free(cw); free(mark); free(Ap); free(Ai);
  return -1;
}

/* terms w_k D(k,i) D(k,j) of the entry (i, j) of D^T W D (original numbering) */
static int count_terms(const ldl_plan *p, int i, int j, int *Tw, int *Ta, int *Tb) {
  int nt = 0;
  for (int k = 0; k < p->nw; k++) {
    int si = -1, sj = -1;
    for (int q = p->Dp[k]; q < p->Dp[k + 1]; q++) {
      if (p->Dj[q] == i) si = p->Ds[q];
      if (p->Dj[q] == j) sj = p->Ds[q];
    }
    if (si < 0 || sj < 0) continue;
    if (Tw) { Tw[nt] = k; Ta[nt] = si; Tb[nt] = sj; }
    nt++;
  }
  return nt;
}

/* free the analysis part of the plan (ordering onwards) */
static void free_analysis(ldl_plan *p) {
  free(p->perm); free(p->iperm);
  free(p->Up); free(p->Ui); free(p->Us);
  free(p->Tp); free(p->Tw); free(p->Ta); free(p->Tb);
  free(p->parent); free(p->Lp); free(p->Li);
  free(p->Rp); free(p->Rj); free(p->Rpos);
  p->perm = p->iperm = p->Up = p->Ui = p->Us = p->Tp = p->Tw = p->Ta = p->Tb = NULL;
  p->parent = p->Lp = p->Li = p->Rp = p->Rj = p->Rpos = NULL;
}

/* CAMD with the constraint sets C on the pattern (Ap, Ai) of K_aug, then the
 * permuted upper triangle with its value sources, the elimination tree, the
 * pattern of L and the flop count.  0 or -1. */
static int analyze(const mb_model *m, ldl_plan *p, const int *Ap, const int *Ai, const int *C) {
  int n = m->n, nv = m->nv;
  int *anc = NULL, *flag = NULL, *cnt = NULL;
  uentry *U = NULL;
  free_analysis(p);
  p->perm = malloc(sizeof(int) * (size_t)(n + 1));
  p->iperm = malloc(sizeof(int) * (size_t)(n + 1));
  if (!p->perm || !p->iperm) goto fail;
  double control[CAMD_CONTROL], info[CAMD_INFO];
  camd_defaults(control);
  control[CAMD_DENSE] = -1; /* no dense-row postponement: keep the sets intact */
  if (n > 0) {
    int st = camd_order(n, Ap, Ai, p->perm, control, info, (int *)C);
    if (st != CAMD_OK && st != CAMD_OK_BUT_JUMBLED) goto fail;
  }
  for (int k = 0; k < n; k++) p->iperm[p->perm[k]] = k;
  for (int k = 1; k < n; k++)
    if (C[p->perm[k]] < C[p->perm[k - 1]]) goto fail; /* CAMD broke a constraint */

  /* upper triangle of P K_aug P^T, with the sources of every value */
  int nnzfull = Ap[n];
  U = malloc(sizeof(uentry) * (size_t)(nnzfull + 1));
  if (!U) goto fail;
  int nu = 0;
  for (int j = 0; j < n; j++)
    for (int q = Ap[j]; q < Ap[j + 1]; q++) {
      int i = Ai[q], pi = p->iperm[i], pj = p->iperm[j];
      if (pi > pj) continue;
      U[nu++] = (uentry){pj, pi, i, j, kslot(m, i, j)};
    }
  qsort(U, (size_t)nu, sizeof *U, uentry_cmp);
  p->nnzA = nu;
  p->Up = calloc((size_t)n + 1, sizeof(int));
  p->Ui = malloc(sizeof(int) * (size_t)(nu + 1));
  p->Us = malloc(sizeof(int) * (size_t)(nu + 1));
  p->Tp = calloc((size_t)nu + 1, sizeof(int));
  if (!p->Up || !p->Ui || !p->Us || !p->Tp) goto fail;
  int nt = 0;
  for (int e = 0; e < nu; e++) {
    p->Up[U[e].col + 1]++;
    p->Ui[e] = U[e].row;
    p->Us[e] = U[e].slot;
    if (U[e].i < nv && U[e].j < nv) nt += count_terms(p, U[e].i, U[e].j, NULL, NULL, NULL);
    p->Tp[e + 1] = nt;
  }
  for (int k = 0; k < n; k++) p->Up[k + 1] += p->Up[k];
  p->Tw = malloc(sizeof(int) * (size_t)(nt + 1));
  p->Ta = malloc(sizeof(int) * (size_t)(nt + 1));
  p->Tb = malloc(sizeof(int) * (size_t)(nt + 1));
  if (!p->Tw || !p->Ta || !p->Tb) goto fail;
  for (int e = 0; e < nu; e++)
    if (U[e].i < nv && U[e].j < nv)
      count_terms(p, U[e].i, U[e].j, p->Tw + p->Tp[e], p->Ta + p->Tp[e], p->Tb + p->Tp[e]);

  /* elimination tree (Liu): walk from each i < k of column k towards its
   * current root, compressing the path to k; a root reached becomes a child of k */
  p->parent = malloc(sizeof(int) * (size_t)(n + 1));
  anc = malloc(sizeof(int) * (size_t)(n + 1));
  flag = malloc(sizeof(int) * (size_t)(n + 1));
  cnt = calloc((size_t)n + 1, sizeof(int));
  if (!p->parent || !anc || !flag || !cnt) goto fail;
  for (int k = 0; k < n; k++) {
    p->parent[k] = -1;
    anc[k] = -1;
    for (int e = p->Up[k]; e < p->Up[k + 1]; e++) {
      int i = p->Ui[e];
      while (i != -1 && i < k) {
        int next = anc[i];
        anc[i] = k;
        if (next == -1) p->parent[i] = k;
        i = next;
      }
    }
  }
  /* column counts: row k of L is the union of the etree paths from each
   * i < k of column k up to k; every node on them gains one entry */
  for (int pass = 0; pass < 2; pass++) {
    for (int k = 0; k < n; k++) flag[k] = -1;
    if (pass) memset(cnt, 0, sizeof(int) * (size_t)n);
    for (int k = 0; k < n; k++) {
      flag[k] = k;
      for (int e = p->Up[k]; e < p->Up[k + 1]; e++)
        for (int i = p->Ui[e]; flag[i] != k; i = p->parent[i]) {
          flag[i] = k;
          if (pass) p->Li[p->Lp[i] + cnt[i]] = k; /* k ascends: rows come sorted */
          cnt[i]++;
        }
    }
    if (!pass) {
      p->Lp = calloc((size_t)n + 1, sizeof(int));
      if (!p->Lp) goto fail;
      for (int k = 0; k < n; k++) p->Lp[k + 1] = p->Lp[k] + cnt[k];
      p->nnzL = p->Lp[n];
      p->Li = malloc(sizeof(int) * (size_t)(p->nnzL + 1));
      if (!p->Li) goto fail;
    }
  }
  /* the same entries by rows (the transpose), columns ascending */
  p->Rp = calloc((size_t)n + 1, sizeof(int));
  p->Rj = malloc(sizeof(int) * (size_t)(p->nnzL + 1));
  p->Rpos = malloc(sizeof(int) * (size_t)(p->nnzL + 1));
  if (!p->Rp || !p->Rj || !p->Rpos) goto fail;
  for (long q = 0; q < p->nnzL; q++) p->Rp[p->Li[q] + 1]++;
  for (int k = 0; k < n; k++) p->Rp[k + 1] += p->Rp[k];
  memset(cnt, 0, sizeof(int) * (size_t)n);
  for (int j = 0; j < n; j++)
    for (int q = p->Lp[j]; q < p->Lp[j + 1]; q++) {
      int k = p->Li[q], r = p->Rp[k] + cnt[k]++;
      p->Rj[r] = j;
      p->Rpos[r] = q;
    }
  /* flops of the up-looking factorization (header comment) and of a solve */
  double fl = n;
  for (int k = 0; k < n; k++)
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) fl += 2.0 * (p->Rpos[r] - p->Lp[p->Rj[r]]) + 3;
  p->flops = fl;
  p->flops_solve = 4.0 * (double)p->nnzL + n;
  free(U); free(anc); free(flag); free(cnt);
  return 0;
fail:
  free(U); free(anc); free(flag); free(cnt);
  free_analysis(p);
  return -1;
}

/* Constraint sets from the mechanism's spanning tree (rooted at the ground).
 * Each body b reached from its parent body (or the ground) p is assigned the
 * rows between p and b whose restriction to b's columns is independent at
 * t = 0 (Gram-Schmidt, a generous threshold); the other rows close loops.
 * Sets: body b at 2 h(b), its assigned rows at 2 h(b) + 1 (h: height in the
 * tree, leaves 0), loop rows after everything.  Every leading block of the
 * order then holds rows with a block-triangular, full-row-rank restriction
 * to the leading bodies, and those bodies' block of M + D^T W D is positive
 * definite: each leading principal block of K_aug is nonsingular with one
 * positive eigenvalue per body unknown and one negative per row, so the
 * static pivots are nonzero and their signs fixed -- as with all bodies
 * first, but without coupling every pair of rows that share a body (no fill
 * at all for a tree).  Returns the number of sets, or -1. */
static int tree_sets(const mb_model *m, const double *Kx, int *C) {
  int nb = m->nbody, nv = m->nv, nc = m->nc, n = m->n;
  int *par = malloc(sizeof(int) * (size_t)(nb + 1)), *queue = malloc(sizeof(int) * (size_t)(nb + 1));
  int *height = calloc((size_t)nb + 1, sizeof(int)), *assigned = malloc(sizeof(int) * (size_t)(nc + 1));
  int *rb0 = malloc(sizeof(int) * (size_t)(nc + 1)), *rb1 = malloc(sizeof(int) * (size_t)(nc + 1));
  int *bodyof = malloc(sizeof(int) * (size_t)(nv + 1));
  double *basis = NULL, *vec = NULL;
  int nsets = -1, maxw = 6;
  if (!par || !queue || !height || !assigned || !rb0 || !rb1 || !bodyof) goto done;
  for (int b = 0; b < nb; b++) {
    int w = 6 + (m->body[b].kind == MB_BODY_FLEXIBLE ? m->body[b].nm : 0);
    if (w > maxw) maxw = w;
    for (int j = 0; j < w; j++)
      if (m->body[b].vadr + j < nv) bodyof[m->body[b].vadr + j] = b;
  }
  basis = malloc(sizeof(double) * (size_t)maxw * (size_t)(maxw + 1));
  vec = malloc(sizeof(double) * (size_t)(maxw + 1));
  if (!basis || !vec) goto done;
  for (int r = 0; r < nc; r++) {
    rb0[r] = m->marker[m->row[r].m0].body;
    rb1[r] = m->marker[m->row[r].m1].body;
    assigned[r] = -1;
  }
  /* breadth-first from the ground, then from any body not connected to it */
  for (int b = 0; b < nb; b++) par[b] = -2; /* -2: not reached, -1: ground or root */
  int head = 0, tail = 0;
  for (int r = 0; r < nc; r++) {
    int b = rb0[r] < 0 ? rb1[r] : rb1[r] < 0 ? rb0[r] : -1;
    if (b >= 0 && par[b] == -2) { par[b] = -1; queue[tail++] = b; }
  }
  for (int root = 0;; root++) {
    while (head < tail) {
      int b = queue[head++];
      for (int r = 0; r < nc; r++) {
        int o = rb0[r] == b ? rb1[r] : rb1[r] == b ? rb0[r] : -2;
        if (o >= 0 && par[o] == -2) { par[o] = b; queue[tail++] = o; }
      }
    }
    while (root < nb && par[root] != -2) root++;
    if (root >= nb) break;
    par[root] = -1;
    queue[tail++] = root;
  }
  /* rows between each body and its parent, kept while independent on the body */
  for (int b = 0; b < nb; b++) {
    int w = 6 + (m->body[b].kind == MB_BODY_FLEXIBLE ? m->body[b].nm : 0), rank = 0;
    for (int r = 0; r < nc && rank < w; r++) {
      int other = rb0[r] == b ? rb1[r] : rb1[r] == b ? rb0[r] : -2;
      if (other == -2 || other != par[b] || rb0[r] == rb1[r]) continue;
      double norm = 0;
      for (int j = 0; j < w; j++) {
        int s = kslot(m, nv + r, m->body[b].vadr + j);
        vec[j] = s >= 0 ? Kx[s] : 0;
        norm += vec[j] * vec[j];
      }
      norm = sqrt(norm);
      if (!(norm > 0)) continue;
      for (int pass = 0; pass < 2; pass++)
        for (int k = 0; k < rank; k++) {
          double d = 0;
          for (int j = 0; j < w; j++) d += basis[k * maxw + j] * vec[j];
          for (int j = 0; j < w; j++) vec[j] -= d * basis[k * maxw + j];
        }
      double rest = 0;
      for (int j = 0; j < w; j++) rest += vec[j] * vec[j];
      rest = sqrt(rest);
      if (rest < 1e-3 * norm) continue; /* (nearly) dependent on b: a loop row */
      for (int j = 0; j < w; j++) basis[rank * maxw + j] = vec[j] / rest;
      rank++;
      assigned[r] = b;
    }
  }
  /* heights: children before parents (reverse breadth-first order) */
  int hmax = 0;
  for (int k = tail - 1; k >= 0; k--) {
    int b = queue[k];
    if (par[b] >= 0 && height[par[b]] < height[b] + 1) height[par[b]] = height[b] + 1;
    if (height[b] > hmax) hmax = height[b];
  }
  for (int i = 0; i < nv; i++) C[i] = 2 * height[bodyof[i]];
  for (int r = 0; r < nc; r++) C[nv + r] = assigned[r] >= 0 ? 2 * height[assigned[r]] + 1 : 2 * hmax + 2;
  nsets = 2 * hmax + 3;
  /* CAMD wants every set from 0 to max non-empty: renumber the sets used */
  {
    int *used = calloc((size_t)nsets + 1, sizeof(int));
    if (!used) { nsets = -1; goto done; }
    for (int i = 0; i < n; i++) used[C[i]] = 1;
    int k = 0;
    for (int c = 0; c < nsets; c++) used[c] = used[c] ? k++ : -1;
    for (int i = 0; i < n; i++) C[i] = used[C[i]];
    nsets = k;
    free(used);
  }
done:
  free(par); free(queue); free(height); free(assigned); free(rb0); free(rb1); free(bodyof);
  free(basis); free(vec);
  return nsets;
}

static double default_budget = -1; /* < 0: the host's compile-time rule */
void ldl_set_default_budget(double flops) { default_budget = flops; }

double ldl_payback_calls(const ldl_plan *p, int jobs) {
  double gain = (LDL_NS_PER_FLOP_LOOPED - LDL_NS_PER_FLOP_STRAIGHT) * 1e-9 * (p->flops + p->flops_solve);
  return gain > 0 ? LDL_GCC_SECONDS_PER_FLOP * (p->flops + p->flops_solve) / (jobs > 0 ? jobs : 1) / gain : 0;
}

int ldl_plan_build(const lmodel *L, ldl_plan *p) {
  const mb_model *m = &L->m;
  memset(p, 0, sizeof *p);
  int n = m->n, nv = m->nv;
  p->n = n;
  p->nv = nv;
  p->nc = m->nc;
  const char *env = getenv("MBCC_LDL_BUDGET");
  p->budget = env && *env ? atof(env) : default_budget;
  const char *ord = getenv("MBCC_LDL_ORDER"); /* "bodies-first" or "tree": force one */
  int *Ap = NULL, *Ai = NULL, *C2 = NULL, *Ct = NULL;
  double *Kx = kx_at_start(m), *Kr = NULL;
  mb_model m1;
  if (!Kx) goto fail;
  /* massless bodies (MBCC_LDL_MASSLESS=0: none); from here on m is K1 */
  if (find_massless(m, Kx, p) || ml_pattern(m, p)) goto fail;
  Kr = malloc(sizeof(double) * (size_t)(p->nnz1 + 1));
  if (!Kr || ml_values(p, Kx, Kr)) goto fail;
  m1 = *m;
  m1.Kp = p->K1p;
  m1.Ki = p->K1i;
  m1.nnz = p->nnz1;
  m = &m1;
  free(Kx);
  Kx = Kr;
  Kr = NULL;
  /* block pivots (MBCC_LDL_BLOCK=0: none, the weld rows are weighted instead);
     from here on m is K' (pattern Krp/Kri, values Kr) */
  const char *blk = getenv("MBCC_LDL_BLOCK");
  if (find_elims(m, Kx, p)) goto fail;
  if (blk && !strcmp(blk, "0")) p->nelim = 0;
  if (elim_pattern(m, p)) goto fail;
  Kr = malloc(sizeof(double) * (size_t)(p->nnzR + 1));
  if (!Kr || elim_values(p, Kx, Kr)) goto fail;
  mb_model mr = *m;
  mr.Kp = p->Krp;
  mr.Ki = p->Kri;
  mr.nnz = p->nnzR;
  m = &mr;
  free(Kx);
  Kx = Kr;
  Kr = NULL;
  if (choose_weights(m, Kx, p)) goto fail;
  if (aug_pattern(m, p, &Ap, &Ai)) goto fail;
  C2 = malloc(sizeof(int) * (size_t)(n + 1));
  Ct = malloc(sizeof(int) * (size_t)(n + 1));
  if (!C2 || !Ct) goto fail;
  /* all body unknowns before all constraint rows (always valid) */
  for (int i = 0; i < n; i++) C2[i] = i >= nv;
  int nt = tree_sets(m, Kx, Ct);
  double f2 = INFINITY;
  if (!(ord && !strcmp(ord, "tree"))) {
    if (analyze(m, p, Ap, Ai, C2)) goto fail;
    f2 = p->flops;
    p->nsets = 2;
  }
  if (nt > 0 && !(ord && !strcmp(ord, "bodies-first"))) {
    ldl_plan t = *p; /* same weights; a second analysis */
    t.perm = t.iperm = t.Up = t.Ui = t.Us = t.Tp = t.Tw = t.Ta = t.Tb = NULL;
    t.parent = t.Lp = t.Li = t.Rp = t.Rj = t.Rpos = NULL;
    if (!analyze(m, &t, Ap, Ai, Ct) && t.flops < f2) {
      free_analysis(p);
      *p = t;
      p->nsets = nt;
      p->tree = 1;
    } else {
      free_analysis(&t);
    }
  }
  if (!p->perm) goto fail;
  /* the block pivots' own work with dense 6 x 6 blocks (the looped code's):
     LU of Du, a transposed solve per S row and the product with Dx; per solve
     the right side (W g_r, Dx^T Du^-T f_u) and the recovery (two 6 x 6
     solves).  An upper bound: the straight-line code skips the structural
     zeros of Du, Du^-1, W and Dx (a weld's Du is four blocks on the diagonal) */
  p->flops_block = 0;
  p->flops_block_solve = 0;
  p->flops_ml = 0;
  p->flops_ml_solve = 0;
  for (int e = 0; e < p->nml; e++) {
    double r = p->mlrp[e + 1] - p->mlrp[e], ny = p->mlyp[e + 1] - p->mlyp[e];
    p->flops_ml += 12 * r + 2 * 6 * 6 * 6 + (r - 6) * (72 + 12 * ny);
    p->flops_ml_solve += 2 * (72 + 12 * ny + 12 * (r - 6)) + 12 * (r - 6);
  }
  for (int e = 0; e < p->nelim; e++) {
    double nxe = p->exp_[e + 1] - p->exp_[e], nse = p->esp[e + 1] - p->esp[e];
    p->flops_block += 150 + nse * (72 + 12 * nxe);
    p->flops_block_solve += 4 * 72 + 24 * (nxe + nse);
  }
  /* the choice (order.h): the straight-line block pivots and massless
     bodies are code too (their bounds: the flexible_virtual car's 18096 flops
     of block pivots took about 6 s of gcc) */
  p->cc_seconds = LDL_GCC_SECONDS_PER_FLOP * (p->flops + p->flops_solve + p->flops_block + p->flops_block_solve +
                                              p->flops_ml + p->flops_ml_solve);
  p->straight = p->budget >= 0 ? p->flops <= p->budget : p->cc_seconds <= LDL_STRAIGHT_SECONDS;
  free(Kx); free(Ap); free(Ai); free(C2); free(Ct);
  return 0;
fail:
  free(Kx); free(Kr); free(Ap); free(Ai); free(C2); free(Ct);
  ldl_plan_free(p);
  return -1;
}

void ldl_plan_report(const ldl_plan *plan, FILE *out) {
  if (!plan) {
    fprintf(out, "  LDL^T             not available (ordering failed)\n");
    return;
  }
  const ldl_plan *p = plan;
  if (p->tree)
    fprintf(out, "  ordering          CAMD, %d sets from the spanning tree (bodies before their joints' rows)\n",
            p->nsets);
  else
    fprintf(out, "  ordering          CAMD, %d body unknowns before %d constraint rows\n", p->nv, p->nc);
  if (p->nmassless)
    fprintf(out, "  zero mass         %d massless unknowns: %d rows weighted (K_aug = [M + D^T W D, D^T; D, 0])\n",
            p->nmassless, p->nw);
  if (p->nml)
    fprintf(out, "  massless bodies   %d eliminated with 6 of their rows each, chosen by pivoting "
                 "(at most %.0f flops per factorization, %.0f per solve)\n", p->nml, p->flops_ml, p->flops_ml_solve);
  if (p->nelim)
    fprintf(out, "  block pivots      %d welded virtual bodies eliminated with their weld rows "
                 "(at most %.0f flops per factorization, %.0f per solve)\n", p->nelim, p->flops_block, p->flops_block_solve);
  fprintf(out, "  nnz(L)            %ld (strictly lower; L + D + L^T has %ld)\n", p->nnzL, 2 * p->nnzL + p->n);
  fprintf(out, "  LDL^T flops       %.0f per factorization, %.0f per solve\n", p->flops, p->flops_solve);
  if (p->budget >= 0)
    fprintf(out, "  LDL^T code        %s (flop budget %.0f)\n", p->straight ? "straight-line" : "looped", p->budget);
  else
    fprintf(out, "  LDL^T code        %s (straight-line: about %.1f s of gcc CPU, limit %.0f s; it pays back its build "
                 "after about %.2g calls on 2 cores)\n",
            p->straight ? "straight-line" : "looped", p->cc_seconds, LDL_STRAIGHT_SECONDS, ldl_payback_calls(p, 2));
}
