/* trade.c: `mbcc trade`: what each unit of speed costs in accuracy for one model:
 * a reference solution checked against a stricter one, then a sweep of the
 * settings that trade speed for accuracy (integrator and step or tolerance,
 * modes, coupling, joints direct or virtual, solver, float or double), each run
 * timed (median CPU time) and compared with the reference; a table with the
 * Pareto front, CSV, a log-log plot, and the cheapest run meeting an error
 * target.  The method is described in docs/trade.md. */
#define _DEFAULT_SOURCE
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <unistd.h>

#include "diag.h"
#include "emit.h"
#include "outfile.h"
#include "unit.h"
#include "trade.h"
#include "trade_metric.h"

#ifndef MBCC_RTLIB
#define MBCC_RTLIB "build/libmbrt.a"
#endif

enum { MAXV = 24, MAXI = 24, MAXS = 4, MAXRUN = MAXV * MAXI * MAXS, MAXCOL = 256 };

/* one integrator setting: rk4 with a step, or an adaptive one with a tolerance */
typedef struct {
  char name[16];   /* rk4, dopri5, genalpha, ... (passed to --integrator as is) */
  double value;    /* rk4: the step; otherwise rtol (atol = rtol / 100) */
} integ_setting;

/* one structural variant: its own generated code and simulator */
typedef struct {
  char label[48];     /* base, modes-8, cutoff-1000Hz, coupling-rigid, joints-virtual, real-float, reference */
  int modes;          /* -2: as in the model, -1: all, >= 0: count (per flexible body) */
  double cutoff;      /* > 0: modes up to this frequency, Hz */
  int coupling;       /* -1: as in the model, else ir_coupling */
  int joints;         /* -1: as in the model, 0 direct, 1 virtual */
  int real_float;
  /* after building */
  int ok;
  char why[300];      /* why it could not be built */
  char exe[4400];
  int nmodes;         /* total modes of the flexible bodies */
  char coupling_name[16], joints_name[16];
} variant;

typedef struct {
  int v, i;            /* variant, integrator setting */
  const char *solver;
  double cpu;          /* median CPU seconds */
  trade_error err;
  int failed, pareto;
  char why[200];
} trade_run;

typedef struct {
  const char *model, *scene, *outputs, *csv, *plot, *workdir;
  double max_error[8], end, ref_rtol, output_step;
  int nmax_error, reps, quiet;
  char integrators[512], modes[256], couplings[128], joints[64], solvers[64], reals[64];
} trade_options;

/* the outputs of one run as read back from its CSV */
typedef struct {
  int nrows, ncols;
  char *names[MAXCOL];
  double *t, *y;       /* nrows; nrows x ncols */
} table;

/* snprintf where truncating a long path or message is acceptable */
static void textf(char *buf, size_t n, const char *fmt, ...) DIAG_PRINTF(3, 4);
static void textf(char *buf, size_t n, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, n, fmt, ap);
  va_end(ap);
}

static const char *const COUPLING_NAMES[] = {"full", "partial", "constant", "rigid"};

static void table_free(table *tb) {
  for (int c = 0; c < tb->ncols; c++) free(tb->names[c]);
  free(tb->t);
  free(tb->y);
  memset(tb, 0, sizeof *tb);
}

/* read a simulator CSV (header "t,a,b,..."); 0 or -1 */
static int read_table(const char *path, table *tb) {
  memset(tb, 0, sizeof *tb);
  FILE *f = fopen(path, "r");
  if (!f) return -1;
  size_t cap = 1 << 16;
  char *line = malloc(cap);
  int rc = -1, rows_cap = 0;
  if (!line || !fgets(line, (int)cap, f)) goto done;
  line[strcspn(line, "\r\n")] = 0;
  char *save = NULL;
  char *tok = strtok_r(line, ",", &save);
  if (!tok || strcmp(tok, "t")) goto done;
  while ((tok = strtok_r(NULL, ",", &save)) && tb->ncols < MAXCOL) tb->names[tb->ncols++] = strdup(tok);
  while (fgets(line, (int)cap, f)) {
    if (tb->nrows == rows_cap) {
      rows_cap = rows_cap ? 2 * rows_cap : 256;
      double *t = realloc(tb->t, sizeof(double) * (size_t)rows_cap);
      if (!t) goto done;
      tb->t = t;
      double *y = realloc(tb->y, sizeof(double) * (size_t)rows_cap * (size_t)(tb->ncols ? tb->ncols : 1));
      if (!y) goto done;
      tb->y = y;
    }
    char *p = line, *end;
    tb->t[tb->nrows] = strtod(p, &end);
    if (end == p) goto done;
    for (int c = 0; c < tb->ncols; c++) {
      if (*end != ',') goto done;
      p = end + 1;
      tb->y[(size_t)tb->nrows * (size_t)tb->ncols + (size_t)c] = strtod(p, &end);
      if (end == p) goto done;
    }
    tb->nrows++;
  }
  rc = 0;
done:
  free(line);
  fclose(f);
  if (rc) table_free(tb);
  return rc;
}

/* the chosen columns of tb (indices sel[0..nsel-1]) at its first nrows rows */
static double *pick_columns(const table *tb, const int *sel, int nsel, int nrows) {
  double *y = malloc(sizeof(double) * (size_t)(nrows ? nrows : 1) * (size_t)(nsel ? nsel : 1));
  if (!y) return NULL;
  for (int k = 0; k < nrows; k++)
    for (int c = 0; c < nsel; c++)
      y[(size_t)k * (size_t)nsel + (size_t)c] = tb->y[(size_t)k * (size_t)tb->ncols + (size_t)sel[c]];
  return y;
}

/* --- which outputs to compare ---------------------------------------------------- */

/* Without --outputs, compare only the outputs that vary: an output that is
 * constant, whose variation is round-off (below 1e-12 of the largest of its
 * output's columns), or that varies no more than the reference's own error
 * (a conserved quantity: total energy, momentum of a free system) measures
 * nothing but noise, and an error relative to its range is meaningless.
 * Says which it left out and why; -1 (after a message) when none is left. */
static int drop_flat_outputs(const table *ref, const table *strict, int *sel, char (*selnames)[128], int *nsel) {
  int kept = 0, nrows = ref->nrows < strict->nrows ? ref->nrows : strict->nrows;
  const char *cn[MAXCOL];
  int group[MAXCOL];
  double range[MAXCOL], big[MAXCOL], noise[MAXCOL];
  for (int c = 0; c < *nsel; c++) {
    cn[c] = selnames[c];
    double lo = INFINITY, hi = -INFINITY, mx = 0, dmax = 0;
    for (int k = 0; k < ref->nrows; k++) {
      double y = ref->y[(size_t)k * (size_t)ref->ncols + (size_t)sel[c]];
      if (y < lo) lo = y;
      if (y > hi) hi = y;
      if (fabs(y) > mx) mx = fabs(y);
    }
    for (int k = 0; k < nrows; k++) {
      double d = fabs(ref->y[(size_t)k * (size_t)ref->ncols + (size_t)sel[c]] -
                      strict->y[(size_t)k * (size_t)strict->ncols + (size_t)sel[c]]);
      if (d > dmax) dmax = d;
    }
    range[c] = ref->nrows ? hi - lo : 0;
    big[c] = mx;
    noise[c] = dmax;
  }
  trade_column_groups(cn, *nsel, group);
  static char left[MAXCOL][320];
  int nleft = 0;
  for (int c = 0; c < *nsel; c++) {
    double kin = big[c];
    for (int d = 0; d < *nsel; d++)
      if (group[d] == group[c] && big[d] > kin) kin = big[d];
    const char *why = NULL;
    char buf[160];
    if (range[c] == 0) why = "constant";
    else if (range[c] <= 1e-12 * kin) {
      snprintf(buf, sizeof buf, "varies %.2g, round-off of its scale %.2g", range[c], kin);
      why = buf;
    } else if (range[c] <= 10 * noise[c]) {
      snprintf(buf, sizeof buf, "conserved: varies %.2g, within 10x the reference's own error %.2g", range[c], noise[c]);
      why = buf;
    }
    if (why) {
      if (nleft < MAXCOL) snprintf(left[nleft++], sizeof left[0], "%.127s (%.180s)", selnames[c], why);
      continue;
    }
    sel[kept] = sel[c];
    if (kept != c) memcpy(selnames[kept], selnames[c], sizeof selnames[0]);
    kept++;
  }
  if (nleft) {
    printf("left out %d output%s that do%s not vary (name them with --outputs to compare them):\n", nleft,
           nleft > 1 ? "s" : "", nleft > 1 ? "" : "es");
    for (int i = 0; i < nleft; i++) printf("  %s\n", left[i]);
  }
  if (!kept) {
    fprintf(stderr, "mbcc: error: no output varies; name the outputs to compare with --outputs\n");
    return -1;
  }
  *nsel = kept;
  return 0;
}

/* --- options ------------------------------------------------------------------ */

static void trade_usage(void) {
  fprintf(stderr,
          "usage: mbcc trade M.yaml [--scene S] [--outputs a,b,...] [--max-error E[,E2,...]]\n"
          "                [--csv FILE] [--plot FILE.png|none] [--reps N] [--end T]\n"
          "                [--output-step H] [--integrators rk4@H,dopri5@R,genalpha@R,...] [--solvers ldl,klu,dense]\n"
          "                [--modes all,N,FHz,...] [--couplings full,partial,constant,rigid]\n"
          "                [--joints direct,virtual] [--reals double,float]\n"
          "                [--ref-rtol R] [--workdir DIR] [--quiet]\n");
}

static int positive_number(const char *opt, const char *s, double *x) {
  char *end;
  errno = 0;
  *x = strtod(s, &end);
  if (end == s || *end || errno || !(*x > 0) || !isfinite(*x)) {
    fprintf(stderr, "mbcc: error: '%s' needs a positive number, got '%s'\n", opt, s);
    return -1;
  }
  return 0;
}

/* every comma-separated item of list is one of allowed[] */
static int check_list(const char *opt, const char *list, const char *const *allowed) {
  char buf[512];
  snprintf(buf, sizeof buf, "%s", list);
  char *save = NULL;
  int n = 0;
  for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save), n++) {
    int ok = 0;
    for (int k = 0; allowed[k]; k++) ok |= !strcmp(tok, allowed[k]);
    if (!ok) {
      fprintf(stderr, "mbcc: error: %s: unknown value '%s' (expected", opt, tok);
      for (int k = 0; allowed[k]; k++) fprintf(stderr, "%s%s", k ? ", " : " ", allowed[k]);
      fprintf(stderr, ")\n");
      return -1;
    }
  }
  if (!n) { fprintf(stderr, "mbcc: error: %s needs at least one value\n", opt); return -1; }
  return 0;
}

static int in_list(const char *list, const char *item) {
  char buf[512];
  snprintf(buf, sizeof buf, "%s", list);
  char *save = NULL;
  for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save))
    if (!strcmp(tok, item)) return 1;
  return 0;
}

static int parse_trade_options(int argc, char **argv, trade_options *o) {
  memset(o, 0, sizeof *o);
  o->reps = 3;
  o->ref_rtol = 1e-10;
  snprintf(o->couplings, sizeof o->couplings, "full,partial,constant,rigid");
  snprintf(o->joints, sizeof o->joints, "direct,virtual");
  snprintf(o->solvers, sizeof o->solvers, "ldl,klu,dense");
  snprintf(o->reals, sizeof o->reals, "double,float");
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (a[0] != '-') {
      if (o->model) { fprintf(stderr, "mbcc: error: more than one model given ('%s')\n", a); return 2; }
      o->model = a;
      continue;
    }
    if (!strcmp(a, "--quiet")) { o->quiet = 1; continue; }
    if (!v) { fprintf(stderr, "mbcc: error: option '%s' needs a value\n", a); return 2; }
    i++;
    double x;
    if (!strcmp(a, "--scene")) o->scene = v;
    else if (!strcmp(a, "--outputs")) o->outputs = v;
    else if (!strcmp(a, "--csv")) o->csv = v;
    else if (!strcmp(a, "--plot")) o->plot = v;
    else if (!strcmp(a, "--workdir")) o->workdir = v;
    else if (!strcmp(a, "--max-error")) {
      /* one target or a comma-separated list */
      char buf[256];
      snprintf(buf, sizeof buf, "%s", v);
      char *save = NULL;
      o->nmax_error = 0;
      for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (o->nmax_error == 8) { fprintf(stderr, "mbcc: error: --max-error: at most 8 targets\n"); return 2; }
        if (positive_number(a, tok, &o->max_error[o->nmax_error++])) return 2;
      }
      if (!o->nmax_error) { fprintf(stderr, "mbcc: error: --max-error needs a value\n"); return 2; }
    } else if (!strcmp(a, "--end")) {
      if (positive_number(a, v, &o->end)) return 2;
    } else if (!strcmp(a, "--output-step")) {
      if (positive_number(a, v, &o->output_step)) return 2;
    } else if (!strcmp(a, "--ref-rtol")) {
      if (positive_number(a, v, &o->ref_rtol)) return 2;
      if (o->ref_rtol < 1e-13) { fprintf(stderr, "mbcc: error: --ref-rtol below 1e-13 leaves no room for the stricter run\n"); return 2; }
    } else if (!strcmp(a, "--reps")) {
      if (positive_number(a, v, &x)) return 2;
      if (x != floor(x) || x > 100) { fprintf(stderr, "mbcc: error: --reps needs a whole number 1..100, got '%s'\n", v); return 2; }
      o->reps = (int)x;
    } else if (!strcmp(a, "--integrators") || !strcmp(a, "--modes")) {
      char *dst = !strcmp(a, "--modes") ? o->modes : o->integrators;
      size_t n = !strcmp(a, "--modes") ? sizeof o->modes : sizeof o->integrators;
      if (strlen(v) >= n || !*v) { fprintf(stderr, "mbcc: error: bad value for %s\n", a); return 2; }
      memcpy(dst, v, strlen(v) + 1);
    } else {
      char *dst = NULL;
      size_t n = 0;
      static const char *const coup[] = {"full", "partial", "constant", "rigid", NULL};
      static const char *const jof[] = {"direct", "virtual", NULL};
      static const char *const sol[] = {"ldl", "klu", "dense", NULL};
      static const char *const real[] = {"double", "float", NULL};
      const char *const *allowed = NULL;
      if (!strcmp(a, "--couplings")) { dst = o->couplings; n = sizeof o->couplings; allowed = coup; }
      else if (!strcmp(a, "--joints")) { dst = o->joints; n = sizeof o->joints; allowed = jof; }
      else if (!strcmp(a, "--solvers")) { dst = o->solvers; n = sizeof o->solvers; allowed = sol; }
      else if (!strcmp(a, "--reals")) { dst = o->reals; n = sizeof o->reals; allowed = real; }
      if (!dst) {
        fprintf(stderr, "mbcc: error: unknown option '%s'\n", a);
        trade_usage();
        return 2;
      }
      if (strlen(v) >= n) { fprintf(stderr, "mbcc: error: bad value for %s\n", a); return 2; }
      if (check_list(a, v, allowed)) return 2;
      memcpy(dst, v, strlen(v) + 1);
    }
  }
  if (!o->model) { trade_usage(); return 2; }
  return 0;
}

/* --integrators: "name@value,..." into set[]; rk4's value is a step, the others' a tolerance */
static int parse_integrators(const char *list, integ_setting *set, int *n) {
  char buf[512];
  snprintf(buf, sizeof buf, "%s", list);
  char *save = NULL;
  *n = 0;
  for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
    char *at = strchr(tok, '@');
    if (!at || at == tok || at - tok >= 16) {
      fprintf(stderr, "mbcc: error: --integrators: '%s' is not NAME@STEP or NAME@RTOL (e.g. rk4@1e-4, dopri5@1e-6)\n", tok);
      return -1;
    }
    *at = 0;
    if (!strcmp(tok, "") || strspn(tok, "abcdefghijklmnopqrstuvwxyz0123456789_") != strlen(tok)) {
      fprintf(stderr, "mbcc: error: --integrators: bad integrator name '%s'\n", tok);
      return -1;
    }
    if (*n >= MAXI) { fprintf(stderr, "mbcc: error: --integrators: at most %d settings\n", MAXI); return -1; }
    snprintf(set[*n].name, sizeof set[*n].name, "%s", tok);
    if (positive_number("--integrators", at + 1, &set[*n].value)) return -1;
    (*n)++;
  }
  if (!*n) { fprintf(stderr, "mbcc: error: --integrators needs at least one setting\n"); return -1; }
  return 0;
}

/* --- building a variant ------------------------------------------------------------ */

static int mkdirs(const char *path) {
  char buf[4096];
  snprintf(buf, sizeof buf, "%s", path);
  for (char *p = buf + 1; *p; p++)
    if (*p == '/') {
      *p = 0;
      if (mkdir(buf, 0777) && errno != EEXIST) return -1;
      *p = '/';
    }
  return mkdir(buf, 0777) && errno != EEXIST ? -1 : 0;
}

/* apply a variant's structural settings to the IR, before lowering */
static void apply_variant(ir_model *ir, const variant *v) {
  for (int b = 0; b < ir->nbodies; b++) {
    ir_flex *fx = ir->bodies[b].flex;
    if (!fx) continue;
    if (v->cutoff > 0) { fx->select = MODES_MAX_FREQUENCY; fx->max_frequency = v->cutoff; }
    else if (v->modes == -1) fx->select = MODES_ALL;
    else if (v->modes >= 0) { fx->select = MODES_COUNT; fx->count = v->modes; }
    if (v->coupling >= 0) fx->coupling = (ir_coupling)v->coupling;
  }
  if (v->joints >= 0) {
    ir->sim.joints_on_flexible = v->joints ? JOF_VIRTUAL : JOF_DIRECT;
    for (int j = 0; j < ir->njoints; j++) {
      ir_joint *J = &ir->joints[j];
      J->via_virtual = v->joints && (J->node[0] >= 0 || J->node[1] >= 0);
    }
  }
}

/* the last line of a log that says "error" (the reason of a failure) */
static void last_error_line(const char *log, char *why, size_t n) {
  FILE *f = fopen(log, "r");
  if (!f) return;
  char line[1024];
  while (fgets(line, sizeof line, f))
    if (strstr(line, "error")) {
      line[strcspn(line, "\r\n")] = 0;
      const char *sim = strstr(line, "_sim: error: "); /* without the simulator's path */
      textf(why, n, "%s", sim ? sim + 6 : line);
    }
  fclose(f);
}

/* stderr into 'log' until restore_stderr(saved) */
static int redirect_stderr(const char *log) {
  fflush(stderr);
  int saved = dup(2);
  int fd = open(log, O_WRONLY | O_CREAT | O_APPEND, 0666);
  if (fd >= 0) { dup2(fd, 2); close(fd); }
  return saved;
}

static void restore_stderr(int saved) {
  fflush(stderr);
  if (saved >= 0) { dup2(saved, 2); close(saved); }
}

/* read, apply, lower, assemble, emit and compile a variant into workdir/label;
 * messages go to workdir/label.log.  Sets v->ok, or v->why. */
static void build_variant(const trade_options *o, const char *workdir, variant *v) {
  char dir[4200], log[4300];
  snprintf(dir, sizeof dir, "%s/%s", workdir, v->label);
  snprintf(log, sizeof log, "%s/%s.log", workdir, v->label);
  remove(log);
  v->ok = 0;
  textf(v->why, sizeof v->why, "the model does not build with these settings (see %s)", log);
  int saved = redirect_stderr(log);
  diag_reset();
  mbc_unit u;
  int st = mbc_unit_read(&u, o->model, o->scene);
  if (!st) {
    apply_variant(u.ir, v);
    u.overridden = 1; /* the IR is no longer the file's: run-time parameters stay at their values */
    st = mbc_unit_finish(&u, 0);
  }
  u.real_float = v->real_float;
  const ir_model *ir = u.ir;
  const lmodel *L = u.lowered;
  if (!st && !emit_model(&u, dir)) {
    v->nmodes = 0;
    int coup = -1, virt = 0;
    for (int b = 1; b < ir->nbodies; b++)
      if (ir->bodies[b].flex) {
        coup = (int)ir->bodies[b].flex->coupling;
        if (coup != COUPLING_RIGID) v->nmodes += L->m.body[b - 1].nm;
      }
    for (int j = 0; j < ir->njoints; j++) virt |= ir->joints[j].via_virtual && ir->joints[j].active;
    snprintf(v->coupling_name, sizeof v->coupling_name, "%s", coup < 0 ? "-" : COUPLING_NAMES[coup]);
    snprintf(v->joints_name, sizeof v->joints_name, "%s", coup < 0 ? "-" : virt ? "virtual" : "direct");
    char main_src[4300];
    snprintf(main_src, sizeof main_src, "%s/main.c", dir);
    snprintf(v->exe, sizeof v->exe, "%s/%s_sim", dir, L->m.name);
    /* single precision: the code emitted with real_float against libmbrt_float.a */
    int rc = compile_generated(dir, L->m.name, main_src, v->exe, NULL, v->real_float, v->real_float);
    if (rc && v->real_float) textf(v->why, sizeof v->why, "the single-precision build failed");
    v->ok = !rc;
  }
  restore_stderr(saved);
  if (!v->ok) last_error_line(log, v->why, sizeof v->why);
  mbc_unit_free(&u);
  diag_reset();
}

/* --- running ---------------------------------------------------------------------- */

/* run argv with stdout and stderr appended to log; its exit status (128 if
 * killed, -1 if not started) and CPU time (user + system) in *cpu */
static int run_timed(char *const argv[], const char *log, double *cpu) {
  fflush(stdout);
  fflush(stderr);
  pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    int fd = open(log, O_WRONLY | O_CREAT | O_APPEND, 0666);
    if (fd >= 0) { dup2(fd, 1); dup2(fd, 2); close(fd); }
    execv(argv[0], argv);
    fprintf(stderr, "mbcc trade: error: cannot run '%s': %s\n", argv[0], strerror(errno));
    _exit(127);
  }
  int status = 0;
  struct rusage ru;
  if (wait4(pid, &status, 0, &ru) < 0) return -1;
  *cpu = (double)ru.ru_utime.tv_sec + 1e-6 * (double)ru.ru_utime.tv_usec + (double)ru.ru_stime.tv_sec +
         1e-6 * (double)ru.ru_stime.tv_usec;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* the simulator's arguments for integrator setting s (rtol/atol or step), solver, end, extra */
typedef struct {
  char *argv[32];
  int n, nbuf;
  char buf[8][64];
} sim_args;

static void sim_arg(sim_args *a, const char *s) { a->argv[a->n++] = (char *)s; }
static void sim_num(sim_args *a, const char *opt, double x) {
  int k = a->nbuf++ % 8; /* at most 5 numbers per run */
  snprintf(a->buf[k], sizeof a->buf[k], "%.6g", x);
  sim_arg(a, opt);
  sim_arg(a, a->buf[k]);
}

/* Run the simulator reps times; CSV to csv.  0, or 1 with the reason in why. */
static int simulate(const char *exe, const integ_setting *s, const char *solver, double end, double output_step,
                    double max_step,
                    int reps, const char *csv, const char *log, double *cpu_median, char *why, size_t nwhy) {
  sim_args a = {0};
  sim_arg(&a, (char *)exe);
  sim_arg(&a, "--quiet");
  sim_arg(&a, "-o");
  sim_arg(&a, csv);
  sim_arg(&a, "--integrator");
  sim_arg(&a, s->name);
  sim_arg(&a, "--solver");
  sim_arg(&a, solver);
  if (!strcmp(s->name, "rk4")) sim_num(&a, "--step", s->value);
  else {
    sim_num(&a, "--rtol", s->value);
    sim_num(&a, "--atol", s->value * 1e-2);
  }
  if (end > 0) sim_num(&a, "--end", end);
  if (output_step > 0) sim_num(&a, "--output-step", output_step);
  if (max_step > 0) sim_num(&a, "--max-step", max_step);
  a.argv[a.n] = NULL;
  double times[100];
  remove(csv);
  for (int r = 0; r < reps && r < 100; r++) {
    int st = run_timed(a.argv, log, &times[r]);
    if (st) {
      snprintf(why, nwhy, "simulator exit status %d", st);
      last_error_line(log, why, nwhy);
      return 1;
    }
  }
  qsort(times, (size_t)reps, sizeof *times, cmp_double);
  *cpu_median = reps % 2 ? times[reps / 2] : 0.5 * (times[reps / 2 - 1] + times[reps / 2]);
  return 0;
}

/* compare the run's CSV against the reference's chosen columns; 0, or 1 with why */
static int compare_run(const char *csv, const table *ref, const int *sel, int nsel, const double *refy,
                       const double *scale, trade_error *e, char *why, size_t nwhy) {
  table tb;
  if (read_table(csv, &tb)) { snprintf(why, nwhy, "no readable results CSV"); return 1; }
  int rc = 1;
  if (tb.nrows < ref->nrows) {
    snprintf(why, nwhy, "results end early (%d of %d output rows)", tb.nrows, ref->nrows);
    goto done;
  }
  int cols[MAXCOL];
  for (int c = 0; c < nsel; c++) {
    cols[c] = -1;
    for (int d = 0; d < tb.ncols; d++)
      if (!strcmp(tb.names[d], ref->names[sel[c]])) cols[c] = d;
    if (cols[c] < 0) { snprintf(why, nwhy, "output '%s' missing", ref->names[sel[c]]); goto done; }
  }
  for (int k = 0; k < ref->nrows; k++)
    if (fabs(tb.t[k] - ref->t[k]) > 1e-9 * fmax(1, fabs(ref->t[k]))) {
      snprintf(why, nwhy, "output times differ from the reference's (row %d)", k + 1);
      goto done;
    }
  double *y = pick_columns(&tb, cols, nsel, ref->nrows);
  if (!y) { snprintf(why, nwhy, "out of memory"); goto done; }
  if (trade_compare(refy, y, ref->nrows, nsel, scale, e)) snprintf(why, nwhy, "non-finite output");
  else rc = 0;
  free(y);
done:
  table_free(&tb);
  return rc;
}

/* --- reporting ----------------------------------------------------------------------- */

static void run_settings(const variant *V, const integ_setting *I, const trade_run *r, char *buf, size_t n) {
  snprintf(buf, n, "modes %d, coupling %s, joints %s, %s, %s %s %.3g, solver %s", V[r->v].nmodes,
           V[r->v].coupling_name, V[r->v].joints_name, V[r->v].real_float ? "float" : "double", I[r->i].name,
           strcmp(I[r->i].name, "rk4") ? "rtol" : "step", I[r->i].value, r->solver);
}

static int write_csv(const char *path, const variant *V, const integ_setting *I, const trade_run *R, int nrun) {
  out_file out;
  if (out_file_open(&out, path)) return 2;
  FILE *f = out.f;
  fprintf(f, "run,variant,modes,coupling,joints,real,integrator,step,rtol,solver,cpu_s,max_err,rms_err,failed,pareto,note\n");
  for (int k = 0; k < nrun; k++) {
    const trade_run *r = &R[k];
    const variant *v = &V[r->v];
    const integ_setting *s = &I[r->i];
    int rk4 = !strcmp(s->name, "rk4");
    fprintf(f, "%d,%s,%d,%s,%s,%s,%s,", k + 1, v->label, v->nmodes, v->coupling_name, v->joints_name,
            v->real_float ? "float" : "double", s->name);
    if (rk4) fprintf(f, "%.6g,,", s->value);
    else fprintf(f, ",%.6g,", s->value);
    fprintf(f, "%s,", r->solver);
    if (r->failed) fprintf(f, ",,,1,0,");
    else fprintf(f, "%.6g,%.6g,%.6g,0,%d,", r->cpu, r->err.max_err, r->err.rms_err, r->pareto);
    /* the note is free text: no commas or quotes in it */
    for (const char *p = r->why; *p; p++) fputc(*p == ',' || *p == '"' ? ';' : *p, f);
    fputc('\n', f);
  }
  return out_file_commit(&out);
}

/* log-log error against CPU time: every successful run, the Pareto front as a line */
static int write_plot(const char *png, const char *title, const trade_run *R, int nrun, double ref_err) {
  int nok = 0;
  for (int k = 0; k < nrun; k++) nok += !R[k].failed;
  if (!nok) { printf("no plot: every run failed\n"); return -1; }
  char dat[8400], gp[8400];
  snprintf(dat, sizeof dat, "%s.dat", png);
  snprintf(gp, sizeof gp, "%s.gp", png);
  FILE *d = fopen(dat, "w");
  if (!d) { fprintf(stderr, "mbcc: error: cannot write '%s'\n", dat); return 2; }
  /* block 0: all runs; block 1: the front sorted by CPU time */
  for (int k = 0; k < nrun; k++)
    if (!R[k].failed) fprintf(d, "%.6g %.6g\n", R[k].cpu, fmax(R[k].err.max_err, 1e-16));
  fprintf(d, "\n\n");
  int idx[MAXRUN], nf = 0;
  for (int k = 0; k < nrun; k++)
    if (R[k].pareto) idx[nf++] = k;
  for (int a = 1; a < nf; a++)
    for (int b = a; b > 0 && R[idx[b]].cpu < R[idx[b - 1]].cpu; b--) {
      int t = idx[b]; idx[b] = idx[b - 1]; idx[b - 1] = t;
    }
  for (int a = 0; a < nf; a++) fprintf(d, "%.6g %.6g %d\n", R[idx[a]].cpu, fmax(R[idx[a]].err.max_err, 1e-16), idx[a] + 1);
  /* block 2: the reference's own error across the runs' CPU times */
  double lo = INFINITY, hi = 0;
  for (int k = 0; k < nrun; k++)
    if (!R[k].failed) { lo = fmin(lo, R[k].cpu); hi = fmax(hi, R[k].cpu); }
  fprintf(d, "\n\n%.6g %.6g\n%.6g %.6g\n", lo, fmax(ref_err, 1e-16), hi, fmax(ref_err, 1e-16));
  fclose(d);
  FILE *g = fopen(gp, "w");
  if (!g) { remove(dat); fprintf(stderr, "mbcc: error: cannot write '%s'\n", gp); return 2; }
  fprintf(g, "set terminal pngcairo size 800,560 noenhanced font ',10'\nset output '%s'\n", png);
  fprintf(g, "set logscale xy\nset grid\nset format y '%%.0e'\nset key top right\n");
  fprintf(g, "set title '%s'\nset xlabel 'CPU time [s] (median)'\nset ylabel 'max error (relative to output range)'\n", title);
  fprintf(g, "plot '%s' index 0 using 1:2 with points pt 7 ps 0.8 lc rgb '#4477aa' title 'runs', \\\n"
             "     '%s' index 1 using 1:2 with linespoints pt 6 ps 1.6 lw 1.5 lc rgb '#cc3311' title 'Pareto front', \\\n"
             "     '%s' index 1 using 1:2:3 with labels offset 1.2,0.6 font ',8' notitle, \\\n"
             "     '%s' index 2 using 1:2 with lines dt 2 lc rgb 'gray40' title 'reference error'\n", dat, dat, dat, dat);
  fclose(g);
  char *argv[] = {"gnuplot", gp, NULL};
  int st = run_command(argv);
  remove(gp);
  remove(dat);
  if (st) { fprintf(stderr, "mbcc: error: gnuplot failed (status %d)\n", st); return 2; }
  return 0;
}

/* --- the study ------------------------------------------------------------------------- */

static variant *add_variant(variant *V, int *nv, const char *label) {
  if (*nv >= MAXV) return NULL;
  variant *v = &V[(*nv)++];
  memset(v, 0, sizeof *v);
  snprintf(v->label, sizeof v->label, "%s", label);
  v->modes = -2;
  v->coupling = -1;
  v->joints = -1;
  return v;
}

/* the settings a variant ends up with, "as in the model" resolved */
typedef struct {
  int modes, coupling, joints, real_float;
  double cutoff;
} structure;

static structure resolved(const variant *v, int model_count, int model_coupling, int model_virtual) {
  structure s = {v->modes, v->coupling, v->joints, v->real_float, v->cutoff};
  if (s.cutoff > 0) s.modes = -3;
  else if (s.modes == -2 && model_count >= 0) s.modes = model_count;
  if (s.coupling < 0) s.coupling = model_coupling;
  if (s.joints < 0) s.joints = model_virtual;
  return s;
}

static int same_structure(structure a, structure b) {
  return a.modes == b.modes && a.coupling == b.coupling && a.joints == b.joints && a.real_float == b.real_float &&
         a.cutoff == b.cutoff;
}

int cmd_trade(int argc, char **argv) {
  trade_options o;
  if (parse_trade_options(argc, argv, &o)) return 2;

  /* the model as written: errors in it (or an unknown scene) are reported here */
  mbc_unit u;
  if (mbc_unit_build(&u, o.model, o.scene, 0)) {
    mbc_unit_free(&u);
    return 2;
  }
  const ir_model *ir = u.ir;
  const lmodel *L = u.lowered;
  char name[256];
  snprintf(name, sizeof name, "%s", L->m.name);
  /* the chosen outputs */
  int nsel = 0;
  char selnames[MAXCOL][128];
  if (o.outputs) {
    char buf[4096];
    snprintf(buf, sizeof buf, "%s", o.outputs);
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
      int found = 0;
      for (int c = 0; c < L->m.ncols; c++) found |= !strcmp(L->m.col_name[c], tok);
      if (!found) {
        fprintf(stderr, "mbcc: error: --outputs: '%s' is not an output column of %s (columns:", tok, name);
        for (int c = 0; c < L->m.ncols; c++) fprintf(stderr, " %s", L->m.col_name[c]);
        fprintf(stderr, ")\n");
        mbc_unit_free(&u);
        return 2;
      }
      if (nsel < MAXCOL) snprintf(selnames[nsel++], sizeof selnames[0], "%s", tok);
    }
  } else {
    for (int c = 0; c < L->m.ncols && nsel < MAXCOL; c++) snprintf(selnames[nsel++], sizeof selnames[0], "%s", L->m.col_name[c]);
  }
  if (!nsel) { fprintf(stderr, "mbcc: error: the model has no outputs to compare\n"); mbc_unit_free(&u); return 2; }
  /* what the model has: flexible bodies and their mode selection */
  int nflex = 0, model_count = -1, model_coupling = -1, model_virtual = 0;
  for (int b = 1; b < ir->nbodies; b++) {
    ir_flex *fx = ir->bodies[b].flex;
    if (!fx) continue;
    nflex++;
    if (model_count < 0 && fx->select == MODES_COUNT) model_count = fx->count;
    if (model_coupling < 0) model_coupling = (int)fx->coupling;
  }
  for (int j = 0; j < ir->njoints; j++) model_virtual |= ir->joints[j].via_virtual;
  double output_step = o.output_step > 0 ? o.output_step : ir->sim.output_step;
  mbc_unit_free(&u);

  /* the integrator settings: rk4 at a quarter and a sixteenth of the output
     step, dopri5 and genalpha at three tolerances */
  integ_setting I[MAXI];
  int ni = 0;
  if (!o.integrators[0])
    snprintf(o.integrators, sizeof o.integrators, "rk4@%.6g,rk4@%.6g,dopri5@1e-4,dopri5@1e-6,dopri5@1e-8,"
             "genalpha@1e-4,genalpha@1e-6,genalpha@1e-8", output_step / 4, output_step / 16);
  if (parse_integrators(o.integrators, I, &ni)) return 2;

  /* the mode sweep: counts (and cutoffs "FHz", "all"); default twice, half and
     none of the model's count of (fixed-interface) normal modes */
  if (!o.modes[0] && model_count >= 0) {
    int c2 = model_count ? 2 * model_count : 4;
    snprintf(o.modes, sizeof o.modes, "%d", c2);
    if (model_count / 2 != model_count && model_count / 2 > 0) snprintf(o.modes + strlen(o.modes), 32, ",%d", model_count / 2);
    if (model_count) strcat(o.modes, ",0");
  }
  variant V[MAXV];
  int nv = 0;
  add_variant(V, &nv, "base");
  int ref_modes = -2; /* the reference's: the largest count swept, or all */
  double ref_cutoff = 0;
  if (o.modes[0]) { /* checked even for a model without flexible bodies (then no variants) */
    char buf[256];
    snprintf(buf, sizeof buf, "%s", o.modes);
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
      char label[48];
      int modes = -2;
      double cutoff = 0;
      size_t len = strlen(tok);
      if (!strcmp(tok, "all")) { modes = -1; snprintf(label, sizeof label, "modes-all"); }
      else if (len > 2 && !strcmp(tok + len - 2, "Hz")) {
        char num[64];
        snprintf(num, sizeof num, "%.*s", (int)(len - 2), tok);
        if (positive_number("--modes", num, &cutoff)) return 2;
        textf(label, sizeof label, "cutoff-%sHz", num);
      } else {
        char *end;
        long c = strtol(tok, &end, 10);
        if (*end || end == tok || c < 0 || c > 1000) {
          fprintf(stderr, "mbcc: error: --modes: '%s' is not a mode count, 'all' or a cutoff like 1000Hz\n", tok);
          return 2;
        }
        modes = (int)c;
        snprintf(label, sizeof label, "modes-%d", modes);
        if (modes == model_count) continue; /* that is the base */
      }
      if (!nflex) continue;
      variant *v = add_variant(V, &nv, label);
      if (!v) { fprintf(stderr, "mbcc: error: too many variants\n"); return 2; }
      v->modes = modes;
      v->cutoff = cutoff;
      if (modes == -1) ref_modes = -1;
      else if (modes >= 0 && ref_modes != -1 && modes > ref_modes) ref_modes = modes;
      else if (cutoff > 0 && ref_modes == -2 && cutoff > ref_cutoff) ref_cutoff = cutoff;
    }
    if (ref_modes >= 0 && ref_modes < model_count) ref_modes = model_count;
    if (ref_modes >= 0) ref_cutoff = 0;
  }
  if (nflex) {
    for (int c = 0; c < 4; c++) {
      if (c == model_coupling || !in_list(o.couplings, COUPLING_NAMES[c])) continue;
      char label[48];
      snprintf(label, sizeof label, "coupling-%s", COUPLING_NAMES[c]);
      variant *v = add_variant(V, &nv, label);
      if (!v) { fprintf(stderr, "mbcc: error: too many variants\n"); return 2; }
      v->coupling = c;
    }
    for (int j = 0; j < 2; j++) {
      if (j == model_virtual || !in_list(o.joints, j ? "virtual" : "direct")) continue;
      variant *v = add_variant(V, &nv, j ? "joints-virtual" : "joints-direct");
      if (!v) { fprintf(stderr, "mbcc: error: too many variants\n"); return 2; }
      v->joints = j;
    }
  }
  if (in_list(o.reals, "float")) {
    variant *v = add_variant(V, &nv, "real-float");
    if (!v) { fprintf(stderr, "mbcc: error: too many variants\n"); return 2; }
    v->real_float = 1;
  }
  int base_double = in_list(o.reals, "double");
  variant *ref = add_variant(V, &nv, "reference");
  if (!ref) { fprintf(stderr, "mbcc: error: too many variants\n"); return 2; }
  ref->modes = ref_modes;
  ref->cutoff = ref_cutoff;
  if (nflex) { ref->coupling = COUPLING_FULL; ref->joints = 0; }

  /* the scratch directory */
  char workdir[4096];
  if (o.workdir) snprintf(workdir, sizeof workdir, "%s", o.workdir);
  else snprintf(workdir, sizeof workdir, "generated/%s_trade", name);
  if (mkdirs(workdir)) { fprintf(stderr, "mbcc: error: cannot create '%s'\n", workdir); return 2; }
  char csv_default[4400], png[4400];
  const char *csv = o.csv;
  if (!csv) { snprintf(csv_default, sizeof csv_default, "%s/trade.csv", workdir); csv = csv_default; }
  if (o.plot) snprintf(png, sizeof png, "%s", o.plot);
  else {
    snprintf(png, sizeof png, "%s", csv);
    char *dot = strrchr(png, '.');
    if (dot && !strcmp(dot, ".csv")) strcpy(dot, ".png");
    else strncat(png, ".png", sizeof png - strlen(png) - 1);
  }

  /* the reference first: nothing else is worth doing without it */
  if (!o.quiet) fprintf(stderr, "mbcc trade: building the reference (%s modes, full coupling, direct joints, double)\n",
                        ref_modes == -1 ? "all" : ref_modes == -2 ? "the model's" : "the most");
  build_variant(&o, workdir, ref);
  if (!ref->ok) { fprintf(stderr, "mbcc: error: the reference could not be built: %s\n", ref->why); return 1; }
  char ref_csv[4400], strict_csv[4400], ref_log[4400], why[300] = "";
  snprintf(ref_csv, sizeof ref_csv, "%s/reference.csv", workdir);
  snprintf(strict_csv, sizeof strict_csv, "%s/reference_strict.csv", workdir);
  snprintf(ref_log, sizeof ref_log, "%s/reference.run.log", workdir);
  remove(ref_log);
  integ_setting ref_set = {"dopri5", o.ref_rtol}, strict_set = {"dopri5", o.ref_rtol * 1e-2};
  double ref_cpu = 0, strict_cpu = 0;
  if (simulate(ref->exe, &ref_set, "klu", o.end, o.output_step, 0, 1, ref_csv, ref_log, &ref_cpu, why, sizeof why) ||
      simulate(ref->exe, &strict_set, "klu", o.end, o.output_step, output_step / 2, 1, strict_csv, ref_log, &strict_cpu, why, sizeof why)) {
    fprintf(stderr, "mbcc: error: the reference run failed: %s (see %s)\n", why, ref_log);
    return 1;
  }
  table reft, strictt;
  if (read_table(ref_csv, &reft) || read_table(strict_csv, &strictt)) {
    fprintf(stderr, "mbcc: error: cannot read the reference results in %s\n", workdir);
    return 1;
  }
  int sel[MAXCOL];
  for (int c = 0; c < nsel; c++) {
    sel[c] = -1;
    for (int d = 0; d < reft.ncols; d++)
      if (!strcmp(reft.names[d], selnames[c])) sel[c] = d;
    if (sel[c] < 0) { fprintf(stderr, "mbcc: error: the reference has no output '%s'\n", selnames[c]); return 1; }
  }
  if (!o.outputs && drop_flat_outputs(&reft, &strictt, sel, selnames, &nsel)) return 1;
  double *refy = pick_columns(&reft, sel, nsel, reft.nrows);
  double scale[MAXCOL];
  int group[MAXCOL];
  const char *cn[MAXCOL];
  for (int c = 0; c < nsel; c++) cn[c] = selnames[c];
  trade_column_groups(cn, nsel, group);
  trade_column_scales(refy, reft.nrows, nsel, group, scale);
  trade_error ref_err;
  {
    /* the reference's own error: against the stricter run, on the same scales */
    double *sy = strictt.nrows >= reft.nrows ? pick_columns(&strictt, sel, nsel, reft.nrows) : NULL;
    if (!sy || trade_compare(sy, refy, reft.nrows, nsel, scale, &ref_err)) {
      fprintf(stderr, "mbcc: error: the stricter reference run does not match the reference's output times\n");
      free(sy);
      return 1;
    }
    free(sy);
  }
  printf("model %s: %d outputs compared (%s%s), %d output times\n", name, nsel, cn[0], nsel > 1 ? ", ..." : "", reft.nrows);
  printf("reference: %d modes, coupling %s, joints %s, double, dopri5 rtol %.3g atol %.3g, klu, %.3g s CPU\n",
         ref->nmodes, ref->coupling_name, ref->joints_name, ref_set.value, ref_set.value * 1e-2, ref_cpu);
  printf("stricter:  dopri5 rtol %.3g atol %.3g, max step %.3g, %.3g s CPU\n", strict_set.value, strict_set.value * 1e-2,
         output_step / 2, strict_cpu);
  printf("reference error: max_err %.3e rms_err %.3e (worst output %s)\n", ref_err.max_err, ref_err.rms_err,
         ref_err.worst_col >= 0 ? cn[ref_err.worst_col] : "-");
  fflush(stdout);

  /* the sweep: every variant (one setting changed from the model as written)
     with every integrator setting and the ldl solver; the other solvers on the
     base variant; float only with ldl */
  static trade_run R[MAXRUN];
  int nrun = 0;
  char solvers[64];
  snprintf(solvers, sizeof solvers, "%s", o.solvers);
  const char *solver_names[] = {"ldl", "klu", "dense"};
  for (int v = 0; v < nv; v++) {
    if (&V[v] == ref) continue;
    if (!V[v].real_float && !base_double) continue; /* --reals float: only the float runs */
    for (int s = 0; s < 3; s++) {
      if (!in_list(solvers, solver_names[s])) continue;
      int first_solver = 1;
      for (int t = 0; t < s; t++) first_solver &= !in_list(solvers, solver_names[t]);
      /* the variants run with the first solver listed; only the base with all */
      if (v != 0 && !first_solver) continue;
      if (V[v].real_float && strcmp(solver_names[s], "ldl")) continue;
      for (int i = 0; i < ni; i++) {
        trade_run *r = &R[nrun++];
        memset(r, 0, sizeof *r);
        r->v = v;
        r->i = i;
        r->solver = solver_names[s];
      }
    }
  }
  if (!nrun) { fprintf(stderr, "mbcc: error: nothing to sweep (check --reals and --solvers)\n"); return 2; }
  if (!o.quiet) fprintf(stderr, "mbcc trade: %d runs in %d variants, %d repetitions each\n", nrun, nv - 1, o.reps);
  int built_v = -1;
  for (int k = 0; k < nrun; k++) {
    trade_run *r = &R[k];
    variant *v = &V[r->v];
    if (r->v != built_v && !v->ok && !v->why[0]) {
      structure sv = resolved(v, model_count, model_coupling, model_virtual);
      if (same_structure(sv, resolved(ref, model_count, model_coupling, model_virtual))) {
        /* the reference's code: no second build */
        char label[48];
        memcpy(label, v->label, sizeof label);
        *v = *ref;
        memcpy(v->label, label, sizeof label);
      } else {
        if (!o.quiet) fprintf(stderr, "mbcc trade: building variant %s\n", v->label);
        build_variant(&o, workdir, v);
      }
      built_v = r->v;
    }
    if (!v->ok) {
      r->failed = 1;
      snprintf(r->why, sizeof r->why, "%s", v->why);
      continue;
    }
    char run_csv[4400], run_log[4400];
    snprintf(run_csv, sizeof run_csv, "%s/%s/run%d.csv", workdir, v->label, k + 1);
    snprintf(run_log, sizeof run_log, "%s/%s/run%d.log", workdir, v->label, k + 1);
    char vdir[4300];
    snprintf(vdir, sizeof vdir, "%s/%s", workdir, v->label);
    mkdirs(vdir);
    remove(run_log);
    if (simulate(v->exe, &I[r->i], r->solver, o.end, o.output_step, 0, o.reps, run_csv, run_log, &r->cpu, r->why, sizeof r->why) ||
        compare_run(run_csv, &reft, sel, nsel, refy, scale, &r->err, r->why, sizeof r->why)) {
      r->failed = 1;
      r->cpu = NAN;
    }
    if (!o.quiet) {
      char s[300];
      run_settings(V, I, r, s, sizeof s);
      if (r->failed) fprintf(stderr, "mbcc trade: run %d/%d: %s: failed: %s\n", k + 1, nrun, s, r->why);
      else fprintf(stderr, "mbcc trade: run %d/%d: %s: %.3g s, max_err %.2e\n", k + 1, nrun, s, r->cpu, r->err.max_err);
    }
  }
  free(refy);
  table_free(&reft);
  table_free(&strictt);

  /* the Pareto front and the table */
  double cpu[MAXRUN], err[MAXRUN];
  int failed[MAXRUN], pareto[MAXRUN];
  for (int k = 0; k < nrun; k++) {
    cpu[k] = R[k].cpu;
    err[k] = R[k].failed ? NAN : R[k].err.max_err;
    failed[k] = R[k].failed;
  }
  trade_pareto(cpu, err, failed, nrun, pareto);
  for (int k = 0; k < nrun; k++) R[k].pareto = pareto[k];
  printf("\n  run  variant          modes coupling joints  real    integrator  step/rtol  solver   cpu_s      max_err    rms_err\n");
  for (int k = 0; k < nrun; k++) {
    const trade_run *r = &R[k];
    const variant *v = &V[r->v];
    printf("%4d%c  %-16s %5d %-8s %-7s %-7s %-11s %-9.3g  %-7s", k + 1, r->pareto ? '*' : ' ', v->label, v->nmodes,
           v->coupling_name, v->joints_name, v->real_float ? "float" : "double", I[r->i].name, I[r->i].value, r->solver);
    if (r->failed) printf("  failed: %s\n", r->why);
    else printf("  %-9.3g  %-9.3e  %-9.3e\n", r->cpu, r->err.max_err, r->err.rms_err);
  }
  printf("(* on the Pareto front: no other run is both faster and more accurate)\n");
  for (int t = 0; t < o.nmax_error; t++) {
    double target = o.max_error[t];
    int best = trade_cheapest(cpu, err, failed, nrun, target);
    if (t == 0) printf("\n");
    if (best < 0) printf("max_err <= %.3g: no run meets it\n", target);
    else {
      char s[300];
      run_settings(V, I, &R[best], s, sizeof s);
      printf("max_err <= %.3g: cheapest is run %d: %s: %.3g s CPU, max_err %.3e\n", target, best + 1, s,
             R[best].cpu, R[best].err.max_err);
    }
    if (target < ref_err.max_err)
      printf("warning: the target %.3g is below the reference's own error %.3e: tighten --ref-rtol\n", target,
             ref_err.max_err);
  }
  int st = write_csv(csv, V, I, R, nrun);
  if (!st) printf("wrote %s\n", csv);
  if (!st && strcmp(png, "none")) {
    char title[400];
    snprintf(title, sizeof title, "%s: max error vs CPU time (reference error %.2e)", name, ref_err.max_err);
    st = write_plot(png, title, R, nrun, ref_err.max_err);
    if (!st) printf("wrote %s\n", png);
    if (st < 0) st = 0;
  }
  return st;
}
