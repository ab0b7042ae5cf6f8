/* compose.c: the YAML document as the reader sees it (compose.h): merge keys
 * ('<<: *anchor') expanded in place, and the files of a top-level 'include:'
 * merged into the model's sections.  Nodes keep the marks of the text they
 * came from; an included file's lines carry the file (diag.h), so that every
 * later message points into the right file. */
#define _DEFAULT_SOURCE /* realpath */
#include "compose.h"

#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <stdint.h>
#include <string.h>

#include "bounds.h"
#include "diag.h"
#include "yaml_map.h"

/* the sections an included file may supply; everything else belongs to the
 * including model */
static const char *const included_sections[] = {"bodies", "joints",     "drivers",    "forces", "outputs",
                                                "scenes", "parameters", "subsystems", NULL};

typedef struct {
  const char *path;   /* the file the document came from, for messages */
  yaml_document_t *doc;
  unsigned char *state; /* per node: 0 not seen, 1 being expanded, 2 done */
  bool ok;
} merger;

static ir_loc mark_loc(yaml_mark_t mark) {
  ir_loc loc = {(int)mark.line + 1, (int)mark.column + 1};
  return loc;
}

static bool is_merge_key(const yaml_node_t *key) {
  return key->type == YAML_SCALAR_NODE && key->data.scalar.style == YAML_PLAIN_SCALAR_STYLE &&
         key->data.scalar.length == 2 && memcmp(key->data.scalar.value, "<<", 2) == 0;
}

static bool same_scalar(const yaml_node_t *a, const yaml_node_t *b) {
  return a->type == YAML_SCALAR_NODE && b->type == YAML_SCALAR_NODE &&
         a->data.scalar.length == b->data.scalar.length &&
         memcmp(a->data.scalar.value, b->data.scalar.value, a->data.scalar.length) == 0;
}

static int npairs(const yaml_node_t *n) {
  return (int)(n->data.mapping.pairs.top - n->data.mapping.pairs.start);
}

/* true if 'key' is among pairs[0..count) */
static bool has_key(yaml_document_t *doc, const yaml_node_pair_t *pairs, int count,
                    const yaml_node_t *key) {
  for (int i = 0; i < count; i++)
    if (same_scalar(yaml_document_get_node(doc, pairs[i].key), key)) return true;
  return false;
}

static void expand(merger *g, int index);

/* appends to out[*count] the pairs of merge source 'src' that neither the
 * mapping itself ('own', its explicit keys) nor an earlier source gave */
static void take_source(merger *g, int src, const yaml_node_pair_t *own, int nown,
                        yaml_node_pair_t *out, int *count) {
  yaml_node_t *s = yaml_document_get_node(g->doc, src);
  if (s->type != YAML_MAPPING_NODE) {
    diag_error(g->path, mark_loc(s->start_mark),
               "'<<' merges a mapping or a list of mappings (got %s)",
               s->type == YAML_SEQUENCE_NODE ? "a list" : "a scalar");
    g->ok = false;
    return;
  }
  expand(g, src);
  s = yaml_document_get_node(g->doc, src);
  for (int i = 0; i < npairs(s); i++) {
    yaml_node_pair_t p = s->data.mapping.pairs.start[i];
    yaml_node_t *key = yaml_document_get_node(g->doc, p.key);
    bool explicit_key = false;
    for (int k = 0; k < nown && !explicit_key; k++)
      explicit_key = !is_merge_key(yaml_document_get_node(g->doc, own[k].key)) &&
                     same_scalar(yaml_document_get_node(g->doc, own[k].key), key);
    if (!explicit_key && !has_key(g->doc, out, *count, key)) out[(*count)++] = p;
  }
}

/* The merge keys of mapping 'index' replaced by the pairs they merge, at
 * their place; explicit keys win, and of several sources the first wins
 * (the YAML merge-key convention).  Sources are expanded first. */
static void expand(merger *g, int index) {
  yaml_node_t *n = yaml_document_get_node(g->doc, index);
  if (n == NULL || n->type != YAML_MAPPING_NODE || g->state[index] == 2) return;
  if (g->state[index] == 1) {
    diag_error(g->path, mark_loc(n->start_mark), "this mapping merges itself ('<<' cycle)");
    g->ok = false;
    return;
  }
  g->state[index] = 1;
  int count = npairs(n), capacity = 0;
  bool any = false;
  for (int i = 0; i < count; i++) {
    yaml_node_pair_t p = n->data.mapping.pairs.start[i];
    yaml_node_t *v = yaml_document_get_node(g->doc, p.value);
    if (!is_merge_key(yaml_document_get_node(g->doc, p.key))) { capacity++; continue; }
    any = true;
    if (v->type == YAML_MAPPING_NODE)
      capacity += npairs(v);
    else if (v->type == YAML_SEQUENCE_NODE)
      for (yaml_node_item_t *it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++) {
        yaml_node_t *src = yaml_document_get_node(g->doc, *it);
        capacity += src->type == YAML_MAPPING_NODE ? npairs(src) : 0;
      }
  }
  if (!any) { g->state[index] = 2; return; }
  /* the sources' own merges may add keys: expand them before sizing */
  for (int i = 0; i < count; i++) {
    yaml_node_pair_t p = n->data.mapping.pairs.start[i];
    if (!is_merge_key(yaml_document_get_node(g->doc, p.key))) continue;
    yaml_node_t *v = yaml_document_get_node(g->doc, p.value);
    if (v->type == YAML_MAPPING_NODE) expand(g, p.value);
    else if (v->type == YAML_SEQUENCE_NODE)
      for (yaml_node_item_t *it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++)
        expand(g, *it);
  }
  n = yaml_document_get_node(g->doc, index);
  capacity = 0;
  for (int i = 0; i < count; i++) {
    yaml_node_pair_t p = n->data.mapping.pairs.start[i];
    yaml_node_t *v = yaml_document_get_node(g->doc, p.value);
    if (!is_merge_key(yaml_document_get_node(g->doc, p.key))) capacity++;
    else if (v->type == YAML_MAPPING_NODE) capacity += npairs(v);
    else if (v->type == YAML_SEQUENCE_NODE)
      for (yaml_node_item_t *it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++) {
        yaml_node_t *src = yaml_document_get_node(g->doc, *it);
        capacity += src->type == YAML_MAPPING_NODE ? npairs(src) : 0;
      }
  }
  yaml_node_pair_t *out = malloc(sizeof *out * (size_t)(capacity + 1));
  if (out == NULL) out_of_memory();
  yaml_node_pair_t *own = n->data.mapping.pairs.start;
  int nout = 0;
  for (int i = 0; i < count; i++) {
    yaml_node_pair_t p = own[i];
    yaml_node_t *key = yaml_document_get_node(g->doc, p.key);
    if (!is_merge_key(key)) {
      out[nout++] = p;
      continue;
    }
    yaml_node_t *v = yaml_document_get_node(g->doc, p.value);
    if (v->type == YAML_SEQUENCE_NODE) {
      for (yaml_node_item_t *it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++)
        take_source(g, *it, own, count, out, &nout);
    } else {
      take_source(g, p.value, own, count, out, &nout);
    }
  }
  /* libyaml frees the pairs with free() (yaml_document_delete) */
  free(n->data.mapping.pairs.start);
  n->data.mapping.pairs.start = out;
  n->data.mapping.pairs.top = out + nout;
  n->data.mapping.pairs.end = out + capacity + 1;
  g->state[index] = 2;
}

static bool expand_merges(const char *path, yaml_document_t *doc) {
  int count = (int)(doc->nodes.top - doc->nodes.start);
  merger g = {path, doc, xcalloc((size_t)count + 1, 1), true};
  for (int i = 1; i <= count; i++) expand(&g, i);
  free(g.state);
  return g.ok;
}

/* ---------------------------------------------------------------------------
 * include:
 * ------------------------------------------------------------------------- */

typedef struct {
  const char *path;       /* the model's file */
  yaml_document_t *doc;   /* the model's document, receiving the included nodes */
  compose_files *files;   /* every file included, for the input hash */
  char *stack[LIMIT_INCLUDE_DEPTH + 1]; /* the canonical paths being included (cycles) */
  int depth;
  bool ok;
} includer;

static bool compose_into(includer *c, const char *path, yaml_document_t *doc);

/* a path named in 'from' (a file), relative to its directory */
static char *relative_to(const char *from, const char *name, size_t length) {
  const char *slash = strrchr(from, '/');
  size_t dl = (slash && name[0] != '/') ? (size_t)(slash - from + 1) : 0;
  char *path = xcalloc(dl + length + 1, 1);
  memcpy(path, from, dl);
  memcpy(path + dl, name, length);
  return path;
}

/* loads one YAML file; its lines are moved to its registered number */
static bool load_file(const char *path, ir_loc at, const char *at_file, int instance, yaml_document_t *doc) {
  FILE *f = fopen(path, "rb");
  if (f == NULL) {
    diag_error(at_file, at, "cannot read the included file '%s': %s", path, strerror(errno));
    return false;
  }
  fseek(f, 0, SEEK_END);
  long size = ftell(f);
  fseek(f, 0, SEEK_SET);
  if (size < 0 || (double)size > LIMIT_INPUT_BYTES) {
    fclose(f);
    diag_error(at_file, at, "the included file '%s' is larger than the limit of %.0f bytes", path,
               (double)LIMIT_INPUT_BYTES);
    return false;
  }
  char *data = xcalloc((size_t)size + 1, 1);
  size_t got = fread(data, 1, (size_t)size, f);
  fclose(f);
  if (!diag_check_lines(path, data, got)) {
    free(data);
    return false;
  }
  size_t deep_at = 0;
  if (yaml_flow_depth(data, got, LIMIT_YAML_DEPTH, &deep_at) > LIMIT_YAML_DEPTH) {
    diag_error(path, (ir_loc){1, 1}, "brackets nested more than %d deep (the limit of the model reader)",
               LIMIT_YAML_DEPTH);
    free(data);
    return false;
  }
  int k = instance ? instance : diag_register_file(path);
  if (k == 0) {
    diag_error(at_file, at, "more than %d included files", DIAG_MAX_FILES);
    free(data);
    return false;
  }
  yaml_parser_t parser;
  if (!yaml_parser_initialize(&parser)) out_of_memory();
  yaml_parser_set_input_string(&parser, (const unsigned char *)data, got);
  bool ok = yaml_parser_load(&parser, doc) != 0;
  if (!ok) {
    ir_loc loc = mark_loc(parser.problem_mark);
    if (parser.error == YAML_READER_ERROR) loc = (ir_loc){1, 1};
    diag_error(path, loc, "invalid YAML: %s", parser.problem ? parser.problem : "unknown problem");
  } else if (yaml_document_get_root_node(doc) == NULL) {
    diag_error(path, (ir_loc){1, 1}, "empty included file (expected a mapping with sections such as 'bodies')");
    yaml_document_delete(doc);
    ok = false;
  } else {
    for (yaml_node_t *n = doc->nodes.start; n < doc->nodes.top; n++) {
      n->start_mark.line += (size_t)k * DIAG_FILE_LINES;
      n->end_mark.line += (size_t)k * DIAG_FILE_LINES;
    }
  }
  yaml_parser_delete(&parser);
  free(data);
  return ok;
}

/* a deep copy of node 'index' of 'src' into c->doc (marks kept; shared nodes
 * stay shared through 'copied'); the new node's index */
static int copy_node(includer *c, yaml_document_t *src, int index, int *copied) {
  if (copied[index]) return copied[index];
  yaml_node_t n = *yaml_document_get_node(src, index);
  int to = 0;
  if (n.type == YAML_SCALAR_NODE) {
    to = yaml_document_add_scalar(c->doc, n.tag, n.data.scalar.value, (int)n.data.scalar.length,
                                  n.data.scalar.style);
  } else if (n.type == YAML_SEQUENCE_NODE) {
    to = yaml_document_add_sequence(c->doc, n.tag, n.data.sequence.style);
    if (to) copied[index] = to;
    for (yaml_node_item_t *it = n.data.sequence.items.start; to && it < n.data.sequence.items.top; it++)
      if (!yaml_document_append_sequence_item(c->doc, to, copy_node(c, src, *it, copied))) to = 0;
  } else if (n.type == YAML_MAPPING_NODE) {
    to = yaml_document_add_mapping(c->doc, n.tag, n.data.mapping.style);
    if (to) copied[index] = to;
    for (yaml_node_pair_t *p = n.data.mapping.pairs.start; to && p < n.data.mapping.pairs.top; p++) {
      int key = copy_node(c, src, p->key, copied);
      int value = copy_node(c, src, p->value, copied);
      if (!yaml_document_append_mapping_pair(c->doc, to, key, value)) to = 0;
    }
  }
  if (!to) out_of_memory();
  yaml_node_t *dst = yaml_document_get_node(c->doc, to);
  dst->start_mark = n.start_mark;
  dst->end_mark = n.end_mark;
  copied[index] = to;
  return to;
}

/* the root's pair for 'key', or -1 */
static int root_pair(yaml_document_t *doc, const char *key) {
  yaml_node_t *root = yaml_document_get_root_node(doc);
  for (int i = 0; i < npairs(root); i++)
    if (scalar_equals(yaml_document_get_node(doc, root->data.mapping.pairs.start[i].key), key)) return i;
  return -1;
}

/* the sections of included document 'src' appended to the model's */
static void merge_sections(includer *c, const char *path, yaml_document_t *src) {
  yaml_node_t *root = yaml_document_get_root_node(src);
  if (root->type != YAML_MAPPING_NODE) {
    diag_error(path, mark_loc(root->start_mark),
               "an included file must be a mapping of sections (bodies, joints, drivers, forces, "
               "outputs, scenes, parameters, subsystems)");
    c->ok = false;
    return;
  }
  int *copied = xcalloc((size_t)(src->nodes.top - src->nodes.start) + 1, sizeof *copied);
  for (int i = 0; i < npairs(root); i++) {
    yaml_node_pair_t p = root->data.mapping.pairs.start[i];
    yaml_node_t *key = yaml_document_get_node(src, p.key);
    if (scalar_equals(key, "include")) continue; /* done */
    bool allowed = false;
    for (int s = 0; included_sections[s] && !allowed; s++) allowed = scalar_equals(key, included_sections[s]);
    if (!allowed) {
      diag_error(path, mark_loc(key->start_mark),
                 "%s%.*s%s cannot come from an included file (it supplies parameters, bodies, joints, drivers, "
                 "forces, outputs, scenes and subsystems)", key->type == YAML_SCALAR_NODE ? "'" : "",
                 key->type == YAML_SCALAR_NODE ? (int)key->data.scalar.length : 7,
                 key->type == YAML_SCALAR_NODE ? (const char *)key->data.scalar.value : "this key",
                 key->type == YAML_SCALAR_NODE ? "'" : "");
      c->ok = false;
      continue;
    }
    yaml_node_t *value = yaml_document_get_node(src, p.value);
    bool list = scalar_equals(key, "outputs");
    if (value->type != (list ? YAML_SEQUENCE_NODE : YAML_MAPPING_NODE)) {
      diag_error(path, mark_loc(value->start_mark), "'%.*s' of an included file must be a %s",
                 (int)key->data.scalar.length, (const char *)key->data.scalar.value,
                 list ? "list" : "mapping");
      c->ok = false;
      continue;
    }
    const char *name = (const char *)key->data.scalar.value;
    char section[16];
    snprintf(section, sizeof section, "%.*s", (int)key->data.scalar.length, name);
    int at = root_pair(c->doc, section);
    if (at < 0) { /* the model has no such section: the included one becomes it */
      int k = copy_node(c, src, p.key, copied), v = copy_node(c, src, p.value, copied);
      if (!yaml_document_append_mapping_pair(c->doc, 1, k, v)) out_of_memory();
      continue;
    }
    yaml_node_t *mroot = yaml_document_get_root_node(c->doc);
    int target = mroot->data.mapping.pairs.start[at].value;
    yaml_node_t *t = yaml_document_get_node(c->doc, target);
    if (t->type != value->type) continue; /* the reader reports the model's own section */
    if (list) {
      for (yaml_node_item_t *it = value->data.sequence.items.start; it < value->data.sequence.items.top; it++)
        if (!yaml_document_append_sequence_item(c->doc, target, copy_node(c, src, *it, copied))) out_of_memory();
    } else {
      for (yaml_node_pair_t *q = value->data.mapping.pairs.start; q < value->data.mapping.pairs.top; q++) {
        int k = copy_node(c, src, q->key, copied), v = copy_node(c, src, q->value, copied);
        if (!yaml_document_append_mapping_pair(c->doc, target, k, v)) out_of_memory();
      }
    }
  }
  free(copied);
}

/* the 'include:' of document 'doc' (read from 'path'): each file read,
 * composed (its own merges and includes) and merged into c->doc */
static void include_files(includer *c, const char *path, yaml_document_t *doc) {
  yaml_node_t *root = yaml_document_get_root_node(doc);
  if (root == NULL || root->type != YAML_MAPPING_NODE) return;
  int at = -1;
  for (int i = 0; i < npairs(root); i++)
    if (scalar_equals(yaml_document_get_node(doc, root->data.mapping.pairs.start[i].key), "include")) at = i;
  if (at < 0) return;
  int list_index = root->data.mapping.pairs.start[at].value;
  yaml_node_t *list = yaml_document_get_node(doc, list_index);
  int count = list->type == YAML_SEQUENCE_NODE ? (int)(list->data.sequence.items.top - list->data.sequence.items.start) : 1;
  for (int i = 0; i < count; i++) {
    list = yaml_document_get_node(doc, list_index);
    int item_index = list->type == YAML_SEQUENCE_NODE ? list->data.sequence.items.start[i] : list_index;
    yaml_node_t *item = yaml_document_get_node(doc, item_index);
    ir_loc loc = mark_loc(item->start_mark);
    if (item->type != YAML_SCALAR_NODE || item->data.scalar.length == 0) {
      diag_error(path, loc, "'include' must be a file name or a list of file names");
      c->ok = false;
      continue;
    }
    char *file = relative_to(diag_loc_file(loc, path), (const char *)item->data.scalar.value,
                             item->data.scalar.length);
    char *canonical = realpath(file, NULL);
    bool cycle = false;
    for (int d = 0; canonical && d < c->depth; d++) cycle = cycle || strcmp(c->stack[d], canonical) == 0;
    if (cycle) {
      diag_error(path, loc, "include cycle: '%s' is already being included", file);
      c->ok = false;
    } else if (c->depth >= LIMIT_INCLUDE_DEPTH) {
      diag_error(path, loc, "includes nested more than %d deep", LIMIT_INCLUDE_DEPTH);
      c->ok = false;
    } else {
      yaml_document_t included;
      if (!load_file(file, loc, path, 0, &included)) {
        c->ok = false;
      } else {
        c->stack[c->depth++] = canonical;
        canonical = NULL;
        if (c->files->count < (int)(sizeof c->files->path / sizeof *c->files->path))
          c->files->path[c->files->count++] = xstrdup(file);
        if (compose_into(c, file, &included)) merge_sections(c, file, &included);
        free(c->stack[--c->depth]);
        yaml_document_delete(&included);
      }
    }
    free(canonical);
    free(file);
  }
}


/* ---------------------------------------------------------------------------
 * subsystems:
 * ------------------------------------------------------------------------- */

bool compose_is_mirrored(const yaml_node_t *n) {
  return n->type == YAML_SCALAR_NODE && n->tag != NULL && strcmp((const char *)n->tag, COMPOSE_MIRROR_TAG) == 0;
}

double compose_mirror_value(double v) { return v == 0 ? 0.0 : -v; }

bool compose_placement_of(const yaml_node_t *n, compose_placement *p) {
  memset(p, 0, sizeof *p);
  if (n->type != YAML_SCALAR_NODE || n->tag == NULL) return false;
  const char *tag = (const char *)n->tag;
  if (strcmp(tag, COMPOSE_MIRROR_TAG) == 0) {
    p->negate = true;
    return true;
  }
  size_t head = strlen(COMPOSE_PLACED_TAG);
  if (strncmp(tag, COMPOSE_PLACED_TAG, head) != 0) return false;
  const char *at = tag + head;
  p->negate = *at == '-';
  if (*at) at++;
  while (*at == ';' && p->nterms <= LIMIT_INCLUDE_DEPTH) { /* compose.c wrote it: well formed */
    p->subtract[p->nterms] = at[1] == '-';
    char *end = NULL;
    p->node[p->nterms++] = (int)strtol(at + 2, &end, 10);
    at = end;
  }
  return true;
}

enum { KIND_BODY, KIND_JOINT, KIND_DRIVER, KIND_FORCE, KIND_PARAM, KIND_COUNT };
static const char *const kind_section[KIND_COUNT] = {"bodies", "joints", "drivers", "forces", "parameters"};
static const char *const kind_word[KIND_COUNT] = {"body", "joint", "driver", "force", "parameter"};

typedef struct {
  char **name;
  int count, cap;
} name_set;

static void names_add(name_set *s, const char *name, size_t length) {
  if (s->count == s->cap) {
    s->cap = s->cap ? 2 * s->cap : 16;
    s->name = realloc(s->name, (size_t)s->cap * sizeof *s->name);
    if (s->name == NULL) out_of_memory();
  }
  s->name[s->count++] = xstrndup(name, length);
}

static int names_find(const name_set *s, const char *name, size_t length) {
  for (int i = 0; i < s->count; i++)
    if (strlen(s->name[i]) == length && memcmp(s->name[i], name, length) == 0) return i;
  return -1;
}

static void names_free(name_set *s) {
  for (int i = 0; i < s->count; i++) free(s->name[i]);
  free(s->name);
  memset(s, 0, sizeof *s);
}

/* one subsystem instance being expanded */
typedef struct scope {
  struct scope *parent; /* the enclosing instance, NULL for the model */
  const char *path;     /* the subsystem file */
  char *prefix;         /* the full prefix of its names (the enclosing ones' first) */
  size_t own_prefix;    /* the length of the enclosing prefix, where its own begins */
  bool mirror;          /* y -> -y, the enclosing instances' mirrors included */
  /* the translation of its points, per axis: the offsets (scalars of the
     composed document) of this instance and the enclosing ones, innermost
     first, each added or subtracted (COMPOSE_PLACED_TAG) */
  int offset_node[3][LIMIT_INCLUDE_DEPTH + 1];
  bool offset_subtract[3][LIMIT_INCLUDE_DEPTH + 1];
  int noffsets[3];
  const char *moved_path; /* the 'position' of the nearest instance that moves it, for */
  ir_loc moved_at;        /* messages; moved_path NULL when nothing moves it */
  name_set local[KIND_COUNT]; /* its own names (and those its inner instances made), unprefixed */
  name_set attach;      /* its attachments (bodies, then the 'nodes' of the header) ... */
  char **attach_to;     /* ... and the model bodies (nodes) they map to */
  int nbody_attach;     /* attach.name[0..nbody_attach) are bodies */
} scope;

/* the model's name for 'name' of kind 'kind' used in scope s, or NULL */
static char *resolve(const scope *s, int kind, const char *name, size_t length) {
  if (s == NULL) return xstrndup(name, length);
  if (names_find(&s->local[kind], name, length) >= 0) {
    size_t pl = strlen(s->prefix);
    char *out = xcalloc(pl + length + 1, 1);
    memcpy(out, s->prefix, pl);
    memcpy(out + pl, name, length);
    return out;
  }
  if (kind != KIND_BODY) return NULL;
  if (length == 6 && memcmp(name, "ground", 6) == 0) return xstrdup("ground");
  int a = names_find(&s->attach, name, length);
  return a >= 0 && a < s->nbody_attach ? xstrdup(s->attach_to[a]) : NULL;
}


/* a new scalar with the marks of 'like' (copied first: adding a node may move
 * the document's nodes, 'like' among them) */
static int add_scalar_like(yaml_document_t *doc, const yaml_node_t *like, const char *tag, const char *text) {
  yaml_mark_t start = like->start_mark, end = like->end_mark;
  int to = yaml_document_add_scalar(doc, (yaml_char_t *)(uintptr_t)tag, (const yaml_char_t *)text, (int)strlen(text),
                                    YAML_PLAIN_SCALAR_STYLE);
  if (!to) out_of_memory();
  yaml_node_t *n = yaml_document_get_node(doc, to);
  n->start_mark = start;
  n->end_mark = end;
  return to;
}

typedef struct {
  includer *c;
  scope *s;
  bool ok;
} instancer;

/* *slot (a node of c->doc naming a 'kind') replaced by the model's name */
static void rename_ref(instancer *g, yaml_node_item_t *slot, int kind) {
  yaml_document_t *doc = g->c->doc;
  yaml_node_t *n = yaml_document_get_node(doc, *slot);
  if (n == NULL || n->type != YAML_SCALAR_NODE) return; /* the reader reports the type */
  char *to = resolve(g->s, kind, (const char *)n->data.scalar.value, n->data.scalar.length);
  if (to == NULL) {
    diag_error(g->s->path, mark_loc(n->start_mark),
               "unknown %s '%.*s' in the subsystem (neither one of its own%s)", kind_word[kind],
               (int)n->data.scalar.length, (const char *)n->data.scalar.value,
               kind == KIND_BODY ? " bodies, 'ground' nor one of its 'attachments'" : "");
    g->ok = false;
    return;
  }
  *slot = add_scalar_like(doc, n, (const char *)n->tag, to);
  free(to);
}

/* the value of 'key' in mapping 'map' (c->doc), as a slot, or NULL */
static yaml_node_item_t *value_slot(yaml_document_t *doc, int map, const char *key) {
  yaml_node_t *m = yaml_document_get_node(doc, map);
  if (m == NULL || m->type != YAML_MAPPING_NODE) return NULL;
  for (yaml_node_pair_t *p = m->data.mapping.pairs.start; p < m->data.mapping.pairs.top; p++)
    if (scalar_equals(yaml_document_get_node(doc, p->key), key)) return &p->value;
  return NULL;
}

/* a fresh copy of the sequence in *slot (the original may be shared through
 * anchors), each item passed through 'change'; returns the copy's node id */
typedef void item_change(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx);
static int copy_sequence(yaml_document_t *doc, const yaml_node_item_t *slot, item_change *change, void *ctx) {
  yaml_node_t *v = yaml_document_get_node(doc, *slot);
  int list = yaml_document_add_sequence(doc, v->tag, v->data.sequence.style);
  if (!list) out_of_memory();
  v = yaml_document_get_node(doc, *slot); /* adding a node may move them all */
  int count = (int)(v->data.sequence.items.top - v->data.sequence.items.start);
  yaml_mark_t start = v->start_mark, end = v->end_mark;
  for (int i = 0; i < count; i++) {
    v = yaml_document_get_node(doc, *slot);
    yaml_node_item_t item = v->data.sequence.items.start[i];
    change(doc, i, &item, ctx);
    if (!yaml_document_append_sequence_item(doc, list, item)) out_of_memory();
  }
  yaml_node_t *l = yaml_document_get_node(doc, list);
  l->start_mark = start;
  l->end_mark = end;
  return list;
}

typedef struct { instancer *g; int kind; } rename_ctx;
static void rename_item(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx) {
  (void)doc, (void)index;
  const rename_ctx *r = ctx;
  rename_ref(r->g, item, r->kind);
}

static void rename_key(instancer *g, int map, const char *key, int kind) {
  yaml_node_item_t *slot = value_slot(g->c->doc, map, key);
  if (slot == NULL) return;
  yaml_node_t *v = yaml_document_get_node(g->c->doc, *slot);
  if (v->type == YAML_SEQUENCE_NODE) { /* a list of names */
    rename_ctx r = {g, kind};
    int list = copy_sequence(g->c->doc, slot, rename_item, &r);
    *value_slot(g->c->doc, map, key) = list;
  } else {
    rename_ref(g, slot, kind);
  }
}

/* an FE node named in the subsystem: a node attachment becomes the instance's node, anything else stays */
static void rename_node(yaml_document_t *doc, const scope *s, yaml_node_item_t *slot) {
  yaml_node_t *n = yaml_document_get_node(doc, *slot);
  if (n == NULL || n->type != YAML_SCALAR_NODE) return;
  int a = names_find(&s->attach, (const char *)n->data.scalar.value, n->data.scalar.length);
  if (a >= s->nbody_attach) *slot = add_scalar_like(doc, n, NULL, s->attach_to[a]);
}

static void rename_node_item(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx) {
  (void)index;
  rename_node(doc, ctx, item);
}

static void rename_nodes(instancer *g, int map) {
  yaml_document_t *doc = g->c->doc;
  if (g->s->nbody_attach == g->s->attach.count) return;
  yaml_node_item_t *one = value_slot(doc, map, "node");
  if (one != NULL) rename_node(doc, g->s, one);
  yaml_node_item_t *slot = value_slot(doc, map, "nodes");
  if (slot == NULL || yaml_document_get_node(doc, *slot)->type != YAML_SEQUENCE_NODE) return;
  *value_slot(doc, map, "nodes") = copy_sequence(doc, slot, rename_node_item, (void *)g->s);
}

/* mirror: the numbers at the set bits of 'mask' of the list in *slot change
 * sign (a fresh list and fresh scalars carrying COMPOSE_MIRROR_TAG: the
 * original nodes may be shared through anchors) */
static void flip_item(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx) {
  unsigned mask = *(const unsigned *)ctx;
  yaml_node_t *n = yaml_document_get_node(doc, *item);
  if (index >= 32 || !(mask >> index & 1u) || n->type != YAML_SCALAR_NODE) return;
  char *text = xstrndup((const char *)n->data.scalar.value, n->data.scalar.length);
  n = yaml_document_get_node(doc, *item);
  int to = add_scalar_like(doc, n, compose_is_mirrored(n) ? NULL : COMPOSE_MIRROR_TAG, text);
  yaml_node_t *t = yaml_document_get_node(doc, to);
  n = yaml_document_get_node(doc, *item);
  t->data.scalar.style = n->data.scalar.style;
  free(text);
  *item = to;
}

static void flip(yaml_document_t *doc, yaml_node_item_t *slot, unsigned mask) {
  if (slot == NULL) return;
  yaml_node_t *v = yaml_document_get_node(doc, *slot);
  if (v == NULL || v->type != YAML_SEQUENCE_NODE) return;
  *slot = copy_sequence(doc, slot, flip_item, &mask);
}

enum { POLAR = 2u, AXIAL = 5u }; /* y flips for a position, x and z for a rotation axis */

typedef struct { const unsigned *rows; int nrows; } row_masks;
static void flip_row(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx) {
  const row_masks *m = ctx;
  flip(doc, item, m->rows[index < m->nrows ? index : m->nrows - 1]);
}

/* flips every row of the list of lists in *slot by its mask (rows[i], or the last one) */
static void flip_rows(yaml_document_t *doc, yaml_node_item_t *slot, const unsigned *rows, int nrows) {
  if (slot == NULL) return;
  yaml_node_t *v = yaml_document_get_node(doc, *slot);
  if (v == NULL || v->type != YAML_SEQUENCE_NODE) return;
  row_masks m = {rows, nrows};
  *slot = copy_sequence(doc, slot, flip_row, &m); /* a fresh outer list too */
}

static bool value_is(yaml_document_t *doc, int map, const char *key, const char *text) {
  yaml_node_item_t *slot = value_slot(doc, map, key);
  return slot != NULL && scalar_equals(yaml_document_get_node(doc, *slot), text);
}

static bool scope_moves(const scope *s) { return s->noffsets[0] + s->noffsets[1] + s->noffsets[2] > 0; }

/* coordinate 'axis' of a point of scope 'ctx', *item: a fresh scalar that
 * says how the instances placed it (mirrored, then moved; compose.h), or as
 * flip_item mirrors it when nothing moves that coordinate */
static void place_item(yaml_document_t *doc, int axis, yaml_node_item_t *item, void *ctx) {
  const scope *s = ctx;
  yaml_node_t *n = yaml_document_get_node(doc, *item);
  if (axis >= 3 || n->type != YAML_SCALAR_NODE) return;
  bool negate = axis == 1 && s->mirror;
  if (s->noffsets[axis] == 0) {
    unsigned y_only = POLAR;
    if (negate) flip_item(doc, axis, item, &y_only);
    return;
  }
  char tag[sizeof COMPOSE_PLACED_TAG + 2 + (LIMIT_INCLUDE_DEPTH + 1) * 16];
  int length = snprintf(tag, sizeof tag, "%s%c", COMPOSE_PLACED_TAG, negate ? '-' : '+');
  for (int k = 0; k < s->noffsets[axis]; k++)
    length += snprintf(tag + length, sizeof tag - (size_t)length, ";%c%d", s->offset_subtract[axis][k] ? '-' : '+',
                       s->offset_node[axis][k]);
  char *text = xstrndup((const char *)n->data.scalar.value, n->data.scalar.length);
  yaml_scalar_style_t style = n->data.scalar.style;
  int to = add_scalar_like(doc, n, tag, text);
  yaml_document_get_node(doc, to)->data.scalar.style = style;
  free(text);
  *item = to;
}

/* the point [x, y, z] in *slot as scope s places it (a fresh list: the
 * original may be shared through anchors) */
static void place(yaml_document_t *doc, scope *s, yaml_node_item_t *slot) {
  if (slot == NULL || (!s->mirror && !scope_moves(s))) return;
  yaml_node_t *v = yaml_document_get_node(doc, *slot);
  if (v == NULL || v->type != YAML_SEQUENCE_NODE) return;
  *slot = copy_sequence(doc, slot, place_item, s);
}

static void place_row(yaml_document_t *doc, int index, yaml_node_item_t *item, void *ctx) {
  (void)index;
  place(doc, ctx, item);
}

/* every point of the list of points in *slot */
static void place_rows(yaml_document_t *doc, scope *s, yaml_node_item_t *slot) {
  if (slot == NULL || (!s->mirror && !scope_moves(s))) return;
  yaml_node_t *v = yaml_document_get_node(doc, *slot);
  if (v == NULL || v->type != YAML_SEQUENCE_NODE) return;
  *slot = copy_sequence(doc, slot, place_row, s);
}

/* a body without 'position' sits at the origin: in a moved instance it gets
 * the position [0, 0, 0] placed, at the body's mapping */
static void add_origin(instancer *g, int e) {
  yaml_document_t *doc = g->c->doc;
  yaml_node_t *body = yaml_document_get_node(doc, e);
  yaml_node_t like = *body; /* its marks, for the new nodes */
  int key = add_scalar_like(doc, &like, NULL, "position");
  int list = yaml_document_add_sequence(doc, NULL, YAML_FLOW_SEQUENCE_STYLE);
  if (!list) out_of_memory();
  for (int i = 0; i < 3; i++)
    if (!yaml_document_append_sequence_item(doc, list, add_scalar_like(doc, &like, NULL, "0"))) out_of_memory();
  yaml_node_t *l = yaml_document_get_node(doc, list);
  l->start_mark = like.start_mark;
  l->end_mark = like.end_mark;
  if (!yaml_document_append_mapping_pair(doc, e, key, list)) out_of_memory();
  place(doc, g->s, value_slot(doc, e, "position"));
}

/* an FE file's nodes are global: they cannot follow a moved instance */
static bool refuse_fe_file(instancer *g, int e, const char *what, const char *name) {
  yaml_document_t *doc = g->c->doc;
  yaml_node_item_t *fe = value_slot(doc, e, "fe_file");
  if (fe == NULL || !scope_moves(g->s)) return false;
  diag_error(g->s->moved_path, g->s->moved_at,
             "this subsystem instance cannot be moved ('position'): its %s '%s' reads an FE file (fe_file), whose "
             "node positions are global and would stay where they are; read the body from a modal file instead "
             "(modal_file: its nodes are in body axes and move with the body's 'position')", what, name);
  diag_note(g->s->path, mark_loc(yaml_document_get_node(doc, *fe)->start_mark), "the FE file of '%s' is named here", name);
  g->ok = false;
  return true;
}

/* element 'e' (named 'name') of section 'kind' as the instance places it:
 * mirrored (y -> -y, a reflection: positions flip y; rotation axes, angular
 * velocities and torques are axial vectors and flip x and z, so that a
 * mirrored joint turns by the same angle as its original; inertia products
 * with one y index change sign), then moved: its points (global positions)
 * translated, its directions not */
static void place_element(instancer *g, int kind, int e, const char *name) {
  yaml_document_t *doc = g->c->doc;
  scope *s = g->s;
  bool mirror = s->mirror;
  static const unsigned frame_axes[3] = {POLAR, AXIAL, POLAR}; /* rows x, y, z of a proper mirrored frame */
  static const unsigned six[1] = {0x2Au}; /* 6-vectors: y, then the x and z rotations */
  if (kind == KIND_BODY) {
    bool flexible = value_is(doc, e, "type", "flexible");
    if (flexible && mirror) {
      yaml_node_t *n = yaml_document_get_node(doc, e);
      diag_error(s->path, mark_loc(n->start_mark), "a flexible body cannot be mirrored (mirror: true) yet");
      g->ok = false;
      return;
    }
    if (refuse_fe_file(g, e, "flexible body", name)) return;
    /* an FE model of the body's own ('line', 'nodes') is global: it moves,
       and the body frame (by default its first reference node) with it */
    bool own_fe = flexible && value_slot(doc, e, "modal_file") == NULL;
    if (own_fe) {
      yaml_node_item_t *line = value_slot(doc, e, "line");
      if (line != NULL) {
        place(doc, s, value_slot(doc, *line, "from"));
        place(doc, s, value_slot(doc, *line, "to"));
      }
      place_rows(doc, s, value_slot(doc, e, "nodes"));
    }
    if (value_slot(doc, e, "position") != NULL) place(doc, s, value_slot(doc, e, "position"));
    else if (scope_moves(s) && !own_fe) add_origin(g, e);
    if (mirror) {
      flip(doc, value_slot(doc, e, "velocity"), POLAR);
      flip(doc, value_slot(doc, e, "angular_velocity"), AXIAL);
      yaml_node_item_t *o = value_slot(doc, e, "orientation");
      if (o != NULL) {
        yaml_node_t *on = yaml_document_get_node(doc, *o);
        if (on->type == YAML_SEQUENCE_NODE) flip(doc, o, 0xAu); /* e1, e3 */
        else flip(doc, value_slot(doc, *o, "axis"), AXIAL);
      }
      yaml_node_item_t *in = value_slot(doc, e, "inertia");
      if (in != NULL) {
        yaml_node_t *n = yaml_document_get_node(doc, *in);
        int count = n->type == YAML_SEQUENCE_NODE ? (int)(n->data.sequence.items.top - n->data.sequence.items.start) : 0;
        bool matrix = count == 3 && yaml_document_get_node(doc, n->data.sequence.items.start[0])->type == YAML_SEQUENCE_NODE;
        static const unsigned products[3] = {2u, 5u, 2u}; /* Ixy, Iyz (and their transposes) */
        if (matrix) flip_rows(doc, in, products, 3);
        else if (count == 6) flip(doc, in, 0x28u); /* [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] */
      }
    }
    yaml_node_item_t *shape = value_slot(doc, e, "shape");
    if (shape != NULL) {
      place(doc, s, value_slot(doc, *shape, "center"));
      if (mirror) flip(doc, value_slot(doc, *shape, "axis"), POLAR);
    }
  } else if (kind == KIND_JOINT) {
    place(doc, s, value_slot(doc, e, "point"));
    place_rows(doc, s, value_slot(doc, e, "points"));
    if (mirror) { /* directions: a 'reference' is one too (the joint's x, across its axis) */
      static const unsigned axial[1] = {AXIAL};
      flip(doc, value_slot(doc, e, "axis"), value_is(doc, e, "type", "prismatic") ? POLAR : AXIAL);
      flip_rows(doc, value_slot(doc, e, "axes"), axial, 1);
      flip(doc, value_slot(doc, e, "reference"), POLAR);
    }
  } else if (kind == KIND_FORCE) {
    if (refuse_fe_file(g, e, "superelement", name)) return;
    place(doc, s, value_slot(doc, e, "point"));
    place_rows(doc, s, value_slot(doc, e, "points"));
    if (mirror) {
      flip(doc, value_slot(doc, e, "value"), value_is(doc, e, "type", "torque") ? AXIAL : POLAR);
      flip(doc, value_slot(doc, e, "axis"), AXIAL); /* a tyre's spin axis */
      flip_rows(doc, value_slot(doc, e, "axes"), frame_axes, 3);
      if (value_is(doc, e, "type", "bushing") || value_is(doc, e, "type", "field")) {
        flip(doc, value_slot(doc, e, "preload"), six[0]);
        if (value_is(doc, e, "type", "field")) { /* D K D, D = diag(1, -1, 1, -1, 1, -1) */
          static const unsigned rows[6] = {0x2Au, 0x15u, 0x2Au, 0x15u, 0x2Au, 0x15u};
          flip_rows(doc, value_slot(doc, e, "stiffness"), rows, 6);
          flip_rows(doc, value_slot(doc, e, "damping"), rows, 6);
        }
      }
      yaml_node_item_t *section = value_slot(doc, e, "section");
      if (section != NULL) flip(doc, value_slot(doc, *section, "yaxis"), AXIAL);
    }
  }
}

/* the outputs' names prefixed and their references renamed (and mirrored) */
static void instance_output(instancer *g, int o) {
  yaml_document_t *doc = g->c->doc;
  yaml_node_item_t *name = value_slot(doc, o, "name");
  if (name != NULL && yaml_document_get_node(doc, *name)->type == YAML_SCALAR_NODE) {
    yaml_node_t *n = yaml_document_get_node(doc, *name);
    size_t pl = strlen(g->s->prefix);
    char *to = xcalloc(pl + n->data.scalar.length + 1, 1);
    memcpy(to, g->s->prefix, pl);
    memcpy(to + pl, n->data.scalar.value, n->data.scalar.length);
    *name = add_scalar_like(doc, n, NULL, to);
    free(to);
  }
  rename_key(g, o, "body", KIND_BODY);
  rename_key(g, o, "bodies", KIND_BODY);
  if (!value_is(doc, o, "frame", "global")) rename_key(g, o, "frame", KIND_BODY);
  yaml_node_item_t *rel = value_slot(doc, o, "relative_to");
  if (rel != NULL) rename_key(g, *rel, "body", KIND_BODY);
  if (value_is(doc, o, "type", "force") || value_is(doc, o, "type", "tyre")) rename_key(g, o, "element", KIND_FORCE);
  rename_key(g, o, "joint", KIND_JOINT);
  rename_key(g, o, "driver", KIND_DRIVER);
  rename_nodes(g, o);
  /* points of outputs are global at t = 0 */
  place(doc, g->s, value_slot(doc, o, "point"));
  rel = value_slot(doc, o, "relative_to");
  if (rel != NULL) place(doc, g->s, value_slot(doc, *rel, "point"));
  if (g->s->mirror) flip(doc, value_slot(doc, o, "axis"), AXIAL);
}

/* the model's section 'name' (created empty when absent), a node of c->doc */
static int model_section(includer *c, const char *name, bool list) {
  int at = root_pair(c->doc, name);
  if (at >= 0) return yaml_document_get_root_node(c->doc)->data.mapping.pairs.start[at].value;
  int k = yaml_document_add_scalar(c->doc, NULL, (const yaml_char_t *)name, (int)strlen(name), YAML_PLAIN_SCALAR_STYLE);
  int v = list ? yaml_document_add_sequence(c->doc, NULL, YAML_BLOCK_SEQUENCE_STYLE)
               : yaml_document_add_mapping(c->doc, NULL, YAML_BLOCK_MAPPING_STYLE);
  if (!k || !v || !yaml_document_append_mapping_pair(c->doc, 1, k, v)) out_of_memory();
  return v;
}

static void instantiate(includer *c, scope *parent, const char *from_path, yaml_document_t *from_doc,
                        int key_index, int value_index);

/* the 'subsystems:' of document 'doc' (the model, parent NULL, or a subsystem file) */
static void instantiate_all(includer *c, scope *parent, const char *path, yaml_document_t *doc) {
  yaml_node_t *root = yaml_document_get_root_node(doc);
  if (root == NULL || root->type != YAML_MAPPING_NODE) return;
  int at = -1;
  for (int i = 0; i < npairs(root); i++)
    if (scalar_equals(yaml_document_get_node(doc, root->data.mapping.pairs.start[i].key), "subsystems")) at = i;
  if (at < 0) return;
  int list = root->data.mapping.pairs.start[at].value;
  yaml_node_t *l = yaml_document_get_node(doc, list);
  if (l->type != YAML_MAPPING_NODE) {
    diag_error(path, mark_loc(l->start_mark), "'subsystems' must be a mapping of instance name -> {file, ...}");
    c->ok = false;
    return;
  }
  int count = npairs(l);
  for (int i = 0; i < count; i++) { /* the document's nodes move as instances add to it: by index */
    l = yaml_document_get_node(doc, list);
    yaml_node_pair_t p = l->data.mapping.pairs.start[i];
    instantiate(c, parent, path, doc, p.key, p.value);
  }
}

static char *scalar_copy(const yaml_node_t *n) {
  return xstrndup((const char *)n->data.scalar.value, n->data.scalar.length);
}

/* the names of the attachments in the subsystem's header */
static bool read_header(includer *c, scope *s, yaml_document_t *src, ir_loc from, const char *from_path) {
  yaml_node_t *root = yaml_document_get_root_node(src);
  int at = -1;
  for (int i = 0; i < npairs(root); i++)
    if (scalar_equals(yaml_document_get_node(src, root->data.mapping.pairs.start[i].key), "subsystem")) at = i;
  if (at < 0) {
    diag_error(from_path, from, "'%s' is no subsystem file (it has no 'subsystem:' header with its 'attachments')",
               s->path);
    return false;
  }
  yaml_node_t *h = yaml_document_get_node(src, root->data.mapping.pairs.start[at].value);
  if (h->type != YAML_MAPPING_NODE) {
    diag_error(s->path, mark_loc(h->start_mark), "'subsystem' must be a mapping (attachments, description)");
    return false;
  }
  bool ok = true;
  for (int pass = 0; pass < 2; pass++) /* the bodies first, then the nodes */
  for (int i = 0; i < npairs(h); i++) {
    if (pass == 1 && i == 0) s->nbody_attach = s->attach.count;
    yaml_node_t *k = yaml_document_get_node(src, h->data.mapping.pairs.start[i].key);
    yaml_node_t *v = yaml_document_get_node(src, h->data.mapping.pairs.start[i].value);
    if (scalar_equals(k, "description")) continue;
    if (!scalar_equals(k, "attachments") && !scalar_equals(k, "nodes")) {
      diag_error(s->path, mark_loc(k->start_mark), "unknown key in 'subsystem' (expected attachments, nodes, "
                 "description)");
      ok = false;
      continue;
    }
    if (v->type != YAML_SEQUENCE_NODE) {
      diag_error(s->path, mark_loc(v->start_mark), "'%s' must be a list of names",
                 scalar_equals(k, "nodes") ? "nodes" : "attachments");
      ok = false;
      continue;
    }
    if (scalar_equals(k, "nodes") != (pass == 1)) continue;
    for (yaml_node_item_t *it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++) {
      yaml_node_t *a = yaml_document_get_node(src, *it);
      if (a->type != YAML_SCALAR_NODE || a->data.scalar.length == 0) {
        diag_error(s->path, mark_loc(a->start_mark), "an attachment is a name");
        ok = false;
      } else if (names_find(&s->attach, (const char *)a->data.scalar.value, a->data.scalar.length) >= 0) {
        diag_error(s->path, mark_loc(a->start_mark), "attachment '%.*s' is named twice",
                   (int)a->data.scalar.length, (const char *)a->data.scalar.value);
        ok = false;
      } else {
        names_add(&s->attach, (const char *)a->data.scalar.value, a->data.scalar.length);
      }
    }
  }
  if (npairs(h) == 0) s->nbody_attach = s->attach.count;
  (void)c;
  return ok;
}

/* 'position' of an instance: [x, y, z] of scalars (numbers or expressions, read by the reader) */
static bool is_point(yaml_document_t *doc, const yaml_node_t *n) {
  if (n->type != YAML_SEQUENCE_NODE || n->data.sequence.items.top - n->data.sequence.items.start != 3) return false;
  for (yaml_node_item_t *it = n->data.sequence.items.start; it < n->data.sequence.items.top; it++) {
    const yaml_node_t *x = yaml_document_get_node(doc, *it);
    if (x->type != YAML_SCALAR_NODE || x->data.scalar.length == 0) return false;
  }
  return true;
}

/* a number written 0 (0, 0.0, -0, 0e3): that coordinate does not move */
static bool written_zero(const yaml_node_t *n) {
  char *text = xstrndup((const char *)n->data.scalar.value, n->data.scalar.length);
  char *end = NULL;
  double v = strtod(text, &end);
  bool zero = end != text && *end == '\0' && v == 0;
  free(text);
  return zero;
}

/* the translation of scope s, per axis: the components of its own
 * 'position' (node position_index of from_doc, 0 when none) that are not
 * written 0, as scalars of the composed document, their y subtracted under
 * an enclosing mirror; then the enclosing instances' offsets */
static void take_offsets(includer *c, scope *s, const scope *parent, const char *from_path, yaml_document_t *from_doc,
                         int position_index) {
  if (position_index != 0) {
    int *copied = from_doc == c->doc ? NULL : xcalloc((size_t)(from_doc->nodes.top - from_doc->nodes.start) + 1,
                                                     sizeof *copied);
    for (int axis = 0; axis < 3; axis++) {
      yaml_node_t *p = yaml_document_get_node(from_doc, position_index);
      int item = p->data.sequence.items.start[axis];
      if (written_zero(yaml_document_get_node(from_doc, item))) continue;
      /* the reader reads the composed document: a subsystem file's scalar is copied
         there, keeping its marks (its messages, the parameters its names mean) */
      s->offset_node[axis][0] = copied ? copy_node(c, from_doc, item, copied) : item;
      s->offset_subtract[axis][0] = axis == 1 && parent != NULL && parent->mirror;
      s->noffsets[axis] = 1;
      if (s->moved_path == NULL) {
        s->moved_path = from_path;
        s->moved_at = mark_loc(yaml_document_get_node(from_doc, position_index)->start_mark);
      }
    }
    free(copied);
  }
  if (parent == NULL) return;
  for (int axis = 0; axis < 3; axis++)
    for (int k = 0; k < parent->noffsets[axis]; k++) {
      int n = s->noffsets[axis]++;
      s->offset_node[axis][n] = parent->offset_node[axis][k];
      s->offset_subtract[axis][n] = parent->offset_subtract[axis][k];
    }
  if (s->moved_path == NULL) {
    s->moved_path = parent->moved_path;
    s->moved_at = parent->moved_at;
  }
}

static void instantiate(includer *c, scope *parent, const char *from_path, yaml_document_t *from_doc,
                        int key_index, int value_index) {
  yaml_node_t *key = yaml_document_get_node(from_doc, key_index);
  yaml_node_t *inst = yaml_document_get_node(from_doc, value_index);
  ir_loc at = mark_loc(key->start_mark);
  if (key->type != YAML_SCALAR_NODE || inst->type != YAML_MAPPING_NODE) {
    diag_error(from_path, at, "a subsystem instance is 'name: {file: F, prefix: P, mirror: true|false, position: "
                              "[x, y, z], attach: {...}, parameters: {...}}'");
    c->ok = false;
    return;
  }
  char *name = scalar_copy(key);
  yaml_node_t *file = NULL, *prefix = NULL, *mirror = NULL, *attach = NULL, *params = NULL, *position = NULL;
  int params_index = 0, position_index = 0;
  bool ok = true;
  for (int i = 0; i < npairs(inst); i++) {
    yaml_node_t *k = yaml_document_get_node(from_doc, inst->data.mapping.pairs.start[i].key);
    yaml_node_t *v = yaml_document_get_node(from_doc, inst->data.mapping.pairs.start[i].value);
    if (scalar_equals(k, "file")) file = v;
    else if (scalar_equals(k, "prefix")) prefix = v;
    else if (scalar_equals(k, "mirror")) mirror = v;
    else if (scalar_equals(k, "attach")) attach = v;
    else if (scalar_equals(k, "position")) {
      position = v;
      position_index = inst->data.mapping.pairs.start[i].value;
    }
    else if (scalar_equals(k, "parameters")) {
      params = v;
      params_index = inst->data.mapping.pairs.start[i].value;
    }
    else {
      diag_error(from_path, mark_loc(k->start_mark),
                 "unknown key in subsystem instance '%s' (expected file, prefix, mirror, position, attach, "
                 "parameters)", name);
      ok = false;
    }
  }
  if (file == NULL || file->type != YAML_SCALAR_NODE || file->data.scalar.length == 0) {
    diag_error(from_path, file ? mark_loc(file->start_mark) : at, "subsystem instance '%s' needs 'file: NAME.yaml'",
               name);
    ok = false;
  }
  if (prefix != NULL && prefix->type != YAML_SCALAR_NODE) {
    diag_error(from_path, mark_loc(prefix->start_mark), "'prefix' must be text such as 'fl_'");
    ok = false;
  }
  if (mirror != NULL && !scalar_equals(mirror, "true") && !scalar_equals(mirror, "false")) {
    diag_error(from_path, mark_loc(mirror->start_mark), "'mirror' must be true or false");
    ok = false;
  }
  if (position != NULL && !is_point(from_doc, position)) {
    diag_error(from_path, mark_loc(position->start_mark), "'position' of subsystem instance '%s' must be a list of 3 "
               "numbers or expressions [x, y, z] (the translation of everything the subsystem places)", name);
    ok = false;
  }
  if (attach != NULL && attach->type != YAML_MAPPING_NODE) {
    diag_error(from_path, mark_loc(attach->start_mark), "'attach' must map the subsystem's attachments to bodies");
    ok = false;
  }
  if (params != NULL && params->type != YAML_MAPPING_NODE) {
    diag_error(from_path, mark_loc(params->start_mark), "'parameters' of an instance must be a mapping name -> value");
    ok = false;
  }
  if (!ok) {
    free(name);
    c->ok = false;
    return;
  }
  scope s = {.parent = parent};
  s.path = relative_to(diag_loc_file(mark_loc(file->start_mark), from_path), (const char *)file->data.scalar.value,
                       file->data.scalar.length);
  {
    const char *outer = parent ? parent->prefix : "";
    size_t ol = strlen(outer);
    const char *own = prefix ? (const char *)prefix->data.scalar.value : name;
    size_t length = prefix ? prefix->data.scalar.length : strlen(name) + 1;
    s.prefix = xcalloc(ol + length + 1, 1);
    memcpy(s.prefix, outer, ol);
    memcpy(s.prefix + ol, own, prefix ? length : length - 1);
    if (!prefix) s.prefix[ol + length - 1] = '_';
    s.own_prefix = ol;
  }
  s.mirror = (parent && parent->mirror) != (mirror != NULL && scalar_equals(mirror, "true"));
  take_offsets(c, &s, parent, from_path, from_doc, position_index);
  char *canonical = realpath(s.path, NULL);
  bool cycle = false;
  for (int d = 0; canonical && d < c->depth; d++) cycle = cycle || strcmp(c->stack[d], canonical) == 0;
  yaml_document_t src;
  int k = 0;
  if (cycle) {
    diag_error(from_path, at, "'%s' is already being instantiated (subsystem cycle)", s.path);
    ok = false;
  } else if (c->depth >= LIMIT_INCLUDE_DEPTH) {
    diag_error(from_path, at, "subsystems nested more than %d deep", LIMIT_INCLUDE_DEPTH);
    ok = false;
  } else if ((k = diag_register_instance(s.path, name, s.prefix, at, from_path)) == 0) {
    diag_error(from_path, at, "more than %d included files", DIAG_MAX_FILES);
    ok = false;
  } else if (!load_file(s.path, at, from_path, k, &src)) {
    ok = false;
  }
  if (!ok) {
    free(canonical);
    free((char *)s.path);
    free(s.prefix);
    free(name);
    c->ok = false;
    return;
  }
  c->stack[c->depth++] = canonical;
  if (c->files->count < (int)(sizeof c->files->path / sizeof *c->files->path))
    c->files->path[c->files->count++] = xstrdup(s.path);
  instancer g = {c, &s, expand_merges(s.path, &src)};
  yaml_node_t *root = yaml_document_get_root_node(&src);
  if (root->type != YAML_MAPPING_NODE) {
    diag_error(s.path, mark_loc(root->start_mark), "a subsystem file must be a mapping of sections");
    g.ok = false;
  } else {
    g.ok = read_header(c, &s, &src, at, from_path) && g.ok;
    static const char *const allowed[] = {"subsystem", "parameters", "bodies", "joints", "drivers", "forces",
                                          "outputs", "subsystems", "templates", NULL};
    for (int i = 0; i < npairs(root); i++) {
      yaml_node_t *sk = yaml_document_get_node(&src, root->data.mapping.pairs.start[i].key);
      yaml_node_t *sv = yaml_document_get_node(&src, root->data.mapping.pairs.start[i].value);
      bool known = false;
      for (int a = 0; allowed[a] && !known; a++) known = scalar_equals(sk, allowed[a]);
      if (!known) {
        diag_error(s.path, mark_loc(sk->start_mark),
                   "this key cannot be in a subsystem file (it has subsystem, parameters, bodies, joints, drivers, "
                   "forces, outputs, subsystems and templates)");
        g.ok = false;
        continue;
      }
      for (int kind = 0; kind < KIND_COUNT; kind++) {
        if (!scalar_equals(sk, kind_section[kind])) continue;
        if (sv->type != YAML_MAPPING_NODE) {
          diag_error(s.path, mark_loc(sv->start_mark), "'%s' must be a mapping", kind_section[kind]);
          g.ok = false;
          continue;
        }
        for (int j = 0; j < npairs(sv); j++) {
          yaml_node_t *ek = yaml_document_get_node(&src, sv->data.mapping.pairs.start[j].key);
          if (ek->type == YAML_SCALAR_NODE)
            names_add(&s.local[kind], (const char *)ek->data.scalar.value, ek->data.scalar.length);
        }
      }
      if (scalar_equals(sk, "outputs") && sv->type != YAML_SEQUENCE_NODE) {
        diag_error(s.path, mark_loc(sv->start_mark), "'outputs' must be a list");
        g.ok = false;
      }
    }
  }
  /* the instance's attachments: each one mapped, to a body of the enclosing model or subsystem */
  s.attach_to = xcalloc((size_t)s.attach.count + 1, sizeof *s.attach_to);
  for (int i = 0; g.ok && attach != NULL && i < npairs(attach); i++) {
    yaml_node_t *ak = yaml_document_get_node(from_doc, attach->data.mapping.pairs.start[i].key);
    yaml_node_t *av = yaml_document_get_node(from_doc, attach->data.mapping.pairs.start[i].value);
    int a = ak->type == YAML_SCALAR_NODE ? names_find(&s.attach, (const char *)ak->data.scalar.value,
                                                      ak->data.scalar.length) : -1;
    if (a < 0) {
      char list[512] = "";
      for (int j = 0; j < s.attach.count; j++)
        snprintf(list + strlen(list), sizeof list - strlen(list), "%s%s", j ? ", " : "", s.attach.name[j]);
      diag_error(from_path, mark_loc(ak->start_mark), "unknown attachment '%.*s' of the subsystem '%s' (it has: %s)",
                 ak->type == YAML_SCALAR_NODE ? (int)ak->data.scalar.length : 1,
                 ak->type == YAML_SCALAR_NODE ? (const char *)ak->data.scalar.value : "?", s.path,
                 s.attach.count ? list : "none");
      g.ok = false;
      continue;
    }
    char *to = av->type != YAML_SCALAR_NODE ? NULL
               : a >= s.nbody_attach ? xstrndup((const char *)av->data.scalar.value, av->data.scalar.length)
               : resolve(parent, KIND_BODY, (const char *)av->data.scalar.value, av->data.scalar.length);
    if (to == NULL) {
      diag_error(from_path, mark_loc(av->start_mark), "attachment '%s' must name a body%s", s.attach.name[a],
                 parent ? " of the enclosing subsystem, 'ground' or one of its attachments" : "");
      g.ok = false;
      continue;
    }
    free(s.attach_to[a]);
    s.attach_to[a] = to;
  }
  for (int a = 0; g.ok && a < s.attach.count; a++)
    if (s.attach_to[a] == NULL) {
      diag_error(from_path, at, "subsystem instance '%s' does not say what its attachment '%s' is ('attach: {%s: BODY}')",
                 name, s.attach.name[a], s.attach.name[a]);
      g.ok = false;
    }
  /* parameter overrides name parameters of the subsystem */
  for (int i = 0; g.ok && params != NULL && i < npairs(params); i++) {
    yaml_node_t *pk = yaml_document_get_node(from_doc, params->data.mapping.pairs.start[i].key);
    if (pk->type != YAML_SCALAR_NODE ||
        names_find(&s.local[KIND_PARAM], (const char *)pk->data.scalar.value, pk->data.scalar.length) < 0) {
      diag_error(from_path, mark_loc(pk->start_mark), "the subsystem '%s' has no parameter '%.*s' to set", s.path,
                 pk->type == YAML_SCALAR_NODE ? (int)pk->data.scalar.length : 1,
                 pk->type == YAML_SCALAR_NODE ? (const char *)pk->data.scalar.value : "?");
      g.ok = false;
    }
  }
  /* inner instances first: the subsystem's own elements may name what they make */
  if (g.ok) {
    bool outer_ok = c->ok;
    c->ok = true;
    instantiate_all(c, &s, s.path, &src);
    g.ok = c->ok;
    c->ok = outer_ok;
  }
  if (g.ok) {
    int *copied = xcalloc((size_t)(src.nodes.top - src.nodes.start) + 1, sizeof *copied);
    int *copied_from = from_doc == c->doc ? NULL
                                          : xcalloc((size_t)(from_doc->nodes.top - from_doc->nodes.start) + 1, sizeof *copied_from);
    root = yaml_document_get_root_node(&src);
    bool clash = false;
    for (int i = 0; i < npairs(root); i++) {
      yaml_node_pair_t p = root->data.mapping.pairs.start[i];
      yaml_node_t *sk = yaml_document_get_node(&src, p.key);
      bool outputs = scalar_equals(sk, "outputs");
      int kind = -1;
      for (int kk = 0; kk < KIND_COUNT; kk++)
        if (scalar_equals(sk, kind_section[kk])) kind = kk;
      if (kind < 0 && !outputs) continue;
      yaml_node_t *sv = yaml_document_get_node(&src, p.value);
      if (outputs) {
        if (sv->type != YAML_SEQUENCE_NODE) continue;
        int target = model_section(c, "outputs", true);
        for (int j = 0; j < (int)(sv->data.sequence.items.top - sv->data.sequence.items.start); j++) {
          sv = yaml_document_get_node(&src, p.value);
          int o = copy_node(c, &src, sv->data.sequence.items.start[j], copied);
          if (yaml_document_get_node(c->doc, o)->type == YAML_MAPPING_NODE) instance_output(&g, o);
          if (!yaml_document_append_sequence_item(c->doc, target, o)) out_of_memory();
        }
        continue;
      }
      if (sv->type != YAML_MAPPING_NODE) continue;
      int target = model_section(c, kind_section[kind], false);
      for (int j = 0; j < npairs(sv); j++) {
        sv = yaml_document_get_node(&src, p.value);
        yaml_node_pair_t q = sv->data.mapping.pairs.start[j];
        yaml_node_t *ek = yaml_document_get_node(&src, q.key);
        if (ek->type != YAML_SCALAR_NODE) continue;
        char *full = resolve(&s, kind, (const char *)ek->data.scalar.value, ek->data.scalar.length);
        /* a name the model (or another instance) already has: the prefixes clash */
        yaml_node_t *t = yaml_document_get_node(c->doc, target);
        for (yaml_node_pair_t *tp = t->data.mapping.pairs.start; !clash && tp < t->data.mapping.pairs.top; tp++)
          if (scalar_equals(yaml_document_get_node(c->doc, tp->key), full)) {
            yaml_node_t *other = yaml_document_get_node(c->doc, tp->key);
            diag_error(from_path, at, "prefix clash: the subsystem instance '%s' makes the %s '%s', which exists "
                       "already", name, kind_word[kind], full);
            diag_note(c->path, mark_loc(other->start_mark), "the %s '%s' is defined here", kind_word[kind], full);
            g.ok = false;
            clash = true; /* one message per instance */
          }
        int keyn = add_scalar_like(c->doc, yaml_document_get_node(&src, q.key), NULL, full);
        int value = copy_node(c, &src, q.value, copied);
        if (kind == KIND_PARAM && params != NULL) { /* the instance's value wins */
          ek = yaml_document_get_node(&src, q.key);
          params = yaml_document_get_node(from_doc, params_index); /* c->doc's nodes may have moved */
          for (int a = 0; a < npairs(params); a++) {
            yaml_node_pair_t o = params->data.mapping.pairs.start[a];
            if (!same_scalar(yaml_document_get_node(from_doc, o.key), ek)) continue;
            int over = copied_from ? copy_node(c, from_doc, o.value, copied_from) : o.value;
            yaml_node_item_t *slot = value_slot(c->doc, value, "value");
            if (slot != NULL) *slot = over;
            else value = over;
          }
        }
        if (kind != KIND_PARAM) {
          /* a fresh mapping: copies of one anchor would otherwise share the renaming */
          yaml_node_t *vn = yaml_document_get_node(c->doc, value);
          if (vn->type == YAML_MAPPING_NODE) {
            int fresh = yaml_document_add_mapping(c->doc, vn->tag, vn->data.mapping.style);
            if (!fresh) out_of_memory();
            vn = yaml_document_get_node(c->doc, value);
            int count = npairs(vn);
            yaml_mark_t sm = vn->start_mark, em = vn->end_mark;
            for (int a = 0; a < count; a++) {
              vn = yaml_document_get_node(c->doc, value);
              yaml_node_pair_t vp = vn->data.mapping.pairs.start[a];
              if (!yaml_document_append_mapping_pair(c->doc, fresh, vp.key, vp.value)) out_of_memory();
            }
            yaml_node_t *f = yaml_document_get_node(c->doc, fresh);
            f->start_mark = sm;
            f->end_mark = em;
            value = fresh;
            if (kind == KIND_JOINT || kind == KIND_FORCE) {
              rename_key(&g, value, "bodies", KIND_BODY);
              rename_nodes(&g, value);
            }
            if (kind == KIND_FORCE) rename_key(&g, value, "body", KIND_BODY);
            if (kind == KIND_DRIVER) rename_key(&g, value, "joint", KIND_JOINT);
            if (s.mirror || scope_moves(&s)) place_element(&g, kind, value, full);
          }
        }
        free(full);
        if (!yaml_document_append_mapping_pair(c->doc, target, keyn, value)) out_of_memory();
      }
    }
    free(copied);
    free(copied_from);
  }
  /* what the instance made, named in the enclosing scope */
  if (parent != NULL)
    for (int kind = 0; kind < KIND_COUNT; kind++)
      for (int i = 0; i < s.local[kind].count; i++) {
        const char *own = s.prefix + s.own_prefix;
        char *made = xcalloc(strlen(own) + strlen(s.local[kind].name[i]) + 1, 1);
        strcpy(made, own);
        strcat(made, s.local[kind].name[i]);
        names_add(&parent->local[kind], made, strlen(made));
        free(made);
      }
  free(c->stack[--c->depth]);
  yaml_document_delete(&src);
  for (int kind = 0; kind < KIND_COUNT; kind++) names_free(&s.local[kind]);
  for (int a = 0; a < s.attach.count; a++) free(s.attach_to[a]);
  free(s.attach_to);
  names_free(&s.attach);
  free((char *)s.path);
  free(s.prefix);
  free(name);
  if (!g.ok) c->ok = false;
}

static bool compose_into(includer *c, const char *path, yaml_document_t *doc) {
  bool ok = expand_merges(path, doc);
  include_files(c, path, doc);
  return ok && c->ok;
}

bool compose_document(const char *path, yaml_document_t *doc, compose_files *files) {
  memset(files, 0, sizeof *files);
  if (!expand_merges(path, doc)) return false;
  yaml_node_t *root = yaml_document_get_root_node(doc);
  if (root == NULL || root->type != YAML_MAPPING_NODE) return true; /* the reader says what is wrong */
  includer c = {.path = path, .doc = doc, .files = files, .ok = true};
  c.stack[0] = realpath(path, NULL);
  c.depth = c.stack[0] != NULL;
  include_files(&c, path, doc);
  instantiate_all(&c, NULL, path, doc);
  while (c.depth > 0) free(c.stack[--c.depth]);
  return c.ok;
}

void compose_files_free(compose_files *files) {
  for (int i = 0; i < files->count; i++) free(files->path[i]);
  memset(files, 0, sizeof *files);
}
