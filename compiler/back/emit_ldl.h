/* emit_ldl.h: the emitted LDL^T (solver "ldl") in the generated code; see
 * order.h for the analysis and emit_ldl.c for what is written. */
#ifndef MBCC_EMIT_LDL_H
#define MBCC_EMIT_LDL_H

#include <stdio.h>

#include "emit_util.h"

/* <model>.h: the workspace-size macros and the prototypes */
void emit_ldl_header(emit_ctx *cx);
/* Where emit_ldl writes.  out NULL: all of it to cx->f, one file's text.
 * Else the LDL^T's tables and functions go to cx->f, the model record's
 * wrappers (ldl_factor_m, ldl_solve_m, which <model>.c points at) to
 * 'wrappers', and each out-of-line part of the straight-line code (the bulk
 * of it) to the stream part_file returns: extern functions <model>_ldl_...,
 * declared where they are called.  *fresh = 1 from part_file: a new stream
 * (a file of its own), which gets the macros the parts use first. */
typedef struct {
  FILE *wrappers;
  FILE *(*part_file)(void *ctx, int *fresh);
  void *ctx;
} ldl_out;

/* <model>.c: tables and functions, before the model initializer; returns 1
 * when emitted, 0 when not (no plan: the model then has no ldl; or out of
 * memory: cx->failed set) */
int emit_ldl(emit_ctx *cx, const ldl_out *out);
/* inside the initializer: the designated initializers of the ldl fields */
void emit_ldl_fields(emit_ctx *cx, int emitted);

#endif
