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

/* K and M as triplets (i, j, value; duplicates to be summed, both
 * triangles) in the 6-per-node DOF numbering: the sparse assembly of large
 * bodies.  Returns 0, or nonzero with err (the arrays then freed). */
int fe_assemble_triplets(const ir_flex *fx, ir_fe_matrix *K, ir_fe_matrix *M, char *err, size_t nerr,
                         ir_loc *where);

/* an RBE2's dependent DOF d as a combination of its independent node's 6 DOFs */
void fe_link_row(const ir_flex *fx, const ir_rigid_link *L, int d, double coef[6]);

/* The lowest nev eigenpairs of (K, M) restricted to the free DOFs (free[i]:
 * the free index of DOF i, or -1; nf of them), RBE2-dependent DOFs folded
 * into their independent ones: shift-invert Lanczos (ARPACK) about sigma,
 * K - sigma M factored by CHOLMOD.  lam ascending (Rayleigh quotients), X
 * (nf x nev, column-major) M-orthonormal.  Returns 0, or nonzero with err. */
int fe_sparse_eigs(const ir_flex *fx, const ir_fe_matrix *K, const ir_fe_matrix *M, const int *free_index,
                   int nf, int nev, double sigma, double *lam, double *X, char *err, size_t nerr);

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
  int sparse;           /* computed by the sparse eigensolver (fe_sparse.c) */
} fe_modes;

/* Reduce a flexible body to modes: from its FE model (reference nodes fixed;
 * Craig-Bampton when interface nodes are given: static constraint modes of the
 * interface DOFs plus fixed-interface normal modes, then orthonormalized by
 * the reduced eigenproblem so that each has a frequency), or from its modal
 * data file.  Applies the mode selection.  Returns 0, or nonzero with err. */
int fe_compute_modes(const ir_flex *fx, fe_modes *out, char *err, size_t nerr);
void fe_modes_free(fe_modes *m);

/* As fe_assemble and fe_compute_modes, and also report in *where the source
 * location of the item at fault (a beam, a point mass, a node, or the body);
 * line 0 when there is none.  A modal data file's modes come from the IR
 * (fx->modal, read and checked by the front end): only the selection applies.
 * Node numbers in messages are the IR's (0-based) indices.
 * Craig-Bampton: the selection applies to the fixed-interface normal modes,
 * and all_freq_hz lists those; the result is the 6 x (interface nodes) +
 * selected modes of the reduced eigenproblem, each with its frequency.
 * Constrained normal modes: all_freq_hz lists every mode, and the selected
 * ones hold exactly the values in freq_hz. */
int fe_assemble_at(const ir_flex *fx, fe_system *out, char *err, size_t nerr, ir_loc *where);
int fe_compute_modes_at(const ir_flex *fx, fe_modes *out, char *err, size_t nerr, ir_loc *where);

/* Lumped (HRZ) nodal masses and rotary inertias of the FE model, point masses
 * included: node_mass[nnodes], node_inertia[9 nnodes] (body axes, row-major).
 * Returns 0, or nonzero with err. */
int fe_lumped_nodes(const ir_flex *fx, double *node_mass, double *node_inertia, char *err,
                    size_t nerr, ir_loc *where);

/* Section resultants of beam e at its end (0: A, 1: B) per unit modal
 * coordinate: rows (6 x nmodes, row-major) N Vy Vz T My Mz in the element's
 * axes, on the face whose outward normal is the element's +x (tension,
 * and the moments the part beyond applies); sec: A, Iy, Iz.  0 or -1 with err. */
int fe_section_rows(const ir_flex *fx, int e, int end, const fe_modes *fm, double *rows, double sec[3],
                    char *err, size_t nerr);

/* Static (Guyan) condensation for a massless superelement: the 6 x 6
 * stiffness K6 (row-major, symmetric, the FE model's axes) of node 'loaded'
 * with node 'clamped' held (all 6 DOFs), every other node free: the inverse
 * of the loaded node's flexibility, equal to the Schur complement
 * K_BB - K_Bi K_ii^-1 K_iB.  SPCs and RBE2s of the model apply.  Returns 0,
 * or nonzero with err. */
int fe_condense(const ir_flex *fx, int clamped, int loaded, double K6[36], char *err, size_t nerr,
                ir_loc *where);
/* The same for any number of loaded nodes (a superelement with more than
 * two interface nodes): Kc, (6 nloaded)^2 row-major, the stiffness of the
 * loaded nodes' DOFs (in their order) with 'clamped' held, the Schur
 * complement of K onto them.  Errors: a mechanism with 'clamped' held, a
 * loaded DOF fixed by an SPC, or loaded DOFs that cannot move apart. */
int fe_condense_nodes(const ir_flex *fx, int clamped, const int *loaded, int nloaded, double *Kc, char *err,
                      size_t nerr, ir_loc *where);

/* Write m (its selected modes) as a modal data file (docs/modal-file.md);
 * 'description' may be NULL.  Returns 0, or nonzero with err. */
int fe_modes_write(const fe_modes *m, const char *path, const char *description, char *err,
                   size_t nerr);

#endif
