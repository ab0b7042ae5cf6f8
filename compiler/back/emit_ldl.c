/* emit_ldl.c: writes the emitted LDL^T of K (solver "ldl") into the
 * generated <model>.c: the pattern, the ordering and every index fixed at
 * compile time (order.c), no library, no allocation.
 *
 *   int <m>_ldl_factor(const mb_real *Kx, mb_real *work)
 *     forms K_aug = [M + D^T W D, D^T; D, 0] from Kx in the CAMD order and
 *     factorizes it up-looking into L D L^T; returns 0, or 1 + the original
 *     unknown whose pivot is zero, tiny (|d| <= 1e-14 of the magnitudes that
 *     formed it) or not finite.
 *   int <m>_ldl_solve(const mb_real *Kx, mb_real *work, mb_real *b, mb_real *res)
 *     solves K x = b in place: x from the factors of K_aug with right side
 *     [b_top + D^T W b_bot; b_bot], then iterative refinement on the exact
 *     system (r = b - K x with the original Kx, correction from the same
 *     factors): none when the relative residual ||r||_inf / (||K||_inf
 *     ||x||_inf + ||b||_inf) of the first solution is already at roundoff
 *     level (<= LDL_REFINE_TOL = 1e-15), else one step, a second when it is
 *     still above 1e-12; res[0] gets that relative residual, res[1] the one
 *     of the first solution (before any refinement).  With res NULL
 *     and no weighted rows (<M>_LDL_EXACT: K_aug = K, so the first solution
 *     is already the direct one) the solve is that single pass, without
 *     residual or refinement, as a library LDL^T would do it; with weighted
 *     rows it still refines.  Returns MB_OK or MB_ERR_NONFINITE.
 *
 * Below the flop budget (order.h: the host's compile-time limit, the embedded
 * target's flash budget) every operation is emitted
 * with constant indices (straight-line, the factorization split into
 * out-of-line parts of about LDL_CHUNK_FLOPS); above it the same operations
 * run as loops over static const index arrays, so that the C compiler's time
 * stays bounded (gcc 12 -O2 needs about 0.26 ms per straight-line flop).
 * Written into files of their own (ldl_out), the straight-line parts of a
 * large model compile in parallel.
 *
 * The workspace (<M>_LDL_WORK mb_real) holds Lx (nnz(L)), 1/d (n), then x,
 * r, t and the best x of the refinement (n each). */
#include <ctype.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "emit_ldl.h"
#include "emit_split.h"
#include "emit_util.h"
#include "order.h"

/* A table of the looped form that only the emitted code indexes: short when
 * every entry fits (half the flash of int; the sizes of an embedded model's
 * K are far below 32767), else int. */
static void idx_array(FILE *f, const char *name, const int *x, long n) {
  int fits = 1;
  for (long i = 0; i < n; i++) fits &= x[i] >= -32767 && x[i] <= 32767;
  fprintf(f, "static const %s %s[%ld] = {", fits ? "short" : "int", name, n > 0 ? n : 1);
  if (n <= 0) fputs("0", f);
  for (long i = 0; i < n; i++) fprintf(f, "%s%d", i % 16 ? ", " : (i ? ",\n  " : "\n  "), x[i]);
  fprintf(f, "\n};\n");
}

/* the comment above ldl_block_rhs (both forms) */
#define BLOCK_RHS_COMMENT                                                                      \
  "/* the right side of K' from r, in place: g'_s = g_s - W g_r, f'_x = f_x - Dx^T Du^-T f_u.\n" \
  " * Rows S and columns X change; the weld rows and the body's columns, which\n"                 \
  " * ldl_block_back reads, do not.  Their unknowns are decoupled in K' (unit\n"                 \
  " * diagonal): the solve gives them a value that ldl_block_back overwrites */\n"

/* the block pivots' workspace: Du^-1 (36, then 6 unused), W = Eu Du^-1 (6 per S row) */
static long block_work(const ldl_plan *p, int e) { return 42L + 6L * (p->esp[e + 1] - p->esp[e]); }

/* the massless bodies' workspace: pi (r), Du^-1 (36), W = D_SU Du^-1 (6 per slot) */
static long ml_work(const ldl_plan *p, int e) {
  long r = p->mlrp[e + 1] - p->mlrp[e];
  return r + 36 + 6 * (r - 6) + 1; /* pi, Du^-1, W, which rows (1: the compile-time ones) */
}

/* largest r and r x ny over the massless bodies (their scratch) */
static void ml_max(const ldl_plan *p, int *rmax, long *dmax) {
  *rmax = 6;
  *dmax = 1;
  for (int e = 0; e < p->nml; e++) {
    int r = p->mlrp[e + 1] - p->mlrp[e];
    long d = (long)r * (p->mlyp[e + 1] - p->mlyp[e]);
    if (r > *rmax) *rmax = r;
    if (d > *dmax) *dmax = d;
  }
}

/* offset of the block pivots' workspace: after Lx, 1/d, x, r, t, best x, K', d
 * (K' only with block pivots: LDL_DD follows LDL_KR directly without them) */
static long block_base(const ldl_plan *p) { return p->nnzL + 5L * p->n + (p->nelim ? p->nnzR : 0) + p->n; }

/* offset of the massless bodies' part of the workspace: K1, r1, D scratch, blocks */
static long ml_base(const ldl_plan *p) {
  long w = p->nnzL + 5L * p->n;
  if (p->nelim || p->nml) w = block_base(p);
  for (int e = 0; e < p->nelim; e++) w += block_work(p, e);
  return w;
}

typedef struct ldl_tail ldl_tail;
static int tail_plan(const ldl_plan *p, long base, ldl_tail *t);
static long work_size_tail(const ldl_plan *p, long base);
static int tail_rows(const ldl_plan *p, long base);

/* the workspace before the dense tail's blocks */
static long work_size_base(const ldl_plan *p) {
  long w = ml_base(p);
  if (p->nml) {
    int rmax;
    long dmax;
    ml_max(p, &rmax, &dmax);
    w += p->nnz1 + p->n + dmax;
    for (int e = 0; e < p->nml; e++) w += ml_work(p, e);
  }
  return w;
}

static long work_size(const ldl_plan *p) {
  long w = work_size_base(p);
  return w + work_size_tail(p, w);
}

void emit_ldl_header(emit_ctx *cx) {
  FILE *f = cx->f;
  const char *nm = cx->nm, *U = cx->NM;
  if (!cx->u->have_plan) return;
  const ldl_plan *p = &cx->u->plan;
  fprintf(f, "/* emitted LDL^T of K (solver \"ldl\"), see %s.c */\n", nm);
  fprintf(f, "#define %s_LDL_NNZL %ld      /* nonzeros of L (strictly lower) */\n", U, p->nnzL);
  fprintf(f, "#define %s_LDL_FLOPS %.0f.0  /* flops of one numeric factorization */\n", U, p->flops);
  fprintf(f, "#define %s_LDL_STRAIGHT %d   /* 1: straight-line code, 0: loops over tables */\n", U,
          p->straight);
  fprintf(f, "#define %s_LDL_WORK %ld      /* mb_real elements of the workspace */\n", U, work_size(p));
  fprintf(f, "#define %s_LDL_EXACT %d      /* 1: the factors are those of K (no weighted rows) */\n", U,
          p->nw == 0);
  int tail_nt = tail_rows(p, work_size_base(p));
  if (tail_nt) fprintf(f, "#define %s_LDL_TAIL %d       /* the last rows of L, formed as a dense block */\n", U, tail_nt);
  fprintf(f, "int %s_ldl_factor(const mb_real *Kx, mb_real *work);\n", nm);
  fprintf(f, "int %s_ldl_solve(const mb_real *Kx, mb_real *work, mb_real *b, mb_real *residual);\n", nm);
}

void emit_ldl_fields(emit_ctx *cx, int emitted) {
  if (!emitted) return;
  const char *U = cx->NM;
  fprintf(cx->f, "  .ldl_factor = ldl_factor_m, .ldl_solve = ldl_solve_m, .ldl_worksize = %s_LDL_WORK,\n"
             "  .ldl_nnzL = %s_LDL_NNZL, .ldl_flops = %s_LDL_FLOPS, .ldl_straight = %s_LDL_STRAIGHT,\n"
             "  .ldl_exact = %s_LDL_EXACT,\n",
          U, U, U, U, U);
}

/* ---------------------------------------------------------------- helpers */


static int kconst(const emit_ctx *cx, int q, double *v);

/* a compile-time constant of K or of the factorization: sym's literal */
static void klit(FILE *f, double c) {
  char b[40];
  sym_literal(b, sizeof b, c);
  fputs(b, f);
}

/* 1 if the slot of the block pivots' space (k1) or of Kx holds a compile-time
 * constant (K1's constants, init's entries of Kx), its value in *v */
static int slot_const(const emit_ctx *cx, int slot, int k1, double *v) {
  if (k1 && cx->ldl.k1_map) {
    int s = cx->ldl.k1_map[slot];
    if (s == -4) return 0;
    if (s < 0) {
      *v = s == -2 ? 1 : s == -3 ? -1 : 0;
      return 1;
    }
    slot = s;
  }
  if (!cx->ldl.kx_cst || !cx->ldl.kx_cst[slot]) return 0;
  *v = cx->ldl.kx_cst[slot];
  return 1;
}

/* where the straight-line code reads slot q, into buf: of Kx (k1 = 0), or of
 * the block pivots' space (k1 = 1: K1 with massless bodies, else Kx) */
static void kname_buf(const emit_ctx *cx, char *buf, size_t n, int q, int k1) {
  int s = k1 && cx->ldl.k1_direct && cx->ldl.k1_map ? cx->ldl.k1_map[q] : q;
  if (!k1 || !cx->ldl.k1_direct || !cx->ldl.k1_map || s >= 0) snprintf(buf, n, "Kx[%d]", s);
  else if (s == -4) snprintf(buf, n, "K1[%d]", q);
  else snprintf(buf, n, "%s", s == -2 ? "1" : s == -3 ? "-1" : "0");
}

static void kname(emit_ctx *cx, int q) {
  FILE *f = cx->f;
  char b[32];
  kname_buf(cx, b, sizeof b, q, 1);
  fputs(b, f);
}

/* into buf: kname_buf's name of the slot (space k1), or its value when it is
 * a compile-time constant */
static void kput_buf(const emit_ctx *cx, char *buf, size_t n, int slot, int k1) {
  double c;
  if (slot_const(cx, slot, k1, &c)) sym_literal(buf, n, c);
  else kname_buf(cx, buf, n, slot, k1);
}

/* kput_buf of the slot in the space kput_k1, written to f */
static void kput(emit_ctx *cx, int slot) {
  FILE *f = cx->f;
  char b[32];
  kput_buf(cx, b, sizeof b, slot, cx->ldl.kput_k1);
  fputs(b, f);
}

/* one term "coef * v" of a sum: coef a C expression, or (known) the constant
 * c, a factor 1 then dropped and a zero term left out; 'any': a term came
 * before (then " + " or " - ").  The same products in the same order: a
 * product with +-1 is exact, so the numbers do not change. */
static void put_term(emit_ctx *cx, int *any, int known, double c, const char *coef, const char *v) {
  FILE *f = cx->f;
  if (known) {
    if (c == 0) return;
    fputs(*any ? (c < 0 ? " - " : " + ") : (c < 0 ? "-" : ""), f);
    if (fabs(c) != 1) {
      klit(f, fabs(c));
      fputs(" * ", f);
    }
    fputs(v, f);
  } else {
    fprintf(f, "%s%s * %s", *any ? " + " : "", coef, v);
  }
  *any = 1;
}

/* put_term with the slot's entry (space kput_k1) as the coefficient */
static void put_kterm(emit_ctx *cx, int *any, int slot, const char *v) {
  double c;
  char coef[32];
  int known = slot_const(cx, slot, cx->ldl.kput_k1, &c);
  kname_buf(cx, coef, sizeof coef, slot, cx->ldl.kput_k1);
  put_term(cx, any, known, c, coef, v);
}

static void kval(emit_ctx *cx, int q) {
  FILE *f = cx->f;
  double c;
  if (kconst(cx, q, &c)) klit(f, c);
  else if (!cx->ldl.kc_of) kname(cx, q);
  else if (cx->ldl.kc_of[q] >= 0) fprintf(f, "Kc[%d]", cx->ldl.kc_of[q]);
  else if (cx->ldl.kc_map[q] >= 0) kname(cx, cx->ldl.kc_map[q]);
  else fputs(cx->ldl.kc_map[q] == -2 ? "1" : cx->ldl.kc_map[q] == -3 ? "-1" : "0", f); /* a constant of K' */
}

/* 1 if kval(q) writes a constant of K' (the decoupled diagonals of the block
 * pivots' unknowns and rows), its value in *v */
static int kconst(const emit_ctx *cx, int q, double *v) {
  int src = q;
  if (cx->ldl.kc_of) {
    if (cx->ldl.kc_of[q] >= 0) {
      return cx->ldl.kc_sym && sym_is_const(&cx->ldl.sym, cx->ldl.kc_sym[cx->ldl.kc_of[q]], v);
    }
    src = cx->ldl.kc_map[q];
    if (src < 0) {
      *v = src == -2 ? 1 : src == -3 ? -1 : 0;
      return 1;
    }
  }
  return slot_const(cx, src, 1, v);
}

/* pivot k of K_aug is a decoupled unknown whose value the block pivots or the
 * massless bodies recover (ldl_block_back, ldl_ml_back overwrite it): empty
 * row and column of L, a constant diagonal +-1.  The solve leaves it out. */
/* pivot k's value when it is a compile-time constant +-1: an empty row of L
 * and a constant diagonal of K_aug (no weighted terms); else 0 */
static int ldl_const_pivot(const emit_ctx *cx, const ldl_plan *p, int k) {
  if (p->Rp[k + 1] != p->Rp[k]) return 0;
  int diag = -1;
  for (int e = p->Up[k]; e < p->Up[k + 1]; e++)
    if (p->Ui[e] == k) diag = e;
  double c;
  if (diag < 0 || p->Us[diag] < 0 || p->Tp[diag] != p->Tp[diag + 1] || !kconst(cx, p->Us[diag], &c)) return 0;
  return c == 1 ? 1 : c == -1 ? -1 : 0;
}

static int ldl_decoupled(const emit_ctx *cx, const ldl_plan *p, int k) {
  if (!p->straight || p->Lp[k + 1] != p->Lp[k] || !ldl_const_pivot(cx, p, k)) return 0;
  int u = p->perm[k];
  for (int e = 0; e < p->nelim; e++)
    for (int i = 0; i < 6; i++)
      if (p->eu[e][i] == u || p->er[e][i] == u) return 1;
  for (int e = 0; e < p->nml; e++) {
    for (int i = 0; i < 6; i++)
      if (p->mlu[e][i] == u) return 1;
    for (int i = p->mlrp[e]; i < p->mlrp[e + 1]; i++)
      if (p->mlR[i] == u) return 1;
  }
  return 0;
}

/* the value of K_aug entry e (upper triangle, permuted) as a C expression */
static void aug_value(emit_ctx *cx, const ldl_plan *p, int e) {
  FILE *f = cx->f;
  int any = 0;
  if (p->Us[e] >= 0) { kval(cx, p->Us[e]); any = 1; }
  for (int t = p->Tp[e]; t < p->Tp[e + 1]; t++) {
    fputs(any ? " + " : "", f);
    num(f, p->w[p->Tw[t]]);
    fputs(" * ", f);
    kval(cx, p->Ta[t]);
    fputs(" * ", f);
    kval(cx, p->Tb[t]);
    any = 1;
  }
  if (!any) fputs("0", f);
}

/* row sums of |K| (the same straight-line / looped choice as the factorization) */
static void emit_knorm(emit_ctx *cx, const lmodel *L, const ldl_plan *p) {
  FILE *f = cx->f;
  const mb_model *m = &L->m;
  fputs("/* ||K||_inf: the largest row sum of |K| (for the relative residual); 'work' from\n"
        " * LDL_R on is scratch */\n"
        "static mb_real ldl_knorm(const mb_real *Kx, mb_real *work) {\n", f);
  if (!p->straight) {
    fputs("  {\n    mb_real *rs = work + LDL_R, a = 0;\n", f);
    fputs("    for (int i = 0; i < LDL_N; i++) rs[i] = 0;\n", f);
    fputs("    for (int j = 0; j < LDL_N; j++)\n"
          "      for (int q = ldl_Kp[j]; q < ldl_Kp[j + 1]; q++) rs[ldl_Ki[q]] += fabs(Kx[q]);\n", f);
    fputs("    for (int i = 0; i < LDL_N; i++) if (rs[i] > a) a = rs[i];\n", f);
    fputs("    return a;\n  }\n}\n\n", f);
    return;
  }
  /* rows of K: the entries (i, j) sit in column j */
  int n = m->n;
  int *cnt = calloc((size_t)n + 1, sizeof(int)), *rp = calloc((size_t)n + 1, sizeof(int));
  int *rs = malloc(sizeof(int) * (size_t)(m->nnz + 1));
  if (!cnt || !rp || !rs) { free(cnt); free(rp); free(rs); cx->failed = 1; return; }
  fputs("  {\n    mb_real a = 0, c;\n", f);
  for (int q = 0; q < m->nnz; q++) rp[m->Ki[q] + 1]++;
  for (int i = 0; i < n; i++) rp[i + 1] += rp[i];
  for (int j = 0; j < n; j++)
    for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++) rs[rp[m->Ki[q]] + cnt[m->Ki[q]]++] = q;
  for (int i = 0; i < n; i++) {
    if (rp[i] == rp[i + 1]) continue;
    fputs("    c = ", f);
    for (int q = rp[i]; q < rp[i + 1]; q++) fprintf(f, "%sfabs(Kx[%d])", q > rp[i] ? " + " : "", rs[q]);
    fputs(";\n    if (c > a) a = c;\n", f);
  }
  fputs("    (void)work;\n    return a;\n  }\n}\n\n", f);
  free(cnt); free(rp); free(rs);
}

/* sum over k of the terms 'fmt' (two %d: a[k], b[k], e.g. "Lx[%d] * t[%d]"), as up
 * to four interleaved partial sums: one long chain of dependent multiply-adds
 * would leave the straight-line code waiting on latency */
static void emit_sum(emit_ctx *cx, const char *fmt, const int *a, const int *b, int len) {
  FILE *f = cx->f;
  int ways = len >= 8 ? 4 : len >= 4 ? 2 : 1;
  if (ways > 1) fputc('(', f);
  for (int w = 0; w < ways; w++) {
    if (w) fputs(ways == 4 && w == 2 ? ") + (" : " + ", f);
    if (ways > 1) fputc('(', f);
    for (int k = w; k < len; k += ways) {
      if (k > w) fputs(" + ", f);
      fprintf(f, fmt, a[k], b[k]);
    }
    if (ways > 1) fputc(')', f);
  }
  if (ways > 1) fputc(')', f);
}

/* --------------------------------------------------------- factorization */

/* straight-line code is split into functions of about this many flops (kept
 * out of line): the C compiler's register allocation and store-to-load
 * forwarding then work on small functions, and its time stays linear */
#define LDL_CHUNK_FLOPS 600

/* the macros the out-of-line parts use (also in the LDL^T's own preamble) */
#define LDL_PIVTOL_DEFINE "#define LDL_PIVTOL 1e-14\n"

/* an out-of-line part's name: ldl_<what><k>, static, in one file; extern
 * <model>_ldl_<what><k> when the parts go to files of their own */
static void part_name(const emit_ctx *cx, char *buf, size_t n, const char *what, int k) {
  if (cx->ldl.part_file) snprintf(buf, n, "%s_ldl_%s%d", cx->nm, what, k);
  else snprintf(buf, n, "ldl_%s%d", what, k);
}

/* where the next part is written (cx->f from now on), and its storage class */
static const char *part_open(emit_ctx *cx) {
  if (!cx->ldl.part_file) return "static LDL_NOINLINE ";
  int fresh = 0;
  FILE *f = cx->ldl.part_file(cx->ldl.part_ctx, &fresh);
  if (!f) {
    cx->failed = 1; /* the output is discarded: the text goes on where it was */
    return "";
  }
  if (fresh) fputs(LDL_PIVTOL_DEFINE "\n", f);
  cx->f = f;
  return "";
}

/* back to the LDL^T's own stream after a part */
static FILE *part_close(emit_ctx *cx) {
  if (cx->ldl.part_file) cx->f = cx->ldl.body;
  return cx->f;
}

/* a factorization part's parameter list */
static const char *factor_part_params(const emit_ctx *cx, const ldl_plan *p) {
  static const char *const v[4] = {
      "const mb_real *MB_RESTRICT Kx, mb_real *MB_RESTRICT Lx, mb_real *MB_RESTRICT Dinv",
      "const mb_real *MB_RESTRICT Kx, const mb_real *MB_RESTRICT Kc, mb_real *MB_RESTRICT Lx, mb_real *MB_RESTRICT Dinv",
      "const mb_real *MB_RESTRICT Kx, const mb_real *MB_RESTRICT K1, mb_real *MB_RESTRICT Lx, mb_real *MB_RESTRICT Dinv",
      ("const mb_real *MB_RESTRICT Kx, const mb_real *MB_RESTRICT Kc, const mb_real *MB_RESTRICT K1, mb_real *MB_RESTRICT Lx, "
       "mb_real *MB_RESTRICT Dinv")};
  return v[(p->nelim ? 1 : 0) + (cx->ldl.k1_direct ? 2 : 0)];
}

/* ------------------------------------------------------------ dense tail */

/* The last rows of L of a model with a hub (a flexible body's modal block, a
 * chassis that every corner joins, and the loop rows ordered last) are nearly
 * dense: on the flexible car the last 28 of its 200 rows hold 86 % of the
 * factorization's multiply-adds.  Written straight-line, every one of them is an
 * instruction of its own that streams through the instruction cache at every
 * call; as a dense block they are a few short loops over vectors.  The tail's
 * rows T..n-1 are then formed in two steps:
 *   - straight-line, as every other row: their entries in the columns C < T
 *     they touch (a sparse triangular solve with the rows before T), kept as
 *     W = y_c, row a = k - T after row a - 1 (the row's own entries only), and
 *     LcT(c, a) = L(k, c), and the entries of K_aug in the tail's block,
 *     Kt(a, b) = K_aug(T + b, k);
 *   - ldl_tail, dense: row a's unscaled entries S(b) = Kt(a, b) -
 *     sum_c W(a, c) LcT(c, b) (c over the row's entries, b over the whole
 *     tail), then the tail's own triangular solve column by
 *     column (an axpy per column: no reductions, so the C compiler vectorizes
 *     the loops without reordering a sum), the pivot with the straight-line
 *     form's test, and the tail's entries scattered into Lx for the solves.
 * The blocks are padded to multiples of 8 with zeros (cleared at every
 * factorization: the structurally zero entries are never written), so every
 * inner loop has a constant trip count.  The sums run in another order than
 * the straight-line form's: the factors agree to roundoff, not to the bit. */
struct ldl_tail {
  int T, nt, nc, ntp;      /* first row of the tail, its rows, the columns before it, nt padded to 8 */
  int *cidx;               /* T: column j < T -> its place in C, else -1 */
  long nw;                 /* the tail rows' entries in C (W holds them row by row) */
  long tw, tl, tk, tt, size; /* workspace: W (nw), LcT (nc x ntp), Kt and S (nt x ntp) */
};

/* largest tail tried, smallest worth a dense block */
#define LDL_TAIL_MAX 96
#define LDL_TAIL_MIN 8
/* the cost of a multiply-subtract on 8 lanes against a straight-line
 * multiply-add (two AVX or one AVX-512 instruction from a short loop, against
 * an instruction and its constant address streamed from the cache), and the
 * least gain in multiply-adds for which the tail is used */
#define LDL_TAIL_VECTOR_COST 1.0
#define LDL_TAIL_MIN_GAIN 1000.0

static int pad8(int x) { return (x + 7) / 8 * 8; }

/* the columns before T in the rows from T on: their number (cidx: their places) */
static int tail_columns(const ldl_plan *p, int T, int *cidx) {
  int nc = 0;
  for (int j = 0; j < T; j++) cidx[j] = -1;
  for (int k = T; k < p->n; k++)
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++)
      if (p->Rj[r] < T) cidx[p->Rj[r]] = 0;
  for (int j = 0; j < T; j++)
    if (cidx[j] == 0) cidx[j] = nc++;
  return nc;
}

static void tail_layout(ldl_tail *t, long base) {
  t->ntp = pad8(t->nt);
  t->tw = base;
  t->tl = t->tw + (t->nw > 0 ? t->nw : 1);
  t->tk = t->tl + (long)t->nc * t->ntp;
  t->tt = t->tk + (long)t->nt * t->ntp;
  t->size = t->tt + (long)t->nt * t->ntp - base;
}

/* Whether the straight-line factorization takes a dense tail, and which
 * (*t, with t->cidx allocated: tail_free).  MBCC_LDL_TAIL=0: never; =N: the
 * last N rows; else the tail whose estimated cost (straight-line multiply-adds
 * moved out, against the dense loops' vector operations, the extra stores and
 * the scatter) gains most, if it gains at least LDL_TAIL_MIN_GAIN.  Only the
 * plain form (no block pivots, no massless bodies) has one. */
static int tail_plan(const ldl_plan *p, long base, ldl_tail *t) {
  memset(t, 0, sizeof *t);
  int n = p->n;
  if (!p->straight || p->nelim || p->nml || n < 2 * LDL_TAIL_MIN) return 0;
  /* -1: the cost model (unset, or not a whole number: emit_size_setting warns);
     a forced tail is at most LDL_TAIL_MAX rows (its blocks live on the stack) */
  long v = emit_size_setting("MBCC_LDL_TAIL", -1);
  int forced = v < 0 ? -1 : (int)(v < n - 1 ? (v < LDL_TAIL_MAX ? v : LDL_TAIL_MAX) : (n - 1 < LDL_TAIL_MAX ? n - 1 : LDL_TAIL_MAX));
  if (forced == 0 || forced == 1) return 0;
  int *inrow = calloc((size_t)n + 1, sizeof(int)), *cidx = malloc(sizeof(int) * ((size_t)n + 1));
  long *cnt = calloc((size_t)p->nnzL + 1, sizeof(long)); /* terms of y_j in row k, at Rpos order r */
  if (!inrow || !cidx || !cnt) { free(inrow); free(cidx); free(cnt); return 0; }
  int lo = forced > 0 ? n - forced : (n - LDL_TAIL_MAX > 0 ? n - LDL_TAIL_MAX : 1);
  for (int k = lo; k < n; k++) {
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) inrow[p->Rj[r]] = 1;
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
      int j = p->Rj[r];
      for (int rr = p->Rp[j]; rr < p->Rp[j + 1]; rr++) cnt[r] += inrow[p->Rj[rr]];
    }
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) inrow[p->Rj[r]] = 0;
  }
  double best = LDL_TAIL_MIN_GAIN;
  int bestT = -1;
  for (int T = lo; T <= n - LDL_TAIL_MIN; T++) {
    if (forced > 0 && T != n - forced) continue;
    int nt = n - T, nc = tail_columns(p, T, cidx), ntp = pad8(nt);
    double moved = 0, extra = 0, dense = ((double)nc + nt) * ntp / 8; /* the clearing */
    for (int b = 0; b < nt; b++) dense += (double)(nt - b - 1) * (ntp - (b + 1) / 8 * 8) / 8 + 4; /* elimination */
    for (int k = T; k < n; k++) {
      int nck = 0;
      moved += p->Rp[k + 1] - p->Rp[k]; /* the pivot's sum */
      for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
        if (p->Rj[r] >= T) moved += (double)cnt[r] + 1, extra += 1; /* its term, scale; the scatter */
        else extra += 2, nck++; /* W and LcT */
      }
      for (int e = p->Up[k]; e < p->Up[k + 1]; e++) extra += p->Ui[e] >= T; /* Kt */
      dense += (double)nck * ntp / 8 * LDL_TAIL_VECTOR_COST + nck + 10; /* S's row, the scale */
    }
    double gain = moved - dense - extra;
    if (forced > 0 || gain > best) best = gain, bestT = T;
  }
  free(inrow);
  free(cnt);
  if (bestT < 0) { free(cidx); return 0; }
  t->T = bestT;
  t->nt = n - bestT;
  t->nc = tail_columns(p, bestT, cidx);
  t->cidx = cidx;
  for (int k = bestT; k < n; k++)
    for (int r = p->Rp[k]; r < p->Rp[k + 1] && p->Rj[r] < bestT; r++) t->nw++;
  tail_layout(t, base);
  return 1;
}

static void tail_free(ldl_tail *t) {
  free(t->cidx);
  t->cidx = NULL;
}

/* the dense tail's rows (0: none) */
static int tail_rows(const ldl_plan *p, long base) {
  ldl_tail t;
  if (!tail_plan(p, base, &t)) return 0;
  tail_free(&t);
  return t.nt;
}

/* the dense tail's part of the workspace (0: none) */
static long work_size_tail(const ldl_plan *p, long base) {
  ldl_tail t;
  if (!tail_plan(p, base, &t)) return 0;
  tail_free(&t);
  return t.size;
}

/* the dense tail's functions (see above): ldl_tail_clear before the parts,
 * ldl_tail after them */
static void emit_tail_kernel(emit_ctx *cx, const lmodel *L, const ldl_plan *p, const ldl_tail *t) {
  FILE *f = cx->f;
  char name[512];
  long nl = 0;
  for (int k = t->T; k < p->n; k++)
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) nl += p->Rj[r] >= t->T;
  int *lx = malloc(sizeof(int) * (size_t)(nl + 1)), *at = malloc(sizeof(int) * (size_t)(nl + 1));
  int *fail = malloc(sizeof(int) * (size_t)(t->nt + 1)), *wp = malloc(sizeof(int) * (size_t)(t->nt + 1));
  int *wc = malloc(sizeof(int) * (size_t)(t->nw + 1));
  if (!lx || !at || !fail || !wp || !wc) {
    free(lx); free(at); free(fail); free(wp); free(wc);
    cx->failed = 1;
    return;
  }
  nl = 0;
  int nw = 0;
  for (int k = t->T; k < p->n; k++) {
    fail[k - t->T] = p->perm[k] + 1;
    wp[k - t->T] = nw;
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++)
      if (p->Rj[r] >= t->T) {
        lx[nl] = p->Rpos[r];
        at[nl++] = (p->Rj[r] - t->T) * t->ntp + (k - t->T);
      } else {
        wc[nw++] = t->cidx[p->Rj[r]] * t->ntp; /* where its column of LcT starts */
      }
  }
  wp[t->nt] = nw;
  ldl_unknown_name(L, p->perm[t->T], name, sizeof name);
  fprintf(f, "/* the dense tail: rows %d..%d of L (from %s on), which touch %d columns\n"
             " * before it; see emit_ldl.c.  Workspace: W (y of those columns), LcT (their L,\n"
             " * transposed), Kt (K_aug in the tail), LtT (the tail's L, by columns), padded to 8 */\n",
          t->T, p->n - 1, name, t->nc);
  fprintf(f, "#define LDL_TAIL_T %d\n#define LDL_TAIL_NT %d\n#define LDL_TAIL_NC %d\n"
             "#define LDL_TAIL_NTP %d\n"
             "#define LDL_TW %ld\n#define LDL_TL %ld\n#define LDL_TK %ld\n#define LDL_TT %ld\n"
             "#define LDL_TAIL_NL %ld\n",
          t->T, t->nt, t->nc, t->ntp, t->tw, t->tl, t->tk, t->tt, nl);
  fputs("/* 1 + the unknown of each tail pivot (the code of a failed pivot) */\n", f);
  idx_array(f, "ldl_tail_fail", fail, t->nt);
  fputs("/* row a's entries in the columns before the tail: W[ldl_tail_wp[a] ..\n"
        " * ldl_tail_wp[a + 1]), and where each one's column of LcT starts */\n", f);
  idx_array(f, "ldl_tail_wp", wp, t->nt + 1);
  idx_array(f, "ldl_tail_wc", wc, t->nw);
  fputs("/* the tail's entries of L: their Lx positions and their places in LtT */\n", f);
  idx_array(f, "ldl_tail_lx", lx, nl);
  idx_array(f, "ldl_tail_at", at, nl);
  fputs("\n/* LcT and Kt are zero where nothing writes them */\n"
        "static void ldl_tail_clear(mb_real *work) {\n"
        "  for (int i = LDL_TL; i < LDL_TT; i++) work[i] = 0;\n}\n\n", f);
  /* GNU C's vector types let the compiler keep a row of the tail in registers
   * (a loop over an array would go through memory at every step); other
   * compilers get the same loops on scalars */
  fputs("#if defined(__GNUC__)\n"
        "/* 8 reals, aligned as one (rows start anywhere) and read through any pointer;\n"
        "   macros, not functions: a vector argument's ABI depends on the flags */\n"
        "typedef mb_real ldl_vec __attribute__((vector_size(8 * sizeof(mb_real)), aligned(sizeof(mb_real)), may_alias));\n"
        "#define ldl_vload(p) (*(const ldl_vec *)(const void *)(p))\n"
        "#define ldl_vstore(p, v) (*(ldl_vec *)(void *)(p) = (v))\n"
        "#endif\n\n"
        "/* column b of the tail's L from V (its entries from row b on, before the\n"
        " * division by the pivot), and what it adds to the later rows' pivot scales */\n"
        "static int ldl_tail_pivot(int b, const mb_real *V, mb_real *scale, mb_real *Y, mb_real *LtT, mb_real *Dinv) {\n"
        "  const mb_real d = V[b];\n"
        "  if (!(fabs(d) > LDL_PIVTOL * scale[b]) || !isfinite(scale[b])) return ldl_tail_fail[b];\n"
        "  Dinv[b] = 1 / d;\n"
        "  for (int a = b + 1; a < LDL_TAIL_NT; a++) {\n"
        "    const mb_real l = V[a] * Dinv[b];\n"
        "    Y[b * LDL_TAIL_NTP + a] = V[a];\n"
        "    LtT[b * LDL_TAIL_NTP + a] = l;\n"
        "    scale[a] += fabs(l * V[a]);\n"
        "  }\n"
        "  /* zeros where later columns' vectors read past the entries: the padding, and\n"
        "     this column's block of 8 up to the diagonal */\n"
        "  for (int a = b / 8 * 8; a <= b; a++) Y[b * LDL_TAIL_NTP + a] = LtT[b * LDL_TAIL_NTP + a] = 0;\n"
        "  for (int a = LDL_TAIL_NT; a < LDL_TAIL_NTP; a++) Y[b * LDL_TAIL_NTP + a] = LtT[b * LDL_TAIL_NTP + a] = 0;\n"
        "  return 0;\n}\n\n"
        "static int ldl_tail(mb_real *work) {\n"
        "  mb_real *Lx = work, *Dinv = work + LDL_DINV + LDL_TAIL_T, *S = work + LDL_TT;\n"
        "  const mb_real *W = work + LDL_TW, *LcT = work + LDL_TL, *Kt = work + LDL_TK;\n"
        "  mb_real scale[LDL_TAIL_NT], LtT[LDL_TAIL_NT * LDL_TAIL_NTP], Y[LDL_TAIL_NT * LDL_TAIL_NTP], V[LDL_TAIL_NTP];\n"
        "  int rc;\n"
        "#if defined(__GNUC__)\n"
        "  const ldl_vec zero = {0};\n"
        "#endif\n"
        "  /* S = Kt - W LcT^T, the tail's block after the columns before it (whole rows: S is\n"
        "     symmetric), and each pivot's scale: |K_aug(k, k)| + sum_j |L(k, j) y_j| */\n"
        "  for (int a = 0; a < LDL_TAIL_NT; a++) {\n"
        "    mb_real sc = 0;\n"
        "#if defined(__GNUC__)\n"
        "    /* the row in registers: one variable per 8 columns */\n", f);
  /* two sets of sums, the row's entries taken in pairs: a subtraction's latency
     would otherwise set the pace */
  int nv = t->ntp / 8;
  fputs("    ldl_vec", f);
  for (int v = 0; v < nv; v++)
    fprintf(f, "%s s%d = ldl_vload(Kt + a * LDL_TAIL_NTP + %d), u%d = zero", v ? "," : "", v, 8 * v, v);
  fputs(";\n    mb_real sd = 0;\n    int q = ldl_tail_wp[a];\n"
        "    for (; q + 1 < ldl_tail_wp[a + 1]; q += 2) {\n"
        "      const mb_real wc = W[q], *l = LcT + ldl_tail_wc[q], wd = W[q + 1], *m = LcT + ldl_tail_wc[q + 1];\n", f);
  for (int v = 0; v < nv; v++) fprintf(f, "      s%d -= wc * ldl_vload(l + %d);\n      u%d -= wd * ldl_vload(m + %d);\n", v, 8 * v, v, 8 * v);
  fputs("      sc += fabs(wc * l[a]);\n      sd += fabs(wd * m[a]);\n    }\n"
        "    if (q < ldl_tail_wp[a + 1]) {\n"
        "      const mb_real wc = W[q], *l = LcT + ldl_tail_wc[q];\n", f);
  for (int v = 0; v < nv; v++) fprintf(f, "      s%d -= wc * ldl_vload(l + %d);\n", v, 8 * v);
  fputs("      sc += fabs(wc * l[a]);\n    }\n    sc += sd;\n", f);
  for (int v = 0; v < nv; v++) fprintf(f, "    ldl_vstore(S + a * LDL_TAIL_NTP + %d, s%d + u%d);\n", 8 * v, v, v);
  fputs("#else\n"
        "    mb_real *s = S + a * LDL_TAIL_NTP;\n"
        "    for (int c = 0; c < LDL_TAIL_NTP; c++) s[c] = Kt[a * LDL_TAIL_NTP + c];\n"
        "    for (int q = ldl_tail_wp[a]; q < ldl_tail_wp[a + 1]; q++) {\n"
        "      const mb_real wc = W[q], *l = LcT + ldl_tail_wc[q];\n"
        "      for (int c = 0; c < LDL_TAIL_NTP; c++) s[c] -= wc * l[c];\n"
        "      sc += fabs(wc * l[a]);\n"
        "    }\n"
        "#endif\n"
        "    scale[a] = fabs(Kt[a * LDL_TAIL_NTP + a]) + sc;\n"
        "  }\n"
        "  /* L D L^T of S, left-looking by columns: column b (rows b.., row b of S by\n"
        "     symmetry) less sum_{b' < b} y(b', b) L(:, b'), with y(b', b) = L(b, b') d_b' */\n", f);
  fputs("#if defined(__GNUC__)\n", f);
  /* one loop per block of 8 columns, each with the vectors from its block on in
   * registers, the earlier columns taken in pairs */
  for (int v0 = 0; v0 < nv; v0++) {
    fprintf(f, "  for (int b = %d; b < %d && b < LDL_TAIL_NT; b++) {\n", 8 * v0, 8 * v0 + 8);
    fputs("    ldl_vec", f);
    for (int v = v0; v < nv; v++)
      fprintf(f, "%s x%d = ldl_vload(S + b * LDL_TAIL_NTP + %d), z%d = zero", v > v0 ? "," : "", v, 8 * v, v);
    fputs(";\n    int bp = 0;\n    for (; bp + 1 < b; bp += 2) {\n"
          "      const mb_real y = Y[bp * LDL_TAIL_NTP + b], *l = LtT + bp * LDL_TAIL_NTP;\n"
          "      const mb_real yy = Y[(bp + 1) * LDL_TAIL_NTP + b], *ll = LtT + (bp + 1) * LDL_TAIL_NTP;\n", f);
    for (int v = v0; v < nv; v++)
      fprintf(f, "      x%d -= y * ldl_vload(l + %d);\n      z%d -= yy * ldl_vload(ll + %d);\n", v, 8 * v, v, 8 * v);
    fputs("    }\n    if (bp < b) {\n"
          "      const mb_real y = Y[bp * LDL_TAIL_NTP + b], *l = LtT + bp * LDL_TAIL_NTP;\n", f);
    for (int v = v0; v < nv; v++) fprintf(f, "      x%d -= y * ldl_vload(l + %d);\n", v, 8 * v);
    fputs("    }\n", f);
    for (int v = v0; v < nv; v++) fprintf(f, "    ldl_vstore(V + %d, x%d + z%d);\n", 8 * v, v, v);
    fputs("    if ((rc = ldl_tail_pivot(b, V, scale, Y, LtT, Dinv)) != 0) return rc;\n  }\n", f);
  }
  fputs("#else\n"
        "  for (int b = 0; b < LDL_TAIL_NT; b++) {\n"
        "    for (int a = b; a < LDL_TAIL_NTP; a++) V[a] = S[b * LDL_TAIL_NTP + a];\n"
        "    for (int bp = 0; bp < b; bp++) {\n"
        "      const mb_real y = Y[bp * LDL_TAIL_NTP + b], *l = LtT + bp * LDL_TAIL_NTP;\n"
        "      for (int a = b; a < LDL_TAIL_NTP; a++) V[a] -= y * l[a];\n"
        "    }\n"
        "    if ((rc = ldl_tail_pivot(b, V, scale, Y, LtT, Dinv)) != 0) return rc;\n"
        "  }\n"
        "#endif\n"
        "  for (int q = 0; q < LDL_TAIL_NL; q++) Lx[ldl_tail_lx[q]] = LtT[ldl_tail_at[q]];\n"
        "  return 0;\n}\n\n", f);
  free(lx);
  free(at);
  free(fail);
  free(wp);
  free(wc);
}

/* entry r of a row of L, straight-line: y_j = K_aug(j, k) - sum L(j, i) y_i over
 * the earlier columns i of the row (inrow), and L(k, j) = y_j / d_j */
static void emit_row_entry(emit_ctx *cx, const ldl_plan *p, int r, const int *kent, const int *inrow) {
  FILE *f = cx->f;
  int j = p->Rj[r], any = 0;
  fprintf(f, "    y%d = ", j);
  if (kent[j] >= 0) { aug_value(cx, p, kent[j]); any = 1; }
  for (int rr = p->Rp[j]; rr < p->Rp[j + 1]; rr++)
    if (inrow[p->Rj[rr]]) {
      fprintf(f, "%sLx[%d] * y%d", any ? " - " : "-", p->Rpos[rr], p->Rj[rr]);
      any = 1;
    }
  if (!any) fputs("0", f);
  fprintf(f, ";\n    Lx[%d] = y%d * Dinv[%d];\n", p->Rpos[r], j, j);
}

/* row k of the dense tail, straight-line: its entries in the columns before the
 * tail (into Lx, W and LcT) and its entries of K_aug in the tail (into Kt) */
static void emit_tail_row(emit_ctx *cx, const ldl_plan *p, const ldl_tail *t, int k, int *inrow, int *kent,
                          double *chunk_flops) {
  FILE *f = cx->f;
  int a = k - t->T, any_y = 0;
  long q = 0; /* row k's first place in W: the entries in C of the tail rows before it */
  for (int kk = t->T; kk < k; kk++)
    for (int r = p->Rp[kk]; r < p->Rp[kk + 1] && p->Rj[r] < t->T; r++) q++;
  for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
    inrow[p->Rj[r]] = 1;
    any_y |= p->Rj[r] < t->T;
  }
  fputs("  {\n", f);
  if (any_y) {
    fputs("    mb_real", f);
    int first = 1;
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++)
      if (p->Rj[r] < t->T) fprintf(f, "%s y%d", first ? "" : ",", p->Rj[r]), first = 0;
    fputs(";\n", f);
  }
  for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
    int j = p->Rj[r];
    if (j >= t->T) break; /* the row's columns ascend */
    emit_row_entry(cx, p, r, kent, inrow);
    fprintf(f, "    Lx[%ld] = y%d;\n    Lx[%ld] = Lx[%d];\n", t->tw + q++, j,
            t->tl + (long)t->cidx[j] * t->ntp + a, p->Rpos[r]);
    *chunk_flops += 2.0 * (p->Rpos[r] - p->Lp[j]) + 5;
  }
  for (int e = p->Up[k]; e < p->Up[k + 1]; e++)
    if (p->Ui[e] >= t->T) {
      long at = t->tk + (long)a * t->ntp + (p->Ui[e] - t->T), mirror = t->tk + (long)(p->Ui[e] - t->T) * t->ntp + a;
      fprintf(f, "    Lx[%ld] = ", at);
      aug_value(cx, p, e);
      fputs(";\n", f);
      if (mirror != at) fprintf(f, "    Lx[%ld] = Lx[%ld];\n", mirror, at);
      *chunk_flops += 1;
    }
  fputs("  }\n", f);
  for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) inrow[p->Rj[r]] = 0;
  for (int e = p->Up[k]; e < p->Up[k + 1]; e++) kent[p->Ui[e]] = -1;
}

static void emit_factor_straight(emit_ctx *cx, const lmodel *L, const ldl_plan *p, const char *nm) {
  FILE *f = cx->f;
  int n = p->n;
  char name[512];
  /* row k of L is formed in dot-product form: for j in the row (ascending)
   *   y_j = K_aug(j, k) - sum_{i in row k, i < j} L(j, i) y_i,  L(k, j) = y_j / d_j,
   *   d_k = K_aug(k, k) - sum_j L(k, j) y_j,
   * each y_j one expression over earlier values kept in locals: no
   * read-modify-write chains through memory, and the same flops as the
   * column (axpy) form */
  int *inrow = malloc(sizeof(int) * (size_t)(n + 1)); /* column j in row k: 1 */
  int *kent = malloc(sizeof(int) * (size_t)(n + 1));  /* row i of column k of K_aug: entry e */
  if (!inrow || !kent) { free(inrow); free(kent); cx->failed = 1; return; }
  ldl_tail tl;
  int tail = tail_plan(p, work_size_base(p), &tl), T = tail ? tl.T : n;
  for (int j = 0; j < n; j++) inrow[j] = 0, kent[j] = -1;
  int nchunk = 0;
  double chunk_flops = 0;
  for (int k = 0; k < n; k++) {
    if (k == 0 || chunk_flops > LDL_CHUNK_FLOPS) {
      if (k) fputs("  return 0;\n}\n\n", f);
      part_close(cx);
      const char *storage = part_open(cx);
      f = cx->f;
      part_name(cx, name, sizeof name, "factor_part", nchunk++);
      fprintf(f, "%sint %s(%s) {\n", storage, name, factor_part_params(cx, p));
      fprintf(f, "  (void)Kx;\n%s%s  (void)Lx;\n", p->nelim ? "  (void)Kc;\n" : "", cx->ldl.k1_direct ? "  (void)K1;\n" : "");
      chunk_flops = 0;
    }
    int u = p->perm[k];
    ldl_unknown_name(L, u, name, sizeof name);
    fprintf(f, "  /* pivot %d: unknown %d, %s; row %d of L: %d entries */\n", k, u, name, k,
            p->Rp[k + 1] - p->Rp[k]);
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) inrow[p->Rj[r]] = 1;
    int diag = -1;
    for (int e = p->Up[k]; e < p->Up[k + 1]; e++) {
      if (p->Ui[e] == k) diag = e;
      else kent[p->Ui[e]] = e;
    }
    if (k >= T) {
      emit_tail_row(cx, p, &tl, k, inrow, kent, &chunk_flops);
      continue;
    }
    int dc = ldl_const_pivot(cx, p, k);
    if (dc) {
      /* a decoupled unknown: no entries in its row of L, a constant pivot */
      fprintf(f, "  Dinv[%d] = %s;\n", k, dc > 0 ? "1" : "-1");
      chunk_flops += 1;
      for (int e = p->Up[k]; e < p->Up[k + 1]; e++) kent[p->Ui[e]] = -1;
      continue;
    }
    fputs("  {\n", f);
    if (p->Rp[k + 1] > p->Rp[k]) {
      fputs("    mb_real", f);
      for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) fprintf(f, "%s y%d", r > p->Rp[k] ? "," : "", p->Rj[r]);
      fputs(";\n", f);
    }
    fputs("    mb_real d, s;\n", f);
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
      int j = p->Rj[r];
      emit_row_entry(cx, p, r, kent, inrow);
      chunk_flops += 2.0 * (p->Rpos[r] - p->Lp[j]) + 3;
    }
    fputs("    d = ", f);
    if (diag >= 0) aug_value(cx, p, diag);
    else fputs("0", f);
    fputs(";\n    s = fabs(d);\n", f);
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) {
      int j = p->Rj[r];
      fprintf(f, "    d -= Lx[%d] * y%d;\n    s += fabs(Lx[%d] * y%d);\n", p->Rpos[r], j, p->Rpos[r], j);
    }
    fprintf(f, "    if (!(fabs(d) > LDL_PIVTOL * s) || !isfinite(s)) return %d;\n", u + 1);
    fprintf(f, "    Dinv[%d] = 1 / d;\n  }\n", k);
    chunk_flops += 1 + (p->Up[k + 1] - p->Up[k]);
    for (int r = p->Rp[k]; r < p->Rp[k + 1]; r++) inrow[p->Rj[r]] = 0;
    for (int e = p->Up[k]; e < p->Up[k + 1]; e++) kent[p->Ui[e]] = -1;
  }
  free(inrow);
  free(kent);
  if (n) fputs("  return 0;\n}\n\n", f);
  f = part_close(cx);
  (void)nm;
  if (tail) {
    emit_tail_kernel(cx, L, p, &tl);
    tail_free(&tl);
  }
  if (cx->ldl.part_file)
    for (int c = 0; c < nchunk; c++) {
      part_name(cx, name, sizeof name, "factor_part", c);
      fprintf(f, "int %s(%s);\n", name, factor_part_params(cx, p));
    }
  fputs("/* L D L^T of K_aug, whose entries come from Kx (K, or K' after the block pivots) */\n", f);
  fprintf(f, "static int ldl_factor_aug(const mb_real *Kx,%s mb_real *work) {\n", p->nelim ? " const mb_real *Kc," : "");
  fputs("  mb_real *Lx = work, *Dinv = work + LDL_DINV;\n  int rc;\n", f);
  if (tail) fputs("  ldl_tail_clear(work);\n", f);
  fputs("  /* the pivots in order, in parts */\n", f);
  for (int c = 0; c < nchunk; c++) {
    part_name(cx, name, sizeof name, "factor_part", c);
    fprintf(f, "  if ((rc = %s(Kx,%s%s Lx, Dinv)) != 0) return rc;\n", name, p->nelim ? " Kc," : "",
            cx->ldl.k1_direct ? " work + LDL_K1," : "");
  }
  if (tail) fputs("  if ((rc = ldl_tail(work)) != 0) return rc;\n", f);
  fputs("  (void)Lx;\n  (void)Dinv;\n  (void)rc;\n  return 0;\n}\n\n", f);
}

static void emit_factor_looped(emit_ctx *cx, const lmodel *L, const ldl_plan *p, const char *nm) {
  FILE *f = cx->f;
  (void)L;
  (void)nm;
  fputs("/* L D L^T of K_aug, whose entries come from Kx (K, or K' after the block pivots) */\n", f);
  fputs("static int ldl_factor_aug(const mb_real *Kx, mb_real *work) {\n", f);
  fputs("  mb_real *Lx = work, *Dinv = work + LDL_DINV, *y = work + LDL_T;\n", f);
  fputs("  for (int i = 0; i < LDL_N; i++) y[i] = 0;\n", f);
  fputs("  for (int k = 0; k < LDL_N; k++) {\n", f);
  fputs("    /* column k of the upper triangle of K_aug, scattered into y */\n", f);
  fputs("    for (int e = ldl_Up[k]; e < ldl_Up[k + 1]; e++) {\n", f);
  fputs("      mb_real v = ldl_Us[e] >= 0 ? Kx[ldl_Us[e]] : 0;\n", f);
  if (p->Tp[p->nnzA] > 0)
    fputs("      for (int q = ldl_Tp[e]; q < ldl_Tp[e + 1]; q++) v += ldl_Tw[q] * Kx[ldl_Ta[q]] * Kx[ldl_Tb[q]];\n",
          f);
  fputs("      y[ldl_Ui[e]] = v;\n    }\n", f);
  fputs("    mb_real d = y[k], s = fabs(d);\n    y[k] = 0;\n", f);
  fputs("    /* row k of L: a sparse triangular solve along the etree, columns ascending */\n", f);
  fputs("    for (int r = ldl_Rp[k]; r < ldl_Rp[k + 1]; r++) {\n", f);
  fputs("      int j = ldl_Rj[r], pkj = ldl_Rpos[r];\n", f);
  fputs("      mb_real t = y[j], l;\n      y[j] = 0;\n", f);
  fputs("      for (int q = ldl_Lp[j]; q < pkj; q++) y[ldl_Li[q]] -= Lx[q] * t;\n", f);
  fputs("      l = Lx[pkj] = t * Dinv[j];\n      d -= l * t;\n      s += fabs(l * t);\n    }\n", f);
  fputs("    if (!(fabs(d) > LDL_PIVTOL * s) || !isfinite(s)) return 1 + ldl_perm[k];\n", f);
  fputs("    Dinv[k] = 1 / d;\n  }\n  return 0;\n}\n\n", f);
}

/* ----------------------------------------------------------- block pivots */

/* ldl_invn and ldl_inv6 of the generated code (once per file) */
static void emit_inv6(emit_ctx *cx) {
  FILE *f = cx->f;
  if (cx->ldl.inv6_emitted) return;
  cx->ldl.inv6_emitted = 1;
  fputs("\n/* X = A^-1 for an n x n A (row-major, n <= 6; A is overwritten), Gauss-Jordan\n"
        " * with partial pivoting; 1 if a pivot is below 1e-12 amax.  The 6 x 6 are a\n"
        " * body's D_u: a rotation and the identity up to signs, so the explicit inverse\n"
        " * is accurate, and every later use is a 6 x 6 product */\n"
        "static LDL_MAYBE_UNUSED int ldl_invn(int n, mb_real *A, mb_real *X, mb_real amax) {\n"
        "  for (int i = 0; i < n * n; i++) X[i] = i % (n + 1) == 0;\n"
        "  for (int k = 0; k < n; k++) {\n"
        "    int pr = k;\n"
        "    for (int i = k + 1; i < n; i++) if (fabs(A[n * i + k]) > fabs(A[n * pr + k])) pr = i;\n"
        "    if (!(fabs(A[n * pr + k]) > 1e-12 * amax)) return 1;\n"
        "    if (pr != k)\n"
        "      for (int j = 0; j < n; j++) {\n"
        "        mb_real t = A[n * k + j]; A[n * k + j] = A[n * pr + j]; A[n * pr + j] = t;\n"
        "        t = X[n * k + j]; X[n * k + j] = X[n * pr + j]; X[n * pr + j] = t;\n      }\n"
        "    /* columns up to k of A are done (unit vectors): only those right of k change */\n"
        "    mb_real d = 1 / A[n * k + k];\n"
        "    for (int j = k + 1; j < n; j++) A[n * k + j] *= d;\n"
        "    for (int j = 0; j < n; j++) X[n * k + j] *= d;\n"
        "    for (int i = 0; i < n; i++) {\n"
        "      mb_real l = A[n * i + k];\n"
        "      if (i == k || l == 0) continue;\n"
        "      for (int j = k + 1; j < n; j++) A[n * i + j] -= l * A[n * k + j];\n"
        "      for (int j = 0; j < n; j++) X[n * i + j] -= l * X[n * k + j];\n"
        "    }\n  }\n  return 0;\n}\n\n"
        "/* X = A0^-1 for a 6 x 6 A0, the threshold relative to its largest entry */\n"
        "static LDL_MAYBE_UNUSED int ldl_inv6(const mb_real *A0, mb_real *X) {\n"
        "  mb_real A[36], amax = 0;\n"
        "  for (int i = 0; i < 36; i++) {\n"
        "    A[i] = A0[i];\n"
        "    if (fabs(A[i]) > amax) amax = fabs(A[i]);\n  }\n"
        "  return ldl_invn(6, A, X, amax);\n}\n\n", f);
}

/* the entry (i, j) of a block's n x n A in the closed forms below: "a<i><j>",
 * or 0 when it is a structural zero (nz: the block's structure, row-major) */
static int blk_nz(const int *nz, int n, int i, int j) { return nz[n * i + j]; }

/* "+ a_ij a_kl - a_il a_kj" with the structural zeros dropped; 0 if both vanish */
static int emit_minor(emit_ctx *cx, const int *nz, int n, int i, int k, int j, int l) {
  FILE *f = cx->f;
  int t1 = blk_nz(nz, n, i, j) && blk_nz(nz, n, k, l), t2 = blk_nz(nz, n, i, l) && blk_nz(nz, n, k, j);
  if (t1) fprintf(f, "a%d%d * a%d%d", i, j, k, l);
  if (t2) fprintf(f, "%sa%d%d * a%d%d", t1 ? " - " : "-", i, l, k, j);
  return t1 || t2;
}

/* "X = A^-1" on the rows and columns mem[0..n) of a 6 x 6 A (n >= 2), which are
 * one diagonal block of it (slot: A's Kx slots, -1 a structural zero): 2 x 2
 * and 3 x 3 by the adjugate (a well-conditioned D_u block: a rotation or the
 * identity up to signs), larger by ldl_invn.  The emitted code has 'amax' (A's
 * largest entry) in scope; a determinant below 1e-12 amax^n or a Gauss-Jordan
 * pivot below 1e-12 amax runs 'fail'. */
static void emit_inv_small(emit_ctx *cx, const int *slot, const int *mem, int n, const char *X, const char *fail,
                           int adjugate) {
  FILE *f = cx->f;
  int bnz[36];
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) bnz[n * i + j] = slot[6 * mem[i] + mem[j]] >= 0;
  fputs("    {\n", f);
  if (n > 3 || !adjugate) {
    fprintf(f, "      mb_real a[%d], x[%d];\n", n * n, n * n);
    for (int i = 0; i < n; i++)
      for (int j = 0; j < n; j++) {
        int sl = slot[6 * mem[i] + mem[j]];
        fprintf(f, "      a[%d] = ", n * i + j);
        if (sl >= 0) kput(cx, sl);
        else fputc('0', f);
        fputs(";\n", f);
      }
    fprintf(f, "      if (ldl_invn(%d, a, x, amax)) %s;\n", n, fail);
    for (int i = 0; i < n; i++)
      for (int j = 0; j < n; j++) fprintf(f, "      %s[%d] = x[%d];\n", X, 6 * mem[i] + mem[j], n * i + j);
    fputs("    }\n", f);
    return;
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++)
      if (bnz[n * i + j]) {
        fprintf(f, "      const mb_real a%d%d = ", i, j);
        kput(cx, slot[6 * mem[i] + mem[j]]);
        fputs(";\n", f);
      }
  /* cij: the cofactor of a_ij (structural zeros not declared) */
  int cnz[9];
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      if (n == 2) {
        int ii = 1 - i, jj = 1 - j;
        cnz[n * i + j] = bnz[n * ii + jj];
        if (cnz[n * i + j]) fprintf(f, "      const mb_real c%d%d = %sa%d%d;\n", i, j, (i + j) % 2 ? "-" : "", ii, jj);
        continue;
      }
      int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
      cnz[n * i + j] = (bnz[n * i1 + j1] && bnz[n * i2 + j2]) || (bnz[n * i1 + j2] && bnz[n * i2 + j1]);
      if (!cnz[n * i + j]) continue;
      fprintf(f, "      const mb_real c%d%d = ", i, j);
      emit_minor(cx, bnz, n, i1, i2, j1, j2);
      fputs(";\n", f);
    }
  fputs("      const mb_real det = ", f);
  int any = 0;
  for (int j = 0; j < n; j++)
    if (bnz[j] && cnz[j]) {
      fprintf(f, "%sa0%d * c0%d", any ? " + " : "", j, j);
      any = 1;
    }
  fputs(any ? ";\n" : "0;\n", f);
  fprintf(f, "      if (!(fabs(det) > 1e-12 * amax%s)) %s;\n", n == 2 ? " * amax" : " * amax * amax", fail);
  fputs("      const mb_real r = 1 / det;\n", f);
  /* A^-1 = adj(A) / det: X(i, j) = cof(j, i) / det */
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      fprintf(f, "      %s[%d] = ", X, 6 * mem[i] + mem[j]);
      if (cnz[n * j + i]) fprintf(f, "c%d%d * r;\n", j, i);
      else fputs("0;\n", f);
    }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++)
      if (bnz[n * i + j]) fprintf(f, "      (void)a%d%d;\n", i, j);
  fputs("    }\n", f);
}

/* "X = A^-1" for the 6 x 6 A whose entries are the Kx slots slot[36] (-1: a
 * structural zero), block by block (ldl_inv_blocks): a 1 x 1 block by division,
 * larger ones by emit_inv_small; A whole by ldl_inv6 when it is one block.  A
 * pivot (1 x 1) below 1e-12 of A's largest entry runs 'fail', as emit_inv_small's
 * tests.  Only the entries of X inside the blocks are written: the others are
 * structural zeros, and every reader skips them. */
/* the inverse of diagonal block (strongly connected component) c of D_u into X:
 * a division for a 1x1 block, else emit_inv_small; returns the block's size */
/* A 1 x 1 block whose entry is a compile-time constant c != 0 (kput_k1's
 * space) is X = 1 / c with no test (a unit pivot beside a rotation's entries);
 * xk/xc (when not NULL) then get X's entry as known. */
static int emit_inv_component(emit_ctx *cx, const int *slot, const int *comp, int c, const char *X,
                              const char *fail, int adjugate, char *xk, double *xc) {
  FILE *f = cx->f;
  int mem[6], n = 0;
  for (int i = 0; i < 6; i++)
    if (comp[i] == c) mem[n++] = i;
  if (n == 1) {
    int d = 7 * mem[0];
    double v;
    if (slot_const(cx, slot[d], cx->ldl.kput_k1, &v) && v != 0) {
      fprintf(f, "    %s[%d] = ", X, d);
      num(f, 1 / v);
      fputs("; /* a constant pivot */\n", f);
      if (xk) { xk[d] = 1; xc[d] = 1 / v; }
    } else {
      char a[32];
      kname_buf(cx, a, sizeof a, slot[d], cx->ldl.kput_k1);
      fprintf(f, "    if (!(fabs(%s) > 1e-12 * amax)) %s;\n    %s[%d] = 1 / %s;\n", a, fail, X, d, a);
    }
  } else {
    emit_inv_small(cx, slot, mem, n, X, fail, adjugate);
  }
  return n;
}

static void emit_inv_blocked(emit_ctx *cx, const int *slot, const char *X, const char *fail, char *xk,
                             double *xc) {
  FILE *f = cx->f;
  int nz[36], comp[6];
  for (int i = 0; i < 36; i++) nz[i] = slot[i] >= 0;
  int nb = ldl_inv_blocks(nz, comp);
  if (nb == 1) {
    fputs("  {\n    mb_real A[36];\n", f);
    for (int i = 0; i < 36; i++) {
      fprintf(f, "    A[%d] = ", i);
      if (slot[i] >= 0) kput(cx, slot[i]);
      else fputc('0', f);
      fputs(";\n", f);
    }
    fprintf(f, "    if (ldl_inv6(A, %s)) %s;\n  }\n", X, fail);
    return;
  }
  /* amax: the largest |entry|, the constants' part at compile time */
  double cmax = 0, v;
  for (int k = 0; k < 36; k++)
    if (nz[k] && slot_const(cx, slot[k], cx->ldl.kput_k1, &v) && fabs(v) > cmax) cmax = fabs(v);
  fprintf(f, "  { /* block-diagonal: %d blocks inverted apart */\n    mb_real amax = ", nb);
  num(f, cmax);
  fputs(";\n", f);
  for (int k = 0; k < 36; k++)
    if (nz[k] && !slot_const(cx, slot[k], cx->ldl.kput_k1, &v)) {
      char a[32];
      kname_buf(cx, a, sizeof a, slot[k], cx->ldl.kput_k1);
      fprintf(f, "    if (fabs(%s) > amax) amax = fabs(%s);\n", a, a);
    }
  for (int c = 0; c < nb; c++) emit_inv_component(cx, slot, comp, c, X, fail, 1, xk, xc);
  fputs("    (void)amax;\n  }\n", f);
}

/* The block-triangular structure of a 6 x 6 A (slot[36]: Kx slots, -1 a
 * structural zero): its strongly connected components comp[] under i -> j when
 * A(i, j) can be nonzero, in an order blk[0..nb) in which every such entry
 * goes from a block to itself or a later one (A is block upper triangular
 * there); xnz[36] the structure of A^-1 (i reaches j).  Returns nb, or 0 when a
 * 1 x 1 block's diagonal is a structural zero (A is singular in that form: the
 * caller inverts A whole).  A massless slider's D_u (its prismatic rows) is
 * [diag B; 0 C] with C 3 x 3: four blocks. */
static int tri_structure(const int *slot, int comp[6], int blk[6], int xnz[36]) {
  int reach[36];
  for (int i = 0; i < 36; i++) reach[i] = slot[i] >= 0 || i % 7 == 0;
  for (int k = 0; k < 6; k++)
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < 6; j++)
        if (reach[6 * i + k] && reach[6 * k + j]) reach[6 * i + j] = 1;
  int nb = 0;
  for (int i = 0; i < 6; i++) comp[i] = -1;
  for (int i = 0; i < 6; i++) {
    if (comp[i] >= 0) continue;
    for (int j = i; j < 6; j++)
      if (reach[6 * i + j] && reach[6 * j + i]) comp[j] = nb;
    nb++;
  }
  /* a block after every block that reaches it */
  int placed[6] = {0}, no = 0;
  while (no < nb)
    for (int c = 0; c < nb; c++) {
      if (placed[c]) continue;
      int ready = 1;
      for (int i = 0; i < 6; i++)
        for (int j = 0; j < 6; j++)
          if (comp[j] == c && comp[i] != c && !placed[comp[i]] && reach[6 * i + j]) ready = 0;
      if (ready) { placed[c] = 1; blk[no++] = c; }
    }
  for (int i = 0; i < 6; i++) {
    int single = 1;
    for (int j = 0; j < 6; j++) single &= j == i || comp[j] != comp[i];
    if (single && slot[7 * i] < 0) return 0;
  }
  for (int i = 0; i < 36; i++) xnz[i] = reach[i];
  return nb;
}

/* X = A^-1 for the A of tri_structure, block by block from the last:
 * X_kk = A_kk^-1 (1 x 1 by division, larger by emit_inv_small),
 * X_kj = -X_kk T_kj with T_kj = sum over the later blocks l of A_kl X_lj.
 * Only the structural nonzeros (xnz) of X are written.  'fail' runs when a
 * block's pivot or determinant is below 1e-12 of A's largest entry (^n). */
static void emit_inv_triangular(emit_ctx *cx, const int *slot, const char *X, const char *fail) {
  FILE *f = cx->f;
  int comp[6], blk[6], xnz[36];
  int nb = tri_structure(slot, comp, blk, xnz);
  double cmax = 0, v;
  for (int k = 0; k < 36; k++)
    if (slot[k] >= 0 && slot_const(cx, slot[k], cx->ldl.kput_k1, &v) && fabs(v) > cmax) cmax = fabs(v);
  fprintf(f, "  { /* block upper triangular in %d blocks: the diagonal ones inverted, the rest\n"
             "       by substitution */\n    mb_real amax = ", nb);
  num(f, cmax);
  fputs(";\n", f);
  for (int k = 0; k < 36; k++)
    if (slot[k] >= 0 && !slot_const(cx, slot[k], cx->ldl.kput_k1, &v))
      fprintf(f, "    if (fabs(Kx[%d]) > amax) amax = fabs(Kx[%d]);\n", slot[k], slot[k]);
  for (int bi = nb - 1; bi >= 0; bi--) {
    int c = blk[bi], mem[6], n = emit_inv_component(cx, slot, comp, c, X, fail, 0, NULL, NULL);
    for (int i = 0, k = 0; i < 6; i++)
      if (comp[i] == c) mem[k++] = i;
    /* column j of a later block: T(p, j) = sum_q A(p, q) X(q, j) over q outside
       this block, then X(i, j) = -sum_p X(i, p) T(p, j) */
    for (int j = 0; j < 6; j++) {
      if (comp[j] == c) continue;
      int later = 0;
      for (int b2 = bi + 1; b2 < nb; b2++) later |= blk[b2] == comp[j];
      if (!later) continue;
      int tnz[6] = {0};
      for (int pi = 0; pi < n; pi++) {
        int p = mem[pi], any = 0;
        for (int q = 0; q < 6; q++)
          if (comp[q] != c && slot[6 * p + q] >= 0 && xnz[6 * q + j]) {
            char xv[32];
            if (!any) fprintf(f, "    const mb_real t%d_%d = ", p, j);
            snprintf(xv, sizeof xv, "%s[%d]", X, 6 * q + j);
            put_kterm(cx, &any, slot[6 * p + q], xv);
          }
        if (any) fputs(";\n", f);
        tnz[pi] = any;
      }
      for (int ii = 0; ii < n; ii++) {
        int i = mem[ii], any = 0;
        if (!xnz[6 * i + j]) continue;
        fprintf(f, "    %s[%d] = -(", X, 6 * i + j);
        for (int pi = 0; pi < n; pi++)
          if (tnz[pi]) {
            fprintf(f, "%s%s[%d] * t%d_%d", any ? " + " : "", X, 6 * i + mem[pi], mem[pi], j);
            any = 1;
          }
        fputs(any ? ");\n" : "0);\n", f);
      }
    }
  }
  fputs("  }\n", f);
}

/* the block pivots straight-line (below the flop budget): every slot a
 * constant, structural zeros of Du, Dx and Eu skipped */
/* "  v[i] = r[row] - Kx[slot] * d[col] ...;": row of a block's right side less
 * the known unknowns cols[0..n) through the Kx slots slots[6 k + i] (-1: none) */
static void emit_reduced_rhs(emit_ctx *cx, const char *v, int i, int row, const int *slots,
                             const int *cols, int n) {
  FILE *f = cx->f;
  fprintf(f, "  %s[%d] = r[%d]", v, i, row);
  for (int k = 0; k < n; k++) {
    double c;
    int sl = slots[6 * k + i];
    if (sl < 0) continue;
    if (!slot_const(cx, sl, cx->ldl.kput_k1, &c)) { fputs(" - ", f); kname(cx, sl); fprintf(f, " * d[%d]", cols[k]); }
    else if (c == 1 || c == -1) fprintf(f, " %c d[%d]", c == 1 ? '-' : '+', cols[k]);
    else if (c != 0) { fputs(" - ", f); klit(f, c); fprintf(f, " * d[%d]", cols[k]); }
  }
  fputs(";\n", f);
}

/* the entries of a block's Du^-1 (Di) known at compile time: the inverses of
 * its constant 1 x 1 pivots (emit_inv_component) */
typedef struct {
  char k[36];   /* Di's entries known at compile time */
  double c[36]; /* their values */
} blk_known;

static void emit_blocks_straight(emit_ctx *cx, const lmodel *L, const ldl_plan *p, const long *woff) {
  FILE *f = cx->f;
  char name[512], ex[48], vx[48];
  int nkc = 0;
  for (int q = 0; q < p->nnzR; q++)
    if (cx->ldl.kc_of[q] >= 0 && cx->ldl.kc_of[q] + 1 > nkc) nkc = cx->ldl.kc_of[q] + 1;
  int *src = malloc(sizeof(int) * (size_t)(nkc + 1));
  if (!src) { cx->failed = 1; return; }
  for (int q = 0; q < p->nnzR; q++)
    if (cx->ldl.kc_of[q] >= 0) src[cx->ldl.kc_of[q]] = p->Krmap[q];
  /* the blocks' D_u structure, and with it which entries of D_u^-1 can be nonzero */
  int (*dinz)[36] = calloc((size_t)p->nelim + 1, sizeof *dinz);
  blk_known *dk = calloc((size_t)p->nelim + 1, sizeof *dk);
  int nw = 0;
  for (int e = 0; e < p->nelim; e++) nw += 6 * (p->esp[e + 1] - p->esp[e]);
  char *wk = calloc((size_t)nw + 1, 1); /* W's entries known at compile time, per block at 6 esp[e] */
  double *wc = calloc((size_t)nw + 1, sizeof(double));
  sym_graph *g = &cx->ldl.sym;
  cx->ldl.kc_sym = malloc(sizeof(sym_id) * ((size_t)nkc + 1));
  if (cx->ldl.kc_sym)
    for (int k = 0; k < nkc; k++) cx->ldl.kc_sym[k] = -1;
  if (!dinz || !dk || !wk || !wc || !cx->ldl.kc_sym) { free(src); free(dinz); free(dk); free(wk); free(wc); cx->failed = 1; return; }
  for (int e = 0; e < p->nelim; e++) ldl_block_dinz(p, e, dinz[e]);
  /* the entries of Kc that a block's update reaches (their first update sets them) */
  char *updated = calloc((size_t)nkc + 1, 1);
  if (!updated) { free(src); free(dinz); free(dk); free(wk); free(wc); cx->failed = 1; return; }
  for (int e = 0; e < p->nelim; e++) {
    int xs = p->exp_[e], nx = p->exp_[e + 1] - xs, ss = p->esp[e], ns = p->esp[e + 1] - ss, k = p->ekrp[e];
    for (int si = 0; si < ns; si++)
      for (int xi = 0; xi < nx; xi++, k++) {
        const int *dx = p->edx + 6 * (xs + xi);
        for (int i = 0; i < 6; i++)
          if (dx[i] >= 0 && ldl_w_nonzero(p->eeu + 6 * (ss + si), dinz[e], i))
            updated[cx->ldl.kc_of[p->ekr[2 * k]]] = updated[cx->ldl.kc_of[p->ekr[2 * k + 1]]] = 1;
      }
  }
  cx->ldl.kput_k1 = 1;
  /* a function per block (and one for the entries no block changes): one
     function of all of them took gcc 8 s on the car with 8 virtual bodies */
  const char *k1_local = cx->ldl.k1_direct ? "  const mb_real *K1 = work + LDL_K1; /* the massless bodies' computed entries */\n  (void)K1;\n" : "";
  fprintf(f, "/* the entries of K' that no block changes (the others: at their first change) */\n"
             "static LDL_NOINLINE void ldl_block_fixed(const mb_real *Kx, mb_real *work) {\n"
             "  mb_real *Kc = work + LDL_KR;\n%s", k1_local);
  for (int k = 0; k < nkc; k++) {
    double c;
    if (updated[k]) continue;
    if (src[k] < 0 || slot_const(cx, src[k], 1, &c)) { /* a constant of K' */
      cx->ldl.kc_sym[k] = sym_const(g, src[k] >= 0 ? c : src[k] == -2 ? 1 : src[k] == -3 ? -1 : 0);
      continue;
    }
    fprintf(f, "  Kc[%d] = ", k);
    kname(cx, src[k]);
    fputs(";\n", f);
  }
  fputs("  (void)Kx;\n  (void)Kc;\n}\n\n", f);
  for (int e = 0, w0 = 0; e < p->nelim; e++) {
    int xs = p->exp_[e], nx = p->exp_[e + 1] - xs, ss = p->esp[e], ns = p->esp[e + 1] - ss;
    fprintf(f, "/* block %d: Du^-1, W = Eu Du^-1, K'(s, x) -= (W Dx)(s, x); 0, or 1 + a column of\n"
               " * the virtual body if its Du is singular */\n"
               "static LDL_NOINLINE int ldl_block_pivot%d(const mb_real *Kx, mb_real *work) {\n"
               "  mb_real *Kc = work + LDL_KR, *Di, *W, v;\n%s", e, e, k1_local);
    fprintf(f, "  Di = work + %ld;\n  W = Di + 42;\n", woff[e]);
    {
      char fail[32];
      snprintf(fail, sizeof fail, "return %d", 1 + p->eu[e][0]);
      emit_inv_blocked(cx, p->edu[e], "Di", fail, dk[e].k, dk[e].c);
    }
    int k = p->ekrp[e];
    for (int si = 0; si < ns; si++) {
      const int *eu = p->eeu + 6 * (ss + si);
      char *wki = wk + w0 + 6 * si;
      double *wci = wc + w0 + 6 * si;
      ldl_unknown_name(L, p->es[ss + si], name, sizeof name);
      fprintf(f, "  /* %s */\n", name);
      for (int i = 0; i < 6; i++) { /* only the entries w_nonzero: the readers skip the others */
        int any = 0, known = 1;
        sym_id sum = sym_const(g, 0);
        double c;
        for (int c6 = 0; c6 < 6; c6++)
          if (eu[c6] >= 0 && dinz[e][6 * c6 + i]) {
            any = 1;
            if (slot_const(cx, eu[c6], 1, &c) && dk[e].k[6 * c6 + i])
              sum = sym_add(g, sum, sym_mul(g, sym_const(g, c), sym_const(g, dk[e].c[6 * c6 + i])));
            else known = 0;
          }
        if (!any) continue;
        if (known && sym_is_const(g, sum, &wci[i])) { wki[i] = 1; continue; } /* read as a literal */
        fprintf(f, "  W[%d] = ", 6 * si + i);
        any = 0;
        for (int c6 = 0; c6 < 6; c6++)
          if (eu[c6] >= 0 && dinz[e][6 * c6 + i]) {
            int kn = dk[e].k[6 * c6 + i];
            snprintf(vx, sizeof vx, "Di[%d]", 6 * c6 + i);
            if (kn) { /* Di known: the term is Kx * constant, written constant * Kx */
              kput_buf(cx, ex, sizeof ex, eu[c6], 1);
              put_term(cx, &any, 1, dk[e].c[6 * c6 + i], "", ex);
            } else {
              put_kterm(cx, &any, eu[c6], vx);
            }
          }
        fputs(";\n", f);
      }
      for (int xi = 0; xi < nx; xi++, k++) {
        const int *dx = p->edx + 6 * (xs + xi);
        int any = 0, known = 1;
        sym_id vsum = sym_const(g, 0);
        double c, vsum_c = 0;
        for (int i = 0; i < 6; i++)
          if (dx[i] >= 0 && ldl_w_nonzero(eu, dinz[e], i)) {
            any = 1;
            if (wki[i] && slot_const(cx, dx[i], 1, &c)) vsum = sym_add(g, vsum, sym_mul(g, sym_const(g, wci[i]), sym_const(g, c)));
            else known = 0;
          }
        if (!any) continue;
        if (known && !sym_is_const(g, vsum, &vsum_c)) { cx->failed = 1; known = 0; } /* out of memory */
        if (!known) {
          fputs("  v = ", f);
          any = 0;
          for (int i = 0; i < 6; i++)
            if (dx[i] >= 0 && ldl_w_nonzero(eu, dinz[e], i)) {
              snprintf(ex, sizeof ex, "W[%d]", 6 * si + i);
              if (wki[i]) { /* W known: constant * Kx */
                kput_buf(cx, vx, sizeof vx, dx[i], 1);
                put_term(cx, &any, 1, wci[i], "", vx);
              } else {
                put_kterm(cx, &any, dx[i], ex);
              }
            }
          fputs(any ? ";\n" : "0;\n", f);
        }
        for (int h = 0; h < 2; h++) {
          int kc = cx->ldl.kc_of[p->ekr[2 * k + h]];
          if (updated[kc] == 2) { /* a later change */
            double kv;
            int kknown = sym_is_const(g, cx->ldl.kc_sym[kc], &kv);
            if (kknown && known) { cx->ldl.kc_sym[kc] = sym_sub(g, cx->ldl.kc_sym[kc], vsum); continue; }
            if (kknown) {
              fprintf(f, "  Kc[%d] = ", kc);
              klit(f, kv);
              fputs(" - v;\n", f);
              cx->ldl.kc_sym[kc] = -1;
            } else if (known) {
              fprintf(f, "  Kc[%d] -= ", kc);
              klit(f, vsum_c);
              fputs(";\n", f);
            } else {
              fprintf(f, "  Kc[%d] -= v;\n", kc);
            }
            continue;
          }
          updated[kc] = 2; /* its first change: K'(s, x) = K(s, x) - v */
          double base;
          int bknown = src[kc] < 0 || slot_const(cx, src[kc], 1, &base);
          if (src[kc] < 0) base = src[kc] == -2 ? 1 : src[kc] == -3 ? -1 : 0;
          if (bknown && known) { cx->ldl.kc_sym[kc] = sym_sub(g, sym_const(g, base), vsum); continue; }
          fprintf(f, "  Kc[%d] = ", kc);
          if (!bknown) { kname(cx, src[kc]); fputs(" - ", f); }
          else if (base != 0) { klit(f, base); fputs(" - ", f); }
          else fputc('-', f);
          if (known) klit(f, vsum_c);
          else fputc('v', f);
          fputs(";\n", f);
        }
      }
    }
    w0 += 6 * ns;
    fputs("  (void)v;\n  (void)W;\n  (void)Kc;\n  return 0;\n}\n\n", f);
  }
  free(src);
  free(updated);
  fputs("/* Kc (the entries of K' the block pivots set) from Kx; returns 0, or 1 + a column\n"
        " * of a virtual body whose Du is singular.  Entries known at compile time (a\n"
        " * weld's unit translational rows) are literals where they are read, not stored */\n"
        "static int ldl_block_pivots(const mb_real *Kx, mb_real *work) {\n"
        "  int rc = 0;\n  ldl_block_fixed(Kx, work);\n", f);
  for (int e = 0; e < p->nelim; e++) fprintf(f, "  if ((rc = ldl_block_pivot%d(Kx, work)) != 0) return rc;\n", e);
  fputs("  return rc;\n}\n\n", f);

  fputs(BLOCK_RHS_COMMENT
        "static void ldl_block_rhs(const mb_real *Kx, const mb_real *work, mb_real *r) {\n"
        "  const mb_real *Di, *W;\n  mb_real z[6];\n", f);
  if (cx->ldl.k1_direct) fputs("  const mb_real *K1 = work + LDL_K1;\n  (void)K1;\n", f);
  for (int e = 0, w0 = 0; e < p->nelim; e++) {
    int xs = p->exp_[e], nx = p->exp_[e + 1] - xs, ss = p->esp[e], ns = p->esp[e + 1] - ss;
    fprintf(f, "  /* block %d */\n  Di = work + %ld;\n  W = Di + 42;\n", e, woff[e]);
    for (int si = 0; si < ns; si++) {
      const int *eu = p->eeu + 6 * (ss + si);
      int any = 0;
      for (int c = 0; c < 6; c++)
        if (ldl_w_nonzero(eu, dinz[e], c)) {
          if (!any) fprintf(f, "  r[%d] -= ", p->es[ss + si]);
          snprintf(ex, sizeof ex, "W[%d]", 6 * si + c);
          snprintf(vx, sizeof vx, "r[%d]", p->er[e][c]);
          put_term(cx, &any, wk[w0 + 6 * si + c], wc[w0 + 6 * si + c], ex, vx);
        }
      if (any) fputs(";\n", f);
    }
    for (int i = 0; i < 6; i++) {
      int any = 0;
      fprintf(f, "  z[%d] = ", i);
      for (int c = 0; c < 6; c++)
        if (dinz[e][6 * c + i]) {
          snprintf(ex, sizeof ex, "Di[%d]", 6 * c + i);
          snprintf(vx, sizeof vx, "r[%d]", p->eu[e][c]);
          put_term(cx, &any, dk[e].k[6 * c + i], dk[e].c[6 * c + i], ex, vx);
        }
      fputs(any ? ";\n" : "0;\n", f);
    }
    for (int xi = 0; xi < nx; xi++) {
      const int *dx = p->edx + 6 * (xs + xi);
      int any = 0;
      for (int i = 0; i < 6; i++)
        if (dx[i] >= 0) {
          if (!any) fprintf(f, "  r[%d] -= ", p->ex[xs + xi]);
          snprintf(vx, sizeof vx, "z[%d]", i);
          put_kterm(cx, &any, dx[i], vx);
        }
      if (any) fputs(";\n", f);
    }
    w0 += 6 * ns;
  }
  fputs("  (void)Kx;\n  (void)W;\n  (void)Di;\n}\n\n", f);

  fputs("/* the eliminated unknowns of d from the others: a_u = Du^-1 (g_r - Dx a_x),\n"
        " * lambda_r = Du^-T (f_u - Eu^T lambda_s) */\n"
        "static void ldl_block_back(const mb_real *Kx, const mb_real *work, const mb_real *r, mb_real *d) {\n"
        "  const mb_real *Di;\n  mb_real y[6], z[6];\n", f);
  if (cx->ldl.k1_direct) fputs("  const mb_real *K1 = work + LDL_K1;\n  (void)K1;\n", f);
  for (int e = 0; e < p->nelim; e++) {
    int xs = p->exp_[e], nx = p->exp_[e + 1] - xs, ss = p->esp[e], ns = p->esp[e + 1] - ss;
    fprintf(f, "  /* block %d */\n  Di = work + %ld;\n", e, woff[e]);
    for (int i = 0; i < 6; i++) emit_reduced_rhs(cx, "y", i, p->er[e][i], p->edx + 6 * xs, p->ex + xs, nx);
    for (int c = 0; c < 6; c++) emit_reduced_rhs(cx, "z", c, p->eu[e][c], p->eeu + 6 * ss, p->es + ss, ns);
    for (int c = 0; c < 6; c++) {
      int any = 0;
      fprintf(f, "  d[%d] = ", p->eu[e][c]);
      for (int i = 0; i < 6; i++)
        if (dinz[e][6 * c + i]) {
          snprintf(ex, sizeof ex, "Di[%d]", 6 * c + i);
          snprintf(vx, sizeof vx, "y[%d]", i);
          put_term(cx, &any, dk[e].k[6 * c + i], dk[e].c[6 * c + i], ex, vx);
        }
      fprintf(f, "%s;\n  d[%d] = ", any ? "" : "0", p->er[e][c]);
      any = 0;
      for (int i = 0; i < 6; i++)
        if (dinz[e][6 * i + c]) {
          snprintf(ex, sizeof ex, "Di[%d]", 6 * i + c);
          snprintf(vx, sizeof vx, "z[%d]", i);
          put_term(cx, &any, dk[e].k[6 * i + c], dk[e].c[6 * i + c], ex, vx);
        }
      fputs(any ? ";\n" : "0;\n", f);
    }
  }
  fputs("  (void)Kx;\n  (void)Di;\n}\n\n", f);
  cx->ldl.kput_k1 = 0;
  free(dinz);
  free(dk);
  free(wk);
  free(wc);
}

static void emit_blocks(emit_ctx *cx, const lmodel *L, const ldl_plan *p) {
  FILE *f = cx->f;
  const mb_model *m = &L->m;
  char name[512];
  fputs("/* block pivots: each virtual body welded to a massive body is eliminated with\n"
        " * its 6 weld rows as one 12 x 12 pivot [0 Du^T; Du 0] before the LDL^T:\n"
        " *   K'(s, x) = K(s, x) - (Eu Du^-1 Dx)(s, x)  (S: the other rows on its columns,\n"
        " *   X: the columns of the body it is welded to); see docs/formulation.md. */\n", f);
  if (!p->straight)
  fputs("typedef struct {\n"
        "  int nx, ns;      /* columns X, rows S */\n"
        "  int kr, w;       /* first pair in ldl_ekc; workspace: Du^-1, W = Eu Du^-1 */\n"
        "  const int *u, *r, *x, *s; /* its columns, weld rows, X, S (K indices) */\n"
        "  const int *du, *dx, *eu;  /* Kx slots (-1: zero) of Du (6 x 6), Dx (6 per x), Eu (6 per s) */\n"
        "} ldl_block;\n", f);
  long w = block_base(p);
  long *woff = malloc(sizeof(long) * (size_t)(p->nelim + 1));
  if (!woff) { cx->failed = 1; return; }
  for (int e = 0; e < p->nelim; e++) {
    const mb_body *B = &m->body[p->eb[e]];
    int xs = p->exp_[e], nx = p->exp_[e + 1] - xs, ss = p->esp[e], ns = p->esp[e + 1] - ss;
    fprintf(f, "/* block %d: virtual body '%s' (unknowns %d..%d) and its weld rows", e, B->name,
            p->eu[e][0], p->eu[e][5]);
    for (int i = 0; i < 6; i++) fprintf(f, "%s%d", i ? " " : " ", p->er[e][i]);
    ldl_unknown_name(L, p->ex[xs], name, sizeof name);
    fprintf(f, ";\n * X: %d columns from %s; S: %d rows:", nx, name, ns);
    for (int k = 0; k < ns; k++) {
      ldl_unknown_name(L, p->es[ss + k], name, sizeof name);
      fprintf(f, "\n *   %s", name);
    }
    fputs(" */\n", f);
    woff[e] = w;
    w += block_work(p, e);
    if (p->straight) continue;
    char nmx[64];
    snprintf(nmx, sizeof nmx, "ldl_b%d_u", e); int_array(f, nmx, p->eu[e], 6);
    snprintf(nmx, sizeof nmx, "ldl_b%d_r", e); int_array(f, nmx, p->er[e], 6);
    snprintf(nmx, sizeof nmx, "ldl_b%d_x", e); int_array(f, nmx, p->ex + xs, nx);
    snprintf(nmx, sizeof nmx, "ldl_b%d_s", e); int_array(f, nmx, p->es + ss, ns);
    snprintf(nmx, sizeof nmx, "ldl_b%d_du", e); int_array(f, nmx, p->edu[e], 36);
    snprintf(nmx, sizeof nmx, "ldl_b%d_dx", e); int_array(f, nmx, p->edx + 6 * xs, 6L * nx);
    snprintf(nmx, sizeof nmx, "ldl_b%d_eu", e); int_array(f, nmx, p->eeu + 6 * ss, 6L * ns);
  }
  emit_inv6(cx);
  if (p->straight) {
    emit_blocks_straight(cx, L, p, woff);
    free(woff);
    return;
  }
  fprintf(f, "#define LDL_NBLOCK %d\n", p->nelim);
  fprintf(f, "static const ldl_block ldl_blocks[LDL_NBLOCK] = {\n");
  for (int e = 0; e < p->nelim; e++)
    fprintf(f, "  {%d, %d, %d, %ld, ldl_b%d_u, ldl_b%d_r, ldl_b%d_x, ldl_b%d_s, ldl_b%d_du, ldl_b%d_dx, ldl_b%d_eu},\n",
            p->exp_[e + 1] - p->exp_[e], p->esp[e + 1] - p->esp[e], p->ekrp[e], woff[e], e, e, e, e, e, e, e);
  fputs("};\n", f);
  free(woff);
  /* Kc: the entries of K' the block pivots change (straight-line code; the
     others are read from Kx), or all of K' (looped code) */
  int nkc = 0, npair = p->ekrp[p->nelim];
  int *src = malloc(sizeof(int) * (size_t)(p->nnzR + 1)), *ekc = malloc(sizeof(int) * (size_t)(2 * npair + 1));
  if (!src || !ekc) { free(src); free(ekc); cx->failed = 1; return; }
  for (int q = 0; q < p->nnzR; q++)
    if (cx->ldl.kc_of[q] >= 0) src[cx->ldl.kc_of[q]] = p->Krmap[q], nkc = cx->ldl.kc_of[q] + 1 > nkc ? cx->ldl.kc_of[q] + 1 : nkc;
  for (int k = 0; k < 2 * npair; k++) ekc[k] = p->ekr[k] >= 0 ? cx->ldl.kc_of[p->ekr[k]] : -1;
  fputs("/* Kc entries of the corrected pairs (s, x), (x, s), block by block, s-major\n"
        " * (-1: a pair whose correction is structurally zero) */\n", f);
  int_array(f, "ldl_ekc", ekc, 2L * npair);
  fprintf(f, "/* Kc = %s from Kx: a Kx slot, or -1: 0, -2: 1 (eliminated column),\n"
             " * -3: -1 (eliminated row) */\n",
          p->straight ? "the entries of K' the block pivots set" : "K' (CSC, both triangles)");
  fprintf(f, "#define LDL_NKC %d\n", nkc);
  int_array(f, "ldl_Kcsrc", src, nkc);
  free(src);
  free(ekc);

  fputs("/* Kc (the entries of K' above) from Kx; returns 0, or 1 + a column of a virtual\n"
        " * body whose Du is singular */\n"
        "static int ldl_block_pivots(const mb_real *Kx, mb_real *work) {\n"
        "  mb_real *Kc = work + LDL_KR;\n"
        "  for (int q = 0; q < LDL_NKC; q++) {\n"
        "    int s = ldl_Kcsrc[q];\n"
        "    Kc[q] = s >= 0 ? Kx[s] : s == -2 ? 1 : s == -3 ? -1 : 0;\n  }\n"
        "  for (int e = 0; e < LDL_NBLOCK; e++) {\n"
        "    const ldl_block *B = &ldl_blocks[e];\n"
        "    mb_real A[36], *Di = work + B->w, *W = Di + 42;\n"
        "    int k = B->kr;\n"
        "    for (int i = 0; i < 36; i++) A[i] = B->du[i] >= 0 ? Kx[B->du[i]] : 0;\n"
        "    if (ldl_inv6(A, Di)) return 1 + B->u[0];\n"
        "    for (int si = 0; si < B->ns; si++) {\n"
        "      mb_real *w = W + 6 * si, e[6]; /* row s of W = Eu Du^-1 */\n"
        "      for (int c = 0; c < 6; c++) e[c] = B->eu[6 * si + c] >= 0 ? Kx[B->eu[6 * si + c]] : 0;\n"
        "      for (int i = 0; i < 6; i++) {\n"
        "        w[i] = 0;\n"
        "        for (int c = 0; c < 6; c++) w[i] += e[c] * Di[6 * c + i];\n      }\n"
        "      for (int xi = 0; xi < B->nx; xi++, k++) {\n"
        "        const int *dx = B->dx + 6 * xi;\n"
        "        if (ldl_ekc[2 * k] < 0) continue; /* structurally zero */\n"
        "        mb_real v = 0;\n"
        "        for (int i = 0; i < 6; i++) if (dx[i] >= 0) v += w[i] * Kx[dx[i]];\n"
        "        Kc[ldl_ekc[2 * k]] -= v;\n"
        "        Kc[ldl_ekc[2 * k + 1]] -= v;\n"
        "      }\n    }\n  }\n  return 0;\n}\n\n", f);
  fputs(BLOCK_RHS_COMMENT
        "static void ldl_block_rhs(const mb_real *Kx, const mb_real *work, mb_real *r) {\n"
        "  for (int e = 0; e < LDL_NBLOCK; e++) {\n"
        "    const ldl_block *B = &ldl_blocks[e];\n"
        "    const mb_real *Di = work + B->w, *W = Di + 42;\n"
        "    mb_real z[6];\n"
        "    for (int si = 0; si < B->ns; si++) {\n"
        "      mb_real v = 0;\n"
        "      for (int c = 0; c < 6; c++) v += W[6 * si + c] * r[B->r[c]];\n"
        "      r[B->s[si]] -= v;\n    }\n"
        "    for (int i = 0; i < 6; i++) { /* z = Du^-T f_u */\n"
        "      z[i] = 0;\n"
        "      for (int c = 0; c < 6; c++) z[i] += Di[6 * c + i] * r[B->u[c]];\n    }\n"
        "    for (int xi = 0; xi < B->nx; xi++) {\n"
        "      const int *dx = B->dx + 6 * xi;\n"
        "      mb_real v = 0;\n"
        "      for (int i = 0; i < 6; i++) if (dx[i] >= 0) v += Kx[dx[i]] * z[i];\n"
        "      r[B->x[xi]] -= v;\n    }\n  }\n}\n\n", f);
  fputs("/* the eliminated unknowns of d from the others: a_u = Du^-1 (g_r - Dx a_x),\n"
        " * lambda_r = Du^-T (f_u - Eu^T lambda_s) */\n"
        "static void ldl_block_back(const mb_real *Kx, const mb_real *work, const mb_real *r, mb_real *d) {\n"
        "  for (int e = 0; e < LDL_NBLOCK; e++) {\n"
        "    const ldl_block *B = &ldl_blocks[e];\n"
        "    const mb_real *Di = work + B->w;\n"
        "    mb_real y[6], z[6];\n"
        "    for (int i = 0; i < 6; i++) y[i] = r[B->r[i]];\n"
        "    for (int xi = 0; xi < B->nx; xi++) {\n"
        "      const int *dx = B->dx + 6 * xi;\n"
        "      for (int i = 0; i < 6; i++) if (dx[i] >= 0) y[i] -= Kx[dx[i]] * d[B->x[xi]];\n    }\n"
        "    for (int c = 0; c < 6; c++) z[c] = r[B->u[c]];\n"
        "    for (int si = 0; si < B->ns; si++)\n"
        "      for (int c = 0; c < 6; c++) if (B->eu[6 * si + c] >= 0) z[c] -= Kx[B->eu[6 * si + c]] * d[B->s[si]];\n"
        "    for (int c = 0; c < 6; c++) { /* a_u = Du^-1 y, lambda_r = Du^-T z */\n"
        "      mb_real a = 0, l = 0;\n"
        "      for (int i = 0; i < 6; i++) { a += Di[6 * c + i] * y[i]; l += Di[6 * i + c] * z[i]; }\n"
        "      d[B->u[c]] = a;\n      d[B->r[c]] = l;\n    }\n  }\n}\n\n", f);
}


/* ------------------------------------------------------- massless bodies */

/* workspace offset of massless body e's factors (pi, Du^-1, W, which rows) */
static long ml_ws(const ldl_plan *p, int e) {
  int rmax;
  long dmax;
  ml_max(p, &rmax, &dmax);
  long w = ml_base(p) + p->nnz1 + p->n + dmax;
  for (int k = 0; k < e; k++) w += ml_work(p, k);
  return w;
}

/* Kx slot of D_RU (row at position k of R, column c of U) and of D_RY */
static int ml_du(const ldl_plan *p, int e, int k, int c) { return p->mldu[6 * (p->mlrp[e] + k) + c]; }
static int ml_dy(const ldl_plan *p, int e, int k, int t) {
  return p->mldy[p->mldyp[e] + (long)(p->mlyp[e + 1] - p->mlyp[e]) * k + t];
}
static int ml_hy(const ldl_plan *p, int e, int k) {
  int any = 0;
  for (int t = 0; t < p->mlyp[e + 1] - p->mlyp[e]; t++) any |= ml_dy(p, e, k, t) >= 0;
  return any;
}

/* massless body e as the fixed-row emitters see it: its rows R (t = 0 order pi),
 * slots T, columns u and Y, and its workspace offset */
typedef struct {
  int r, ny;
  const int *pi, *R, *T, *u, *Y;
  long w;
} ml_view;

static ml_view ml_body(const ldl_plan *p, int e) {
  int r0 = p->mlrp[e], y0 = p->mlyp[e];
  ml_view v = {p->mlrp[e + 1] - r0, p->mlyp[e + 1] - y0, p->mlpi0 + r0, p->mlR + r0,
               p->mlT + r0 - 6 * e, p->mlu[e], p->mlY + y0, ml_ws(p, e)};
  return v;
}

/* the Kx slots of massless body e's Du with its rows at t = 0, and the structure
 * of Du^-1 as ldl_mlN_fixed computes it (all 36 when Du is inverted whole);
 * returns 1 when it is block triangular (emit_inv_triangular) */
static int ml_fixed_du(const ldl_plan *p, int e, int slot[36], int xnz[36]) {
  ml_view b = ml_body(p, e);
  int comp[6], blk[6];
  for (int i = 0; i < 6; i++)
    for (int c = 0; c < 6; c++) slot[6 * i + c] = ml_du(p, e, b.pi[i], c);
  if (tri_structure(slot, comp, blk, xnz) > 1) return 1;
  for (int i = 0; i < 36; i++) xnz[i] = 1;
  return 0;
}

/* ldl_mlN_fixed: ldl_ml_pivoting with the rows partial pivoting chose at t = 0
 * (plan mlpi0), every index a constant and Du inverted by its block-triangular
 * structure when it has one (emit_inv_triangular; the same numbers as the
 * pivoting code's Gauss-Jordan up to rounding, every other sum in the same
 * order, the structural zeros of Du^-1 skipped here and in the solves); it declines (returns 0) when those rows no
 * longer suit: Du singular, or |W| above LDL_ML_WMAX (the other rows, in
 * terms of the chosen ones, grow) */
static void emit_ml_fixed_factor(emit_ctx *cx, const ldl_plan *p) {
  FILE *f = cx->f;
  fputs("#define LDL_ML_WMAX 4 /* see ldl_mlN_fixed */\n", f);
  for (int e = 0; e < p->nml; e++) {
    ml_view b = ml_body(p, e);
    int r = b.r, ny = b.ny;
    const int *pi = b.pi;
    fprintf(f, "/* massless body %d with its rows at t = 0 (positions in R):", e);
    for (int k = 0; k < r; k++) fprintf(f, " %d", pi[k]);
    fprintf(f, ";\n * 1, or 0 when they no longer suit and ldl_ml_pivoting must choose */\n"
               "static int ldl_ml%d_fixed(const mb_real *Kx, mb_real *work) {\n"
               "  mb_real *K1 = work + LDL_K1, *ws = work + %ld, *Di = ws + %d, *W = Di + 36;\n"
               "  (void)K1;\n", e, b.w, r);
    int slot[36], xnz[36];
    if (ml_fixed_du(p, e, slot, xnz)) {
      emit_inv_triangular(cx, slot, "Di", "return 0");
    } else {
      fputs("  const mb_real Du[36] = {", f);
      for (int i = 0; i < 36; i++) {
        if (slot[i] >= 0) fprintf(f, "%sKx[%d]", i ? ", " : "", slot[i]);
        else fprintf(f, "%s0", i ? ", " : "");
      }
      fputs("};\n  if (ldl_inv6(Du, Di)) return 0;\n", f);
    }
    for (int i = 0; i < r - 6; i++)
      for (int c = 0; c < 6; c++) {
        int any = 0;
        fprintf(f, "  W[%d] = ", 6 * i + c);
        for (int k = 0; k < 6; k++) {
          int sl = ml_du(p, e, pi[6 + i], k);
          if (sl < 0 || !xnz[6 * k + c]) continue;
          fprintf(f, "%sKx[%d] * Di[%d]", any ? " + " : "", sl, 6 * k + c);
          any = 1;
        }
        fputs(any ? ";\n" : "0;\n", f);
      }
    fprintf(f, "  for (int k = 0; k < %d; k++) if (!(fabs(W[k]) <= LDL_ML_WMAX)) return 0;\n", 6 * (r - 6));
    for (int i = 0; i < r - 6; i++)
      for (int y = 0; y < ny; y++) {
        long kk = p->mlkp[e] + (long)i * ny + y;
        int sl = ml_dy(p, e, pi[6 + i], y);
        fprintf(f, "  K1[%d] = ", p->mlk[2 * kk]);
        if (ml_hy(p, e, pi[6 + i]) && sl >= 0) fprintf(f, "Kx[%d]", sl);
        else fputs("0", f);
        for (int c = 0; c < 6; c++) {
          int sc = ml_dy(p, e, pi[c], y);
          if (!ml_hy(p, e, pi[c]) || sc < 0) continue;
          fprintf(f, " - W[%d] * Kx[%d]", 6 * i + c, sc);
        }
        fprintf(f, ";\n  K1[%d] = K1[%d];\n", p->mlk[2 * kk + 1], p->mlk[2 * kk]);
      }
    /* (the pivot order in ws is for the pivoting solve only: not stored here) */
    fprintf(f, "  LDL_ML_FIXED(&ldl_ml[%d], ws) = 1;\n  return 1;\n}\n\n", e);
  }
}

/* "    <lhs> = sum Di[..] * <v>[..];" over the structural nonzeros xnz of Du^-1:
 * row k of Du^-1 (by_row: Di[6 k + c] * v[c]) or column c (Di[6 k + c] * v[k]);
 * vi maps the summation index to v's (NULL: itself) */
static void emit_di_sum(emit_ctx *cx, const char *lhs, const int *xnz, int by_row, int kc, const char *v,
                        const int *vi) {
  FILE *f = cx->f;
  int any = 0;
  fprintf(f, "    %s = ", lhs);
  for (int j = 0; j < 6; j++) {
    int at = by_row ? 6 * kc + j : 6 * j + kc;
    if (!xnz[at]) continue;
    fprintf(f, "%sDi[%d] * %s[%d]", any ? " + " : "", at, v, vi ? vi[j] : j);
    any = 1;
  }
  fputs(any ? ";\n" : "0;\n", f);
}

/* ldl_ml_rhs_pivoting of body e with its rows at t = 0, when the factorization used them */
static void emit_ml_fixed_rhs(emit_ctx *cx, const ldl_plan *p, int e) {
  FILE *f = cx->f;
  ml_view b = ml_body(p, e);
  int r = b.r, ny = b.ny;
  const int *pi = b.pi, *R = b.R, *T = b.T, *u = b.u, *Y = b.Y;
  long w = b.w;
  fprintf(f, "  if (LDL_ML_FIXED(&ldl_ml[%d], (work + %ld))) { /* body %d, its rows at t = 0 */\n"
             "    const mb_real *Di = work + %ld, *W = Di + 36;\n    mb_real z[6];\n    (void)W;\n", e, w, e, w + r);
  for (int k = 0; k < r; k++) fprintf(f, "    r1[%d] = 0;\n", R[k]);
  for (int i = 0; i < r - 6; i++) {
    fprintf(f, "    r1[%d] = r[%d]", T[i], R[pi[6 + i]]);
    for (int c = 0; c < 6; c++) fprintf(f, " - W[%d] * r[%d]", 6 * i + c, R[pi[c]]);
    fputs(";\n", f);
  }
  int slot[36], xnz[36];
  ml_fixed_du(p, e, slot, xnz);
  for (int c = 0; c < 6; c++) {
    char lhs[16];
    snprintf(lhs, sizeof lhs, "z[%d]", c);
    emit_di_sum(cx, lhs, xnz, 0, c, "r", u);
  }
  for (int y = 0; y < ny; y++) {
    int any = 0;
    for (int c = 0; c < 6; c++) {
      int sl = ml_dy(p, e, pi[c], y);
      if (sl < 0) continue;
      if (!any) fprintf(f, "    r1[%d] -= ", Y[y]);
      fprintf(f, "%sKx[%d] * z[%d]", any ? " + " : "", sl, c);
      any = 1;
    }
    if (any) fputs(";\n", f);
  }
  for (int c = 0; c < 6; c++) fprintf(f, "    r1[%d] = 0;\n", u[c]);
  fputs("    (void)z; /* unread when no column of Y meets the body's rows */\n", f);
  fprintf(f, "  } else {\n    ldl_ml_rhs_pivoting(&ldl_ml[%d], Kx, work, r, r1);\n  }\n", e);
}

/* ldl_ml_back_pivoting of body e with its rows at t = 0, when the factorization used them */
static void emit_ml_fixed_back(emit_ctx *cx, const ldl_plan *p, int e) {
  FILE *f = cx->f;
  ml_view b = ml_body(p, e);
  int r = b.r, ny = b.ny;
  const int *pi = b.pi, *R = b.R, *T = b.T, *u = b.u, *Y = b.Y;
  long w = b.w;
  fprintf(f, "  if (LDL_ML_FIXED(&ldl_ml[%d], (work + %ld))) { /* body %d, its rows at t = 0 */\n"
             "    const mb_real *Di = work + %ld;\n    mb_real mu[%d], y[6], z[6];\n    (void)mu;\n", e, w, e, w + r,
          r > 6 ? r - 6 : 1);
  for (int i = 0; i < r - 6; i++) fprintf(f, "    mu[%d] = d[%d];\n", i, T[i]);
  for (int c = 0; c < 6; c++) {
    fprintf(f, "    y[%d] = r[%d]", c, R[pi[c]]);
    for (int t = 0; t < ny; t++) {
      int sl = ml_dy(p, e, pi[c], t);
      if (sl >= 0) fprintf(f, " - Kx[%d] * d[%d]", sl, Y[t]);
    }
    fputs(";\n", f);
  }
  for (int k = 0; k < 6; k++) {
    fprintf(f, "    z[%d] = r[%d]", k, u[k]);
    for (int i = 0; i < r - 6; i++) {
      int sl = ml_du(p, e, pi[6 + i], k);
      if (sl >= 0) fprintf(f, " - Kx[%d] * mu[%d]", sl, i);
    }
    fputs(";\n", f);
  }
  int slot[36], xnz[36];
  ml_fixed_du(p, e, slot, xnz);
  char lhs[32];
  for (int k = 0; k < 6; k++) {
    snprintf(lhs, sizeof lhs, "d[%d]", u[k]);
    emit_di_sum(cx, lhs, xnz, 1, k, "y", NULL);
  }
  for (int c = 0; c < 6; c++) {
    snprintf(lhs, sizeof lhs, "d[%d]", R[pi[c]]);
    emit_di_sum(cx, lhs, xnz, 0, c, "z", NULL);
  }
  for (int i = 0; i < r - 6; i++) fprintf(f, "    d[%d] = mu[%d];\n", R[pi[6 + i]], i);
  fprintf(f, "  } else {\n    ldl_ml_back_pivoting(&ldl_ml[%d], Kx, work, r, d);\n  }\n", e);
}

/* stage 1: the massless bodies that are not welded (see order.h): tables,
 * the elimination, its right side and the recovery of their unknowns */
static void emit_massless(emit_ctx *cx, const lmodel *L, const ldl_plan *p) {
  FILE *f = cx->f;
  const mb_model *m = &L->m;
  char nmx[64], name[512];
  int rmax;
  long dmax;
  ml_max(p, &rmax, &dmax);
  long w = ml_base(p) + p->nnz1 + p->n + dmax;
  fputs("/* massless bodies: each virtual body that is not welded (a massless slider) is\n"
        " * eliminated with 6 of its r rows R, chosen at run time by partial pivoting on\n"
        " * D_RU (P, Du = D_PU); the other r - 6 (S, W = D_SU Du^-1) become new rows\n"
        " *   K1(t_i, y) = D(s_i, y) - (W D_PY)(i, y)\n"
        " * in the compile-time slots t_i (rows of R), whatever the choice; U and the other\n"
        " * rows of R are decoupled (diagonals 1 and -1).  K1 is then factorized as K\n"
        " * would be; see docs/formulation.md. */\n", f);
  fprintf(f, "#define LDL_K1 %ld\n#define LDL_R1 (LDL_K1 + %d)\n#define LDL_MLD (LDL_R1 + LDL_N)\n#define LDL_MLR %d\n",
          ml_base(p), p->nnz1, rmax);
  fputs("typedef struct {\n"
        "  int r, ny;        /* rows R, columns Y */\n"
        "  int k;            /* first (slot, y) pair in its K1 positions */\n"
        "  long w;           /* workspace: pi (r), Du^-1 (36), W (6 per slot) */\n"
        "  const int *u, *R, *T, *Y; /* its columns, rows, slots, the rows' other columns */\n"
        "  const int *du, *dy;       /* Kx slots (-1: zero) of D_RU (6 per row), D_RY (ny per row) */\n"
        "  const int *k1;            /* K1 positions of (t, y), (y, t): 2 per pair, slot-major */\n"
        "  const int *hy;            /* per row: 1 if it has an entry in Y (else D_RY's row is 0) */\n"
        "} ldl_mlb;\n", f);
  for (int e = 0; e < p->nml; e++) {
    int r0 = p->mlrp[e], r = p->mlrp[e + 1] - r0, y0 = p->mlyp[e], ny = p->mlyp[e + 1] - y0;
    fprintf(f, "/* massless body %d: '%s' (unknowns %d..%d), %d rows:", e, m->body[p->mlb[e]].name,
            p->mlu[e][0], p->mlu[e][5], r);
    for (int k = 0; k < r; k++) {
      ldl_unknown_name(L, p->mlR[r0 + k], name, sizeof name);
      fprintf(f, "\n *   %s", name);
    }
    fprintf(f, "\n * Y: %d columns */\n", ny);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_u", e); int_array(f, nmx, p->mlu[e], 6);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_R", e); int_array(f, nmx, p->mlR + r0, r);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_T", e); int_array(f, nmx, p->mlT + r0 - 6 * e, r - 6);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_Y", e); int_array(f, nmx, p->mlY + y0, ny);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_du", e); int_array(f, nmx, p->mldu + 6 * r0, 6L * r);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_dy", e); int_array(f, nmx, p->mldy + p->mldyp[e], (long)r * ny);
    snprintf(nmx, sizeof nmx, "ldl_ml%d_k1", e);
    int_array(f, nmx, p->mlk + 2 * p->mlkp[e], 2L * (p->mlkp[e + 1] - p->mlkp[e]));
    int *hy = calloc((size_t)r + 1, sizeof(int));
    if (!hy) { cx->failed = 1; return; }
    for (int k = 0; k < r; k++)
      for (int y = 0; y < ny; y++) hy[k] |= p->mldy[p->mldyp[e] + (long)k * ny + y] >= 0;
    snprintf(nmx, sizeof nmx, "ldl_ml%d_hy", e); int_array(f, nmx, hy, r);
    free(hy);
  }
  fprintf(f, "#define LDL_NML %d\nstatic const ldl_mlb ldl_ml[LDL_NML] = {\n", p->nml);
  for (int e = 0; e < p->nml; e++) {
    fprintf(f, "  {%d, %d, %d, %ldL, ldl_ml%d_u, ldl_ml%d_R, ldl_ml%d_T, ldl_ml%d_Y, ldl_ml%d_du, ldl_ml%d_dy, "
               "ldl_ml%d_k1, ldl_ml%d_hy},\n",
            p->mlrp[e + 1] - p->mlrp[e], p->mlyp[e + 1] - p->mlyp[e], p->mlkp[e], w, e, e, e, e, e, e, e, e);
    w += ml_work(p, e);
  }
  fputs("};\n", f);
  fputs("/* K1 from Kx: a Kx slot, or -1: 0, -2: 1 (eliminated column), -3: -1 (decoupled row),\n"
        " * -4: computed below */\n", f);
  fprintf(f, "#define LDL_NK1 %d\n", p->nnz1);
  if (!p->straight) idx_array(f, "ldl_K1src", p->K1map, p->nnz1);
  emit_inv6(cx);
  fputs("/* where a body's factors came from: 1 its compile-time rows (ldl_mlN_static), 0 pivoting */\n"
        "#define LDL_ML_FIXED(B, ws) ws[(B)->r + 36 + 6 * ((B)->r - 6)]\n\n", f);
  fputs("/* body B by partial pivoting on D_RU (any configuration): Du^-1, W and the slot\n"
        " * rows of K1; 0, or 1 + a column of B if its rows have lost rank 6 */\n"
        "static int ldl_ml_pivoting(const ldl_mlb *B, const mb_real *Kx, mb_real *work) {\n"
        "  mb_real *K1 = work + LDL_K1, *D = work + LDL_MLD;\n"
        "  int r = B->r, ny = B->ny, pi[LDL_MLR];\n"
        "  mb_real A[6 * LDL_MLR], G[6 * LDL_MLR], Du[36], amax = 0;\n"
        "  mb_real *ws = work + B->w, *Di = ws + r, *W = Di + 36;\n"
        "  LDL_ML_FIXED(B, ws) = 0;\n"
        "  for (int i = 0; i < 6 * r; i++) {\n"
        "    A[i] = G[i] = B->du[i] >= 0 ? Kx[B->du[i]] : 0;\n"
        "    if (fabs(A[i]) > amax) amax = fabs(A[i]);\n  }\n"
        "  for (int i = 0; i < r; i++) /* the rows without Y entries are never read */\n"
        "    if (B->hy[i])\n"
        "      for (int y = ny * i; y < ny * (i + 1); y++) D[y] = B->dy[y] >= 0 ? Kx[B->dy[y]] : 0;\n"
        "  /* P: partial pivoting on D_RU chooses 6 independent rows */\n"
        "  for (int i = 0; i < r; i++) pi[i] = i;\n"
        "  for (int k = 0; k < 6; k++) {\n"
        "    int pr = k;\n"
        "    for (int i = k + 1; i < r; i++) if (fabs(G[6 * i + k]) > fabs(G[6 * pr + k])) pr = i;\n"
        "    if (!(fabs(G[6 * pr + k]) > 1e-12 * amax)) return 1 + B->u[0];\n"
        "    if (pr != k) {\n"
        "      int t = pi[k]; pi[k] = pi[pr]; pi[pr] = t;\n"
        "      for (int j = 0; j < 6; j++) { mb_real g = G[6 * k + j]; G[6 * k + j] = G[6 * pr + j]; G[6 * pr + j] = g; }\n"
        "    }\n"
        "    for (int i = k + 1; i < r; i++) {\n"
        "      mb_real l = G[6 * i + k] / G[6 * k + k];\n"
        "      for (int j = k; j < 6; j++) G[6 * i + j] -= l * G[6 * k + j];\n    }\n  }\n"
        "  for (int i = 0; i < r; i++) ws[i] = (mb_real)pi[i];\n"
        "  for (int i = 0; i < 6; i++)\n"
        "    for (int c = 0; c < 6; c++) Du[6 * i + c] = A[6 * pi[i] + c];\n"
        "  if (ldl_inv6(Du, Di)) return 1 + B->u[0];\n"
        "  /* slot i: row pi[6 + i] less W times the P rows */\n"
        "  for (int i = 0; i < r - 6; i++) {\n"
        "    const mb_real *a = A + 6 * pi[6 + i];\n"
        "    const int *k1 = B->k1 + 2 * ny * i;\n"
        "    for (int c = 0; c < 6; c++) {\n"
        "      mb_real v = 0;\n"
        "      for (int k = 0; k < 6; k++) v += a[k] * Di[6 * k + c];\n"
        "      W[6 * i + c] = v;\n    }\n"
        "    /* rows without Y entries add nothing: the same sums, in the same order */\n"
        "    const mb_real *ds = D + ny * pi[6 + i];\n"
        "    for (int y = 0; y < ny; y++) K1[k1[2 * y]] = B->hy[pi[6 + i]] ? ds[y] : 0;\n"
        "    for (int c = 0; c < 6; c++) {\n"
        "      if (!B->hy[pi[c]]) continue;\n"
        "      const mb_real w = W[6 * i + c], *dp = D + ny * pi[c];\n"
        "      for (int y = 0; y < ny; y++) K1[k1[2 * y]] -= w * dp[y];\n    }\n"
        "    for (int y = 0; y < ny; y++) K1[k1[2 * y + 1]] = K1[k1[2 * y]];\n  }\n  return 0;\n}\n\n", f);
  if (p->straight) emit_ml_fixed_factor(cx, p);
  fputs(p->straight ? "/* the entries of K1 (work + LDL_K1) the massless bodies' elimination computes (its\n"
                     " * other entries are read from Kx or are literals); returns 0, or 1 + a column of a\n"
                     " * massless body whose rows have lost rank 6 on it */\n"
                   : "/* K1 (work + LDL_K1) from Kx; returns 0, or 1 + a column of a massless body whose\n"
                     " * rows have lost rank 6 on it */\n", f);
  fputs(
        "static int ldl_massless(const mb_real *Kx, mb_real *work) {\n"
        "  mb_real *K1 = work + LDL_K1;\n", f);
  if (p->straight) { /* no gather: the readers take K1's other entries from Kx or as literals */
    fputs("  (void)K1;\n", f);
    for (int e = 0; e < p->nml; e++)
      fprintf(f, "  if (!ldl_ml%d_fixed(Kx, work)) {\n"
                 "    int rc = ldl_ml_pivoting(&ldl_ml[%d], Kx, work);\n    if (rc) return rc;\n  }\n", e, e);
    fputs("  return 0;\n}\n\n", f);
  } else {
    fputs("  for (int q = 0; q < LDL_NK1; q++) {\n"
          "    int s = ldl_K1src[q];\n"
          "    K1[q] = s >= 0 ? Kx[s] : s == -2 ? 1 : s == -3 ? -1 : 0;\n  }\n"
          "  for (int e = 0; e < LDL_NML; e++) {\n"
          "    int rc = ldl_ml_pivoting(&ldl_ml[e], Kx, work);\n    if (rc) return rc;\n  }\n"
          "  return 0;\n}\n\n", f);
  }
  fputs("/* body B's part of r1 (the right side of K1, from r): g1_t = g_s - W g_p,\n"
        " * f1_y = f_y - D_PY^T Du^-T f_u, with the rows ldl_ml_pivoting chose */\n"
        "static void ldl_ml_rhs_pivoting(const ldl_mlb *B, const mb_real *Kx, const mb_real *work,\n"
        "                                const mb_real *r, mb_real *r1) {\n"
        "  const mb_real *ws = work + B->w, *Di = ws + B->r, *W = Di + 36;\n"
        "  int nr = B->r, ny = B->ny, pi[LDL_MLR];\n"
        "  mb_real z[6];\n"
        "  for (int i = 0; i < nr; i++) { pi[i] = (int)ws[i]; r1[B->R[i]] = 0; }\n"
        "  for (int i = 0; i < nr - 6; i++) {\n"
        "    mb_real v = r[B->R[pi[6 + i]]];\n"
        "    for (int c = 0; c < 6; c++) v -= W[6 * i + c] * r[B->R[pi[c]]];\n"
        "    r1[B->T[i]] = v;\n  }\n"
        "  for (int c = 0; c < 6; c++) {\n"
        "    z[c] = 0;\n"
        "    for (int k = 0; k < 6; k++) z[c] += Di[6 * k + c] * r[B->u[k]];\n  }\n"
        "  for (int y = 0; y < ny; y++) {\n"
        "    mb_real v = 0;\n"
        "    for (int c = 0; c < 6; c++) {\n"
        "      int s = B->dy[ny * pi[c] + y];\n"
        "      if (s >= 0) v += Kx[s] * z[c];\n    }\n"
        "    r1[B->Y[y]] -= v;\n  }\n"
        "  for (int c = 0; c < 6; c++) r1[B->u[c]] = 0;\n}\n\n", f);
  fputs("/* r1 = the right side of K1 from r */\n"
        "static void ldl_ml_rhs(const mb_real *Kx, const mb_real *work, const mb_real *r, mb_real *r1) {\n"
        "  for (int i = 0; i < LDL_N; i++) r1[i] = r[i];\n", f);
  if (p->straight)
    for (int e = 0; e < p->nml; e++) emit_ml_fixed_rhs(cx, p, e);
  else
    fputs("  for (int e = 0; e < LDL_NML; e++) ldl_ml_rhs_pivoting(&ldl_ml[e], Kx, work, r, r1);\n", f);
  fputs("}\n\n", f);
  fputs("/* body B's unknowns from d (the solution of K1): a_u = Du^-1 (g_p - D_PY a_y),\n"
        " * lambda_s = mu, lambda_p = Du^-T (f_u - D_SU^T mu), with the rows ldl_ml_pivoting chose */\n"
        "static void ldl_ml_back_pivoting(const ldl_mlb *B, const mb_real *Kx, const mb_real *work,\n"
        "                                 const mb_real *r, mb_real *d) {\n"
        "  const mb_real *ws = work + B->w, *Di = ws + B->r;\n"
        "  int nr = B->r, ny = B->ny, pi[LDL_MLR];\n"
        "  mb_real mu[LDL_MLR], y[6], z[6];\n"
        "  for (int i = 0; i < nr; i++) pi[i] = (int)ws[i];\n"
        "  for (int i = 0; i < nr - 6; i++) mu[i] = d[B->T[i]];\n"
        "  for (int c = 0; c < 6; c++) {\n"
        "    mb_real v = r[B->R[pi[c]]];\n"
        "    for (int t = 0; t < ny; t++) {\n"
        "      int s = B->dy[ny * pi[c] + t];\n"
        "      if (s >= 0) v -= Kx[s] * d[B->Y[t]];\n    }\n"
        "    y[c] = v;\n  }\n"
        "  for (int k = 0; k < 6; k++) {\n"
        "    mb_real v = r[B->u[k]];\n"
        "    for (int i = 0; i < nr - 6; i++) {\n"
        "      int s = B->du[6 * pi[6 + i] + k];\n"
        "      if (s >= 0) v -= Kx[s] * mu[i];\n    }\n"
        "    z[k] = v;\n  }\n"
        "  for (int k = 0; k < 6; k++) {\n"
        "    mb_real a = 0;\n"
        "    for (int c = 0; c < 6; c++) a += Di[6 * k + c] * y[c];\n"
        "    d[B->u[k]] = a;\n  }\n"
        "  for (int c = 0; c < 6; c++) {\n"
        "    mb_real l = 0;\n"
        "    for (int k = 0; k < 6; k++) l += Di[6 * k + c] * z[k];\n"
        "    d[B->R[pi[c]]] = l;\n  }\n"
        "  for (int i = 0; i < nr - 6; i++) d[B->R[pi[6 + i]]] = mu[i];\n}\n\n", f);
  fputs("/* d (the solution of K1) into the solution of K */\n"
        "static void ldl_ml_back(const mb_real *Kx, const mb_real *work, const mb_real *r, mb_real *d) {\n", f);
  if (p->straight)
    for (int e = 0; e < p->nml; e++) emit_ml_fixed_back(cx, p, e);
  else
    fputs("  for (int e = 0; e < LDL_NML; e++) ldl_ml_back_pivoting(&ldl_ml[e], Kx, work, r, d);\n", f);
  fputs("}\n\n", f);
}

/* the public factorization: ||K||, the block pivots, then L D L^T of K_aug */
static void emit_factor_entry(emit_ctx *cx, const lmodel *L, const ldl_plan *p, const char *nm) {
  FILE *f = cx->f;
  emit_knorm(cx, L, p);
  fprintf(f, "int %s_ldl_factor(const mb_real *Kx, mb_real *work) {\n", nm);
  /* Kp: the matrix the rest works on (K, or K1 after the massless bodies) */
  if (p->nml)
    fprintf(f, "  int rc1 = ldl_massless(Kx, work);\n  if (rc1) return rc1;\n"
               "  const mb_real *Kp = %s;\n", cx->ldl.k1_direct ? "Kx; /* K1's gathered entries are read from Kx */" : "work + LDL_K1");
  else
    fputs("  const mb_real *Kp = Kx;\n", f);
  if (p->nelim) {
    fputs("  int rc = ldl_block_pivots(Kp, work);\n  if (rc) return rc;\n", f);
    fputs(p->straight ? "  return ldl_factor_aug(Kp, work + LDL_KR, work);\n}\n\n"
                      : "  return ldl_factor_aug(work + LDL_KR, work);\n}\n\n", f);
  } else {
    fputs("  return ldl_factor_aug(Kp, work);\n}\n\n", f);
  }
}

/* ------------------------------------------------------------------ solve */


/* start part *nparts of the forward or backward solve when there is none yet or
 * the open one has passed LDL_CHUNK_FLOPS (closing it) */
static void solve_part_open(emit_ctx *cx, const char *dir, const char *what, int *nparts, double *part_flops) {
  if (*nparts && *part_flops <= LDL_CHUNK_FLOPS) return;
  if (*nparts) fputs("}\n\n", cx->f);
  part_close(cx);
  const char *storage = part_open(cx);
  FILE *f = cx->f;
  char name[320];
  part_name(cx, name, sizeof name, dir, *nparts);
  fprintf(f, "/* %s: %s, row by row (part %d) */\n", dir, what, *nparts);
  fprintf(f, "%svoid %s(const mb_real *MB_RESTRICT Lx, mb_real *MB_RESTRICT t) {\n", storage, name);
  (*nparts)++;
  *part_flops = 0;
}

static void emit_solve_helpers_straight(emit_ctx *cx, const lmodel *L, const ldl_plan *p) {
  FILE *f = cx->f;
  const mb_model *m = &L->m;
  int n = p->n, nv = p->nv;
  /* t = P [r_top + D^T W r_bot; r_bot] */
  fputs("/* t = P [r_top + D^T W r_bot; r_bot]: the right side of K_aug, permuted */\n", f);
  fprintf(f, "static void ldl_aug(const mb_real *Kx,%s%s const mb_real *r, mb_real *t) {\n",
          p->nelim ? " const mb_real *Kc," : "", cx->ldl.k1_direct ? " const mb_real *K1," : "");
  if (p->nelim) fputs("  (void)Kc;\n", f);
  if (cx->ldl.k1_direct) fputs("  (void)K1;\n", f);
  for (int k = 0; k < n; k++) {
    int u = p->perm[k];
    if (ldl_decoupled(cx, p, k)) continue; /* recovered by ldl_block_back / ldl_ml_back */
    fprintf(f, "  t[%d] = r[%d]", k, u);
    if (u < nv)
      for (int w = 0; w < p->nw; w++)
        for (int q = p->Dp[w]; q < p->Dp[w + 1]; q++)
          if (p->Dj[q] == u) {
            fputs(" + ", f);
            num(f, p->w[w]);
            fputs(" * ", f);
            kval(cx, p->Ds[q]);
            fprintf(f, " * r[%d]", nv + p->wrow[w]);
          }
    fputs(";\n", f);
  }
  if (p->nw == 0) fputs("  (void)Kx;\n", f);
  fputs("}\n\n", f);

  /* the triangular solves in out-of-line parts of about LDL_CHUNK_FLOPS, for
   * the same reason as the factorization's: the C compiler's time stays linear */
  int nfwd = 0, nbwd = 0;
  double part_flops = 0;
  for (int i = 0; i < n; i++) {
    int len = p->Rp[i + 1] - p->Rp[i];
    if (!len) continue;
    solve_part_open(cx, "forward", "L y = t", &nfwd, &part_flops);
    f = cx->f;
    fprintf(f, "  t[%d] -= ", i);
    emit_sum(cx, "Lx[%d] * t[%d]", p->Rpos + p->Rp[i], p->Rj + p->Rp[i], len);
    fputs(";\n", f);
    part_flops += 2.0 * len;
  }
  if (nfwd) fputs("}\n\n", f);
  f = part_close(cx);
  for (int j = n - 1; j >= 0; j--) {
    int len = p->Lp[j + 1] - p->Lp[j];
    if (!len) continue;
    solve_part_open(cx, "backward", "L^T x = z", &nbwd, &part_flops);
    f = cx->f;
    int *lq = malloc(sizeof(int) * (size_t)len);
    if (!lq) { cx->failed = 1; break; }
    for (int k = 0; k < len; k++) lq[k] = p->Lp[j] + k;
    fprintf(f, "  t[%d] -= ", j);
    emit_sum(cx, "Lx[%d] * t[%d]", lq, p->Li + p->Lp[j], len);
    fputs(";\n", f);
    free(lq);
    part_flops += 2.0 * len;
  }
  if (nbwd) fputs("}\n\n", f);
  f = part_close(cx);
  char name[320];
  for (int c = 0; cx->ldl.part_file && c < nfwd + nbwd; c++) {
    part_name(cx, name, sizeof name, c < nfwd ? "forward" : "backward", c < nfwd ? c : c - nfwd);
    fprintf(f, "void %s(const mb_real *MB_RESTRICT Lx, mb_real *MB_RESTRICT t);\n", name);
  }
  fputs("/* t <- (L D L^T)^-1 t */\n", f);
  fputs("static void ldl_lsolve(const mb_real *MB_RESTRICT Lx, const mb_real *MB_RESTRICT Dinv, mb_real *MB_RESTRICT t) {\n", f);
  for (int c = 0; c < nfwd; c++) {
    part_name(cx, name, sizeof name, "forward", c);
    fprintf(f, "  %s(Lx, t);\n", name);
  }
  fputs("  /* diagonal: z = D^-1 y */\n", f);
  for (int k = 0; k < n; k++)
    if (!ldl_decoupled(cx, p, k)) fprintf(f, "  t[%d] *= Dinv[%d];\n", k, k);
  for (int c = 0; c < nbwd; c++) {
    part_name(cx, name, sizeof name, "backward", c);
    fprintf(f, "  %s(Lx, t);\n", name);
  }
  if (p->nnzL == 0) fputs("  (void)Lx;\n", f);
  fputs("}\n\n", f);

  if (p->nelim || p->nml) {
    fputs("/* x = P^T t */\n", f);
    fputs("static void ldl_scatter(const mb_real *t, mb_real *x) {\n", f);
    for (int k = 0; k < n; k++)
      if (!ldl_decoupled(cx, p, k)) fprintf(f, "  x[%d] = t[%d];\n", p->perm[k], k);
    fputs("}\n\n", f);
  } else {
    fputs("/* x += P^T t */\n", f);
    fputs("static void ldl_scatter_add(const mb_real *t, mb_real *x) {\n", f);
    for (int k = 0; k < n; k++) fprintf(f, "  x[%d] += t[%d];\n", p->perm[k], k);
    fputs("}\n\n", f);
  }

  /* r = b - K x by rows */
  fputs("/* r = b - K x (the exact system, original Kx) */\n", f);
  fputs("static void ldl_residual(const mb_real *Kx, const mb_real *x, const mb_real *b, mb_real *r) {\n", f);
  int *cnt = calloc((size_t)n + 1, sizeof(int)), *rp = calloc((size_t)n + 1, sizeof(int));
  int *rs = malloc(sizeof(int) * (size_t)(m->nnz + 1)), *rc = malloc(sizeof(int) * (size_t)(m->nnz + 1));
  if (!(cnt && rp && rs && rc)) cx->failed = 1;
  if (cnt && rp && rs && rc) {
    for (int q = 0; q < m->nnz; q++) rp[m->Ki[q] + 1]++;
    for (int i = 0; i < n; i++) rp[i + 1] += rp[i];
    for (int j = 0; j < n; j++)
      for (int q = m->Kp[j]; q < m->Kp[j + 1]; q++) {
        int i = m->Ki[q], s = rp[i] + cnt[i]++;
        rs[s] = q;
        rc[s] = j;
      }
    for (int i = 0; i < n; i++) {
      fprintf(f, "  r[%d] = b[%d]", i, i);
      for (int s = rp[i]; s < rp[i + 1]; s++) fprintf(f, " - Kx[%d] * x[%d]", rs[s], rc[s]);
      fputs(";\n", f);
    }
  }
  free(cnt); free(rp); free(rs); free(rc);
  fputs("}\n\n", f);
}

static void emit_solve_helpers_looped(emit_ctx *cx, const ldl_plan *p) {
  FILE *f = cx->f;
  fputs("/* t = P [r_top + D^T W r_bot; r_bot]: the right side of K_aug, permuted */\n", f);
  fputs("static void ldl_aug(const mb_real *Kx, const mb_real *r, mb_real *t) {\n", f);
  fputs("  for (int k = 0; k < LDL_N; k++) t[k] = r[ldl_perm[k]];\n", f);
  if (p->nw)
    fputs("  for (int q = 0; q < LDL_ND; q++) t[ldl_Dt[q]] += ldl_Dw[q] * Kx[ldl_Ds[q]] * r[ldl_Dr[q]];\n", f);
  else
    fputs("  (void)Kx;\n", f);
  fputs("}\n\n", f);
  fputs("/* t <- (L D L^T)^-1 t */\n", f);
  fputs("static void ldl_lsolve(const mb_real *Lx, const mb_real *Dinv, mb_real *t) {\n", f);
  fputs("  for (int j = 0; j < LDL_N; j++) { /* forward: L y = t */\n"
        "    mb_real tj = t[j];\n"
        "    for (int q = ldl_Lp[j]; q < ldl_Lp[j + 1]; q++) t[ldl_Li[q]] -= Lx[q] * tj;\n  }\n", f);
  fputs("  for (int k = 0; k < LDL_N; k++) t[k] *= Dinv[k]; /* diagonal */\n", f);
  fputs("  for (int j = LDL_N - 1; j >= 0; j--) { /* backward: L^T x = z */\n"
        "    mb_real s = t[j];\n"
        "    for (int q = ldl_Lp[j]; q < ldl_Lp[j + 1]; q++) s -= Lx[q] * t[ldl_Li[q]];\n"
        "    t[j] = s;\n  }\n}\n\n", f);
  if (p->nelim || p->nml)
    fputs("/* x = P^T t */\n"
          "static void ldl_scatter(const mb_real *t, mb_real *x) {\n"
          "  for (int k = 0; k < LDL_N; k++) x[ldl_perm[k]] = t[k];\n}\n\n", f);
  else
    fputs("/* x += P^T t */\n"
          "static void ldl_scatter_add(const mb_real *t, mb_real *x) {\n"
          "  for (int k = 0; k < LDL_N; k++) x[ldl_perm[k]] += t[k];\n}\n\n", f);
  fputs("/* r = b - K x (the exact system, original Kx) */\n", f);
  fputs("static void ldl_residual(const mb_real *Kx, const mb_real *x, const mb_real *b, mb_real *r) {\n"
        "  for (int i = 0; i < LDL_N; i++) r[i] = b[i];\n"
        "  for (int j = 0; j < LDL_N; j++) {\n"
        "    mb_real xj = x[j];\n"
        "    for (int q = ldl_Kp[j]; q < ldl_Kp[j + 1]; q++) r[ldl_Ki[q]] -= Kx[q] * xj;\n  }\n}\n\n", f);
}

/* one pass of the solve: d (or x += ...) from the factors with right side 'rhs' */
static void emit_solve_pass(emit_ctx *cx, const ldl_plan *p, const char *rhs, const char *ind) {
  FILE *f = cx->f;
  int staged = p->nelim || p->nml;
  if (p->nml)
    fprintf(f, "%sldl_ml_rhs(Kx, work, %s, r1); /* the massless bodies' right side: K1 */\n", ind, rhs);
  else
    fprintf(f, "%sr1 = %s;\n", ind, rhs);
  const char *kc = p->straight ? " work + LDL_KR," : "", *k1 = cx->ldl.k1_direct ? " work + LDL_K1," : "";
  if (p->nelim) {
    fprintf(f, "%sldl_block_rhs(Kp, work, r1); /* the block pivots' right side: K' (in place) */\n", ind);
    fprintf(f, "%sldl_aug(%s,%s%s r1, t);\n", ind, p->straight ? "Kp" : "work + LDL_KR", kc, k1);
  } else {
    fprintf(f, "%sldl_aug(Kp,%s r1, t);\n", ind, k1);
  }
  fprintf(f, "%sldl_lsolve(Lx, Dinv, t);\n", ind);
  if (staged) {
    fprintf(f, "%sldl_scatter(t, d);\n", ind);
    if (p->nelim) fprintf(f, "%sldl_block_back(Kp, work, r1, d); /* the block pivots' unknowns */\n", ind);
    if (p->nml) fprintf(f, "%sldl_ml_back(Kx, work, %s, d); /* the massless bodies' unknowns */\n", ind, rhs);
  }
}

static void emit_solve(emit_ctx *cx, const ldl_plan *p, const char *nm) {
  FILE *f = cx->f;
  int staged = p->nelim || p->nml;
  fprintf(f, "int %s_ldl_solve(const mb_real *Kx, mb_real *work, mb_real *b, mb_real *residual) {\n", nm);
  fputs("  const mb_real *Lx = work, *Dinv = work + LDL_DINV;\n"
        "  mb_real *x = work + LDL_X, *r = work + LDL_R, *t = work + LDL_T, *xb = work + LDL_XB;\n", f);
  if (staged) fputs("  mb_real *d = work + LDL_DD;\n", f);
  if (p->nml)
    fprintf(f, "  mb_real *r1 = work + LDL_R1;\n  const mb_real *Kp = %s;\n", cx->ldl.k1_direct ? "Kx" : "work + LDL_K1");
  else fprintf(f, "  const mb_real *Kp = Kx;\n  %smb_real *r1;\n", p->nelim ? "" : "const ");
  if (!p->nw) {
    /* no weighted rows: the factors are those of K itself, and the first
       solution is the one refinement would start from */
    fputs("  if (!residual) { /* one pass: no residual, no refinement */\n", f);
    if (staged) {
      emit_solve_pass(cx, p, "b", "    ");
    } else {
      fputs("    for (int i = 0; i < LDL_N; i++) x[i] = 0;\n", f);
      emit_solve_pass(cx, p, "b", "    ");
      fputs("    ldl_scatter_add(t, x);\n", f);
    }
    /* the copy and the finiteness test in one pass, without a branch per
       entry: x - x is 0 for a finite x and NaN otherwise */
    fprintf(f, "    int finite = 1;\n"
               "    for (int i = 0; i < LDL_N; i++) {\n"
               "      b[i] = %s[i];\n"
               "      finite &= b[i] - b[i] == 0;\n"
               "    }\n"
               "    return finite ? MB_OK : MB_ERR_NONFINITE;\n  }\n", staged ? "d" : "x");
  }
  fputs("  mb_real knorm = ldl_knorm(Kx, work), bn = 0, best = 0, first = 0;\n"
        "  for (int i = 0; i < LDL_N; i++) {\n"
        "    x[i] = 0;\n    r[i] = b[i];\n    if (fabs(b[i]) > bn) bn = fabs(b[i]);\n  }\n"
        "  /* pass 0: the solve; pass 1: refinement; pass 2: a second one if still above 1e-12 */\n"
        "  for (int it = 0; it < 3; it++) {\n"
        "    mb_real rn = 0, xn = 0, den, rel;\n", f);
  emit_solve_pass(cx, p, "r", "    ");
  if (staged) fputs("    for (int i = 0; i < LDL_N; i++) x[i] += d[i];\n", f);
  else fputs("    ldl_scatter_add(t, x);\n", f);
  fputs("    ldl_residual(Kx, x, b, r);\n"
        "    for (int i = 0; i < LDL_N; i++) {\n"
        "      if (!(fabs(r[i]) <= rn)) rn = fabs(r[i]);\n"
        "      if (!(fabs(x[i]) <= xn)) xn = fabs(x[i]);\n    }\n"
        "    den = knorm * xn + bn;\n"
        "    rel = den > 0 ? rn / den : rn;\n"
        "    if (it > 0 && !(rel < best)) break; /* no longer improving: keep the best */\n"
        "    if (it == 0) first = rel;\n"
        "    best = rel;\n"
        "    if (rel <= LDL_REFINE_TOL) break; /* at roundoff level: x is kept as it is */\n"
        "    for (int i = 0; i < LDL_N; i++) xb[i] = x[i];\n"
        "    if (it > 0 && rel <= 1e-12) break;\n  }\n"
        "  if (best <= LDL_REFINE_TOL) for (int i = 0; i < LDL_N; i++) b[i] = x[i];\n"
        "  else for (int i = 0; i < LDL_N; i++) b[i] = xb[i];\n"
        "  if (residual) {\n    residual[0] = best;\n    residual[1] = first;\n  }\n"
        "  (void)Kp;\n  (void)r1;\n"
        "  return isfinite(best) ? MB_OK : MB_ERR_NONFINITE;\n}\n\n", f);
}

int emit_ldl(emit_ctx *cx, const ldl_out *out) {
  FILE *f = cx->f;
  const mbc_unit *u = cx->u;
  const lmodel *L = cx->L;
  const char *nm = cx->nm, *U = cx->NM;
  const ldl_plan *p = &u->plan;
  if (!u->have_plan) {
    fputs("/* --- emitted LDL^T: not available (the ordering failed) --- */\n\n", f);
    return 0;
  }
  int n = p->n;
  char ordering[256];
  if (p->tree)
    snprintf(ordering, sizeof ordering, "CAMD with %d constraint sets from the spanning tree: each body\n"
             " * before the rows joining it to its parent, loop rows last", p->nsets);
  else
    snprintf(ordering, sizeof ordering, "CAMD, the %d body unknowns before the %d constraint rows", p->nv, p->nc);
  fprintf(f, "/* --- emitted LDL^T of K (solver \"ldl\") ---\n"
             " * K_aug = [M + D^T W D, D^T; D, 0], right side [f + D^T W g; g]: the\n"
             " * solution of K x = b; every leading block of the order is nonsingular with\n"
             " * positive pivots for body unknowns, negative for rows.  Ordering:\n"
             " * %s.  nnz(L) = %ld,\n"
             " * %.0f flops per factorization, %.0f per solve; %s.\n",
          ordering, p->nnzL, p->flops, p->flops_solve,
          p->straight ? "straight-line code" : "loops over static tables (above the flop budget)");
  fprintf(f, " * %d massless velocity unknowns; weighted rows (constraint row: w):", p->nmassless);
  if (!p->nw) fputs(" none", f);
  for (int k = 0; k < p->nw; k++) {
    fputs(k % 4 ? ", " : "\n *  ", f);
    fprintf(f, "%d: %.6g", p->wrow[k], p->w[k]);
  }
  fputs("\n * Workspace: Lx, 1/d, x, r, t, best x. */\n", f);
  fprintf(f, "#define LDL_N %d\n#define LDL_DINV %s_LDL_NNZL\n"
             "#define LDL_X (LDL_DINV + LDL_N)\n#define LDL_R (LDL_X + LDL_N)\n#define LDL_T (LDL_R + LDL_N)\n"
             "#define LDL_XB (LDL_T + LDL_N)\n" LDL_PIVTOL_DEFINE
             "#define LDL_KR (LDL_XB + LDL_N)\n#define LDL_DD (LDL_KR + %d)\n"
             "/* a solve whose relative residual is already this small is not refined */\n"
             "#define LDL_REFINE_TOL 1e-15\n"
             "#if defined(__GNUC__)\n#define LDL_NOINLINE __attribute__((noinline))\n#define LDL_MAYBE_UNUSED __attribute__((unused))\n#else\n#define LDL_NOINLINE\n#define LDL_MAYBE_UNUSED\n#endif\n",
          n, U, p->nelim ? p->nnzR : 0);
  /* pivot order as a comment (straight) or a table (looped) */
  if (p->straight) {
    fputs("/* pivot order: ", f);
    for (int k = 0; k < n; k++) fprintf(f, "%s%d", k ? (k % 20 ? " " : "\n *   ") : "", p->perm[k]);
    fputs(" */\n\n", f);
  } else {
    const mb_model *m = &L->m;
    fputs("/* pivot order (original unknowns) */\n", f);
    idx_array(f, "ldl_perm", p->perm, n);
    fputs("/* K_aug, upper triangle of the permuted matrix: rows, Kx slots (-1: none), and the\n"
          " * products w_r D_ri D_rj of the weighted rows (weights, Kx slots) */\n", f);
    idx_array(f, "ldl_Up", p->Up, n + 1);
    idx_array(f, "ldl_Ui", p->Ui, p->nnzA);
    idx_array(f, "ldl_Us", p->Us, p->nnzA);
    int nt = p->Tp[p->nnzA];
    if (nt > 0) {
      double *tw = malloc(sizeof(double) * (size_t)(nt + 1));
      if (!tw) { cx->failed = 1; return 0; }
      for (int t = 0; t < nt; t++) tw[t] = p->w[p->Tw[t]];
      idx_array(f, "ldl_Tp", p->Tp, p->nnzA + 1);
      real_array(f, "ldl_Tw", tw, nt);
      idx_array(f, "ldl_Ta", p->Ta, nt);
      idx_array(f, "ldl_Tb", p->Tb, nt);
      free(tw);
    }
    fputs("/* L: columns (strictly lower, rows ascending) and rows (columns ascending, positions) */\n", f);
    idx_array(f, "ldl_Lp", p->Lp, n + 1);
    idx_array(f, "ldl_Li", p->Li, p->nnzL);
    idx_array(f, "ldl_Rp", p->Rp, n + 1);
    idx_array(f, "ldl_Rj", p->Rj, p->nnzL);
    idx_array(f, "ldl_Rpos", p->Rpos, p->nnzL);
    fputs("/* D entries of the weighted rows: target (permuted), weight, Kx slot, row in b */\n", f);
    if (p->nw) {
      int nd = p->Dp[p->nw];
      int *dt = malloc(sizeof(int) * (size_t)(nd + 1)), *dr = malloc(sizeof(int) * (size_t)(nd + 1));
      double *dw = malloc(sizeof(double) * (size_t)(nd + 1));
      if (!dt || !dr || !dw) { free(dt); free(dr); free(dw); cx->failed = 1; return 0; }
      for (int k = 0; k < p->nw; k++)
        for (int q = p->Dp[k]; q < p->Dp[k + 1]; q++) {
          dt[q] = p->iperm[p->Dj[q]];
          dr[q] = p->nv + p->wrow[k];
          dw[q] = p->w[k];
        }
      fprintf(f, "#define LDL_ND %d\n", nd);
      idx_array(f, "ldl_Dt", dt, nd);
      real_array(f, "ldl_Dw", dw, nd);
      idx_array(f, "ldl_Ds", p->Ds, nd);
      idx_array(f, "ldl_Dr", dr, nd);
      free(dt); free(dr); free(dw);
    }
    fputs("/* the pattern of K (for the residual and ||K||) */\n", f);
    int_array(f, "ldl_Kp", m->Kp, n + 1);
    int_array(f, "ldl_Ki", m->Ki, m->nnz);
    fputc('\n', f);
  }
  /* the compile-time constants: K1's (massless bodies) and init's entries of Kx */
  cx->ldl.k1_map = p->nml && p->straight ? p->K1map : NULL;
  cx->ldl.k1_direct = p->nml && p->straight;
  signed char *cst = p->straight ? calloc((size_t)L->m.nnz + 1, 1) : NULL;
  if (p->straight && !cst) cx->failed = 1;
  if (cst)
    for (int r = 0; r < L->m.nrow; r++)
      for (int s = 0; s < 2; s++)
        for (int j = 0; j < 6; j++) {
          const mb_rowdef *R = &L->row[r];
          if (!R->constant[s][j] || R->slot[s][j] < 0) continue;
          cst[R->slot[s][j]] = cst[R->slotT[s][j]] = (signed char)(s ? 1 : -1); /* as init writes them */
        }
  cx->ldl.kx_cst = cst;
  cx->ldl.part_file = out && p->straight ? out->part_file : NULL;
  cx->ldl.part_ctx = out ? out->ctx : NULL;
  cx->ldl.body = f;
  int *kc = NULL;
  cx->ldl.inv6_emitted = 0;
  if (p->nml) emit_massless(cx, L, p);
  if (p->nelim) {
    kc = malloc(sizeof(int) * (size_t)(p->nnzR + 1));
    if (!kc) { free(cst); cx->failed = 1; return 0; }
    int nkc = 0;
    for (int q = 0; q < p->nnzR; q++) kc[q] = p->straight ? -1 : nkc++;
    if (p->straight) {
      for (int k = 0; k < 2 * p->ekrp[p->nelim]; k++)
        if (p->ekr[k] >= 0) kc[p->ekr[k]] = 0; /* mark */
      /* the others are Kx slots, or constants of K' (kval writes them as literals:
         a virtual body's decoupled diagonals) */
      for (int q = 0; q < p->nnzR; q++) kc[q] = kc[q] == 0 ? nkc++ : -1;
    }
    cx->ldl.kc_of = kc;
    cx->ldl.kc_map = p->Krmap;
    emit_blocks(cx, L, p);
  }
  if (p->straight) emit_factor_straight(cx, L, p, nm);
  else emit_factor_looped(cx, L, p, nm);
  emit_factor_entry(cx, L, p, nm);
  if (p->straight) emit_solve_helpers_straight(cx, L, p);
  else emit_solve_helpers_looped(cx, p);
  emit_solve(cx, p, nm);
  cx->ldl.kc_of = cx->ldl.kc_map = cx->ldl.k1_map = NULL;
  cx->ldl.k1_direct = 0;
  cx->ldl.kx_cst = NULL;
  free(cst);
  if (cx->ldl.sym.failed) cx->failed = 1;
  free(cx->ldl.kc_sym);
  cx->ldl.kc_sym = NULL;
  sym_free(&cx->ldl.sym);
  free(kc);
  cx->ldl.part_file = NULL;
  cx->ldl.part_ctx = NULL;
  cx->ldl.body = NULL;
  if (out) f = out->wrappers;
  fputs("static int ldl_factor_m(const mb_model *m, const mb_real *Kx, mb_real *work) {\n", f);
  fprintf(f, "  (void)m;\n  return %s_ldl_factor(Kx, work);\n}\n", nm);
  fputs("static int ldl_solve_m(const mb_model *m, const mb_real *Kx, mb_real *work, mb_real *b,\n"
        "                       mb_real *residual) {\n", f);
  fprintf(f, "  (void)m;\n  return %s_ldl_solve(Kx, work, b, residual);\n}\n\n", nm);
  return 1;
}
