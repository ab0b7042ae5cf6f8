/* fe.h: 3D beam finite elements (Euler-Bernoulli and Timoshenko) and the
 * modal reduction of a flexible body at compile time: constrained normal
 * modes or Craig-Bampton, from LAPACK's generalized symmetric eigensolver. */
#ifndef MBCC_FE_H
#define MBCC_FE_H

#include <stddef.h>
#include "ir.h"

/* Dense FE matrices of a flexible body: 6 DOFs per node (ux uy uz rx ry rz,
 * body axes), column-major ndof x ndof. */
typedef struct {
  int ndof;
  double *K, *M;
} fe_system;

/* Assemble K and M (consistent or HRZ-lumped as fx->mass says; point masses
 * added).  Returns 0, or nonzero with a message in err. */
int fe_assemble(const ir_flex *fx, fe_system *out, char *err, size_t nerr);
void fe_system_free(fe_system *s);

/* The modal description a flexible body is simulated with. */
typedef struct {
  int nnodes, nmodes;
  double *x;            /* 3 * nnodes: undeformed node positions, body axes */
  double *freq_hz;      /* nmodes, ascending */
  double *shapes;       /* (6 nnodes) x nmodes, column-major; the rows of reference
                           nodes are zero; mass-normalized: X^T M X = I */
  double *node_mass;    /* nnodes: lumped (HRZ) translational mass of each node */
  double *node_inertia; /* 9 nnodes: lumped rotary inertia of each node, body axes */
  int nall;
  double *all_freq_hz;  /* every frequency computed before selection (for `mbcc modes`) */
} fe_modes;

/* Reduce a flexible body to modes: from its FE model (reference nodes fixed;
 * Craig-Bampton when interface nodes are given: static constraint modes of the
 * interface DOFs plus fixed-interface normal modes, then orthonormalized by
 * the reduced eigenproblem so that each has a frequency), or from its modal
 * data file.  Applies the mode selection.  Returns 0, or nonzero with err. */
int fe_compute_modes(const ir_flex *fx, fe_modes *out, char *err, size_t nerr);
void fe_modes_free(fe_modes *m);

#endif
