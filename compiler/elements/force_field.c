/* force_field.c: the 6x6 field elements between two markers: the field
 * (general K and C), the bushing (diagonal), the massless beam (its K
 * from the section, C a ratio of it) and the superelement (its K condensed
 * from an FE model, C a ratio of it); one runtime kind, MB_FORCE_FIELD
 * (kernel runtime/core/elements/mb_field.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "element.h"
#include "fe.h"
#include "emit_force.h"
#include "reader.h"
#include "params.h"

/* Six numbers, each >= 0 when 'nonnegative'. */
static void get_six(mapping *m, const char *key, bool required, bool nonnegative, double out[6]) {
  double v[6];
  if (!get_vector(m, key, 6, required, v))
    return;
  yaml_node_t *list = map_get(m, key);
  for (int i = 0; nonnegative && list != NULL && list->type == YAML_SEQUENCE_NODE && i < 6; i++) {
    char label[64];
    snprintf(label, sizeof label, "'%s' entry %d", key, i + 1);
    params_note_rule(m->r, loc_of(yaml_document_get_node(m->r->doc, list->data.sequence.items.start[i])),
                     RULE_NONNEGATIVE, label);
  }
  for (int i = 0; i < 6; i++) {
    if (nonnegative && !(v[i] >= 0)) {
      error_at(m->r, m->last_loc, "'%s': every entry must be >= 0 (entry %d is %g)", key, i + 1,
               v[i]);
      return;
    }
  }
  memcpy(out, v, sizeof v);
}

/* 'axes': rows x, y, z of an orthonormal right-handed frame (global) */
static void parse_axes(mapping *m, ir_force *f) {
  reader *r = m->r;
  yaml_node_t *axes = map_get(m, "axes");
  double rows[9];
  if (axes == NULL || !to_vector_list(r, axes, "'axes'", 3, 3, rows))
    return;
  for (int i = 0; i < 3; i++) {
    for (int k = i; k < 3; k++) {
      double expected = i == k ? 1 : 0;
      if (fabs(dot3(rows + 3 * i, rows + 3 * k) - expected) > ANGLE_TOLERANCE) {
        error_at(r, loc_of(axes),
                 "'axes' must be orthonormal (row %d . row %d = %g, expected %g)", i + 1,
                 k + 1, dot3(rows + 3 * i, rows + 3 * k), expected);
        return;
      }
    }
  }
  double cross_z = rows[0] * rows[4] - rows[1] * rows[3]; /* (x cross y) . z */
  double cross_y = rows[2] * rows[3] - rows[0] * rows[5];
  double cross_x = rows[1] * rows[5] - rows[2] * rows[4];
  if (cross_x * rows[6] + cross_y * rows[7] + cross_z * rows[8] < 0) {
    error_at(r, loc_of(axes), "'axes' must be right-handed (z = x cross y)");
    return;
  }
  memcpy(f->axes, rows, sizeof rows);
}

/* a 6x6 matrix as a list of 6 rows of 6 numbers */
static bool to_matrix6(reader *r, yaml_node_t *n, const char *label, double out[36]) {
  if (n->type != YAML_SEQUENCE_NODE || seq_length(n) != 6) {
    error_at(r, loc_of(n), "%s: expected a 6x6 matrix (a list of 6 rows of 6 numbers)", label);
    return false;
  }
  bool ok = true;
  for (int i = 0; i < 6; i++) {
    char row_label[SHOWN_SIZE];
    snprintf(row_label, sizeof row_label, "row %d of %s", i + 1, label);
    yaml_node_t *row = seq_item(r, n, i);
    if (row->type != YAML_SEQUENCE_NODE || seq_length(row) != 6) {
      error_at(r, loc_of(row), "%s: expected 6 numbers", row_label);
      ok = false;
      continue;
    }
    for (int j = 0; j < 6; j++) {
      char item_label[SHOWN_SIZE + 32];
      snprintf(item_label, sizeof item_label, "element %d of %s", j + 1, row_label);
      ok = to_number(r, seq_item(r, row, j), item_label, &out[6 * i + j]) && ok;
    }
  }
  return ok;
}

/* The kernels apply a field-type element's reaction on side 0 (the wrench at
 * point 1) through body 0's frame as if it were rigid: on an FE node it would
 * miss the flexible body's modes (a conservative bushing gained energy without
 * bound).  Until that side carries node columns, refuse it. */
static void refuse_node_on_side0(mapping *m, const ir_force *f, const char *what) {
  if (f->node[0] < 0) return;
  error_at(m->r, m->loc, "%s: its first body ('bodies'[0]) is on an FE node, where the element's reaction "
           "would act on the body frame and not on the modes; list the flexible body second "
           "(two FE nodes cannot be joined by one %s yet)", what, what);
}

/* 'bodies' and one 'point' for both sides, or the point of the node given
 * ('node' / 'nodes'): a bushing's or a field's */
static void parse_pair_at_point(mapping *m, ir_force *f) {
  reader *r = m->r;
  bool on_nodes = get_body_pair(m, f->body, f->body_loc) && fe_nodes_given(m, f->body, f->node);
  bool given = get_vector(m, "point", 3, !on_nodes, f->point[0]);
  if (given)
    memcpy(f->point[1], f->point[0], sizeof f->point[0]);
  if (on_nodes) {
    check_node_point(r, r->model, m->loc, f->body, f->node, given, &f->point[0][0]);
    if (!given)
      memcpy(f->point[f->node[0] >= 0 ? 1 : 0], f->point[f->node[0] >= 0 ? 0 : 1], sizeof f->point[0]);
  }
  refuse_node_on_side0(m, f, f->kind == FORCE_FIELD ? "field" : "bushing");
}

/* field: a general 6x6 stiffness and damping between two bodies (seed 001 3.2.6) */
static void parse_field(mapping *m, ir_force *f) {
  reader *r = m->r;
  parse_pair_at_point(m, f);
  yaml_node_t *k = map_require(m, "stiffness", true, "a 6x6 matrix");
  if (k != NULL && to_matrix6(r, k, "'stiffness'", f->K))
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < i; j++)
        if (fabs(f->K[6 * i + j] - f->K[6 * j + i]) > 1e-9 * (fabs(f->K[6 * i + j]) + fabs(f->K[6 * j + i]) + 1e-300)) {
          error_at(r, loc_of(k), "field 'stiffness' must be symmetric (row %d, column %d differs from row %d, column %d)", i + 1, j + 1, j + 1, i + 1);
          i = 6;
          break;
        }
  yaml_node_t *c = map_get(m, "damping");
  if (c != NULL) to_matrix6(r, c, "'damping'", f->C);
  get_six(m, "preload", false, false, f->preload6);
  parse_axes(m, f);
}

/* beam: a massless Euler-Bernoulli or Timoshenko beam from point 0 (clamped on
 * body 0) to point 1 (seed 001 3.2.5), damping = damping_ratio * stiffness */
static void parse_beam_force(mapping *m, ir_force *f) {
  reader *r = m->r;
  bool on_nodes = get_body_pair(m, f->body, f->body_loc) && fe_nodes_given(m, f->body, f->node);
  bool all_nodes = f->node[0] >= 0 && f->node[1] >= 0;
  yaml_node_t *points = map_require(m, "points", !all_nodes, "a list of 2 points [x, y, z]");
  bool given = points != NULL && to_vector_list(r, points, "'points'", 2, 3, &f->point[0][0]);
  if (on_nodes)
    check_node_point(r, r->model, points ? loc_of(points) : m->loc, f->body, f->node, given, &f->point[0][0]);
  refuse_node_on_side0(m, f, "beam");
  int th = 0;
  if (get_choice(m, "theory", "beam theory", theory_names, false, &th)) f->beam.theory = (ir_beam_theory)th;
  f->beam.yaxis[1] = 1;
  parse_beam_properties(r, m, &f->beam);
  get_nonnegative(m, "damping_ratio", false, &f->damping_ratio);
  double x[3];
  for (int i = 0; i < 3; i++) x[i] = f->point[1][i] - f->point[0][i];
  double len = norm3(x);
  if ((given || all_nodes) && !(len > ZERO_LENGTH)) {
    error_at(r, points ? loc_of(points) : m->loc, "beam end points coincide (a beam needs a length)");
    return;
  }
  if (!(len > ZERO_LENGTH)) return;
  scale3(x, 1 / len);
  /* the section's y axis across the beam: given, else global y (global z for a beam along y) */
  double y[3];
  memcpy(y, f->beam.yaxis, sizeof y);
  if (fabs(dot3(x, y)) > 0.9) { y[0] = y[1] = 0; y[2] = 1; }
  double along = dot3(x, y);
  for (int i = 0; i < 3; i++) y[i] -= along * x[i];
  if (!(norm3(y) > 1e-6)) {
    error_at(r, m->loc, "the beam's section 'yaxis' is parallel to the beam");
    return;
  }
  scale3(y, 1 / norm3(y));
  double z[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
  memcpy(f->axes, x, sizeof x);
  memcpy(f->axes + 3, y, sizeof y);
  memcpy(f->axes + 6, z, sizeof z);
}

/* 'bodies' of a superelement with more than two nodes: n names, one per
 * interface node (body 0 holds node 0) */
static bool get_super_bodies(mapping *m, ir_force *f, int n) {
  reader *r = m->r;
  yaml_node_t *list = map_get(m, "bodies");
  if (list == NULL || list->type != YAML_SEQUENCE_NODE || seq_length(list) != n) {
    error_at(r, list ? loc_of(list) : m->loc, "'bodies': a superelement with %d interface nodes takes a list "
             "of %d bodies, one per node (got %s)", n, n, list ? show_node(r, list) : "none");
    return false;
  }
  f->super_body = calloc((size_t)n, sizeof *f->super_body);
  if (!f->super_body) return false;
  bool ok = true;
  for (int k = 0; k < n; k++) {
    yaml_node_t *item = seq_item(r, list, k);
    f->super_body[k] = resolve_name(r, item, NAME_BODY, "bodies");
    ok = ok && f->super_body[k] >= 0;
    if (k < 2) f->body_loc[k] = loc_of(item);
  }
  if (!ok) return false;
  f->body[0] = f->super_body[0];
  f->body[1] = f->super_body[1];
  return true;
}

/* superelement: a massless FE model (fe_file) statically condensed to its
 * 'interface' nodes (seed 001 section 2.2.3), node k attached to body k of
 * 'bodies'.  The condensed stiffness is that of nodes 1.. with node 0 held
 * (the free-free one is singular: rigid-body motion), and the element acts
 * on the motion of each node relative to node 0.  With two nodes it is a
 * field (MB_FORCE_FIELD), with more an MB_FORCE_SUPERELEMENT.  The FE
 * model's coordinates are global at t = 0, damping = damping_ratio *
 * stiffness */
static void parse_superelement(mapping *m, ir_force *f) {
  reader *r = m->r;
  yaml_node_t *bodies = map_get(m, "bodies");
  bool pair = bodies == NULL || bodies->type != YAML_SEQUENCE_NODE || seq_length(bodies) <= 2;
  if (pair) get_body_pair(m, f->body, f->body_loc);
  get_nonnegative(m, "damping_ratio", false, &f->damping_ratio);
  ir_flex *fx = calloc(1, sizeof *fx);
  if (!fx) return;
  int *nodes = NULL, count = 0;
  bool ok = read_superelement_fe(m, f->name, fx, &nodes, &count);
  if (ok && (count > 2 || !pair)) { /* a list of bodies, one per node */
    if (!pair || (bodies && bodies->type == YAML_SEQUENCE_NODE)) ok = get_super_bodies(m, f, count);
    else ok = false; /* no list: get_body_pair said so */
  }
  if (ok) {
    char err[1024];
    ir_loc where;
    int nl = 6 * (count - 1);
    double *K = count == 2 ? f->K : calloc((size_t)nl * (size_t)nl, sizeof *K);
    if (K && fe_condense_nodes(fx, nodes[0], nodes + 1, count - 1, K, err, sizeof err, &where)) {
      error_at(r, where.line > 0 && !fx->fe_path && !fx->fe_source ? where : m->loc, "superelement '%s': %s",
               f->name, err);
    } else if (K) {
      for (int i = 0; i < 2; i++) memcpy(f->point[i], fx->nodes + 3 * nodes[i], sizeof f->point[i]);
      static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      memcpy(f->axes, identity, sizeof identity);
      if (count == 2) {
        for (int i = 0; i < 36; i++) f->C[i] = f->damping_ratio * f->K[i];
      } else {
        f->nsuper = count;
        f->super_K = K;
        K = NULL;
        f->super_C = calloc((size_t)nl * (size_t)nl, sizeof *f->super_C);
        f->super_point = calloc(3 * (size_t)count, sizeof *f->super_point);
        if (f->super_C && f->super_point) {
          for (int i = 0; i < nl * nl; i++) f->super_C[i] = f->damping_ratio * f->super_K[i];
          for (int k = 0; k < count; k++) memcpy(f->super_point + 3 * k, fx->nodes + 3 * nodes[k], 3 * sizeof(double));
        }
      }
    }
    if (K != f->K) free(K);
  }
  free(nodes);
  free_flex(fx);
}

static void parse_bushing(mapping *m, ir_force *f) {
  parse_pair_at_point(m, f);
  get_six(m, "stiffness", true, true, f->k6);
  get_six(m, "damping", false, true, f->c6);
  get_six(m, "preload", false, false, f->preload6);
  parse_axes(m, f);
}

/* both markers with the element's axes (rows of 'axes', global at t = 0);
   the parameters' K, C and preload are zero */
static double *lower_field_common(lmodel *L, const ir_force *F, mb_forcedef *d) {
  double Cg[9];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) Cg[3 * i + j] = F->axes[3 * j + i]; /* columns = axes rows */
  d->m0 = lower_force_marker(L, F, 0, Cg);
  d->m1 = lower_force_marker(L, F, 1, Cg);
  return lower_force_prm(L, d, MB_FIELD_NPRM);
}

static void lower_bushing(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  (void)index;
  double *prm = lower_field_common(L, F, d);
  if (!prm) return; /* out of memory (lower_force_prm) */
  for (int i = 0; i < 6; i++) {
    prm[MB_FIELD_K + 7 * i] = F->k6[i];
    prm[MB_FIELD_C + 7 * i] = F->c6[i];
    prm[MB_FIELD_PRE + i] = F->preload6[i];
  }
}

static void lower_field(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  (void)index;
  double *prm = lower_field_common(L, F, d);
  if (!prm) return; /* out of memory (lower_force_prm) */
  memcpy(prm + MB_FIELD_K, F->K, 36 * sizeof *prm);
  memcpy(prm + MB_FIELD_C, F->C, 36 * sizeof *prm);
  memcpy(prm + MB_FIELD_PRE, F->preload6, 6 * sizeof *prm);
}

/* beam: x from point 0 to point 1, clamped at marker 0 */
static void lower_beam(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  (void)index;
  double *prm = lower_field_common(L, F, d);
  if (!prm) return; /* out of memory (lower_force_prm) */
  double *K = prm + MB_FIELD_K;
  const ir_beam *bm = &F->beam;
  double len = 0;
  for (int i = 0; i < 3; i++) len += (F->point[1][i] - F->point[0][i]) * (F->point[1][i] - F->point[0][i]);
  len = sqrt(len);
  prm[MB_FIELD_D0] = len;
  mb_beam_stiffness(len, bm->E, bm->G, bm->A, bm->Iy, bm->Iz, bm->J, bm->shear_y * bm->A,
                    bm->shear_z * bm->A, K);
  for (int i = 0; i < 36; i++) prm[MB_FIELD_C + i] = F->damping_ratio * K[i];
}

/* superelement: the condensed K in global axes (at t = 0), d0 the offset of
   the loaded node(s) from node 0 */
static void lower_superelement(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  (void)index;
  if (F->nsuper > 2) {
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    int n = F->nsuper - 1, nl = 6 * n;
    d->kind = MB_FORCE_SUPERELEMENT;
    d->m0 = lower_force_marker(L, F, 0, identity);
    for (int k = 0; k < n; k++) { /* markers m1 .. m1 + n - 1, in a row */
      ir_force node = *F;
      node.body[1] = F->super_body[k + 1];
      node.node[1] = -1;
      memcpy(node.point[1], F->super_point + 3 * (k + 1), sizeof node.point[1]);
      int mk = lower_force_marker(L, &node, 1, identity);
      if (k == 0) d->m1 = mk;
    }
    double *prm = lower_force_prm(L, d, mb_superelement_nprm(n));
    if (!prm) return; /* out of memory (lower_force_prm) */
    prm[MB_SUPER_N] = n;
    for (int k = 0; k < n; k++)
      for (int i = 0; i < 3; i++) prm[MB_SUPER_D0 + 3 * k + i] = F->super_point[3 * (k + 1) + i] - F->super_point[i];
    memcpy(prm + MB_SUPER_D0 + 3 * n, F->super_K, (size_t)nl * nl * sizeof *prm);
    memcpy(prm + MB_SUPER_D0 + 3 * n + nl * nl, F->super_C, (size_t)nl * nl * sizeof *prm);
    return;
  }
  double *prm = lower_field_common(L, F, d);
  if (!prm) return; /* out of memory (lower_force_prm) */
  for (int i = 0; i < 3; i++) prm[MB_FIELD_D0 + i] = F->point[1][i] - F->point[0][i];
  memcpy(prm + MB_FIELD_K, F->K, 36 * sizeof *prm);
  memcpy(prm + MB_FIELD_C, F->C, 36 * sizeof *prm);
}

/* a superelement with more than two nodes: the wrench on each of nodes
   1..n at its point, each one's reaction on body 0 at the same point */
static int emit_superelement(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  int n = (int)L->force_prm[d->padr + MB_SUPER_N], b0 = L->marker[d->m0].body;
  fprintf(f, "    const mb_marker *mk[%d] = {", n);
  for (int j = 0; j < n; j++) fprintf(f, "%s&k%d", j ? ", " : "", d->m1 + j);
  fprintf(f, "};\n    mb_real F[%d], T[%d];\n    mb_superelement(&k%d, mk, force_prm + %d, F, T);\n", 3 * n, 3 * n,
          d->m0, d->padr);
  for (int j = 0; j < n; j++) {
    int mk = d->m1 + j, b = L->marker[mk].body;
    char P[32], Fj[16], Tj[16];
    snprintf(P, sizeof P, "k%d.P", mk);
    snprintf(Fj, sizeof Fj, "F + %d", 3 * j);
    snprintf(Tj, sizeof Tj, "T + %d", 3 * j);
    fprintf(f, "    /* node %d */\n", j + 1);
    if (b >= 0) {
      int nc = emit_cols(f, L, mk, P, Fj, Tj, "    ");
      if (nc < 0) return -1;
      emit_add_cols(f, L->body[b].vadr, nc);
    }
    if (b0 >= 0) {
      fprintf(f, "    {\n      mb_real mF[3] = {-F[%d], -F[%d], -F[%d]}, mT[3] = {-T[%d], -T[%d], -T[%d]};\n"
                 "      mb_rigid_cols(&f%d, k%d.P, mF, mT, c); /* reaction at the same point */\n    }\n",
              3 * j, 3 * j + 1, 3 * j + 2, 3 * j, 3 * j + 1, 3 * j + 2, b0, mk);
      emit_add_cols(f, L->body[b0].vadr, 6);
    }
  }
  return 0;
}

/* the wrench on marker 1 at its point; the reaction on body 0 at the same point */
/* a parameter that is zero whatever the run: not a run-time parameter */
static int prm_always_zero(const lmodel *L, int slot) {
  return !(L->prm_runtime && L->prm_runtime[slot]) && L->force_prm[slot] == 0;
}

/* mb_field's F and T with the zeros of K and C (a bushing's off-diagonal
   terms, a tyre stand-in's five unused directions) left out: the kernel's
   6x6 products, its energy and, when no rotation is stiff or damped, the
   relative rotation (an atan2) cost about 700 instructions a call.  The
   terms that remain keep the kernel's order, so the sums are the same. */
static void emit_field_wrench(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  const int K = d->padr + MB_FIELD_K, C = d->padr + MB_FIELD_C, pre = d->padr + MB_FIELD_PRE;
  int rotation = 0, torque = 0;
  for (int i = 0; i < 6; i++)
    for (int j = 0; j < 6; j++) {
      int stiff = !prm_always_zero(L, K + 6 * i + j) || !prm_always_zero(L, C + 6 * i + j);
      if (j >= 3) rotation |= stiff;
      if (i >= 3) torque |= stiff || !prm_always_zero(L, pre + i);
    }
  fprintf(f, "    mb_real u[6], ud[6], fl[6], F[3], T[3];\n"
             "    mb_field_relative_translation(&k%d, &k%d, force_prm + %d, u, ud);\n",
          d->m0, d->m1, d->padr + MB_FIELD_D0);
  if (rotation) fprintf(f, "    mb_field_relative_rotation(&k%d, &k%d, u + 3, ud + 3);\n", d->m0, d->m1);
  for (int i = 0; i < (torque ? 6 : 3); i++) {
    fprintf(f, "    fl[%d] = force_prm[%d]", i, pre + i);
    for (int j = 0; j < 6; j++) {
      int kz = prm_always_zero(L, K + 6 * i + j), cz = prm_always_zero(L, C + 6 * i + j);
      if (kz && cz) continue;
      fputs(" - (", f);
      if (!kz) fprintf(f, "force_prm[%d] * u[%d]", K + 6 * i + j, j);
      if (!kz && !cz) fputs(" + ", f);
      if (!cz) fprintf(f, "force_prm[%d] * ud[%d]", C + 6 * i + j, j);
      fputc(')', f);
    }
    fputs(";\n", f);
  }
  fprintf(f, "    mb_mul3(k%d.R, fl, F);\n", d->m0);
  if (torque)
    fprintf(f, "    mb_mul3(k%d.R, fl + 3, T);\n", d->m0);
  else
    fputs("    T[0] = T[1] = T[2] = 0;\n", f);
}

static int emit_field(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  if (d->kind == MB_FORCE_SUPERELEMENT) return emit_superelement(f, L, k);
  int b0 = L->marker[d->m0].body, b1 = L->marker[d->m1].body;
  emit_field_wrench(f, L, k);
  if (b0 >= 0)
    fputs("    mb_real mF[3] = {-F[0], -F[1], -F[2]}, mT[3] = {-T[0], -T[1], -T[2]};\n", f);
  if (b1 >= 0) {
    char P[32];
    snprintf(P, sizeof P, "k%d.P", d->m1);
    int n = emit_cols(f, L, d->m1, P, "F", "T", "    ");
    if (n < 0) return -1;
    emit_add_cols(f, L->body[b1].vadr, n);
  }
  if (b0 >= 0) {
    fprintf(f, "    mb_rigid_cols(&f%d, k%d.P, mF, mT, c); /* reaction at the same point */\n", b0, d->m1);
    emit_add_cols(f, L->body[b0].vadr, 6);
  }
  return 0;
}

static const char *const field_keys[] = {"type", "bodies", "point", "stiffness", "damping",
                                         "preload", "axes", "node", "nodes", NULL};
static const char *const bushing_keys[] = {"type",    "bodies",  "point", "stiffness",
                                           "damping", "preload", "axes",  "node", "nodes", NULL};
static const char *const beam_keys[] = {"type", "bodies", "points", "node", "nodes", "section",
                                        "material", "theory", "damping_ratio", NULL};
static const char *const superelement_keys[] = {"type", "bodies", "fe_file", "interface", "mass",
                                                "damping_ratio", NULL};
#define FIELD_LAYOUT "d0[3], K[36], C[36], preload[6]"

const element_desc element_bushing = {
    .family = ELEMENT_FORCE, .type = "bushing", .ir_kind = FORCE_BUSHING,
    ELEMENT_RUNTIME_KIND(MB_FORCE_FIELD), .keys = bushing_keys, .prm_layout = FIELD_LAYOUT,
    .parse = parse_bushing, .lower = lower_bushing, .emit_eval = emit_field};

const element_desc element_field = {
    .family = ELEMENT_FORCE, .type = "field", .ir_kind = FORCE_FIELD,
    ELEMENT_RUNTIME_KIND(MB_FORCE_FIELD), .keys = field_keys, .prm_layout = FIELD_LAYOUT,
    .parse = parse_field, .lower = lower_field, .emit_eval = emit_field};

const element_desc element_beam = {
    .family = ELEMENT_FORCE, .type = "beam", .ir_kind = FORCE_BEAM,
    ELEMENT_RUNTIME_KIND(MB_FORCE_FIELD), .keys = beam_keys, .prm_layout = FIELD_LAYOUT,
    .parse = parse_beam_force, .lower = lower_beam, .emit_eval = emit_field};

const element_desc element_superelement = {
    .family = ELEMENT_FORCE, .type = "superelement", .ir_kind = FORCE_SUPERELEMENT,
    ELEMENT_RUNTIME_KIND(MB_FORCE_FIELD), .keys = superelement_keys, .prm_layout = FIELD_LAYOUT,
    .parse = parse_superelement, .lower = lower_superelement, .emit_eval = emit_field};
