/* emit_rows.h: the rigid markers and the spherical and dot-1 rows of the
 * generated evaluation as expressions with the compile-time zeros and ones
 * folded (emit_rows.c, on the expression graph of sym.h).  The writers
 * return -1 when memory ran out (the caller discards the output). */
#ifndef EMIT_ROWS_H
#define EMIT_ROWS_H

#include <stdio.h>
#include "lower.h"

/* 1 if node 'node' of body B is one where all its mode shapes vanish */
int emit_node_static(const mb_body *B, int node);
/* write marker k if it sits on a rigid body (or a static node): 1; 0: not
 * handled; -1 out of memory */
int emit_marker_special(FILE *f, const lmodel *L, int k);
/* the same with only the point P and its velocity V set (a marker that only
 * springs read) */
int emit_marker_point_velocity(FILE *f, const lmodel *L, int k);
/* 1 if marker k coincides with its body's frame (rigid body or static node,
 * s = 0, C = I): the rows of emit_row_special read the frame, not the marker */
int emit_marker_is_frame(const lmodel *L, int k);
/* the values shared by the dot-1 rows between two bodies' own axes (entries
 * of their relative rotation, |w0 - w1|^2), as locals before the rows, for
 * the rows r with no skip[r] (skip NULL: all; a mixed loop form skips the
 * looped rows); -1 out of memory (the caller discards the output) */
int emit_rows_shared(FILE *f, const lmodel *L, const unsigned char *skip);
/* 1 if emit_row_special writes row R (spherical and dot-1 rows): it reads
 * its markers' fields (or their frames), never a marker's address */
int emit_row_is_special(const mb_rowdef *R);
/* write row r if it is a spherical or dot-1 row: 1; 0: not handled; -1 out of memory */
int emit_row_special(FILE *f, const lmodel *L, int r);

/* an earlier marker j < k on the same flexible node with the same axes C,
 * one that computed[j] says the evaluation forms (its numbers are marker
 * k's: a copy replaces the modal sums and the rotation's kernel), or -1 */
int emit_marker_node_twin(const lmodel *L, int k, const char *computed);
/* write marker k on a flexible node: the modal sums with the node's shapes as
 * constants; 0, or -1 out of memory */
int emit_marker_node(FILE *f, const lmodel *L, int k);
/* c = mb_node_cols_mk at marker k (a flexible node) with the node's shapes as
 * constants; dV, dW: names of 3-vectors (zero3: zero, its half of the modal
 * columns dropped); 0, or -1 out of memory */
int emit_node_cols(FILE *f, const lmodel *L, int k, const char *dV, const char *dW, const char *indent);

/* 1 when row r writes entries of D through its marker s (0 or 1): on a body,
 * with varying or modal slots */
int emit_row_side_varies(const lmodel *L, int r, int s);
/* row r's stores into both triangles of K through marker s: the varying body
 * columns from the names c[0..5], the modal columns from c[6 + j] (zero on a
 * node whose shapes vanish); 0, or -1 out of memory */
int emit_row_stores(FILE *f, const lmodel *L, int r, int s, const char *const c[6], const char *indent);

#endif
