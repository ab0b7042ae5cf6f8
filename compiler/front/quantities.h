/* quantities.h: inertia and orientation readers (quantities.c). */
#ifndef MBCC_QUANTITIES_H
#define MBCC_QUANTITIES_H

#include "yaml_map.h"

/* [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix, about the
 * centre of mass, body axes: symmetric, positive definite, and physical */
bool parse_inertia(reader *r, yaml_node_t *n, double inertia[9]);
/* Euler parameters [e0, e1, e2, e3] (normalized here) or {axis, angle} */
void parse_orientation(reader *r, yaml_node_t *n, const char *owner, double e[4]);

#endif
