/* trade_metric.c: the error metric, Pareto front and cheapest-run choice of
 * `mbcc trade` (pure functions; see trade_metric.h and docs/trade.md). */
#include "trade_metric.h"

#include <math.h>
#include <string.h>

void trade_column_groups(const char *const *names, int n, int *group) {
  for (int c = 0; c < n; c++) {
    group[c] = c;
    const char *dot = strrchr(names[c], '.');
    if (!dot) continue;
    size_t len = (size_t)(dot - names[c]);
    for (int d = 0; d < c; d++) {
      const char *dd = strrchr(names[d], '.');
      if (dd && (size_t)(dd - names[d]) == len && !strncmp(names[d], names[c], len)) {
        group[c] = group[d];
        break;
      }
    }
  }
}

void trade_column_scales(const double *ref, int nrows, int ncols, const int *group, double *scale) {
  /* a group's range is the largest of its members' ranges; then the fallbacks */
  for (int c = 0; c < ncols; c++) {
    double range = 0, big = 0;
    for (int d = 0; d < ncols; d++) {
      if (group[d] != group[c]) continue;
      double lo = INFINITY, hi = -INFINITY;
      for (int k = 0; k < nrows; k++) {
        double x = ref[(size_t)k * (size_t)ncols + (size_t)d];
        lo = fmin(lo, x);
        hi = fmax(hi, x);
        big = fmax(big, fabs(x));
      }
      if (hi > lo) range = fmax(range, hi - lo);
    }
    scale[c] = range > 0 ? range : big > 0 ? big : 1;
  }
}

int trade_compare(const double *ref, const double *run, int nrows, int ncols, const double *scale,
                  trade_error *e) {
  double mx = 0, sum2 = 0;
  e->worst_col = -1;
  for (int k = 0; k < nrows; k++)
    for (int c = 0; c < ncols; c++) {
      size_t i = (size_t)k * (size_t)ncols + (size_t)c;
      if (!isfinite(run[i])) {
        e->max_err = e->rms_err = NAN;
        return -1;
      }
      double d = fabs(run[i] - ref[i]) / scale[c];
      sum2 += d * d;
      if (d > mx || e->worst_col < 0) { mx = fmax(mx, d); e->worst_col = c; }
    }
  long n = (long)nrows * ncols;
  e->max_err = mx;
  e->rms_err = n > 0 ? sqrt(sum2 / (double)n) : 0;
  return 0;
}

void trade_pareto(const double *cpu, const double *err, const int *failed, int n, int *pareto) {
  for (int i = 0; i < n; i++) {
    pareto[i] = !failed[i] && isfinite(cpu[i]) && isfinite(err[i]);
    for (int j = 0; j < n && pareto[i]; j++) {
      if (j == i || failed[j] || !isfinite(cpu[j]) || !isfinite(err[j])) continue;
      if (cpu[j] <= cpu[i] && err[j] <= err[i] && (cpu[j] < cpu[i] || err[j] < err[i])) pareto[i] = 0;
    }
  }
}

int trade_cheapest(const double *cpu, const double *err, const int *failed, int n, double max_error) {
  int best = -1;
  for (int i = 0; i < n; i++) {
    if (failed[i] || !isfinite(cpu[i]) || !(err[i] <= max_error)) continue;
    if (best < 0 || cpu[i] < cpu[best] || (cpu[i] == cpu[best] && err[i] < err[best])) best = i;
  }
  return best;
}
