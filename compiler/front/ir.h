/* ir.h: the in-memory model (intermediate representation) that the YAML
 * reader produces and the later compiler stages (scene, lowering, pattern,
 * emit) consume.  Units are SI; every vector given in the model is global
 * and describes the assembled configuration at t = 0. */
#ifndef MBCC_IR_H
#define MBCC_IR_H

#include <stdbool.h>

/* A source location, 1-based (libyaml marks are 0-based: add 1). */
typedef struct {
  int line, col;
} ir_loc;

/* --- time functions (drivers, forces given in time) ---------------------- */
typedef enum {
  PROFILE_NONE = 0,
  PROFILE_CONSTANT,          /* x = value                                   */
  PROFILE_CONSTANT_VELOCITY, /* x = initial + velocity * t                  */
  PROFILE_POLYNOMIAL,        /* x = sum c[k] t^k, k < nc (nc <= 8)           */
  PROFILE_RAMP,              /* cubic step from (t0, x0) to (t1, x1), as
                                Adams STEP: flat before t0 and after t1     */
  PROFILE_SINE,              /* x = offset + amplitude sin(2 pi f t + phase) */
  PROFILE_TABLE              /* natural cubic spline through (t_k, x_k),
                                held constant outside the table            */
} ir_profile_kind;

typedef struct {
  ir_profile_kind kind;
  double c[8];   /* CONSTANT: c[0]=value.  CONSTANT_VELOCITY: c[0]=initial,
                    c[1]=velocity.  POLYNOMIAL: c[0..nc-1].  RAMP: c[0]=t0,
                    c[1]=x0, c[2]=t1, c[3]=x1.  SINE: c[0]=amplitude,
                    c[1]=frequency (Hz), c[2]=phase (rad), c[3]=offset      */
  int nc;
  double *table; /* TABLE: ntable pairs t0,x0,t1,x1,... (t strictly rising) */
  int ntable;
  ir_loc loc;
} ir_profile;

/* --- bodies ----------------------------------------------------------------- */
typedef enum { BODY_GROUND, BODY_RIGID, BODY_VIRTUAL, BODY_FLEXIBLE } ir_body_kind;

/* --- flexible bodies: an FE beam model or a modal data file ------------------ */
typedef enum { BEAM_EULER_BERNOULLI, BEAM_TIMOSHENKO } ir_beam_theory;
typedef enum { MASS_LUMPED, MASS_CONSISTENT } ir_mass_kind;
typedef enum { COUPLING_FULL, COUPLING_PARTIAL, COUPLING_CONSTANT, COUPLING_RIGID } ir_coupling;
typedef enum { MODES_COUNT, MODES_MAX_FREQUENCY, MODES_LIST, MODES_ALL } ir_mode_select;
typedef enum { DAMPING_NONE, DAMPING_RATIO, DAMPING_BANDS, DAMPING_LIST } ir_damping_kind;

typedef struct {
  int node[2];             /* node indices */
  ir_beam_theory theory;
  double E, G, rho;        /* material */
  double A, Iy, Iz, J;     /* section: area, second moments about local y and z, torsion constant */
  double shear_y, shear_z; /* Timoshenko shear area ratios (A_s = ratio * A); 0 for Euler-Bernoulli */
  double yaxis[3];         /* unit local y of the section (perpendicular to the element), body axes */
  double nsm;              /* non-structural mass per length, kg/m: lumped like rho A (translation and
                              bending rotary inertia), none in torsion (it sits on the beam's axis) */
  ir_loc loc;
} ir_beam;

typedef struct {
  int node;
  double mass;
  double inertia[9];       /* body axes, about the node */
  ir_loc loc;
} ir_point_mass;

/* RBE2: the 'dofs' (bit d: DOF d of ux uy uz rx ry rz) of node 'dependent'
 * follow node 'independent' rigidly */
typedef struct {
  int independent, dependent;
  unsigned dofs;
  ir_loc loc;
} ir_rigid_link;

/* An FE matrix given as such (Matrix Market import): nnz entries (row, col,
 * value) in the 6-per-node DOF numbering, body axes; both triangles. */
typedef struct {
  int nnz;
  int *row, *col;
  double *val;
} ir_fe_matrix;

/* reference conditions: nodes clamped to the body frame; a pinned-pinned
 * (chord) frame; free-free modes in mean axes (frame at the centre of mass) */
typedef enum { REFERENCE_CLAMPED, REFERENCE_CHORD, REFERENCE_FREE } ir_reference_kind;

/* The content of a modal data file (docs/modal-file.md), as the reader read
 * and checked it (compiler/front/modal_file.c): every mode, before the
 * body's mode selection (compiler/flex/fe.c applies that). */
#define IR_MODAL_FORMAT "mbcc-modal-1"
typedef struct {
  int nnodes, nmodes;
  double *position;  /* 3 nnodes: undeformed, body axes, relative to the body frame origin */
  double *mass;      /* nnodes: lumped translational masses */
  double *inertia;   /* 9 nnodes: rotary inertias about the nodes, body axes, row-major */
  double *freq_hz;   /* nmodes, ascending */
  double *shapes;    /* 6 nnodes per mode, mode after mode; orthonormal with respect to
                        the nodal masses and inertias */
} ir_modal_data;

typedef struct ir_flex {
  /* FE description (modal_file == NULL) */
  int nnodes;
  double *nodes;           /* 3 * nnodes: positions in body axes relative to the body frame origin */
  ir_loc *node_loc;        /* where each node (or the generator) was given */
  ir_beam *beams;
  int nbeams;
  ir_point_mass *point_masses;
  int npoint_masses;
  ir_mass_kind mass;       /* FE mass matrix: lumped (HRZ) or consistent */
  int *reference;          /* nodes fixed to the body frame (reference conditions) */
  int nreference;
  int *interface;          /* Craig-Bampton interface nodes (none: constrained normal modes) */
  int ninterface;
  int *residual;           /* residual_modes: nodes whose unit loads add residual attachment modes
                              (static correction; inertia relief on a free-free body) */
  int nresidual;
  ir_reference_kind reference_kind; /* CHORD: reference = [A, B]; FREE: none */
  int eigensolver;         /* 0 auto (sparse above FE_SPARSE_MIN_DOFS free DOFs), 1 dense, 2 sparse */
  /* imported FE models (fe_file) */
  long *beam_ids;          /* nbeams: the deck's element ids (NULL: 0, 1, ...) */
  char *fe_path;           /* the FE file it came from (NULL: inline); its errors are reported
                              by the importer, later ones at the body, naming nodes by id */
  long *node_ids;          /* nnodes: the deck's GRID ids that name the nodes (NULL: 0, 1, ...) */
  unsigned char *fixed;    /* 6 * nnodes: DOFs fixed to the body frame besides 'reference' (SPC,
                              DOFs an FE export does not have), or NULL */
  ir_rigid_link *links;    /* RBE2 */
  int nlinks;
  ir_fe_matrix *K_given, *M_given; /* Matrix Market: the whole K and M (instead of beams) */
  char *fe_source;         /* a YAML FE file (fe_file: X.fe.yaml): the file the locations of nodes,
                              beams and point masses refer to; NULL: the model file */
  char **node_names;       /* named nodes (node_names: {J1: 16}): usable wherever a node number is */
  int *node_name_index;
  int nnode_names;
  double *w0, *wd0;        /* initial modal coordinates and rates (n0, nd0 of them), or NULL */
  int nw0, nwd0;
  ir_loc w0_loc, wd0_loc;
  /* modal data file instead of FE (documented neutral format) */
  char *modal_file;        /* its path */
  ir_modal_data *modal;    /* its content */
  /* mode selection */
  ir_mode_select select;
  int count;               /* MODES_COUNT */
  double max_frequency;    /* MODES_MAX_FREQUENCY, Hz */
  int *list;               /* MODES_LIST: 1-based mode numbers */
  int nlist;
  /* modal damping */
  ir_damping_kind damping;
  double ratio;            /* DAMPING_RATIO */
  double *ratios;          /* DAMPING_LIST, one per selected mode */
  int nratios;
  ir_coupling coupling;
  bool geometric_stiffening; /* second-order (foreshortening) terms: compiler/flex/stiffening.c */
  ir_loc stiffening_loc;     /* of the key, when given */
  ir_loc loc;
} ir_flex;

/* what the browser animation draws for a rigid or virtual body (mbcc animate);
 * the simulation does not use it */
typedef enum { SHAPE_NONE, SHAPE_BOX, SHAPE_CYLINDER, SHAPE_SPHERE } ir_shape_kind;
typedef struct {
  ir_shape_kind kind;
  double size[3];             /* BOX: edge lengths along the body axes */
  double radius;              /* CYLINDER, SPHERE */
  double length;              /* CYLINDER: along 'axis' */
  double axis[3];             /* CYLINDER: unit axis, body axes (default z) */
  double offset[3];           /* centre in body axes (default the body frame origin) */
} ir_shape;

typedef struct {
  char *name;
  ir_loc loc;                 /* of the body's key */
  ir_body_kind kind;
  double mass;                /* 0 for virtual and ground */
  double inertia[9];          /* about the centre of mass, in body axes, row-major */
  double position[3];         /* body frame origin (centre of mass), global */
  double orientation[4];      /* Euler parameters e0..e3, normalized */
  double velocity[3];         /* initial, global (made consistent at assembly) */
  double angular_velocity[3]; /* initial, global */
  struct ir_flex *flex;       /* NULL unless kind == BODY_FLEXIBLE */
  ir_shape shape;             /* rigid and virtual: optional 'shape:' (animation only) */
} ir_body;

/* --- joints ------------------------------------------------------------------ */
typedef enum {
  JOINT_SPHERICAL,
  JOINT_REVOLUTE,    /* rotation about axis */
  JOINT_CYLINDRICAL, /* rotation about and translation along axis */
  JOINT_PRISMATIC,   /* translation along axis */
  JOINT_UNIVERSAL,   /* axis[0] fixed in body 0, axis[1] fixed in body 1, perpendicular */
  JOINT_FIXED,
  JOINT_DISTANCE     /* |point[1]-point[0]| held at its initial length */
} ir_joint_kind;

typedef struct {
  char *name;
  ir_loc loc;
  ir_joint_kind kind;
  int body[2];        /* indices into ir_model.bodies (0 is ground) */
  ir_loc body_loc[2];
  int node[2];        /* FE node on a flexible body, or -1 */
  double point[2][3]; /* global joint point on each side (equal except distance) */
  double axis[2][3];  /* unit joint axis on each side (equal except universal) */
  double ref[3];      /* unit reference direction perpendicular to axis[0] (the
                         marker x axis; angles of a driver are measured about
                         axis[0] from it); chosen by the reader if not given */
  bool active;        /* false when a scene deactivates it */
  bool via_virtual;   /* on a flexible node: lower through a massless virtual body
                         (simulation.joints_on_flexible: virtual, or this joint listed) */
} ir_joint;

/* --- drivers ------------------------------------------------------------------- */
typedef enum { DRIVER_ROTATION, DRIVER_TRANSLATION } ir_driver_dof;

typedef struct {
  char *name;
  ir_loc loc;
  int joint;          /* index into ir_model.joints */
  ir_driver_dof dof;  /* relative rotation about / translation along the joint axis,
                         measured from the configuration at t = 0 */
  ir_profile motion;
  bool active;
} ir_driver;

/* --- forces ---------------------------------------------------------------------- */
typedef enum {
  FORCE_POINT_FORCE,   /* a force at a point of one body */
  FORCE_POINT_TORQUE,  /* a torque on one body */
  FORCE_SPRING_DAMPER, /* along the line between two points */
  FORCE_BUSHING,       /* 6 diagonal stiffness and damping terms in a frame */
  FORCE_FIELD,         /* general 6x6 stiffness and damping in a frame */
  FORCE_BEAM,          /* massless Euler-Bernoulli / Timoshenko beam between two points */
  FORCE_TYRE,          /* tyre of a wheel body on a road (compiler/elements/force_tyre.c) */
  FORCE_SUPERELEMENT   /* massless FE model condensed to two nodes (K from fe_condense) */
} ir_force_kind;

/* a road (top-level 'roads'): z = h(x, y) */
typedef enum { ROAD_FLAT, ROAD_COSINE_BUMP, ROAD_TABLE } ir_road_kind;

typedef struct {
  char *name;
  ir_loc loc;
  ir_road_kind kind;
  double height;          /* FLAT */
  double length, start;   /* COSINE_BUMP: height H, length, start x0, y window */
  double y_range[2];
  int nx, ny;             /* TABLE: z[i ny + j] at (x[i], y[j]), both rising */
  double *x, *y, *z;
} ir_road;

/* a tyre (FORCE_TYRE): the wheel centre is point[0] on body[0] */
typedef struct {
  int road;               /* index into ir_model.roads */
  int model;              /* 0 gim_nikravesh, 1 fiala */
  double axis[3];         /* spin axis, global at t = 0 */
  double radius, width, kz, cz, ks, ka, kg, mu0, mu1, crr;
  double low_speed;       /* slip regularization velocity, m/s */
  double damping_blend;   /* deflection over which the radial damping fades in, m */
} ir_tyre;

typedef enum { LAW_NONE = 0, LAW_LINEAR, LAW_POWER, LAW_TABLE } ir_law_kind;

/* Force law F(x): LINEAR F = coef x; POWER F = coef sign(x) |x|^exponent;
 * TABLE: piecewise linear through (x_k, F_k), extrapolated linearly. */
typedef struct {
  ir_law_kind kind;
  double coef, exponent;
  double *table;  /* ntable pairs x0,F0,x1,F1,... (x strictly rising) */
  int ntable;
  ir_loc loc;
} ir_law;

typedef enum { FRAME_GLOBAL, FRAME_BODY } ir_frame;

typedef struct {
  char *name;
  ir_loc loc;
  ir_force_kind kind;
  int body[2];        /* POINT_FORCE/TORQUE use body[0]; body[1] = -1 */
  ir_loc body_loc[2];
  int node[2];        /* FE node on a flexible body, or -1 */
  double point[2][3]; /* global application points (spring ends; bushing: both = point) */
  /* point force / torque: value(t) = vector * scale(t) (scale: constant 1 if absent) */
  double vector[3];
  ir_frame frame;     /* vector fixed in global axes or in the body's axes */
  ir_profile scale;
  /* spring-damper: tension T = stiffness(L - free_length) + damping(dL/dt) + preload */
  ir_law stiffness, damping;
  double free_length; /* defaults to the initial length */
  double preload;
  /* bushing: in the frame 'axes' (rows are the global x, y, z axes of the
     bushing frame at t = 0; default identity), forces -k x - c v + preload */
  double k6[6], c6[6], preload6[6];
  double axes[9];     /* rows: the element frame's x, y, z (beam: x along it, y the section's) */
  /* field: 6x6 stiffness and damping, row-major, in the frame 'axes' */
  double K[36], C[36];
  /* beam: section and material (node[] unused), damping = ratio * stiffness */
  ir_beam beam;
  double damping_ratio;
  ir_tyre tyre;
  /* superelement with more than two interface nodes: nsuper nodes, node k
     on body super_body[k] at global point super_point[3k..] (nodes 0 and 1
     also in body[], point[]); super_K, super_C: (6 (nsuper - 1))^2
     row-major, nodes 1.. with node 0 held; 0 / NULL otherwise */
  int nsuper;
  int *super_body;
  double *super_point, *super_K, *super_C;
  bool active;
} ir_force;

/* --- outputs ----------------------------------------------------------------------- */
typedef enum {
  OUT_POSITION,             /* body (or point on it) position, global: 3 columns or one */
  OUT_ORIENTATION,          /* Euler parameters: 4 columns */
  OUT_ANGLE,                /* rotation angle about 'axis' (global), unwrapped: 1 column */
  OUT_VELOCITY,             /* global, 3 or 1 */
  OUT_ANGULAR_VELOCITY,     /* global, 3 or 1 */
  OUT_ACCELERATION,         /* global, 3 or 1 */
  OUT_ANGULAR_ACCELERATION, /* global, 3 or 1 */
  OUT_REACTION,             /* joint: force (3) and torque (3) on body[1] at its point, global */
  OUT_EFFORT,               /* driver: torque or force along the joint axis: 1 */
  OUT_KINETIC_ENERGY,       /* system: 1 */
  OUT_POTENTIAL_ENERGY,     /* system, gravity and springs: 1 */
  OUT_TOTAL_ENERGY,         /* system: 1 */
  OUT_DEFLECTION,           /* flexible body: node deflection X_k w, body axes: 3 or 1 */
  OUT_MODAL,                /* flexible body: modal coordinate 'mode' (1-based in the model) */
  OUT_MOMENTUM,             /* system: linear and angular momentum (about the origin): 6 */
  OUT_SECTION,              /* flexible body: a beam's section forces at one end (6 or 1), or the
                               normal stress at a point of the section (1) */
  OUT_FORCE,                /* force element: force and torque on its body 1 at its point: 6 or 1 */
  OUT_RELATIVE,             /* motion of a marker relative to another, in a body's axes: 3 or 1 */
  OUT_JOINT,                /* joint angle and/or travel from t = 0: 1 or 2 */
  OUT_CENTER_OF_MASS,       /* system (or a subset of bodies): 3 or 1 */
  OUT_TYRE                  /* tyre force element: Fx Fy Fz Mx My Mz slip slip_angle camber
                               deflection (10 or 1) */
} ir_output_kind;

/* OUT_RELATIVE and OUT_CENTER_OF_MASS: what is measured */
typedef enum { QUANTITY_POSITION, QUANTITY_VELOCITY, QUANTITY_ACCELERATION } ir_quantity;

typedef struct {
  char *name;
  ir_loc loc;
  ir_output_kind kind;
  int body;          /* or -1 */
  int joint;         /* or -1 */
  int driver;        /* or -1 */
  int node;          /* or -1 */
  int chord[2];      /* DEFLECTION: measured from the chord between these nodes, or -1 */
  int mode;          /* MODAL: 0-based mode index */
  bool has_point;
  double point[3];   /* global point on the body at t = 0 */
  double axis[3];    /* OUT_ANGLE: unit axis */
  int component;     /* -1: all components; 0, 1, 2: x, y, z only */
  double scale;      /* multiply the output by this (default 1) */
  int element, end;  /* SECTION: the beam (index into the body's beams) and its end (0: A, 1: B) */
  bool has_fiber;    /* SECTION: the stress at fiber (y, z) of the section, element axes */
  double fiber[2];
  int force;         /* FORCE, TYRE: index into ir_model.forces; FORCE: component 6 is the tension */
  ir_quantity quantity; /* RELATIVE, CENTER_OF_MASS */
  int rel_body;      /* RELATIVE: the marker measured from ('relative_to'; 0: ground) */
  int rel_node;      /*   its FE node, or -1 */
  bool rel_has_point;
  double rel_point[3]; /* its global point at t = 0 */
  int frame_body;    /* RELATIVE: the body whose axes resolve the result; 0: global */
  int *cm_bodies;    /* CENTER_OF_MASS: the bodies (indices into bodies), or NULL for all */
  int ncm_bodies;
} ir_output;

/* --- simulation settings --------------------------------------------------------------- */
/* the same numbers as the runtime's MB_RK4, MB_DOPRI5, MB_GENALPHA, MB_AUTO */
typedef enum { INTEGRATOR_RK4, INTEGRATOR_DOPRI5, INTEGRATOR_GENALPHA, INTEGRATOR_AUTO } ir_integrator;
/* the order of the reader's names; ldl (the emitted LDL^T) last so that the
 * numbers of the older two stay */
typedef enum { SOLVER_KLU, SOLVER_DENSE, SOLVER_LDL } ir_solver;
typedef enum { STAB_PROJECTION, STAB_BAUMGARTE, STAB_NONE } ir_stab;
typedef enum { JOF_DIRECT, JOF_VIRTUAL, JOF_LIST } ir_jof;

typedef struct {
  double end_time;      /* default 1 */
  double output_step;   /* default end_time / 100 */
  double step;          /* RK4 step, DOPRI5 initial step; default output_step / 10 */
  double rtol, atol;    /* DOPRI5; defaults 1e-6, 1e-8 */
  double min_step, max_step; /* DOPRI5; defaults 1e-12, end_time */
  ir_integrator integrator;  /* default dopri5 */
  ir_solver solver;          /* default ldl: the emitted LDL^T (the generic path: klu) */
  ir_stab stabilization;     /* default projection */
  double baumgarte_alpha, baumgarte_beta; /* defaults 10, 10 */
  double rho_inf;            /* generalized-alpha; default 0.8 */
  ir_jof joints_on_flexible; /* default direct */
  bool equilibrium;          /* static equilibrium before the run; default false */
} ir_sim;

/* --- parameters and expressions (compiler/front/params.c) ------------------------------ */
/* An arithmetic expression over parameters, as a small tree of nodes (index
 * 'root'); 'pos' is each node's byte offset in the scalar, for messages. */
typedef enum {
  EXPR_NUMBER, EXPR_PARAM, EXPR_NEG, EXPR_ADD, EXPR_SUB, EXPR_MUL, EXPR_DIV, EXPR_POW, EXPR_CALL
} ir_expr_op;

typedef struct {
  ir_expr_op op;
  double number;  /* NUMBER */
  int param;      /* PARAM: index into ir_model.params; CALL: the function (params.c) */
  int a, b;       /* operands (b: -1 when unary) */
  int pos;
} ir_expr_node;

typedef struct {
  ir_expr_node *node;
  int count, root;
} ir_expr;

typedef struct {
  char *name;
  ir_loc loc;         /* its key in 'parameters:' */
  double value;       /* the default (or the --set override) */
  bool runtime;       /* an input of the generated code (mbcc run --set) */
  bool input;         /* runtime, and an input of the embedded API (<m>_set_input) */
  double min, max;    /* bounds of a run-time value (-inf, inf when not given) */
  char *unit;         /* documentation only, or NULL */
  ir_expr *expr;      /* its definition when not a plain number, else NULL */
  bool uses_runtime;  /* runtime, or defined through a run-time parameter */
  int state;          /* while reading: 0 not evaluated, 1 being evaluated, 2 done, 3 failed */
} ir_param;

typedef enum { RULE_ANY, RULE_NONNEGATIVE, RULE_POSITIVE } ir_value_rule;

/* A numeric field of the model written as an expression that names parameters. */
typedef struct {
  ir_loc loc;
  ir_expr *expr;
  double value;
  bool uses_runtime;
  bool pruned;        /* in a body, joint, driver or force that the scene removed */
  /* the rule the reader checks the field's value against, recorded where it
     checks it (params_note_rule), so that a run-time value is checked the
     same way (--set, sweeps, the generated set_params) */
  ir_value_rule rule;
  char field[40];     /* the field's key as the message names it, e.g. 'stiffness' */
} ir_expr_use;

/* --- the model ------------------------------------------------------------------------- */
typedef struct {
  char *path;        /* the file read */
  char *name;
  char *scene;       /* the scene applied, or NULL */
  double gravity[3]; /* default 0 */
  ir_body *bodies;   /* bodies[0] is the implicit ground */
  int nbodies;
  ir_joint *joints;
  int njoints;
  ir_driver *drivers;
  int ndrivers;
  ir_force *forces;
  int nforces;
  ir_road *roads;    /* top-level 'roads' */
  int nroads;
  ir_output *outputs;
  int noutputs;
  ir_sim sim;
  ir_param *params;     /* 'parameters:' in file order */
  int nparams;
  ir_expr_use *uses;    /* fields given by expressions over parameters, in reading order */
  int nuses, cap_uses;
  char **included;   /* files read through 'include:' (the input hash covers them) */
  char *pruned;      /* what the scene removed, one line each ("body 'x'"), or NULL */
  int nincluded;
} ir_model;

/* Read and validate a model, applying scene 'scene' (NULL: the base model).
 * On any error, prints GNU-style diagnostics "file:line:col: error: ..." to
 * stderr and returns NULL. */
ir_model *ir_read(const char *path, const char *scene);
void ir_free(ir_model *m);

int ir_find_body(const ir_model *m, const char *name);   /* -1 if absent */
int ir_find_joint(const ir_model *m, const char *name);

#endif
