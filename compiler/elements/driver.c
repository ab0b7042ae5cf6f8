/* driver.c: the driver: the rotation about or translation along a joint's
 * axis follows a time function (one row, runtime MB_PRIM_ROT or
 * MB_PRIM_TRANS; its reaction is the effort). */
#include <stdio.h>

#include "element.h"
#include "reader.h"

static const char *const dof_names[] = {"rotation", "translation", NULL};

static void parse_driver(mapping *m, ir_driver *d) {
  reader *r = m->r;
  ir_model *model = r->model;
  ir_loc joint_loc = d->loc;
  get_ref(m, "joint", NAME_JOINT, true, &d->joint, &joint_loc);
  int dof = -1;
  bool dof_given = map_has(m, "dof");
  bool dof_valid = get_choice(m, "dof", "dof", dof_names, false, &dof);
  ir_loc dof_loc = m->last_loc;
  if (d->joint >= 0) {
    const ir_joint *j = &model->joints[d->joint];
    const joint_desc *jd = joint_element(j->kind);
    bool rotates = jd->free_dofs & JOINT_FREE_ROTATION;
    bool slides = jd->free_dofs & JOINT_FREE_TRANSLATION;
    if (!rotates && !slides) {
      error_at(r, joint_loc,
               "%s joint '%s' cannot be driven (a driver needs a revolute, prismatic or "
               "cylindrical joint)",
               jd->type, j->name);
    } else if (dof_valid) {
      if ((dof == DRIVER_ROTATION && !rotates) || (dof == DRIVER_TRANSLATION && !slides))
        error_at(r, dof_loc, "%s joint '%s' has no %s dof (expected 'dof: %s')",
                 jd->type, j->name, dof_names[dof], dof_names[1 - dof]);
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
  yaml_node_t *motion = map_require(m, "motion", true, "a profile such as {type: constant, value: 0}");
  if (motion != NULL) {
    char label[SHOWN_SIZE];
    snprintf(label, sizeof label, "'motion' of driver '%s'", d->name);
    parse_profile(r, motion, label, &d->motion);
  }
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

/* the row between the joint's markers, about/along marker 0's z */
static int lower_driver(lmodel *L, int index, const int *jm0, const int *jm1) {
  const ir_driver *D = &L->ir->drivers[index];
  int p = lower_add_profile(L, &D->motion, index, -1);
  if (p < 0) return -1;
  int rot = D->dof == DRIVER_ROTATION;
  lower_add_row(L, rot ? MB_PRIM_ROT : MB_PRIM_TRANS, jm0[D->joint], jm1[D->joint], 2, 0,
                rot ? "rotation about the joint axis follows the motion"
                    : "translation along the joint axis follows the motion",
                -1, index, D->loc, D->name, "driver");
  L->row[L->m.nrow - 1].profile = p;
  return 0;
}

static const char *const driver_keys[] = {"joint", "dof", "motion", NULL};

const driver_desc element_driver = {
    .family = ELEMENT_DRIVER, .keys = driver_keys, .parse = parse_driver, .check = check_drivers,
    .lower = lower_driver};
