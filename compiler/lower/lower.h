/* lower.h: the lowered model: the IR turned into coordinates, markers,
 * constraint rows, force and output tables, and the fixed CSC pattern of
 * K = [M D^T; D 0] -- an mb_model (runtime/core/mb_model.h) that owns its tables,
 * plus where each entry came from (for diagnostics and generated comments). */
#ifndef MBCC_LOWER_H
#define MBCC_LOWER_H

#include "flex.h"
#include "ir.h"
#include "mb_model.h"

typedef struct {
  mb_model m;                /* tables below; eval = mb_generic_eval */
  const ir_model *ir;
  mb_body *body;             /* m.nbody: IR body b+1 is mb body b */
  mb_markerdef *marker;
  mb_rowdef *row;
  mb_forcedef *force;
  double *force_prm;         /* m.nforce_prm reals (mb_forcedef.padr) */
  size_t force_prm_cap;      /* reals allocated for force_prm (grows: a tyre carries its road) */
  int out_of_memory;         /* lower_force_prm failed (lower_model returns NULL) */
  mb_law *force_law;         /* m.nforce_law laws (mb_forcedef.ladr) */
  mb_profile *profile;
  mb_outputdef *output;
  double *output_coef;       /* SECTION outputs' coefficient rows (m.output_coef) */
  int noutput_coef;
  int *Kp, *Ki;
  double *q0, *v0;
  char **col_name;
  char **joint_name;
  /* provenance */
  char **marker_desc;        /* "joint 'pin' on body 'crank'" */
  ir_loc *marker_loc;        /* the YAML element that made the marker */
  char **row_desc;           /* "joint 'pin' (revolute): spherical x" */
  ir_loc *row_loc;
  int *force_ir;             /* IR force index of each force */
  int *profile_driver;       /* IR driver (or -1) / force (>= 0 in profile_force) */
  int *profile_force;
  double **spline;           /* owned spline and table arrays of table profiles */
  double **table;
  /* flexible bodies: per mb body (unused for others); they point into the
   * flexible-body stage's product (flex_reduce), which must outlive L */
  const fe_modes *modes;
  const flex_data *flexd;
  int **mslotf;
  int *modal_slot;           /* slots of constraint rows' modal columns */
  int nmodal_slot;
  /* force-element tangents (an implicit method asked for; else NULL, 0):
   * m.force_tslot and m.tangent_slot, see mb_model.h */
  int *force_tslot;
  int *tangent_slot;
  int ntangent_slot;
  int nvirtual;              /* virtual bodies inserted for joints on flexible nodes */
  char **body_name;          /* owned names of inserted bodies */
  char *name;                /* model name, with the scene's appended: <model>_<scene> */
  int bad;                   /* an error was reported while lowering */
  int nredundant;            /* rows removed at assembly */
  int dof;
  /* per force_prm entry: 1 when a run-time parameter sets it (the emitted code
   * then reads the pool instead of a literal); NULL when none does.  Owned by
   * the compilation unit (pipeline.c). */
  unsigned char *prm_runtime;
  /* per marker: 1 when its offset s is set by run-time parameters (a force
     element's attachment point): the emitted code reads markers[k].s */
  unsigned char *marker_runtime;
  /* the rows the assembly removed as redundant (assemble.c), kept for the
   * generated code's re-assembly check when run-time geometry may change
   * their redundancy: their records (slots unset) and descriptions */
  mb_rowdef *removed_row;
  char **removed_desc;
  int nremoved;
  /* q0 and v0 as lowered, before the assembly moved them (assemble.c): where
   * the generated code's re-assembly starts */
  double *q_given, *v_given;
} lmodel;

/* For the lowering hooks of the elements (compiler/elements/): the marker
 * of a force's side (0 or 1) with axes C (columns, global); the force record
 * d's n reals of the parameter pool (zeroed; NULL when memory ran out: the
 * hook returns, lower_model reports it) and n laws of the law pool; a time
 * function (force: the IR force index, for provenance). */
int lower_force_marker(lmodel *L, const ir_force *F, int side, const double C[9]);
double *lower_force_prm(lmodel *L, mb_forcedef *d, int n);
mb_law *lower_force_laws(lmodel *L, mb_forcedef *d, int n);
int lower_add_profile(lmodel *L, const ir_profile *p, int driver, int force);
/* For the joints and drivers: a constraint row between markers m0 and m1
 * (mb_rowdef's a, b), described as "<ekind> '<elem>': <what>" at loc; joint
 * and driver: its source element, or -1. */
void lower_add_row(lmodel *L, mb_prim_kind kind, int m0, int m1, int a, int b, const char *what,
                   int joint, int driver, ir_loc loc, const char *elem, const char *ekind);

/* Build the tables and pattern from the IR (positions as given) and the
 * flexible bodies' reduction (flex_reduce of the same IR).  Returns NULL and
 * reports on error. */
lmodel *lower_model(const ir_model *ir, const flex_product *flex);
/* (Re)build the CSC pattern and every slot from the current rows. */
int lower_pattern(lmodel *L);
/* Remove constraint rows whose keep[r] is 0, then rebuild the pattern. */
int lower_remove_rows(lmodel *L, const int *keep);
void lower_free(lmodel *L);
/* 1 if some translational (X) / rotational (Psi) mode shape of flexible body B
 * is nonzero at node 'node' */
int lower_node_translates(const mb_body *B, int node);
int lower_node_rotates(const mb_body *B, int node);

/* Assembly analysis at t = 0 (assemble.c): Newton onto the position
 * constraints, redundant rows removed (warnings), consistent velocities,
 * singularity check.  Returns 0, or 2 after reporting an error. */
int assemble_model(lmodel *L, int verbose);

#endif
