/* joint.c: what the joint kinds share: parsing the reference direction and
 * the joint point, and the groups of constraint rows (lower) that the kinds
 * (joint_axis.c, joint_universal.c, joint_distance.c) are made of. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "joint.h"
#include "reader.h"

/* The global axis least aligned with 'axis', made perpendicular to it:
 * deterministic, and never nearly parallel. */
void joint_default_reference(const double axis[3], double ref[3]) {
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(axis[i]) < fabs(axis[k]))
      k = i;
  double e[3] = {0, 0, 0};
  e[k] = 1;
  double along = dot3(e, axis);
  for (int i = 0; i < 3; i++)
    ref[i] = e[i] - along * axis[i];
  scale3(ref, 1 / norm3(ref));
}

void joint_parse_reference(mapping *m, ir_joint *j) {
  double ref[3];
  joint_default_reference(j->axis[0], j->ref);
  if (!get_vector(m, "reference", 3, false, ref))
    return;
  double length = norm3(ref);
  if (!(length >= ZERO_LENGTH)) {
    error_at(m->r, m->last_loc, "zero-length reference ('reference' must be a nonzero direction)");
    return;
  }
  double along = dot3(ref, j->axis[0]);
  for (int i = 0; i < 3; i++)
    ref[i] -= along * j->axis[0][i];
  double across = norm3(ref);
  if (!(across >= ANGLE_TOLERANCE * length)) {
    error_at(m->r, m->last_loc,
             "'reference' is parallel to the joint axis (expected a direction across it)");
    return;
  }
  scale3(ref, 1 / across);
  memcpy(j->ref, ref, sizeof ref);
}

void joint_parse_point(mapping *m, ir_joint *j, bool on_nodes) {
  reader *r = m->r;
  bool point_given = get_vector(m, "point", 3, !on_nodes, j->point[0]);
  if (point_given)
    memcpy(j->point[1], j->point[0], sizeof j->point[0]);
  if (on_nodes) {
    check_node_point(r, r->model, point_given ? m->loc : j->loc, j->body, j->node, point_given, &j->point[0][0]);
    if (!point_given) /* both sides at the node that was given */
      memcpy(j->point[j->node[0] >= 0 ? 1 : 0], j->point[j->node[0] >= 0 ? 0 : 1], sizeof j->point[0]);
  }
}

/* --- rows ------------------------------------------------------------------- */

static const char *axis_name[3] = {"x", "y", "z"};

void joint_row(lmodel *L, int j, mb_prim_kind kind, int m0, int m1, int a, int b, const char *what) {
  const ir_joint *J = &L->ir->joints[j];
  lower_add_row(L, kind, m0, m1, a, b, what, j, -1, J->loc, J->name, joint_element(J->kind)->type);
}

void joint_rows_coincident(lmodel *L, int j, int m0, int m1) {
  char what[64];
  for (int k = 0; k < 3; k++) {
    snprintf(what, sizeof what, "coincident points, %s", axis_name[k]);
    joint_row(L, j, MB_PRIM_SPH, m0, m1, k, 0, what);
  }
}

void joint_rows_axis_parallel(lmodel *L, int j, int m0, int m1) {
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 0, 2, "axis z1 perpendicular to x0");
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 1, 2, "axis z1 perpendicular to y0");
}

void joint_rows_on_axis(lmodel *L, int j, int m0, int m1) {
  joint_row(L, j, MB_PRIM_DOT2, m0, m1, 0, 0, "point 1 on axis, x0 offset");
  joint_row(L, j, MB_PRIM_DOT2, m0, m1, 1, 0, "point 1 on axis, y0 offset");
}
