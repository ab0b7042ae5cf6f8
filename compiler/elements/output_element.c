/* output_element.c: the outputs that measure a joint, driver or force
 * element: a joint's reaction, a driver's effort, a joint's angle and
 * travel, a force element's force, a tyre's forces and slips (kernel:
 * mb_model_outputs, runtime/core/model_generic.c). */
#include <stdio.h>
#include <string.h>

#include "diag.h"
#include "element.h"
#include "reader.h"

/* The measuring kinds (force, relative, joint, center_of_mass) carry the
   quantity as the runtime's number. */
_Static_assert((int)QUANTITY_POSITION == MB_QUANTITY_POSITION &&
                   (int)QUANTITY_VELOCITY == MB_QUANTITY_VELOCITY &&
                   (int)QUANTITY_ACCELERATION == MB_QUANTITY_ACCELERATION,
               "ir_quantity and MB_QUANTITY_* differ");

void output_measure_init(mb_outputdef *d, const ir_output *o) {
  d->frame = d->body2 = d->node2 = d->element = -1;
  d->jmarker[0] = d->jmarker[1] = -1;
  d->quantity = (int)o->quantity;
}

/* --- reaction, effort ---------------------------------------------------- */

static void parse_reaction(mapping *m, ir_output *o) {
  get_ref(m, "joint", NAME_JOINT, true, &o->joint, NULL);
}

static int lower_reaction(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)L, (void)jm0;
  d->reaction_marker = jm1[o->joint];
  return 0;
}

static void parse_effort(mapping *m, ir_output *o) {
  get_ref(m, "driver", NAME_DRIVER, true, &o->driver, NULL);
}

static int lower_effort(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d) {
  (void)jm1;
  const ir_driver *D = &L->ir->drivers[o->driver];
  d->driver_marker = jm0[D->joint];
  d->driver_rotation = D->dof == DRIVER_ROTATION;
  for (int r = 0; r < L->m.nrow; r++)
    if (L->row[r].driver == o->driver) d->driver_row = r;
  return 0;
}

/* --- joint: angle and/or travel ---------------------------------------- */

static void parse_joint_motion(mapping *m, ir_output *o) {
  reader *r = m->r;
  if (get_ref(m, "joint", NAME_JOINT, true, &o->joint, NULL)) {
    if (!joint_element(r->model->joints[o->joint].kind)->free_dofs)
      error_at(r, m->last_loc, "joint output '%s' needs a revolute, prismatic or cylindrical joint ('%s' is not)",
               o->name ? o->name : "?", r->model->joints[o->joint].name);
  }
}

/* one column for each free dof of the joint */
static int joint_motion_columns(const ir_model *ir, const ir_output *o) {
  return o->joint >= 0 && joint_element(ir->joints[o->joint].kind)->free_dofs ==
                              (JOINT_FREE_ROTATION | JOINT_FREE_TRANSLATION) ? 2 : 1;
}

static int lower_joint_motion(lmodel *L, const ir_output *o, const int *jm0, const int *jm1,
                              mb_outputdef *d) {
  const ir_joint *J = &L->ir->joints[o->joint];
  output_measure_init(d, o);
  if (jm0[o->joint] < 0) {
    diag_error(L->ir->path, o->loc, "output '%s': joint '%s' is not active", o->name, J->name);
    return -1;
  }
  d->jmarker[0] = jm0[o->joint];
  d->jmarker[1] = jm1[o->joint];
  d->joint_dofs = (int)joint_element(J->kind)->free_dofs;
  return 0;
}

/* --- force element ------------------------------------------------------ */

static const char *const force_components[] = {"fx", "fy", "fz", "tx", "ty", "tz", "tension", NULL};

static void parse_force_output(mapping *m, ir_output *o) {
  reader *r = m->r;
  get_ref(m, "element", NAME_FORCE, true, &o->force, NULL);
  get_choice(m, "component", "component", force_components, false, &o->component);
  if (o->component == 6 && o->force >= 0 && r->model->forces[o->force].kind != FORCE_SPRING_DAMPER)
    error_at(r, m->last_loc, "component 'tension' needs a spring_damper ('%s' is not)",
             r->model->forces[o->force].name);
}

static int lower_force_output(lmodel *L, const ir_output *o, const int *jm0, const int *jm1,
                              mb_outputdef *d) {
  (void)jm0, (void)jm1;
  output_measure_init(d, o);
  for (int k = 0; k < L->m.nforce; k++)
    if (L->force_ir[k] == o->force) d->element = k;
  if (d->element < 0) {
    diag_error(L->ir->path, o->loc, "output '%s': force '%s' is not active", o->name,
               L->ir->forces[o->force].name);
    return -1;
  }
  return 0;
}

/* --- tyre ---------------------------------------------------------------- */

/* the columns of a tyre output, in the order of mb_model_outputs */
const char *const tyre_component_names[] = {"Fx", "Fy", "Fz", "Mx", "My", "Mz", "slip",
                                            "slip_angle", "camber", "deflection", NULL};

static void parse_tyre_output(mapping *m, ir_output *o) {
  reader *r = m->r;
  o->force = -1;
  if (get_ref(m, "element", NAME_FORCE, true, &o->force, NULL) &&
      r->model->forces[o->force].kind != FORCE_TYRE) {
    error_at(r, m->last_loc, "tyre output '%s': force '%s' is not a tyre", o->name ? o->name : "?",
             r->model->forces[o->force].name);
    o->force = -1;
  }
  get_choice(m, "component", "tyre component", tyre_component_names, false, &o->component);
}

/* joint: the lowered force record */
static int lower_tyre_output(lmodel *L, const ir_output *o, const int *jm0, const int *jm1,
                             mb_outputdef *d) {
  (void)jm0, (void)jm1;
  d->joint = -1;
  for (int e = 0; e < L->m.nforce; e++)
    if (L->force_ir[e] == o->force) d->joint = e;
  if (d->joint < 0) {
    diag_error(L->ir->path, o->loc, "output '%s': tyre '%s' is switched off in this scene", o->name,
               L->ir->forces[o->force].name);
    return -1;
  }
  return 0;
}

/* --- the descriptors -------------------------------------------------------- */

static const char *const reaction_keys[] = {"name", "type", "joint", "scale", NULL};
static const char *const effort_keys[] = {"name", "type", "driver", "scale", NULL};
static const char *const joint_keys[] = {"name", "type", "joint", "scale", NULL};
static const char *const force_keys[] = {"name", "type", "element", "component", "scale", NULL};
static const char *const tyre_keys[] = {"name", "type", "element", "component", "scale", NULL};
static const char *const wrench[] = {"fx", "fy", "fz", "tx", "ty", "tz", NULL};
static const char *const joint_columns[] = {"angle", "travel", NULL};

const output_desc element_out_reaction = {
    .family = ELEMENT_OUTPUT, .type = "reaction", .ir_kind = OUT_REACTION,
    OUTPUT_RUNTIME_KIND(MB_OUT_REACTION), .keys = reaction_keys, .columns = wrench,
    .parse = parse_reaction, .lower = lower_reaction};
const output_desc element_out_effort = {
    .family = ELEMENT_OUTPUT, .type = "effort", .ir_kind = OUT_EFFORT,
    OUTPUT_RUNTIME_KIND(MB_OUT_EFFORT), .keys = effort_keys, .parse = parse_effort,
    .lower = lower_effort};
const output_desc element_out_joint = {
    .family = ELEMENT_OUTPUT, .type = "joint", .ir_kind = OUT_JOINT,
    OUTPUT_RUNTIME_KIND(MB_OUT_JOINT), .keys = joint_keys, .columns = joint_columns,
    .parse = parse_joint_motion, .count_columns = joint_motion_columns, .lower = lower_joint_motion};
const output_desc element_out_force = {
    .family = ELEMENT_OUTPUT, .type = "force", .ir_kind = OUT_FORCE,
    OUTPUT_RUNTIME_KIND(MB_OUT_FORCE), .keys = force_keys, .columns = wrench,
    .parse = parse_force_output, .lower = lower_force_output};
const output_desc element_out_tyre = {
    .family = ELEMENT_OUTPUT, .type = "tyre", .ir_kind = OUT_TYRE,
    OUTPUT_RUNTIME_KIND(MB_OUT_TYRE), .keys = tyre_keys, .columns = tyre_component_names,
    .parse = parse_tyre_output, .lower = lower_tyre_output};
