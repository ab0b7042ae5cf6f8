/* sym.h: the expression layer of the back end: a hash-consed DAG of scalar
 * expressions (constants, symbols, + - * / neg sqrt sin cos) with constant
 * folding, shared subexpressions, forward derivatives and one printer of C
 * expressions with the shortest round-trip literals.
 *
 * A symbol is a C expression the compiler does not know the value of (q[3],
 * f0.A[2], a run-time parameter): it never folds.  Building the same
 * expression twice gives the same node (hash-consing), so shared
 * subexpressions are found by construction; sym_print_block writes each node
 * used more than once as a local, once.
 *
 * Folding keeps the numbers of the unfolded expression for finite values: a
 * product with an exact 0 is 0, with 1 its other factor, with -1 its negation;
 * constants are combined in double.  Operands of + and * are put in a
 * canonical order (both are commutative in IEEE arithmetic), unless the
 * graph keeps the order it was given (keep_order); association is never
 * changed: (a + b) + c and a + (b + c) stay two expressions and print with
 * the parentheses that keep their order. */
#ifndef MBCC_SYM_H
#define MBCC_SYM_H

#include <stddef.h>
#include <stdio.h>

typedef enum {
  SYM_CONST, SYM_SYMBOL, SYM_ADD, SYM_SUB, SYM_MUL, SYM_DIV, SYM_NEG, SYM_SQRT, SYM_SIN, SYM_COS
} sym_op;

/* a node of the graph; -1: none (out of memory: the graph's 'failed' is set) */
typedef int sym_id;

typedef struct {
  sym_op op;
  sym_id a, b;    /* operands (-1 unused) */
  double value;   /* SYM_CONST */
  char *text;     /* SYM_SYMBOL: its C expression (an atom: a name, a[i], s.f[i]) */
} sym_node;

typedef struct {
  sym_node *node;
  int n, cap;
  int *slot;      /* open addressing: node index + 1, 0 empty */
  int nslot;      /* a power of 2 */
  int failed;     /* an allocation failed: every later result is -1 */
  int keep_order; /* set after sym_init: + and * keep their operands in the
                     order given (the printed C reads as the runtime kernel
                     it replaces; a + b and b + a are then two nodes) */
} sym_graph;

void sym_init(sym_graph *g);
void sym_free(sym_graph *g);

sym_id sym_const(sym_graph *g, double value);
sym_id sym_symbol(sym_graph *g, const char *text);
sym_id sym_add(sym_graph *g, sym_id a, sym_id b);
sym_id sym_sub(sym_graph *g, sym_id a, sym_id b);
sym_id sym_mul(sym_graph *g, sym_id a, sym_id b);
sym_id sym_div(sym_graph *g, sym_id a, sym_id b);
sym_id sym_neg(sym_graph *g, sym_id a);
sym_id sym_sqrt(sym_graph *g, sym_id a);
sym_id sym_sin(sym_graph *g, sym_id a);
sym_id sym_cos(sym_graph *g, sym_id a);

/* 1 if x is a constant, its value in *value */
int sym_is_const(const sym_graph *g, sym_id x, double *value);

/* d x / d s (forward mode) for the symbol s; -1 if s is not a symbol */
sym_id sym_deriv(sym_graph *g, sym_id x, sym_id s);

/* x's value with the symbols' values from value_of(text, ctx) (the tests'
 * independent check) */
double sym_eval(const sym_graph *g, sym_id x, double (*value_of)(const char *text, void *ctx), void *ctx);

/* the shortest of %.15g, %.16g, %.17g that reads back (strtod) as x exactly,
 * "0" for both zeros; the length written (snprintf's) */
int sym_literal(char *buf, size_t n, double x);

/* x as one C expression (no locals) */
void sym_print(FILE *f, const sym_graph *g, sym_id x);

/* the roots as C statements: every operation node used more than once among
 * them becomes "<indent>const mb_real <prefix><k> = ...;" (once, before its
 * first use), then "<indent><lhs[i]> = <root i>;".  Returns 0, or -1 out of
 * memory (nothing written). */
int sym_print_block(FILE *f, const sym_graph *g, const sym_id *roots, const char *const *lhs, int nroots,
                    const char *prefix, const char *indent);

#endif
