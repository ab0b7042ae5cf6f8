/* mb_solver.h: linear solvers for K x = b on the model's fixed pattern.
 * Hosted runtime (they allocate at creation, never per step). */
#ifndef MB_SOLVER_H
#define MB_SOLVER_H

#include "mb_model.h"

typedef struct mb_solver {
  const char *name;
  int n;
  long factorizations;   /* numeric factorizations (incl. refactorizations) */
  long full_factorizations; /* of which with a new pivot order (KLU) */
  int (*factor)(struct mb_solver *s, const mb_real *Kx); /* MB_OK or MB_ERR_SINGULAR */
  int (*solve)(struct mb_solver *s, mb_real *b);         /* in place */
  void (*destroy)(struct mb_solver *s);
  /* optional: told the simulation's workspace (the general generic path
     reads its triplets there) */
  void (*bind)(struct mb_solver *s, void *work);
  /* ldl: relative residual ||b - K x||_inf / (||K||_inf ||x||_inf + ||b||_inf) of the
   * last solve after refinement and the largest so far; the unknown whose pivot
   * failed in the last factorization, or -1 (other solvers leave these 0) */
  double residual, residual_max;
  int bad_pivot;
  /* ldl: the residual is computed (and the solution refined) on every
   * check_every-th solve, counted by 'solves'; 1 = on every solve.  The largest
   * residual of a single pass seen; refine_always once it exceeded MB_LDL_PASS_TOL */
  int check_every, refine_always;
  long solves, residual_checks;
  double residual_pass_max;
  /* set by a caller that leaves the Kx it passed to factor() unchanged until
     the next factor() (the simulation drivers do): the ldl solver then reads
     that Kx in its solves instead of keeping a copy (nnz values per factor) */
  int kx_stable;
  /* klu: the reciprocal condition estimate (min |u_ii| / max |u_ii|) of the
     last factorization with fresh pivots: with the pivot order of an earlier
     configuration a small u_ii says little; 0 when not estimated */
  double rcond;
  /* set by a solver whose solve() itself returns MB_ERR_NONFINITE when the
     solution holds a NaN or an Inf (ldl: the emitted solve tests it in its
     last pass), so that its callers need not test again */
  int checks_finite;
} mb_solver;

/* SuiteSparse KLU: analyze once, refactor per step, factor again (new pivots)
 * when the reciprocal condition estimate drops by 1e3 from the last full factor */
mb_solver *mb_solver_klu(const mb_model *m);
/* LAPACK dgetrf/dgetrs on the full n x n matrix */
mb_solver *mb_solver_dense(const mb_model *m);
/* The general generic path's solvers (model eval = mb_generic_triplet_eval):
 * each factorization assembles K from the triplets into CSC (sorting and
 * summing duplicates), then KLU (symbolic analysis reused while the assembled
 * pattern does not change) or LAPACK dense LU. */
mb_solver *mb_solver_generic(const mb_model *m, int dense);
/* the LDL^T emitted with the model (m->ldl_factor, compiler/back/emit_ldl.c); NULL
 * when the model has none */
mb_solver *mb_solver_ldl(const mb_model *m);
/* ldl's default check_every on models without weighted rows: the residual of one
 * solve in 64 (the factors are those of K; the check watches the conditioning) */
#define MB_LDL_CHECK_EVERY 64
/* a single pass with a larger relative residual turns refinement on for good: a
 * tenth of the 1e-12 every solve must meet, for the residual varies along a run */
#define MB_LDL_PASS_TOL 1e-13
/* by name: "klu" or "dense"; NULL if unknown or out of memory */
mb_solver *mb_solver_new(const char *name, const mb_model *m);
/* the names mb_solver_new accepts for m, as a phrase for messages */
const char *mb_solver_choices(const mb_model *m);

#endif
