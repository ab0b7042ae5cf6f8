/* force_spring.c: the spring-damper along the line between two points, with
 * linear, power or table laws (kernel runtime/core/elements/mb_spring.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "element.h"
#include "emit_force.h"
#include "reader.h"
#include "params.h"

/* A number (linear), {coefficient, exponent} (power) or {table: ...}. */
static void parse_law(reader *r, yaml_node_t *n, const char *key, const char *owner, ir_law *law) {
  law->loc = loc_of(n);
  char label[64];
  quote_key(label, sizeof label, key);
  if (n->type == YAML_SCALAR_NODE) {
    double coef;
    if (!to_number(r, n, label, &coef))
      return;
    params_note_rule(r, loc_of(n), RULE_NONNEGATIVE, label);
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

static void parse_spring_damper(mapping *m, ir_force *f) {
  reader *r = m->r;
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

static void lower_spring_damper(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  (void)index;
  d->m0 = lower_force_marker(L, F, 0, I3);
  d->m1 = lower_force_marker(L, F, 1, I3);
  double *prm = lower_force_prm(L, d, MB_SPRING_NPRM);
  if (!prm) return; /* out of memory (lower_force_prm) */
  mb_law *law = lower_force_laws(L, d, MB_SPRING_NLAW);
  const ir_law *laws[MB_SPRING_NLAW] = {[MB_SPRING_STIFFNESS] = &F->stiffness,
                                        [MB_SPRING_DAMPING] = &F->damping};
  for (int l = 0; l < MB_SPRING_NLAW; l++) {
    law[l].kind = (mb_law_kind)laws[l]->kind; /* the enumerations agree (lower.c) */
    law[l].coef = laws[l]->coef;
    law[l].exponent = laws[l]->exponent;
    law[l].ntable = laws[l]->ntable;
    law[l].table = laws[l]->table; /* owned by the IR, which outlives L */
  }
  prm[MB_SPRING_L0] = F->free_length;
  prm[MB_SPRING_PRELOAD] = F->preload;
}

static int emit_spring_damper(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  int b0 = L->marker[d->m0].body, b1 = L->marker[d->m1].body;
  fprintf(f, "    mb_real F0[3], F1[3];\n"
             "    mb_spring(&k%d, &k%d, force_prm + %d, force_laws + %d, F0, F1, 0);\n",
          d->m0, d->m1, d->padr, d->ladr);
  if (b0 >= 0) {
    char P[32];
    snprintf(P, sizeof P, "k%d.P", d->m0);
    int n = emit_cols(f, L, d->m0, P, "F0", "zero3", "    ");
    if (n < 0) return -1;
    emit_add_cols(f, L->body[b0].vadr, n);
  }
  if (b1 >= 0) {
    char P[32];
    snprintf(P, sizeof P, "k%d.P", d->m1);
    int n = emit_cols(f, L, d->m1, P, "F1", "zero3", "    ");
    if (n < 0) return -1;
    emit_add_cols(f, L->body[b1].vadr, n);
  }
  return 0;
}

static const char *const spring_keys[] = {"type",    "bodies",      "points",  "stiffness",
                                          "damping", "free_length", "preload", "node", "nodes", NULL};

static const char *const law_names[] = {[MB_SPRING_STIFFNESS] = "stiffness",
                                        [MB_SPRING_DAMPING] = "damping", NULL};

const element_desc element_spring_damper = {
    .family = ELEMENT_FORCE, .type = "spring_damper", .ir_kind = FORCE_SPRING_DAMPER,
    ELEMENT_RUNTIME_KIND(MB_FORCE_SPRING), .keys = spring_keys, .prm_layout = "free length, preload",
    .law_names = law_names,
    .parse = parse_spring_damper, .lower = lower_spring_damper, .emit_eval = emit_spring_damper};
