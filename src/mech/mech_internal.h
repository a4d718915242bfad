/* src/mech/mech_internal.h — shared by the files of src/mech: the state of one modes
 * computation and the dense linear algebra (mech_dense.c, the only caller of LAPACK).
 * SPDX-License-Identifier: MIT */
#ifndef CV_MECH_INTERNAL_H
#define CV_MECH_INTERNAL_H

#include "core/cv_memory.h"
#include "mech/mech.h"

/* One modes computation. The partials of L and of the constraints at (x, y, y' = 0) are one
 * tape's outputs, val = [L_y (n) | L_yy | L_y'y' | L_y'y (n*n each, row-major) | per
 * constraint c: G_c, G_c,y (n), G_c,yy (n*n)] (P-9, P-10, P-13). */
typedef struct {
  const mech_problem *mp;
  int n, nc, nn, N; /* N = n + nc: unknowns and multipliers of the stationarity system */
  int per, nout;    /* outputs per constraint, all outputs */
  ex_id *outs;      /* [nout] */
  ex_tape *tape;
  double *tape_work;
  double *val;  /* [nout] at the current point */
  double *zero; /* [n] y' = 0 */
  double *J;    /* [N*N] symmetric Jacobian of the stationarity system, then its r [N] */
  double *r;
  double *step; /* [N] */
  int lw;       /* LAPACK workspace: work holds N*N + N + lw doubles */
  double *work;
} mech_ctx;

/* mech_modes.c: val = the partials at y (y' = 0). Returns 0, or -1 out of memory. */
int mech_eval_partials(mech_ctx *c, const double *y);

/* mech_equilibrium.c: Newton on the stationarity of L + lambda.G at y' = 0 from mp->start
 * (P-9, P-13); md->equilibrium, multipliers, residual and iterations are filled, c->val and
 * c->J hold the partials and the Jacobian at the equilibrium. cv_status of mech_modes_new. */
cv_status mech_equilibrium(mech_ctx *c, mech_modes *md, int *at, char *err, size_t errlen);

/* ---- mech_dense.c ---- */
double mech_maxabs(int m, const double *v);
int mech_all_finite(int m, const double *v);
/* The larger of dsyev's (order N) and dsygv's (order n) optimal workspace, at least 3N. */
int mech_workspace(int N, int n);
/* The Newton step -J^+ g by the eigen-decomposition of the symmetric J (N x N; minimum norm
 * where J is singular: neutral directions do not move). work holds N*N + N + lw doubles.
 * Returns 0, or -1 if LAPACK dsyev fails. */
int mech_pinv_step(int N, const double *J, const double *g, double *step, double *work, int lw);
/* Orthonormal basis T (n x (n - nc), column-major) of {v : A^T v = 0}, A (n x nc,
 * column-major). Returns 0, 1 if the columns of A are dependent, -1 on a LAPACK failure,
 * -2 out of memory. */
int mech_tangent_basis(int n, int nc, const double *A, double *T);
/* P = T^T X T for X (n x n, row-major) and T (n x m, column-major): P is m x m, row-major. */
void mech_project(int n, int m, const double *T, const double *X, double *P);
/* K w = omega2 M w (m x m, symmetric; overwritten: K by the eigenvectors w with
 * w^T M w = 1, column k at K + k*m), omega2 increasing. Returns LAPACK dsygv's info. */
int mech_sygv(int m, double *K, double *M, double *omega2, double *work, int lw);
/* The 2n eigenvalues lambda = re + i im of lambda^2 M v + lambda G v + K v = 0 with
 * G = C - C^T (P-12). Returns 0, -1 if LAPACK dggev fails, -2 out of memory. */
int mech_gyro_eigenvalues(int n, const double *M, const double *K, const double *C, double *re,
                          double *im);

#endif /* CV_MECH_INTERNAL_H */
