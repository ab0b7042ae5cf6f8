/* pipeline.c: the stages in order, each product built once into the unit. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "params.h"
#include "unit.h"
#include "scene.h"
#include <stdlib.h>

/* FNV-1a 64 step over n bytes */
static uint64_t fnv1a(uint64_t h, const unsigned char *b, size_t n) {
  for (size_t i = 0; i < n; i++) {
    h ^= b[i];
    h *= 0x100000001b3ULL;
  }
  return h;
}

/* folds the bytes of file 'path' into *h; 2 after reporting */
static int hash_file(const char *path, uint64_t *h) {
  FILE *f = fopen(path, "rb");
  if (!f) {
    diag_error(path, (ir_loc){0, 0}, "cannot read the model file again to hash it");
    return 2;
  }
  unsigned char buf[8192];
  size_t n;
  while ((n = fread(buf, 1, sizeof buf, f)) > 0) *h = fnv1a(*h, buf, n);
  int bad = ferror(f);
  fclose(f);
  if (bad) {
    diag_error(path, (ir_loc){0, 0}, "cannot read the model file again to hash it");
    return 2;
  }
  return 0;
}

/* a scene's modal changes drop the outputs of modes gone (scene.c); 2 when out of memory */
static int drop_modal_outputs(ir_model *ir, const flex_product *flex) {
  if (!ir->scene) return 0;
  int *modes = calloc((size_t)ir->nbodies + 1, sizeof *modes);
  if (!modes) return 2;
  for (int b = 0; b < ir->nbodies; b++)
    modes[b] = ir->bodies[b].kind == BODY_FLEXIBLE ? flex->data[b].flex.nm : 0;
  scene_drop_modal_outputs(ir, modes);
  free(modes);
  return 0;
}

/* the input hash (unit.h); 0 after reporting if the file cannot be read */
static int hash_input(mbc_unit *u) {
  uint64_t h = 0xcbf29ce484222325ULL;
  if (hash_file(u->path, &h)) return 2;
  /* included files, and the recorded motion of a rig, after the model's
     own bytes (a model without them hashes as before) */
  for (int i = 0; i < u->ir->nincluded; i++)
    if (hash_file(u->ir->included[i], &h)) return 2;
  h = fnv1a(h, (const unsigned char *)"", 1);
  if (u->scene) h = fnv1a(h, (const unsigned char *)u->scene, strlen(u->scene));
  u->input_hash = h;
  return 0;
}

int mbc_unit_read(mbc_unit *u, const char *path, const char *scene) {
  memset(u, 0, sizeof *u);
  u->path = path;
  u->scene = scene;
  const char *slash = strrchr(path, '/');
  u->file_name = slash ? slash + 1 : path;
  u->ir = ir_read(path, scene);
  if (!u->ir) return 2;
  if (hash_input(u)) {
    mbc_unit_free(u);
    return 2;
  }
  return 0;
}

/* the first run-time parameter that use i depends on (for messages) */
static const char *runtime_name(const ir_model *ir, const ir_expr *e) {
  for (int k = 0; k < ir->nparams; k++)
    if (ir->params[k].uses_runtime && expr_names(e, k)) {
      const ir_param *P = &ir->params[k];
      if (P->runtime || !P->expr) return P->name;
      return runtime_name(ir, P->expr);
    }
  return "?";
}

static bool same(double a, double b) { return memcmp(&a, &b, sizeof a) == 0; }

/* The attachment points of force elements written as expressions over
 * run-time parameters (B: the model read with the parameters moved): each
 * moved coordinate of a force's global point must equal, in both readings, a
 * field of the model; its marker's body-frame offset then follows it at run
 * time (set_params writes markers[k].s).  Markers on flexible nodes and tyres
 * are not supported: a located error. */
static int bind_force_points(mbc_unit *u, const ir_model *B, const lmodel *LB, bool *bound, const ir_param *first) {
  const ir_model *A = u->ir;
  lmodel *LA = u->lowered;
  int rc = 0;
  for (int k = 0; k < LA->m.nforce; k++) {
    const mb_forcedef *d = &LA->force[k];
    const ir_force *FA = &A->forces[LA->force_ir[k]], *FB = &B->forces[LB->force_ir[k]];
    for (int side = 0; side < 2; side++) {
      int mk = side ? d->m1 : d->m0;
      if (mk < 0) continue;
      for (int j = 0; j < 3; j++) {
        double a = FA->point[side][j], b = FB->point[side][j];
        if (same(a, b)) continue;
        const mb_markerdef *M = &LA->marker[mk];
        int use = -1;
        for (int pass = 0; pass < 2 && use < 0; pass++)
          for (int i = 0; i < A->nuses && use < 0; i++)
            if (A->uses[i].uses_runtime && (pass || !bound[i]) && same(A->uses[i].value, a) && same(B->uses[i].value, b))
              use = i;
        const char *why = use < 0 ? "its point is derived from the parameter rather than written in its field"
                          : M->node >= 0 ? "the point is on a flexible body's node"
                          : d->kind == MB_FORCE_TYRE ? "a tyre's wheel centre is fixed at compile time" : NULL;
        if (why) {
          diag_error(u->path, FA->loc, "force '%s': run-time parameter '%s' moves its attachment point, but %s "
                     "(run-time points are supported for force elements on rigid bodies and the ground, written "
                     "as global coordinates in 'point' fields); make the parameter compile-time (drop 'runtime: "
                     "true')", FA->name, first->name, why);
          rc = 2;
          continue;
        }
        bound[use] = true;
        runtime_binding *bd = &u->bind[u->nbind++];
        *bd = (runtime_binding){.pool = BIND_MARKER_POINT, .index = mk, .use = use, .force = k};
        bd->component = j;
        bd->side = side;
        static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        if (M->body < 0) {
          memcpy(bd->frame_A, I3, sizeof I3);
        } else {
          const double *q = LA->q0 + LA->body[M->body].qadr;
          mb_euler_to_A(q + 3, bd->frame_A);
          memcpy(bd->frame_r, q, sizeof bd->frame_r);
        }
        LA->marker_runtime[mk] = 1;
      }
    }
  }
  return rc;
}

/* the field of ir->uses that holds value a in the model as read and b in the
 * model read with the run-time parameters moved (B), a field of its own first
 * (equal values written several times); -1: none */
static int find_use(const ir_model *A, const ir_model *B, const bool *bound, double a, double b) {
  for (int pass = 0; pass < 2; pass++)
    for (int i = 0; i < A->nuses; i++)
      if (A->uses[i].uses_runtime && (pass || !bound[i]) && same(A->uses[i].value, a) && same(B->uses[i].value, b))
        return i;
  return -1;
}

const runtime_body *mbc_runtime_body(const mbc_unit *u, int b) {
  for (int i = 0; b >= 0 && i < u->nrbody; i++)
    if (u->rbody[i].body == b) return &u->rbody[i];
  return NULL;
}

/* the joint whose rows use marker k, and its side; -1: none */
static int marker_joint(const lmodel *L, int k, int *side) {
  for (int r = 0; r < L->m.nrow; r++) {
    const mb_rowdef *R = &L->row[r];
    if (R->joint < 0 || (R->m0 != k && R->m1 != k)) continue;
    *side = R->m1 == k;
    return R->joint;
  }
  return -1;
}

/* Run-time geometry: body positions and the points of joints (and of forces
 * on bodies that move) written as expressions over run-time parameters (B:
 * the model read with the parameters moved).  Each moved coordinate of a
 * rigid body's initial position must be its 'position' field; each moved
 * marker offset s = A^T (P - r) is then written by set_params from its point
 * P (the joint's or force's 'point' fields, literal or run-time) and r, and
 * the simulator re-assembles at start.  Markers on flexible bodies, tyres,
 * orientations: located errors. */
static int bind_geometry(mbc_unit *u, const ir_model *B, const lmodel *LB, bool *bound, const ir_param *first) {
  const ir_model *A = u->ir;
  lmodel *LA = u->lowered;
  int rc = 0;
  u->rbody = calloc((size_t)LA->m.nbody + 1, sizeof *u->rbody);
  u->rmark = calloc((size_t)(LA->m.nmarker + LA->m.noutput) + 1, sizeof *u->rmark);
  if (!u->rbody || !u->rmark) {
    diag_error(u->path, (ir_loc){0, 0}, "out of memory while binding run-time parameters");
    return 2;
  }
  for (int b = 0; b < LA->m.nbody && b + 1 < A->nbodies; b++) {
    const double *qa = LA->q0 + LA->body[b].qadr, *qb = LB->q0 + LB->body[b].qadr;
    const ir_body *IB = &A->bodies[b + 1];
    if (memcmp(qa + 3, qb + 3, 4 * sizeof *qa)) {
      diag_error(u->path, IB->loc, "body '%s': run-time parameter '%s' turns its initial orientation, which "
                 "stays compile-time (run-time geometry: joint points and body positions); make the "
                 "parameter compile-time (drop 'runtime: true')", IB->name, first->name);
      rc = 2;
      continue;
    }
    runtime_body rb = {.body = b, .use = {-1, -1, -1}};
    int moved = 0;
    for (int j = 0; j < 3; j++) {
      rb.r[j] = qa[j];
      if (same(qa[j], qb[j])) continue;
      int use = find_use(A, B, bound, qa[j], qb[j]);
      const char *why = use < 0 ? "its position is derived from the parameter rather than written in its field"
                        : LA->body[b].kind != MB_BODY_RIGID ? "it is not a rigid body" : NULL;
      if (why) {
        diag_error(u->path, IB->loc, "body '%s': run-time parameter '%s' moves its initial position, but %s "
                   "(run-time positions are supported for rigid bodies, written in their 'position' field); "
                   "make the parameter compile-time (drop 'runtime: true')", IB->name, first->name, why);
        rc = 2;
        continue;
      }
      bound[use] = true;
      rb.use[j] = use;
      moved = 1;
    }
    if (moved) u->rbody[u->nrbody++] = rb;
  }
  for (int k = 0; k < LA->m.nmarker; k++) {
    const mb_markerdef *M = &LA->marker[k];
    if (LA->marker_runtime[k] || !memcmp(M->s, LB->marker[k].s, sizeof M->s)) continue;
    int side = 0, joint = marker_joint(LA, k, &side), force = -1;
    for (int e = 0; e < LA->m.nforce && joint < 0 && force < 0; e++)
      if (LA->force[e].m0 == k || LA->force[e].m1 == k) {
        force = e;
        side = LA->force[e].m1 == k;
      }
    const double *PA = NULL, *PB = NULL;
    const char *owner = "?";
    ir_loc loc = LA->marker_loc[k];
    if (joint >= 0) {
      PA = A->joints[joint].point[side];
      PB = B->joints[joint].point[side];
      owner = A->joints[joint].name;
    } else if (force >= 0) {
      PA = A->forces[LA->force_ir[force]].point[side];
      PB = B->forces[LB->force_ir[force]].point[side];
      owner = A->forces[LA->force_ir[force]].name;
    }
    runtime_marker rm = {.marker = k, .output = -1, .body = M->body, .use = {-1, -1, -1}};
    snprintf(rm.what, sizeof rm.what, "%s '%s', point %d", joint >= 0 ? "joint" : "force", owner, side);
    const char *why = !PA ? "the marker is not a joint's or a force's point"
                      : M->node >= 0 || (M->body >= 0 && LA->body[M->body].kind != MB_BODY_RIGID)
                      ? "the point is on a flexible body's node or a virtual body"
                      : force >= 0 && LA->force[force].kind == MB_FORCE_TYRE ? "a tyre's wheel centre is fixed at compile time"
                      : NULL;
    for (int j = 0; j < 3 && !why; j++) {
      rm.P[j] = PA[j];
      if (same(PA[j], PB[j])) continue;
      rm.use[j] = find_use(A, B, bound, PA[j], PB[j]);
      if (rm.use[j] < 0) why = "the point is derived from the parameter rather than written in its 'point' field";
      else bound[rm.use[j]] = true;
    }
    if (why) {
      diag_error(u->path, loc, "%s: run-time parameter '%s' moves its point, but %s (run-time geometry is "
                 "supported for joint and force points on rigid bodies and the ground, written as global "
                 "coordinates in 'point' fields, and for rigid bodies' positions); make the parameter "
                 "compile-time (drop 'runtime: true')", rm.what, first->name, why);
      rc = 2;
      continue;
    }
    static const double I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (M->body < 0) {
      memcpy(rm.frame_A, I3, sizeof I3);
    } else {
      const double *q = LA->q0 + LA->body[M->body].qadr;
      mb_euler_to_A(q + 3, rm.frame_A);
      memcpy(rm.frame_r, q, sizeof rm.frame_r);
    }
    u->rmark[u->nrmark++] = rm;
    LA->marker_runtime[k] = 1;
  }
  /* outputs measure points in body axes, taken at the lowered q0: those on
     bodies that move follow them (set_params writes outputs[k].s) */
  for (int k = 0; k < LA->m.noutput; k++) {
    const mb_outputdef *OA = &LA->output[k], *OB = &LB->output[k];
    bool moved_s = memcmp(OA->s, OB->s, sizeof OA->s) != 0;
    if (!moved_s && !memcmp(OA->s2, OB->s2, sizeof OA->s2)) continue;
    const ir_output *IO = &A->outputs[k];
    bool point_kind = OA->kind == MB_OUT_POSITION || OA->kind == MB_OUT_VELOCITY || OA->kind == MB_OUT_ACCELERATION;
    runtime_marker rm = {.marker = -1, .output = k, .body = OA->body, .use = {-1, -1, -1}};
    snprintf(rm.what, sizeof rm.what, "output '%s', point", IO->name);
    const char *why = !moved_s || !point_kind ? "it is not a position, velocity or acceleration output's point"
                      : OA->body < 0 || OA->node >= 0 || LA->body[OA->body].kind != MB_BODY_RIGID
                      ? "it is not on a rigid body's frame" : NULL;
    for (int j = 0; j < 3 && !why; j++) {
      rm.P[j] = IO->point[j];
      if (same(IO->point[j], B->outputs[k].point[j])) continue;
      rm.use[j] = find_use(A, B, bound, IO->point[j], B->outputs[k].point[j]);
      if (rm.use[j] < 0) why = "the point is derived from the parameter rather than written in its 'point' field";
      else bound[rm.use[j]] = true;
    }
    if (why) {
      diag_error(u->path, IO->loc, "output '%s': run-time parameter '%s' moves the point it measures, but %s; "
                 "make the parameter compile-time (drop 'runtime: true')", IO->name, first->name, why);
      rc = 2;
      continue;
    }
    const double *q = LA->q0 + LA->body[OA->body].qadr;
    mb_euler_to_A(q + 3, rm.frame_A);
    memcpy(rm.frame_r, q, sizeof rm.frame_r);
    u->rmark[u->nrmark++] = rm;
  }
  /* a marker at its body's origin has no rotational columns in the pattern:
     one that moves at run time needs them (lower.c, marker_offset) */
  int rebuild = 0;
  for (int i = 0; i < u->nrmark; i++) {
    if (u->rmark[i].marker < 0) continue;
    const double *s0 = LA->marker[u->rmark[i].marker].s;
    rebuild |= u->rmark[i].body >= 0 && s0[0] == 0 && s0[1] == 0 && s0[2] == 0;
  }
  if (!rc && rebuild && lower_pattern(LA)) {
    diag_error(u->path, (ir_loc){0, 0}, "out of memory while binding run-time parameters");
    rc = 2;
  }
  return rc;
}

/* whether expression e depends on parameter k (directly, or through
 * parameters defined by expressions) */
static bool expr_depends(const ir_model *ir, const ir_expr *e, int k) {
  if (expr_names(e, k)) return true;
  for (int i = 0; i < ir->nparams; i++)
    if (i != k && ir->params[i].uses_runtime && !ir->params[i].runtime && ir->params[i].expr &&
        expr_names(e, i) && expr_depends(ir, ir->params[i].expr, k))
      return true;
  return false;
}

bool mbc_param_moves_assembly(const mbc_unit *u, int k) {
  const ir_model *ir = u->ir;
  for (int i = 0; i < u->nrbody; i++)
    for (int j = 0; j < 3; j++)
      if (u->rbody[i].use[j] >= 0 && expr_depends(ir, ir->uses[u->rbody[i].use[j]].expr, k)) return true;
  for (int i = 0; i < u->nrmark; i++)
    for (int j = 0; j < 3; j++)
      if (u->rmark[i].use[j] >= 0 && expr_depends(ir, ir->uses[u->rmark[i].use[j]].expr, k)) return true;
  return false;
}

/* Which pool entries of the lowered model the run-time parameters set.  The
 * model is read and lowered a second time with every run-time parameter
 * moved a little (by a different fraction each); an entry of the force pools
 * that moves must equal, in both readings, a field written as an expression
 * over run-time parameters: it is then bound to that expression.  A moved
 * expression that lands nowhere in the pools (a mass, a point, a table), a
 * pool entry derived from one, or any other change of the lowered model is
 * an error: the generated code fixes those at compile time. */
static int bind_runtime(mbc_unit *u) {
  const ir_model *A = u->ir;
  const lmodel *LA = u->lowered;
  int nrt = 0;
  for (int k = 0; k < A->nparams; k++) nrt += A->params[k].runtime;
  if (!nrt) return 0;
  const char **names = calloc((size_t)nrt, sizeof *names);
  double *values = calloc((size_t)nrt, sizeof *values);
  bool *bound = calloc((size_t)A->nuses + 1, sizeof *bound);
  u->bind = calloc((size_t)(LA->m.nforce_prm + 2 * LA->m.nforce_law + 6 * LA->m.nforce) + 1, sizeof *u->bind);
  u->lowered->prm_runtime = calloc((size_t)LA->m.nforce_prm + 1, 1);
  u->lowered->marker_runtime = calloc((size_t)LA->m.nmarker + 1, 1);
  if (!names || !values || !bound || !u->bind || !u->lowered->prm_runtime || !u->lowered->marker_runtime) {
    free(names); free(values); free(bound);
    diag_error(u->path, (ir_loc){0, 0}, "out of memory while binding run-time parameters");
    return 2;
  }
  const ir_param *first = NULL;
  for (int k = 0, j = 0; k < A->nparams; k++) {
    const ir_param *P = &A->params[k];
    if (!P->runtime) continue;
    if (!first) first = P;
    double step = (P->value != 0 ? fabs(P->value) : 1) * ldexp(1 + 0.37 * j, -12);
    names[j] = P->name;
    values[j] = P->value + step <= P->max ? P->value + step : P->value - step;
    j++;
  }
  int errors = diag_errors();
  params_set_overrides(names, values, nrt);
  diag_mute(1);
  ir_model *B = ir_read(u->path, u->scene);
  flex_product flexB;
  memset(&flexB, 0, sizeof flexB);
  lmodel *LB = B && !flex_reduce(B, &flexB) && !drop_modal_outputs(B, &flexB) ? lower_model(B, &flexB) : NULL;
  diag_mute(0);
  params_set_overrides(NULL, NULL, 0);
  int rc = 0;
  if (!LB || diag_errors() > errors || B->nuses != A->nuses || LB->m.nforce_prm != LA->m.nforce_prm ||
      LB->m.nforce_law != LA->m.nforce_law || LB->m.nbody != LA->m.nbody || LB->m.nmarker != LA->m.nmarker ||
      LB->m.nrow != LA->m.nrow || LB->m.nforce != LA->m.nforce) {
    diag_error(u->path, first->loc,
               "moving run-time parameter '%s' a little changes the model's structure or makes it invalid: "
               "it must be compile-time (drop 'runtime: true')", first->name);
    rc = 2;
    goto done;
  }
  /* the pools: force_prm, then each law's coefficient and exponent */
  for (int s = 0; s < LA->m.nforce_prm + 2 * LA->m.nforce_law; s++) {
    runtime_pool pool = s < LA->m.nforce_prm ? BIND_PRM : (s - LA->m.nforce_prm) % 2 ? BIND_LAW_EXPONENT : BIND_LAW_COEF;
    int index = pool == BIND_PRM ? s : (s - LA->m.nforce_prm) / 2;
    double a = pool == BIND_PRM ? LA->force_prm[index] : pool == BIND_LAW_COEF ? LA->force_law[index].coef : LA->force_law[index].exponent;
    double b = pool == BIND_PRM ? LB->force_prm[index] : pool == BIND_LAW_COEF ? LB->force_law[index].coef : LB->force_law[index].exponent;
    if (same(a, b)) continue;
    int force = 0;
    for (int k = 0; k < LA->m.nforce; k++) {
      const mb_forcedef *d = &LA->force[k];
      if (pool == BIND_PRM ? index >= d->padr && index < d->padr + d->pnum : index >= d->ladr && index < d->ladr + d->lnum)
        force = k;
    }
    /* equal values written several times ([k, k, k]): each slot takes a field of its own first */
    int use = -1;
    for (int pass = 0; pass < 2 && use < 0; pass++)
      for (int i = 0; i < A->nuses && use < 0; i++)
        if (A->uses[i].uses_runtime && (pass || !bound[i]) && same(A->uses[i].value, a) && same(B->uses[i].value, b))
          use = i;
    const ir_force *F = &A->forces[LA->force_ir[force]];
    if (use < 0) {
      diag_error(u->path, F->loc, "force '%s' uses a value derived from run-time parameter '%s' (only values written "
                 "in its fields can be run-time: stiffness, damping, preload, free length, force and torque "
                 "values, attachment points; a spring's free length measured from run-time points must be "
                 "written as 'free_length'); make the parameter compile-time (drop 'runtime: true')", F->name, first->name);
      rc = 2;
      continue;
    }
    bound[use] = true;
    u->bind[u->nbind++] = (runtime_binding){.pool = pool, .index = index, .use = use, .force = force};
    if (pool == BIND_PRM) u->lowered->prm_runtime[index] = 1;
  }
  if (bind_force_points(u, B, LB, bound, first)) rc = 2;
  if (bind_geometry(u, B, LB, bound, first)) rc = 2;
  for (int k = 0; k < A->nparams; k++) /* the embedded step API sets inputs without re-assembling */
    if (A->params[k].input && mbc_param_moves_assembly(u, k)) {
      diag_error(u->path, A->params[k].loc, "input parameter '%s' moves joint points or body positions, which "
                 "are re-assembled only at start: it cannot be an input (drop 'input: true')", A->params[k].name);
      rc = 2;
    }
  for (int i = 0; i < A->nuses; i++)
    if (A->uses[i].uses_runtime && !A->uses[i].pruned && !bound[i] && !same(A->uses[i].value, B->uses[i].value)) {
      diag_error(u->path, A->uses[i].loc,
                 "this value depends on run-time parameter '%s', but the generated code fixes it at compile "
                 "time (run-time parameters can set force-element constants: stiffness, damping, preload, free "
                 "length, force and torque values, the attachment points of force elements and the points of "
                 "joints on rigid bodies and the ground, and rigid bodies' initial positions; not orientations, "
                 "axes, masses, inertia, flexible bodies or gravity); make the parameter compile-time (drop "
                 "'runtime: true')",
                 runtime_name(A, A->uses[i].expr));
      rc = 2;
    }
  /* anything else that moved: the bodies, the markers, the rows, gravity */
  bool moved = memcmp(LA->m.gravity, LB->m.gravity, sizeof LA->m.gravity) != 0;
  for (int b = 0; b < LA->m.nbody && !moved; b++)
    moved = !same(LA->body[b].mass, LB->body[b].mass) || memcmp(LA->body[b].J, LB->body[b].J, sizeof LA->body[b].J);
  for (int k = 0; k < LA->m.nmarker && !moved; k++)
    moved = (!LA->marker_runtime[k] && memcmp(LA->marker[k].s, LB->marker[k].s, sizeof LA->marker[k].s)) ||
            memcmp(LA->marker[k].C, LB->marker[k].C, sizeof LA->marker[k].C);
  for (int k = 0; k < LA->m.nrow && !moved; k++) moved = !same(LA->row[k].L, LB->row[k].L);
  if (moved && !rc) {
    diag_error(u->path, first->loc, "run-time parameter '%s' changes the model's masses, geometry or gravity, which "
               "the generated code fixes at compile time (of the geometry, joint and force points and rigid "
               "bodies' positions can be run-time, not a distance joint's length, axes or orientations): make it "
               "compile-time (drop 'runtime: true')", first->name);
    rc = 2;
  }
done:
  if (LB) lower_free(LB);
  flex_product_free(&flexB);
  ir_free(B);
  free(names);
  free(values);
  free(bound);
  return rc;
}

int mbc_check_runtime_rules(const mbc_unit *u, const double *p, const char *context) {
  const ir_model *ir = u->ir;
  int rc = 0;
  for (int i = 0; i < u->nbind; i++) {
    const ir_expr_use *use = &ir->uses[u->bind[i].use];
    if (use->rule == RULE_ANY) continue;
    double v = expr_eval_runtime(ir, use->expr, p);
    if (params_rule_holds(use->rule, v)) continue;
    const ir_force *F = &ir->forces[u->lowered->force_ir[u->bind[i].force]];
    diag_error(ir->path, use->loc, "%s: %s of force '%s' would be %g, but it %s (it depends on run-time parameter "
               "'%s')", context, use->field, F->name, v, params_rule_text(use->rule), runtime_name(ir, use->expr));
    rc = 2;
  }
  return rc;
}

int mbc_unit_finish(mbc_unit *u, int verbose) {
  if (flex_reduce(u->ir, &u->flex)) return 2;
  if (drop_modal_outputs(u->ir, &u->flex)) return 2;
  u->lowered = lower_model(u->ir, &u->flex);
  if (!u->lowered) {
    if (!diag_errors()) diag_error(u->path, (ir_loc){0, 0}, "out of memory while lowering");
    return 2;
  }
  if (!u->overridden && bind_runtime(u)) return 2;
  if (assemble_model(u->lowered, verbose)) return 2;
  /* the plan reads the assembled model: removed rows and the values at t = 0 */
  u->have_plan = !ldl_plan_build(u->lowered, &u->plan);
  return 0;
}

int mbc_unit_build(mbc_unit *u, const char *path, const char *scene, int verbose) {
  if (mbc_unit_read(u, path, scene)) return 2;
  return mbc_unit_finish(u, verbose);
}

void mbc_unit_free(mbc_unit *u) {
  if (u->have_plan) ldl_plan_free(&u->plan);
  free(u->bind);
  free(u->rmark);
  free(u->rbody);
  if (u->lowered) {
    free(u->lowered->prm_runtime);
    free(u->lowered->marker_runtime);
    lower_free(u->lowered);
  }
  flex_product_free(&u->flex);
  if (u->ir) ir_free(u->ir);
  memset(u, 0, sizeof *u);
}
