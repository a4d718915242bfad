/* src/mech/mech_dense.c — the dense linear algebra of the equilibrium and its modes, with
 * LAPACK: a pseudo-inverse Newton step, the constraints' tangent space, the generalised
 * symmetric eigenproblem and the gyroscopic pencil (docs/theory.md (P-9), (P-10), (P-12),
 * (P-13)). With cv_contact.c (a least-squares fit), the only files that call LAPACK.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "mech/mech_internal.h"

/* LAPACK (Fortran calling convention; the hidden lengths of the one-character arguments
 * are not passed, as is usual for C callers of these routines). */
void dsygv_(const int *itype, const char *jobz, const char *uplo, const int *n, double *a,
            const int *lda, double *b, const int *ldb, double *w, double *work, const int *lwork,
            int *info);
void dsyev_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda, double *w,
            double *work, const int *lwork, int *info);
void dgeqrf_(const int *m, const int *n, double *a, const int *lda, double *tau, double *work,
             const int *lwork, int *info);
void dorgqr_(const int *m, const int *n, const int *k, double *a, const int *lda, const double *tau,
             double *work, const int *lwork, int *info);
void dggev_(const char *jobvl, const char *jobvr, const int *n, double *a, const int *lda,
            double *b, const int *ldb, double *alphar, double *alphai, double *beta, double *vl,
            const int *ldvl, double *vr, const int *ldvr, double *work, const int *lwork,
            int *info);

/* Eigenvalues of the stiffness below this fraction of the largest are dropped from the
 * Newton step (a neutral direction: the step is the minimum-norm one). */
static const double PINV_RTOL = 1e-12;

double mech_maxabs(int m, const double *v) {
  double r = 0;
  for (int k = 0; k < m; k++) r = fabs(v[k]) > r || isnan(v[k]) ? fabs(v[k]) : r;
  return r;
}

int mech_all_finite(int m, const double *v) {
  for (int k = 0; k < m; k++)
    if (!isfinite(v[k])) return 0;
  return 1;
}

int mech_workspace(int N, int n) {
  int lw = -1, lw2 = -1, info = 0, one = 1;
  double q1 = 0, q2 = 0, dummy = 0, a = 0;
  dsyev_("V", "U", &N, &a, &N, &dummy, &q1, &lw, &info);
  dsygv_(&one, "V", "U", &n, &a, &n, &a, &n, &dummy, &q2, &lw2, &info);
  return (int)fmax(fmax(q1, q2), 3.0 * N);
}

int mech_pinv_step(int n, const double *J, const double *g, double *step, double *work, int lw) {
  double *V = work, *lam = work + n * n, *w = lam + n;
  int info = 0;
  memcpy(V, J, (size_t)n * n * sizeof *V);
  dsyev_("V", "U", &n, V, &n, lam, w, &lw, &info);
  if (info != 0) return -1;
  double big = mech_maxabs(n, lam);
  memset(step, 0, (size_t)n * sizeof *step);
  for (int k = 0; k < n; k++) {
    if (!(fabs(lam[k]) > PINV_RTOL * big)) continue;
    const double *v = V + (size_t)k * n; /* column k (column-major) */
    double c = 0;
    for (int i = 0; i < n; i++) c += v[i] * g[i];
    c /= lam[k];
    for (int i = 0; i < n; i++) step[i] -= c * v[i];
  }
  return 0;
}

/* A QR of A (dgeqrf, dorgqr): T is the last n - nc columns of Q; the columns of A are
 * dependent when |R_kk| <= 1e-12 max|R|. */
int mech_tangent_basis(int n, int nc, const double *A, double *T) {
  int info = 0, lw = -1;
  double q = 0;
  double *Q = cv_malloc(((size_t)n * n + n) * sizeof *Q);
  if (!Q) return -2;
  double *tau = Q + (size_t)n * n;
  memset(Q, 0, (size_t)n * n * sizeof *Q);
  memcpy(Q, A, (size_t)n * nc * sizeof *Q);
  dgeqrf_(&n, &nc, Q, &n, tau, &q, &lw, &info);
  lw = (int)fmax(q, (double)n);
  double *work = cv_malloc((size_t)lw * sizeof *work);
  if (!work) {
    cv_free(Q);
    return -2;
  }
  dgeqrf_(&n, &nc, Q, &n, tau, work, &lw, &info);
  int rc = info != 0 ? -1 : 0;
  double rmax = 0;
  for (int k = 0; k < nc && rc == 0; k++) rmax = fmax(rmax, fabs(Q[k + (size_t)k * n]));
  for (int k = 0; k < nc && rc == 0; k++)
    if (!(fabs(Q[k + (size_t)k * n]) > 1e-12 * rmax)) rc = 1;
  if (rc == 0) {
    int lw2 = -1;
    dorgqr_(&n, &n, &nc, Q, &n, tau, &q, &lw2, &info);
    if ((int)q > lw) {
      cv_free(work);
      lw = (int)q;
      if (!(work = cv_malloc((size_t)lw * sizeof *work))) {
        cv_free(Q);
        return -2;
      }
    }
    dorgqr_(&n, &n, &nc, Q, &n, tau, work, &lw, &info);
    if (info != 0)
      rc = -1;
    else
      memcpy(T, Q + (size_t)n * nc, (size_t)n * (n - nc) * sizeof *T);
  }
  cv_free(work);
  cv_free(Q);
  return rc;
}

void mech_project(int n, int m, const double *T, const double *X, double *P) {
  for (int a = 0; a < m; a++)
    for (int b = 0; b < m; b++) {
      double sum = 0;
      for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
          sum += T[i + (size_t)a * n] * X[i * n + j] * T[j + (size_t)b * n];
      P[a * m + b] = sum;
    }
}

int mech_sygv(int m, double *K, double *M, double *omega2, double *work, int lw) {
  int one = 1, info = 0;
  dsygv_(&one, "V", "U", &m, K, &m, M, &m, omega2, work, &lw, &info);
  return info;
}

/* The pencil [[0, I], [-K, -G]] z = lambda [[I, 0], [0, M]] z of order 2n (dggev, no
 * inverse of M). B is positive definite: beta > 0, no infinite lambda. */
int mech_gyro_eigenvalues(int n, const double *M, const double *K, const double *C, double *re,
                          double *im) {
  int N = 2 * n, info = 0, lw = -1;
  double q = 0;
  double *A = cv_calloc((size_t)N * N * 2 + 3 * (size_t)N, sizeof *A);
  if (!A) return -2;
  double *B = A + (size_t)N * N, *ar = B + (size_t)N * N, *ai = ar + N, *be = ai + N;
  for (int i = 0; i < n; i++) {
    A[i + (size_t)(n + i) * N] = 1.0;
    B[i + (size_t)i * N] = 1.0;
    for (int j = 0; j < n; j++) {
      A[(n + i) + (size_t)j * N] = -K[i * n + j];
      A[(n + i) + (size_t)(n + j) * N] = -(C[i * n + j] - C[j * n + i]);
      B[(n + i) + (size_t)(n + j) * N] = M[i * n + j];
    }
  }
  dggev_("N", "N", &N, A, &N, B, &N, ar, ai, be, NULL, &N, NULL, &N, &q, &lw, &info);
  lw = (int)fmax(q, 8.0 * N);
  double *work = cv_malloc((size_t)lw * sizeof *work);
  if (!work) {
    cv_free(A);
    return -2;
  }
  dggev_("N", "N", &N, A, &N, B, &N, ar, ai, be, NULL, &N, NULL, &N, work, &lw, &info);
  cv_free(work);
  if (info == 0)
    for (int k = 0; k < N; k++) {
      re[k] = ar[k] / be[k];
      im[k] = ai[k] / be[k];
    }
  cv_free(A);
  return info != 0 ? -1 : 0;
}

/* The directions v (|v| = 1) with R v = 0 for the m x n matrix R (row-major): the
 * eigenvectors of R^T R whose eigenvalues are below rtol times the largest (dsyev). Writes
 * them to V (n per direction) and returns their count, or -1 on failure. */
int mech_null_directions(int n, int m, const double *R, double rtol, double *V) {
  double *A = cv_malloc((size_t)n * n * sizeof *A), *lam = cv_malloc((size_t)n * sizeof *lam);
  int lw = 8 * n + 8, info = 0, count = 0;
  double *w = cv_malloc((size_t)lw * sizeof *w);
  if (!A || !lam || !w) {
    cv_free(A), cv_free(lam), cv_free(w);
    return -1;
  }
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      double sum = 0.0;
      for (int k = 0; k < m; k++) sum += R[(size_t)k * n + i] * R[(size_t)k * n + j];
      A[(size_t)j * n + i] = sum;
    }
  dsyev_("V", "U", &n, A, &n, lam, w, &lw, &info);
  double big = info == 0 ? mech_maxabs(n, lam) : NAN;
  for (int k = 0; k < n && info == 0; k++)
    if (fabs(lam[k]) <= rtol * big)
      memcpy(V + (size_t)count++ * n, A + (size_t)k * n, (size_t)n * sizeof *V);
  cv_free(A), cv_free(lam), cv_free(w);
  return info == 0 && big > 0 ? count : -1;
}
