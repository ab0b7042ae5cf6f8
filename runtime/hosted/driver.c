/* driver.c: the simulator's command line: options, progress on stderr,
 * CSV output, and the closing statistics. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <sys/stat.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>
#include "mb_driver.h"

typedef struct {
  const mb_model *m;
  FILE *csv;
  mb_real *out, *angle_ref; /* angle_ref: unwrapped angles, radians (mb_model_track_angles) */
  int have_ref;
  int write_failed;         /* a write to the CSV failed (e.g. a full disk) */
  void *work;
  double end_time, last_report, wall0;
  int progress;
  int nonfinite;   /* 1 + the output column that was not finite, or 0 */
  int digits;      /* significant digits of the values (--precision) */
} writer;

static double wall(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int write_row(void *user, double t, const mb_real *q, const mb_real *v, const mb_real *vd,
                     const mb_real *lambda) {
  writer *w = user;
  const mb_model *m = w->m;
  mb_model_outputs(m, t, q, v, vd, lambda, w->have_ref ? w->angle_ref : NULL, w->out, w->work);
  for (int j = 0; j < m->ncols; j++)
    if (!isfinite(w->out[j])) { w->nonfinite = j + 1; return 1; } /* never print NaN as data */
  int bad = fprintf(w->csv, "%.*g", w->digits > 10 ? w->digits : 10, t) < 0;
  for (int j = 0; j < m->ncols; j++) bad |= fprintf(w->csv, ",%.*g", w->digits, (double)w->out[j]) < 0;
  bad |= fputc('\n', w->csv) == EOF;
  if (bad) { w->write_failed = errno ? errno : EIO; return 1; }
  mb_model_track_angles(m, q, v, w->angle_ref, w->have_ref, w->work);
  w->have_ref = 1;
  double now = wall();
  if (w->progress && now - w->wall0 > 1.0 && now - w->last_report > 0.5) {
    fprintf(stderr, "\r  t = %.6g / %.6g (%3.0f%%)", t, w->end_time, 100 * t / w->end_time);
    w->last_report = now;
  }
  return 0;
}

/* after every accepted step: angles unwrapped however far apart the rows are */
static void track_angles(void *user, double t, const mb_real *q, const mb_real *v) {
  writer *w = user;
  (void)t;
  mb_model_track_angles(w->m, q, v, w->angle_ref, w->have_ref, w->work);
  w->have_ref = 1;
}

/* the temporary CSV, removed if the simulator is interrupted or killed by a signal */
static char partial_csv[4200];
static void remove_partial_and_die(int sig) {
  if (partial_csv[0]) unlink(partial_csv);
  signal(sig, SIG_DFL);
  raise(sig);
}

/* The largest number of output rows a run may write (1e7, about a gigabyte of
 * CSV): more is refused before the run starts.  MB_MAX_ROWS lifts it. */
static double max_rows(void) {
  const char *e = getenv("MB_MAX_ROWS");
  double x = e && *e ? strtod(e, NULL) : 0;
  return x > 0 ? x : 1e7;
}

const char *mb_lapack_context;

#ifndef MB_REAL_FLOAT
/* LAPACK reports an illegal argument (often a NaN or an overflowed size that
 * reached it) through xerbla_, whose reference version prints a line and
 * returns, leaving garbage results: this one stops with a located failure. */
void xerbla_(const char *routine, const int *info, size_t routine_len);
void xerbla_(const char *routine, const int *info, size_t routine_len) {
  int n = routine_len > 0 && routine_len < 32 ? (int)routine_len : 6;
  while (n > 0 && (routine[n - 1] == ' ' || routine[n - 1] == 0)) n--; /* Fortran pads with blanks */
  fprintf(stderr, "%s: error: LAPACK routine %.*s got an illegal value in argument %d (a value out of "
          "range reached it); stopped\n", mb_lapack_context ? mb_lapack_context : "runtime", n, routine,
          info ? *info : 0);
  fflush(stderr);
  exit(1);
}

void dgesvd_(const char *jobu, const char *jobvt, const int *m, const int *n, double *a,
             const int *lda, double *s, double *u, const int *ldu, double *vt, const int *ldvt,
             double *work, const int *lwork, int *info);

/* After a numerical failure: is the configuration where the run stopped a
 * singular one (dead point, change point, lock-up), or did the integration
 * blow up (the velocities by then)?  The singular values of
 * the constraint Jacobian D tell, at the state the failed factorization,
 * solve or projection was at (a stage or iterate inside the step), else at
 * the last accepted state.  Bands: below 1e-6 of the largest, singular to
 * round-off; below 1e-5, ill-conditioned enough that Newton's corrections
 * stall (generalized-alpha stops there, a few microseconds before the point);
 * a regular mechanism at its design pose measures 1e-3 to 1e-1 (the
 * flexible sports car, whose modal columns are small, 7e-4). */
static void diagnose_configuration(mb_sim *sim, const char *prog) {
  const mb_model *m = sim->m;
  int nc = m->nc, nv = m->nv;
  if (nc == 0) return;
  double *D = calloc((size_t)nc * (size_t)nv, sizeof(double));
  double *sv = calloc((size_t)(nc < nv ? nc : nv) + 1, sizeof(double));
  int lwork = 8 * (nc + nv) + 64;
  double *work = malloc(sizeof(double) * (size_t)lwork);
  if (!D || !sv || !work) { free(D); free(sv); free(work); return; }
  int at_failure = sim->fail_state;
  /* a stage that blew up holds no configuration to judge: the last accepted state then */
  for (int i = 0; at_failure && i < m->nq; i++) at_failure = isfinite(sim->fail_q[i]);
  for (int i = 0; at_failure && i < nv; i++) at_failure = isfinite(sim->fail_v[i]);
  /* velocities a million times the start's (or 1, m/s or rad/s) by the
     failure: the integration blew up (an explicit step too large for the
     stiffest mode or element, or a force growing without bound), and a
     singular D there says nothing about the mechanism */
  double v0 = 1, vnow = 0;
  for (int i = 0; i < nv; i++) v0 = fmax(v0, fabs((double)m->v0[i]));
  for (int i = 0; i < nv; i++) vnow = fmax(vnow, fabs((double)sim->v[i]));
  for (int i = 0; at_failure && i < nv; i++) vnow = fmax(vnow, fabs((double)sim->fail_v[i]));
  if (!(vnow <= 1e6 * v0)) {
    fprintf(stderr, "%s: note: by t = %.9g the velocities had grown to %.3g (the largest velocity coordinate; %.3g "
            "at the start): the integration blew up (a step too large for the stiffest mode or force element, "
            "or a force growing without bound), not a singular configuration\n",
            prog, at_failure ? sim->fail_state_t : sim->t, vnow, v0);
    free(D); free(sv); free(work);
    return;
  }
  double t = at_failure ? sim->fail_state_t : sim->t;
  m->eval(m, t, at_failure ? sim->fail_q : sim->q, at_failure ? sim->fail_v : sim->v, sim->Kx, sim->rhs, sim->phi,
          sim->nu, sim->work);
  for (int j = 0; j < nv; j++)
    for (int p = m->Kp[j]; p < m->Kp[j + 1]; p++)
      if (m->Ki[p] >= nv) D[(size_t)(m->Ki[p] - nv) + (size_t)nc * (size_t)j] = sim->Kx[p];
  int info = 0, one = 1, finite = 1;
  for (size_t i = 0; i < (size_t)nc * (size_t)nv; i++) finite &= isfinite(D[i]) != 0;
  if (!finite) { free(D); free(sv); free(work); return; } /* the error already says what is not finite */
  dgesvd_("N", "N", &nc, &nv, D, &nc, sv, NULL, &one, NULL, &one, work, &lwork, &info);
  int k = nc < nv ? nc : nv;
  const char *where = at_failure ? " (the state it failed at)" : " (the last accepted state)";
  if (info == 0 && sv[0] > 0) {
    double ratio = sv[k - 1] / sv[0];
    if (ratio < 1e-6)
      fprintf(stderr, "%s: note: at t = %.9g%s the constraint Jacobian is nearly singular (smallest/largest "
              "singular value %.2g): a singular configuration (dead point, change point or lock-up)\n",
              prog, t, where, ratio);
    else if (ratio < 1e-5)
      fprintf(stderr, "%s: note: at t = %.9g%s the constraint Jacobian is ill-conditioned (smallest/largest "
              "singular value %.2g): near a singular configuration (dead point, change point or lock-up)\n",
              prog, t, where, ratio);
    else
      fprintf(stderr, "%s: note: at t = %.9g%s the constraint Jacobian is regular (smallest/largest singular "
              "value %.2g)\n", prog, t, where, ratio);
  }
  free(D); free(sv); free(work);
}
#endif

/* the SI unit of output column k of o (o->col <= k < o->col + o->ncols) */
static const char *base_unit(const mb_outputdef *o, int k) {
  int first3 = k - o->col < 3; /* reaction, momentum: force/linear first, then moment */
  switch (o->kind) {
  case MB_OUT_POSITION: case MB_OUT_DEFLECTION: return "m";
  case MB_OUT_ORIENTATION: return "1";
  case MB_OUT_ANGLE: return "rad";
  case MB_OUT_VELOCITY: return "m/s";
  case MB_OUT_ANGULAR_VELOCITY: return "rad/s";
  case MB_OUT_ACCELERATION: return "m/s^2";
  case MB_OUT_ANGULAR_ACCELERATION: return "rad/s^2";
  case MB_OUT_REACTION: return first3 ? "N" : "N m";
  case MB_OUT_EFFORT: return o->driver_rotation ? "N m" : "N";
  case MB_OUT_KINETIC_ENERGY: case MB_OUT_POTENTIAL_ENERGY: case MB_OUT_TOTAL_ENERGY: return "J";
  case MB_OUT_MODAL: return "kg^(1/2) m"; /* mass-normalized modal coordinate */
  case MB_OUT_MOMENTUM: return first3 ? "kg m/s" : "kg m^2/s";
  case MB_OUT_TYRE: { /* Fx Fy Fz Mx My Mz slip slip_angle camber deflection */
    static const char *const unit[10] = {"N", "N", "N", "N m", "N m", "N m", "1", "rad", "rad", "m"};
    return unit[o->component >= 0 ? o->component : k - o->col];
  }
  case MB_OUT_FORCE: /* one column: fx..tz or the tension */
    if (o->ncols == 1) return o->component >= 3 && o->component < 6 ? "N m" : "N";
    return first3 ? "N" : "N m";
  case MB_OUT_RELATIVE: case MB_OUT_CENTER_OF_MASS:
    return o->quantity == MB_QUANTITY_POSITION ? "m" : o->quantity == MB_QUANTITY_VELOCITY ? "m/s" : "m/s^2";
  case MB_OUT_JOINT: return o->joint_dofs == 2 || k > o->col ? "m" : "rad";
  case MB_OUT_SECTION: /* N Vy Vz T My Mz, one of them, or a fiber's stress */
    if (o->component == 6) return "Pa";
    return (o->component >= 0 ? o->component < 3 : first3) ? "N" : "N m";
  }
  return "?"; /* not a kind: a corrupt table */
}

static mode_t current_umask(void) {
  mode_t u = umask(022);
  umask(u);
  return u;
}

/* CSV.units beside the results: "column,unit" and a row per CSV column; an
   output with a scale s is in units of 1/s of its SI unit ("0.001 m") */
static int write_units(const mb_model *m, const char *csv_path) {
  char path[4200], tmp[4300];
  snprintf(path, sizeof path, "%s.units", csv_path);
  /* a temporary name of this process's own, as for the CSV: concurrent runs
     of one model each rename a complete file into place */
  snprintf(tmp, sizeof tmp, "%s.XXXXXX", path);
  int fd = mkstemp(tmp);
  FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!f) {
    if (fd >= 0) { close(fd); unlink(tmp); }
    return -1;
  }
  fchmod(fd, 0644 & ~current_umask());
  fprintf(f, "column,unit\nt,s\n");
  for (int i = 0; i < m->noutput; i++) {
    const mb_outputdef *o = &m->output[i];
    for (int k = o->col; k < o->col + o->ncols; k++) {
      if (o->scale == 1) fprintf(f, "%s,%s\n", m->col_name[k], base_unit(o, k));
      else fprintf(f, "%s,%.6g %s\n", m->col_name[k], 1 / (double)o->scale, base_unit(o, k));
    }
  }
  if (fclose(f) || rename(tmp, path)) { remove(tmp); return -1; }
  return 0;
}

int mb_settings_option(mb_settings *set, const char *opt, const char *val, const char *prog) {
  if (!strcmp(opt, "--integrator")) {
    if (!strcmp(val, "rk4")) set->integrator = MB_RK4;
    else if (!strcmp(val, "dopri5")) set->integrator = MB_DOPRI5;
    else if (!strcmp(val, "genalpha")) set->integrator = MB_GENALPHA;
    else if (!strcmp(val, "auto")) set->integrator = MB_AUTO;
    else { fprintf(stderr, "%s: error: unknown integrator '%s' (expected rk4, dopri5, genalpha or auto)\n", prog, val); return -1; }
    return 1;
  }
  if (!strcmp(opt, "--stabilization")) {
    if (!strcmp(val, "projection")) set->stabilization = MB_STAB_PROJECTION;
    else if (!strcmp(val, "baumgarte")) set->stabilization = MB_STAB_BAUMGARTE;
    else if (!strcmp(val, "none")) set->stabilization = MB_STAB_NONE;
    else { fprintf(stderr, "%s: error: unknown stabilization '%s' (expected projection, baumgarte or none)\n", prog, val); return -1; }
    return 1;
  }
  static const char *const names[] = {"--end", "--output-step", "--step", "--rtol", "--atol", "--max-step", "--rho-inf", "--max-steps"};
  double *fields[] = {&set->end_time, &set->output_step, &set->step, &set->rtol, &set->atol, &set->max_step, &set->rho_inf, &set->max_steps};
  for (int k = 0; k < 8; k++) {
    if (strcmp(opt, names[k])) continue;
    char *end;
    double x = strtod(val, &end);
    if (k == 6 && !*end && x >= 0 && x <= 1) { *fields[k] = x; return 1; }
    if (k == 6) {
      fprintf(stderr, "%s: error: '--rho-inf' needs a number from 0 to 1, got '%s'\n", prog, val);
      return -1;
    }
    if (*end || !(x > 0) || !isfinite(x)) {
      fprintf(stderr, "%s: error: '%s' needs a positive number, got '%s'\n", prog, opt, val);
      return -1;
    }
    *fields[k] = x;
    return 1;
  }
  return 0;
}

static void usage(const char *prog) {
  fprintf(stderr,
          "usage: %s [-o results.csv] [--solver ldl|klu|dense] [--integrator rk4|dopri5|genalpha|auto]\n"
          "          [--end T] [--output-step H] [--step H] [--max-step H] [--rtol R] [--atol A]\n"
          "          [--rho-inf R] [--max-steps N]\n"
          "          [--stabilization projection|baumgarte|none] [--precision N] [--set NAME=VALUE]... [--quiet]\n"
          "          [--equilibrium]\n",
          prog);
}

/* After --set moved joint points or body positions: the model re-assembled
 * (mb_reassemble) into *assembled, a copy of m with its own initial state
 * (*q0, *v0: the caller frees them); 0, or 2 after reporting the parameters
 * and the cause */
static int reassemble_sets(const mb_model *m, const char *prog, int nsets, const char *const *sets,
                           const int *moved, mb_model *assembled, mb_real **q0, mb_real **v0) {
  *q0 = malloc(sizeof(mb_real) * ((size_t)m->nq + 1));
  *v0 = malloc(sizeof(mb_real) * ((size_t)m->nv + 1));
  char why[1024];
  if (!*q0 || !*v0) {
    fprintf(stderr, "%s: error: out of memory\n", prog);
    return 2;
  }
  if (mb_reassemble(m, *q0, *v0, why, sizeof why)) {
    fprintf(stderr, "%s: error: --set", prog);
    for (int i = 0; i < nsets; i++)
      if (moved[i]) fprintf(stderr, " %s", sets[i]);
    fprintf(stderr, " moves the assembly: %s; no results written\n", why);
    return 2;
  }
  *assembled = *m;
  assembled->q0 = *q0;
  assembled->v0 = *v0;
  return 0;
}

/* --set NAME=VALUE (each item of 'sets'): the model's run-time parameters
 * from their defaults, then set (m->set_params), and the model re-assembled
 * when they move its geometry (*m then points to *assembled, whose initial
 * state *q0, *v0 the caller frees); 0, or 2 after reporting */
static int apply_sets(const mb_model **model, const char *prog, int nsets, const char *const *sets,
                      mb_model *assembled, mb_real **q0, mb_real **v0) {
  const mb_model *m = *model;
  int moved[64] = {0}, any_moved = 0;
  if (!nsets) return 0;
  if (!m->nparam) {
    fprintf(stderr, "%s: error: --set %s: the model has no run-time parameters ('runtime: true' in its "
            "'parameters:' makes one)\n", prog, sets[0]);
    return 2;
  }
  mb_real *p = malloc((size_t)m->nparam * sizeof *p);
  if (!p) { fprintf(stderr, "%s: error: out of memory\n", prog); return 2; }
  memcpy(p, m->param_value, (size_t)m->nparam * sizeof *p);
  for (int i = 0; i < nsets; i++) {
    const char *eq = strchr(sets[i], '=');
    size_t length = eq ? (size_t)(eq - sets[i]) : strlen(sets[i]);
    int k = -1;
    for (int j = 0; j < m->nparam && k < 0; j++)
      if (strlen(m->param_name[j]) == length && !strncmp(m->param_name[j], sets[i], length)) k = j;
    if (k < 0 || !eq) {
      if (!eq)
        fprintf(stderr, "%s: error: --set needs NAME=VALUE, got '%s'\n", prog, sets[i]);
      else {
        fprintf(stderr, "%s: error: --set %s: no run-time parameter '%.*s' (the model's are:", prog, sets[i],
                (int)length, sets[i]);
        for (int j = 0; j < m->nparam; j++) fprintf(stderr, " %s", m->param_name[j]);
        fputs(")\n", stderr);
      }
      free(p);
      return 2;
    }
    char *end;
    errno = 0;
    double v = strtod(eq + 1, &end);
    if (end == eq + 1 || *end || !isfinite(v)) {
      fprintf(stderr, "%s: error: --set %s: the value must be a finite number\n", prog, sets[i]);
      free(p);
      return 2;
    }
    if (fabs(v) > 1e30) { /* the compiler's bound on a number in the model file (LIMIT_MAGNITUDE) */
      fprintf(stderr, "%s: error: --set %s: %g is beyond the limit 1e+30 on the size of a number\n", prog, sets[i], v);
      free(p);
      return 2;
    }
    if (!(v >= (double)m->param_min[k] && v <= (double)m->param_max[k])) {
      fprintf(stderr, "%s: error: --set %s: outside the parameter's range [%g, %g]\n", prog, sets[i],
              (double)m->param_min[k], (double)m->param_max[k]);
      free(p);
      return 2;
    }
    p[k] = (mb_real)v;
    moved[i] = m->param_geometry && m->param_geometry[k];
    any_moved |= moved[i];
  }
  const char *broken = m->set_params(m, p);
  free(p);
  if (broken) {
    fprintf(stderr, "%s: error: --set", prog);
    for (int i = 0; i < nsets; i++) fprintf(stderr, " %s", sets[i]);
    fprintf(stderr, ": %s\n", broken);
    return 2;
  }
  if (!any_moved) return 0;
  if (reassemble_sets(m, prog, nsets, sets, moved, assembled, q0, v0)) return 2;
  *model = assembled;
  return 0;
}

int mb_main(int argc, char **argv, const mb_model *m, const mb_settings *defaults,
            const char *solver) {
  mb_settings set = *defaults;
  const char *csv_path = "results.csv";
  int output_given = 0, max_given = 0;
  int quiet = 0, digits = 12;
  const char *sets[64];
  int nsets = 0;
  for (int i = 1; i < argc; i++) {
    const char *a = argv[i], *val = (i + 1 < argc) ? argv[i + 1] : NULL;
    int takes = 1;
    if (!strcmp(a, "--quiet")) { quiet = 1; takes = 0; }
    else if (!strcmp(a, "--equilibrium")) { set.equilibrium = 1; takes = 0; }
    else if (!val) { usage(argv[0]); return 2; }
    else if (!strcmp(a, "-o")) csv_path = val;
    else if (!strcmp(a, "--solver")) solver = val;
    else if (!strcmp(a, "--set")) {
      if (nsets == 64) { fprintf(stderr, "%s: error: more than 64 --set options\n", argv[0]); return 2; }
      sets[nsets++] = val;
    }
    else if (!strcmp(a, "--precision")) {
      char *end;
      long d = strtol(val, &end, 10);
      if (*end || d < 1 || d > 17) {
        fprintf(stderr, "%s: error: '--precision' needs a number of digits from 1 to 17, got '%s'\n", argv[0], val);
        return 2;
      }
      digits = (int)d;
    }
    else {
      int k = mb_settings_option(&set, a, val, argv[0]);
      if (k < 0) return 2;
      if (k == 0) { usage(argv[0]); return 2; }
      if (!strcmp(a, "--output-step")) output_given = 1;
      if (!strcmp(a, "--max-step")) max_given = 1;
    }
    i += takes;
  }
#ifdef MB_REAL_FLOAT
  /* single precision resolves about 1e-7: a tighter tolerance only makes the
     step control chase round-off */
  if (set.rtol < 1e-5 && set.integrator != MB_RK4) {
    if (!quiet)
      fprintf(stderr, "%s: warning: rtol %g is below what single precision resolves; using 1e-5\n",
              argv[0], set.rtol);
    set.rtol = 1e-5;
  }
  /* ... and positions to about 4 ulp of the model's size: an absolute tolerance
     below that (it also bounds the modal amplitudes, which the constraints tie
     to the positions) cannot be met */
  double size = 1;
  for (int b = 0; b < m->nbody; b++)
    for (int j = 0; j < 3; j++) size = fmax(size, fabs((double)m->q0[m->body[b].qadr + j]));
  double atol_min = 4 * 1.1920929e-7 * size;
  if (set.atol < atol_min && set.integrator != MB_RK4) {
    if (!quiet)
      fprintf(stderr, "%s: warning: atol %g is below what single precision resolves for this model; "
              "using %.2g\n", argv[0], set.atol, atol_min);
    set.atol = atol_min;
  }
#endif
  if (set.output_step > set.end_time) set.output_step = set.end_time;
  (void)output_given; (void)max_given;
  /* finite but absurd time spans: refused, not truncated to a row or two */
  double rows = floor(set.end_time / set.output_step) + 1;
  if (!(rows <= max_rows())) {
    fprintf(stderr, "%s: error: end time %g with output step %g means %.3g output rows, more than the "
            "limit %.3g (choose a larger --output-step or a smaller --end; MB_MAX_ROWS=N lifts the limit)\n",
            argv[0], set.end_time, set.output_step, rows, max_rows());
    return 2;
  }
  if (set.end_time > 1e9 || set.end_time + set.output_step == set.end_time) {
    fprintf(stderr, "%s: error: end time %g s is beyond what the time steps resolve (at most 1e9 s)\n",
            argv[0], set.end_time);
    return 2;
  }

  mb_model assembled;           /* m re-assembled after --set moved its geometry */
  mb_real *assembled_q0 = NULL, *assembled_v0 = NULL;
  if (apply_sets(&m, argv[0], nsets, sets, &assembled, &assembled_q0, &assembled_v0)) {
    free(assembled_q0);
    free(assembled_v0);
    return 2;
  }
  mb_solver *ls = mb_solver_new(solver, m);
  if (!ls) {
    if (!strcmp(solver, "ldl"))
      fprintf(stderr, "%s: error: solver 'ldl' is the LDL^T emitted with generated code, which this "
              "model has not (expected %s)\n", argv[0], mb_solver_choices(m));
    else
      fprintf(stderr, "%s: error: unknown solver '%s' (expected %s)\n", argv[0], solver, mb_solver_choices(m));
    free(assembled_q0); free(assembled_v0);
    return 2;
  }
  /* write to a temporary file of this process's own (mkstemp: two runs of one
     model never share it) beside the result, renamed on success: nothing
     half-written, nothing mixed */
  char *tmp = partial_csv;
  snprintf(tmp, sizeof partial_csv, "%s.XXXXXX", csv_path);
  writer w = {0};
  w.m = m;
  int fd = mkstemp(tmp);
  w.csv = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!w.csv) {
    fprintf(stderr, "%s: error: cannot write '%s': %s\n", argv[0], csv_path, strerror(errno));
    if (fd >= 0) { close(fd); unlink(tmp); }
    tmp[0] = 0;
    ls->destroy(ls);
    free(assembled_q0); free(assembled_v0);
    return 2;
  }
  fchmod(fd, 0644 & ~current_umask());
  signal(SIGINT, remove_partial_and_die);
  signal(SIGTERM, remove_partial_and_die);
  signal(SIGHUP, remove_partial_and_die);
  w.out = calloc((size_t)m->ncols + 1, sizeof(mb_real));
  w.angle_ref = calloc((size_t)m->ncols + 1, sizeof(mb_real));
  w.work = malloc(mb_model_worksize(m) + 16);
  w.end_time = set.end_time;
  w.wall0 = wall();
  w.progress = !quiet;
  w.digits = digits;
  fprintf(w.csv, "t");
  for (int j = 0; j < m->ncols; j++) fprintf(w.csv, ",%s", m->col_name[j]);
  fputc('\n', w.csv);

  if (set.integrator == MB_AUTO) {
    char why[320];
    set.integrator = mb_integrator_auto(m, &set, why, sizeof why);
    if (!quiet) fprintf(stderr, "%s: integrator auto: %s\n", argv[0], why);
  }
  if (set.integrator == MB_GENALPHA && !m->force_tslot && !quiet) {
    int nstiff = 0;
    for (int e = 0; e < m->nforce; e++)
      nstiff += m->force[e].kind == MB_FORCE_SPRING || m->force[e].kind == MB_FORCE_FIELD ||
                m->force[e].kind == MB_FORCE_TYRE;
    if (nstiff)
      fprintf(stderr, "%s: note: the model was compiled without its force elements' tangents "
                      "(its integrator is not genalpha or auto): generalized-alpha's Newton sees "
                      "only the masses and the modes, and stiff springs, bushings, beams or tyres force "
                      "small steps\n", argv[0]);
  }
  mb_sim sim;
  int st = mb_sim_init(&sim, m, ls, &set);
  sim.on_step = track_angles;
  sim.on_step_user = &w;
  int equilibrium_failed = 0;
  mb_model settled; /* the model whose initial state is the equilibrium */
  mb_real *settled_q0 = NULL, *settled_v0 = NULL;
  if (!st && set.equilibrium) {
    mb_equilibrium_info eq;
    st = mb_sim_equilibrium(&sim, &eq);
    if (st) {
      fprintf(stderr, "%s: error: static equilibrium: %s; no results written\n", argv[0], eq.why);
      equilibrium_failed = 1;
    } else if (!quiet) {
      fprintf(stderr, "%s: static equilibrium in %d Newton iterations: force residual %.3g of %.6g N "
              "(the weight or the largest applied force), constraint residual %.3g", argv[0],
              eq.iterations, eq.force_residual, eq.force_scale, eq.constraint_residual);
      if (eq.damped_steps > 0)
        fprintf(stderr, "; %d damped steps past a turning point", eq.damped_steps);
      if (eq.free_directions > 0)
        fprintf(stderr, "; %d free direction%s without load left as given", eq.free_directions,
                eq.free_directions > 1 ? "s" : "");
      fprintf(stderr, "\n");
    }
    /* relative displacements and joint outputs count from the equilibrium
       (docs/model-format.md), not from the assembled state */
    if (!st && (settled_q0 = malloc(sizeof(mb_real) * ((size_t)m->nq + 1))) &&
        (settled_v0 = malloc(sizeof(mb_real) * ((size_t)m->nv + 1)))) {
      memcpy(settled_q0, sim.q, sizeof(mb_real) * (size_t)m->nq);
      memcpy(settled_v0, sim.v, sizeof(mb_real) * (size_t)m->nv);
      settled = *m;
      settled.q0 = settled_q0;
      settled.v0 = settled_v0;
      w.m = &settled;
    } else if (!st) {
      st = MB_ERR_NOMEM;
    }
  }
  if (!st) st = mb_sim_run(&sim, write_row, &w);
  if (w.progress && wall() - w.wall0 > 1.0) fprintf(stderr, "\n");
  int nonfinite_output = !st && w.nonfinite;
  /* every byte on the disk before the rename, or an error */
  errno = 0;
  if (!w.write_failed && (fflush(w.csv) || ferror(w.csv) || fsync(fileno(w.csv))))
    w.write_failed = errno ? errno : EIO;
  if (fclose(w.csv) && !w.write_failed) w.write_failed = errno ? errno : EIO;
  int rc = 0;
  if (w.write_failed) {
    unlink(tmp);
    fprintf(stderr, "%s: error: cannot write '%s': %s; no results written\n", argv[0], csv_path,
            strerror(w.write_failed));
    rc = 2;
  } else if (equilibrium_failed) {
    unlink(tmp);
    rc = 1;
  } else if (st || nonfinite_output) {
    unlink(tmp);
    if (nonfinite_output)
      fprintf(stderr, "%s: error: at t = %.9g: output '%s' is not finite; no results written\n", argv[0],
              sim.t, m->col_name[w.nonfinite - 1]);
    else
      fprintf(stderr, "%s: error: at t = %.9g: %s; no results written\n", argv[0], sim.fail_time,
              sim.fail_detail[0] ? sim.fail_detail : mb_status_text(st));
#ifndef MB_REAL_FLOAT
    if (st != MB_ERR_STEP_BUDGET && st != MB_ERR_INVALID && st != MB_ERR_NOMEM && sim.q)
      diagnose_configuration(&sim, argv[0]);
#endif
    rc = 1;
  } else if (rename(tmp, csv_path)) {
    fprintf(stderr, "%s: error: cannot write '%s': %s\n", argv[0], csv_path, strerror(errno));
    unlink(tmp);
    rc = 2;
  } else if (write_units(m, csv_path)) {
    fprintf(stderr, "%s: error: cannot write '%s.units'\n", argv[0], csv_path);
    rc = 2;
  }
  tmp[0] = 0;
  if (!rc && !quiet) {
    const mb_stats *s = &sim.stats;
    printf("model %s: %d bodies, %d coordinates (q), %d velocities, %d constraint rows, n = %d, nnz(K) = %d\n",
           m->name, m->nbody, m->nq, m->nv, m->nc, m->n, m->nnz);
    printf("integrator %s, solver %s, stabilization %s, t = 0 .. %g\n",
           mb_integrator_name(set.integrator), ls->name,
           set.stabilization == MB_STAB_PROJECTION ? "projection"
           : set.stabilization == MB_STAB_BAUMGARTE ? "baumgarte" : "none", set.end_time);
    printf("steps %ld (rejected %ld), evaluations %ld, factorizations %ld (full %ld), solves %ld, projections %ld\n",
           s->steps, s->rejected, s->evals, s->factorizations, s->full_factorizations, s->solves,
           s->projections);
    printf("time %.3f s: assembly %.3f s, factor+solve %.3f s, other %.3f s\n", s->t_total,
           s->t_assembly, s->t_solve, s->t_total - s->t_assembly - s->t_solve);
    if (set.integrator == MB_GENALPHA)
      printf("Newton iterations %ld (%.2f per step), Newton failures %ld, rho_inf %g\n",
             s->newton_iterations, s->steps ? (double)s->newton_iterations / (double)s->steps : 0.0,
             s->newton_failures, set.rho_inf);
    printf("max |phi| at outputs %.3g\n", s->max_phi);
    if (s->rcond_first > 0 && s->rcond_min < 1e-6 * s->rcond_first)
      fprintf(stderr, "%s: warning: near t = %.9g the condition estimate of K fell to %.2g (%.2g at the "
              "start): the run passed close to a singular configuration; check the results there\n",
              argv[0], s->rcond_min_t, s->rcond_min, s->rcond_first);
    if (!strcmp(ls->name, "ldl"))
      printf("ldl residual after refinement (checked on %ld of %ld solves%s): last %.3g, largest %.3g; "
             "single pass: largest %.3g\n", ls->residual_checks, ls->solves,
             ls->refine_always ? ", refined on every solve" : "", ls->residual, ls->residual_max,
             ls->residual_pass_max);
    printf("wrote %s (%d columns)\n", csv_path, m->ncols + 1);
  }
  mb_sim_free(&sim);
  ls->destroy(ls);
  free(w.out); free(w.angle_ref); free(w.work); free(settled_q0); free(settled_v0);
  free(assembled_q0); free(assembled_v0);
  return rc;
}
