/* emit_force.h: what the force elements' emit hooks (compiler/elements/)
 * use from the emitter (emit.c).  Inside the generated eval, a force's block
 * has c[] (6 + modes) for body columns, zero3, x[3] (profiles), the frames
 * fB and markers kM. */
#ifndef EMIT_FORCE_H
#define EMIT_FORCE_H

#include <stdio.h>
#include "lower.h"

/* a real as a reproducible literal (%.17g, no -0) */
void emit_num(FILE *f, double x);
/* c = the body columns of the pair (dV, dW) (names of 3-vectors) at marker k
 * whose point is the expression P; returns how many columns (6 or 6 + modes),
 * -1 out of memory (the element's emit_eval returns -1) */
int emit_cols(FILE *f, const lmodel *L, int k, const char *P, const char *dV, const char *dW,
              const char *indent);
/* rhs[vadr + j] += c[j], j < n */
void emit_add_cols(FILE *f, int vadr, int n);

#endif
