/* joint.h: what the joint kinds (joint_*.c) share, from joint.c: the
 * reference direction, the joint point, and the groups of constraint rows
 * the kinds are made of. */
#ifndef MBCC_JOINT_H
#define MBCC_JOINT_H

#include "element.h"

/* The global axis least aligned with 'axis', made perpendicular to it. */
void joint_default_reference(const double axis[3], double ref[3]);
/* 'reference' (the marker x axis, across axis[0]), or the default */
void joint_parse_reference(mapping *m, ir_joint *j);
/* 'point' (required unless on nodes); on nodes, the node's position */
void joint_parse_point(mapping *m, ir_joint *j, bool on_nodes);

/* one row of joint j (its name and kind describe it) */
void joint_row(lmodel *L, int j, mb_prim_kind kind, int m0, int m1, int a, int b, const char *what);
/* the point of m1 coincides with m0's: 3 rows */
void joint_rows_coincident(lmodel *L, int j, int m0, int m1);
/* z1 perpendicular to x0 and y0: 2 rows */
void joint_rows_axis_parallel(lmodel *L, int j, int m0, int m1);
/* the point of m1 on the axis of m0: 2 rows */
void joint_rows_on_axis(lmodel *L, int j, int m0, int m1);

#endif
