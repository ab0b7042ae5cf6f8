/* unit.h: one compilation unit, the products of every stage of the pipeline
 *   read -> scene -> flexible bodies -> lower -> pattern -> assembly analysis -> plan
 * each built once (compiler/pipeline.c) and then only read: by `mbcc check`,
 * by the emitters (every output file from the same plan), by the tools. */
#ifndef MBCC_UNIT_H
#define MBCC_UNIT_H

#include <stdbool.h>
#include <stdint.h>

#include "flex.h"
#include "ir.h"
#include "lower.h"
#include "order.h"

typedef struct mbc_unit {
  const char *path, *scene; /* as given on the command line */
  ir_model *ir;             /* read, the scene applied (ir_read) */
  const char *file_name;    /* the model file's name in its own directory (path's basename):
                               what the generated code quotes, however the path was typed */
  uint64_t input_hash;      /* FNV-1a 64 of the model file's bytes, a 0 byte and the scene's name */
  flex_product flex;        /* the flexible bodies' modes and invariants (flex_reduce) */
  lmodel *lowered;          /* coordinates, rows, pattern, assembled (lower_model, assemble_model) */
  ldl_plan plan;            /* the emitted LDL^T's ordering and symbolic factorization */
  int have_plan;            /* 0: the ordering failed (the model then has no emitted LDL^T) */
  int real_float;           /* emit for single precision (--real float) */
  /* run-time parameters (ir->params with runtime): the pool entries each sets
   * (pipeline.c, bind_runtime); none when the model has no run-time parameter */
  struct runtime_binding *bind;
  int nbind;
  /* run-time geometry (pipeline.c, bind_geometry): the markers of joints
   * (and of forces on moved bodies) whose body-frame offsets set_params
   * writes, and the bodies whose initial positions it writes; the simulator
   * then re-assembles at start (runtime/hosted/reassemble.c) */
  struct runtime_marker *rmark;
  int nrmark;
  struct runtime_body *rbody;
  int nrbody;
  int overridden;           /* read with --set values (the generic path), or the IR changed after
                               reading (mbcc trade's variants): run-time parameters are not bound,
                               and the emitted code folds them like compile-time ones */
} mbc_unit;

/* one pool entry of the lowered model set by an expression over run-time
 * parameters: force_prm[index], or force_law[index].coef / .exponent, or
 * (BIND_MARKER_POINT) coordinate `component` of the global point at t = 0 of
 * force marker `index`, whose body-frame offset markers[index].s follows it */
typedef enum { BIND_PRM, BIND_LAW_COEF, BIND_LAW_EXPONENT, BIND_MARKER_POINT } runtime_pool;
typedef struct runtime_binding {
  runtime_pool pool;
  int index;
  int component; /* BIND_MARKER_POINT: x, y or z */
  int side;      /* BIND_MARKER_POINT: which end of the force element */
  /* BIND_MARKER_POINT: the body's frame the offset was taken in (A, r at the
     lowered q0, before assembly: as lower.c's add_marker took it) */
  double frame_A[9], frame_r[3];
  int use;      /* ir->uses[use]: its expression and location */
  int force;    /* the force element (lowered index) */
} runtime_binding;

/* a marker whose offset s = A^T (P - r) follows run-time parameters: its
 * global point P at t = 0 as written (each coordinate a literal or the
 * expression of ir->uses[use[j]]), its body's frame at the lowered q0 (A, and
 * r unless the body's position is itself run-time, runtime_body) */
typedef struct runtime_marker {
  int marker;
  int output;            /* >= 0: instead of a marker, the point s of this output */
  int body;              /* lowered body, -1: the ground */
  double P[3];
  int use[3];            /* -1: the literal P[j] */
  double frame_A[9], frame_r[3];
  char what[160];        /* "joint 'pin', point 0" (the generated comment) */
} runtime_marker;

/* a body whose initial position (body frame origin, global) has run-time
 * coordinates: use[j] >= 0 for those, r the lowered (as written) position */
typedef struct runtime_body {
  int body;
  int use[3];
  double r[3];
} runtime_body;

/* body b's run-time position (lowered index), or NULL when it is fixed */
const runtime_body *mbc_runtime_body(const mbc_unit *u, int b);
/* whether run-time parameter k (an index of ir->params) moves joint points or
 * body positions: the simulator then re-assembles at start */
bool mbc_param_moves_assembly(const mbc_unit *u, int k);

/* The first stage alone: read the model and apply the scene, so that a tool
 * can change the IR before the rest (mbcc trade's variants).  0, or 2 after
 * reporting (nothing is then held).  Every function here leaves u ready for
 * mbc_unit_free, also after a failure. */
int mbc_unit_read(mbc_unit *u, const char *path, const char *scene);
/* The stages after reading: flexible bodies, lowering and pattern, assembly
 * analysis (verbose: its report on stdout), the LDL^T plan.  0, or 2 after
 * reporting. */
int mbc_unit_finish(mbc_unit *u, int verbose);
/* the fields the run-time parameters set (u->bind), at the run-time values
 * p (in the order of run-time parameters), against the rule the reader checks
 * them by (>= 0, > 0): 0, or 2 after an error at each field that breaks its
 * rule ('context' leads the message, e.g. "--set k=-5") */
int mbc_check_runtime_rules(const mbc_unit *u, const double *p, const char *context);
/* Both: the whole pipeline */
int mbc_unit_build(mbc_unit *u, const char *path, const char *scene, int verbose);
void mbc_unit_free(mbc_unit *u);

#endif
