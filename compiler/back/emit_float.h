/* emit_float.h: rewrite an emitted C file into its single-precision dialect
 * (float literals, MB_* math macros); see emit_float.c. */
#ifndef MBCC_EMIT_FLOAT_H
#define MBCC_EMIT_FLOAT_H

/* rewrite the file at path in place; 0, or -1 when it cannot be read or written */
int emit_float_dialect(const char *path);

#endif
