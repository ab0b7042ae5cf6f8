/* sweep.c: see sweep.h.  The runs are independent processes of the one
 * compiled simulator, so the distribution is left to GNU parallel (a job
 * list, -j, --sshlogin) or to Slurm (a job array over the same list);
 * mbcc only designs, writes the list and merges. */
#define _XOPEN_SOURCE 700
#include "sweep.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "bounds.h"
#include "outfile.h"
#include "proc.h"

static int parse_number(const char *s, size_t len, double *x) {
  char buf[64];
  if (len == 0 || len >= sizeof buf) return -1;
  memcpy(buf, s, len);
  buf[len] = 0;
  char *end;
  errno = 0;
  *x = strtod(buf, &end);
  return (*end || errno || !isfinite(*x)) ? -1 : 0;
}

static int parse_vary_values(const char *arg, sweep_var *v) {
  memset(v, 0, sizeof *v);
  const char *eq = strchr(arg, '=');
  if (!eq || eq == arg || (size_t)(eq - arg) >= sizeof v->name) {
    fprintf(stderr, "mbcc: error: '--vary %s' needs NAME=v1,v2,... or NAME=lo:hi:n or NAME=lo:hi\n", arg);
    return 2;
  }
  memcpy(v->name, arg, (size_t)(eq - arg));
  const char *spec = eq + 1;
  if (strchr(spec, ':')) {
    /* lo:hi[:n[:log]] */
    const char *f[4];
    size_t len[4];
    int nf = 0;
    for (const char *p = spec; nf < 4;) {
      const char *c = strchr(p, ':');
      f[nf] = p;
      len[nf++] = c ? (size_t)(c - p) : strlen(p);
      if (!c) break;
      p = c + 1;
    }
    double n = 0;
    if (nf < 2 || parse_number(f[0], len[0], &v->lo) || parse_number(f[1], len[1], &v->hi) ||
        (nf >= 3 && (parse_number(f[2], len[2], &n) || n != floor(n) || n < 2 || n > SWEEP_MAX_RUNS)) ||
        (nf == 4 && (len[3] != 3 || strncmp(f[3], "log", 3)))) {
      fprintf(stderr, "mbcc: error: '--vary %s': expected lo:hi (a range), lo:hi:n (n >= 2 values) "
              "or lo:hi:n:log\n", arg);
      return 2;
    }
    if (!(v->hi > v->lo)) {
      fprintf(stderr, "mbcc: error: '--vary %s': hi must be greater than lo\n", arg);
      return 2;
    }
    v->logspace = nf == 4;
    if (v->logspace && !(v->lo > 0)) {
      fprintf(stderr, "mbcc: error: '--vary %s': a logarithmic range needs lo > 0\n", arg);
      return 2;
    }
    if (nf >= 3) {
      v->nvalue = (int)n;
      v->values = malloc((size_t)v->nvalue * sizeof(double));
      if (!v->values) { fprintf(stderr, "mbcc: error: out of memory\n"); return 2; }
      for (int i = 0; i < v->nvalue; i++) {
        double s = (double)i / (v->nvalue - 1);
        v->values[i] = v->logspace ? v->lo * pow(v->hi / v->lo, s) : v->lo + s * (v->hi - v->lo);
      }
      v->values[v->nvalue - 1] = v->hi; /* exactly the given end */
    }
    return 0;
  }
  int n = 1;
  for (const char *p = spec; *p; p++) n += *p == ',';
  v->values = malloc((size_t)n * sizeof(double));
  if (!v->values) { fprintf(stderr, "mbcc: error: out of memory\n"); return 2; }
  for (const char *p = spec;;) {
    const char *c = strchr(p, ',');
    size_t len = c ? (size_t)(c - p) : strlen(p);
    if (parse_number(p, len, &v->values[v->nvalue])) {
      fprintf(stderr, "mbcc: error: '--vary %s': '%.*s' is not a number\n", arg, (int)len, p);
      return 2;
    }
    v->nvalue++;
    if (!c) break;
    p = c + 1;
  }
  return 0;
}

/* the reader's bound on the size of a number in the file (bounds.h), for
 * the values a sweep sets too: beyond it a run would stop at t = 0 */
static int beyond_limit(const char *arg, double x) {
  if (!(fabs(x) > LIMIT_MAGNITUDE)) return 0;
  fprintf(stderr, "mbcc: error: '--vary %s': %g is beyond the limit %g on the size of a number\n", arg, x,
          LIMIT_MAGNITUDE);
  return 1;
}

int sweep_parse_vary(const char *arg, sweep_var *v) {
  if (parse_vary_values(arg, v)) return 2;
  int bad = !v->nvalue && (beyond_limit(arg, v->lo) || beyond_limit(arg, v->hi));
  for (int i = 0; i < v->nvalue && !bad; i++) bad = beyond_limit(arg, v->values[i]);
  return bad ? 2 : 0;
}

/* splitmix64: a small reproducible generator for the Latin hypercube */
static unsigned long long next_random(unsigned long long *s) {
  unsigned long long z = (*s += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}
static double uniform01(unsigned long long *s) { return (double)(next_random(s) >> 11) * 0x1.0p-53; }

static double var_middle(const sweep_var *v) {
  if (v->nvalue) return v->values[(v->nvalue - 1) / 2];
  return v->logspace ? sqrt(v->lo * v->hi) : 0.5 * (v->lo + v->hi);
}

int sweep_design(const sweep_plan *p, const double *baseline, double **table, int *nrun) {
  *table = NULL;
  *nrun = 0;
  int nv = p->nvar;
  if (p->design != SWEEP_LHS)
    for (int k = 0; k < nv; k++)
      if (!p->var[k].nvalue) {
        fprintf(stderr, "mbcc: error: '--vary %s=lo:hi' is a range: the %s design needs values "
                "(lo:hi:n or a list), or use --design lhs --samples N\n", p->var[k].name,
                p->design == SWEEP_FULL ? "full" : "oat");
        return 2;
      }
  long long n = 0;
  if (p->design == SWEEP_FULL) {
    n = 1;
    for (int k = 0; k < nv && n <= SWEEP_MAX_RUNS; k++) n *= p->var[k].nvalue;
  } else if (p->design == SWEEP_LHS) {
    if (p->samples < 1) {
      fprintf(stderr, "mbcc: error: --design lhs needs --samples N (N >= 1)\n");
      return 2;
    }
    n = p->samples;
  } else {
    n = 1;
    for (int k = 0; k < nv; k++) n += p->var[k].nvalue;
  }
  if (n > SWEEP_MAX_RUNS) {
    fprintf(stderr, "mbcc: error: the design has %lld runs; the limit is %d\n", n, SWEEP_MAX_RUNS);
    return 2;
  }
  double *t = malloc((size_t)(n * (nv ? nv : 1)) * sizeof(double));
  if (!t) { fprintf(stderr, "mbcc: error: out of memory for %lld runs\n", n); return 2; }
  if (p->design == SWEEP_FULL) {
    /* the last variable varies fastest */
    for (long long r = 0; r < n; r++) {
      long long rest = r;
      for (int k = nv - 1; k >= 0; k--) {
        t[r * nv + k] = p->var[k].values[rest % p->var[k].nvalue];
        rest /= p->var[k].nvalue;
      }
    }
  } else if (p->design == SWEEP_LHS) {
    /* each variable's range cut into n strata, one sample in each, the
       strata of the variables paired by independent random permutations */
    unsigned long long s = p->seed;
    int *perm = malloc((size_t)n * sizeof(int));
    if (!perm) { free(t); fprintf(stderr, "mbcc: error: out of memory\n"); return 2; }
    for (int k = 0; k < nv; k++) {
      const sweep_var *v = &p->var[k];
      for (int i = 0; i < n; i++) perm[i] = i;
      for (int i = (int)n - 1; i > 0; i--) {
        int j = (int)(next_random(&s) % (unsigned long long)(i + 1));
        int x = perm[i]; perm[i] = perm[j]; perm[j] = x;
      }
      double lo = v->nvalue ? v->values[0] : v->lo, hi = v->nvalue ? v->values[v->nvalue - 1] : v->hi;
      for (int i = 0; i < n; i++) {
        double u = (perm[i] + uniform01(&s)) / (double)n;
        t[(long long)i * nv + k] = v->logspace ? lo * pow(hi / lo, u) : lo + u * (hi - lo);
      }
    }
    free(perm);
  } else {
    /* one at a time: the baseline, then each variable over its values with
       the others at their baselines */
    double base[SWEEP_MAX_VARS];
    for (int k = 0; k < nv; k++)
      base[k] = baseline && !isnan(baseline[k]) ? baseline[k] : var_middle(&p->var[k]);
    long long r = 0;
    for (int k = 0; k < nv; k++) t[k] = base[k];
    r = 1;
    for (int k = 0; k < nv; k++)
      for (int i = 0; i < p->var[k].nvalue; i++) {
        if (p->var[k].values[i] == base[k]) continue; /* the baseline run already has it */
        for (int j = 0; j < nv; j++) t[r * nv + j] = base[j];
        t[r * nv + k] = p->var[k].values[i];
        r++;
      }
    n = r;
  }
  *table = t;
  *nrun = (int)n;
  return 0;
}

/* the shortest of %.15g, %.16g, %.17g that reads back as x: what the
 * design and the jobs say is exactly the run's value */
static const char *shortest(char buf[32], double x) {
  for (int digits = 15; digits <= 17; digits++) {
    snprintf(buf, 32, "%.*g", digits, x);
    if (strtod(buf, NULL) == x) break;
  }
  return buf;
}

/* s in single quotes for the shell */
static void shell_quote(FILE *f, const char *s) {
  fputc('\'', f);
  for (; *s; s++)
    if (*s == '\'') fputs("'\\''", f);
    else fputc(*s, f);
  fputc('\'', f);
}

static int make_dir(const char *path) {
  if (mkdir(path, 0777) && errno != EEXIST) {
    fprintf(stderr, "mbcc: error: cannot make the directory '%s': %s\n", path, strerror(errno));
    return 2;
  }
  return 0;
}

/* the runs' files of an earlier sweep in the same directory would be merged
   as this one's: removed first */
static void clear_runs(const char *runs) {
  DIR *d = opendir(runs);
  if (!d) return;
  char path[8400];
  for (struct dirent *e; (e = readdir(d));) {
    if (strncmp(e->d_name, "run_", 4)) continue;
    snprintf(path, sizeof path, "%s/%s", runs, e->d_name);
    unlink(path);
  }
  closedir(d);
}

int sweep_write_jobs(const char *dir, const char *exe, const sweep_plan *p, const double *table,
                     int nrun, char *const fixed_args[]) {
  char adir[PATH_MAX], aexe[PATH_MAX], runs[PATH_MAX + 8], path[PATH_MAX + 32];
  if (make_dir(dir)) return 2;
  if (!realpath(dir, adir) || !realpath(exe, aexe)) {
    fprintf(stderr, "mbcc: error: cannot resolve '%s': %s\n", realpath(dir, adir) ? exe : dir, strerror(errno));
    return 2;
  }
  snprintf(runs, sizeof runs, "%s/runs", adir);
  if (make_dir(runs)) return 2;
  clear_runs(runs);
  int nv = p->nvar;
  snprintf(path, sizeof path, "%s/design.csv", adir);
  out_file df;
  if (out_file_open(&df, path)) return 2;
  FILE *f = df.f;
  fprintf(f, "run");
  for (int k = 0; k < nv; k++) fprintf(f, ",%s", p->var[k].name);
  fputc('\n', f);
  for (int r = 0; r < nrun; r++) {
    fprintf(f, "%d", r + 1);
    char b[32];
    for (int k = 0; k < nv; k++) fprintf(f, ",%s", shortest(b, table[(long long)r * nv + k]));
    fputc('\n', f);
  }
  if (out_file_commit(&df)) return 2;
  snprintf(path, sizeof path, "%s/jobs.txt", adir);
  out_file jf;
  if (out_file_open(&jf, path)) return 2;
  f = jf.f;
  for (int r = 0; r < nrun; r++) {
    /* the simulator's exit status goes to run_N.status whatever it is: the
       merge tells a failed run from one that never ran */
    char base[PATH_MAX + 32];
    snprintf(base, sizeof base, "%s/run_%06d", runs, r + 1);
    shell_quote(f, aexe);
    fputs(" --quiet -o ", f);
    char csv[PATH_MAX + 40];
    snprintf(csv, sizeof csv, "%s.csv", base);
    shell_quote(f, csv);
    for (int i = 0; fixed_args && fixed_args[i]; i++) {
      fputc(' ', f);
      shell_quote(f, fixed_args[i]);
    }
    char b[32];
    for (int k = 0; k < nv; k++) fprintf(f, " --set %s=%s", p->var[k].name, shortest(b, table[(long long)r * nv + k]));
    fputs(" 2>", f);
    snprintf(csv, sizeof csv, "%s.log", base);
    shell_quote(f, csv);
    fputs("; echo $? >", f);
    snprintf(csv, sizeof csv, "%s.status", base);
    shell_quote(f, csv);
    fputc('\n', f);
  }
  return out_file_commit(&jf) ? 2 : 0;
}

static int count_status_files(const char *runs) {
  DIR *d = opendir(runs);
  if (!d) return 0;
  int n = 0;
  for (struct dirent *e; (e = readdir(d));) {
    size_t len = strlen(e->d_name);
    n += len > 7 && !strcmp(e->d_name + len - 7, ".status");
  }
  closedir(d);
  return n;
}

typedef struct {
  const char *runs;
  int nrun, last;
} progress;

/* on a terminal one line rewritten in place, else a line per tenth */
static void show_progress(void *user) {
  progress *pr = user;
  int done = count_status_files(pr->runs);
  if (done == pr->last) return;
  if (isatty(2)) fprintf(stderr, "\rmbcc sweep: %d / %d runs done", done, pr->nrun);
  else if (pr->last < 0 || done * 10 / pr->nrun != pr->last * 10 / pr->nrun)
    fprintf(stderr, "mbcc sweep: %d / %d runs done\n", done, pr->nrun);
  pr->last = done;
}

int sweep_run_parallel(const char *dir, int nrun, int jobs, const char *sshlogin, int quiet) {
  char adir[PATH_MAX], jobfile[PATH_MAX + 16], joblog[PATH_MAX + 16], runs[PATH_MAX + 8], j[32];
  if (!realpath(dir, adir)) {
    fprintf(stderr, "mbcc: error: cannot resolve '%s': %s\n", dir, strerror(errno));
    return 2;
  }
  snprintf(jobfile, sizeof jobfile, "%s/jobs.txt", adir);
  snprintf(joblog, sizeof joblog, "%s/joblog.txt", adir);
  snprintf(runs, sizeof runs, "%s/runs", adir);
  snprintf(j, sizeof j, jobs > 0 ? "%d" : "100%%", jobs);
  char *argv[16];
  int na = 0;
  argv[na++] = "parallel";
  argv[na++] = "--will-cite";
  argv[na++] = "--jobs";
  argv[na++] = j;
  argv[na++] = "--joblog";
  argv[na++] = joblog;
  if (sshlogin) {
    argv[na++] = "--sshlogin";
    argv[na++] = (char *)sshlogin;
  }
  argv[na++] = "--arg-file";
  argv[na++] = jobfile;
  argv[na] = NULL;
  remove(joblog);
  progress pr = {runs, nrun, -1};
  int rc = proc_run_watch(argv, quiet ? NULL : show_progress, &pr);
  if (!quiet) {
    show_progress(&pr);
    if (isatty(2)) fputc('\n', stderr);
  }
  if (rc == 127 || rc < 0) {
    fprintf(stderr, "mbcc: error: cannot run GNU parallel (Debian package 'parallel')\n");
    return 2;
  }
  if (rc) fprintf(stderr, "mbcc: note: GNU parallel exited with status %d (see %s)\n", rc, joblog);
  return 0;
}

int sweep_write_slurm(const char *dir, const char *script, const char *model_name, int nrun, int jobs) {
  char adir[PATH_MAX];
  if (!realpath(dir, adir)) {
    fprintf(stderr, "mbcc: error: cannot resolve '%s': %s\n", dir, strerror(errno));
    return 2;
  }
  out_file sf;
  if (out_file_open(&sf, script)) return 2;
  FILE *f = sf.f;
  fprintf(f, "#!/bin/bash\n"
             "# Slurm job array of an mbcc sweep of %s: task k runs line k of jobs.txt.\n"
             "# Submit with: sbatch %s\n"
             "# then merge with: mbcc sweep --merge %s [--metric ...] [--csv FILE]\n",
          model_name, script, adir);
  fprintf(f, "#SBATCH --job-name=mbcc-sweep-%s\n", model_name);
  if (jobs > 0) fprintf(f, "#SBATCH --array=1-%d%%%d\n", nrun, jobs);
  else fprintf(f, "#SBATCH --array=1-%d\n", nrun);
  fprintf(f, "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n");
  fprintf(f, "#SBATCH --output=");
  shell_quote(f, adir);
  fprintf(f, "/runs/slurm_%%a.out\n");
  fprintf(f, "set -u\njobs=");
  shell_quote(f, adir);
  fprintf(f, "/jobs.txt\n"
             "line=$(sed -n \"${SLURM_ARRAY_TASK_ID}p\" \"$jobs\")\n"
             "if [ -z \"$line\" ]; then echo \"no job $SLURM_ARRAY_TASK_ID in $jobs\" >&2; exit 2; fi\n"
             "exec bash -c \"$line\"\n");
  if (out_file_commit(&sf)) return 2;
  chmod(script, 0755);
  return 0;
}

/* ---- merge ---- */

typedef enum { STAT_MAX, STAT_MIN, STAT_MAXABS, STAT_FINAL, STAT_MEAN, STAT_RMS } stat_kind;
static const char *const stat_names[] = {"max", "min", "maxabs", "final", "mean", "rms"};

typedef struct {
  char column[256];
  stat_kind stat;
} metric;

static int parse_metric(const char *s, metric *m) {
  const char *c = strrchr(s, ':');
  if (!c || c == s || (size_t)(c - s) >= sizeof m->column) goto bad;
  memcpy(m->column, s, (size_t)(c - s));
  m->column[c - s] = 0;
  for (int k = 0; k < 6; k++)
    if (!strcmp(c + 1, stat_names[k])) { m->stat = (stat_kind)k; return 0; }
bad:
  fprintf(stderr, "mbcc: error: '--metric %s': expected COLUMN:STAT with STAT one of max, min, maxabs, "
          "final, mean, rms\n", s);
  return 2;
}

/* one CSV line, split on commas in place */
static int split(char *line, char **field, int max) {
  int n = 0;
  line[strcspn(line, "\r\n")] = 0;
  for (char *p = line; n < max;) {
    field[n++] = p;
    char *c = strchr(p, ',');
    if (!c) break;
    *c = 0;
    p = c + 1;
  }
  return n;
}

typedef struct {
  double max, min, maxabs, final, sum, sumsq;
  long n;
} column_stats;

/* the statistics of every column of a run's CSV; NULL and a reason if unreadable */
static column_stats *read_run(const char *path, char ***names, int *ncol, const char **why) {
  FILE *f = fopen(path, "r");
  if (!f) { *why = "no results (the run failed or did not run)"; return NULL; }
  char *line = NULL;
  size_t cap = 0;
  column_stats *st = NULL;
  char *field[4096];
  if (getline(&line, &cap, f) < 0) { *why = "empty results file"; goto fail; }
  int nc = split(line, field, 4096);
  if (nc < 2 || nc >= 4096) { *why = "no output columns"; goto fail; }
  *ncol = nc - 1;
  *names = calloc((size_t)nc, sizeof(char *));
  st = calloc((size_t)nc, sizeof *st);
  if (!*names || !st) { *why = "out of memory"; goto fail; }
  for (int j = 1; j < nc; j++) (*names)[j - 1] = strdup(field[j]);
  for (int j = 0; j < nc - 1; j++) { st[j].max = -INFINITY; st[j].min = INFINITY; }
  while (getline(&line, &cap, f) >= 0) {
    int n = split(line, field, 4096);
    if (n != nc) { *why = "a row with the wrong number of values"; goto fail; }
    for (int j = 1; j < nc; j++) {
      char *end;
      double x = strtod(field[j], &end);
      if (end == field[j] || *end || !isfinite(x)) { *why = "a value that is not a finite number"; goto fail; }
      column_stats *s = &st[j - 1];
      if (x > s->max) s->max = x;
      if (x < s->min) s->min = x;
      if (fabs(x) > s->maxabs) s->maxabs = fabs(x);
      s->final = x;
      s->sum += x;
      s->sumsq += x * x;
      s->n++;
    }
  }
  if (!st[0].n) { *why = "no rows"; goto fail; }
  free(line);
  fclose(f);
  return st;
fail:
  free(line);
  fclose(f);
  if (*names)
    for (int j = 0; j < *ncol; j++) free((*names)[j]);
  free(*names);
  *names = NULL;
  free(st);
  return NULL;
}

static double stat_value(const column_stats *s, stat_kind k) {
  switch (k) {
  case STAT_MAX: return s->max;
  case STAT_MIN: return s->min;
  case STAT_MAXABS: return s->maxabs;
  case STAT_FINAL: return s->final;
  case STAT_MEAN: return s->sum / (double)s->n;
  case STAT_RMS: return sqrt(s->sumsq / (double)s->n);
  }
  return NAN;
}

static void last_line_of(const char *path, char *out, size_t n) {
  out[0] = 0;
  FILE *f = fopen(path, "r");
  if (!f) return;
  char line[512];
  while (fgets(line, sizeof line, f))
    if (line[0] != '\n') snprintf(out, n, "%s", line);
  fclose(f);
  out[strcspn(out, "\r\n")] = 0;
}

static void free_names(char **names, int n) {
  if (names)
    for (int j = 0; j < n; j++) free(names[j]);
  free(names);
}

int sweep_merge(const char *dir, const sweep_plan *p, const char *out_csv, int quiet) {
  char path[PATH_MAX + 64];
  snprintf(path, sizeof path, "%s/design.csv", dir);
  FILE *df = fopen(path, "r");
  if (!df) {
    fprintf(stderr, "mbcc: error: cannot read '%s': %s (not a sweep directory?)\n", path, strerror(errno));
    return 2;
  }
  metric mt[SWEEP_MAX_METRICS];
  int nm = 0;
  for (int i = 0; i < p->nmetric; i++)
    if (parse_metric(p->metric[i], &mt[nm++])) { fclose(df); return 2; }
  /* the design's rows */
  char *line = NULL, **rows = NULL;
  size_t cap = 0;
  int nrow = 0, rows_cap = 0;
  while (getline(&line, &cap, df) >= 0) {
    line[strcspn(line, "\r\n")] = 0;
    if (!line[0]) continue;
    if (nrow == rows_cap) {
      rows_cap = rows_cap ? 2 * rows_cap : 256;
      char **r = realloc(rows, (size_t)rows_cap * sizeof *rows);
      if (!r) { fprintf(stderr, "mbcc: error: out of memory\n"); free_names(rows, nrow); free(line); fclose(df); return 2; }
      rows = r;
    }
    rows[nrow++] = strdup(line);
  }
  free(line);
  fclose(df);
  int rc = 0;
  if (nrow < 2) {
    fprintf(stderr, "mbcc: error: '%s' lists no runs\n", path);
    free_names(rows, nrow);
    return 2;
  }
  /* the first run with results fixes the columns; the metrics default to
     the maximum and minimum of every output column */
  char **cols = NULL;
  int ncol = 0;
  for (int r = 1; r < nrow && !cols; r++) {
    char csv[PATH_MAX + 64];
    snprintf(csv, sizeof csv, "%s/runs/run_%06d.csv", dir, atoi(rows[r]));
    const char *why;
    column_stats *st = read_run(csv, &cols, &ncol, &why);
    free(st);
  }
  if (!cols) {
    char log[PATH_MAX + 64], reason[512];
    snprintf(log, sizeof log, "%s/runs/run_%06d.log", dir, atoi(rows[1]));
    last_line_of(log, reason, sizeof reason);
    fprintf(stderr, "mbcc: error: none of the %d runs has results: nothing to merge (run %d: %s; the "
            "runs' messages are in %s/runs/run_*.log)\n", nrow - 1, atoi(rows[1]),
            reason[0] ? reason : "no message", dir);
    free_names(rows, nrow);
    return 2;
  }
  if (!nm)
    for (int j = 0; j < ncol && nm + 2 <= SWEEP_MAX_METRICS; j++) {
      snprintf(mt[nm].column, sizeof mt[nm].column, "%s", cols[j]);
      mt[nm++].stat = STAT_MAX;
      snprintf(mt[nm].column, sizeof mt[nm].column, "%s", cols[j]);
      mt[nm++].stat = STAT_MIN;
    }
  int mcol[SWEEP_MAX_METRICS];
  for (int i = 0; i < nm; i++) {
    mcol[i] = -1;
    for (int j = 0; j < ncol && mcol[i] < 0; j++)
      if (!strcmp(cols[j], mt[i].column)) mcol[i] = j;
    if (mcol[i] < 0) {
      fprintf(stderr, "mbcc: error: no column '%s' in the results (they have:", mt[i].column);
      for (int j = 0; j < ncol; j++) fprintf(stderr, " %s", cols[j]);
      fprintf(stderr, ")\n");
      rc = 2;
    }
  }
  out_file of;
  if (rc || out_file_open(&of, out_csv)) {
    free_names(cols, ncol);
    free_names(rows, nrow);
    return 2;
  }
  FILE *out = of.f;
  fprintf(out, "%s,status", rows[0]);
  for (int i = 0; i < nm; i++) fprintf(out, ",%s.%s", mt[i].column, stat_names[mt[i].stat]);
  fputc('\n', out);
  int nfailed = 0;
  for (int r = 1; r < nrow; r++) {
    int run = atoi(rows[r]);
    char csv[PATH_MAX + 64], status[PATH_MAX + 64], log[PATH_MAX + 64];
    snprintf(csv, sizeof csv, "%s/runs/run_%06d.csv", dir, run);
    snprintf(status, sizeof status, "%s/runs/run_%06d.status", dir, run);
    snprintf(log, sizeof log, "%s/runs/run_%06d.log", dir, run);
    char **names = NULL;
    int nc = 0;
    const char *why = NULL;
    column_stats *st = read_run(csv, &names, &nc, &why);
    char exitline[64] = "";
    last_line_of(status, exitline, sizeof exitline);
    if (st && exitline[0] && strcmp(exitline, "0")) why = "the simulator failed";
    if (st && !why) {
      if (nc != ncol) why = "different columns from the other runs";
      for (int j = 0; j < nc && !why; j++)
        if (strcmp(names[j], cols[j])) why = "different columns from the other runs";
    }
    if (st && !why) {
      fprintf(out, "%s,ok", rows[r]);
      for (int i = 0; i < nm; i++) fprintf(out, ",%.17g", stat_value(&st[mcol[i]], mt[i].stat));
      fputc('\n', out);
    } else {
      char reason[512];
      last_line_of(log, reason, sizeof reason);
      fprintf(stderr, "mbcc: run %d failed: %s%s%s\n", run, why, reason[0] ? ": " : "", reason);
      nfailed++;
      fprintf(out, "%s,failed", rows[r]);
      for (int i = 0; i < nm; i++) fputc(',', out);
      fputc('\n', out);
    }
    free_names(names, nc);
    free(st);
  }
  free_names(cols, ncol);
  free_names(rows, nrow);
  if (out_file_commit(&of)) return 2;
  if (!quiet)
    fprintf(stderr, "mbcc sweep: %d runs, %d failed; merged into %s\n", nrow - 1, nfailed, out_csv);
  return nfailed ? 1 : 0;
}

void sweep_plan_free(sweep_plan *p) {
  for (int k = 0; k < p->nvar; k++) free(p->var[k].values);
  p->nvar = 0;
}
