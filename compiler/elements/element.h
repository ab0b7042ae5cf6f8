/* element.h: an element family as one unit.  A descriptor names everything
 * the compiler does with one YAML element type: its keys, how it is parsed
 * and validated (front), how it is lowered to a runtime record and its
 * parameter pool (lower), and, optionally, how its evaluation is emitted
 * (back).  registry.c holds the one table of descriptors; the reader, the
 * lowering and the emitter dispatch through it, so adding a force element
 * is its own file here, its kernel in runtime/core/elements/, and one line
 * in registry.c (docs/architecture.md walks through it). */
#ifndef MBCC_ELEMENT_H
#define MBCC_ELEMENT_H

#include <stdio.h>

#include "ir.h"
#include "lower.h"
#include "yaml_map.h"

typedef enum { ELEMENT_FORCE } element_family;

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

/* the force elements, in the order of ir_force_kind; NULL-terminated */
extern const element_desc *const force_elements[];
/* the descriptor of an IR force kind */
const element_desc *force_element(ir_force_kind kind);
/* the YAML type names of the force elements, NULL-terminated (for "expected one of") */
const char *const *force_type_names(void);

#endif
