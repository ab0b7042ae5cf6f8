/* yaml_map.c: the typed YAML access layer of the reader: memory, the reader's
 * diagnostics (file:line:col), quoting user text, sequences, mappings that
 * catch duplicate and unknown keys, and typed look-ups (numbers, vectors,
 * tables, choices, unit axes).  Used by every reader of YAML in the
 * compiler (yaml_map.h lists them). */
#include "yaml_map.h"
#include "bounds.h"
#include "params.h"

#include <errno.h>
#include <setjmp.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---------------------------------------------------------------------------
 * memory
 * ------------------------------------------------------------------------- */

/* ir_read's recovery point (reader_catch_oom): every allocation of the
   reader happens while ir_read runs, and one that fails unwinds there */
static jmp_buf *oom_recovery;

void reader_catch_oom(jmp_buf *recovery) { oom_recovery = recovery; }

_Noreturn void out_of_memory(void) { longjmp(*oom_recovery, 1); }
void *xcalloc(size_t count, size_t size) {
  void *p = calloc(count ? count : 1, size ? size : 1);
  if (p == NULL)
    out_of_memory();
  return p;
}

char *xstrndup(const char *s, size_t length) {
  char *copy = xcalloc(length + 1, 1);
  memcpy(copy, s, length);
  return copy;
}



ir_loc loc_of(const yaml_node_t *n) {
  ir_loc loc = {(int)n->start_mark.line + 1, (int)n->start_mark.column + 1};
  return loc;
}


void error_at(reader *r, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_verror(r->path, loc, fmt, ap);
  va_end(ap);
}

void note_at(reader *r, ir_loc loc, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  diag_vnote(r->path, loc, fmt, ap);
  va_end(ap);
}

/* User text, escaped (control characters would garble a terminal) and
 * shortened to keep messages on one line. */
const char *show_text(reader *r, const char *s, size_t length) {
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



bool scalar_equals(const yaml_node_t *n, const char *s) {
  size_t length = strlen(s);
  return n->type == YAML_SCALAR_NODE && scalar_length(n) == length &&
         memcmp(scalar_text(n), s, length) == 0;
}

/* "'text'", "an empty value", "a list" or "a mapping", for "(got ...)". */
const char *show_node(reader *r, const yaml_node_t *n) {
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


int seq_length(const yaml_node_t *n) {
  return (int)(n->data.sequence.items.top - n->data.sequence.items.start);
}

yaml_node_t *seq_item(reader *r, const yaml_node_t *n, int i) {
  return node_at(r, n->data.sequence.items.start[i]);
}


void name_list_add(name_list *l, const char *name) {
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

const char *join_choices(name_list *l, const char *const *choices) {
  l->length = 0;
  l->count = 0;
  l->text[0] = '\0';
  for (int i = 0; choices[i] != NULL; i++)
    name_list_add(l, choices[i]);
  return l->text;
}

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

yaml_node_t *map_key_node(const mapping *m, int i) {
  return node_at(m->r, m->node->data.mapping.pairs.start[i].key);
}

yaml_node_t *map_value_node(const mapping *m, int i) {
  return node_at(m->r, m->node->data.mapping.pairs.start[i].value);
}

void map_describe(mapping *m, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(m->what, sizeof m->what, fmt, ap);
  va_end(ap);
}

/* Reports duplicate and non-scalar keys (those are then ignored).  On a
 * non-mapping, reports it and returns false; the look-ups then find nothing
 * and map_close is still safe to call. */
bool map_open(mapping *m, reader *r, yaml_node_t *node, ir_loc loc, const char *fmt, ...) {
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
      ir_loc first_loc = loc_of(map_key_node(m, keys[first].pair));
      const char *first_file = diag_loc_file(first_loc, NULL);
      if (first_file == diag_loc_file(loc_of(dup), NULL))
        error_at(r, loc_of(dup), "duplicate key '%s' (first at line %d)",
                 show_text(r, keys[k].text, keys[k].length), diag_loc_in_file(first_loc).line);
      else
        error_at(r, loc_of(dup), "duplicate key '%s' (first at %s:%d)",
                 show_text(r, keys[k].text, keys[k].length),
                 first_file ? first_file : r->path, diag_loc_in_file(first_loc).line);
      m->handled[keys[k].pair] = true;
      k++;
    }
  }
  free(keys);
  return true;
}

void map_close(mapping *m) {
  free(m->handled);
  m->handled = NULL;
}

int map_find(const mapping *m, const char *key) {
  for (int i = 0; i < m->npairs; i++)
    if (!m->handled[i] && scalar_equals(map_key_node(m, i), key))
      return i;
  return -1;
}


yaml_node_t *map_get(mapping *m, const char *key) {
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
void map_reject(mapping *m, const char *key, const char *fmt, ...) {
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
void map_check_keys(mapping *m, const char *const *expected) {
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

yaml_node_t *map_require(mapping *m, const char *key, bool required, const char *expected) {
  yaml_node_t *n = map_get(m, key);
  if (n == NULL && required)
    error_at(m->r, m->loc, "missing '%s' in %s (expected %s)", key, m->what, expected);
  return n;
}

/* ---------------------------------------------------------------------------
 * values
 * ------------------------------------------------------------------------- */

/* 'label' names the value in messages, e.g. "'mass'" or "element 2 of 'point'". */
bool to_number(reader *r, yaml_node_t *n, const char *label, double *out) {
  if (n->type == YAML_SCALAR_NODE && scalar_length(n) > 0) {
    const char *text = scalar_text(n);
    char *end = NULL;
    /* strtod would skip leading blanks; a quoted " 1" is not a number */
    bool blank_start = text[0] == ' ' || text[0] == '\t' || text[0] == '\n' || text[0] == '\r';
    double value = blank_start ? 0 : strtod(text, &end);
    if (!blank_start && end == text + scalar_length(n)) {
      if (isfinite(value) && fabs(value) <= LIMIT_MAGNITUDE) {
        *out = value;
        return params_place(r, n, label, out); /* mirrored or moved by a subsystem instance */
      }
      if (isfinite(value)) {
        error_at(r, loc_of(n), "%s is %s, beyond the limit %g on the size of a number", label,
                 show_node(r, n), LIMIT_MAGNITUDE);
        return false;
      }
      error_at(r, loc_of(n), "%s must be a finite number (got %s)", label, show_node(r, n));
      return false;
    }
    if (!blank_start) { /* an expression over parameters (params.c) */
      int as_expression = expr_number(r, n, label, out);
      if (as_expression != 0) return as_expression > 0;
    }
  }
  error_at(r, loc_of(n), "%s must be a number (got %s)", label, show_node(r, n));
  return false;
}

/* Writes 'out' only if the whole vector is valid. */
bool to_vector(reader *r, yaml_node_t *n, const char *label, int length, double *out) {
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
bool to_vector_list(reader *r, yaml_node_t *n, const char *label, int count, int length,
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
bool to_table(reader *r, yaml_node_t *n, const char *label, const char *pair,
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

bool to_choice(reader *r, yaml_node_t *n, const char *key, const char *noun,
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

void quote_key(char *label, size_t size, const char *key) {
  snprintf(label, size, "'%s'", key);
}

bool get_number(mapping *m, const char *key, bool required, double *out) {
  yaml_node_t *n = map_require(m, key, required, "a number");
  char label[64];
  quote_key(label, sizeof label, key);
  return n != NULL && to_number(m->r, n, label, out);
}

/* the rule of field 'key' of m noted for a value written as an expression */
static void note_rule(mapping *m, const char *key, ir_value_rule rule) {
  yaml_node_t *n = map_get(m, key);
  char label[64];
  quote_key(label, sizeof label, key);
  if (n != NULL) params_note_rule(m->r, loc_of(n), rule, label);
}

bool get_positive(mapping *m, const char *key, bool required, double *out) {
  double value;
  if (!get_number(m, key, required, &value))
    return false;
  note_rule(m, key, RULE_POSITIVE);
  if (!(value > 0)) {
    error_at(m->r, m->last_loc, "'%s' must be positive (got %g)", key, value);
    return false;
  }
  *out = value;
  return true;
}

bool get_nonnegative(mapping *m, const char *key, bool required, double *out) {
  double value;
  if (!get_number(m, key, required, &value))
    return false;
  note_rule(m, key, RULE_NONNEGATIVE);
  if (!(value >= 0)) {
    error_at(m->r, m->last_loc, "'%s' must be >= 0 (got %g)", key, value);
    return false;
  }
  *out = value;
  return true;
}

bool get_vector(mapping *m, const char *key, int length, bool required, double *out) {
  char expected[32], label[64];
  snprintf(expected, sizeof expected, "a %d-vector", length);
  yaml_node_t *n = map_require(m, key, required, expected);
  quote_key(label, sizeof label, key);
  return n != NULL && to_vector(m->r, n, label, length, out);
}

bool get_choice(mapping *m, const char *key, const char *noun, const char *const *choices,
                       bool required, int *out) {
  name_list l;
  char expected[sizeof l.text + 16];
  snprintf(expected, sizeof expected, "one of: %s", join_choices(&l, choices));
  yaml_node_t *n = map_require(m, key, required, expected);
  return n != NULL && to_choice(m->r, n, key, noun, choices, out);
}

/* A unit direction; 'label' as for to_number. */
bool to_unit_axis(reader *r, yaml_node_t *n, const char *label, double out[3]) {
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

bool get_axis(mapping *m, const char *key, bool required, double out[3]) {
  char label[64];
  yaml_node_t *n = map_require(m, key, required, "a 3-vector");
  quote_key(label, sizeof label, key);
  return n != NULL && to_unit_axis(m->r, n, label, out);
}
