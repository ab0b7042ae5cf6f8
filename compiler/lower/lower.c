/* lower.c: lowers the IR to coordinates, markers, constraint rows, force and
 * output tables, and works out the fixed CSC pattern of K = [M D^T; D 0]. */
#define _POSIX_C_SOURCE 200809L
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "lower.h"
#include "element.h"

/* The IR's profile and law kinds are copied into the runtime's by value
   (lower_add_profile, the spring's laws): the two enumerations must agree. */
_Static_assert((int)PROFILE_CONSTANT == (int)MB_PROFILE_CONSTANT &&
                   (int)PROFILE_CONSTANT_VELOCITY == (int)MB_PROFILE_CONSTANT_VELOCITY &&
                   (int)PROFILE_POLYNOMIAL == (int)MB_PROFILE_POLYNOMIAL &&
                   (int)PROFILE_RAMP == (int)MB_PROFILE_RAMP && (int)PROFILE_SINE == (int)MB_PROFILE_SINE &&
                   (int)PROFILE_TABLE == (int)MB_PROFILE_TABLE,
               "ir_profile_kind and mb_profile_kind differ");
_Static_assert((int)LAW_NONE == (int)MB_LAW_NONE && (int)LAW_LINEAR == (int)MB_LAW_LINEAR &&
                   (int)LAW_POWER == (int)MB_LAW_POWER && (int)LAW_TABLE == (int)MB_LAW_TABLE,
               "ir_law_kind and mb_law_kind differ");

static char *xstrdup_printf(const char *fmt, const char *a, const char *b, const char *c) {
  char buf[512];
  snprintf(buf, sizeof buf, fmt, a, b, c);
  return strdup(buf);
}

/* global axes frame (columns x, y, z) from a z axis and an x reference */
static void frame_from_axes(const double z[3], const double xref[3], double C[9]) {
  double x[3], y[3];
  double d = mb_dot3(xref, z);
  for (int k = 0; k < 3; k++) x[k] = xref[k] - d * z[k];
  double n = sqrt(mb_dot3(x, x));
  for (int k = 0; k < 3; k++) x[k] /= n;
  mb_cross3(z, x, y);
  for (int k = 0; k < 3; k++) {
    C[3 * k + 0] = x[k];
    C[3 * k + 1] = y[k];
    C[3 * k + 2] = z[k];
  }
}

/* natural cubic spline second derivatives through ntable (t, x) pairs */
static void natural_spline(const double *d, int n, double *m2) {
  double *u = calloc((size_t)n, sizeof(double));
  m2[0] = m2[n - 1] = 0;
  if (u) {
    u[0] = 0;
    for (int i = 1; i < n - 1; i++) {
      double sig = (d[2 * i] - d[2 * i - 2]) / (d[2 * i + 2] - d[2 * i - 2]);
      double p = sig * m2[i - 1] + 2;
      m2[i] = (sig - 1) / p;
      double du = (d[2 * i + 3] - d[2 * i + 1]) / (d[2 * i + 2] - d[2 * i]) -
                  (d[2 * i + 1] - d[2 * i - 1]) / (d[2 * i] - d[2 * i - 2]);
      u[i] = (6 * du / (d[2 * i + 2] - d[2 * i - 2]) - sig * u[i - 1]) / p;
    }
    for (int i = n - 2; i >= 0; i--) m2[i] = m2[i] * m2[i + 1] + u[i];
    free(u);
  }
}

double *lower_force_prm(lmodel *L, mb_forcedef *d, int n) {
  size_t need = (size_t)L->m.nforce_prm + (size_t)n + 1;
  if (need > L->force_prm_cap) {
    size_t cap = 2 * need;
    double *p = realloc(L->force_prm, cap * sizeof *p);
    if (!p) { /* reported by lower_model after the element's hook */
      L->out_of_memory = 1;
      return NULL;
    }
    memset(p + L->force_prm_cap, 0, (cap - L->force_prm_cap) * sizeof *p);
    L->force_prm = p;
    L->force_prm_cap = cap;
  }
  d->padr = L->m.nforce_prm;
  d->pnum = n;
  L->m.nforce_prm += n;
  return L->force_prm + d->padr;
}

mb_law *lower_force_laws(lmodel *L, mb_forcedef *d, int n) {
  d->ladr = L->m.nforce_law;
  d->lnum = n;
  L->m.nforce_law += n;
  return L->force_law + d->ladr;
}

int lower_add_profile(lmodel *L, const ir_profile *p, int driver, int force) {
  int k = L->m.nprofile++;
  mb_profile *P = &L->profile[k];
  memset(P, 0, sizeof *P);
  P->kind = (mb_profile_kind)p->kind; /* the enumerations agree (asserted above) */
  for (int j = 0; j < 8; j++) P->c[j] = p->c[j];
  P->nc = p->nc;
  L->profile_driver[k] = driver;
  L->profile_force[k] = force;
  if (p->kind == PROFILE_TABLE) {
    L->table[k] = malloc(sizeof(double) * 2 * (size_t)p->ntable);
    L->spline[k] = malloc(sizeof(double) * (size_t)p->ntable);
    if (!L->table[k] || !L->spline[k]) return -1;
    memcpy(L->table[k], p->table, sizeof(double) * 2 * (size_t)p->ntable);
    natural_spline(p->table, p->ntable, L->spline[k]);
    P->ntable = p->ntable;
    P->table = L->table[k];
    P->spline = L->spline[k];
  }
  return k;
}

/* a marker on mb body b (-1: ground) at global point P with global axes Cg;
 * on FE node 'node' of a flexible body when node >= 0 */
static int add_marker(lmodel *L, int b, int node, const double P[3], const double Cg[9], char *desc,
                      ir_loc loc) {
  int k = L->m.nmarker++;
  mb_markerdef *d = &L->marker[k];
  L->marker_desc[k] = desc;
  L->marker_loc[k] = loc;
  d->body = b;
  d->node = -1;
  if (b < 0) {
    memcpy(d->s, P, sizeof(double) * 3);
    memcpy(d->C, Cg, sizeof(double) * 9);
    return k;
  }
  const double *q = L->q0 + L->body[b].qadr;
  double A[9], rel[3];
  mb_euler_to_A(q + 3, A);
  for (int j = 0; j < 3; j++) rel[j] = P[j] - q[j];
  mb_mul3t(A, rel, d->s);
  if (node >= 0 && L->body[b].kind == MB_BODY_FLEXIBLE) {
    const fe_modes *fm = &L->modes[b];
    d->node = node;
    if (node >= fm->nnodes) {
      diag_error(L->ir->path, loc, "%s: body '%s' has no node %d (it has %d)", desc,
                 L->body[b].name, node, fm->nnodes);
      L->bad = 1;
      return k;
    }
    /* the point given must be the node's (checked here for modal data files) */
    double off = 0;
    for (int j = 0; j < 3; j++) off += (d->s[j] - fm->x[3 * node + j]) * (d->s[j] - fm->x[3 * node + j]);
    if (sqrt(off) > 1e-6 * (1 + sqrt(mb_dot3(d->s, d->s)))) {
      diag_error(L->ir->path, loc, "%s: the point is %g from node %d of body '%s'", desc,
                 sqrt(off), node, L->body[b].name);
      L->bad = 1;
    }
    memcpy(d->s, fm->x + 3 * node, sizeof(double) * 3);
  }
  /* C = A^T Cg */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++)
      d->C[3 * i + j] = A[i] * Cg[j] + A[3 + i] * Cg[3 + j] + A[6 + i] * Cg[6 + j];
  return k;
}

int lower_force_marker(lmodel *L, const ir_force *F, int side, const double C[9]) {
  return add_marker(L, F->body[side] - 1, F->node[side], F->point[side], C,
                    xstrdup_printf("force '%s', on body '%s'%s", F->name,
                                   L->ir->bodies[F->body[side]].name, ""), F->body_loc[side]);
}

void lower_add_row(lmodel *L, mb_prim_kind kind, int m0, int m1, int a, int b, const char *what,
                   int joint, int driver, ir_loc loc, const char *elem, const char *ekind) {
  int r = L->m.nrow++;
  mb_rowdef *R = &L->row[r];
  memset(R, 0, sizeof *R);
  R->kind = kind;
  R->m0 = m0;
  R->m1 = m1;
  R->a = a;
  R->b = b;
  R->profile = -1;
  R->mslot[0] = R->mslot[1] = -1;
  R->joint = joint;
  R->driver = driver;
  L->row_desc[r] = xstrdup_printf("%s '%s': %s", ekind, elem, what);
  L->row_loc[r] = loc;
}

static const char *axis_name[3] = {"x", "y", "z"};

lmodel *lower_model(const ir_model *ir, const flex_product *flex) {
  lmodel *L = calloc(1, sizeof *L);
  if (!L) return NULL;
  L->ir = ir;
  int nb = ir->nbodies - 1;
  /* joints on flexible nodes lowered through virtual bodies: one body each */
  int nvirt_max = 0;
  for (int j = 0; j < ir->njoints; j++)
    for (int s = 0; s < 2; s++)
      if (ir->joints[j].active && ir->joints[j].via_virtual && ir->joints[j].node[s] >= 0) nvirt_max++;
  int nbmax = nb + nvirt_max;
  int maxmk = 2 * ir->njoints + 2 * ir->nforces + 2 * nvirt_max + 1;
  int maxrow = 6 * ir->njoints + ir->ndrivers + 6 * nvirt_max + 1;
  int maxprof = ir->ndrivers + ir->nforces + 1;
  L->body = calloc((size_t)nbmax + 1, sizeof *L->body);
  /* mb body b is IR body b + 1 */
  L->modes = flex->modes + 1;
  L->flexd = flex->data + 1;
  L->mslotf = calloc((size_t)nbmax + 1, sizeof *L->mslotf);
  L->body_name = calloc((size_t)nbmax + 1, sizeof *L->body_name);
  L->marker = calloc((size_t)maxmk, sizeof *L->marker);
  L->marker_desc = calloc((size_t)maxmk, sizeof(char *));
  L->marker_loc = calloc((size_t)maxmk, sizeof *L->marker_loc);
  L->row = calloc((size_t)maxrow, sizeof *L->row);
  L->row_desc = calloc((size_t)maxrow, sizeof(char *));
  L->row_loc = calloc((size_t)maxrow, sizeof(ir_loc));
  L->force = calloc((size_t)ir->nforces + 1, sizeof *L->force);
  L->force_ir = calloc((size_t)ir->nforces + 1, sizeof(int));
  /* pools: at most the largest kind's parameters and laws per force */
  L->force_prm_cap = (size_t)ir->nforces * MB_FIELD_NPRM + 1;
  L->force_prm = calloc(L->force_prm_cap, sizeof *L->force_prm);
  L->force_law = calloc((size_t)ir->nforces * MB_SPRING_NLAW + 1, sizeof *L->force_law);
  L->profile = calloc((size_t)maxprof, sizeof *L->profile);
  L->profile_driver = calloc((size_t)maxprof, sizeof(int));
  L->profile_force = calloc((size_t)maxprof, sizeof(int));
  L->spline = calloc((size_t)maxprof, sizeof(double *));
  L->table = calloc((size_t)maxprof, sizeof(double *));
  L->output = calloc((size_t)ir->noutputs + 1, sizeof *L->output);
  L->joint_name = calloc((size_t)ir->njoints + 1, sizeof(char *));
  int ncols = 0;
  for (int k = 0; k < ir->noutputs; k++) ncols += output_columns(ir, &ir->outputs[k]);
  L->col_name = calloc((size_t)ncols + 1, sizeof(char *));
  if (!L->body || !L->marker || !L->marker_desc || !L->row || !L->row_desc || !L->row_loc ||
      !L->force || !L->force_ir || !L->force_prm || !L->force_law || !L->profile || !L->profile_driver || !L->profile_force ||
      !L->spline || !L->table || !L->output || !L->joint_name || !L->col_name || !L->marker_loc || !L->mslotf || !L->body_name) {
    lower_free(L);
    return NULL;
  }
  mb_model *m = &L->m;
  /* a scene's code gets its own symbols: <model>_<scene>, made an identifier */
  L->name = malloc(strlen(ir->name) + (ir->scene ? strlen(ir->scene) + 2 : 1));
  if (!L->name) { lower_free(L); return NULL; }
  strcpy(L->name, ir->name);
  if (ir->scene) {
    char *e = L->name + strlen(L->name);
    *e++ = '_';
    for (const char *c = ir->scene; *c; c++) *e++ = (isalnum((unsigned char)*c) || *c == '_') ? *c : '_';
    *e = 0;
  }
  m->name = L->name;
  memcpy(m->gravity, ir->gravity, sizeof m->gravity);

  /* bodies: 7 position and 6 velocity coordinates each, plus the modes of a
     flexible body (the flexible-body stage's: they size the coordinates) */
  int nq = 0, nv = 0;
  for (int b = 0; b < nb; b++) {
    const ir_body *B = &ir->bodies[b + 1];
    mb_body *d = &L->body[b];
    d->name = B->name;
    d->kind = B->kind == BODY_VIRTUAL ? MB_BODY_VIRTUAL : MB_BODY_RIGID;
    d->mass = B->mass;
    memcpy(d->J, B->inertia, sizeof d->J);
    d->qadr = nq;
    d->vadr = nv;
    if (B->kind == BODY_FLEXIBLE) {
      d->kind = MB_BODY_FLEXIBLE;
      d->flex = &L->flexd[b].flex;
      d->stiff = L->flexd[b].stiff_P ? &L->flexd[b].stiff : NULL; /* geometric stiffening */
      d->nm = d->flex->nm;
      d->mass = d->flex->mass;
      memcpy(d->J, d->flex->J0, sizeof d->J);
    }
    nq += 7 + d->nm;
    nv += 6 + d->nm;
  }
  L->q0 = calloc((size_t)nq + 7 * (size_t)nvirt_max + 1, sizeof(double));
  L->v0 = calloc((size_t)nv + 6 * (size_t)nvirt_max + 1, sizeof(double));
  if (!L->q0 || !L->v0) { lower_free(L); return NULL; }
  for (int b = 0; b < nb; b++) {
    const ir_body *B = &ir->bodies[b + 1];
    const mb_body *d = &L->body[b];
    double A[9];
    mb_euler_to_A(B->orientation, A);
    memcpy(L->q0 + d->qadr, B->position, sizeof(double) * 3);
    memcpy(L->q0 + d->qadr + 3, B->orientation, sizeof(double) * 4);
    memcpy(L->v0 + d->vadr, B->velocity, sizeof(double) * 3);
    mb_mul3t(A, B->angular_velocity, L->v0 + d->vadr + 3);
  }
  m->nbody = nb;
  /* initial modal coordinates and rates (assembly then moves the frames only) */
  for (int b = 0; b < nb; b++) {
    const ir_body *B = &ir->bodies[b + 1];
    const mb_body *d = &L->body[b];
    const ir_flex *fx = B->kind == BODY_FLEXIBLE ? B->flex : NULL;
    for (int k = 0; fx && k < 2; k++) {
      int n = k ? fx->nwd0 : fx->nw0;
      const double *w = k ? fx->wd0 : fx->w0;
      if (!w) continue;
      if (n != d->nm) {
        diag_error(ir->path, k ? fx->wd0_loc : fx->w0_loc, "flexible body '%s': '%s' has %d values, the body "
                   "has %d selected modes", B->name, k ? "initial_mode_rates" : "initial_modes", n, d->nm);
        lower_free(L);
        return NULL;
      }
      memcpy(k ? L->v0 + d->vadr + 6 : L->q0 + d->qadr + 7, w, sizeof(double) * (size_t)n);
    }
  }

  /* joints: two markers each (frames z = axis), then their rows; a side on a
     flexible node lowered through a virtual body gets the body and the 6-row
     rigid joint of seed 000 eqs. 33-42 between it and the node */
  int *jm0 = calloc((size_t)ir->njoints + 1, sizeof(int));
  int *jm1 = calloc((size_t)ir->njoints + 1, sizeof(int));
  if (!jm0 || !jm1) { free(jm0); free(jm1); lower_free(L); return NULL; }
  for (int j = 0; j < ir->njoints; j++) {
    const ir_joint *J = &ir->joints[j];
    L->joint_name[j] = J->name;
    if (!J->active) { jm0[j] = jm1[j] = -1; continue; }
    double C[2][9];
    frame_from_axes(J->axis[0], J->ref, C[0]);
    const joint_desc *desc = joint_element(J->kind);
    if (desc->cross_axes)
      frame_from_axes(J->axis[1], J->axis[0], C[1]); /* x1 along the other cross axis */
    else
      memcpy(C[1], C[0], sizeof C[1]);
    int mk[2];
    for (int s = 0; s < 2; s++) {
      int b = J->body[s] - 1, node = J->node[s];
      if (b >= 0 && node >= 0 && J->via_virtual && L->body[b].kind == MB_BODY_FLEXIBLE) {
        /* a massless body at the node, in the flexible body's axes */
        int v = m->nbody++;
        char name[300];
        snprintf(name, sizeof name, "%s_%s_virtual", J->name, L->body[b].name);
        L->body_name[v] = strdup(name);
        mb_body *d = &L->body[v];
        d->name = L->body_name[v];
        d->kind = MB_BODY_VIRTUAL;
        d->qadr = nq;
        d->vadr = nv;
        nq += 7;
        nv += 6;
        const double *qb = L->q0 + L->body[b].qadr;
        double A[9], P[3], Cg[9];
        mb_euler_to_A(qb + 3, A);
        /* a node it does not have: add_marker reports it at the joint */
        if (node < L->modes[b].nnodes) mb_mul3(A, L->modes[b].x + 3 * node, P);
        else memset(P, 0, sizeof P);
        for (int i = 0; i < 3; i++) P[i] += qb[i];
        for (int i = 0; i < 9; i++) Cg[i] = A[i];
        memcpy(L->q0 + d->qadr, P, sizeof P);
        memcpy(L->q0 + d->qadr + 3, qb + 3, sizeof(double) * 4);
        /* it starts moving with the frame at the node (v + w x r; the same
           body-axis angular velocity): at rest, the assembly's minimum-norm
           velocity correction would slow the whole system down */
        const double *vb = L->v0 + L->body[b].vadr;
        double wg[3], r[3], wxr[3];
        mb_mul3(A, vb + 3, wg);
        for (int i = 0; i < 3; i++) r[i] = P[i] - qb[i];
        mb_cross3(wg, r, wxr);
        for (int i = 0; i < 3; i++) L->v0[d->vadr + i] = vb[i] + wxr[i];
        memcpy(L->v0 + d->vadr + 3, vb + 3, sizeof(double) * 3);
        int mn = add_marker(L, b, node, P, Cg,
                            xstrdup_printf("node of body '%s' under virtual body '%s'%s",
                                           L->body[b].name, name, ""), J->body_loc[s]);
        int mv = add_marker(L, v, -1, P, Cg,
                            xstrdup_printf("virtual body '%s' at its node%s%s", name, "", ""), J->loc);
        char what[64];
        for (int k = 0; k < 3; k++) {
          snprintf(what, sizeof what, "node and virtual body coincide, %s", axis_name[k]);
          lower_add_row(L, MB_PRIM_SPH, mn, mv, k, 0, what, -1, -1, J->loc, name, "rigid joint of virtual body");
        }
        lower_add_row(L, MB_PRIM_DOT1, mn, mv, 0, 1, "no relative rotation about z", -1, -1, J->loc, name, "rigid joint of virtual body");
        lower_add_row(L, MB_PRIM_DOT1, mn, mv, 1, 2, "no relative rotation about x", -1, -1, J->loc, name, "rigid joint of virtual body");
        lower_add_row(L, MB_PRIM_DOT1, mn, mv, 2, 0, "no relative rotation about y", -1, -1, J->loc, name, "rigid joint of virtual body");
        L->nvirtual++;
        b = v;
        node = -1;
      }
      mk[s] = add_marker(L, b, node, J->point[s], C[s],
                         xstrdup_printf("joint '%s', on body '%s'%s", J->name,
                                        b >= 0 ? L->body[b].name : "ground", ""), J->body_loc[s]);
    }
    jm0[j] = mk[0];
    jm1[j] = mk[1];
    desc->lower_rows(L, j, jm0[j], jm1[j]); /* compiler/elements/joint_*.c */
  }
  m->nq = nq;
  m->nv = nv;
  if (L->bad) { free(jm0); free(jm1); lower_free(L); return NULL; }
  for (int d = 0; d < ir->ndrivers; d++) {
    const ir_driver *D = &ir->drivers[d];
    if (!D->active || !ir->joints[D->joint].active) continue;
    if (element_driver.lower(L, d, jm0, jm1)) { free(jm0); free(jm1); lower_free(L); return NULL; }
  }

  /* forces: each kind lowered by its element descriptor (compiler/elements/) */
  for (int e = 0; e < ir->nforces; e++) {
    const ir_force *F = &ir->forces[e];
    if (!F->active) continue;
    int k = m->nforce++;
    mb_forcedef *d = &L->force[k];
    L->force_ir[k] = e;
    d->profile = -1;
    d->m1 = -1;
    const element_desc *desc = force_element(F->kind);
    d->kind = desc->runtime_kind;
    desc->lower(L, F, e, d);
  }
  if (L->out_of_memory) { free(jm0); free(jm1); lower_free(L); return NULL; }

  /* outputs */
  int col = 0;
  for (int k = 0; k < ir->noutputs; k++) {
    const ir_output *o = &ir->outputs[k];
    mb_outputdef *d = &L->output[k];
    const output_desc *desc = output_element(o->kind);
    d->kind = desc->runtime_kind;
    d->body = o->body >= 0 ? o->body - 1 : -1;
    d->component = o->component;
    d->scale = o->scale;
    d->joint = o->joint;
    d->driver_row = -1;
    d->reaction_marker = -1;
    d->driver_marker = -1;
    d->node = -1;
    d->chord[0] = d->chord[1] = -1;
    d->ncols = output_columns(ir, o);
    d->col = col;
    if (d->body >= 0 && o->has_point) {
      const ir_body *B = &ir->bodies[o->body];
      double A[9], rel[3];
      mb_euler_to_A(B->orientation, A);
      for (int j = 0; j < 3; j++) rel[j] = o->point[j] - B->position[j];
      mb_mul3t(A, rel, d->s);
    }
    /* the kind's own fields (compiler/elements/output_*.c) */
    if (desc->lower && desc->lower(L, o, jm0, jm1, d)) {
      free(jm0);
      free(jm1);
      lower_free(L);
      return NULL;
    }
    for (int j = 0; j < d->ncols; j++)
      L->col_name[col + j] = d->ncols > 1 ? xstrdup_printf("%s.%s%s", o->name, desc->columns[j], "")
                                          : strdup(o->name);
    col += d->ncols;
  }
  m->noutput = ir->noutputs;
  m->ncols = col;
  m->njoint = ir->njoints;
  free(jm0);
  free(jm1);

  m->body = L->body;
  m->marker = L->marker;
  m->row = L->row;
  m->force = L->force;
  m->force_prm = L->force_prm;
  m->force_law = L->force_law;
  m->profile = L->profile;
  m->output = L->output;
  m->output_coef = L->output_coef;
  m->q0 = L->q0;
  m->v0 = L->v0;
  m->col_name = (const char *const *)L->col_name;
  m->joint_name = (const char *const *)L->joint_name;
  m->eval = mb_generic_eval;
  m->init = mb_generic_init;
  if (lower_pattern(L)) { lower_free(L); return NULL; }
  return L;
}

/* --- the CSC pattern of K ---------------------------------------------------- */
typedef struct { int row, col; } entry;

static int entry_cmp(const void *a, const void *b) {
  const entry *x = a, *y = b;
  if (x->col != y->col) return x->col < y->col ? -1 : 1;
  return (x->row > y->row) - (x->row < y->row);
}

/* does node 'node' of flexible body B move with its modes: translate (X) or
 * rotate (Psi)?  Shared with the emitter (emit_node_static) */
static int node_shapes_nonzero(const mb_body *B, int node, int rotational) {
  const mb_flex *f = B->flex;
  const double *T = (rotational ? f->node_Psi : f->node_X) + 3 * (size_t)node * f->nm;
  for (size_t i = 0; i < 3 * (size_t)f->nm; i++)
    if (T[i] != 0) return 1;
  return 0;
}
int lower_node_translates(const mb_body *B, int node) { return node_shapes_nonzero(B, node, 0); }
int lower_node_rotates(const mb_body *B, int node) { return node_shapes_nonzero(B, node, 1); }

/* can marker md's point lie away from its body's frame origin?  A node
 * marker can, unless every translational mode shape vanishes at the node and
 * the node sits at the origin (the reference node of a body frame): then
 * P = r exactly and a point row has no rotational columns there */
static int marker_offset(const lmodel *L, const mb_markerdef *md) {
  if (L->marker_runtime && L->marker_runtime[md - L->marker]) return 1; /* set at run time (pipeline.c) */
  if (md->node < 0) return fabs(md->s[0]) + fabs(md->s[1]) + fabs(md->s[2]) > 0;
  const mb_body *B = &L->body[md->body];
  const double *x = B->flex->node_x + 3 * (size_t)md->node;
  return lower_node_translates(B, md->node) || x[0] != 0 || x[1] != 0 || x[2] != 0;
}

/* the marker's axes are A C exactly: on a rigid body, or on a node where all
 * rotational mode shapes vanish */
static int marker_axes_rigid(const lmodel *L, const mb_markerdef *md) {
  if (md->body < 0) return 0;
  return md->node < 0 || !lower_node_rotates(&L->body[md->body], md->node);
}

/* which of a row's 6 columns on side s are structurally nonzero, and which constant */
static void row_structure(const lmodel *L, const mb_rowdef *R, int s, int nz[6], int cst[6]) {
  const mb_markerdef *md = &L->marker[s ? R->m1 : R->m0];
  int offset = marker_offset(L, md);
  for (int j = 0; j < 6; j++) nz[j] = cst[j] = 0;
  switch (R->kind) {
  case MB_PRIM_SPH:
    nz[R->a] = cst[R->a] = 1;
    if (offset) nz[3] = nz[4] = nz[5] = 1;
    break;
  case MB_PRIM_DIST:
    nz[0] = nz[1] = nz[2] = 1;
    if (offset) nz[3] = nz[4] = nz[5] = 1;
    break;
  case MB_PRIM_DOT1:
    nz[3] = nz[4] = nz[5] = 1;
    /* the side's rotational columns are A^T (ai x aj) (signed); with its own
       axis a = A C e_a and C e_a = +-e_k, component k is (C e_a) . (C e_a x
       A^T aj) = 0 exactly */
    if (marker_axes_rigid(L, md)) {
      int a = s ? R->b : R->a, k = -1, unit = 1;
      for (int l = 0; l < 3; l++) {
        double c = md->C[3 * l + a];
        if (c == 1 || c == -1) k = k < 0 ? l : 3;
        else if (c != 0) unit = 0;
      }
      if (unit && k >= 0 && k < 3) nz[3 + k] = 0;
    }
    break;
  case MB_PRIM_ROT:
    nz[3] = nz[4] = nz[5] = 1;
    break;
  case MB_PRIM_DOT2:
  case MB_PRIM_TRANS:
    for (int j = 0; j < 6; j++) nz[j] = 1;
    break;
  }
}

/* can a row's column of mode j on side s be nonzero (a node marker whose
 * shape rows for mode j are nonzero in the part the primitive uses)? */
static int modal_nonzero(const lmodel *L, const mb_rowdef *R, int s, int j) {
  const mb_markerdef *md = &L->marker[s ? R->m1 : R->m0];
  if (md->body < 0 || md->node < 0) return 0;
  const mb_flex *f = L->body[md->body].flex;
  const double *X = f->node_X + 3 * ((size_t)md->node * f->nm + j);
  const double *P = f->node_Psi + 3 * ((size_t)md->node * f->nm + j);
  int uses_V = R->kind != MB_PRIM_DOT1 && R->kind != MB_PRIM_ROT;
  int uses_W = R->kind != MB_PRIM_SPH && R->kind != MB_PRIM_DIST;
  return (uses_V && (X[0] != 0 || X[1] != 0 || X[2] != 0)) ||
         (uses_W && (P[0] != 0 || P[1] != 0 || P[2] != 0));
}

static int find_slot(const int *Kp, const int *Ki, int row, int col) {
  for (int p = Kp[col]; p < Kp[col + 1]; p++)
    if (Ki[p] == row) return p;
  return -1;
}

/* does the model ask for an implicit method (genalpha, or auto, which may
 * choose it)?  Then the pattern carries the force elements' tangent blocks */
static int wants_tangents(const lmodel *L) {
  return L->ir && (L->ir->sim.integrator == INTEGRATOR_GENALPHA ||
                   L->ir->sim.integrator == INTEGRATOR_AUTO);
}

/* the entries of force e's tangent blocks: the columns of each side's body
 * against each other's (E NULL: count them) */
static size_t tangent_entries(const lmodel *L, int e, entry *E) {
  const mb_forcedef *d = &L->force[e];
  size_t ne = 0;
  for (int s = 0; s < 2; s++)
    for (int u = 0; u < 2; u++) {
      int ns = mb_force_tangent_side_cols(L->body, L->marker, d, s);
      int nu = mb_force_tangent_side_cols(L->body, L->marker, d, u);
      if (!ns || !nu) continue;
      int rs = L->body[L->marker[s ? d->m1 : d->m0].body].vadr;
      int cu = L->body[L->marker[u ? d->m1 : d->m0].body].vadr;
      for (int i = 0; i < ns; i++)
        for (int j = 0; j < nu; j++) {
          if (E) E[ne] = (entry){rs + i, cu + j};
          ne++;
        }
    }
  return ne;
}

int lower_pattern(lmodel *L) {
  mb_model *m = &L->m;
  m->nc = m->nrow;
  m->n = m->nv + m->nc;
  int tangents = wants_tangents(L);
  size_t cap = 24 * (size_t)m->nrow + 1;
  if (tangents)
    for (int e = 0; e < m->nforce; e++) cap += tangent_entries(L, e, NULL);
  for (int b = 0; b < m->nbody; b++) cap += (size_t)(6 + L->body[b].nm) * (size_t)(6 + L->body[b].nm) + 12;
  for (int r = 0; r < m->nrow; r++)
    for (int s = 0; s < 2; s++) {
      int b = L->marker[s ? L->row[r].m1 : L->row[r].m0].body;
      if (b >= 0) cap += 2 * (size_t)L->body[b].nm;
    }
  entry *E = malloc(cap * sizeof *E);
  if (!E) return -1;
  size_t ne = 0;
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &L->body[b];
    if (B->kind == MB_BODY_FLEXIBLE) {
      int nbk = 6 + B->nm;
      for (int i = 0; i < nbk; i++)
        for (int l = 0; l < nbk; l++)
          if (flex_mass_entry(B->flex, B->stiff, i, l)) E[ne++] = (entry){B->vadr + i, B->vadr + l};
      continue;
    }
    if (B->kind != MB_BODY_RIGID) continue;
    for (int j = 0; j < 3; j++) E[ne++] = (entry){B->vadr + j, B->vadr + j};
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        if (B->J[3 * i + j] != 0) E[ne++] = (entry){B->vadr + 3 + i, B->vadr + 3 + j};
  }
  for (int r = 0; r < m->nrow; r++) {
    const mb_rowdef *R = &L->row[r];
    for (int s = 0; s < 2; s++) {
      int b = L->marker[s ? R->m1 : R->m0].body, nz[6], cst[6];
      if (b < 0) continue;
      row_structure(L, R, s, nz, cst);
      for (int j = 0; j < 6; j++)
        if (nz[j]) {
          E[ne++] = (entry){m->nv + r, L->body[b].vadr + j};
          E[ne++] = (entry){L->body[b].vadr + j, m->nv + r};
        }
      for (int j = 0; j < L->body[b].nm; j++)
        if (modal_nonzero(L, R, s, j)) {
          E[ne++] = (entry){m->nv + r, L->body[b].vadr + 6 + j};
          E[ne++] = (entry){L->body[b].vadr + 6 + j, m->nv + r};
        }
    }
  }
  if (tangents)
    for (int e = 0; e < m->nforce; e++) ne += tangent_entries(L, e, E + ne);
  qsort(E, ne, sizeof *E, entry_cmp);
  free(L->Kp);
  free(L->Ki);
  L->Kp = calloc((size_t)m->n + 1, sizeof(int));
  L->Ki = malloc((ne + 1) * sizeof(int));
  if (!L->Kp || !L->Ki) { free(E); return -1; }
  size_t nnz = 0;
  for (size_t k = 0; k < ne; k++) {
    if (k > 0 && E[k].row == E[k - 1].row && E[k].col == E[k - 1].col) continue;
    L->Ki[nnz++] = E[k].row;
    L->Kp[E[k].col + 1]++;
  }
  for (int j = 0; j < m->n; j++) L->Kp[j + 1] += L->Kp[j];
  free(E);
  m->nnz = (int)nnz;
  m->Kp = L->Kp;
  m->Ki = L->Ki;

  /* slots */
  for (int b = 0; b < m->nbody; b++) {
    mb_body *B = &L->body[b];
    for (int j = 0; j < 12; j++) B->mslot[j] = -1;
    if (B->kind == MB_BODY_FLEXIBLE) {
      int nbk = 6 + B->nm;
      free(L->mslotf[b]);
      L->mslotf[b] = malloc(sizeof(int) * (size_t)nbk * (size_t)nbk);
      if (!L->mslotf[b]) return -1;
      for (int i = 0; i < nbk; i++)
        for (int l = 0; l < nbk; l++)
          L->mslotf[b][nbk * i + l] = flex_mass_entry(B->flex, B->stiff, i, l)
                                          ? find_slot(L->Kp, L->Ki, B->vadr + i, B->vadr + l)
                                          : -1;
      B->mslotf = L->mslotf[b];
      continue;
    }
    if (B->kind != MB_BODY_RIGID) continue;
    for (int j = 0; j < 3; j++) B->mslot[j] = find_slot(L->Kp, L->Ki, B->vadr + j, B->vadr + j);
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < 3; j++)
        B->mslot[3 + 3 * i + j] = find_slot(L->Kp, L->Ki, B->vadr + 3 + i, B->vadr + 3 + j);
  }
  /* force tangents: each element's blocks in the order of tangent_entries */
  free(L->force_tslot);
  free(L->tangent_slot);
  L->force_tslot = NULL;
  L->tangent_slot = NULL;
  L->ntangent_slot = 0;
  m->force_tslot = m->tangent_slot = NULL;
  if (tangents) {
    size_t nts = 0;
    for (int e = 0; e < m->nforce; e++) nts += tangent_entries(L, e, NULL);
    entry *T = malloc((nts + 1) * sizeof *T);
    L->force_tslot = malloc(((size_t)m->nforce + 1) * sizeof(int));
    L->tangent_slot = malloc((nts + 1) * sizeof(int));
    if (!T || !L->force_tslot || !L->tangent_slot) { free(T); return -1; }
    nts = 0;
    for (int e = 0; e < m->nforce; e++) {
      size_t k = tangent_entries(L, e, T + nts);
      L->force_tslot[e] = k ? (int)nts : -1;
      for (size_t i = nts; i < nts + k; i++) L->tangent_slot[i] = find_slot(L->Kp, L->Ki, T[i].row, T[i].col);
      nts += k;
    }
    free(T);
    L->ntangent_slot = (int)nts;
    m->force_tslot = L->force_tslot;
    m->tangent_slot = L->tangent_slot;
  }
  /* modal columns of rows on node markers: nm slots, then nm transposed slots */
  size_t nms = 0;
  for (int r = 0; r < m->nrow; r++)
    for (int s = 0; s < 2; s++) {
      const mb_markerdef *md = &L->marker[s ? L->row[r].m1 : L->row[r].m0];
      if (md->body >= 0 && md->node >= 0) nms += 2 * (size_t)L->body[md->body].nm;
    }
  free(L->modal_slot);
  L->modal_slot = malloc(sizeof(int) * (nms + 1));
  if (!L->modal_slot) return -1;
  L->nmodal_slot = (int)nms;
  m->modal_slot = L->modal_slot;
  nms = 0;
  for (int r = 0; r < m->nrow; r++) {
    mb_rowdef *R = &L->row[r];
    for (int s = 0; s < 2; s++) {
      const mb_markerdef *md = &L->marker[s ? R->m1 : R->m0];
      R->mslot[s] = -1;
      if (md->body < 0 || md->node < 0) continue;
      const mb_body *B = &L->body[md->body];
      R->mslot[s] = (int)nms;
      for (int j = 0; j < B->nm; j++) {
        int nz = modal_nonzero(L, R, s, j), c = B->vadr + 6 + j;
        L->modal_slot[nms + (size_t)j] = nz ? find_slot(L->Kp, L->Ki, m->nv + r, c) : -1;
        L->modal_slot[nms + (size_t)B->nm + (size_t)j] = nz ? find_slot(L->Kp, L->Ki, c, m->nv + r) : -1;
      }
      nms += 2 * (size_t)B->nm;
    }
  }
  for (int r = 0; r < m->nrow; r++) {
    mb_rowdef *R = &L->row[r];
    for (int s = 0; s < 2; s++) {
      int b = L->marker[s ? R->m1 : R->m0].body, nz[6], cst[6];
      for (int j = 0; j < 6; j++) {
        R->slot[s][j] = R->slotT[s][j] = -1;
        R->constant[s][j] = 0;
      }
      if (b < 0) continue;
      row_structure(L, R, s, nz, cst);
      for (int j = 0; j < 6; j++)
        if (nz[j]) {
          int c = L->body[b].vadr + j;
          R->slot[s][j] = find_slot(L->Kp, L->Ki, m->nv + r, c);
          R->slotT[s][j] = find_slot(L->Kp, L->Ki, c, m->nv + r);
          R->constant[s][j] = (unsigned char)cst[j];
        }
    }
  }
  return 0;
}

int lower_remove_rows(lmodel *L, const int *keep) {
  mb_model *m = &L->m;
  int *newidx = malloc(sizeof(int) * ((size_t)m->nrow + 1));
  if (!newidx) return -1;
  int k = 0;
  for (int r = 0; r < m->nrow; r++) {
    newidx[r] = keep[r] ? k : -1;
    if (keep[r]) {
      L->row[k] = L->row[r];
      char *desc = L->row_desc[r];
      L->row_desc[r] = NULL;
      L->row_desc[k] = desc;
      L->row_loc[k] = L->row_loc[r];
      k++;
    } else {
      free(L->row_desc[r]);
      L->row_desc[r] = NULL;
    }
  }
  for (int o = 0; o < m->noutput; o++)
    if (L->output[o].driver_row >= 0) L->output[o].driver_row = newidx[L->output[o].driver_row];
  free(newidx);
  m->nrow = k;
  return lower_pattern(L);
}

void lower_free(lmodel *L) {
  if (!L) return;
  for (int k = 0; k < L->m.nmarker; k++) free(L->marker_desc[k]);
  for (int r = 0; r < L->m.nrow; r++) free(L->row_desc[r]);
  for (int k = 0; k < L->m.nprofile; k++) { free(L->spline[k]); free(L->table[k]); }
  for (int c = 0; c < L->m.ncols; c++) free(L->col_name[c]);
  free(L->output_coef);
  free(L->body); free(L->marker); free(L->marker_desc); free(L->row); free(L->row_desc);
  free(L->row_loc); free(L->force); free(L->force_ir); free(L->force_prm); free(L->force_law);
  free(L->profile);
  free(L->profile_driver); free(L->profile_force); free(L->spline); free(L->table);
  free(L->output); free(L->q0); free(L->v0); free(L->col_name); free(L->joint_name);
  free(L->Kp); free(L->Ki);
  free(L->marker_loc);
  for (int b = 0; b < L->m.nbody; b++) {
    if (L->mslotf) free(L->mslotf[b]);
    if (L->body_name) free(L->body_name[b]);
  }
  free(L->name);
  free(L->mslotf); free(L->body_name); free(L->modal_slot);
  free(L->force_tslot); free(L->tangent_slot);
  for (int r = 0; r < L->nremoved; r++) free(L->removed_desc[r]);
  free(L->removed_row); free(L->removed_desc);
  free(L->q_given); free(L->v_given);
  free(L);
}
