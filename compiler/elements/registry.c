/* registry.c: the tables of element descriptors (forces, joints, drivers,
 * outputs).  A new force element, joint kind or output kind is one line
 * here (and its file in this folder). */
#include "element.h"

/* the families, one file each */
extern const element_desc element_point_force, element_point_torque;    /* force_point.c */
extern const element_desc element_spring_damper;                        /* force_spring.c */
extern const element_desc element_bushing, element_field, element_beam; /* force_field.c */
extern const element_desc element_superelement;                         /* force_field.c */
extern const element_desc element_tyre;                                 /* force_tyre.c */

const element_desc *const force_elements[] = {
    &element_point_force, &element_point_torque, &element_spring_damper,
    &element_bushing,     &element_field,        &element_beam,
    &element_tyre,        &element_superelement, NULL,
};

enum { NFORCE_ELEMENTS = sizeof force_elements / sizeof *force_elements - 1 };
_Static_assert(NFORCE_ELEMENTS == FORCE_SUPERELEMENT + 1, "one descriptor per ir_force_kind");

const element_desc *force_element(ir_force_kind kind) {
  for (int i = 0; force_elements[i]; i++)
    if (force_elements[i]->ir_kind == kind) return force_elements[i];
  return NULL;
}

const char *const *force_type_names(void) {
  static const char *names[NFORCE_ELEMENTS + 1];
  if (!names[0])
    for (int i = 0; i < NFORCE_ELEMENTS; i++) names[i] = force_elements[i]->type;
  return names;
}

/* --- joints: one descriptor per ir_joint_kind, in its order -------------- */
extern const joint_desc element_spherical, element_revolute, element_cylindrical, element_prismatic,
    element_fixed;                                     /* joint_axis.c */
extern const joint_desc element_universal;             /* joint_universal.c */
extern const joint_desc element_distance;              /* joint_distance.c */

const joint_desc *const joint_elements[] = {
    &element_spherical, &element_revolute, &element_cylindrical, &element_prismatic,
    &element_universal, &element_fixed,    &element_distance,    NULL,
};

enum { NJOINT_ELEMENTS = sizeof joint_elements / sizeof *joint_elements - 1 };
_Static_assert(NJOINT_ELEMENTS == JOINT_DISTANCE + 1, "one descriptor per ir_joint_kind");

const joint_desc *joint_element(ir_joint_kind kind) {
  for (int i = 0; joint_elements[i]; i++)
    if (joint_elements[i]->ir_kind == kind) return joint_elements[i];
  return NULL;
}

const char *const *joint_type_names(void) {
  static const char *names[NJOINT_ELEMENTS + 1];
  if (!names[0])
    for (int i = 0; i < NJOINT_ELEMENTS; i++) names[i] = joint_elements[i]->type;
  return names;
}

/* --- outputs: one descriptor per ir_output_kind, in its order ------------ */
extern const output_desc element_out_position, element_out_orientation, element_out_angle,
    element_out_velocity, element_out_angular_velocity, element_out_acceleration,
    element_out_angular_acceleration, element_out_relative;            /* output_motion.c */
extern const output_desc element_out_reaction, element_out_effort, element_out_joint,
    element_out_force, element_out_tyre;                               /* output_element.c */
extern const output_desc element_out_kinetic_energy, element_out_potential_energy,
    element_out_total_energy, element_out_momentum, element_out_center_of_mass; /* output_system.c */
extern const output_desc element_out_deflection, element_out_modal, element_out_section; /* output_flex.c */

const output_desc *const output_elements[] = {
    &element_out_position,       &element_out_orientation,       &element_out_angle,
    &element_out_velocity,       &element_out_angular_velocity,  &element_out_acceleration,
    &element_out_angular_acceleration, &element_out_reaction,    &element_out_effort,
    &element_out_kinetic_energy, &element_out_potential_energy,  &element_out_total_energy,
    &element_out_deflection,     &element_out_modal,             &element_out_momentum,
    &element_out_section,        &element_out_force,             &element_out_relative,
    &element_out_joint,          &element_out_center_of_mass,    &element_out_tyre,
    NULL,
};

enum { NOUTPUT_ELEMENTS = sizeof output_elements / sizeof *output_elements - 1 };
_Static_assert(NOUTPUT_ELEMENTS == OUT_TYRE + 1, "one descriptor per ir_output_kind");

const output_desc *output_element(ir_output_kind kind) {
  for (int i = 0; output_elements[i]; i++)
    if (output_elements[i]->ir_kind == kind) return output_elements[i];
  return NULL;
}

const char *const *output_type_names(void) {
  static const char *names[NOUTPUT_ELEMENTS + 1];
  if (!names[0])
    for (int i = 0; i < NOUTPUT_ELEMENTS; i++) names[i] = output_elements[i]->type;
  return names;
}

int output_columns(const ir_model *ir, const ir_output *o) {
  const output_desc *e = output_element(o->kind);
  if (e->count_columns) return e->count_columns(ir, o);
  if (o->component >= 0 || o->has_fiber || !e->columns) return 1;
  int n = 0;
  while (e->columns[n]) n++;
  return n;
}
