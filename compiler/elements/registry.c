/* registry.c: the one table of element descriptors.  A new force element
 * is one line here (and its file in this folder). */
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
