/* fe_sparse.c: the modal reduction of large FE models: sparse K and M (the
 * triplets of fe_assemble_triplets, RBE2s folded, restricted to the free
 * DOFs), K - sigma M factored by CHOLMOD, and the lowest modes by ARPACK's
 * shift-invert Lanczos (dsaupd mode 3: OP = (K - sigma M)^-1 M, B = M). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <suitesparse/cholmod.h>

#include "fe.h"

/* ARPACK (Fortran; character arguments of fixed declared length) */
void dsaupd_(int *ido, const char *bmat, const int *n, const char *which, const int *nev,
             const double *tol, double *resid, const int *ncv, double *v, const int *ldv, int *iparam,
             int *ipntr, double *workd, double *workl, const int *lworkl, int *info);
void dseupd_(const int *rvec, const char *howmny, int *select, double *d, double *z, const int *ldz,
             const double *sigma, const char *bmat, const int *n, const char *which, const int *nev,
             const double *tol, double *resid, const int *ncv, double *v, const int *ldv, int *iparam,
             int *ipntr, double *workd, double *workl, const int *lworkl, int *info);

/* the free-DOF upper triangle of a triplet matrix, dependent DOFs folded */
static cholmod_sparse *free_part(const ir_flex *fx, const ir_fe_matrix *A, const int *link_of,
                                 const int *free_index, int nf, cholmod_common *cm) {
  /* every entry expands to at most 7 x 7 (a dependent DOF: up to 6 independent ones) */
  size_t cap = (size_t)A->nnz + 64, nnz = 0;
  cholmod_triplet *T = cholmod_allocate_triplet((size_t)nf, (size_t)nf, cap, 1, CHOLMOD_REAL, cm);
  if (!T) return NULL;
  for (int t = 0; t < A->nnz; t++) {
    int is[6], js[6], ni = 0, nj = 0;
    double ci[6], cj[6];
    for (int side = 0; side < 2; side++) {
      int dof = side ? A->col[t] : A->row[t], *ix = side ? js : is, *cnt = side ? &nj : &ni;
      double *cc = side ? cj : ci;
      if (link_of[dof] < 0) {
        ix[0] = dof;
        cc[0] = 1;
        *cnt = 1;
      } else {
        const ir_rigid_link *L = &fx->links[link_of[dof]];
        double coef[6];
        fe_link_row(fx, L, dof % 6, coef);
        for (int a = 0; a < 6; a++)
          if (coef[a] != 0) {
            ix[*cnt] = 6 * L->independent + a;
            cc[(*cnt)++] = coef[a];
          }
      }
    }
    for (int a = 0; a < ni; a++)
      for (int b = 0; b < nj; b++) {
        int r = free_index[is[a]], c = free_index[js[b]];
        if (r < 0 || c < 0 || r > c) continue;
        if (nnz == T->nzmax && !cholmod_reallocate_triplet(2 * T->nzmax, T, cm)) {
          cholmod_free_triplet(&T, cm);
          return NULL;
        }
        ((int *)T->i)[nnz] = r;
        ((int *)T->j)[nnz] = c;
        ((double *)T->x)[nnz++] = ci[a] * cj[b] * A->val[t];
        T->nnz = nnz;
      }
  }
  cholmod_sparse *S = cholmod_triplet_to_sparse(T, nnz, cm);
  cholmod_free_triplet(&T, cm);
  return S;
}

int fe_sparse_eigs(const ir_flex *fx, const ir_fe_matrix *K, const ir_fe_matrix *M, const int *free_index,
                   int nf, int nev, double sigma, double *lam, double *X, char *err, size_t nerr) {
  int ndof = 6 * fx->nnodes, rc = -1;
  int *link_of = malloc((size_t)ndof * sizeof *link_of);
  cholmod_common cm;
  cholmod_start(&cm);
  cm.print = 0;
  cholmod_sparse *Ks = NULL, *Ms = NULL, *As = NULL;
  cholmod_factor *F = NULL;
  cholmod_dense *x = NULL, *y = NULL, *sol = NULL;
  int ncv = 2 * nev + 1 < 20 ? 20 : 2 * nev + 1;
  if (ncv > nf) ncv = nf;
  int lworkl = ncv * (ncv + 8);
  double *resid = calloc((size_t)nf, sizeof(double)), *V = malloc((size_t)nf * ncv * sizeof(double));
  double *workd = malloc(3 * (size_t)nf * sizeof(double)), *workl = malloc((size_t)lworkl * sizeof(double));
  double *d = malloc((size_t)ncv * sizeof(double));
  int *select = calloc((size_t)ncv, sizeof(int));
  if (!link_of || !resid || !V || !workd || !workl || !d || !select) {
    snprintf(err, nerr, "out of memory (%d free DOFs)", nf);
    goto done;
  }
  if (nev < 1 || nev >= nf) {
    snprintf(err, nerr, "the sparse eigensolver needs 1 <= modes < free DOFs (%d modes of %d DOFs)", nev, nf);
    goto done;
  }
  for (int i = 0; i < ndof; i++) link_of[i] = -1;
  for (int l = 0; l < fx->nlinks; l++)
    for (int k = 0; k < 6; k++)
      if (fx->links[l].dofs >> k & 1) link_of[6 * fx->links[l].dependent + k] = l;
  Ks = free_part(fx, K, link_of, free_index, nf, &cm);
  Ms = free_part(fx, M, link_of, free_index, nf, &cm);
  double one[2] = {1, 0}, shift[2] = {-sigma, 0}, zero[2] = {0, 0};
  if (Ks && Ms) As = cholmod_add(Ks, Ms, one, shift, 1, 1, &cm);
  if (!As) { snprintf(err, nerr, "out of memory in the sparse assembly"); goto done; }
  F = cholmod_analyze(As, &cm);
  if (!F || !cholmod_factorize(As, F, &cm) || cm.status == CHOLMOD_NOT_POSDEF) {
    snprintf(err, nerr, "the %s is not positive definite (a mechanism, or a DOF without mass): the "
             "sparse factorization (CHOLMOD) stopped at column %d", sigma == 0 ? "stiffness matrix" :
             "shifted stiffness K - sigma M", F ? (int)F->minor : -1);
    goto done;
  }
  x = cholmod_allocate_dense((size_t)nf, 1, (size_t)nf, CHOLMOD_REAL, &cm);
  y = cholmod_allocate_dense((size_t)nf, 1, (size_t)nf, CHOLMOD_REAL, &cm);
  if (!x || !y) { snprintf(err, nerr, "out of memory"); goto done; }
  int ido = 0, info = 0, iparam[11] = {0}, ipntr[14] = {0};
  iparam[0] = 1;     /* exact shifts */
  iparam[2] = 10000; /* iterations */
  iparam[6] = 3;     /* shift-invert */
  double tol = 0;    /* machine precision */
  for (;;) {
    dsaupd_(&ido, "G", &nf, "LM", &nev, &tol, resid, &ncv, V, &nf, iparam, ipntr, workd, workl, &lworkl,
            &info);
    if (ido != -1 && ido != 1 && ido != 2) break;
    double *in = workd + ipntr[0] - 1, *out = workd + ipntr[1] - 1;
    if (ido == 2 || ido == -1) { /* M x */
      memcpy(x->x, in, (size_t)nf * sizeof(double));
      cholmod_sdmult(Ms, 0, one, zero, x, y, &cm);
      if (ido == 2) {
        memcpy(out, y->x, (size_t)nf * sizeof(double));
        continue;
      }
    } else {
      memcpy(y->x, workd + ipntr[2] - 1, (size_t)nf * sizeof(double));
    }
    sol = cholmod_solve(CHOLMOD_A, F, y, &cm); /* (K - sigma M)^-1 (M x) */
    if (!sol) { snprintf(err, nerr, "the sparse solve failed (CHOLMOD)"); goto done; }
    memcpy(out, sol->x, (size_t)nf * sizeof(double));
    cholmod_free_dense(&sol, &cm);
  }
  if (info < 0 || (info != 0 && info != 1)) {
    snprintf(err, nerr, "the sparse eigensolver failed (ARPACK dsaupd info %d)", info);
    goto done;
  }
  if (info == 1 || iparam[4] < nev) {
    snprintf(err, nerr, "the sparse eigensolver converged %d of %d modes (ARPACK)", iparam[4], nev);
    goto done;
  }
  int rvec = 1;
  dseupd_(&rvec, "A", select, d, X, &nf, &sigma, "G", &nf, "LM", &nev, &tol, resid, &ncv, V, &nf, iparam,
          ipntr, workd, workl, &lworkl, &info);
  if (info != 0) {
    snprintf(err, nerr, "the sparse eigensolver failed (ARPACK dseupd info %d)", info);
    goto done;
  }
  /* unit modal mass; the eigenvalues are ARPACK's, from the Ritz values of
     the inverse: a Rayleigh quotient x^T K x loses the lowest ones of a fine
     mesh to cancellation (measured: 0 Hz for the first of a 1e5-DOF beam) */
  for (int j = 0; j < nev; j++) {
    double *v = X + (size_t)j * nf, mm = 0;
    memcpy(x->x, v, (size_t)nf * sizeof(double));
    cholmod_sdmult(Ms, 0, one, zero, x, y, &cm);
    for (int i = 0; i < nf; i++) mm += v[i] * ((double *)y->x)[i];
    double s = 1 / sqrt(mm);
    for (int i = 0; i < nf; i++) v[i] *= s;
    lam[j] = d[j];
  }
  for (int i = 1; i < nev; i++) /* insertion sort of the pairs */
    for (int j = i; j > 0 && lam[j - 1] > lam[j]; j--) {
      double t = lam[j]; lam[j] = lam[j - 1]; lam[j - 1] = t;
      double *a = X + (size_t)j * nf, *b = X + (size_t)(j - 1) * nf;
      for (int r = 0; r < nf; r++) { t = a[r]; a[r] = b[r]; b[r] = t; }
    }
  rc = 0;
done:
  cholmod_free_dense(&x, &cm);
  cholmod_free_dense(&y, &cm);
  cholmod_free_factor(&F, &cm);
  cholmod_free_sparse(&Ks, &cm);
  cholmod_free_sparse(&Ms, &cm);
  cholmod_free_sparse(&As, &cm);
  cholmod_finish(&cm);
  free(link_of); free(resid); free(V); free(workd); free(workl); free(d); free(select);
  return rc;
}
