/* joint_axis.c: the joints given by a point and an axis: spherical,
 * revolute, cylindrical, prismatic, fixed (rows: runtime/core
 * mb_prim_* of model_generic.c; the joint frames' z is the axis). */
#include <string.h>

#include "joint.h"
#include "reader.h"

static void parse_axis_joint(mapping *m, ir_joint *j, bool on_nodes) {
  joint_parse_point(m, j, on_nodes);
  bool required = j->kind == JOINT_REVOLUTE || j->kind == JOINT_CYLINDRICAL ||
                  j->kind == JOINT_PRISMATIC;
  if (get_axis(m, "axis", required, j->axis[0]))
    memcpy(j->axis[1], j->axis[0], sizeof j->axis[0]);
  joint_parse_reference(m, j);
}

static void rows_spherical(lmodel *L, int j, int m0, int m1) { joint_rows_coincident(L, j, m0, m1); }

static void rows_revolute(lmodel *L, int j, int m0, int m1) {
  joint_rows_coincident(L, j, m0, m1);
  joint_rows_axis_parallel(L, j, m0, m1);
}

static void rows_cylindrical(lmodel *L, int j, int m0, int m1) {
  joint_rows_axis_parallel(L, j, m0, m1);
  joint_rows_on_axis(L, j, m0, m1);
}

static void rows_prismatic(lmodel *L, int j, int m0, int m1) {
  joint_rows_axis_parallel(L, j, m0, m1);
  joint_rows_on_axis(L, j, m0, m1);
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 0, 1, "no rotation about axis (x0 . y1)");
}

static void rows_fixed(lmodel *L, int j, int m0, int m1) {
  joint_rows_coincident(L, j, m0, m1);
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 0, 1, "no rotation about z (x0 . y1)");
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 1, 2, "no rotation about x (y0 . z1)");
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 2, 0, "no rotation about y (z0 . x1)");
}

static const char *const axis_keys[] = {"type", "bodies", "point", "axis", "reference", "node",
                                        "nodes", NULL};

const joint_desc element_spherical = {
    .family = ELEMENT_JOINT, .type = "spherical", .ir_kind = JOINT_SPHERICAL, .keys = axis_keys,
    .parse = parse_axis_joint, .lower_rows = rows_spherical};
const joint_desc element_revolute = {
    .family = ELEMENT_JOINT, .type = "revolute", .ir_kind = JOINT_REVOLUTE, .keys = axis_keys,
    .free_dofs = JOINT_FREE_ROTATION, .parse = parse_axis_joint, .lower_rows = rows_revolute};
const joint_desc element_cylindrical = {
    .family = ELEMENT_JOINT, .type = "cylindrical", .ir_kind = JOINT_CYLINDRICAL, .keys = axis_keys,
    .free_dofs = JOINT_FREE_ROTATION | JOINT_FREE_TRANSLATION, .parse = parse_axis_joint,
    .lower_rows = rows_cylindrical};
const joint_desc element_prismatic = {
    .family = ELEMENT_JOINT, .type = "prismatic", .ir_kind = JOINT_PRISMATIC, .keys = axis_keys,
    .free_dofs = JOINT_FREE_TRANSLATION, .parse = parse_axis_joint, .lower_rows = rows_prismatic};
const joint_desc element_fixed = {
    .family = ELEMENT_JOINT, .type = "fixed", .ir_kind = JOINT_FIXED, .keys = axis_keys,
    .parse = parse_axis_joint, .lower_rows = rows_fixed};
