/* ldl_harness.c: the emitted LDL^T of one compiled model alone (scripts/ldl-profile.sh
 * links it with the generated <model>.c and a file defining ldl_model).
 *   ldl_harness ldl N    N calls of factor + solve at the initial state (for cachegrind)
 *   ldl_harness eval N   N evaluations (eval's share, for comparison)
 *   ldl_harness time     median and fastest per-call time [us] of factor + solve over
 *                        31 rounds (a round: about 2 ms of calls)
 *   ldl_harness evaltime the same of one evaluation (scripts/loop-profile.sh)
 *   ldl_harness amd      nnz(L) and flops of the model's ordering beside SuiteSparse AMD
 *                        (no constraint sets) on the same pattern of K */
#define _POSIX_C_SOURCE 200809L
#include <amd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mb_model.h"

extern const mb_model *const ldl_model;

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int by_value(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return x < y ? -1 : x > y;
}

/* nnz(L) and the flops of order.c's count (n + sum over columns of c^2 + 2c)
 * of the symmetric pattern of K permuted by perm: column counts from the
 * elimination tree, each row's entries climbing it from the entries of the
 * upper triangle (a marker per row) */
static void symbolic(const mb_model *m, const int *perm, long *nnzl, double *flops) {
  int n = m->n;
  int *iperm = malloc(sizeof(int) * (size_t)n), *parent = malloc(sizeof(int) * (size_t)n);
  int *mark = malloc(sizeof(int) * (size_t)n), *cnt = calloc((size_t)n, sizeof(int));
  for (int k = 0; k < n; k++) iperm[perm[k]] = k;
  for (int k = 0; k < n; k++) {
    parent[k] = -1;
    mark[k] = k;
    int col = perm[k];
    for (int q = m->Kp[col]; q < m->Kp[col + 1]; q++)
      for (int i = iperm[m->Ki[q]]; i < k && mark[i] != k; i = parent[i]) {
        if (parent[i] < 0) parent[i] = k;
        cnt[i]++;
        mark[i] = k;
      }
  }
  *nnzl = 0;
  *flops = n;
  for (int j = 0; j < n; j++) {
    *nnzl += cnt[j];
    *flops += (double)cnt[j] * cnt[j] + 2.0 * cnt[j];
  }
  free(iperm); free(parent); free(mark); free(cnt);
}

/* one call of what the time modes measure: the evaluation, or factor + solve */
static void timed_call(const mb_model *m, int eval_only, const double *q, const double *v, double *Kx,
                       double *rhs, double *phi, double *phid, void *work, double *lw, double *x) {
  if (eval_only) {
    m->eval(m, 0, q, v, Kx, rhs, phi, phid, work);
    return;
  }
  m->ldl_factor(m, Kx, lw);
  memcpy(x, rhs, sizeof(double) * (size_t)m->n);
  m->ldl_solve(m, Kx, lw, x, NULL);
}

int main(int argc, char **argv) {
  const mb_model *m = ldl_model;
  const char *mode = argc > 1 ? argv[1] : "time";
  long calls = argc > 2 ? atol(argv[2]) : 1000;
  if (!m->ldl_factor) { fprintf(stderr, "ldl_harness: the model has no emitted LDL^T\n"); return 2; }
  if (!strcmp(mode, "amd")) {
    int *perm = malloc(sizeof(int) * (size_t)m->n);
    if (amd_order(m->n, m->Kp, m->Ki, perm, NULL, NULL) < 0) { fprintf(stderr, "ldl_harness: AMD failed\n"); return 1; }
    long nnzl;
    double fl;
    symbolic(m, perm, &nnzl, &fl);
    printf("%s: n %d, mbcc's ordering: nnz(L) %ld, %.0f flops; AMD (unconstrained): nnz(L) %ld, %.0f flops (%.2fx)\n",
           m->name, m->n, m->ldl_nnzL, m->ldl_flops, nnzl, fl, m->ldl_flops / fl);
    return 0;
  }
  double *q = malloc(sizeof(double) * (size_t)m->nq), *v = calloc((size_t)m->nv, sizeof(double));
  memcpy(q, m->q0, sizeof(double) * (size_t)m->nq);
  /* a fixed, nonzero velocity (the state does not change the work done) */
  for (int i = 0; i < m->nv; i++) v[i] = 0.01 * ((i * 7919) % 13 - 6);
  void *work = malloc(mb_model_worksize(m) + 16);
  double *Kx = calloc((size_t)m->nnz + 1, sizeof(double)), *rhs = calloc((size_t)m->n, sizeof(double));
  double *x = calloc((size_t)m->n, sizeof(double)), *phi = calloc((size_t)m->nc + 1, sizeof(double));
  double *phid = calloc((size_t)m->nc + 1, sizeof(double)), *lw = calloc(m->ldl_worksize + 1, sizeof(double));
  m->init(m, Kx);
  m->eval(m, 0, q, v, Kx, rhs, phi, phid, work);
  if (m->ldl_factor(m, Kx, lw)) { fprintf(stderr, "ldl_harness: the factorization failed\n"); return 1; }
  if (!strcmp(mode, "ldl") || !strcmp(mode, "eval")) {
    for (long k = 0; k < calls; k++) {
      if (mode[0] == 'e') {
        m->eval(m, 0, q, v, Kx, rhs, phi, phid, work);
        continue;
      }
      m->ldl_factor(m, Kx, lw);
      memcpy(x, rhs, sizeof(double) * (size_t)m->n);
      m->ldl_solve(m, Kx, lw, x, NULL);
    }
    return 0;
  }
  /* time (factor + solve) or evaltime (eval): calls per round from a first
     estimate, 31 rounds */
  int eval_only = !strcmp(mode, "evaltime");
  double t0 = now();
  long reps = 0;
  while (now() - t0 < 2e-3) {
    timed_call(m, eval_only, q, v, Kx, rhs, phi, phid, work, lw, x);
    reps++;
  }
  double t[31];
  for (int r = 0; r < 31; r++) {
    t0 = now();
    for (long k = 0; k < reps; k++) timed_call(m, eval_only, q, v, Kx, rhs, phi, phid, work, lw, x);
    t[r] = (now() - t0) / (double)reps * 1e6;
  }
  qsort(t, 31, sizeof t[0], by_value);
  printf("%.3f %.3f\n", t[15], t[0]);
  return 0;
}
