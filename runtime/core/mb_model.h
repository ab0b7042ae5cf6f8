/* mb_model.h: a compiled model: its element tables (what the compiler fixed:
 * sizes, the CSC pattern of K = [M D^T; D 0], markers, constraint rows, forces,
 * outputs) and the functions that evaluate it.  The generated code provides a
 * const mb_model whose eval is specialized straight-line code; the generic
 * path provides the same tables with eval = mb_generic_eval, which walks them.
 * Both call the kernels of mb_kernels.h and elements/, so they give the same
 * numbers.
 *
 * Force elements are records of a kind and addresses into pools, as in
 * MuJoCo's model arrays: force_prm (reals), force_law (force laws) and a
 * state pool.  Each kind's kernel header (elements/mb_*.h) names the offsets
 * of its parameters; the record holds no union of every kind's fields. */
#ifndef MB_MODEL_H
#define MB_MODEL_H

#include <stddef.h>
#include "mb_flex.h"
#include "elements/mb_field.h"
#include "elements/mb_force_point.h"
#include "elements/mb_spring.h"
#include "elements/mb_superelement.h"
#include "elements/mb_tyre.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { MB_BODY_RIGID = 1, MB_BODY_VIRTUAL = 2, MB_BODY_FLEXIBLE = 3 } mb_body_kind;

typedef struct {
  const char *name;
  mb_body_kind kind;
  mb_real mass;
  mb_real J[9];      /* inertia about the centre of mass, body axes */
  int qadr, vadr;    /* first position / velocity coordinate */
  int mslot[12];     /* Kx slots of m (3 diagonal) and J (9, row-major); -1: none */
  int nm;            /* flexible: modes (coordinates qadr+7.., vadr+6..) */
  const mb_flex *flex;   /* flexible: invariants and node shapes; else NULL */
  const int *mslotf;     /* flexible: Kx slots of the (6+nm)^2 mass block, row-major; -1: none */
  const mb_flex_stiff *stiff; /* flexible with geometric stiffening: its tables; else NULL */
} mb_body;

typedef struct {
  int body;          /* index into body[], or -1 for the ground */
  int node;          /* flexible body: FE node the marker sits on, or -1 (body frame) */
  mb_real s[3];      /* point in body axes (ground: global) */
  mb_real C[9];      /* axes in body axes (ground: global), row-major, columns x y z */
} mb_markerdef;

typedef struct {
  mb_prim_kind kind;
  int m0, m1;        /* markers */
  int a, b;          /* SPH: component in a; DOT1: axes a of m0, b of m1; DOT2/TRANS: axis a of m0 */
  mb_real L;         /* DIST: length */
  int profile;       /* ROT, TRANS: index into profile[]; else -1 */
  int slot[2][6];    /* Kx slot of D(row, body column) for marker 0/1's body; -1: none */
  int slotT[2][6];   /* Kx slot of the transposed entry D^T */
  unsigned char constant[2][6]; /* 1: the entry never changes (written by init only) */
  int mslot[2];      /* flexible node markers: index into modal_slot of this row's modal
                        columns (nm slots, then nm transposed slots); -1: none */
  int joint;         /* the source joint (reactions); -1 for a driver row */
  int driver;        /* the source driver (effort), or -1 */
} mb_rowdef;

typedef enum {
  MB_FORCE_POINT = 1, /* elements/mb_force_point.h */
  MB_FORCE_TORQUE,    /* elements/mb_force_point.h */
  MB_FORCE_SPRING,    /* elements/mb_spring.h */
  MB_FORCE_FIELD,     /* elements/mb_field.h: fields, bushings, beams */
  MB_FORCE_TYRE,      /* elements/mb_tyre.h: tyre on a road (one marker, the wheel centre) */
  MB_FORCE_SUPERELEMENT /* elements/mb_superelement.h: more than two nodes (markers m0, then
                           m1 .. m1 + n - 1); no tangent: an implicit method's Newton
                           sees its stiffness only through the residual */
} mb_force_kind;

typedef struct {
  mb_force_kind kind;
  int m0, m1;        /* markers; m1 = -1 for one-marker kinds (point force, torque); a
                        superelement's nodes 1..n are markers m1 .. m1 + n - 1 */
  int padr, pnum;    /* reals in force_prm (layout: the kind's MB_<KIND>_* offsets) */
  int ladr, lnum;    /* force laws in force_law (spring: stiffness, damping) */
  int sadr, snum;    /* internal state (e.g. a tyre's slip relaxation) in the caller's
                        force state of mb_model.nforce_state reals: reserved, no kind
                        has state yet (snum = 0) */
  int profile;       /* time function scaling the element (point force, torque), or -1 */
  int local;         /* point force, torque: 1 when the vector is in marker 0's body axes */
} mb_forcedef;

typedef enum {
  MB_OUT_POSITION = 1, MB_OUT_ORIENTATION, MB_OUT_ANGLE, MB_OUT_VELOCITY, MB_OUT_ANGULAR_VELOCITY,
  MB_OUT_ACCELERATION, MB_OUT_ANGULAR_ACCELERATION, MB_OUT_REACTION, MB_OUT_EFFORT,
  MB_OUT_KINETIC_ENERGY, MB_OUT_POTENTIAL_ENERGY, MB_OUT_TOTAL_ENERGY, MB_OUT_DEFLECTION,
  MB_OUT_MODAL, MB_OUT_MOMENTUM, MB_OUT_SECTION, MB_OUT_FORCE, MB_OUT_RELATIVE, MB_OUT_JOINT,
  MB_OUT_CENTER_OF_MASS, MB_OUT_TYRE
} mb_output_kind;

/* what a RELATIVE or CENTER_OF_MASS output measures */
enum { MB_QUANTITY_POSITION = 0, MB_QUANTITY_VELOCITY = 1, MB_QUANTITY_ACCELERATION = 2 };

typedef struct {
  mb_output_kind kind;
  int body;          /* or -1 */
  mb_real s[3];      /* point in body axes (position/velocity/acceleration) */
  mb_real axis[3];   /* ANGLE: axis in body axes; the angle is of u about it */
  mb_real u[3];      /* ANGLE: reference direction perpendicular to axis, body axes */
  mb_real axis_g[3]; /* ANGLE: the axis, global */
  mb_real u_g[3];    /* ANGLE: the reference direction, global */
  int component;     /* -1: all; else 0..2 (SECTION: 0..5 one of N Vy Vz T My Mz, 6 the
                        fiber's normal stress; TYRE, FORCE: below) */
  int joint;         /* REACTION: joint index; its marker 1 is reaction_marker; TYRE: the
                        force element's index */
  int reaction_marker;
  int driver_row;    /* EFFORT: the driver's row, or -1 when redundant */
  int driver_marker; /* EFFORT: marker 0 of the driven joint (its z axis) */
  int driver_rotation; /* EFFORT: 1 rotation, 0 translation */
  int node;          /* DEFLECTION: the node (deflection X_k w, body axes); POSITION, VELOCITY:
                        a node of a flexible body, or -1; MODAL: the mode; SECTION: the first
                        of its ncols x nm coefficients (row-major) in the model's output_coef:
                        the output is output_coef rows times w */
  int chord[2];      /* DEFLECTION: minus the chord between these nodes' deflections, or -1 */
  mb_real scale;
  /* FORCE, RELATIVE, JOINT, CENTER_OF_MASS (the fields below are zero for other kinds):
   * FORCE: 'element' is the force element; component 0..5 picks one of fx..tz, 6 the
   * tension of a spring.  RELATIVE: the marker (body, s, node) relative to (body2,
   * s2, node2; body2 = -1: the ground, s2 global), resolved in the axes of body 'frame'
   * (-1: global).  JOINT: the joint's markers jmarker[0], jmarker[1] and joint_dofs
   * (1: rotation, 2: translation, 3: both, angle first).  CENTER_OF_MASS: with node
   * >= 0, output_coef + node holds nbody weights (1: in the subset, 0: not); -1: all. */
  int element;
  int quantity;      /* RELATIVE, CENTER_OF_MASS: MB_QUANTITY_* */
  int body2, node2;
  mb_real s2[3];
  int frame;
  int jmarker[2];
  int joint_dofs;
  int ncols, col;    /* columns in the output vector and the first of them */
} mb_outputdef;

struct mb_model;

/* Fill the varying entries of Kx, rhs = [f; gamma] (length n), and the
 * position and velocity constraint violations phi and phid = D v - nu (length
 * nc) at time t, positions q and velocities v.  'work' has mb_model_worksize
 * bytes (the generated eval needs none). */
typedef void (*mb_eval_fn)(const struct mb_model *m, mb_real t, const mb_real *q,
                           const mb_real *v, mb_real *Kx, mb_real *rhs, mb_real *phi,
                           mb_real *phid, void *work);

typedef struct mb_model {
  const char *name;
  int nbody, nmarker, nrow, nforce, nprofile, noutput, njoint;
  int nq, nv, nc, n, nnz;
  const mb_body *body;
  const mb_markerdef *marker;
  const mb_rowdef *row;
  const mb_forcedef *force;
  const mb_real *force_prm;    /* parameter pool of the force elements (mb_forcedef.padr) */
  const mb_law *force_law;     /* force-law pool (mb_forcedef.ladr) */
  int nforce_prm, nforce_law;
  int nforce_state;            /* reals of force-element state (none yet: 0) */
  const mb_profile *profile;
  const mb_outputdef *output;
  const mb_real *output_coef;  /* SECTION outputs: linear in the modal coordinates (or 0) */
  const char *const *joint_name;
  mb_real gravity[3];
  const int *Kp, *Ki;          /* CSC pattern of K (both triangles), n+1 and nnz */
  const int *modal_slot;       /* Kx slots of constraint rows' modal columns (see mb_rowdef) */
  const mb_real *q0, *v0;      /* assembled, consistent initial state */
  int ncols;                   /* output columns */
  const char *const *col_name; /* their names */
  mb_eval_fn eval;
  void (*init)(const struct mb_model *m, mb_real *Kx); /* the constant entries of K */
  /* the emitted LDL^T of K (solver "ldl", compiler/back/emit_ldl.c); NULL / 0 when the
   * model has none (the generic path).  factor: 0, or 1 + the unknown whose pivot
   * is zero or tiny; solve: K x = b in place with refinement on the exact system,
   * residual[0] = ||b - K x||_inf / (||K||_inf ||x||_inf + ||b||_inf), residual[1]
   * the same before refinement; with residual NULL and ldl_exact, one pass without
   * residual or refinement */
  int (*ldl_factor)(const struct mb_model *m, const mb_real *Kx, mb_real *work);
  int (*ldl_solve)(const struct mb_model *m, const mb_real *Kx, mb_real *work, mb_real *b,
                   mb_real *residual);
  size_t ldl_worksize;         /* mb_real elements of 'work' */
  long ldl_nnzL;               /* nonzeros of L (strictly lower) */
  double ldl_flops;            /* flops of one numeric factorization */
  int ldl_straight;            /* 1: straight-line code, 0: loops over static tables */
  int ldl_exact;               /* 1: no weighted rows, so ldl_solve with residual NULL is
                                  one pass without refinement (the factors are K's) */
  /* run-time parameters ('runtime: true' in the model's 'parameters:'): inputs
   * of the generated code, changed without recompiling (the simulator's --set
   * NAME=VALUE).  set_params(m, p) writes the force pools from the vector p of
   * nparam values (defaults param_value, bounds param_min..param_max) before a
   * run and returns NULL; when a value a field takes breaks the field's rule
   * (a stiffness >= 0, ...) it writes nothing and returns the rule, naming
   * the force, the field and its place in the model.  Not safe while another
   * thread evaluates the model.  0 / NULL: none. */
  int nparam;
  const char *const *param_name;
  const mb_real *param_value, *param_min, *param_max;
  const char *(*set_params)(const struct mb_model *m, const mb_real *p);
  /* force-element tangents on the pattern (models compiled for an implicit
   * method; NULL otherwise): force_tslot[e] is the first of force e's slots
   * in tangent_slot, or -1 when it has none.  Its slots are four blocks of
   * body columns, sides (0,0), (0,1), (1,0), (1,1), each row-major with
   * mb_force_tangent_cols(m, e, s) rows and columns (docs/formulation.md). */
  const int *force_tslot;
  const int *tangent_slot;
  /* run-time geometry (NULL / 0 when no parameter moves it): param_geometry[i]
   * is 1 when parameter i moves joint points or body positions (set_params
   * writes the markers' offsets and q_given), after which the simulator
   * re-assembles at start (mb_reassemble); the nredundant constraint rows the
   * compiler removed as redundant (redundant_row, slots unset; redundant_name
   * describes each) must stay redundant there */
  const unsigned char *param_geometry;
  const mb_real *q_given, *v_given; /* the state as the file gives it (before the
                                       compiler's assembly): the re-assembly's start */
  int nredundant;
  const mb_rowdef *redundant_row;
  const char *const *redundant_name;
} mb_model;

/* How many velocity columns side s (0, 1) of force element d has in the
 * force tangent: 0 on the ground or a virtual body (its columns are
 * eliminated by the solver's compile-time plan), 6 + nm on a flexible node
 * marker (the field's side 0: 6, its reaction acts through the body frame at
 * marker 1's point), else 6.  Springs, fields and tyres have tangents; the
 * tyre has one side (its wheel marker, side 0: the road is ground). */
static inline int mb_force_tangent_side_cols(const mb_body *body, const mb_markerdef *marker,
                                             const mb_forcedef *d, int s) {
  if (d->kind != MB_FORCE_SPRING && d->kind != MB_FORCE_FIELD && d->kind != MB_FORCE_TYRE)
    return 0;
  if (d->kind == MB_FORCE_TYRE ? (s || d->m0 < 0) : (d->m0 < 0 || d->m1 < 0)) return 0;
  const mb_markerdef *md = &marker[s ? d->m1 : d->m0];
  if (md->body < 0) return 0;
  const mb_body *B = &body[md->body];
  if (B->kind == MB_BODY_VIRTUAL) return 0;
  if (d->kind == MB_FORCE_FIELD && s == 0) return 6;
  return md->node >= 0 ? 6 + B->nm : 6;
}
static inline int mb_force_tangent_cols(const struct mb_model *m, int e, int s) {
  return mb_force_tangent_side_cols(m->body, m->marker, &m->force[e], s);
}

/* triplets (row, column, value) of K from the general generic path */
typedef struct {
  int n;
  int *i, *j;
  mb_real *x;
} mb_triplets;

/* generic (table-walking) implementations; freestanding: no allocation, no I/O */
size_t mb_model_worksize(const mb_model *m);
void mb_generic_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid, void *work);
void mb_generic_init(const mb_model *m, mb_real *Kx);
/* The general generic path (the baseline `mbcc bench` times the generated
 * code against): the same element kernels, but every entry of every element
 * block goes into triplets (in 'work', see mb_generic_triplets), with no use of
 * the compile-time pattern; a general sparse solver assembles them each step.
 * Kx is left alone. */
void mb_generic_triplet_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                             mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid,
                             void *work);
void mb_generic_triplet_init(const mb_model *m, mb_real *Kx);
mb_triplets *mb_generic_triplets(const mb_model *m, void *work);

/* qd = G(q) v: position-coordinate rates */
void mb_model_qdot(const mb_model *m, const mb_real *q, const mb_real *v, mb_real *qd);
/* q <- q (+) dv: move positions by a velocity-space increment (exact rotations) */
void mb_model_qincrement(const mb_model *m, mb_real *q, const mb_real *dv);
/* normalize Euler parameters */
void mb_model_normalize(const mb_model *m, mb_real *q);
/* Outputs at one instant: vd and lambda are the accelerations and multipliers
 * (from the same solve).  'prev' holds, at the columns of angle outputs, the
 * unwrapped angles in radians a moment ago (mb_model_track_angles) or is NULL
 * (the first row); angles are unwrapped against it, then scaled.  Writes
 * m->ncols values. */
void mb_model_outputs(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                      const mb_real *vd, const mb_real *lambda, const mb_real *prev,
                      mb_real *out, void *work);
/* The unwrapped angle outputs (radians, unscaled) at q into ref[col] of their
 * columns, each the branch nearest ref's value unless have_ref is 0.  Called
 * after every accepted step, so that an angle is unwrapped however far apart
 * the output rows are. */
void mb_model_track_angles(const struct mb_model *m, const mb_real *q, const mb_real *v,
                           mb_real *ref, int have_ref, void *work);
/* The largest step after which every body with an angle output has turned by
 * at most a quarter turn at its present angular velocity (INFINITY without
 * angle outputs): beyond it unwrapping would be ambiguous. */
double mb_model_angle_step(const struct mb_model *m, const mb_real *q, const mb_real *v, void *work);
/* The force F and torque T (global) that force element k applies on its body 1
 * (the second body; for one-body elements, its body), about its attachment point
 * (that body's marker point).  'work' as for mb_model_outputs. */
void mb_force_wrench(const mb_model *m, int k, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real F[3], mb_real T[3], void *work);
/* Add the force elements' tangents into Kx at their slots (m->force_tslot;
 * nothing when NULL): kfac (-df/dq) + cfac (-df/dv) over the body columns each
 * element connects, f the generalized applied force.  The material part of
 * each kernel's tangent (elements/, I5) mapped through the markers' velocity
 * Jacobians; the geometric terms of order |force| (turning lever arms and
 * axes) are left out.  Used by generalized-alpha for both drivers. */
void mb_model_force_tangent(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                            mb_real kfac, mb_real cfac, mb_real *Kx, void *work);
/* kinetic and potential energy (gravity and force elements) */
void mb_model_energy(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real *kinetic, mb_real *potential, void *work);

#ifdef __cplusplus
}
#endif

#endif
