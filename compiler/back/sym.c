/* sym.c: the hash-consed expression graph (sym.h). */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "sym.h"

void sym_init(sym_graph *g) { memset(g, 0, sizeof *g); }

void sym_free(sym_graph *g) {
  for (int i = 0; i < g->n; i++) free(g->node[i].text);
  free(g->node);
  free(g->slot);
  memset(g, 0, sizeof *g);
}

static uint64_t mix(uint64_t h, uint64_t v) {
  h ^= v + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  return h * 0xff51afd7ed558ccdULL;
}

static uint64_t node_hash(sym_op op, sym_id a, sym_id b, double value, const char *text) {
  uint64_t h = mix(0, (uint64_t)op);
  h = mix(h, (uint64_t)(int64_t)a);
  h = mix(h, (uint64_t)(int64_t)b);
  uint64_t bits;
  memcpy(&bits, &value, sizeof bits);
  h = mix(h, bits);
  for (const char *c = text; c && *c; c++) h = mix(h, (unsigned char)*c);
  return h;
}

static int same(const sym_node *x, sym_op op, sym_id a, sym_id b, double value, const char *text) {
  if (x->op != op || x->a != a || x->b != b) return 0;
  if (op == SYM_CONST) return memcmp(&x->value, &value, sizeof value) == 0; /* 0 and -0 differ */
  if (op == SYM_SYMBOL) return strcmp(x->text, text) == 0;
  return 1;
}

static int grow_slots(sym_graph *g) {
  int ns = g->nslot ? 2 * g->nslot : 256;
  int *slot = calloc((size_t)ns, sizeof *slot);
  if (!slot) return -1;
  for (int i = 0; i < g->n; i++) {
    const sym_node *x = &g->node[i];
    size_t k = (size_t)node_hash(x->op, x->a, x->b, x->value, x->text) & (size_t)(ns - 1);
    while (slot[k]) k = (k + 1) & (size_t)(ns - 1);
    slot[k] = i + 1;
  }
  free(g->slot);
  g->slot = slot;
  g->nslot = ns;
  return 0;
}

/* the node (op, a, b, value, text): the existing one, or a new one */
static sym_id intern(sym_graph *g, sym_op op, sym_id a, sym_id b, double value, const char *text) {
  if (g->failed) return -1;
  if (2 * (g->n + 1) > g->nslot && grow_slots(g)) { g->failed = 1; return -1; }
  size_t mask = (size_t)(g->nslot - 1);
  size_t k = (size_t)node_hash(op, a, b, value, text) & mask;
  for (; g->slot[k]; k = (k + 1) & mask)
    if (same(&g->node[g->slot[k] - 1], op, a, b, value, text)) return g->slot[k] - 1;
  if (g->n == g->cap) {
    int nc = g->cap ? 2 * g->cap : 256;
    sym_node *nn = realloc(g->node, sizeof *nn * (size_t)nc);
    if (!nn) { g->failed = 1; return -1; }
    g->node = nn;
    g->cap = nc;
  }
  sym_node *x = &g->node[g->n];
  x->op = op; x->a = a; x->b = b; x->value = value; x->text = NULL;
  if (text && !(x->text = malloc(strlen(text) + 1))) { g->failed = 1; return -1; }
  if (text) strcpy(x->text, text);
  g->slot[k] = ++g->n;
  return g->n - 1;
}

sym_id sym_const(sym_graph *g, double value) { return intern(g, SYM_CONST, -1, -1, value, NULL); }
sym_id sym_symbol(sym_graph *g, const char *text) { return intern(g, SYM_SYMBOL, -1, -1, 0, text); }

int sym_is_const(const sym_graph *g, sym_id x, double *value) {
  if (x < 0 || g->node[x].op != SYM_CONST) return 0;
  *value = g->node[x].value;
  return 1;
}

static int is_value(const sym_graph *g, sym_id x, double v) {
  double c;
  return sym_is_const(g, x, &c) && c == v;
}

sym_id sym_neg(sym_graph *g, sym_id a) {
  double c;
  if (a < 0) return -1;
  if (sym_is_const(g, a, &c)) return sym_const(g, -c);
  if (g->node[a].op == SYM_NEG) return g->node[a].a;
  return intern(g, SYM_NEG, a, -1, 0, NULL);
}

sym_id sym_add(sym_graph *g, sym_id a, sym_id b) {
  double x, y;
  if (a < 0 || b < 0) return -1;
  if (sym_is_const(g, a, &x) && sym_is_const(g, b, &y)) return sym_const(g, x + y);
  if (is_value(g, a, 0)) return b;
  if (is_value(g, b, 0)) return a;
  if (a > b && !g->keep_order) { sym_id t = a; a = b; b = t; }
  return intern(g, SYM_ADD, a, b, 0, NULL);
}

sym_id sym_sub(sym_graph *g, sym_id a, sym_id b) {
  double x, y;
  if (a < 0 || b < 0) return -1;
  if (sym_is_const(g, a, &x) && sym_is_const(g, b, &y)) return sym_const(g, x - y);
  if (is_value(g, b, 0)) return a;
  if (is_value(g, a, 0)) return sym_neg(g, b);
  return intern(g, SYM_SUB, a, b, 0, NULL);
}

sym_id sym_mul(sym_graph *g, sym_id a, sym_id b) {
  double x, y;
  if (a < 0 || b < 0) return -1;
  if (sym_is_const(g, a, &x) && sym_is_const(g, b, &y)) return sym_const(g, x * y);
  if (is_value(g, a, 0) || is_value(g, b, 0)) return sym_const(g, 0);
  if (is_value(g, a, 1)) return b;
  if (is_value(g, b, 1)) return a;
  if (is_value(g, a, -1)) return sym_neg(g, b);
  if (is_value(g, b, -1)) return sym_neg(g, a);
  if (a > b && !g->keep_order) { sym_id t = a; a = b; b = t; }
  return intern(g, SYM_MUL, a, b, 0, NULL);
}

sym_id sym_div(sym_graph *g, sym_id a, sym_id b) {
  double x, y;
  if (a < 0 || b < 0) return -1;
  if (sym_is_const(g, a, &x) && sym_is_const(g, b, &y) && y != 0) return sym_const(g, x / y);
  if (is_value(g, b, 1)) return a;
  if (is_value(g, b, -1)) return sym_neg(g, a);
  if (is_value(g, a, 0) && !is_value(g, b, 0)) return sym_const(g, 0);
  return intern(g, SYM_DIV, a, b, 0, NULL);
}

static sym_id unary(sym_graph *g, sym_op op, sym_id a, double (*fn)(double)) {
  double c;
  if (a < 0) return -1;
  if (sym_is_const(g, a, &c)) return sym_const(g, fn(c));
  return intern(g, op, a, -1, 0, NULL);
}
sym_id sym_sqrt(sym_graph *g, sym_id a) { return unary(g, SYM_SQRT, a, sqrt); }
sym_id sym_sin(sym_graph *g, sym_id a) { return unary(g, SYM_SIN, a, sin); }
sym_id sym_cos(sym_graph *g, sym_id a) { return unary(g, SYM_COS, a, cos); }

sym_id sym_deriv(sym_graph *g, sym_id x, sym_id s) {
  if (x < 0 || s < 0 || g->node[s].op != SYM_SYMBOL) return -1;
  /* nodes are created after their operands: one pass in index order */
  sym_id *d = malloc(sizeof *d * (size_t)(x + 1));
  if (!d) { g->failed = 1; return -1; }
  sym_id zero = sym_const(g, 0), one = sym_const(g, 1), two = sym_const(g, 2);
  for (sym_id i = 0; i <= x; i++) {
    sym_node n = g->node[i]; /* a copy: the array may move while nodes are added */
    sym_id da = n.a >= 0 ? d[n.a] : -1, db = n.b >= 0 ? d[n.b] : -1;
    switch (n.op) {
    case SYM_CONST: d[i] = zero; break;
    case SYM_SYMBOL: d[i] = i == s ? one : zero; break;
    case SYM_ADD: d[i] = sym_add(g, da, db); break;
    case SYM_SUB: d[i] = sym_sub(g, da, db); break;
    case SYM_MUL: d[i] = sym_add(g, sym_mul(g, da, n.b), sym_mul(g, n.a, db)); break;
    case SYM_DIV: /* (a' b - a b') / (b b) */
      d[i] = sym_div(g, sym_sub(g, sym_mul(g, da, n.b), sym_mul(g, n.a, db)), sym_mul(g, n.b, n.b));
      break;
    case SYM_NEG: d[i] = sym_neg(g, da); break;
    case SYM_SQRT: d[i] = sym_div(g, da, sym_mul(g, two, i)); break;
    case SYM_SIN: d[i] = sym_mul(g, sym_cos(g, n.a), da); break;
    case SYM_COS: d[i] = sym_neg(g, sym_mul(g, sym_sin(g, n.a), da)); break;
    }
  }
  sym_id r = g->failed ? -1 : d[x];
  free(d);
  return r;
}

double sym_eval(const sym_graph *g, sym_id x, double (*value_of)(const char *text, void *ctx), void *ctx) {
  const sym_node *n = &g->node[x];
  switch (n->op) {
  case SYM_CONST: return n->value;
  case SYM_SYMBOL: return value_of(n->text, ctx);
  case SYM_ADD: return sym_eval(g, n->a, value_of, ctx) + sym_eval(g, n->b, value_of, ctx);
  case SYM_SUB: return sym_eval(g, n->a, value_of, ctx) - sym_eval(g, n->b, value_of, ctx);
  case SYM_MUL: return sym_eval(g, n->a, value_of, ctx) * sym_eval(g, n->b, value_of, ctx);
  case SYM_DIV: return sym_eval(g, n->a, value_of, ctx) / sym_eval(g, n->b, value_of, ctx);
  case SYM_NEG: return -sym_eval(g, n->a, value_of, ctx);
  case SYM_SQRT: return sqrt(sym_eval(g, n->a, value_of, ctx));
  case SYM_SIN: return sin(sym_eval(g, n->a, value_of, ctx));
  case SYM_COS: return cos(sym_eval(g, n->a, value_of, ctx));
  }
  return NAN;
}

int sym_literal(char *buf, size_t n, double x) {
  if (x == 0) return snprintf(buf, n, "0");
  char t[40];
  for (int prec = 15; prec < 17; prec++) {
    snprintf(t, sizeof t, "%.*g", prec, x);
    if (strtod(t, NULL) == x) return snprintf(buf, n, "%s", t);
  }
  return snprintf(buf, n, "%.17g", x);
}

/* binding strength: atoms 4, unary minus 3, * / 2, + - 1 */
static int prec_of(const sym_graph *g, sym_id x) {
  switch (g->node[x].op) {
  case SYM_ADD: case SYM_SUB: return 1;
  case SYM_MUL: case SYM_DIV: return 2;
  case SYM_NEG: return 3;
  case SYM_CONST: return g->node[x].value < 0 ? 3 : 4; /* "-0.5" reads as a negation */
  case SYM_SYMBOL: case SYM_SQRT: case SYM_SIN: case SYM_COS: return 4; /* a name, a call */
  }
  return 4;
}

static void print_node(FILE *f, const sym_graph *g, sym_id x, const char *const *local);

/* operand y of x, in parentheses when it binds less tightly than x needs:
 * left operands below x's strength, right operands at or below it (C's
 * left-to-right association would regroup them) */
static void print_operand(FILE *f, const sym_graph *g, sym_id y, int need, const char *const *local) {
  int p = local && local[y] ? 4 : prec_of(g, y);
  if (p < need) fputc('(', f);
  print_node(f, g, y, local);
  if (p < need) fputc(')', f);
}

static void print_node(FILE *f, const sym_graph *g, sym_id x, const char *const *local) {
  if (local && local[x]) { fputs(local[x], f); return; }
  const sym_node *n = &g->node[x];
  char lit[40];
  static const char *const opname[] = {"", "", " + ", " - ", " * ", " / "};
  switch (n->op) {
  case SYM_CONST: sym_literal(lit, sizeof lit, n->value); fputs(lit, f); break;
  case SYM_SYMBOL: fputs(n->text, f); break;
  case SYM_ADD: case SYM_SUB: case SYM_MUL: case SYM_DIV: {
    int p = n->op == SYM_ADD || n->op == SYM_SUB ? 1 : 2;
    print_operand(f, g, n->a, p, local);
    fputs(opname[n->op], f);
    print_operand(f, g, n->b, p + 1, local);
    break;
  }
  case SYM_NEG:
    fputc('-', f);
    print_operand(f, g, n->a, 4, local); /* no "--x", no "-a * b" ambiguity */
    break;
  case SYM_SQRT: case SYM_SIN: case SYM_COS:
    fputs(n->op == SYM_SQRT ? "sqrt(" : n->op == SYM_SIN ? "sin(" : "cos(", f);
    print_node(f, g, n->a, local);
    fputc(')', f);
    break;
  }
}

void sym_print(FILE *f, const sym_graph *g, sym_id x) { print_node(f, g, x, NULL); }

static void count_uses(const sym_graph *g, sym_id x, int *uses) {
  if (uses[x]++) return; /* its operands are counted once */
  const sym_node *n = &g->node[x];
  if (n->a >= 0) count_uses(g, n->a, uses);
  if (n->b >= 0) count_uses(g, n->b, uses);
}

int sym_print_block(FILE *f, const sym_graph *g, const sym_id *roots, const char *const *lhs, int nroots,
                    const char *prefix, const char *indent) {
  int *uses = calloc((size_t)g->n + 1, sizeof *uses);
  char **local = calloc((size_t)g->n + 1, sizeof *local);
  if (!uses || !local) { free(uses); free(local); return -1; }
  for (int r = 0; r < nroots; r++) count_uses(g, roots[r], uses);
  /* in index order: operands before the nodes that use them */
  int nlocal = 0, st = 0;
  for (sym_id i = 0; i < g->n && !st; i++) {
    sym_op op = g->node[i].op;
    if (uses[i] < 2 || op == SYM_CONST || op == SYM_SYMBOL) continue;
    char name[64];
    snprintf(name, sizeof name, "%s%d", prefix, nlocal++);
    fprintf(f, "%sconst mb_real %s = ", indent, name);
    print_node(f, g, i, (const char *const *)local);
    fputs(";\n", f);
    if (!(local[i] = malloc(strlen(name) + 1))) st = -1;
    else strcpy(local[i], name);
  }
  for (int r = 0; r < nroots && !st; r++) {
    fprintf(f, "%s%s = ", indent, lhs[r]);
    print_node(f, g, roots[r], (const char *const *)local);
    fputs(";\n", f);
  }
  for (sym_id i = 0; i < g->n; i++) free(local[i]);
  free(local);
  free(uses);
  return st;
}
