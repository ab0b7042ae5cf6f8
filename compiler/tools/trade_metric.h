/* trade_metric.h: the pure parts of `mbcc trade` (no I/O, no model): the error
 * of a run against the reference, the Pareto front in (CPU time, error), and
 * the cheapest run that meets an error target.  Linked by tests/test_trade.c. */
#ifndef MBCC_TRADE_METRIC_H
#define MBCC_TRADE_METRIC_H

typedef struct {
  double max_err;  /* max over columns and samples of |run - ref| / scale(column) */
  double rms_err;  /* sqrt of the mean of (|run - ref| / scale)^2 over all samples and columns */
  int worst_col;   /* the column of max_err (-1 if no samples) */
} trade_error;

/* group[c] for each of n column names: columns "v.x", "v.y", ... of one vector
 * output share the index of the first of them; any other column its own. */
void trade_column_groups(const char *const *names, int n, int *group);

/* scale[c]: the range (max - min) of column c of the reference ref (nrows x
 * ncols, row-major), the largest range within its group; a group that does
 * not move is measured against its largest |value|, or 1 if that is 0. */
void trade_column_scales(const double *ref, int nrows, int ncols, const int *group, double *scale);

/* The error of run against ref (both nrows x ncols, same output times) with
 * the scales above.  Returns 0, or -1 if run holds a non-finite value. */
int trade_compare(const double *ref, const double *run, int nrows, int ncols, const double *scale,
                  trade_error *e);

/* pareto[i] = 1 if run i succeeded (failed[i] == 0) and no other successful
 * run is at least as good in both cpu and err and better in one; else 0. */
void trade_pareto(const double *cpu, const double *err, const int *failed, int n, int *pareto);

/* The successful run with err <= max_error and the smallest cpu (ties: the
 * smaller err, then the first), or -1 if none meets it. */
int trade_cheapest(const double *cpu, const double *err, const int *failed, int n, double max_error);

#endif
