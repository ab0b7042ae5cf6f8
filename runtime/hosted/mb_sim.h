/* mb_sim.h: time integration of a compiled model: explicit RK4 (fixed step),
 * Dormand-Prince 5(4) (adaptive) and the implicit generalized-alpha method
 * (adaptive, for stiff modal content; genalpha.c), with coordinate projection
 * or Baumgarte stabilization.  Hosted runtime: workspaces are allocated once in
 * mb_sim_init, nothing per step. */
#ifndef MB_SIM_H
#define MB_SIM_H

#include "mb_solver.h"

/* MB_AUTO is resolved by mb_sim_init (mb_integrator_auto) */
enum { MB_RK4 = 0, MB_DOPRI5 = 1, MB_GENALPHA = 2, MB_AUTO = 3 };
enum { MB_STAB_PROJECTION = 0, MB_STAB_BAUMGARTE = 1, MB_STAB_NONE = 2 };

typedef struct {
  int integrator;
  double end_time, output_step;
  double step;                /* RK4 step; DOPRI5 first step */
  double rtol, atol, min_step, max_step;
  int stabilization;
  double alpha, beta;         /* Baumgarte */
  double projection_tol;      /* max |phi| after projection */
  double rho_inf;             /* generalized-alpha: spectral radius at infinite step, 0..1 */
  double max_steps;           /* stop with MB_ERR_STEP_BUDGET beyond this many steps */
  int equilibrium;            /* 1: move the positions to static equilibrium before the run
                                 (mb_sim_equilibrium, equilibrium.c) */
  int timers;                 /* 1: clock each evaluation and factor/solve (the breakdown
                                 mbcc run prints); 0: only the whole run (mbcc bench) */
} mb_settings;

typedef struct {
  long steps, rejected, evals, solves, projections;
  long factorizations, full_factorizations;
  long newton_iterations, newton_failures; /* generalized-alpha */
  double t_assembly, t_solve, t_total; /* seconds (assembly, solve: 0 without timers) */
  double t_setup;                      /* IDA: seconds of t_total before its first step */
  double max_phi, max_phid;            /* largest constraint violations seen at outputs */
  double rcond_first, rcond_min, rcond_min_t; /* KLU's condition estimate of K: first, smallest, when */
} mb_stats;

/* called at t = 0 and every output step; return nonzero to stop */
typedef int (*mb_output_fn)(void *user, double t, const mb_real *q, const mb_real *v,
                            const mb_real *vd, const mb_real *lambda);

typedef struct {
  const mb_model *m;
  mb_solver *ls;
  mb_settings set;
  mb_stats stats;
  double t;                 /* current time */
  mb_real *q, *v;            /* current state (nq, nv) */
  double fail_time;         /* time of a failure */
  char fail_detail[160];    /* what failed */
  /* the state a failed factorization, solve or projection was at (fail_state:
     1 when recorded in the current step), for the diagnosis of its cause */
  int fail_state;
  double fail_state_t;
  mb_real *fail_q, *fail_v;
  /* workspaces */
  mb_real *Kx, *rhs, *x, *phi, *nu, *y, *ytmp, *k[7], *qsave, *dv; /* nu: phid = D v - nu */
  void *work;
  int factored_valid;       /* Kx factorization matches qsave */
  /* called after every accepted step (e.g. to unwrap angles); set after mb_sim_init */
  void (*on_step)(void *user, double t, const mb_real *q, const mb_real *v);
  void *on_step_user;
  double angle_hmax;        /* largest next step that keeps angle outputs unwrappable */
  mb_real *yout;            /* Dormand-Prince: the state at an output time inside a step */
} mb_sim;

void mb_settings_default(mb_settings *s);
int mb_sim_init(mb_sim *s, const mb_model *m, mb_solver *ls, const mb_settings *set);
/* integrate from the model's initial state to end_time */
int mb_sim_run(mb_sim *s, mb_output_fn out, void *user);
/* accelerations and multipliers at (t, q, v) into vd (nv) and lambda (nc) */
int mb_sim_accel(mb_sim *s, double t, const mb_real *q, const mb_real *v, mb_real *vd,
                 mb_real *lambda);
/* project (q, v) onto the position and velocity constraints */
int mb_sim_project(mb_sim *s, double t, mb_real *q, mb_real *v);
/* After set_params moved joint points or body positions (m->param_geometry):
 * the assembly at start (reassemble.c), q (nq) from the state as given
 * (m->q_given) onto the position constraints, v (nv) from m->v_given onto the velocity constraints, with the
 * compiled rows still independent and the compiled redundant rows still
 * redundant.  0, or 1 with the cause in why. */
int mb_reassemble(const mb_model *m, mb_real *q, mb_real *v, char *why, size_t nwhy);
void mb_sim_free(mb_sim *s);

/* Static equilibrium (equilibrium.c): what mb_sim_equilibrium found */
typedef struct {
  int iterations;             /* Newton iterations */
  double force_scale;         /* N: the weight, or the largest applied force if larger */
  double force_residual;      /* max |f - D^T lambda| at v = 0, relative to force_scale */
  double constraint_residual; /* max |phi| */
  int free_directions;        /* unknowns the last tangent left free (no stiffness, no load) */
  double smallest_damping;    /* the shortest line-search step taken (1: full Newton steps) */
  int damped_steps;           /* pseudo-transient steps past a turning point, where the tangent
                                 was singular along a loaded direction (a pendulum released
                                 horizontally) */
  char why[512];              /* the cause of a failure */
} mb_equilibrium_info;
/* Move s->q (from mb_sim_init: the model's initial state) to static
 * equilibrium at t = 0: forces at zero velocity balanced by the constraint
 * reactions, constraints satisfied, drivers at their t = 0 values.  The
 * velocities s->v are kept, projected onto the velocity constraints.  MB_OK,
 * or the status with info->why (MB_ERR_SINGULAR: a free direction under load;
 * MB_ERR_NEWTON: no convergence). */
int mb_sim_equilibrium(mb_sim *s, mb_equilibrium_info *info);

/* The integrator 'auto' picks for this model and these settings, and why
 * (a sentence into why[0..nwhy)); never MB_AUTO. */
int mb_integrator_auto(const mb_model *m, const mb_settings *set, char *why, size_t nwhy);
const char *mb_integrator_name(int integrator);

/* for the integrators (integrate.c, genalpha.c) */
int mb_sim_fail(mb_sim *s, double t, int status, const char *what);
/* mb_sim_fail at the state (q, v) the failure happened at, kept in fail_q, fail_v */
int mb_sim_fail_at(mb_sim *s, double t, const mb_real *q, const mb_real *v, int status, const char *what);
double mb_sim_clock(void); /* monotonic seconds */
int mb_sim_finish_step(mb_sim *s, double t);
/* MB_ERR_STEP_BUDGET (with the detail) once steps + rejections reach max_steps */
int mb_sim_step_budget(mb_sim *s, double h);
int mb_genalpha_run(mb_sim *s, mb_output_fn out, void *user);

/* The energy watchdog of the implicit method (genalpha.c; docs/formulation.md
 * §15, "Watchdog").  The total energy E = T + V (mb_model_energy) of a correct
 * solution rises by no more than the work W_in its driving elements do: the
 * driven constraints (power lambda . D v) and the elements whose work is not
 * a potential (point forces and torques, tyres, fields with a non-symmetric
 * stiffness), integrated as |power| by the trapezoidal rule.  After every
 * accepted step, E - E_0 - W_in above E_ref + W_in + 1e-6 (|T| + |V|),
 * with the model's energy scale E_ref = |T_0| + |V_0| + (total mass) |g| L
 * (L: the model's reach from the origin at t = 0, over its bodies and
 * markers), stops the run with MB_ERR_ENERGY, the time and the cause: a
 * blow-up, never a run's accuracy.  mb_watchdog_start at t = 0
 * (MB_ERR_NOMEM), mb_watchdog_check after each accepted step with the state
 * in s->t, s->q, s->v, K from the step's last evaluation in s->Kx and the
 * step's multipliers, mb_watchdog_free at the end. */
typedef struct {
  mb_model src;          /* the model with only its work-doing elements */
  mb_model none;         /* the model without force elements */
  mb_forcedef *src_force;
  mb_real *Kx, *r_src, *r_none, *phi, *phid;
  void *work;
  double e0, e_ref, w_in, p_prev, t_prev, rise;
} mb_watchdog;
int mb_watchdog_start(mb_watchdog *w, mb_sim *s);
int mb_watchdog_check(mb_watchdog *w, mb_sim *s, const mb_real *lambda);
void mb_watchdog_free(mb_watchdog *w);

#endif
