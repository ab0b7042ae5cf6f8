/* solver_klu.c: K x = b with SuiteSparse KLU on the fixed CSC pattern. */
#include <stdlib.h>
#include <string.h>
#include <suitesparse/klu.h>
#include "mb_solver.h"

typedef struct {
  mb_solver base;
  int *Ap, *Ai;          /* KLU takes non-const int arrays: a copy of the pattern */
  double *Ax;
  klu_symbolic *symbolic;
  klu_numeric *numeric;
  klu_common common;
  double rcond_full;     /* condition estimate at the last full factorization */
} klu_solver;

static int full_factor(klu_solver *k) {
  if (k->numeric) klu_free_numeric(&k->numeric, &k->common);
  k->numeric = klu_factor(k->Ap, k->Ai, k->Ax, k->symbolic, &k->common);
  if (!k->numeric || k->common.status != KLU_OK) return MB_ERR_SINGULAR;
  klu_rcond(k->symbolic, k->numeric, &k->common);
  k->rcond_full = k->common.rcond;
  k->base.rcond = k->common.rcond;
  k->base.full_factorizations++;
  return MB_OK;
}

static int klu_factor_fn(mb_solver *s, const mb_real *Kx) {
  klu_solver *k = (klu_solver *)s;
  for (int j = 0; j < k->Ap[s->n]; j++) k->Ax[j] = Kx[j];
  s->factorizations++;
  if (!k->numeric) return full_factor(k);
  /* same pivot order: refactor, unless it fails or the pivots degrade */
  if (klu_refactor(k->Ap, k->Ai, k->Ax, k->symbolic, k->numeric, &k->common) &&
      k->common.status == KLU_OK && klu_rcond(k->symbolic, k->numeric, &k->common) &&
      k->common.rcond > 1e-3 * k->rcond_full)
    return MB_OK;
  return full_factor(k);
}

static int klu_solve_fn(mb_solver *s, mb_real *b) {
  klu_solver *k = (klu_solver *)s;
  if (!klu_solve(k->symbolic, k->numeric, s->n, 1, b, &k->common)) return MB_ERR_SINGULAR;
  return MB_OK;
}

static void klu_destroy_fn(mb_solver *s) {
  klu_solver *k = (klu_solver *)s;
  if (!k) return;
  if (k->numeric) klu_free_numeric(&k->numeric, &k->common);
  if (k->symbolic) klu_free_symbolic(&k->symbolic, &k->common);
  free(k->Ap); free(k->Ai); free(k->Ax);
  free(k);
}

mb_solver *mb_solver_klu(const mb_model *m) {
  klu_solver *k = calloc(1, sizeof *k);
  if (!k) return NULL;
  k->base.name = "klu";
  k->base.n = m->n;
  k->base.factor = klu_factor_fn;
  k->base.solve = klu_solve_fn;
  k->base.destroy = klu_destroy_fn;
  k->Ap = malloc(sizeof(int) * (size_t)(m->n + 1));
  k->Ai = malloc(sizeof(int) * (size_t)(m->nnz > 0 ? m->nnz : 1));
  k->Ax = malloc(sizeof(double) * (size_t)(m->nnz > 0 ? m->nnz : 1));
  if (!k->Ap || !k->Ai || !k->Ax) { klu_destroy_fn(&k->base); return NULL; }
  memcpy(k->Ap, m->Kp, sizeof(int) * (size_t)(m->n + 1));
  memcpy(k->Ai, m->Ki, sizeof(int) * (size_t)m->nnz);
  klu_defaults(&k->common);
  k->symbolic = klu_analyze(m->n, k->Ap, k->Ai, &k->common);
  if (!k->symbolic) { klu_destroy_fn(&k->base); return NULL; }
  return &k->base;
}
