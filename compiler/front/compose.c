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
#include <string.h>

#include "bounds.h"
#include "diag.h"
#include "yaml_map.h"

/* the sections an included file may supply; everything else belongs to the
 * including model */
static const char *const included_sections[] = {"bodies", "joints", "drivers", "forces",
                                                "outputs", "scenes", NULL};

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
static bool load_file(const char *path, ir_loc at, const char *at_file, yaml_document_t *doc) {
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
  size_t deep_at = 0;
  if (yaml_flow_depth(data, got, LIMIT_YAML_DEPTH, &deep_at) > LIMIT_YAML_DEPTH) {
    diag_error(path, (ir_loc){1, 1}, "brackets nested more than %d deep (the limit of the model reader)",
               LIMIT_YAML_DEPTH);
    free(data);
    return false;
  }
  int k = diag_register_file(path);
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
               "outputs, scenes)");
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
                 "%s%.*s%s cannot come from an included file (it supplies bodies, joints, drivers, forces, "
                 "outputs and scenes)", key->type == YAML_SCALAR_NODE ? "'" : "",
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
      if (!load_file(file, loc, path, &included)) {
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
  includer c = {.doc = doc, .files = files, .ok = true};
  c.stack[0] = realpath(path, NULL);
  c.depth = c.stack[0] != NULL;
  include_files(&c, path, doc);
  while (c.depth > 0) free(c.stack[--c.depth]);
  return c.ok;
}

void compose_files_free(compose_files *files) {
  for (int i = 0; i < files->count; i++) free(files->path[i]);
  memset(files, 0, sizeof *files);
}
