/* support.h: helpers shared by the tests: simulate a compiled model and keep
 * its outputs in memory, read CSV files, run a command and capture its output. */
#ifndef TESTS_SUPPORT_H
#define TESTS_SUPPORT_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "mb_sim.h"

typedef struct {
  int nrows, ncols;   /* ncols: output columns (without t) */
  double *t;          /* nrows */
  double *y;          /* nrows x ncols, row-major */
  int status;         /* mb_sim_run status */
  double fail_time;
  mb_stats stats;
} trajectory;

/* |a - b| <= tol, with the values in the failure message */
#define assert_close(a, b, tol)                                                              \
  do {                                                                                       \
    double a_ = (a), b_ = (b);                                                               \
    if (!(fabs(a_ - b_) <= (tol))) {                                                         \
      print_error("%s = %.17g, %s = %.17g, tolerance %g\n", #a, a_, #b, b_, (double)(tol)); \
      fail();                                                                                \
    }                                                                                        \
  } while (0)

/* settings from a model's defaults: DOPRI5 rtol 1e-9 unless changed by the caller */
void test_settings(mb_settings *s, double end_time, double output_step);
/* simulate and collect every output column at every output time */
int simulate(const mb_model *m, const mb_settings *s, const char *solver, trajectory *out);
void trajectory_free(trajectory *tr);
/* index of output column 'name' (as in the CSV header), or -1 */
int column(const mb_model *m, const char *name);
/* value of column c at row k */
static inline double at(const trajectory *tr, int k, int c) { return tr->y[(size_t)k * (size_t)tr->ncols + (size_t)c]; }

/* Largest difference between two runs of model m over every column and row,
 * relative to the column's range over run a; a column that hardly moves
 * (range below 1e-3 in its units, e.g. a coordinate that stays 0, or a
 * conserved energy) is compared against 1e-3.  Names the worst column in
 * *worst_col when not NULL.  The runs must share their output times. */
double max_rel_diff(const mb_model *m, const trajectory *a, const trajectory *b,
                    const char **worst_col);

/* run a shell command; capture stdout+stderr (truncated to n-1 chars); returns exit status */
int run_capture(const char *cmd, char *out, size_t n);

/* a generic-path copy of a generated model: same tables, table-walking eval */
mb_model generic_twin(const mb_model *m);

/* uniform random in [a, b) from a fixed-seed generator (reproducible) */
double urand(double a, double b);

/* ||b - K x||_inf / (||K||_inf ||x||_inf + ||b||_inf) on K's pattern */
double k_rel_residual(const mb_model *m, const double *Kx, const double *x, const double *b);
/* Kx and the right side at a state near q0 (k = 0: q0 itself): positions moved
 * along a random velocity-space increment (exact rotations), random velocities */
void k_near_q0(const mb_model *m, int k, double *Kx, double *rhs, void *work);

#endif
