/* mb_types.h: the scalar type and status codes shared by the runtime and
 * the generated code.  Build with -DMB_REAL_FLOAT for single precision. */
#ifndef MB_TYPES_H
#define MB_TYPES_H

/* restrict in C99 and later, the compilers' __restrict in C++ (the generated
 * code also compiles as C++), nothing elsewhere */
#if defined(__cplusplus)
#if defined(__GNUC__) || defined(__clang__) || defined(_MSC_VER)
#define MB_RESTRICT __restrict
#else
#define MB_RESTRICT
#endif
#elif defined(__STDC_VERSION__) && __STDC_VERSION__ >= 199901L
#define MB_RESTRICT restrict
#else
#define MB_RESTRICT
#endif

#ifdef __cplusplus
extern "C" {
#endif

#ifdef MB_REAL_FLOAT
typedef float mb_real;
#else
typedef double mb_real;
#endif

/* Status codes: 0 is success; the runtime never prints or exits. */
typedef enum {
  MB_OK = 0,
  MB_ERR_SINGULAR = 1,        /* the system matrix K could not be factorized */
  MB_ERR_NONFINITE = 2,       /* NaN or Inf in the state or the accelerations */
  MB_ERR_STEP_TOO_SMALL = 3,  /* the adaptive step fell below min_step */
  MB_ERR_PROJECTION = 4,      /* coordinate projection did not converge */
  MB_ERR_NOMEM = 5,           /* allocation failed (hosted runtime only) */
  MB_ERR_INVALID = 6,         /* invalid settings */
  MB_ERR_NEWTON = 7,          /* the implicit integrator's Newton iteration diverged */
  MB_ERR_STEP_BUDGET = 8,     /* the run needs more steps than settings.max_steps */
  MB_ERR_ENERGY = 9           /* the energy rose beyond what the model can supply (watchdog) */
} mb_status;

#define MB_PI 3.14159265358979323846

const char *mb_status_text(int status);

#ifdef __cplusplus
}
#endif

#endif
