/* mb_step.h: fixed-step time integration on one caller-supplied data block,
 * for embedded and real-time use: explicit RK4, or generalized-alpha with a
 * fixed number of modified-Newton iterations on the emitted LDL^T, each step
 * followed by a bounded coordinate projection.  Freestanding: no allocation,
 * no I/O, no clock, no errno; every loop has a bound known at compile time.
 *
 * The data block holds an mb_stepper followed by its arrays; its size is a
 * compile-time constant, MB_STEP_BYTES(...) of the model's sizes, which the
 * generated package header spells <M>_DATA_BYTES. */
#ifndef MB_STEP_H
#define MB_STEP_H

#include "mb_model.h"

/* the integrators (numbered as the hosted MB_RK4 / MB_GENALPHA) */
enum { MB_STEP_RK4 = 0, MB_STEP_GENALPHA = 2 };
/* A package built for one integrator defines MB_STEP_INTEGRATOR_ONLY to it
 * (in its mb_types.h): the other is compiled out (less flash; mb_step_init
 * then refuses it with MB_ERR_INVALID). */
#ifdef MB_STEP_INTEGRATOR_ONLY
#define MB_STEP_HAS(k) ((k) == MB_STEP_INTEGRATOR_ONLY)
#else
#define MB_STEP_HAS(k) 1
#endif

typedef struct {
  int integrator;            /* MB_STEP_RK4 or MB_STEP_GENALPHA */
  int newton_iterations;     /* genalpha: modified-Newton iterations per step (fixed) */
  int projection;            /* 1: project (q, v) onto the constraints after every step */
  int projection_iterations; /* most position-projection iterations per step */
  mb_real projection_tol;    /* max |phi| that ends the position projection */
  mb_real rho_inf;           /* genalpha: spectral radius at infinite step, 0..1 */
} mb_step_settings;

/* the generalized-alpha method's constants (Chung & Hulbert) */
typedef struct {
  mb_real am, af, gamma, beta;
} mb_ga_method;

typedef struct {
  const mb_model *m;
  mb_step_settings set;
  mb_real t;
  mb_ga_method ga;                             /* genalpha constants */
  int nin;                                     /* inputs (u) */
  mb_real *q, *v, *Kx, *rhs, *x, *dv, *phi, *nu, *ldl, *u, *frames;
  mb_real *y0, *ytmp, *ksum, *kst;             /* RK4 */
  mb_real *vd, *a, *a1, *dq, *v1, *lam, *q1, *Kmod; /* genalpha */
  long steps;
  int projection_iterations_last;              /* position iterations of the last step */
} mb_stepper;

/* mb_real elements after the mb_stepper (each array has one spare element,
 * as the hosted workspaces: the emitted code may read one past the end).
 * The outputs' and the force tangent's frames share the LDL^T workspace:
 * each is used between an evaluation and the next factorization only. */
#define MB_STEP_MAX_(A, B) ((A) > (B) ? (A) : (B))
#define MB_STEP_REALS(NQ, NV, NC, N, NNZ, LDLW, NIN, FRAMES, GA)                                  \
  ((NQ) + (NV) + (NNZ) + 3 * (N) + 2 * (NC) + MB_STEP_MAX_(LDLW, FRAMES) + (NIN) + 10 +           \
   ((GA) ? 5 * (NV) + (NC) + (NQ) + (NNZ) + 8 : 4 * ((NQ) + (NV) + 1)))
/* bytes of the data block: the mb_stepper, padded to 8, and the arrays */
#define MB_STEP_BYTES(NQ, NV, NC, N, NNZ, LDLW, NIN, FRAMES, GA)                                  \
  ((sizeof(mb_stepper) + 7) / 8 * 8 + sizeof(mb_real) * MB_STEP_REALS(NQ, NV, NC, N, NNZ, LDLW, NIN, FRAMES, GA))
/* mb_real elements of the frames workspace of mb_model_outputs for nbody bodies and nmarker markers */
#define MB_STEP_FRAMES(NBODY, NMARKER)                                                              \
  (((NBODY) * sizeof(mb_frame) + (NMARKER) * sizeof(mb_marker) + sizeof(mb_real) - 1) / sizeof(mb_real))

/* defaults: RK4, projection on, 8 projection iterations, tolerance 1e-10
 * (double) or 1e-5 (float), 3 Newton iterations, rho_inf 0.8 */
void mb_step_defaults(mb_step_settings *set);
/* Lay the stepper out in mem (8-byte aligned, 'bytes' long: at least the
 * MB_STEP_BYTES of the model), start from the model's initial state and
 * project it.  MB_ERR_INVALID when the block is too small, the model has no
 * emitted LDL^T or the settings are out of range. */
int mb_step_init(mb_stepper **sp, void *mem, unsigned long bytes, const mb_model *m, int nin,
                 unsigned long frames, const mb_step_settings *set);
/* one step of h from s->t; MB_OK or the status (the state is then that of
 * the failed step: call mb_step_init again to restart) */
int mb_step(mb_stepper *s, mb_real h);
/* the model's output columns at the current state (m->ncols values) */
int mb_step_outputs(mb_stepper *s, mb_real *y);

/* Classic RK4's step, shared by mb_step and the hosted fixed-step RK4
 * (runtime/hosted/integrate.c): from y0 and its derivative k1,
 * y1 = y0 + h (k1 + 2 k2 + 2 k3 + k4) / 6, the weights summed in this order.
 * deriv(ctx, c, y, dy) gives the derivative at t_n + c h (c = 1/2, 1/2, 1);
 * a nonzero return ends the step with it.  ytmp, k, ksum: ny reals of
 * scratch; k1 may be k and y1 may be ytmp. */
typedef int (*mb_rk4_deriv)(void *ctx, mb_real c, const mb_real *y, mb_real *dy);
int mb_rk4_step(int ny, mb_real h, const mb_real *y0, const mb_real *k1, mb_rk4_deriv deriv, void *ctx,
                mb_real *ytmp, mb_real *k, mb_real *ksum, mb_real *y1);

/* Generalized-alpha's step arithmetic, shared by mb_step and the hosted
 * adaptive genalpha (runtime/hosted/genalpha.c). */
/* the constants for a spectral radius rho_inf at infinite step (0..1) */
void mb_ga_method_init(mb_ga_method *g, mb_real rho_inf);
/* from the state (q, v, vd, a) at t_n and the iterate x = [vd1; lambda1] at
 * t_n + h: the algorithmic accelerations a1, the velocity-space increment dq,
 * v1 and q1 = q (+) dq, normalized (the rotations on their Lie group) */
void mb_ga_predict(const mb_model *m, const mb_ga_method *g, mb_real h, const mb_real *q, const mb_real *v,
                   const mb_real *vd, const mb_real *a, const mb_real *x, mb_real *q1, mb_real *v1,
                   mb_real *a1, mb_real *dq);
/* the iteration matrix scaled by 1/beta': K (Kx) with kfac * stiffness +
 * cfac * damping on the modal diagonal and the force elements' tangents at
 * (t, q, v) on their coupling blocks (models compiled for an implicit
 * method); work: mb_model_worksize bytes (the frames) */
void mb_ga_iteration_matrix(const mb_model *m, const mb_real *Kx, mb_real kfac, mb_real cfac, mb_real *Kmod,
                            mb_real t, const mb_real *q, const mb_real *v, void *work);

#endif
