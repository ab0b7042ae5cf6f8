/* emit_util.c: the emit context and the printing helpers (emit_util.h). */
#include <ctype.h>
#include <string.h>

#include "emit_util.h"

void emit_ctx_init(emit_ctx *cx, FILE *f, const mbc_unit *u) {
  memset(cx, 0, sizeof *cx);
  cx->f = f;
  cx->u = u;
  cx->L = u->lowered;
  cx->nm = u->lowered->m.name;
  upper(cx->NM, cx->nm, sizeof cx->NM);
}

void num(FILE *f, double x) {
  if (x == 0) x = 0; /* no "-0" */
  fprintf(f, "%.17g", x);
}

void vec(FILE *f, const double *x, int n) {
  fputc('{', f);
  for (int i = 0; i < n; i++) {
    if (i) fputs(", ", f);
    num(f, x[i]);
  }
  fputc('}', f);
}

void ivec(FILE *f, const int *x, int n) {
  fputc('{', f);
  for (int i = 0; i < n; i++) fprintf(f, "%s%d", i ? ", " : "", x[i]);
  fputc('}', f);
}

void int_array(FILE *f, const char *name, const int *x, long n) {
  fprintf(f, "static const int %s[%ld] = {", name, n > 0 ? n : 1);
  if (n <= 0) fputs("0", f);
  for (long i = 0; i < n; i++) fprintf(f, "%s%d", i % 16 ? ", " : (i ? ",\n  " : "\n  "), x[i]);
  fprintf(f, "\n};\n");
}

void real_array(FILE *f, const char *name, const double *x, long n) {
  fprintf(f, "static const mb_real %s[%ld] = {", name, n > 0 ? n : 1);
  if (n <= 0) fputs("0", f);
  for (long i = 0; i < n; i++) {
    fputs(i % 4 ? ", " : (i ? ",\n  " : "\n  "), f);
    num(f, x[i]);
  }
  fprintf(f, "\n};\n");
}

void upper(char *dst, const char *src, size_t n) {
  size_t i = 0;
  for (; src[i] && i + 1 < n; i++) dst[i] = (char)toupper((unsigned char)src[i]);
  dst[i] = 0;
}
