/* solver_generic.c: the general generic path's linear solver: triplets from
 * the element loops are assembled into a compressed-column matrix every step
 * (counting sort by column, rows sorted, duplicates summed), then factorized
 * by KLU, reusing its symbolic analysis while the pattern is unchanged, or by
 * LAPACK's dense LU.  This is the competent general-purpose baseline the
 * generated code is timed against. */
#include <stdlib.h>
#include <string.h>
#include <suitesparse/klu.h>
#include "mb_solver.h"

void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info);

typedef struct {
  mb_solver base;
  const mb_model *m;
  void *work;
  int dense;
  int cap;                  /* triplet capacity */
  int *Ap, *Ai, *next;      /* assembled CSC and a column-fill cursor */
  double *Ax;
  int *Pp, *Pi;             /* the pattern KLU analyzed */
  int pnz;
  klu_symbolic *symbolic;
  klu_numeric *numeric;
  klu_common common;
  double rcond_full;
  double *A;                /* dense */
  int *ipiv;
} gen_solver;

/* triplets -> CSC with sorted rows and summed duplicates; returns nnz */
static int assemble(gen_solver *g) {
  const mb_triplets *T = mb_generic_triplets(g->m, g->work);
  int n = g->base.n;
  memset(g->Ap, 0, sizeof(int) * (size_t)(n + 1));
  for (int k = 0; k < T->n; k++) g->Ap[T->j[k] + 1]++;
  for (int j = 0; j < n; j++) g->Ap[j + 1] += g->Ap[j];
  memcpy(g->next, g->Ap, sizeof(int) * (size_t)n);
  for (int k = 0; k < T->n; k++) {
    int p = g->next[T->j[k]]++;
    g->Ai[p] = T->i[k];
    g->Ax[p] = T->x[k];
  }
  /* each column: insertion sort by row, then sum duplicates in place */
  int nz = 0;
  for (int j = 0; j < n; j++) {
    int lo = g->Ap[j], hi = g->Ap[j + 1];
    for (int p = lo + 1; p < hi; p++) {
      int r = g->Ai[p];
      double x = g->Ax[p];
      int q = p - 1;
      while (q >= lo && g->Ai[q] > r) {
        g->Ai[q + 1] = g->Ai[q];
        g->Ax[q + 1] = g->Ax[q];
        q--;
      }
      g->Ai[q + 1] = r;
      g->Ax[q + 1] = x;
    }
    g->Ap[j] = nz;
    for (int p = lo; p < hi; p++) {
      if (nz > g->Ap[j] && g->Ai[nz - 1] == g->Ai[p]) {
        g->Ax[nz - 1] += g->Ax[p];
      } else {
        g->Ai[nz] = g->Ai[p];
        g->Ax[nz] = g->Ax[p];
        nz++;
      }
    }
  }
  g->Ap[n] = nz;
  return nz;
}

static int klu_full(gen_solver *g) {
  if (g->numeric) klu_free_numeric(&g->numeric, &g->common);
  g->numeric = klu_factor(g->Ap, g->Ai, g->Ax, g->symbolic, &g->common);
  if (!g->numeric || g->common.status != KLU_OK) return MB_ERR_SINGULAR;
  klu_rcond(g->symbolic, g->numeric, &g->common);
  g->rcond_full = g->common.rcond;
  g->base.full_factorizations++;
  return MB_OK;
}

static int gen_factor(mb_solver *s, const mb_real *Kx) {
  gen_solver *g = (gen_solver *)s;
  (void)Kx;
  int n = s->n, nz = assemble(g);
  s->factorizations++;
  if (g->dense) {
    int info = 0;
    memset(g->A, 0, sizeof(double) * (size_t)n * (size_t)n);
    for (int j = 0; j < n; j++)
      for (int p = g->Ap[j]; p < g->Ap[j + 1]; p++) g->A[(size_t)j * (size_t)n + (size_t)g->Ai[p]] = g->Ax[p];
    s->full_factorizations++;
    dgetrf_(&n, &n, g->A, &n, g->ipiv, &info);
    return info == 0 ? MB_OK : MB_ERR_SINGULAR;
  }
  int same = g->symbolic && nz == g->pnz && !memcmp(g->Ap, g->Pp, sizeof(int) * (size_t)(n + 1)) &&
             !memcmp(g->Ai, g->Pi, sizeof(int) * (size_t)nz);
  if (!same) { /* a new pattern: analyze it */
    if (g->numeric) klu_free_numeric(&g->numeric, &g->common);
    if (g->symbolic) klu_free_symbolic(&g->symbolic, &g->common);
    memcpy(g->Pp, g->Ap, sizeof(int) * (size_t)(n + 1));
    memcpy(g->Pi, g->Ai, sizeof(int) * (size_t)nz);
    g->pnz = nz;
    g->symbolic = klu_analyze(n, g->Pp, g->Pi, &g->common);
    if (!g->symbolic) return MB_ERR_SINGULAR;
    return klu_full(g);
  }
  if (klu_refactor(g->Ap, g->Ai, g->Ax, g->symbolic, g->numeric, &g->common) &&
      g->common.status == KLU_OK && klu_rcond(g->symbolic, g->numeric, &g->common) &&
      g->common.rcond > 1e-3 * g->rcond_full)
    return MB_OK;
  return klu_full(g);
}

static int gen_solve(mb_solver *s, mb_real *b) {
  gen_solver *g = (gen_solver *)s;
  int n = s->n;
  if (g->dense) {
    int one = 1, info = 0;
    dgetrs_("N", &n, &one, g->A, &n, g->ipiv, b, &n, &info);
    return info == 0 ? MB_OK : MB_ERR_SINGULAR;
  }
  return klu_solve(g->symbolic, g->numeric, n, 1, b, &g->common) ? MB_OK : MB_ERR_SINGULAR;
}

static void gen_bind(mb_solver *s, void *work) { ((gen_solver *)s)->work = work; }

static void gen_destroy(mb_solver *s) {
  gen_solver *g = (gen_solver *)s;
  if (!g) return;
  if (g->numeric) klu_free_numeric(&g->numeric, &g->common);
  if (g->symbolic) klu_free_symbolic(&g->symbolic, &g->common);
  free(g->Ap); free(g->Ai); free(g->next); free(g->Ax); free(g->Pp); free(g->Pi);
  free(g->A); free(g->ipiv);
  free(g);
}

mb_solver *mb_solver_generic(const mb_model *m, int dense) {
  gen_solver *g = calloc(1, sizeof *g);
  if (!g) return NULL;
  int n = m->n;
  size_t cap = 0;
  for (int b = 0; b < m->nbody; b++) cap += (size_t)(6 + m->body[b].nm) * (size_t)(6 + m->body[b].nm);
  for (int r = 0; r < m->nrow; r++)
    for (int s = 0; s < 2; s++) {
      int k = s ? m->row[r].m1 : m->row[r].m0;
      if (m->marker[k].body >= 0) cap += 2 * (size_t)(6 + m->body[m->marker[k].body].nm);
    }
  g->base.name = dense ? "generic-dense" : "generic-klu";
  g->base.n = n;
  g->base.factor = gen_factor;
  g->base.solve = gen_solve;
  g->base.destroy = gen_destroy;
  g->base.bind = gen_bind;
  g->m = m;
  g->dense = dense;
  g->Ap = malloc(sizeof(int) * (size_t)(n + 1));
  g->next = malloc(sizeof(int) * (size_t)(n + 1));
  g->Pp = malloc(sizeof(int) * (size_t)(n + 1));
  g->Ai = malloc(sizeof(int) * (cap + 1));
  g->Pi = malloc(sizeof(int) * (cap + 1));
  g->Ax = malloc(sizeof(double) * (cap + 1));
  if (dense) {
    g->A = malloc(sizeof(double) * (size_t)n * (size_t)n + 1);
    g->ipiv = malloc(sizeof(int) * (size_t)n + 1);
  }
  if (!g->Ap || !g->next || !g->Pp || !g->Ai || !g->Pi || !g->Ax || (dense && (!g->A || !g->ipiv))) {
    gen_destroy(&g->base);
    return NULL;
  }
  klu_defaults(&g->common);
  return &g->base;
}
