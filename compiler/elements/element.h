/* element.h: an element family as one unit.  A descriptor names everything
 * the compiler does with one YAML element type: its keys, how it is parsed
 * and validated (front), how it is lowered to a runtime record and its
 * parameter pool (lower), and, optionally, how its evaluation is emitted
 * (back).  Forces, joints, drivers and outputs each have a descriptor type
 * below; registry.c holds the tables; the reader, the lowering and the
 * emitter dispatch through them, so adding a force element is its own file
 * here, its kernel in runtime/core/elements/, and one line in registry.c
 * (docs/architecture.md walks through it). */
#ifndef MBCC_ELEMENT_H
#define MBCC_ELEMENT_H

#include <stdio.h>

#include "ir.h"
#include "lower.h"
#include "yaml_map.h"

typedef enum { ELEMENT_FORCE, ELEMENT_JOINT, ELEMENT_DRIVER, ELEMENT_OUTPUT } element_family;

/* the runtime kind and its enumerator's name, in a descriptor's initializer */
#define ELEMENT_RUNTIME_KIND(k) .runtime_kind = k, .runtime_kind_name = #k

typedef struct element_desc {
  element_family family;
  const char *type;            /* the YAML 'type' value */
  ir_force_kind ir_kind;       /* the IR record's kind */
  mb_force_kind runtime_kind;  /* the runtime record's kind (runtime/core/mb_model.h) */
  const char *runtime_kind_name; /* its enumerator, for the emitted tables */
  const char *const *keys;     /* accepted keys, NULL-terminated: any other is an error */
  const char *prm_layout;      /* its force_prm reals, for the emitted table's comment */
  const char *const *law_names; /* its force laws in order (NULL: none), for the comments */
  /* front: fill f from its mapping (the keys were checked, f->kind is set) */
  void (*parse)(mapping *m, ir_force *f);
  /* lower: markers, record d (kind, markers, pool addresses) and its pools */
  void (*lower)(lmodel *L, const ir_force *F, int index, mb_forcedef *d);
  /* back: the statements of force k inside the emitted eval (its block's
     braces and comment are the emitter's), adding into rhs; 0, or -1 when
     memory ran out (emit_cols < 0; the output is discarded) */
  int (*emit_eval)(FILE *f, const lmodel *L, int k);
} element_desc;

/* --- joints (joint.c: what the kinds share; joint_*.c: the kinds) -------- */

/* what a joint leaves free about and along its axis (drivers and joint
   outputs act on these); the bits are the runtime's joint_dofs (mb_outputdef) */
enum { JOINT_FREE_ROTATION = 1, JOINT_FREE_TRANSLATION = 2 };

typedef struct joint_desc {
  element_family family;
  const char *type;            /* the YAML 'type' value */
  ir_joint_kind ir_kind;
  const char *const *keys;     /* accepted keys, NULL-terminated */
  unsigned free_dofs;          /* JOINT_FREE_* bits */
  bool cross_axes;             /* the side-1 marker's z is axis[1], its x axis[0] (universal);
                                  else both markers share side 0's frame */
  /* front: after 'type', the keys check and 'bodies'/'node(s)' (on_nodes:
     the joint sits on FE nodes): its points, axes and reference */
  void (*parse)(mapping *m, ir_joint *j, bool on_nodes);
  /* lower: the constraint rows of joint j between its markers m0 and m1 */
  void (*lower_rows)(lmodel *L, int j, int m0, int m1);
} joint_desc;

/* --- drivers (driver.c) ------------------------------------------------- */

typedef struct driver_desc {
  element_family family;
  const char *const *keys;
  /* front: fill d from its mapping (keys checked) */
  void (*parse)(mapping *m, ir_driver *d);
  /* front, after the scene: cross-driver checks (two drivers on one dof) */
  void (*check)(reader *r);
  /* lower: the row of driver index (its joint's markers jm0, jm1); 0, or -1
     when out of memory */
  int (*lower)(lmodel *L, int index, const int *jm0, const int *jm1);
} driver_desc;

/* --- outputs (output_*.c) ------------------------------------------------ */

typedef struct output_desc {
  element_family family;
  const char *type;            /* the YAML 'type' value */
  ir_output_kind ir_kind;
  mb_output_kind runtime_kind;
  const char *runtime_kind_name;
  const char *const *keys;     /* accepted keys, NULL-terminated */
  /* its columns' name suffixes when it has more than one, NULL-terminated
     (NULL: one column); one column when a single component is asked for */
  const char *const *columns;
  /* front: fill o from its mapping after the keys check ('scale' is the
     reader's); NULL: nothing but the common keys */
  void (*parse)(mapping *m, ir_output *o);
  /* the number of columns when it is not given by 'columns' (NULL: it is) */
  int (*count_columns)(const ir_model *ir, const ir_output *o);
  /* lower: the kind's fields of d after the common ones (kind, body, point,
     component, scale, columns); jm0, jm1: the joints' markers (-1: off).
     0, or -1 after reporting an error.  NULL: none. */
  int (*lower)(lmodel *L, const ir_output *o, const int *jm0, const int *jm1, mb_outputdef *d);
} output_desc;

/* the fields of the kinds that measure elements and markers (force,
   relative, joint, center_of_mass; output_element.c), before their own */
void output_measure_init(mb_outputdef *d, const ir_output *o);

/* the runtime kind and its enumerator's name, in an output's initializer */
#define OUTPUT_RUNTIME_KIND(k) .runtime_kind = k, .runtime_kind_name = #k

/* --- the tables (registry.c) --------------------------------------------- */

/* the force elements, in the order of ir_force_kind; NULL-terminated */
extern const element_desc *const force_elements[];
/* the descriptor of an IR force kind */
const element_desc *force_element(ir_force_kind kind);
/* the YAML type names of the force elements, NULL-terminated (for "expected one of") */
const char *const *force_type_names(void);

/* the joint kinds in the order of ir_joint_kind, their type names; the one
   driver family; the output kinds in the order of ir_output_kind, their
   type names (NULL-terminated) */
extern const joint_desc *const joint_elements[];
const joint_desc *joint_element(ir_joint_kind kind);
const char *const *joint_type_names(void);
extern const driver_desc element_driver;
extern const output_desc *const output_elements[];
const output_desc *output_element(ir_output_kind kind);
const char *const *output_type_names(void);
/* the number of columns of output o */
int output_columns(const ir_model *ir, const ir_output *o);

#endif
