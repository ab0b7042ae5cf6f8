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
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "emit_rows.h"

#define EXPR 640 /* longest expression kept symbolic; longer ones go to locals */

typedef struct { char e[3][EXPR]; } svec;

/* an element of a braced mb_real initializer, converted explicitly when it
 * holds a floating literal (a double: where mb_real is float, C converts the
 * value implicitly, C++ rejects the narrowing in braces); expressions of
 * mb_real variables and integers as they are */
static void init_elem(FILE *f, const char *e) {
  int real_literal = 0;
  for (const char *c = e; *c; c++) {
    int starts = isdigit((unsigned char)*c) &&
                 (c == e || !(isalnum((unsigned char)c[-1]) || c[-1] == '_' || c[-1] == '.' || c[-1] == '['));
    if (!starts) continue;
    const char *t = c;
    while (isalnum((unsigned char)*t) || *t == '.' || ((*t == '-' || *t == '+') && (t[-1] == 'e' || t[-1] == 'E'))) {
      real_literal |= *t == '.' || *t == 'e' || *t == 'E';
      t++;
    }
    c = t - 1;
  }
  if (real_literal) fprintf(f, "(mb_real)(%s)", e);
  else fputs(e, f);
}

/* "{e0, e1, e2}" with init_elem's elements */
static void init3(FILE *f, const svec *v) {
  fputc('{', f);
  for (int i = 0; i < 3; i++) {
    if (i) fputs(", ", f);
    init_elem(f, v->e[i]);
  }
  fputc('}', f);
}

static int is_zero(const char *a) { return !strcmp(a, "0"); }
static int is_one(const char *a) { return !strcmp(a, "1"); }
static int is_mone(const char *a) { return !strcmp(a, "-1"); }
static int is_atom(const char *a) { return !strchr(a, ' '); }

static void lit(char *o, double x) {
  if (x == 0) x = 0; /* no "-0" */
  snprintf(o, EXPR, "%.17g", x);
}

/* an expression that did not fit its buffer becomes a token that no C
 * compiler accepts: the build fails loudly instead of compiling a cut
 * (and possibly still valid) expression */
#define EXPR_TOO_LONG "@mbcc_internal_error_expression_longer_than_EXPR@"
static void checked(char *t, int written) {
  if (written < 0 || written >= EXPR) memcpy(t, EXPR_TOO_LONG, sizeof EXPR_TOO_LONG);
}

static void s_neg(char *o, const char *a) {
  char t[EXPR];
  if (is_zero(a)) checked(t, snprintf(t, sizeof t, "0"));
  else if (is_atom(a) && a[0] == '-') checked(t, snprintf(t, sizeof t, "%s", a + 1));
  else if (is_atom(a)) checked(t, snprintf(t, sizeof t, "-%s", a));
  else checked(t, snprintf(t, sizeof t, "-(%s)", a));
  memcpy(o, t, EXPR);
}

/* o = a * b */
static void s_mul(char *o, const char *a, const char *b) {
  char t[EXPR];
  if (is_zero(a) || is_zero(b)) checked(t, snprintf(t, sizeof t, "0"));
  else if (is_one(a)) checked(t, snprintf(t, sizeof t, "%s", b));
  else if (is_one(b)) checked(t, snprintf(t, sizeof t, "%s", a));
  else if (is_mone(a)) s_neg(t, b);
  else if (is_mone(b)) s_neg(t, a);
  else
    checked(t, snprintf(t, sizeof t, "%s%s%s * %s%s%s", is_atom(a) ? "" : "(", a, is_atom(a) ? "" : ")",
             is_atom(b) ? "" : "(", b, is_atom(b) ? "" : ")"));
  memcpy(o, t, EXPR);
}

/* o = a + b (a's own sum is left-associative: no parentheses needed) */
static void s_add(char *o, const char *a, const char *b) {
  char t[EXPR];
  if (is_zero(b)) checked(t, snprintf(t, sizeof t, "%s", a));
  else if (is_zero(a)) checked(t, snprintf(t, sizeof t, "%s", b));
  else checked(t, snprintf(t, sizeof t, "%s + %s%s%s", a, is_atom(b) ? "" : "(", b, is_atom(b) ? "" : ")"));
  memcpy(o, t, EXPR);
}

/* o = a - b */
static void s_sub(char *o, const char *a, const char *b) {
  char t[EXPR];
  if (is_zero(b)) checked(t, snprintf(t, sizeof t, "%s", a));
  else if (is_zero(a)) s_neg(t, b);
  else checked(t, snprintf(t, sizeof t, "%s - %s%s%s", a, is_atom(b) ? "" : "(", b, is_atom(b) ? "" : ")"));
  memcpy(o, t, EXPR);
}

/* a . b, summed left to right as mb_dot3 */
static void s_dot(char *o, const svec *a, const svec *b) {
  char t[EXPR], p[EXPR];
  s_mul(t, a->e[0], b->e[0]);
  s_mul(p, a->e[1], b->e[1]);
  s_add(t, t, p);
  s_mul(p, a->e[2], b->e[2]);
  s_add(o, t, p);
}

/* a x b as mb_cross3 */
static void s_cross(svec *o, const svec *a, const svec *b) {
  svec t;
  char p[EXPR], q[EXPR];
  for (int i = 0; i < 3; i++) {
    int j = (i + 1) % 3, k = (i + 2) % 3;
    s_mul(p, a->e[j], b->e[k]);
    s_mul(q, a->e[k], b->e[j]);
    s_sub(t.e[i], p, q);
  }
  *o = t;
}

/* A^T x (A row-major, 9 expressions) as mb_mul3t */
static void s_mul3t(svec *o, char A[9][EXPR], const svec *x) {
  svec t;
  char p[EXPR];
  for (int i = 0; i < 3; i++) {
    s_mul(t.e[i], A[i], x->e[0]);
    s_mul(p, A[3 + i], x->e[1]);
    s_add(t.e[i], t.e[i], p);
    s_mul(p, A[6 + i], x->e[2]);
    s_add(t.e[i], t.e[i], p);
  }
  *o = t;
}

static void s_names(svec *o, const char *fmt, int a) {
  for (int i = 0; i < 3; i++) {
    char base[64];
    snprintf(base, sizeof base, fmt, a);
    snprintf(o->e[i], EXPR, "%s[%d]", base, i);
  }
}

static void s_zero(svec *o) {
  for (int i = 0; i < 3; i++) snprintf(o->e[i], EXPR, "0");
}

/* declare a local 'name' for the entries of v that are not atoms; they become
 * name[i] (an entry that is zero or an atom stays as it is) */
static void s_local(FILE *f, svec *v, const char *name, const char *indent) {
  int need = 0;
  for (int i = 0; i < 3; i++) need |= !is_atom(v->e[i]);
  if (!need) return;
  fprintf(f, "%smb_real %s[3] = ", indent, name);
  init3(f, v);
  fputs(";\n", f);
  for (int i = 0; i < 3; i++)
    if (!is_atom(v->e[i])) snprintf(v->e[i], EXPR, "%s[%d]", name, i);
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

int emit_marker_special(FILE *f, const lmodel *L, int k) {
  const double *s;
  if (!marker_rigid(L, k, &s)) return 0;
  const mb_markerdef *d = &L->marker[k];
  const int runtime_s = L->marker_runtime && L->marker_runtime[k]; /* s read from markers[k] (set_params) */
  int b = d->body;
  /* mb_marker_rigid: u = A s, R = A C, P = r + u, V = rd + w x u, W = w,
     aP = w x (w x u), aW = 0 */
  char A[9][EXPR], p[EXPR], c[EXPR];
  for (int i = 0; i < 9; i++) snprintf(A[i], EXPR, "f%d.A[%d]", b, i);
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      char e[EXPR];
      lit(c, d->C[j]);
      s_mul(e, A[3 * i], c);
      lit(c, d->C[3 + j]);
      s_mul(p, A[3 * i + 1], c);
      s_add(e, e, p);
      lit(c, d->C[6 + j]);
      s_mul(p, A[3 * i + 2], c);
      s_add(e, e, p);
      fprintf(f, "  k%d.R[%d] = %s;\n", k, 3 * i + j, e);
    }
  svec u;
  char sj[3][EXPR];
  for (int j = 0; j < 3; j++)
    if (runtime_s) snprintf(sj[j], EXPR, "markers[%d].s[%d]", k, j);
    else lit(sj[j], s[j]);
  for (int i = 0; i < 3; i++) {
    s_mul(u.e[i], A[3 * i], sj[0]);
    s_mul(p, A[3 * i + 1], sj[1]);
    s_add(u.e[i], u.e[i], p);
    s_mul(p, A[3 * i + 2], sj[2]);
    s_add(u.e[i], u.e[i], p);
  }
  int moving = !(is_zero(u.e[0]) && is_zero(u.e[1]) && is_zero(u.e[2]));
  if (moving) {
    fputs("  {\n    mb_real u[3] = ", f);
    init3(f, &u);
    fputs(", wu[3];\n", f);
    fprintf(f, "    mb_cross3(f%d.w, u, wu);\n    mb_cross3(f%d.w, wu, k%d.aP);\n", b, b, k);
    for (int i = 0; i < 3; i++)
      fprintf(f, "    k%d.P[%d] = f%d.r[%d] + u[%d];\n    k%d.V[%d] = f%d.rd[%d] + wu[%d];\n", k, i, b,
              i, i, k, i, b, i, i);
    fputs("  }\n", f);
  } else {
    for (int i = 0; i < 3; i++)
      fprintf(f, "  k%d.P[%d] = f%d.r[%d];\n  k%d.V[%d] = f%d.rd[%d];\n  k%d.aP[%d] = 0;\n", k, i, b,
              i, k, i, b, i, k, i);
  }
  for (int i = 0; i < 3; i++) fprintf(f, "  k%d.W[%d] = f%d.w[%d];\n  k%d.aW[%d] = 0;\n", k, i, b, i, k, i);
  return 1;
}

/* marker k on a flexible node (mb_marker_node): the node's modal sums with
 * its shapes as constants (zeros dropped, the kernel's order kept), then
 * mb_marker_node_sums */
void emit_marker_node(FILE *f, const lmodel *L, int k) {
  const mb_markerdef *d = &L->marker[k];
  const mb_body *B = &L->body[d->body];
  const mb_flex *fx = B->flex;
  int nm = fx->nm, node = d->node;
  const double *X = fx->node_X + 3 * node * nm, *Psi = fx->node_Psi + 3 * node * nm;
  fputs("  {\n    mb_real b[3], th[3], thd[3], Xwd[3];\n", f);
  const char *nmv[4] = {"b", "th", "thd", "Xwd"};
  for (int s = 0; s < 4; s++) {
    const double *T = (s == 0 || s == 3) ? X : Psi;
    int qa = (s == 0 || s == 1) ? B->qadr + 7 : B->vadr + 6;
    const char *arr = (s == 0 || s == 1) ? "q" : "v";
    for (int i = 0; i < 3; i++) {
      /* written term by term (as s_add would join them): a sum over
         hundreds of modes does not fit an expression buffer */
      fprintf(f, "    %s[%d] = ", nmv[s], i);
      int any = 0;
      for (int j = 0; j <= nm; j++) {
        char c[EXPR], x[EXPR];
        if (j < nm) {
          lit(c, T[3 * j + i]);
          snprintf(x, sizeof x, "%s[%d]", arr, qa + j);
          s_mul(c, c, x);
        } else if (s == 0) lit(c, fx->node_x[3 * node + i]);
        else break;
        if (is_zero(c)) continue;
        if (!any) fputs(c, f);
        else fprintf(f, " + %s%s%s", is_atom(c) ? "" : "(", c, is_atom(c) ? "" : ")");
        any = 1;
      }
      fprintf(f, "%s;\n", any ? "" : "0");
    }
  }
  fprintf(f, "    mb_marker_node_sums(&f%d, b, th, thd, Xwd, (const mb_real[9]){", d->body);
  for (int i = 0; i < 9; i++) {
    char c[EXPR];
    lit(c, d->C[i]);
    fprintf(f, "%s%s", i ? ", " : "", c);
  }
  fprintf(f, "}, &k%d);\n  }\n", k);
}

void emit_node_cols(FILE *f, const lmodel *L, int k, const char *dV, const char *dW, const char *indent) {
  const mb_markerdef *d = &L->marker[k];
  const mb_flex *fx = L->body[d->body].flex;
  int nm = fx->nm;
  const double *X = fx->node_X + 3 * d->node * nm, *Psi = fx->node_Psi + 3 * d->node * nm;
  fprintf(f, "%s{ /* mb_node_cols_mk, node %d's shapes as constants */\n", indent, d->node);
  fprintf(f, "%s  mb_real lV[3], JtW[3];\n", indent);
  fprintf(f, "%s  mb_node_cols_local(&f%d, &k%d, %s, %s, c, lV, JtW);\n", indent, d->body, k, dV, dW);
  svec lv, jw;
  for (int i = 0; i < 3; i++) {
    snprintf(lv.e[i], EXPR, "lV[%d]", i);
    snprintf(jw.e[i], EXPR, "JtW[%d]", i);
  }
  for (int j = 0; j < nm; j++) {
    svec xj, pj;
    char a[EXPR], b[EXPR];
    for (int i = 0; i < 3; i++) {
      lit(xj.e[i], X[3 * j + i]);
      lit(pj.e[i], Psi[3 * j + i]);
    }
    s_dot(a, &xj, &lv);
    s_dot(b, &pj, &jw);
    s_add(a, a, b);
    fprintf(f, "%s  c[%d] = %s;\n", indent, 6 + j, a);
  }
  fprintf(f, "%s}\n", indent);
}

/* what the rows know of marker k: its fields as expressions, zeros folded */
typedef struct {
  svec P, V, W, aP, aW;
  char R[9][EXPR];
  int rigid;   /* rigid body (or static node): columns by mb_rigid_cols */
  int at_origin; /* rigid and s = 0: P = r exactly */
} smark;

/* marker k is its body's frame: on a rigid body (or a static node) at the
 * frame's origin with the frame's axes, so P = r, V = rd, W = w, R = A and
 * aP = aW = 0 exactly; rows read the frame itself */
static int frame_axes(const lmodel *L, int k);

int emit_marker_is_frame(const lmodel *L, int k) {
  const double *s;
  if (frame_axes(L, k) < 0 || !marker_rigid(L, k, &s)) return 0;
  if (L->marker_runtime && L->marker_runtime[k]) return 0; /* its offset is set at run time */
  return s[0] == 0 && s[1] == 0 && s[2] == 0;
}

static void mark_view(const lmodel *L, int k, smark *m) {
  const mb_markerdef *d = &L->marker[k];
  const double *s = NULL;
  memset(m, 0, sizeof *m);
  if (d->body < 0) {
    for (int i = 0; i < 3; i++) lit(m->P.e[i], d->s[i]);
    for (int i = 0; i < 9; i++) lit(m->R[i], d->C[i]);
    s_zero(&m->V); s_zero(&m->W); s_zero(&m->aP); s_zero(&m->aW);
    return;
  }
  if (emit_marker_is_frame(L, k)) {
    int b = d->body;
    s_names(&m->P, "f%d.r", b);
    s_names(&m->V, "f%d.rd", b);
    s_names(&m->W, "f%d.w", b);
    s_zero(&m->aP);
    s_zero(&m->aW);
    for (int i = 0; i < 9; i++) snprintf(m->R[i], EXPR, "f%d.A[%d]", b, i);
    m->rigid = m->at_origin = 1;
    return;
  }
  s_names(&m->P, "k%d.P", k);
  s_names(&m->V, "k%d.V", k);
  s_names(&m->W, "k%d.W", k);
  s_names(&m->aP, "k%d.aP", k);
  s_names(&m->aW, "k%d.aW", k);
  for (int i = 0; i < 9; i++) snprintf(m->R[i], EXPR, "k%d.R[%d]", k, i);
  if (marker_rigid(L, k, &s)) {
    m->rigid = 1;
    s_zero(&m->aW);
    if (s[0] == 0 && s[1] == 0 && s[2] == 0 && !(L->marker_runtime && L->marker_runtime[k])) {
      m->at_origin = 1;
      s_zero(&m->aP);
    }
  }
}

/* dV0.a0 + dW0.b0 + dV1.a1 + dW1.b1, summed left to right as mb_row_phidot and
 * mb_row_gamma do (a, b: the markers' V, W or aP, aW) */
static void s_row_sum(char *o, const svec dV[2], const svec dW[2], const svec *a0, const svec *b0,
                      const svec *a1, const svec *b1) {
  char p[EXPR];
  s_dot(o, &dV[0], a0);
  s_dot(p, &dW[0], b0);
  s_add(o, o, p);
  s_dot(p, &dV[1], a1);
  s_add(o, o, p);
  s_dot(p, &dW[1], b1);
  s_add(o, o, p);
}

int emit_row_side_varies(const lmodel *L, int r, int s) {
  const mb_rowdef *R = &L->row[r];
  if (L->marker[s ? R->m1 : R->m0].body < 0) return 0;
  if (R->mslot[s] >= 0) return 1;
  for (int j = 0; j < 6; j++)
    if (R->slot[s][j] >= 0 && !R->constant[s][j]) return 1;
  return 0;
}

void emit_row_stores(FILE *f, const lmodel *L, int r, int s, const char *const c[6], const char *indent) {
  const mb_rowdef *R = &L->row[r];
  int k = s ? R->m1 : R->m0;
  const mb_body *B = &L->body[L->marker[k].body];
  for (int j = 0; j < 6; j++)
    if (R->slot[s][j] >= 0 && !R->constant[s][j])
      fprintf(f, "%sKx[%d] = Kx[%d] = %s;\n", indent, R->slot[s][j], R->slotT[s][j], c[j]);
  if (R->mslot[s] < 0) return;
  int stat = marker_rigid(L, k, NULL);
  const int *ms = L->modal_slot + R->mslot[s];
  for (int j = 0; j < B->nm; j++)
    if (ms[j] >= 0 && stat) fprintf(f, "%sKx[%d] = Kx[%d] = 0;\n", indent, ms[j], ms[B->nm + j]);
    else if (ms[j] >= 0) fprintf(f, "%sKx[%d] = Kx[%d] = c[%d];\n", indent, ms[j], ms[B->nm + j], 6 + j);
}

/* a row's phi, phid, gamma and its entries of D (both triangles of K), from
 * the row's d(phidot)/dV, d(phidot)/dW of each marker, its quadratic term and
 * nu, as mb_row_phidot, mb_row_gamma and mb_rigid_cols / mb_node_cols_mk */
static void emit_row_common(FILE *f, const lmodel *L, int r, const smark mk[2], svec dV[2], svec dW[2],
                            const char *quad) {
  const mb_model *m = &L->m;
  const mb_rowdef *R = &L->row[r];
  char t[EXPR], p[EXPR];
  /* phid = dV0.V0 + dW0.W0 + dV1.V1 + dW1.W1 - nu (nu = 0: no driver) */
  s_row_sum(t, dV, dW, &mk[0].V, &mk[0].W, &mk[1].V, &mk[1].W);
  fprintf(f, "    phid[%d] = %s;\n", r, t);
  /* gamma = -(dV0.aP0 + dW0.aW0 + dV1.aP1 + dW1.aW1 + quad) */
  s_row_sum(t, dV, dW, &mk[0].aP, &mk[0].aW, &mk[1].aP, &mk[1].aW);
  s_add(t, t, quad);
  s_neg(t, t);
  fprintf(f, "    rhs[%d] = %s;\n", m->nv + r, t);
  for (int s = 0; s < 2; s++) {
    int k = s ? R->m1 : R->m0, b = L->marker[k].body;
    if (!emit_row_side_varies(L, r, s)) continue;
    char c[6][EXPR];
    if (mk[s].rigid) {
      /* mb_rigid_cols: [dV; A^T ((P - r) x dV + dW)] */
      svec u, x;
      char A[9][EXPR];
      for (int i = 0; i < 9; i++) snprintf(A[i], EXPR, "f%d.A[%d]", b, i);
      if (mk[s].at_origin) s_zero(&u);
      else
        for (int i = 0; i < 3; i++) {
          snprintf(p, sizeof p, "f%d.r[%d]", b, i);
          s_sub(u.e[i], mk[s].P.e[i], p);
        }
      s_cross(&x, &u, &dV[s]);
      for (int i = 0; i < 3; i++) s_add(x.e[i], x.e[i], dW[s].e[i]);
      s_local(f, &x, s ? "t1" : "t0", "    ");
      svec a;
      s_mul3t(&a, A, &x);
      for (int i = 0; i < 3; i++) {
        memcpy(c[i], dV[s].e[i], EXPR);
        memcpy(c[3 + i], a.e[i], EXPR);
      }
    } else {
      /* a flexible node: its modal columns too */
      svec v = dV[s], w = dW[s];
      fprintf(f, "    mb_real dV%d[3] = ", s);
      init3(f, &v);
      fprintf(f, ", dW%d[3] = ", s);
      init3(f, &w);
      fputs(";\n", f);
      char nv[16], nw[16];
      snprintf(nv, sizeof nv, "dV%d", s);
      snprintf(nw, sizeof nw, "dW%d", s);
      emit_node_cols(f, L, k, nv, nw, "    ");
      for (int j = 0; j < 6; j++) snprintf(c[j], EXPR, "c[%d]", j);
    }
    const char *cs[6] = {c[0], c[1], c[2], c[3], c[4], c[5]};
    emit_row_stores(f, L, r, s, cs, "    ");
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

static void rel_name(char *o, int b0, int b1, int k, int l) { snprintf(o, EXPR, "rr%d_%d_%d%d", b0, b1, k, l); }

/* a dot-1 row of a pair of body frames: the pair first, for the sort */
typedef struct { int b0, b1, r; } frame_pair_row;

static int frame_pair_cmp(const void *x, const void *y) {
  const frame_pair_row *a = x, *b = y;
  if (a->b0 != b->b0) return a->b0 < b->b0 ? -1 : 1;
  if (a->b1 != b->b1) return a->b1 < b->b1 ? -1 : 1;
  return a->r < b->r ? -1 : a->r > b->r;
}

int emit_rows_shared(FILE *f, const lmodel *L) {
  const mb_model *m = &L->m;
  /* the rows grouped by pair, pairs in (b0, b1) order: one pass and a sort,
     not a pass over the rows for every pair of bodies (cubic in a chain) */
  frame_pair_row *pr = malloc(sizeof *pr * ((size_t)m->nrow + 1));
  int npr = 0;
  if (!pr) return -1; /* the caller reports it (no exit in library code) */
  for (int r = 0; r < m->nrow; r++) {
    int x0, x1;
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
        char nmv[EXPR];
        rel_name(nmv, b0, b1, k, l);
        fprintf(f, "  const mb_real %s = f%d.A[%d] * f%d.A[%d] + f%d.A[%d] * f%d.A[%d] + f%d.A[%d] * f%d.A[%d];\n",
                nmv, b0, k, b1, l, b0, 3 + k, b1, 3 + l, b0, 6 + k, b1, 6 + l);
      }
    fprintf(f, "  mb_real dd%d_%d;\n  {\n    mb_real dw[3] = {f%d.w[0] - f%d.w[0], f%d.w[1] - f%d.w[1], f%d.w[2] - f%d.w[2]};\n"
               "    dd%d_%d = dw[0] * dw[0] + dw[1] * dw[1] + dw[2] * dw[2];\n  }\n",
            b0, b1, b0, b1, b0, b1, b0, b1, b0, b1);
  }
  free(pr);
  return 0;
}

static void emit_dot1_frames(FILE *f, const lmodel *L, int r, int b0, int b1) {
  const mb_rowdef *R = &L->row[r];
  int i = R->a, j = R->b;
  svec colj, rowi, ei, ej, c0, c1, wl0, wl1;
  char t[EXPR], p[EXPR], s01[EXPR], s10[EXPR], quad[EXPR], dd[EXPR];
  for (int k = 0; k < 3; k++) {
    rel_name(colj.e[k], b0, b1, k, j);
    rel_name(rowi.e[k], b0, b1, i, k);
  }
  s_zero(&ei);
  s_zero(&ej);
  snprintf(ei.e[i], EXPR, "1");
  snprintf(ej.e[j], EXPR, "1");
  s_cross(&c0, &ei, &colj);
  s_cross(&c1, &ej, &rowi);
  s_names(&wl0, "f%d.wl", b0);
  s_names(&wl1, "f%d.wl", b1);
  fprintf(f, "  { /* from the relative rotation of bodies '%s' and '%s' */\n", L->body[b0].name, L->body[b1].name);
  fprintf(f, "    phi[%d] = %s;\n", r, rowi.e[j]);
  s_dot(t, &c0, &wl0);
  s_dot(p, &c1, &wl1);
  s_add(t, t, p);
  fprintf(f, "    phid[%d] = %s;\n", r, t);
  s_dot(s01, &wl0, &colj);
  s_dot(s10, &wl1, &rowi);
  fprintf(f, "    const mb_real s01 = %s, s10 = %s;\n", s01, s10);
  /* quad = s00 s01 + s11 s10 - 2 s01 s10 - phi |W0 - W1|^2 */
  snprintf(t, sizeof t, "f%d.wl[%d] * s01 + f%d.wl[%d] * s10 - 2 * (s01 * s10)", b0, i, b1, j);
  snprintf(dd, sizeof dd, "dd%d_%d", b0, b1);
  s_mul(p, rowi.e[j], dd);
  s_sub(quad, t, p);
  s_neg(t, quad);
  fprintf(f, "    rhs[%d] = %s;\n", L->m.nv + r, t);
  for (int s = 0; s < 2; s++) {
    if (!emit_row_side_varies(L, r, s)) continue;
    const svec *c = s ? &c1 : &c0;
    const char *cs[6] = {"0", "0", "0", c->e[0], c->e[1], c->e[2]};
    emit_row_stores(f, L, r, s, cs, "    ");
  }
  fputs("  }\n", f);
}

int emit_row_is_special(const mb_rowdef *R) { return R->kind == MB_PRIM_SPH || R->kind == MB_PRIM_DOT1; }

int emit_row_special(FILE *f, const lmodel *L, int r) {
  const mb_rowdef *R = &L->row[r];
  if (!emit_row_is_special(R)) return 0;
  int b0, b1;
  if (dot1_frames(L, r, &b0, &b1)) {
    emit_dot1_frames(f, L, r, b0, b1);
    return 1;
  }
  smark mk[2];
  mark_view(L, R->m0, &mk[0]);
  mark_view(L, R->m1, &mk[1]);
  svec dV[2], dW[2];
  char t[EXPR];
  fputs("  {\n", f);
  if (R->kind == MB_PRIM_SPH) {
    /* mb_prim_sph: phi = (P1 - P0)_a, dV0 = -e_a, dV1 = e_a */
    int a = R->a;
    s_sub(t, mk[1].P.e[a], mk[0].P.e[a]);
    fprintf(f, "    phi[%d] = %s;\n", r, t);
    for (int s = 0; s < 2; s++) {
      s_zero(&dV[s]);
      s_zero(&dW[s]);
      snprintf(dV[s].e[a], EXPR, s ? "1" : "-1");
    }
    emit_row_common(f, L, r, mk, dV, dW, "0");
  } else {
    /* mb_prim_dot1: phi = ai . aj (ai axis a of marker 0, aj axis b of
       marker 1), dW0 = ai x aj = -dW1, quad = s00 s01 + s11 s10 - 2 s01 s10
       - phi |W0 - W1|^2 (s00 = W0.ai, s01 = W0.aj, s10 = W1.ai, s11 = W1.aj) */
    svec ai, aj, cr, dw;
    char p[EXPR], quad[EXPR], ph[EXPR], sc[4][EXPR];
    for (int i = 0; i < 3; i++) {
      memcpy(ai.e[i], mk[0].R[3 * i + R->a], EXPR);
      memcpy(aj.e[i], mk[1].R[3 * i + R->b], EXPR);
    }
    s_dot(t, &ai, &aj);
    fprintf(f, "    const mb_real ph = %s;\n    phi[%d] = ph;\n", t, r);
    snprintf(ph, sizeof ph, "ph");
    s_cross(&cr, &ai, &aj);
    s_local(f, &cr, "cr", "    ");
    for (int k = 0; k < 4; k++) {
      s_dot(sc[k], &mk[k / 2].W, k % 2 ? &aj : &ai);
      if (is_atom(sc[k])) continue;
      fprintf(f, "    const mb_real s%d%d = %s;\n", k / 2, k % 2, sc[k]);
      snprintf(sc[k], EXPR, "s%d%d", k / 2, k % 2);
    }
    for (int i = 0; i < 3; i++) s_sub(dw.e[i], mk[0].W.e[i], mk[1].W.e[i]);
    s_local(f, &dw, "dw", "    ");
    s_mul(quad, sc[0], sc[1]);
    s_mul(p, sc[3], sc[2]);
    s_add(quad, quad, p);
    s_mul(p, sc[1], sc[2]);
    s_mul(p, "2", p);
    s_sub(quad, quad, p);
    s_dot(t, &dw, &dw);
    s_mul(p, ph, t);
    s_sub(quad, quad, p);
    for (int s = 0; s < 2; s++) s_zero(&dV[s]);
    dW[0] = cr;
    for (int i = 0; i < 3; i++) s_neg(dW[1].e[i], cr.e[i]);
    emit_row_common(f, L, r, mk, dV, dW, quad);
  }
  fputs("  }\n", f);
  return 1;
}
