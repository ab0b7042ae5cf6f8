/* solver_ldl.c: K x = b with the LDL^T that the compiler emitted with the
 * model (m->ldl_factor / m->ldl_solve, compiler/emit_ldl.c): pattern,
 * ordering and every index fixed at compile time.  This wrapper only holds
 * the workspace and a copy of Kx (the refinement works on the exact system,
 * so the solve needs the K that was factored); it allocates at creation only. */
#include <stdlib.h>
#include <string.h>
#include "mb_solver.h"

typedef struct {
  mb_solver base;
  const mb_model *m;
  mb_real *Kx;    /* the K of the last factorization */
  mb_real *work;  /* m->ldl_worksize */
} ldl_solver;

static int ldl_factor_fn(mb_solver *s, const mb_real *Kx) {
  ldl_solver *l = (ldl_solver *)s;
  memcpy(l->Kx, Kx, sizeof(mb_real) * (size_t)l->m->nnz);
  s->factorizations++;
  s->full_factorizations++;
  int rc = l->m->ldl_factor(l->m, l->Kx, l->work);
  s->bad_pivot = rc ? rc - 1 : -1;
  return rc ? MB_ERR_SINGULAR : MB_OK;
}

static int ldl_solve_fn(mb_solver *s, mb_real *b) {
  ldl_solver *l = (ldl_solver *)s;
  mb_real res = 0;
  int rc = l->m->ldl_solve(l->m, l->Kx, l->work, b, &res);
  s->residual = res;
  if (!(res <= s->residual_max)) s->residual_max = res;
  return rc;
}

static void ldl_destroy_fn(mb_solver *s) {
  ldl_solver *l = (ldl_solver *)s;
  if (!l) return;
  free(l->Kx);
  free(l->work);
  free(l);
}

mb_solver *mb_solver_ldl(const mb_model *m) {
  if (!m->ldl_factor || !m->ldl_solve) return NULL;
  ldl_solver *l = calloc(1, sizeof *l);
  if (!l) return NULL;
  l->base.name = "ldl";
  l->base.n = m->n;
  l->base.factor = ldl_factor_fn;
  l->base.solve = ldl_solve_fn;
  l->base.destroy = ldl_destroy_fn;
  l->base.bad_pivot = -1;
  l->m = m;
  l->Kx = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  l->work = calloc(m->ldl_worksize + 1, sizeof(mb_real));
  if (!l->Kx || !l->work) { ldl_destroy_fn(&l->base); return NULL; }
  return &l->base;
}
