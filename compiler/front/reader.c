/* reader.c: reads a model file (YAML, schema v1, docs/model-format.md) into
 * the IR of ir.h and validates everything that can be checked before
 * assembly.  The reader keeps going after an error so that one run shows as
 * many problems as possible; ir_read returns NULL if any error was reported.
 *
 * The walk over the YAML document is driven by the schema, never by the
 * document's shape, so its depth is bounded even for cyclic aliases
 * (libyaml allows "&a [*a]"). */
#include "ir.h"

#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "diag.h"

/* ---------------------------------------------------------------------------
 * memory
 * ------------------------------------------------------------------------- */

static void out_of_memory(void) {
  fputs("mbcc: error: out of memory\n", stderr);
  abort();
}

static void *xcalloc(size_t count, size_t size) {
  void *p = calloc(count ? count : 1, size ? size : 1);
  if (p == NULL)
    out_of_memory();
  return p;
}

static char *xstrndup(const char *s, size_t length) {
  char *copy = xcalloc(length + 1, 1);
  memcpy(copy, s, length);
  return copy;
}

static char *xstrdup(const char *s) { return xstrndup(s, strlen(s)); }

/* ---------------------------------------------------------------------------
 * small vector helpers
 * ------------------------------------------------------------------------- */

static double dot3(const double a[3], const double b[3]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double norm3(const double a[3]) { return sqrt(dot3(a, a)); }

static double distance3(const double a[3], const double b[3]) {
  double d[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  return norm3(d);
}

/* rotation matrix (row-major, body to global) of unit Euler parameters */
static void quaternion_to_matrix(const double e[4], double A[9]) {
  double e0 = e[0], e1 = e[1], e2 = e[2], e3 = e[3];
  A[0] = 2 * (e0 * e0 + e1 * e1) - 1; A[1] = 2 * (e1 * e2 - e0 * e3); A[2] = 2 * (e1 * e3 + e0 * e2);
  A[3] = 2 * (e1 * e2 + e0 * e3); A[4] = 2 * (e0 * e0 + e2 * e2) - 1; A[5] = 2 * (e2 * e3 - e0 * e1);
  A[6] = 2 * (e1 * e3 - e0 * e2); A[7] = 2 * (e2 * e3 + e0 * e1); A[8] = 2 * (e0 * e0 + e3 * e3) - 1;
}

static void scale3(double a[3], double factor) {
  a[0] *= factor;
  a[1] *= factor;
  a[2] *= factor;
}

/* Lengths below this are treated as zero (axes, point separations). */
#define ZERO_LENGTH 1e-12
/* Tolerance on unit-vector dot products (perpendicular / orthonormal). */
#define ANGLE_TOLERANCE 1e-6
#define PI 3.14159265358979323846 /* M_PI is not in strict C11 */

/* ---------------------------------------------------------------------------
 * names of bodies, joints, drivers, forces and outputs: one namespace,
 * because each becomes a symbol of the generated code
 * ------------------------------------------------------------------------- */

typedef enum { NAME_BODY, NAME_JOINT, NAME_DRIVER, NAME_FORCE, NAME_OUTPUT } name_kind;

static const char *const name_kind_words[] = {"body", "joint", "driver", "force", "output"};
static const char *const name_kind_plurals[] = {"bodies", "joints", "drivers", "forces",
                                                "outputs"};

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

static uint64_t hash_name(const char *s) {
  uint64_t h = 1469598103934665603u; /* FNV-1a */
  for (; *s; s++) {
    h ^= (unsigned char)*s;
    h *= 1099511628211u;
  }
  return h;
}

static name_entry *table_find(const name_table *t, const char *name) {
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

static void table_add(name_table *t, name_entry entry) {
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

static void table_free(name_table *t) {
  free(t->slots);
  t->slots = NULL;
  t->capacity = t->count = 0;
}

/* ---------------------------------------------------------------------------
 * the reader state and diagnostics
 * ------------------------------------------------------------------------- */

enum { SHOWN_BUFFERS = 4, SHOWN_SIZE = 200, SHOWN_MAX_CHARS = 60 };

/* A scene chosen with ir_read(path, scene), applied after everything is
 * read: replacing the outputs frees names that the name table points to. */
typedef struct {
  bool found;
  char *name;
  bool has_gravity;
  double gravity[3];
  bool has_outputs;
  ir_output *outputs;
  int noutputs;
  bool *joint_off, *driver_off, *force_off;
  ir_sim sim;
  yaml_node_t *jof_list;
  ir_flex **flex;   /* per body: the scene's modal settings, or NULL */
} chosen_scene;

typedef struct {
  const char *path;
  yaml_document_t *doc;
  ir_model *model;
  name_table names;
  chosen_scene scene;
  /* show_*() format user text into these, so a message can quote a few */
  char shown[SHOWN_BUFFERS][SHOWN_SIZE];
  int next_shown;
} reader;

static ir_loc loc_of(const yaml_node_t *n) {
  ir_loc loc = {(int)n->start_mark.line + 1, (int)n->start_mark.column + 1};
  return loc;
}

static const ir_loc file_start = {1, 1};

static void error_at(reader *r, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
static void error_at(reader *r, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_verror(r->path, loc, fmt, ap);
  va_end(ap);
}

static void note_at(reader *r, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
static void note_at(reader *r, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_vnote(r->path, loc, fmt, ap);
  va_end(ap);
}

/* User text, escaped (control characters would garble a terminal) and
 * shortened to keep messages on one line. */
static const char *show_text(reader *r, const char *s, size_t length) {
  char *out = r->shown[r->next_shown];
  r->next_shown = (r->next_shown + 1) % SHOWN_BUFFERS;
  size_t n = 0;
  for (size_t i = 0; i < length; i++) {
    unsigned char c = (unsigned char)s[i];
    if (n >= SHOWN_MAX_CHARS && (c & 0xC0) != 0x80) { /* not inside a UTF-8 character */
      memcpy(out + n, "...", 4);
      return out;
    }
    if (c < 0x20 || c == 0x7f)
      n += (size_t)snprintf(out + n, SHOWN_SIZE - n, "\\x%02x", c);
    else
      out[n++] = (char)c;
  }
  out[n] = '\0';
  return out;
}

static const char *scalar_text(const yaml_node_t *n) { return (const char *)n->data.scalar.value; }

static size_t scalar_length(const yaml_node_t *n) { return n->data.scalar.length; }

static bool scalar_equals(const yaml_node_t *n, const char *s) {
  size_t length = strlen(s);
  return n->type == YAML_SCALAR_NODE && scalar_length(n) == length &&
         memcmp(scalar_text(n), s, length) == 0;
}

/* "'text'", "an empty value", "a list" or "a mapping", for "(got ...)". */
static const char *show_node(reader *r, const yaml_node_t *n) {
  if (n == NULL)
    return "nothing";
  if (n->type == YAML_SEQUENCE_NODE)
    return "a list";
  if (n->type == YAML_MAPPING_NODE)
    return "a mapping";
  if (n->type != YAML_SCALAR_NODE)
    return "nothing";
  if (scalar_length(n) == 0 && n->data.scalar.style == YAML_PLAIN_SCALAR_STYLE)
    return "an empty value";
  const char *text = show_text(r, scalar_text(n), scalar_length(n));
  char *out = r->shown[r->next_shown];
  r->next_shown = (r->next_shown + 1) % SHOWN_BUFFERS;
  snprintf(out, SHOWN_SIZE, "'%s'", text);
  return out;
}

static yaml_node_t *node_at(reader *r, int index) { return yaml_document_get_node(r->doc, index); }

static int seq_length(const yaml_node_t *n) {
  return (int)(n->data.sequence.items.top - n->data.sequence.items.start);
}

static yaml_node_t *seq_item(reader *r, const yaml_node_t *n, int i) {
  return node_at(r, n->data.sequence.items.start[i]);
}

/* A comma-separated list of names for "(expected one of: ...)". */
enum { LIST_MAX_NAMES = 12 };

typedef struct {
  char text[512];
  size_t length;
  int count;
} name_list;

static void name_list_add(name_list *l, const char *name) {
  const char *piece = name;
  const char *separator = l->count > 0 ? ", " : "";
  if (l->count == LIST_MAX_NAMES)
    piece = "...";
  if (l->count <= LIST_MAX_NAMES) {
    size_t room = sizeof l->text - l->length;
    int n = snprintf(l->text + l->length, room, "%s%s", separator, piece);
    l->length += n < 0 ? 0 : ((size_t)n < room ? (size_t)n : room - 1);
  }
  l->count++;
}

static const char *join_choices(name_list *l, const char *const *choices) {
  l->length = 0;
  l->count = 0;
  l->text[0] = '\0';
  for (int i = 0; choices[i] != NULL; i++)
    name_list_add(l, choices[i]);
  return l->text;
}

static void list_names_of_kind(reader *r, name_kind kind, name_list *l) {
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
 * mappings: duplicate and unknown keys, and typed look-ups
 * ------------------------------------------------------------------------- */

typedef struct {
  reader *r;
  yaml_node_t *node;  /* the mapping */
  int npairs;
  bool *handled;      /* per pair: a duplicate or already reported */
  char what[160];     /* e.g. "rigid body 'crank'", for messages */
  ir_loc loc;         /* where "missing key" errors go */
  ir_loc last_loc;    /* the value of the last key looked up (else loc) */
} mapping;

typedef struct {
  const char *text;
  size_t length;
  int pair;
} key_ref;

static int compare_keys(const void *a, const void *b) {
  const key_ref *x = a, *y = b;
  size_t common = x->length < y->length ? x->length : y->length;
  int c = memcmp(x->text, y->text, common);
  if (c != 0)
    return c;
  if (x->length != y->length)
    return x->length < y->length ? -1 : 1;
  return (x->pair > y->pair) - (x->pair < y->pair); /* first occurrence first */
}

static yaml_node_t *map_key_node(const mapping *m, int i) {
  return node_at(m->r, m->node->data.mapping.pairs.start[i].key);
}

static yaml_node_t *map_value_node(const mapping *m, int i) {
  return node_at(m->r, m->node->data.mapping.pairs.start[i].value);
}

static void map_describe(mapping *m, const char *fmt, ...) DIAG_PRINTF(2, 3);
static void map_describe(mapping *m, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(m->what, sizeof m->what, fmt, ap);
  va_end(ap);
}

/* Reports duplicate and non-scalar keys (those are then ignored).  On a
 * non-mapping, reports it and returns false; the look-ups then find nothing
 * and map_close is still safe to call. */
static bool map_open(mapping *m, reader *r, yaml_node_t *node, ir_loc loc, const char *fmt, ...)
    DIAG_PRINTF(5, 6);
static bool map_open(mapping *m, reader *r, yaml_node_t *node, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(m->what, sizeof m->what, fmt, ap);
  va_end(ap);
  m->r = r;
  m->node = NULL;
  m->npairs = 0;
  m->handled = NULL;
  m->loc = m->last_loc = loc;
  if (node == NULL || node->type != YAML_MAPPING_NODE) {
    error_at(r, node ? loc_of(node) : loc, "%s must be a mapping (got %s)", m->what,
             show_node(r, node));
    return false;
  }
  m->node = node;
  m->npairs = (int)(node->data.mapping.pairs.top - node->data.mapping.pairs.start);
  m->handled = xcalloc((size_t)m->npairs, sizeof *m->handled);

  key_ref *keys = xcalloc((size_t)m->npairs, sizeof *keys);
  int nkeys = 0;
  for (int i = 0; i < m->npairs; i++) {
    yaml_node_t *key = map_key_node(m, i);
    if (key->type != YAML_SCALAR_NODE) {
      error_at(r, loc_of(key), "keys in %s must be plain names (got %s)", m->what,
               show_node(r, key));
      m->handled[i] = true;
      continue;
    }
    keys[nkeys].text = scalar_text(key);
    keys[nkeys].length = scalar_length(key);
    keys[nkeys].pair = i;
    nkeys++;
  }
  qsort(keys, (size_t)nkeys, sizeof *keys, compare_keys);
  for (int k = 1; k < nkeys; k++) {
    int first = k - 1;
    while (k < nkeys && keys[k].length == keys[first].length &&
           memcmp(keys[k].text, keys[first].text, keys[k].length) == 0) {
      yaml_node_t *dup = map_key_node(m, keys[k].pair);
      error_at(r, loc_of(dup), "duplicate key '%s' (first at line %d)",
               show_text(r, keys[k].text, keys[k].length),
               loc_of(map_key_node(m, keys[first].pair)).line);
      m->handled[keys[k].pair] = true;
      k++;
    }
  }
  free(keys);
  return true;
}

static void map_close(mapping *m) {
  free(m->handled);
  m->handled = NULL;
}

static int map_find(const mapping *m, const char *key) {
  for (int i = 0; i < m->npairs; i++)
    if (!m->handled[i] && scalar_equals(map_key_node(m, i), key))
      return i;
  return -1;
}

static bool map_has(const mapping *m, const char *key) { return map_find(m, key) >= 0; }

static yaml_node_t *map_get(mapping *m, const char *key) {
  int i = map_find(m, key);
  if (i < 0) {
    m->last_loc = m->loc;
    return NULL;
  }
  yaml_node_t *value = map_value_node(m, i);
  m->last_loc = loc_of(value);
  return value;
}

/* A key that must not be here, with a specific explanation. */
static void map_reject(mapping *m, const char *key, const char *fmt, ...) DIAG_PRINTF(3, 4);
static void map_reject(mapping *m, const char *key, const char *fmt, ...) {
  int i = map_find(m, key);
  if (i < 0)
    return;
  va_list ap;
  va_start(ap, fmt);
  diag_verror(m->r->path, loc_of(map_key_node(m, i)), fmt, ap);
  va_end(ap);
  m->handled[i] = true;
}

/* Every key not in 'expected' (NULL-terminated) is an error. */
static void map_check_keys(mapping *m, const char *const *expected) {
  for (int i = 0; i < m->npairs; i++) {
    if (m->handled[i])
      continue;
    yaml_node_t *key = map_key_node(m, i);
    bool known = false;
    for (int k = 0; expected[k] != NULL && !known; k++)
      known = scalar_equals(key, expected[k]);
    if (!known) {
      name_list l;
      error_at(m->r, loc_of(key), "unknown key '%s' in %s (expected one of: %s)",
               show_text(m->r, scalar_text(key), scalar_length(key)), m->what,
               join_choices(&l, expected));
      m->handled[i] = true;
    }
  }
}

static yaml_node_t *map_require(mapping *m, const char *key, bool required, const char *expected) {
  yaml_node_t *n = map_get(m, key);
  if (n == NULL && required)
    error_at(m->r, m->loc, "missing '%s' in %s (expected %s)", key, m->what, expected);
  return n;
}

/* ---------------------------------------------------------------------------
 * values
 * ------------------------------------------------------------------------- */

/* 'label' names the value in messages, e.g. "'mass'" or "element 2 of 'point'". */
static bool to_number(reader *r, yaml_node_t *n, const char *label, double *out) {
  if (n->type == YAML_SCALAR_NODE && scalar_length(n) > 0) {
    const char *text = scalar_text(n);
    char *end = NULL;
    /* strtod would skip leading blanks; a quoted " 1" is not a number */
    bool blank_start = text[0] == ' ' || text[0] == '\t' || text[0] == '\n' || text[0] == '\r';
    double value = blank_start ? 0 : strtod(text, &end);
    if (!blank_start && end == text + scalar_length(n)) {
      if (isfinite(value)) {
        *out = value;
        return true;
      }
      error_at(r, loc_of(n), "%s must be a finite number (got %s)", label, show_node(r, n));
      return false;
    }
  }
  error_at(r, loc_of(n), "%s must be a number (got %s)", label, show_node(r, n));
  return false;
}

/* Writes 'out' only if the whole vector is valid. */
static bool to_vector(reader *r, yaml_node_t *n, const char *label, int length, double *out) {
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "%s: expected a list of %d numbers, got %s", label, length,
             show_node(r, n));
    return false;
  }
  if (seq_length(n) != length) {
    error_at(r, loc_of(n), "%s: expected a list of %d numbers, got %d", label, length,
             seq_length(n));
    return false;
  }
  double value[9];
  if (length > 9)
    return false;
  bool ok = true;
  for (int i = 0; i < length; i++) {
    char item_label[SHOWN_SIZE];
    snprintf(item_label, sizeof item_label, "element %d of %s", i + 1, label);
    ok = to_number(r, seq_item(r, n, i), item_label, &value[i]) && ok;
  }
  if (ok)
    memcpy(out, value, (size_t)length * sizeof *out);
  return ok;
}

/* 'count' vectors of 'length' numbers, stored one after the other. */
static bool to_vector_list(reader *r, yaml_node_t *n, const char *label, int count, int length,
                           double *out) {
  if (n->type != YAML_SEQUENCE_NODE || seq_length(n) != count) {
    char got[SHOWN_SIZE];
    if (n->type == YAML_SEQUENCE_NODE)
      snprintf(got, sizeof got, "%d items", seq_length(n));
    else
      snprintf(got, sizeof got, "%s", show_node(r, n));
    error_at(r, loc_of(n), "%s: expected a list of %d vectors of %d numbers, got %s", label,
             count, length, got);
    return false;
  }
  double value[9];
  if (count * length > 9)
    return false;
  bool ok = true;
  for (int i = 0; i < count; i++) {
    char item_label[SHOWN_SIZE];
    snprintf(item_label, sizeof item_label, "item %d of %s", i + 1, label);
    ok = to_vector(r, seq_item(r, n, i), item_label, length, value + i * length) && ok;
  }
  if (ok)
    memcpy(out, value, (size_t)(count * length) * sizeof *out);
  return ok;
}

/* A table of at least 2 pairs (x, y) with x strictly increasing; 'pair'
 * describes an item for messages, e.g. "[t, x]". */
static bool to_table(reader *r, yaml_node_t *n, const char *label, const char *pair,
                     const char *x_name, double **table, int *count) {
  if (n->type != YAML_SEQUENCE_NODE || seq_length(n) < 2) {
    char got[SHOWN_SIZE];
    if (n->type == YAML_SEQUENCE_NODE)
      snprintf(got, sizeof got, "%d", seq_length(n));
    else
      snprintf(got, sizeof got, "%s", show_node(r, n));
    error_at(r, loc_of(n), "%s: expected a list of at least 2 %s pairs, got %s", label, pair,
             got);
    return false;
  }
  int npoints = seq_length(n);
  double *values = xcalloc((size_t)npoints * 2, sizeof *values);
  bool ok = true;
  for (int i = 0; i < npoints; i++) {
    char item_label[SHOWN_SIZE];
    snprintf(item_label, sizeof item_label, "item %d of %s", i + 1, label);
    yaml_node_t *item = seq_item(r, n, i);
    if (!to_vector(r, item, item_label, 2, values + 2 * i)) {
      ok = false;
      continue;
    }
    if (ok && i > 0 && !(values[2 * i] > values[2 * i - 2])) {
      error_at(r, loc_of(item),
               "%s: %s must be strictly increasing (item %d has %s = %g after %s = %g)", label,
               x_name, i + 1, x_name, values[2 * i], x_name, values[2 * i - 2]);
      ok = false;
    }
  }
  if (!ok) {
    free(values);
    return false;
  }
  *table = values;
  *count = npoints;
  return true;
}

static bool to_choice(reader *r, yaml_node_t *n, const char *key, const char *noun,
                      const char *const *choices, int *out) {
  name_list l;
  if (n->type != YAML_SCALAR_NODE) {
    error_at(r, loc_of(n), "'%s' must be one of: %s (got %s)", key, join_choices(&l, choices),
             show_node(r, n));
    return false;
  }
  for (int i = 0; choices[i] != NULL; i++) {
    if (scalar_equals(n, choices[i])) {
      *out = i;
      return true;
    }
  }
  error_at(r, loc_of(n), "unknown %s %s (expected one of: %s)", noun, show_node(r, n),
           join_choices(&l, choices));
  return false;
}

static void quote_key(char *label, size_t size, const char *key) {
  snprintf(label, size, "'%s'", key);
}

static bool get_number(mapping *m, const char *key, bool required, double *out) {
  yaml_node_t *n = map_require(m, key, required, "a number");
  char label[64];
  quote_key(label, sizeof label, key);
  return n != NULL && to_number(m->r, n, label, out);
}

static bool get_positive(mapping *m, const char *key, bool required, double *out) {
  double value;
  if (!get_number(m, key, required, &value))
    return false;
  if (!(value > 0)) {
    error_at(m->r, m->last_loc, "'%s' must be positive (got %g)", key, value);
    return false;
  }
  *out = value;
  return true;
}

static bool get_nonnegative(mapping *m, const char *key, bool required, double *out) {
  double value;
  if (!get_number(m, key, required, &value))
    return false;
  if (!(value >= 0)) {
    error_at(m->r, m->last_loc, "'%s' must be >= 0 (got %g)", key, value);
    return false;
  }
  *out = value;
  return true;
}

static bool get_vector(mapping *m, const char *key, int length, bool required, double *out) {
  char expected[32], label[64];
  snprintf(expected, sizeof expected, "a %d-vector", length);
  yaml_node_t *n = map_require(m, key, required, expected);
  quote_key(label, sizeof label, key);
  return n != NULL && to_vector(m->r, n, label, length, out);
}

static bool get_choice(mapping *m, const char *key, const char *noun, const char *const *choices,
                       bool required, int *out) {
  name_list l;
  char expected[sizeof l.text + 16];
  snprintf(expected, sizeof expected, "one of: %s", join_choices(&l, choices));
  yaml_node_t *n = map_require(m, key, required, expected);
  return n != NULL && to_choice(m->r, n, key, noun, choices, out);
}

/* A unit direction; 'label' as for to_number. */
static bool to_unit_axis(reader *r, yaml_node_t *n, const char *label, double out[3]) {
  double v[3];
  if (!to_vector(r, n, label, 3, v))
    return false;
  double length = norm3(v);
  if (!(length >= ZERO_LENGTH)) {
    error_at(r, loc_of(n), "zero-length axis (%s must be a nonzero direction)", label);
    return false;
  }
  scale3(v, 1 / length);
  memcpy(out, v, sizeof v);
  return true;
}

static bool get_axis(mapping *m, const char *key, bool required, double out[3]) {
  char label[64];
  yaml_node_t *n = map_require(m, key, required, "a 3-vector");
  quote_key(label, sizeof label, key);
  return n != NULL && to_unit_axis(m->r, n, label, out);
}

/* ---------------------------------------------------------------------------
 * names
 * ------------------------------------------------------------------------- */

static bool is_identifier(const char *s, size_t length) {
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

static bool is_c_keyword(const char *s) {
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
static bool check_identifier(reader *r, const yaml_node_t *n) {
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
static char *new_name(reader *r, const yaml_node_t *n, name_kind kind, int index,
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
static int resolve_name(reader *r, yaml_node_t *n, name_kind kind, const char *key) {
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

static bool get_ref(mapping *m, const char *key, name_kind kind, bool required, int *index,
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
static bool get_body_pair(mapping *m, int body[2], ir_loc body_loc[2]) {
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

static bool is_null_scalar(const yaml_node_t *n) {
  return n->type == YAML_SCALAR_NODE &&
         (scalar_length(n) == 0 || scalar_equals(n, "~") || scalar_equals(n, "null"));
}

/* node index 'n' on flexible body b (checked against its node count when known) */
static int to_fe_node(reader *r, yaml_node_t *n, const ir_body *b) {
  double v;
  char label[SHOWN_SIZE];
  snprintf(label, sizeof label, "FE node of body '%s'", b->name);
  if (!to_number(r, n, label, &v)) return -1;
  int nn = b->flex && b->flex->nodes ? b->flex->nnodes : -1;
  if (v != floor(v) || v < 0 || (nn >= 0 && v >= nn)) {
    if (nn >= 0)
      error_at(r, loc_of(n), "body '%s' has no node %g (its nodes are numbered 0 to %d)", b->name, v, nn - 1);
    else
      error_at(r, loc_of(n), "%s must be a node number (got %g)", label, v);
    return -1;
  }
  return (int)v;
}

/* FE nodes of an element on one or two bodies: 'node: K' on its one flexible
 * body, or 'nodes: [K0, K1]' with ~ on a side that is not flexible. */
static bool get_fe_nodes(mapping *m, const int body[2], int node[2]) {
  reader *r = m->r;
  const ir_model *model = r->model;
  yaml_node_t *one = map_get(m, "node"), *two = map_get(m, "nodes");
  node[0] = node[1] = -1;
  if (one != NULL && two != NULL) {
    error_at(r, loc_of(two), "give either 'node' or 'nodes', not both");
    return false;
  }
  bool flex[2];
  for (int s = 0; s < 2; s++)
    flex[s] = body[s] >= 0 && model->bodies[body[s]].kind == BODY_FLEXIBLE && model->bodies[body[s]].flex;
  if (one != NULL) {
    if (flex[0] && flex[1]) {
      error_at(r, loc_of(one), "both bodies are flexible: say which node of each with 'nodes: [K0, K1]'");
      return false;
    }
    if (!flex[0] && !flex[1]) {
      error_at(r, loc_of(one), "FE nodes need a flexible body (no body of %s is flexible)", m->what);
      return false;
    }
    int s = flex[0] ? 0 : 1;
    node[s] = to_fe_node(r, one, &model->bodies[body[s]]);
  }
  if (two != NULL) {
    if (two->type != YAML_SEQUENCE_NODE || seq_length(two) != 2) {
      error_at(r, loc_of(two), "'nodes': expected [K0, K1] with ~ for a body that is not flexible");
      return false;
    }
    for (int s = 0; s < 2; s++) {
      yaml_node_t *item = seq_item(r, two, s);
      if (is_null_scalar(item)) continue;
      if (!flex[s]) {
        error_at(r, loc_of(item), "FE nodes need a flexible body ('%s' is not flexible; use ~)",
                 body[s] >= 0 ? model->bodies[body[s]].name : "?");
        continue;
      }
      node[s] = to_fe_node(r, item, &model->bodies[body[s]]);
    }
  }
  return node[0] >= 0 || node[1] >= 0;
}

static void node_global(const ir_body *b, int k, double out[3]);

/* whether the element is given on FE nodes (true also when the nodes given
 * were wrong: that was reported, and the point is then not required) */
static bool fe_nodes_given(mapping *m, const int body[2], int node[2]) {
  bool given = get_fe_nodes(m, body, node) || map_has(m, "node") || map_has(m, "nodes");
  /* a body from a modal data file: its node positions are read later, so the
     point must be given (it is checked against the node when the file is read) */
  for (int s = 0; s < 2; s++)
    if (node[s] >= 0 && !m->r->model->bodies[body[s]].flex->nodes) return false;
  return given;
}

/* the point of side s: the node's position when a node is given (a point
 * given as well must coincide with it) */
static void check_node_point(reader *r, const ir_model *model, ir_loc loc, const int body[2],
                             const int node[2], bool point_given, double *point) {
  for (int s = 0; s < 2; s++) {
    if (node[s] < 0 || !model->bodies[body[s]].flex || !model->bodies[body[s]].flex->nodes) continue;
    double P[3];
    node_global(&model->bodies[body[s]], node[s], P);
    if (!point_given) {
      memcpy(point + 3 * s, P, sizeof P);
    } else if (distance3(P, point + 3 * s) > 1e-9 * (1 + norm3(P))) {
      error_at(r, loc, "the point is %g away from node %d of body '%s' (expected the node's position "
               "[%g, %g, %g], or leave the point out)", distance3(P, point + 3 * s), node[s],
               model->bodies[body[s]].name, P[0], P[1], P[2]);
    }
  }
}

/* ---------------------------------------------------------------------------
 * bodies
 * ------------------------------------------------------------------------- */

/* Eigenvalues of a symmetric 3x3 matrix by cyclic Jacobi rotations. */
static void symmetric_eigenvalues(const double matrix[9], double eigenvalues[3]) {
  double a[3][3];
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      a[i][j] = matrix[3 * i + j];
  for (int sweep = 0; sweep < 50; sweep++) {
    double off = a[0][1] * a[0][1] + a[0][2] * a[0][2] + a[1][2] * a[1][2];
    double diagonal = a[0][0] * a[0][0] + a[1][1] * a[1][1] + a[2][2] * a[2][2];
    if (!(off > 1e-32 * diagonal))
      break;
    for (int p = 0; p < 2; p++) {
      for (int q = p + 1; q < 3; q++) {
        if (a[p][q] == 0)
          continue;
        double theta = (a[q][q] - a[p][p]) / (2 * a[p][q]);
        double t = fabs(theta) > 1e150 ? 0.5 / theta
                                       : (theta >= 0 ? 1 : -1) / (fabs(theta) + sqrt(theta * theta + 1));
        double c = 1 / sqrt(t * t + 1), s = t * c;
        for (int k = 0; k < 3; k++) { /* a := a P, then P^T a */
          double akp = a[k][p], akq = a[k][q];
          a[k][p] = c * akp - s * akq;
          a[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 3; k++) {
          double apk = a[p][k], aqk = a[q][k];
          a[p][k] = c * apk - s * aqk;
          a[q][k] = s * apk + c * aqk;
        }
      }
    }
  }
  for (int i = 0; i < 3; i++)
    eigenvalues[i] = a[i][i];
}

static bool cholesky_succeeds(const double a[9]) {
  double l[3][3] = {{0}};
  for (int j = 0; j < 3; j++) {
    double d = a[3 * j + j];
    for (int k = 0; k < j; k++)
      d -= l[j][k] * l[j][k];
    if (!(d > 0))
      return false;
    l[j][j] = sqrt(d);
    for (int i = j + 1; i < 3; i++) {
      double v = a[3 * i + j];
      for (int k = 0; k < j; k++)
        v -= l[i][k] * l[j][k];
      l[i][j] = v / l[j][j];
    }
  }
  return true;
}

/* [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 matrix; must be
 * symmetric positive definite with physically possible principal moments. */
static bool parse_inertia(reader *r, yaml_node_t *n, double inertia[9]) {
  double I[9] = {0};
  int length = n->type == YAML_SEQUENCE_NODE ? seq_length(n) : -1;
  bool matrix = length == 3 && seq_item(r, n, 0)->type == YAML_SEQUENCE_NODE;
  if (matrix) {
    if (!to_vector_list(r, n, "'inertia'", 3, 3, I))
      return false;
    double largest = 0;
    for (int i = 0; i < 9; i++)
      largest = fmax(largest, fabs(I[i]));
    for (int i = 0; i < 3; i++) {
      for (int j = i + 1; j < 3; j++) {
        if (fabs(I[3 * i + j] - I[3 * j + i]) > 1e-9 * largest) {
          error_at(r, loc_of(n),
                   "'inertia' must be symmetric (row %d column %d is %g but row %d column %d "
                   "is %g)",
                   i + 1, j + 1, I[3 * i + j], j + 1, i + 1, I[3 * j + i]);
          return false;
        }
        I[3 * i + j] = I[3 * j + i] = 0.5 * (I[3 * i + j] + I[3 * j + i]);
      }
    }
  } else if (length == 3 || length == 6) {
    double v[6] = {0};
    if (!to_vector(r, n, "'inertia'", length, v))
      return false;
    I[0] = v[0];
    I[4] = v[1];
    I[8] = v[2];
    I[1] = I[3] = v[3]; /* Ixy */
    I[2] = I[6] = v[4]; /* Ixz */
    I[5] = I[7] = v[5]; /* Iyz */
  } else {
    char got[SHOWN_SIZE];
    if (length >= 0)
      snprintf(got, sizeof got, "a list of %d", length);
    else
      snprintf(got, sizeof got, "%s", show_node(r, n));
    error_at(r, loc_of(n),
             "'inertia': expected [Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 "
             "matrix, got %s",
             got);
    return false;
  }

  double moments[3];
  symmetric_eigenvalues(I, moments);
  if (!cholesky_succeeds(I)) {
    error_at(r, loc_of(n),
             "'inertia' is not positive definite (principal moments %g, %g, %g; all must be > 0)",
             moments[0], moments[1], moments[2]);
    return false;
  }
  double sum = moments[0] + moments[1] + moments[2];
  for (int i = 0; i < 3; i++) {
    double others = sum - moments[i];
    if (moments[i] > others + 1e-9 * sum) {
      error_at(r, loc_of(n),
               "'inertia' violates the triangle inequality: principal moment %g exceeds the "
               "sum of the other two (%g)",
               moments[i], others);
      return false;
    }
  }
  memcpy(inertia, I, sizeof I);
  return true;
}

/* Euler parameters [e0, e1, e2, e3] (normalized here) or {axis, angle}. */
static void parse_orientation(reader *r, yaml_node_t *n, const char *owner, double e[4]) {
  if (n->type == YAML_SEQUENCE_NODE) {
    double v[4];
    if (!to_vector(r, n, "'orientation'", 4, v))
      return;
    double length = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
    if (!(length >= ZERO_LENGTH)) {
      error_at(r, loc_of(n), "'orientation': the Euler parameters have zero length");
      return;
    }
    for (int i = 0; i < 4; i++)
      e[i] = v[i] / length;
  } else if (n->type == YAML_MAPPING_NODE) {
    mapping m;
    map_open(&m, r, n, loc_of(n), "'orientation' of %s", owner);
    static const char *const keys[] = {"axis", "angle", NULL};
    map_check_keys(&m, keys);
    double axis[3], angle;
    bool ok = get_axis(&m, "axis", true, axis);
    ok = get_number(&m, "angle", true, &angle) && ok;
    if (ok) {
      e[0] = cos(0.5 * angle);
      for (int i = 0; i < 3; i++)
        e[i + 1] = axis[i] * sin(0.5 * angle);
    }
    map_close(&m);
  } else {
    error_at(r, loc_of(n),
             "'orientation': expected Euler parameters [e0, e1, e2, e3] or {axis: [x, y, z], "
             "angle: radians}, got %s",
             show_node(r, n));
  }
}

static const char *const body_type_names[] = {"rigid", "virtual", "flexible", NULL};

/* Keys every body kind understands. */
static void parse_body_state(mapping *m, ir_body *b) {
  get_vector(m, "position", 3, false, b->position);
  yaml_node_t *orientation = map_get(m, "orientation");
  if (orientation != NULL)
    parse_orientation(m->r, orientation, m->what, b->orientation);
  get_vector(m, "velocity", 3, false, b->velocity);
  get_vector(m, "angular_velocity", 3, false, b->angular_velocity);
}

static const char *const shape_type_names[] = {"box", "cylinder", "sphere", NULL};

/* 'shape': what the browser animation draws for the body (mbcc animate); the
 * simulation does not use it.  Like every vector of the model, 'center' and
 * 'axis' are global at t = 0; they are stored in body axes. */
static void parse_shape(mapping *body, ir_body *b) {
  yaml_node_t *n = map_get(body, "shape");
  if (n == NULL)
    return;
  mapping m;
  if (!map_open(&m, body->r, n, loc_of(n), "'shape' of body '%s'", b->name)) {
    map_close(&m);
    return;
  }
  static const char *const keys[] = {"type", "size", "radius", "length", "axis", "center", NULL};
  int type;
  ir_shape *S = &b->shape;
  double A[9], axis[3] = {0, 0, 1}, center[3];
  quaternion_to_matrix(b->orientation, A);
  for (int i = 0; i < 3; i++) { /* the defaults: the body's z axis, its origin */
    axis[i] = A[3 * i + 2];
    center[i] = b->position[i];
  }
  if (get_choice(&m, "type", "shape type", shape_type_names, true, &type)) {
    S->kind = (ir_shape_kind)(type + 1);
    if (S->kind != SHAPE_BOX)
      map_reject(&m, "size", "'size' is for a box; a %s has 'radius'", shape_type_names[type]);
    if (S->kind != SHAPE_CYLINDER) {
      map_reject(&m, "length", "'length' is for a cylinder");
      map_reject(&m, "axis", "'axis' is for a cylinder");
    }
    if (S->kind == SHAPE_BOX) {
      map_reject(&m, "radius", "'radius' is for a cylinder or a sphere; a box has 'size'");
      if (get_vector(&m, "size", 3, true, S->size))
        for (int i = 0; i < 3; i++)
          if (!(S->size[i] > 0))
            error_at(m.r, m.last_loc, "'size' of a box: every edge must be positive (got %g)",
                     S->size[i]);
    } else {
      get_positive(&m, "radius", true, &S->radius);
    }
    if (S->kind == SHAPE_CYLINDER) {
      get_positive(&m, "length", true, &S->length);
      get_axis(&m, "axis", false, axis);
    }
  }
  get_vector(&m, "center", 3, false, center);
  map_check_keys(&m, keys);
  map_close(&m);
  for (int i = 0; i < 3; i++) { /* to body axes: A^T axis, A^T (center - position) */
    S->axis[i] = S->offset[i] = 0;
    for (int k = 0; k < 3; k++) {
      S->axis[i] += A[3 * k + i] * axis[k];
      S->offset[i] += A[3 * k + i] * (center[k] - b->position[k]);
    }
  }
}

static void parse_rigid_body(mapping *m, ir_body *b) {
  static const char *const keys[] = {"type",        "mass",     "inertia",          "position",
                                     "orientation", "velocity", "angular_velocity", "shape", NULL};
  map_check_keys(m, keys);
  get_positive(m, "mass", true, &b->mass);
  yaml_node_t *inertia = map_require(m, "inertia", true,
                                     "[Ixx, Iyy, Izz], [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] or a 3x3 "
                                     "matrix");
  if (inertia != NULL)
    parse_inertia(m->r, inertia, b->inertia);
  parse_body_state(m, b);
  parse_shape(m, b);
}

static void parse_virtual_body(mapping *m, ir_body *b) {
  static const char *const keys[] = {"type", "position", "orientation", "velocity",
                                     "angular_velocity", "shape", NULL};
  map_reject(m, "mass", "virtual body '%s' is massless: remove 'mass'", b->name);
  map_reject(m, "inertia", "virtual body '%s' is massless: remove 'inertia'", b->name);
  map_check_keys(m, keys);
  parse_body_state(m, b);
  parse_shape(m, b);
}

/* A list of node indices, each < nnodes (nnodes < 0: not checked yet). */
static int *to_node_list(reader *r, yaml_node_t *n, const char *label, int nnodes, int *count) {
  *count = 0;
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "%s: expected a list of node numbers, got %s", label, show_node(r, n));
    return NULL;
  }
  int k = seq_length(n);
  int *out = xcalloc((size_t)k + 1, sizeof *out);
  for (int i = 0; i < k; i++) {
    double v;
    yaml_node_t *item = seq_item(r, n, i);
    char item_label[SHOWN_SIZE];
    snprintf(item_label, sizeof item_label, "item %d of %s", i + 1, label);
    if (!to_number(r, item, item_label, &v)) continue;
    if (v != floor(v) || v < 0 || (nnodes >= 0 && v >= nnodes)) {
      error_at(r, loc_of(item), "%s: node %g does not exist (nodes are numbered 0 to %d)", label, v,
               nnodes - 1);
      continue;
    }
    out[(*count)++] = (int)v;
  }
  return out;
}

static const char *const theory_names[] = {"euler_bernoulli", "timoshenko", NULL};
static const char *const mass_kind_names[] = {"lumped", "consistent", NULL};
static const char *const coupling_names[] = {"full", "partial", "constant", "rigid", NULL};

/* section and material of a beam (fields of ir_beam other than the nodes) */
static void parse_beam_properties(reader *r, mapping *body, ir_beam *proto) {
  yaml_node_t *n = map_require(body, "section", true, "a mapping {area, Iy, Iz, J, ...}");
  if (n != NULL) {
    mapping m;
    if (map_open(&m, r, n, loc_of(n), "'section' of %s", body->what)) {
      static const char *const keys[] = {"area", "Iy", "Iz", "J", "shear_y", "shear_z", "yaxis", NULL};
      map_check_keys(&m, keys);
      get_positive(&m, "area", true, &proto->A);
      /* defaults: a solid circular section of that area */
      proto->Iy = proto->Iz = proto->A * proto->A / (4 * PI);
      proto->J = 2 * proto->Iy;
      get_positive(&m, "Iy", false, &proto->Iy);
      get_positive(&m, "Iz", false, &proto->Iz);
      get_positive(&m, "J", false, &proto->J);
      if (proto->theory == BEAM_TIMOSHENKO) proto->shear_y = proto->shear_z = 5.0 / 6.0;
      get_positive(&m, "shear_y", false, &proto->shear_y);
      get_positive(&m, "shear_z", false, &proto->shear_z);
      if (proto->theory == BEAM_EULER_BERNOULLI) proto->shear_y = proto->shear_z = 0;
      get_axis(&m, "yaxis", false, proto->yaxis);
    }
    map_close(&m);
  }
  n = map_require(body, "material", true, "a mapping {E, nu or G, density}");
  if (n != NULL) {
    mapping m;
    if (map_open(&m, r, n, loc_of(n), "'material' of %s", body->what)) {
      static const char *const keys[] = {"E", "G", "nu", "density", NULL};
      map_check_keys(&m, keys);
      get_positive(&m, "E", true, &proto->E);
      get_positive(&m, "density", true, &proto->rho);
      double nu = 0.3;
      bool has_nu = get_number(&m, "nu", false, &nu);
      if (has_nu && !(nu > -1 && nu < 0.5))
        error_at(r, m.last_loc, "'nu' must lie between -1 and 0.5 (got %g)", nu);
      proto->G = proto->E / (2 * (1 + nu));
      if (map_has(&m, "G")) {
        if (has_nu) error_at(r, m.loc, "give either 'G' or 'nu', not both");
        get_positive(&m, "G", false, &proto->G);
      }
    }
    map_close(&m);
  }
}

/* A flexible body: an FE beam model (line generator or nodes and beams) or a
 * modal data file, with reference conditions, mode selection, damping and
 * coupling.  Node positions are global at t = 0; they are stored in body axes
 * relative to the body frame origin. */
/* The modal settings of a flexible body (a body definition or a scene's
 * override): 'modes', 'damping', 'coupling'.  Only the keys given change fx. */
static void parse_modal_settings(mapping *m, ir_flex *fx) {
  reader *r = m->r;
  int c;
  if (get_choice(m, "coupling", "coupling", coupling_names, false, &c)) fx->coupling = (ir_coupling)c;
  /* mode selection */
  yaml_node_t *modes = map_get(m, "modes");
  if (modes != NULL) {
    if (modes->type == YAML_SCALAR_NODE && scalar_equals(modes, "all")) {
      fx->select = MODES_ALL;
    } else if (modes->type == YAML_SCALAR_NODE) {
      double k;
      if (to_number(r, modes, "'modes'", &k)) {
        if (k != floor(k) || k < 1) error_at(r, loc_of(modes), "'modes' must be a positive whole number, 'all' or a mapping (got %g)", k);
        fx->select = MODES_COUNT;
        fx->count = (int)k;
      }
    } else {
      mapping mm;
      if (map_open(&mm, r, modes, loc_of(modes), "'modes' of %s", m->what)) {
        static const char *const mkeys[] = {"count", "max_frequency", "list", NULL};
        map_check_keys(&mm, mkeys);
        double v;
        if (map_has(&mm, "count") + map_has(&mm, "max_frequency") + map_has(&mm, "list") != 1)
          error_at(r, loc_of(modes), "'modes' takes exactly one of 'count', 'max_frequency', 'list'");
        if (get_positive(&mm, "count", false, &v)) { fx->select = MODES_COUNT; fx->count = (int)v; }
        if (get_positive(&mm, "max_frequency", false, &v)) { fx->select = MODES_MAX_FREQUENCY; fx->max_frequency = v; }
        yaml_node_t *l = map_get(&mm, "list");
        if (l != NULL) {
          fx->select = MODES_LIST;
          fx->list = to_node_list(r, l, "'list' of modes", -1, &fx->nlist);
          for (int i = 0; i < fx->nlist; i++)
            if (fx->list[i] < 1) error_at(r, loc_of(l), "mode numbers start at 1");
        }
      }
      map_close(&mm);
    }
  }
  /* modal damping */
  yaml_node_t *damp = map_get(m, "damping");
  if (damp != NULL) {
    if (damp->type == YAML_SCALAR_NODE && scalar_equals(damp, "bands")) {
      fx->damping = DAMPING_BANDS;
    } else if (damp->type == YAML_SCALAR_NODE && scalar_equals(damp, "none")) {
      fx->damping = DAMPING_NONE;
    } else if (damp->type == YAML_SEQUENCE_NODE) {
      fx->damping = DAMPING_LIST;
      fx->nratios = seq_length(damp);
      fx->ratios = xcalloc((size_t)fx->nratios + 1, sizeof *fx->ratios);
      for (int i = 0; i < fx->nratios; i++) {
        char label[64];
        snprintf(label, sizeof label, "item %d of 'damping'", i + 1);
        if (to_number(r, seq_item(r, damp, i), label, &fx->ratios[i]) && fx->ratios[i] < 0)
          error_at(r, loc_of(seq_item(r, damp, i)), "%s must be >= 0", label);
      }
    } else if (to_number(r, damp, "'damping' (a ratio, 'bands', 'none' or a list)", &fx->ratio)) {
      fx->damping = DAMPING_RATIO;
      if (fx->ratio < 0) error_at(r, loc_of(damp), "'damping' must be >= 0 (got %g)", fx->ratio);
    }
  }
}

static void parse_flexible_body(mapping *m, ir_body *b, ir_loc type_loc) {
  reader *r = m->r;
  (void)type_loc;
  static const char *const keys[] = {
      "type",    "position",  "orientation", "velocity", "angular_velocity", "line",
      "nodes",   "beams",     "section",     "material", "theory",           "mass",
      "point_masses", "reference", "interface", "modes", "damping", "coupling", "modal_file", NULL};
  map_reject(m, "inertia", "flexible body '%s': its inertia comes from its FE model", b->name);
  map_check_keys(m, keys);
  ir_flex *fx = xcalloc(1, sizeof *fx);
  b->flex = fx;
  fx->loc = b->loc;
  fx->select = MODES_ALL;
  fx->coupling = COUPLING_FULL;
  fx->damping = DAMPING_BANDS; /* seed 001 section 2.6: the three-band default */
  yaml_node_t *orientation = map_get(m, "orientation");
  if (orientation != NULL) parse_orientation(r, orientation, m->what, b->orientation);
  get_vector(m, "velocity", 3, false, b->velocity);
  get_vector(m, "angular_velocity", 3, false, b->angular_velocity);
  yaml_node_t *modal_file = map_get(m, "modal_file");
  yaml_node_t *line = map_get(m, "line"), *nodes = map_get(m, "nodes");
  double *global = NULL; /* node positions, global */
  if (modal_file != NULL) {
    static const char *const fe_only[] = {"line", "nodes", "beams", "section", "material",
                                          "theory", "mass", "point_masses", "interface", NULL};
    for (int i = 0; fe_only[i]; i++)
      map_reject(m, fe_only[i], "flexible body '%s': '%s' does not go with 'modal_file'", b->name, fe_only[i]);
    if (modal_file->type != YAML_SCALAR_NODE) {
      error_at(r, loc_of(modal_file), "'modal_file' must be a file name (got %s)", show_node(r, modal_file));
    } else {
      /* relative to the model file's directory */
      const char *slash = strrchr(r->path, '/');
      const char *fname = scalar_text(modal_file);
      size_t dl = (slash && fname[0] != '/') ? (size_t)(slash - r->path + 1) : 0;
      fx->modal_file = xcalloc(dl + scalar_length(modal_file) + 1, 1);
      memcpy(fx->modal_file, r->path, dl);
      memcpy(fx->modal_file + dl, fname, scalar_length(modal_file));
    }
  } else if (line != NULL && nodes != NULL) {
    error_at(r, loc_of(nodes), "give either 'line' or 'nodes', not both");
  } else if (line == NULL && nodes == NULL) {
    error_at(r, m->loc, "flexible body '%s' needs an FE model ('line' or 'nodes' and 'beams') or a 'modal_file'", b->name);
  } else {
    ir_beam proto;
    memset(&proto, 0, sizeof proto);
    int th = 0;
    if (get_choice(m, "theory", "beam theory", theory_names, false, &th)) proto.theory = (ir_beam_theory)th;
    int mk = 0;
    if (get_choice(m, "mass", "mass matrix", mass_kind_names, false, &mk)) fx->mass = (ir_mass_kind)mk;
    if (line != NULL) {
      mapping lm;
      if (map_open(&lm, r, line, loc_of(line), "'line' of %s", m->what)) {
        static const char *const lkeys[] = {"from", "to", "elements", NULL};
        map_check_keys(&lm, lkeys);
        double p0[3], p1[3], ne = 0;
        bool ok = get_vector(&lm, "from", 3, true, p0);
        ok = get_vector(&lm, "to", 3, true, p1) && ok;
        ok = get_positive(&lm, "elements", true, &ne) && ok;
        if (ok && (ne != floor(ne) || ne > 100000)) {
          error_at(r, lm.last_loc, "'elements' must be a whole number (got %g)", ne);
          ok = false;
        }
        if (ok && distance3(p0, p1) <= ZERO_LENGTH) {
          error_at(r, loc_of(line), "'line' has zero length");
          ok = false;
        }
        if (ok) {
          int n = (int)ne;
          fx->nnodes = n + 1;
          global = xcalloc(3 * (size_t)(n + 1), sizeof *global);
          fx->node_loc = xcalloc((size_t)n + 1, sizeof *fx->node_loc);
          for (int k = 0; k <= n; k++) {
            for (int i = 0; i < 3; i++) global[3 * k + i] = p0[i] + (p1[i] - p0[i]) * k / n;
            fx->node_loc[k] = loc_of(line);
          }
          fx->nbeams = n;
          fx->beams = xcalloc((size_t)n, sizeof *fx->beams);
          for (int e = 0; e < n; e++) {
            fx->beams[e].node[0] = e;
            fx->beams[e].node[1] = e + 1;
            fx->beams[e].loc = loc_of(line);
          }
        }
      }
      map_close(&lm);
      map_reject(m, "beams", "'beams' does not go with 'line' (the line makes its own elements)");
    } else {
      int n = nodes->type == YAML_SEQUENCE_NODE ? seq_length(nodes) : 0;
      if (n < 2) {
        error_at(r, loc_of(nodes), "'nodes': expected a list of at least 2 points [x, y, z]");
      } else {
        fx->nnodes = n;
        global = xcalloc(3 * (size_t)n, sizeof *global);
        fx->node_loc = xcalloc((size_t)n, sizeof *fx->node_loc);
        for (int k = 0; k < n; k++) {
          char label[64];
          snprintf(label, sizeof label, "node %d", k);
          yaml_node_t *item = seq_item(r, nodes, k);
          to_vector(r, item, label, 3, global + 3 * k);
          fx->node_loc[k] = loc_of(item);
        }
        yaml_node_t *beams = map_get(m, "beams");
        if (beams == NULL) { /* consecutive nodes */
          fx->nbeams = n - 1;
          fx->beams = xcalloc((size_t)n, sizeof *fx->beams);
          for (int e = 0; e < n - 1; e++) {
            fx->beams[e].node[0] = e;
            fx->beams[e].node[1] = e + 1;
            fx->beams[e].loc = loc_of(nodes);
          }
        } else if (beams->type != YAML_SEQUENCE_NODE || seq_length(beams) < 1) {
          error_at(r, loc_of(beams), "'beams': expected a list of node pairs [i, j]");
        } else {
          int ne = seq_length(beams);
          fx->beams = xcalloc((size_t)ne, sizeof *fx->beams);
          for (int e = 0; e < ne; e++) {
            yaml_node_t *item = seq_item(r, beams, e);
            char label[64];
            snprintf(label, sizeof label, "beam %d", e + 1);
            int cnt = 0;
            int *pair = to_node_list(r, item, label, n, &cnt);
            if (cnt == 2 && pair[0] != pair[1] && seq_length(item) == 2) {
              fx->beams[fx->nbeams].node[0] = pair[0];
              fx->beams[fx->nbeams].node[1] = pair[1];
              fx->beams[fx->nbeams].loc = loc_of(item);
              fx->nbeams++;
            } else if (cnt == seq_length(item)) {
              error_at(r, loc_of(item), "%s: expected two different node numbers [i, j]", label);
            }
            free(pair);
          }
        }
      }
    }
    /* section and material: common to all beams */
    proto.yaxis[1] = 1; /* default: global y, unless along the element (fixed below) */
    bool yaxis_given = false;
    {
      yaml_node_t *sec = map_get(m, "section");
      if (sec != NULL && sec->type == YAML_MAPPING_NODE) {
        mapping probe;
        if (map_open(&probe, r, sec, loc_of(sec), "'section'")) yaxis_given = map_has(&probe, "yaxis");
        /* map_close of a probe would report nothing: keys are checked below */
        free(probe.handled);
      }
    }
    parse_beam_properties(r, m, &proto);
    for (int e = 0; e < fx->nbeams; e++) {
      ir_beam *bm = &fx->beams[e];
      int nd[2] = {bm->node[0], bm->node[1]};
      ir_loc loc = bm->loc;
      *bm = proto;
      bm->node[0] = nd[0];
      bm->node[1] = nd[1];
      bm->loc = loc;
      if (global && !yaxis_given) {
        /* a y axis across the element: global y, or global z for elements along y */
        double d[3];
        for (int i = 0; i < 3; i++) d[i] = global[3 * nd[1] + i] - global[3 * nd[0] + i];
        double len = norm3(d);
        if (len > 0 && fabs(d[1]) > 0.9 * len) { bm->yaxis[0] = bm->yaxis[1] = 0; bm->yaxis[2] = 1; }
      }
    }
    yaml_node_t *pm = map_get(m, "point_masses");
    if (pm != NULL) {
      if (pm->type != YAML_SEQUENCE_NODE) {
        error_at(r, loc_of(pm), "'point_masses': expected a list of {node, mass, inertia}");
      } else {
        int np = seq_length(pm);
        fx->point_masses = xcalloc((size_t)np + 1, sizeof *fx->point_masses);
        for (int i = 0; i < np; i++) {
          yaml_node_t *item = seq_item(r, pm, i);
          mapping pmm;
          if (map_open(&pmm, r, item, loc_of(item), "point mass %d of %s", i + 1, m->what)) {
            static const char *const pkeys[] = {"node", "mass", "inertia", NULL};
            map_check_keys(&pmm, pkeys);
            ir_point_mass *p = &fx->point_masses[fx->npoint_masses];
            double node = -1;
            p->loc = loc_of(item);
            if (get_number(&pmm, "node", true, &node) &&
                (node != floor(node) || node < 0 || node >= fx->nnodes))
              error_at(r, pmm.last_loc, "node %g does not exist (nodes are numbered 0 to %d)", node, fx->nnodes - 1);
            else
              p->node = (int)node;
            get_nonnegative(&pmm, "mass", true, &p->mass);
            yaml_node_t *in = map_get(&pmm, "inertia");
            if (in != NULL) parse_inertia(r, in, p->inertia);
            fx->npoint_masses++;
          }
          map_close(&pmm);
        }
      }
    }
  }

  /* reference conditions and Craig-Bampton interface */
  int nn = modal_file ? -1 : fx->nnodes;
  yaml_node_t *ref = map_get(m, "reference");
  if (ref != NULL) {
    fx->reference = to_node_list(r, ref, "'reference'", nn, &fx->nreference);
  } else if (!modal_file) {
    fx->reference = xcalloc(1, sizeof *fx->reference);
    fx->nreference = 1; /* node 0 */
  }
  yaml_node_t *itf = map_get(m, "interface");
  if (itf != NULL) fx->interface = to_node_list(r, itf, "'interface'", nn, &fx->ninterface);

  /* body frame: the given position, or the first reference node */
  bool has_position = get_vector(m, "position", 3, false, b->position);
  if (!has_position && global && fx->nreference > 0)
    memcpy(b->position, global + 3 * fx->reference[0], sizeof b->position);
  if (global) {
    double A[9];
    quaternion_to_matrix(b->orientation, A);
    fx->nodes = xcalloc(3 * (size_t)fx->nnodes, sizeof *fx->nodes);
    for (int k = 0; k < fx->nnodes; k++) {
      double d[3];
      for (int i = 0; i < 3; i++) d[i] = global[3 * k + i] - b->position[i];
      for (int i = 0; i < 3; i++)
        fx->nodes[3 * k + i] = A[i] * d[0] + A[3 + i] * d[1] + A[6 + i] * d[2];
    }
    /* beam y axes are given globally too */
    for (int e = 0; e < fx->nbeams; e++) {
      double y[3];
      memcpy(y, fx->beams[e].yaxis, sizeof y);
      for (int i = 0; i < 3; i++)
        fx->beams[e].yaxis[i] = A[i] * y[0] + A[3 + i] * y[1] + A[6 + i] * y[2];
    }
    free(global);
  }

  parse_modal_settings(m, fx);
}

/* global position of node k of flexible body b */
static void node_global(const ir_body *b, int k, double out[3]) {
  double A[9];
  quaternion_to_matrix(b->orientation, A);
  const double *x = b->flex->nodes + 3 * k;
  for (int i = 0; i < 3; i++) out[i] = b->position[i] + A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}

static void parse_body(reader *r, yaml_node_t *key, yaml_node_t *value) {
  ir_model *model = r->model;
  if (scalar_equals(key, "ground")) { /* skipped: there is a single ground */
    error_at(r, loc_of(key),
             "name 'ground' is reserved for the implicit ground body (do not define it)");
    return;
  }
  int index = model->nbodies++;
  ir_body *b = &model->bodies[index];
  b->loc = loc_of(key);
  b->orientation[0] = 1;
  b->name = new_name(r, key, NAME_BODY, index, NULL);
  b->kind = BODY_RIGID;

  mapping m;
  if (!map_open(&m, r, value, b->loc, "body '%s'", b->name))
    return;
  int type;
  if (get_choice(&m, "type", "body type", body_type_names, true, &type)) {
    ir_loc type_loc = m.last_loc;
    map_describe(&m, "%s body '%s'", body_type_names[type], b->name);
    switch (type) {
    case 0:
      b->kind = BODY_RIGID;
      parse_rigid_body(&m, b);
      break;
    case 1:
      b->kind = BODY_VIRTUAL;
      parse_virtual_body(&m, b);
      break;
    default:
      b->kind = BODY_FLEXIBLE;
      parse_flexible_body(&m, b, type_loc);
      break;
    }
  }
  map_close(&m);
}

static void parse_bodies(reader *r, yaml_node_t *n) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'bodies'"))
    return;
  if (m.npairs == 0)
    error_at(r, loc_of(n), "'bodies' is empty (expected at least one body besides the ground)");
  for (int i = 0; i < m.npairs; i++)
    if (!m.handled[i])
      parse_body(r, map_key_node(&m, i), map_value_node(&m, i));
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * joints
 * ------------------------------------------------------------------------- */

static const char *const joint_type_names[] = {"spherical", "revolute", "cylindrical", "prismatic",
                                               "universal", "fixed",    "distance",    NULL};

/* The global axis least aligned with 'axis', made perpendicular to it:
 * deterministic, and never nearly parallel. */
static void default_reference(const double axis[3], double ref[3]) {
  int k = 0;
  for (int i = 1; i < 3; i++)
    if (fabs(axis[i]) < fabs(axis[k]))
      k = i;
  double e[3] = {0, 0, 0};
  e[k] = 1;
  double along = dot3(e, axis);
  for (int i = 0; i < 3; i++)
    ref[i] = e[i] - along * axis[i];
  scale3(ref, 1 / norm3(ref));
}

static void parse_reference(mapping *m, ir_joint *j) {
  double ref[3];
  default_reference(j->axis[0], j->ref);
  if (!get_vector(m, "reference", 3, false, ref))
    return;
  double length = norm3(ref);
  if (!(length >= ZERO_LENGTH)) {
    error_at(m->r, m->last_loc, "zero-length reference ('reference' must be a nonzero direction)");
    return;
  }
  double along = dot3(ref, j->axis[0]);
  for (int i = 0; i < 3; i++)
    ref[i] -= along * j->axis[0][i];
  double across = norm3(ref);
  if (!(across >= ANGLE_TOLERANCE * length)) {
    error_at(m->r, m->last_loc,
             "'reference' is parallel to the joint axis (expected a direction across it)");
    return;
  }
  scale3(ref, 1 / across);
  memcpy(j->ref, ref, sizeof ref);
}

static void parse_joint(reader *r, yaml_node_t *key, yaml_node_t *value) {
  ir_model *model = r->model;
  int index = model->njoints++;
  ir_joint *j = &model->joints[index];
  j->loc = loc_of(key);
  j->name = new_name(r, key, NAME_JOINT, index, NULL);
  j->body[0] = j->body[1] = -1;
  j->node[0] = j->node[1] = -1;
  j->active = true;
  j->axis[0][2] = j->axis[1][2] = 1;
  j->ref[0] = 1;

  mapping m;
  if (!map_open(&m, r, value, j->loc, "joint '%s'", j->name))
    return;
  int type;
  if (!get_choice(&m, "type", "joint type", joint_type_names, true, &type)) {
    map_close(&m);
    return;
  }
  j->kind = (ir_joint_kind)type;
  map_describe(&m, "%s joint '%s'", joint_type_names[type], j->name);

  static const char *const distance_keys[] = {"type", "bodies", "points", "node", "nodes", NULL};
  static const char *const universal_keys[] = {"type", "bodies", "point", "axes", "reference",
                                               "node", "nodes", NULL};
  static const char *const axis_keys[] = {"type", "bodies", "point", "axis", "reference", "node",
                                          "nodes", NULL};
  map_check_keys(&m, j->kind == JOINT_DISTANCE    ? distance_keys
                     : j->kind == JOINT_UNIVERSAL ? universal_keys
                                                  : axis_keys);
  bool on_nodes = false;
  if (get_body_pair(&m, j->body, j->body_loc))
    on_nodes = fe_nodes_given(&m, j->body, j->node);

  if (j->kind == JOINT_DISTANCE) {
    yaml_node_t *n = map_require(&m, "points", !on_nodes, "a list of 2 points [x, y, z]");
    bool given = n != NULL && to_vector_list(r, n, "'points'", 2, 3, &j->point[0][0]);
    if (on_nodes) {
      /* a side on a node without 'points': the node; the other side needs the points */
      if (!given && (j->node[0] < 0 || j->node[1] < 0))
        error_at(r, j->loc, "distance joint '%s' needs 'points' for its side that is not on a node", j->name);
      check_node_point(r, model, n ? loc_of(n) : j->loc, j->body, j->node, given, &j->point[0][0]);
    }
    if (given || on_nodes) {
      double d[3];
      for (int i = 0; i < 3; i++)
        d[i] = j->point[1][i] - j->point[0][i];
      double length = norm3(d);
      if (!(length > ZERO_LENGTH)) {
        error_at(r, loc_of(n), "distance joint points coincide (they must be apart)");
      } else { /* the axis of a distance joint is its initial direction */
        scale3(d, 1 / length);
        memcpy(j->axis[0], d, sizeof d);
        memcpy(j->axis[1], d, sizeof d);
      }
    }
    default_reference(j->axis[0], j->ref);
    map_close(&m);
    return;
  }

  bool point_given = get_vector(&m, "point", 3, !on_nodes, j->point[0]);
  if (point_given)
    memcpy(j->point[1], j->point[0], sizeof j->point[0]);
  if (on_nodes) {
    check_node_point(r, model, point_given ? m.loc : j->loc, j->body, j->node, point_given, &j->point[0][0]);
    if (!point_given) /* both sides at the node that was given */
      memcpy(j->point[j->node[0] >= 0 ? 1 : 0], j->point[j->node[0] >= 0 ? 0 : 1], sizeof j->point[0]);
  }

  if (j->kind == JOINT_UNIVERSAL) {
    yaml_node_t *n = map_require(&m, "axes", true, "a list of 2 perpendicular axes");
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
  } else {
    bool required = j->kind == JOINT_REVOLUTE || j->kind == JOINT_CYLINDRICAL ||
                    j->kind == JOINT_PRISMATIC;
    if (get_axis(&m, "axis", required, j->axis[0]))
      memcpy(j->axis[1], j->axis[0], sizeof j->axis[0]);
  }
  parse_reference(&m, j);
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * time functions
 * ------------------------------------------------------------------------- */

static const char *const profile_type_names[] = {"constant", "constant_velocity", "polynomial",
                                                 "ramp",     "sine",              "table",
                                                 NULL};

/* 'label' says whose profile it is, e.g. "'motion' of driver 'd'". */
static void parse_profile(reader *r, yaml_node_t *n, const char *label, ir_profile *p) {
  memset(p, 0, sizeof *p);
  p->loc = loc_of(n);
  mapping m;
  if (!map_open(&m, r, n, p->loc, "%s", label))
    return;
  int type;
  if (!get_choice(&m, "type", "profile type", profile_type_names, true, &type)) {
    map_close(&m);
    return;
  }
  map_describe(&m, "%s profile", profile_type_names[type]);
  switch (type) {
  case 0: {
    static const char *const keys[] = {"type", "value", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_CONSTANT;
    p->nc = 1;
    get_number(&m, "value", true, &p->c[0]);
    break;
  }
  case 1: {
    static const char *const keys[] = {"type", "velocity", "initial", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_CONSTANT_VELOCITY;
    p->nc = 2;
    get_number(&m, "initial", false, &p->c[0]);
    get_number(&m, "velocity", true, &p->c[1]);
    break;
  }
  case 2: {
    static const char *const keys[] = {"type", "coefficients", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_POLYNOMIAL;
    yaml_node_t *list = map_require(&m, "coefficients", true, "a list of 1 to 8 numbers");
    if (list == NULL)
      break;
    int count = list->type == YAML_SEQUENCE_NODE ? seq_length(list) : -1;
    if (count < 1 || count > 8) {
      char got[SHOWN_SIZE];
      if (count >= 0)
        snprintf(got, sizeof got, "%d", count);
      else
        snprintf(got, sizeof got, "%s", show_node(r, list));
      error_at(r, loc_of(list), "'coefficients': expected a list of 1 to 8 numbers, got %s", got);
      break;
    }
    if (to_vector(r, list, "'coefficients'", count, p->c))
      p->nc = count;
    break;
  }
  case 3: {
    static const char *const keys[] = {"type", "t0", "x0", "t1", "x1", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_RAMP;
    p->nc = 4;
    bool ok = get_number(&m, "t0", true, &p->c[0]);
    get_number(&m, "x0", true, &p->c[1]);
    ok = get_number(&m, "t1", true, &p->c[2]) && ok;
    if (ok && !(p->c[2] > p->c[0]))
      error_at(r, loc_of(map_get(&m, "t1")), "'t1' (%g) must be greater than 't0' (%g)", p->c[2],
               p->c[0]);
    get_number(&m, "x1", true, &p->c[3]);
    break;
  }
  case 4: {
    static const char *const keys[] = {"type", "amplitude", "frequency", "phase", "offset", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_SINE;
    p->nc = 4;
    get_number(&m, "amplitude", true, &p->c[0]);
    get_number(&m, "frequency", true, &p->c[1]);
    get_number(&m, "phase", false, &p->c[2]);
    get_number(&m, "offset", false, &p->c[3]);
    break;
  }
  default: {
    static const char *const keys[] = {"type", "points", NULL};
    map_check_keys(&m, keys);
    p->kind = PROFILE_TABLE;
    yaml_node_t *points = map_require(&m, "points", true, "a list of [t, x] pairs");
    if (points != NULL)
      to_table(r, points, "'points'", "[t, x]", "t", &p->table, &p->ntable);
    break;
  }
  }
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * drivers
 * ------------------------------------------------------------------------- */

static const char *const dof_names[] = {"rotation", "translation", NULL};

static void parse_driver(reader *r, yaml_node_t *key, yaml_node_t *value) {
  ir_model *model = r->model;
  int index = model->ndrivers++;
  ir_driver *d = &model->drivers[index];
  d->loc = loc_of(key);
  d->name = new_name(r, key, NAME_DRIVER, index, NULL);
  d->joint = -1;
  d->active = true;

  mapping m;
  if (!map_open(&m, r, value, d->loc, "driver '%s'", d->name))
    return;
  static const char *const keys[] = {"joint", "dof", "motion", NULL};
  map_check_keys(&m, keys);

  ir_loc joint_loc = d->loc;
  get_ref(&m, "joint", NAME_JOINT, true, &d->joint, &joint_loc);
  int dof = -1;
  bool dof_given = map_has(&m, "dof");
  bool dof_valid = get_choice(&m, "dof", "dof", dof_names, false, &dof);
  ir_loc dof_loc = m.last_loc;
  if (d->joint >= 0) {
    const ir_joint *j = &model->joints[d->joint];
    bool rotates = j->kind == JOINT_REVOLUTE || j->kind == JOINT_CYLINDRICAL;
    bool slides = j->kind == JOINT_PRISMATIC || j->kind == JOINT_CYLINDRICAL;
    if (!rotates && !slides) {
      error_at(r, joint_loc,
               "%s joint '%s' cannot be driven (a driver needs a revolute, prismatic or "
               "cylindrical joint)",
               joint_type_names[j->kind], j->name);
    } else if (dof_valid) {
      if ((dof == DRIVER_ROTATION && !rotates) || (dof == DRIVER_TRANSLATION && !slides))
        error_at(r, dof_loc, "%s joint '%s' has no %s dof (expected 'dof: %s')",
                 joint_type_names[j->kind], j->name, dof_names[dof], dof_names[1 - dof]);
      d->dof = (ir_driver_dof)dof;
    } else if (!dof_given) {
      if (rotates && slides)
        error_at(r, d->loc,
                 "missing 'dof' in driver '%s' (expected rotation or translation: joint '%s' "
                 "is cylindrical)",
                 d->name, j->name);
      d->dof = rotates ? DRIVER_ROTATION : DRIVER_TRANSLATION;
    }
  }
  yaml_node_t *motion = map_require(&m, "motion", true, "a profile such as {type: constant, value: 0}");
  if (motion != NULL) {
    char label[SHOWN_SIZE];
    snprintf(label, sizeof label, "'motion' of driver '%s'", d->name);
    parse_profile(r, motion, label, &d->motion);
  }
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * forces
 * ------------------------------------------------------------------------- */

static const char *const force_type_names[] = {"force", "torque", "spring_damper", "bushing", "field", "beam", NULL};
static const char *const frame_names[] = {"global", "body", NULL};

/* A number (linear), {coefficient, exponent} (power) or {table: ...}. */
static void parse_law(reader *r, yaml_node_t *n, const char *key, const char *owner, ir_law *law) {
  law->loc = loc_of(n);
  char label[64];
  quote_key(label, sizeof label, key);
  if (n->type == YAML_SCALAR_NODE) {
    double coef;
    if (!to_number(r, n, label, &coef))
      return;
    if (!(coef >= 0)) {
      error_at(r, loc_of(n), "%s must be >= 0 (got %g)", label, coef);
      return;
    }
    law->kind = LAW_LINEAR;
    law->coef = coef;
    return;
  }
  if (n->type != YAML_MAPPING_NODE) {
    error_at(r, loc_of(n),
             "%s: expected a number, {coefficient: c, exponent: e} or {table: [[x, F], ...]}, "
             "got %s",
             label, show_node(r, n));
    return;
  }
  mapping m;
  map_open(&m, r, n, loc_of(n), "%s of %s", label, owner);
  if (map_has(&m, "table")) {
    static const char *const keys[] = {"table", NULL};
    map_check_keys(&m, keys);
    if (to_table(r, map_get(&m, "table"), "'table'", "[x, F]", "x", &law->table, &law->ntable))
      law->kind = LAW_TABLE;
  } else {
    static const char *const keys[] = {"coefficient", "exponent", NULL};
    map_check_keys(&m, keys);
    bool ok = get_nonnegative(&m, "coefficient", true, &law->coef);
    ok = get_positive(&m, "exponent", true, &law->exponent) && ok;
    if (ok)
      law->kind = LAW_POWER;
  }
  map_close(&m);
}

/* Six numbers, each >= 0 when 'nonnegative'. */
static void get_six(mapping *m, const char *key, bool required, bool nonnegative, double out[6]) {
  double v[6];
  if (!get_vector(m, key, 6, required, v))
    return;
  for (int i = 0; i < 6; i++) {
    if (nonnegative && !(v[i] >= 0)) {
      error_at(m->r, m->last_loc, "'%s': every entry must be >= 0 (entry %d is %g)", key, i + 1,
               v[i]);
      return;
    }
  }
  memcpy(out, v, sizeof v);
}

static void parse_point_load(mapping *m, ir_force *f) {
  reader *r = m->r;
  static const char *const force_keys[] = {"type",  "body",  "point", "value",
                                           "frame", "scale", "node", NULL};
  static const char *const torque_keys[] = {"type", "body", "value", "frame", "scale", "node", NULL};
  bool is_force = f->kind == FORCE_POINT_FORCE;
  map_check_keys(m, is_force ? force_keys : torque_keys);
  bool on_node = false;
  if (get_ref(m, "body", NAME_BODY, true, &f->body[0], &f->body_loc[0])) {
    memcpy(f->point[0], r->model->bodies[f->body[0]].position, sizeof f->point[0]);
    on_node = fe_nodes_given(m, f->body, f->node);
  }
  bool given = is_force && get_vector(m, "point", 3, false, f->point[0]);
  if (on_node) check_node_point(r, r->model, m->loc, f->body, f->node, given, &f->point[0][0]);
  get_vector(m, "value", 3, true, f->vector);
  int frame = FRAME_GLOBAL;
  if (get_choice(m, "frame", "frame", frame_names, false, &frame))
    f->frame = (ir_frame)frame;
  yaml_node_t *scale = map_get(m, "scale");
  if (scale != NULL) {
    char label[SHOWN_SIZE];
    snprintf(label, sizeof label, "'scale' of %s '%s'", force_type_names[f->kind], f->name);
    parse_profile(r, scale, label, &f->scale);
  }
}

static void parse_spring_damper(mapping *m, ir_force *f) {
  reader *r = m->r;
  static const char *const keys[] = {"type",    "bodies",      "points",  "stiffness",
                                     "damping", "free_length", "preload", "node", "nodes", NULL};
  map_check_keys(m, keys);
  bool on_nodes = get_body_pair(m, f->body, f->body_loc) && fe_nodes_given(m, f->body, f->node);
  bool all_nodes = f->node[0] >= 0 && f->node[1] >= 0;
  yaml_node_t *points = map_require(m, "points", !all_nodes, "a list of 2 points [x, y, z]");
  bool have_points = false, given = points != NULL && to_vector_list(r, points, "'points'", 2, 3, &f->point[0][0]);
  if (on_nodes) check_node_point(r, r->model, points ? loc_of(points) : m->loc, f->body, f->node, given, &f->point[0][0]);
  if (given || all_nodes) {
    have_points = distance3(f->point[0], f->point[1]) > ZERO_LENGTH;
    if (!have_points)
      error_at(r, points ? loc_of(points) : m->loc,
               "spring_damper end points coincide (the line of action would be undefined)");
  }
  bool has_law = false;
  yaml_node_t *stiffness = map_get(m, "stiffness");
  if (stiffness != NULL) {
    parse_law(r, stiffness, "stiffness", m->what, &f->stiffness);
    has_law = true;
  }
  yaml_node_t *damping = map_get(m, "damping");
  if (damping != NULL) {
    parse_law(r, damping, "damping", m->what, &f->damping);
    has_law = true;
  }
  has_law = map_has(m, "preload") || has_law;
  get_number(m, "preload", false, &f->preload);
  if (have_points)
    f->free_length = distance3(f->point[0], f->point[1]);
  get_nonnegative(m, "free_length", false, &f->free_length);
  if (!has_law)
    error_at(r, m->loc,
             "spring_damper '%s' has no force law (expected at least one of 'stiffness', "
             "'damping', 'preload')",
             f->name);
}

/* 'axes': rows x, y, z of an orthonormal right-handed frame (global) */
static void parse_axes(mapping *m, ir_force *f) {
  reader *r = m->r;
  yaml_node_t *axes = map_get(m, "axes");
  double rows[9];
  if (axes == NULL || !to_vector_list(r, axes, "'axes'", 3, 3, rows))
    return;
  for (int i = 0; i < 3; i++) {
    for (int k = i; k < 3; k++) {
      double expected = i == k ? 1 : 0;
      if (fabs(dot3(rows + 3 * i, rows + 3 * k) - expected) > ANGLE_TOLERANCE) {
        error_at(r, loc_of(axes),
                 "'axes' must be orthonormal (row %d . row %d = %g, expected %g)", i + 1,
                 k + 1, dot3(rows + 3 * i, rows + 3 * k), expected);
        return;
      }
    }
  }
  double cross_z = rows[0] * rows[4] - rows[1] * rows[3]; /* (x cross y) . z */
  double cross_y = rows[2] * rows[3] - rows[0] * rows[5];
  double cross_x = rows[1] * rows[5] - rows[2] * rows[4];
  if (cross_x * rows[6] + cross_y * rows[7] + cross_z * rows[8] < 0) {
    error_at(r, loc_of(axes), "'axes' must be right-handed (z = x cross y)");
    return;
  }
  memcpy(f->axes, rows, sizeof rows);
}

/* a 6x6 matrix as a list of 6 rows of 6 numbers */
static bool to_matrix6(reader *r, yaml_node_t *n, const char *label, double out[36]) {
  if (n->type != YAML_SEQUENCE_NODE || seq_length(n) != 6) {
    error_at(r, loc_of(n), "%s: expected a 6x6 matrix (a list of 6 rows of 6 numbers)", label);
    return false;
  }
  bool ok = true;
  for (int i = 0; i < 6; i++) {
    char row_label[SHOWN_SIZE];
    snprintf(row_label, sizeof row_label, "row %d of %s", i + 1, label);
    yaml_node_t *row = seq_item(r, n, i);
    if (row->type != YAML_SEQUENCE_NODE || seq_length(row) != 6) {
      error_at(r, loc_of(row), "%s: expected 6 numbers", row_label);
      ok = false;
      continue;
    }
    for (int j = 0; j < 6; j++) {
      char item_label[SHOWN_SIZE + 32];
      snprintf(item_label, sizeof item_label, "element %d of %s", j + 1, row_label);
      ok = to_number(r, seq_item(r, row, j), item_label, &out[6 * i + j]) && ok;
    }
  }
  return ok;
}

/* 'bodies' and one 'point' for both sides, or the point of the node given
 * ('node' / 'nodes'): a bushing's or a field's */
static void parse_pair_at_point(mapping *m, ir_force *f) {
  reader *r = m->r;
  bool on_nodes = get_body_pair(m, f->body, f->body_loc) && fe_nodes_given(m, f->body, f->node);
  bool given = get_vector(m, "point", 3, !on_nodes, f->point[0]);
  if (given)
    memcpy(f->point[1], f->point[0], sizeof f->point[0]);
  if (on_nodes) {
    check_node_point(r, r->model, m->loc, f->body, f->node, given, &f->point[0][0]);
    if (!given)
      memcpy(f->point[f->node[0] >= 0 ? 1 : 0], f->point[f->node[0] >= 0 ? 0 : 1], sizeof f->point[0]);
  }
}

/* field: a general 6x6 stiffness and damping between two bodies (seed 001 3.2.6) */
static void parse_field(mapping *m, ir_force *f) {
  reader *r = m->r;
  static const char *const keys[] = {"type", "bodies", "point", "stiffness", "damping",
                                     "preload", "axes", "node", "nodes", NULL};
  map_check_keys(m, keys);
  parse_pair_at_point(m, f);
  yaml_node_t *k = map_require(m, "stiffness", true, "a 6x6 matrix");
  if (k != NULL && to_matrix6(r, k, "'stiffness'", f->K))
    for (int i = 0; i < 6; i++)
      for (int j = 0; j < i; j++)
        if (fabs(f->K[6 * i + j] - f->K[6 * j + i]) > 1e-9 * (fabs(f->K[6 * i + j]) + fabs(f->K[6 * j + i]) + 1e-300)) {
          error_at(r, loc_of(k), "field 'stiffness' must be symmetric (row %d, column %d differs from row %d, column %d)", i + 1, j + 1, j + 1, i + 1);
          i = 6;
          break;
        }
  yaml_node_t *c = map_get(m, "damping");
  if (c != NULL) to_matrix6(r, c, "'damping'", f->C);
  get_six(m, "preload", false, false, f->preload6);
  parse_axes(m, f);
}

/* beam: a massless Euler-Bernoulli or Timoshenko beam from point 0 (clamped on
 * body 0) to point 1 (seed 001 3.2.5), damping = damping_ratio * stiffness */
static void parse_beam_force(mapping *m, ir_force *f) {
  reader *r = m->r;
  static const char *const keys[] = {"type", "bodies", "points", "node", "nodes", "section",
                                     "material", "theory", "damping_ratio", NULL};
  map_check_keys(m, keys);
  bool on_nodes = get_body_pair(m, f->body, f->body_loc) && fe_nodes_given(m, f->body, f->node);
  bool all_nodes = f->node[0] >= 0 && f->node[1] >= 0;
  yaml_node_t *points = map_require(m, "points", !all_nodes, "a list of 2 points [x, y, z]");
  bool given = points != NULL && to_vector_list(r, points, "'points'", 2, 3, &f->point[0][0]);
  if (on_nodes)
    check_node_point(r, r->model, points ? loc_of(points) : m->loc, f->body, f->node, given, &f->point[0][0]);
  int th = 0;
  if (get_choice(m, "theory", "beam theory", theory_names, false, &th)) f->beam.theory = (ir_beam_theory)th;
  f->beam.yaxis[1] = 1;
  parse_beam_properties(r, m, &f->beam);
  get_nonnegative(m, "damping_ratio", false, &f->damping_ratio);
  double x[3];
  for (int i = 0; i < 3; i++) x[i] = f->point[1][i] - f->point[0][i];
  double len = norm3(x);
  if ((given || all_nodes) && !(len > ZERO_LENGTH)) {
    error_at(r, points ? loc_of(points) : m->loc, "beam end points coincide (a beam needs a length)");
    return;
  }
  if (!(len > ZERO_LENGTH)) return;
  scale3(x, 1 / len);
  /* the section's y axis across the beam: given, else global y (global z for a beam along y) */
  double y[3];
  memcpy(y, f->beam.yaxis, sizeof y);
  if (fabs(dot3(x, y)) > 0.9) { y[0] = y[1] = 0; y[2] = 1; }
  double along = dot3(x, y);
  for (int i = 0; i < 3; i++) y[i] -= along * x[i];
  if (!(norm3(y) > 1e-6)) {
    error_at(r, m->loc, "the beam's section 'yaxis' is parallel to the beam");
    return;
  }
  scale3(y, 1 / norm3(y));
  double z[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
  memcpy(f->axes, x, sizeof x);
  memcpy(f->axes + 3, y, sizeof y);
  memcpy(f->axes + 6, z, sizeof z);
}

static void parse_bushing(mapping *m, ir_force *f) {
  static const char *const keys[] = {"type",    "bodies",  "point", "stiffness",
                                     "damping", "preload", "axes",  "node", "nodes", NULL};
  map_check_keys(m, keys);
  parse_pair_at_point(m, f);
  get_six(m, "stiffness", true, true, f->k6);
  get_six(m, "damping", false, true, f->c6);
  get_six(m, "preload", false, false, f->preload6);
  parse_axes(m, f);
}

static void parse_force(reader *r, yaml_node_t *key, yaml_node_t *value) {
  ir_model *model = r->model;
  int index = model->nforces++;
  ir_force *f = &model->forces[index];
  f->loc = loc_of(key);
  f->name = new_name(r, key, NAME_FORCE, index, NULL);
  f->body[0] = f->body[1] = -1;
  f->node[0] = f->node[1] = -1;
  f->active = true;
  f->axes[0] = f->axes[4] = f->axes[8] = 1;
  f->scale.kind = PROFILE_NONE; /* absent: constant 1, and no work for later stages */
  f->scale.loc = f->loc;

  mapping m;
  if (!map_open(&m, r, value, f->loc, "force '%s'", f->name))
    return;
  int type;
  if (get_choice(&m, "type", "force type", force_type_names, true, &type)) {
    f->kind = (ir_force_kind)type;
    map_describe(&m, "%s '%s'", force_type_names[type], f->name);
    switch (f->kind) {
    case FORCE_POINT_FORCE:
    case FORCE_POINT_TORQUE:
      parse_point_load(&m, f);
      break;
    case FORCE_SPRING_DAMPER:
      parse_spring_damper(&m, f);
      break;
    case FORCE_BUSHING:
      parse_bushing(&m, f);
      break;
    case FORCE_FIELD:
      parse_field(&m, f);
      break;
    case FORCE_BEAM:
      parse_beam_force(&m, f);
      break;
    }
  }
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * outputs
 * ------------------------------------------------------------------------- */

static const char *const output_type_names[] = {
    "position",     "orientation",          "angle",    "velocity",       "angular_velocity",
    "acceleration", "angular_acceleration", "reaction", "effort",         "kinetic_energy",
    "potential_energy", "total_energy",     "deflection", "modal", "momentum", NULL};
static const char *const component_names[] = {"x", "y", "z", NULL};

static void parse_output(reader *r, yaml_node_t *n, int item, name_table *scene_outputs,
                         ir_output *o) {
  o->loc = loc_of(n);
  o->body = o->joint = o->driver = o->node = -1;
  o->chord[0] = o->chord[1] = -1;
  o->mode = -1;
  o->component = -1;
  o->scale = 1;

  mapping m;
  if (!map_open(&m, r, n, o->loc, "output %d", item + 1))
    return;
  yaml_node_t *name = map_require(&m, "name", true, "a name");
  if (name != NULL && name->type != YAML_SCALAR_NODE)
    error_at(r, loc_of(name), "'name' must be a name (got %s)", show_node(r, name));
  else if (name != NULL)
    o->name = new_name(r, name, NAME_OUTPUT, item, scene_outputs);
  if (o->name != NULL)
    map_describe(&m, "output '%s'", o->name);

  int type;
  if (!get_choice(&m, "type", "output type", output_type_names, true, &type)) {
    map_close(&m);
    return;
  }
  o->kind = (ir_output_kind)type;
  map_describe(&m, "%s output '%s'", output_type_names[type], o->name ? o->name : "?");

  ir_output_kind k = o->kind;
  bool of_body = k <= OUT_ANGULAR_ACCELERATION || k == OUT_DEFLECTION || k == OUT_MODAL;
  bool has_point = k == OUT_POSITION || k == OUT_VELOCITY || k == OUT_ACCELERATION;
  bool has_component = of_body && k != OUT_ORIENTATION && k != OUT_ANGLE && k != OUT_MODAL;
  const char *keys[10];
  int nkeys = 0;
  keys[nkeys++] = "name";
  keys[nkeys++] = "type";
  if (of_body)
    keys[nkeys++] = "body";
  if (has_point)
    keys[nkeys++] = "point";
  if (k == OUT_POSITION || k == OUT_VELOCITY)
    keys[nkeys++] = "node";
  if (k == OUT_ANGLE)
    keys[nkeys++] = "axis";
  if (has_component)
    keys[nkeys++] = "component";
  if (k == OUT_REACTION)
    keys[nkeys++] = "joint";
  if (k == OUT_EFFORT)
    keys[nkeys++] = "driver";
  if (k == OUT_DEFLECTION) {
    keys[nkeys++] = "node";
    keys[nkeys++] = "chord";
  }
  if (k == OUT_MODAL)
    keys[nkeys++] = "mode";
  keys[nkeys++] = "scale";
  keys[nkeys] = NULL;
  map_check_keys(&m, keys);

  if (of_body)
    get_ref(&m, "body", NAME_BODY, true, &o->body, NULL);
  if (has_point)
    o->has_point = get_vector(&m, "point", 3, false, o->point);
  if ((k == OUT_POSITION || k == OUT_VELOCITY) && map_has(&m, "node") && o->body >= 0) {
    const ir_body *b = &r->model->bodies[o->body];
    yaml_node_t *nd = map_get(&m, "node");
    if (b->kind != BODY_FLEXIBLE)
      error_at(r, loc_of(nd), "'node' needs a flexible body ('%s' is not)", b->name);
    else if (o->has_point)
      error_at(r, loc_of(nd), "give either 'point' or 'node', not both");
    else
      o->node = to_fe_node(r, nd, b);
  }
  if (k == OUT_ANGLE)
    get_axis(&m, "axis", true, o->axis);
  if (has_component)
    get_choice(&m, "component", "component", component_names, false, &o->component);
  if (k == OUT_REACTION)
    get_ref(&m, "joint", NAME_JOINT, true, &o->joint, NULL);
  if (k == OUT_EFFORT)
    get_ref(&m, "driver", NAME_DRIVER, true, &o->driver, NULL);
  if ((k == OUT_DEFLECTION || k == OUT_MODAL) && o->body >= 0 &&
      r->model->bodies[o->body].kind != BODY_FLEXIBLE) {
    error_at(r, m.loc, "%s output '%s' needs a flexible body ('%s' is not)", output_type_names[k],
             o->name ? o->name : "?", r->model->bodies[o->body].name);
  } else if (k == OUT_DEFLECTION && o->body >= 0) {
    const ir_body *b = &r->model->bodies[o->body];
    yaml_node_t *nd = map_require(&m, "node", true, "a node number");
    if (nd != NULL) o->node = to_fe_node(r, nd, b);
    yaml_node_t *ch = map_get(&m, "chord");
    if (ch != NULL) {
      if (ch->type != YAML_SEQUENCE_NODE || seq_length(ch) != 2)
        error_at(r, loc_of(ch), "'chord': expected [K0, K1], two node numbers");
      else
        for (int i = 0; i < 2; i++) o->chord[i] = to_fe_node(r, seq_item(r, ch, i), b);
    }
  } else if (k == OUT_MODAL) {
    double mode;
    if (get_positive(&m, "mode", true, &mode)) {
      if (mode != floor(mode)) error_at(r, m.last_loc, "'mode' must be a mode number (1, 2, ...)");
      o->mode = (int)mode - 1;
    }
  }
  get_number(&m, "scale", false, &o->scale);
  map_close(&m);
}

/* Outputs are a list (their order is the column order); 'scene_outputs' as
 * for new_name. */
static void parse_outputs(reader *r, yaml_node_t *n, name_table *scene_outputs,
                          ir_output **outputs, int *count) {
  *outputs = NULL;
  *count = 0;
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "'outputs' must be a list of {name: ..., type: ...} (got %s)",
             show_node(r, n));
    return;
  }
  int length = seq_length(n);
  *outputs = xcalloc((size_t)length, sizeof **outputs);
  for (int i = 0; i < length; i++) {
    parse_output(r, seq_item(r, n, i), i, scene_outputs, &(*outputs)[i]);
    *count = i + 1; /* for ir_free, should a later error abandon the model */
  }
}

static void free_outputs(ir_output *outputs, int count) {
  for (int i = 0; i < count; i++)
    free(outputs[i].name);
  free(outputs);
}

/* ---------------------------------------------------------------------------
 * simulation settings: a base mapping and per-scene overrides
 * ------------------------------------------------------------------------- */

enum {
  SIM_END_TIME,
  SIM_OUTPUT_STEP,
  SIM_STEP,
  SIM_RTOL,
  SIM_ATOL,
  SIM_MIN_STEP,
  SIM_MAX_STEP,
  SIM_ALPHA,
  SIM_BETA,
  SIM_RHO_INF,
  SIM_INTEGRATOR,
  SIM_SOLVER,
  SIM_STABILIZATION,
  SIM_JOINTS_ON_FLEXIBLE,
  SIM_FIELDS
};

/* Where a setting came from: derived defaults are computed last, from the
 * merged values, and inherit the source of what they derive from. */
typedef enum { FROM_DEFAULT, FROM_BASE, FROM_SCENE } sim_source;

typedef struct {
  yaml_node_t *jof_list;    /* joints_on_flexible given as a list of joint names */
  double value[SIM_FIELDS]; /* choices hold their index */
  sim_source source[SIM_FIELDS];
  ir_loc loc[SIM_FIELDS];
} sim_settings;

static const char *const sim_keys[SIM_FIELDS] = {
    "end_time", "output_step", "step",       "rtol",          "atol",
    "min_step", "max_step",    "alpha",      "beta",          "rho_inf",   "integrator",
    "solver",   "stabilization", "joints_on_flexible"};

static const char *const integrator_names[] = {"rk4", "dopri5", "genalpha", "auto", NULL};
static const char *const solver_names[] = {"klu", "dense", NULL};
static const char *const stabilization_names[] = {"projection", "baumgarte", "none", NULL};
static const char *const jof_names[] = {"direct", "virtual", NULL};

static void sim_defaults(sim_settings *s) {
  memset(s, 0, sizeof *s);
  s->value[SIM_END_TIME] = 1;
  s->value[SIM_RTOL] = 1e-6;
  s->value[SIM_ATOL] = 1e-8;
  s->value[SIM_MIN_STEP] = 1e-12;
  s->value[SIM_ALPHA] = 10;
  s->value[SIM_BETA] = 10;
  s->value[SIM_RHO_INF] = 0.8;
  s->value[SIM_INTEGRATOR] = INTEGRATOR_DOPRI5;
  s->value[SIM_SOLVER] = SOLVER_KLU;
  s->value[SIM_STABILIZATION] = STAB_PROJECTION;
  s->value[SIM_JOINTS_ON_FLEXIBLE] = JOF_DIRECT;
}

static void sim_set(sim_settings *s, int field, double value, sim_source source, ir_loc loc) {
  s->value[field] = value;
  s->source[field] = source;
  s->loc[field] = loc;
}

/* Only the keys given change 's'. */
static void parse_sim(reader *r, yaml_node_t *n, const char *what, sim_source source,
                      sim_settings *s) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "%s", what))
    return;
  static const char *const keys[] = {"end_time",  "output_step", "step",
                                     "rtol",      "atol",        "min_step",
                                     "max_step",  "integrator",  "solver",
                                     "stabilization", "baumgarte", "joints_on_flexible",
                                     "rho_inf", NULL};
  map_check_keys(&m, keys);
  for (int field = SIM_END_TIME; field <= SIM_MAX_STEP; field++) {
    double value;
    if (get_positive(&m, sim_keys[field], false, &value))
      sim_set(s, field, value, source, m.last_loc);
  }
  double rho_inf;
  if (get_nonnegative(&m, "rho_inf", false, &rho_inf)) {
    if (rho_inf > 1)
      error_at(r, m.last_loc, "'rho_inf' of %s must be from 0 to 1 (the spectral radius of the "
               "generalized-alpha method at an infinite step), got %g", what, rho_inf);
    else
      sim_set(s, SIM_RHO_INF, rho_inf, source, m.last_loc);
  }
  yaml_node_t *baumgarte = map_get(&m, "baumgarte");
  if (baumgarte != NULL) {
    mapping b;
    if (map_open(&b, r, baumgarte, loc_of(baumgarte), "'baumgarte' of %s", what)) {
      static const char *const gains[] = {"alpha", "beta", NULL};
      map_check_keys(&b, gains);
      for (int field = SIM_ALPHA; field <= SIM_BETA; field++) {
        double value;
        if (get_nonnegative(&b, sim_keys[field], false, &value))
          sim_set(s, field, value, source, b.last_loc);
      }
    }
    map_close(&b);
  }
  static const char *const *const choices[] = {integrator_names, solver_names,
                                               stabilization_names, jof_names};
  yaml_node_t *jof = map_get(&m, "joints_on_flexible");
  if (jof != NULL && jof->type == YAML_SEQUENCE_NODE) {
    s->jof_list = jof;
    sim_set(s, SIM_JOINTS_ON_FLEXIBLE, JOF_LIST, source, loc_of(jof));
  } else if (jof != NULL) {
    s->jof_list = NULL;
  }
  for (int field = SIM_INTEGRATOR; field < SIM_FIELDS; field++) {
    int choice;
    if (field == SIM_JOINTS_ON_FLEXIBLE && jof != NULL && jof->type == YAML_SEQUENCE_NODE)
      continue;
    if (get_choice(&m, sim_keys[field], sim_keys[field], choices[field - SIM_INTEGRATOR], false,
                   &choice))
      sim_set(s, field, choice, source, m.last_loc);
  }
  map_close(&m);
}

/* Fills derived defaults and checks the settings against each other.  For a
 * scene only conflicts that involve its own keys are reported: the others
 * were reported for the base settings already. */
static bool sim_finish(reader *r, sim_settings *s, bool is_scene, ir_sim *out) {
  double *v = s->value;
  if (s->source[SIM_OUTPUT_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_OUTPUT_STEP, v[SIM_END_TIME] / 100, s->source[SIM_END_TIME], s->loc[SIM_END_TIME]);
  if (s->source[SIM_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_STEP, v[SIM_OUTPUT_STEP] / 10, s->source[SIM_OUTPUT_STEP],
            s->loc[SIM_OUTPUT_STEP]);
  if (s->source[SIM_MAX_STEP] == FROM_DEFAULT)
    sim_set(s, SIM_MAX_STEP, v[SIM_OUTPUT_STEP], s->source[SIM_OUTPUT_STEP],
            s->loc[SIM_OUTPUT_STEP]);

  static const int smaller[][2] = {{SIM_OUTPUT_STEP, SIM_END_TIME}, {SIM_MIN_STEP, SIM_MAX_STEP}};
  bool ok = true;
  for (size_t i = 0; i < sizeof smaller / sizeof smaller[0]; i++) {
    int a = smaller[i][0], b = smaller[i][1];
    if (v[a] <= v[b])
      continue;
    int blamed = s->source[a] >= s->source[b] ? a : b;
    if (is_scene && s->source[blamed] != FROM_SCENE)
      continue;
    error_at(r, s->source[blamed] == FROM_DEFAULT ? file_start : s->loc[blamed],
             "'%s' (%g) must not be larger than '%s' (%g)", sim_keys[a], v[a], sim_keys[b], v[b]);
    ok = false;
  }
  out->end_time = v[SIM_END_TIME];
  out->output_step = v[SIM_OUTPUT_STEP];
  out->step = v[SIM_STEP];
  out->rtol = v[SIM_RTOL];
  out->atol = v[SIM_ATOL];
  out->min_step = v[SIM_MIN_STEP];
  out->max_step = v[SIM_MAX_STEP];
  out->baumgarte_alpha = v[SIM_ALPHA];
  out->baumgarte_beta = v[SIM_BETA];
  out->rho_inf = v[SIM_RHO_INF];
  out->integrator = (ir_integrator)(int)v[SIM_INTEGRATOR];
  out->solver = (ir_solver)(int)v[SIM_SOLVER];
  out->stabilization = (ir_stab)(int)v[SIM_STABILIZATION];
  out->joints_on_flexible = (ir_jof)(int)v[SIM_JOINTS_ON_FLEXIBLE];
  return ok;
}

/* ---------------------------------------------------------------------------
 * scenes
 * ------------------------------------------------------------------------- */

static void parse_deactivate(reader *r, yaml_node_t *n, bool *joint_off, bool *driver_off,
                             bool *force_off) {
  if (n->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(n), "'deactivate': expected a list of joint, driver or force names, got %s",
             show_node(r, n));
    return;
  }
  for (int i = 0; i < seq_length(n); i++) {
    yaml_node_t *item = seq_item(r, n, i);
    if (item->type != YAML_SCALAR_NODE) {
      error_at(r, loc_of(item), "'deactivate' must list joint, driver or force names (got %s)",
               show_node(r, item));
      continue;
    }
    const char *text = scalar_text(item);
    size_t length = scalar_length(item);
    name_entry *e = strlen(text) == length ? table_find(&r->names, text) : NULL;
    if (e != NULL && e->kind == NAME_JOINT) {
      joint_off[e->index] = true;
    } else if (e != NULL && e->kind == NAME_DRIVER) {
      driver_off[e->index] = true;
    } else if (e != NULL && e->kind == NAME_FORCE) {
      force_off[e->index] = true;
    } else if (e != NULL) {
      error_at(r, loc_of(item), "'%s' is a%s %s; only joints, drivers and forces can be deactivated",
               e->name, e->kind == NAME_OUTPUT ? "n" : "", name_kind_words[e->kind]);
    } else {
      name_list l = {.length = 0};
      list_names_of_kind(r, NAME_JOINT, &l);
      list_names_of_kind(r, NAME_DRIVER, &l);
      list_names_of_kind(r, NAME_FORCE, &l);
      error_at(r, loc_of(item), "unknown joint, driver or force '%s' in 'deactivate' (%s%s)",
               show_text(r, text, length), l.count ? "expected one of: " : "the model has none",
               l.text);
    }
  }
}

static void free_scene_flex(ir_flex **flex, int nbodies) {
  if (!flex) return;
  for (int b = 0; b < nbodies; b++)
    if (flex[b]) { free(flex[b]->list); free(flex[b]->ratios); free(flex[b]); }
  free(flex);
}

/* A scene's 'bodies': flexible body name -> {modes, damping, coupling}, each
 * overriding the body's own (coupling: rigid makes the body rigid).  Returns
 * per body the settings the scene gives it (NULL for the others). */
static ir_flex **parse_scene_bodies(reader *r, yaml_node_t *n, const char *what) {
  ir_model *model = r->model;
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'bodies' of %s", what))
    return NULL;
  ir_flex **flex = xcalloc((size_t)model->nbodies + 1, sizeof *flex);
  for (int i = 0; i < m.npairs; i++) {
    yaml_node_t *key = map_key_node(&m, i), *value = map_value_node(&m, i);
    m.handled[i] = true;
    int b = -1;
    for (int k = 1; k < model->nbodies; k++)
      if (model->bodies[k].name && scalar_equals(key, model->bodies[k].name)) b = k;
    if (b < 0 || !model->bodies[b].flex) {
      name_list l = {.length = 0};
      for (int k = 1; k < model->nbodies; k++)
        if (model->bodies[k].flex) name_list_add(&l, model->bodies[k].name);
      error_at(r, loc_of(key), "%s %s in 'bodies' of %s (%s%s)",
               b < 0 ? "unknown body" : "not a flexible body:", show_node(r, key), what,
               l.count ? "expected a flexible body: " : "the model has no flexible body", l.text);
      continue;
    }
    mapping bm;
    char label[SHOWN_SIZE + 40];
    snprintf(label, sizeof label, "body '%s' in %s", model->bodies[b].name, what);
    if (!map_open(&bm, r, value, loc_of(key), "%s", label))
      continue;
    static const char *const keys[] = {"modes", "damping", "coupling", NULL};
    map_check_keys(&bm, keys);
    /* start from the body's own settings; the lists are copied */
    const ir_flex *own = model->bodies[b].flex;
    ir_flex *fx = xcalloc(1, sizeof *fx);
    fx->select = own->select; fx->count = own->count; fx->max_frequency = own->max_frequency;
    fx->damping = own->damping; fx->ratio = own->ratio; fx->coupling = own->coupling;
    bool new_list = map_has(&bm, "modes"), new_ratios = map_has(&bm, "damping");
    if (!new_list && own->nlist) {
      fx->list = xcalloc((size_t)own->nlist, sizeof *fx->list);
      memcpy(fx->list, own->list, sizeof *fx->list * (size_t)own->nlist);
      fx->nlist = own->nlist;
    }
    if (!new_ratios && own->nratios) {
      fx->ratios = xcalloc((size_t)own->nratios + 1, sizeof *fx->ratios);
      memcpy(fx->ratios, own->ratios, sizeof *fx->ratios * (size_t)own->nratios);
      fx->nratios = own->nratios;
    }
    parse_modal_settings(&bm, fx);
    map_close(&bm);
    if (flex[b]) { free(flex[b]->list); free(flex[b]->ratios); free(flex[b]); }
    flex[b] = fx;
  }
  map_close(&m);
  return flex;
}

static void parse_scene(reader *r, yaml_node_t *key, yaml_node_t *value,
                        const sim_settings *base_sim, bool chosen) {
  ir_model *model = r->model;
  const char *name = show_text(r, scalar_text(key), scalar_length(key));
  char what[SHOWN_SIZE];
  snprintf(what, sizeof what, "scene '%s'", name);
  mapping m;
  if (!map_open(&m, r, value, loc_of(key), "%s", what))
    return;
  static const char *const keys[] = {"simulation", "outputs", "deactivate", "gravity", "bodies", NULL};
  map_check_keys(&m, keys);

  sim_settings sim = *base_sim;
  yaml_node_t *n = map_get(&m, "simulation");
  if (n != NULL) {
    char label[SHOWN_SIZE + 20];
    snprintf(label, sizeof label, "'simulation' of %s", what);
    parse_sim(r, n, label, FROM_SCENE, &sim);
  }
  ir_sim merged;
  sim_finish(r, &sim, true, &merged);

  ir_output *outputs = NULL;
  int noutputs = 0;
  n = map_get(&m, "outputs");
  if (n != NULL) {
    name_table scene_names = {NULL, 0, 0};
    parse_outputs(r, n, &scene_names, &outputs, &noutputs);
    table_free(&scene_names);
  }
  bool *joint_off = xcalloc((size_t)model->njoints, sizeof *joint_off);
  bool *driver_off = xcalloc((size_t)model->ndrivers, sizeof *driver_off);
  bool *force_off = xcalloc((size_t)model->nforces, sizeof *force_off);
  n = map_get(&m, "deactivate");
  if (n != NULL)
    parse_deactivate(r, n, joint_off, driver_off, force_off);
  ir_flex **flex = NULL;
  n = map_get(&m, "bodies");
  if (n != NULL)
    flex = parse_scene_bodies(r, n, what);
  double gravity[3];
  bool has_gravity = get_vector(&m, "gravity", 3, false, gravity);
  bool has_outputs = map_has(&m, "outputs");
  map_close(&m);

  chosen_scene *s = &r->scene;
  if (!chosen) {
    free_outputs(outputs, noutputs);
    free(joint_off);
    free(driver_off);
    free(force_off);
    free_scene_flex(flex, model->nbodies);
    return;
  }
  s->found = true;
  s->name = xstrndup(scalar_text(key), scalar_length(key));
  s->has_gravity = has_gravity;
  memcpy(s->gravity, gravity, sizeof gravity);
  s->has_outputs = has_outputs;
  s->outputs = outputs;
  s->noutputs = noutputs;
  s->joint_off = joint_off;
  s->driver_off = driver_off;
  s->force_off = force_off;
  s->sim = merged;
  s->jof_list = sim.jof_list;
  s->flex = flex;
}

/* Every scene is validated; the one named 'chosen' is kept in r->scene. */
static void parse_scenes(reader *r, yaml_node_t *n, const sim_settings *base_sim,
                         const char *chosen) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'scenes'"))
    return;
  for (int i = 0; i < m.npairs; i++) {
    if (m.handled[i])
      continue;
    yaml_node_t *key = map_key_node(&m, i);
    bool is_chosen = chosen != NULL && strlen(chosen) == scalar_length(key) &&
                     memcmp(chosen, scalar_text(key), scalar_length(key)) == 0;
    parse_scene(r, key, map_value_node(&m, i), base_sim, is_chosen);
  }
  map_close(&m);
}

static void report_unknown_scene(reader *r, yaml_node_t *scenes, const char *chosen) {
  name_list l = {.length = 0};
  if (scenes != NULL && scenes->type == YAML_MAPPING_NODE) {
    yaml_node_pair_t *pair = scenes->data.mapping.pairs.start;
    for (; pair < scenes->data.mapping.pairs.top; pair++) {
      yaml_node_t *key = node_at(r, pair->key);
      if (key->type == YAML_SCALAR_NODE)
        name_list_add(&l, show_text(r, scalar_text(key), scalar_length(key)));
    }
  }
  const char *shown = show_text(r, chosen, strlen(chosen));
  if (l.count == 0)
    error_at(r, scenes ? loc_of(scenes) : file_start,
             "unknown scene '%s' (the model defines no scenes)", shown);
  else
    error_at(r, loc_of(scenes), "unknown scene '%s' (expected one of: %s)", shown, l.text);
}

/* joints on flexible nodes lowered through virtual bodies: all of them
 * (joints_on_flexible: virtual) or those listed */
static void mark_virtual_joints(reader *r, yaml_node_t *list) {
  ir_model *model = r->model;
  if (model->sim.joints_on_flexible == JOF_VIRTUAL)
    for (int j = 0; j < model->njoints; j++)
      model->joints[j].via_virtual = model->joints[j].node[0] >= 0 || model->joints[j].node[1] >= 0;
  if (model->sim.joints_on_flexible != JOF_LIST || list == NULL)
    return;
  for (int i = 0; i < seq_length(list); i++) {
    yaml_node_t *item = seq_item(r, list, i);
    int j = -1;
    if (item->type == YAML_SCALAR_NODE)
      for (int k = 0; k < model->njoints; k++)
        if (model->joints[k].name && scalar_equals(item, model->joints[k].name)) j = k;
    if (j < 0) {
      error_at(r, loc_of(item), "'joints_on_flexible': expected 'direct', 'virtual' or a list of joint names (%s is not a joint)", show_node(r, item));
      continue;
    }
    if (model->joints[j].node[0] < 0 && model->joints[j].node[1] < 0) {
      error_at(r, loc_of(item), "'joints_on_flexible': joint '%s' is not on an FE node", model->joints[j].name);
      continue;
    }
    model->joints[j].via_virtual = true;
  }
}

static void apply_scene(ir_model *model, chosen_scene *s) {
  model->scene = s->name;
  s->name = NULL;
  if (s->has_gravity)
    memcpy(model->gravity, s->gravity, sizeof s->gravity);
  if (s->has_outputs) {
    free_outputs(model->outputs, model->noutputs);
    model->outputs = s->outputs;
    model->noutputs = s->noutputs;
    s->outputs = NULL;
    s->noutputs = 0;
  }
  for (int i = 0; i < model->njoints; i++)
    if (s->joint_off[i])
      model->joints[i].active = false;
  for (int i = 0; i < model->ndrivers; i++) {
    int joint = model->drivers[i].joint;
    if (s->driver_off[i] || (joint >= 0 && !model->joints[joint].active))
      model->drivers[i].active = false;
  }
  for (int i = 0; i < model->nforces; i++)
    if (s->force_off[i])
      model->forces[i].active = false;
  for (int b = 0; s->flex && b < model->nbodies; b++) {
    ir_flex *to = model->bodies[b].flex, *from = s->flex[b];
    if (!from || !to) continue;
    free(to->list); free(to->ratios);
    to->select = from->select; to->count = from->count; to->max_frequency = from->max_frequency;
    to->list = from->list; to->nlist = from->nlist;
    to->damping = from->damping; to->ratio = from->ratio;
    to->ratios = from->ratios; to->nratios = from->nratios;
    to->coupling = from->coupling;
    free(from);
    s->flex[b] = NULL;
  }
  model->sim = s->sim;
}

static void free_chosen_scene(chosen_scene *s, int nbodies) {
  free_scene_flex(s->flex, nbodies);
  free(s->name);
  free_outputs(s->outputs, s->noutputs);
  free(s->joint_off);
  free(s->driver_off);
  free(s->force_off);
  memset(s, 0, sizeof *s);
}

/* Two active drivers on one joint dof would over-constrain it. */
static void check_drivers(reader *r) {
  const ir_model *model = r->model;
  for (int i = 0; i < model->ndrivers; i++) {
    const ir_driver *d = &model->drivers[i];
    if (!d->active || d->joint < 0)
      continue;
    for (int k = 0; k < i; k++) {
      const ir_driver *first = &model->drivers[k];
      if (first->active && first->joint == d->joint && first->dof == d->dof) {
        error_at(r, d->loc, "joint '%s' is already driven in %s by driver '%s'",
                 model->joints[d->joint].name, dof_names[d->dof], first->name);
        note_at(r, first->loc, "driver '%s' is defined here", first->name);
        break;
      }
    }
  }
}

/* ---------------------------------------------------------------------------
 * the model
 * ------------------------------------------------------------------------- */

static int mapping_size(const yaml_node_t *n) {
  if (n == NULL || n->type != YAML_MAPPING_NODE)
    return 0;
  return (int)(n->data.mapping.pairs.top - n->data.mapping.pairs.start);
}

/* Parses the entries of a name -> definition mapping, in file order. */
static void parse_named(reader *r, yaml_node_t *n, const char *key,
                        void (*parse)(reader *, yaml_node_t *, yaml_node_t *)) {
  mapping m;
  if (!map_open(&m, r, n, loc_of(n), "'%s'", key))
    return;
  for (int i = 0; i < m.npairs; i++)
    if (!m.handled[i])
      parse(r, map_key_node(&m, i), map_value_node(&m, i));
  map_close(&m);
}

static void parse_model(reader *r, yaml_node_t *root, const char *chosen_scene_name) {
  ir_model *model = r->model;
  if (root->type != YAML_MAPPING_NODE) {
    error_at(r, file_start, "a model must be a mapping with keys such as 'name' and 'bodies' (got %s)",
             show_node(r, root));
    return;
  }
  mapping top;
  map_open(&top, r, root, file_start, "the model");
  static const char *const keys[] = {"name",    "gravity", "bodies",     "joints", "drivers",
                                     "forces",  "outputs", "simulation", "scenes", NULL};
  map_check_keys(&top, keys);

  yaml_node_t *name = map_require(&top, "name", true, "a C identifier");
  if (name != NULL && name->type != YAML_SCALAR_NODE)
    error_at(r, loc_of(name), "'name' must be a C identifier (got %s)", show_node(r, name));
  else if (name != NULL && check_identifier(r, name))
    model->name = xstrndup(scalar_text(name), scalar_length(name));

  get_vector(&top, "gravity", 3, false, model->gravity);

  /* bodies[0] is the ground; the arrays are sized by their mappings */
  yaml_node_t *bodies = map_require(&top, "bodies", true, "a mapping of body names to bodies");
  model->bodies = xcalloc(1 + (size_t)mapping_size(bodies), sizeof *model->bodies);
  model->nbodies = 1;
  model->bodies[0].name = xstrdup("ground");
  model->bodies[0].kind = BODY_GROUND;
  model->bodies[0].orientation[0] = 1;
  name_entry ground = {model->bodies[0].name, NAME_BODY, 0, {0, 0}};
  table_add(&r->names, ground);
  if (bodies != NULL)
    parse_bodies(r, bodies);

  yaml_node_t *joints = map_get(&top, "joints");
  model->joints = xcalloc((size_t)mapping_size(joints), sizeof *model->joints);
  if (joints != NULL)
    parse_named(r, joints, "joints", parse_joint);

  yaml_node_t *drivers = map_get(&top, "drivers");
  model->drivers = xcalloc((size_t)mapping_size(drivers), sizeof *model->drivers);
  if (drivers != NULL)
    parse_named(r, drivers, "drivers", parse_driver);

  yaml_node_t *forces = map_get(&top, "forces");
  model->forces = xcalloc((size_t)mapping_size(forces), sizeof *model->forces);
  if (forces != NULL)
    parse_named(r, forces, "forces", parse_force);

  yaml_node_t *outputs = map_get(&top, "outputs");
  if (outputs != NULL)
    parse_outputs(r, outputs, NULL, &model->outputs, &model->noutputs);

  sim_settings base_sim;
  sim_defaults(&base_sim);
  yaml_node_t *simulation = map_get(&top, "simulation");
  if (simulation != NULL)
    parse_sim(r, simulation, "'simulation'", FROM_BASE, &base_sim);
  sim_finish(r, &base_sim, false, &model->sim);

  yaml_node_t *scenes = map_get(&top, "scenes");
  if (scenes != NULL)
    parse_scenes(r, scenes, &base_sim, chosen_scene_name);
  if (chosen_scene_name != NULL && !r->scene.found)
    report_unknown_scene(r, scenes, chosen_scene_name);
  map_close(&top);

  /* last: replacing the outputs frees names the name table refers to */
  table_free(&r->names);
  yaml_node_t *jof_list = r->scene.found ? r->scene.jof_list : base_sim.jof_list;
  if (r->scene.found)
    apply_scene(model, &r->scene);
  check_drivers(r);
  mark_virtual_joints(r, jof_list);
}

/* ---------------------------------------------------------------------------
 * files and YAML syntax
 * ------------------------------------------------------------------------- */

static char *read_file(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return NULL;
  size_t capacity = 1 << 16, length = 0;
  char *data = xcalloc(capacity, 1);
  for (;;) {
    length += fread(data + length, 1, capacity - length, f);
    if (length < capacity)
      break;
    capacity *= 2;
    char *bigger = realloc(data, capacity);
    if (bigger == NULL)
      out_of_memory();
    data = bigger;
  }
  bool failed = ferror(f) != 0;
  int saved_errno = errno;
  fclose(f);
  if (failed) {
    free(data);
    errno = saved_errno;
    return NULL;
  }
  *size = length;
  return data;
}

/* libyaml's reader errors carry a byte offset instead of a mark. */
static ir_loc loc_of_offset(const char *data, size_t size, size_t offset) {
  ir_loc loc = {1, 1};
  for (size_t i = 0; i < offset && i < size; i++) {
    if (data[i] == '\n') {
      loc.line++;
      loc.col = 1;
    } else {
      loc.col++;
    }
  }
  return loc;
}

static ir_loc loc_of_mark(yaml_mark_t mark) {
  ir_loc loc = {(int)mark.line + 1, (int)mark.column + 1};
  return loc;
}

static void report_yaml_error(const char *path, const yaml_parser_t *parser, const char *data,
                              size_t size) {
  const char *problem = parser->problem ? parser->problem : "unknown problem";
  switch (parser->error) {
  case YAML_MEMORY_ERROR:
    diag_error(path, file_start, "out of memory while reading YAML");
    break;
  case YAML_READER_ERROR:
    if (parser->problem_value != -1)
      diag_error(path, loc_of_offset(data, size, parser->problem_offset),
                 "invalid YAML: %s (byte 0x%02x)", problem, (unsigned)parser->problem_value & 0xff);
    else
      diag_error(path, loc_of_offset(data, size, parser->problem_offset), "invalid YAML: %s",
                 problem);
    break;
  default:
    diag_error(path, loc_of_mark(parser->problem_mark), "invalid YAML: %s", problem);
    if (parser->context != NULL)
      diag_note(path, loc_of_mark(parser->context_mark), "%s", parser->context);
    break;
  }
}

ir_model *ir_read(const char *path, const char *scene) {
  int errors_before = diag_errors();
  size_t size = 0;
  char *data = read_file(path, &size);
  if (data == NULL) {
    ir_loc nowhere = {0, 0};
    diag_error(path, nowhere, "cannot read the model: %s", strerror(errno));
    return NULL;
  }

  yaml_parser_t parser;
  if (!yaml_parser_initialize(&parser))
    out_of_memory();
  yaml_parser_set_input_string(&parser, (const unsigned char *)data, size);
  yaml_document_t doc;
  ir_model *model = NULL;
  if (!yaml_parser_load(&parser, &doc)) {
    report_yaml_error(path, &parser, data, size);
  } else {
    yaml_node_t *root = yaml_document_get_root_node(&doc);
    if (root == NULL) {
      diag_error(path, file_start,
                 "empty model file (expected a mapping with at least 'name' and 'bodies')");
    } else {
      yaml_document_t extra;
      if (!yaml_parser_load(&parser, &extra)) {
        report_yaml_error(path, &parser, data, size);
      } else {
        yaml_node_t *extra_root = yaml_document_get_root_node(&extra);
        if (extra_root != NULL)
          diag_error(path, loc_of(extra_root),
                     "a model file holds a single YAML document (remove everything after '---')");
        yaml_document_delete(&extra);
      }
      model = xcalloc(1, sizeof *model);
      model->path = xstrdup(path);
      reader r;
      memset(&r, 0, sizeof r);
      r.path = path;
      r.doc = &doc;
      r.model = model;
      parse_model(&r, root, scene);
      table_free(&r.names);
      free_chosen_scene(&r.scene, model->nbodies);
    }
    yaml_document_delete(&doc);
  }
  yaml_parser_delete(&parser);
  free(data);

  if (diag_errors() > errors_before) {
    ir_free(model);
    return NULL;
  }
  return model;
}

static void free_flex(ir_flex *fx) {
  if (fx == NULL)
    return;
  free(fx->nodes);
  free(fx->node_loc);
  free(fx->beams);
  free(fx->point_masses);
  free(fx->reference);
  free(fx->interface);
  free(fx->modal_file);
  free(fx->list);
  free(fx->ratios);
  free(fx);
}

void ir_free(ir_model *m) {
  if (m == NULL)
    return;
  free(m->path);
  free(m->name);
  free(m->scene);
  for (int i = 0; i < m->nbodies; i++) {
    free(m->bodies[i].name);
    free_flex(m->bodies[i].flex);
  }
  free(m->bodies);
  for (int i = 0; i < m->njoints; i++)
    free(m->joints[i].name);
  free(m->joints);
  for (int i = 0; i < m->ndrivers; i++) {
    free(m->drivers[i].name);
    free(m->drivers[i].motion.table);
  }
  free(m->drivers);
  for (int i = 0; i < m->nforces; i++) {
    free(m->forces[i].name);
    free(m->forces[i].scale.table);
    free(m->forces[i].stiffness.table);
    free(m->forces[i].damping.table);
  }
  free(m->forces);
  free_outputs(m->outputs, m->noutputs);
  free(m);
}

int ir_find_body(const ir_model *m, const char *name) {
  for (int i = 0; m != NULL && name != NULL && i < m->nbodies; i++)
    if (strcmp(m->bodies[i].name, name) == 0)
      return i;
  return -1;
}

int ir_find_joint(const ir_model *m, const char *name) {
  for (int i = 0; m != NULL && name != NULL && i < m->njoints; i++)
    if (strcmp(m->joints[i].name, name) == 0)
      return i;
  return -1;
}
