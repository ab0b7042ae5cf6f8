/* emit_split.c: the generated evaluation in parts of bounded size.
 *
 * One straight-line function for the whole evaluation makes the C compiler's
 * time and memory grow faster than linearly with the model (its optimisation
 * passes see every value of the function at once): gcc -O2 took 16 s for a
 * 20-link chain, 842 s and 2.4 GB for 200 links.  Parts of bounded size keep
 * the cost per function bounded, so the total grows linearly.
 *
 * The parts are cut from the text emit_eval writes, at the element
 * boundaries it marks; the expressions themselves are not touched.  A value
 * declared at the top level of one part (a body frame f<b>, a marker k<m>, a
 * shared relative rotation entry) and read by a later part goes through a
 * struct in the calling function's frame: the declaring part stores it at its
 * end, each reading part copies it into a const local of the same name at its
 * start, so the text in between reads as in the single function.  Anything
 * this reader of the emitted text does not recognise (a top-level declaration
 * of another type, an array that crosses parts) leaves the evaluation as one
 * function: never a wrong split. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emit_split.h"

#define DEFAULT_PART_BYTES 24000L /* measured: docs/benchmarks.md, "Evaluation in parts" */
/* what one inlined kernel call costs gcc, in bytes of plain emitted text
 * (measured: docs/architecture.md, "What a part costs the C compiler") */
#define DEFAULT_CALL_BYTES 300L

/* from this many parts on, <m>_eval calls them in a loop over a table */
#define LOOPED_CALLS_FROM 32

static int ident_start(int c) { return isalpha(c) || c == '_'; }
static int ident_char(int c) { return isalnum(c) || c == '_'; }

long emit_size_setting(const char *env, long fallback) {
  const char *e = getenv(env);
  if (e && *e) {
    char *end;
    long v = strtol(e, &end, 10);
    if (*end == 0 && v >= 0) return v;
    /* a tuning knob, so the code stays right either way; but say so (once) */
    static char warned[256];
    if (strstr(warned, env) == NULL) {
      if (fallback >= 0) fprintf(stderr, "mbcc: warning: %s=%s is not a whole number >= 0; using %ld\n", env, e, fallback);
      else fprintf(stderr, "mbcc: warning: %s=%s is not a whole number >= 0; ignored\n", env, e);
      if (strlen(warned) + strlen(env) + 2 < sizeof warned) strcat(strcat(warned, env), " ");
    }
  }
  return fallback;
}

long eval_part_bytes(void) { return emit_size_setting("MBCC_EVAL_PART_BYTES", DEFAULT_PART_BYTES); }

long eval_call_bytes(void) { return emit_size_setting("MBCC_EVAL_CALL_BYTES", DEFAULT_CALL_BYTES); }

/* the calls of runtime kernels in text[a, b) that gcc inlines (an
 * identifier mb_<name> followed by '('), not counting the small vector
 * helpers whose inlined body is about the size of their call */
static long kernel_calls(const char *text, long a, long b) {
  static const char *const small[] = {"mb_cross3", "mb_dot3", "mb_mul3", "mb_mul3t", "mb_col3"};
  long n = 0;
  for (long i = a; i + 3 < b; i++) {
    if (text[i] != 'm' || text[i + 1] != 'b' || text[i + 2] != '_' || (i > a && ident_char((unsigned char)text[i - 1])))
      continue;
    long e = i + 3;
    while (e < b && ident_char((unsigned char)text[e])) e++;
    if (e >= b || text[e] != '(') { i = e; continue; }
    int is_small = 0;
    for (size_t k = 0; k < sizeof small / sizeof *small; k++)
      if ((size_t)(e - i) == strlen(small[k]) && !memcmp(text + i, small[k], (size_t)(e - i))) is_small = 1;
    n += !is_small;
    i = e;
  }
  return n;
}

int eval_split_begin(eval_split *s) {
  memset(s, 0, sizeof *s);
  s->body = open_memstream(&s->text, &s->len);
  return s->body ? 0 : -1;
}

/* one more mark fits (arrays doubled as needed); on failure the split is off */
static int room_for_mark(eval_split *s) {
  if (s->nmark < s->cap) return 0;
  int cap = s->cap ? 2 * s->cap : 256;
  long *mk = realloc(s->mark, sizeof *mk * (size_t)cap);
  if (mk) s->mark = mk;
  char **lb = realloc(s->label, sizeof *lb * (size_t)cap);
  if (lb) s->label = lb;
  if (!mk || !lb) { s->failed = 1; return -1; }
  s->cap = cap;
  return 0;
}

void eval_split_mark(eval_split *s, const char *fmt, ...) {
  if (s->failed || s->one_function) return;
  if (room_for_mark(s)) return;
  char buf[256];
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(buf, sizeof buf, fmt, ap);
  va_end(ap);
  for (char *p = buf; *p; p++) /* the label goes into a comment */
    if (*p == '*' && p[1] == '/') *p = '+';
  fflush(s->body);
  s->mark[s->nmark] = ftell(s->body);
  s->label[s->nmark] = strdup(buf);
  if (!s->label[s->nmark]) { s->failed = 1; return; }
  s->nmark++;
}

void eval_split_mark_lines(eval_split *s, long from, const char *prefix, const char *label) {
  if (s->failed || s->one_function || fflush(s->body)) return;
  size_t n = strlen(prefix);
  long end = ftell(s->body);
  /* the stream's buffer is valid after fflush, up to ftell */
  for (long i = from + 1; i + (long)n <= end; i++)
    if (s->text[i - 1] == '\n' && !memcmp(s->text + i, prefix, n) && i > s->mark[s->nmark - 1]) {
      if (room_for_mark(s)) return;
      s->mark[s->nmark] = i;
      s->label[s->nmark] = strdup(label);
      if (!s->label[s->nmark]) { s->failed = 1; return; }
      s->nmark++;
    }
}

/* --- the variables declared at the top level of the body ------------------ */

typedef struct {
  char *name;
  char type[16]; /* mb_frame, mb_marker, mb_real */
  int array;     /* declared with [N]: cannot cross parts (arrays do not assign) */
  int decl_part, last_part;
  int seen_part; /* scratch: last_part kept while one part is walked again */
} var;

typedef struct {
  var *v;
  int n, cap;
  int *slot; /* open addressing over v, nslot a power of two */
  int nslot;
} vars;

static uint32_t hash(const char *p, size_t n) {
  uint32_t h = 2166136261u;
  for (size_t i = 0; i < n; i++) h = (h ^ (unsigned char)p[i]) * 16777619u;
  return h;
}

static int find(const vars *t, const char *p, size_t n) {
  if (!t->nslot) return -1;
  for (uint32_t i = hash(p, n) & (uint32_t)(t->nslot - 1);; i = (i + 1) & (uint32_t)(t->nslot - 1)) {
    int k = t->slot[i];
    if (k < 0) return -1;
    if (strlen(t->v[k].name) == n && !memcmp(t->v[k].name, p, n)) return k;
  }
}

static int grow(vars *t) {
  int ns = t->nslot ? 2 * t->nslot : 1024;
  int *sl = malloc(sizeof *sl * (size_t)ns);
  if (!sl) return -1;
  for (int i = 0; i < ns; i++) sl[i] = -1;
  for (int k = 0; k < t->n; k++) {
    uint32_t i = hash(t->v[k].name, strlen(t->v[k].name)) & (uint32_t)(ns - 1);
    while (sl[i] >= 0) i = (i + 1) & (uint32_t)(ns - 1);
    sl[i] = k;
  }
  free(t->slot);
  t->slot = sl;
  t->nslot = ns;
  return 0;
}

/* -1 out of memory, -2 declared twice */
static int add(vars *t, const char *p, size_t n, const char *type, int array, int part) {
  if (find(t, p, n) >= 0) return -2;
  if (2 * (t->n + 1) > t->nslot && grow(t)) return -1;
  if (t->n == t->cap) {
    int cap = t->cap ? 2 * t->cap : 256;
    var *nv = realloc(t->v, sizeof *nv * (size_t)cap);
    if (!nv) return -1;
    t->v = nv;
    t->cap = cap;
  }
  var *v = &t->v[t->n];
  memset(v, 0, sizeof *v);
  v->name = strndup(p, n);
  if (!v->name) return -1;
  snprintf(v->type, sizeof v->type, "%s", type);
  v->array = array;
  v->decl_part = v->last_part = part;
  v->seen_part = -1;
  uint32_t i = hash(p, n) & (uint32_t)(t->nslot - 1);
  while (t->slot[i] >= 0) i = (i + 1) & (uint32_t)(t->nslot - 1);
  t->slot[i] = t->n++;
  return 0;
}

/* --- a small reader of the emitted C ---------------------------------------- */

/* a top-level declaration at p (after a statement end): its type (mb_frame,
 * mb_marker, mb_real, or "" when it is not a declaration), its name and
 * whether it is an array.  Returns 0, or -1 for a declaration this reader
 * does not handle (another type, several declarators). */
static int read_decl(const char *p, const char *end, char type[16], const char **name, size_t *nlen,
                     int *array) {
  type[0] = 0;
  const char *q = p;
  if (end - q > 6 && !memcmp(q, "const ", 6)) q += 6;
  const char *t = q;
  while (q < end && ident_char((unsigned char)*q)) q++;
  size_t tl = (size_t)(q - t);
  if (q >= end || *q != ' ' || !(q + 1 < end && ident_start((unsigned char)q[1]))) {
    /* no "TYPE NAME": a statement; but a bare keyword-led declaration is not expected */
    return 0;
  }
  static const char *const known[] = {"mb_frame", "mb_marker", "mb_real"};
  int k = -1;
  for (int i = 0; i < 3; i++)
    if (tl == strlen(known[i]) && !memcmp(t, known[i], tl)) k = i;
  if (tl == 6 && !memcmp(t, "return", 6)) return 0;
  if (k < 0) return -1;
  q++;
  *name = q;
  while (q < end && ident_char((unsigned char)*q)) q++;
  *nlen = (size_t)(q - *name);
  *array = q < end && *q == '[';
  /* one declarator only: no ',' at depth 0 before the ';' */
  int depth = 0;
  for (; q < end && *q != ';'; q++) {
    if (*q == '(' || *q == '{' || *q == '[') depth++;
    else if (*q == ')' || *q == '}' || *q == ']') depth--;
    else if (*q == ',' && depth == 0) return -1;
  }
  snprintf(type, 16, "%s", known[k]);
  return 0;
}

/* what one pass over a part's text does with the identifiers */
enum { PASS_DECLARE, PASS_READ };

/* walk text[a, b) of part 'part': PASS_DECLARE adds its top-level
 * declarations; PASS_READ records the declared variables it reads.  0, or -1
 * (out of memory or a declaration the reader does not handle). */
static int walk(vars *t, const char *text, long a, long b, int part, int pass) {
  const char *p = text + a, *end = text + b;
  int braces = 0, parens = 0, at_start = 1;
  while (p < end) {
    int c = (unsigned char)*p;
    if (c == '/' && p + 1 < end && p[1] == '*') {
      const char *e = strstr(p + 2, "*/");
      p = e && e < end ? e + 2 : end;
      continue;
    }
    if (c == '/' && p + 1 < end && p[1] == '/') {
      while (p < end && *p != '\n') p++;
      continue;
    }
    if (c == '"' || c == '\'') {
      for (p++; p < end && *p != c; p++)
        if (*p == '\\') p++;
      p++;
      at_start = 0;
      continue;
    }
    if (isspace(c)) { p++; continue; }
    if (ident_start(c)) {
      if (at_start && braces == 0 && parens == 0 && pass == PASS_DECLARE) {
        char type[16];
        const char *name = 0;
        size_t nlen = 0;
        int array = 0;
        if (read_decl(p, end, type, &name, &nlen, &array)) return -1;
        if (type[0]) {
          int r = add(t, name, nlen, type, array, part);
          if (r) return -1;
        }
      }
      at_start = 0;
      const char *s = p;
      while (p < end && ident_char((unsigned char)*p)) p++;
      /* a member name after '.' or '->' is not a variable */
      const char *before = s - 1;
      while (before >= text + a && (*before == ' ')) before--;
      int member = before >= text + a && (*before == '.' || (*before == '>' && before > text && before[-1] == '-'));
      if (pass == PASS_READ && !member) {
        int k = find(t, s, (size_t)(p - s));
        if (k >= 0 && t->v[k].last_part < part) t->v[k].last_part = part;
      }
      continue;
    }
    if (isdigit(c)) {
      while (p < end && (ident_char((unsigned char)*p) || *p == '.')) p++;
      at_start = 0;
      continue;
    }
    at_start = 0;
    if (c == '(') parens++;
    else if (c == ')') parens--;
    else if (c == '{') braces++;
    else if (c == '}') {
      braces--;
      if (braces == 0 && parens == 0) {
        /* a block statement ends here, unless an initializer or compound literal goes on */
        const char *n = p + 1;
        while (n < end && isspace((unsigned char)*n)) n++;
        at_start = !(n < end && (*n == ';' || *n == ',' || *n == ')'));
      }
    } else if (c == ';' && braces == 0 && parens == 0) at_start = 1;
    p++;
  }
  return 0;
}

/* --- writing the parts ------------------------------------------------------- */

static void free_split(eval_split *s) {
  if (s->body) fclose(s->body);
  s->body = NULL;
  free(s->text);
  for (int i = 0; i < s->nmark; i++) free(s->label[i]);
  free(s->mark);
  free(s->label);
  memset(s, 0, sizeof *s);
}

static void free_vars(vars *t) {
  for (int i = 0; i < t->n; i++) free(t->v[i].name);
  free(t->v);
  free(t->slot);
}

static const char *const part_args =
    "const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,\n"
    "    mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid";

int eval_split_finish(eval_split *s, FILE *out, const char *nm, const char *head, const eval_files *files) {
  if (!out) { free_split(s); return -1; }
  if (s->failed || fflush(s->body) || ferror(s->body)) { free_split(s); return -1; }
  fclose(s->body);
  s->body = NULL;
  long len = (long)s->len, budget = eval_part_bytes(), call = eval_call_bytes();
  /* the parts: marks grouped greedily up to the budget, each element
     weighed by its text and its inlined kernel calls (what gcc sees) */
  int *first = malloc(sizeof *first * (size_t)(s->nmark + 2));
  long *cost = malloc(sizeof *cost * (size_t)(s->nmark + 1));
  if (!first || !cost) { free(first); free(cost); free_split(s); return -1; }
  cost[0] = 0; /* cost[i]: of the text before mark i; cost[nmark]: of all */
  for (int i = 0; i < s->nmark; i++) {
    long a = s->mark[i], b = i + 1 < s->nmark ? s->mark[i + 1] : len;
    cost[i + 1] = cost[i] + (b - a) + call * kernel_calls(s->text, a, b);
  }
  int nparts = 0;
  long start = 0;
  if (budget > 0 && len > 2 * budget && s->nmark > 1 && s->mark[0] == 0) {
    first[nparts++] = 0;
    for (int i = 1; i < s->nmark; i++) {
      if (cost[i] - start >= budget) {
        first[nparts++] = i;
        start = cost[i];
      }
    }
  }
  free(cost);
  first[nparts] = s->nmark;
  vars t = {0};
  int ok = nparts > 1;
  for (int p = 0; ok && p < nparts; p++) {
    long a = s->mark[first[p]], b = first[p + 1] < s->nmark ? s->mark[first[p + 1]] : len;
    if (walk(&t, s->text, a, b, p, PASS_DECLARE)) ok = 0;
  }
  for (int p = 0; ok && p < nparts; p++) {
    long a = s->mark[first[p]], b = first[p + 1] < s->nmark ? s->mark[first[p + 1]] : len;
    if (walk(&t, s->text, a, b, p, PASS_READ)) ok = 0;
  }
  for (int k = 0; ok && k < t.n; k++)
    if (t.v[k].array && t.v[k].last_part > t.v[k].decl_part) ok = 0;
  if (!ok) { /* one function, as before */
    fputs(head, out);
    fwrite(s->text, 1, s->len, out);
    fputs("}\n", out);
    free_vars(&t);
    free(first);
    free_split(s);
    return 1;
  }
  /* with files: the struct and the parts' prototypes go into the private
     header, each part into the file files->part_file gives it, and the
     parts have external linkage (one translation unit each group) */
  FILE *decl = files ? files->header : out;
  fprintf(decl, "\n/* The evaluation in %d parts, each a function of bounded size (so that the C\n"
                " * compiler's cost per function stays bounded).  A value one part declares and\n"
                " * later parts read (a body frame f<b>, a marker k<m>, ...) passes through\n"
                " * %s_eval_shared: stored by its part, read into a const local of the same name. */\n",
          nparts, nm);
  fputs("typedef struct {\n", decl);
  int nshared = 0;
  for (int k = 0; k < t.n; k++)
    if (t.v[k].last_part > t.v[k].decl_part) {
      fprintf(decl, "  %s %s;\n", t.v[k].type, t.v[k].name);
      nshared++;
    }
  if (!nshared) fputs("  char unused; /* no value crosses parts */\n", decl);
  fprintf(decl, "} %s_eval_shared;\n\n", nm);
  fputs("#if defined(__GNUC__)\n#define EVAL_NOINLINE __attribute__((noinline))\n#else\n"
        "#define EVAL_NOINLINE\n#endif\n", decl);
  if (files)
    for (int p = 0; p < nparts; p++)
      fprintf(decl, "void %s_eval_part%d(%s_eval_shared *W, %s);\n", nm, p, nm, part_args);
  int ok_files = 1;
  for (int p = 0; p < nparts; p++) {
    long a = s->mark[first[p]], b = first[p + 1] < s->nmark ? s->mark[first[p + 1]] : len;
    FILE *pf = files ? files->part_file(files->ctx, p, nparts) : out;
    if (!pf) { ok_files = 0; break; }
    fprintf(pf, "\n/* part %d of %d: from %s to %s */\n", p + 1, nparts, s->label[first[p]],
            s->label[first[p + 1] - 1]);
    fprintf(pf, "%sEVAL_NOINLINE void %s_eval_part%d(%s_eval_shared *W, %s) {\n", files ? "" : "static ", nm, p,
            nm, part_args);
    fputs("  static const mb_real zero3[3] = {0, 0, 0};\n"
          "  mb_row r;\n  mb_real c[6 + MB_MAX_MODES], x[3];\n"
          "  (void)W; (void)m; (void)t; (void)q; (void)v; (void)x; (void)c; (void)r; (void)zero3;\n"
          "  (void)Kx; (void)rhs; (void)phi; (void)phid;\n", pf);
    /* the values of earlier parts this one names, in declaration order: one
       more walk over its text with last_part cleared finds them */
    for (int k = 0; k < t.n; k++) { t.v[k].seen_part = t.v[k].last_part; t.v[k].last_part = -1; }
    walk(&t, s->text, a, b, p, PASS_READ);
    for (int k = 0; k < t.n; k++) {
      var *x = &t.v[k];
      if (x->decl_part < p && x->last_part == p)
        fprintf(pf, "  const %s %s = W->%s;\n", x->type, x->name, x->name);
      x->last_part = x->seen_part;
    }
    fwrite(s->text + a, 1, (size_t)(b - a), pf);
    for (int k = 0; k < t.n; k++) {
      var *x = &t.v[k];
      if (x->decl_part == p && x->last_part > p) fprintf(pf, "  W->%s = %s;\n", x->name, x->name);
    }
    fputs("}\n", pf);
  }
  if (files) fprintf(out, "\n#include \"%s\"\n", files->header_name);
  fputs(head, out);
  fprintf(out, "  %s_eval_shared W;\n", nm);
  if (nparts > LOOPED_CALLS_FROM) {
    /* one call in a loop over a table of the parts: gcc's alias analysis
       walks, at each call that may write W, the calls before it (measured:
       the 1000-link chain's 286 calls cost 7 s of gcc CPU written out) */
    fprintf(out, "  static void (*const part[%d])(%s_eval_shared *, %s) = {\n", nparts, nm, part_args);
    for (int p = 0; p < nparts; p++) fprintf(out, "    %s_eval_part%d%s\n", nm, p, p + 1 < nparts ? "," : "");
    fprintf(out, "  };\n  for (int i = 0; i < %d; i++) part[i](&W, m, t, q, v, Kx, rhs, phi, phid);\n", nparts);
  } else
    for (int p = 0; p < nparts; p++) fprintf(out, "  %s_eval_part%d(&W, m, t, q, v, Kx, rhs, phi, phid);\n", nm, p);
  fputs("}\n", out);
  if (!ok_files) nparts = -1;
  free_vars(&t);
  free(first);
  free_split(s);
  return nparts;
}
