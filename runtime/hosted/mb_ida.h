/* mb_ida.h: a compiled model's equations of motion integrated as a DAE by
 * SUNDIALS IDA (variable-order BDF), the general-purpose DAE solver that
 * `mbcc bench` times the specialized paths against.  Hosted runtime: needs
 * -lsundials_ida -lsundials_nvecserial (SUNDIALS 6.x). */
#ifndef MB_IDA_H
#define MB_IDA_H

#include "mb_sim.h"

/* Simulate from the model's q0, v0 to s->end_time with IDA.
 * Unknowns y = [q; v; lambda] (nq + nv + nc); residual
 *   F = [qdot - G(q) v;  M vdot + D^T lambda - f;  D vdot - gamma]
 * (index 1: the constraints at acceleration level; lambda algebraic).  The
 * linear solver is IDA's dense LU with its difference-quotient Jacobian.
 * Tolerances s->rtol, s->atol on q and v (lambda, algebraic, is left out of
 * the error test: it follows from q and v; vanishing multipliers would carry
 * only the round-off of the large ones and fail any tolerance); steps at
 * most s->max_step (if > 0) and at least s->min_step.  Positions drift from
 * the position and velocity constraints by the integration error: nothing
 * projects them, and Euler parameters are normalized only in what 'out'
 * receives.  'out' (may be NULL) is called at t = 0 and at every output
 * time k * s->output_step <= end_time with the interpolated state and the
 * accelerations and multipliers from K [vdot; lambda] = [f; gamma] solved
 * there.  'stats' (may be NULL) receives steps, rejected (error-test and
 * convergence failures), evals (residual evaluations, the difference-
 * quotient Jacobian's included), solves (Newton iterations), factorizations
 * (linear solver setups), full_factorizations (Jacobian evaluations),
 * t_assembly (time in the model's eval) and t_total.  On failure returns an
 * MB_ERR_* status and stores the time reached in *fail_time (if not NULL).
 * Never prints. */
int mb_ida_simulate(const mb_model *m, const mb_settings *s, mb_output_fn out, void *user,
                    mb_stats *stats, double *fail_time);

/* The same with a choice of IDA's linear solver:
 *   MB_IDA_DENSE: dense LU on a difference-quotient Jacobian (mb_ida_simulate);
 *   MB_IDA_KLU: SuiteSparse KLU (SUNLinSol_KLU, a CSC SUNMatrix) on a sparse
 *     Jacobian dF/dy + cj dF/dy' assembled from the model's analytic pieces:
 *     the emitted K = [M D^T; D 0] (cj M, cj D, D^T), the exact derivatives of
 *     qdot - G(q) v, and the flexible bodies' modal stiffness and damping.  The
 *     q and v derivatives of the other terms (gyroscopic, D(q)^T lambda, force
 *     elements, gamma), which mbcc does not emit, are left out: IDA's Newton
 *     iteration converges with the approximate matrix, and the accuracy is set
 *     by the residual, which is exact.  Needs -lsundials_sunlinsolklu
 *     -lsundials_sunmatrixsparse and KLU. */
enum { MB_IDA_DENSE = 0, MB_IDA_KLU = 1 };
int mb_ida_run(const mb_model *m, const mb_settings *s, int linsol, mb_output_fn out, void *user,
               mb_stats *stats, double *fail_time);

/* For tests (allocate per call): the residual F(t, y, yp) into r (nq + n), and
 * MB_IDA_KLU's Jacobian at (t, y) for cj as a dense column-major N x N matrix
 * (N = nq + n) with the number of entries of its sparse pattern in *nnz. */
int mb_ida_residual(const mb_model *m, double t, const double *y, const double *yp, double *r);
int mb_ida_jacobian_dense(const mb_model *m, double t, const double *y, double cj, double *J,
                          int *nnz);

/* entries of MB_IDA_KLU's sparse Jacobian pattern (0: out of memory) */
int mb_ida_klu_nnz(const mb_model *m);

/* the DAE's dimension nq + nv + nc */
int mb_ida_size(const mb_model *m);

#endif
