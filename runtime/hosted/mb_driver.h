/* mb_driver.h: the command-line simulator around a compiled model (hosted). */
#ifndef MB_DRIVER_H
#define MB_DRIVER_H

#include "mb_sim.h"

/* Parse options, simulate, write CSV, print a summary.  'defaults' are the
 * model's simulation settings; 'solver' its default solver name.
 * Returns 0 on success, 1 on a numerical failure, 2 on bad options. */
int mb_main(int argc, char **argv, const mb_model *m, const mb_settings *defaults,
            const char *solver);

/* One simulation-settings option of the command line (--integrator,
 * --stabilization, --end, --output-step, --step, --max-step, --rtol, --atol):
 * 1 if applied, 0 if opt is not one of them, -1 after printing an error. */
int mb_settings_option(mb_settings *set, const char *opt, const char *val, const char *prog);

/* What a LAPACK argument error (xerbla_, driver.c) names: the model file in
 * mbcc, NULL in a simulator.  Such an error stops the process with status 1. */
extern const char *mb_lapack_context;

#endif
