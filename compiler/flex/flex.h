/* flex.h: a flexible body's runtime description (mb_flex) built from its
 * modes at compile time: inertia invariants, modal stiffness and damping. */
#ifndef MBCC_FLEX_H
#define MBCC_FLEX_H

#include "fe.h"
#include "ir.h"
#include "mb_flex.h"

typedef struct {
  mb_flex flex; /* points into the arrays below */
  double *S1, *E, *F, *G, *C0, *CPsi, *Mff, *stiffness, *damping;
  double *node_x, *node_X, *node_Psi;
  double *stiff_P, *stiff_R; /* geometric stiffening (NULL: off), stiffening.c */
  mb_flex_stiff stiff;       /* points into them */
} flex_data;

int flex_build(const ir_flex *fx, const fe_modes *fm, flex_data *out, char *err, size_t nerr);
void flex_data_free(flex_data *d);
/* Geometric stiffening (compiler/flex/stiffening.c): the tables P_ij, R_ij
 * of mb_flex from the beams' geometric stiffness under the static axial
 * forces of unit inertia loads; sets out->stiff.  0, or -1 with err. */
int flex_stiffening_build(const ir_flex *fx, const fe_modes *fm, flex_data *out, char *err, size_t nerr);
/* 0: structurally zero, 1: constant, 2: varying entry (i, l) of the mass block */
int flex_mass_entry(const mb_flex *f, const mb_flex_stiff *st, int i, int l);

/* fe_compute_modes with diagnostics at the faulty element; 0 or 2 */
int flex_compute_modes(const char *path, const ir_body *B, fe_modes *fm);

/* The flexible-body stage's product: the modes and the runtime description of
 * every flexible body, indexed like the IR's bodies (0 is the ground; entries
 * of other bodies are zero).  Lowering reads it; the compilation unit owns it. */
typedef struct {
  int nbodies;
  fe_modes *modes;
  flex_data *data;
} flex_product;

/* Reduce every flexible body of the IR (modes, then invariants).  Returns 0,
 * or 2 after reporting at the body (out of memory included). */
int flex_reduce(const ir_model *ir, flex_product *out);
void flex_product_free(flex_product *fp);

#endif
