/* fe.c: 3D beam finite elements (Euler-Bernoulli and Timoshenko stiffness,
 * consistent and HRZ-lumped mass), dense assembly, and the modal reduction of
 * a flexible body: constrained normal modes or Craig-Bampton (LAPACK: the
 * generalized symmetric-definite eigenproblem, see gen_eig), mode selection,
 * and the modal data file (docs/modal-file.md): the selection among its
 * modes (the front end reads it: compiler/front/modal_file.c), and writing one.
 *
 * Conventions.  6 DOFs per node: ux uy uz rx ry rz in body axes.  An
 * element's local frame: x from node 0 to node 1, y = the section's yaxis
 * made perpendicular to x, z = x cross y.  Bending in the local x-y plane
 * (uy, rz) uses Iz and the shear area ratio shear_y; in the x-z plane (uz, ry)
 * Iy and shear_z; torsion G J; axial E A.  Shear parameter (Przemieniecki)
 * Phi = 12 E I / (G A_s L^2) with A_s = ratio * A (0 for Euler-Bernoulli).
 * Mass:
 *   consistent, Euler-Bernoulli: the standard cubic-Hermite translational
 *     mass (rhoAL/420 [156 22L 54 -13L; ...]) without rotary inertia;
 *   consistent, Timoshenko: Przemieniecki's shear-dependent translational
 *     mass plus the rotary inertia of the sections (rho I terms), both with Phi;
 *   axial rho A L/6 [2 1; 1 2]; torsion rho Ip L/6 [2 1; 1 2] with the polar
 *     moment Ip = Iy + Iz (the mass moment of the section about the axis; the
 *     torsion constant J is a stiffness property and is smaller than Ip for any
 *     non-circular section);
 *   lumped (HRZ): each node gets rho A L/2 in every direction, the bending
 *     rotary inertia (rho A L/2) m22/m11 of the translational consistent matrix
 *     (= rho A L^3/78 for Euler-Bernoulli) plus, for Timoshenko, half the
 *     section rotary inertia rho I L/2; torsion rho Ip L/2.  In body axes the
 *     node's rotary inertia is a full 3x3 block.
 * A non-structural mass per length (nsm) adds to rho A in the translational
 * and bending terms, not to the section rotary inertia or the torsion.
 * Point masses add m to the three translational diagonal terms of their node
 * and their 3x3 inertia to its rotational block, in either mass formulation. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bounds.h"
#include "fe.h"

/* LAPACK / BLAS (Fortran interfaces; one-character arguments, no hidden lengths,
 * as in runtime/hosted/solver_dense.c) */
void dpotrf_(const char *uplo, const int *n, double *a, const int *lda, int *info);
void dpotrs_(const char *uplo, const int *n, const int *nrhs, const double *a, const int *lda,
             double *b, const int *ldb, int *info);
void dsygst_(const int *itype, const char *uplo, const int *n, double *a, const int *lda,
             const double *b, const int *ldb, int *info);
void dsytrd_(const char *uplo, const int *n, double *a, const int *lda, double *d, double *e,
             double *tau, double *work, const int *lwork, int *info);
void dsterf_(const int *n, double *d, double *e, int *info);
void dstemr_(const char *jobz, const char *range, const int *n, double *d, double *e,
             const double *vl, const double *vu, const int *il, const int *iu, int *m, double *w,
             double *z, const int *ldz, const int *nzc, int *isuppz, int *tryrac, double *work,
             const int *lwork, int *iwork, const int *liwork, int *info);
void dormtr_(const char *side, const char *uplo, const char *trans, const int *m, const int *n,
             const double *a, const int *lda, const double *tau, double *c, const int *ldc,
             double *work, const int *lwork, int *info);

void dtrsm_(const char *side, const char *uplo, const char *transa, const char *diag, const int *m,
            const int *n, const double *alpha, const double *a, const int *lda, double *b,
            const int *ldb);
void dgemm_(const char *transa, const char *transb, const int *m, const int *n, const int *k,
            const double *alpha, const double *a, const int *lda, const double *b, const int *ldb,
            const double *beta, double *c, const int *ldc);

static const char *const dof_names[6] = {"ux", "uy", "uz", "rx", "ry", "rz"};

#define FE_PI 3.14159265358979323846
/* a pivot of K this small relative to its diagonal term means a mechanism */
#define FE_PIVOT_TOL 1e-11
/* above this many free DOFs the sparse eigensolver is used (eigensolver: auto) */
#define FE_SPARSE_MIN_DOFS 3000

/* ------------------------------------------------------------------------- */
/* errors                                                                    */

typedef struct {
  char *err;
  size_t nerr;
  ir_loc *where;
} fe_ctx;

#if defined(__GNUC__) || defined(__clang__)
__attribute__((format(printf, 3, 4)))
#endif
static int fail_at(fe_ctx *c, ir_loc loc, const char *fmt, ...) {
  if (c->err && c->nerr) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(c->err, c->nerr, fmt, ap);
    va_end(ap);
  }
  if (c->where) *c->where = loc;
  return -1;
}

static const ir_loc no_loc = {0, 0};

static ir_loc node_loc(const ir_flex *fx, int k) {
  if (fx->node_loc && k >= 0 && k < fx->nnodes) return fx->node_loc[k];
  return fx->loc;
}

/* the id a node is known by in messages: its deck id (imported) or its number */
static long node_name(const ir_flex *fx, int k) { return fx->node_ids ? fx->node_ids[k] : k; }

static void *xcalloc(size_t n, size_t size) { return calloc(n ? n : 1, size); }

/* ------------------------------------------------------------------------- */
/* element matrices                                                           */

typedef struct {
  double L;
  double R[9];     /* rows: local x, y, z in body axes (u_local = R u_body) */
  double K[144];   /* local 12x12, column-major */
  double M[144];   /* local consistent mass */
  double lump[12]; /* local HRZ-lumped diagonal: per node m m m Jx Jy Jz */
} beam_el;

static int finite_pos(double v) { return isfinite(v) && v > 0; }

/* Check a beam's data and compute its frame and length. */
static int beam_frame(const ir_flex *fx, int e, beam_el *el, fe_ctx *c) {
  const ir_beam *b = &fx->beams[e];
  int n0 = b->node[0], n1 = b->node[1];
  if (n0 < 0 || n0 >= fx->nnodes || n1 < 0 || n1 >= fx->nnodes)
    return fail_at(c, b->loc, "beam %d: node index out of range (the body has %d nodes)", e, fx->nnodes);
  if (n0 == n1) return fail_at(c, b->loc, "beam %d: both ends are node %d (zero-length element)", e, n0);
  struct { const char *name; double v; } props[] = {
      {"Young's modulus E", b->E}, {"shear modulus G", b->G}, {"density rho", b->rho},
      {"area A", b->A}, {"second moment Iy", b->Iy}, {"second moment Iz", b->Iz},
      {"torsion constant J", b->J}};
  if (!isfinite(b->nsm) || b->nsm < 0)
    return fail_at(c, b->loc, "beam %d: the non-structural mass must be >= 0 (got %g)", e, b->nsm);
  /* an imported deck may have rods (no bending), no torsion or massless bars:
     a mechanism or a DOF without mass is then reported by the eigen-analysis */
  for (size_t i = 0; i < sizeof props / sizeof props[0]; i++)
    if (!finite_pos(props[i].v) && !(fx->fe_path && i != 0 && i != 1 && i != 3 && props[i].v == 0))
      return fail_at(c, b->loc, "beam %d: %s must be positive (got %g)", e, props[i].name, props[i].v);
  if (b->theory == BEAM_TIMOSHENKO && (!finite_pos(b->shear_y) || !finite_pos(b->shear_z)))
    return fail_at(c, b->loc,
                   "beam %d: a Timoshenko beam needs positive shear area ratios (got y %g, z %g)", e,
                   b->shear_y, b->shear_z);
  const double *p0 = fx->nodes + 3 * n0, *p1 = fx->nodes + 3 * n1;
  double x[3], scale = 0;
  for (int k = 0; k < 3; k++) {
    x[k] = p1[k] - p0[k];
    scale = fmax(scale, fmax(fabs(p0[k]), fabs(p1[k])));
  }
  double L = sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  if (!(L > 1e-12 * scale) || L == 0)
    return fail_at(c, b->loc, "beam %d: zero-length element (nodes %d and %d coincide)", e, n0, n1);
  for (int k = 0; k < 3; k++) x[k] /= L;
  const double *ya = b->yaxis;
  double yn = sqrt(ya[0] * ya[0] + ya[1] * ya[1] + ya[2] * ya[2]);
  if (!(yn > 0) || !isfinite(yn))
    return fail_at(c, b->loc, "beam %d: the section's yaxis is zero", e);
  double d = (ya[0] * x[0] + ya[1] * x[1] + ya[2] * x[2]) / yn, y[3];
  for (int k = 0; k < 3; k++) y[k] = ya[k] / yn - d * x[k];
  double n = sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2]);
  if (n < 1e-6)
    return fail_at(c, b->loc,
                   "beam %d: the section's yaxis (%g, %g, %g) is parallel to the element (nodes %d-%d)",
                   e, ya[0], ya[1], ya[2], n0, n1);
  for (int k = 0; k < 3; k++) y[k] /= n;
  double z[3] = {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
  for (int k = 0; k < 3; k++) {
    el->R[0 + k] = x[k];
    el->R[3 + k] = y[k];
    el->R[6 + k] = z[k];
  }
  el->L = L;
  return 0;
}

/* One bending plane, DOFs (v0, t0, v1, t1) with t = dv/dx (the x-y plane:
 * v = uy, t = rz).  k, m: 4x4 row-major (symmetric).  EI, shear parameter phi,
 * rhoA; rhoI > 0 adds the rotary inertia of the sections (Timoshenko).
 * *lump_rot: HRZ rotary inertia of each node. */
static void bending_plane(double L, double EI, double phi, double rhoA, double rhoI, double k[16],
                          double m[16], double *lump_rot) {
  double c = EI / (L * L * L * (1 + phi)), L2 = L * L;
  double kk[16] = {12,      6 * L,             -12,     6 * L,
                   6 * L,   (4 + phi) * L2,    -6 * L,  (2 - phi) * L2,
                   -12,     -6 * L,            12,      -6 * L,
                   6 * L,   (2 - phi) * L2,    -6 * L,  (4 + phi) * L2};
  for (int i = 0; i < 16; i++) k[i] = c * kk[i];
  double p = phi, p2 = phi * phi, a = rhoA * L / ((1 + p) * (1 + p));
  double m11 = a * (13.0 / 35 + 7.0 / 10 * p + p2 / 3);
  double m12 = a * L * (11.0 / 210 + 11.0 / 120 * p + p2 / 24);
  double m13 = a * (9.0 / 70 + 3.0 / 10 * p + p2 / 6);
  double m14 = -a * L * (13.0 / 420 + 3.0 / 40 * p + p2 / 24);
  double m22 = a * L2 * (1.0 / 105 + p / 60 + p2 / 120);
  double m24 = -a * L2 * (1.0 / 140 + p / 60 + p2 / 120);
  double mm[16] = {m11, m12,  m13,  m14,
                   m12, m22,  -m14, m24,
                   m13, -m14, m11,  -m12,
                   m14, m24,  -m12, m22};
  *lump_rot = 0.5 * rhoA * L * m22 / m11;
  if (rhoI > 0) {
    double r = rhoI / (L * (1 + p) * (1 + p));
    double r11 = r * 6.0 / 5, r12 = r * L * (1.0 / 10 - p / 2);
    double r22 = r * L2 * (2.0 / 15 + p / 6 + p2 / 3), r24 = r * L2 * (-1.0 / 30 - p / 6 + p2 / 6);
    double rr[16] = {r11,  r12,  -r11, r12,
                     r12,  r22,  -r12, r24,
                     -r11, -r12, r11,  -r12,
                     r12,  r24,  -r12, r22};
    for (int i = 0; i < 16; i++) mm[i] += rr[i];
    *lump_rot += 0.5 * rhoI * L;
  }
  memcpy(m, mm, sizeof mm);
}

/* local 12x12 stiffness, consistent mass and HRZ lumped diagonal */
static void beam_local(const ir_beam *b, beam_el *el) {
  double L = el->L;
  memset(el->K, 0, sizeof el->K);
  memset(el->M, 0, sizeof el->M);
  int timo = b->theory == BEAM_TIMOSHENKO;
  /* mass per length: the section's and the non-structural mass (on the axis:
     no section rotary inertia, no torsion inertia) */
  double rhoA = b->rho * b->A + b->nsm, Ip = b->Iy + b->Iz;
#define KL(i, j) el->K[(j) * 12 + (i)]
#define ML(i, j) el->M[(j) * 12 + (i)]
  /* axial (0, 6) and torsion (3, 9) */
  double ka = b->E * b->A / L, kt = b->G * b->J / L;
  double ma = rhoA * L / 6, mt = b->rho * Ip * L / 6;
  int ax[2] = {0, 6}, tr[2] = {3, 9};
  for (int i = 0; i < 2; i++)
    for (int j = 0; j < 2; j++) {
      double s = i == j ? 1 : -1;
      KL(ax[i], ax[j]) = s * ka;
      KL(tr[i], tr[j]) = s * kt;
      ML(ax[i], ax[j]) = (i == j ? 2 : 1) * ma;
      ML(tr[i], tr[j]) = (i == j ? 2 : 1) * mt;
    }
  /* x-y plane: (uy, rz), Iz, shear_y; x-z plane: (uz, -ry), Iy, shear_z */
  double phiy = 0, phiz = 0;
  if (timo) {
    phiy = 12 * b->E * b->Iz / (b->G * b->shear_y * b->A * L * L);
    phiz = 12 * b->E * b->Iy / (b->G * b->shear_z * b->A * L * L);
  }
  double k4[16], m4[16], rot_z, rot_y;
  int py[4] = {1, 5, 7, 11};
  double sy[4] = {1, 1, 1, 1};
  bending_plane(L, b->E * b->Iz, phiy, rhoA, timo ? b->rho * b->Iz : 0, k4, m4, &rot_z);
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      KL(py[i], py[j]) = sy[i] * sy[j] * k4[4 * i + j];
      ML(py[i], py[j]) = sy[i] * sy[j] * m4[4 * i + j];
    }
  int pz[4] = {2, 4, 8, 10};
  double sz[4] = {1, -1, 1, -1};
  bending_plane(L, b->E * b->Iy, phiz, rhoA, timo ? b->rho * b->Iy : 0, k4, m4, &rot_y);
  for (int i = 0; i < 4; i++)
    for (int j = 0; j < 4; j++) {
      KL(pz[i], pz[j]) = sz[i] * sz[j] * k4[4 * i + j];
      ML(pz[i], pz[j]) = sz[i] * sz[j] * m4[4 * i + j];
    }
#undef KL
#undef ML
  for (int a = 0; a < 2; a++) {
    double *l = el->lump + 6 * a;
    l[0] = l[1] = l[2] = 0.5 * rhoA * L;
    l[3] = 0.5 * b->rho * Ip * L;
    l[4] = rot_y;
    l[5] = rot_z;
  }
}

/* body-axes 3x3 block B = R^T A R of a local 3x3 block (A column-major with
 * leading dimension lda, B written with leading dimension ldb, added) */
static void rotate_add(const double R[9], const double *A, int lda, double *B, int ldb, double s) {
  double t[9];
  /* t = A R  (t_ij = sum_k A_ik R_kj) */
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double v = 0;
      for (int k = 0; k < 3; k++) v += A[k * lda + i] * R[3 * k + j];
      t[3 * i + j] = v;
    }
  for (int i = 0; i < 3; i++)
    for (int j = 0; j < 3; j++) {
      double v = 0;
      for (int k = 0; k < 3; k++) v += R[3 * k + i] * t[3 * k + j];
      B[j * ldb + i] += s * v;
    }
}

static int check_point_masses(const ir_flex *fx, fe_ctx *c) {
  for (int p = 0; p < fx->npoint_masses; p++) {
    const ir_point_mass *pm = &fx->point_masses[p];
    if (pm->node < 0 || pm->node >= fx->nnodes)
      return fail_at(c, pm->loc, "point mass %d: node %d out of range (the body has %d nodes)", p,
                     pm->node, fx->nnodes);
    if (!isfinite(pm->mass) || pm->mass < 0)
      return fail_at(c, pm->loc, "point mass %d: mass must be nonnegative (got %g)", p, pm->mass);
    const double *I = pm->inertia;
    double big = 0;
    for (int i = 0; i < 9; i++) {
      if (!isfinite(I[i])) return fail_at(c, pm->loc, "point mass %d: inertia is not finite", p);
      big = fmax(big, fabs(I[i]));
    }
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < i; j++)
        if (fabs(I[3 * i + j] - I[3 * j + i]) > 1e-9 * big)
          return fail_at(c, pm->loc, "point mass %d: inertia is not symmetric", p);
    double m2 = I[0] * I[4] - I[1] * I[3], det = I[0] * (I[4] * I[8] - I[5] * I[7]) -
                                                 I[1] * (I[3] * I[8] - I[5] * I[6]) +
                                                 I[2] * (I[3] * I[7] - I[4] * I[6]);
    if (I[0] < 0 || I[4] < 0 || I[8] < 0 || m2 < -1e-9 * big * big || det < -1e-9 * big * big * big)
      return fail_at(c, pm->loc, "point mass %d: inertia is not positive semidefinite", p);
  }
  return 0;
}

int fe_lumped_nodes(const ir_flex *fx, double *node_mass, double *node_inertia, char *err,
                    size_t nerr, ir_loc *where) {
  fe_ctx c = {err, nerr, where};
  if (where) *where = no_loc;
  memset(node_mass, 0, sizeof(double) * (size_t)fx->nnodes);
  memset(node_inertia, 0, sizeof(double) * 9 * (size_t)fx->nnodes);
  if (fx->M_given) {
    /* an exported mass matrix: each node's mass by row sums of the
       translational rows (the total mass is kept exactly), its rotary inertia
       the node's own rotational block */
    const ir_fe_matrix *Mg = fx->M_given;
    for (int t = 0; t < Mg->nnz; t++) {
      int i = Mg->row[t], j = Mg->col[t];
      if (i < 0 || j < 0 || i >= 6 * fx->nnodes || j >= 6 * fx->nnodes) continue;
      if (i % 6 < 3 && j % 6 == i % 6) node_mass[i / 6] += Mg->val[t] / 3;
      if (i % 6 >= 3 && j % 6 >= 3 && i / 6 == j / 6)
        node_inertia[9 * (i / 6) + 3 * (i % 6 - 3) + (j % 6 - 3)] += Mg->val[t];
    }
    return 0;
  }
  for (int e = 0; e < fx->nbeams; e++) {
    beam_el el;
    if (beam_frame(fx, e, &el, &c)) return -1;
    beam_local(&fx->beams[e], &el);
    for (int a = 0; a < 2; a++) {
      int n = fx->beams[e].node[a];
      node_mass[n] += el.lump[6 * a];
      double J[9] = {0};
      J[0] = el.lump[6 * a + 3];
      J[4] = el.lump[6 * a + 4];
      J[8] = el.lump[6 * a + 5];
      double B[9] = {0};
      rotate_add(el.R, J, 3, B, 3, 1.0); /* column-major B; symmetric */
      for (int i = 0; i < 9; i++) node_inertia[9 * n + i] += B[i];
    }
  }
  if (check_point_masses(fx, &c)) return -1;
  for (int p = 0; p < fx->npoint_masses; p++) {
    const ir_point_mass *pm = &fx->point_masses[p];
    node_mass[pm->node] += pm->mass;
    for (int i = 0; i < 9; i++) node_inertia[9 * pm->node + i] += pm->inertia[i];
  }
  /* exact symmetry */
  for (int n = 0; n < fx->nnodes; n++) {
    double *I = node_inertia + 9 * n;
    for (int i = 0; i < 3; i++)
      for (int j = 0; j < i; j++) I[3 * i + j] = I[3 * j + i] = 0.5 * (I[3 * i + j] + I[3 * j + i]);
  }
  return 0;
}

static int check_flex_common(const ir_flex *fx, fe_ctx *c) {
  if (fx->nnodes <= 0 || !fx->nodes) return fail_at(c, fx->loc, "the FE model has no nodes");
  for (int k = 0; k < 3 * fx->nnodes; k++)
    if (!isfinite(fx->nodes[k])) return fail_at(c, node_loc(fx, k / 3), "node %d: position is not finite", k / 3);
  return 0;
}

int fe_assemble_at(const ir_flex *fx, fe_system *out, char *err, size_t nerr, ir_loc *where) {
  fe_ctx c = {err, nerr, where};
  memset(out, 0, sizeof *out);
  if (where) *where = no_loc;
  if (check_flex_common(fx, &c)) return -1;
  int n = 6 * fx->nnodes;
  size_t nn = (size_t)n * (size_t)n;
  double *K = xcalloc(nn, sizeof(double)), *M = xcalloc(nn, sizeof(double));
  double *nm = xcalloc((size_t)fx->nnodes, sizeof(double));
  double *ni = xcalloc(9 * (size_t)fx->nnodes, sizeof(double));
  if (!K || !M || !nm || !ni) {
    free(K); free(M); free(nm); free(ni);
    return fail_at(&c, fx->loc, "out of memory assembling %d DOFs", n);
  }
  if (fx->K_given) { /* an exported K and M: taken as they are */
    const ir_fe_matrix *G[2] = {fx->K_given, fx->M_given};
    double *D[2] = {K, M};
    for (int g = 0; g < 2; g++)
      for (int t = 0; t < G[g]->nnz; t++) {
        int i = G[g]->row[t], j = G[g]->col[t];
        if (i < 0 || j < 0 || i >= n || j >= n) {
          fail_at(&c, fx->loc, "FE matrix entry (%d, %d) outside the %d DOFs", i, j, n);
          goto fail;
        }
        D[g][(size_t)j * n + i] += G[g]->val[t];
      }
    goto symmetric;
  }
  for (int e = 0; e < fx->nbeams; e++) {
    beam_el el;
    if (beam_frame(fx, e, &el, &c)) goto fail;
    beam_local(&fx->beams[e], &el);
    for (int a = 0; a < 2; a++)
      for (int bb = 0; bb < 2; bb++)
        for (int p = 0; p < 2; p++)
          for (int q = 0; q < 2; q++) {
            int li = 6 * a + 3 * p, lj = 6 * bb + 3 * q;
            int gi = 6 * fx->beams[e].node[a] + 3 * p, gj = 6 * fx->beams[e].node[bb] + 3 * q;
            rotate_add(el.R, el.K + lj * 12 + li, 12, K + (size_t)gj * n + gi, n, 1.0);
            if (fx->mass == MASS_CONSISTENT)
              rotate_add(el.R, el.M + lj * 12 + li, 12, M + (size_t)gj * n + gi, n, 1.0);
          }
  }
  if (fx->mass == MASS_CONSISTENT) {
    if (check_point_masses(fx, &c)) goto fail;
    for (int p = 0; p < fx->npoint_masses; p++) {
      const ir_point_mass *pm = &fx->point_masses[p];
      int g = 6 * pm->node;
      for (int i = 0; i < 3; i++) {
        M[(size_t)(g + i) * n + g + i] += pm->mass;
        for (int j = 0; j < 3; j++) M[(size_t)(g + 3 + j) * n + g + 3 + i] += pm->inertia[3 * i + j];
      }
    }
  } else {
    if (fe_lumped_nodes(fx, nm, ni, err, nerr, where)) goto fail;
    for (int k = 0; k < fx->nnodes; k++) {
      int g = 6 * k;
      for (int i = 0; i < 3; i++) {
        M[(size_t)(g + i) * n + g + i] = nm[k];
        for (int j = 0; j < 3; j++) M[(size_t)(g + 3 + j) * n + g + 3 + i] = ni[9 * k + 3 * i + j];
      }
    }
  }
symmetric:
  /* exact symmetry */
  for (int j = 0; j < n; j++)
    for (int i = 0; i < j; i++) {
      size_t u = (size_t)j * n + i, l = (size_t)i * n + j;
      K[u] = K[l] = 0.5 * (K[u] + K[l]);
      M[u] = M[l] = 0.5 * (M[u] + M[l]);
    }
  free(nm);
  free(ni);
  out->ndof = n;
  out->K = K;
  out->M = M;
  return 0;
fail:
  free(K); free(M); free(nm); free(ni);
  return -1;
}

/* triplet list that grows */
static int trip_add(ir_fe_matrix *t, int *cap, int i, int j, double v) {
  if (v == 0) return 0;
  if (t->nnz == *cap) {
    int nc = *cap ? 2 * *cap : 1024;
    int *r = realloc(t->row, (size_t)nc * sizeof *r), *c = NULL;
    if (r) t->row = r;
    c = realloc(t->col, (size_t)nc * sizeof *c);
    if (c) t->col = c;
    double *v2 = realloc(t->val, (size_t)nc * sizeof *v2);
    if (v2) t->val = v2;
    if (!r || !c || !v2) return -1;
    *cap = nc;
  }
  t->row[t->nnz] = i;
  t->col[t->nnz] = j;
  t->val[t->nnz++] = v;
  return 0;
}

int fe_assemble_triplets(const ir_flex *fx, ir_fe_matrix *K, ir_fe_matrix *M, char *err, size_t nerr,
                         ir_loc *where) {
  fe_ctx c = {err, nerr, where};
  if (where) *where = no_loc;
  memset(K, 0, sizeof *K);
  memset(M, 0, sizeof *M);
  if (check_flex_common(fx, &c)) return -1;
  int capk = 0, capm = 0, n = fx->nnodes, bad = 0;
  if (fx->K_given) {
    const ir_fe_matrix *G[2] = {fx->K_given, fx->M_given};
    ir_fe_matrix *D[2] = {K, M};
    int *cap[2] = {&capk, &capm};
    for (int g = 0; g < 2; g++)
      for (int t = 0; t < G[g]->nnz && !bad; t++)
        bad = trip_add(D[g], cap[g], G[g]->row[t], G[g]->col[t], G[g]->val[t]);
  } else {
    for (int e = 0; e < fx->nbeams && !bad; e++) {
      beam_el el;
      if (beam_frame(fx, e, &el, &c)) goto fail;
      beam_local(&fx->beams[e], &el);
      for (int a = 0; a < 2; a++)
        for (int bb = 0; bb < 2; bb++)
          for (int p = 0; p < 2; p++)
            for (int q = 0; q < 2; q++) {
              int li = 6 * a + 3 * p, lj = 6 * bb + 3 * q;
              int gi = 6 * fx->beams[e].node[a] + 3 * p, gj = 6 * fx->beams[e].node[bb] + 3 * q;
              double Bk[9] = {0}, Bm[9] = {0};
              rotate_add(el.R, el.K + lj * 12 + li, 12, Bk, 3, 1.0);
              if (fx->mass == MASS_CONSISTENT) rotate_add(el.R, el.M + lj * 12 + li, 12, Bm, 3, 1.0);
              for (int jj = 0; jj < 3; jj++)
                for (int ii = 0; ii < 3; ii++) {
                  bad |= trip_add(K, &capk, gi + ii, gj + jj, Bk[3 * jj + ii]);
                  bad |= trip_add(M, &capm, gi + ii, gj + jj, Bm[3 * jj + ii]);
                }
            }
    }
    if (check_point_masses(fx, &c)) goto fail;
    if (fx->mass == MASS_CONSISTENT) {
      for (int p = 0; p < fx->npoint_masses && !bad; p++) {
        const ir_point_mass *pm = &fx->point_masses[p];
        int g = 6 * pm->node;
        for (int i = 0; i < 3; i++) {
          bad |= trip_add(M, &capm, g + i, g + i, pm->mass);
          for (int j = 0; j < 3; j++) bad |= trip_add(M, &capm, g + 3 + i, g + 3 + j, pm->inertia[3 * i + j]);
        }
      }
    } else {
      double *nm = xcalloc((size_t)n, sizeof(double)), *ni = xcalloc(9 * (size_t)n, sizeof(double));
      if (!nm || !ni || fe_lumped_nodes(fx, nm, ni, err, nerr, where)) { free(nm); free(ni); goto fail; }
      for (int k = 0; k < n && !bad; k++)
        for (int i = 0; i < 3; i++) {
          bad |= trip_add(M, &capm, 6 * k + i, 6 * k + i, nm[k]);
          for (int j = 0; j < 3; j++) bad |= trip_add(M, &capm, 6 * k + 3 + i, 6 * k + 3 + j, ni[9 * k + 3 * i + j]);
        }
      free(nm);
      free(ni);
    }
  }
  if (!bad) return 0;
  fail_at(&c, fx->loc, "out of memory assembling %d DOFs", 6 * n);
fail:
  free(K->row); free(K->col); free(K->val);
  free(M->row); free(M->col); free(M->val);
  memset(K, 0, sizeof *K);
  memset(M, 0, sizeof *M);
  return -1;
}

int fe_assemble(const ir_flex *fx, fe_system *out, char *err, size_t nerr) {
  return fe_assemble_at(fx, out, err, nerr, NULL);
}

void fe_system_free(fe_system *s) {
  if (!s) return;
  free(s->K);
  free(s->M);
  memset(s, 0, sizeof *s);
}

/* ------------------------------------------------------------------------- */
/* dense linear algebra helpers                                               */

/* Generalized symmetric-definite eigenproblem K x = lambda M x (n x n,
 * column-major, K and M positive definite, not modified).
 *
 * Accuracy: the usual reduction to a standard problem with the Cholesky
 * factor of M leaves an absolute error of about eps * lambda_max in every
 * eigenvalue.  The lowest frequencies, the ones a flexible body keeps, would
 * then lose digits in proportion to lambda_max / lambda_min, which reaches
 * 1e12 for a fine, slender mesh (measured: the two equal bending frequencies
 * of a square cantilever split by 1e-4 with dsygvd on (K, M)).  So the
 * inverse problem M x = mu K x (mu = 1/lambda) is reduced instead, with the
 * Cholesky factor of K: C = L^-1 M L^-T, whose largest mu (the lowest
 * frequencies) come out to a few eps.  C is tridiagonalized once (dsytrd);
 * all eigenvalues come from dsterf (for the list of frequencies), and
 * eigenvectors only for the index range needed, by MRRR (dstemr), then
 * x = L^-T Q z.  The vectors are scaled to unit modal mass, re-orthonormalized
 * in the M inner product by one Cholesky-QR sweep in ascending frequency
 * order (the lowest modes are left as they are; the highest, whose mu carry
 * the largest relative error, absorb the correction), and each lambda is the
 * Rayleigh quotient x^T K x of its M-normalized vector. */
typedef struct {
  int n;
  double *L;   /* Cholesky factor of K (lower) */
  double *C;   /* L^-1 M L^-T, then its Householder vectors (lower) */
  double *tau, *d, *e;
} eig_ws;

static void eig_free(eig_ws *w) {
  free(w->L); free(w->C); free(w->tau); free(w->d); free(w->e);
  memset(w, 0, sizeof *w);
}

/* reduce and return every lambda, ascending.  0, 2 if K is not positive
 * definite, 1 if some mu <= 0 (M singular), -1 otherwise */
static int eig_reduce(int n, const double *K, const double *M, eig_ws *w, double *lam) {
  memset(w, 0, sizeof *w);
  w->n = n;
  if (n == 0) return 0;
  size_t nn = (size_t)n * (size_t)n;
  int info = 0, itype = 1, lwork = -1;
  double wq = 0, *work = NULL, *d2 = NULL, *e2 = NULL;
  w->L = malloc(nn * sizeof(double));
  w->C = malloc(nn * sizeof(double));
  w->tau = malloc((size_t)n * sizeof(double));
  w->d = malloc((size_t)n * sizeof(double));
  w->e = malloc((size_t)n * sizeof(double));
  d2 = malloc((size_t)n * sizeof(double));
  e2 = malloc((size_t)n * sizeof(double));
  int rc = -1;
  if (!w->L || !w->C || !w->tau || !w->d || !w->e || !d2 || !e2) goto done;
  memcpy(w->L, K, nn * sizeof(double));
  memcpy(w->C, M, nn * sizeof(double));
  dpotrf_("L", &n, w->L, &n, &info);
  if (info != 0) { rc = info > 0 ? 2 : -1; goto done; }
  dsygst_(&itype, "L", &n, w->C, &n, w->L, &n, &info);
  if (info != 0) goto done;
  dsytrd_("L", &n, w->C, &n, w->d, w->e, w->tau, &wq, &lwork, &info);
  lwork = (int)wq + 1;
  if (info != 0 || !(work = malloc((size_t)lwork * sizeof(double)))) goto done;
  dsytrd_("L", &n, w->C, &n, w->d, w->e, w->tau, work, &lwork, &info);
  if (info != 0) goto done;
  memcpy(d2, w->d, (size_t)n * sizeof(double));
  memcpy(e2, w->e, (size_t)n * sizeof(double));
  dsterf_(&n, d2, e2, &info);
  if (info != 0) goto done;
  for (int i = 0; i < n; i++) {
    double mu = d2[n - 1 - i];
    if (!(mu > 0)) { rc = 1; goto done; }
    lam[i] = 1 / mu;
  }
  rc = 0;
done:
  free(work); free(d2); free(e2);
  return rc;
}

/* eigenvectors lo..hi (0-based, ascending lambda) into X (n x (hi-lo+1)),
 * M-orthonormal, with their Rayleigh-quotient lambdas in lam */
static int eig_vectors(const eig_ws *w, const double *K, const double *M, int lo, int hi,
                       double *lam, double *X) {
  int n = w->n, m = hi - lo + 1, il = n - hi, iu = n - lo, found = 0, info = 0;
  if (m <= 0) return 0;
  int rc = -1, tryrac = 1, lwork = -1, liwork = -1, iwq = 0, nzc = m;
  double vl = 0, vu = 0, wq = 0, one = 1, zero = 0;
  double *d = malloc((size_t)n * sizeof(double)), *e = malloc((size_t)n * sizeof(double));
  double *mu = malloc((size_t)n * sizeof(double)), *Z = malloc((size_t)n * m * sizeof(double));
  double *P = malloc((size_t)n * m * sizeof(double)), *G = malloc((size_t)m * m * sizeof(double));
  int *isuppz = malloc(2 * (size_t)m * sizeof(int)), *order = malloc((size_t)m * sizeof(int));
  double *work = NULL;
  int *iwork = NULL;
  if (!d || !e || !mu || !Z || !P || !G || !isuppz || !order) goto done;
  memcpy(d, w->d, (size_t)n * sizeof(double));
  memcpy(e, w->e, (size_t)n * sizeof(double));
  dstemr_("V", "I", &n, d, e, &vl, &vu, &il, &iu, &found, mu, Z, &n, &nzc, isuppz, &tryrac, &wq,
          &lwork, &iwq, &liwork, &info);
  if (info != 0) goto done;
  lwork = (int)wq + 1;
  liwork = iwq > 0 ? iwq : 1;
  {
    /* dormtr's workspace: query it too, take the larger */
    int lw2 = -1;
    double wq2 = 0;
    dormtr_("L", "L", "N", &n, &m, w->C, &n, w->tau, Z, &n, &wq2, &lw2, &info);
    if (info != 0) goto done;
    if ((int)wq2 + 1 > lwork) lwork = (int)wq2 + 1;
  }
  work = malloc((size_t)lwork * sizeof(double));
  iwork = malloc((size_t)liwork * sizeof(int));
  if (!work || !iwork) goto done;
  dstemr_("V", "I", &n, d, e, &vl, &vu, &il, &iu, &found, mu, Z, &n, &nzc, isuppz, &tryrac, work,
          &lwork, iwork, &liwork, &info);
  if (info != 0 || found != m) goto done;
  dormtr_("L", "L", "N", &n, &m, w->C, &n, w->tau, Z, &n, work, &lwork, &info);
  if (info != 0) goto done;
  dtrsm_("L", "L", "T", "N", &n, &m, &one, w->L, &n, Z, &n); /* x = L^-T Q z */
  /* ascending lambda = descending mu; unit modal mass */
  for (int i = 0; i < m; i++) {
    double mi = mu[m - 1 - i];
    if (!(mi > 0)) goto done;
    double s = 1 / sqrt(mi);
    const double *z = Z + (size_t)(m - 1 - i) * n;
    for (int r = 0; r < n; r++) X[(size_t)i * n + r] = s * z[r];
  }
  /* Cholesky-QR in the M inner product: G = X^T M X = R^T R, X <- X R^-1 */
  dgemm_("N", "N", &n, &m, &n, &one, M, &n, X, &n, &zero, P, &n);
  dgemm_("T", "N", &m, &m, &n, &one, X, &n, P, &n, &zero, G, &m);
  dpotrf_("U", &m, G, &m, &info);
  if (info != 0) goto done;
  dtrsm_("R", "U", "N", "N", &n, &m, &one, G, &m, X, &n);
  /* Rayleigh quotients, then ascending order */
  dgemm_("N", "N", &n, &m, &n, &one, K, &n, X, &n, &zero, P, &n);
  for (int i = 0; i < m; i++) {
    double q = 0;
    for (int r = 0; r < n; r++) q += X[(size_t)i * n + r] * P[(size_t)i * n + r];
    mu[i] = q;
    order[i] = i;
  }
  for (int i = 1; i < m; i++) { /* insertion sort: sorted already up to round-off */
    int o = order[i], j = i;
    while (j > 0 && mu[order[j - 1]] > mu[o]) { order[j] = order[j - 1]; j--; }
    order[j] = o;
  }
  memcpy(P, X, (size_t)n * m * sizeof(double));
  for (int i = 0; i < m; i++) {
    lam[i] = mu[order[i]];
    memcpy(X + (size_t)i * n, P + (size_t)order[i] * n, (size_t)n * sizeof(double));
  }
  rc = 0;
done:
  free(d); free(e); free(mu); free(Z); free(P); free(G); free(isuppz); free(order);
  free(work); free(iwork);
  return rc;
}

/* all eigenpairs: lambda ascending in w, M-orthonormal vectors in X (n x n).
 * Returns 0, or as eig_reduce */
static int gen_eig(int n, const double *K, const double *M, double *w, double *X, int *bad) {
  eig_ws ws;
  (void)bad;
  int rc = eig_reduce(n, K, M, &ws, w);
  if (rc == 0 && eig_vectors(&ws, K, M, 0, n - 1, w, X)) rc = -1;
  eig_free(&ws);
  return rc;
}

/* a deterministic sign: the component of largest magnitude (the first one
 * within a relative 1e-8 of it) is positive */
static void fix_sign(double *x, int n) {
  double big = 0;
  for (int i = 0; i < n; i++) big = fmax(big, fabs(x[i]));
  for (int i = 0; i < n; i++)
    if (fabs(x[i]) >= (1 - 1e-8) * big) {
      if (x[i] < 0)
        for (int j = 0; j < n; j++) x[j] = -x[j];
      return;
    }
}

static void gather(const double *A, int lda, const int *rows, int nr, const int *cols, int nc,
                   double *B) {
  for (int j = 0; j < nc; j++)
    for (int i = 0; i < nr; i++) B[(size_t)j * nr + i] = A[(size_t)cols[j] * lda + rows[i]];
}

static double lam_to_hz(double lam) { return sqrt(lam > 0 ? lam : 0) / (2 * FE_PI); }

/* ------------------------------------------------------------------------- */
/* mode selection                                                             */

static int cmp_int(const void *a, const void *b) {
  int x = *(const int *)a, y = *(const int *)b;
  return (x > y) - (x < y);
}

/* indices (0-based, ascending) of the selected modes among n with ascending
 * frequencies freq; 'what' names them in messages */
static int select_modes(const ir_flex *fx, const double *freq, int n, int *idx, int *nsel,
                        const char *what, fe_ctx *c) {
  int k = 0;
  if ((unsigned)fx->select > MODES_ALL)
    return fail_at(c, fx->loc, "unknown mode selection %d", (int)fx->select);
  switch (fx->select) {
  case MODES_ALL:
    for (int i = 0; i < n; i++) idx[k++] = i;
    break;
  case MODES_COUNT:
    if (fx->count < 0) return fail_at(c, fx->loc, "mode count must be nonnegative (got %d)", fx->count);
    if (fx->count > n)
      return fail_at(c, fx->loc, "mode count %d exceeds the %d %s available", fx->count, n, what);
    for (int i = 0; i < fx->count; i++) idx[k++] = i;
    break;
  case MODES_MAX_FREQUENCY:
    if (!(fx->max_frequency >= 0))
      return fail_at(c, fx->loc, "maximum mode frequency must be nonnegative (got %g Hz)", fx->max_frequency);
    for (int i = 0; i < n; i++)
      if (freq[i] <= fx->max_frequency) idx[k++] = i;
    break;
  case MODES_LIST: {
    int *l = xcalloc((size_t)fx->nlist, sizeof(int));
    if (!l) return fail_at(c, fx->loc, "out of memory");
    for (int i = 0; i < fx->nlist; i++) {
      if (fx->list[i] < 1 || fx->list[i] > n) {
        int v = fx->list[i];
        free(l);
        return fail_at(c, fx->loc, "mode number %d out of range (there are %d %s, numbered from 1)",
                       v, n, what);
      }
      l[i] = fx->list[i] - 1;
    }
    qsort(l, (size_t)fx->nlist, sizeof(int), cmp_int);
    for (int i = 0; i < fx->nlist; i++) {
      if (i > 0 && l[i] == l[i - 1]) {
        int v = l[i] + 1;
        free(l);
        return fail_at(c, fx->loc, "mode number %d is listed twice", v);
      }
      idx[k++] = l[i];
    }
    free(l);
    break;
  }
  }
  *nsel = k;
  return 0;
}

/* ------------------------------------------------------------------------- */
/* modes from the FE model                                                    */

static int uf_find(int *p, int i) {
  while (p[i] != i) i = p[i] = p[p[i]];
  return i;
}

/* every node reaches a reference node through beams */
static int check_connectivity(const ir_flex *fx, const char *is_ref, fe_ctx *c) {
  int n = fx->nnodes;
  int *p = xcalloc((size_t)n, sizeof(int)), *deg = xcalloc((size_t)n, sizeof(int));
  char *held = xcalloc((size_t)n, 1);
  if (!p || !deg || !held) { free(p); free(deg); free(held); return fail_at(c, fx->loc, "out of memory"); }
  for (int i = 0; i < n; i++) p[i] = i;
  for (int e = 0; e < fx->nbeams; e++) {
    int a = fx->beams[e].node[0], b = fx->beams[e].node[1];
    deg[a]++; deg[b]++;
    p[uf_find(p, a)] = uf_find(p, b);
  }
  for (int l = 0; l < fx->nlinks; l++) { /* an RBE2 connects as a beam would */
    int a = fx->links[l].independent, b = fx->links[l].dependent;
    deg[a]++; deg[b]++;
    p[uf_find(p, a)] = uf_find(p, b);
  }
  for (int i = 0; i < n; i++)
    if (is_ref[i]) held[uf_find(p, i)] = 1;
  int rc = 0;
  for (int i = 0; i < n && !rc; i++) {
    if (is_ref[i]) continue;
    if (deg[i] == 0)
      rc = fail_at(c, node_loc(fx, i),
                   "node %ld is not connected to any beam and is not a reference node: its DOFs "
                   "have no stiffness (a mechanism)", node_name(fx, i));
    else if (!held[uf_find(p, i)])
      rc = fail_at(c, node_loc(fx, i),
                   "node %ld is not connected through beams to any reference node: that part of the "
                   "structure is free-floating (a mechanism not held by the reference nodes)", node_name(fx, i));
  }
  free(p); free(deg); free(held);
  return rc;
}

/* Cholesky of the free-DOF stiffness or mass (a copy); a failing or tiny
 * pivot means a mechanism (K) or a DOF without mass (M) */
static int check_definite(const ir_flex *fx, const double *Kf, int nf, const int *dof, int is_mass,
                          fe_ctx *c) {
  if (nf == 0) return 0;
  size_t nn = (size_t)nf * (size_t)nf;
  double *A = malloc(nn * sizeof(double));
  if (!A) return fail_at(c, fx->loc, "out of memory");
  memcpy(A, Kf, nn * sizeof(double));
  int info = 0, bad = -1;
  dpotrf_("U", &nf, A, &nf, &info);
  if (info > 0) bad = info - 1;
  else
    for (int j = 0; j < nf; j++) {
      double piv = A[(size_t)j * nf + j];
      if (!(piv * piv > FE_PIVOT_TOL * Kf[(size_t)j * nf + j])) { bad = j; break; }
    }
  free(A);
  if (bad >= 0) {
    int node = dof[bad] / 6;
    if (is_mass)
      return fail_at(c, node_loc(fx, node),
                     "the mass matrix is singular at node %ld DOF %s: a free DOF without mass or "
                     "rotary inertia", node_name(fx, node), dof_names[dof[bad] % 6]);
    return fail_at(c, node_loc(fx, node),
                   "the stiffness matrix is singular at node %ld DOF %s: a mechanism not held by the "
                   "reference nodes", node_name(fx, node), dof_names[dof[bad] % 6]);
  }
  return 0;
}

static int alloc_modes(fe_modes *out, int nnodes, int nmodes, int nall) {
  out->nnodes = nnodes;
  out->nmodes = nmodes;
  out->nall = nall;
  out->x = xcalloc(3 * (size_t)nnodes, sizeof(double));
  out->freq_hz = xcalloc((size_t)nmodes, sizeof(double));
  out->shapes = xcalloc(6 * (size_t)nnodes * (size_t)nmodes, sizeof(double));
  out->node_mass = xcalloc((size_t)nnodes, sizeof(double));
  out->node_inertia = xcalloc(9 * (size_t)nnodes, sizeof(double));
  out->all_freq_hz = xcalloc((size_t)nall, sizeof(double));
  return out->x && out->freq_hz && out->shapes && out->node_mass && out->node_inertia &&
                 out->all_freq_hz
             ? 0
             : -1;
}

static void mul(const char *ta, const char *tb, int m, int n, int k, const double *A, int lda,
                const double *B, int ldb, double *C, int ldc) {
  if (m == 0 || n == 0) return;
  double one = 1, zero = 0;
  if (k == 0) {
    for (int j = 0; j < n; j++)
      for (int i = 0; i < m; i++) C[(size_t)j * ldc + i] = 0;
    return;
  }
  dgemm_(ta, tb, &m, &n, &k, &one, A, &lda, B, &ldb, &zero, C, &ldc);
}

/* Eigen-analysis of (K, M) with the body's mode selection: all frequencies
 * in all_hz (n), the selected modes' indices in sel (*ns of them, ascending),
 * their frequencies in hz and M-orthonormal shapes in X (n x *ns).  The
 * selected entries of all_hz are the refined (Rayleigh-quotient) values. */
static int eig_select(const ir_flex *fx, int n, const double *K, const double *M, const char *what,
                      double *all_hz, int *sel, int *ns, double *hz, double *X, fe_ctx *c) {
  eig_ws ws;
  int rc = eig_reduce(n, K, M, &ws, all_hz);
  if (rc) {
    eig_free(&ws);
    return fail_at(c, fx->loc, "the eigensolver failed (%s)",
                   rc == 2 ? "the stiffness matrix is not positive definite"
                           : rc == 1 ? "the mass matrix is not positive definite" : "LAPACK error");
  }
  for (int i = 0; i < n; i++) all_hz[i] = lam_to_hz(all_hz[i]);
  if (select_modes(fx, all_hz, n, sel, ns, what, c)) { eig_free(&ws); return -1; }
  if (*ns > 0) {
    int lo = sel[0], hi = sel[*ns - 1], m = hi - lo + 1;
    double *lam = malloc((size_t)m * sizeof(double)), *Xr = malloc((size_t)n * m * sizeof(double));
    if (!lam || !Xr || eig_vectors(&ws, K, M, lo, hi, lam, Xr)) {
      free(lam); free(Xr); eig_free(&ws);
      return fail_at(c, fx->loc, "the eigensolver failed (LAPACK error computing mode shapes)");
    }
    for (int j = 0; j < *ns; j++) {
      int i = sel[j] - lo;
      hz[j] = all_hz[sel[j]] = lam_to_hz(lam[i]);
      memcpy(X + (size_t)j * n, Xr + (size_t)i * n, (size_t)n * sizeof(double));
    }
    free(lam); free(Xr);
  }
  eig_free(&ws);
  return 0;
}

/* Each FE DOF: free (0), fixed to the body frame (1: reference conditions,
 * SPCs, DOFs an export lacks), or following another node (2: RBE2). */
static int dof_states(const ir_flex *fx, char *state, char *is_int, fe_ctx *c) {
  int nnodes = fx->nnodes;
  for (int r = 0; r < fx->nreference; r++) {
    int k = fx->reference[r];
    if (k < 0 || k >= nnodes)
      return fail_at(c, fx->loc, "reference node %d out of range (the body has %d nodes)", k, nnodes);
  }
  switch (fx->reference_kind) {
  case REFERENCE_CLAMPED:
    if ((fx->nreference < 1 || !fx->reference) && !fx->fixed)
      return fail_at(c, fx->loc,
                     "an FE flexible body needs at least one reference node (nodes fixed to the body "
                     "frame)");
    for (int r = 0; r < fx->nreference; r++) memset(state + 6 * fx->reference[r], 1, 6);
    break;
  case REFERENCE_CHORD: {
    /* pinned at A (translations, and the twist about the chord), on the
       chord's line at B (the two translations across it); body x = chord */
    if (fx->nreference != 2 || fx->reference[0] == fx->reference[1])
      return fail_at(c, fx->loc, "a chord frame needs two different nodes [A, B]");
    int a = fx->reference[0], b = fx->reference[1];
    const double *pa = fx->nodes + 3 * a, *pb = fx->nodes + 3 * b;
    double d = hypot(hypot(pb[0] - pa[0], pb[1] - pa[1]), pb[2] - pa[2]);
    if (!(pa[0] == 0 && pa[1] == 0 && pa[2] == 0) || !(fabs(pb[1]) <= 1e-12 * d && fabs(pb[2]) <= 1e-12 * d && pb[0] > 0))
      return fail_at(c, fx->loc, "a chord frame needs its origin at node %ld and its x axis towards node %ld",
                     node_name(fx, a), node_name(fx, b));
    memset(state + 6 * a, 1, 4);
    state[6 * b + 1] = state[6 * b + 2] = 1;
    break;
  }
  case REFERENCE_FREE:
    break;
  }
  if (fx->fixed)
    for (int i = 0; i < 6 * nnodes; i++)
      if (fx->fixed[i]) state[i] = 1;
  for (int r = 0; r < fx->ninterface; r++) {
    int k = fx->interface[r];
    if (k < 0 || k >= nnodes)
      return fail_at(c, fx->loc, "interface node %d out of range (the body has %d nodes)", k, nnodes);
    for (int d = 0; d < 6; d++)
      if (!state[6 * k + d]) is_int[k] = 1;
  }
  for (int l = 0; l < fx->nlinks; l++) {
    const ir_rigid_link *L = &fx->links[l];
    for (int d = 0; d < 6; d++) {
      if (!(L->dofs >> d & 1)) continue;
      if (state[6 * L->dependent + d] || is_int[L->dependent])
        return fail_at(c, L->loc, "RBE2: node %ld's DOF %s is already fixed, an interface DOF or "
                       "dependent on another RBE2", node_name(fx, L->dependent), dof_names[d]);
      state[6 * L->dependent + d] = 2;
    }
  }
  for (int l = 0; l < fx->nlinks; l++) {
    const ir_rigid_link *L = &fx->links[l];
    for (int d = 0; d < 6; d++)
      if (state[6 * L->independent + d] == 2)
        return fail_at(c, L->loc, "RBE2: independent node %ld is itself dependent (chained RBE2s)",
                       node_name(fx, L->independent));
  }
  return 0;
}

/* Row 'dep' DOF d of an RBE2 as a combination of the independent node's
 * DOFs: u_d = u_i + theta_i x (x_d - x_i), theta_d = theta_i.  coef[6]. */
void fe_link_row(const ir_flex *fx, const ir_rigid_link *L, int d, double coef[6]) {
  const double *xi = fx->nodes + 3 * L->independent, *xd = fx->nodes + 3 * L->dependent;
  double r[3] = {xd[0] - xi[0], xd[1] - xi[1], xd[2] - xi[2]};
  memset(coef, 0, 6 * sizeof(double));
  coef[d] = 1;
  if (d < 3) { /* (theta x r)_d = sum_k eps_{d k j} theta_k r_j */
    int d1 = (d + 1) % 3, d2 = (d + 2) % 3;
    coef[3 + d1] = r[d2];
    coef[3 + d2] = -r[d1];
  }
}

/* fold the RBE2-dependent DOFs of K (n x n) into their independent DOFs:
 * K <- T^T K T with the dependent rows and columns then zero */
static void fold_links(const ir_flex *fx, double *K, int n) {
  for (int l = 0; l < fx->nlinks; l++) {
    const ir_rigid_link *L = &fx->links[l];
    for (int d = 0; d < 6; d++) {
      if (!(L->dofs >> d & 1)) continue;
      int i = 6 * L->dependent + d;
      double coef[6];
      fe_link_row(fx, L, d, coef);
      for (int a = 0; a < 6; a++) { /* rows */
        if (coef[a] == 0) continue;
        int t = 6 * L->independent + a;
        for (int j = 0; j < n; j++) K[(size_t)j * n + t] += coef[a] * K[(size_t)j * n + i];
      }
      for (int a = 0; a < 6; a++) { /* columns */
        if (coef[a] == 0) continue;
        int t = 6 * L->independent + a;
        for (int j = 0; j < n; j++) K[(size_t)t * n + j] += coef[a] * K[(size_t)i * n + j];
      }
      for (int j = 0; j < n; j++) K[(size_t)j * n + i] = K[(size_t)i * n + j] = 0;
    }
  }
}

/* the dependent rows of shapes X (n x m, full DOF numbering) from their independent ones */
static void unfold_links(const ir_flex *fx, double *X, int n, int m) {
  for (int l = 0; l < fx->nlinks; l++) {
    const ir_rigid_link *L = &fx->links[l];
    for (int d = 0; d < 6; d++) {
      if (!(L->dofs >> d & 1)) continue;
      double coef[6];
      fe_link_row(fx, L, d, coef);
      for (int j = 0; j < m; j++) {
        double v = 0;
        for (int a = 0; a < 6; a++) v += coef[a] * X[(size_t)j * n + 6 * L->independent + a];
        X[(size_t)j * n + 6 * L->dependent + d] = v;
      }
    }
  }
}

/* Free-free modes in mean axes: the problem (K + sigma M) x = (lambda + sigma) M x
 * (positive definite); its 6 lowest modes are the rigid-body motions and are
 * dropped, the rest are M-orthogonal to them (the mean-axis conditions:
 * sum m u = 0, sum (m x u + J theta) = 0).  The selection applies to the
 * elastic modes. */
static int eig_select_free(const ir_flex *fx, int n, const double *K, const double *M,
                           double *all_hz, int *sel, int *ns, double *hz, double *X, fe_ctx *c) {
  if (n <= 6) return fail_at(c, fx->loc, "a free-free body needs more than 6 free DOFs");
  size_t nn = (size_t)n * (size_t)n;
  double kmax = 0, mmax = 0;
  for (int i = 0; i < n; i++) {
    kmax = fmax(kmax, K[(size_t)i * n + i]);
    mmax = fmax(mmax, M[(size_t)i * n + i]);
  }
  /* small beside the stiff end of the spectrum, yet a well-conditioned factor */
  double sigma = 1e-8 * kmax / mmax;
  double *Ks = malloc(nn * sizeof(double)), *lam = malloc((size_t)n * sizeof(double));
  eig_ws ws;
  memset(&ws, 0, sizeof ws);
  int rc = -1;
  if (!Ks || !lam) { fail_at(c, fx->loc, "out of memory"); goto done; }
  for (size_t i = 0; i < nn; i++) Ks[i] = K[i] + sigma * M[i];
  int e = eig_reduce(n, Ks, M, &ws, lam);
  if (e) {
    fail_at(c, fx->loc, "the eigensolver failed (%s)",
            e == 1 ? "the mass matrix is not positive definite" : "LAPACK error");
    goto done;
  }
  for (int i = 0; i < n; i++) lam[i] -= sigma;
  if (!(lam[6] > 1e-6 * sigma)) {
    fail_at(c, fx->loc, "the free-free body has more than 6 rigid-body modes (a mechanism, or parts "
            "not connected)");
    goto done;
  }
  for (int i = 6; i < n; i++) all_hz[i - 6] = lam_to_hz(lam[i]);
  if (select_modes(fx, all_hz, n - 6, sel, ns, "free-free elastic modes", c)) goto done;
  if (*ns > 0) {
    int lo = sel[0] + 6, hi = sel[*ns - 1] + 6, m = hi - lo + 1;
    double *lv = malloc((size_t)m * sizeof(double)), *Xr = malloc((size_t)n * m * sizeof(double));
    if (!lv || !Xr || eig_vectors(&ws, K, M, lo, hi, lv, Xr)) {
      free(lv); free(Xr);
      fail_at(c, fx->loc, "the eigensolver failed (LAPACK error computing mode shapes)");
      goto done;
    }
    for (int j = 0; j < *ns; j++) {
      int i = sel[j] + 6 - lo;
      hz[j] = all_hz[sel[j]] = lam_to_hz(lv[i]);
      memcpy(X + (size_t)j * n, Xr + (size_t)i * n, (size_t)n * sizeof(double));
    }
    free(lv); free(Xr);
  }
  rc = 0;
done:
  free(Ks); free(lam); eig_free(&ws);
  return rc;
}

/* Large bodies: sparse assembly and shift-invert Lanczos (fe_sparse.c) for
 * the selected count of lowest modes (free-free: 6 more, the rigid-body
 * modes, then dropped).  No Craig-Bampton. */
static int modes_sparse(const ir_flex *fx, fe_modes *out, const char *state, int nf, fe_ctx *c) {
  int nnodes = fx->nnodes, ndof = 6 * nnodes, nev = 0, rigid = fx->reference_kind == REFERENCE_FREE ? 6 : 0;
  if (fx->nresidual > 0)
    return fail_at(c, fx->loc, "the sparse eigensolver does not add residual modes: use eigensolver: dense");
  if (fx->ninterface > 0)
    return fail_at(c, fx->loc, "the sparse eigensolver does not do Craig-Bampton (interface nodes): use "
                   "eigensolver: dense");
  if (fx->select == MODES_COUNT) nev = fx->count;
  else if (fx->select == MODES_LIST)
    for (int i = 0; i < fx->nlist; i++) nev = fx->list[i] > nev ? fx->list[i] : nev;
  else
    return fail_at(c, fx->loc, "a large body (%d free DOFs; the sparse eigensolver) needs its modes "
                   "as a count or a list ('modes: 20')", nf);
  if (nev < 1 || nev + rigid >= nf)
    return fail_at(c, fx->loc, "mode count %d: the sparse eigensolver finds 1 to %d modes", nev, nf - rigid - 1);
  ir_fe_matrix K, M;
  int *fidx = xcalloc((size_t)ndof, sizeof(int)), *perm = xcalloc((size_t)nf, sizeof(int)), *sel = NULL;
  double *lam = xcalloc((size_t)(nev + rigid), sizeof(double));
  double *X = xcalloc((size_t)nf * (size_t)(nev + rigid), sizeof(double)), *hz = NULL;
  int rc = -1;
  if (!fidx || !perm || !lam || !X) {
    fail_at(c, fx->loc, "out of memory");
    goto done;
  }
  for (int i = 0, k = 0; i < ndof; i++) {
    fidx[i] = state[i] == 0 ? k : -1;
    if (state[i] == 0) perm[k++] = i;
  }
  if (fe_assemble_triplets(fx, &K, &M, c->err, c->nerr, c->where)) goto done;
  double sigma = 0;
  if (rigid) { /* below zero by a small fraction of the stiff end: K - sigma M is definite */
    double kmax = 0, mmax = 0;
    for (int t = 0; t < K.nnz; t++)
      if (K.row[t] == K.col[t]) kmax = fmax(kmax, K.val[t]);
    for (int t = 0; t < M.nnz; t++)
      if (M.row[t] == M.col[t]) mmax = fmax(mmax, M.val[t]);
    sigma = -1e-8 * kmax / mmax;
  }
  int e = fe_sparse_eigs(fx, &K, &M, fidx, nf, nev + rigid, sigma, lam, X, c->err, c->nerr);
  free(K.row); free(K.col); free(K.val); free(M.row); free(M.col); free(M.val);
  if (e) {
    if (c->where) *c->where = no_loc;
    goto done;
  }
  for (int j = rigid; j < nev + rigid; j++)
    if (!(lam[j] > 0)) {
      fail_at(c, fx->loc, "the sparse eigensolver found a mode at %g rad^2/s^2 (not positive): the stiffness "
              "matrix is singular to double precision (a mechanism, or elements so short beside the body "
              "that the spectrum spans more than 1e16)", lam[j]);
      goto done;
    }
  if (rigid && !(lam[6] > 1e-6 * -sigma)) {
    fail_at(c, fx->loc, "the free-free body has more than 6 rigid-body modes (a mechanism, or parts not "
            "connected)");
    goto done;
  }
  hz = xcalloc((size_t)nev, sizeof(double));
  sel = xcalloc((size_t)nev, sizeof(int));
  if (!hz || !sel) { fail_at(c, fx->loc, "out of memory"); goto done; }
  for (int j = 0; j < nev; j++) hz[j] = lam_to_hz(lam[j + rigid]);
  int ns = 0;
  if (select_modes(fx, hz, nev, sel, &ns, "modes computed", c)) goto done;
  if (alloc_modes(out, nnodes, ns, nev)) { fail_at(c, fx->loc, "out of memory"); goto done; }
  out->sparse = 1;
  memcpy(out->all_freq_hz, hz, (size_t)nev * sizeof(double));
  for (int j = 0; j < ns; j++) {
    double *x = X + (size_t)(sel[j] + rigid) * nf;
    fix_sign(x, nf);
    out->freq_hz[j] = hz[sel[j]];
    for (int i = 0; i < nf; i++) out->shapes[(size_t)j * ndof + perm[i]] = x[i];
  }
  unfold_links(fx, out->shapes, ndof, ns);
  memcpy(out->x, fx->nodes, 3 * (size_t)nnodes * sizeof(double));
  if (fe_lumped_nodes(fx, out->node_mass, out->node_inertia, c->err, c->nerr, c->where)) goto done;
  rc = 0;
done:
  free(fidx); free(perm); free(sel); free(lam); free(X); free(hz);
  return rc;
}

/* Residual attachment modes (static correction) for unit loads at each free
 * DOF of the residual_modes nodes, added to the ns kept modes X (nf x ns,
 * M-orthonormal, frequencies hz).  Each load f gives the residual flexibility
 * shape psi = G f - sum_j x_j x_j^T f / lambda_j, which is M- and
 * K-orthogonal to the kept modes; the psi are then M-orthonormalized and
 * diagonalized by their own small eigenproblem (the projected mass is kept,
 * as in Rubin's method, not dropped as in MacNeal's), so that every column
 * has a frequency.  A free-free body (free != 0) has no G: the load is first
 * balanced by the rigid-body inertia forces it causes (inertia relief,
 * f - M R R^T f with R the M-orthonormal rigid-body motions) and the elastic
 * deflection solved with K + s (M R)(M R)^T (any s > 0), which leaves it
 * M-orthogonal to R.
 * Columns whose residual vanishes (the kept modes already span the load's
 * deflection) are dropped.  On success *Xout (nf x *nout) and *hzout hold the
 * kept and residual modes by ascending frequency (malloc'd). */
static int add_residual_modes(const ir_flex *fx, const char *state, const int *perm, int nf,
                              const double *Kf, const double *Mf, int free_body, int ns,
                              const double *hz, const double *X, int *nout, double **Xout,
                              double **hzout, fe_ctx *c) {
  int ndof = 6 * fx->nnodes, rc = -1, nl = 0;
  int *where = malloc((size_t)ndof * sizeof(int));
  double *F = NULL, *U = NULL, *Kr = NULL, *R = NULL, *MR = NULL, *Kq = NULL, *Mq = NULL, *Y = NULL,
         *w = NULL, *tmp = NULL, *norm0 = NULL, *all = NULL, *allhz = NULL;
  int *order = NULL;
  if (!where) return fail_at(c, fx->loc, "out of memory");
  for (int i = 0; i < ndof; i++) where[i] = -1;
  for (int p = 0; p < nf; p++) where[perm[p]] = p;
  for (int r = 0; r < fx->nresidual; r++) {
    int k = fx->residual[r];
    if (k < 0 || k >= fx->nnodes) {
      fail_at(c, fx->loc, "residual_modes: node %d out of range (the body has %d nodes)", k, fx->nnodes);
      goto done;
    }
  }
  F = xcalloc((size_t)nf * (size_t)(6 * fx->nresidual), sizeof(double));
  if (!F) { fail_at(c, fx->loc, "out of memory"); goto done; }
  /* one load column per free (or RBE2-dependent) DOF; a dependent DOF's
     load acts on its independent node through the link */
  for (int r = 0; r < fx->nresidual; r++) {
    int k = fx->residual[r];
    int dup = 0;
    for (int q = 0; q < r; q++) dup |= fx->residual[q] == k;
    if (dup) continue;
    for (int d = 0; d < 6; d++) {
      int i = 6 * k + d;
      double *f = F + (size_t)nl * nf;
      if (state[i] == 0) {
        f[where[i]] = 1;
      } else if (state[i] == 2) {
        for (int l = 0; l < fx->nlinks; l++) {
          const ir_rigid_link *L = &fx->links[l];
          if (L->dependent != k || !(L->dofs >> d & 1)) continue;
          double coef[6];
          fe_link_row(fx, L, d, coef);
          for (int a = 0; a < 6; a++) {
            int t = where[6 * L->independent + a];
            if (t >= 0) f[t] += coef[a];
          }
        }
      } else {
        continue; /* fixed to the body frame: no deflection */
      }
      nl++;
    }
  }
  size_t nn = (size_t)nf * (size_t)nf;
  Kr = malloc(nn * sizeof(double));
  U = xcalloc((size_t)nf * (size_t)(nl ? nl : 1), sizeof(double));
  tmp = xcalloc((size_t)nf * (size_t)(nl > 6 ? nl : 6), sizeof(double));
  norm0 = xcalloc((size_t)(nl ? nl : 1), sizeof(double));
  if (!Kr || !U || !tmp || !norm0) { fail_at(c, fx->loc, "out of memory"); goto done; }
  memcpy(Kr, Kf, nn * sizeof(double));
  if (free_body) {
    /* rigid-body motions of the free DOFs (RBE2s folded: the independent
       nodes carry them), M-orthonormalized */
    R = xcalloc((size_t)nf * 6, sizeof(double));
    MR = xcalloc((size_t)nf * 6, sizeof(double));
    if (!R || !MR) { fail_at(c, fx->loc, "out of memory"); goto done; }
    for (int p = 0; p < nf; p++) {
      int k = perm[p] / 6, d = perm[p] % 6;
      const double *x = fx->nodes + 3 * k;
      for (int a = 0; a < 3; a++) {
        R[(size_t)a * nf + p] = d == a;
        /* rotation about axis a: u = e_a x x, theta = e_a */
        double e[3] = {0, 0, 0}, u[3];
        e[a] = 1;
        u[0] = e[1] * x[2] - e[2] * x[1];
        u[1] = e[2] * x[0] - e[0] * x[2];
        u[2] = e[0] * x[1] - e[1] * x[0];
        R[(size_t)(3 + a) * nf + p] = d < 3 ? u[d] : (d - 3 == a);
      }
    }
    for (int pass = 0; pass < 2; pass++)
      for (int a = 0; a < 6; a++) {
        double *ra = R + (size_t)a * nf;
        mul("N", "N", nf, 1, nf, Mf, nf, ra, nf, tmp, nf);
        for (int b = 0; b < a; b++) {
          double g = 0;
          for (int p = 0; p < nf; p++) g += R[(size_t)b * nf + p] * tmp[p];
          for (int p = 0; p < nf; p++) ra[p] -= g * R[(size_t)b * nf + p];
        }
        mul("N", "N", nf, 1, nf, Mf, nf, ra, nf, tmp, nf);
        double g = 0;
        for (int p = 0; p < nf; p++) g += ra[p] * tmp[p];
        if (!(g > 0)) { fail_at(c, fx->loc, "residual_modes: the free-free body's rigid-body motions are degenerate"); goto done; }
        for (int p = 0; p < nf; p++) ra[p] /= sqrt(g);
      }
    mul("N", "N", nf, 6, nf, Mf, nf, R, nf, MR, nf);
    /* K + (M R)(M R)^T: positive definite, and equal to K on elastic shapes */
    mul("N", "T", nf, nf, 6, MR, nf, MR, nf, Kr, nf);
    /* scaled to K's size, so that the factor stays well conditioned */
    double kmax = 0, rmax = 0;
    for (int i = 0; i < nf; i++) {
      kmax = fmax(kmax, Kf[(size_t)i * nf + i]);
      rmax = fmax(rmax, Kr[(size_t)i * nf + i]);
    }
    double scale = rmax > 0 ? kmax / rmax : 1;
    for (size_t i = 0; i < nn; i++) Kr[i] = Kf[i] + scale * Kr[i];
    /* inertia relief: f - M R R^T f */
    for (int j = 0; j < nl; j++) {
      double *f = F + (size_t)j * nf;
      for (int a = 0; a < 6; a++) {
        double g = 0;
        for (int p = 0; p < nf; p++) g += R[(size_t)a * nf + p] * f[p];
        for (int p = 0; p < nf; p++) f[p] -= g * MR[(size_t)a * nf + p];
      }
    }
  }
  memcpy(U, F, (size_t)nf * (size_t)nl * sizeof(double));
  if (nl > 0) {
    int info = 0;
    dpotrf_("U", &nf, Kr, &nf, &info);
    if (info == 0) dpotrs_("U", &nf, &nl, Kr, &nf, U, &nf, &info);
    if (info != 0) { fail_at(c, fx->loc, "residual_modes: the stiffness matrix is singular"); goto done; }
  }
  /* minus the kept modes' static part; then M-orthonormal, M-orthogonal to
     the kept modes (again, for rounding) */
  for (int j = 0; j < nl; j++) {
    double *u = U + (size_t)j * nf;
    const double *f = F + (size_t)j * nf;
    double g0 = 0;
    mul("N", "N", nf, 1, nf, Mf, nf, u, nf, tmp, nf);
    for (int p = 0; p < nf; p++) g0 += u[p] * tmp[p];
    norm0[j] = sqrt(g0);
    for (int m = 0; m < ns; m++) {
      const double *x = X + (size_t)m * nf;
      double lam = 4 * FE_PI * FE_PI * hz[m] * hz[m], g = 0;
      for (int p = 0; p < nf; p++) g += x[p] * f[p];
      for (int p = 0; p < nf; p++) u[p] -= g / lam * x[p];
    }
  }
  int nq = 0;
  for (int j = 0; j < nl; j++) {
    double *u = U + (size_t)j * nf, g = 0;
    for (int pass = 0; pass < 2; pass++) {
      mul("N", "N", nf, 1, nf, Mf, nf, u, nf, tmp, nf);
      for (int m = 0; m < ns; m++) {
        const double *x = X + (size_t)m * nf;
        double h = 0;
        for (int p = 0; p < nf; p++) h += x[p] * tmp[p];
        for (int p = 0; p < nf; p++) u[p] -= h * x[p];
      }
      for (int b = 0; b < nq; b++) {
        double *v = U + (size_t)b * nf, h = 0;
        for (int p = 0; p < nf; p++) h += v[p] * tmp[p];
        for (int p = 0; p < nf; p++) u[p] -= h * v[p];
      }
    }
    mul("N", "N", nf, 1, nf, Mf, nf, u, nf, tmp, nf);
    for (int p = 0; p < nf; p++) g += u[p] * tmp[p];
    /* nothing left beyond the kept modes (and earlier loads): dropped */
    if (!(g > 1e-16 * norm0[j] * norm0[j]) || norm0[j] == 0) continue;
    double *dst = U + (size_t)nq * nf;
    for (int p = 0; p < nf; p++) dst[p] = u[p] / sqrt(g);
    nq++;
  }
  /* the residual block's own eigenproblem: U^T K U y = lambda y */
  Kq = xcalloc((size_t)nq * (size_t)nq, sizeof(double));
  Mq = xcalloc((size_t)nq * (size_t)nq, sizeof(double));
  Y = xcalloc((size_t)nq * (size_t)nq, sizeof(double));
  w = xcalloc((size_t)nq, sizeof(double));
  double *K2 = xcalloc((size_t)nf * (size_t)(nq ? nq : 1), sizeof(double));
  all = xcalloc((size_t)nf * (size_t)(ns + nq), sizeof(double));
  allhz = xcalloc((size_t)(ns + nq), sizeof(double));
  order = xcalloc((size_t)(ns + nq), sizeof(int));
  if (!Kq || !Mq || !Y || !w || !K2 || !all || !allhz || !order) {
    free(K2);
    fail_at(c, fx->loc, "out of memory");
    goto done;
  }
  mul("N", "N", nf, nq, nf, Kf, nf, U, nf, K2, nf);
  mul("T", "N", nq, nq, nf, U, nf, K2, nf, Kq, nq);
  free(K2);
  for (int j = 0; j < nq; j++) {
    Mq[(size_t)j * nq + j] = 1;
    for (int i = 0; i < j; i++)
      Kq[(size_t)j * nq + i] = Kq[(size_t)i * nq + j] = 0.5 * (Kq[(size_t)j * nq + i] + Kq[(size_t)i * nq + j]);
  }
  int bad = -1;
  if (nq > 0 && gen_eig(nq, Kq, Mq, w, Y, &bad) != 0) {
    fail_at(c, fx->loc, "residual_modes: the residual modes' eigenproblem failed (LAPACK)");
    goto done;
  }
  /* merge by ascending frequency (stable: kept modes first on ties) */
  for (int j = 0; j < ns; j++) { allhz[j] = hz[j]; order[j] = j; }
  for (int j = 0; j < nq; j++) { allhz[ns + j] = lam_to_hz(w[j]); order[ns + j] = ns + j; }
  for (int a = 1; a < ns + nq; a++)
    for (int b = a; b > 0 && allhz[order[b]] < allhz[order[b - 1]]; b--) {
      int t = order[b]; order[b] = order[b - 1]; order[b - 1] = t;
    }
  *hzout = xcalloc((size_t)(ns + nq), sizeof(double));
  *Xout = xcalloc((size_t)nf * (size_t)(ns + nq), sizeof(double));
  if (!*hzout || !*Xout) {
    free(*hzout); free(*Xout); *hzout = NULL; *Xout = NULL;
    fail_at(c, fx->loc, "out of memory");
    goto done;
  }
  if (nq > 0) mul("N", "N", nf, nq, nq, U, nf, Y, nq, all + (size_t)ns * nf, nf);
  memcpy(all, X, (size_t)nf * (size_t)ns * sizeof(double));
  for (int j = 0; j < ns + nq; j++) {
    (*hzout)[j] = allhz[order[j]];
    memcpy(*Xout + (size_t)j * nf, all + (size_t)order[j] * nf, (size_t)nf * sizeof(double));
  }
  *nout = ns + nq;
  rc = 0;
done:
  free(where); free(F); free(U); free(Kr); free(R); free(MR); free(Kq); free(Mq); free(Y); free(w);
  free(tmp); free(norm0); free(all); free(allhz); free(order);
  return rc;
}

static int modes_from_fe(const ir_flex *fx, fe_modes *out, fe_ctx *c) {
  if (check_flex_common(fx, c)) return -1;
  int nnodes = fx->nnodes, ndof = 6 * nnodes;
  char *is_ref = xcalloc((size_t)nnodes, 1), *is_int = xcalloc((size_t)nnodes, 1);
  char *state = xcalloc((size_t)ndof, 1);
  int *perm = xcalloc((size_t)ndof, sizeof(int));
  int *sel = NULL;
  double *Kf = NULL, *Mf = NULL, *X = NULL, *w = NULL, *T = NULL, *Kr = NULL, *Mr = NULL,
         *tmp = NULL, *Y = NULL, *wi = NULL, *Phi = NULL, *Kii = NULL, *Mii = NULL;
  fe_system sys = {0, NULL, NULL};
  int rc = -1;
  if (!is_ref || !is_int || !perm || !state) { fail_at(c, fx->loc, "out of memory"); goto done; }
  if (dof_states(fx, state, is_int, c)) goto done;
  /* held nodes for the connectivity test: any fixed DOF (free-free: the first node) */
  for (int i = 0; i < ndof; i++)
    if (state[i] == 1) is_ref[i / 6] = 1;
  if (fx->reference_kind == REFERENCE_FREE) is_ref[0] = 1;
  if (!fx->K_given && check_connectivity(fx, is_ref, c)) goto done;
  {
    int nfree = 0;
    for (int i = 0; i < ndof; i++) nfree += state[i] == 0;
    int sparse = fx->eigensolver == 2 ||
                 (fx->eigensolver == 0 && nfree > FE_SPARSE_MIN_DOFS && fx->ninterface == 0 &&
                  fx->nresidual == 0);
    if (sparse) {
      rc = modes_sparse(fx, out, state, nfree, c);
      goto done;
    }
    /* the dense path's time grows with the cube: refused before it starts */
    double max_dofs = limit_value("MBCC_MAX_FE_DOFS", LIMIT_FE_DOFS);
    if (nfree > max_dofs) {
      fail_at(c, fx->loc, "%d free FE degrees of freedom, more than the limit %g of the dense modal analysis "
              "(eigensolver: sparse or auto takes larger bodies without interface nodes; MBCC_MAX_FE_DOFS=N "
              "lifts the limit)", nfree, max_dofs);
      goto done;
    }
  }
  if (fe_assemble_at(fx, &sys, c->err, c->nerr, c->where)) goto done;
  fold_links(fx, sys.K, ndof);
  fold_links(fx, sys.M, ndof);

  /* free DOFs, ordered interface (b) first, then internal (i) */
  int nb = 0, ni = 0;
  for (int k = 0; k < nnodes; k++)
    if (is_int[k])
      for (int d = 0; d < 6; d++)
        if (!state[6 * k + d]) perm[nb++] = 6 * k + d;
  for (int k = 0; k < nnodes; k++)
    if (!is_int[k])
      for (int d = 0; d < 6; d++)
        if (!state[6 * k + d]) perm[nb + ni++] = 6 * k + d;
  int nf = nb + ni;
  size_t nnf = (size_t)nf * (size_t)nf;
  Kf = xcalloc(nnf, sizeof(double));
  Mf = xcalloc(nnf, sizeof(double));
  if (!Kf || !Mf) { fail_at(c, fx->loc, "out of memory"); goto done; }
  gather(sys.K, ndof, perm, nf, perm, nf, Kf);
  gather(sys.M, ndof, perm, nf, perm, nf, Mf);
  if ((fx->reference_kind != REFERENCE_FREE && check_definite(fx, Kf, nf, perm, 0, c)) ||
      check_definite(fx, Mf, nf, perm, 1, c))
    goto done;
  if (fx->nresidual > 0 && nb > 0) {
    fail_at(c, fx->loc, "'residual_modes' goes with free-interface modes, not with 'interface' (Craig-Bampton's "
            "constraint modes already are the static shapes of its interface)");
    goto done;
  }
  if (fx->reference_kind == REFERENCE_FREE && nb > 0) {
    fail_at(c, fx->loc, "a free-free body takes no interface nodes (its modes are free-interface)");
    goto done;
  }

  int nmodes, nall, bad = -1, e;
  if (nb == 0) {
    /* constrained normal modes */
    X = xcalloc(nnf, sizeof(double));
    w = xcalloc((size_t)nf, sizeof(double));
    wi = xcalloc((size_t)nf, sizeof(double));
    sel = xcalloc((size_t)nf, sizeof(int));
    if (!X || !w || !wi || !sel) { fail_at(c, fx->loc, "out of memory"); goto done; }
    int ns = 0;
    if (fx->reference_kind == REFERENCE_FREE) {
      if (eig_select_free(fx, nf, Kf, Mf, wi, sel, &ns, w, X, c)) goto done;
      nall = nf - 6;
    } else {
      if (eig_select(fx, nf, Kf, Mf, "constrained normal modes", wi, sel, &ns, w, X, c)) goto done;
      nall = nf;
    }
    if (fx->nresidual > 0) {
      double *Xs = NULL, *hs = NULL;
      if (add_residual_modes(fx, state, perm, nf, Kf, Mf, fx->reference_kind == REFERENCE_FREE, ns, w, X,
                             &ns, &Xs, &hs, c))
        goto done;
      free(X); free(w);
      X = Xs;
      w = hs;
    }
    nmodes = ns;
    if (alloc_modes(out, nnodes, nmodes, nall)) { fail_at(c, fx->loc, "out of memory"); goto done; }
    memcpy(out->all_freq_hz, wi, (size_t)nall * sizeof(double));
    for (int j = 0; j < nmodes; j++) {
      double *x = X + (size_t)j * nf;
      fix_sign(x, nf);
      out->freq_hz[j] = w[j];
      for (int i = 0; i < nf; i++) out->shapes[(size_t)j * ndof + perm[i]] = x[i];
    }
  } else {
    /* Craig-Bampton: T = [I 0; Psi Phi_n] on (b, i) */
    size_t nni = (size_t)ni * (size_t)ni;
    Kii = xcalloc(nni, sizeof(double));
    Mii = xcalloc(nni, sizeof(double));
    Phi = xcalloc(nni, sizeof(double));
    wi = xcalloc((size_t)ni, sizeof(double));
    sel = xcalloc((size_t)ni, sizeof(int));
    if (!Kii || !Mii || !Phi || !wi || !sel) { fail_at(c, fx->loc, "out of memory"); goto done; }
    for (int j = 0; j < ni; j++)
      for (int i = 0; i < ni; i++) {
        Kii[(size_t)j * ni + i] = Kf[(size_t)(nb + j) * nf + nb + i];
        Mii[(size_t)j * ni + i] = Mf[(size_t)(nb + j) * nf + nb + i];
      }
    int ns = 0;
    double *hzi = xcalloc((size_t)ni, sizeof(double));
    if (!hzi) { fail_at(c, fx->loc, "out of memory"); goto done; }
    e = eig_select(fx, ni, Kii, Mii, "fixed-interface normal modes", wi, sel, &ns, hzi, Phi, c);
    free(hzi);
    if (e) goto done;
    int nr = nb + ns;
    T = xcalloc((size_t)nf * (size_t)nr, sizeof(double));
    if (!T) { fail_at(c, fx->loc, "out of memory"); goto done; }
    /* T column j < nb: unit displacement of interface DOF j, Psi_c = -K_ii^-1 K_ib */
    for (int j = 0; j < nb; j++) {
      double *t = T + (size_t)j * nf;
      t[j] = 1;
      for (int i = 0; i < ni; i++) t[nb + i] = -Kf[(size_t)j * nf + nb + i];
    }
    if (ni > 0) {
      int info = 0;
      /* Kii still holds K_ii: the eigensolver works on copies */
      dpotrf_("U", &ni, Kii, &ni, &info);
      if (info == 0) dpotrs_("U", &ni, &nb, Kii, &ni, T + nb, &nf, &info);
      if (info != 0) { fail_at(c, fx->loc, "the internal stiffness K_ii is singular"); goto done; }
    }
    for (int j = 0; j < ns; j++) {
      double *t = T + (size_t)(nb + j) * nf;
      memcpy(t + nb, Phi + (size_t)j * ni, (size_t)ni * sizeof(double));
    }
    size_t nnr = (size_t)nr * (size_t)nr;
    Kr = xcalloc(nnr, sizeof(double));
    Mr = xcalloc(nnr, sizeof(double));
    tmp = xcalloc((size_t)nf * (size_t)nr, sizeof(double));
    Y = xcalloc(nnr, sizeof(double));
    w = xcalloc((size_t)nr, sizeof(double));
    X = xcalloc((size_t)nf * (size_t)nr, sizeof(double));
    if (!Kr || !Mr || !tmp || !Y || !w || !X) { fail_at(c, fx->loc, "out of memory"); goto done; }
    mul("N", "N", nf, nr, nf, Kf, nf, T, nf, tmp, nf);
    mul("T", "N", nr, nr, nf, T, nf, tmp, nf, Kr, nr);
    mul("N", "N", nf, nr, nf, Mf, nf, T, nf, tmp, nf);
    mul("T", "N", nr, nr, nf, T, nf, tmp, nf, Mr, nr);
    for (int j = 0; j < nr; j++)
      for (int i = 0; i < j; i++) {
        size_t u = (size_t)j * nr + i, l = (size_t)i * nr + j;
        Kr[u] = Kr[l] = 0.5 * (Kr[u] + Kr[l]);
        Mr[u] = Mr[l] = 0.5 * (Mr[u] + Mr[l]);
      }
    if (gen_eig(nr, Kr, Mr, w, Y, &bad) != 0) {
      fail_at(c, fx->loc, "the reduced Craig-Bampton eigenproblem failed (LAPACK)");
      goto done;
    }
    mul("N", "N", nf, nr, nr, T, nf, Y, nr, X, nf);
    nmodes = nr;
    nall = ni;
    if (alloc_modes(out, nnodes, nmodes, nall)) { fail_at(c, fx->loc, "out of memory"); goto done; }
    memcpy(out->all_freq_hz, wi, (size_t)ni * sizeof(double));
    for (int j = 0; j < nmodes; j++) {
      double *x = X + (size_t)j * nf;
      fix_sign(x, nf);
      out->freq_hz[j] = lam_to_hz(w[j]);
      for (int i = 0; i < nf; i++) out->shapes[(size_t)j * ndof + perm[i]] = x[i];
    }
  }
  unfold_links(fx, out->shapes, ndof, out->nmodes);
  memcpy(out->x, fx->nodes, 3 * (size_t)nnodes * sizeof(double));
  if (fe_lumped_nodes(fx, out->node_mass, out->node_inertia, c->err, c->nerr, c->where)) goto done;
  rc = 0;
done:
  fe_system_free(&sys);
  free(is_ref); free(is_int); free(state); free(perm); free(sel);
  free(Kf); free(Mf); free(X); free(w); free(T); free(Kr); free(Mr); free(tmp); free(Y);
  free(wi); free(Phi); free(Kii); free(Mii);
  return rc;
}

/* ------------------------------------------------------------------------- */
/* static condensation (superelement)                                          */

int fe_condense(const ir_flex *fx, int clamped, int loaded, double K6[36], char *err, size_t nerr,
                ir_loc *where) {
  return fe_condense_nodes(fx, clamped, &loaded, 1, K6, err, nerr, where);
}

int fe_condense_nodes(const ir_flex *fx, int clamped, const int *loaded, int nloaded, double *Kc, char *err,
                      size_t nerr, ir_loc *where) {
  fe_ctx cc = {err, nerr, where}, *c = &cc;
  if (where) *where = no_loc;
  int nnodes = fx->nnodes, ndof = 6 * nnodes, rc = -1, nl = 6 * nloaded;
  if (clamped < 0 || clamped >= nnodes || nloaded < 1)
    return fail_at(c, fx->loc, "a superelement needs at least two different nodes of its FE model");
  for (int a = 0; a < nloaded; a++) {
    if (loaded[a] < 0 || loaded[a] >= nnodes || loaded[a] == clamped)
      return fail_at(c, fx->loc, "a superelement needs %s different nodes of its FE model",
                     nloaded == 1 ? "two" : "its interface nodes to be");
    for (int b = 0; b < a; b++)
      if (loaded[a] == loaded[b])
        return fail_at(c, fx->loc, "superelement: interface node %ld is listed twice", node_name(fx, loaded[a]));
  }
  ir_flex held = *fx; /* the clamped node as the only reference, no interface */
  held.reference = &clamped;
  held.nreference = 1;
  held.reference_kind = REFERENCE_CLAMPED;
  held.interface = NULL;
  held.ninterface = 0;
  held.nresidual = 0;
  char *state = xcalloc((size_t)ndof, 1), *is_int = xcalloc((size_t)nnodes, 1), *is_ref = xcalloc((size_t)nnodes, 1);
  int *perm = xcalloc((size_t)ndof, sizeof(int)), *where_f = xcalloc((size_t)ndof, sizeof(int));
  double *Kf = NULL, *F = NULL, *U = NULL, *G = NULL;
  fe_system sys = {0, NULL, NULL};
  if (!state || !is_int || !is_ref || !perm || !where_f) { fail_at(c, fx->loc, "out of memory"); goto done; }
  if (dof_states(&held, state, is_int, c)) goto done;
  for (int i = 0; i < ndof; i++)
    if (state[i] == 1) is_ref[i / 6] = 1;
  if (!fx->K_given && check_connectivity(&held, is_ref, c)) goto done;
  if (fe_assemble_at(&held, &sys, c->err, c->nerr, c->where)) goto done;
  fold_links(&held, sys.K, ndof);
  int nf = 0;
  for (int i = 0; i < ndof; i++) {
    where_f[i] = -1;
    if (!state[i]) { where_f[i] = nf; perm[nf++] = i; }
  }
  Kf = xcalloc((size_t)nf * (size_t)nf, sizeof(double));
  F = xcalloc((size_t)nf * (size_t)nl, sizeof(double));
  U = xcalloc((size_t)nf * (size_t)nl, sizeof(double));
  G = xcalloc((size_t)nl * (size_t)nl, sizeof(double));
  if (!Kf || !F || !U || !G) { fail_at(c, fx->loc, "out of memory"); goto done; }
  gather(sys.K, ndof, perm, nf, perm, nf, Kf);
  /* with the first node held the FE model must have no mechanism (its
     free-free K is singular by nature: the element works relative to that node) */
  if (check_definite(&held, Kf, nf, perm, 0, c)) goto done;
  /* unit loads on the loaded nodes' DOFs (an RBE2-dependent DOF's through its link) */
  for (int a = 0; a < nloaded; a++)
    for (int d = 0; d < 6; d++) {
      int i = 6 * loaded[a] + d;
      double *f = F + (size_t)(6 * a + d) * nf;
      if (state[i] == 0) {
        f[where_f[i]] = 1;
      } else if (state[i] == 2) {
        for (int l = 0; l < fx->nlinks; l++) {
          const ir_rigid_link *L = &fx->links[l];
          if (L->dependent != loaded[a] || !(L->dofs >> d & 1)) continue;
          double coef[6];
          fe_link_row(fx, L, d, coef);
          for (int k = 0; k < 6; k++)
            if (where_f[6 * L->independent + k] >= 0) f[where_f[6 * L->independent + k]] += coef[k];
        }
      } else {
        fail_at(c, fx->loc, "superelement: DOF %s of node %ld is fixed (an SPC), so the condensed stiffness "
                "is infinite", dof_names[d], node_name(fx, loaded[a]));
        goto done;
      }
    }
  /* the loaded nodes' flexibility G = f^T K^-1 f (nl x nl), Kc = G^-1: the
     Schur complement of K onto the loaded DOFs, the first node held */
  int info = 0;
  memcpy(U, F, (size_t)nf * (size_t)nl * sizeof(double));
  dpotrf_("U", &nf, Kf, &nf, &info);
  if (info == 0) dpotrs_("U", &nf, &nl, Kf, &nf, U, &nf, &info);
  if (info == 0) mul("T", "N", nl, nl, nf, F, nf, U, nf, G, nl);
  if (info != 0) { fail_at(c, fx->loc, "superelement: the stiffness with the first node clamped is singular"); goto done; }
  for (int j = 0; j < nl; j++)
    for (int i = 0; i < j; i++) G[(size_t)nl * j + i] = G[(size_t)nl * i + j] = 0.5 * (G[(size_t)nl * j + i] + G[(size_t)nl * i + j]);
  /* the inverse, by solving G Kc = I */
  memset(Kc, 0, (size_t)nl * (size_t)nl * sizeof(double));
  for (int i = 0; i < nl; i++) Kc[(size_t)(nl + 1) * i] = 1;
  dpotrf_("U", &nl, G, &nl, &info);
  if (info == 0) {
    /* a pivot far below the largest diagonal: interface DOFs that cannot
       move apart (two interface nodes tied by one RBE2, say) */
    double dmax = 0, dmin = INFINITY;
    for (int i = 0; i < nl; i++) {
      double p = G[(size_t)(nl + 1) * i] * G[(size_t)(nl + 1) * i];
      dmax = fmax(dmax, p);
      dmin = fmin(dmin, p);
    }
    if (!(dmin > 1e-13 * dmax)) info = 1;
  }
  if (info == 0) dpotrs_("U", &nl, &nl, G, &nl, Kc, &nl, &info);
  if (info != 0) {
    fail_at(c, fx->loc, "superelement: the interface nodes' flexibility is singular (interface DOFs that "
            "cannot move independently of each other, e.g. nodes tied by one RBE2), so the condensed "
            "stiffness is infinite");
    goto done;
  }
  for (int j = 0; j < nl; j++)
    for (int i = 0; i < j; i++)
      Kc[(size_t)nl * j + i] = Kc[(size_t)nl * i + j] = 0.5 * (Kc[(size_t)nl * j + i] + Kc[(size_t)nl * i + j]);
  rc = 0;
done:
  fe_system_free(&sys);
  free(state); free(is_int); free(is_ref); free(perm); free(where_f); free(Kf); free(F); free(U); free(G);
  return rc;
}

/* ------------------------------------------------------------------------- */
/* modal data file                                                            */

/* the modes of a modal data file, read and checked by the front end
   (compiler/front/modal_file.c): the selection applies to them */
static int modes_from_data(const ir_flex *fx, fe_modes *out, fe_ctx *c) {
  const ir_modal_data *md = fx->modal;
  if (!md) return fail_at(c, fx->loc, "its modal data file %s was not read", fx->modal_file);
  int nn = md->nnodes, nm = md->nmodes, ns = 0;
  int *sel = xcalloc((size_t)nm, sizeof(int));
  if (!sel) return fail_at(c, fx->loc, "out of memory");
  int rc = select_modes(fx, md->freq_hz, nm, sel, &ns, "modes in the modal data file", c);
  if (!rc && alloc_modes(out, nn, ns, nm)) rc = fail_at(c, fx->loc, "out of memory");
  if (!rc) {
    memcpy(out->x, md->position, 3 * (size_t)nn * sizeof(double));
    memcpy(out->node_mass, md->mass, (size_t)nn * sizeof(double));
    memcpy(out->node_inertia, md->inertia, 9 * (size_t)nn * sizeof(double));
    memcpy(out->all_freq_hz, md->freq_hz, (size_t)nm * sizeof(double));
    for (int j = 0; j < ns; j++) {
      out->freq_hz[j] = md->freq_hz[sel[j]];
      memcpy(out->shapes + (size_t)j * 6 * nn, md->shapes + (size_t)sel[j] * 6 * nn,
             6 * (size_t)nn * sizeof(double));
    }
  }
  free(sel);
  return rc;
}

static void write_string(FILE *f, const char *s) {
  fputc('"', f);
  for (; *s; s++) {
    unsigned char ch = (unsigned char)*s;
    if (ch == '"' || ch == '\\') fprintf(f, "\\%c", ch);
    else if (ch == '\n') fputs("\\n", f);
    else if (ch < 0x20) fprintf(f, "\\x%02x", ch);
    else fputc(ch, f);
  }
  fputc('"', f);
}

int fe_modes_write(const fe_modes *m, const char *path, const char *description, char *err,
                   size_t nerr) {
  fe_ctx c = {err, nerr, NULL};
  FILE *f = fopen(path, "w");
  if (!f) return fail_at(&c, no_loc, "%s: error: cannot write the modal data file: %s", path, strerror(errno));
  fprintf(f, "# modal data file of a flexible body (format: docs/modal-file.md); SI units.\n");
  fprintf(f, "# Shapes are mass-normalized with respect to the nodal masses and inertias.\n");
  fprintf(f, "format: " IR_MODAL_FORMAT "\n");
  if (description) {
    fprintf(f, "description: ");
    write_string(f, description);
    fputc('\n', f);
  }
  fprintf(f, "nodes:            # position (body axes, m), mass (kg), inertia (kg m^2, 3x3 row-major)\n");
  for (int k = 0; k < m->nnodes; k++) {
    const double *x = m->x + 3 * k, *J = m->node_inertia + 9 * k;
    fprintf(f, "  - {position: [%.17g, %.17g, %.17g], mass: %.17g,\n     inertia: [", x[0], x[1], x[2],
            m->node_mass[k]);
    for (int i = 0; i < 9; i++) fprintf(f, "%.17g%s", J[i], i < 8 ? ", " : "]}\n");
  }
  fprintf(f, "modes:%s\n", m->nmodes ? "            # frequency (Hz), shape: one row per node, ux uy uz rx ry rz" : " []");
  for (int j = 0; j < m->nmodes; j++) {
    fprintf(f, "  - frequency: %.17g\n    shape:\n", m->freq_hz[j]);
    for (int k = 0; k < m->nnodes; k++) {
      const double *s = m->shapes + (size_t)j * 6 * m->nnodes + 6 * k;
      fprintf(f, "      - [%.17g, %.17g, %.17g, %.17g, %.17g, %.17g]\n", s[0], s[1], s[2], s[3], s[4], s[5]);
    }
  }
  int bad = ferror(f);
  if (fclose(f) != 0 || bad)
    return fail_at(&c, no_loc, "%s: error: writing the modal data file failed", path);
  return 0;
}

/* ------------------------------------------------------------------------- */

int fe_compute_modes_at(const ir_flex *fx, fe_modes *out, char *err, size_t nerr, ir_loc *where) {
  fe_ctx c = {err, nerr, where};
  memset(out, 0, sizeof *out);
  if (where) *where = no_loc;
  int rc = fx->modal_file ? modes_from_data(fx, out, &c) : modes_from_fe(fx, out, &c);
  if (rc) fe_modes_free(out);
  return rc ? -1 : 0;
}

int fe_compute_modes(const ir_flex *fx, fe_modes *out, char *err, size_t nerr) {
  return fe_compute_modes_at(fx, out, err, nerr, NULL);
}

void fe_modes_free(fe_modes *m) {
  if (!m) return;
  free(m->x);
  free(m->freq_hz);
  free(m->shapes);
  free(m->node_mass);
  free(m->node_inertia);
  free(m->all_freq_hz);
  memset(m, 0, sizeof *m);
}

/* ------------------------------------------------------------------------- */
/* stress recovery                                                            */

int fe_section_rows(const ir_flex *fx, int e, int end, const fe_modes *fm, double *rows, double sec[3],
                    char *err, size_t nerr) {
  fe_ctx c = {err, nerr, NULL};
  if (!fx->beams || e < 0 || e >= fx->nbeams) return fail_at(&c, fx->loc, "no beam %d", e);
  beam_el el;
  if (beam_frame(fx, e, &el, &c)) return -1;
  beam_local(&fx->beams[e], &el);
  int nm = fm->nmodes, ndof = 6 * fm->nnodes;
  double *u = xcalloc(12 * (size_t)(nm ? nm : 1), sizeof(double));
  if (!u) return fail_at(&c, fx->loc, "out of memory");
  /* the element's local DOFs per mode: R (translations; rotations) of its two nodes */
  for (int j = 0; j < nm; j++)
    for (int a = 0; a < 2; a++) {
      const double *x = fm->shapes + (size_t)j * ndof + 6 * fx->beams[e].node[a];
      for (int p = 0; p < 2; p++)
        for (int i = 0; i < 3; i++)
          u[12 * j + 6 * a + 3 * p + i] =
              el.R[3 * i] * x[3 * p] + el.R[3 * i + 1] * x[3 * p + 1] + el.R[3 * i + 2] * x[3 * p + 2];
    }
  /* nodal forces f = K u; the section resultant on the face whose outward
     normal is +x: -f at end A, f at end B */
  for (int r = 0; r < 6; r++)
    for (int j = 0; j < nm; j++) {
      double f = 0;
      for (int k = 0; k < 12; k++) f += el.K[k * 12 + 6 * end + r] * u[12 * j + k];
      rows[(size_t)r * nm + j] = end ? f : -f;
    }
  free(u);
  sec[0] = fx->beams[e].A;
  sec[1] = fx->beams[e].Iy;
  sec[2] = fx->beams[e].Iz;
  return 0;
}
