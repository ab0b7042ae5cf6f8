/* names.h: the one namespace of bodies, joints, drivers, forces and outputs
 * (each becomes a symbol of the generated code), identifiers, and references
 * by name (names.c). */
#ifndef MBCC_NAMES_H
#define MBCC_NAMES_H

#include <stdbool.h>
#include <stddef.h>
#include <yaml.h>

#include "ir.h"

typedef enum { NAME_BODY, NAME_JOINT, NAME_DRIVER, NAME_FORCE, NAME_OUTPUT } name_kind;

extern const char *const name_kind_words[];
extern const char *const name_kind_plurals[];

typedef struct {
  const char *name; /* owned by the model object it names */
  name_kind kind;
  int index;        /* into the model array of that kind */
  ir_loc loc;       /* line 0 for the implicit ground */
} name_entry;

/* Open addressing with linear probing; capacity is a power of two. */
typedef struct {
  name_entry *slots;
  size_t capacity, count;
} name_table;

struct reader;
struct mapping;
struct name_list;

name_entry *table_find(const name_table *t, const char *name);
void table_add(name_table *t, name_entry entry);
void table_free(name_table *t);
/* every name of one kind, for "(expected one of: ...)" */
void list_names_of_kind(struct reader *r, name_kind kind, struct name_list *l);
bool is_identifier(const char *s, size_t length);
bool is_c_keyword(const char *s);
/* Checks that 'n' (a scalar) is a C identifier, not a keyword; reports it. */
bool check_identifier(struct reader *r, const yaml_node_t *n);
/* Checks and registers the name of a new object; returns a copy for the
 * object (escaped if invalid, so later messages stay printable).
 * 'scene_outputs' is NULL except for the outputs of a scene. */
char *new_name(struct reader *r, const yaml_node_t *n, name_kind kind, int index,
               name_table *scene_outputs);
/* The index of the object of 'kind' named by scalar 'n', or -1 (reported). */
int resolve_name(struct reader *r, yaml_node_t *n, name_kind kind, const char *key);
/* the object of 'kind' named by the value of 'key' */
bool get_ref(struct mapping *m, const char *key, name_kind kind, bool required, int *index,
             ir_loc *loc);
/* 'bodies': two different body names. */
bool get_body_pair(struct mapping *m, int body[2], ir_loc body_loc[2]);

#endif
