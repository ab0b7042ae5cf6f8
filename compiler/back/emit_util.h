/* emit_util.h: what every emitter shares: the emit context passed to each
 * emitting function (no file-scope state in the emitters), and the one copy
 * of the printing helpers. */
#ifndef MBCC_EMIT_UTIL_H
#define MBCC_EMIT_UTIL_H

#include <stdio.h>

#include "sym.h"
#include "unit.h"

/* The emitted LDL^T's compile-time knowledge of K while its code is written
 * (emit_ldl.c; set up and released by emit_ldl, NULL / 0 outside it). */
typedef struct {
  /* where the straight-line code reads the entry at position q of K' (the
   * plan's slots): with block pivots, the entries they change (and the
   * decoupled diagonals) are in Kc (kc_of[q] >= 0), all others straight from
   * Kx (slot kc_map[q] = Krmap[q]); without, K' = K.  (The looped code
   * gathers all of K' into Kc instead: kc_of[q] = q.) */
  const int *kc_of, *kc_map;
  /* with massless bodies (straight-line code): the K1 gather's sources (a Kx
   * slot, or -1: 0, -2: 1, -3: -1, -4: computed), to write K1's constants as
   * literals */
  const int *k1_map;
  /* straight-line code: the entries of Kx that init sets once and eval never
   * writes (+1 or -1: a rigid body's translational columns in a point row),
   * 0 for the others; they become literals too */
  const signed char *kx_cst;
  /* the space of the slots kput prints: 1 the block pivots' (K1 with
   * massless bodies, else Kx), 0 Kx itself (the massless bodies' code) */
  int kput_k1;
  /* straight-line code with massless bodies: K1 is not gathered; a read of
   * its slot q goes to Kx at the slot it was gathered from (k1_map[q] >= 0),
   * to the K1 array only for the entries the massless bodies' elimination
   * computes (-4), and constants are literals */
  int k1_direct;
  /* straight-line block pivots: the entries of Kc known at compile time (a
   * weld's translational rows: unit D_u and unit rows on both sides) are
   * constant nodes of 'sym', kc_sym[k] (-1: stored in Kc); the block updates
   * fold into them there, and their readers get the literal */
  sym_id *kc_sym;
  sym_graph sym;
  int inv6_emitted; /* ldl_invn and ldl_inv6 are written once per file */
  /* a model in several files (emit_ldl.h, ldl_out): the stream of the next
   * out-of-line part of the straight-line code, NULL: they stay in body */
  FILE *(*part_file)(void *ctx, int *fresh);
  void *part_ctx;
  FILE *body; /* the LDL^T's own stream, where the parts are called */
} emit_ldl_state;

typedef struct {
  FILE *f;              /* the file being written */
  const mbc_unit *u;    /* what is emitted: only read */
  const lmodel *L;      /* u->lowered */
  const char *nm;       /* the model's C name (prefix of its symbols) */
  char NM[256];         /* the same in upper case (macro prefix) */
  int failed;           /* out of memory while emitting: the output is discarded */
  emit_ldl_state ldl;
} emit_ctx;

/* a context writing unit u to f */
void emit_ctx_init(emit_ctx *cx, FILE *f, const mbc_unit *u);

/* the printing helpers: doubles as %.17g (round-trip, no "-0") */
void num(FILE *f, double x);
/* {x0, x1, ...} */
void vec(FILE *f, const double *x, int n);
void ivec(FILE *f, const int *x, int n);
/* static const int / mb_real NAME[n] = {...}, 16 / 4 a line; an empty array
 * gets one 0 */
void int_array(FILE *f, const char *name, const int *x, long n);
void real_array(FILE *f, const char *name, const double *x, long n);
/* dst = src in upper case (at most n - 1 characters) */
void upper(char *dst, const char *src, size_t n);

#endif
