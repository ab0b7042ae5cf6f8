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

/* the files included (for the input hash) */
typedef struct {
  char *path[DIAG_MAX_FILES];
  int count;
} compose_files;

/* false after reporting errors (file:line:col in the file concerned) */
bool compose_document(const char *path, yaml_document_t *doc, compose_files *files);
void compose_files_free(compose_files *files);

#endif
