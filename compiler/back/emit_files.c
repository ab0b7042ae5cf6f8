/* emit_files.c: a large generated model as several translation units
 * (emit_files.h has the layout).
 *
 * Why: one file of a large model is compiled by one C compiler process,
 * whatever the number of cores, and its time grows with the model; the
 * evaluation's parts (emit_split.c) and the LDL^T are independent functions,
 * so they can be compiled apart and in parallel (the build step of mbcc run
 * forks one compiler per core).
 *
 * The parts read some of <m>.c's static tables (markers' offsets, force
 * parameters, profiles, flexible bodies' data), whose text does not change.
 * A constant one (and the constant tables and functions it names) is copied
 * into each part file that reads it, static there too, so that the C
 * compiler folds its values as it did in one file.  One that set_params
 * changes (a run-time parameter's pool) must exist once: <m>.c defines a
 * const pointer to it (<m>_ref_<table>, declared in <m>_parts.h) and the part
 * file maps the table's name onto it with a macro.  Either way the parts'
 * text is the single file's. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "emit_files.h"
#include "emit_util.h"

#define DEFAULT_FILE_BYTES 100000L /* measured: docs/architecture.md, "The evaluation in parts" */

long eval_file_bytes(void) { return emit_size_setting("MBCC_EVAL_FILE_BYTES", DEFAULT_FILE_BYTES); }

static int text_open(gen_text *g) {
  if (g->f) return 0;
  g->f = open_memstream(&g->text, &g->len);
  return g->f ? 0 : -1;
}

/* the text so far (valid until the next write) */
static int text_sync(gen_text *g) {
  if (!g->f) return 0;
  return fflush(g->f) || ferror(g->f) ? -1 : 0;
}

static void text_free(gen_text *g) {
  if (g->f) fclose(g->f);
  free(g->text);
  memset(g, 0, sizeof *g);
}

void emit_files_init(emit_files *F, const char *nm) {
  memset(F, 0, sizeof *F);
  F->nm = nm;
  F->file_bytes = eval_file_bytes();
}

static FILE *part_file(void *ctx, int part, int nparts) {
  emit_files *F = ctx;
  if (F->failed) return NULL;
  if (!F->eval) {
    long per = eval_part_bytes();
    int k = per > 0 ? (int)((F->file_bytes + per / 2) / per) : 1;
    F->parts_per_file = k < 1 ? 1 : k;
    F->neval = (nparts + F->parts_per_file - 1) / F->parts_per_file;
    F->eval = calloc((size_t)F->neval, sizeof *F->eval);
    F->eval_macros = calloc((size_t)F->neval, sizeof *F->eval_macros);
    if (!F->eval || !F->eval_macros) { F->failed = 1; return NULL; }
    for (int i = 0; i < F->neval; i++) snprintf(F->eval[i].name, sizeof F->eval[i].name, "%s_eval%d.c", F->nm, i);
  }
  F->active = 1;
  int k = part / F->parts_per_file;
  if (k >= F->neval || text_open(&F->eval[k])) { F->failed = 1; return NULL; }
  return F->eval[k].f;
}

const eval_files *emit_files_eval_hooks(emit_files *F) {
  if (F->file_bytes <= 0) return NULL;
  snprintf(F->header.name, sizeof F->header.name, "%s_parts.h", F->nm);
  if (text_open(&F->header)) return NULL;
  F->hooks.header = F->header.f;
  F->hooks.header_name = F->header.name;
  F->hooks.part_file = part_file;
  F->hooks.ctx = F;
  return &F->hooks;
}

/* --- identifiers in emitted C ---------------------------------------------- */

static int ident_char(int c) { return isalnum(c) || c == '_'; }

/* the next name of text[*pp, end): an identifier outside comments, strings
 * and numbers that is not a member (after '.' or '->'); its length in *n, NULL
 * at the end */
static const char *next_name(const char *text, const char **pp, const char *end, size_t *n) {
  const char *p = *pp;
  while (p < end) {
    if (*p == '/' && p + 1 < end && p[1] == '*') {
      const char *e = p + 2;
      while (e + 1 < end && !(e[0] == '*' && e[1] == '/')) e++;
      p = e + 2;
      continue;
    }
    if (*p == '/' && p + 1 < end && p[1] == '/') {
      while (p < end && *p != '\n') p++;
      continue;
    }
    if (*p == '"' || *p == '\'') {
      char q = *p;
      for (p++; p < end && *p != q; p++)
        if (*p == '\\') p++;
      p++;
      continue;
    }
    if (ident_char((unsigned char)*p)) {
      const char *s = p;
      while (p < end && ident_char((unsigned char)*p)) p++;
      if (isdigit((unsigned char)*s)) continue;
      const char *b = s - 1;
      while (b >= text && *b == ' ') b--;
      if (b >= text && (*b == '.' || (*b == '>' && b > text && b[-1] == '-'))) continue;
      *pp = p;
      *n = (size_t)(p - s);
      return s;
    }
    p++;
  }
  *pp = end;
  return NULL;
}

int c_text_names(const char *text, size_t len, const char *name) {
  size_t n = strlen(name), k;
  const char *p = text, *s;
  while ((s = next_name(text, &p, text + len, &k)) != NULL)
    if (k == n && !memcmp(s, name, n)) return 1;
  return 0;
}

/* names[0..count) by hash (open addressing): which of them a text names, in
 * one pass over the text (a scan per name grew with files x statics x text) */
typedef struct {
  const char *const *names;
  int *slot, mask;
} name_index;

static unsigned name_hash(const char *s, size_t n) {
  unsigned h = 2166136261u; /* FNV-1a */
  for (size_t i = 0; i < n; i++) h = (h ^ (unsigned char)s[i]) * 16777619u;
  return h;
}

static int index_build(name_index *x, const char *const *names, int count) {
  int cap = 16;
  while (cap < 2 * count + 1) cap *= 2;
  x->names = names;
  x->mask = cap - 1;
  x->slot = malloc(sizeof(int) * (size_t)cap);
  if (!x->slot) return -1;
  for (int i = 0; i < cap; i++) x->slot[i] = -1;
  for (int i = 0; i < count; i++) {
    unsigned h = name_hash(names[i], strlen(names[i])) & (unsigned)x->mask;
    while (x->slot[h] >= 0) h = (h + 1) & (unsigned)x->mask;
    x->slot[h] = i;
  }
  return 0;
}

/* the first of the names equal to s[0..n), or -1 */
static int index_find(const name_index *x, const char *s, size_t n) {
  unsigned h = name_hash(s, n) & (unsigned)x->mask;
  for (; x->slot[h] >= 0; h = (h + 1) & (unsigned)x->mask) {
    const char *c = x->names[x->slot[h]];
    if (strlen(c) == n && !memcmp(c, s, n)) return x->slot[h];
  }
  return -1;
}

/* count[i] += how often text names names[i] (count may be NULL: mark[i] = 1) */
static void index_scan(const name_index *x, const char *text, size_t len, int *count, char *mark) {
  const char *p = text, *s;
  size_t k;
  while ((s = next_name(text, &p, text + len, &k)) != NULL) {
    int i = index_find(x, s, k);
    if (i < 0) continue;
    if (count) count[i]++;
    if (mark && !mark[i]) mark[i] = 1;
  }
}

/* --- the tables the parts read ---------------------------------------------- */

enum { DECL_ARRAY, DECL_OBJECT, DECL_FUNCTION, DECL_OTHER };

/* a file-scope "static PRE NAME..." line at p: its kind, name and PRE (the
 * text before the name), and for a function its parameter list */
static int read_static(const char *p, const char *end, const char **name, size_t *nlen, const char **pre,
                       size_t *plen, const char **params, size_t *parlen) {
  p += 7; /* "static " */
  *pre = p;
  const char *d = p;
  while (d < end && *d != '\n' && !strchr("[(=;{", *d)) d++;
  if (d >= end || *d == '\n') return DECL_OTHER;
  const char *e = d;
  while (e > p && e[-1] == ' ') e--;
  const char *s = e;
  while (s > p && ident_char((unsigned char)s[-1])) s--;
  if (s == e || s == p) return DECL_OTHER;
  *name = s;
  *nlen = (size_t)(e - s);
  const char *pe = s;
  while (pe > p && pe[-1] == ' ') pe--;
  *plen = (size_t)(pe - p);
  if (*d == '[') {
    const char *c = strchr(d, ']');
    return c && c + 1 < end && c[1] != '[' ? DECL_ARRAY : DECL_OTHER; /* one dimension only */
  }
  if (*d == '(') {
    int depth = 0;
    const char *c = d;
    for (; c < end && *c != '\n'; c++) {
      if (*c == '(') depth++;
      else if (*c == ')' && --depth == 0) break;
    }
    if (c >= end || *c != ')') return DECL_OTHER;
    *params = d;
    *parlen = (size_t)(c + 1 - d);
    return DECL_FUNCTION;
  }
  return DECL_OBJECT;
}

static int append(char **dst, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(NULL, 0, fmt, ap);
  va_end(ap);
  if (n < 0) return -1;
  size_t old = *dst ? strlen(*dst) : 0;
  char *r = realloc(*dst, old + (size_t)n + 1);
  if (!r) return -1;
  va_start(ap, fmt);
  vsnprintf(r + old, (size_t)n + 1, fmt, ap);
  va_end(ap);
  *dst = r;
  return 0;
}

/* a file-scope static of <m>.c */
typedef struct {
  char name[128];
  int kind, mutable_; /* mutable_: an object set_params may change (no const) */
  const char *pre, *params;
  size_t plen, parlen;
  const char *block; /* its whole declaration, up to the statement's end */
  size_t blen;
} static_decl;

/* the end of the statement or function that starts at p (depth back to 0
 * at a ';' or a closing '}' ending its line) */
static const char *block_end(const char *p, const char *end) {
  int depth = 0;
  for (; p < end; p++) {
    if (*p == '/' && p + 1 < end && p[1] == '*') {
      for (p += 2; p + 1 < end && !(p[0] == '*' && p[1] == '/'); p++) {}
      p++;
      continue;
    }
    if (*p == '"' || *p == '\'') {
      char q = *p;
      for (p++; p < end && *p != q; p++)
        if (*p == '\\') p++;
      continue;
    }
    if (*p == '(' || *p == '{' || *p == '[') depth++;
    else if (*p == ')' || *p == ']') depth--;
    else if (*p == '}') {
      if (--depth == 0 && (p + 1 >= end || p[1] == '\n')) return p + 1 < end ? p + 2 : end;
    } else if (*p == ';' && depth == 0) {
      while (p < end && *p != '\n') p++;
      return p < end ? p + 1 : end;
    }
  }
  return end;
}

static int parse_statics(const char *text, size_t len, static_decl **out) {
  const char *end = text + len;
  int n = 0, cap = 0;
  static_decl *v = NULL;
  for (const char *p = text; p < end; p++) {
    if (!(p == text || p[-1] == '\n') || end - p < 8 || memcmp(p, "static ", 7)) continue;
    static_decl d;
    memset(&d, 0, sizeof d);
    const char *name = 0;
    size_t nlen = 0;
    d.kind = read_static(p, end, &name, &nlen, &d.pre, &d.plen, &d.params, &d.parlen);
    if (!name || nlen >= sizeof d.name) continue;
    memcpy(d.name, name, nlen);
    d.mutable_ = d.kind != DECL_FUNCTION && strncmp(d.pre, "const ", 6);
    d.block = p;
    const char *e = block_end(p, end);
    d.blen = (size_t)(e - p);
    if (n == cap) {
      cap = cap ? 2 * cap : 64;
      static_decl *nv = realloc(v, sizeof *nv * (size_t)cap);
      if (!nv) { free(v); return -1; }
      v = nv;
    }
    v[n++] = d;
    p = e - 1;
  }
  *out = v;
  return n;
}

/* the pointer <m>_ref_<name> to a static of <m>.c: declared in <m>_parts.h,
 * defined in <m>.c (src) */
static void write_ref(emit_files *F, FILE *src, int kind, int plen, const char *pre, int parlen, const char *params,
                      const char *name) {
  if (kind == DECL_FUNCTION) {
    fprintf(F->refs.f, "extern %.*s (*const %s_ref_%s)%.*s;\n", plen, pre, F->nm, name, parlen, params);
    fprintf(src, "%.*s (*const %s_ref_%s)%.*s = %s;\n", plen, pre, F->nm, name, parlen, params, name);
    return;
  }
  fprintf(F->refs.f, "extern %.*s *const %s_ref_%s;\n", plen, pre, F->nm, name);
  fprintf(src, "%.*s *const %s_ref_%s = %s%s;\n", plen, pre, F->nm, name, kind == DECL_OBJECT ? "&" : "", name);
}

int emit_files_keep(emit_files *F, FILE *src, const char *text, size_t len) {
  int first = 1, nc = F->ncopied;
  /* how often <m>.c names each copied static, and how often its own text does */
  const char **names = malloc(sizeof *names * (size_t)(nc + 1));
  int *all = calloc((size_t)nc + 1, sizeof(int)), *own = calloc((size_t)nc + 1, sizeof(int));
  name_index x = {0};
  int ok = names && all && own;
  for (int i = 0; ok && i < nc; i++) {
    names[i] = F->copied[i].name;
    ok = F->copied[i].to <= len;
  }
  ok = ok && index_build(&x, names, nc) == 0;
  if (ok) {
    index_scan(&x, text, len, all, NULL);
    for (int i = 0; i < nc; i++) { /* its name in its own declaration */
      const keep_decl *c = &F->copied[i];
      const char *p = text + c->from, *e = text + c->to, *t;
      size_t k, n = strlen(c->name);
      while ((t = next_name(text, &p, e, &k)) != NULL) own[i] += k == n && !memcmp(t, c->name, n);
    }
  }
  for (int i = 0; ok && i < nc; i++) {
    keep_decl *c = &F->copied[i];
    if (all[i] > own[i]) continue; /* read elsewhere in <m>.c */
    if (c->kind == DECL_OTHER) { ok = 0; break; }
    if (first) fputs("\n/* tables only the evaluation's parts read (they have copies): kept for them */\n", src);
    first = 0;
    const char *par = c->params ? c->params : "";
    write_ref(F, src, c->kind, (int)strlen(c->decl_head), c->decl_head, (int)strlen(par), par, c->name);
  }
  free(names);
  free(all);
  free(own);
  free(x.slot);
  return ok ? text_sync(&F->refs) : -1;
}

int emit_files_tables(emit_files *F, FILE *src, const char *text, size_t len) {
  if (!F->active || F->failed || text_open(&F->refs)) return -1;
  for (int k = 0; k < F->neval; k++)
    if (text_sync(&F->eval[k])) return -1;
  static_decl *d = NULL;
  int n = parse_statics(text, len, &d);
  if (n < 0) return -1;
  char *need = calloc((size_t)n + 1, 1), *pointed = calloc((size_t)n + 1, 1), *copied = calloc((size_t)n + 1, 1);
  /* the statics each static's text names (refs[rp[i]..rp[i+1])), found once */
  const char **names = malloc(sizeof *names * (size_t)(n + 1));
  int *rp = calloc((size_t)n + 2, sizeof(int)), *refs = NULL;
  char *mark = calloc((size_t)n + 1, 1);
  name_index x = {0};
  int rc = need && pointed && copied && names && rp && mark ? 0 : -1;
  for (int i = 0; !rc && i < n; i++) names[i] = d[i].name;
  if (!rc) rc = index_build(&x, names, n);
  for (int i = 0; !rc && i < n; i++) {
    memset(mark, 0, (size_t)n);
    index_scan(&x, d[i].block, d[i].blen, NULL, mark);
    int cnt = 0;
    for (int j = 0; j < n; j++) cnt += mark[j] && j != i;
    int *nr = realloc(refs, sizeof(int) * (size_t)(rp[i] + cnt + 1));
    if (!nr) { rc = -1; break; }
    refs = nr;
    rp[i + 1] = rp[i];
    for (int j = 0; j < n; j++)
      if (mark[j] && j != i) refs[rp[i + 1]++] = j;
  }
  /* per file: the statics its parts read, and what the constant ones among
     them read in turn; a constant one is copied into the file (static
     there too, so the C compiler folds its values as in one file), a
     mutable one (set_params changes it) is read through a pointer */
  for (int k = 0; !rc && k < F->neval; k++) {
    memset(need, 0, (size_t)n);
    if (!F->eval[k].text) continue;
    index_scan(&x, F->eval[k].text, F->eval[k].len, NULL, need);
    for (int changed = 1; changed;) {
      changed = 0;
      for (int i = 0; i < n; i++) {
        if (!need[i] || d[i].mutable_ || need[i] == 2) continue;
        need[i] = 2; /* its references followed */
        for (int r = rp[i]; r < rp[i + 1]; r++)
          if (!need[refs[r]]) { need[refs[r]] = 1; changed = 1; }
      }
    }
    for (int i = 0; !rc && i < n; i++) {
      if (!need[i] || !d[i].mutable_) continue;
      if (d[i].kind != DECL_ARRAY && d[i].kind != DECL_OBJECT) { rc = -1; break; } /* not pointed at: one file */
      pointed[i] = 1;
      rc = append(&F->eval_macros[k], d[i].kind == DECL_ARRAY ? "#define %s %s_ref_%s\n" : "#define %s (*%s_ref_%s)\n",
                  d[i].name, F->nm, d[i].name);
    }
    for (int i = 0; !rc && i < n; i++) {
      if (!need[i] || d[i].mutable_) continue;
      copied[i] = 1;
      char *copy = malloc(d[i].blen + 1);
      if (!copy) { rc = -1; break; }
      memcpy(copy, d[i].block, d[i].blen);
      copy[d[i].blen] = 0;
      rc = append(&F->eval_macros[k], "%s", copy);
      free(copy);
    }
  }
  /* the copied statics: emit_files_keep looks at them once <m>.c is complete */
  for (int i = 0; !rc && i < n; i++) {
    if (!copied[i] || pointed[i]) continue;
    if (F->ncopied % 64 == 0) {
      keep_decl *nk = realloc(F->copied, sizeof *nk * (size_t)(F->ncopied + 64));
      if (!nk) { rc = -1; break; }
      F->copied = nk;
    }
    keep_decl *c = &F->copied[F->ncopied++];
    memset(c, 0, sizeof *c);
    snprintf(c->name, sizeof c->name, "%s", d[i].name);
    c->kind = d[i].kind;
    c->from = (size_t)(d[i].block - text);
    c->to = c->from + d[i].blen;
    if (append(&c->decl_head, "%.*s", (int)d[i].plen, d[i].pre) ||
        (d[i].kind == DECL_FUNCTION && append(&c->params, "%.*s", (int)d[i].parlen, d[i].params)))
      rc = -1;
  }
  int first = 1;
  for (int i = 0; !rc && i < n; i++) {
    if (!pointed[i]) continue;
    if (first) fputs("\n/* the tables the evaluation's parts read through a pointer (<m>_parts.h) */\n", src);
    first = 0;
    write_ref(F, src, d[i].kind, (int)d[i].plen, d[i].pre, (int)d[i].parlen, d[i].params, d[i].name);
  }
  free(names);
  free(rp);
  free(refs);
  free(mark);
  free(x.slot);
  free(need);
  free(pointed);
  free(copied);
  free(d);
  return rc ? -1 : text_sync(&F->refs);
}

/* the stream of the LDL^T's next part: the last file while it holds less
 * than file_bytes, else a new one */
static FILE *ldl_part_file(void *ctx, int *fresh) {
  emit_files *F = ctx;
  *fresh = 0;
  if (F->nldl_part) {
    gen_text *g = F->ldl_part[F->nldl_part - 1];
    if (text_sync(g)) return NULL;
    if ((long)g->len < F->file_bytes) return g->f;
  }
  /* each its own allocation: its stream writes through &g->text, &g->len */
  gen_text **v = realloc(F->ldl_part, sizeof *v * (size_t)(F->nldl_part + 1));
  if (!v) return NULL;
  F->ldl_part = v;
  gen_text *g = calloc(1, sizeof *g);
  if (!g) return NULL;
  v[F->nldl_part++] = g;
  snprintf(g->name, sizeof g->name, "%s_ldl%d.c", F->nm, F->nldl_part - 1);
  if (text_open(g)) return NULL;
  *fresh = 1;
  return g->f;
}

FILE *emit_files_ldl(emit_files *F, FILE *src, ldl_out *out) {
  snprintf(F->ldl.name, sizeof F->ldl.name, "%s_ldl.c", F->nm);
  if (text_open(&F->ldl)) return NULL;
  F->has_ldl = 1;
  out->wrappers = src;
  out->part_file = ldl_part_file;
  out->ctx = F;
  return F->ldl.f;
}

long emit_files_ldl_bytes(emit_files *F) {
  long n = 0;
  if (text_sync(&F->ldl)) return -1;
  n += (long)F->ldl.len;
  for (int k = 0; k < F->nldl_part; k++) {
    if (text_sync(F->ldl_part[k])) return -1;
    n += (long)F->ldl_part[k]->len;
  }
  return n;
}

/* the evaluation's files (the private header, then the parts' files): none
 * when only the LDL^T has files of its own */
static int eval_file_count(const emit_files *F) { return F->active ? 1 + F->neval : 0; }

int emit_files_count(const emit_files *F) {
  return F->active || F->has_ldl ? eval_file_count(F) + F->has_ldl + F->nldl_part + 1 : 0;
}

/* a malloc'ed copy of a + b + c */
static char *join3(const char *a, const char *b, size_t blen, const char *c, size_t *len) {
  size_t la = strlen(a), lc = strlen(c);
  char *r = malloc(la + blen + lc + 1);
  if (!r) return NULL;
  memcpy(r, a, la);
  if (blen) memcpy(r + la, b, blen);
  memcpy(r + la + blen, c, lc + 1);
  *len = la + blen + lc;
  return r;
}

char *emit_files_text(emit_files *F, int i, const char **name, size_t *len) {
  char head[2048], NM[256];
  upper(NM, F->nm, sizeof NM);
  if (text_sync(&F->header) || text_sync(&F->refs)) return NULL;
  if (F->active && i == 0) {
    *name = F->header.name;
    char *refs = F->refs.text ? F->refs.text : "";
    snprintf(head, sizeof head,
             "#ifndef %s_PARTS_H\n#define %s_PARTS_H\n\n#include \"%s.h\"\n\n"
             "/* the tables of %s.c the evaluation's parts read */\n",
             NM, NM, F->nm, F->nm);
    size_t l1;
    char *a = join3(head, refs, F->refs.len, "", &l1);
    if (!a) return NULL;
    char *r = join3(a, F->header.text, F->header.len, "\n#endif\n", len);
    free(a);
    return r;
  }
  if (F->active && i <= F->neval) {
    gen_text *g = &F->eval[i - 1];
    if (text_sync(g)) return NULL;
    *name = g->name;
    const char *mac = F->eval_macros[i - 1] ? F->eval_macros[i - 1] : "";
    snprintf(head, sizeof head, "\n#include \"%s\"\n\n/* the tables of %s.c these parts read: the constant ones copied, the others through their pointers */\n",
             F->header.name, F->nm);
    size_t l1;
    char *a = join3(head, mac, strlen(mac), "", &l1);
    if (!a) return NULL;
    char *r = join3(a, g->text, g->len, "", len);
    free(a);
    return r;
  }
  int k = i - eval_file_count(F) - F->has_ldl; /* an LDL^T part file: k >= 0 */
  if (F->has_ldl && k < F->nldl_part) {
    gen_text *g = k < 0 ? &F->ldl : F->ldl_part[k];
    if (text_sync(g)) return NULL;
    *name = g->name;
    snprintf(head, sizeof head, "\n#include \"%s.h\"\n\n", F->nm);
    return join3(head, g->text, g->len, "", len);
  }
  /* the list of the C files, <m>.c first */
  static char list_name[320];
  snprintf(list_name, sizeof list_name, "%s.sources", F->nm);
  *name = list_name;
  char *r = NULL;
  if (append(&r, "%s.c\n", F->nm)) return NULL;
  for (int k = 0; k < F->neval; k++)
    if (append(&r, "%s\n", F->eval[k].name)) { free(r); return NULL; }
  if (F->has_ldl && append(&r, "%s\n", F->ldl.name)) { free(r); return NULL; }
  for (int k = 0; k < F->nldl_part; k++)
    if (append(&r, "%s\n", F->ldl_part[k]->name)) { free(r); return NULL; }
  *len = strlen(r);
  return r;
}

void emit_files_free(emit_files *F) {
  text_free(&F->header);
  text_free(&F->refs);
  for (int k = 0; k < F->neval; k++) {
    text_free(&F->eval[k]);
    free(F->eval_macros[k]);
  }
  free(F->eval);
  free(F->eval_macros);
  text_free(&F->ldl);
  for (int k = 0; k < F->nldl_part; k++) {
    text_free(F->ldl_part[k]);
    free(F->ldl_part[k]);
  }
  free(F->ldl_part);
  for (int i = 0; i < F->ncopied; i++) {
    free(F->copied[i].decl_head);
    free(F->copied[i].params);
  }
  free(F->copied);
  memset(F, 0, sizeof *F);
}

char **emit_files_read_list(const char *dir, const char *nm) {
  char path[4400], line[400];
  snprintf(path, sizeof path, "%s/%s.sources", dir, nm);
  FILE *f = fopen(path, "r");
  if (!f) return NULL;
  char **v = calloc(1, sizeof *v);
  int n = 0, ok = v != NULL;
  while (ok && fgets(line, sizeof line, f)) {
    line[strcspn(line, "\n")] = 0;
    if (!line[0] || strchr(line, '/')) continue;
    char **bigger = realloc(v, (size_t)(n + 2) * sizeof *v);
    if (bigger) v = bigger;
    ok = bigger && (v[n] = strdup(line)) != NULL;
    if (ok) v[++n] = NULL;
  }
  fclose(f);
  if (!ok) {
    emit_files_list_free(v);
    return NULL;
  }
  return v;
}

void emit_files_list_free(char **names) {
  for (int i = 0; names && names[i]; i++) free(names[i]);
  free(names);
}
