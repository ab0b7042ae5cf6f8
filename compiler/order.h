/* order.h: compile-time analysis for the emitted LDL^T (solver "ldl"):
 *  - zero-mass handling: the constraint rows that touch a massless velocity
 *    unknown (a column of the M block that is zero at t = 0: virtual bodies,
 *    a massless slider) get a weight w_r, and the matrix factorized is
 *      K_aug = [M + D^T W D, D^T; D, 0]   (right side [f + D^T W g; g]),
 *    which has the solution of K x = b and positive pivots in the body block;
 *  - fill-reducing ordering of K_aug with SuiteSparse CAMD, all body unknowns
 *    (0..nv-1) constrained before all constraint rows (nv..n-1): then the body
 *    block is symmetric positive definite and the Schur complement
 *    -D (M + D^T W D)^-1 D^T negative definite, so a static pivot order works.
 *    A second candidate uses constraint sets from the mechanism's spanning
 *    tree (each body before the rows joining it to its parent, loop rows
 *    last; order.c proves it as safe); the one with fewer flops is kept
 *    (MBCC_LDL_ORDER=bodies-first or tree forces one);
 *  - elimination tree, column counts, the pattern of L (strictly lower, CSC,
 *    rows sorted), nnz(L) and the flop count of the numeric factorization.
 * Everything here is in the numbering of the permuted matrix P K_aug P^T
 * unless said otherwise ("original" = the unknowns of K). */
#ifndef MBCC_ORDER_H
#define MBCC_ORDER_H

#include <stdio.h>

#include "lower.h"

/* default flop budget for straight-line code (above it: loops over tables);
 * the environment variable MBCC_LDL_BUDGET overrides it */
#define LDL_FLOP_BUDGET 10000.0

typedef struct {
  int n, nv, nc;
  /* ordering: perm[k] = original unknown of pivot k; iperm its inverse */
  int *perm, *iperm;

  /* zero-mass handling (original numbering) */
  int nmassless;     /* velocity unknowns with a zero M column at t = 0 */
  int nw;            /* weighted constraint rows */
  int *wrow;         /* nw: their constraint index (K row nv + wrow[k]) */
  double *w;         /* nw: weights */
  int *Dp, *Dj, *Ds; /* weighted row k: velocity columns Dj[Dp[k]..Dp[k+1]) and the Kx slot
                        of each D entry (row nv + wrow[k], column Dj) */

  /* K_aug in the permuted numbering, upper triangle with the diagonal, CSC
   * with rows sorted: column k holds Ui[Up[k]..Up[k+1]) (last one may be k).
   * Value of entry e: Kx[Us[e]] (if Us[e] >= 0) plus the products
   * e's terms Tp[e]..Tp[e+1]-1: w[Tw[t]] * Kx[Ta[t]] * Kx[Tb[t]]. */
  int *Up, *Ui, *Us;
  int *Tp, *Tw, *Ta, *Tb;
  int nnzA;          /* entries of the upper triangle incl. diagonal */

  /* symbolic factorization of P K_aug P^T = L D L^T */
  int *parent;       /* elimination tree, -1 at roots */
  int *Lp, *Li;      /* strictly lower L, CSC, rows sorted; Lp[k+1]-Lp[k] = column count */
  int *Rp, *Rj, *Rpos; /* the same entries by rows: row k holds columns Rj[Rp[k]..Rp[k+1])
                          (ascending), the entry of L(k, Rj) at Li/Lx position Rpos */
  long nnzL;
  double flops;      /* numeric factorization (multiply-add = 2), see order.c */
  double flops_solve; /* one forward/diagonal/backward solve */
  int tree;          /* ordering: 1 spanning-tree constraint sets, 0 bodies first */
  int nsets;         /* CAMD constraint sets used */
  int straight;      /* 1: flops <= budget (straight-line code), 0: loops */
  double budget;
} ldl_plan;

/* Build the plan of the lowered, assembled model.  Returns 0, or -1 (out of
 * memory or CAMD failure; *p is then freed). */
int ldl_plan_build(const lmodel *L, ldl_plan *p);
void ldl_plan_free(ldl_plan *p);

/* `mbcc check`: the ordering, nnz(L), the flop count and the code form */
void ldl_plan_report(const lmodel *L, FILE *out);

/* "body 'crank' w_z" / "constraint row 3: joint 'pin' (revolute): ..." */
void ldl_unknown_name(const lmodel *L, int u, char *buf, size_t n);

#endif
