/* bench.c: `mbcc bench`: the same simulation through every path (generated
 * and generic evaluation x ldl, klu, dense; SUNDIALS IDA), timed as medians
 * over repetitions interleaved round after round, with set-up timed apart
 * from the steps, and the trajectories compared against the first path. */
#define _POSIX_C_SOURCE 199309L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "mb_bench.h"
#include "mb_driver.h"
#include "mb_ida.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

enum { EVAL_GENERATED, EVAL_GENERIC, EVAL_IDA, EVAL_IDA_KLU };
#define IS_IDA(e) ((e) == EVAL_IDA || (e) == EVAL_IDA_KLU)

typedef struct {
  const char *name;    /* as in the table and the CSV: generated+ldl, ..., ida */
  int eval;            /* EVAL_* */
  const char *solver;  /* mb_solver_new name; NULL for IDA (generated eval) */
} path_def;

static const path_def PATHS[] = {
    {"generated+ldl", EVAL_GENERATED, "ldl"},  {"generated+klu", EVAL_GENERATED, "klu"},
    {"generated+dense", EVAL_GENERATED, "dense"}, {"generic+klu", EVAL_GENERIC, "generic-klu"},
    {"generic+dense", EVAL_GENERIC, "generic-dense"},  {"ida", EVAL_IDA, NULL},
    {"ida+klu", EVAL_IDA_KLU, NULL},
};
#define NPATH ((int)(sizeof PATHS / sizeof PATHS[0]))

/* the outputs at every output time, kept in one preallocated block */
typedef struct {
  const mb_model *m;
  int cap, nrows;
  double *y;           /* cap x ncols */
  void *work;
} recorder;

static int record(void *user, double t, const double *q, const double *v, const double *vd,
                  const double *lambda) {
  recorder *r = user;
  (void)t;
  if (r->nrows >= r->cap) return 0; /* more outputs than expected: keep the first cap */
  int nc = r->m->ncols;
  double *row = r->y + (size_t)r->nrows * (size_t)nc;
  mb_model_outputs(r->m, t, q, v, vd, lambda, r->nrows ? row - nc : NULL, row, r->work);
  r->nrows++;
  return 0;
}

typedef struct {
  int state;           /* 0 not selected, 1 ran, 2 skipped, 3 failed */
  char note[200];
  int n, nnz;          /* system dimension and nnz of its matrix */
  double step_med, run_med, setup_med;
  long steps, evals;
  double *walls, *setups, *per; /* per repetition: whole run, its set-up, (run - set-up) / steps */
  double residual;     /* ldl: largest relative residual of a solve after refinement */
  double max_rel;      /* against the reference path, every output */
  int worst_col;
  double max_rel_pos;  /* the same over the position outputs only (is_position_col) */
  int worst_col_pos;
  recorder rec;
} path_result;

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *a, int n) {
  qsort(a, (size_t)n, sizeof *a, cmp_double);
  return n % 2 ? a[n / 2] : 0.5 * (a[n / 2 - 1] + a[n / 2]);
}

/* one run of path p: its wall time, the part of it spent setting up (solver
 * creation, symbolic analysis, initial state: not in the per-step figure),
 * steps and the recorded outputs */
static int run_once(const path_def *p, const mb_model *m, const mb_settings *set, double ida_rtol,
                    recorder *rec,
                    double *wall, double *setup, long *steps, long *evals, double *residual, double *fail_time,
                    char *detail, size_t ndetail) {
  rec->nrows = 0;
  detail[0] = 0;
  int st;
  double t0 = now();
  if (p->eval == EVAL_IDA || p->eval == EVAL_IDA_KLU) {
    mb_stats stats;
    mb_settings ida_set = *set;
    if (ida_rtol > 0) { /* tighter (or looser) BDF tolerances, atol scaled alike */
      ida_set.atol = set->atol * ida_rtol / set->rtol;
      ida_set.rtol = ida_rtol;
    }
    st = mb_ida_run(m, &ida_set, p->eval == EVAL_IDA_KLU ? MB_IDA_KLU : MB_IDA_DENSE, record, rec, &stats,
                    fail_time);
    *wall = now() - t0;
    *setup = stats.t_setup;
    *steps = stats.steps;
    *evals = stats.evals;
    if (st) snprintf(detail, ndetail, "%s", mb_status_text(st));
    return st;
  }
  mb_solver *ls = mb_solver_new(p->solver, m);
  if (!ls) return -1;
  mb_sim sim;
  st = mb_sim_init(&sim, m, ls, set);
  *setup = now() - t0;
  if (!st) st = mb_sim_run(&sim, record, rec);
  *wall = now() - t0;
  *steps = sim.stats.steps;
  *evals = sim.stats.evals;
  *fail_time = sim.fail_time;
  *residual = ls->residual_max;
  if (st) snprintf(detail, ndetail, "%s", sim.fail_detail[0] ? sim.fail_detail : mb_status_text(st));
  mb_sim_free(&sim);
  ls->destroy(ls);
  return st;
}

/* the range of column j of the reference over the run; the columns of one vector output
 * ("name.x", "name.y", ...) share the largest of their ranges, so that a component
 * that stays at round-off level (a planar mechanism's out-of-plane force) is measured
 * against its vector's scale */
static double col_scale(const mb_model *m, const recorder *ref, int j) {
  const char *nj = m->col_name[j], *dj = strrchr(nj, '.');
  size_t len = dj ? (size_t)(dj - nj) : strlen(nj);
  double range = 0, big = 0;
  for (int c = 0; c < m->ncols; c++) {
    const char *nc = m->col_name[c], *dc = strrchr(nc, '.');
    if (c != j && !(dj && dc && (size_t)(dc - nc) == len && !strncmp(nc, nj, len))) continue;
    double lo = INFINITY, hi = -INFINITY;
    for (int k = 0; k < ref->nrows; k++) {
      double x = ref->y[(size_t)k * (size_t)m->ncols + (size_t)c];
      lo = fmin(lo, x);
      hi = fmax(hi, x);
      big = fmax(big, fabs(x));
    }
    if (hi > lo) range = fmax(range, hi - lo);
  }
  return range > 0 ? range : big > 0 ? big : 1;
}

/* column j belongs to a configuration output: a position, orientation, angle,
 * deflection, modal coordinate, joint coordinate, relative displacement or centre
 * of mass position (the quantities the agreement target is stated on) */
static int is_position_col(const mb_model *m, int j) {
  for (int o = 0; o < m->noutput; o++) {
    const mb_outputdef *d = &m->output[o];
    if (j >= d->col && j < d->col + d->ncols)
      return d->kind == MB_OUT_POSITION || d->kind == MB_OUT_ORIENTATION ||
             d->kind == MB_OUT_ANGLE || d->kind == MB_OUT_DEFLECTION || d->kind == MB_OUT_MODAL ||
             d->kind == MB_OUT_JOINT ||
             ((d->kind == MB_OUT_RELATIVE || d->kind == MB_OUT_CENTER_OF_MASS) &&
              d->quantity == MB_QUANTITY_POSITION);
  }
  return 0;
}

/* max over columns (only position columns when positions_only) and output times of
 * |a - ref| / col_scale */
static double compare(const mb_model *m, const recorder *ref, const recorder *a, int positions_only,
                      int *worst) {
  int nc = m->ncols, nr = ref->nrows < a->nrows ? ref->nrows : a->nrows;
  double mx = 0;
  *worst = -1;
  for (int j = 0; j < nc; j++) {
    if (positions_only && !is_position_col(m, j)) continue;
    double scale = col_scale(m, ref, j);
    for (int k = 0; k < nr; k++) {
      double d = fabs(a->y[(size_t)k * (size_t)nc + (size_t)j] - ref->y[(size_t)k * (size_t)nc + (size_t)j]) / scale;
      if (!(d <= mx)) { mx = isfinite(d) ? d : INFINITY; *worst = j; }
    }
  }
  return mx;
}

static void usage(const char *prog) {
  fprintf(stderr,
          "usage: %s [--reps N] [--csv FILE] [--paths a,b,...] [--quiet] [--ida-rtol R]\n"
          "          [--integrator rk4|dopri5] [--stabilization projection|baumgarte|none]\n"
          "          [--end T] [--output-step H] [--step H] [--rtol R] [--atol A]\n"
          "paths: generated+ldl generated+klu generated+dense generic+klu generic+dense ida ida+klu\n",
          prog);
}

static int selected(const char *list, const char *name) {
  if (!list) return 1;
  size_t n = strlen(name);
  for (const char *s = list; *s;) {
    const char *e = strchr(s, ',');
    size_t len = e ? (size_t)(e - s) : strlen(s);
    if (len == n && !strncmp(s, name, n)) return 1;
    if (!e) break;
    s = e + 1;
  }
  return 0;
}

static void fmt_long(char *buf, size_t n, long v) {
  if (v < 0) snprintf(buf, n, "-");
  else snprintf(buf, n, "%ld", v);
}

int mb_bench_main(int argc, char **argv, const mb_model *m, const mb_settings *defaults) {
  mb_settings set = *defaults;
  set.timers = 0; /* every path is timed as a whole run: no clock inside the steps */
  const char *csv_path = NULL, *paths = NULL;
  int reps = 5, quiet = 0;
  double ida_rtol = 0; /* --ida-rtol: 0 = the model's rtol */
  long nnz_l = m->ldl_factor ? m->ldl_nnzL : -1; /* the emitted LDL^T's fill */
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *val = (i + 1 < argc) ? argv[i + 1] : NULL;
    if (!strcmp(a, "--quiet")) { quiet = 1; continue; }
    if (!val) { usage(argv[0]); return 2; }
    i++;
    if (!strcmp(a, "--csv")) csv_path = val;
    else if (!strcmp(a, "--paths")) {
      paths = val;
      for (const char *s = val; *s;) {
        const char *e = strchr(s, ',');
        size_t len = e ? (size_t)(e - s) : strlen(s);
        int known = 0;
        for (int p = 0; p < NPATH; p++)
          known |= strlen(PATHS[p].name) == len && !strncmp(PATHS[p].name, s, len);
        if (!known) {
          fprintf(stderr, "%s: error: unknown path '%.*s'\n", argv[0], (int)len, s);
          usage(argv[0]);
          return 2;
        }
        if (!e) break;
        s = e + 1;
      }
    } else if (!strcmp(a, "--ida-rtol")) {
      char *end;
      ida_rtol = strtod(val, &end);
      if (*end || !(ida_rtol > 0) || !(ida_rtol < 1)) {
        fprintf(stderr, "%s: error: '--ida-rtol' needs a number between 0 and 1\n", argv[0]);
        return 2;
      }
    } else if (!strcmp(a, "--reps")) {
      char *end;
      double x = strtod(val, &end);
      if (*end || !(x >= 1) || x != floor(x) || x > 1000) {
        fprintf(stderr, "%s: error: '--reps' needs a whole number from 1 to 1000\n", argv[0]);
        return 2;
      }
      reps = (int)x;
    } else {
      int k = mb_settings_option(&set, a, val, argv[0]);
      if (k < 0) return 2;
      if (k == 0) { fprintf(stderr, "%s: error: unknown option '%s'\n", argv[0], a); usage(argv[0]); return 2; }
    }
  }
  if (set.output_step > set.end_time) set.output_step = set.end_time;
  if (set.max_step > set.output_step) set.max_step = set.output_step;

  /* the generic path: the same tables walked at run time, every element block
     into triplets, assembled and factorized by a general sparse (or dense) solver */
  mb_model generic = *m;
  generic.eval = mb_generic_triplet_eval;
  generic.init = mb_generic_triplet_init;
  long nout = (long)floor(set.end_time / set.output_step + 1e-9) + 1;
  path_result res[NPATH];
  memset(res, 0, sizeof res);
  int rc = 0, ref = -1;

  /* set-up: the paths that can run, their recorders and timing slots */
  for (int p = 0; p < NPATH; p++) {
    const path_def *pd = &PATHS[p];
    path_result *r = &res[p];
    if (!selected(paths, pd->name)) continue;
    const mb_model *pm = pd->eval == EVAL_GENERIC ? &generic : m;
    r->n = IS_IDA(pd->eval) ? mb_ida_size(m) : m->n;
    r->nnz = pd->eval == EVAL_IDA ? r->n * r->n : pd->eval == EVAL_IDA_KLU ? mb_ida_klu_nnz(m) : m->nnz;
    if (pd->solver) {
      mb_solver *probe = mb_solver_new(pd->solver, pm);
      if (!probe) {
        r->state = 2;
        snprintf(r->note, sizeof r->note, "skipped: solver '%s' is not available in this runtime", pd->solver);
        if (!quiet) fprintf(stderr, "bench: %-16s %s\n", pd->name, r->note);
        continue;
      }
      probe->destroy(probe);
    }
    r->rec.m = m;
    r->rec.cap = (int)nout + 1;
    r->rec.y = malloc(sizeof(double) * (size_t)r->rec.cap * (size_t)(m->ncols + 1));
    r->rec.work = malloc(mb_model_worksize(m) + 16);
    r->walls = malloc(sizeof(double) * (size_t)reps);
    r->setups = malloc(sizeof(double) * (size_t)reps);
    r->per = malloc(sizeof(double) * (size_t)reps);
    if (!r->rec.y || !r->rec.work || !r->walls || !r->setups || !r->per) {
      r->state = 3; snprintf(r->note, sizeof r->note, "out of memory"); rc = 1; continue;
    }
    r->state = 1;
  }

  /* the repetitions interleaved, round after round (each round starting one
     path later), so that a machine's changing load falls on every path alike
     rather than on whichever ran during it */
  int order[NPATH], nrun = 0;
  for (int p = 0; p < NPATH; p++)
    if (res[p].state == 1) order[nrun++] = p;
  for (int k = 0; k < reps; k++) {
    if (!quiet) fprintf(stderr, "bench: round %d/%d:", k + 1, reps);
    for (int i = 0; i < nrun; i++) {
      int p = order[(i + k) % nrun];
      const path_def *pd = &PATHS[p];
      path_result *r = &res[p];
      if (r->state != 1) continue;
      const mb_model *pm = pd->eval == EVAL_GENERIC ? &generic : m;
      double ft = 0;
      char detail[160];
      int st = run_once(pd, pm, &set, ida_rtol, &r->rec, &r->walls[k], &r->setups[k], &r->steps, &r->evals,
                        &r->residual, &ft, detail, sizeof detail);
      if (st) {
        r->state = 3;
        snprintf(r->note, sizeof r->note, "failed at t = %.6g: %s", ft, detail);
        rc = 1;
        if (!quiet) fprintf(stderr, " %s %s", pd->name, r->note);
        continue;
      }
      double stepping = r->walls[k] - r->setups[k];
      r->per[k] = r->steps > 0 ? stepping / (double)r->steps : stepping;
      if (!quiet) fprintf(stderr, " %s %.3gs", pd->name, r->walls[k]);
    }
    if (!quiet) fprintf(stderr, "\n");
  }

  for (int p = 0; p < NPATH; p++) {
    path_result *r = &res[p];
    if (r->state != 1) continue;
    r->run_med = median(r->walls, reps);
    r->setup_med = median(r->setups, reps);
    r->step_med = median(r->per, reps);
    if (ref < 0) ref = p;
    r->max_rel = compare(m, &res[ref].rec, &r->rec, 0, &r->worst_col);
    r->max_rel_pos = compare(m, &res[ref].rec, &r->rec, 1, &r->worst_col_pos);
    if (r->rec.nrows != res[ref].rec.nrows)
      snprintf(r->note, sizeof r->note, "%d output rows, reference %d", r->rec.nrows, res[ref].rec.nrows);
    else if (r->residual > 0)
      snprintf(r->note, sizeof r->note, "solve residual <= %.1e", r->residual);
  }

  /* run ratios against the fastest run; per-step ratios against the fastest step of the
     paths that share the integrator (IDA's BDF steps are other steps) */
  double best_run = INFINITY, best_step = INFINITY, best_step_all = INFINITY;
  for (int p = 0; p < NPATH; p++)
    if (res[p].state == 1) {
      best_run = fmin(best_run, res[p].run_med);
      best_step_all = fmin(best_step_all, res[p].step_med);
      if (!IS_IDA(PATHS[p].eval)) best_step = fmin(best_step, res[p].step_med);
    }
  if (!isfinite(best_step)) best_step = best_step_all;

  char nl[32];
  fmt_long(nl, sizeof nl, nnz_l);
  printf("model %s: n = %d, nnz(K) = %d, nnz(L) = %s; nq = %d, nv = %d, nc = %d\n", m->name, m->n,
         m->nnz, nl, m->nq, m->nv, m->nc);
  printf("%s, rtol %g, atol %g, t = 0 .. %g, output step %g, %s; medians of %d run%s\n",
         set.integrator == MB_RK4 ? "rk4" : "dopri5", set.rtol, set.atol, set.end_time,
         set.output_step,
         set.stabilization == MB_STAB_PROJECTION ? "projection"
         : set.stabilization == MB_STAB_BAUMGARTE ? "baumgarte" : "no stabilization",
         reps, reps == 1 ? "" : "s");
  if (ida_rtol > 0 && selected(paths, "ida"))
    printf("ida: rtol %g, atol %g (--ida-rtol)\n", ida_rtol, set.atol * ida_rtol / set.rtol);
  printf("\n%-16s %5s %7s %7s %8s %13s %10s %10s %7s %7s %12s %10s\n", "path", "n", "nnz(K)", "nnz(L)",
         "steps", "per step [s]", "run [s]", "set-up [s]", "ratio", "r.step", "max rel diff", "positions");
  for (int p = 0; p < NPATH; p++) {
    const path_result *r = &res[p];
    if (!r->state) continue;
    if (r->state != 1) { printf("%-16s %5d %7d %7s  %s\n", PATHS[p].name, r->n, r->nnz, "-", r->note); continue; }
    printf("%-16s %5d %7d %7s %8ld %13.4g %10.4g %10.3g %7.2f %7.2f %12.3g %10.3g", PATHS[p].name, r->n,
           r->nnz, IS_IDA(PATHS[p].eval) ? "-" : nl, r->steps, r->step_med, r->run_med, r->setup_med,
           r->run_med / best_run, r->step_med / best_step, r->max_rel, r->max_rel_pos);
    if (p == ref) printf("  (reference)");
    else if (r->worst_col >= 0 && r->max_rel > 0) {
      printf("  (%s", m->col_name[r->worst_col]);
      if (r->worst_col_pos >= 0 && r->worst_col_pos != r->worst_col && r->max_rel_pos > 0)
        printf("; positions: %s", m->col_name[r->worst_col_pos]);
      printf(")");
    }
    if (r->note[0]) printf("  %s", r->note);
    printf("\n");
  }
  printf("\nrepetitions interleaved, round after round.  run: whole-run time (medians over the\n"
         "repetitions); set-up: its part before the first step (solver, symbolic analysis, initial\n"
         "state), left out of per step = (run - set-up) / steps.\n"
         "ratio: whole-run time / the fastest path's; r.step: per-step time / the fastest per-step\n"
         "time of the paths that use %s.\n"
         "max rel diff: largest |difference| from the reference path over all outputs and output\n"
         "times, relative to the range of that output over the run (for a vector output, the largest\n"
         "range of its components).  positions: the same over the position, orientation, angle,\n"
         "deflection and modal outputs only.  ida: the DAE in y = [q; v; lambda] (n = nq + nv + nc), dense\n"
         "Jacobian by difference quotients, generated eval; its BDF steps are not %s steps.\n"
         "ida+klu: the same DAE with KLU on a sparse Jacobian from the emitted K and the exact\n"
         "rate and modal terms (nnz(K): the Jacobian's pattern).\n",
         set.integrator == MB_RK4 ? "rk4" : "dopri5", set.integrator == MB_RK4 ? "rk4" : "dopri5");

  if (csv_path) {
    char tmp[4096];
    snprintf(tmp, sizeof tmp, "%s.part", csv_path);
    FILE *f = fopen(tmp, "w");
    if (!f) { fprintf(stderr, "%s: error: cannot write '%s'\n", argv[0], tmp); rc = 2; goto out; }
    fprintf(f, "path,n,nnz_K,nnz_L,step_median_s,run_s,ratio,steps,max_rel_diff,step_ratio,status,max_rel_diff_positions,worst_output,worst_output_positions,setup_s\n");
    for (int p = 0; p < NPATH; p++) {
      const path_result *r = &res[p];
      if (!r->state) continue;
      const char *l = IS_IDA(PATHS[p].eval) ? "-" : nl;
      if (r->state == 1)
        fprintf(f, "%s,%d,%d,%s,%.6g,%.6g,%.4f,%ld,%.3g,%.4f,ok,%.3g,%s,%s,%.6g\n", PATHS[p].name, r->n,
                r->nnz, l, r->step_med, r->run_med, r->run_med / best_run, r->steps, r->max_rel,
                r->step_med / best_step, r->max_rel_pos,
                r->worst_col >= 0 && r->max_rel > 0 ? m->col_name[r->worst_col] : "",
                r->worst_col_pos >= 0 && r->max_rel_pos > 0 ? m->col_name[r->worst_col_pos] : "",
                r->setup_med);
      else
        fprintf(f, "%s,%d,%d,%s,,,,,,,%s,,,,\n", PATHS[p].name, r->n, r->nnz, l,
                r->state == 2 ? "skipped" : "failed");
    }
    if (fclose(f) || rename(tmp, csv_path)) {
      remove(tmp);
      fprintf(stderr, "%s: error: cannot write '%s'\n", argv[0], csv_path);
      rc = 2;
    } else if (!quiet) {
      printf("wrote %s\n", csv_path);
    }
  }
out:
  for (int p = 0; p < NPATH; p++) {
    free(res[p].rec.y); free(res[p].rec.work);
    free(res[p].walls); free(res[p].setups); free(res[p].per);
  }
  return rc;
}
