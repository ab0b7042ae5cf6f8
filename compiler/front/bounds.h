/* bounds.h: the resource limits of the compiler's front end, each checked
 * before the work it bounds starts (docs/reliability.md lists them).  The
 * ones a large but sensible model may reach can be lifted by an environment
 * variable, named in the error message. */
#ifndef MBCC_BOUNDS_H
#define MBCC_BOUNDS_H

#include <stdlib.h>

/* a model file larger than this is refused unread (MBCC_MAX_INPUT=BYTES) */
#define LIMIT_INPUT_BYTES (16.0 * 1024 * 1024)
/* brackets nested deeper than this ([[[...) are refused before YAML parsing
   (libyaml's time grows with the square of the depth) */
#define LIMIT_YAML_DEPTH 64
/* a count or index read as a number (modes, nodes, elements) */
#define LIMIT_COUNT 1000000.0
/* the largest magnitude of a number in a model: beyond it products in the
   emitted code (m g, E I / L^3, ...) could overflow */
#define LIMIT_MAGNITUDE 1e30
/* bodies (with virtual ones): the analysis is sparse (a 2000-link chain
   checks in 0.4 s), but the emitted code and its C compile grow with the
   model (MBCC_MAX_BODIES=N) */
#define LIMIT_BODIES 10000.0
/* the free DOFs of a dense FE eigenproblem (eigensolver: dense, or
   Craig-Bampton), whose time grows with the cube and memory with the square
   (MBCC_MAX_FE_DOFS=N); eigensolver auto goes sparse above 3000 anyway */
#define LIMIT_FE_DOFS 3000.0

/* a limit: the environment variable's value if it is a positive number */
static inline double limit_value(const char *env, double dflt) {
  const char *e = getenv(env);
  char *end = NULL;
  double x = e && *e ? strtod(e, &end) : 0;
  return x > 0 && end && !*end ? x : dflt;
}



#include <stddef.h>
/* The deepest nesting of flow collections ('[' and '{') in YAML text, with
 * quoted scalars and comments skipped; stops at the first place deeper than
 * 'limit' and returns its byte offset in *where.  Linear in the size. */
int yaml_flow_depth(const char *data, size_t size, int limit, size_t *where);
/* Why a model's C name (the model's, or <model>_<scene>) would collide with
 * the generated files' neighbours or the runtime's symbols (main.c, mb_*.h,
 * a standard header found through -I, MB_*_H guards), or NULL if it is free. */
const char *reserved_c_name(const char *name);

#endif
