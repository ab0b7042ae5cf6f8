/* eval_harness.c: the emitted evaluation of one compiled model alone
 * (scripts/loop-profile.sh links it with the generated model and a file
 * defining eval_model).
 *   eval_harness calls N   N evaluations at the initial state (for cachegrind)
 *   eval_harness time      median and fastest per-call time [us] over 31 rounds
 *                          (a round: about 2 ms of calls)
 *   eval_harness dump      the evaluation's outputs (K's entries, rhs, phi,
 *                          phid) at the initial state, one %.17g a line */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mb_model.h"

extern const mb_model *const eval_model;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

int main(int argc, char **argv) {
  const mb_model *m = eval_model;
  const char *mode = argc > 1 ? argv[1] : "time";
  long calls = argc > 2 ? atol(argv[2]) : 1000;
  double *q = malloc(sizeof(double) * (size_t)m->nq), *v = calloc((size_t)m->nv, sizeof(double));
  memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
  /* a fixed, nonzero velocity (the state does not change the work done) */
  for (int i = 0; i < m->nv; i++) v[i] = 0.01 * ((i * 7919) % 13 - 6);
  void *work = malloc(mb_model_worksize(m) + 16);
  double *Kx = calloc((size_t)m->nnz + 1, sizeof(double)), *rhs = calloc((size_t)m->n, sizeof(double));
  double *phi = calloc((size_t)m->nc + 1, sizeof(double)), *phid = calloc((size_t)m->nc + 1, sizeof(double));
  m->init(m, Kx);
  m->eval(m, 0.25, q, v, Kx, rhs, phi, phid, work);
  if (!strcmp(mode, "dump")) {
    for (int i = 0; i < m->nnz; i++) printf("K %d %.17g\n", i, Kx[i]);
    for (int i = 0; i < m->n; i++) printf("rhs %d %.17g\n", i, rhs[i]);
    for (int i = 0; i < m->nc; i++) printf("phi %d %.17g %.17g\n", i, phi[i], phid[i]);
    return 0;
  }
  if (!strcmp(mode, "calls")) {
    for (long k = 0; k < calls; k++) m->eval(m, 0.25, q, v, Kx, rhs, phi, phid, work);
    return 0;
  }
  double t0 = now();
  long reps = 0;
  while (now() - t0 < 2e-3) {
    m->eval(m, 0.25, q, v, Kx, rhs, phi, phid, work);
    reps++;
  }
  double t[31];
  for (int r = 0; r < 31; r++) {
    t0 = now();
    for (long k = 0; k < reps; k++) m->eval(m, 0.25, q, v, Kx, rhs, phi, phid, work);
    t[r] = (now() - t0) / (double)reps * 1e6;
  }
  qsort(t, 31, sizeof t[0], by_value);
  printf("%.3f %.3f\n", t[15], t[0]);
  return 0;
}
