/* emit_ldl.h: the emitted LDL^T (solver "ldl") in the generated code; see
 * order.h for the analysis and emit_ldl.c for what is written. */
#ifndef MBCC_EMIT_LDL_H
#define MBCC_EMIT_LDL_H

#include <stdio.h>

#include "unit.h"

/* <model>.h: the workspace-size macros and the prototypes */
void emit_ldl_header(FILE *f, const mbc_unit *u, const char *nm);
/* <model>.c: tables and functions, before the model initializer; returns 1
 * when emitted, 0 when not (no plan, or out of memory: the model then has no ldl) */
int emit_ldl(FILE *f, const mbc_unit *u, const char *nm);
/* inside the initializer: the designated initializers of the ldl fields */
void emit_ldl_fields(FILE *f, const char *nm, int emitted);

#endif
