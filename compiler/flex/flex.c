/* flex.c: turns a flexible body's modes (fe_modes) into the runtime's mb_flex:
 * the inertia invariants of the lumped-mass formulation (seed 000 eqs. 8, 16;
 * docs/formulation.md), modal stiffness and damping, node shape rows. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "diag.h"
#include "flex.h"

/* modal damping ratio of a mode of frequency f (Hz) */
/* entries of a table below 1e-10 of its largest (in magnitude) become 0 */
static void clean_table(double *t, size_t n) {
  double mx = 0;
  for (size_t i = 0; i < n; i++) mx = fmax(mx, fabs(t[i]));
  for (size_t i = 0; i < n; i++)
    if (fabs(t[i]) <= 1e-10 * mx) t[i] = 0;
}

static double damping_ratio(const ir_flex *fx, int j, double f) {
  switch (fx->damping) {
  case DAMPING_RATIO: return fx->ratio;
  case DAMPING_LIST: return j < fx->nratios ? fx->ratios[j] : 0;
  case DAMPING_BANDS: /* seed 001 section 2.6: 1 % below 100 Hz, 10 % to 1 kHz, 100 % above */
    return f < 100 ? 0.01 : f <= 1000 ? 0.10 : 1.0;
  case DAMPING_NONE: return 0;
  }
  return 0;
}

int flex_build(const ir_flex *fx, const fe_modes *fm, flex_data *out, char *err, size_t nerr) {
  memset(out, 0, sizeof *out);
  int nm = fx->coupling == COUPLING_RIGID ? 0 : fm->nmodes, nn = fm->nnodes;
  if (nm > MB_MAX_MODES) {
    snprintf(err, nerr, "%d modes selected; at most %d are supported", nm, MB_MAX_MODES);
    return -1;
  }
  size_t n3 = 3 * (size_t)nm, n9 = 9 * (size_t)nm;
  out->S1 = calloc(n3 + 1, sizeof(double));
  out->E = calloc(n9 + 1, sizeof(double));
  out->F = calloc(n9 * (size_t)nm + 1, sizeof(double));
  out->G = calloc(n3 * (size_t)nm + 1, sizeof(double));
  out->C0 = calloc(n3 + 1, sizeof(double));
  out->CPsi = calloc(n3 + 1, sizeof(double));
  out->Mff = calloc((size_t)nm * (size_t)nm + 1, sizeof(double));
  out->stiffness = calloc((size_t)nm + 1, sizeof(double));
  out->damping = calloc((size_t)nm + 1, sizeof(double));
  out->node_x = calloc(3 * (size_t)nn + 1, sizeof(double));
  out->node_X = calloc(n3 * (size_t)nn + 1, sizeof(double));
  out->node_Psi = calloc(n3 * (size_t)nn + 1, sizeof(double));
  if (!out->S1 || !out->E || !out->F || !out->G || !out->C0 || !out->CPsi || !out->Mff ||
      !out->stiffness || !out->damping || !out->node_x || !out->node_X || !out->node_Psi) {
    snprintf(err, nerr, "out of memory");
    return -1;
  }
  if (fx->damping == DAMPING_LIST && fx->nratios != nm) {
    snprintf(err, nerr, "'damping' lists %d ratios for %d selected modes (expected one per mode)",
             fx->nratios, nm);
    return -1;
  }
  mb_flex *f = &out->flex;
  f->nm = nm;
  f->coupling = fx->coupling == COUPLING_PARTIAL ? MB_COUPLING_PARTIAL
                : fx->coupling == COUPLING_CONSTANT ? MB_COUPLING_CONSTANT : MB_COUPLING_FULL;
  f->nnode = nn;
  /* node rows: X_k (translations) and Psi_k (rotations), 3 x nm by columns */
  for (int k = 0; k < nn; k++) {
    for (int i = 0; i < 3; i++) out->node_x[3 * k + i] = fm->x[3 * k + i];
    for (int j = 0; j < nm; j++)
      for (int i = 0; i < 3; i++) {
        size_t col = (size_t)j * 6 * (size_t)nn;
        out->node_X[3 * ((size_t)k * nm + j) + i] = fm->shapes[col + 6 * (size_t)k + i];
        out->node_Psi[3 * ((size_t)k * nm + j) + i] = fm->shapes[col + 6 * (size_t)k + 3 + i];
      }
  }
  /* the shapes' rounding residue (an in-plane mode's out-of-plane entries
     come out of the eigensolver at 1e-30 and below) becomes exact zeros, as
     the invariants' below: the same tables for both paths, and the generated
     code drops them (compiler/back/emit_rows.c, a node marker's modal sums) */
  clean_table(out->node_X, n3 * (size_t)nn);
  clean_table(out->node_Psi, n3 * (size_t)nn);
  /* invariants: sums over the nodes' lumped masses m_k and rotary inertias J_k */
  for (int k = 0; k < nn; k++) {
    double mk = fm->node_mass[k];
    const double *x = out->node_x + 3 * k, *Jk = fm->node_inertia + 9 * k;
    const double *X = out->node_X + 3 * (size_t)k * nm, *Psi = out->node_Psi + 3 * (size_t)k * nm;
    f->mass += mk;
    double xx = x[0] * x[0] + x[1] * x[1] + x[2] * x[2];
    for (int i = 0; i < 3; i++) {
      f->S0[i] += mk * x[i];
      for (int l = 0; l < 3; l++) f->J0[3 * i + l] += mk * ((i == l) * xx - x[i] * x[l]) + Jk[3 * i + l];
    }
    for (int j = 0; j < nm; j++) {
      const double *Xj = X + 3 * j, *Pj = Psi + 3 * j;
      double xXj[3], JP[3];
      mb_cross3(x, Xj, xXj);
      mb_mul3(Jk, Pj, JP);
      for (int i = 0; i < 3; i++) {
        out->S1[3 * j + i] += mk * Xj[i];
        out->C0[3 * j + i] += mk * xXj[i] + JP[i];
        out->CPsi[3 * j + i] += JP[i];
        for (int l = 0; l < 3; l++) out->E[9 * j + 3 * i + l] += mk * Xj[i] * x[l];
      }
      for (int a = 0; a < nm; a++) {
        const double *Xa = X + 3 * a, *Pa = Psi + 3 * a;
        double g[3], JPa[3];
        mb_cross3(Xa, Xj, g);
        mb_mul3(Jk, Pa, JPa);
        for (int i = 0; i < 3; i++) {
          out->G[3 * ((size_t)a * nm + j) + i] += mk * g[i];
          for (int l = 0; l < 3; l++) out->F[9 * ((size_t)a * nm + j) + 3 * i + l] += mk * Xa[i] * Xj[l];
        }
        out->Mff[(size_t)a * nm + j] += mk * mb_dot3(Xa, Xj) + mb_dot3(Pj, JPa);
      }
    }
  }
  /* exact zeros: sums over the nodes of products of shapes that are
     structurally orthogonal (bending in y against bending in z, axial against
     either, ...) leave a rounding residue of about 1e-13 of the table's
     largest entry, where the smallest true entries are above 1e-7 of it in
     the shipped models; entries below 1e-10 of the largest are set to zero,
     so that both paths use the same tables and the generated code can drop
     them (compiler/back/emit.c, the flexible body's contractions) */
  clean_table(out->S1, 3 * (size_t)nm);
  clean_table(out->E, 9 * (size_t)nm);
  clean_table(out->F, 9 * (size_t)nm * (size_t)nm);
  clean_table(out->G, 3 * (size_t)nm * (size_t)nm);
  clean_table(out->C0, 3 * (size_t)nm);
  clean_table(out->CPsi, 3 * (size_t)nm);
  /* M_ff of mass-normalized modes is I up to rounding: its off-diagonal
     residue is not a coupling (and not an entry of K's pattern) */
  clean_table(out->Mff, (size_t)nm * (size_t)nm);
  for (int j = 0; j < nm; j++) {
    double om = 2 * MB_PI * fm->freq_hz[j];
    /* mass-normalized modes: X^T K X = diag(omega^2); the damping ratio
       refers to the same modal mass */
    out->stiffness[j] = om * om;
    out->damping[j] = 2 * damping_ratio(fx, j, fm->freq_hz[j]) * om * sqrt(out->Mff[(size_t)j * nm + j]);
  }
  f->S1 = out->S1; f->E = out->E; f->F = out->F; f->G = out->G; f->C0 = out->C0;
  f->CPsi = out->CPsi; f->Mff = out->Mff; f->stiffness = out->stiffness; f->damping = out->damping;
  f->node_x = out->node_x; f->node_X = out->node_X; f->node_Psi = out->node_Psi;
  return 0;
}

void flex_data_free(flex_data *d) {
  free(d->S1); free(d->E); free(d->F); free(d->G); free(d->C0); free(d->CPsi); free(d->Mff);
  free(d->stiffness); free(d->damping); free(d->node_x); free(d->node_X); free(d->node_Psi);
  free(d->stiff_P); free(d->stiff_R);
  memset(d, 0, sizeof *d);
}

/* Which entries of the (6+nm)^2 mass block can be nonzero, and which of those
 * never change: 0 none, 1 constant, 2 varying. */
int flex_mass_entry(const mb_flex *f, const mb_flex_stiff *st, int i, int l) {
  int nm = f->nm, n = 6 + nm;
  if (i < 0 || l < 0 || i >= n || l >= n) return 0;
  int bi = i < 3 ? 0 : i < 6 ? 1 : 2, bl = l < 3 ? 0 : l < 6 ? 1 : 2;
  int cst = f->coupling == MB_COUPLING_CONSTANT;
  if (bi > bl) { int t = i; i = l; l = t; t = bi; bi = bl; bl = t; }
  double S1n = 0;
  for (int k = 0; k < 3 * nm; k++) S1n += fabs(f->S1[k]);
  for (size_t k = 0; st && k < 3 * (size_t)nm * (size_t)nm; k++) S1n += fabs(st->P[k]);
  if (bi == 0 && bl == 0) return i == l ? 1 : 0;
  if (bi == 0 && bl == 1) return fabs(f->S0[0]) + fabs(f->S0[1]) + fabs(f->S0[2]) + S1n > 0 ? 2 : 0;
  if (bi == 0 && bl == 2) {
    int j = l - 6;
    double Pj = 0; /* geometric stiffening: d S / d w_j gains sum_a w_a P_aj */
    for (int a = 0; st && a < nm; a++)
      for (int i = 0; i < 3; i++) Pj += fabs(st->P[3 * ((size_t)a * nm + j) + i]);
    return fabs(f->S1[3 * j]) + fabs(f->S1[3 * j + 1]) + fabs(f->S1[3 * j + 2]) + Pj > 0 ? 2 : 0;
  }
  if (bi == 1 && bl == 1) return cst ? (f->J0[3 * (i - 3) + (l - 3)] != 0 ? 1 : 0) : 2;
  if (bi == 1 && bl == 2) return cst ? (f->C0[3 * (l - 6) + (i - 3)] != 0 ? 1 : 0) : 2;
  return f->Mff[(size_t)(i - 6) * nm + (l - 6)] != 0 ? 1 : 0;
}

int flex_compute_modes(const char *path, const ir_body *B, fe_modes *fm) {
  char err[512];
  ir_loc where = {0, 0};
  if (!fe_compute_modes_at(B->flex, fm, err, sizeof err, &where)) return 0;
  if (B->flex->fe_path) { /* imported: places in the FE file are the importer's; nodes by id */
    diag_error(path, B->loc, "flexible body '%s' (FE file %s): %s", B->name, B->flex->fe_path, err);
    return 2;
  }
  if (where.line > 0) /* at a node, beam or point mass: of the YAML FE file if it has one */
    diag_error(B->flex->fe_source ? B->flex->fe_source : path, where, "flexible body '%s': %s", B->name, err);
  else
    diag_error(path, B->loc, "flexible body '%s': %s", B->name, err);
  return 2;
}

int flex_reduce(const ir_model *ir, flex_product *out) {
  memset(out, 0, sizeof *out);
  out->nbodies = ir->nbodies;
  out->modes = calloc((size_t)ir->nbodies + 1, sizeof *out->modes);
  out->data = calloc((size_t)ir->nbodies + 1, sizeof *out->data);
  if (!out->modes || !out->data) {
    diag_error(ir->path, (ir_loc){0, 0}, "out of memory while reducing the flexible bodies");
    flex_product_free(out);
    return 2;
  }
  for (int b = 1; b < ir->nbodies; b++) {
    const ir_body *B = &ir->bodies[b];
    if (B->kind != BODY_FLEXIBLE) continue;
    char err[512];
    if (flex_compute_modes(ir->path, B, &out->modes[b])) {
      flex_product_free(out);
      return 2;
    }
    if (flex_build(B->flex, &out->modes[b], &out->data[b], err, sizeof err)) {
      diag_error(ir->path, B->loc, "flexible body '%s': %s", B->name, err);
      flex_product_free(out);
      return 2;
    }
    if (B->flex->geometric_stiffening &&
        flex_stiffening_build(B->flex, &out->modes[b], &out->data[b], err, sizeof err)) {
      /* at the option's key (line 0 when a scene gave it: at the body) */
      ir_loc at = B->flex->stiffening_loc.line > 0 ? B->flex->stiffening_loc : B->loc;
      diag_error(ir->path, at, "flexible body '%s': %s", B->name, err);
      flex_product_free(out);
      return 2;
    }
  }
  return 0;
}

void flex_product_free(flex_product *fp) {
  for (int b = 0; b < fp->nbodies; b++) {
    if (fp->modes) fe_modes_free(&fp->modes[b]);
    if (fp->data) flex_data_free(&fp->data[b]);
  }
  free(fp->modes);
  free(fp->data);
  memset(fp, 0, sizeof *fp);
}
