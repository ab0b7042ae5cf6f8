/* timing_main.c (host only): @MODEL@_step in a fixed-rate loop as a real-time
 * task would call it, each call timed; prints the median and the worst step
 * time against the period @UMODEL@_STEP.  The loop does not sleep: it is the
 * task body, and the worst case is what a deadline must allow for (run it on
 * an idle machine: here every other process shows up in the worst case).
 *   ./host-timing [steps]   (default 20000) */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <time.h>
#include "@MODEL@_api.h"

static @MODEL@_data data;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  long n = argc > 1 ? atol(argv[1]) : 20000;
  if (n < 1) n = 1;
  double *dt = malloc(sizeof(double) * (size_t)n);
  if (!dt) return 1;
  int st = @MODEL@_init(&data);
  long k = 0;
  for (; !st && k < n; k++) {
    double t0 = now();
    st = @MODEL@_step(&data, (mb_real)@UMODEL@_STEP);
    dt[k] = now() - t0;
  }
  if (st) { fprintf(stderr, "step %ld: status %d\n", k, st); return 1; }
  qsort(dt, (size_t)n, sizeof *dt, by_value);
  printf("steps %ld period %.3g us median %.3f us worst %.3f us (median %.1f%% of the period)\n", n,
         1e6 * @UMODEL@_STEP, 1e6 * dt[n / 2], 1e6 * dt[n - 1], 100 * dt[n / 2] / @UMODEL@_STEP);
  free(dt);
  return 0;
}
