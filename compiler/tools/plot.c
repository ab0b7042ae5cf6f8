/* plot.c: see plot.h.  gnuplot draws; this file reads the CSV files (names,
 * units, the range of every column), decides what each panel shows, and
 * writes the gnuplot script.  gnuplot's own chatter goes to a file that is
 * shown only when gnuplot fails. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>
#include "bounds.h"
#include "plot.h"
#include "proc.h"

enum { PANELS_PER_PAGE = 8, MAX_CURVES = 16 };

const char *plot_keep_script;

/* below this fraction of its reference scale a variation is round-off */
#define ROUNDOFF 1e-12

typedef struct {
  char *name, *unit;       /* unit: "" when unknown */
  double lo, hi, maxabs;   /* over every row */
} column;

typedef struct {
  const char *path;
  column *col;
  int ncol, nrow;
  char *text; /* the header line, split in place */
} csvfile;

static void csv_free(csvfile *f) {
  for (int c = 0; c < f->ncol; c++) free(f->col[c].unit);
  free(f->col);
  free(f->text);
}

int csv_file_check(const char *path) {
  struct stat st;
  if (stat(path, &st)) { fprintf(stderr, "mbcc: error: cannot read '%s': %s\n", path, strerror(errno)); return 2; }
  if (!S_ISREG(st.st_mode)) {
    fprintf(stderr, "mbcc: error: '%s' is not a regular file (a results CSV is read whole)\n", path);
    return 2;
  }
  double limit = limit_value("MBCC_MAX_CSV", 1024.0 * 1024 * 1024);
  if ((double)st.st_size > limit) {
    fprintf(stderr, "mbcc: error: '%s' has %.0f bytes, more than the limit %.0f (MBCC_MAX_CSV=BYTES lifts it)\n",
            path, (double)st.st_size, limit);
    return 2;
  }
  return 0;
}

/* the header, the units file and the range of every column; 0 or 2 */
static int csv_read(const char *path, csvfile *f) {
  memset(f, 0, sizeof *f);
  f->path = path;
  if (csv_file_check(path)) return 2;
  FILE *in = fopen(path, "r");
  if (!in) { fprintf(stderr, "mbcc: error: cannot read '%s'\n", path); return 2; }
  size_t cap = 0;
  ssize_t len = getline(&f->text, &cap, in);
  if (len <= 0) { fclose(in); fprintf(stderr, "%s:1:1: error: empty CSV file\n", path); return 2; }
  f->text[strcspn(f->text, "\r\n")] = 0;
  int n = 1;
  for (char *p = f->text; *p; p++) n += *p == ',';
  f->col = calloc((size_t)n, sizeof *f->col);
  if (!f->col) { fclose(in); return 2; }
  char *save = NULL;
  for (char *tok = strtok_r(f->text, ",", &save); tok && f->ncol < n; tok = strtok_r(NULL, ",", &save)) {
    column *c = &f->col[f->ncol++];
    c->name = tok;
    c->lo = INFINITY; c->hi = -INFINITY;
  }
  char *line = NULL;
  size_t lcap = 0;
  int lineno = 1;
  while (getline(&line, &lcap, in) > 0) {
    lineno++;
    char *p = line;
    for (int c = 0; c < f->ncol; c++) {
      char *end;
      double x = strtod(p, &end);
      if (end == p || (*end != ',' && *end != '\n' && *end != '\r' && *end)) {
        fprintf(stderr, "%s:%d:%d: error: column '%s' is not a number\n", path, lineno, (int)(p - line) + 1,
                f->col[c].name);
        free(line); fclose(in); return 2;
      }
      column *k = &f->col[c];
      if (x < k->lo) k->lo = x;
      if (x > k->hi) k->hi = x;
      if (fabs(x) > k->maxabs) k->maxabs = fabs(x);
      p = *end == ',' ? end + 1 : end;
    }
    f->nrow++;
  }
  free(line);
  fclose(in);
  /* units: CSV.units, "column,unit" rows (mbcc run writes it) */
  char upath[4200];
  snprintf(upath, sizeof upath, "%s.units", path);
  FILE *u = fopen(upath, "r");
  char ul[512];
  while (u && fgets(ul, sizeof ul, u)) {
    ul[strcspn(ul, "\r\n")] = 0;
    char *comma = strchr(ul, ',');
    if (!comma) continue;
    *comma = 0;
    for (int c = 0; c < f->ncol; c++)
      if (!strcmp(f->col[c].name, ul) && !f->col[c].unit) f->col[c].unit = strdup(comma + 1);
  }
  if (u) fclose(u);
  for (int c = 0; c < f->ncol; c++)
    if (!f->col[c].unit) f->col[c].unit = strdup("");
  return 0;
}

static int find_column(const csvfile *f, const char *name) {
  for (int c = 1; c < f->ncol; c++)
    if (!strcmp(f->col[c].name, name)) return c;
  return -1;
}

/* the scale a column's variation is measured against: its own, or the
 * largest of its kin (the same unit when the units are known, else the same
 * output: the name before the '.') */
static double kin_scale(const csvfile *f, int c) {
  double s = f->col[c].maxabs;
  const char *dot = strchr(f->col[c].name, '.');
  size_t stem = dot ? (size_t)(dot - f->col[c].name) : strlen(f->col[c].name);
  for (int k = 1; k < f->ncol; k++) {
    int kin = f->col[c].unit[0] ? !strcmp(f->col[k].unit, f->col[c].unit)
                                : !strncmp(f->col[k].name, f->col[c].name, stem) &&
                                      (f->col[k].name[stem] == '.' || !f->col[k].name[stem]);
    if (kin && f->col[k].maxabs > s) s = f->col[k].maxabs;
  }
  return s;
}

/* gnuplot strings in single quotes: a quote is doubled */
static void quoted(FILE *g, const char *s) {
  fputc('\'', g);
  for (; *s; s++) {
    if (*s == '\'') fputc('\'', g);
    fputc(*s, g);
  }
  fputc('\'', g);
}

static const char *base_name(const char *p) {
  const char *s = strrchr(p, '/');
  return s ? s + 1 : p;
}

/* gnuplot SCRIPT, its output in LOG; its exit status.  Through proc_run, so
 * that gnuplot dies with mbcc and the temporary files go with it. */
static int run_gnuplot(const char *script, const char *log) {
  char *argv[] = {"sh", "-c", "exec gnuplot \"$1\" > \"$2\" 2>&1", "sh", (char *)script, (char *)log, NULL};
  return proc_run(argv);
}

/* gnuplot may say nothing of a failed write (a full disk): a picture is
 * complete when it ends with PNG's closing IEND chunk and has reached the disk */
static int png_complete(const char *path) {
  static const unsigned char iend[8] = {'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  unsigned char tail[8];
  int fd = open(path, O_RDONLY);
  struct stat ps;
  int ok = fd >= 0 && !fstat(fd, &ps) && ps.st_size >= 8 && pread(fd, tail, 8, ps.st_size - 8) == 8 &&
           !memcmp(tail, iend, 8) && !fsync(fd);
  if (fd >= 0) close(fd);
  return ok;
}

/* a temporary name of this process's own beside 'path' (mkstemp), registered
 * for removal if mbcc is killed; 0 or -1 */
static int temp_beside(const char *path, char *out, size_t n) {
  if (snprintf(out, n, "%s.XXXXXX", path) >= (int)n) { errno = ENAMETOOLONG; return -1; }
  int fd = mkstemp(out);
  if (fd < 0) return -1;
  close(fd);
  proc_cleanup_add(out);
  return 0;
}

static void temp_drop(const char *path) {
  unlink(path);
  proc_cleanup_remove(path);
}

/* page k (from 0) of png: png itself, then NAME-2.png, NAME-3.png ... */
static void page_name(const char *png, int k, char *out, size_t n) {
  if (k == 0) { snprintf(out, n, "%s", png); return; }
  const char *dot = strrchr(png, '.');
  const char *slash = strrchr(png, '/');
  if (!dot || (slash && dot < slash)) dot = png + strlen(png);
  snprintf(out, n, "%.*s-%d%s", (int)(dot - png), png, k + 1, dot);
}

/* one panel: every column of 'names' ("a+b") from every file */
static int panel_script(FILE *g, const csvfile *F, int ncsv, const char *names_in) {
  char names[1024];
  snprintf(names, sizeof names, "%s", names_in);
  struct { int f, c, mode; double value; char title[600]; } curve[MAX_CURVES];
  int n = 0, same_unit = 1;
  const char *unit = NULL;
  char *save = NULL;
  for (char *nm = strtok_r(names, "+", &save); nm; nm = strtok_r(NULL, "+", &save))
    for (int f = 0; f < ncsv && n < MAX_CURVES; f++) {
      int c = find_column(&F[f], nm);
      const column *k = &F[f].col[c];
      if (!unit) unit = k->unit;
      else if (strcmp(unit, k->unit)) same_unit = 0;
      double ref = kin_scale(&F[f], c), var = F[f].nrow ? k->hi - k->lo : 0;
      curve[n].f = f;
      curve[n].c = c;
      snprintf(curve[n].title, sizeof curve[n].title, "%s%s%s", nm, ncsv > 1 ? " " : "",
               ncsv > 1 ? base_name(F[f].path) : "");
      size_t t = strlen(curve[n].title);
      if (F[f].nrow && ref > k->maxabs && k->maxabs <= ROUNDOFF * ref) {
        /* round-off about zero: |y| below 1e-12 of its kin's scale */
        curve[n].mode = 1;
        curve[n].value = 0;
        if (k->maxabs > 0)
          snprintf(curve[n].title + t, sizeof curve[n].title - t, " = 0 (drawn so: |y| <= %.2g is round-off)", k->maxabs);
        else
          snprintf(curve[n].title + t, sizeof curve[n].title - t, " = 0 exactly");
      } else if (F[f].nrow && var <= ROUNDOFF * k->maxabs) {
        /* a constant (a conserved quantity): its variation is round-off */
        curve[n].mode = 1;
        curve[n].value = 0.5 * (k->hi + k->lo);
        if (var > 0)
          snprintf(curve[n].title + t, sizeof curve[n].title - t, " = %.12g (drawn constant: its variation %.2g is round-off)",
                   curve[n].value, var);
        else
          snprintf(curve[n].title + t, sizeof curve[n].title - t, " = %.12g, constant", curve[n].value);
      } else {
        curve[n].mode = 0;
      }
      n++;
    }
  /* one curve: the panel's title says what it is; several: a legend */
  fprintf(g, "set title ");
  quoted(g, n == 1 ? curve[0].title : names_in);
  char ylabel[300];
  snprintf(ylabel, sizeof ylabel, "%s", same_unit && unit && unit[0] ? unit : "");
  fprintf(g, "\nset ylabel ");
  if (ylabel[0]) {
    char lab[320];
    snprintf(lab, sizeof lab, "[%s]", ylabel);
    quoted(g, lab);
  } else {
    quoted(g, "");
  }
  fprintf(g, n > 1 ? "\nset key top left Left reverse opaque box font ',8'\n" : "\nunset key\n");
  fprintf(g, "plot ");
  for (int i = 0; i < n; i++) {
    if (i) fprintf(g, ", \\\n     ");
    quoted(g, F[curve[i].f].path);
    if (curve[i].mode) fprintf(g, " every ::1 using 1:(%.17g) with lines lw 1.5 title ", curve[i].value);
    else fprintf(g, " every ::1 using 1:%d with lines lw 1.5 title ", curve[i].c + 1);
    quoted(g, curve[i].title);
  }
  fputc('\n', g);
  return 0;
}

int plot_files(int ncsv, const char *const *csv, const char *png, const char *columns, int quiet) {
  csvfile *F = calloc((size_t)ncsv, sizeof *F);
  if (!F) return 2;
  int st = 0, nf = 0;
  for (; nf < ncsv && !st; nf++) st = csv_read(csv[nf], &F[nf]);
  /* the panels: lists of column names */
  char *spec = NULL;
  if (!st) {
    if (columns) spec = strdup(columns);
    else {
      size_t n = 1;
      for (int c = 1; c < F[0].ncol; c++) n += strlen(F[0].col[c].name) + 1;
      spec = calloc(n, 1);
      for (int c = 1; spec && c < F[0].ncol; c++) {
        if (!strncmp(F[0].col[c].name, "body.", 5)) continue; /* run --animate's pose columns: for the animation */
        if (spec[0]) strcat(spec, ",");
        strcat(spec, F[0].col[c].name);
      }
    }
    if (!spec) st = 2;
  }
  char **panel = NULL;
  int npanel = 0;
  if (!st) {
    panel = calloc(strlen(spec) + 1, sizeof *panel);
    char *save = NULL;
    for (char *tok = strtok_r(spec, ",", &save); panel && tok; tok = strtok_r(NULL, ",", &save)) panel[npanel++] = tok;
    if (!panel) st = 2;
    else if (npanel == 0) { fprintf(stderr, "mbcc: error: no columns to plot in '%s'\n", csv[0]); st = 2; }
  }
  /* every name in every file, else an error listing the file's columns */
  for (int p = 0; !st && p < npanel; p++) {
    char names[1024];
    snprintf(names, sizeof names, "%s", panel[p]);
    char *save = NULL;
    int ncurve = 0;
    for (char *nm = strtok_r(names, "+", &save); nm && !st; nm = strtok_r(NULL, "+", &save))
      for (int f = 0; f < ncsv && !st; f++) {
        ncurve++;
        if (find_column(&F[f], nm) >= 0) continue;
        fprintf(stderr, "mbcc: error: no column '%s' in '%s' (it has:", nm, csv[f]);
        for (int c = 1; c < F[f].ncol; c++) fprintf(stderr, "%s%s", c > 1 ? ", " : " ", F[f].col[c].name);
        fprintf(stderr, ")\n");
        st = 2;
      }
    if (!st && ncurve > MAX_CURVES) {
      fprintf(stderr, "mbcc: error: panel '%s' has %d curves (at most %d)\n", panel[p], ncurve, MAX_CURVES);
      st = 2;
    }
  }
  /* the script, gnuplot's log and every page under names of this process's
     own; a page replaces the old picture only when gnuplot finished it */
  char script[4200], log[4200];
  int npages = (npanel + PANELS_PER_PAGE - 1) / PANELS_PER_PAGE;
  char (*part)[4300] = st ? NULL : calloc((size_t)npages + 1, sizeof *part);
  int nparts = 0;
  if (!st && !part) st = 2;
  if (!st && plot_keep_script) snprintf(script, sizeof script, "%s", plot_keep_script);
  else if (!st && temp_beside(png, script, sizeof script)) {
    fprintf(stderr, "mbcc: error: cannot write beside '%s': %s\n", png, strerror(errno));
    st = 2;
  }
  int have_script = !st && !plot_keep_script, have_log = 0;
  if (!st) {
    if (temp_beside(png, log, sizeof log)) {
      fprintf(stderr, "mbcc: error: cannot write beside '%s': %s\n", png, strerror(errno));
      st = 2;
    } else have_log = 1;
  }
  for (; !st && nparts < npages; nparts++) {
    char out[4300];
    page_name(png, nparts, out, sizeof out);
    if (temp_beside(out, part[nparts], sizeof part[nparts])) {
      fprintf(stderr, "mbcc: error: cannot write beside '%s': %s\n", out, strerror(errno));
      st = 2;
      break;
    }
  }
  FILE *g = st ? NULL : fopen(script, "w");
  if (!st && !g) { fprintf(stderr, "mbcc: error: cannot write '%s'\n", script); st = 2; }
  for (int page = 0; g && page < npages; page++) {
    int first = page * PANELS_PER_PAGE, count = npanel - first;
    if (count > PANELS_PER_PAGE) count = PANELS_PER_PAGE;
    int rows = (count + 1) / 2, cols = count > 1 ? 2 : 1;
    fprintf(g, "set terminal pngcairo size %d,%d noenhanced font ',9'\nset output ", 560 * cols, 320 * rows);
    quoted(g, part[page]);
    fprintf(g, "\nset datafile separator ','\nset grid\nset xlabel 't [%s]'\nset multiplot layout %d,%d\n",
            F[0].col[0].unit[0] ? F[0].col[0].unit : "s", rows, cols);
    for (int p = first; p < first + count; p++)
      if (panel_script(g, F, ncsv, panel[p])) st = 2;
    fprintf(g, "unset multiplot\nunset output\n");
  }
  if (g) {
    int bad = ferror(g);
    if (fclose(g) || bad) { fprintf(stderr, "mbcc: error: cannot write '%s'\n", script); st = 2; }
  }
  if (!st) {
    int rc = run_gnuplot(script, log);
    if (rc) {
      fprintf(stderr, "mbcc: error: gnuplot failed (status %d)", rc);
      FILE *l = fopen(log, "r");
      char line[512];
      fprintf(stderr, "%s\n", l ? ":" : "");
      while (l && fgets(line, sizeof line, l)) fprintf(stderr, "  %s", line);
      if (l) fclose(l);
      st = 2;
    }
    for (int page = 0; !st && page < npages; page++)
      if (!png_complete(part[page])) {
        fprintf(stderr, "mbcc: error: gnuplot wrote no complete picture (a full disk?); '%s' left as it was\n", png);
        st = 2;
      }
    for (int page = 0; !st && page < npages; page++) {
      char out[4300];
      page_name(png, page, out, sizeof out);
      if (rename(part[page], out)) {
        fprintf(stderr, "mbcc: error: cannot write '%s': %s\n", out, strerror(errno));
        st = 2;
      } else {
        proc_cleanup_remove(part[page]);
        if (!quiet) printf("wrote %s\n", out);
      }
    }
  }
  for (int page = 0; page < nparts; page++) temp_drop(part[page]);
  free(part);
  if (have_script) temp_drop(script);
  if (have_log) temp_drop(log);
  free(panel);
  free(spec);
  for (int f = 0; f < nf; f++) csv_free(&F[f]);
  free(F);
  return st;
}
