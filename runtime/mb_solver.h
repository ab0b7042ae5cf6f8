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
} mb_solver;

/* SuiteSparse KLU: analyze once, refactor per step, factor again (new pivots)
 * when the reciprocal condition estimate drops by 1e3 from the last full factor */
mb_solver *mb_solver_klu(const mb_model *m);
/* LAPACK dgetrf/dgetrs on the full n x n matrix */
mb_solver *mb_solver_dense(const mb_model *m);
/* by name: "klu" or "dense"; NULL if unknown or out of memory */
mb_solver *mb_solver_new(const char *name, const mb_model *m);

#endif
