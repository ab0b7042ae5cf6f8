/* joint_distance.c: the distance joint: two points held at their initial
 * distance (one row, runtime mb_prim MB_PRIM_DIST). */
#include <math.h>
#include <string.h>

#include "joint.h"
#include "reader.h"

static void parse_distance(mapping *m, ir_joint *j, bool on_nodes) {
  reader *r = m->r;
  yaml_node_t *n = map_require(m, "points", !on_nodes, "a list of 2 points [x, y, z]");
  bool given = n != NULL && to_vector_list(r, n, "'points'", 2, 3, &j->point[0][0]);
  if (on_nodes) {
    /* a side on a node without 'points': the node; the other side needs the points */
    if (!given && (j->node[0] < 0 || j->node[1] < 0))
      error_at(r, j->loc, "distance joint '%s' needs 'points' for its side that is not on a node", j->name);
    check_node_point(r, r->model, n ? loc_of(n) : j->loc, j->body, j->node, given, &j->point[0][0]);
  }
  if (given || on_nodes) {
    double d[3];
    for (int i = 0; i < 3; i++)
      d[i] = j->point[1][i] - j->point[0][i];
    double length = norm3(d);
    if (!(length > ZERO_LENGTH)) {
      error_at(r, n ? loc_of(n) : j->loc, "distance joint points coincide (they must be apart)");
    } else { /* the axis of a distance joint is its initial direction */
      scale3(d, 1 / length);
      memcpy(j->axis[0], d, sizeof d);
      memcpy(j->axis[1], d, sizeof d);
    }
  }
  joint_default_reference(j->axis[0], j->ref);
}

/* the row holds the initial length */
static void rows_distance(lmodel *L, int j, int m0, int m1) {
  const ir_joint *J = &L->ir->joints[j];
  double d[3];
  for (int k = 0; k < 3; k++) d[k] = J->point[1][k] - J->point[0][k];
  joint_row(L, j, MB_PRIM_DIST, m0, m1, 0, 0, "distance");
  L->row[L->m.nrow - 1].L = sqrt(mb_dot3(d, d));
}

static const char *const distance_keys[] = {"type", "bodies", "points", "node", "nodes", NULL};

const joint_desc element_distance = {
    .family = ELEMENT_JOINT, .type = "distance", .ir_kind = JOINT_DISTANCE, .keys = distance_keys,
    .parse = parse_distance, .lower_rows = rows_distance};
