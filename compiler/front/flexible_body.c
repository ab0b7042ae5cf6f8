/* flexible_body.c: the flexible body's keys in a model file (docs/model-format.md
 * "Flexible bodies"): its FE beam model written inline or read from 'fe_file'
 * (a YAML file, a Nastran deck, Matrix Market matrices), sections and
 * materials, node names, modal settings, the reference frame, initial modes;
 * FE node references of elements.  Part of the document walk of reader.c,
 * which calls parse_flexible_body for a body of type 'flexible'. */
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

/* a scalar that reads as a name (a letter or '_' first), not a number */
static bool looks_like_name(const yaml_node_t *n) {
  if (n->type != YAML_SCALAR_NODE || scalar_length(n) == 0) return false;
  unsigned char c = (unsigned char)scalar_text(n)[0];
  return isalpha(c) || c == '_';
}

/* the node that fx names n (node_names), or -1 after an error at n */
static int named_node(reader *r, const yaml_node_t *n, const ir_flex *fx, const char *label) {
  for (int i = 0; fx && i < fx->nnode_names; i++)
    if (scalar_equals(n, fx->node_names[i])) return fx->node_name_index[i];
  name_list l;
  memset(&l, 0, sizeof l);
  for (int i = 0; fx && i < fx->nnode_names; i++) name_list_add(&l, fx->node_names[i]);
  error_at(r, loc_of(n), "%s: no node is named %s (%s%s)", label, show_node(r, n),
           l.count ? "named nodes: " : "the FE model names no nodes: see 'node_names'", l.text);
  return -1;
}

int to_fe_node(reader *r, yaml_node_t *n, const ir_body *b) {
  double v;
  char label[SHOWN_SIZE];
  snprintf(label, sizeof label, "FE node of body '%s'", b->name);
  if (b->flex && looks_like_name(n)) return named_node(r, n, b->flex, label);
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

/* A list of node indices, each < nnodes (nnodes < 0: not checked yet), or
 * names of nodes of fx (when fx is not NULL). */
static int *to_node_list(reader *r, yaml_node_t *n, const char *label, const ir_flex *fx, int nnodes,
                         int *count) {
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
    if (fx && looks_like_name(item)) {
      int k = named_node(r, item, fx, item_label);
      if (k >= 0) out[(*count)++] = k;
      continue;
    }
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

/* A beam section: explicit A, Iy, Iz, J, or a shape that gives them, and
 * the local axes: 'yaxis', 'zaxis' (FE models only) or the default rule. */
typedef struct {
  double A, Iy, Iz, J, shear_y, shear_z;
  int axes;       /* 0: the default rule, 1: 'yaxis' given, 2: 'zaxis' given */
  double axis[3]; /* the yaxis or zaxis given (global) */
  bool ok;
} section_def;

typedef struct {
  double E, G, rho;
  bool ok;
} material_def;

static const char *const shape_names[] = {"box", "tube", NULL};

/* Closed forms of the thin- and thick-walled sections (h along the local z
 * axis): a rectangular box h x b with wall t, a circular tube of outer
 * diameter d and wall t.  Torsion: Bredt's thin-walled closed section
 * J = 4 Am^2 t / perimeter_m = 2 t hm^2 bm^2 / (hm + bm) on the wall's mid-line
 * (hm = h - t, bm = b - t); a tube J = Iy + Iz (exact for a circular ring). */
static void box_section(double h, double b, double t, section_def *s) {
  double hi = h - 2 * t, bi = b - 2 * t, hm = h - t, bm = b - t;
  s->A = h * b - hi * bi;
  s->Iy = (b * h * h * h - bi * hi * hi * hi) / 12;
  s->Iz = (h * b * b * b - hi * bi * bi * bi) / 12;
  s->J = 2 * t * hm * hm * bm * bm / (hm + bm);
}

static void tube_section(double d, double t, section_def *s) {
  double ro = d / 2, ri = d / 2 - t;
  s->A = PI * (ro * ro - ri * ri);
  s->Iy = s->Iz = PI * (ro * ro * ro * ro - ri * ri * ri * ri) / 4;
  s->J = 2 * s->Iy;
}

static void parse_section(reader *r, yaml_node_t *n, const char *what, ir_beam_theory theory,
                          bool allow_zaxis, section_def *s) {
  memset(s, 0, sizeof *s);
  mapping m;
  if (map_open(&m, r, n, loc_of(n), "%s", what)) {
    static const char *const keys[] = {"area", "Iy", "Iz", "J", "shear_y", "shear_z", "yaxis", "zaxis",
                                       "shape", "h", "b", "t", "d", NULL};
    map_check_keys(&m, keys);
    if (!allow_zaxis) map_reject(&m, "zaxis", "%s: a beam force element takes 'yaxis'", what);
    int shape = -1;
    int errors = diag_errors();
    if (get_choice(&m, "shape", "section shape", shape_names, false, &shape)) {
      static const char *const explicit_keys[] = {"area", "Iy", "Iz", "J", NULL};
      for (int i = 0; explicit_keys[i]; i++)
        map_reject(&m, explicit_keys[i], "%s: '%s' comes from the 'shape' (give one or the other)", what,
                   explicit_keys[i]);
      double h = 0, b = 0, t = 0, d = 0;
      get_positive(&m, "t", true, &t);
      if (shape == 0) {
        map_reject(&m, "d", "%s: a box has 'h', 'b' and 't'", what);
        get_positive(&m, "h", true, &h);
        get_positive(&m, "b", true, &b);
        if (diag_errors() == errors && !(2 * t < fmin(h, b)))
          error_at(r, m.loc, "%s: the wall t = %g must be less than half of h = %g and of b = %g", what, t, h, b);
        else if (diag_errors() == errors)
          box_section(h, b, t, s);
      } else if (shape == 1) {
        map_reject(&m, "h", "%s: a tube has 'd' and 't'", what);
        map_reject(&m, "b", "%s: a tube has 'd' and 't'", what);
        get_positive(&m, "d", true, &d);
        if (diag_errors() == errors && !(2 * t < d))
          error_at(r, m.loc, "%s: the wall t = %g must be less than half of d = %g", what, t, d);
        else if (diag_errors() == errors)
          tube_section(d, t, s);
      }
    } else {
      static const char *const shape_keys[] = {"h", "b", "t", "d", NULL};
      for (int i = 0; shape_keys[i]; i++)
        map_reject(&m, shape_keys[i], "%s: '%s' belongs to a 'shape' (box: h, b, t; tube: d, t)", what,
                   shape_keys[i]);
      get_positive(&m, "area", true, &s->A);
      /* defaults: a solid circular section of that area */
      s->Iy = s->Iz = s->A * s->A / (4 * PI);
      s->J = 2 * s->Iy;
      get_positive(&m, "Iy", false, &s->Iy);
      get_positive(&m, "Iz", false, &s->Iz);
      get_positive(&m, "J", false, &s->J);
    }
    if (theory == BEAM_TIMOSHENKO) s->shear_y = s->shear_z = 5.0 / 6.0;
    get_positive(&m, "shear_y", false, &s->shear_y);
    get_positive(&m, "shear_z", false, &s->shear_z);
    if (theory == BEAM_EULER_BERNOULLI) s->shear_y = s->shear_z = 0;
    if (map_has(&m, "yaxis") && map_has(&m, "zaxis"))
      error_at(r, m.loc, "%s: give either 'yaxis' or 'zaxis', not both", what);
    else if (get_axis(&m, "yaxis", false, s->axis))
      s->axes = 1;
    else if (get_axis(&m, "zaxis", false, s->axis))
      s->axes = 2;
    s->ok = diag_errors() == errors;
  }
  map_close(&m);
}

static void parse_material(reader *r, yaml_node_t *n, const char *what, material_def *mt) {
  memset(mt, 0, sizeof *mt);
  mapping m;
  if (map_open(&m, r, n, loc_of(n), "%s", what)) {
    int errors = diag_errors();
    static const char *const keys[] = {"E", "G", "nu", "density", NULL};
    map_check_keys(&m, keys);
    get_positive(&m, "E", true, &mt->E);
    get_positive(&m, "density", true, &mt->rho);
    double nu = 0.3;
    bool has_nu = get_number(&m, "nu", false, &nu);
    if (has_nu && !(nu > -1 && nu < 0.5))
      error_at(r, m.last_loc, "'nu' must lie between -1 and 0.5 (got %g)", nu);
    mt->G = mt->E / (2 * (1 + nu));
    if (map_has(&m, "G")) {
      if (has_nu) error_at(r, m.loc, "give either 'G' or 'nu', not both");
      get_positive(&m, "G", false, &mt->G);
    }
    mt->ok = diag_errors() == errors;
  }
  map_close(&m);
}

static void apply_section(ir_beam *bm, const section_def *s) {
  bm->A = s->A;
  bm->Iy = s->Iy;
  bm->Iz = s->Iz;
  bm->J = s->J;
  bm->shear_y = s->shear_y;
  bm->shear_z = s->shear_z;
}

static void apply_material(ir_beam *bm, const material_def *mt) {
  bm->E = mt->E;
  bm->G = mt->G;
  bm->rho = mt->rho;
}

/* section and material of a beam force element (fields of ir_beam other
 * than the nodes; proto->theory set) */
void parse_beam_properties(reader *r, mapping *body, ir_beam *proto) {
  yaml_node_t *n = map_require(body, "section", true, "a mapping {area, Iy, Iz, J, ...} or {shape, ...}");
  if (n != NULL) {
    section_def s;
    char what[200];
    snprintf(what, sizeof what, "'section' of %s", body->what);
    parse_section(r, n, what, proto->theory, false, &s);
    apply_section(proto, &s);
    if (s.axes == 1) memcpy(proto->yaxis, s.axis, sizeof s.axis);
  }
  n = map_require(body, "material", true, "a mapping {E, nu or G, density}");
  if (n != NULL) {
    material_def mt;
    char what[200];
    snprintf(what, sizeof what, "'material' of %s", body->what);
    parse_material(r, n, what, &mt);
    apply_material(proto, &mt);
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
          fx->list = to_node_list(r, l, "'list' of modes", NULL, -1, &fx->nlist);
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
char *model_relative_path(reader *r, const yaml_node_t *n) {
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
static double *parse_fe_model(mapping *m, ir_flex *fx);

/* a file name that ends in .yaml or .yml */
static bool is_yaml_name(const char *path) {
  size_t n = strlen(path);
  return (n > 5 && !strcmp(path + n - 5, ".yaml")) || (n > 4 && !strcmp(path + n - 4, ".yml"));
}

/* 'fe_file: X.fe.yaml': the FE beam model in a YAML file of its own, with the
 * keys of an inline one; errors are located in that file.  Returns the node
 * positions (global), or NULL after an error. */
static double *parse_fe_yaml(reader *r, ir_body *b, ir_flex *fx, char *path) {
  yaml_document_t doc;
  bool unreadable = false;
  if (!load_named_yaml(path, &doc, &unreadable)) {
    if (unreadable)
      diag_error(path, (ir_loc){0, 0}, "cannot read the FE file: %s",
                 errno == EFBIG ? "larger than MBCC_MAX_INPUT" : strerror(errno));
    free(path);
    return NULL;
  }
  double *global = NULL;
  yaml_node_t *root = yaml_document_get_root_node(&doc);
  reader fr; /* the FE file's own reader: its diagnostics name that file */
  memset(&fr, 0, sizeof fr);
  fr.path = path;
  fr.doc = &doc;
  fr.model = r->model;
  mapping fm;
  if (root == NULL) {
    diag_error(path, file_start, "empty FE file (expected a mapping with 'nodes' and 'beams')");
  } else if (map_open(&fm, &fr, root, loc_of(root), "the FE model of flexible body '%s'", b->name)) {
    static const char *const keys[] = {"description", "line", "nodes", "beams", "section", "material",
                                       "sections", "materials", "theory", "mass", "nonstructural_mass",
                                       "point_masses", "node_names", NULL};
    map_check_keys(&fm, keys);
    map_get(&fm, "description");
    int errors = diag_errors();
    global = parse_fe_model(&fm, fx);
    map_close(&fm);
    if (diag_errors() > errors) {
      free(global);
      global = NULL;
    }
  } else {
    map_close(&fm);
  }
  yaml_document_delete(&doc);
  if (global) fx->fe_source = path;
  else free(path);
  return global;
}

static double *parse_fe_file(mapping *m, ir_body *b, ir_flex *fx) {
  reader *r = m->r;
  static const char *const fe_inline[] = {"line", "nodes", "beams", "section", "material", "theory",
                                          "point_masses", "modal_file", "sections", "materials",
                                          "nonstructural_mass", "node_names", NULL};
  for (int i = 0; fe_inline[i]; i++)
    map_reject(m, fe_inline[i], "flexible body '%s': '%s' does not go with 'fe_file' (the FE file holds "
               "the model)", b->name, fe_inline[i]);
  yaml_node_t *n = map_get(m, "fe_file");
  double *global = NULL;
  int rc = 0;
  if (n->type == YAML_SCALAR_NODE && is_yaml_name(scalar_text(n))) {
    map_reject(m, "mass", "flexible body '%s': 'mass' goes in its FE file %s", b->name, scalar_text(n));
    int errors = diag_errors();
    global = parse_fe_yaml(r, b, fx, model_relative_path(r, n));
    rc = diag_errors() > errors;
  } else if (n->type == YAML_SCALAR_NODE) {
    char *path = model_relative_path(r, n);
    const char *dot = strrchr(path, '.');
    char ext[8] = "";
    for (size_t i = 0; dot && dot[i] && i + 1 < sizeof ext; i++) ext[i] = (char)tolower((unsigned char)dot[i]);
    if (strcmp(ext, ".bdf") && strcmp(ext, ".dat") && strcmp(ext, ".nas")) {
      error_at(r, loc_of(n), "'fe_file': a YAML FE model ends in .yaml or .yml, a Nastran deck in .bdf, .dat "
               "or .nas (got '%s'); Matrix Market files are given as {stiffness, mass, dofs, nodes}", scalar_text(n));
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
  if (!fx->node_ids) return to_node_list(r, n, label, fx, nnodes, count);
  int *out = to_node_list(r, n, label, NULL, -1, count);
  for (int i = 0; out && i < *count; i++) {
    int k = fe_node_index(fx, out[i]);
    if (k < 0)
      error_at(r, loc_of(n), "%s: node %d is not a node id of %s", label, out[i], fx->fe_path);
    out[i] = k < 0 ? 0 : k;
  }
  return out;
}

/* A superelement's FE model ('fe_file' of force 'owner') and its nodes
 * ('interface': [node 0, loaded nodes...], numbered as the file numbers
 * them; *nodes allocated, *count of them, 2 or more).  The nodes stay in
 * global axes (fx->nodes).  Returns false after an error. */
bool read_superelement_fe(mapping *m, const char *owner, ir_flex *fx, int **nodes, int *count) {
  reader *r = m->r;
  ir_body owner_body;
  memset(&owner_body, 0, sizeof owner_body);
  owner_body.name = (char *)owner;
  fx->loc = m->loc;
  yaml_node_t *file = map_require(m, "fe_file", true, "an FE file");
  yaml_node_t *itf = map_require(m, "interface", true, "[node 0, loaded nodes ...]");
  if (!file) return false;
  int errors = diag_errors();
  double *global = parse_fe_file(m, &owner_body, fx);
  if (!global || diag_errors() > errors) { free(global); return false; }
  fx->nodes = global;
  if (fx->fe_path) {
    static const double identity[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    fe_import_to_body(fx, identity);
  }
  if (!itf) return false;
  *count = 0;
  int *list = to_flex_node_list(r, itf, "'interface'", fx, fx->nnodes, count);
  bool ok = list && *count >= 2 && *count <= 1 + MB_SUPER_MAX_NODES && diag_errors() == errors;
  if (list && (*count < 2 || *count > 1 + MB_SUPER_MAX_NODES))
    error_at(r, loc_of(itf), "'interface': a superelement takes 2 nodes or more, at most %d [node 0 (held, "
             "the element's frame), loaded nodes ...] (got %d)", 1 + MB_SUPER_MAX_NODES, *count);
  if (ok) *nodes = list;
  else free(list);
  return ok;
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

/* the local y axis of an element p0 -> p1 (global) by its section's rule:
 * 'yaxis' as given; 'zaxis': local z = zaxis made perpendicular to the
 * element, or, for an element within ~18 degrees of it (|cos| > 0.95), the
 * global axis least aligned with zaxis (x first), and y = z x x; default:
 * global y, or global z for an element within ~26 degrees of y. */
static void section_yaxis(const section_def *s, const double *p0, const double *p1, double y[3]) {
  double d[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
  double len = norm3(d);
  if (s->axes == 1) {
    memcpy(y, s->axis, 3 * sizeof *y);
    return;
  }
  if (s->axes == 2) {
    double z[3];
    memcpy(z, s->axis, sizeof z);
    if (!(len > 0)) {
      y[0] = 0, y[1] = 1, y[2] = 0;
      return;
    }
    if (fabs(dot3(d, z)) > 0.95 * len) {
      int k = 0;
      for (int i = 1; i < 3; i++)
        if (fabs(s->axis[i]) < fabs(s->axis[k])) k = i;
      z[0] = z[1] = z[2] = 0;
      z[k] = 1;
    }
    double c[3] = {z[1] * d[2] - z[2] * d[1], z[2] * d[0] - z[0] * d[2], z[0] * d[1] - z[1] * d[0]};
    double n = norm3(c);
    for (int i = 0; i < 3; i++) y[i] = c[i] / n;
    return;
  }
  y[0] = 0, y[1] = 1, y[2] = 0;
  if (len > 0 && fabs(d[1]) > 0.9 * len) y[1] = 0, y[2] = 1;
}

/* named sections or materials: 'sections: {NAME: {...}}' */
typedef struct {
  int n;
  yaml_node_t **key;
  section_def *sec;
  material_def *mat;
} named_defs;

static void parse_named_defs(reader *r, mapping *m, const char *key, ir_beam_theory theory, named_defs *out) {
  memset(out, 0, sizeof *out);
  yaml_node_t *n = map_get(m, key);
  if (n == NULL) return;
  mapping dm;
  if (map_open(&dm, r, n, loc_of(n), "'%s' of %s", key, m->what)) {
    out->key = xcalloc((size_t)dm.npairs + 1, sizeof *out->key);
    if (key[0] == 's') out->sec = xcalloc((size_t)dm.npairs + 1, sizeof *out->sec);
    else out->mat = xcalloc((size_t)dm.npairs + 1, sizeof *out->mat);
    for (int i = 0; i < dm.npairs; i++) {
      yaml_node_t *k = map_key_node(&dm, i), *v = map_value_node(&dm, i);
      if (dm.handled[i]) continue; /* a duplicate, reported */
      if (k->type != YAML_SCALAR_NODE || !looks_like_name(k)) {
        error_at(r, loc_of(k), "'%s': a name starts with a letter or '_' (got %s)", key, show_node(r, k));
        continue;
      }
      char what[SHOWN_SIZE + 32];
      snprintf(what, sizeof what, "%s '%s'", key[0] == 's' ? "section" : "material", show_node(r, k));
      out->key[out->n] = k;
      if (out->sec) parse_section(r, v, what, theory, true, &out->sec[out->n]);
      else parse_material(r, v, what, &out->mat[out->n]);
      out->n++;
      dm.handled[i] = true;
    }
  }
  map_close(&dm);
}

static int find_named_def(const named_defs *d, const yaml_node_t *name) {
  for (int i = 0; i < d->n; i++)
    if (name->type == YAML_SCALAR_NODE && scalar_length(name) == scalar_length(d->key[i]) &&
        memcmp(scalar_text(name), scalar_text(d->key[i]), scalar_length(name)) == 0)
      return i;
  return -1;
}

static void free_named_defs(named_defs *d) {
  free(d->key);
  free(d->sec);
  free(d->mat);
}

/* 'node_names: {J1: 16, ...}': names of nodes (numbers < nnodes) */
static void parse_node_names(reader *r, mapping *m, ir_flex *fx) {
  yaml_node_t *n = map_get(m, "node_names");
  if (n == NULL) return;
  mapping nm;
  if (map_open(&nm, r, n, loc_of(n), "'node_names' of %s", m->what)) {
    fx->node_names = xcalloc((size_t)nm.npairs + 1, sizeof *fx->node_names);
    fx->node_name_index = xcalloc((size_t)nm.npairs + 1, sizeof *fx->node_name_index);
    for (int i = 0; i < nm.npairs; i++) {
      yaml_node_t *k = map_key_node(&nm, i), *v = map_value_node(&nm, i);
      if (nm.handled[i]) continue;
      nm.handled[i] = true;
      if (k->type != YAML_SCALAR_NODE || !looks_like_name(k)) {
        error_at(r, loc_of(k), "'node_names': a node's name starts with a letter or '_' (got %s)",
                 show_node(r, k));
        continue;
      }
      double v_num;
      char label[SHOWN_SIZE + 32];
      snprintf(label, sizeof label, "node '%s'", show_node(r, k));
      if (!to_number(r, v, label, &v_num)) continue;
      if (v_num != floor(v_num) || v_num < 0 || v_num >= fx->nnodes) {
        error_at(r, loc_of(v), "%s: node %g does not exist (nodes are numbered 0 to %d)", label, v_num,
                 fx->nnodes - 1);
        continue;
      }
      fx->node_names[fx->nnode_names] = xstrndup(scalar_text(k), scalar_length(k));
      fx->node_name_index[fx->nnode_names++] = (int)v_num;
    }
  }
  map_close(&nm);
}

/* a beam's section or material: the one it names (its index), -1: none
 * named (the default), -2: an unknown name (reported) */
static int beam_def(reader *r, mapping *bm, const char *key, const named_defs *named, const char *label) {
  yaml_node_t *n = map_get(bm, key);
  if (n == NULL) return -1;
  int k = find_named_def(named, n);
  if (k < 0) {
    name_list l;
    memset(&l, 0, sizeof l);
    for (int i = 0; i < named->n; i++) name_list_add(&l, scalar_text(named->key[i]));
    error_at(r, loc_of(n), "%s: no %s is named %s (%s%s)", label, key, show_node(r, n),
             l.count ? "expected one of: " : "there are no ", l.count ? l.text : key[0] == 's' ? "'sections'" : "'materials'");
    return -2;
  }
  return k;
}

/* An FE beam model from mapping m (a flexible body's keys, or a YAML FE
 * file's): nodes ('line' generator or 'nodes'), named nodes, beams with
 * their sections and materials, point masses.  Returns the node positions
 * (global), or NULL. */
static double *parse_fe_model(mapping *m, ir_flex *fx) {
  reader *r = m->r;
  double *global = NULL;
  yaml_node_t *line = map_get(m, "line"), *nodes = map_get(m, "nodes");
  ir_beam_theory theory = BEAM_EULER_BERNOULLI;
  int th = 0;
  if (get_choice(m, "theory", "beam theory", theory_names, false, &th)) theory = (ir_beam_theory)th;
  int mk = 0;
  if (get_choice(m, "mass", "mass matrix", mass_kind_names, false, &mk)) fx->mass = (ir_mass_kind)mk;
  if (line != NULL && nodes != NULL) {
    error_at(r, loc_of(nodes), "give either 'line' or 'nodes', not both");
    return NULL;
  }
  if (line == NULL && nodes == NULL) {
    error_at(r, m->loc, "%s needs an FE model ('line' or 'nodes' and 'beams')", m->what);
    return NULL;
  }
  /* the sections and materials: defaults and named ones */
  section_def dsec;
  material_def dmat;
  memset(&dsec, 0, sizeof dsec);
  memset(&dmat, 0, sizeof dmat);
  named_defs secs, mats;
  parse_named_defs(r, m, "sections", theory, &secs);
  parse_named_defs(r, m, "materials", theory, &mats);
  /* the defaults: a mapping, or the name of a named one */
  char label[200];
  snprintf(label, sizeof label, "the default of %s", m->what);
  yaml_node_t *n = map_get(m, "section");
  bool has_dsec = n != NULL, has_dmat;
  if (n && n->type == YAML_SCALAR_NODE) {
    int k = beam_def(r, m, "section", &secs, label);
    if (k >= 0) dsec = secs.sec[k];
  } else if (n) {
    char what[200];
    snprintf(what, sizeof what, "'section' of %s", m->what);
    parse_section(r, n, what, theory, true, &dsec);
  }
  n = map_get(m, "material");
  has_dmat = n != NULL;
  if (n && n->type == YAML_SCALAR_NODE) {
    int k = beam_def(r, m, "material", &mats, label);
    if (k >= 0) dmat = mats.mat[k];
  } else if (n) {
    char what[200];
    snprintf(what, sizeof what, "'material' of %s", m->what);
    parse_material(r, n, what, &dmat);
  }
  double dnsm = 0;
  get_nonnegative(m, "nonstructural_mass", false, &dnsm);

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
        int ne_ = (int)ne;
        fx->nnodes = ne_ + 1;
        global = xcalloc(3 * (size_t)(ne_ + 1), sizeof *global);
        fx->node_loc = xcalloc((size_t)ne_ + 1, sizeof *fx->node_loc);
        for (int k = 0; k <= ne_; k++) {
          for (int i = 0; i < 3; i++) global[3 * k + i] = p0[i] + (p1[i] - p0[i]) * k / ne_;
          fx->node_loc[k] = loc_of(line);
        }
        fx->nbeams = ne_;
        fx->beams = xcalloc((size_t)ne_, sizeof *fx->beams);
        for (int e = 0; e < ne_; e++) {
          fx->beams[e].node[0] = e;
          fx->beams[e].node[1] = e + 1;
          fx->beams[e].loc = loc_of(line);
        }
      }
    }
    map_close(&lm);
    map_reject(m, "beams", "'beams' does not go with 'line' (the line makes its own elements)");
  } else {
    int nn = nodes->type == YAML_SEQUENCE_NODE ? seq_length(nodes) : 0;
    if (nn < 2) {
      error_at(r, loc_of(nodes), "'nodes': expected a list of at least 2 points [x, y, z]");
    } else {
      fx->nnodes = nn;
      global = xcalloc(3 * (size_t)nn, sizeof *global);
      fx->node_loc = xcalloc((size_t)nn, sizeof *fx->node_loc);
      for (int k = 0; k < nn; k++) {
        char label[64];
        snprintf(label, sizeof label, "node %d", k);
        yaml_node_t *item = seq_item(r, nodes, k);
        to_vector(r, item, label, 3, global + 3 * k);
        fx->node_loc[k] = loc_of(item);
      }
    }
  }
  parse_node_names(r, m, fx);

  /* the beams: [i, j] or {nodes: [i, j], section, material, nonstructural_mass} */
  int *sec_of = NULL, *mat_of = NULL; /* per beam: the named one, -1 the default, -2 none */
  yaml_node_t *beams = map_get(m, "beams");
  if (nodes != NULL && global != NULL) {
    int nn = fx->nnodes;
    if (beams == NULL) { /* consecutive nodes */
      fx->nbeams = nn - 1;
      fx->beams = xcalloc((size_t)nn, sizeof *fx->beams);
      for (int e = 0; e < nn - 1; e++) {
        fx->beams[e].node[0] = e;
        fx->beams[e].node[1] = e + 1;
        fx->beams[e].loc = loc_of(nodes);
      }
    } else if (beams->type != YAML_SEQUENCE_NODE || seq_length(beams) < 1) {
      error_at(r, loc_of(beams), "'beams': expected a list of node pairs [i, j] or {nodes: [i, j], ...}");
    } else {
      int ne = seq_length(beams);
      fx->beams = xcalloc((size_t)ne, sizeof *fx->beams);
      sec_of = xcalloc((size_t)ne, sizeof *sec_of);
      mat_of = xcalloc((size_t)ne, sizeof *mat_of);
      for (int e = 0; e < ne; e++) {
        yaml_node_t *item = seq_item(r, beams, e), *pair_node = item;
        char label[64];
        snprintf(label, sizeof label, "beam %d", e + 1);
        ir_beam *bm = &fx->beams[fx->nbeams];
        bm->nsm = dnsm;
        int si = -1, mi = -1;
        mapping bmm;
        bool is_map = item->type == YAML_MAPPING_NODE;
        if (is_map) {
          if (!map_open(&bmm, r, item, loc_of(item), "%s of %s", label, m->what)) continue;
          static const char *const bkeys[] = {"nodes", "section", "material", "nonstructural_mass", NULL};
          map_check_keys(&bmm, bkeys);
          pair_node = map_require(&bmm, "nodes", true, "[i, j]");
          si = beam_def(r, &bmm, "section", &secs, label);
          mi = beam_def(r, &bmm, "material", &mats, label);
          get_nonnegative(&bmm, "nonstructural_mass", false, &bm->nsm);
        }
        if (pair_node != NULL) {
          int cnt = 0;
          int *pair = to_node_list(r, pair_node, label, fx, nn, &cnt);
          if (cnt == 2 && pair[0] != pair[1] && seq_length(pair_node) == 2) {
            bm->node[0] = pair[0];
            bm->node[1] = pair[1];
            bm->loc = loc_of(item);
            sec_of[fx->nbeams] = si;
            mat_of[fx->nbeams] = mi;
            fx->nbeams++;
          } else if (pair_node->type == YAML_SEQUENCE_NODE && cnt == seq_length(pair_node)) {
            error_at(r, loc_of(pair_node), "%s: expected two different nodes [i, j]", label);
          }
          free(pair);
        }
        if (is_map) map_close(&bmm);
      }
    }
  }
  /* the defaults are required when a beam names no section or material */
  bool default_sec = !sec_of && fx->nbeams > 0, default_mat = default_sec;
  for (int e = 0; sec_of && e < fx->nbeams; e++) {
    default_sec |= sec_of[e] == -1;
    default_mat |= mat_of[e] == -1;
  }
  if (default_sec && !has_dsec)
    map_require(m, "section", true, "a mapping {area, Iy, Iz, J, ...} or {shape, ...}, for the beams that name none");
  if (default_mat && !has_dmat)
    map_require(m, "material", true, "a mapping {E, nu or G, density}, for the beams that name none");
  /* the beams' properties and local axes */
  for (int e = 0; global && e < fx->nbeams; e++) {
    ir_beam *bm = &fx->beams[e];
    int si = sec_of ? sec_of[e] : -1, mi = mat_of ? mat_of[e] : -1;
    if (si == -2 || mi == -2) continue; /* reported */
    const section_def *sd = si >= 0 ? &secs.sec[si] : &dsec;
    const material_def *md = mi >= 0 ? &mats.mat[mi] : &dmat;
    bm->theory = theory;
    if (!sec_of) bm->nsm = dnsm;
    apply_section(bm, sd);
    apply_material(bm, md);
    section_yaxis(sd, global + 3 * bm->node[0], global + 3 * bm->node[1], bm->yaxis);
  }
  free(sec_of);
  free(mat_of);
  free_named_defs(&secs);
  free_named_defs(&mats);

  yaml_node_t *pm = map_get(m, "point_masses");
  if (pm != NULL && global != NULL) {
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
          p->loc = loc_of(item);
          yaml_node_t *nd = map_require(&pmm, "node", true, "a node number or name");
          if (nd != NULL) {
            char label[64];
            snprintf(label, sizeof label, "point mass %d", i + 1);
            double v = -1;
            if (looks_like_name(nd)) {
              int k = named_node(r, nd, fx, label);
              p->node = k < 0 ? 0 : k;
            } else if (to_number(r, nd, label, &v)) {
              if (v != floor(v) || v < 0 || v >= fx->nnodes)
                error_at(r, loc_of(nd), "node %g does not exist (nodes are numbered 0 to %d)", v, fx->nnodes - 1);
              else
                p->node = (int)v;
            }
          }
          get_nonnegative(&pmm, "mass", true, &p->mass);
          yaml_node_t *in = map_get(&pmm, "inertia");
          if (in != NULL) parse_inertia(r, in, p->inertia);
          fx->npoint_masses++;
        }
        map_close(&pmm);
      }
    }
  }
  return global;
}

void parse_flexible_body(mapping *m, ir_body *b, ir_loc type_loc) {
  reader *r = m->r;
  (void)type_loc;
  static const char *const keys[] = {
      "type",    "position",  "orientation", "velocity", "angular_velocity", "line",
      "nodes",   "beams",     "section",     "material", "theory",           "mass",
      "point_masses", "reference", "interface", "modes", "damping", "coupling", "modal_file",
      "fe_file", "initial_modes", "initial_mode_rates", "eigensolver", "sections", "materials",
      "nonstructural_mass", "node_names", "residual_modes", "geometric_stiffening", NULL};
  map_reject(m, "inertia", "flexible body '%s': its inertia comes from its FE model", b->name);
  map_check_keys(m, keys);
  ir_flex *fx = xcalloc(1, sizeof *fx);
  b->flex = fx;
  fx->loc = b->loc;
  fx->select = MODES_ALL;
  fx->coupling = COUPLING_FULL;
  fx->damping = DAMPING_BANDS; /* seed 001 section 2.6: the three-band default */
  {
    static const char *const flag_names[] = {"false", "true", NULL};
    int on = 0;
    yaml_node_t *gs = map_get(m, "geometric_stiffening");
    if (gs != NULL) fx->stiffening_loc = loc_of(gs);
    if (get_choice(m, "geometric_stiffening", "geometric_stiffening setting", flag_names, false, &on))
      fx->geometric_stiffening = on == 1;
  }
  yaml_node_t *orientation = map_get(m, "orientation");
  if (orientation != NULL) parse_orientation(r, orientation, m->what, b->orientation);
  get_vector(m, "velocity", 3, false, b->velocity);
  get_vector(m, "angular_velocity", 3, false, b->angular_velocity);
  yaml_node_t *modal_file = map_get(m, "modal_file");
  yaml_node_t *line = map_get(m, "line"), *nodes = map_get(m, "nodes");
  double *global = NULL; /* node positions, global */
  if (modal_file != NULL) {
    static const char *const fe_only[] = {"line", "nodes", "beams", "section", "material",
                                          "theory", "mass", "point_masses", "interface", "sections",
                                          "materials", "nonstructural_mass", "node_names", "residual_modes", NULL};
    for (int i = 0; fe_only[i]; i++)
      map_reject(m, fe_only[i], "flexible body '%s': '%s' does not go with 'modal_file'", b->name, fe_only[i]);
    if (modal_file->type != YAML_SCALAR_NODE)
      error_at(r, loc_of(modal_file), "'modal_file' must be a file name (got %s)", show_node(r, modal_file));
    else
      read_modal_file(r, modal_file, b, fx);
  } else if (map_get(m, "fe_file") != NULL) {
    global = parse_fe_file(m, b, fx);
  } else if (line != NULL && nodes != NULL) {
    error_at(r, loc_of(nodes), "give either 'line' or 'nodes', not both");
  } else if (line == NULL && nodes == NULL) {
    error_at(r, m->loc, "flexible body '%s' needs an FE model ('line' or 'nodes' and 'beams') or a 'modal_file'", b->name);
  } else {
    global = parse_fe_model(m, fx);
  }

  /* reference conditions and Craig-Bampton interface */
  int nn = modal_file ? -1 : fx->nnodes;
  yaml_node_t *ref = map_get(m, "reference");
  if (map_get(m, "fe_file") && !global) { /* the import failed (reported): nothing to refer to */
    map_get(m, "interface");
    map_get(m, "residual_modes");
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
  yaml_node_t *res = map_get(m, "residual_modes");
  if (res != NULL) fx->residual = to_flex_node_list(r, res, "'residual_modes'", fx, nn, &fx->nresidual);

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
void fe_node_global(const ir_body *b, int k, double out[3]) {
  double A[9];
  quaternion_to_matrix(b->orientation, A);
  const double *x = b->flex->nodes + 3 * k;
  for (int i = 0; i < 3; i++) out[i] = b->position[i] + A[3 * i] * x[0] + A[3 * i + 1] * x[1] + A[3 * i + 2] * x[2];
}
