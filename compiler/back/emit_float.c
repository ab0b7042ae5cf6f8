/* emit_float.c: the single-precision dialect of an emitted C file.  The
 * emitters write one C text for both precisions, with literals printed by
 * %.17g and the double libm names (fabs, sqrt); compiled with mb_real =
 * float that text computes in double wherever a literal or a libm call
 * appears (0.1 * x promotes x).  This pass rewrites the file outside comments,
 * strings and preprocessor lines:
 *   - a floating literal (one with a '.' or an exponent, no suffix) becomes
 *     the nearest float, printed with %.9g (which reads back exactly) and the
 *     suffix f;
 *   - a call of a double libm function becomes its MB_* macro of mb_math.h.
 * Integer literals stay: int op float is float.  Double output is never
 * touched, so it stays byte-identical; one pass over the finished file keeps
 * the emitters free of a precision flag. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emit_float.h"

static const char *const libm_names[][2] = {
    {"fabs", "MB_FABS"}, {"sqrt", "MB_SQRT"}, {"sin", "MB_SIN"},     {"cos", "MB_COS"},
    {"tan", "MB_TAN"},   {"atan2", "MB_ATAN2"}, {"asin", "MB_ASIN"}, {"acos", "MB_ACOS"},
    {"pow", "MB_POW"},   {"exp", "MB_EXP"},   {"log", "MB_LOG"},     {"floor", "MB_FLOOR"},
    {"ceil", "MB_CEIL"}, {"fmax", "MB_FMAX"}, {"fmin", "MB_FMIN"}};

static int is_ident(int c) { return isalnum(c) || c == '_'; }

/* a preprocessing number starting at s: its length */
static size_t pp_number(const char *s) {
  size_t n = 0;
  while (s[n]) {
    if ((s[n] == '+' || s[n] == '-') && n && strchr("eEpP", s[n - 1])) { n++; continue; }
    if (is_ident((unsigned char)s[n]) || s[n] == '.') { n++; continue; }
    break;
  }
  return n;
}

/* macros whose value goes into a double field of mb_model (statistics, not
 * model numbers): <M>_LDL_FLOPS initializes mb_model.ldl_flops */
static int define_stays_double(const char *name) {
  size_t n = strcspn(name, " (\n");
  static const char suffix[] = "_LDL_FLOPS";
  return n >= sizeof suffix - 1 && !memcmp(name + n - (sizeof suffix - 1), suffix, sizeof suffix - 1);
}

static void float_literal(FILE *out, const char *tok, size_t n) {
  int floating = !(n > 1 && tok[0] == '0' && (tok[1] == 'x' || tok[1] == 'X')) &&
                 (memchr(tok, '.', n) || memchr(tok, 'e', n) || memchr(tok, 'E', n)) &&
                 !strchr("fFlL", tok[n - 1]);
  if (!floating) { fwrite(tok, 1, n, out); return; }
  char buf[64];
  if (n >= sizeof buf) { fwrite(tok, 1, n, out); fputc('f', out); return; }
  memcpy(buf, tok, n);
  buf[n] = 0;
  float x = (float)strtod(buf, NULL);
  char txt[64];
  snprintf(txt, sizeof txt, "%.9g", (double)x);
  /* keep it a floating literal: "1" must become "1.0f", not "1f" */
  if (!strpbrk(txt, ".eEni")) strcat(txt, ".0");
  fprintf(out, "%sf", txt);
}

int emit_float_dialect(const char *path) {
  FILE *in = fopen(path, "rb");
  if (!in) return -1;
  if (fseek(in, 0, SEEK_END)) { fclose(in); return -1; }
  long size = ftell(in);
  rewind(in);
  char *src = size >= 0 ? malloc((size_t)size + 1) : NULL;
  if (!src || fread(src, 1, (size_t)size, in) != (size_t)size) { free(src); fclose(in); return -1; }
  fclose(in);
  src[size] = 0;
  char tmp[4200];
  snprintf(tmp, sizeof tmp, "%s.float", path);
  FILE *out = fopen(tmp, "wb");
  if (!out) { free(src); return -1; }
  for (const char *p = src; *p;) {
    if (p[0] == '/' && p[1] == '*') {
      const char *e = strstr(p + 2, "*/");
      e = e ? e + 2 : p + strlen(p);
      fwrite(p, 1, (size_t)(e - p), out);
      p = e;
    } else if (p[0] == '/' && p[1] == '/') {
      const char *e = strchr(p, '\n');
      e = e ? e : p + strlen(p);
      fwrite(p, 1, (size_t)(e - p), out);
      p = e;
    } else if (*p == '"' || *p == '\'') {
      const char *e = p + 1;
      while (*e && *e != *p) e += (*e == '\\' && e[1]) ? 2 : 1;
      if (*e) e++;
      fwrite(p, 1, (size_t)(e - p), out);
      p = e;
    } else if (!strncmp(p, "#define ", 8) && define_stays_double(p + 8)) {
      const char *e = strchr(p, '\n');
      e = e ? e : p + strlen(p);
      fwrite(p, 1, (size_t)(e - p), out);
      p = e;
    } else if (isalpha((unsigned char)*p) || *p == '_') {
      const char *e = p;
      while (is_ident((unsigned char)*e)) e++;
      size_t n = (size_t)(e - p);
      const char *name = NULL;
      const char *after = e;
      while (*after == ' ') after++;
      if (*after == '(')
        for (size_t k = 0; k < sizeof libm_names / sizeof libm_names[0]; k++)
          if (strlen(libm_names[k][0]) == n && !memcmp(p, libm_names[k][0], n)) name = libm_names[k][1];
      if (name) fputs(name, out);
      else fwrite(p, 1, n, out);
      p = e;
    } else if (isdigit((unsigned char)*p) || (*p == '.' && isdigit((unsigned char)p[1]))) {
      size_t n = pp_number(p);
      float_literal(out, p, n);
      p += n;
    } else {
      fputc(*p++, out);
    }
  }
  free(src);
  int bad = ferror(out);
  if (fclose(out) || bad || rename(tmp, path)) { remove(tmp); return -1; }
  return 0;
}
