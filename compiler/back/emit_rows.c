/* emit_rows.c: the markers on rigid bodies and the spherical and dot-1 rows of
 * the generated evaluation, written out expression by expression.
 *
 * The kernels of runtime/core/mb_kernels.h (mb_marker_rigid, mb_prim_sph,
 * mb_prim_dot1, mb_row_phidot, mb_row_gamma, mb_rigid_cols) are general: a
 * spherical row's Jacobian is a unit vector, a dot-1 row has no point terms,
 * a rigid marker's angular acceleration term is zero, a ground marker does
 * not move, most markers have axes C = I, and the kernels multiply and add
 * all of these zeros and ones at run time.  The compiler knows them.  Here
 * the same formulas are written as C expressions over the frames and markers
 * with the compile-time zeros and ones folded: a product with an exact zero
 * is dropped and a product with one is its other factor.  The remaining terms
 * keep the kernels' order of operations, so for finite values the numbers are
 * the kernels' own (up to the sign of a zero); test_generic and test_ldl
 * compare the two paths. */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emit_rows.h"
#include "sym.h"

/* Every vector component is a node of the entry point's graph (sym.h):
 * compile-time numbers are constants that fold, the frames' and markers'
 * fields and run-time marker offsets are symbols that never fold.  The graph
 * keeps the operands in the order given, so the printed C reads as the
 * kernel it replaces.  An allocation that fails marks the graph (every later
 * node is -1); the entry point returns -1 and emit_model discards the output. */
typedef struct { sym_id e[3]; } svec;

static void rows_graph(sym_graph *g) {
  sym_init(g);
  g->keep_order = 1;
}

/* the symbol printf(fmt, ...): a field or local of the generated code */
static sym_id named(sym_graph *g, const char *fmt, ...) {
  char text[96];
  va_list ap;
  va_start(ap, fmt);
  int n = vsnprintf(text, sizeof text, fmt, ap);
  va_end(ap);
  if (n < 0 || (size_t)n >= sizeof text) { g->failed = 1; return -1; } /* names are short: never */
  return sym_symbol(g, text);
}

/* a compile-time number (no -0: it prints as 0 and stays 0 in products) */
static sym_id lit(sym_graph *g, double x) { return sym_const(g, x == 0 ? 0 : x); }

static int is_zero(const sym_graph *g, sym_id x) {
  double c;
  return sym_is_const(g, x, &c) && c == 0;
}

/* a number, a name or a negated one: kept in place, never given a local */
static int is_atom(const sym_graph *g, sym_id x) {
  if (x < 0) return 1;
  sym_op op = g->node[x].op;
  if (op == SYM_NEG) op = g->node[g->node[x].a].op;
  return op == SYM_CONST || op == SYM_SYMBOL;
}

static void put(FILE *f, const sym_graph *g, sym_id x) {
  if (x >= 0) sym_print(f, g, x); /* -1: the graph failed, the output is discarded */
}

/* 1 if expression x holds a floating literal (one with '.' or an exponent) */
static int has_real_literal(const sym_graph *g, sym_id x) {
  if (x < 0) return 0;
  const sym_node *n = &g->node[x];
  if (n->op == SYM_CONST) {
    char t[40];
    sym_literal(t, sizeof t, n->value);
    return strpbrk(t, ".eE") != NULL;
  }
  return has_real_literal(g, n->a) || has_real_literal(g, n->b);
}

/* an element of a braced mb_real initializer, converted explicitly when it
 * holds a floating literal (a double: where mb_real is float, C converts the
 * value implicitly, C++ rejects the narrowing in braces); expressions of
 * mb_real variables and integers as they are */
static void init_elem(FILE *f, const sym_graph *g, sym_id x) {
  int real_literal = has_real_literal(g, x);
  if (real_literal) fputs("(mb_real)(", f);
  put(f, g, x);
  if (real_literal) fputc(')', f);
}

/* "{e0, e1, e2}" with init_elem's elements */
static void init3(FILE *f, const sym_graph *g, const svec *v) {
  fputc('{', f);
  for (int i = 0; i < 3; i++) {
    if (i) fputs(", ", f);
    init_elem(f, g, v->e[i]);
  }
  fputc('}', f);
}

/* a . b, summed left to right as mb_dot3 */
static sym_id s_dot(sym_graph *g, const svec *a, const svec *b) {
  sym_id t = sym_mul(g, a->e[0], b->e[0]);
  t = sym_add(g, t, sym_mul(g, a->e[1], b->e[1]));
  return sym_add(g, t, sym_mul(g, a->e[2], b->e[2]));
}

/* a x b as mb_cross3 */
static svec s_cross(sym_graph *g, const svec *a, const svec *b) {
  svec t;
  for (int i = 0; i < 3; i++) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    t.e[i] = sym_sub(g, sym_mul(g, a->e[j], b->e[k]), sym_mul(g, a->e[k], b->e[j]));
  }
  return t;
}

/* A^T x (A row-major, 9 entries) as mb_mul3t */
static svec s_mul3t(sym_graph *g, const sym_id A[9], const svec *x) {
  svec t;
  for (int i = 0; i < 3; i++) {
    t.e[i] = sym_mul(g, A[i], x->e[0]);
    t.e[i] = sym_add(g, t.e[i], sym_mul(g, A[3 + i], x->e[1]));
    t.e[i] = sym_add(g, t.e[i], sym_mul(g, A[6 + i], x->e[2]));
  }
  return t;
}

/* the vector field "<fmt % a>[0..2]" */
static svec s_names(sym_graph *g, const char *fmt, int a) {
  char base[64];
  svec v;
  int n = snprintf(base, sizeof base, fmt, a);
  for (int i = 0; i < 3; i++) v.e[i] = n < 0 || (size_t)n >= sizeof base ? -1 : named(g, "%s[%d]", base, i);
  if (n < 0 || (size_t)n >= sizeof base) g->failed = 1;
  return v;
}

static svec s_zero(sym_graph *g) {
  svec v;
  for (int i = 0; i < 3; i++) v.e[i] = lit(g, 0);
  return v;
}

/* body b's rotation matrix A (row-major) */
static void frame_A(sym_graph *g, int b, sym_id A[9]) {
  for (int i = 0; i < 9; i++) A[i] = named(g, "f%d.A[%d]", b, i);
}

/* declare a local 'name' for the entries of v that are not atoms; they become
 * name[i] (an entry that is zero or an atom stays as it is) */
static void s_local(FILE *f, sym_graph *g, svec *v, const char *name, const char *indent) {
  int need = 0;
  for (int i = 0; i < 3; i++) need |= !is_atom(g, v->e[i]);
  if (!need) return;
  fprintf(f, "%smb_real %s[3] = ", indent, name);
  init3(f, g, v);
  fputs(";\n", f);
  for (int i = 0; i < 3; i++)
    if (!is_atom(g, v->e[i])) v->e[i] = named(g, "%s[%d]", name, i);
}

/* the graph's end: -1 if any of its nodes failed */
static int rows_graph_done(sym_graph *g) {
  int st = g->failed ? -1 : 0;
  sym_free(g);
  return st;
}

/* a node whose mode shapes all vanish there (the reference node of the body
 * frame, or Craig-Bampton interface nodes held by it): its marker is a rigid
 * marker at the node's position, the same numbers without the modal sums,
 * the rotation exponential and the zero modal columns (known at compile time) */
int emit_node_static(const mb_body *B, int node) {
  return B->flex && node >= 0 && !lower_node_translates(B, node) && !lower_node_rotates(B, node);
}

/* a marker on a rigid body (or on a node whose mode shapes vanish there) */
static int marker_rigid(const lmodel *L, int k, const double **s) {
  const mb_markerdef *d = &L->marker[k];
  if (d->body < 0) return 0;
  const mb_body *B = &L->body[d->body];
  if (d->node >= 0 && !emit_node_static(B, d->node)) return 0;
  if (s) *s = d->node >= 0 ? B->flex->node_x + 3 * d->node : d->s;
  return 1;
}

/* 1 if marker k's offset in its body's frame is set at run time
 * (set_params writes markers[k].s) */
static int offset_runtime(const lmodel *L, int k) { return L->marker_runtime && L->marker_runtime[k]; }

/* marker k's offset in its body's frame (a rigid marker: s, or a static
 * node's position): literals, or the symbols markers[k].s[0..2] when the
 * offset is set at run time.  The one place an offset enters the rows'
 * expressions. */
static svec marker_offset(sym_graph *g, const lmodel *L, int k) {
  const double *s = NULL;
  svec v;
  marker_rigid(L, k, &s);
  for (int j = 0; j < 3; j++) v.e[j] = offset_runtime(L, k) ? named(g, "markers[%d].s[%d]", k, j) : lit(g, s[j]);
  return v;
}

static int svec_is_zero(const sym_graph *g, const svec *v) {
  return is_zero(g, v->e[0]) && is_zero(g, v->e[1]) && is_zero(g, v->e[2]);
}

/* mb_marker_rigid's fields, or with point_only only P and V (all a spring
   reads: the axes and the accelerations it never reads are left unset) */
static int marker_rigid_fields(FILE *f, const lmodel *L, int k, int point_only) {
  if (!marker_rigid(L, k, NULL)) return 0;
  const mb_markerdef *d = &L->marker[k];
  int b = d->body;
  sym_graph g;
  rows_graph(&g);
  /* mb_marker_rigid: u = A s, R = A C, P = r + u, V = rd + w x u, W = w,
     aP = w x (w x u), aW = 0 */
  sym_id A[9];
  frame_A(&g, b, A);
  svec Ai[3];
  for (int i = 0; i < 3; i++)
    for (int l = 0; l < 3; l++) Ai[i].e[l] = A[3 * i + l];
  for (int i = 0; i < 3 && !point_only; i++)
    for (int j = 0; j < 3; j++) {
      svec Cj = {{lit(&g, d->C[j]), lit(&g, d->C[3 + j]), lit(&g, d->C[6 + j])}};
      fprintf(f, "  k%d.R[%d] = ", k, 3 * i + j);
      put(f, &g, s_dot(&g, &Ai[i], &Cj));
      fputs(";\n", f);
    }
  svec s = marker_offset(&g, L, k), u;
  for (int i = 0; i < 3; i++) u.e[i] = s_dot(&g, &Ai[i], &s);
  if (!svec_is_zero(&g, &u)) {
    fputs("  {\n    mb_real u[3] = ", f);
    init3(f, &g, &u);
    fputs(", wu[3];\n", f);
    fprintf(f, "    mb_cross3(f%d.w, u, wu);\n", b);
    if (!point_only) fprintf(f, "    mb_cross3(f%d.w, wu, k%d.aP);\n", b, k);
    for (int i = 0; i < 3; i++)
      fprintf(f, "    k%d.P[%d] = f%d.r[%d] + u[%d];\n    k%d.V[%d] = f%d.rd[%d] + wu[%d];\n", k, i, b,
              i, i, k, i, b, i, i);
    fputs("  }\n", f);
  } else {
    for (int i = 0; i < 3; i++) {
      fprintf(f, "  k%d.P[%d] = f%d.r[%d];\n  k%d.V[%d] = f%d.rd[%d];\n", k, i, b, i, k, i, b, i);
      if (!point_only) fprintf(f, "  k%d.aP[%d] = 0;\n", k, i);
    }
  }
  for (int i = 0; i < 3 && !point_only; i++)
    fprintf(f, "  k%d.W[%d] = f%d.w[%d];\n  k%d.aW[%d] = 0;\n", k, i, b, i, k, i);
  return rows_graph_done(&g) ? -1 : 1;
}

int emit_marker_node_twin(const lmodel *L, int k, const char *computed) {
  const mb_markerdef *d = &L->marker[k];
  if (d->body < 0 || d->node < 0 || emit_node_static(&L->body[d->body], d->node)) return -1;
  for (int j = 0; j < k; j++) {
    const mb_markerdef *e = &L->marker[j];
    if (computed[j] && e->body == d->body && e->node == d->node && !memcmp(e->C, d->C, sizeof d->C)) return j;
  }
  return -1;
}

int emit_marker_special(FILE *f, const lmodel *L, int k) { return marker_rigid_fields(f, L, k, 0); }

int emit_marker_point_velocity(FILE *f, const lmodel *L, int k) { return marker_rigid_fields(f, L, k, 1); }

/* marker k on a flexible node (mb_marker_node): the node's modal sums with
 * its shapes as constants (zeros dropped, the kernel's order kept), then
 * mb_marker_node_sums */
int emit_marker_node(FILE *f, const lmodel *L, int k) {
  const mb_markerdef *d = &L->marker[k];
  const mb_body *B = &L->body[d->body];
  const mb_flex *fx = B->flex;
  int nm = fx->nm, node = d->node;
  const double *X = fx->node_X + 3 * node * nm, *Psi = fx->node_Psi + 3 * node * nm;
  sym_graph g;
  rows_graph(&g);
  fputs("  {\n    mb_real b[3], th[3], thd[3], Xwd[3];\n", f);
  const char *nmv[4] = {"b", "th", "thd", "Xwd"};
  for (int s = 0; s < 4; s++) {
    const double *T = (s == 0 || s == 3) ? X : Psi;
    int qa = (s == 0 || s == 1) ? B->qadr + 7 : B->vadr + 6;
    const char *arr = (s == 0 || s == 1) ? "q" : "v";
    for (int i = 0; i < 3; i++) {
      sym_id sum = lit(&g, 0);
      for (int j = 0; j <= nm; j++) {
        sym_id c;
        if (j < nm) c = sym_mul(&g, lit(&g, T[3 * j + i]), named(&g, "%s[%d]", arr, qa + j));
        else if (s == 0) c = lit(&g, fx->node_x[3 * node + i]);
        else break;
        sum = sym_add(&g, sum, c); /* a zero term drops */
      }
      fprintf(f, "    %s[%d] = ", nmv[s], i);
      put(f, &g, sum);
      fputs(";\n", f);
    }
  }
  static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  fprintf(f, "    mb_marker_node_sums(&f%d, b, th, thd, Xwd, ", d->body);
  if (!memcmp(d->C, I, sizeof I)) /* the node's own axes: no product with C */
    fputs("NULL", f);
  else {
    fputs("(const mb_real[9]){", f);
    for (int i = 0; i < 9; i++) {
      if (i) fputs(", ", f);
      put(f, &g, lit(&g, d->C[i]));
    }
    fputc('}', f);
  }
  fprintf(f, ", &k%d);\n  }\n", k);
  return rows_graph_done(&g);
}

/* The modal columns of mb_node_cols_mk at marker k (a flexible node) for the
 * direction (dV, dW): X_j . lV + Psi_j . JtW, lV = A^T dV, JtW = Jl^T A^T dW,
 * with the node's shapes as constants.  A zero dV or dW (a coincident-point
 * row has no dW, an axis row and a force no dV or no dW) drops its half: the
 * kernel multiplied those zeros at run time.  lV, lW and JtW become locals
 * (their names end in 'sfx'); modal[j] is column 6 + j. */
static void node_modal_cols(FILE *f, sym_graph *g, const lmodel *L, int k, const svec *dV, const svec *dW,
                            const char *sfx, const char *indent, sym_id *modal) {
  const mb_markerdef *d = &L->marker[k];
  const mb_flex *fx = L->body[d->body].flex;
  int nm = fx->nm;
  const double *X = fx->node_X + 3 * d->node * nm, *Psi = fx->node_Psi + 3 * d->node * nm;
  sym_id A[9], Jl[9];
  char nv[16];
  frame_A(g, d->body, A);
  for (int i = 0; i < 9; i++) Jl[i] = named(g, "k%d.Jl[%d]", k, i);
  svec lV = s_mul3t(g, A, dV), lW = s_mul3t(g, A, dW);
  snprintf(nv, sizeof nv, "lV%s", sfx);
  s_local(f, g, &lV, nv, indent);
  snprintf(nv, sizeof nv, "lW%s", sfx);
  s_local(f, g, &lW, nv, indent);
  svec JtW = s_mul3t(g, Jl, &lW);
  snprintf(nv, sizeof nv, "JtW%s", sfx);
  s_local(f, g, &JtW, nv, indent);
  for (int j = 0; j < nm; j++) {
    svec xj, pj;
    for (int i = 0; i < 3; i++) {
      xj.e[i] = lit(g, X[3 * j + i]);
      pj.e[i] = lit(g, Psi[3 * j + i]);
    }
    modal[j] = sym_add(g, s_dot(g, &xj, &lV), s_dot(g, &pj, &JtW));
  }
}

/* the 3-vector named 'name' of the generated code (the force elements pass a
 * zero force or moment as zero3: constant zeros) */
static svec arg_vec(sym_graph *g, const char *name) {
  if (!strcmp(name, "zero3")) return s_zero(g);
  svec v;
  for (int i = 0; i < 3; i++) v.e[i] = named(g, "%s[%d]", name, i);
  return v;
}

int emit_node_cols(FILE *f, const lmodel *L, int k, const char *dV, const char *dW, const char *indent) {
  const mb_markerdef *d = &L->marker[k];
  int nm = L->body[d->body].flex->nm;
  sym_graph g;
  rows_graph(&g);
  char in2[32];
  snprintf(in2, sizeof in2, "%s  ", indent);
  fprintf(f, "%s{ /* mb_node_cols_mk, node %d's shapes as constants */\n", indent, d->node);
  fprintf(f, "%smb_rigid_cols(&f%d, k%d.P, %s, %s, c);\n", in2, d->body, k, dV, dW);
  svec v = arg_vec(&g, dV), w = arg_vec(&g, dW);
  sym_id *modal = malloc(sizeof *modal * (size_t)(nm ? nm : 1));
  if (!modal) g.failed = 1;
  else {
    node_modal_cols(f, &g, L, k, &v, &w, "", in2, modal);
    for (int j = 0; j < nm; j++) {
      fprintf(f, "%sc[%d] = ", in2, 6 + j);
      put(f, &g, modal[j]);
      fputs(";\n", f);
    }
    free(modal);
  }
  fprintf(f, "%s}\n", indent);
  return rows_graph_done(&g);
}

/* what the rows know of marker k: its fields as expressions, zeros folded */
typedef struct {
  svec P, V, W, aP, aW;
  sym_id R[9];
  int rigid;   /* rigid body (or static node): columns by mb_rigid_cols */
  int at_origin; /* rigid with a zero offset: P = r exactly */
} smark;

/* marker k is its body's frame: on a rigid body (or a static node) at the
 * frame's origin with the frame's axes, so P = r, V = rd, W = w, R = A and
 * aP = aW = 0 exactly; rows read the frame itself */
static int frame_axes(const lmodel *L, int k);

int emit_marker_is_frame(const lmodel *L, int k) {
  const double *s;
  if (frame_axes(L, k) < 0 || !marker_rigid(L, k, &s)) return 0;
  if (offset_runtime(L, k)) return 0;
  return s[0] == 0 && s[1] == 0 && s[2] == 0;
}

static void mark_view(sym_graph *g, const lmodel *L, int k, smark *m) {
  const mb_markerdef *d = &L->marker[k];
  memset(m, 0, sizeof *m);
  if (d->body < 0) {
    for (int i = 0; i < 3; i++) /* a ground marker's point: set at run time, or literal */
      m->P.e[i] = offset_runtime(L, k) ? named(g, "markers[%d].s[%d]", k, i) : lit(g, d->s[i]);
    for (int i = 0; i < 9; i++) m->R[i] = lit(g, d->C[i]);
    m->V = m->W = m->aP = m->aW = s_zero(g);
    return;
  }
  if (emit_marker_is_frame(L, k)) {
    int b = d->body;
    m->P = s_names(g, "f%d.r", b);
    m->V = s_names(g, "f%d.rd", b);
    m->W = s_names(g, "f%d.w", b);
    m->aP = m->aW = s_zero(g);
    frame_A(g, b, m->R);
    m->rigid = m->at_origin = 1;
    return;
  }
  m->P = s_names(g, "k%d.P", k);
  m->V = s_names(g, "k%d.V", k);
  m->W = s_names(g, "k%d.W", k);
  m->aP = s_names(g, "k%d.aP", k);
  m->aW = s_names(g, "k%d.aW", k);
  for (int i = 0; i < 9; i++) m->R[i] = named(g, "k%d.R[%d]", k, i);
  if (marker_rigid(L, k, NULL)) {
    m->rigid = 1;
    m->aW = s_zero(g);
    svec s = marker_offset(g, L, k);
    if (svec_is_zero(g, &s)) {
      m->at_origin = 1;
      m->aP = s_zero(g);
    }
  }
}

/* dV0.a0 + dW0.b0 + dV1.a1 + dW1.b1, summed left to right as mb_row_phidot and
 * mb_row_gamma do (a, b: the markers' V, W or aP, aW) */
static sym_id s_row_sum(sym_graph *g, const svec dV[2], const svec dW[2], const svec *a0, const svec *b0,
                        const svec *a1, const svec *b1) {
  sym_id o = s_dot(g, &dV[0], a0);
  o = sym_add(g, o, s_dot(g, &dW[0], b0));
  o = sym_add(g, o, s_dot(g, &dV[1], a1));
  return sym_add(g, o, s_dot(g, &dW[1], b1));
}

int emit_row_side_varies(const lmodel *L, int r, int s) {
  const mb_rowdef *R = &L->row[r];
  if (L->marker[s ? R->m1 : R->m0].body < 0) return 0;
  if (R->mslot[s] >= 0) return 1;
  for (int j = 0; j < 6; j++)
    if (R->slot[s][j] >= 0 && !R->constant[s][j]) return 1;
  return 0;
}

/* row r's stores through marker s, the body columns c[0..5] nodes of g */
static void row_stores(FILE *f, const sym_graph *g, const lmodel *L, int r, int s, const sym_id c[6],
                       const sym_id *modal, const char *indent) {
  const mb_rowdef *R = &L->row[r];
  int k = s ? R->m1 : R->m0;
  const mb_body *B = &L->body[L->marker[k].body];
  for (int j = 0; j < 6; j++)
    if (R->slot[s][j] >= 0 && !R->constant[s][j]) {
      fprintf(f, "%sKx[%d] = Kx[%d] = ", indent, R->slot[s][j], R->slotT[s][j]);
      put(f, g, c[j]);
      fputs(";\n", f);
    }
  if (R->mslot[s] < 0) return;
  int stat = marker_rigid(L, k, NULL);
  const int *ms = L->modal_slot + R->mslot[s];
  for (int j = 0; j < B->nm; j++)
    if (ms[j] >= 0 && stat) fprintf(f, "%sKx[%d] = Kx[%d] = 0;\n", indent, ms[j], ms[B->nm + j]);
    else if (ms[j] >= 0 && modal) {
      fprintf(f, "%sKx[%d] = Kx[%d] = ", indent, ms[j], ms[B->nm + j]);
      put(f, g, modal[j]);
      fputs(";\n", f);
    } else if (ms[j] >= 0)
      fprintf(f, "%sKx[%d] = Kx[%d] = c[%d];\n", indent, ms[j], ms[B->nm + j], 6 + j);
}

int emit_row_stores(FILE *f, const lmodel *L, int r, int s, const char *const c[6], const char *indent) {
  sym_graph g;
  rows_graph(&g);
  sym_id cs[6];
  for (int j = 0; j < 6; j++) cs[j] = sym_symbol(&g, c[j]);
  row_stores(f, &g, L, r, s, cs, NULL, indent);
  return rows_graph_done(&g);
}

/* a row's phi, phid, gamma and its entries of D (both triangles of K), from
 * the row's d(phidot)/dV, d(phidot)/dW of each marker, its quadratic term and
 * nu, as mb_row_phidot, mb_row_gamma and mb_rigid_cols / mb_node_cols_mk */
static void emit_row_common(FILE *f, sym_graph *g, const lmodel *L, int r, const smark mk[2], const svec dV[2],
                            const svec dW[2], sym_id quad) {
  const mb_model *m = &L->m;
  const mb_rowdef *R = &L->row[r];
  /* phid = dV0.V0 + dW0.W0 + dV1.V1 + dW1.W1 - nu (nu = 0: no driver) */
  fprintf(f, "    phid[%d] = ", r);
  put(f, g, s_row_sum(g, dV, dW, &mk[0].V, &mk[0].W, &mk[1].V, &mk[1].W));
  fputs(";\n", f);
  /* gamma = -(dV0.aP0 + dW0.aW0 + dV1.aP1 + dW1.aW1 + quad) */
  sym_id t = s_row_sum(g, dV, dW, &mk[0].aP, &mk[0].aW, &mk[1].aP, &mk[1].aW);
  fprintf(f, "    rhs[%d] = ", m->nv + r);
  put(f, g, sym_neg(g, sym_add(g, t, quad)));
  fputs(";\n", f);
  for (int s = 0; s < 2; s++) {
    int k = s ? R->m1 : R->m0, b = L->marker[k].body;
    if (!emit_row_side_varies(L, r, s)) continue;
    /* mb_rigid_cols: [dV; A^T ((P - r) x dV + dW)], on a flexible node too
       (mb_node_cols_mk) with its modal columns after them */
    sym_id c[6], modal[MB_MAX_MODES];
    sym_id A[9];
    frame_A(g, b, A);
    svec u = s_zero(g);
    if (!mk[s].at_origin)
      for (int i = 0; i < 3; i++) u.e[i] = sym_sub(g, mk[s].P.e[i], named(g, "f%d.r[%d]", b, i));
    svec x = s_cross(g, &u, &dV[s]);
    for (int i = 0; i < 3; i++) x.e[i] = sym_add(g, x.e[i], dW[s].e[i]);
    s_local(f, g, &x, s ? "t1" : "t0", "    ");
    svec a = s_mul3t(g, A, &x);
    for (int i = 0; i < 3; i++) {
      c[i] = dV[s].e[i];
      c[3 + i] = a.e[i];
    }
    if (!mk[s].rigid) node_modal_cols(f, g, L, k, &dV[s], &dW[s], s ? "1" : "0", "    ", modal);
    row_stores(f, g, L, r, s, c, mk[s].rigid ? NULL : modal, "    ");
  }
}

/* --- dot-1 rows between two bodies' own axes ------------------------------
 * When both markers of a dot-1 row take their axes from their bodies' frames
 * (rigid body or static node, C = I), the row is a function of the relative
 * rotation Rr = A0^T A1 (Rr[k][l] = a0k . a1l) and the body-axes angular
 * velocities w0', w1'.  For axis i of body 0 and axis j of body 1, with A0 and
 * A1 proper rotations (A^T (u x v) = A^T u x A^T v):
 *   phi = Rr[i][j],
 *   columns  c0 = A0^T (a0i x a1j) = e_i x Rr[:, j],
 *            c1 = -A1^T (a0i x a1j) = e_j x Rr[i, :],
 *   phid = c0 . w0' + c1 . w1',
 *   s00 = W0 . a0i = w0'_i, s01 = W0 . a1j = w0' . Rr[:, j],
 *   s10 = W1 . a0i = w1' . Rr[i, :], s11 = W1 . a1j = w1'_j,
 * and mb_prim_dot1's quad from these.  The entries of Rr and |W0 - W1|^2 are
 * shared by all such rows between the same two bodies (a weld's three, a
 * revolute's two): about a third of the kernel's flops.  The numbers equal the
 * kernel's up to rounding (A is orthonormal to rounding: mb_euler_to_A
 * normalizes); test_generic and test_ldl compare the two paths. */

/* body whose frame gives marker k its axes (on a body, rigid or a static
 * node, C = I), or -1 */
static int frame_axes(const lmodel *L, int k) {
  static const double I[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const mb_markerdef *d = &L->marker[k];
  if (d->body < 0 || !marker_rigid(L, k, NULL)) return -1;
  for (int i = 0; i < 9; i++)
    if (d->C[i] != I[i]) return -1;
  return d->body;
}

static int dot1_frames(const lmodel *L, int r, int *b0, int *b1) {
  const mb_rowdef *R = &L->row[r];
  if (R->kind != MB_PRIM_DOT1) return 0;
  *b0 = frame_axes(L, R->m0);
  *b1 = frame_axes(L, R->m1);
  return *b0 >= 0 && *b1 >= 0 && *b0 != *b1;
}

/* entry (k, l) of the relative rotation of bodies b0 and b1 (a local of emit_rows_shared) */
static sym_id rel(sym_graph *g, int b0, int b1, int k, int l) { return named(g, "rr%d_%d_%d%d", b0, b1, k, l); }

/* a dot-1 row of a pair of body frames: the pair first, for the sort */
typedef struct { int b0, b1, r; } frame_pair_row;

static int frame_pair_cmp(const void *x, const void *y) {
  const frame_pair_row *a = x, *b = y;
  if (a->b0 != b->b0) return a->b0 < b->b0 ? -1 : 1;
  if (a->b1 != b->b1) return a->b1 < b->b1 ? -1 : 1;
  return a->r < b->r ? -1 : a->r > b->r;
}

int emit_rows_shared(FILE *f, const lmodel *L, const unsigned char *skip) {
  const mb_model *m = &L->m;
  /* the rows grouped by pair, pairs in (b0, b1) order: one pass and a sort,
     not a pass over the rows for every pair of bodies (cubic in a chain) */
  frame_pair_row *pr = malloc(sizeof *pr * ((size_t)m->nrow + 1));
  int npr = 0;
  if (!pr) return -1; /* the caller reports it (no exit in library code) */
  for (int r = 0; r < m->nrow; r++) {
    int x0, x1;
    if (skip && skip[r]) continue;
    if (dot1_frames(L, r, &x0, &x1)) pr[npr++] = (frame_pair_row){x0, x1, r};
  }
  qsort(pr, (size_t)npr, sizeof *pr, frame_pair_cmp);
  for (int first = 0, last; first < npr; first = last) {
    int b0 = pr[first].b0, b1 = pr[first].b1, need[9] = {0};
    for (last = first; last < npr && pr[last].b0 == b0 && pr[last].b1 == b1; last++) {
      int i = L->row[pr[last].r].a, j = L->row[pr[last].r].b;
      for (int k = 0; k < 3; k++) need[3 * k + j] = need[3 * i + k] = 1; /* column j, row i */
    }
    fprintf(f, "  /* relative rotation A0^T A1 of body '%s' to body '%s' (the entries its dot-1 rows\n"
               "     use) and |w0 - w1|^2 */\n", L->body[b0].name, L->body[b1].name);
    for (int k = 0; k < 3; k++)
      for (int l = 0; l < 3; l++) {
        if (!need[3 * k + l]) continue;
        fprintf(f, "  const mb_real rr%d_%d_%d%d = f%d.A[%d] * f%d.A[%d] + f%d.A[%d] * f%d.A[%d] + f%d.A[%d] * f%d.A[%d];\n",
                b0, b1, k, l, b0, k, b1, l, b0, 3 + k, b1, 3 + l, b0, 6 + k, b1, 6 + l);
      }
    fprintf(f, "  mb_real dd%d_%d;\n  {\n    mb_real dw[3] = {f%d.w[0] - f%d.w[0], f%d.w[1] - f%d.w[1], f%d.w[2] - f%d.w[2]};\n"
               "    dd%d_%d = dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2];\n  }\n",
            b0, b1, b0, b1, b0, b1, b0, b1, b0, b1);
  }
  free(pr);
  return 0;
}

static void emit_dot1_frames(FILE *f, sym_graph *g, const lmodel *L, int r, int b0, int b1) {
  const mb_rowdef *R = &L->row[r];
  int i = R->a, j = R->b;
  svec colj, rowi, ei = s_zero(g), ej = s_zero(g);
  for (int k = 0; k < 3; k++) {
    colj.e[k] = rel(g, b0, b1, k, j);
    rowi.e[k] = rel(g, b0, b1, i, k);
  }
  ei.e[i] = ej.e[j] = lit(g, 1);
  svec c0 = s_cross(g, &ei, &colj), c1 = s_cross(g, &ej, &rowi);
  svec wl0 = s_names(g, "f%d.wl", b0), wl1 = s_names(g, "f%d.wl", b1);
  fprintf(f, "  { /* from the relative rotation of bodies '%s' and '%s' */\n", L->body[b0].name, L->body[b1].name);
  fprintf(f, "    phi[%d] = ", r);
  put(f, g, rowi.e[j]);
  fprintf(f, ";\n    phid[%d] = ", r);
  put(f, g, sym_add(g, s_dot(g, &c0, &wl0), s_dot(g, &c1, &wl1)));
  fputs(";\n    const mb_real s01 = ", f);
  put(f, g, s_dot(g, &wl0, &colj));
  fputs(", s10 = ", f);
  put(f, g, s_dot(g, &wl1, &rowi));
  fputs(";\n", f);
  /* quad = s00 s01 + s11 s10 - 2 s01 s10 - phi |W0 - W1|^2 */
  sym_id s01 = named(g, "s01"), s10 = named(g, "s10");
  sym_id quad = sym_add(g, sym_mul(g, wl0.e[i], s01), sym_mul(g, wl1.e[j], s10));
  quad = sym_sub(g, quad, sym_mul(g, lit(g, 2), sym_mul(g, s01, s10)));
  quad = sym_sub(g, quad, sym_mul(g, rowi.e[j], named(g, "dd%d_%d", b0, b1)));
  fprintf(f, "    rhs[%d] = ", L->m.nv + r);
  put(f, g, sym_neg(g, quad));
  fputs(";\n", f);
  for (int s = 0; s < 2; s++) {
    if (!emit_row_side_varies(L, r, s)) continue;
    const svec *c = s ? &c1 : &c0;
    sym_id zero = lit(g, 0), cs[6] = {zero, zero, zero, c->e[0], c->e[1], c->e[2]};
    row_stores(f, g, L, r, s, cs, NULL, "    ");
  }
  fputs("  }\n", f);
}

int emit_row_is_special(const mb_rowdef *R) { return R->kind == MB_PRIM_SPH || R->kind == MB_PRIM_DOT1; }

int emit_row_special(FILE *f, const lmodel *L, int r) {
  const mb_rowdef *R = &L->row[r];
  if (!emit_row_is_special(R)) return 0;
  sym_graph g;
  rows_graph(&g);
  int b0, b1;
  if (dot1_frames(L, r, &b0, &b1)) {
    emit_dot1_frames(f, &g, L, r, b0, b1);
    return rows_graph_done(&g) ? -1 : 1;
  }
  smark mk[2];
  mark_view(&g, L, R->m0, &mk[0]);
  mark_view(&g, L, R->m1, &mk[1]);
  svec dV[2], dW[2];
  fputs("  {\n", f);
  if (R->kind == MB_PRIM_SPH) {
    /* mb_prim_sph: phi = (P1 - P0)_a, dV0 = -e_a, dV1 = e_a */
    int a = R->a;
    fprintf(f, "    phi[%d] = ", r);
    put(f, &g, sym_sub(&g, mk[1].P.e[a], mk[0].P.e[a]));
    fputs(";\n", f);
    for (int s = 0; s < 2; s++) {
      dV[s] = dW[s] = s_zero(&g);
      dV[s].e[a] = lit(&g, s ? 1 : -1);
    }
    emit_row_common(f, &g, L, r, mk, dV, dW, lit(&g, 0));
  } else {
    /* mb_prim_dot1: phi = ai . aj (ai axis a of marker 0, aj axis b of
       marker 1), dW0 = ai x aj = -dW1, quad = s00 s01 + s11 s10 - 2 s01 s10
       - phi |W0 - W1|^2 (s00 = W0.ai, s01 = W0.aj, s10 = W1.ai, s11 = W1.aj) */
    svec ai, aj, dw;
    sym_id sc[4];
    for (int i = 0; i < 3; i++) {
      ai.e[i] = mk[0].R[3 * i + R->a];
      aj.e[i] = mk[1].R[3 * i + R->b];
    }
    fputs("    const mb_real ph = ", f);
    put(f, &g, s_dot(&g, &ai, &aj));
    fprintf(f, ";\n    phi[%d] = ph;\n", r);
    sym_id ph = named(&g, "ph");
    svec cr = s_cross(&g, &ai, &aj);
    s_local(f, &g, &cr, "cr", "    ");
    for (int k = 0; k < 4; k++) {
      sc[k] = s_dot(&g, &mk[k / 2].W, k % 2 ? &aj : &ai);
      if (is_atom(&g, sc[k])) continue;
      fprintf(f, "    const mb_real s%d%d = ", k / 2, k % 2);
      put(f, &g, sc[k]);
      fputs(";\n", f);
      sc[k] = named(&g, "s%d%d", k / 2, k % 2);
    }
    for (int i = 0; i < 3; i++) dw.e[i] = sym_sub(&g, mk[0].W.e[i], mk[1].W.e[i]);
    s_local(f, &g, &dw, "dw", "    ");
    sym_id quad = sym_add(&g, sym_mul(&g, sc[0], sc[1]), sym_mul(&g, sc[3], sc[2]));
    quad = sym_sub(&g, quad, sym_mul(&g, lit(&g, 2), sym_mul(&g, sc[1], sc[2])));
    quad = sym_sub(&g, quad, sym_mul(&g, ph, s_dot(&g, &dw, &dw)));
    for (int s = 0; s < 2; s++) dV[s] = s_zero(&g);
    dW[0] = cr;
    for (int i = 0; i < 3; i++) dW[1].e[i] = sym_neg(&g, cr.e[i]);
    emit_row_common(f, &g, L, r, mk, dV, dW, quad);
  }
  fputs("  }\n", f);
  return rows_graph_done(&g) ? -1 : 1;
}
