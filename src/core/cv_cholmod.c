/* src/core/cv_cholmod.c — sparse symmetric LDL^T with CHOLMOD: analysis once, numeric
 * refactorisation per Newton step, inertia from the pivots. The only file with cholmod.h.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include <cholmod.h>

#include "cv_internal.h"

struct cv_ldlt {
  cholmod_common c;
  cholmod_sparse *A;
  cholmod_factor *L;
  cholmod_dense *X, *Y, *E; /* solve workspace reused across iterations (cholmod_solve2) */
  long n;
};

cv_ldlt *cv_ldlt_new(int nfree, const long *colptr) {
  cv_ldlt *L = cv_calloc(1, sizeof *L);
  if (!L) return NULL;
  cholmod_l_start(&L->c);
  /* The Hessian is block-banded in node-major order, so the natural ordering has no
   * fill beyond the band; AMD would scramble it (DESIGN.md performance model). */
  L->c.nmethods = 1;
  L->c.method[0].ordering = CHOLMOD_NATURAL;
  L->c.postorder = 0;
  L->c.supernodal = CHOLMOD_SIMPLICIAL;
  L->c.final_ll = 0; /* keep LDL^T: the pivots give the inertia */
  L->c.quick_return_if_not_posdef = 0;
  L->c.print = 0;
  L->c.error_handler = NULL;
  L->n = nfree;
  long nnz = colptr[nfree];
  L->A = cholmod_l_allocate_sparse((size_t)nfree, (size_t)nfree, (size_t)(nnz ? nnz : 1), 1,
                                   1, 1, CHOLMOD_REAL, &L->c);
  if (!L->A) {
    cv_ldlt_free(L);
    return NULL;
  }
  SuiteSparse_long *Ap = L->A->p, *Ai = L->A->i;
  for (long c = 0; c <= nfree; c++) Ap[c] = colptr[c];
  for (long c = 0; c < nfree; c++) {
    long len = colptr[c + 1] - colptr[c], r0 = c + 1 - len;
    for (long k = 0; k < len; k++) Ai[colptr[c] + k] = r0 + k;
  }
  memset(L->A->x, 0, (size_t)(nnz ? nnz : 1) * sizeof(double));
  return L;
}

void cv_ldlt_free(cv_ldlt *L) {
  if (!L) return;
  cholmod_l_free_sparse(&L->A, &L->c);
  cholmod_l_free_factor(&L->L, &L->c);
  cholmod_l_free_dense(&L->X, &L->c);
  cholmod_l_free_dense(&L->Y, &L->c);
  cholmod_l_free_dense(&L->E, &L->c);
  cholmod_l_finish(&L->c);
  cv_free(L);
}

double *cv_ldlt_values(cv_ldlt *L) { return L->A->x; }

cv_status cv_ldlt_factor(cv_ldlt *L, int *neg, double *dmin, double *dmax, char *msg,
                         size_t len) {
  if (!L->L) {
    L->L = cholmod_l_analyze(L->A, &L->c);
    if (!L->L) {
      cv_set_msg(msg, len, "CHOLMOD analysis failed (status %d)", L->c.status);
      return L->c.status == CHOLMOD_OUT_OF_MEMORY ? CVAR_ENOMEM : CVAR_EDEPENDENCY;
    }
  }
  int ok = cholmod_l_factorize(L->A, L->L, &L->c);
  if (!ok || L->c.status < CHOLMOD_OK) {
    cv_set_msg(msg, len, "CHOLMOD factorisation failed (status %d)", L->c.status);
    return L->c.status == CHOLMOD_OUT_OF_MEMORY ? CVAR_ENOMEM : CVAR_EDEPENDENCY;
  }
  /* Simplicial LDL^T: D(j) is the first entry of column j of L. The pivot is compared
   * with the diagonal entry A(j,j) (the last entry of column j of the upper triangle):
   * |D(j)| / |A(j,j)| is dimensionless and independent of the mesh width, so a small value
   * marks a (nearly) degenerate direction, not merely a small element (theory N-5). */
  const SuiteSparse_long *Lp = L->L->p, *Ap = L->A->p;
  const double *Lx = L->L->x, *Ax = L->A->x;
  int nneg = 0;
  double lo = INFINITY, hi = 0.0;
  for (long j = 0; j < L->n; j++) {
    double dj = Lx[Lp[j]], ajj = fabs(Ax[Ap[j + 1] - 1]);
    if (dj < 0) nneg++;
    double a = fabs(dj), rel = ajj > 0 ? a / ajj : (a > 0 ? 1.0 : 0.0);
    if (!(rel >= lo)) lo = rel; /* a NaN pivot makes lo NaN */
    if (a > hi) hi = a;
  }
  *neg = nneg;
  *dmin = L->n ? lo : 1.0;
  *dmax = hi;
  /* CHOLMOD stops LDL^T at an exactly zero or NaN pivot and reports it as "not positive
   * definite" with L->minor < n; a TRUE return alone does not mean success (STYLE.md 4). */
  if (L->c.status == CHOLMOD_NOT_POSDEF || L->L->minor < (size_t)L->n) {
    cv_set_msg(msg, len, "zero pivot in the LDL^T factorisation at unknown %ld",
               (long)L->L->minor);
    return CVAR_ESINGULAR;
  }
  return CVAR_OK;
}

static cv_status solve_sys(cv_ldlt *L, int sys, double *x) {
  cholmod_dense B;
  memset(&B, 0, sizeof B);
  B.nrow = B.d = B.nzmax = (size_t)L->n;
  B.ncol = 1;
  B.x = x;
  B.xtype = CHOLMOD_REAL;
  B.dtype = CHOLMOD_DOUBLE;
  if (!cholmod_l_solve2(sys, L->L, &B, NULL, &L->X, NULL, &L->Y, &L->E, &L->c))
    return L->c.status == CHOLMOD_OUT_OF_MEMORY ? CVAR_ENOMEM : CVAR_EDEPENDENCY;
  memcpy(x, L->X->x, (size_t)L->n * sizeof *x);
  return CVAR_OK;
}

cv_status cv_ldlt_solve(cv_ldlt *L, double *x) { return solve_sys(L, CHOLMOD_A, x); }

/* The natural ordering leaves no permutation, so L and L^T solves act on x directly. */
cv_status cv_ldlt_solve_L(cv_ldlt *L, int transpose, double *x) {
  return solve_sys(L, transpose ? CHOLMOD_Lt : CHOLMOD_L, x);
}

void cv_ldlt_diag(const cv_ldlt *L, double *D) {
  const SuiteSparse_long *Lp = L->L->p;
  const double *Lx = L->L->x;
  for (long j = 0; j < L->n; j++) D[j] = Lx[Lp[j]];
}
