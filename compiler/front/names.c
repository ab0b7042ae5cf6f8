/* names.c: the one namespace of bodies, joints, drivers, forces and outputs
 * (each becomes a symbol of the generated code): the name table, identifier
 * checks, and references by name ('body: crank', 'bodies: [a, b]'). */
#include "names.h"

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "yaml_map.h"

const char *const name_kind_words[] = {"body", "joint", "driver", "force", "output"};
const char *const name_kind_plurals[] = {"bodies", "joints", "drivers", "forces", "outputs"};


static uint64_t hash_name(const char *s) {
  uint64_t h = 1469598103934665603u; /* FNV-1a */
  for (; *s; s++) {
    h ^= (unsigned char)*s;
    h *= 1099511628211u;
  }
  return h;
}

name_entry *table_find(const name_table *t, const char *name) {
  if (t->capacity == 0)
    return NULL;
  size_t mask = t->capacity - 1;
  for (size_t i = hash_name(name) & mask;; i = (i + 1) & mask) {
    name_entry *e = &t->slots[i];
    if (e->name == NULL)
      return NULL;
    if (strcmp(e->name, name) == 0)
      return e;
  }
}

static void table_insert(name_table *t, name_entry entry) {
  size_t mask = t->capacity - 1;
  size_t i = hash_name(entry.name) & mask;
  while (t->slots[i].name != NULL)
    i = (i + 1) & mask;
  t->slots[i] = entry;
  t->count++;
}

void table_add(name_table *t, name_entry entry) {
  if (2 * (t->count + 1) > t->capacity) { /* keep the load below 1/2 */
    name_entry *old = t->slots;
    size_t old_capacity = t->capacity;
    t->capacity = old_capacity ? 2 * old_capacity : 64;
    t->slots = xcalloc(t->capacity, sizeof *t->slots);
    t->count = 0;
    for (size_t i = 0; i < old_capacity; i++)
      if (old[i].name != NULL)
        table_insert(t, old[i]);
    free(old);
  }
  table_insert(t, entry);
}

void table_free(name_table *t) {
  free(t->slots);
  t->slots = NULL;
  t->capacity = t->count = 0;
}


void list_names_of_kind(reader *r, name_kind kind, name_list *l) {
  const ir_model *m = r->model;
  switch (kind) {
  case NAME_BODY:
    for (int i = 0; i < m->nbodies; i++)
      name_list_add(l, m->bodies[i].name);
    break;
  case NAME_JOINT:
    for (int i = 0; i < m->njoints; i++)
      name_list_add(l, m->joints[i].name);
    break;
  case NAME_DRIVER:
    for (int i = 0; i < m->ndrivers; i++)
      name_list_add(l, m->drivers[i].name);
    break;
  case NAME_FORCE:
    for (int i = 0; i < m->nforces; i++)
      name_list_add(l, m->forces[i].name);
    break;
  case NAME_OUTPUT:
    for (int i = 0; i < m->noutputs; i++)
      if (m->outputs[i].name != NULL)
        name_list_add(l, m->outputs[i].name);
    break;
  }
}

/* ---------------------------------------------------------------------------
 * names
 * ------------------------------------------------------------------------- */

bool is_identifier(const char *s, size_t length) {
  if (length == 0)
    return false;
  for (size_t i = 0; i < length; i++) {
    char c = s[i];
    bool letter = (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_';
    bool digit = c >= '0' && c <= '9';
    if (!(letter || (digit && i > 0)))
      return false;
  }
  return true;
}

bool is_c_keyword(const char *s) {
  static const char *const keywords[] = {
      "auto", "break", "case", "char", "const", "continue", "default", "do", "double", "else",
      "enum", "extern", "float", "for", "goto", "if", "inline", "int", "long", "register",
      "restrict", "return", "short", "signed", "sizeof", "static", "struct", "switch",
      "typedef", "union", "unsigned", "void", "volatile", "while", "_Alignas", "_Alignof",
      "_Atomic", "_Bool", "_Complex", "_Generic", "_Imaginary", "_Noreturn", "_Static_assert",
      "_Thread_local", NULL};
  for (int i = 0; keywords[i] != NULL; i++)
    if (strcmp(s, keywords[i]) == 0)
      return true;
  return false;
}

/* Checks that 'n' (a scalar) is a C identifier, not a keyword; reports it. */
bool check_identifier(reader *r, const yaml_node_t *n) {
  const char *text = scalar_text(n);
  size_t length = scalar_length(n);
  if (!is_identifier(text, length)) {
    error_at(r, loc_of(n),
             "'%s' is not a valid name (expected a C identifier: a letter or '_', then "
             "letters, digits or '_')",
             show_text(r, text, length));
    return false;
  }
  if (is_c_keyword(text)) {
    error_at(r, loc_of(n), "'%s' is a C keyword and cannot be used as a name", text);
    return false;
  }
  return true;
}

/* Checks and registers the name of a new object; returns a copy for the
 * object (escaped if invalid, so later messages stay printable).
 * 'scene_outputs' is NULL except for the outputs of a scene: those replace
 * the base outputs, so they may reuse their names. */
char *new_name(reader *r, const yaml_node_t *n, name_kind kind, int index,
                      name_table *scene_outputs) {
  bool valid = check_identifier(r, n);
  char *name = valid ? xstrndup(scalar_text(n), scalar_length(n))
                     : xstrdup(show_text(r, scalar_text(n), scalar_length(n)));
  name_entry *prior = table_find(&r->names, name);
  if (prior != NULL && scene_outputs != NULL && prior->kind == NAME_OUTPUT)
    prior = NULL;
  if (prior == NULL && scene_outputs != NULL)
    prior = table_find(scene_outputs, name);
  if (prior != NULL && prior->kind == NAME_BODY && prior->index == 0) {
    error_at(r, loc_of(n), "name 'ground' is reserved for the implicit ground body");
  } else if (prior != NULL) {
    if (valid) { /* an invalid name already has its error */
      error_at(r, loc_of(n),
               "name '%s' is already used by %s '%s' (names of bodies, joints, drivers, "
               "forces and outputs must all be different)",
               name, name_kind_words[prior->kind],
               prior->name);
      note_at(r, prior->loc, "'%s' first defined here", prior->name);
    }
  } else {
    name_entry entry = {name, kind, index, loc_of(n)};
    table_add(scene_outputs != NULL ? scene_outputs : &r->names, entry);
  }
  return name;
}

/* The index of the object of 'kind' named by scalar 'n', or -1 (reported). */
int resolve_name(reader *r, yaml_node_t *n, name_kind kind, const char *key) {
  const char *word = name_kind_words[kind];
  if (n->type != YAML_SCALAR_NODE) {
    error_at(r, loc_of(n), "'%s' must be a %s name (got %s)", key, word, show_node(r, n));
    return -1;
  }
  const char *text = scalar_text(n);
  size_t length = scalar_length(n);
  name_entry *e = strlen(text) == length ? table_find(&r->names, text) : NULL;
  if (e != NULL && e->kind == kind)
    return e->index;
  const char *shown = show_text(r, text, length);
  if (e != NULL) {
    error_at(r, loc_of(n), "'%s' is a%s %s, not a %s", shown, e->kind == NAME_OUTPUT ? "n" : "",
             name_kind_words[e->kind], word);
    if (e->loc.line > 0)
      note_at(r, e->loc, "'%s' is defined here", e->name);
    return -1;
  }
  name_list l = {.length = 0};
  list_names_of_kind(r, kind, &l);
  if (l.count == 0)
    error_at(r, loc_of(n), "unknown %s '%s' (the model has no %s)", word, shown,
             name_kind_plurals[kind]);
  else
    error_at(r, loc_of(n), "unknown %s '%s' (expected one of: %s)", word, shown, l.text);
  return -1;
}

bool get_ref(mapping *m, const char *key, name_kind kind, bool required, int *index,
                    ir_loc *loc) {
  char expected[32];
  snprintf(expected, sizeof expected, "a %s name", name_kind_words[kind]);
  yaml_node_t *n = map_require(m, key, required, expected);
  if (n == NULL)
    return false;
  if (loc != NULL)
    *loc = loc_of(n);
  int found = resolve_name(m->r, n, kind, key);
  if (found < 0)
    return false;
  *index = found;
  return true;
}

/* 'bodies': two different body names. */
bool get_body_pair(mapping *m, int body[2], ir_loc body_loc[2]) {
  reader *r = m->r;
  yaml_node_t *n = map_require(m, "bodies", true, "a list of 2 body names");
  if (n == NULL)
    return false;
  if (n->type != YAML_SEQUENCE_NODE || seq_length(n) != 2) {
    char got[SHOWN_SIZE];
    if (n->type == YAML_SEQUENCE_NODE)
      snprintf(got, sizeof got, "%d", seq_length(n));
    else
      snprintf(got, sizeof got, "%s", show_node(r, n));
    error_at(r, loc_of(n), "'bodies': expected a list of 2 body names, got %s", got);
    return false;
  }
  for (int i = 0; i < 2; i++) {
    yaml_node_t *item = seq_item(r, n, i);
    body_loc[i] = loc_of(item);
    body[i] = resolve_name(r, item, NAME_BODY, "bodies");
  }
  if (body[0] < 0 || body[1] < 0)
    return false;
  if (body[0] == body[1]) {
    error_at(r, body_loc[1], "'bodies' lists '%s' twice (expected two different bodies)",
             r->model->bodies[body[0]].name);
    return false;
  }
  return true;
}
