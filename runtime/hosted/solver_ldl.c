/* solver_ldl.c: K x = b with the LDL^T that the compiler emitted with the
 * model (m->ldl_factor / m->ldl_solve, compiler/back/emit_ldl.c): pattern,
 * ordering and every index fixed at compile time.  This wrapper only holds
 * the workspace and the K that was factored (the solve reads it: the massless
 * bodies' right side, the residual and the refinement): a copy, or the
 * caller's own Kx when the caller promises to keep it (kx_stable); it
 * allocates at creation only. */
#include <stdlib.h>
#include <string.h>
#include "mb_solver.h"

typedef struct {
  mb_solver base;
  const mb_model *m;
  mb_real *Kx;    /* a copy of the K of the last factorization */
  const mb_real *K; /* the K of the last factorization: Kx, or the caller's */
  mb_real *work;  /* m->ldl_worksize */
} ldl_solver;

static int ldl_factor_fn(mb_solver *s, const mb_real *Kx) {
  ldl_solver *l = (ldl_solver *)s;
  if (s->kx_stable) {
    l->K = Kx;
  } else {
    memcpy(l->Kx, Kx, sizeof(mb_real) * (size_t)l->m->nnz);
    l->K = l->Kx;
  }
  s->factorizations++;
  s->full_factorizations++;
  int rc = l->m->ldl_factor(l->m, l->K, l->work);
  s->bad_pivot = rc ? rc - 1 : -1;
  return rc ? MB_ERR_SINGULAR : MB_OK;
}

/* Every check_every-th solve (the first included) computes the residual and
 * refines; the others are the single pass of a library LDL^T.  When a checked
 * solve finds the single pass above MB_LDL_PASS_TOL (static pivots on a badly
 * scaled K: a slender body's tiny inertia), every later solve refines.  Models
 * with weighted rows refine on every solve whatever check_every says (the
 * emitted solve does), they only report less often. */
static int ldl_solve_fn(mb_solver *s, mb_real *b) {
  ldl_solver *l = (ldl_solver *)s;
  int check = s->check_every <= 1 || s->refine_always || s->solves % s->check_every == 0;
  s->solves++;
  if (!check) return l->m->ldl_solve(l->m, l->K, l->work, b, NULL);
  mb_real res[2] = {0, 0};
  int rc = l->m->ldl_solve(l->m, l->K, l->work, b, res);
  s->residual = res[0];
  s->residual_checks++;
  if (!(res[0] <= s->residual_max)) s->residual_max = res[0];
  if (!(res[1] <= s->residual_pass_max)) s->residual_pass_max = res[1];
  if (!(res[1] <= MB_LDL_PASS_TOL)) s->refine_always = 1;
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
  l->base.check_every = m->ldl_exact ? MB_LDL_CHECK_EVERY : 1;
  l->base.checks_finite = 1; /* every emitted *_ldl_solve tests its result */
  l->m = m;
  l->Kx = calloc((size_t)m->nnz + 1, sizeof(mb_real));
  l->work = calloc(m->ldl_worksize + 1, sizeof(mb_real));
  if (!l->Kx || !l->work) { ldl_destroy_fn(&l->base); return NULL; }
  l->K = l->Kx;
  return &l->base;
}
