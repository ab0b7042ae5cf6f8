/* force_point.c: the point force and the point torque (one body, one marker;
 * kernel runtime/core/elements/mb_force_point.h). */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "element.h"
#include "emit_force.h"
#include "reader.h"

static const char *const frame_names[] = {"global", "body", NULL};

static void parse_point_load(mapping *m, ir_force *f) {
  reader *r = m->r;
  bool is_force = f->kind == FORCE_POINT_FORCE;
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
    snprintf(label, sizeof label, "'scale' of %s '%s'", force_element(f->kind)->type, f->name);
    parse_profile(r, scale, label, &f->scale);
  }
}

static void lower_point_load(lmodel *L, const ir_force *F, int index, mb_forcedef *d) {
  static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  d->m0 = lower_force_marker(L, F, 0, I3);
  double *prm = lower_force_prm(L, d, MB_POINT_NPRM);
  if (!prm) return; /* out of memory (lower_force_prm) */
  memcpy(prm + MB_POINT_VEC, F->vector, 3 * sizeof *prm);
  d->local = F->frame == FRAME_BODY;
  if (F->scale.kind != PROFILE_NONE) d->profile = lower_add_profile(L, &F->scale, -1, index);
}

/* the vector as literals (scaled by the profile), turned by the body when local */
static int emit_point_load(FILE *f, const lmodel *L, int k) {
  const mb_forcedef *d = &L->force[k];
  int b0 = L->marker[d->m0].body;
  if (b0 < 0) { fputs("    /* on the ground: no effect */\n", f); return 0; }
  fputs("    mb_real s = 1, val[3];\n", f);
  if (d->profile >= 0) fprintf(f, "    mb_profile_eval(&profiles[%d], t, x);\n    s = x[0];\n", d->profile);
  for (int j = 0; j < 3; j++) {
    fprintf(f, "    val[%d] = s * ", j);
    int slot = d->padr + MB_POINT_VEC + j;
    if (L->prm_runtime && L->prm_runtime[slot]) fprintf(f, "force_prm[%d]", slot); /* a run-time parameter */
    else emit_num(f, L->force_prm[slot]);
    fputs(";\n", f);
  }
  if (d->local) fprintf(f, "    mb_mul3(f%d.A, val, val);\n", b0);
  char P[32];
  snprintf(P, sizeof P, "k%d.P", d->m0);
  int n = emit_cols(f, L, d->m0, P, d->kind == MB_FORCE_POINT ? "val" : "zero3",
                    d->kind == MB_FORCE_POINT ? "zero3" : "val", "    ");
  if (n < 0) return -1;
  emit_add_cols(f, L->body[b0].vadr, n);
  return 0;
}

static const char *const force_keys[] = {"type",  "body",  "point", "value",
                                         "frame", "scale", "node", NULL};
static const char *const torque_keys[] = {"type", "body", "value", "frame", "scale", "node", NULL};

const element_desc element_point_force = {
    .family = ELEMENT_FORCE, .type = "force", .ir_kind = FORCE_POINT_FORCE,
    ELEMENT_RUNTIME_KIND(MB_FORCE_POINT), .keys = force_keys, .prm_layout = "force vector",
    .parse = parse_point_load, .lower = lower_point_load, .emit_eval = emit_point_load};

const element_desc element_point_torque = {
    .family = ELEMENT_FORCE, .type = "torque", .ir_kind = FORCE_POINT_TORQUE,
    ELEMENT_RUNTIME_KIND(MB_FORCE_TORQUE), .keys = torque_keys, .prm_layout = "torque vector",
    .parse = parse_point_load, .lower = lower_point_load, .emit_eval = emit_point_load};
