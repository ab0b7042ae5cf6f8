/* solver_dense.c: K x = b with LAPACK LU on the full matrix (the "full LU"
 * of the seed's tables): the pattern is scattered into an n x n array. */
#include <stdlib.h>
#include <string.h>
#include "mb_solver.h"

void dgetrf_(const int *m, const int *n, double *a, const int *lda, int *ipiv, int *info);
void dgetrs_(const char *trans, const int *n, const int *nrhs, const double *a, const int *lda,
             const int *ipiv, double *b, const int *ldb, int *info);

typedef struct {
  mb_solver base;
  const int *Kp, *Ki;
  double *A; /* column-major n x n */
  int *ipiv;
} dense_solver;

static int dense_factor(mb_solver *s, const mb_real *Kx) {
  dense_solver *d = (dense_solver *)s;
  int n = s->n, info = 0;
  memset(d->A, 0, sizeof(double) * (size_t)n * (size_t)n);
  for (int j = 0; j < n; j++)
    for (int p = d->Kp[j]; p < d->Kp[j + 1]; p++) d->A[(size_t)j * (size_t)n + (size_t)d->Ki[p]] = Kx[p];
  s->factorizations++;
  s->full_factorizations++;
  dgetrf_(&n, &n, d->A, &n, d->ipiv, &info);
  return info == 0 ? MB_OK : MB_ERR_SINGULAR;
}

static int dense_solve(mb_solver *s, mb_real *b) {
  dense_solver *d = (dense_solver *)s;
  int n = s->n, one = 1, info = 0;
  dgetrs_("N", &n, &one, d->A, &n, d->ipiv, b, &n, &info);
  return info == 0 ? MB_OK : MB_ERR_SINGULAR;
}

static void dense_destroy(mb_solver *s) {
  dense_solver *d = (dense_solver *)s;
  if (!d) return;
  free(d->A); free(d->ipiv); free(d);
}

mb_solver *mb_solver_dense(const mb_model *m) {
  dense_solver *d = calloc(1, sizeof *d);
  if (!d) return NULL;
  d->base.name = "dense";
  d->base.n = m->n;
  d->base.factor = dense_factor;
  d->base.solve = dense_solve;
  d->base.destroy = dense_destroy;
  d->Kp = m->Kp;
  d->Ki = m->Ki;
  d->A = malloc(sizeof(double) * (size_t)m->n * (size_t)m->n + 1);
  d->ipiv = malloc(sizeof(int) * (size_t)m->n + 1);
  if (!d->A || !d->ipiv) { dense_destroy(&d->base); return NULL; }
  return &d->base;
}

