/* import_nastran.c: a flexible body's FE model from a Nastran bulk-data
 * deck: GRID, CORD2R, CBAR, CBEAM, CROD, CONM2, PBAR, PBARL (ROD, TUBE, BAR,
 * BOX, I), PBEAM (constant section), PROD, MAT1, SPC, SPC1, RBE2; small-field
 * (8 columns) and free-field (commas) lines, continuation lines, INCLUDE.
 * The supported subset and its conventions: docs/model-format.md. */
#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "yaml_map.h"
#include "fe_import.h"

#define NAS_PI 3.14159265358979323846
#define NAS_MAX_INCLUDE_DEPTH 16

/* one field of a card: its text (trimmed, upper case) and where it starts */
typedef struct {
  char text[24];
  ir_loc loc;
} nas_field;

typedef struct {
  char name[24];
  const char *file; /* path of the file the card is in */
  ir_loc loc;
  nas_field *f; /* f[1..nf-1]: data fields by logical position (8 per line) */
  int nf;
  int half;     /* large-field: the last line gave only the first 4 of its 8 fields */
} nas_card;

typedef struct {
  nas_card *cards;
  int ncards, cap;
  char **files; /* every file read (kept for the cards' messages) */
  int nfiles;
  int errors;
  int done; /* ENDDATA seen */
} nas_deck;

/* the reader's allocator: out of memory unwinds to ir_read, which reports it */
static void *nas_alloc(size_t n, size_t size) { return xcalloc(n ? n : 1, size); }

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 4, 5)))
#endif
static void nas_error(nas_deck *d, const char *file, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_verror(file, loc, fmt, ap);
  va_end(ap);
  d->errors++;
}

static nas_card *new_card(nas_deck *d, const char *name, const char *file, ir_loc loc) {
  if (d->ncards == d->cap) {
    d->cap = d->cap ? 2 * d->cap : 64;
    nas_card *c = realloc(d->cards, (size_t)d->cap * sizeof *c);
    if (!c) out_of_memory();
    d->cards = c;
  }
  nas_card *c = &d->cards[d->ncards++];
  memset(c, 0, sizeof *c);
  snprintf(c->name, sizeof c->name, "%s", name);
  c->file = file;
  c->loc = loc;
  c->nf = 1;
  c->f = nas_alloc(1, sizeof *c->f);
  c->f[0].loc = loc;
  return c;
}

/* append one line's 8 data fields (fewer are padded with blanks) */
static void add_line_fields(nas_card *c, nas_field *data, int n) {
  int base = c->nf;
  nas_field *f = realloc(c->f, (size_t)(base + 8) * sizeof *f);
  if (!f) out_of_memory();
  c->f = f;
  for (int i = 0; i < 8; i++) {
    if (i < n) c->f[base + i] = data[i];
    else {
      memset(&c->f[base + i], 0, sizeof c->f[base + i]);
      c->f[base + i].loc = n > 0 ? data[n - 1].loc : c->loc;
    }
  }
  c->nf = base + 8;
}

/* trimmed, upper-cased copy of s[0..len) into out (size cap); 0 if too long */
static int copy_field(const char *s, size_t len, char *out, size_t cap, int *lead) {
  size_t a = 0, b = len;
  while (a < b && isspace((unsigned char)s[a])) a++;
  while (b > a && isspace((unsigned char)s[b - 1])) b--;
  if (lead) *lead = (int)a;
  if (b - a >= cap) return 0;
  for (size_t i = a; i < b; i++) out[i - a] = (char)toupper((unsigned char)s[i]);
  out[b - a] = 0;
  return 1;
}

static int read_file(nas_deck *d, const char *path, const char *from, ir_loc from_loc, int depth);

/* the path of 'name' relative to the directory of 'base' */
static char *relative_path(const char *base, const char *name) {
  const char *slash = strrchr(base, '/');
  size_t dl = (slash && name[0] != '/') ? (size_t)(slash - base + 1) : 0;
  char *p = nas_alloc(dl + strlen(name) + 1, 1);
  memcpy(p, base, dl);
  strcpy(p + dl, name);
  return p;
}

static int starts_with_ci(const char *s, const char *word) {
  for (; *word; s++, word++)
    if (toupper((unsigned char)*s) != *word) return 0;
  return 1;
}

/* one line (no newline, comments removed) of file 'path' at line 'lineno' */
static void read_line(nas_deck *d, const char *path, int lineno, char *line, int depth) {
  /* tabs to the next multiple of 8 columns (small-field decks) */
  char buf[512];
  size_t o = 0;
  for (const char *p = line; *p && o + 9 < sizeof buf; p++) {
    if (*p == '\t') {
      do buf[o++] = ' '; while (o % 8);
    } else {
      buf[o++] = *p;
    }
  }
  buf[o] = 0;
  size_t len = o;
  while (len > 0 && isspace((unsigned char)buf[len - 1])) buf[--len] = 0;
  if (len == 0) return;
  ir_loc loc = {lineno, 1};
  const char *s = buf;
  while (*s == ' ') s++;
  if (starts_with_ci(s, "INCLUDE") && (s[7] == ' ' || s[7] == '\'' || s[7] == '"')) {
    const char *q = s + 7;
    while (*q == ' ') q++;
    char name[400];
    size_t n = 0;
    if (*q == '\'' || *q == '"') {
      char quote = *q++;
      while (*q && *q != quote && n + 1 < sizeof name) name[n++] = *q++;
      if (*q != quote) {
        nas_error(d, path, loc, "INCLUDE: the file name has no closing quote");
        return;
      }
    } else {
      while (*q && *q != ' ' && n + 1 < sizeof name) name[n++] = *q++;
    }
    name[n] = 0;
    if (n == 0) {
      nas_error(d, path, loc, "INCLUDE: no file name");
      return;
    }
    char *inc = relative_path(path, name);
    read_file(d, inc, path, loc, depth + 1);
    free(inc);
    return;
  }
  if (starts_with_ci(s, "ENDDATA")) {
    d->done = 1;
    return;
  }
  nas_field data[16];
  int nd = 0;
  char name[24] = "";
  int free_field = strchr(buf, ',') != NULL;
  /* large field: a name with '*' (GRID*) and its '*' continuations hold 4
     fields of 16 columns each, two lines making one small-field line */
  int large = 0;
  {
    char first[24];
    int lead = 0;
    const char *e = free_field ? strchr(buf, ',') : NULL;
    size_t flen = e ? (size_t)(e - buf) : (len < 8 ? len : 8);
    if (copy_field(buf, flen, first, sizeof first, &lead)) large = strchr(first, '*') != NULL;
  }
  if (free_field) {
    /* name, then up to 8 data fields, then a continuation mark (ignored) */
    const char *p = buf;
    int k = 0;
    for (;;) {
      const char *e = strchr(p, ',');
      size_t flen = e ? (size_t)(e - p) : strlen(p);
      int lead = 0;
      char text[24];
      ir_loc floc = {lineno, (int)(p - buf) + 1};
      if (!copy_field(p, flen, text, sizeof text, &lead)) {
        nas_error(d, path, floc, "field %d is too long", k + 1);
        return;
      }
      floc.col += lead;
      if (k == 0) {
        strcpy(name, text);
      } else if (k <= (large ? 4 : 8)) {
        snprintf(data[nd].text, sizeof data[nd].text, "%s", text);
        data[nd++].loc = floc;
      } else if (k == (large ? 5 : 9)) {
        /* continuation mark */
      } else {
        nas_error(d, path, floc, large ? "a large-field free-field line holds at most 4 data fields and a "
                  "continuation mark (continue the card on a line starting with '*')"
                  : "a free-field line holds at most 8 data fields and a continuation "
                  "mark (continue the card on a line starting with '+' or ',')");
        return;
      }
      k++;
      if (!e) break;
      p = e + 1;
    }
  } else {
    int lead = 0;
    if (!copy_field(buf, len < 8 ? len : 8, name, sizeof name, &lead)) return;
    int width = large ? 16 : 8, nfields = large ? 4 : 8;
    for (int i = 0; i < nfields; i++) {
      size_t a = 8 + (size_t)width * (size_t)i;
      if (a >= len) break;
      size_t flen = len - a < (size_t)width ? len - a : (size_t)width;
      copy_field(buf + a, flen, data[nd].text, sizeof data[nd].text, &lead);
      data[nd].loc = (ir_loc){lineno, (int)a + 1 + (data[nd].text[0] ? lead : 0)};
      nd++;
    }
  }
  if (name[0] == '+' || name[0] == '*' || name[0] == 0) {
    if (d->ncards == 0 || d->cards[d->ncards - 1].file == NULL) {
      nas_error(d, path, loc, "a continuation line without a card before it");
      return;
    }
    nas_card *c = &d->cards[d->ncards - 1];
    if (large && c->half) { /* the second half of a large-field line */
      for (int i = 0; i < 4; i++) {
        nas_field *f = &c->f[c->nf - 4 + i];
        if (i < nd) *f = data[i];
        else { memset(f, 0, sizeof *f); f->loc = nd > 0 ? data[nd - 1].loc : loc; }
      }
      c->half = 0;
      return;
    }
    add_line_fields(c, data, nd);
    c->half = large;
    return;
  }
  if (large) {
    size_t n = strlen(name);
    if (n < 2 || name[n - 1] != '*' || strchr(name, '*') != name + n - 1) {
      nas_error(d, path, loc, "'%s' is not a card name (large field: the name followed by one '*')", name);
      return;
    }
    name[n - 1] = 0;
  }
  for (const char *c = name; *c; c++)
    if (!isalnum((unsigned char)*c)) {
      nas_error(d, path, loc, "'%s' is not a card name", name);
      return;
    }
  nas_card *c = new_card(d, name, path, loc);
  add_line_fields(c, data, nd);
  c->half = large;
}

static int read_file(nas_deck *d, const char *path, const char *from, ir_loc from_loc, int depth) {
  if (depth > NAS_MAX_INCLUDE_DEPTH) {
    nas_error(d, from, from_loc, "INCLUDE nested more than %d deep (an INCLUDE loop?)",
              NAS_MAX_INCLUDE_DEPTH);
    return -1;
  }
  FILE *f = fopen(path, "r");
  if (!f) {
    if (from) nas_error(d, from, from_loc, "cannot open included file '%s': %s", path, strerror(errno));
    else nas_error(d, NULL, (ir_loc){0, 0}, "cannot open FE file '%s': %s", path, strerror(errno));
    return -1;
  }
  char **files = realloc(d->files, (size_t)(d->nfiles + 1) * sizeof *files);
  if (!files) out_of_memory();
  d->files = files;
  char *kept = nas_alloc(strlen(path) + 1, 1);
  strcpy(kept, path);
  d->files[d->nfiles++] = kept;
  /* the bulk data starts after BEGIN BULK when the deck has one */
  int bulk = 1;
  if (depth == 0) {
    char line[1024];
    while (fgets(line, sizeof line, f))
      if (starts_with_ci(line, "BEGIN") && strstr(line, "BULK")) bulk = 0;
    rewind(f);
  }
  char line[1024];
  int lineno = 0;
  while (!d->done && fgets(line, sizeof line, f)) {
    lineno++;
    size_t n = strlen(line);
    if (n == sizeof line - 1 && line[n - 1] != '\n') {
      nas_error(d, kept, (ir_loc){lineno, 1}, "line longer than %d characters", (int)sizeof line - 2);
      break;
    }
    if (!bulk) {
      for (char *p = line; *p; p++) *p = (char)toupper((unsigned char)*p);
      if (starts_with_ci(line, "BEGIN") && strstr(line, "BULK")) bulk = 1;
      continue;
    }
    char *dollar = strchr(line, '$');
    if (dollar) *dollar = 0;
    line[strcspn(line, "\r\n")] = 0;
    read_line(d, kept, lineno, line, depth);
  }
  fclose(f);
  return 0;
}

/* --- field values ---------------------------------------------------------------- */

static const nas_field *field(const nas_card *c, int i) {
  static const nas_field blank = {"", {0, 0}};
  return i < c->nf ? &c->f[i] : &blank;
}

static ir_loc field_loc(const nas_card *c, int i) {
  if (i < c->nf && c->f[i].loc.line > 0) return c->f[i].loc;
  return c->loc;
}

static int is_blank(const nas_card *c, int i) { return field(c, i)->text[0] == 0; }

/* a whole number; blank gives def (required: blank is an error) */
static int get_int(nas_deck *d, const nas_card *c, int i, const char *what, int required, long def,
                   long *out) {
  const char *t = field(c, i)->text;
  *out = def;
  if (!*t) {
    if (required) nas_error(d, c->file, field_loc(c, i), "%s: %s (field %d) is required", c->name, what, i + 1);
    return !required;
  }
  char *end;
  errno = 0;
  long v = strtol(t, &end, 10);
  if (*end || errno) {
    nas_error(d, c->file, field_loc(c, i), "%s: %s must be an integer (got '%s')", c->name, what, t);
    return 0;
  }
  *out = v;
  return 1;
}

/* a Nastran real: 1.5, 1.5E3, 1.5+3 (implicit exponent), 1.5D-3 */
static int parse_real(const char *t, double *v) {
  char buf[40];
  size_t n = 0;
  for (size_t i = 0; t[i] && n + 2 < sizeof buf; i++) {
    char ch = t[i];
    if (ch == 'D') ch = 'E';
    if ((ch == '+' || ch == '-') && i > 0 && t[i - 1] != 'E' && t[i - 1] != 'D') buf[n++] = 'E';
    buf[n++] = ch;
  }
  buf[n] = 0;
  char *end;
  errno = 0;
  *v = strtod(buf, &end);
  return n > 0 && !*end && !errno && isfinite(*v);
}

static int get_real(nas_deck *d, const nas_card *c, int i, const char *what, int required, double def,
                    double *out) {
  const char *t = field(c, i)->text;
  *out = def;
  if (!*t) {
    if (required) nas_error(d, c->file, field_loc(c, i), "%s: %s (field %d) is required", c->name, what, i + 1);
    return !required;
  }
  if (!parse_real(t, out)) {
    nas_error(d, c->file, field_loc(c, i), "%s: %s must be a real number (got '%s')", c->name, what, t);
    return 0;
  }
  return 1;
}

/* DOF components "123456" as bits 0..5 */
static int get_components(nas_deck *d, const nas_card *c, int i, unsigned *out) {
  const char *t = field(c, i)->text;
  *out = 0;
  if (!*t) {
    nas_error(d, c->file, field_loc(c, i), "%s: the DOF components (field %d) are required", c->name, i + 1);
    return 0;
  }
  for (; *t; t++) {
    if (*t < '1' || *t > '6') {
      if (*t == '0' && t[1] == 0 && t == field(c, i)->text) return 1; /* 0: none */
      nas_error(d, c->file, field_loc(c, i), "%s: DOF components are digits 1 to 6 (got '%s')",
                c->name, field(c, i)->text);
      return 0;
    }
    *out |= 1u << (*t - '1');
  }
  return 1;
}

/* --- the model ------------------------------------------------------------------- */

typedef struct {
  long id;
  const nas_card *card;
  double E, G, rho;
} nas_mat;

typedef struct {
  long id;
  const nas_card *card;
  long mid;
  double A, I1, I2, J, nsm, k1, k2;
  int timoshenko, rod;
} nas_prop;

typedef struct {
  long id, rid;
  const nas_card *card;
  double a[3], b[3], c[3];
  double origin[3], axes[9]; /* rows: x, y, z in basic */
  int state;                 /* 0 not resolved, 1 resolving, 2 resolved */
} nas_cord;

static int cmp_long_first(const void *a, const void *b) {
  long x = *(const long *)a, y = *(const long *)b;
  return (x > y) - (x < y);
}

static void cross3(const double a[3], const double b[3], double out[3]) {
  out[0] = a[1] * b[2] - a[2] * b[1];
  out[1] = a[2] * b[0] - a[0] * b[2];
  out[2] = a[0] * b[1] - a[1] * b[0];
}
static double norm3v(const double a[3]) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

static nas_cord *find_cord(nas_cord *cs, int n, long id) {
  for (int i = 0; i < n; i++)
    if (cs[i].id == id) return &cs[i];
  return NULL;
}

/* basic position of a point given in system cs */
static void cord_to_basic(const nas_cord *cs, const double p[3], double out[3]) {
  for (int i = 0; i < 3; i++)
    out[i] = cs->origin[i] + cs->axes[i] * p[0] + cs->axes[3 + i] * p[1] + cs->axes[6 + i] * p[2];
}

static int resolve_cord(nas_deck *d, nas_cord *cs, int n, nas_cord *c) {
  if (c->state == 2) return 0;
  if (c->state == 1) {
    nas_error(d, c->card->file, c->card->loc, "CORD2R %ld: its reference systems form a loop", c->id);
    return -1;
  }
  c->state = 1;
  double a[3], b[3], p[3];
  memcpy(a, c->a, sizeof a);
  memcpy(b, c->b, sizeof b);
  memcpy(p, c->c, sizeof p);
  if (c->rid != 0) {
    nas_cord *r = find_cord(cs, n, c->rid);
    if (!r) {
      nas_error(d, c->card->file, field_loc(c->card, 2), "CORD2R %ld: reference system %ld is not defined",
                c->id, c->rid);
      return -1;
    }
    if (resolve_cord(d, cs, n, r)) return -1;
    cord_to_basic(r, c->a, a);
    cord_to_basic(r, c->b, b);
    cord_to_basic(r, c->c, p);
  }
  double z[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, ac[3] = {p[0] - a[0], p[1] - a[1], p[2] - a[2]};
  double y[3], x[3];
  cross3(z, ac, y);
  double nz = norm3v(z), ny = norm3v(y);
  if (!(nz > 0) || !(ny > 1e-12 * nz * norm3v(ac))) {
    nas_error(d, c->card->file, c->card->loc, "CORD2R %ld: points A, B, C do not define axes (A = B, "
              "or C on the z axis)", c->id);
    return -1;
  }
  for (int i = 0; i < 3; i++) { z[i] /= nz; y[i] /= ny; }
  cross3(y, z, x);
  memcpy(c->origin, a, sizeof a);
  memcpy(c->axes, x, sizeof x);
  memcpy(c->axes + 3, y, sizeof y);
  memcpy(c->axes + 6, z, sizeof z);
  c->state = 2;
  return 0;
}

/* a direction given in system cs (NULL: basic) in basic */
static void cord_dir_to_basic(const nas_cord *cs, const double v[3], double out[3]) {
  double t[3] = {v[0], v[1], v[2]};
  for (int j = 0; j < 3; j++) out[j] = cs ? cs->axes[j] * t[0] + cs->axes[3 + j] * t[1] + cs->axes[6 + j] * t[2] : t[j];
}

/* DOF components (bits 0..5) given in the displacement system cs of GRID
 * gid (NULL: basic) as basic components.  A set of translations (or of
 * rotations) constrains the span of those cs axes; it maps onto basic
 * components when that span is also spanned by basic axes (the whole set,
 * or cs axes along basic axes), else it is an error at field i of card c:
 * a constraint along a skew direction would need a DOF transformation. */
static int basic_components(nas_deck *d, const nas_card *c, int i, const nas_cord *cs, long gid, unsigned comps,
                            unsigned *out) {
  *out = comps;
  if (!cs) return 1;
  *out = 0;
  for (int h = 0; h < 2; h++) { /* translations, rotations */
    unsigned set = comps >> (3 * h) & 7u;
    double P[9] = {0}; /* the projector onto the span of the set's axes, basic */
    for (int a = 0; a < 3; a++)
      if (set >> a & 1)
        for (int j = 0; j < 3; j++)
          for (int k = 0; k < 3; k++) P[3 * j + k] += cs->axes[3 * a + j] * cs->axes[3 * a + k];
    int aligned = 1;
    for (int j = 0; j < 3; j++)
      for (int k = 0; k < 3; k++) {
        double want = j != k ? 0 : P[3 * j + j] > 0.5 ? 1 : 0;
        aligned &= fabs(P[3 * j + k] - want) < 1e-9;
      }
    if (!aligned) {
      nas_error(d, c->file, field_loc(c, i), "%s: components %s of GRID %ld are in its displacement system "
                "CD %ld, whose axes are skew to the basic axes: only whole sets (123, 456) or components along "
                "basic axes are supported", c->name, field(c, i)->text, gid, cs->id);
      return 0;
    }
    for (int j = 0; j < 3; j++)
      if (P[3 * j + j] > 0.5) *out |= 1u << (3 * h + j);
  }
  return 1;
}

/* section properties of a PBARL shape (Nastran's dimensions: DIM1.. in
 * field 9 on); I1 bends in the element's x-y plane (about z), I2 in x-z */
static int pbarl_section(nas_deck *d, const nas_card *c, nas_prop *p) {
  char type[24];
  snprintf(type, sizeof type, "%s", field(c, 4)->text);
  static const struct { const char *name; int ndim; } shapes[] = {
      {"ROD", 1}, {"TUBE", 2}, {"BAR", 2}, {"BOX", 4}, {"I", 6}};
  int s = -1;
  for (int i = 0; i < 5; i++)
    if (!strcmp(type, shapes[i].name)) s = i;
  if (s < 0) {
    nas_error(d, c->file, field_loc(c, 4), "PBARL %ld: section type '%s' is not supported (ROD, TUBE, "
              "BAR, BOX, I)", p->id, type);
    return -1;
  }
  double D[6];
  for (int i = 0; i < shapes[s].ndim; i++) {
    char what[16];
    snprintf(what, sizeof what, "DIM%d", i + 1);
    if (!get_real(d, c, 9 + i, what, 1, 0, &D[i])) return -1;
    if (!(D[i] > 0)) {
      nas_error(d, c->file, field_loc(c, 9 + i), "PBARL %ld: %s must be positive", p->id, what);
      return -1;
    }
  }
  if (!get_real(d, c, 9 + shapes[s].ndim, "NSM", 0, 0, &p->nsm)) return -1;
  double A, I1, I2, J;
  switch (s) {
  case 0: /* solid circle, radius DIM1 */
    A = NAS_PI * D[0] * D[0];
    I1 = I2 = NAS_PI * pow(D[0], 4) / 4;
    J = 2 * I1;
    break;
  case 1: /* tube, outer and inner radius */
    if (!(D[1] < D[0])) {
      nas_error(d, c->file, field_loc(c, 10), "PBARL %ld: TUBE inner radius DIM2 must be below DIM1", p->id);
      return -1;
    }
    A = NAS_PI * (D[0] * D[0] - D[1] * D[1]);
    I1 = I2 = NAS_PI * (pow(D[0], 4) - pow(D[1], 4)) / 4;
    J = 2 * I1;
    break;
  case 2: { /* rectangle: DIM1 along z, DIM2 along y; Saint-Venant torsion (series approximation) */
    double b = D[0], h = D[1], a = fmax(b, h), t = fmin(b, h);
    A = b * h;
    I1 = b * h * h * h / 12;
    I2 = h * b * b * b / 12;
    J = a * t * t * t * (1.0 / 3 - 0.21 * (t / a) * (1 - pow(t / a, 4) / 12));
    break;
  }
  case 3: { /* box: width DIM1 (z), height DIM2 (y), flanges DIM3 thick, webs DIM4; Bredt torsion */
    double b = D[0], h = D[1], tf = D[2], tw = D[3];
    if (!(2 * tw < b && 2 * tf < h)) {
      nas_error(d, c->file, field_loc(c, 11), "PBARL %ld: BOX walls thicker than the box", p->id);
      return -1;
    }
    double bi = b - 2 * tw, hi = h - 2 * tf;
    A = b * h - bi * hi;
    I1 = (b * h * h * h - bi * hi * hi * hi) / 12;
    I2 = (h * b * b * b - hi * bi * bi * bi) / 12;
    J = 2 * tw * tf * (b - tw) * (b - tw) * (h - tf) * (h - tf) / (b * tw + h * tf - tw * tw - tf * tf);
    break;
  }
  default: { /* I: height DIM1 (y), flange widths DIM2 (bottom) DIM3 (top), web DIM4,
                flange thicknesses DIM5 (bottom) DIM6 (top); thin-walled open torsion */
    double h = D[0], wb = D[1], wt = D[2], tw = D[3], tb = D[4], tt = D[5], hw = h - tb - tt;
    if (!(hw > 0) || !(tw <= wb && tw <= wt)) {
      nas_error(d, c->file, field_loc(c, 9), "PBARL %ld: I section: flanges thicker than its height or "
                "a web wider than its flanges", p->id);
      return -1;
    }
    double Ab = wb * tb, At = wt * tt, Aw = tw * hw;
    A = Ab + At + Aw;
    double yb = tb / 2, yt = h - tt / 2, yw = tb + hw / 2; /* from the bottom */
    double yc = (Ab * yb + At * yt + Aw * yw) / A;
    I1 = wb * tb * tb * tb / 12 + Ab * (yb - yc) * (yb - yc) + wt * tt * tt * tt / 12 +
         At * (yt - yc) * (yt - yc) + tw * hw * hw * hw / 12 + Aw * (yw - yc) * (yw - yc);
    I2 = tb * wb * wb * wb / 12 + tt * wt * wt * wt / 12 + hw * tw * tw * tw / 12;
    J = (wb * tb * tb * tb + wt * tt * tt * tt + hw * tw * tw * tw) / 3;
    break;
  }
  }
  p->A = A;
  p->I1 = I1;
  p->I2 = I2;
  p->J = J;
  return 0;
}

static nas_prop *find_prop(nas_prop *ps, int n, long id) {
  for (int i = 0; i < n; i++)
    if (ps[i].id == id) return &ps[i];
  return NULL;
}
static nas_mat *find_mat(nas_mat *ms, int n, long id) {
  for (int i = 0; i < n; i++)
    if (ms[i].id == id) return &ms[i];
  return NULL;
}

/* node index of a GRID id through the sorted (id, index) pairs */
static int grid_index(const long *sorted, int n, long id) {
  int lo = 0, hi = n - 1;
  while (lo <= hi) {
    int mid = (lo + hi) / 2;
    if (sorted[2 * mid] == id) return (int)sorted[2 * mid + 1];
    if (sorted[2 * mid] < id) lo = mid + 1;
    else hi = mid - 1;
  }
  return -1;
}

static int grid_ref(nas_deck *d, const nas_card *c, int i, const char *what, const long *sorted,
                    int n, int *out) {
  long id;
  if (!get_int(d, c, i, what, 1, 0, &id)) return 0;
  *out = grid_index(sorted, n, id);
  if (*out < 0) {
    nas_error(d, c->file, field_loc(c, i), "%s: %s %ld is not a GRID of the deck", c->name, what, id);
    return 0;
  }
  return 1;
}

static void push_link(ir_rigid_link **links, int *n, int *cap, ir_rigid_link l) {
  if (*n == *cap) {
    *cap = *cap ? 2 * *cap : 16;
    ir_rigid_link *grown = realloc(*links, (size_t)*cap * sizeof *grown);
    if (!grown) out_of_memory();
    *links = grown;
  }
  (*links)[(*n)++] = l;
}

static const char *const known_ignored[] = {"PARAM", "EIGRL", "EIGR", NULL};

int fe_import_nastran(const char *path, ir_flex *fx, double **global) {
  nas_deck d;
  memset(&d, 0, sizeof d);
  int errors_before = diag_errors();
  read_file(&d, path, NULL, (ir_loc){0, 0}, 0);
  int ngrid = 0, ncord = 0, nprop = 0, nmat = 0, nel = 0, nmass = 0, nrbe = 0;
  for (int i = 0; i < d.ncards; i++) {
    const char *n = d.cards[i].name;
    if (!strcmp(n, "GRID")) ngrid++;
    else if (!strcmp(n, "CORD2R")) ncord++;
    else if (!strcmp(n, "PBAR") || !strcmp(n, "PBARL") || !strcmp(n, "PBEAM") || !strcmp(n, "PROD")) nprop++;
    else if (!strcmp(n, "MAT1")) nmat++;
    else if (!strcmp(n, "CBAR") || !strcmp(n, "CBEAM") || !strcmp(n, "CROD")) nel++;
    else if (!strcmp(n, "CONM2")) nmass++;
    else if (!strcmp(n, "RBE2")) nrbe++;
    else if (!strcmp(n, "SPC") || !strcmp(n, "SPC1")) {
    } else if (!strcmp(n, "CORD2C") || !strcmp(n, "CORD2S") || !strncmp(n, "CORD1", 5)) {
      nas_error(&d, d.cards[i].file, d.cards[i].loc, "%s: only rectangular systems given by three points "
                "(CORD2R) are supported, not cylindrical, spherical or CORD1 systems", n);
    } else {
      int known = 0;
      for (int k = 0; known_ignored[k]; k++) known |= !strcmp(n, known_ignored[k]);
      if (!known)
        nas_error(&d, d.cards[i].file, d.cards[i].loc, "card '%s' is not supported (see "
                  "docs/model-format.md, FE files, for the cards mbcc reads)", n);
    }
  }
  if (d.errors == 0 && ngrid < 2)
    nas_error(&d, path, (ir_loc){0, 0}, "the deck has %d GRID cards (a flexible body needs at least 2)", ngrid);

  nas_cord *cs = nas_alloc((size_t)ncord, sizeof *cs);
  nas_prop *ps = nas_alloc((size_t)nprop, sizeof *ps);
  nas_mat *ms = nas_alloc((size_t)nmat, sizeof *ms);
  long *ids = nas_alloc((size_t)ngrid, sizeof *ids), *sorted = nas_alloc(2 * (size_t)ngrid, sizeof *sorted);
  long *cp = nas_alloc((size_t)ngrid, sizeof *cp), *cd = nas_alloc((size_t)ngrid, sizeof *cd);
  unsigned *ps_comps = nas_alloc((size_t)ngrid, sizeof *ps_comps);
  const nas_cord **gcd = nas_alloc((size_t)ngrid, sizeof *gcd); /* displacement systems (NULL: basic) */
  /* CBAR/CBEAM offsets: the element's ends as nodes of their own, appended
     after the GRIDs, each the dependent of an all-DOF RBE2 on its GRID */
  double *off_x = NULL;
  long *off_id = NULL;
  int noff = 0, capoff = 0;
  const nas_card **grid_card = nas_alloc((size_t)ngrid, sizeof *grid_card);
  double *x = nas_alloc(3 * (size_t)ngrid, sizeof *x);
  unsigned char *fixed = nas_alloc(6 * (size_t)ngrid, 1);
  ir_beam *beams = nas_alloc((size_t)nel, sizeof *beams);
  long *eids = nas_alloc((size_t)nel, sizeof *eids);
  ir_point_mass *pms = nas_alloc((size_t)nmass, sizeof *pms);
  int nlinks = 0, capl = 0;
  ir_rigid_link *links = NULL;
  ncord = nprop = nmat = ngrid = 0;
  if (d.errors) goto done;

  /* first pass: systems, materials, properties, grids */
  for (int i = 0; i < d.ncards; i++) {
    const nas_card *c = &d.cards[i];
    if (!strcmp(c->name, "CORD2R")) {
      nas_cord *s = &cs[ncord];
      s->card = c;
      if (!get_int(&d, c, 1, "CID", 1, 0, &s->id) || !get_int(&d, c, 2, "RID", 0, 0, &s->rid)) continue;
      int ok = 1;
      for (int k = 0; k < 3; k++) {
        ok &= get_real(&d, c, 3 + k, "A", 0, 0, &s->a[k]);
        ok &= get_real(&d, c, 6 + k, "B", 0, 0, &s->b[k]);
        ok &= get_real(&d, c, 9 + k, "C", 0, 0, &s->c[k]);
      }
      if (!ok) continue;
      if (s->id <= 0 || find_cord(cs, ncord, s->id)) {
        nas_error(&d, c->file, field_loc(c, 1), "CORD2R: system id %ld is not positive or defined twice", s->id);
        continue;
      }
      ncord++;
    } else if (!strcmp(c->name, "MAT1")) {
      nas_mat *m = &ms[nmat];
      m->card = c;
      double E, G, nu, rho;
      int given_g = !is_blank(c, 3), given_nu = !is_blank(c, 4);
      if (!get_int(&d, c, 1, "MID", 1, 0, &m->id) || !get_real(&d, c, 2, "E", 1, 0, &E) ||
          !get_real(&d, c, 3, "G", 0, 0, &G) || !get_real(&d, c, 4, "NU", 0, 0, &nu) ||
          !get_real(&d, c, 5, "RHO", 0, 0, &rho))
        continue;
      if (!given_g && !given_nu) {
        nas_error(&d, c->file, c->loc, "MAT1 %ld: give G or NU (the shear modulus is needed for torsion)", m->id);
        continue;
      }
      if (!given_g) G = E / (2 * (1 + nu));
      if (!(E > 0) || !(G > 0) || rho < 0) {
        nas_error(&d, c->file, c->loc, "MAT1 %ld: E and G must be positive and RHO nonnegative", m->id);
        continue;
      }
      if (find_mat(ms, nmat, m->id)) {
        nas_error(&d, c->file, field_loc(c, 1), "MAT1 %ld is defined twice", m->id);
        continue;
      }
      m->E = E;
      m->G = G;
      m->rho = rho;
      nmat++;
    } else if (!strcmp(c->name, "PBAR") || !strcmp(c->name, "PBARL") || !strcmp(c->name, "PBEAM") ||
               !strcmp(c->name, "PROD")) {
      nas_prop *p = &ps[nprop];
      memset(p, 0, sizeof *p);
      p->card = c;
      if (!get_int(&d, c, 1, "PID", 1, 0, &p->id) || !get_int(&d, c, 2, "MID", 1, 0, &p->mid)) continue;
      int ok = 1;
      double i12 = 0;
      if (!strcmp(c->name, "PBAR")) {
        ok = get_real(&d, c, 3, "A", 1, 0, &p->A) && get_real(&d, c, 4, "I1", 0, 0, &p->I1) &&
             get_real(&d, c, 5, "I2", 0, 0, &p->I2) && get_real(&d, c, 6, "J", 0, 0, &p->J) &&
             get_real(&d, c, 7, "NSM", 0, 0, &p->nsm) && get_real(&d, c, 17, "K1", 0, 0, &p->k1) &&
             get_real(&d, c, 18, "K2", 0, 0, &p->k2) && get_real(&d, c, 19, "I12", 0, 0, &i12);
      } else if (!strcmp(c->name, "PBEAM")) {
        const char *so = field(c, 9)->text;
        if (so[0] && isalpha((unsigned char)so[0])) {
          nas_error(&d, c->file, field_loc(c, 9), "PBEAM %ld: intermediate stations (a tapered beam) are "
                    "not supported: only a constant section", p->id);
          continue;
        }
        ok = get_real(&d, c, 3, "A", 1, 0, &p->A) && get_real(&d, c, 4, "I1", 0, 0, &p->I1) &&
             get_real(&d, c, 5, "I2", 0, 0, &p->I2) && get_real(&d, c, 6, "I12", 0, 0, &i12) &&
             get_real(&d, c, 7, "J", 0, 0, &p->J) && get_real(&d, c, 8, "NSM", 0, 0, &p->nsm) &&
             get_real(&d, c, 17, "K1", 0, 1, &p->k1) && get_real(&d, c, 18, "K2", 0, 1, &p->k2);
      } else if (!strcmp(c->name, "PROD")) {
        ok = get_real(&d, c, 3, "A", 1, 0, &p->A) && get_real(&d, c, 4, "J", 0, 0, &p->J) &&
             get_real(&d, c, 6, "NSM", 0, 0, &p->nsm);
        p->rod = 1;
      } else {
        ok = pbarl_section(&d, c, p) == 0;
      }
      if (!ok) continue;
      if (i12 != 0) {
        nas_error(&d, c->file, c->loc, "%s %ld: a product of area I12 is not supported (use principal axes)",
                  c->name, p->id);
        continue;
      }
      if (!(p->A > 0) || p->I1 < 0 || p->I2 < 0 || p->J < 0 || p->nsm < 0 || p->k1 < 0 || p->k2 < 0) {
        nas_error(&d, c->file, c->loc, "%s %ld: A must be positive, I1, I2, J, NSM, K1, K2 nonnegative",
                  c->name, p->id);
        continue;
      }
      if ((p->k1 > 0) != (p->k2 > 0)) {
        nas_error(&d, c->file, field_loc(c, 17), "%s %ld: shear flexibility in one plane only (K1 %g, K2 %g) "
                  "is not supported", c->name, p->id, p->k1, p->k2);
        continue;
      }
      p->timoshenko = p->k1 > 0;
      if (find_prop(ps, nprop, p->id)) {
        nas_error(&d, c->file, field_loc(c, 1), "property %ld is defined twice", p->id);
        continue;
      }
      nprop++;
    } else if (!strcmp(c->name, "GRID")) {
      long id, seid;
      unsigned comps = 0;
      double p[3];
      if (!get_int(&d, c, 1, "ID", 1, 0, &id) || !get_int(&d, c, 2, "CP", 0, 0, &cp[ngrid]) ||
          !get_real(&d, c, 3, "X1", 0, 0, &p[0]) || !get_real(&d, c, 4, "X2", 0, 0, &p[1]) ||
          !get_real(&d, c, 5, "X3", 0, 0, &p[2]) || !get_int(&d, c, 6, "CD", 0, 0, &cd[ngrid]) ||
          !get_int(&d, c, 8, "SEID", 0, 0, &seid))
        continue;
      if (!is_blank(c, 7) && !get_components(&d, c, 7, &comps)) continue;
      if (cd[ngrid] < 0) {
        nas_error(&d, c->file, field_loc(c, 6), "GRID %ld: CD must be 0 or a CORD2R (got %ld)", id, cd[ngrid]);
        continue;
      }
      if (seid != 0) {
        nas_error(&d, c->file, field_loc(c, 8), "GRID %ld: superelements are not supported", id);
        continue;
      }
      ids[ngrid] = id;
      grid_card[ngrid] = c;
      memcpy(x + 3 * ngrid, p, sizeof p);
      ps_comps[ngrid] = comps; /* in CD: applied once the systems are known */
      ngrid++;
    }
  }
  for (int i = 0; i < ncord; i++) resolve_cord(&d, cs, ncord, &cs[i]);
  if (d.errors) goto done;
  for (int k = 0; k < ngrid; k++) {
    sorted[2 * k] = ids[k];
    sorted[2 * k + 1] = k;
    if (cp[k] != 0) {
      nas_cord *s = find_cord(cs, ncord, cp[k]);
      if (!s) {
        nas_error(&d, grid_card[k]->file, field_loc(grid_card[k], 2), "GRID %ld: coordinate system %ld "
                  "is not defined (only CORD2R)", ids[k], cp[k]);
        continue;
      }
      double p[3];
      cord_to_basic(s, x + 3 * k, p);
      memcpy(x + 3 * k, p, sizeof p);
    }
    if (cd[k] != 0) {
      gcd[k] = find_cord(cs, ncord, cd[k]);
      if (!gcd[k]) {
        nas_error(&d, grid_card[k]->file, field_loc(grid_card[k], 6), "GRID %ld: displacement coordinate "
                  "system %ld is not defined (only CORD2R)", ids[k], cd[k]);
        continue;
      }
    }
    unsigned comps;
    if (ps_comps[k] && basic_components(&d, grid_card[k], 7, gcd[k], ids[k], ps_comps[k], &comps))
      for (int b = 0; b < 6; b++)
        if (comps >> b & 1) fixed[6 * k + b] = 1;
  }
  qsort(sorted, (size_t)ngrid, 2 * sizeof *sorted, cmp_long_first);
  for (int k = 1; k < ngrid; k++)
    if (sorted[2 * k] == sorted[2 * k - 2]) {
      const nas_card *c = grid_card[sorted[2 * k + 1]];
      nas_error(&d, c->file, field_loc(c, 1), "GRID %ld is defined twice", sorted[2 * k]);
    }
  if (d.errors) goto done;

  /* second pass: elements, masses, constraints */
  nel = nmass = 0;
  for (int i = 0; i < d.ncards; i++) {
    const nas_card *c = &d.cards[i];
    if (!strcmp(c->name, "CBAR") || !strcmp(c->name, "CBEAM") || !strcmp(c->name, "CROD")) {
      int rod = !strcmp(c->name, "CROD");
      long eid, pid;
      int ga, gb;
      if (!get_int(&d, c, 1, "EID", 1, 0, &eid) || !get_int(&d, c, 2, "PID", 1, 0, &pid) ||
          !grid_ref(&d, c, 3, "GA", sorted, ngrid, &ga) || !grid_ref(&d, c, 4, "GB", sorted, ngrid, &gb))
        continue;
      nas_prop *p = find_prop(ps, nprop, pid);
      if (!p) {
        nas_error(&d, c->file, field_loc(c, 2), "%s %ld: property %ld is not defined", c->name, eid, pid);
        continue;
      }
      if (p->rod != rod || (!strcmp(c->name, "CBEAM") && strcmp(p->card->name, "PBEAM")) ||
          (!strcmp(c->name, "CBAR") && strcmp(p->card->name, "PBAR") && strcmp(p->card->name, "PBARL"))) {
        nas_error(&d, c->file, field_loc(c, 2), "%s %ld: property %ld is a %s", c->name, eid, pid, p->card->name);
        continue;
      }
      nas_mat *m = find_mat(ms, nmat, p->mid);
      if (!m) {
        nas_error(&d, p->card->file, field_loc(p->card, 2), "%s %ld: material %ld is not defined (MAT1)",
                  p->card->name, p->id, p->mid);
        continue;
      }
      if (ga == gb) {
        nas_error(&d, c->file, c->loc, "%s %ld: its two GRIDs coincide (zero length)", c->name, eid);
        continue;
      }
      double v[3] = {0, 0, 0}, w[2][3] = {{0, 0, 0}, {0, 0, 0}}; /* orientation, offsets WA, WB */
      if (!rod) {
        const char *t5 = field(c, 5)->text;
        int g0 = t5[0] && !strchr(t5, '.') && !strchr(t5, 'E') && is_blank(c, 6) && is_blank(c, 7);
        if (g0) {
          int go;
          if (!grid_ref(&d, c, 5, "G0", sorted, ngrid, &go)) continue;
          for (int k = 0; k < 3; k++) v[k] = x[3 * go + k] - x[3 * ga + k];
        } else if (!get_real(&d, c, 5, "X1", 1, 0, &v[0]) || !get_real(&d, c, 6, "X2", 0, 0, &v[1]) ||
                   !get_real(&d, c, 7, "X3", 0, 0, &v[2])) {
          continue;
        }
        /* OFFT: the system of the orientation vector (G: GA's displacement
           system, B: basic), then of the offsets at A and at B (G: that end's
           displacement system; O, the element's system, is not read) */
        const char *offt = field(c, 8)->text;
        if (offt[0] && strcmp(offt, "GGG") && strcmp(offt, "BGG")) {
          nas_error(&d, c->file, field_loc(c, 8), "%s %ld: OFFT '%s' is not supported (GGG or BGG: offsets in "
                    "the element system, O, are not)", c->name, eid, offt);
          continue;
        }
        if (!g0) cord_dir_to_basic(offt[0] == 'B' ? NULL : gcd[ga], v, v);
        int bad = 0;
        for (int k = 9; k <= 18 && !bad; k++) {
          if (k >= 11 && k <= 16) continue; /* the offsets */
          if (!is_blank(c, k)) {
            double val = 0;
            const char *t = field(c, k)->text;
            bad = !(parse_real(t, &val) && val == 0) && strcmp(t, "0");
            if (bad)
              nas_error(&d, c->file, field_loc(c, k), "%s %ld: pin flags and warping are not supported "
                        "(field %d is '%s')", c->name, eid, k + 1, t);
          }
        }
        for (int k = 0; k < 6 && !bad; k++) bad = !get_real(&d, c, 11 + k, k < 3 ? "WA" : "WB", 0, 0, &w[k / 3][k % 3]);
        if (bad) continue;
        cord_dir_to_basic(gcd[ga], w[0], w[0]);
        cord_dir_to_basic(gcd[gb], w[1], w[1]);
      }
      /* the element runs between its ends, the GRIDs moved by the offsets */
      double ax[3], len;
      for (int k = 0; k < 3; k++) ax[k] = x[3 * gb + k] + w[1][k] - x[3 * ga + k] - w[0][k];
      len = norm3v(ax);
      if (!(len > 0)) {
        nas_error(&d, c->file, c->loc, "%s %ld: its two ends coincide (zero length)", c->name, eid);
        continue;
      }
      if (rod) { /* no bending: any axis across it */
        v[fabs(ax[0]) <= fabs(ax[1]) && fabs(ax[0]) <= fabs(ax[2]) ? 0 : fabs(ax[1]) <= fabs(ax[2]) ? 1 : 2] = 1;
      } else {
        double cr[3];
        cross3(ax, v, cr);
        if (!(norm3v(cr) > 1e-6 * len * norm3v(v))) {
          nas_error(&d, c->file, field_loc(c, 5), "%s %ld: the orientation vector is zero or along the "
                    "element", c->name, eid);
          continue;
        }
      }
      int end_node[2] = {ga, gb};
      for (int e = 0; e < 2; e++) {
        if (w[e][0] == 0 && w[e][1] == 0 && w[e][2] == 0) continue;
        if (noff == capoff) {
          capoff = capoff ? 2 * capoff : 16;
          double *nx = realloc(off_x, 3 * (size_t)capoff * sizeof *nx);
          long *ni = realloc(off_id, (size_t)capoff * sizeof *ni);
          if (!nx || !ni) out_of_memory();
          off_x = nx;
          off_id = ni;
        }
        for (int k = 0; k < 3; k++) off_x[3 * noff + k] = x[3 * end_node[e] + k] + w[e][k];
        off_id[noff] = -(10 * eid + 1 + e); /* no GRID id is negative */
        push_link(&links, &nlinks, &capl, (ir_rigid_link){end_node[e], ngrid + noff, 63, field_loc(c, 11 + 3 * e)});
        end_node[e] = ngrid + noff++;
      }
      eids[nel] = eid;
      ir_beam *b = &beams[nel++];
      memset(b, 0, sizeof *b);
      b->node[0] = end_node[0];
      b->node[1] = end_node[1];
      b->theory = p->timoshenko ? BEAM_TIMOSHENKO : BEAM_EULER_BERNOULLI;
      b->E = m->E;
      b->G = m->G;
      b->rho = m->rho + p->nsm / p->A; /* non-structural mass spread like the section's */
      b->A = p->A;
      b->Iz = rod ? 0 : p->I1; /* plane 1 (x-y) bends about z */
      b->Iy = rod ? 0 : p->I2;
      b->J = p->J;
      b->shear_y = p->timoshenko ? p->k1 : 0;
      b->shear_z = p->timoshenko ? p->k2 : 0;
      memcpy(b->yaxis, v, sizeof v);
      b->loc = c->loc;
    } else if (!strcmp(c->name, "CONM2")) {
      long eid, cid;
      int g;
      double mass, off[3], I[6];
      if (!get_int(&d, c, 1, "EID", 1, 0, &eid) || !grid_ref(&d, c, 2, "G", sorted, ngrid, &g) ||
          !get_int(&d, c, 3, "CID", 0, 0, &cid) || !get_real(&d, c, 4, "M", 1, 0, &mass))
        continue;
      int ok = 1;
      for (int k = 0; k < 3; k++) ok &= get_real(&d, c, 5 + k, "X", 0, 0, &off[k]);
      for (int k = 0; k < 6; k++) ok &= get_real(&d, c, 9 + k, "I", 0, 0, &I[k]);
      if (!ok) continue;
      if (off[0] != 0 || off[1] != 0 || off[2] != 0) {
        nas_error(&d, c->file, field_loc(c, 5), "CONM2 %ld: an offset mass is not supported (put a GRID at "
                  "its centre of mass and an RBE2 to it)", eid);
        continue;
      }
      if (mass < 0) {
        nas_error(&d, c->file, field_loc(c, 4), "CONM2 %ld: negative mass", eid);
        continue;
      }
      /* Nastran's products of inertia enter with a minus sign */
      double J[9] = {I[0], -I[1], -I[3], -I[1], I[2], -I[4], -I[3], -I[4], I[5]};
      if (cid > 0) {
        nas_cord *s = find_cord(cs, ncord, cid);
        if (!s) {
          nas_error(&d, c->file, field_loc(c, 3), "CONM2 %ld: coordinate system %ld is not defined", eid, cid);
          continue;
        }
        double T[9] = {0}, R[9]; /* R = axes^T (columns x, y, z): J_basic = R J R^T */
        for (int a = 0; a < 3; a++)
          for (int b = 0; b < 3; b++) R[3 * a + b] = s->axes[3 * b + a];
        for (int a = 0; a < 3; a++)
          for (int b = 0; b < 3; b++)
            for (int k = 0; k < 3; k++) T[3 * a + b] += R[3 * a + k] * J[3 * k + b];
        for (int a = 0; a < 3; a++)
          for (int b = 0; b < 3; b++) {
            J[3 * a + b] = 0;
            for (int k = 0; k < 3; k++) J[3 * a + b] += T[3 * a + k] * R[3 * b + k];
          }
      } else if (cid < -1) {
        nas_error(&d, c->file, field_loc(c, 3), "CONM2 %ld: CID must be -1, 0 or a CORD2R", eid);
        continue;
      }
      ir_point_mass *pm = &pms[nmass++];
      pm->node = g;
      pm->mass = mass;
      memcpy(pm->inertia, J, sizeof J);
      pm->loc = c->loc;
    } else if (!strcmp(c->name, "SPC")) {
      for (int k = 0; k < 2; k++) {
        if (k == 1 && is_blank(c, 5)) break;
        int g;
        unsigned comps;
        double v;
        if (!grid_ref(&d, c, 2 + 3 * k, "G", sorted, ngrid, &g) || !get_components(&d, c, 3 + 3 * k, &comps) ||
            !get_real(&d, c, 4 + 3 * k, "D", 0, 0, &v))
          break;
        if (v != 0) {
          nas_error(&d, c->file, field_loc(c, 4 + 3 * k), "SPC: an enforced displacement is not supported");
          break;
        }
        if (!basic_components(&d, c, 3 + 3 * k, gcd[g], ids[g], comps, &comps)) break;
        for (int b = 0; b < 6; b++)
          if (comps >> b & 1) fixed[6 * g + b] = 1;
      }
    } else if (!strcmp(c->name, "SPC1")) {
      unsigned comps;
      if (!get_components(&d, c, 2, &comps)) continue;
      for (int k = 3; k < c->nf; k++) {
        if (is_blank(c, k)) continue;
        if (!strcmp(field(c, k)->text, "THRU")) {
          long lo, hi;
          if (k < 4 || !get_int(&d, c, k - 1, "G", 1, 0, &lo) || !get_int(&d, c, k + 1, "G", 1, 0, &hi) || hi < lo) {
            nas_error(&d, c->file, field_loc(c, k), "SPC1: 'THRU' needs a GRID id before and a larger one after");
            break;
          }
          for (long id = lo + 1; id < hi; id++) {
            int g = grid_index(sorted, ngrid, id);
            unsigned basic;
            if (g >= 0 && basic_components(&d, c, 2, gcd[g], ids[g], comps, &basic))
              for (int b = 0; b < 6; b++)
                if (basic >> b & 1) fixed[6 * g + b] = 1;
          }
          continue;
        }
        int g;
        unsigned basic;
        if (!grid_ref(&d, c, k, "G", sorted, ngrid, &g) || !basic_components(&d, c, 2, gcd[g], ids[g], comps, &basic))
          break;
        for (int b = 0; b < 6; b++)
          if (basic >> b & 1) fixed[6 * g + b] = 1;
      }
    } else if (!strcmp(c->name, "RBE2")) {
      long eid;
      int gn;
      unsigned comps;
      if (!get_int(&d, c, 1, "EID", 1, 0, &eid) || !grid_ref(&d, c, 2, "GN", sorted, ngrid, &gn) ||
          !get_components(&d, c, 3, &comps))
        continue;
      int count = 0;
      for (int k = 4; k < c->nf; k++) {
        if (is_blank(c, k)) continue;
        if (strchr(field(c, k)->text, '.')) break; /* ALPHA (thermal): ignored */
        int g;
        unsigned dofs;
        if (!grid_ref(&d, c, k, "GM", sorted, ngrid, &g) || !basic_components(&d, c, 3, gcd[g], ids[g], comps, &dofs))
          break;
        if (g == gn) {
          nas_error(&d, c->file, field_loc(c, k), "RBE2 %ld: GRID %ld is both independent and dependent", eid, ids[g]);
          break;
        }
        int clash = 0;
        for (int l = 0; l < nlinks && !clash; l++)
          clash = (links[l].dependent == g && (links[l].dofs & dofs)) || links[l].independent == g ||
                  links[l].dependent == gn;
        if (clash) {
          nas_error(&d, c->file, field_loc(c, k), "RBE2 %ld: GRID %ld is dependent in two RBE2s, or "
                    "RBE2s are chained (an independent GRID dependent on another RBE2)", eid, ids[g]);
          break;
        }
        push_link(&links, &nlinks, &capl, (ir_rigid_link){gn, g, dofs, field_loc(c, k)});
        count++;
      }
      if (count == 0 && d.errors == 0)
        nas_error(&d, c->file, c->loc, "RBE2 %ld: no dependent GRIDs", eid);
    }
  }
  if (d.errors) goto done;
  if (noff) { /* the offset ends after the GRIDs */
    long *all_ids = nas_alloc((size_t)(ngrid + noff), sizeof *all_ids);
    double *all_x = nas_alloc(3 * (size_t)(ngrid + noff), sizeof *all_x);
    unsigned char *all_fixed = nas_alloc(6 * (size_t)(ngrid + noff), 1);
    memcpy(all_ids, ids, (size_t)ngrid * sizeof *ids);
    memcpy(all_ids + ngrid, off_id, (size_t)noff * sizeof *ids);
    memcpy(all_x, x, 3 * (size_t)ngrid * sizeof *x);
    memcpy(all_x + 3 * ngrid, off_x, 3 * (size_t)noff * sizeof *x);
    memcpy(all_fixed, fixed, 6 * (size_t)ngrid);
    free(ids); free(x); free(fixed);
    ids = all_ids;
    x = all_x;
    fixed = all_fixed;
    ngrid += noff;
  }
  /* the model */
  fx->nnodes = ngrid;
  fx->node_ids = ids;
  ids = NULL;
  fx->beams = beams;
  fx->nbeams = nel;
  beams = NULL;
  fx->beam_ids = eids;
  eids = NULL;
  fx->point_masses = pms;
  fx->npoint_masses = nmass;
  pms = NULL;
  fx->links = links;
  fx->nlinks = nlinks;
  links = NULL;
  int any_fixed = 0;
  for (int i = 0; i < 6 * ngrid; i++) any_fixed |= fixed[i];
  if (any_fixed) {
    fx->fixed = fixed;
    fixed = NULL;
  }
  fx->fe_path = nas_alloc(strlen(path) + 1, 1);
  strcpy(fx->fe_path, path);
  *global = x;
  x = NULL;
done:
  free(cs); free(ps); free(ms); free(ids); free(sorted); free(cp); free(cd); free(ps_comps); free(gcd);
  free(off_x); free(off_id); free(grid_card); free(x);
  free(fixed); free(beams); free(eids); free(pms); free(links);
  for (int i = 0; i < d.ncards; i++) free(d.cards[i].f);
  free(d.cards);
  for (int i = 0; i < d.nfiles; i++) free(d.files[i]);
  free(d.files);
  return diag_errors() > errors_before || d.errors ? 2 : 0;
}

/* --- shared by the importers ---------------------------------------------------- */

void fe_import_to_body(ir_flex *fx, const double A[9]) {
  int identity = 1;
  for (int i = 0; i < 9; i++) identity &= A[i] == (i % 4 == 0 ? 1.0 : 0.0);
  if (identity) return;
  for (int p = 0; p < fx->npoint_masses; p++) { /* J_body = A^T J A */
    double *J = fx->point_masses[p].inertia, T[9] = {0}, B[9] = {0};
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        for (int k = 0; k < 3; k++) T[3 * a + b] += A[3 * k + a] * J[3 * k + b];
    for (int a = 0; a < 3; a++)
      for (int b = 0; b < 3; b++)
        for (int k = 0; k < 3; k++) B[3 * a + b] += T[3 * a + k] * A[3 * k + b];
    memcpy(J, B, sizeof B);
  }
  ir_fe_matrix *G[2] = {fx->K_given, fx->M_given};
  for (int g = 0; g < 2; g++) { /* K_body = R^T K R, R = blockdiag(A): 9 entries from each */
    if (!G[g]) continue;
    int n = G[g]->nnz;
    int *row = nas_alloc(9 * (size_t)n, sizeof *row), *col = nas_alloc(9 * (size_t)n, sizeof *col);
    double *val = nas_alloc(9 * (size_t)n, sizeof *val);
    int m = 0;
    for (int t = 0; t < n; t++) {
      int i = G[g]->row[t], j = G[g]->col[t], al = i % 3, be = j % 3;
      for (int a = 0; a < 3; a++)
        for (int b = 0; b < 3; b++) {
          double v = A[3 * al + a] * G[g]->val[t] * A[3 * be + b];
          if (v == 0) continue;
          row[m] = i - al + a;
          col[m] = j - be + b;
          val[m++] = v;
        }
    }
    free(G[g]->row); free(G[g]->col); free(G[g]->val);
    G[g]->row = row;
    G[g]->col = col;
    G[g]->val = val;
    G[g]->nnz = m;
  }
}

int fe_node_index(const ir_flex *fx, long id) {
  if (!fx->node_ids) return id >= 0 && id < fx->nnodes ? (int)id : -1;
  for (int k = 0; k < fx->nnodes; k++)
    if (fx->node_ids[k] == id) return k;
  return -1;
}

int fe_chord_axes(const double a[3], const double b[3], double e[4]) {
  double x[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]}, n = norm3v(x);
  if (!(n > 0)) return -1;
  for (int i = 0; i < 3; i++) x[i] /= n;
  double y[3] = {0, 1, 0};
  if (fabs(x[1]) > 0.9) { y[1] = 0; y[2] = 1; }
  double dd = x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
  for (int i = 0; i < 3; i++) y[i] -= dd * x[i];
  double ny = norm3v(y);
  for (int i = 0; i < 3; i++) y[i] /= ny;
  double z[3];
  cross3(x, y, z);
  /* A = [x y z] (columns): global = A body; Euler parameters from A */
  double A[9] = {x[0], y[0], z[0], x[1], y[1], z[1], x[2], y[2], z[2]};
  double tr = A[0] + A[4] + A[8];
  if (tr > 0) {
    double s = 2 * sqrt(1 + tr);
    e[0] = s / 4; e[1] = (A[7] - A[5]) / s; e[2] = (A[2] - A[6]) / s; e[3] = (A[3] - A[1]) / s;
  } else if (A[0] > A[4] && A[0] > A[8]) {
    double s = 2 * sqrt(1 + A[0] - A[4] - A[8]);
    e[0] = (A[7] - A[5]) / s; e[1] = s / 4; e[2] = (A[1] + A[3]) / s; e[3] = (A[2] + A[6]) / s;
  } else if (A[4] > A[8]) {
    double s = 2 * sqrt(1 + A[4] - A[0] - A[8]);
    e[0] = (A[2] - A[6]) / s; e[1] = (A[1] + A[3]) / s; e[2] = s / 4; e[3] = (A[5] + A[7]) / s;
  } else {
    double s = 2 * sqrt(1 + A[8] - A[0] - A[4]);
    e[0] = (A[3] - A[1]) / s; e[1] = (A[2] + A[6]) / s; e[2] = (A[5] + A[7]) / s; e[3] = s / 4;
  }
  return 0;
}

void fe_import_free(ir_flex *fx) {
  free(fx->fe_path);
  free(fx->node_ids);
  free(fx->beam_ids);
  free(fx->fixed);
  free(fx->links);
  ir_fe_matrix *G[2] = {fx->K_given, fx->M_given};
  for (int g = 0; g < 2; g++)
    if (G[g]) { free(G[g]->row); free(G[g]->col); free(G[g]->val); free(G[g]); }
  free(fx->w0);
  free(fx->wd0);
}
