/* emit_loops.c: the loop form of the emitted evaluation (emit_loops.h).
 *
 * The groups: rigid (or virtual) bodies of equal mass and inertia (their
 * frame, gravity and gyroscopic terms; the mass blocks are constant, set by
 * init); the markers (on the ground, on a rigid body); force elements of one
 * kind, time function and sides on the ground; joints, as blocks of
 * consecutive constraint rows between one pair of markers, equal when their
 * rows have the same primitives (kind, axes, length, time function), the
 * same sides on the ground and the same varying entries of K.  Members join
 * the first group whose first member equals them (quadratic in the number of
 * groups, which repeated structure keeps small).  Each group's loop body is
 * written once, with what the members share folded (the group's mass,
 * inertia, primitives, which columns are stored); what differs per member
 * (coordinates, markers, rows, slots) is in its table.  The kernels are the
 * generic path's (runtime/core/mb_kernels.h): one physics, two drivers.
 *
 * Frames and markers are arrays on the evaluation's stack, fr[] and mk[] (a
 * straight-line evaluation keeps the same values in named locals).  The
 * elements without a loop form (flexible bodies and what sits on them,
 * superelements: loop_choice) are left to emit.c, which writes them
 * straight-line after the loops, reading fr[] and mk[] (a mixed model). */
#include <stdlib.h>
#include <string.h>

#include "emit_loops.h"
#include "emit_split.h"
#include "emit_util.h"

/* measured: docs/architecture.md, "The loop form" */
#define LOOP_MIN_GROUP 32
/* a mixed model's elements without a loop form are written straight-line in the
 * one evaluation function, which is not cut into parts: they may be at most
 * this share of its elements (a fleet of cars, whose chassis and the joints
 * on its nodes have none, builds faster straight-line in parts: 16 cars took
 * 90 s of gcc and 752 MB as one looped file; docs/architecture.md) */
#define LOOP_MIXED_MAX_SHARE 0.2

int loop_min_group(void) {
  long v = emit_size_setting("MBCC_LOOP_MIN", LOOP_MIN_GROUP);
  return v > 1000000000 ? 1000000000 : (int)v;
}

/* a joint's rows: rows r0 .. r0 + n - 1, all between the same two markers */
typedef struct {
  int r0, n;
  int group;
} row_block;

typedef struct {
  int *body_group;   /* per body: its group */
  int nbody_group;
  int *body_count;   /* members per body group */
  int *body_first;   /* the first member of each body group */
  row_block *block;
  int nblock;
  int njoint_group;
  int *joint_count;  /* members per joint group */
  int *joint_first;  /* the first member (block index) of each joint group */
  int *force_group;  /* per force element: its group */
  int nforce_group;
  int *force_count;  /* members per force group */
  int *force_first;  /* the first member of each force group */
  int largest;
} loop_plan;

static void plan_free(loop_plan *p) {
  free(p->body_group);
  free(p->body_count);
  free(p->body_first);
  free(p->block);
  free(p->joint_count);
  free(p->joint_first);
  free(p->force_group);
  free(p->force_count);
  free(p->force_first);
  memset(p, 0, sizeof *p);
}

/* an entry of K a row's side writes at each evaluation */
static int entry_varies(const mb_rowdef *R, int s, int j) { return R->slot[s][j] >= 0 && !R->constant[s][j]; }

static int side_on_ground(const lmodel *L, const mb_rowdef *R, int s) {
  return L->marker[s ? R->m1 : R->m0].body < 0;
}

static int same_body(const mb_body *a, const mb_body *b) {
  if (a->kind != b->kind || a->mass != b->mass) return 0;
  for (int j = 0; j < 9; j++)
    if (a->J[j] != b->J[j]) return 0;
  return 1;
}

static int same_row(const lmodel *L, const mb_rowdef *x, const mb_rowdef *y) {
  if (x->kind != y->kind || x->a != y->a || x->b != y->b || x->profile != y->profile) return 0;
  if (x->kind == MB_PRIM_DIST && x->L != y->L) return 0;
  for (int s = 0; s < 2; s++) {
    if (side_on_ground(L, x, s) != side_on_ground(L, y, s)) return 0;
    for (int j = 0; j < 6; j++)
      if (entry_varies(x, s, j) != entry_varies(y, s, j)) return 0;
  }
  return 1;
}

static int same_block(const lmodel *L, const row_block *x, const row_block *y) {
  if (x->n != y->n) return 0;
  for (int i = 0; i < x->n; i++)
    if (!same_row(L, &L->row[x->r0 + i], &L->row[y->r0 + i])) return 0;
  return 1;
}

/* the force kinds with a loop form: those whose kernel reads everything
 * from the pools (the tyre's road too: force_tyre.c copies it there) and two
 * markers at most (the superelement's nodes are a list) */
static int force_has_loop(const mb_forcedef *d) {
  switch (d->kind) {
  case MB_FORCE_POINT:
  case MB_FORCE_TORQUE:
  case MB_FORCE_SPRING:
  case MB_FORCE_FIELD:
  case MB_FORCE_TYRE: return 1;
  case MB_FORCE_SUPERELEMENT: return 0;
  }
  return 0;
}

static int same_force(const lmodel *L, const mb_forcedef *x, const mb_forcedef *y) {
  if (x->kind != y->kind || x->profile != y->profile || x->local != y->local) return 0;
  if ((L->marker[x->m0].body < 0) != (L->marker[y->m0].body < 0)) return 0;
  if (x->m1 >= 0 && (L->marker[x->m1].body < 0) != (L->marker[y->m1].body < 0)) return 0;
  return 1;
}

/* a marker with a loop form: on the ground or a rigid (or virtual) body's
 * frame, not on a flexible body */
static int marker_has_loop(const lmodel *L, int k) {
  const mb_markerdef *d = &L->marker[k];
  return d->node < 0 && (d->body < 0 || L->body[d->body].kind != MB_BODY_FLEXIBLE);
}

void loop_choice_free(loop_choice *c) {
  free(c->body);
  free(c->marker);
  free(c->force);
  free(c->row);
  memset(c, 0, sizeof *c);
}

/* which elements have a loop form (c->mixed: not all); 0, or -1 out of memory */
static int mark_loopable(const lmodel *L, loop_choice *c) {
  const mb_model *m = &L->m;
  memset(c, 0, sizeof *c);
  c->body = calloc((size_t)m->nbody + 1, 1);
  c->marker = calloc((size_t)m->nmarker + 1, 1);
  c->force = calloc((size_t)m->nforce + 1, 1);
  c->row = calloc((size_t)m->nrow + 1, 1);
  if (!c->body || !c->marker || !c->force || !c->row) { loop_choice_free(c); return -1; }
  for (int b = 0; b < m->nbody; b++) c->body[b] = L->body[b].kind != MB_BODY_FLEXIBLE;
  for (int k = 0; k < m->nmarker; k++) c->marker[k] = (unsigned char)marker_has_loop(L, k);
  for (int i = 0; i < m->nforce; i++) {
    const mb_forcedef *d = &L->force[i];
    c->force[i] = force_has_loop(d) && c->marker[d->m0] && (d->m1 < 0 || c->marker[d->m1]);
  }
  /* a joint (its block of rows) has one when every row does: no modal columns */
  for (int r = 0; r < m->nrow;) {
    int n = 0, all = 1;
    for (; r + n < m->nrow && L->row[r + n].m0 == L->row[r].m0 && L->row[r + n].m1 == L->row[r].m1; n++)
      all &= L->row[r + n].mslot[0] < 0 && L->row[r + n].mslot[1] < 0;
    all &= c->marker[L->row[r].m0] && c->marker[L->row[r].m1];
    for (int i = 0; i < n; i++) c->row[r + i] = (unsigned char)all;
    r += n;
  }
  for (int b = 0; b < m->nbody; b++) c->mixed |= !c->body[b];
  for (int k = 0; k < m->nmarker; k++) c->mixed |= !c->marker[k];
  for (int i = 0; i < m->nforce; i++) c->mixed |= !c->force[i];
  for (int r = 0; r < m->nrow; r++) c->mixed |= !c->row[r];
  return 0;
}

/* the groups of the elements of L that c loops (the others: group -1); 0,
 * or -1 out of memory */
static int plan_groups(const lmodel *L, const loop_choice *c, loop_plan *p) {
  const mb_model *m = &L->m;
  memset(p, 0, sizeof *p);
  p->body_group = malloc(sizeof *p->body_group * (size_t)m->nbody);
  p->body_count = calloc((size_t)m->nbody, sizeof *p->body_count);
  p->body_first = malloc(sizeof *p->body_first * (size_t)m->nbody);
  p->block = malloc(sizeof *p->block * (size_t)(m->nrow + 1));
  p->joint_count = calloc((size_t)m->nrow + 1, sizeof *p->joint_count);
  p->joint_first = malloc(sizeof *p->joint_first * (size_t)(m->nrow + 1));
  p->force_group = malloc(sizeof *p->force_group * (size_t)(m->nforce + 1));
  p->force_count = calloc((size_t)m->nforce + 1, sizeof *p->force_count);
  p->force_first = malloc(sizeof *p->force_first * (size_t)(m->nforce + 1));
  if (!p->body_group || !p->body_count || !p->body_first || !p->block || !p->joint_count || !p->joint_first || !p->force_group ||
      !p->force_count || !p->force_first) {
    plan_free(p);
    return -1;
  }
  for (int b = 0; b < m->nbody; b++) {
    p->body_group[b] = -1;
    if (!c->body[b]) continue;
    int g = 0;
    while (g < p->nbody_group && !same_body(&L->body[b], &L->body[p->body_first[g]])) g++;
    if (g == p->nbody_group) p->body_first[p->nbody_group++] = b;
    p->body_group[b] = g;
    p->body_count[g]++;
  }
  /* row blocks: consecutive rows between the same markers */
  for (int r = 0; r < m->nrow;) {
    int n = 1;
    while (r + n < m->nrow && L->row[r + n].m0 == L->row[r].m0 && L->row[r + n].m1 == L->row[r].m1) n++;
    row_block *B = &p->block[p->nblock++];
    B->r0 = r;
    B->n = n;
    B->group = -1;
    r += n;
    if (!c->row[B->r0]) continue;
    int g = 0;
    while (g < p->njoint_group && !same_block(L, B, &p->block[p->joint_first[g]])) g++;
    if (g == p->njoint_group) p->joint_first[p->njoint_group++] = p->nblock - 1;
    B->group = g;
    p->joint_count[g]++;
  }
  for (int i = 0; i < m->nforce; i++) {
    p->force_group[i] = -1;
    if (!c->force[i]) continue;
    int g = 0;
    while (g < p->nforce_group && !same_force(L, &L->force[i], &L->force[p->force_first[g]])) g++;
    if (g == p->nforce_group) p->force_first[p->nforce_group++] = i;
    p->force_group[i] = g;
    p->force_count[g]++;
  }
  for (int g = 0; g < p->nforce_group; g++)
    if (p->force_count[g] > p->largest) p->largest = p->force_count[g];
  for (int g = 0; g < p->nbody_group; g++)
    if (p->body_count[g] > p->largest) p->largest = p->body_count[g];
  for (int g = 0; g < p->njoint_group; g++)
    if (p->joint_count[g] > p->largest) p->largest = p->joint_count[g];
  return 0;
}

/* the share of a mixed model's elements (bodies, markers, joints' rows, force
 * elements) that have no loop form */
static double straight_share(const lmodel *L, const loop_choice *c) {
  const mb_model *m = &L->m;
  long all = (long)m->nbody + m->nmarker + m->nforce + m->nrow, straight = 0;
  for (int b = 0; b < m->nbody; b++) straight += !c->body[b];
  for (int k = 0; k < m->nmarker; k++) straight += !c->marker[k];
  for (int i = 0; i < m->nforce; i++) straight += !c->force[i];
  for (int r = 0; r < m->nrow; r++) straight += !c->row[r];
  return all > 0 ? (double)straight / (double)all : 0;
}

int emit_loops_choose(const lmodel *L, loop_choice *c) {
  if (L->m.nbody < 1 || L->m.nmarker < 1) { memset(c, 0, sizeof *c); return 0; }
  if (mark_loopable(L, c)) return -1;
  loop_plan p;
  if (plan_groups(L, c, &p)) { loop_choice_free(c); return -1; }
  int chosen = p.largest >= loop_min_group() && p.largest > 0;
  /* MBCC_LOOP_MIN set: the loop form whenever its groups are that large */
  const char *forced = getenv("MBCC_LOOP_MIN");
  if (chosen && c->mixed && !(forced && *forced) && straight_share(L, c) > LOOP_MIXED_MAX_SHARE) chosen = 0;
  plan_free(&p);
  if (!chosen) loop_choice_free(c);
  return chosen;
}

/* the name of a row block's joint for a comment: its row description up to
 * the first ':' ("revolute 'hinge2'") */
static void block_comment(FILE *f, const lmodel *L, const row_block *B) {
  const char *d = L->row_desc[B->r0];
  const char *colon = strchr(d, ':');
  fprintf(f, " /* %.*s */\n", colon ? (int)(colon - d) : (int)strlen(d), d);
}

static void write_bodies(FILE *t, FILE *f, const lmodel *L, const loop_plan *p) {
  const mb_model *m = &L->m;
  fputs("\n/* the loop form's bodies: frame, gravity and gyroscopic terms (emit_loops.c) */\n"
        "typedef struct {\n  int body, qadr, vadr;\n} loop_body;\n",
        t);
  for (int g = 0; g < p->nbody_group; g++) {
    const mb_body *B0 = &L->body[p->body_first[g]];
    fprintf(t, "static const loop_body loop_bodies%d[%d] = {\n", g, p->body_count[g]);
    for (int b = 0; b < m->nbody; b++) {
      if (p->body_group[b] != g) continue;
      fprintf(t, "  {.body = %d, .qadr = %d, .vadr = %d}, /* '%s' */\n", b, L->body[b].qadr, L->body[b].vadr,
              L->body[b].name);
    }
    fputs("};\n", t);
    int zeroJ = 1;
    for (int j = 0; j < 9; j++) zeroJ &= B0->J[j] == 0;
    if (!zeroJ) {
      fprintf(t, "static const mb_real loop_bodies%d_J[9] = ", g);
      vec(t, B0->J, 9);
      fputs(";\n", t);
    }
    fprintf(f, "  /* %d %s bodies of mass ", p->body_count[g], B0->kind == MB_BODY_VIRTUAL ? "virtual" : "rigid");
    num(f, B0->mass);
    fprintf(f, " (loop_bodies%d) */\n  for (int e = 0; e < %d; e++) {\n"
               "    const loop_body *B = &loop_bodies%d[e];\n"
               "    mb_frame_rigid(q + B->qadr, v + B->vadr, &fr[B->body]);\n",
            g, p->body_count[g], g);
    for (int j = 0; j < 3; j++) {
      fprintf(f, "    rhs[B->vadr + %d] = ", j);
      num(f, B0->mass * m->gravity[j]);
      fputs(";\n", f);
    }
    if (zeroJ) fputs("    rhs[B->vadr + 3] = rhs[B->vadr + 4] = rhs[B->vadr + 5] = 0;\n", f);
    else fprintf(f, "    mb_rigid_gyro(loop_bodies%d_J, fr[B->body].wl, rhs + B->vadr + 3);\n", g);
    fputs("  }\n", f);
  }
}

static void write_markers(FILE *t, FILE *f, const lmodel *L, const loop_choice *c) {
  const mb_model *m = &L->m;
  int nground = 0, nrigid = 0;
  for (int k = 0; k < m->nmarker; k++) {
    nground += c->marker[k] && L->marker[k].body < 0;
    nrigid += c->marker[k] && L->marker[k].body >= 0;
  }
  if (nground) {
    fprintf(t, "/* the loop form's markers on the ground */\nstatic const int loop_ground_markers[%d] = {", nground);
    for (int k = 0, i = 0; k < m->nmarker; k++)
      if (c->marker[k] && L->marker[k].body < 0) {
        fprintf(t, "%s%s%d", i ? "," : "", i % 16 == 0 ? "\n  " : " ", k);
        i++;
      }
    fputs("\n};\n", t);
    fprintf(f, "  /* %d markers on the ground */\n  for (int e = 0; e < %d; e++) {\n"
               "    const int k = loop_ground_markers[e];\n"
               "    mb_marker_ground(markers[k].s, markers[k].C, &mk[k]);\n  }\n",
            nground, nground);
  }
  if (nrigid) {
    fprintf(t, "/* the loop form's markers on rigid bodies */\n"
               "typedef struct {\n  int marker, body;\n} loop_marker;\n"
               "static const loop_marker loop_markers[%d] = {\n", nrigid);
    for (int k = 0; k < m->nmarker; k++)
      if (c->marker[k] && L->marker[k].body >= 0) fprintf(t, "  {.marker = %d, .body = %d},\n", k, L->marker[k].body);
    fputs("};\n", t);
    fprintf(f, "  /* %d markers on rigid bodies (their offsets and axes: markers[]) */\n"
               "  for (int e = 0; e < %d; e++) {\n    const loop_marker *M = &loop_markers[e];\n"
               "    mb_marker_rigid(&fr[M->body], markers[M->marker].s, markers[M->marker].C, &mk[M->marker]);\n  }\n",
            nrigid, nrigid);
  }
}

/* rhs of side s's body += the body columns of (dV, dW) at point P */
static void add_wrench(FILE *f, int s, const char *P, const char *dV, const char *dW) {
  fprintf(f, "    mb_rigid_cols(&fr[E->b%d], %s, %s, %s, c);\n"
             "    for (int j = 0; j < 6; j++) rhs[E->v%d + j] += c[j];\n", s, P, dV, dW, s);
}

static void write_forces(FILE *t, FILE *f, const lmodel *L, const loop_plan *p) {
  const mb_model *m = &L->m;
  if (!p->nforce_group) return;
  fputs("/* the loop form's force elements: markers, their bodies and first velocities (-1: the\n"
        "   ground), the element's reals in force_prm and laws in force_laws */\n"
        "typedef struct {\n  int m0, m1, b0, b1, v0, v1, padr, ladr;\n} loop_force;\n", t);
  for (int g = 0; g < p->nforce_group; g++) {
    const mb_forcedef *d0 = &L->force[p->force_first[g]];
    fprintf(t, "static const loop_force loop_forces%d[%d] = {\n", g, p->force_count[g]);
    for (int i = 0; i < m->nforce; i++) {
      if (p->force_group[i] != g) continue;
      const mb_forcedef *d = &L->force[i];
      int b0 = L->marker[d->m0].body, b1 = d->m1 >= 0 ? L->marker[d->m1].body : -1;
      fprintf(t, "  {.m0 = %d, .m1 = %d, .b0 = %d, .b1 = %d, .v0 = %d, .v1 = %d, .padr = %d, .ladr = %d}, /* '%s' */\n",
              d->m0, d->m1, b0, b1, b0 >= 0 ? L->body[b0].vadr : -1, b1 >= 0 ? L->body[b1].vadr : -1, d->padr,
              d->ladr, L->ir->forces[L->force_ir[i]].name);
    }
    fputs("};\n", t);
    int ground0 = L->marker[d0->m0].body < 0, ground1 = d0->m1 < 0 || L->marker[d0->m1].body < 0;
    fprintf(f, "  /* %d force elements (loop_forces%d) */\n  for (int e = 0; e < %d; e++) {\n"
               "    const loop_force *E = &loop_forces%d[e];\n",
            p->force_count[g], g, p->force_count[g], g);
    switch (d0->kind) {
    case MB_FORCE_POINT:
    case MB_FORCE_TORQUE:
      if (ground0) { fputs("    (void)E; /* on the ground: no effect */\n  }\n", f); continue; }
      fputs("    mb_real s = 1, val[3];\n", f);
      if (d0->profile >= 0) fprintf(f, "    mb_profile_eval(&profiles[%d], t, x);\n    s = x[0];\n", d0->profile);
      fprintf(f, "    mb_point_vector(force_prm + E->padr, s, %s, val);\n", d0->local ? "fr[E->b0].A" : "0");
      add_wrench(f, 0, "mk[E->m0].P", d0->kind == MB_FORCE_POINT ? "val" : "zero3",
                 d0->kind == MB_FORCE_POINT ? "zero3" : "val");
      break;
    case MB_FORCE_SPRING:
      fputs("    mb_real F0[3], F1[3];\n"
            "    mb_spring(&mk[E->m0], &mk[E->m1], force_prm + E->padr, force_laws + E->ladr, F0, F1, 0);\n", f);
      if (!ground0) add_wrench(f, 0, "mk[E->m0].P", "F0", "zero3");
      if (!ground1) add_wrench(f, 1, "mk[E->m1].P", "F1", "zero3");
      break;
    case MB_FORCE_FIELD:
      fputs("    mb_real F[3], T[3];\n    mb_field(&mk[E->m0], &mk[E->m1], force_prm + E->padr, F, T, 0);\n", f);
      if (!ground1) add_wrench(f, 1, "mk[E->m1].P", "F", "T");
      if (!ground0) {
        fputs("    mb_real mF[3] = {-F[0], -F[1], -F[2]}, mT[3] = {-T[0], -T[1], -T[2]};\n", f);
        add_wrench(f, 0, "mk[E->m1].P", "mF", "mT"); /* the reaction at the same point */
      }
      break;
    case MB_FORCE_TYRE: /* one marker, the wheel centre: force and torque on the wheel */
      if (ground0) { fputs("    (void)E; /* on the ground: no effect */\n  }\n", f); continue; }
      fputs("    mb_real Fv[3], Tv[3];\n    mb_tyre(&mk[E->m0], force_prm + E->padr, Fv, Tv, 0, 0);\n", f);
      add_wrench(f, 0, "mk[E->m0].P", "Fv", "Tv");
      break;
    case MB_FORCE_SUPERELEMENT: break; /* no loop form (force_has_loop) */
    }
    fputs("  }\n", f);
  }
}

/* the slots a block writes, in the loop body's order: (slot, slotT) pairs */
static int block_slots(const lmodel *L, const row_block *B, int *K) {
  int n = 0;
  for (int i = 0; i < B->n; i++) {
    const mb_rowdef *R = &L->row[B->r0 + i];
    for (int s = 0; s < 2; s++)
      for (int j = 0; j < 6; j++)
        if (entry_varies(R, s, j)) {
          if (K) { K[2 * n] = R->slot[s][j]; K[2 * n + 1] = R->slotT[s][j]; }
          n++;
        }
  }
  return n;
}

static void write_row_call(FILE *f, const mb_rowdef *R) {
  switch (R->kind) {
  case MB_PRIM_SPH: fprintf(f, "    mb_prim_sph(m0, m1, %d, &r);\n", R->a); break;
  case MB_PRIM_DOT1: fprintf(f, "    mb_prim_dot1(m0, m1, %d, %d, &r);\n", R->a, R->b); break;
  case MB_PRIM_DOT2: fprintf(f, "    mb_prim_dot2(m0, m1, %d, zero3, &r);\n", R->a); break;
  case MB_PRIM_DIST:
    fputs("    mb_prim_dist(m0, m1, ", f);
    num(f, R->L);
    fputs(", &r);\n", f);
    break;
  case MB_PRIM_ROT:
    fprintf(f, "    mb_profile_eval(&profiles[%d], t, x);\n    mb_prim_rot(m0, m1, x, &r);\n", R->profile);
    break;
  case MB_PRIM_TRANS:
    fprintf(f, "    mb_profile_eval(&profiles[%d], t, x);\n    mb_prim_dot2(m0, m1, 2, x, &r);\n", R->profile);
    break;
  }
}

static int write_joints(FILE *t, FILE *f, const lmodel *L, const loop_plan *p) {
  const mb_model *m = &L->m;
  int *K = malloc(sizeof *K * (size_t)(2 * 12 * (m->nrow + 1)));
  if (!K) return -1;
  for (int g = 0; g < p->njoint_group; g++) {
    const row_block *B0 = &p->block[p->joint_first[g]];
    int ns = block_slots(L, B0, NULL);
    fprintf(t, "/* the loop form's joints, group %d: %d rows between two markers; K: the slots of\n"
               "   their varying entries of D and D^T, in pairs */\n"
               "typedef struct {\n  int m0, m1, b0, b1, row;\n  int K[%d];\n} loop_joint%d;\n"
               "static const loop_joint%d loop_joints%d[%d] = {\n",
            g, B0->n, ns ? 2 * ns : 1, g, g, g, p->joint_count[g]);
    for (int i = 0; i < p->nblock; i++) {
      const row_block *B = &p->block[i];
      if (B->group != g) continue;
      const mb_rowdef *R = &L->row[B->r0];
      fprintf(t, "  {.m0 = %d, .m1 = %d, .b0 = %d, .b1 = %d, .row = %d, .K = {", R->m0, R->m1,
              L->marker[R->m0].body, L->marker[R->m1].body, B->r0);
      int n = block_slots(L, B, K);
      for (int j = 0; j < 2 * n; j++) fprintf(t, "%s%d", j ? ", " : "", K[j]);
      if (!n) fputc('0', t);
      fputs("}},", t);
      block_comment(t, L, B);
    }
    fputs("};\n", t);
    fprintf(f, "  /* %d joints of %d rows (loop_joints%d) */\n  for (int e = 0; e < %d; e++) {\n"
               "    const loop_joint%d *E = &loop_joints%d[e];\n"
               "    const mb_marker *m0 = &mk[E->m0], *m1 = &mk[E->m1];\n",
            p->joint_count[g], B0->n, g, p->joint_count[g], g, g);
    int slot = 0;
    for (int i = 0; i < B0->n; i++) {
      const mb_rowdef *R = &L->row[B0->r0 + i];
      fprintf(f, "    /* row +%d:%s */\n", i, strchr(L->row_desc[B0->r0 + i], ':') ? strchr(L->row_desc[B0->r0 + i], ':') + 1 : "");
      write_row_call(f, R);
      fprintf(f, "    phi[E->row + %d] = r.phi;\n    phid[E->row + %d] = mb_row_phidot(&r, m0, m1);\n"
                 "    rhs[%d + E->row + %d] = mb_row_gamma(&r, m0, m1);\n", i, i, m->nv, i);
      for (int s = 0; s < 2; s++) {
        int any = 0;
        for (int j = 0; j < 6; j++) any |= entry_varies(R, s, j);
        if (!any) continue;
        fprintf(f, "    mb_rigid_cols(&fr[E->b%d], m%d->P, r.dV[%d], r.dW[%d], c);\n", s, s, s, s);
        for (int j = 0; j < 6; j++)
          if (entry_varies(R, s, j)) {
            fprintf(f, "    Kx[E->K[%d]] = Kx[E->K[%d]] = c[%d];\n", 2 * slot, 2 * slot + 1, j);
            slot++;
          }
      }
    }
    fputs("  }\n", f);
  }
  free(K);
  return 0;
}

int emit_loops_eval(FILE *tables, FILE *body, const lmodel *L, const loop_choice *c) {
  loop_plan p;
  if (plan_groups(L, c, &p)) return -1;
  const mb_model *m = &L->m;
  fprintf(body, "\n  /* the loop form (emit_loops.c): frames and markers in arrays */\n"
                "  mb_frame fr[%d];\n  mb_marker mk[%d];\n",
          m->nbody, m->nmarker);
  write_bodies(tables, body, L, &p);
  write_markers(tables, body, L, c);
  write_forces(tables, body, L, &p);
  int failed = write_joints(tables, body, L, &p);
  plan_free(&p);
  return failed;
}

void emit_loops_init(FILE *f, const lmodel *L) {
  const mb_model *m = &L->m;
  fprintf(f, "  /* the loop form (emit_loops.c): the rigid bodies' mass and inertia (bodies[]), the\n"
             "     constant entries of the rows' D, -1 on marker 0's body and +1 on marker 1's (rows[]) */\n"
             "  for (int b = 0; b < %d; b++)\n    if (bodies[b].kind == MB_BODY_RIGID)\n"
             "      for (int j = 0; j < 12; j++)\n"
             "        if (bodies[b].mslot[j] >= 0) Kx[bodies[b].mslot[j]] = j < 3 ? bodies[b].mass : bodies[b].J[j - 3];\n",
          m->nbody);
  if (m->nrow)
    fprintf(f, "  for (int r = 0; r < %d; r++)\n    for (int s = 0; s < 2; s++)\n      for (int j = 0; j < 6; j++)\n"
               "        if (rows[r].constant[s][j] && rows[r].slot[s][j] >= 0)\n"
               "          Kx[rows[r].slot[s][j]] = Kx[rows[r].slotT[s][j]] = s ? 1 : -1;\n",
            m->nrow);
}
