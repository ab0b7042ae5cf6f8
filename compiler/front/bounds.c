/* bounds.c: the bounds the front end checks before the work they bound. */
#include "bounds.h"

#include <string.h>
#include <strings.h>

int yaml_flow_depth(const char *data, size_t size, int limit, size_t *where) {
  int depth = 0, deepest = 0;
  char quote = 0;         /* inside a '...' or "..." scalar */
  int token_start = 1;    /* a quote here starts a quoted scalar, '#' a comment */
  for (size_t i = 0; i < size; i++) {
    char c = data[i];
    if (quote) {
      if (quote == '"' && c == '\\') i++;
      else if (c == quote) {
        if (quote == '\'' && i + 1 < size && data[i + 1] == '\'') i++; /* '' inside '...' */
        else quote = 0;
      }
      continue;
    }
    if (c == '#' && token_start) {
      while (i < size && data[i] != '\n') i++;
      token_start = 1;
      continue;
    }
    if ((c == '"' || c == '\'') && token_start) { quote = c; continue; }
    if (c == '[' || c == '{') {
      if (++depth > deepest) deepest = depth;
      if (depth > limit) { *where = i; return depth; }
    } else if ((c == ']' || c == '}') && depth > 0) {
      depth--;
    }
    token_start = c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '[' || c == '{' ||
                  c == ',' || c == ':' || c == '-' || c == '?';
  }
  return deepest;
}

const char *reserved_c_name(const char *name) {
  static const char *const taken[] = {
      /* files beside the generated code, and what the runtime links */
      "main", "bench_main", "support", "klu", "amd", "colamd", "btf", "camd", "cmocka", "yaml",
      "lapack", "cblas", "SuiteSparse_config", "unistd", "ida",
      /* the C standard headers (a generated NAME.h would hide one) */
      "assert", "complex", "ctype", "errno", "fenv", "float", "inttypes", "iso646", "limits",
      "locale", "math", "setjmp", "signal", "stdalign", "stdarg", "stdatomic", "stdbool",
      "stddef", "stdint", "stdio", "stdlib", "stdnoreturn", "string", "tgmath", "threads",
      "time", "uchar", "wchar", "wctype", NULL};
  for (int i = 0; taken[i]; i++)
    if (!strcasecmp(name, taken[i])) return "it would clash with a file or symbol of the C build";
  if (!strncasecmp(name, "mb_", 3) || !strcasecmp(name, "mb"))
    return "names beginning with 'mb_' belong to the runtime";
  if (name[0] == '_' && (name[1] == '_' || (name[1] >= 'A' && name[1] <= 'Z')))
    return "names beginning with '__' or '_' and a capital are reserved in C";
  return NULL;
}
