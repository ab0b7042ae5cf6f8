/* emit_ldl.h: the emitted LDL^T (solver "ldl") in the generated code; see
 * order.h for the analysis and emit_ldl.c for what is written. */
#ifndef MBCC_EMIT_LDL_H
#define MBCC_EMIT_LDL_H

#include <stdio.h>

#include "emit_util.h"

/* <model>.h: the workspace-size macros and the prototypes */
void emit_ldl_header(emit_ctx *cx);
/* <model>.c: tables and functions, before the model initializer; returns 1
 * when emitted, 0 when not (no plan: the model then has no ldl; or out of
 * memory: cx->failed set) */
int emit_ldl(emit_ctx *cx);
/* inside the initializer: the designated initializers of the ldl fields */
void emit_ldl_fields(emit_ctx *cx, int emitted);

#endif
