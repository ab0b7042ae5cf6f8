/* animate.c: `mbcc animate`: one self-contained HTML page that plays the
 * motion of a result.  The page is templates/animate.html.in with the player
 * script (web/player.js bundled with three.js by `make web`) and the data
 * inlined, so that nothing is fetched when it is viewed.
 *
 * The data: the output times; per body its position and Euler parameters at
 * every time (the pose columns that `mbcc run --animate` adds, see
 * animate_add_pose_outputs), the points to draw in body axes (its joint and
 * marker points, from the lowered model), its optional shape, and for a
 * flexible body the undeformed FE nodes, the beams, the translational mode
 * shapes at the nodes and the modal coordinates at every time. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "paths.h"
#include "animate.h"
#include "plot.h"
#include "diag.h"
#include "element.h"
#include "flex.h"
#include "lower.h"
#include "unit.h"

#ifndef MBCC_ROOT
#define MBCC_ROOT "."
#endif
#ifndef MBCC_PLAYER_JS
#define MBCC_PLAYER_JS MBCC_ROOT "/build/web/player.js"
#endif

/* the bundled player: $MBCC_PLAYER_JS, an installed one (PREFIX/share/mbcc,
   compiler/paths.c), or the one `make web` built */
static const char *player_path(void) {
  const char *p = getenv("MBCC_PLAYER_JS");
  if (p && *p) return p;
  p = mbcc_installed_file("player.js");
  return p ? p : MBCC_PLAYER_JS;
}

static char *read_all(const char *path, size_t *len) {
  FILE *f = fopen(path, "rb");
  if (!f) return NULL;
  size_t cap = 1 << 16, n = 0;
  char *buf = malloc(cap + 1);
  size_t got;
  while (buf && (got = fread(buf + n, 1, cap - n, f)) > 0) {
    n += got;
    if (n == cap) {
      char *nb = realloc(buf, 2 * cap + 1);
      if (!nb) { free(buf); buf = NULL; break; }
      buf = nb;
      cap *= 2;
    }
  }
  fclose(f);
  if (buf) buf[n] = 0;
  if (len) *len = n;
  return buf;
}

/* --- the pose outputs -------------------------------------------------------- */

static char *printf_dup(const char *fmt, const char *a, int j) {
  size_t n = (size_t)snprintf(NULL, 0, fmt, a, j) + 1;
  char *s = malloc(n);
  if (s) snprintf(s, n, fmt, a, j);
  return s;
}

/* modes the simulation gives body B (0 for coupling 'rigid'), or -1 after reporting */
static int body_modes(const ir_model *ir, const ir_body *B) {
  if (B->flex->coupling == COUPLING_RIGID) return 0;
  fe_modes fm;
  if (flex_compute_modes(ir->path, B, &fm)) return -1;
  int nm = fm.nmodes;
  fe_modes_free(&fm);
  return nm;
}

int animate_add_pose_outputs(ir_model *ir) {
  int extra = 0;
  int *nm = calloc((size_t)ir->nbodies + 1, sizeof *nm);
  if (!nm) return 2;
  for (int b = 1; b < ir->nbodies; b++) {
    if (ir->bodies[b].kind == BODY_FLEXIBLE && (nm[b] = body_modes(ir, &ir->bodies[b])) < 0) {
      free(nm);
      return 2;
    }
    extra += 2 + nm[b];
  }
  ir_output *out = realloc(ir->outputs, (size_t)(ir->noutputs + extra + 1) * sizeof *out);
  if (!out) { free(nm); return 2; }
  ir->outputs = out;
  for (int b = 1; b < ir->nbodies; b++) {
    const ir_body *B = &ir->bodies[b];
    for (int k = 0; k < 2 + nm[b]; k++) {
      ir_output *o = &ir->outputs[ir->noutputs++];
      memset(o, 0, sizeof *o);
      o->loc = B->loc;
      o->body = b;
      o->joint = o->driver = o->node = -1;
      o->chord[0] = o->chord[1] = -1;
      o->component = -1;
      o->scale = 1;
      /* names with dots: never a model's own output (those are C identifiers) */
      if (k == 0) { o->kind = OUT_POSITION; o->name = printf_dup("body.%s.r", B->name, 0); }
      else if (k == 1) { o->kind = OUT_ORIENTATION; o->name = printf_dup("body.%s.p", B->name, 0); }
      else { o->kind = OUT_MODAL; o->mode = k - 2; o->name = printf_dup("body.%s.w%d", B->name, k - 1); }
      if (!o->name) { free(nm); return 2; }
    }
  }
  free(nm);
  return 0;
}

/* --- the CSV ---------------------------------------------------------------- */

typedef struct {
  int ncols, nrows;
  char **name;
  double *x; /* nrows x ncols, row-major */
} csv_table;

static void csv_free(csv_table *t) {
  for (int c = 0; c < t->ncols; c++) free(t->name[c]);
  free(t->name);
  free(t->x);
}

static int csv_read(const char *path, csv_table *t) {
  memset(t, 0, sizeof *t);
  size_t len;
  if (csv_file_check(path)) return 2;
  char *text = read_all(path, &len);
  if (!text) { fprintf(stderr, "mbcc: error: cannot read '%s': %s\n", path, strerror(errno)); return 2; }
  char *line = text, *eol = strchr(line, '\n');
  if (!eol || eol == line) { fprintf(stderr, "%s:1:1: error: no header line\n", path); free(text); return 2; }
  *eol = 0;
  if (eol > line && eol[-1] == '\r') eol[-1] = 0;
  for (char *p = line; *p; p++) t->ncols += *p == ',';
  t->ncols++;
  t->name = calloc((size_t)t->ncols, sizeof *t->name);
  int c = 0;
  for (char *tok = line, *next; t->name && tok; tok = next, c++) {
    next = strchr(tok, ',');
    if (next) *next++ = 0;
    t->name[c] = strdup(tok);
  }
  int cap = 1024;
  t->x = malloc((size_t)cap * (size_t)t->ncols * sizeof *t->x);
  if (!t->name || !t->x) { free(text); csv_free(t); fprintf(stderr, "mbcc: error: out of memory\n"); return 2; }
  int lineno = 1;
  for (char *p = eol + 1; *p; lineno++) {
    char *end = strchr(p, '\n');
    if (end) *end = 0;
    if (*p && *p != '\r') {
      if (t->nrows == cap) {
        cap *= 2;
        double *nx = realloc(t->x, (size_t)cap * (size_t)t->ncols * sizeof *t->x);
        if (!nx) { free(text); csv_free(t); fprintf(stderr, "mbcc: error: out of memory\n"); return 2; }
        t->x = nx;
      }
      char *q = p;
      for (c = 0; c < t->ncols; c++) {
        char *after;
        double v = strtod(q, &after);
        if (after == q || (c + 1 < t->ncols ? *after != ',' : (*after && *after != '\r'))) {
          fprintf(stderr, "%s:%d:%d: error: expected %d numbers separated by commas\n", path, lineno + 1,
                  (int)(q - p) + 1, t->ncols);
          free(text);
          csv_free(t);
          return 2;
        }
        t->x[(size_t)t->nrows * (size_t)t->ncols + (size_t)c] = v;
        q = after + 1;
      }
      t->nrows++;
    }
    if (!end) break;
    p = end + 1;
  }
  free(text);
  if (t->nrows == 0) { fprintf(stderr, "%s:2:1: error: no data rows\n", path); csv_free(t); return 2; }
  return 0;
}

static int csv_column(const csv_table *t, const char *name) {
  for (int c = 0; c < t->ncols; c++)
    if (!strcmp(t->name[c], name)) return c;
  return -1;
}

/* --- the page ---------------------------------------------------------------- */

/* a growing string */
typedef struct {
  char *s;
  size_t n, cap;
  int bad;
} sbuf;

static void sb_add(sbuf *b, const char *fmt, ...) DIAG_PRINTF(2, 3);
static void sb_add(sbuf *b, const char *fmt, ...) {
  va_list ap;
  for (;;) {
    va_start(ap, fmt);
    int k = vsnprintf(b->s ? b->s + b->n : NULL, b->s ? b->cap - b->n : 0, fmt, ap);
    va_end(ap);
    if (k < 0) { b->bad = 1; return; }
    if (b->s && b->n + (size_t)k < b->cap) { b->n += (size_t)k; return; }
    size_t cap = (b->cap + (size_t)k + 1) * 2;
    char *ns = realloc(b->s, cap);
    if (!ns) { b->bad = 1; return; }
    b->s = ns;
    b->cap = cap;
  }
}

/* a JSON string; '<' escaped too, so that no text can close the inline script */
static void sb_string(sbuf *b, const char *text) {
  sb_add(b, "\"");
  for (const unsigned char *c = (const unsigned char *)text; *c; c++) {
    if (*c == '"' || *c == '\\') sb_add(b, "\\%c", *c);
    else if (*c < 0x20 || *c == '<' || *c == '>' || *c == '&') sb_add(b, "\\u%04x", *c);
    else sb_add(b, "%c", *c);
  }
  sb_add(b, "\"");
}

static void sb_vec(sbuf *b, const double *v, int n) {
  sb_add(b, "[");
  for (int i = 0; i < n; i++) sb_add(b, "%s%.9g", i ? "," : "", v[i]);
  sb_add(b, "]");
}

/* columns cols[0..n-1] of every row, as one flat JSON array */
static void sb_columns(sbuf *b, const csv_table *t, const int *cols, int n) {
  sb_add(b, "[");
  for (int r = 0; r < t->nrows; r++)
    for (int i = 0; i < n; i++)
      sb_add(b, "%s%.9g", r || i ? "," : "", t->x[(size_t)r * (size_t)t->ncols + (size_t)cols[i]]);
  sb_add(b, "]");
}

/* the pose columns of body 'name': 3 + 4 + nm, or the count found before one is missing */
static int pose_columns(const csv_table *t, const char *name, int nm, int *cols) {
  static const char *suffix[7] = {"r.x", "r.y", "r.z", "p.e0", "p.e1", "p.e2", "p.e3"};
  char key[512];
  for (int i = 0; i < 7 + nm; i++) {
    if (i < 7) snprintf(key, sizeof key, "body.%s.%s", name, suffix[i]);
    else snprintf(key, sizeof key, "body.%s.w%d", name, i - 6);
    if ((cols[i] = csv_column(t, key)) < 0) return i;
  }
  return 7 + nm;
}

/* the JSON of one body drawn from the model (L: lowered; b: its IR index) */
static void body_from_model(sbuf *b, const lmodel *L, int ib, const csv_table *t, const int *cols) {
  const ir_body *B = &L->ir->bodies[ib];
  const mb_body *mb = &L->m.body[ib - 1];
  static const char *kinds[] = {"ground", "rigid", "virtual", "flexible"};
  sb_add(b, "{\"name\":\"%s\",\"kind\":\"%s\",\"r\":", B->name, kinds[B->kind]);
  sb_columns(b, t, cols, 3);
  sb_add(b, ",\"p\":");
  sb_columns(b, t, cols + 3, 4);
  /* the points of its joints and force elements that sit in the body frame
   * (points on FE nodes are drawn as the nodes), then those of its outputs
   * given at a point, each once */
  sb_add(b, ",\"points\":[");
  int np = 0, nmk = L->m.nmarker, nout = L->ir->noutputs;
  double *seen = malloc(3 * (size_t)(nmk + nout + 1) * sizeof *seen);
  for (int k = 0; seen && k < nmk + nout; k++) {
    const double *s;
    double sk[3];
    if (k < nmk) {
      const mb_markerdef *M = &L->marker[k];
      if (M->body != ib - 1 || M->node >= 0) continue;
      for (int i = 0; i < 3; i++) sk[i] = M->s[i];
    } else {
      const ir_output *o = &L->ir->outputs[k - nmk];
      if (o->body != ib || !o->has_point || (o->kind == OUT_POSITION && o->node >= 0)) continue;
      for (int i = 0; i < 3; i++) sk[i] = L->output[k - nmk].s[i];
    }
    s = sk;
    int dup = 0;
    for (int j = 0; j < np && !dup; j++)
      dup = fabs(seen[3 * j] - s[0]) + fabs(seen[3 * j + 1] - s[1]) + fabs(seen[3 * j + 2] - s[2]) < 1e-12;
    if (dup) continue;
    memcpy(seen + 3 * np, s, 3 * sizeof *s);
    sb_add(b, "%s", np++ ? "," : "");
    sb_vec(b, s, 3);
  }
  if (!seen) b->bad = 1;
  free(seen);
  sb_add(b, "]");
  const ir_shape *S = &B->shape;
  if (S->kind != SHAPE_NONE) {
    static const char *shape_names[] = {"none", "box", "cylinder", "sphere"};
    sb_add(b, ",\"shape\":{\"type\":\"%s\",\"size\":", shape_names[S->kind]);
    sb_vec(b, S->size, 3);
    sb_add(b, ",\"radius\":%.9g,\"length\":%.9g,\"axis\":", S->radius, S->length);
    sb_vec(b, S->axis, 3);
    sb_add(b, ",\"offset\":");
    sb_vec(b, S->offset, 3);
    sb_add(b, "}");
  }
  if (B->kind == BODY_FLEXIBLE) {
    const fe_modes *fm = &L->modes[ib - 1];
    int nn = fm->nnodes, nm = mb->nm;
    sb_add(b, ",\"nodes\":");
    sb_vec(b, fm->x, 3 * nn);
    sb_add(b, ",\"beams\":[");
    const ir_flex *fx = B->flex;
    if (fx->nbeams > 0)
      for (int e = 0; e < fx->nbeams; e++)
        sb_add(b, "%s[%d,%d]", e ? "," : "", fx->beams[e].node[0], fx->beams[e].node[1]);
    else /* a modal data file has no elements: join the nodes in their order */
      for (int k = 0; k + 1 < nn; k++) sb_add(b, "%s[%d,%d]", k ? "," : "", k, k + 1);
    sb_add(b, "],\"nmodes\":%d,\"modes\":[", nm);
    for (int j = 0; j < nm; j++) {
      sb_add(b, "%s[", j ? "," : "");
      for (int k = 0; k < nn; k++)
        for (int i = 0; i < 3; i++)
          sb_add(b, "%s%.9g", k || i ? "," : "", fm->shapes[(size_t)j * 6 * (size_t)nn + 6 * (size_t)k + (size_t)i]);
      sb_add(b, "]");
    }
    sb_add(b, "],\"w\":");
    sb_columns(b, t, cols + 7, nm);
  }
  sb_add(b, "}");
}

static int write_page(const char *html, const char *title, const sbuf *data, int quiet) {
  char tpl_path[4200];
  snprintf(tpl_path, sizeof tpl_path, "%s/animate.html.in", mbcc_templates_dir());
  char *tpl = read_all(tpl_path, NULL);
  if (!tpl) {
    fprintf(stderr, "mbcc: error: cannot read the template '%s' (set MBCC_ROOT?)\n", tpl_path);
    return 2;
  }
  char *player = read_all(player_path(), NULL);
  if (!player) {
    fprintf(stderr,
            "mbcc: error: the animation player '%s' is not built: run 'make web' (it needs npm, "
            "see scripts/install-deps.sh), or set MBCC_PLAYER_JS\n",
            player_path());
    free(tpl);
    return 2;
  }
  if (strstr(player, "</script")) { /* it would end the inline script early */
    fprintf(stderr, "mbcc: error: the player '%s' contains '</script' and cannot be inlined\n", player_path());
    free(tpl);
    free(player);
    return 2;
  }
  char part[4200];
  snprintf(part, sizeof part, "%s.part", html);
  FILE *f = fopen(part, "w");
  if (!f) {
    fprintf(stderr, "mbcc: error: cannot write '%s': %s\n", part, strerror(errno));
    free(tpl);
    free(player);
    return 2;
  }
  for (const char *p = tpl; *p;) {
    if (!strncmp(p, "@TITLE@", 7)) { /* HTML text: a CSV's name may hold any character */
      for (const char *c = title; *c; c++) {
        if (*c == '<') fputs("&lt;", f);
        else if (*c == '>') fputs("&gt;", f);
        else if (*c == '&') fputs("&amp;", f);
        else if (*c == '"') fputs("&quot;", f);
        else fputc(*c, f);
      }
      p += 7;
    }
    else if (!strncmp(p, "@DATA@", 6)) { fwrite(data->s, 1, data->n, f); p += 6; }
    else if (!strncmp(p, "@PLAYER@", 8)) { fputs(player, f); p += 8; }
    else fputc(*p++, f);
  }
  free(tpl);
  free(player);
  if (ferror(f) | fclose(f) || rename(part, html)) {
    fprintf(stderr, "mbcc: error: cannot write '%s'\n", html);
    remove(part);
    return 2;
  }
  if (!quiet) printf("wrote %s\n", html);
  return 0;
}

int animate_write(const char *csv, const char *model, const char *scene, const char *html, double scale,
                  int quiet) {
  csv_table t;
  if (csv_read(csv, &t)) return 2;
  if (strcmp(t.name[0], "t")) {
    fprintf(stderr, "%s:1:1: error: the first column is '%s', expected the time 't'\n", csv, t.name[0]);
    csv_free(&t);
    return 2;
  }
  /* the model's stages up to lowering (no assembly: the drawing needs the
     bodies, markers and modes, not the state at t = 0) */
  mbc_unit u;
  memset(&u, 0, sizeof u);
  if (model) {
    if (!mbc_unit_read(&u, model, scene) && !flex_reduce(u.ir, &u.flex))
      u.lowered = lower_model(u.ir, &u.flex);
    if (!u.lowered) {
      if (u.ir && !diag_errors()) fprintf(stderr, "mbcc: error: out of memory while lowering\n");
      mbc_unit_free(&u);
      csv_free(&t);
      return 2;
    }
  }
  const ir_model *ir = u.ir;
  const lmodel *L = u.lowered;
  sbuf b = {0};
  int rc = 0, tcol = 0;
  sb_add(&b, "{\"model\":");
  sb_string(&b, model ? L->name : csv);
  sb_add(&b, ",\"deformation_scale\":%.9g,\"time\":", scale);
  sb_columns(&b, &t, &tcol, 1);
  sb_add(&b, ",\"bodies\":[");
  int cols[7 + 64 + 1], nbodies = 0;
  if (L) {
    for (int ib = 1; ib < ir->nbodies && !rc; ib++) {
      int nm = L->m.body[ib - 1].nm;
      int found = pose_columns(&t, ir->bodies[ib].name, nm, cols);
      if (found < 7 + nm) {
        fprintf(stderr,
                "%s:1:1: error: no column '%s' for body '%s' (the animation needs every body's pose%s: "
                "'mbcc run %s --animate' adds them)\n",
                csv, found < 3 ? "body.<name>.r.x" : found < 7 ? "body.<name>.p.e0" : "body.<name>.w<j>",
                ir->bodies[ib].name, nm ? " and modal coordinates" : "", model);
        rc = 2;
        break;
      }
      sb_add(&b, "%s", nbodies++ ? "," : "");
      body_from_model(&b, L, ib, &t, cols);
    }
  } else {
    /* without the model: every body with pose columns, drawn as its frame */
    for (int c = 0; c < t.ncols; c++) {
      const char *n = t.name[c];
      size_t len = strlen(n);
      if (strncmp(n, "body.", 5) || len < 9 || strcmp(n + len - 4, ".r.x")) continue;
      char name[256];
      snprintf(name, sizeof name, "%.*s", (int)(len - 9), n + 5);
      if (pose_columns(&t, name, 0, cols) < 7) continue;
      sb_add(&b, "%s{\"name\":", nbodies++ ? "," : "");
      sb_string(&b, name);
      sb_add(&b, ",\"kind\":\"rigid\",\"r\":");
      sb_columns(&b, &t, cols, 3);
      sb_add(&b, ",\"p\":");
      sb_columns(&b, &t, cols + 3, 4);
      sb_add(&b, ",\"points\":[]}");
    }
    if (!nbodies) {
      fprintf(stderr,
              "%s:1:1: error: no pose columns (body.<name>.r.x, ...): run the model with "
              "'mbcc run M.yaml --animate'\n", csv);
      rc = 2;
    } else if (!quiet) {
      fprintf(stderr, "mbcc: note: without the model (-m M.yaml) bodies are drawn as their frames only\n");
    }
  }
  /* the ground's joint points, and the axes of its revolute, prismatic and cylindrical joints */
  sb_add(&b, "],\"ground_points\":[");
  int ng = 0;
  for (int k = 0; L && k < L->m.nmarker; k++)
    if (L->marker[k].body < 0) {
      double s[3] = {L->marker[k].s[0], L->marker[k].s[1], L->marker[k].s[2]};
      sb_add(&b, "%s", ng++ ? "," : "");
      sb_vec(&b, s, 3);
    }
  sb_add(&b, "],\"ground_axes\":[");
  ng = 0;
  for (int j = 0; ir && j < ir->njoints; j++) {
    const ir_joint *J = &ir->joints[j];
    if (!J->active || (J->body[0] != 0 && J->body[1] != 0)) continue;
    if (!joint_element(J->kind)->free_dofs) continue; /* revolute, prismatic, cylindrical */
    int side = J->body[0] == 0 ? 0 : 1;
    sb_add(&b, "%s{\"joint\":\"%s\",\"kind\":\"%s\",\"point\":", ng++ ? "," : "", J->name,
           joint_element(J->kind)->type);
    sb_vec(&b, J->point[side], 3);
    sb_add(&b, ",\"axis\":");
    sb_vec(&b, J->axis[side], 3);
    sb_add(&b, "}");
  }
  sb_add(&b, "]}");
  if (!rc && b.bad) { fprintf(stderr, "mbcc: error: out of memory\n"); rc = 2; }
  if (!rc) rc = write_page(html, model ? L->name : csv, &b, quiet);
  free(b.s);
  mbc_unit_free(&u);
  csv_free(&t);
  return rc;
}

void animate_page_name(const char *csv, char *html, size_t n) {
  snprintf(html, n, "%s", csv);
  char *dot = strrchr(html, '.'), *slash = strrchr(html, '/');
  if (dot && (!slash || dot > slash)) *dot = 0;
  strncat(html, ".html", n - strlen(html) - 1);
}

int cmd_animate(int argc, char **argv) {
  const char *csv = NULL, *model = NULL, *scene = NULL, *out = NULL;
  double scale = 1;
  int quiet = 0;
  for (int i = 2; i < argc; i++) {
    const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
    if (a[0] != '-') {
      if (csv) { fprintf(stderr, "mbcc: error: more than one results file given ('%s')\n", a); return 2; }
      csv = a;
      continue;
    }
    if (!strcmp(a, "--quiet")) { quiet = 1; continue; }
    if (!v) { fprintf(stderr, "mbcc: error: option '%s' needs a value\n", a); return 2; }
    i++;
    if (!strcmp(a, "-m") || !strcmp(a, "--model")) model = v;
    else if (!strcmp(a, "--scene")) scene = v;
    else if (!strcmp(a, "-o")) out = v;
    else if (!strcmp(a, "--scale")) {
      char *end;
      scale = strtod(v, &end);
      if (*end || !(scale >= 0) || !isfinite(scale)) {
        fprintf(stderr, "mbcc: error: '--scale' must be a number >= 0, got '%s'\n", v);
        return 2;
      }
    } else {
      fprintf(stderr, "mbcc: error: unknown option '%s' (usage: mbcc animate results.csv [-m M.yaml] "
                      "[--scene S] [-o out.html] [--scale S] [--quiet])\n", a);
      return 2;
    }
  }
  if (!csv) {
    fprintf(stderr, "usage: mbcc animate results.csv [-m M.yaml] [--scene S] [-o out.html] [--scale S] [--quiet]\n");
    return 2;
  }
  if (scene && !model) { fprintf(stderr, "mbcc: error: '--scene' needs the model (-m M.yaml)\n"); return 2; }
  char html[4096];
  if (out) snprintf(html, sizeof html, "%s", out);
  else animate_page_name(csv, html, sizeof html);
  return animate_write(csv, model, scene, html, scale, quiet);
}
