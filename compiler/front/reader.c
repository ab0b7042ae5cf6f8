/* reader.c: reads a model file (YAML, schema v1, docs/model-format.md) into
 * the IR of ir.h and validates everything that can be checked before
 * assembly.  The reader keeps going after an error so that one run shows as
 * many problems as possible; ir_read returns NULL if any error was reported.
 *
 * The walk over the YAML document is driven by the schema, never by the
 * document's shape, so its depth is bounded even for cyclic aliases
 * (libyaml allows "&a [*a]").
 *
 * The typed YAML layer (reader state, diagnostics, mappings, typed look-ups)
 * is yaml_map.c; the namespace of names and references, names.c; the
 * flexible body's keys and its FE model, flexible_body.c. */
#include "ir.h"

#include <ctype.h>
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <yaml.h>

#include "diag.h"
#include "bounds.h"
#include "names.h"
#include "params.h"
#include "quantities.h"
#include "reader.h"
#include "scene.h"
#include "compose.h"
#include "sim.h"
#include "element.h"
#include "yaml_map.h"
#include "fe_import.h"
#include "fe.h"
#include "modal_file.h"


static bool is_null_scalar(const yaml_node_t *n) {
  return n->type == YAML_SCALAR_NODE &&
         (scalar_length(n) == 0 || scalar_equals(n, "~") || scalar_equals(n, "null"));
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


/* whether the element is given on FE nodes (true also when the nodes given
 * were wrong: that was reported, and the point is then not required) */
bool fe_nodes_given(mapping *m, const int body[2], int node[2]) {
  bool given = get_fe_nodes(m, body, node) || map_has(m, "node") || map_has(m, "nodes");
  /* a body from a modal data file: its node positions are read later, so the
     point must be given (it is checked against the node when the file is read) */
  for (int s = 0; s < 2; s++)
    if (node[s] >= 0 && !m->r->model->bodies[body[s]].flex->nodes) return false;
  return given;
}

/* the point of side s: the node's position when a node is given (a point
 * given as well must coincide with it) */
void check_node_point(reader *r, const ir_model *model, ir_loc loc, const int body[2],
                             const int node[2], bool point_given, double *point) {
  for (int s = 0; s < 2; s++) {
    if (node[s] < 0 || !model->bodies[body[s]].flex || !model->bodies[body[s]].flex->nodes) continue;
    double P[3];
    fe_node_global(&model->bodies[body[s]], node[s], P);
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

/* each kind's keys, points and axes are its element descriptor's
   (compiler/elements/joint_*.c) */
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
  if (!get_choice(&m, "type", "joint type", joint_type_names(), true, &type)) {
    map_close(&m);
    return;
  }
  const joint_desc *e = joint_elements[type];
  j->kind = e->ir_kind;
  map_describe(&m, "%s joint '%s'", e->type, j->name);
  map_check_keys(&m, e->keys);
  bool on_nodes = false;
  if (get_body_pair(&m, j->body, j->body_loc))
    on_nodes = fe_nodes_given(&m, j->body, j->node);
  e->parse(&m, j, on_nodes);
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * time functions
 * ------------------------------------------------------------------------- */

static const char *const profile_type_names[] = {"constant", "constant_velocity", "polynomial",
                                                 "ramp",     "sine",              "table",
                                                 NULL};

/* 'label' says whose profile it is, e.g. "'motion' of driver 'd'". */
void parse_profile(reader *r, yaml_node_t *n, const char *label, ir_profile *p) {
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

/* its keys and fields are the driver descriptor's (compiler/elements/driver.c) */
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
  map_check_keys(&m, element_driver.keys);
  element_driver.parse(&m, d);
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * forces: each type's keys and parser are its element descriptor's
 * (compiler/elements/, one table in registry.c)
 * ------------------------------------------------------------------------- */

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
  if (get_choice(&m, "type", "force type", force_type_names(), true, &type)) {
    const element_desc *e = force_elements[type];
    f->kind = e->ir_kind;
    map_describe(&m, "%s '%s'", e->type, f->name);
    map_check_keys(&m, e->keys);
    e->parse(&m, f);
  }
  map_close(&m);
}

/* ---------------------------------------------------------------------------
 * outputs
 * ------------------------------------------------------------------------- */

static void parse_output(reader *r, yaml_node_t *n, int item, name_table *scene_outputs,
                         ir_output *o) {
  o->loc = loc_of(n);
  o->body = o->joint = o->driver = o->node = -1;
  o->chord[0] = o->chord[1] = -1;
  o->mode = -1;
  o->component = -1;
  o->scale = 1;
  o->force = o->rel_node = -1;
  o->rel_body = o->frame_body = 0; /* the ground, global axes */

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

  /* each type's keys and fields are its element descriptor's (compiler/elements/output_*.c) */
  int type;
  if (!get_choice(&m, "type", "output type", output_type_names(), true, &type)) {
    map_close(&m);
    return;
  }
  const output_desc *e = output_elements[type];
  o->kind = e->ir_kind;
  map_describe(&m, "%s output '%s'", e->type, o->name ? o->name : "?");
  map_check_keys(&m, e->keys);
  if (e->parse) e->parse(&m, o);
  get_number(&m, "scale", false, &o->scale);
  map_close(&m);
}

/* Outputs are a list (their order is the column order); 'scene_outputs' as
 * for new_name. */
void parse_outputs(reader *r, yaml_node_t *n, name_table *scene_outputs,
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

void free_outputs(ir_output *outputs, int count) {
  for (int i = 0; i < count; i++) {
    free(outputs[i].name);
    free(outputs[i].cm_bodies);
  }
  free(outputs);
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
                                     "forces",  "outputs", "simulation", "scenes", "parameters",
                                     "include", "templates", "roads", "subsystems", NULL};
  map_check_keys(&top, keys);
  /* first: every numeric field may name parameters */
  parse_parameters(r, map_get(&top, "parameters"));

  yaml_node_t *name = map_require(&top, "name", true, "a C identifier");
  if (name != NULL && name->type != YAML_SCALAR_NODE)
    error_at(r, loc_of(name), "'name' must be a C identifier (got %s)", show_node(r, name));
  else if (name != NULL && check_identifier(r, name)) {
    model->name = xstrndup(scalar_text(name), scalar_length(name));
    const char *why = reserved_c_name(model->name);
    if (why != NULL)
      error_at(r, loc_of(name), "'%s' cannot name a model: %s", model->name, why);
  }

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
  double max_bodies = limit_value("MBCC_MAX_BODIES", LIMIT_BODIES);
  if (bodies != NULL && mapping_size(bodies) > max_bodies) {
    /* alone: the joints on them would only repeat it */
    error_at(r, loc_of(bodies), "%d bodies, more than the limit %g (the emitted code and its C "
             "compile grow with the model; MBCC_MAX_BODIES=N lifts the limit)", mapping_size(bodies), max_bodies);
    map_close(&top);
    return;
  }
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

  yaml_node_t *roads = map_get(&top, "roads");
  model->roads = xcalloc((size_t)mapping_size(roads), sizeof *model->roads);
  if (roads != NULL)
    parse_named(r, roads, "roads", parse_road);

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
  scene_mark_pruned_uses(r, root);
  element_driver.check(r);
  mark_virtual_joints(r, jof_list);
}

/* ---------------------------------------------------------------------------
 * files and YAML syntax
 * ------------------------------------------------------------------------- */

/* the whole file, or NULL (errno set; EFBIG past 'limit' bytes: /dev/zero
   and its kind stop there) */
char *read_text_file(const char *path, size_t *size, double limit) {
  FILE *f = fopen(path, "rb");
  if (f == NULL)
    return NULL;
  size_t capacity = 1 << 16, length = 0;
  char *data = xcalloc(capacity, 1);
  for (;;) {
    length += fread(data + length, 1, capacity - length, f);
    if ((double)length > limit) {
      fclose(f);
      free(data);
      errno = EFBIG;
      return NULL;
    }
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

void report_yaml_error(const char *path, const yaml_parser_t *parser, const char *data,
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

bool load_named_yaml(const char *path, yaml_document_t *doc, bool *unreadable) {
  size_t size = 0;
  char *data = read_text_file(path, &size, limit_value("MBCC_MAX_INPUT", LIMIT_INPUT_BYTES));
  *unreadable = data == NULL;
  if (data == NULL) return false;
  bool loaded = false;
  size_t deep_at = 0;
  if (!diag_check_lines(path, data, size)) {
  } else if (yaml_flow_depth(data, size, LIMIT_YAML_DEPTH, &deep_at) > LIMIT_YAML_DEPTH) {
    diag_error(path, loc_of_offset(data, size, deep_at),
               "brackets nested more than %d deep (the limit of the model reader)", LIMIT_YAML_DEPTH);
  } else {
    yaml_parser_t parser;
    if (!yaml_parser_initialize(&parser)) out_of_memory();
    yaml_parser_set_input_string(&parser, (const unsigned char *)data, size);
    loaded = yaml_parser_load(&parser, doc) != 0;
    if (!loaded) report_yaml_error(path, &parser, data, size);
    yaml_parser_delete(&parser);
  }
  free(data);
  return loaded;
}

static ir_model *read_model(const char *path, const char *scene) {
  int errors_before = diag_errors();
  size_t size = 0;
  double max_input = limit_value("MBCC_MAX_INPUT", LIMIT_INPUT_BYTES);
  char *data = read_text_file(path, &size, max_input);
  if (data == NULL) {
    ir_loc nowhere = {0, 0};
    if (errno == EFBIG)
      diag_error(path, nowhere, "the model file is larger than the limit of %.0f bytes "
                 "(MBCC_MAX_INPUT=BYTES lifts it)", max_input);
    else
      diag_error(path, nowhere, "cannot read the model: %s", strerror(errno));
    return NULL;
  }
  if (!diag_check_lines(path, data, size)) {
    free(data);
    return NULL;
  }
  size_t deep_at = 0;
  if (yaml_flow_depth(data, size, LIMIT_YAML_DEPTH, &deep_at) > LIMIT_YAML_DEPTH) {
    diag_error(path, loc_of_offset(data, size, deep_at),
               "brackets nested more than %d deep (the limit of the model reader)", LIMIT_YAML_DEPTH);
    free(data);
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
      compose_files files;
      bool composed = compose_document(path, &doc, &files);
      if (files.count > 0) {
        model->included = xcalloc((size_t)files.count, sizeof *model->included);
        for (int i = 0; i < files.count; i++) model->included[i] = xstrdup(files.path[i]);
        model->nincluded = files.count;
      }
      compose_files_free(&files);
      root = yaml_document_get_root_node(&doc);
      reader r;
      memset(&r, 0, sizeof r);
      r.path = path;
      r.doc = &doc;
      r.model = model;
      if (composed)
        parse_model(&r, root, scene);
      table_free(&r.names);
      free_chosen_scene(&r.scene, model->nbodies);
      free(r.param_nodes);
      free(r.offset_state);
      free(r.offset_value);
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

/* the reader's one recovery point: an allocation that fails anywhere in
   read_model unwinds here (out_of_memory, yaml_map.h) */
ir_model *ir_read(const char *path, const char *scene) {
  jmp_buf oom;
  if (setjmp(oom)) {
    reader_catch_oom(NULL);
    diag_error(path, file_start, "out of memory while reading the model");
    return NULL;
  }
  reader_catch_oom(&oom);
  ir_model *model = read_model(path, scene);
  reader_catch_oom(NULL);
  return model;
}

void free_flex(ir_flex *fx) {
  if (fx == NULL)
    return;
  free(fx->nodes);
  free(fx->node_loc);
  free(fx->beams);
  free(fx->point_masses);
  free(fx->reference);
  free(fx->interface);
  free(fx->residual);
  free(fx->modal_file);
  free_modal_data(fx->modal);
  free(fx->fe_source);
  for (int i = 0; i < fx->nnode_names; i++) free(fx->node_names[i]);
  free(fx->node_names);
  free(fx->node_name_index);
  free(fx->list);
  free(fx->ratios);
  fe_import_free(fx);
  free(fx);
}

void ir_free(ir_model *m) {
  if (m == NULL)
    return;
  free(m->path);
  for (int i = 0; i < m->nincluded; i++)
    free(m->included[i]);
  free(m->included);
  free(m->pruned);
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
    free(m->forces[i].super_body);
    free(m->forces[i].super_point);
    free(m->forces[i].super_K);
    free(m->forces[i].super_C);
    free(m->forces[i].scale.table);
    free(m->forces[i].stiffness.table);
    free(m->forces[i].damping.table);
  }
  free(m->forces);
  for (int i = 0; i < m->nroads; i++) {
    free(m->roads[i].name);
    free(m->roads[i].x);
    free(m->roads[i].y);
    free(m->roads[i].z);
  }
  free(m->roads);
  free_outputs(m->outputs, m->noutputs);
  params_free(m);
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
