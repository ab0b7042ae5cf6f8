/* mb_math.h: the math of mb_real, per precision.  With MB_REAL_FLOAT every
 * call is the single-precision libm function (sqrtf, sinf, ...) and every
 * literal written MB_R(x) is a float literal, so a float build computes in
 * float only: a Cortex-M4F has a single-precision FPU and would emulate any
 * double in software (the build is clean under -Wdouble-promotion).  In
 * double precision the macros are the plain double functions and literals,
 * so double results are bit for bit those of code written without them. */
#ifndef MB_MATH_H
#define MB_MATH_H

#include <math.h>
#include "mb_types.h"

/* a floating literal (written with a '.' or an exponent) of type mb_real;
 * two levels so that a macro argument (MB_R(MB_PI)) is expanded first */
#ifdef MB_REAL_FLOAT
#define MB_R(x) MB_R_PASTE_(x)
#define MB_R_PASTE_(x) x##f
#define MB_SQRT(x) sqrtf(x)
#define MB_SIN(x) sinf(x)
#define MB_COS(x) cosf(x)
#define MB_TAN(x) tanf(x)
#define MB_FABS(x) fabsf(x)
#define MB_ATAN2(y, x) atan2f(y, x)
#define MB_ASIN(x) asinf(x)
#define MB_ACOS(x) acosf(x)
#define MB_POW(x, y) powf(x, y)
#define MB_EXP(x) expf(x)
#define MB_LOG(x) logf(x)
#define MB_FLOOR(x) floorf(x)
#define MB_CEIL(x) ceilf(x)
#define MB_FMAX(x, y) fmaxf(x, y)
#define MB_FMIN(x, y) fminf(x, y)
#define MB_NEARBYINT(x) nearbyintf(x)
#else
#define MB_R(x) x
#define MB_SQRT(x) sqrt(x)
#define MB_SIN(x) sin(x)
#define MB_COS(x) cos(x)
#define MB_TAN(x) tan(x)
#define MB_FABS(x) fabs(x)
#define MB_ATAN2(y, x) atan2(y, x)
#define MB_ASIN(x) asin(x)
#define MB_ACOS(x) acos(x)
#define MB_POW(x, y) pow(x, y)
#define MB_EXP(x) exp(x)
#define MB_LOG(x) log(x)
#define MB_FLOOR(x) floor(x)
#define MB_CEIL(x) ceil(x)
#define MB_FMAX(x, y) fmax(x, y)
#define MB_FMIN(x, y) fmin(x, y)
#define MB_NEARBYINT(x) nearbyint(x)
#endif

/* -ffreestanding (the embedded package's flags) implies -fno-builtin: sqrt
 * and fabs would be library calls, and newlib's sqrtf wrapper sets errno,
 * which links its reentrancy data (1 KB of RAM).  The builtins are the FPU's
 * instructions (with -fno-math-errno), with the same correctly rounded values;
 * a hosted build already treats the plain names as these builtins. */
#if defined(__GNUC__)
#undef MB_SQRT
#undef MB_FABS
#ifdef MB_REAL_FLOAT
#define MB_SQRT(x) __builtin_sqrtf(x)
#define MB_FABS(x) __builtin_fabsf(x)
#else
#define MB_SQRT(x) __builtin_sqrt(x)
#define MB_FABS(x) __builtin_fabs(x)
#endif
#endif

/* isfinite is type-generic (a macro of <math.h>): no promotion either way */
#define MB_ISFINITE(x) isfinite(x)

#endif
