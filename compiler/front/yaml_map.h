/* yaml_map.h: the typed YAML access layer of the reader (yaml_map.c): the
 * reader state, diagnostics at file:line:col, sequences, mappings that catch
 * duplicate and unknown keys, and typed look-ups.  Every reader of YAML in
 * the compiler goes through it: the model's document walk (reader.c, scene.c,
 * sim.c, params.c, quantities.c, names.c, compiler/elements/), the YAML FE
 * files (fe_file) and the modal data files (modal_file.c).  compose.c comes
 * before it: it builds the document that the walk reads (merge keys
 * expanded, included files loaded and spliced in, checking only which
 * sections they supply). */
#ifndef MBCC_YAML_MAP_H
#define MBCC_YAML_MAP_H

#include <setjmp.h>
#include <stdbool.h>
#include <stddef.h>
#include <string.h>
#include <yaml.h>

#include "diag.h"
#include "ir.h"
#include "names.h"
#include "vec3.h"

/* memory: the reader's allocations never return NULL.  Out of memory
   unwinds (longjmp) to the recovery point that ir_read sets with
   reader_catch_oom before it reads; ir_read then reports "out of memory" as
   a located error and returns NULL, as for any other error (what was
   allocated is then not freed).  No exit or abort in the library. */
void reader_catch_oom(jmp_buf *recovery);
_Noreturn void out_of_memory(void);
void *xcalloc(size_t count, size_t size);
char *xstrndup(const char *s, size_t length);
static inline char *xstrdup(const char *s) { return xstrndup(s, strlen(s)); }

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
  bool *body_removed; /* per body: 'remove' or not kept by 'rig' */
  bool rig;           /* 'rig': joints to removed bodies become joints to the ground */
  double **motion;    /* rig with a recorded motion: per removed body its rows
                         t, x, y, z, e0, e1, e2, e3 (NULL: not recorded) */
  int nmotion_rows;
  char *gone;         /* "section name\n" of each body, joint, driver, force pruned */
  int nbodies;        /* the model's bodies when the scene was read (the
                         per-body arrays' length; pruning changes the model's) */
  char *motion_path;
  ir_loc motion_loc;
  struct scene_replacement *replace; /* 'replace': joints made bushings */
  int nreplace;
} chosen_scene;

/* a joint replaced by a bushing at its point, in its axes (z = the axis) */
typedef struct scene_replacement {
  int joint;
  double k6[6], c6[6];
  ir_loc loc;
} scene_replacement;

typedef struct reader {
  const char *path;
  yaml_document_t *doc;
  ir_model *model;
  name_table names;
  chosen_scene scene;
  /* 'parameters:' (params.c): the value node of each, evaluated on first use */
  yaml_node_t **param_nodes;
  /* the offsets of moved subsystem instances (compose.h), by node of doc,
     each read once: state 0 not yet, 1 read (offset_value), 2 failed */
  unsigned char *offset_state;
  double *offset_value;
  bool params_block;  /* the model has a 'parameters:' block */
  /* show_*() format user text into these, so a message can quote a few */
  char shown[SHOWN_BUFFERS][SHOWN_SIZE];
  int next_shown;
} reader;

static const ir_loc file_start = {1, 1};

ir_loc loc_of(const yaml_node_t *n);
void error_at(reader *r, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
void note_at(reader *r, ir_loc loc, const char *fmt, ...) DIAG_PRINTF(3, 4);
/* user text, quoted and shortened, in one of the reader's 'shown' buffers */
const char *show_text(reader *r, const char *s, size_t length);
const char *show_node(reader *r, const yaml_node_t *n);
static inline const char *scalar_text(const yaml_node_t *n) { return (const char *)n->data.scalar.value; }
static inline size_t scalar_length(const yaml_node_t *n) { return n->data.scalar.length; }
bool scalar_equals(const yaml_node_t *n, const char *s);
static inline yaml_node_t *node_at(reader *r, int index) { return yaml_document_get_node(r->doc, index); }
int seq_length(const yaml_node_t *n);
yaml_node_t *seq_item(reader *r, const yaml_node_t *n, int i);

/* A comma-separated list of names for "(expected one of: ...)". */
enum { LIST_MAX_NAMES = 12 };

typedef struct name_list {
  char text[512];
  size_t length;
  int count;
} name_list;

void name_list_add(name_list *l, const char *name);
const char *join_choices(name_list *l, const char *const *choices);

/* a mapping being read: duplicate and unknown keys, and typed look-ups */
typedef struct mapping {
  reader *r;
  yaml_node_t *node;  /* the mapping */
  int npairs;
  bool *handled;      /* per pair: a duplicate or already reported */
  char what[160];     /* e.g. "rigid body 'crank'", for messages */
  ir_loc loc;         /* where "missing key" errors go */
  ir_loc last_loc;    /* the value of the last key looked up (else loc) */
} mapping;

yaml_node_t *map_key_node(const mapping *m, int i);
yaml_node_t *map_value_node(const mapping *m, int i);
void map_describe(mapping *m, const char *fmt, ...) DIAG_PRINTF(2, 3);
bool map_open(mapping *m, reader *r, yaml_node_t *node, ir_loc loc, const char *fmt, ...)
    DIAG_PRINTF(5, 6);
void map_close(mapping *m);
int map_find(const mapping *m, const char *key);
static inline bool map_has(const mapping *m, const char *key) { return map_find(m, key) >= 0; }
yaml_node_t *map_get(mapping *m, const char *key);
void map_reject(mapping *m, const char *key, const char *fmt, ...) DIAG_PRINTF(3, 4);
/* reports every key not in the NULL-terminated 'expected' */
void map_check_keys(mapping *m, const char *const *expected);
yaml_node_t *map_require(mapping *m, const char *key, bool required, const char *expected);

/* typed conversions of a node, and look-ups of a key (false: absent or reported) */
bool to_number(reader *r, yaml_node_t *n, const char *label, double *out);
bool to_vector(reader *r, yaml_node_t *n, const char *label, int length, double *out);
bool to_vector_list(reader *r, yaml_node_t *n, const char *label, int count, int length,
                    double *out);
bool to_table(reader *r, yaml_node_t *n, const char *label, const char *pair,
              const char *x_name, double **table, int *count);
bool to_choice(reader *r, yaml_node_t *n, const char *key, const char *noun,
               const char *const *choices, int *out);
void quote_key(char *label, size_t size, const char *key);
bool get_number(mapping *m, const char *key, bool required, double *out);
bool get_positive(mapping *m, const char *key, bool required, double *out);
bool get_nonnegative(mapping *m, const char *key, bool required, double *out);
bool get_vector(mapping *m, const char *key, int length, bool required, double *out);
bool get_choice(mapping *m, const char *key, const char *noun, const char *const *choices,
                bool required, int *out);
bool to_unit_axis(reader *r, yaml_node_t *n, const char *label, double out[3]);
bool get_axis(mapping *m, const char *key, bool required, double out[3]);

#endif
