/* fe_import.h: flexible bodies from FE files (docs/model-format.md, "FE
 * files"): a Nastran bulk-data subset (import_nastran.c) and Matrix Market
 * stiffness and mass matrices with a node/DOF map (import_mtx.c).
 *
 * An import fills the FE model of fx: nnodes, node_ids (the file's node ids,
 * which name the nodes in the model), node positions (global, returned in
 * *global: the reader moves them to body axes), and either beams (section
 * y axes global), point masses (inertia global), RBE2 links, fixed DOFs, or
 * the given matrices K_given / M_given (global axes: fe_import_to_body turns
 * them, and the point masses' inertia, into body axes).  fx->fe_path is set.
 * Errors are reported with diag_error at the FE file's line and column (the
 * file an INCLUDE names, if there); the functions return 0, or 2 after an
 * error, leaving fx as it was. */
#ifndef MBCC_FE_IMPORT_H
#define MBCC_FE_IMPORT_H

#include "ir.h"

int fe_import_nastran(const char *path, ir_flex *fx, double **global);

typedef struct {
  const char *stiffness, *mass; /* Matrix Market files */
  const char *dofs;             /* one line per matrix row: node id and DOF */
  const char *nodes;            /* one line per node: id, x, y, z (global) */
} fe_mtx_files;
int fe_import_mtx(const fe_mtx_files *files, ir_flex *fx, double **global);

/* body axes: A maps body to global coordinates (row-major, global = A body) */
void fe_import_to_body(ir_flex *fx, const double A[9]);

/* the node index of id (-1: none) */
int fe_node_index(const ir_flex *fx, long id);

/* Euler parameters of axes whose x is the direction a -> b (y as close to
 * global y as it can be, global z for a direction near y).  0, or -1 if a == b. */
int fe_chord_axes(const double a[3], const double b[3], double e[4]);

void fe_import_free(ir_flex *fx);

#endif
