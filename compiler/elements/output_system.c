/* output_system.c: the outputs of the whole system (or a subset of its
 * bodies): kinetic, potential and total energy, momentum, centre of mass
 * (kernel: mb_model_outputs, runtime/core/model_generic.c). */
#include <stdio.h>
#include <stdlib.h>

#include "diag.h"
#include "element.h"
#include "reader.h"

/* --- centre of mass ------------------------------------------------------- */

static void parse_center_of_mass(mapping *m, ir_output *o) {
  static const char *const cm_quantity_names[] = {"position", "velocity", "acceleration", NULL};
  static const char *const component_names[] = {"x", "y", "z", NULL};
  reader *r = m->r;
  int choice = 0;
  if (get_choice(m, "quantity", "quantity", cm_quantity_names, false, &choice))
    o->quantity = (ir_quantity)choice;
  get_choice(m, "component", "component", component_names, false, &o->component);
  yaml_node_t *list = map_get(m, "bodies");
  if (list == NULL) return;
  int n = list->type == YAML_SEQUENCE_NODE ? seq_length(list) : 0;
  if (n == 0) {
    error_at(r, loc_of(list), "'bodies' must be a list of body names (got %s)", show_node(r, list));
    return;
  }
  o->cm_bodies = xcalloc((size_t)n, sizeof *o->cm_bodies);
  for (int i = 0; i < n; i++) {
    yaml_node_t *item = seq_item(r, list, i);
    int b = resolve_name(r, item, NAME_BODY, "bodies");
    if (b == 0) error_at(r, loc_of(item), "'bodies': the ground has no centre of mass");
    for (int j = 0; j < o->ncm_bodies && b > 0; j++)
      if (o->cm_bodies[j] == b) error_at(r, loc_of(item), "'bodies': '%s' is listed twice", r->model->bodies[b].name);
    if (b > 0) o->cm_bodies[o->ncm_bodies++] = b;
  }
}

/* the subset's weights (1: in it) in output_coef; the total mass must be positive */
static int lower_center_of_mass(lmodel *L, const ir_output *o, const int *jm0, const int *jm1,
                                mb_outputdef *d) {
  (void)jm0, (void)jm1;
  mb_model *m = &L->m;
  output_measure_init(d, o);
  double total = 0;
  d->node = -1;
  if (o->cm_bodies) { /* the subset's weights in output_coef */
    double *c = realloc(L->output_coef, sizeof(double) * (size_t)(L->noutput_coef + m->nbody + 1));
    if (!c) return -1;
    L->output_coef = c;
    d->node = L->noutput_coef;
    for (int b = 0; b < m->nbody; b++) c[d->node + b] = 0;
    for (int i = 0; i < o->ncm_bodies; i++) c[d->node + o->cm_bodies[i] - 1] = 1;
    L->noutput_coef += m->nbody;
  }
  for (int b = 0; b < m->nbody; b++)
    if (d->node < 0 || L->output_coef[d->node + b] != 0)
      total += L->body[b].kind == MB_BODY_FLEXIBLE ? L->body[b].flex->mass : L->body[b].mass;
  if (!(total > 0)) {
    diag_error(L->ir->path, o->loc, "output '%s': the bodies have no mass", o->name);
    return -1;
  }
  return 0;
}

/* --- the descriptors -------------------------------------------------------- */

static const char *const system_keys[] = {"name", "type", "scale", NULL};
static const char *const cm_keys[] = {"name", "type", "quantity", "bodies", "component", "scale", NULL};
static const char *const momentum_columns[] = {"px", "py", "pz", "hx", "hy", "hz", NULL};
static const char *const xyz[] = {"x", "y", "z", NULL};

const output_desc element_out_kinetic_energy = {
    .family = ELEMENT_OUTPUT, .type = "kinetic_energy", .ir_kind = OUT_KINETIC_ENERGY,
    OUTPUT_RUNTIME_KIND(MB_OUT_KINETIC_ENERGY), .keys = system_keys};
const output_desc element_out_potential_energy = {
    .family = ELEMENT_OUTPUT, .type = "potential_energy", .ir_kind = OUT_POTENTIAL_ENERGY,
    OUTPUT_RUNTIME_KIND(MB_OUT_POTENTIAL_ENERGY), .keys = system_keys};
const output_desc element_out_total_energy = {
    .family = ELEMENT_OUTPUT, .type = "total_energy", .ir_kind = OUT_TOTAL_ENERGY,
    OUTPUT_RUNTIME_KIND(MB_OUT_TOTAL_ENERGY), .keys = system_keys};
const output_desc element_out_momentum = {
    .family = ELEMENT_OUTPUT, .type = "momentum", .ir_kind = OUT_MOMENTUM,
    OUTPUT_RUNTIME_KIND(MB_OUT_MOMENTUM), .keys = system_keys, .columns = momentum_columns};
const output_desc element_out_center_of_mass = {
    .family = ELEMENT_OUTPUT, .type = "center_of_mass", .ir_kind = OUT_CENTER_OF_MASS,
    OUTPUT_RUNTIME_KIND(MB_OUT_CENTER_OF_MASS), .keys = cm_keys, .columns = xyz,
    .parse = parse_center_of_mass, .lower = lower_center_of_mass};
