/* mb_sim.h: time integration of a compiled model: explicit RK4 (fixed step)
 * and Dormand-Prince 5(4) (adaptive), with coordinate projection or
 * Baumgarte stabilization.  Hosted runtime: workspaces are allocated once in
 * mb_sim_init, nothing per step. */
#ifndef MB_SIM_H
#define MB_SIM_H

#include "mb_solver.h"

enum { MB_RK4 = 0, MB_DOPRI5 = 1 };
enum { MB_STAB_PROJECTION = 0, MB_STAB_BAUMGARTE = 1, MB_STAB_NONE = 2 };

typedef struct {
  int integrator;
  double end_time, output_step;
  double step;                /* RK4 step; DOPRI5 first step */
  double rtol, atol, min_step, max_step;
  int stabilization;
  double alpha, beta;         /* Baumgarte */
  double projection_tol;      /* max |phi| after projection */
} mb_settings;

typedef struct {
  long steps, rejected, evals, solves, projections;
  long factorizations, full_factorizations;
  double t_assembly, t_solve, t_total; /* seconds */
  double max_phi, max_phid;            /* largest constraint violations seen at outputs */
} mb_stats;

/* called at t = 0 and every output step; return nonzero to stop */
typedef int (*mb_output_fn)(void *user, double t, const double *q, const double *v,
                            const double *vd, const double *lambda);

typedef struct {
  const mb_model *m;
  mb_solver *ls;
  mb_settings set;
  mb_stats stats;
  double t;                 /* current time */
  double *q, *v;            /* current state (nq, nv) */
  double fail_time;         /* time of a failure */
  char fail_detail[160];    /* what failed */
  /* workspaces */
  double *Kx, *rhs, *x, *phi, *nu, *y, *ytmp, *k[7], *qsave, *dv; /* nu: phid = D v - nu */
  void *work;
  int factored_valid;       /* Kx factorization matches qsave */
} mb_sim;

void mb_settings_default(mb_settings *s);
int mb_sim_init(mb_sim *s, const mb_model *m, mb_solver *ls, const mb_settings *set);
/* integrate from the model's initial state to end_time */
int mb_sim_run(mb_sim *s, mb_output_fn out, void *user);
/* accelerations and multipliers at (t, q, v) into vd (nv) and lambda (nc) */
int mb_sim_accel(mb_sim *s, double t, const double *q, const double *v, double *vd,
                 double *lambda);
/* project (q, v) onto the position and velocity constraints */
int mb_sim_project(mb_sim *s, double t, double *q, double *v);
void mb_sim_free(mb_sim *s);

#endif
