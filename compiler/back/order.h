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
 * unless said otherwise ("original" = the unknowns of K).
 *  - block pivots: a virtual body welded to a massive body (inserted for a
 *    joint on a flexible node) is eliminated together with its 6 weld rows
 *    before all of this (see nelim below): no weights, no fill beyond the
 *    joint rows it carries moving onto the node's columns. */
#ifndef MBCC_ORDER_H
#define MBCC_ORDER_H

#include <stdio.h>

#include "lower.h"

/* The host's choice of form is a compile-time limit derived from measured
 * costs (docs/architecture.md, "The emitted LDL^T: its two forms, measured"):
 * straight-line code runs LDL_NS_PER_FLOP_STRAIGHT per flop of factor + solve
 * against the looped form's LDL_NS_PER_FLOP_LOOPED, and costs
 * LDL_GCC_SECONDS_PER_FLOP of gcc -O2 CPU per such flop (the looped form's
 * compile time is small and does not grow with the flops).  Both the gain
 * per call and the compile time grow with the flops, so the calls after
 * which straight-line code has paid for its build do not depend on the
 * model's size (ldl_payback_calls); what limits it is the build's time:
 * straight-line while its estimated gcc CPU stays under LDL_STRAIGHT_SECONDS
 * (its files compile in parallel with the evaluation's; the limit keeps the
 * cars' builds near the 10 s aim on 2 cores). */
#define LDL_GCC_SECONDS_PER_FLOP 2.6e-4
#define LDL_NS_PER_FLOP_STRAIGHT 0.27
#define LDL_NS_PER_FLOP_LOOPED 0.38
#define LDL_STRAIGHT_SECONDS 12.0
/* the embedded target's flop budget (per factorization): straight-line
 * LDL^T costs about 10 bytes of Cortex-M4F flash per flop (the flexible
 * slider-crank's 2118 + 923 flops: 31.6 KB more than its loops), so above
 * 2000 flops per factorization the loops keep a package near a 64 KiB flash */
#define LDL_FLOP_BUDGET_EMBEDDED 2000.0
/* a flop budget per factorization for the plans built from now on, instead
 * of the host's compile-time rule (the environment variable MBCC_LDL_BUDGET
 * overrides both: 0 always loops, 1e12 always straight-line) */
void ldl_set_default_budget(double flops);
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

  /* block pivots (original numbering): each virtual body welded to a massive
   * body is eliminated with the 6 rows of its weld before the LDL^T, as one
   * 12 x 12 pivot [0 Du^T; Du 0] (Du: the weld rows on its own 6 columns).
   * With Eu the other rows S on its columns and Dx the weld rows on the
   * columns X of the body it is welded to, what remains is K' (same size as
   * K; the eliminated unknowns decoupled with diagonal 1 / -1):
   *   K'(s, x) = K(s, x) - (Eu Du^-1 Dx)(s, x),  right side
   *   g'_s = g_s - Eu Du^-1 g_r,  f'_x = f_x - Dx^T Du^-T f_u,
   * then a_u = Du^-1 (g_r - Dx a_x), lambda_r = Du^-T (f_u - Eu^T lambda_s).
   * Everything below (weights, K_aug, ordering, L) is of K', whose values
   * Kr (nnzR, in the CSC order Krp/Kri) are gathered from Kx by Krmap
   * (>= 0: a Kx slot, -1: 0, -2: 1, -3: -1) and then corrected. */
  /* massless bodies (stage 1, before the block pivots): a virtual body that is
   * not welded, with r >= 6 rows R on its 6 columns U (D_RU of rank 6, e.g. a
   * massless slider: prismatic + spherical), is eliminated with 6 of those
   * rows chosen at run time by partial pivoting (P, Du = D_PU); the other
   * r - 6 (S, W = D_SU Du^-1) become the new rows
   *   D1(s, y) = D(s, y) - (W D_PY)(s, y)   for the columns Y of R outside U,
   * stored in the compile-time slots T (r - 6 rows of R): a null-space
   * elimination D1 = N^T D_RY with N^T D_RU = 0, whose pattern (T x Y) does
   * not depend on the choice.  U and R \ T are decoupled (diagonals 1, -1).
   * Right side: g1_t = g_s - W g_p, f1_y = f_y - D_PY^T Du^-T f_u; back:
   * a_u = Du^-1 (g_p - D_PY a_y), lambda_s = mu_t, lambda_p = Du^-T (f_u - D_SU^T mu).
   * What follows (block pivots, weights, ordering, L) is of K1 (pattern
   * K1p/K1i, values gathered by K1map: >= 0 a Kx slot, -1: 0, -2: 1, -3: -1,
   * -4: computed). */
  int nml;           /* massless bodies eliminated */
  int *mlb;          /* nml: the body */
  int (*mlu)[6];     /* its 6 velocity columns */
  int *mlrp, *mlR;   /* rows R (K indices) of body b: mlR[mlrp[b]..mlrp[b+1]) */
  int *mlT;          /* slots: r - 6 per body, at mlrp[b] - 6 b */
  int *mlpi0;        /* the order partial pivoting finds at t = 0 (positions in R,
                        r per body at mlrp[b]): the straight-line code's rows */
  int *mlyp, *mlY;   /* columns Y: mlY[mlyp[b]..mlyp[b+1]) */
  int *mldu;         /* Kx slots of D_RU: 6 per row of R (-1: zero) */
  int *mldy;         /* Kx slots of D_RY: ny per row of R, at mldyp[b] */
  int *mldyp;
  int *mlk;          /* K1 positions of (t, y) and (y, t): 2 per pair, at mlkp[b] */
  int *mlkp;
  int nnz1;
  int *K1p, *K1i, *K1map;
  double flops_ml, flops_ml_solve;

  int nelim;         /* eliminated (welded virtual) bodies */
  int *eb;           /* nelim: the body */
  int (*eu)[6];      /* its 6 velocity columns */
  int (*er)[6];      /* its 6 weld rows (K indices nv + r) */
  int *exp_, *ex;    /* X: columns ex[exp_[e]..exp_[e+1]) */
  int *esp, *es;     /* S: K indices of the other rows on its columns */
  int (*edu)[36];    /* Kx slots of Du (row-major, -1: structurally zero) */
  int *edx;          /* Kx slots of Dx: 6 per column of X, at 6 exp_[e] */
  int *eeu;          /* Kx slots of Eu: 6 per row of S, at 6 esp[e] */
  int *ekr;          /* Kr positions of K'(s, x) and K'(x, s): 2 per pair, at 2 (sum ns nx);
                        -1 where the correction is structurally zero */
  int *ekrp;         /* nelim + 1: start of body e in ekr (pairs) */
  int nnzR;
  int *Krp, *Kri, *Krmap;
  double flops_block, flops_block_solve; /* the block pivots' flops, dense 6 x 6 (a bound; not in flops) */

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
  int straight;      /* 1: straight-line code, 0: loops over tables */
  double budget;     /* the flop budget per factorization that chose, or < 0: the host's rule */
  double cc_seconds; /* straight-line code's estimated gcc -O2 CPU (the host's rule): of the
                        flops of factor and solve, block pivots and massless bodies */
} ldl_plan;

/* Build the plan of the lowered, assembled model.  Returns 0, or -1 (out of
 * memory or CAMD failure; *p is then freed). */
int ldl_plan_build(const lmodel *L, ldl_plan *p);
void ldl_plan_free(ldl_plan *p);
/* the factor + solve calls after which straight-line code's extra build
 * time (CPU on 'jobs' cores) is won back by its faster calls */
double ldl_payback_calls(const ldl_plan *p, int jobs);

/* the diagonal blocks of a 6 x 6 matrix of structure nz[36] (1: can be nonzero):
 * comp[i] the block of row and column i; returns the number of blocks.  Its
 * inverse can be nonzero only inside them (see order.c) */
int ldl_inv_blocks(const int *nz, int comp[6]);
/* W(s, i) = (Eu Du^-1)(s, i) can be nonzero (eu: row s's slots in the body's
 * columns, -1 none; dinz[36]: the structure of Du^-1) */
int ldl_w_nonzero(const int *eu, const int *dinz, int i);
/* dinz[36]: the structure of block pivot e's D_u^-1 (its D_u's diagonal blocks) */
void ldl_block_dinz(const ldl_plan *p, int e, int dinz[36]);

/* `mbcc check`: the ordering, nnz(L), the flop count and the code form of
 * the plan (NULL: the ordering failed) */
void ldl_plan_report(const ldl_plan *p, FILE *out);

/* "body 'crank' w_z" / "constraint row 3: joint 'pin' (revolute): ..." */
void ldl_unknown_name(const lmodel *L, int u, char *buf, size_t n);

#endif
