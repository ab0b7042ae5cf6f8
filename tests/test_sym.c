/* test_sym.c: the expression layer (compiler/back/sym.c), against truths that
 * do not come from it:
 *   - folding: the identities of 0, 1 and -1, constants combined in double,
 *     association never changed;
 *   - hash-consing: the same expression built twice (also a + b and b + a)
 *     is one node; a shared subexpression is written once as a local; a
 *     graph that keeps the order (keep_order) prints b * a as built;
 *   - the literal printer on 200000 random doubles (random bit patterns,
 *     every exponent): strtod gives the same bits back, and no shorter
 *     precision of %.15g / %.16g would have;
 *   - derivatives of random expressions against central finite differences;
 *   - the printed C compiles and computes what sym_eval computes (a generated
 *     program, built with the C compiler). */
// models:
#define _POSIX_C_SOURCE 200809L
#include "../compiler/back/sym.c"

#include <unistd.h>

#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

static double values[4];
static double value_of(const char *text, void *ctx) {
  (void)ctx;
  return values[text[2] - '0']; /* "x[k]" */
}

static void test_folding(void **state) {
  (void)state;
  sym_graph g;
  sym_init(&g);
  sym_id x = sym_symbol(&g, "x[0]"), y = sym_symbol(&g, "x[1]");
  sym_id zero = sym_const(&g, 0), one = sym_const(&g, 1), mone = sym_const(&g, -1);
  double c;
  assert_int_equal(sym_add(&g, x, zero), x);
  assert_int_equal(sym_add(&g, zero, x), x);
  assert_int_equal(sym_sub(&g, x, zero), x);
  assert_int_equal(sym_sub(&g, zero, x), sym_neg(&g, x));
  assert_int_equal(sym_mul(&g, x, one), x);
  assert_int_equal(sym_mul(&g, one, x), x);
  assert_int_equal(sym_mul(&g, x, zero), zero);
  assert_int_equal(sym_mul(&g, x, mone), sym_neg(&g, x));
  assert_int_equal(sym_div(&g, x, one), x);
  assert_int_equal(sym_div(&g, x, mone), sym_neg(&g, x));
  assert_int_equal(sym_neg(&g, sym_neg(&g, x)), x);
  assert_true(sym_is_const(&g, sym_mul(&g, sym_const(&g, 3), sym_const(&g, 0.1)), &c));
  assert_true(c == 3 * 0.1);
  assert_true(sym_is_const(&g, sym_sqrt(&g, sym_const(&g, 2)), &c) && c == sqrt(2.0));
  assert_true(sym_is_const(&g, sym_neg(&g, sym_const(&g, 2.5)), &c) && c == -2.5);
  /* a division by a constant zero is kept (no silent infinity at compile time) */
  assert_false(sym_is_const(&g, sym_div(&g, one, zero), &c));
  /* symbols never fold */
  assert_false(sym_is_const(&g, sym_add(&g, x, y), &c));
  /* association is kept: (x + y) + 1 and x + (y + 1) are different */
  sym_id l = sym_add(&g, sym_add(&g, x, y), sym_const(&g, 1.5));
  sym_id r = sym_add(&g, x, sym_add(&g, y, sym_const(&g, 1.5)));
  assert_int_not_equal(l, r);
  char buf[256];
  FILE *f = fmemopen(buf, sizeof buf, "w");
  sym_print(f, &g, l); fputs(" | ", f);
  sym_print(f, &g, r); fputs(" | ", f);
  sym_print(f, &g, sym_sub(&g, x, sym_sub(&g, y, one))); fputs(" | ", f);
  sym_print(f, &g, sym_neg(&g, sym_mul(&g, x, y)));
  fclose(f);
  assert_string_equal(buf, "x[0] + x[1] + 1.5 | x[0] + (x[1] + 1.5) | x[0] - (x[1] - 1) | -(x[0] * x[1])");
  sym_free(&g);
}

static void test_hash_consing(void **state) {
  (void)state;
  sym_graph g;
  sym_init(&g);
  sym_id x = sym_symbol(&g, "x[0]"), y = sym_symbol(&g, "x[1]");
  assert_int_equal(sym_symbol(&g, "x[0]"), x);
  sym_id a = sym_mul(&g, sym_add(&g, x, y), sym_sin(&g, x));
  int n = g.n;
  sym_id b = sym_mul(&g, sym_sin(&g, x), sym_add(&g, y, x));
  assert_int_equal(a, b);
  assert_int_equal(g.n, n); /* nothing new */
  assert_int_not_equal(sym_const(&g, 0.0), sym_const(&g, -0.0));
  /* the shared x + y is computed once */
  sym_id roots[2] = {sym_mul(&g, sym_add(&g, x, y), sym_const(&g, 2)), sym_div(&g, sym_add(&g, x, y), y)};
  const char *lhs[2] = {"out[0]", "out[1]"};
  char buf[512];
  FILE *f = fmemopen(buf, sizeof buf, "w");
  assert_int_equal(sym_print_block(f, &g, roots, lhs, 2, "t", "  "), 0);
  fclose(f);
  assert_string_equal(buf, "  const mb_real t0 = x[0] + x[1];\n  out[0] = t0 * 2;\n  out[1] = t0 / x[1];\n");
  sym_free(&g);

  /* keep_order: the operands stay as given, the same expression is still one node */
  sym_init(&g);
  g.keep_order = 1;
  x = sym_symbol(&g, "x[0]");
  y = sym_symbol(&g, "x[1]");
  sym_id yx = sym_add(&g, sym_mul(&g, y, x), x);
  assert_int_not_equal(sym_mul(&g, y, x), sym_mul(&g, x, y));
  assert_int_equal(sym_add(&g, sym_mul(&g, y, x), x), yx);
  f = fmemopen(buf, sizeof buf, "w");
  sym_print(f, &g, yx);
  fclose(f);
  assert_string_equal(buf, "x[1] * x[0] + x[0]");
  sym_free(&g);
}

static uint64_t rng = 0x2545f4914f6cdd1dULL;
static uint64_t next(void) {
  rng ^= rng << 13; rng ^= rng >> 7; rng ^= rng << 17;
  return rng;
}

static void test_literals(void **state) {
  (void)state;
  char buf[64], t[64];
  for (int i = 0; i < 200000; i++) {
    uint64_t bits = next();
    double x;
    memcpy(&x, &bits, sizeof x);
    if (!isfinite(x)) continue;
    sym_literal(buf, sizeof buf, x);
    double back = strtod(buf, NULL);
    if (x == 0) { assert_string_equal(buf, "0"); continue; }
    if (memcmp(&back, &x, sizeof x)) fail_msg("%s does not read back as %.17g", buf, x);
    /* shortest: no lower precision of the three reads back */
    for (int p = 15; p < 17; p++) {
      snprintf(t, sizeof t, "%.*g", p, x);
      if (strtod(t, NULL) == x) {
        if (strlen(buf) > strlen(t)) fail_msg("%s printed, %s is shorter and exact", buf, t);
        break;
      }
    }
  }
  sym_literal(buf, sizeof buf, 0.1);
  assert_string_equal(buf, "0.1");
  sym_literal(buf, sizeof buf, 1.0 / 3);
  assert_string_equal(buf, "0.3333333333333333");
}

/* a random expression of depth d over x[0..2], values kept away from the
 * singularities of / and sqrt */
static sym_id random_expr(sym_graph *g, int d) {
  static const char *names[] = {"x[0]", "x[1]", "x[2]"};
  if (d == 0) {
    if (next() % 4 == 0) return sym_const(g, (double)(next() % 1000) / 250 - 2);
    return sym_symbol(g, names[next() % 3]);
  }
  sym_id a = random_expr(g, d - 1), b = random_expr(g, d - 1);
  switch (next() % 8) {
  case 0: return sym_add(g, a, b);
  case 1: return sym_sub(g, a, b);
  case 2: return sym_mul(g, a, b);
  case 3: return sym_div(g, a, sym_add(g, sym_const(g, 3), sym_mul(g, b, b)));
  case 4: return sym_neg(g, a);
  case 5: return sym_sqrt(g, sym_add(g, sym_const(g, 1), sym_mul(g, a, a)));
  case 6: return sym_sin(g, a);
  default: return sym_cos(g, a);
  }
}

static void test_derivatives(void **state) {
  (void)state;
  for (int trial = 0; trial < 300; trial++) {
    sym_graph g;
    sym_init(&g);
    sym_id e = random_expr(&g, 4);
    for (int k = 0; k < 3; k++) values[k] = (double)(next() % 2000) / 1000 - 1;
    for (int k = 0; k < 3; k++) {
      static const char *names[] = {"x[0]", "x[1]", "x[2]"};
      sym_id s = sym_symbol(&g, names[k]);
      sym_id de = sym_deriv(&g, e, s);
      assert_true(de >= 0);
      double x0 = values[k], h = 1e-5;
      values[k] = x0 + h;
      double fp = sym_eval(&g, e, value_of, NULL);
      values[k] = x0 - h;
      double fm = sym_eval(&g, e, value_of, NULL);
      values[k] = x0;
      double fd = (fp - fm) / (2 * h), an = sym_eval(&g, de, value_of, NULL);
      if (fabs(fd - an) > 1e-6 * (1 + fabs(an)))
        fail_msg("trial %d, d/dx[%d]: analytic %.12g, finite differences %.12g", trial, k, an, fd);
    }
    assert_false(g.failed);
    sym_free(&g);
  }
}

/* the printed C, compiled, computes sym_eval's values exactly (same
 * operations in the same order) */
static void test_printed_c(void **state) {
  (void)state;
  const char *cc = getenv("CC");
  char dir[] = "/tmp/test_symXXXXXX";
  assert_non_null(mkdtemp(dir));
  char src[64], exe[64], cmd[1024], out[64];
  snprintf(src, sizeof src, "%s/e.c", dir);
  snprintf(exe, sizeof exe, "%s/e", dir);
  snprintf(out, sizeof out, "%s/out.txt", dir);
  sym_graph g;
  sym_init(&g);
  enum { N = 40 };
  sym_id roots[N];
  char lhs_buf[N][16];
  const char *lhs[N];
  for (int i = 0; i < N; i++) {
    roots[i] = random_expr(&g, 5);
    snprintf(lhs_buf[i], sizeof lhs_buf[i], "y[%d]", i);
    lhs[i] = lhs_buf[i];
  }
  for (int k = 0; k < 3; k++) values[k] = (double)(next() % 2000) / 1000 - 1;
  FILE *f = fopen(src, "w");
  assert_non_null(f);
  fprintf(f, "#include <math.h>\n#include <stdio.h>\ntypedef double mb_real;\n"
             "int main(void) {\n  double x[3] = {%.17g, %.17g, %.17g}, y[%d];\n",
          values[0], values[1], values[2], N);
  assert_int_equal(sym_print_block(f, &g, roots, lhs, N, "t", "  "), 0);
  fprintf(f, "  for (int i = 0; i < %d; i++) printf(\"%%a\\n\", y[i]);\n  return 0;\n}\n", N);
  fclose(f);
  snprintf(cmd, sizeof cmd, "%s -std=c99 -O0 -ffp-contract=off -Wall -Werror -o %s %s -lm && %s > %s",
           cc && *cc ? cc : "cc", exe, src, exe, out);
  assert_int_equal(system(cmd), 0);
  FILE *in = fopen(out, "r");
  assert_non_null(in);
  for (int i = 0; i < N; i++) {
    char line[64];
    assert_non_null(fgets(line, sizeof line, in));
    double got = strtod(line, NULL), want = sym_eval(&g, roots[i], value_of, NULL);
    if (!(got == want || (isnan(got) && isnan(want))))
      fail_msg("root %d: the compiled C gives %a, sym_eval %a", i, got, want);
  }
  fclose(in);
  sym_free(&g);
  remove(src); remove(exe); remove(out); rmdir(dir);
}

int main(void) {
  const struct CMUnitTest tests[] = {
      cmocka_unit_test(test_folding),     cmocka_unit_test(test_hash_consing),
      cmocka_unit_test(test_literals),    cmocka_unit_test(test_derivatives),
      cmocka_unit_test(test_printed_c),
  };
  return cmocka_run_group_tests(tests, NULL, NULL);
}
