/* emit.h: the back end's entry points: the generated code of a compilation
 * unit (compiler/unit.h), which the emitters only read. */
#ifndef MBCC_EMIT_H
#define MBCC_EMIT_H

#include "unit.h"

/* Emit DIR/<name>.h, DIR/<name>.c and DIR/main.c, all or nothing.  Returns 0,
 * or 2 after reporting. */
int emit_model(const mbc_unit *u, const char *dir);
/* Fill templates/<name> (model name, simulation settings, solver) into the
 * file 'out'.  Returns 0, or 2 after reporting. */
int emit_template(const mbc_unit *u, const char *name, const char *out);
/* where the templates and runtime sources are: $MBCC_ROOT, else the build's checkout */
const char *emit_root_dir(void);
/* mbcc compile --target embedded: the package of compiler/back/emit_embedded.c;
 * integrator MB_RK4 or MB_GENALPHA, step the suggested fixed step.  Returns 0,
 * or 2 after reporting. */
int emit_embedded(const mbc_unit *u, const char *dir, int integrator, double step);

#endif
