/* joint_universal.c: the universal (Cardan) joint: a point and two
 * perpendicular axes, axes[0] fixed in body 0, axes[1] in body 1. */
#include <math.h>
#include <string.h>

#include "joint.h"
#include "reader.h"

static void parse_universal(mapping *m, ir_joint *j, bool on_nodes) {
  reader *r = m->r;
  joint_parse_point(m, j, on_nodes);
  yaml_node_t *n = map_require(m, "axes", true, "a list of 2 perpendicular axes");
  double axes[6];
  if (n != NULL && to_vector_list(r, n, "'axes'", 2, 3, axes)) {
    bool ok = true;
    for (int i = 0; i < 2; i++) {
      double length = norm3(axes + 3 * i);
      if (!(length >= ZERO_LENGTH)) {
        error_at(r, loc_of(seq_item(r, n, i)),
                 "zero-length axis (item %d of 'axes' must be a nonzero direction)", i + 1);
        ok = false;
      } else {
        scale3(axes + 3 * i, 1 / length);
      }
    }
    double cosine = dot3(axes, axes + 3);
    if (ok && fabs(cosine) > ANGLE_TOLERANCE) {
      error_at(r, loc_of(n),
               "universal joint axes must be perpendicular (they are %.6g degrees apart)",
               acos(fmax(-1, fmin(1, cosine))) * 180 / PI);
      ok = false;
    }
    if (ok) {
      memcpy(j->axis[0], axes, 3 * sizeof *axes);
      memcpy(j->axis[1], axes + 3, 3 * sizeof *axes);
    }
  }
  joint_parse_reference(m, j);
}

static void rows_universal(lmodel *L, int j, int m0, int m1) {
  joint_rows_coincident(L, j, m0, m1);
  joint_row(L, j, MB_PRIM_DOT1, m0, m1, 2, 2, "cross axes perpendicular (z0 . z1)");
}

static const char *const universal_keys[] = {"type", "bodies", "point", "axes", "reference",
                                             "node", "nodes", NULL};

/* the second marker's frame: z along axes[1], x along axes[0] */
const joint_desc element_universal = {
    .family = ELEMENT_JOINT, .type = "universal", .ir_kind = JOINT_UNIVERSAL, .keys = universal_keys,
    .cross_axes = true, .parse = parse_universal, .lower_rows = rows_universal};
