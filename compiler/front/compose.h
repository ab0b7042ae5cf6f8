/* compose.h: the YAML document before the reader reads it (compose.c): merge
 * keys ('<<: *anchor', explicit keys win) expanded, and the files named by a
 * top-level 'include:' (relative to the including file) read, composed the
 * same way and their sections (bodies, joints, drivers, forces, outputs,
 * scenes) appended to the model's. */
#ifndef MBCC_COMPOSE_H
#define MBCC_COMPOSE_H

#include <stdbool.h>
#include <yaml.h>

#include "diag.h"

#define LIMIT_INCLUDE_DEPTH 16

/* A scalar whose sign a mirrored subsystem instance flips (y -> -y) carries
 * this tag; the reader's numbers (yaml_map.c to_number, params.c) negate it,
 * so that messages still point at the text as written. */
#define COMPOSE_MIRROR_TAG "tag:mbcc:mirrored"
bool compose_is_mirrored(const yaml_node_t *n);
/* -v, but +0 for 0 (a mirrored 0 is written 0, not -0) */
double compose_mirror_value(double v);

/* A coordinate of a point of a moved instance ('position: [x, y, z]', and
 * the instances around it) carries the tag COMPOSE_PLACED_TAG, then '-' (a
 * mirrored y) or '+', then per offset ";+N" or ";-N": node N of the composed
 * document is that offset's component as the instance wrote it, added or
 * subtracted (an enclosing mirror turns an inner offset's y), innermost
 * first.  The reader's number is then ((±v) ± t1) ± t2 ..., the composition
 * outer_translate(outer_mirror(inner_translate(inner_mirror(v)))). */
#define COMPOSE_PLACED_TAG "tag:mbcc:placed:"
typedef struct {
  bool negate;                          /* mirrored: -v first */
  int nterms;
  int node[LIMIT_INCLUDE_DEPTH + 1];    /* the offsets' scalars, innermost first */
  bool subtract[LIMIT_INCLUDE_DEPTH + 1];
} compose_placement;
/* false for a scalar as written; else how an instance placed it */
bool compose_placement_of(const yaml_node_t *n, compose_placement *p);

/* the files included (for the input hash) */
typedef struct {
  char *path[DIAG_MAX_FILES];
  int count;
} compose_files;

/* false after reporting errors (file:line:col in the file concerned) */
bool compose_document(const char *path, yaml_document_t *doc, compose_files *files);
void compose_files_free(compose_files *files);

#endif
