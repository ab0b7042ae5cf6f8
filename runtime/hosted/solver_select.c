/* solver_select.c: a linear solver by name.  The single-precision runtime
 * (-DMB_REAL_FLOAT, for embedded targets) has only the emitted LDL^T: KLU and
 * LAPACK work in double. */
#include <string.h>
#include "mb_solver.h"

mb_solver *mb_solver_new(const char *name, const mb_model *m) {
  if (!strcmp(name, "ldl")) return mb_solver_ldl(m);
#ifndef MB_REAL_FLOAT
  if (!strcmp(name, "klu")) return mb_solver_klu(m);
  if (!strcmp(name, "dense")) return mb_solver_dense(m);
  if (!strcmp(name, "generic-klu")) return mb_solver_generic(m, 0);
  if (!strcmp(name, "generic-dense")) return mb_solver_generic(m, 1);
#endif
  return NULL;
}

/* the names mb_solver_new accepts for model m, for messages: the emitted
   LDL^T only with generated code, KLU and LAPACK only in double */
const char *mb_solver_choices(const mb_model *m) {
#ifdef MB_REAL_FLOAT
  (void)m;
  return "ldl";
#else
  return m->ldl_factor ? "ldl, klu or dense" : "klu or dense";
#endif
}
