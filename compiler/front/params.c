/* params.c: named parameters ('parameters:') and arithmetic expressions over
 * them in any numeric field of the model.
 *
 * Grammar (docs/model-format.md, Parameters):
 *   sum     := product (('+' | '-') product)*
 *   product := unary (('*' | '/') unary)*
 *   unary   := ('-' | '+') unary | power
 *   power   := primary ('^' unary)?          right-associative: -2^2 = -4
 *   primary := number | name | name '(' sum (',' sum)* ')' | '(' sum ')'
 * Names are parameters, the constant pi, and the functions of 'functions'.
 * A parameter is evaluated on first use, so parameters may use each other in
 * any order; a cycle is an error at the reference that closes it. */
#include "params.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>

#include "bounds.h"
#include "compose.h"

static const struct {
  const char *name;
  int nargs;
} functions[] = {{"sqrt", 1}, {"sin", 1}, {"cos", 1}, {"tan", 1}, {"atan2", 2}, {"exp", 1},
                 {"log", 1},  {"abs", 1}, {"min", 2}, {"max", 2}};
enum { FN_SQRT, FN_SIN, FN_COS, FN_TAN, FN_ATAN2, FN_EXP, FN_LOG, FN_ABS, FN_MIN, FN_MAX, FN_COUNT };
_Static_assert(sizeof functions / sizeof *functions == FN_COUNT, "one entry per function");

static const char *const *override_names;
static const double *override_values;
static int override_count;

void params_set_overrides(const char *const *names, const double *values, int count) {
  override_names = names;
  override_values = values;
  override_count = count;
}

static bool is_reserved(const char *name, size_t length) {
  if (length == 2 && !memcmp(name, "pi", 2)) return true;
  for (int i = 0; i < FN_COUNT; i++)
    if (strlen(functions[i].name) == length && !memcmp(functions[i].name, name, length)) return true;
  return false;
}

/* edit distance, for "did you mean" */
static int distance(const char *a, size_t na, const char *b, size_t nb) {
  if (na > 60 || nb > 60) return 99;
  int row[64];
  for (size_t j = 0; j <= nb; j++) row[j] = (int)j;
  for (size_t i = 1; i <= na; i++) {
    int diagonal = row[0];
    row[0] = (int)i;
    for (size_t j = 1; j <= nb; j++) {
      int up = row[j];
      int best = diagonal + (a[i - 1] != b[j - 1]);
      if (up + 1 < best) best = up + 1;
      if (row[j - 1] + 1 < best) best = row[j - 1] + 1;
      row[j] = best;
      diagonal = up;
    }
  }
  return row[nb];
}

static int find_length(const ir_model *m, const char *name, size_t length, char *suggest, size_t size) {
  int best = 99;
  if (suggest && size) suggest[0] = '\0';
  for (int k = 0; k < m->nparams; k++) {
    const char *p = m->params[k].name;
    if (strlen(p) == length && !memcmp(p, name, length)) return k;
    int d = distance(name, length, p, strlen(p));
    int allowed = (int)(length / 3) > 1 ? (int)(length / 3) : 1;
    if (d <= allowed && d < best && suggest) {
      best = d;
      snprintf(suggest, size, "%s", p);
    }
  }
  return -1;
}

int params_find(const ir_model *m, const char *name, char *suggest, size_t size) {
  return find_length(m, name, strlen(name), suggest, size);
}

int params_runtime_index(const ir_model *m, int k) {
  if (!m->params[k].runtime) return -1;
  int index = 0;
  for (int i = 0; i < k; i++) index += m->params[i].runtime;
  return index;
}

/* ---------------------------------------------------------------------------
 * parsing
 * ------------------------------------------------------------------------- */

typedef struct {
  reader *r;
  const yaml_node_t *scalar;
  const char *text;
  size_t length, at;
  ir_expr *e;
  bool quiet;   /* no 'parameters:' block: syntax errors are left to the caller */
  bool failed;
} parser;

/* where byte 'pos' of the scalar is in the file (exact on one line) */
static ir_loc loc_at(const parser *p, size_t pos) {
  ir_loc loc = loc_of(p->scalar);
  if (memchr(p->text, '\n', pos < p->length ? pos : p->length)) return loc;
  yaml_scalar_style_t style = p->scalar->data.scalar.style;
  int quote = style == YAML_SINGLE_QUOTED_SCALAR_STYLE || style == YAML_DOUBLE_QUOTED_SCALAR_STYLE;
  loc.col += quote + (int)pos;
  return loc;
}

static void fail(parser *p, size_t pos, bool syntax, const char *fmt, ...) DIAG_PRINTF(4, 5);
static void fail(parser *p, size_t pos, bool syntax, const char *fmt, ...) {
  if (p->failed) return;
  p->failed = true;
  if (syntax && p->quiet) return;
  va_list ap;
  va_start(ap, fmt);
  diag_verror(p->r->path, loc_at(p, pos), fmt, ap);
  va_end(ap);
}

static int append_node(ir_expr *e, ir_expr_op op, size_t pos) {
  if (e->count % 16 == 0) {
    ir_expr_node *bigger = realloc(e->node, (size_t)(e->count + 16) * sizeof *bigger);
    if (!bigger) out_of_memory();
    e->node = bigger;
  }
  ir_expr_node *n = &e->node[e->count];
  memset(n, 0, sizeof *n);
  n->op = op;
  n->a = n->b = -1;
  n->pos = (int)pos;
  return e->count++;
}

static int add_node(parser *p, ir_expr_op op, size_t pos) { return append_node(p->e, op, pos); }

static void skip_blanks(parser *p) {
  while (p->at < p->length && (p->text[p->at] == ' ' || p->text[p->at] == '\t')) p->at++;
}

static bool next_is(parser *p, char c) {
  skip_blanks(p);
  return p->at < p->length && p->text[p->at] == c;
}

static int parse_sum(parser *p, int depth);

static const char *shown_char(parser *p, size_t pos) {
  if (pos >= p->length) return "the end";
  char c[2] = {p->text[pos], 0};
  static char out[16];
  snprintf(out, sizeof out, "'%s'", show_text(p->r, c, 1));
  return out;
}

static int parse_primary(parser *p, int depth) {
  skip_blanks(p);
  size_t start = p->at;
  if (depth > 64) {
    fail(p, start, false, "expression nested too deeply");
    return -1;
  }
  if (p->at >= p->length) {
    fail(p, start, true, "expression ends where a number, a parameter or '(' was expected");
    return -1;
  }
  char c = p->text[p->at];
  if (isdigit((unsigned char)c) || c == '.') {
    if (c == '0' && p->at + 1 < p->length && (p->text[p->at + 1] == 'x' || p->text[p->at + 1] == 'X')) {
      fail(p, start, true, "hexadecimal numbers are not part of expressions");
      return -1;
    }
    char buffer[64];
    size_t n = 0;
    while (p->at + n < p->length && n + 1 < sizeof buffer &&
           (isalnum((unsigned char)p->text[p->at + n]) || p->text[p->at + n] == '.' ||
            ((p->text[p->at + n] == '+' || p->text[p->at + n] == '-') && n > 0 &&
             (p->text[p->at + n - 1] == 'e' || p->text[p->at + n - 1] == 'E'))))
      n++;
    memcpy(buffer, p->text + p->at, n);
    buffer[n] = '\0';
    char *end;
    double value = strtod(buffer, &end);
    if ((size_t)(end - buffer) != n) {
      fail(p, start, true, "malformed number '%s'", show_text(p->r, buffer, n));
      return -1;
    }
    p->at += n;
    int k = add_node(p, EXPR_NUMBER, start);
    p->e->node[k].number = value;
    return k;
  }
  if (isalpha((unsigned char)c) || c == '_') {
    size_t n = 0;
    while (p->at + n < p->length && (isalnum((unsigned char)p->text[p->at + n]) || p->text[p->at + n] == '_')) n++;
    const char *name = p->text + p->at;
    p->at += n;
    if (n == 2 && !memcmp(name, "pi", 2)) {
      int k = add_node(p, EXPR_NUMBER, start);
      p->e->node[k].number = 3.141592653589793238462643;
      return k;
    }
    if (next_is(p, '(')) {
      int fn = -1;
      for (int i = 0; i < FN_COUNT; i++)
        if (strlen(functions[i].name) == n && !memcmp(functions[i].name, name, n)) fn = i;
      if (fn < 0) {
        name_list l;
        l.length = 0;
        l.count = 0;
        l.text[0] = '\0';
        for (int i = 0; i < FN_COUNT; i++) name_list_add(&l, functions[i].name);
        fail(p, start, true, "unknown function '%s' (expected one of: %s)", show_text(p->r, name, n), l.text);
        return -1;
      }
      p->at++; /* ( */
      int k = add_node(p, EXPR_CALL, start);
      p->e->node[k].param = fn;
      int args[2] = {-1, -1}, nargs = 0;
      for (;;) {
        int a = parse_sum(p, depth + 1);
        if (a < 0) return -1;
        if (nargs < 2) args[nargs] = a;
        nargs++;
        if (next_is(p, ',')) { p->at++; continue; }
        if (next_is(p, ')')) { p->at++; break; }
        fail(p, p->at, true, "expected ',' or ')' in the arguments of %s, got %s", functions[fn].name,
             shown_char(p, p->at));
        return -1;
      }
      if (nargs != functions[fn].nargs) {
        fail(p, start, false, "%s takes %d argument%s, got %d", functions[fn].name, functions[fn].nargs,
             functions[fn].nargs == 1 ? "" : "s", nargs);
        return -1;
      }
      p->e->node[k].a = args[0];
      p->e->node[k].b = args[1];
      return k;
    }
    const ir_model *m = p->r->model;
    char suggest[128];
    /* in a subsystem instance, its own (prefixed) parameters hide the
       enclosing ones' (compose.c) */
    int param = -1;
    for (int in = diag_loc_instance(loc_of(p->scalar)); param < 0 && in != 0; in = diag_instance_parent(in)) {
      char scoped[256];
      int length = snprintf(scoped, sizeof scoped, "%s%.*s", diag_instance_prefix(in), (int)n, name);
      if (length > 0 && (size_t)length < sizeof scoped) param = find_length(m, scoped, (size_t)length, NULL, 0);
    }
    if (param < 0) param = find_length(m, name, n, suggest, sizeof suggest);
    if (param < 0) {
      if (is_reserved(name, n))
        fail(p, start, false, "'%s' is a function: write %s(...)", show_text(p->r, name, n),
             show_text(p->r, name, n));
      else if (suggest[0])
        fail(p, start, true, "unknown parameter '%s' (did you mean '%s'?)", show_text(p->r, name, n), suggest);
      else if (p->r->params_block)
        fail(p, start, true, "unknown parameter '%s' (not in 'parameters:')", show_text(p->r, name, n));
      else
        fail(p, start, true, "unknown parameter '%s' (the model has no 'parameters:' block)",
             show_text(p->r, name, n));
      return -1;
    }
    int k = add_node(p, EXPR_PARAM, start);
    p->e->node[k].param = param;
    return k;
  }
  if (c == '(') {
    p->at++;
    int k = parse_sum(p, depth + 1);
    if (k < 0) return -1;
    if (!next_is(p, ')')) {
      fail(p, p->at, true, "expected ')' to close the '(' at column %d, got %s", loc_at(p, start).col,
           shown_char(p, p->at));
      return -1;
    }
    p->at++;
    return k;
  }
  fail(p, start, true, "unexpected %s in an expression (expected a number, a parameter or '(')",
       shown_char(p, start));
  return -1;
}

static int parse_unary(parser *p, int depth);

static int parse_power(parser *p, int depth) {
  int base = parse_primary(p, depth);
  if (base < 0) return -1;
  if (!next_is(p, '^')) return base;
  size_t pos = p->at++;
  int exponent = parse_unary(p, depth + 1);
  if (exponent < 0) return -1;
  int k = add_node(p, EXPR_POW, pos);
  p->e->node[k].a = base;
  p->e->node[k].b = exponent;
  return k;
}

static int parse_unary(parser *p, int depth) {
  skip_blanks(p);
  if (depth > 64) {
    fail(p, p->at, false, "expression nested too deeply");
    return -1;
  }
  if (p->at < p->length && (p->text[p->at] == '-' || p->text[p->at] == '+')) {
    size_t pos = p->at;
    bool minus = p->text[p->at++] == '-';
    int a = parse_unary(p, depth + 1);
    if (a < 0 || !minus) return a;
    int k = add_node(p, EXPR_NEG, pos);
    p->e->node[k].a = a;
    return k;
  }
  return parse_power(p, depth);
}

static int parse_binary(parser *p, int depth, bool sum) {
  int left = sum ? parse_binary(p, depth, false) : parse_unary(p, depth);
  while (left >= 0) {
    skip_blanks(p);
    if (p->at >= p->length) break;
    char c = p->text[p->at];
    ir_expr_op op;
    if (sum && c == '+') op = EXPR_ADD;
    else if (sum && c == '-') op = EXPR_SUB;
    else if (!sum && c == '*') op = EXPR_MUL;
    else if (!sum && c == '/') op = EXPR_DIV;
    else break;
    size_t pos = p->at++;
    int right = sum ? parse_binary(p, depth, false) : parse_unary(p, depth);
    if (right < 0) return -1;
    int k = add_node(p, op, pos);
    p->e->node[k].a = left;
    p->e->node[k].b = right;
    left = k;
  }
  return left;
}

static int parse_sum(parser *p, int depth) { return parse_binary(p, depth, true); }

/* ---------------------------------------------------------------------------
 * evaluation
 * ------------------------------------------------------------------------- */

static bool param_value(reader *r, int k, const parser *from, size_t pos, double *out);

static bool eval_node(parser *p, int k, double *out, bool *runtime) {
  const ir_expr_node *n = &p->e->node[k];
  double a = 0, b = 0;
  if (n->a >= 0 && !eval_node(p, n->a, &a, runtime)) return false;
  if (n->b >= 0 && !eval_node(p, n->b, &b, runtime)) return false;
  double v = 0;
  switch (n->op) {
  case EXPR_NUMBER: v = n->number; break;
  case EXPR_PARAM:
    if (!param_value(p->r, n->param, p, (size_t)n->pos, &v)) {
      p->failed = true;
      return false;
    }
    *runtime = *runtime || p->r->model->params[n->param].uses_runtime;
    break;
  case EXPR_NEG: v = -a; break;
  case EXPR_ADD: v = a + b; break;
  case EXPR_SUB: v = a - b; break;
  case EXPR_MUL: v = a * b; break;
  case EXPR_DIV:
    if (b == 0) {
      fail(p, (size_t)n->pos, false, "division by zero");
      return false;
    }
    v = a / b;
    break;
  case EXPR_POW:
    if (a < 0 && b != floor(b)) {
      fail(p, (size_t)n->pos, false, "negative base %g to the non-integer power %g", a, b);
      return false;
    }
    v = pow(a, b);
    break;
  case EXPR_CALL:
    switch (n->param) {
    case FN_SQRT:
      if (a < 0) { fail(p, (size_t)n->pos, false, "sqrt of the negative number %g", a); return false; }
      v = sqrt(a);
      break;
    case FN_SIN: v = sin(a); break;
    case FN_COS: v = cos(a); break;
    case FN_TAN: v = tan(a); break;
    case FN_ATAN2: v = atan2(a, b); break;
    case FN_EXP: v = exp(a); break;
    case FN_LOG:
      if (!(a > 0)) { fail(p, (size_t)n->pos, false, "log of %g (needs a positive number)", a); return false; }
      v = log(a);
      break;
    case FN_ABS: v = fabs(a); break;
    case FN_MIN: v = fmin(a, b); break;
    case FN_MAX: v = fmax(a, b); break;
    }
    break;
  }
  if (!isfinite(v)) {
    fail(p, (size_t)n->pos, false, "the expression overflows here (the value is not finite)");
    return false;
  }
  *out = v;
  return true;
}

/* The scalar as an expression: parsed into *e (owned by the caller) and evaluated. */
static bool parse_eval(reader *r, const yaml_node_t *n, bool quiet, ir_expr *e, double *out, bool *runtime) {
  parser p = {.r = r, .scalar = n, .text = scalar_text(n), .length = scalar_length(n), .e = e, .quiet = quiet};
  memset(e, 0, sizeof *e);
  e->root = parse_sum(&p, 0);
  if (e->root >= 0) {
    skip_blanks(&p);
    if (p.at < p.length)
      fail(&p, p.at, true, "unexpected %s after the end of the expression", shown_char(&p, p.at));
  }
  if (p.failed) return false;
  *runtime = false;
  return eval_node(&p, e->root, out, runtime);
}

bool expr_names(const ir_expr *e, int k) {
  for (int i = 0; i < e->count; i++)
    if (e->node[i].op == EXPR_PARAM && e->node[i].param == k) return true;
  return false;
}

static bool names_any(const ir_expr *e) {
  for (int i = 0; i < e->count; i++)
    if (e->node[i].op == EXPR_PARAM) return true;
  return false;
}

static void record_use(reader *r, const yaml_node_t *n, ir_expr *e, double value, bool runtime) {
  ir_model *m = r->model;
  if (m->nuses == m->cap_uses) {
    int cap = m->cap_uses ? 2 * m->cap_uses : 16;
    ir_expr_use *bigger = realloc(m->uses, (size_t)cap * sizeof *bigger);
    if (!bigger) out_of_memory();
    m->uses = bigger;
    m->cap_uses = cap;
  }
  ir_expr_use *u = &m->uses[m->nuses++];
  *u = (ir_expr_use){0}; /* every field, 'pruned' included, starts cleared */
  u->loc = loc_of(n);
  u->expr = xcalloc(1, sizeof *u->expr);
  *u->expr = *e;
  u->value = value;
  u->uses_runtime = runtime;
}

void params_note_rule(reader *r, ir_loc loc, ir_value_rule rule, const char *field) {
  ir_model *m = r->model;
  if (m == NULL) return;
  for (int i = m->nuses - 1; i >= 0; i--)
    if (m->uses[i].loc.line == loc.line && m->uses[i].loc.col == loc.col) {
      m->uses[i].rule = rule;
      snprintf(m->uses[i].field, sizeof m->uses[i].field, "%s", field);
      return;
    }
}

const char *params_rule_text(ir_value_rule rule) {
  return rule == RULE_NONNEGATIVE ? "must be >= 0" : rule == RULE_POSITIVE ? "must be positive" : "";
}

bool params_rule_holds(ir_value_rule rule, double v) {
  return rule == RULE_NONNEGATIVE ? v >= 0 : rule == RULE_POSITIVE ? v > 0 : true;
}

static bool place_value(reader *r, const yaml_node_t *n, const char *label, const compose_placement *placed,
                        double *v, double *offset);

int expr_number(reader *r, yaml_node_t *n, const char *label, double *out) {
  if (n->type != YAML_SCALAR_NODE || scalar_length(n) == 0 || r->model == NULL) return 0;
  ir_expr e;
  double value;
  bool runtime;
  int errors = diag_errors();
  bool ok = parse_eval(r, n, !r->params_block, &e, &value, &runtime);
  if (ok && fabs(value) > LIMIT_MAGNITUDE) {
    error_at(r, loc_of(n), "%s is %g, beyond the limit %g on the size of a number", label, value, LIMIT_MAGNITUDE);
    ok = false;
  }
  if (!ok) {
    free(e.node);
    if (diag_errors() > errors) return -1;
    /* without 'parameters:', not an expression: the caller says "must be a
       number"; with, a parameter it names failed and was reported there */
    return r->params_block ? -1 : 0;
  }
  compose_placement placed;
  if (compose_placement_of(n, &placed)) {
    if (placed.negate && runtime) {
      error_at(r, loc_of(n), "%s is mirrored (a subsystem instance with 'mirror: true') and cannot use a run-time "
               "parameter", label);
      free(e.node);
      return -1;
    }
    double offset[LIMIT_INCLUDE_DEPTH + 1];
    if (!place_value(r, n, label, &placed, &value, offset)) {
      free(e.node);
      return -1;
    }
    /* a run-time value is computed by the generated code from the
       expression: the offsets (compile-time numbers) join it, in the order
       they were added */
    for (int k = 0; runtime && k < placed.nterms; k++) {
      int number = append_node(&e, EXPR_NUMBER, 0);
      e.node[number].number = offset[k];
      int sum = append_node(&e, placed.subtract[k] ? EXPR_SUB : EXPR_ADD, 0);
      e.node[sum].a = e.root;
      e.node[sum].b = number;
      e.root = sum;
    }
  }
  *out = value;
  if (names_any(&e)) record_use(r, n, &e, value, runtime);
  else free(e.node);
  return 1;
}

/* the offset of a moved instance (compose.h): node k of the document, a
 * component of its 'position', read once (an error in it is reported once) */
static bool offset_value(reader *r, int k, double *out) {
  size_t count = (size_t)(r->doc->nodes.top - r->doc->nodes.start);
  if (k < 1 || (size_t)k > count || r->model == NULL) return false;
  if (r->offset_state == NULL) {
    r->offset_state = xcalloc(count + 1, sizeof *r->offset_state);
    r->offset_value = xcalloc(count + 1, sizeof *r->offset_value);
  }
  if (r->offset_state[k] != 0) {
    *out = r->offset_value[k];
    return r->offset_state[k] == 1;
  }
  r->offset_state[k] = 2;
  yaml_node_t *n = node_at(r, k);
  int uses = r->model->nuses;
  double v;
  if (!to_number(r, n, "a component of the instance's 'position'", &v)) return false;
  /* an expression naming a run-time parameter was recorded as such */
  if (r->model->nuses > uses && r->model->uses[r->model->nuses - 1].uses_runtime) {
    error_at(r, loc_of(n), "the 'position' of a subsystem instance cannot use a run-time parameter (it moves "
             "the instance's points at compile time)");
    return false;
  }
  r->offset_state[k] = 1;
  r->offset_value[k] = *out = v;
  return true;
}

/* *v as placed: negated, then each offset added or subtracted in order
 * (their values in offset[]) */
static bool place_value(reader *r, const yaml_node_t *n, const char *label, const compose_placement *placed,
                        double *v, double *offset) {
  if (placed->negate) *v = compose_mirror_value(*v);
  for (int k = 0; k < placed->nterms; k++) {
    if (!offset_value(r, placed->node[k], &offset[k])) return false;
    *v = placed->subtract[k] ? *v - offset[k] : *v + offset[k];
  }
  if (fabs(*v) > LIMIT_MAGNITUDE) {
    error_at(r, loc_of(n), "%s moved by its subsystem instance's 'position' is %g, beyond the limit %g on the size "
             "of a number", label, *v, LIMIT_MAGNITUDE);
    return false;
  }
  return true;
}

bool params_place(reader *r, const yaml_node_t *n, const char *label, double *value) {
  compose_placement placed;
  double offset[LIMIT_INCLUDE_DEPTH + 1];
  return !compose_placement_of(n, &placed) || place_value(r, n, label, &placed, value, offset);
}

/* ---------------------------------------------------------------------------
 * the parameters block
 * ------------------------------------------------------------------------- */

/* a parameter's number: plain, or an expression (kept in *expr when it names others) */
static bool definition_value(reader *r, int k, yaml_node_t *n, double *out) {
  ir_param *P = &r->model->params[k];
  char label[SHOWN_SIZE];
  snprintf(label, sizeof label, "parameter '%s'", P->name);
  if (n->type != YAML_SCALAR_NODE) {
    error_at(r, loc_of(n), "%s must be a number, an expression or {value: ...} (got %s)", label, show_node(r, n));
    return false;
  }
  const char *text = scalar_text(n);
  char *end = NULL;
  double v = scalar_length(n) && !isspace((unsigned char)text[0]) ? strtod(text, &end) : 0;
  if (end == text + scalar_length(n)) {
    if (!isfinite(v) || fabs(v) > LIMIT_MAGNITUDE) {
      error_at(r, loc_of(n), "%s must be a finite number no larger than %g (got %s)", label, LIMIT_MAGNITUDE,
               show_node(r, n));
      return false;
    }
    *out = v;
    return true;
  }
  ir_expr e;
  bool runtime;
  if (!parse_eval(r, n, false, &e, out, &runtime)) {
    free(e.node); /* reported, here or at the definition of a parameter it names */
    return false;
  }
  P->uses_runtime = P->uses_runtime || runtime;
  if (names_any(&e)) {
    P->expr = xcalloc(1, sizeof *P->expr);
    *P->expr = e;
  } else {
    free(e.node);
  }
  return true;
}

static bool param_value(reader *r, int k, const parser *from, size_t pos, double *out) {
  ir_param *P = &r->model->params[k];
  if (P->state == 2) { *out = P->value; return true; }
  if (P->state == 3) return false;
  if (P->state == 1) {
    if (from) error_at(r, loc_at(from, pos), "parameter '%s' depends on itself (a cycle among parameters)", P->name);
    P->state = 3;
    return false;
  }
  P->state = 1;
  yaml_node_t *n = r->param_nodes[k];
  bool ok;
  if (n->type == YAML_MAPPING_NODE) {
    mapping m;
    map_open(&m, r, n, loc_of(n), "parameter '%s'", P->name);
    static const char *const keys[] = {"value", "runtime", "input", "min", "max", "unit", NULL};
    map_check_keys(&m, keys);
    yaml_node_t *value = map_require(&m, "value", true, "a number or an expression");
    ok = value != NULL && definition_value(r, k, value, &P->value);
    yaml_node_t *runtime = map_get(&m, "runtime");
    if (runtime != NULL) {
      if (scalar_equals(runtime, "true")) P->runtime = P->uses_runtime = true;
      else if (!scalar_equals(runtime, "false")) {
        error_at(r, loc_of(runtime), "'runtime' must be true or false (got %s)", show_node(r, runtime));
        ok = false;
      }
    }
    /* an input (the embedded package's <m>_set_input) is a run-time parameter */
    yaml_node_t *input = map_get(&m, "input");
    if (input != NULL) {
      if (scalar_equals(input, "true")) {
        if (runtime != NULL && scalar_equals(runtime, "false")) {
          error_at(r, loc_of(input), "an input is set at run time: 'input: true' needs 'runtime: true' (or no 'runtime')");
          ok = false;
        }
        P->input = P->runtime = P->uses_runtime = true;
      } else if (!scalar_equals(input, "false")) {
        error_at(r, loc_of(input), "'input' must be true or false (got %s)", show_node(r, input));
        ok = false;
      }
    }
    if (P->runtime && P->expr) {
      /* a run-time parameter is an independent input: its definition gives only the default */
      P->uses_runtime = true;
    }
    if (map_has(&m, "min") && !get_number(&m, "min", false, &P->min)) ok = false;
    if (map_has(&m, "max") && !get_number(&m, "max", false, &P->max)) ok = false;
    yaml_node_t *unit = map_get(&m, "unit");
    if (unit != NULL && unit->type == YAML_SCALAR_NODE) P->unit = xstrndup(scalar_text(unit), scalar_length(unit));
    else if (unit != NULL) {
      error_at(r, loc_of(unit), "'unit' must be text such as N/m (got %s)", show_node(r, unit));
      ok = false;
    }
    map_close(&m);
  } else {
    ok = definition_value(r, k, n, &P->value);
  }
  bool overridden = false;  /* --set values were checked against the range by their caller */
  for (int i = 0; ok && i < override_count; i++) {
    if (strcmp(override_names[i], P->name)) continue;
    if (!P->runtime) {
      error_at(r, P->loc, "--set %s: the parameter is compile-time (give it 'runtime: true' to set it at run time)",
               P->name);
      ok = false;
    } else {
      P->value = override_values[i];
      overridden = true;
    }
  }
  if (ok && P->min > P->max) {
    error_at(r, P->loc, "parameter '%s': 'min' %g is above 'max' %g", P->name, P->min, P->max);
    ok = false;
  } else if (ok && !overridden && !(P->value >= P->min && P->value <= P->max)) {
    error_at(r, P->loc, "parameter '%s' is %g, outside its range [%g, %g]", P->name, P->value, P->min, P->max);
    ok = false;
  }
  P->state = ok ? 2 : 3;
  *out = P->value;
  return ok;
}

void parse_parameters(reader *r, yaml_node_t *n) {
  ir_model *model = r->model;
  if (n == NULL) return;
  r->params_block = true;
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'parameters'")) {
    map_close(&m);
    return;
  }
  model->params = xcalloc((size_t)m.npairs, sizeof *model->params);
  r->param_nodes = xcalloc((size_t)m.npairs, sizeof *r->param_nodes);
  for (int i = 0; i < m.npairs; i++) {
    if (m.handled[i]) continue;
    yaml_node_t *key = map_key_node(&m, i);
    const char *name = scalar_text(key);
    size_t length = scalar_length(key);
    bool identifier = length > 0 && (isalpha((unsigned char)name[0]) || name[0] == '_');
    for (size_t j = 0; j < length; j++)
      identifier = identifier && (isalnum((unsigned char)name[j]) || name[j] == '_');
    if (!identifier) {
      error_at(r, loc_of(key), "parameter name '%s' must be a name of letters, digits and _ (not starting with a digit)",
               show_text(r, name, length));
      continue;
    }
    if (is_reserved(name, length)) {
      error_at(r, loc_of(key), "'%s' cannot name a parameter: it is a function or constant of expressions",
               show_text(r, name, length));
      continue;
    }
    ir_param *P = &model->params[model->nparams];
    P->name = xstrndup(name, length);
    P->loc = loc_of(key);
    P->min = -INFINITY;
    P->max = INFINITY;
    r->param_nodes[model->nparams++] = map_value_node(&m, i);
  }
  map_close(&m);
  for (int k = 0; k < model->nparams; k++) {
    double v;
    param_value(r, k, NULL, 0, &v);
  }
  for (int i = 0; i < override_count; i++)
    if (params_find(model, override_names[i], NULL, 0) < 0) {
      char suggest[128];
      params_find(model, override_names[i], suggest, sizeof suggest);
      error_at(r, loc_of(n), "--set %s: the model has no such parameter%s%s%s", override_names[i],
               suggest[0] ? " (did you mean '" : "", suggest, suggest[0] ? "'?)" : "");
    }
}

/* ---------------------------------------------------------------------------
 * C text
 * ------------------------------------------------------------------------- */

static double eval_runtime(const ir_model *m, const ir_expr *e, int k, const double *p) {
  const ir_expr_node *n = &e->node[k];
  double a = n->a >= 0 ? eval_runtime(m, e, n->a, p) : 0, b = n->b >= 0 ? eval_runtime(m, e, n->b, p) : 0;
  switch (n->op) {
  case EXPR_NUMBER: return n->number;
  case EXPR_PARAM: {
    const ir_param *P = &m->params[n->param];
    if (P->runtime) return p[params_runtime_index(m, n->param)];
    if (P->uses_runtime && P->expr) return eval_runtime(m, P->expr, P->expr->root, p);
    return P->value;
  }
  case EXPR_NEG: return -a;
  case EXPR_ADD: return a + b;
  case EXPR_SUB: return a - b;
  case EXPR_MUL: return a * b;
  case EXPR_DIV: return a / b;
  case EXPR_POW: return pow(a, b);
  case EXPR_CALL:
    switch (n->param) {
    case FN_SQRT: return sqrt(a);
    case FN_SIN: return sin(a);
    case FN_COS: return cos(a);
    case FN_TAN: return tan(a);
    case FN_ATAN2: return atan2(a, b);
    case FN_EXP: return exp(a);
    case FN_LOG: return log(a);
    case FN_ABS: return fabs(a);
    case FN_MIN: return fmin(a, b);
    case FN_MAX: return fmax(a, b);
    }
  }
  return NAN;
}

double expr_eval_runtime(const ir_model *m, const ir_expr *e, const double *p) {
  return eval_runtime(m, e, e->root, p);
}

static void print_number(FILE *f, double v) {
  char text[40];
  snprintf(text, sizeof text, "%.17g", v);
  fputs(text, f);
  if (!strpbrk(text, ".eEn")) fputs(".0", f); /* never C's integer division */
}

static void print_node(FILE *f, const ir_model *m, const ir_expr *e, int k, const char *vector) {
  static const char *const c_names[FN_COUNT] = {"sqrt", "sin", "cos", "tan", "atan2", "exp", "log", "fabs", "fmin", "fmax"};
  const ir_expr_node *n = &e->node[k];
  switch (n->op) {
  case EXPR_NUMBER: print_number(f, n->number); return;
  case EXPR_PARAM: {
    const ir_param *P = &m->params[n->param];
    if (P->runtime) fprintf(f, "%s[%d]", vector, params_runtime_index(m, n->param));
    else if (P->uses_runtime && P->expr) {
      fputc('(', f);
      print_node(f, m, P->expr, P->expr->root, vector);
      fputc(')', f);
    } else {
      fputc('(', f);
      print_number(f, P->value);
      fputc(')', f);
    }
    return;
  }
  case EXPR_NEG: fputs("(-", f); print_node(f, m, e, n->a, vector); fputc(')', f); return;
  case EXPR_ADD: case EXPR_SUB: case EXPR_MUL: case EXPR_DIV: {
    const char op = n->op == EXPR_ADD ? '+' : n->op == EXPR_SUB ? '-' : n->op == EXPR_MUL ? '*' : '/';
    fputc('(', f);
    print_node(f, m, e, n->a, vector);
    fprintf(f, " %c ", op);
    print_node(f, m, e, n->b, vector);
    fputc(')', f);
    return;
  }
  case EXPR_POW:
    fputs("pow(", f);
    print_node(f, m, e, n->a, vector);
    fputs(", ", f);
    print_node(f, m, e, n->b, vector);
    fputc(')', f);
    return;
  case EXPR_CALL:
    fprintf(f, "%s(", c_names[n->param]);
    print_node(f, m, e, n->a, vector);
    if (n->b >= 0) {
      fputs(", ", f);
      print_node(f, m, e, n->b, vector);
    }
    fputc(')', f);
    return;
  }
}

void expr_print_c(FILE *f, const ir_model *m, const ir_expr *e, const char *vector) {
  print_node(f, m, e, e->root, vector);
}

static void free_expr(ir_expr *e) {
  if (!e) return;
  free(e->node);
  free(e);
}

void params_free(ir_model *m) {
  for (int k = 0; k < m->nparams; k++) {
    free(m->params[k].name);
    free(m->params[k].unit);
    free_expr(m->params[k].expr);
  }
  free(m->params);
  for (int i = 0; i < m->nuses; i++) free_expr(m->uses[i].expr);
  free(m->uses);
}
