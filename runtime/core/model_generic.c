/* model_generic.c: evaluates a model by walking its element tables: the
 * generic path, and the shared code for outputs, energy and coordinate
 * updates that the generated code also uses.  No allocation, no I/O. */
#include "mb_model.h"

const char *mb_status_text(int status) {
  switch (status) {
  case MB_OK: return "ok";
  case MB_ERR_SINGULAR: return "singular system matrix";
  case MB_ERR_NONFINITE: return "non-finite value (NaN or Inf) in the solution";
  case MB_ERR_STEP_TOO_SMALL: return "step size fell below the minimum";
  case MB_ERR_PROJECTION: return "coordinate projection did not converge";
  case MB_ERR_NOMEM: return "out of memory";
  case MB_ERR_INVALID: return "invalid settings";
  case MB_ERR_NEWTON: return "Newton iteration did not converge";
  case MB_ERR_STEP_BUDGET: return "more steps than the step budget (max_steps)";
  case MB_ERR_ENERGY: return "the energy blew up (the solution is wrong)";
  default: return "unknown error";
  }
}

/* most triplets one evaluation of the generic path can produce */
static size_t max_triplets(const mb_model *m) {
  size_t n = 0;
  for (int b = 0; b < m->nbody; b++) n += (size_t)(6 + m->body[b].nm) * (size_t)(6 + m->body[b].nm);
  for (int r = 0; r < m->nrow; r++)
    for (int s = 0; s < 2; s++) {
      int k = s ? m->row[r].m1 : m->row[r].m0;
      if (m->marker[k].body >= 0) n += 2 * (size_t)(6 + m->body[m->marker[k].body].nm);
    }
  return n;
}

static size_t frames_size(const mb_model *m) {
  size_t z = (size_t)m->nbody * sizeof(mb_frame) + (size_t)m->nmarker * sizeof(mb_marker);
  return (z + sizeof(double) - 1) / sizeof(double) * sizeof(double);
}

size_t mb_model_worksize(const mb_model *m) {
  return frames_size(m) + sizeof(mb_triplets) +
         max_triplets(m) * (2 * sizeof(int) + sizeof(mb_real)) + sizeof(double);
}

mb_triplets *mb_generic_triplets(const mb_model *m, void *work) {
  return (mb_triplets *)((char *)work + frames_size(m));
}

/* where an entry of K goes: a slot of the fixed pattern, or a triplet */
typedef struct {
  mb_real *Kx;
  mb_triplets *T;
} sink;

static inline void put(sink *k, int slot, int row, int col, mb_real x) {
  if (k->T) {
    mb_triplets *T = k->T;
    T->i[T->n] = row;
    T->j[T->n] = col;
    T->x[T->n] = x;
    T->n++;
  } else if (slot >= 0) {
    k->Kx[slot] = x;
  }
}

/* body frames at (q, v) */
static void frames_only(const mb_model *m, const mb_real *q, const mb_real *v, mb_frame *F) {
  for (int b = 0; b < m->nbody; b++)
    mb_frame_rigid(q + m->body[b].qadr, v + m->body[b].vadr, &F[b]);
}

/* marker k at (q, v) from its body's frame in F */
static void marker_from_frame(const mb_model *m, const mb_real *q, const mb_real *v, const mb_frame *F,
                              int k, mb_marker *mk) {
  const mb_markerdef *d = &m->marker[k];
  if (d->body < 0) {
    mb_marker_ground(d->s, d->C, mk);
  } else if (d->node >= 0) {
    const mb_body *B = &m->body[d->body];
    mb_marker_node(&F[d->body], B->flex, d->node, q + B->qadr + 7, v + B->vadr + 6, d->C, mk);
  } else {
    mb_marker_rigid(&F[d->body], d->s, d->C, mk);
  }
}

/* body frames and markers at (q, v) */
static void frames_and_markers(const mb_model *m, const mb_real *q, const mb_real *v,
                               mb_frame *F, mb_marker *MK) {
  frames_only(m, q, v, F);
  for (int k = 0; k < m->nmarker; k++) marker_from_frame(m, q, v, F, k, &MK[k]);
}

/* the body columns of a force-like pair (dV, dW) at marker k: 6 or 6 + nm values */
static int marker_cols(const mb_model *m, const mb_frame *F, const mb_marker *MK, int k,
                       const mb_real *q, const mb_real dV[3], const mb_real dW[3], mb_real *c) {
  const mb_markerdef *d = &m->marker[k];
  (void)q;
  const mb_body *B = &m->body[d->body];
  if (d->node >= 0) {
    mb_node_cols_mk(&F[d->body], B->flex, d->node, &MK[k], dV, dW, c);
    return 6 + B->nm;
  }
  mb_rigid_cols(&F[d->body], MK[k].P, dV, dW, c);
  return 6;
}

/* one constraint row, dispatched on its primitive */
static void row_eval(const mb_model *m, const mb_rowdef *rd, const mb_marker *MK, mb_real t,
                     mb_row *r) {
  static const mb_real none[3] = {0, 0, 0};
  mb_real x[3];
  const mb_marker *m0 = &MK[rd->m0], *m1 = &MK[rd->m1];
  switch (rd->kind) {
  case MB_PRIM_SPH: mb_prim_sph(m0, m1, rd->a, r); break;
  case MB_PRIM_DOT1: mb_prim_dot1(m0, m1, rd->a, rd->b, r); break;
  case MB_PRIM_DOT2: mb_prim_dot2(m0, m1, rd->a, none, r); break;
  case MB_PRIM_DIST: mb_prim_dist(m0, m1, rd->L, r); break;
  case MB_PRIM_ROT:
    mb_profile_eval(&m->profile[rd->profile], t, x);
    mb_prim_rot(m0, m1, x, r);
    break;
  case MB_PRIM_TRANS:
    mb_profile_eval(&m->profile[rd->profile], t, x);
    mb_prim_dot2(m0, m1, 2, x, r);
    break;
  }
}

/* add a force Fv at marker k's point and a torque T (global) into f */
static void add_wrench(const mb_model *m, const mb_frame *F, const mb_marker *MK, int k,
                       const mb_real *q, const mb_real Fv[3], const mb_real T[3], mb_real *f) {
  int b = m->marker[k].body;
  if (b < 0) return;
  mb_real c[6 + MB_MAX_MODES];
  int nc = marker_cols(m, F, MK, k, q, Fv, T, c);
  for (int j = 0; j < nc; j++) f[m->body[b].vadr + j] += c[j];
}

/* the bushing's reaction on body 0 acts at marker 1's point: the same
   pair of forces at one point (angular momentum is conserved) */
static void add_wrench_at(const mb_model *m, const mb_frame *F, int b, const mb_real P[3],
                          const mb_real Fv[3], const mb_real T[3], mb_real *f) {
  if (b < 0) return;
  mb_real c[6];
  mb_rigid_cols(&F[b], P, Fv, T, c);
  for (int j = 0; j < 6; j++) f[m->body[b].vadr + j] += c[j];
}

/* applied forces of the force elements, added into f; returns their potential energy */
static mb_real forces_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_frame *F,
                           const mb_marker *MK, mb_real *f) {
  static const mb_real zero[3] = {0, 0, 0};
  mb_real E = 0;
  for (int e = 0; e < m->nforce; e++) {
    const mb_forcedef *d = &m->force[e];
    const mb_marker *m0 = &MK[d->m0];
    int b0 = m->marker[d->m0].body;
    const mb_real *prm = m->force_prm + d->padr;
    switch (d->kind) {
    case MB_FORCE_POINT:
    case MB_FORCE_TORQUE: {
      mb_real s = 1, x[3], val[3];
      if (d->profile >= 0) { mb_profile_eval(&m->profile[d->profile], t, x); s = x[0]; }
      mb_point_vector(prm, s, d->local && b0 >= 0 ? F[b0].A : 0, val);
      if (d->kind == MB_FORCE_POINT)
        add_wrench(m, F, MK, d->m0, q, val, zero, f);
      else
        add_wrench(m, F, MK, d->m0, q, zero, val, f);
      break;
    }
    case MB_FORCE_SPRING: {
      mb_real F0[3], F1[3];
      const mb_marker *m1 = &MK[d->m1];
      E += mb_spring(m0, m1, prm, m->force_law + d->ladr, F0, F1, 0);
      add_wrench(m, F, MK, d->m0, q, F0, zero, f);
      add_wrench(m, F, MK, d->m1, q, F1, zero, f);
      break;
    }
    case MB_FORCE_FIELD: {
      mb_real Fv[3], T[3], mF[3], mT[3];
      const mb_marker *m1 = &MK[d->m1];
      E += mb_field(m0, m1, prm, Fv, T, 0);
      for (int j = 0; j < 3; j++) { mF[j] = -Fv[j]; mT[j] = -T[j]; }
      add_wrench(m, F, MK, d->m1, q, Fv, T, f);
      add_wrench_at(m, F, b0, m1->P, mF, mT, f); /* reaction at the same point */
      break;
    }
    case MB_FORCE_TYRE: {
      mb_real Fv[3], T[3];
      E += mb_tyre(m0, prm, Fv, T, 0, 0);
      add_wrench(m, F, MK, d->m0, q, Fv, T, f);
      break;
    }
    case MB_FORCE_SUPERELEMENT: {
      int n = (int)prm[MB_SUPER_N];
      const mb_marker *mk[MB_SUPER_MAX_NODES];
      mb_real Fv[3 * MB_SUPER_MAX_NODES], T[3 * MB_SUPER_MAX_NODES];
      for (int k = 0; k < n; k++) mk[k] = &MK[d->m1 + k];
      E += mb_superelement(m0, mk, prm, Fv, T);
      for (int k = 0; k < n; k++) {
        mb_real mF[3], mT[3];
        for (int j = 0; j < 3; j++) { mF[j] = -Fv[3 * k + j]; mT[j] = -T[3 * k + j]; }
        add_wrench(m, F, MK, d->m1 + k, q, Fv + 3 * k, T + 3 * k, f);
        add_wrench_at(m, F, b0, mk[k]->P, mF, mT, f); /* reaction at the same point */
      }
      break;
    }
    }
  }
  return E;
}

void mb_generic_init(const mb_model *m, mb_real *Kx) {
  for (int k = 0; k < m->nnz; k++) Kx[k] = 0;
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (B->kind == MB_BODY_FLEXIBLE) continue; /* written by every evaluation */
    for (int j = 0; j < 3; j++)
      if (B->mslot[j] >= 0) Kx[B->mslot[j]] = B->mass;
    for (int j = 0; j < 9; j++)
      if (B->mslot[3 + j] >= 0) Kx[B->mslot[3 + j]] = B->J[j];
  }
  /* the only constant constraint entries: a spherical row's translational
     columns, -1 on marker 0's body and +1 on marker 1's */
  for (int r = 0; r < m->nrow; r++) {
    const mb_rowdef *rd = &m->row[r];
    for (int s = 0; s < 2; s++)
      for (int j = 0; j < 6; j++)
        if (rd->constant[s][j] && rd->slot[s][j] >= 0) {
          Kx[rd->slot[s][j]] = s ? 1 : -1;
          Kx[rd->slotT[s][j]] = s ? 1 : -1;
        }
  }
}


/* the velocity Jacobian of side s of force element d, as d rows (the wrench
 * components the kernel's tangent is of: 3 forces for a spring, force and
 * torque for a field) over the side's nc body columns: row k is the body
 * columns of a unit wrench component k (J^T e_k) at the side's point */
static int tangent_jacobian(const mb_model *m, const mb_frame *F, const mb_marker *MK,
                            const mb_forcedef *d, int s, int dim, mb_real *A) {
  static const mb_real zero[3] = {0, 0, 0};
  int nc = mb_force_tangent_cols(m, (int)(d - m->force), s);
  if (!nc) return 0;
  int k = s ? d->m1 : d->m0;
  for (int r = 0; r < dim; r++) {
    mb_real e[3] = {0, 0, 0};
    e[r % 3] = 1;
    const mb_real *dV = r < 3 ? e : zero, *dW = r < 3 ? zero : e;
    if (d->kind == MB_FORCE_FIELD && s == 0) /* the reaction at marker 1's point */
      mb_rigid_cols(&F[m->marker[k].body], MK[d->m1].P, dV, dW, A + r * nc);
    else
      marker_cols(m, F, MK, k, 0, dV, dW, A + r * nc);
  }
  return nc;
}

void mb_model_force_tangent(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                            mb_real kfac, mb_real cfac, mb_real *Kx, void *work) {
  (void)t; /* no force kernel with a tangent depends on time */
  if (!m->force_tslot) return;
  mb_frame *F = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(F + m->nbody);
  frames_and_markers(m, q, v, F, MK);
  for (int e = 0; e < m->nforce; e++) {
    const mb_forcedef *d = &m->force[e];
    if (m->force_tslot[e] < 0) continue;
    const int *slot = m->tangent_slot + m->force_tslot[e];
    mb_real tan[72], F0[3], F1[3], T[3], S[36];
    int dim;
    if (d->kind == MB_FORCE_SPRING) {
      mb_spring(&MK[d->m0], &MK[d->m1], m->force_prm + d->padr, m->force_law + d->ladr, F0, F1, tan);
      dim = 3;
      for (int i = 0; i < 9; i++) S[i] = kfac * tan[i] + cfac * tan[9 + i];
    } else if (d->kind == MB_FORCE_FIELD) {
      mb_field(&MK[d->m0], &MK[d->m1], m->force_prm + d->padr, F1, T, tan);
      dim = 6;
      for (int i = 0; i < 36; i++) S[i] = kfac * tan[i] + cfac * tan[36 + i];
    } else if (d->kind == MB_FORCE_TYRE) {
      mb_tyre(&MK[d->m0], m->force_prm + d->padr, F1, T, 0, tan);
      dim = 6;
      for (int i = 0; i < 36; i++) S[i] = kfac * tan[i] + cfac * tan[36 + i];
    } else {
      continue;
    }
    /* the wrench W on side 1 depends on the relative motion A1 dq1 - A0 dq0
       (side 0 gets -W through A0): -df_s/dq_t = -sg_s sg_t A_s^T S A_t.  The
       tyre's wrench acts on its only side, 0, and depends on that side's
       motion alone: -df_0/dq_0 = -A_0^T S A_0, the same sign */
    mb_real A[2][6 * (6 + MB_MAX_MODES)], SA[6 * (6 + MB_MAX_MODES)];
    int nc[2];
    for (int s = 0; s < 2; s++) nc[s] = tangent_jacobian(m, F, MK, d, s, dim, A[s]);
    for (int s = 0; s < 2; s++)
      for (int u = 0; u < 2; u++) {
        int ns = nc[s], nu = nc[u];
        if (!ns || !nu) { slot += ns * nu; continue; }
        mb_real sign = (s == u) ? -1 : 1;
        for (int k = 0; k < dim; k++) /* SA = S A_u */
          for (int j = 0; j < nu; j++) {
            mb_real x = 0;
            for (int l = 0; l < dim; l++) x += S[dim * k + l] * A[u][l * nu + j];
            SA[k * nu + j] = x;
          }
        for (int i = 0; i < ns; i++)
          for (int j = 0; j < nu; j++) {
            mb_real x = 0;
            for (int k = 0; k < dim; k++) x += A[s][k * ns + i] * SA[k * nu + j];
            int sl = slot[i * nu + j];
            if (sl >= 0) Kx[sl] += sign * x;
          }
        slot += ns * nu;
      }
  }
}

/* a flexible body's mass block and forces: mb_flex_body, or with geometric
 * stiffening mb_flex_body_stiff through the body's pointer (its code is then
 * the model's, not the library's: the embedded flash budget) */
static void flex_block(const mb_body *B, const mb_frame *f, const mb_real *w, const mb_real *wd,
                       const mb_real g[3], mb_real *Mb, mb_real *fb) {
  if (B->stiff) B->stiff->body(B->flex, B->stiff, f, w, wd, g, Mb, fb);
  else mb_flex_body(B->flex, f, w, wd, g, Mb, fb);
}

/* The evaluation of both generic variants: entries of K go to the fixed
 * pattern's slots (K written by the caller's init for constants), or, on
 * the general path, every entry of every element block goes to triplets. */
static void generic_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                         sink *K, mb_real *rhs, mb_real *phi, mb_real *phid, void *work) {
  mb_frame *F = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(F + m->nbody);
  frames_and_markers(m, q, v, F, MK);

  /* body forces: gravity and the quadratic-velocity (gyroscopic) terms */
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    mb_real *f = rhs + B->vadr, s[3];
    if (B->kind == MB_BODY_FLEXIBLE) {
      mb_real Mb[(6 + MB_MAX_MODES) * (6 + MB_MAX_MODES)];
      int nb = 6 + B->nm;
      flex_block(B, &F[b], q + B->qadr + 7, v + B->vadr + 6, m->gravity, Mb, f);
      for (int i = 0; i < nb * nb; i++)
        if (K->T || B->mslotf[i] >= 0) put(K, B->mslotf[i], B->vadr + i / nb, B->vadr + i % nb, Mb[i]);
      continue;
    }
    if (K->T && B->kind == MB_BODY_RIGID) { /* the general path assembles M too */
      for (int j = 0; j < 3; j++) put(K, -1, B->vadr + j, B->vadr + j, B->mass);
      for (int j = 0; j < 9; j++) put(K, -1, B->vadr + 3 + j / 3, B->vadr + 3 + j % 3, B->J[j]);
    }
    for (int j = 0; j < 3; j++) f[j] = B->mass * m->gravity[j];
    mb_rigid_gyro(B->J, F[b].wl, s);
    for (int j = 0; j < 3; j++) f[3 + j] = s[j];
  }
  forces_eval(m, t, q, F, MK, rhs);

  /* constraint rows: D (both triangles of K), gamma, phi, phid */
  for (int r = 0; r < m->nrow; r++) {
    const mb_rowdef *rd = &m->row[r];
    mb_row row;
    row_eval(m, rd, MK, t, &row);
    phi[r] = row.phi;
    phid[r] = mb_row_phidot(&row, &MK[rd->m0], &MK[rd->m1]);
    rhs[m->nv + r] = mb_row_gamma(&row, &MK[rd->m0], &MK[rd->m1]);
    for (int s = 0; s < 2; s++) {
      int k = s ? rd->m1 : rd->m0;
      if (m->marker[k].body < 0) continue;
      mb_real c[6 + MB_MAX_MODES];
      int nc = marker_cols(m, F, MK, k, q, row.dV[s], row.dW[s], c);
      int col0 = m->body[m->marker[k].body].vadr, rowi = m->nv + r;
      if (K->T) { /* every column of the body: no compile-time structure */
        for (int j = 0; j < nc; j++) {
          put(K, -1, rowi, col0 + j, c[j]);
          put(K, -1, col0 + j, rowi, c[j]);
        }
        continue;
      }
      for (int j = 0; j < 6; j++)
        if (rd->slot[s][j] >= 0 && !rd->constant[s][j]) {
          put(K, rd->slot[s][j], rowi, col0 + j, c[j]);
          put(K, rd->slotT[s][j], col0 + j, rowi, c[j]);
        }
      if (rd->mslot[s] >= 0) {
        const int *ms = m->modal_slot + rd->mslot[s];
        int nm = nc - 6;
        for (int j = 0; j < nm; j++) {
          put(K, ms[j], rowi, col0 + 6 + j, c[6 + j]);
          put(K, ms[nm + j], col0 + 6 + j, rowi, c[6 + j]);
        }
      }
    }
  }
}

void mb_generic_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid, void *work) {
  sink K = {Kx, 0};
  generic_eval(m, t, q, v, &K, rhs, phi, phid, work);
}

void mb_generic_triplet_eval(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                             mb_real *Kx, mb_real *rhs, mb_real *phi, mb_real *phid,
                             void *work) {
  mb_triplets *T = mb_generic_triplets(m, work);
  size_t cap = max_triplets(m);
  T->i = (int *)(T + 1);
  T->j = T->i + cap;
  T->x = (mb_real *)(void *)(T->j + cap);
  T->n = 0;
  sink K = {Kx, T};
  generic_eval(m, t, q, v, &K, rhs, phi, phid, work);
}

void mb_generic_triplet_init(const mb_model *m, mb_real *Kx) {
  (void)m;
  (void)Kx; /* the general path assembles everything in every evaluation */
}

void mb_model_qdot(const mb_model *m, const mb_real *q, const mb_real *v, mb_real *qd) {
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    for (int j = 0; j < 3; j++) qd[B->qadr + j] = v[B->vadr + j];
    mb_euler_rates(q + B->qadr + 3, v + B->vadr + 3, qd + B->qadr + 3);
    for (int j = 0; j < B->nm; j++) qd[B->qadr + 7 + j] = v[B->vadr + 6 + j];
  }
}

void mb_model_qincrement(const mb_model *m, mb_real *q, const mb_real *dv) {
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    for (int j = 0; j < 3; j++) q[B->qadr + j] += dv[B->vadr + j];
    mb_euler_rotate(q + B->qadr + 3, dv + B->vadr + 3);
    for (int j = 0; j < B->nm; j++) q[B->qadr + 7 + j] += dv[B->vadr + 6 + j];
  }
}

void mb_model_normalize(const mb_model *m, mb_real *q) {
  for (int b = 0; b < m->nbody; b++) {
    mb_real *p = q + m->body[b].qadr + 3;
    mb_real n = MB_SQRT(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]);
    for (int j = 0; j < 4; j++) p[j] /= n;
  }
}

void mb_model_energy(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real *kinetic, mb_real *potential, void *work) {
  mb_frame *F = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(F + m->nbody);
  frames_and_markers(m, q, v, F, MK);
  mb_real T = 0, U = 0;
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (B->kind == MB_BODY_FLEXIBLE) {
      const mb_flex *fx = B->flex;
      const mb_real *w = q + B->qadr + 7;
      mb_real Mb[(6 + MB_MAX_MODES) * (6 + MB_MAX_MODES)], fb[6 + MB_MAX_MODES], S[3], AS[3];
      { /* 1/2 v^T Mb v (mb_flex_kinetic through the one flex_block) */
        static const mb_real zero[3] = {0, 0, 0};
        int nb = 6 + fx->nm;
        mb_real vb[6 + MB_MAX_MODES];
        flex_block(B, &F[b], w, v + B->vadr + 6, zero, Mb, fb);
        for (int i = 0; i < 3; i++) { vb[i] = F[b].rd[i]; vb[3 + i] = F[b].wl[i]; }
        for (int j = 0; j < fx->nm; j++) vb[6 + j] = v[B->vadr + 6 + j];
        for (int i = 0; i < nb; i++)
          for (int l = 0; l < nb; l++) T += MB_R(0.5) * vb[i] * Mb[nb * i + l] * vb[l];
      }
      /* gravity: -g . (m r + A S(w));  elastic: 1/2 sum k_j w_j^2 */
      mb_real dS[3];
      mb_modal3(fx->S1, fx->nm, w, S);
      mb_flex_stiff_S(B->stiff, fx, w, dS); /* geometric stiffening: the second-order part */
      for (int i = 0; i < 3; i++) S[i] += fx->S0[i] + dS[i];
      mb_mul3(F[b].A, S, AS);
      U -= mb_dot3(m->gravity, AS) + fx->mass * mb_dot3(m->gravity, F[b].r);
      for (int j = 0; j < fx->nm; j++) U += MB_R(0.5) * fx->stiffness[j] * w[j] * w[j];
      continue;
    }
    T += mb_rigid_kinetic(B->mass, B->J, &F[b]);
    U -= B->mass * mb_dot3(m->gravity, F[b].r);
  }
  /* force elements: their potential (the forces themselves are not needed) */
  for (int e = 0; e < m->nforce; e++) {
    const mb_forcedef *d = &m->force[e];
    const mb_real *prm = m->force_prm + d->padr;
    mb_real F0[3], F1[3];
    switch (d->kind) {
    case MB_FORCE_POINT:
    case MB_FORCE_TORQUE: break; /* applied loads: no potential */
    case MB_FORCE_SPRING: U += mb_spring(&MK[d->m0], &MK[d->m1], prm, m->force_law + d->ladr, F0, F1, 0); break;
    case MB_FORCE_FIELD: U += mb_field(&MK[d->m0], &MK[d->m1], prm, F0, F1, 0); break;
    case MB_FORCE_TYRE: U += mb_tyre(&MK[d->m0], prm, F0, F1, 0, 0); break;
    case MB_FORCE_SUPERELEMENT: {
      const mb_marker *mk[MB_SUPER_MAX_NODES];
      mb_real Fs[3 * MB_SUPER_MAX_NODES], Ts[3 * MB_SUPER_MAX_NODES];
      for (int k = 0; k < (int)prm[MB_SUPER_N]; k++) mk[k] = &MK[d->m1 + k];
      U += mb_superelement(&MK[d->m0], mk, prm, Fs, Ts);
      break;
    }
    }
  }
  (void)t;
  *kinetic = T;
  *potential = U;
}

/* force element k's force and torque on its body 1 about its marker point, from
 * the markers: the same kernels and scaling as forces_eval */
static void force_wrench_markers(const mb_model *m, int k, mb_real t, const mb_frame *F,
                                 const mb_marker *MK, mb_real Fv[3], mb_real T[3]) {
  const mb_forcedef *d = &m->force[k];
  const mb_real *prm = m->force_prm + d->padr;
  int b0 = m->marker[d->m0].body;
  for (int j = 0; j < 3; j++) Fv[j] = T[j] = 0;
  switch (d->kind) {
  case MB_FORCE_POINT:
  case MB_FORCE_TORQUE: {
    mb_real s = 1, x[3];
    if (d->profile >= 0) { mb_profile_eval(&m->profile[d->profile], t, x); s = x[0]; }
    mb_point_vector(prm, s, d->local && b0 >= 0 ? F[b0].A : 0, d->kind == MB_FORCE_POINT ? Fv : T);
    break;
  }
  case MB_FORCE_SPRING: {
    mb_real F0[3];
    mb_spring(&MK[d->m0], &MK[d->m1], prm, m->force_law + d->ladr, F0, Fv, 0);
    break;
  }
  case MB_FORCE_FIELD:
    mb_field(&MK[d->m0], &MK[d->m1], prm, Fv, T, 0);
    break;
  case MB_FORCE_TYRE: /* one marker, the wheel centre: force and torque on the wheel */
    mb_tyre(&MK[d->m0], prm, Fv, T, 0, 0);
    break;
  case MB_FORCE_SUPERELEMENT: { /* the wrench on its node 1 (marker m1) */
    const mb_marker *mk[MB_SUPER_MAX_NODES];
    mb_real Fs[3 * MB_SUPER_MAX_NODES], Ts[3 * MB_SUPER_MAX_NODES];
    for (int k = 0; k < (int)prm[MB_SUPER_N]; k++) mk[k] = &MK[d->m1 + k];
    mb_superelement(&MK[d->m0], mk, prm, Fs, Ts);
    for (int j = 0; j < 3; j++) { Fv[j] = Fs[j]; T[j] = Ts[j]; }
    break;
  }
  }
}

void mb_force_wrench(const mb_model *m, int k, mb_real t, const mb_real *q, const mb_real *v,
                     mb_real F[3], mb_real T[3], void *work) {
  mb_frame *Fr = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(Fr + m->nbody);
  frames_and_markers(m, q, v, Fr, MK);
  force_wrench_markers(m, k, t, Fr, MK, F, T);
}

/* position P, velocity V and (with vd) acceleration Acc, global, of a point of
 * body b: s in body axes, or FE node 'node' of a flexible body; b = -1: the
 * fixed global point s.  Builds the body's frame itself, so that it also
 * serves at the initial state. */
static void point_motion(const mb_model *m, int b, const mb_real s[3], int node, const mb_real *q,
                         const mb_real *v, const mb_real *vd, mb_real P[3], mb_real V[3], mb_real Acc[3]) {
  if (b < 0) {
    for (int j = 0; j < 3; j++) { P[j] = s[j]; V[j] = Acc[j] = 0; }
    return;
  }
  const mb_body *B = &m->body[b];
  mb_frame f;
  mb_frame_rigid(q + B->qadr, v + B->vadr, &f);
  mb_real u[3], t1[3], t2[3], wd[3];
  const mb_real *a = vd ? vd + B->vadr : 0;
  if (a) mb_mul3(f.A, a + 3, wd);
  if (node >= 0) {
    static const mb_real I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    const mb_flex *fx = B->flex;
    const mb_real *w = q + B->qadr + 7;
    mb_marker nk;
    mb_marker_node(&f, fx, node, w, v + B->vadr + 6, I3, &nk);
    for (int j = 0; j < 3; j++) { P[j] = nk.P[j]; V[j] = nk.V[j]; }
    if (!a) return;
    /* Acc = rdd + A (wd' x b + X wdd) + aP,  b = x_k + X_k w the node in body axes */
    mb_real b3[3], Xa[3], l[3];
    mb_modal3(fx->node_X + 3 * node * fx->nm, fx->nm, w, b3);
    for (int j = 0; j < 3; j++) b3[j] += fx->node_x[3 * node + j];
    mb_modal3(fx->node_X + 3 * node * fx->nm, fx->nm, a + 6, Xa);
    mb_cross3(a + 3, b3, l);
    for (int j = 0; j < 3; j++) l[j] += Xa[j];
    mb_mul3(f.A, l, t1);
    for (int j = 0; j < 3; j++) Acc[j] = a[j] + t1[j] + nk.aP[j];
    return;
  }
  mb_mul3(f.A, s, u);
  mb_cross3(f.w, u, t1);
  for (int j = 0; j < 3; j++) { P[j] = f.r[j] + u[j]; V[j] = f.rd[j] + t1[j]; }
  if (!a) return;
  mb_cross3(wd, u, t1);
  mb_wwa(f.w, u, t2);
  for (int j = 0; j < 3; j++) Acc[j] = a[j] + t1[j] + t2[j];
}

/* RELATIVE: with r = P - P2 (global) and R the frame body's rotation, d = R^T r
 * and its first and second time derivatives as seen in that body,
 *   d' = R^T r' - w x d,  d'' = R^T r'' - wd x d - 2 w x d' - w x (w x d)
 * (w, wd: the body's angular velocity and acceleration in its own axes); the
 * displacement is d less its value at the initial state q0 (from_initial). */
static void relative_motion(const mb_model *m, const mb_outputdef *o, const mb_real *q, const mb_real *v,
                            const mb_real *vd, int from_initial, mb_real val[3]) {
  mb_real P[3], V[3], Acc[3] = {0, 0, 0}, P2[3], V2[3], Acc2[3] = {0, 0, 0}, r[3], rd[3], rdd[3];
  const mb_real *need_vd = o->quantity == MB_QUANTITY_ACCELERATION ? vd : 0;
  point_motion(m, o->body, o->s, o->node, q, v, need_vd, P, V, Acc);
  point_motion(m, o->body2, o->s2, o->node2, q, v, need_vd, P2, V2, Acc2);
  for (int j = 0; j < 3; j++) { r[j] = P[j] - P2[j]; rd[j] = V[j] - V2[j]; rdd[j] = Acc[j] - Acc2[j]; }
  if (o->frame < 0) {
    const mb_real *x = o->quantity == MB_QUANTITY_POSITION ? r : o->quantity == MB_QUANTITY_VELOCITY ? rd : rdd;
    for (int j = 0; j < 3; j++) val[j] = x[j];
  } else {
    const mb_body *B = &m->body[o->frame];
    mb_frame f;
    mb_frame_rigid(q + B->qadr, v + B->vadr, &f);
    mb_real d[3], dd[3], t1[3], t2[3], t3[3];
    mb_mul3t(f.A, r, d);
    mb_mul3t(f.A, rd, dd);
    mb_cross3(f.wl, d, t1);
    for (int j = 0; j < 3; j++) dd[j] -= t1[j];
    if (o->quantity == MB_QUANTITY_POSITION) for (int j = 0; j < 3; j++) val[j] = d[j];
    else if (o->quantity == MB_QUANTITY_VELOCITY) for (int j = 0; j < 3; j++) val[j] = dd[j];
    else {
      mb_mul3t(f.A, rdd, val);
      mb_cross3(vd + B->vadr + 3, d, t1);
      mb_cross3(f.wl, dd, t2);
      mb_wwa(f.wl, d, t3);
      for (int j = 0; j < 3; j++) val[j] -= t1[j] + 2 * t2[j] + t3[j];
    }
  }
  if (o->quantity == MB_QUANTITY_POSITION && from_initial) {
    mb_real d0[3];
    relative_motion(m, o, m->q0, m->v0, 0, 0, d0);
    for (int j = 0; j < 3; j++) val[j] -= d0[j];
  }
}

/* a marker of the table at (q, v), its body's frame built here */
static void marker_at(const mb_model *m, int k, const mb_real *q, const mb_real *v, mb_marker *mk) {
  const mb_markerdef *d = &m->marker[k];
  if (d->body < 0) { mb_marker_ground(d->s, d->C, mk); return; }
  const mb_body *B = &m->body[d->body];
  mb_frame f;
  mb_frame_rigid(q + B->qadr, v + B->vadr, &f);
  if (d->node >= 0) mb_marker_node(&f, B->flex, d->node, q + B->qadr + 7, v + B->vadr + 6, d->C, mk);
  else mb_marker_rigid(&f, d->s, d->C, mk);
}

/* JOINT: the rotation from marker 0's x axis to marker 1's about marker 0's z
 * axis (as a rotation driver measures it) and the travel of marker 1's point
 * along that axis, at (q, v), less their values at the initial state q0; the
 * angle is the branch nearest 'ref' (unwrapped, radians) when it is given */
static void joint_motion(const mb_model *m, const mb_outputdef *o, const mb_real *q, const mb_real *v,
                         const mb_real *ref, mb_real *angle, mb_real *travel) {
  mb_marker k0, k1, i0, i1;
  mb_real x0[3], y0[3], z0[3], x1[3], d[3];
  marker_at(m, o->jmarker[0], q, v, &k0);
  marker_at(m, o->jmarker[1], q, v, &k1);
  marker_at(m, o->jmarker[0], m->q0, m->v0, &i0);
  marker_at(m, o->jmarker[1], m->q0, m->v0, &i1);
  mb_real a = 0;
  for (int s = 0; s < 2; s++) { /* now, then at q0 */
    const mb_marker *A = s ? &i0 : &k0, *B = s ? &i1 : &k1;
    mb_col3(A->R, 0, x0);
    mb_col3(A->R, 1, y0);
    mb_col3(A->R, 2, z0);
    mb_col3(B->R, 0, x1);
    for (int j = 0; j < 3; j++) d[j] = B->P[j] - A->P[j];
    mb_real an = MB_ATAN2(mb_dot3(y0, x1), mb_dot3(x0, x1)), tr = mb_dot3(z0, d);
    if (s) { a -= an; *travel -= tr; }
    else { a = an; *travel = tr; }
  }
  if (ref && MB_ISFINITE(*ref)) a += 2 * MB_R(MB_PI) * MB_NEARBYINT((*ref - a) / (2 * MB_R(MB_PI)));
  *angle = a;
}

/* CENTER_OF_MASS: the mass-weighted position, velocity or acceleration of the
 * bodies (a flexible body with its deformation: m r + A S(w), S = S0 + S1 w) */
static void center_of_mass(const mb_model *m, const mb_outputdef *o, const mb_real *q, const mb_real *v,
                           const mb_real *vd, mb_real val[3]) {
  mb_real total = 0, sum[3] = {0, 0, 0};
  for (int b = 0; b < m->nbody; b++) {
    const mb_body *B = &m->body[b];
    if (o->node >= 0 && m->output_coef[o->node + b] == 0) continue;
    mb_frame f;
    mb_frame_rigid(q + B->qadr, v + B->vadr, &f);
    const mb_real *a = vd ? vd + B->vadr : 0;
    mb_real mass = B->mass, x[3] = {0, 0, 0}, l[3] = {0, 0, 0}, S[3], Sd[3], t1[3], t2[3], g[3];
    if (B->kind == MB_BODY_FLEXIBLE) {
      /* the first moment A S about the frame origin and its derivatives, body axes in l */
      const mb_flex *fx = B->flex;
      const mb_real *w = q + B->qadr + 7, *wd = v + B->vadr + 6;
      mass = fx->mass;
      mb_modal3(fx->S1, fx->nm, w, S);
      for (int j = 0; j < 3; j++) S[j] += fx->S0[j];
      mb_modal3(fx->S1, fx->nm, wd, Sd);
      if (o->quantity == MB_QUANTITY_POSITION) {
        for (int j = 0; j < 3; j++) l[j] = S[j];
      } else if (o->quantity == MB_QUANTITY_VELOCITY) {
        mb_cross3(f.wl, S, t1);
        for (int j = 0; j < 3; j++) l[j] = t1[j] + Sd[j];
      } else {
        mb_real Sdd[3];
        mb_modal3(fx->S1, fx->nm, a + 6, Sdd);
        mb_cross3(a + 3, S, t1);
        mb_wwa(f.wl, S, t2);
        mb_cross3(f.wl, Sd, g);
        for (int j = 0; j < 3; j++) l[j] = t1[j] + t2[j] + 2 * g[j] + Sdd[j];
      }
      mb_mul3(f.A, l, x);
    }
    const mb_real *c = o->quantity == MB_QUANTITY_POSITION ? f.r : o->quantity == MB_QUANTITY_VELOCITY ? f.rd : a;
    for (int j = 0; j < 3; j++) sum[j] += mass * c[j] + x[j];
    total += mass;
  }
  for (int j = 0; j < 3; j++) val[j] = total > 0 ? sum[j] / total : 0;
}

/* the angle of a body-fixed direction about a global axis, measured from its
 * initial direction, in radians; with a reference (the unwrapped angle a
 * moment ago, radians, less than pi away) the branch nearest to it.  Closed
 * form, not a loop: a huge or non-finite reference cannot make it spin. */
static mb_real body_angle(const mb_outputdef *o, const mb_frame *f, const mb_real *ref) {
  mb_real u[3], c[3];
  mb_mul3(f->A, o->u, u);
  mb_cross3(o->u_g, u, c);
  mb_real a = MB_ATAN2(mb_dot3(o->axis_g, c), mb_dot3(o->u_g, u));
  if (ref && MB_ISFINITE(*ref)) a += 2 * MB_R(MB_PI) * MB_NEARBYINT((*ref - a) / (2 * MB_R(MB_PI)));
  return a;
}

/* a JOINT output with an angle column (to unwrap) */
static int joint_angle_output(const mb_outputdef *o) {
  return o->kind == MB_OUT_JOINT && (o->joint_dofs & 1);
}

void mb_model_track_angles(const mb_model *m, const mb_real *q, const mb_real *v, mb_real *ref,
                           int have_ref, void *work) {
  int any = 0;
  for (int k = 0; k < m->noutput; k++) any |= m->output[k].kind == MB_OUT_ANGLE || joint_angle_output(&m->output[k]);
  if (!any) return;
  mb_frame *F = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(F + m->nbody);
  frames_and_markers(m, q, v, F, MK);
  for (int k = 0; k < m->noutput; k++) {
    const mb_outputdef *o = &m->output[k];
    if (o->kind == MB_OUT_ANGLE) ref[o->col] = body_angle(o, &F[o->body], have_ref ? ref + o->col : 0);
    if (joint_angle_output(o)) {
      mb_real travel;
      joint_motion(m, o, q, v, have_ref ? ref + o->col : 0, ref + o->col, &travel);
    }
  }
}

/* called after every step: only the frames and markers the angle outputs
 * read are formed, not the model's every marker */
double mb_model_angle_step(const mb_model *m, const mb_real *q, const mb_real *v, void *work) {
  int any = 0;
  for (int k = 0; k < m->noutput; k++) any |= m->output[k].kind == MB_OUT_ANGLE || joint_angle_output(&m->output[k]);
  if (!any) return (double)INFINITY; /* INFINITY is a float: the cast keeps -Wdouble-promotion quiet */
  (void)work;
  mb_real wmax = 0;
  for (int k = 0; k < m->noutput; k++) {
    const mb_outputdef *o = &m->output[k];
    mb_real w[3];
    if (o->kind == MB_OUT_ANGLE) {
      mb_frame f;
      mb_frame_rigid(q + m->body[o->body].qadr, v + m->body[o->body].vadr, &f);
      for (int j = 0; j < 3; j++) w[j] = f.w[j];
    } else if (joint_angle_output(o)) { /* the joint's relative angular velocity */
      mb_marker k0, k1;
      marker_at(m, o->jmarker[0], q, v, &k0);
      marker_at(m, o->jmarker[1], q, v, &k1);
      for (int j = 0; j < 3; j++) w[j] = k1.W[j] - k0.W[j];
    } else {
      continue;
    }
    wmax = MB_FMAX(wmax, MB_SQRT(w[0] * w[0] + w[1] * w[1] + w[2] * w[2]));
  }
  /* a quarter turn at most between two unwrappings (pi would be ambiguous) */
  return wmax > 0 ? (double)(MB_R(0.25) * MB_R(MB_PI) / wmax) : (double)INFINITY;
}

/* the two markers of constraint row rd, from the frames F */
static void need_row_markers(const mb_model *m, const mb_rowdef *rd, const mb_real *q, const mb_real *v,
                             const mb_frame *F, mb_marker *MK) {
  marker_from_frame(m, q, v, F, rd->m0, &MK[rd->m0]);
  marker_from_frame(m, q, v, F, rd->m1, &MK[rd->m1]);
}

void mb_model_outputs(const mb_model *m, mb_real t, const mb_real *q, const mb_real *v,
                      const mb_real *vd, const mb_real *lambda, const mb_real *prev,
                      mb_real *out, void *work) {
  mb_frame *F = (mb_frame *)work;
  mb_marker *MK = (mb_marker *)(F + m->nbody);
  mb_real kin = 0, pot = 0;
  int need_energy = 0;
  for (int k = 0; k < m->noutput; k++) {
    mb_output_kind kind = m->output[k].kind;
    if (kind == MB_OUT_KINETIC_ENERGY || kind == MB_OUT_POTENTIAL_ENERGY ||
        kind == MB_OUT_TOTAL_ENERGY)
      need_energy = 1;
  }
  if (need_energy) mb_model_energy(m, t, q, v, &kin, &pot, work);
  /* every frame, but only the markers an output reads (need_marker): a row
     comes at every output time, and a flexible body's node markers are
     costly */
  frames_only(m, q, v, F);

  for (int k = 0; k < m->noutput; k++) {
    const mb_outputdef *o = &m->output[k];
    const mb_frame *f = o->body >= 0 ? &F[o->body] : 0;
    mb_real val[7] = {0, 0, 0, 0, 0, 0, 0}, u[3], tmp[3], tmp2[3];
    int nval = 3;
    if (o->kind == MB_OUT_ACCELERATION && o->node >= 0) { /* a node of a flexible body */
      mb_real P[3], V[3];
      point_motion(m, o->body, o->s, o->node, q, v, vd, P, V, val);
      if (o->component >= 0) out[o->col] = o->scale * val[o->component];
      else for (int j = 0; j < 3; j++) out[o->col + j] = o->scale * val[j];
      continue;
    }
    if ((o->kind == MB_OUT_POSITION || o->kind == MB_OUT_VELOCITY) && o->node >= 0) {
      /* a node of a flexible body */
      const mb_body *B = &m->body[o->body];
      static const mb_real I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
      mb_marker nk;
      mb_marker_node(f, B->flex, o->node, q + B->qadr + 7, v + B->vadr + 6, I3, &nk);
      for (int j = 0; j < 3; j++) val[j] = o->kind == MB_OUT_POSITION ? nk.P[j] : nk.V[j];
      if (o->component >= 0) out[o->col] = o->scale * val[o->component];
      else for (int j = 0; j < 3; j++) out[o->col + j] = o->scale * val[j];
      continue;
    }
    switch (o->kind) {
    case MB_OUT_POSITION:
      mb_mul3(f->A, o->s, u);
      for (int j = 0; j < 3; j++) val[j] = f->r[j] + u[j];
      break;
    case MB_OUT_ORIENTATION: {
      const mb_real *p = q + m->body[o->body].qadr + 3;
      mb_real n = MB_SQRT(p[0] * p[0] + p[1] * p[1] + p[2] * p[2] + p[3] * p[3]);
      for (int j = 0; j < 4; j++) val[j] = p[j] / n;
      nval = 4;
      break;
    }
    case MB_OUT_ANGLE:
      val[0] = body_angle(o, f, prev ? prev + o->col : 0);
      nval = 1;
      break;
    case MB_OUT_VELOCITY:
      mb_mul3(f->A, o->s, u);
      mb_cross3(f->w, u, tmp);
      for (int j = 0; j < 3; j++) val[j] = f->rd[j] + tmp[j];
      break;
    case MB_OUT_ANGULAR_VELOCITY:
      for (int j = 0; j < 3; j++) val[j] = f->w[j];
      break;
    case MB_OUT_ACCELERATION: {
      const mb_real *a = vd + m->body[o->body].vadr;
      mb_real wd[3];
      mb_mul3(f->A, a + 3, wd);
      mb_mul3(f->A, o->s, u);
      mb_cross3(wd, u, tmp);
      mb_wwa(f->w, u, tmp2);
      for (int j = 0; j < 3; j++) val[j] = a[j] + tmp[j] + tmp2[j];
      break;
    }
    case MB_OUT_ANGULAR_ACCELERATION:
      mb_mul3(f->A, vd + m->body[o->body].vadr + 3, val);
      break;
    case MB_OUT_REACTION:
      /* constraint force on body 1 at its joint point: -sum lambda (dV1, dW1) */
      for (int r = 0; r < m->nrow; r++) {
        if (m->row[r].joint != o->joint) continue;
        mb_row row;
        need_row_markers(m, &m->row[r], q, v, F, MK);
        row_eval(m, &m->row[r], MK, t, &row);
        for (int j = 0; j < 3; j++) {
          val[j] -= lambda[r] * row.dV[1][j];
          val[3 + j] -= lambda[r] * row.dW[1][j];
        }
      }
      nval = 6;
      break;
    case MB_OUT_EFFORT:
      nval = 1;
      if (o->driver_row >= 0) {
        mb_row row;
        mb_real z[3];
        need_row_markers(m, &m->row[o->driver_row], q, v, F, MK);
        marker_from_frame(m, q, v, F, o->driver_marker, &MK[o->driver_marker]);
        row_eval(m, &m->row[o->driver_row], MK, t, &row);
        mb_col3(MK[o->driver_marker].R, 2, z);
        val[0] = -lambda[o->driver_row] * mb_dot3(o->driver_rotation ? row.dW[1] : row.dV[1], z);
      }
      break;
    case MB_OUT_DEFLECTION: {
      /* node deflection X_k w in body axes, less the chord between two nodes */
      const mb_body *B = &m->body[o->body];
      const mb_flex *fx = B->flex;
      const mb_real *w = q + B->qadr + 7;
      mb_modal3(fx->node_X + 3 * o->node * fx->nm, fx->nm, w, val);
      if (o->chord[0] >= 0) {
        mb_real d0[3], d1[3], x0[3], x1[3], xk[3];
        mb_modal3(fx->node_X + 3 * o->chord[0] * fx->nm, fx->nm, w, d0);
        mb_modal3(fx->node_X + 3 * o->chord[1] * fx->nm, fx->nm, w, d1);
        for (int j = 0; j < 3; j++) {
          x0[j] = fx->node_x[3 * o->chord[0] + j];
          x1[j] = fx->node_x[3 * o->chord[1] + j];
          xk[j] = fx->node_x[3 * o->node + j];
        }
        /* the chord point at the node's position along the undeformed chord */
        mb_real e[3] = {x1[0] - x0[0], x1[1] - x0[1], x1[2] - x0[2]}, r[3];
        for (int j = 0; j < 3; j++) r[j] = xk[j] - x0[j];
        mb_real s = mb_dot3(r, e) / mb_dot3(e, e);
        for (int j = 0; j < 3; j++) val[j] -= (1 - s) * d0[j] + s * d1[j];
      }
      break;
    }
    case MB_OUT_MODAL: {
      const mb_body *B = &m->body[o->body];
      nval = 1;
      val[0] = q[B->qadr + 7 + o->node];
      break;
    }
    case MB_OUT_MOMENTUM:
      /* linear momentum and angular momentum about the global origin */
      for (int b = 0; b < m->nbody; b++) {
        const mb_body *B = &m->body[b];
        mb_real p[3], h[3], Ah[3], rp[3];
        if (B->kind == MB_BODY_FLEXIBLE) {
          int nb = 6 + B->nm;
          mb_real Mb[(6 + MB_MAX_MODES) * (6 + MB_MAX_MODES)], fb[6 + MB_MAX_MODES];
          static const mb_real zero[3] = {0, 0, 0};
          const mb_real *vb = v + B->vadr;
          flex_block(B, &F[b], q + B->qadr + 7, vb + 6, zero, Mb, fb);
          for (int i = 0; i < 3; i++) {
            p[i] = h[i] = 0;
            for (int l = 0; l < nb; l++) {
              p[i] += Mb[nb * i + l] * vb[l];
              h[i] += Mb[nb * (3 + i) + l] * vb[l];
            }
          }
          /* h holds S~ A^T rd + J w' + M_thf wd: momentum about the frame origin, body axes */
        } else {
          for (int i = 0; i < 3; i++) p[i] = B->mass * F[b].rd[i];
          mb_mul3(B->J, F[b].wl, h);
        }
        mb_mul3(F[b].A, h, Ah);
        mb_cross3(F[b].r, p, rp);
        for (int i = 0; i < 3; i++) { val[i] += p[i]; val[3 + i] += rp[i] + Ah[i]; }
      }
      nval = 6;
      break;
    case MB_OUT_SECTION: {
      /* beam section forces or a stress: rows of coefficients times w */
      const mb_body *B = &m->body[o->body];
      const mb_real *w = q + B->qadr + 7, *c = m->output_coef + o->node;
      nval = o->ncols;
      for (int i = 0; i < nval; i++)
        for (int j = 0; j < B->nm; j++) val[i] += c[i * B->nm + j] * w[j];
      break;
    }
    case MB_OUT_TYRE: {
      /* the tyre's forces, moments, slips and deflection (output's component: one of them) */
      const mb_forcedef *d = &m->force[o->joint];
      mb_tyre_state ts;
      mb_real Fv[3], Tv[3], all[10];
      marker_from_frame(m, q, v, F, d->m0, &MK[d->m0]);
      mb_tyre(&MK[d->m0], m->force_prm + d->padr, Fv, Tv, &ts, 0);
      all[0] = ts.Fx; all[1] = ts.Fy; all[2] = ts.Fz; all[3] = ts.Mx; all[4] = ts.My;
      all[5] = ts.Mz; all[6] = ts.slip; all[7] = ts.slip_angle; all[8] = ts.camber;
      all[9] = ts.deflection;
      if (o->component >= 0) out[o->col] = o->scale * all[o->component];
      else for (int j = 0; j < 10; j++) out[o->col + j] = o->scale * all[j];
      continue;
    }
    case MB_OUT_FORCE: {
      const mb_forcedef *d = &m->force[o->element];
      if (d->m0 >= 0) marker_from_frame(m, q, v, F, d->m0, &MK[d->m0]);
      if (d->m1 >= 0) marker_from_frame(m, q, v, F, d->m1, &MK[d->m1]);
      force_wrench_markers(m, o->element, t, F, MK, val, val + 3);
      nval = 6;
      if (d->kind == MB_FORCE_SPRING) { /* tension: the pull along P1 - P0 (F1 = -T n) */
        mb_real d1[3];
        for (int j = 0; j < 3; j++) d1[j] = MK[d->m1].P[j] - MK[d->m0].P[j];
        val[6] = -mb_dot3(val, d1) / MB_SQRT(mb_dot3(d1, d1));
      }
      break;
    }
    case MB_OUT_RELATIVE:
      relative_motion(m, o, q, v, vd, 1, val);
      break;
    case MB_OUT_JOINT: {
      mb_real angle, travel;
      joint_motion(m, o, q, v, prev ? prev + o->col : 0, &angle, &travel);
      nval = o->ncols;
      if (o->joint_dofs == 2) val[0] = travel;
      else { val[0] = angle; val[1] = travel; }
      break;
    }
    case MB_OUT_CENTER_OF_MASS:
      center_of_mass(m, o, q, v, vd, val);
      break;
    case MB_OUT_KINETIC_ENERGY: val[0] = kin; nval = 1; break;
    case MB_OUT_POTENTIAL_ENERGY: val[0] = pot; nval = 1; break;
    case MB_OUT_TOTAL_ENERGY: val[0] = kin + pot; nval = 1; break;
    }
    if (o->component >= 0 && o->ncols == 1 && nval > 1) {
      out[o->col] = o->scale * val[o->component];
    } else {
      for (int j = 0; j < o->ncols; j++) out[o->col + j] = o->scale * val[j];
    }
  }
}
