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
 * is yaml_map.c; the namespace of names and references, names.c. */
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
  if (b->flex && b->flex->node_ids) { /* an imported FE model: nodes by their ids */
    int k = v == floor(v) && fabs(v) < 1e15 ? fe_node_index(b->flex, (long)v) : -1;
    if (k < 0) error_at(r, loc_of(n), "body '%s' has no node %g (its FE file %s has no such node id)", b->name, v,
                        b->flex->fe_path);
    return k;
  }
  int nn = b->flex && b->flex->nodes ? b->flex->nnodes : -1;
  if (v != floor(v) || v < 0 || (nn >= 0 && v >= nn) || v > LIMIT_COUNT) {
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
    if (v != floor(v) || v < 0 || (nnodes >= 0 && v >= nnodes) || v > LIMIT_COUNT) {
      error_at(r, loc_of(item), "%s: node %g does not exist (nodes are numbered 0 to %d)", label, v,
               nnodes - 1);
      continue;
    }
    out[(*count)++] = (int)v;
  }
  return out;
}

const char *const theory_names[] = {"euler_bernoulli", "timoshenko", NULL};
static const char *const mass_kind_names[] = {"lumped", "consistent", NULL};
static const char *const coupling_names[] = {"full", "partial", "constant", "rigid", NULL};

/* section and material of a beam (fields of ir_beam other than the nodes) */
void parse_beam_properties(reader *r, mapping *body, ir_beam *proto) {
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
void parse_modal_settings(mapping *m, ir_flex *fx) {
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
        if (k != floor(k) || k < 1 || k > LIMIT_COUNT)
          error_at(r, loc_of(modes), "'modes' must be a positive whole number up to %g, 'all' or a mapping (got %g)",
                   LIMIT_COUNT, k);
        else {
          fx->select = MODES_COUNT;
          fx->count = (int)k;
        }
      }
    } else {
      mapping mm;
      if (map_open(&mm, r, modes, loc_of(modes), "'modes' of %s", m->what)) {
        static const char *const mkeys[] = {"count", "max_frequency", "list", NULL};
        map_check_keys(&mm, mkeys);
        double v;
        if (map_has(&mm, "count") + map_has(&mm, "max_frequency") + map_has(&mm, "list") != 1)
          error_at(r, loc_of(modes), "'modes' takes exactly one of 'count', 'max_frequency', 'list'");
        if (get_positive(&mm, "count", false, &v)) {
          if (v != floor(v) || v > LIMIT_COUNT)
            error_at(r, mm.last_loc, "'count' must be a whole number up to %g (got %g)", LIMIT_COUNT, v);
          else { fx->select = MODES_COUNT; fx->count = (int)v; }
        }
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

/* a file name given in the model, relative to the directory of the file
 * that names it (the model file or an included one) */
static char *model_relative_path(reader *r, const yaml_node_t *n) {
  const char *base = diag_loc_file(loc_of(n), r->path);
  const char *slash = strrchr(base, '/');
  const char *fname = scalar_text(n);
  size_t dl = (slash && fname[0] != '/') ? (size_t)(slash - base + 1) : 0;
  char *path = xcalloc(dl + scalar_length(n) + 1, 1);
  memcpy(path, base, dl);
  memcpy(path + dl, fname, scalar_length(n));
  return path;
}

/* 'fe_file': a Nastran deck, or Matrix Market matrices with their DOF map
 * and nodes (compiler/flex/fe_import.h); the node positions, global */
static double *parse_fe_file(mapping *m, ir_body *b, ir_flex *fx) {
  reader *r = m->r;
  static const char *const fe_inline[] = {"line", "nodes", "beams", "section", "material", "theory",
                                          "point_masses", "modal_file", NULL};
  for (int i = 0; fe_inline[i]; i++)
    map_reject(m, fe_inline[i], "flexible body '%s': '%s' does not go with 'fe_file' (the FE file holds "
               "the model)", b->name, fe_inline[i]);
  yaml_node_t *n = map_get(m, "fe_file");
  double *global = NULL;
  int rc = 0;
  if (n->type == YAML_SCALAR_NODE) {
    char *path = model_relative_path(r, n);
    const char *dot = strrchr(path, '.');
    char ext[8] = "";
    for (size_t i = 0; dot && dot[i] && i + 1 < sizeof ext; i++) ext[i] = (char)tolower((unsigned char)dot[i]);
    if (strcmp(ext, ".bdf") && strcmp(ext, ".dat") && strcmp(ext, ".nas")) {
      error_at(r, loc_of(n), "'fe_file': a Nastran deck ends in .bdf, .dat or .nas (got '%s'); Matrix "
               "Market files are given as {stiffness, mass, dofs, nodes}", scalar_text(n));
      free(path);
      return NULL;
    }
    int mk = 0;
    if (get_choice(m, "mass", "mass matrix", mass_kind_names, false, &mk)) fx->mass = (ir_mass_kind)mk;
    rc = fe_import_nastran(path, fx, &global);
    free(path);
  } else {
    mapping fm;
    if (map_open(&fm, r, n, loc_of(n), "'fe_file' of %s", m->what)) {
      static const char *const keys[] = {"stiffness", "mass", "dofs", "nodes", NULL};
      map_check_keys(&fm, keys);
      char *paths[4] = {NULL, NULL, NULL, NULL};
      for (int i = 0; i < 4; i++) {
        yaml_node_t *v = map_require(&fm, keys[i], true, "a file name");
        if (v && v->type == YAML_SCALAR_NODE) paths[i] = model_relative_path(r, v);
        else if (v) error_at(r, loc_of(v), "'%s' must be a file name", keys[i]);
      }
      map_reject(m, "mass", "flexible body '%s': the mass matrix comes from 'fe_file'", b->name);
      if (paths[0] && paths[1] && paths[2] && paths[3]) {
        fe_mtx_files files = {paths[0], paths[1], paths[2], paths[3]};
        rc = fe_import_mtx(&files, fx, &global);
      }
      for (int i = 0; i < 4; i++) free(paths[i]);
    }
    map_close(&fm);
  }
  if (rc) diag_note(r->path, loc_of(n), "in the FE file of flexible body '%s'", b->name);
  return global;
}

/* node numbers of fx (imported: the file's node ids) */
static int *to_flex_node_list(reader *r, yaml_node_t *n, const char *label, const ir_flex *fx, int nnodes,
                              int *count) {
  if (!fx->node_ids) return to_node_list(r, n, label, nnodes, count);
  int *out = to_node_list(r, n, label, -1, count);
  for (int i = 0; out && i < *count; i++) {
    int k = fe_node_index(fx, out[i]);
    if (k < 0)
      error_at(r, loc_of(n), "%s: node %d is not a node id of %s", label, out[i], fx->fe_path);
    out[i] = k < 0 ? 0 : k;
  }
  return out;
}

/* 'reference': a list of clamped nodes, {chord: [A, B]} or free */
static int *parse_flex_reference(reader *r, yaml_node_t *ref, ir_flex *fx, int nnodes, int *count) {
  *count = 0;
  if (ref->type == YAML_SCALAR_NODE && scalar_equals(ref, "free")) {
    fx->reference_kind = REFERENCE_FREE;
    return NULL;
  }
  if (ref->type == YAML_MAPPING_NODE) {
    mapping rm;
    int *out = NULL;
    if (map_open(&rm, r, ref, loc_of(ref), "'reference'")) {
      static const char *const keys[] = {"chord", NULL};
      map_check_keys(&rm, keys);
      yaml_node_t *ch = map_require(&rm, "chord", true, "two nodes [A, B]");
      if (ch) {
        out = to_flex_node_list(r, ch, "'chord'", fx, nnodes, count);
        if (*count != 2 || seq_length(ch) != 2 || out[0] == out[1])
          error_at(r, loc_of(ch), "'chord': expected two different nodes [A, B]");
        fx->reference_kind = REFERENCE_CHORD;
      }
    }
    map_close(&rm);
    return out;
  }
  if (ref->type != YAML_SEQUENCE_NODE) {
    error_at(r, loc_of(ref), "'reference': expected a list of nodes, {chord: [A, B]} or free (got %s)",
             show_node(r, ref));
    return NULL;
  }
  return to_flex_node_list(r, ref, "'reference'", fx, nnodes, count);
}

/* the body frame of a chord (origin at A, x towards B) or free-free (origin
 * at the centre of mass) reference; global: the node positions */
static void place_reference_frame(mapping *m, ir_body *b, const double *global, bool has_position,
                                  bool has_orientation) {
  reader *r = m->r;
  ir_flex *fx = b->flex;
  if (fx->reference_kind == REFERENCE_CHORD && fx->nreference == 2) {
    if (!has_orientation &&
        fe_chord_axes(global + 3 * fx->reference[0], global + 3 * fx->reference[1], b->orientation))
      error_at(r, m->loc, "flexible body '%s': the chord's nodes coincide", b->name);
    return;
  }
  if (fx->reference_kind != REFERENCE_FREE) return;
  if (has_position) {
    error_at(r, m->last_loc, "flexible body '%s': a free-free body's frame is at its centre of mass (leave "
             "'position' out)", b->name);
    return;
  }
  /* lumped masses (rotation-invariant: the model is still global here) */
  double *nm = xcalloc((size_t)fx->nnodes, sizeof *nm), *ni = xcalloc(9 * (size_t)fx->nnodes, sizeof *ni);
  double *keep = fx->nodes, total = 0, c[3] = {0, 0, 0};
  char err[256];
  fx->nodes = (double *)global;
  if (fe_lumped_nodes(fx, nm, ni, err, sizeof err, NULL) == 0)
    for (int k = 0; k < fx->nnodes; k++) {
      total += nm[k];
      for (int i = 0; i < 3; i++) c[i] += nm[k] * global[3 * k + i];
    }
  fx->nodes = keep;
  if (total > 0)
    for (int i = 0; i < 3; i++) b->position[i] = c[i] / total;
  free(nm);
  free(ni);
}

/* 'initial_modes', 'initial_mode_rates': w and its rate at t = 0 (one value
 * per selected mode; checked when the modes are known) */
static void parse_initial_modes(mapping *m, ir_flex *fx) {
  reader *r = m->r;
  static const char *const keys[2] = {"initial_modes", "initial_mode_rates"};
  double **dst[2] = {&fx->w0, &fx->wd0};
  int *cnt[2] = {&fx->nw0, &fx->nwd0};
  ir_loc *loc[2] = {&fx->w0_loc, &fx->wd0_loc};
  for (int k = 0; k < 2; k++) {
    yaml_node_t *n = map_get(m, keys[k]);
    if (!n) continue;
    *loc[k] = loc_of(n);
    if (n->type != YAML_SEQUENCE_NODE || seq_length(n) < 1) {
      error_at(r, loc_of(n), "'%s': expected a list of numbers, one per selected mode", keys[k]);
      continue;
    }
    *cnt[k] = seq_length(n);
    *dst[k] = xcalloc((size_t)*cnt[k], sizeof **dst[k]);
    for (int i = 0; i < *cnt[k]; i++) {
      char label[64];
      snprintf(label, sizeof label, "item %d of '%s'", i + 1, keys[k]);
      to_number(r, seq_item(r, n, i), label, &(*dst[k])[i]);
    }
  }
}

static void parse_flexible_body(mapping *m, ir_body *b, ir_loc type_loc) {
  reader *r = m->r;
  (void)type_loc;
  static const char *const keys[] = {
      "type",    "position",  "orientation", "velocity", "angular_velocity", "line",
      "nodes",   "beams",     "section",     "material", "theory",           "mass",
      "point_masses", "reference", "interface", "modes", "damping", "coupling", "modal_file",
      "fe_file", "initial_modes", "initial_mode_rates", "eigensolver", NULL};
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
  } else if (map_get(m, "fe_file") != NULL) {
    global = parse_fe_file(m, b, fx);
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
  if (map_get(m, "fe_file") && !global) { /* the import failed (reported): nothing to refer to */
    map_get(m, "interface");
    map_get(m, "position");
    parse_modal_settings(m, fx);
    parse_initial_modes(m, fx);
    return;
  }
  if (ref != NULL) {
    fx->reference = parse_flex_reference(r, ref, fx, nn, &fx->nreference);
  } else if (!modal_file) {
    fx->reference = xcalloc(1, sizeof *fx->reference);
    fx->nreference = 1; /* the first node */
  }
  yaml_node_t *itf = map_get(m, "interface");
  if (itf != NULL) fx->interface = to_flex_node_list(r, itf, "'interface'", fx, nn, &fx->ninterface);

  /* body frame: the given position, or the first reference node (free-free:
     the centre of mass; chord: x along it) */
  bool has_position = get_vector(m, "position", 3, false, b->position);
  if (!has_position && global && fx->nreference > 0)
    memcpy(b->position, global + 3 * fx->reference[0], sizeof b->position);
  if (global && fx->reference_kind != REFERENCE_CLAMPED)
    place_reference_frame(m, b, global, has_position, orientation != NULL);
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
    if (fx->fe_path) fe_import_to_body(fx, A);
    free(global);
  }

  parse_modal_settings(m, fx);
  parse_initial_modes(m, fx);
  static const char *const eigensolver_names[] = {"auto", "dense", "sparse", NULL};
  int es = 0;
  if (get_choice(m, "eigensolver", "eigensolver", eigensolver_names, false, &es)) fx->eigensolver = es;
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

static const char *const output_type_names[] = {
    "position",     "orientation",          "angle",    "velocity",       "angular_velocity",
    "acceleration", "angular_acceleration", "reaction", "effort",         "kinetic_energy",
    "potential_energy", "total_energy",     "deflection", "modal", "momentum", "section", NULL};
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
  bool of_body = k <= OUT_ANGULAR_ACCELERATION || k == OUT_DEFLECTION || k == OUT_MODAL || k == OUT_SECTION;
  bool has_point = k == OUT_POSITION || k == OUT_VELOCITY || k == OUT_ACCELERATION;
  bool has_component = of_body && k != OUT_ORIENTATION && k != OUT_ANGLE && k != OUT_MODAL;
  const char *keys[12];
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
  if (k == OUT_SECTION) {
    keys[nkeys++] = "element";
    keys[nkeys++] = "end";
    keys[nkeys++] = "fiber";
  }
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
  static const char *const section_names[] = {"N", "Vy", "Vz", "T", "My", "Mz", NULL};
  if (has_component)
    get_choice(&m, "component", "component", k == OUT_SECTION ? section_names : component_names, false,
               &o->component);
  if (k == OUT_REACTION)
    get_ref(&m, "joint", NAME_JOINT, true, &o->joint, NULL);
  if (k == OUT_EFFORT)
    get_ref(&m, "driver", NAME_DRIVER, true, &o->driver, NULL);
  if ((k == OUT_DEFLECTION || k == OUT_MODAL || k == OUT_SECTION) && o->body >= 0 &&
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
  } else if (k == OUT_SECTION && o->body >= 0) {
    const ir_flex *fx = r->model->bodies[o->body].flex;
    double e = -1;
    if (get_number(&m, "element", true, &e)) {
      o->element = -1;
      if (fx && fx->nodes && e == floor(e))
        for (int i = 0; i < fx->nbeams; i++)
          if ((fx->beam_ids ? fx->beam_ids[i] : i) == (long)e) o->element = i;
      if (o->element < 0)
        error_at(r, m.last_loc, "body '%s' has no beam %g (%s)", r->model->bodies[o->body].name, e,
                 fx && fx->beam_ids ? "elements by their ids in the FE file" : "beams are numbered from 0");
    }
    static const char *const end_names[] = {"A", "B", NULL};
    get_choice(&m, "end", "element end", end_names, false, &o->end);
    yaml_node_t *fb = map_get(&m, "fiber");
    if (fb != NULL) {
      o->has_fiber = to_vector(r, fb, "'fiber'", 2, o->fiber);
      if (map_has(&m, "component")) error_at(r, loc_of(fb), "give either 'fiber' (a stress) or 'component'");
    }
  } else if (k == OUT_MODAL) {
    double mode;
    if (get_positive(&m, "mode", true, &mode)) {
      if (mode != floor(mode) || mode > LIMIT_COUNT)
        error_at(r, m.last_loc, "'mode' must be a mode number (1, 2, ... up to %g)", LIMIT_COUNT);
      else
        o->mode = (int)mode - 1;
    }
  }
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
  for (int i = 0; i < count; i++)
    free(outputs[i].name);
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
                                     "include", "templates", NULL};
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
  check_drivers(r);
  mark_virtual_joints(r, jof_list);
}

/* ---------------------------------------------------------------------------
 * files and YAML syntax
 * ------------------------------------------------------------------------- */

/* the whole file, or NULL (errno set; EFBIG past 'limit' bytes: /dev/zero
   and its kind stop there) */
static char *read_file(const char *path, size_t *size, double limit) {
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

static ir_model *read_model(const char *path, const char *scene) {
  int errors_before = diag_errors();
  size_t size = 0;
  double max_input = limit_value("MBCC_MAX_INPUT", LIMIT_INPUT_BYTES);
  char *data = read_file(path, &size, max_input);
  if (data == NULL) {
    ir_loc nowhere = {0, 0};
    if (errno == EFBIG)
      diag_error(path, nowhere, "the model file is larger than the limit of %.0f bytes "
                 "(MBCC_MAX_INPUT=BYTES lifts it)", max_input);
    else
      diag_error(path, nowhere, "cannot read the model: %s", strerror(errno));
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
  free(fx->modal_file);
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
    free(m->forces[i].scale.table);
    free(m->forces[i].stiffness.table);
    free(m->forces[i].damping.table);
  }
  free(m->forces);
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
