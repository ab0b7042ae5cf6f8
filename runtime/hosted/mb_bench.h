/* mb_bench.h: the timing comparison of `mbcc bench`: one model simulated in
 * one process through every path (generated or generic evaluation, ldl, klu
 * or dense solver, and SUNDIALS IDA), as in seed Tables 3 and 6 (hosted). */
#ifndef MB_BENCH_H
#define MB_BENCH_H

#include "mb_sim.h"

/* Options: [--reps N] [--csv FILE] [--paths a,b,...] [--quiet]
 *          [--integrator rk4|dopri5] [--stabilization projection|baumgarte|none]
 *          [--end T] [--output-step H] [--step H] [--rtol R] [--atol A]
 * 'defaults' are the model's simulation settings.  Prints the table on stdout
 * (progress on stderr unless --quiet).  Returns 0 when every path that is
 * available ran to the end, 1 when one failed, 2 on bad options or when the
 * CSV cannot be written. */
int mb_bench_main(int argc, char **argv, const mb_model *m, const mb_settings *defaults);

#endif
