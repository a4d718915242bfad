/* src/scene/scene_modes.c — equilibrium of a Lagrangian L(y, y') and its small
 * oscillations: Newton on dL/dy = 0 at y' = 0, then K v = omega2 M v with LAPACK, and with
 * gyroscopic terms the motions of M y'' + G y' + K y = 0 (docs/theory.md (P-9), (P-10),
 * (P-12)). SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_mechanics.h"

/* LAPACK (Fortran calling convention; the hidden lengths of the one-character arguments
 * are not passed, as is usual for C callers of these routines). */
void dsygv_(const int *itype, const char *jobz, const char *uplo, const int *n, double *a,
            const int *lda, double *b, const int *ldb, double *w, double *work,
            const int *lwork, int *info);
void dsyev_(const char *jobz, const char *uplo, const int *n, double *a, const int *lda,
            double *w, double *work, const int *lwork, int *info);
void dgeqrf_(const int *m, const int *n, double *a, const int *lda, double *tau,
             double *work, const int *lwork, int *info);
void dorgqr_(const int *m, const int *n, const int *k, double *a, const int *lda,
             const double *tau, double *work, const int *lwork, int *info);
void dggev_(const char *jobvl, const char *jobvr, const int *n, double *a, const int *lda,
            double *b, const int *ldb, double *alphar, double *alphai, double *beta,
            double *vl, const int *ldvl, double *vr, const int *ldvr, double *work,
            const int *lwork, int *info);

enum { MAX_NEWTON = 100 };

/* Newton steps stop when max|step| <= STEP_RTOL max(1, max|y|). */
static const double STEP_RTOL = 1e-14;
/* The equilibrium is accepted when max|dL/dy| <= RES_RTOL max|d2L/dy2| max(1, max|y|):
 * the residual is round-off of the force against the stiffness scale. */
static const double RES_RTOL = 1e-10;
/* Eigenvalues of the stiffness below this fraction of the largest are dropped from the
 * Newton step (a neutral direction: the step is the minimum-norm one). */
static const double PINV_RTOL = 1e-12;

static double maxabs(int m, const double *v)
{
  double r = 0;
  for (int k = 0; k < m; k++)
    r = fabs(v[k]) > r || isnan(v[k]) ? fabs(v[k]) : r;
  return r;
}

static int all_finite(int m, const double *v)
{
  for (int k = 0; k < m; k++)
    if (!isfinite(v[k]))
      return 0;
  return 1;
}

/* Partials of L at (a, y, 0), one tape call: out = [L_y (n) | L_yy (n*n) | L_y'y' (n*n) |
 * L_y'y (n*n)], matrices row-major. */
static int eval_partials(const scene *s, int nout, const ex_id *outs, const double *y,
                         double *out)
{
  int n = s->n;
  double x = s->a;
  double *dy = cv_calloc((size_t)n, sizeof *dy);
  if (!dy)
    return -1;
  int rc = sc_eval_exprs(s, nout, outs, 1, &x, y, dy, out);
  cv_free(dy);
  return rc;
}

/* The Newton step -J^+ g by the eigen-decomposition of the symmetric J (minimum norm where
 * J is singular: neutral directions do not move). work holds n*n + n + lw doubles. */
static int newton_step(int n, const double *J, const double *g, double *step, double *work,
                       int lw)
{
  double *V = work, *lam = work + n * n, *w = lam + n;
  int info = 0;
  memcpy(V, J, (size_t)n * n * sizeof *V);
  dsyev_("V", "U", &n, V, &n, lam, w, &lw, &info);
  if (info != 0)
    return -1;
  double big = maxabs(n, lam);
  memset(step, 0, (size_t)n * sizeof *step);
  for (int k = 0; k < n; k++) {
    if (!(fabs(lam[k]) > PINV_RTOL * big))
      continue;
    const double *v = V + (size_t)k * n; /* column k (column-major) */
    double c = 0;
    for (int i = 0; i < n; i++)
      c += v[i] * g[i];
    c /= lam[k];
    for (int i = 0; i < n; i++)
      step[i] -= c * v[i];
  }
  return 0;
}

/* The gyroscopic problem (P-12) of order n (on the constraints' tangent space, P-13):
 * lambda^2 M v + lambda G v + K v = 0 as the pencil
 * [[0, I], [-K, -G]] z = lambda [[I, 0], [0, M]] z of order 2n (LAPACK dggev, no inverse
 * of M). Of each pair lambda, -conj(lambda) of a conservative system one is kept: the
 * eigenvalues with Im > 0 and Re >= 0 (up to round-off), the real ones with Re > 0, and
 * half of the zero ones. Returns 0, or -1 if LAPACK fails (or -2 out of memory). */
static int gyro_modes(sc_modes *md, int n, const double *M, const double *K, const double *C)
{
  int N = 2 * n, info = 0, lw = -1;
  double q = 0;
  double *A = cv_calloc((size_t)N * N * 2 + 3 * (size_t)N, sizeof *A);
  if (!A)
    return -2;
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
  if (info != 0) {
    cv_free(A);
    return -1;
  }
  double big = 0;
  for (int k = 0; k < N; k++) { /* B is positive definite: beta > 0, no infinite lambda */
    ar[k] /= be[k], ai[k] /= be[k];
    big = fmax(big, hypot(ar[k], ai[k]));
  }
  /* A free direction is a double zero with a Jordan block, computed as two eigenvalues of
   * size sqrt(eps) |lambda|: "zero" is 1e-6 of the largest. Re lambda of a stable pair is
   * round-off of a non-normal eigenproblem: "zero" is 1e-7 of the largest. */
  double tol0 = 1e-6 * big, tolre = 1e-7 * big;
  int nzero = 0, m = 0;
  for (int k = 0; k < N; k++) {
    double re = ar[k], im = ai[k];
    if (hypot(re, im) <= tol0) {
      nzero++;
      continue;
    }
    if (im < 0 || re < -tolre || (fabs(im) <= tolre && re <= tolre))
      continue; /* the partner of a kept one */
    md->gyro_kind[m] = re > tolre ? SC_MODE_UNSTABLE : SC_MODE_STABLE;
    md->gyro_growth[m] = re > tolre ? re : 0.0;
    md->gyro_omega[m] = im > tolre ? im : 0.0;
    m++;
  }
  for (int k = 0; k < nzero / 2 && m < n; k++, m++) {
    md->gyro_kind[m] = SC_MODE_NEUTRAL;
    md->gyro_omega[m] = md->gyro_growth[m] = 0.0;
  }
  /* order: neutral and stable by omega, then unstable by growth (insertion sort, m <= n) */
  for (int a = 1; a < m; a++)
    for (int b = a; b > 0; b--) {
      int ub = md->gyro_kind[b] == SC_MODE_UNSTABLE;
      int ua = md->gyro_kind[b - 1] == SC_MODE_UNSTABLE;
      double kb = ub ? md->gyro_growth[b] : md->gyro_omega[b];
      double ka = ua ? md->gyro_growth[b - 1] : md->gyro_omega[b - 1];
      if (ua < ub || (ua == ub && ka <= kb))
        break;
      double t = md->gyro_omega[b];
      md->gyro_omega[b] = md->gyro_omega[b - 1], md->gyro_omega[b - 1] = t;
      t = md->gyro_growth[b];
      md->gyro_growth[b] = md->gyro_growth[b - 1], md->gyro_growth[b - 1] = t;
      sc_mode_kind kk = md->gyro_kind[b];
      md->gyro_kind[b] = md->gyro_kind[b - 1], md->gyro_kind[b - 1] = kk;
    }
  md->ngyro = m;
  cv_free(A);
  return 0;
}

static int fail(const scene *s, char *err, size_t errlen, int code, const char *msg)
{
  sc_err(err, errlen, s->file, 0, "%s", msg);
  return code;
}

/* Orthonormal basis T (n x (n - nc), column-major) of the tangent space {v : A^T v = 0} of
 * the constraints, A (n x nc, column-major) their gradients, by a QR of A (LAPACK dgeqrf,
 * dorgqr): T is the last n - nc columns of Q. Returns 0, 1 if the gradients are dependent
 * (|R_kk| <= 1e-12 max|R|), -1 on a LAPACK failure, -2 out of memory. */
static int tangent_basis(int n, int nc, const double *A, double *T)
{
  int info = 0, lw = -1;
  double q = 0;
  double *Q = cv_malloc(((size_t)n * n + n) * sizeof *Q);
  if (!Q)
    return -2;
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
  for (int k = 0; k < nc && rc == 0; k++)
    rmax = fmax(rmax, fabs(Q[k + (size_t)k * n]));
  for (int k = 0; k < nc && rc == 0; k++)
    if (!(fabs(Q[k + (size_t)k * n]) > 1e-12 * rmax))
      rc = 1;
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

/* P = T^T X T for X (n x n, row-major, any) and T (n x m, column-major): P is m x m,
 * row-major. */
static void project(int n, int m, const double *T, const double *X, double *P)
{
  for (int a = 0; a < m; a++)
    for (int b = 0; b < m; b++) {
      double sum = 0;
      for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
          sum += T[i + (size_t)a * n] * X[i * n + j] * T[j + (size_t)b * n];
      P[a * m + b] = sum;
    }
}

int scene_modes_new(scene *s, sc_modes *md, char *err, size_t errlen)
{
  int n = s->n, nn = n * n, nc = s->ncons, N = n + nc, rc = SC_MODES_NOMEM, info = 0;
  ex_dag *d = s->dag;
  ex_id *outs = NULL;
  double *val = NULL, *work = NULL, *A = NULL, *Jk = NULL, *T = NULL, *Ag = NULL;
  memset(md, 0, sizeof *md);
  md->n = n;
  if (err && errlen)
    err[0] = '\0';
  if (scene_F_depends_on_variable(s)) {
    sc_err(err, errlen, s->file, s->F_line, "the integrand depends explicitly on %s; modes "
           "needs a Lagrangian L(y, y') without it", s->variable);
    return SC_MODES_EXPLICIT;
  }
  if (s->nints > 0) {
    sc_err(err, errlen, s->file, s->ints[0].line,
           "modes does not handle integral constraints: they constrain the whole path, not "
           "the positions near an equilibrium");
    return SC_MODES_CONSTRAINED;
  }
  for (int c = 0; c < nc; c++)
    if (ex_depends_on(d, s->cons[c].expr, 0)) {
      sc_err(err, errlen, s->file, s->cons[c].line, "the constraint '%s' depends on %s (it "
             "moves): modes needs constraints G(y) that hold still", s->cons[c].name,
             s->variable);
      return SC_MODES_EXPLICIT;
    }
  if (nc >= n) {
    sc_err(err, errlen, s->file, s->cons[0].line, "%d constraints on %d unknowns leave "
           "nothing to oscillate", nc, n);
    return SC_MODES_CONSTRAINED;
  }
  /* Outputs: L_y (n), L_yy, L_y'y', L_y'y (n*n each), then per constraint G, G_y (n),
   * G_yy (n*n) (P-9, P-10, P-13). */
  int per = 1 + n + nn, nout = n + 3 * nn + nc * per, m = n - nc;
  outs = cv_malloc((size_t)nout * sizeof *outs);
  val = cv_malloc((size_t)nout * sizeof *val);
  md->equilibrium = cv_malloc((size_t)n * sizeof *md->equilibrium);
  md->multipliers = cv_malloc((size_t)(nc ? nc : 1) * sizeof *md->multipliers);
  md->omega2 = cv_malloc((size_t)n * sizeof *md->omega2);
  md->kind = cv_malloc((size_t)n * sizeof *md->kind);
  md->shape = cv_malloc((size_t)nn * sizeof *md->shape);
  md->mass = cv_malloc((size_t)nn * sizeof *md->mass);
  md->stiffness = cv_malloc((size_t)nn * sizeof *md->stiffness);
  md->gyro_omega = cv_malloc((size_t)n * sizeof *md->gyro_omega);
  md->gyro_growth = cv_malloc((size_t)n * sizeof *md->gyro_growth);
  md->gyro_kind = cv_malloc((size_t)n * sizeof *md->gyro_kind);
  A = cv_malloc((size_t)(2 * N * N + 2 * N) * sizeof *A);
  Jk = cv_malloc((size_t)(N * N + N) * sizeof *Jk);
  T = cv_malloc((size_t)(nn + 3 * nn) * sizeof *T);
  Ag = cv_malloc((size_t)nn * sizeof *Ag); /* constraint gradients, n x nc column-major */
  if (!outs || !val || !md->equilibrium || !md->multipliers || !md->omega2 || !md->kind ||
      !md->shape || !md->mass || !md->stiffness || !A || !md->gyro_omega ||
      !md->gyro_growth || !md->gyro_kind || !Jk || !T || !Ag)
    goto cleanup;
  md->nc = nc;

  /* The expressions (exact symbolic derivatives). */
  for (int i = 0; i < n; i++) {
    ex_id gi = ex_diff(d, s->F, 1 + i), pi = ex_diff(d, s->F, 1 + n + i);
    if (gi < 0 || pi < 0)
      goto cleanup;
    outs[i] = gi;
    for (int j = 0; j < n; j++) {
      if ((outs[n + i * n + j] = ex_diff(d, gi, 1 + j)) < 0 ||
          (outs[n + nn + i * n + j] = ex_diff(d, pi, 1 + n + j)) < 0 ||
          (outs[n + 2 * nn + i * n + j] = ex_diff(d, pi, 1 + j)) < 0)
        goto cleanup;
    }
  }
  for (int c = 0; c < nc; c++) {
    ex_id *o = outs + n + 3 * nn + c * per, G = s->cons[c].expr;
    o[0] = G;
    for (int i = 0; i < n; i++) {
      if ((o[1 + i] = ex_diff(d, G, 1 + i)) < 0)
        goto cleanup;
      for (int j = 0; j < n; j++)
        if ((o[1 + n + i * n + j] = ex_diff(d, o[1 + i], 1 + j)) < 0)
          goto cleanup;
    }
  }

  /* Workspace: the larger of dsyev's (order N) and dsygv's (order n) optimal sizes. */
  int lw = -1, lw2 = -1;
  double q1 = 0, q2 = 0, dummy = 0;
  int one = 1;
  dsyev_("V", "U", &N, A, &N, &dummy, &q1, &lw, &info);
  dsygv_(&one, "V", "U", &n, A, &n, A + nn, &n, &dummy, &q2, &lw2, &info);
  lw = (int)fmax(fmax(q1, q2), 3.0 * N);
  if (!(work = cv_malloc(((size_t)N * N + N + (size_t)lw) * sizeof *work)))
    goto cleanup;

  /* Equilibrium: Newton on the stationarity of L + lambda.G at y' = 0 (with G = 0) from
   * the guess at the start of the interval and lambda = 0 (P-9, P-13). */
  double *y = md->equilibrium, *lam = md->multipliers, *step = A;
  double *r = Jk + (size_t)N * N, *J = Jk;
  const double *g = val, *Lyy = val + n;
  if (scene_eval_guess(s, 1, &s->a, y) < 0)
    goto cleanup;
  for (int c = 0; c < nc; c++)
    lam[c] = 0;
  int converged = 0;
  double tol = 0;
  for (int it = 0; it <= MAX_NEWTON; it++) {
    if (eval_partials(s, nout, outs, y, val) < 0)
      goto cleanup;
    if (!all_finite(nout, val) || !all_finite(n, y) || !all_finite(nc, lam)) {
      rc = fail(s, err, errlen, SC_MODES_NONFINITE,
                it == 0 ? "the Lagrangian's derivatives are not finite at the guess (the "
                          "start values of the unknowns at y' = 0)"
                        : "Newton for the equilibrium reached a point where the "
                          "Lagrangian's derivatives are not finite");
      goto cleanup;
    }
    /* residual r = (L_y + sum_c lam_c G_c,y, G) and its symmetric Jacobian */
    memset(J, 0, (size_t)N * N * sizeof *J);
    for (int i = 0; i < n; i++) {
      r[i] = g[i];
      for (int j = 0; j < n; j++)
        J[i * N + j] = Lyy[i * n + j];
    }
    for (int c = 0; c < nc; c++) {
      const double *gc = val + n + 3 * nn + c * per;
      r[n + c] = gc[0];
      for (int i = 0; i < n; i++) {
        r[i] += lam[c] * gc[1 + i];
        J[i * N + n + c] = J[(n + c) * N + i] = gc[1 + i];
        for (int j = 0; j < n; j++)
          J[i * N + j] += lam[c] * gc[1 + n + i * n + j];
      }
    }
    md->iterations = it;
    md->residual = maxabs(N, r);
    tol = RES_RTOL * maxabs(N * N, J) * fmax(1.0, maxabs(n, y));
    if (converged || md->residual == 0)
      break;
    if (it == MAX_NEWTON)
      break;
    if (newton_step(N, J, r, step, work, lw) < 0) {
      rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
                "the eigenvalues of the stiffness did not converge (LAPACK dsyev)");
      goto cleanup;
    }
    for (int i = 0; i < n; i++)
      y[i] += step[i];
    for (int c = 0; c < nc; c++)
      lam[c] += step[n + c];
    /* Converged steps: one more evaluation at the new point, then stop. */
    converged = maxabs(n, step) <= STEP_RTOL * fmax(1.0, maxabs(n, y)) &&
                md->residual <= 1e3 * tol;
  }
  if (!(md->residual <= tol)) {
    sc_err(err, errlen, s->file, 0, "no equilibrium found from the guess: after %d Newton "
           "iterations max |dL/dy%s| = %.3g at y' = 0 (a force that nothing balances?)",
           md->iterations, nc ? " + lambda.dG/dy|, |G" : "", md->residual);
    rc = SC_MODES_NO_EQUILIBRIUM;
    goto cleanup;
  }

  /* M, K = -(L_yy + sum_c lam_c G_c,yy), C = L_y'y (P-10, P-13) */
  const double *Mv = val + n + nn, *C = val + n + 2 * nn;
  md->gyroscopic = 0;
  double cmax = maxabs(nn, C);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      md->mass[i * n + j] = Mv[i * n + j];
      md->stiffness[i * n + j] = 0.0 - J[i * N + j]; /* no -0 in the output */
    }
  /* On the constraints' tangent space: T (n x m, orthonormal), M_r = T'MT, K_r = T'KT,
   * C_r = T'CT; without constraints T = I and these are M, K, C. */
  double *Mr = T + nn, *Kr = Mr + nn, *Cr = Kr + nn;
  if (nc > 0) {
    for (int c = 0; c < nc; c++)
      for (int i = 0; i < n; i++)
        Ag[i + (size_t)c * n] = val[n + 3 * nn + c * per + 1 + i];
    int t = tangent_basis(n, nc, Ag, T);
    if (t == -2)
      goto cleanup;
    if (t != 0) {
      rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
                t == 1 ? "the constraints' gradients are dependent at the equilibrium: their "
                         "tangent space is not defined there"
                       : "the constraints' tangent space could not be computed (LAPACK "
                         "dgeqrf/dorgqr)");
      goto cleanup;
    }
    project(n, m, T, md->mass, Mr);
    project(n, m, T, md->stiffness, Kr);
    project(n, m, T, C, Cr);
  } else {
    memset(T, 0, (size_t)nn * sizeof *T);
    for (int i = 0; i < n; i++)
      T[i + (size_t)i * n] = 1.0;
    memcpy(Mr, md->mass, (size_t)nn * sizeof *Mr);
    memcpy(Kr, md->stiffness, (size_t)nn * sizeof *Kr);
    memcpy(Cr, C, (size_t)nn * sizeof *Cr);
  }
  md->nmodes = m;
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++)
      md->gyroscopic = fmax(md->gyroscopic, fabs(Cr[i * m + j] - Cr[j * m + i]));
  /* G below round-off of C itself (the two mixed partials differ in their last bits) */
  if (md->gyroscopic <= 1e-13 * cmax)
    md->gyroscopic = 0;

  /* K_r w = omega2 M_r w: dsygv, type 1, eigenvectors with w^T M_r w = 1, omega2
   * increasing; the shape is v = T w (so v^T M v = 1). */
  double *Ka = A, *Mb = A + (size_t)m * m;
  memcpy(Ka, Kr, (size_t)m * m * sizeof *Ka);
  memcpy(Mb, Mr, (size_t)m * m * sizeof *Mb);
  dsygv_(&one, "V", "U", &m, Ka, &m, Mb, &m, md->omega2, work, &lw, &info);
  if (info > m) {
    sc_err(err, errlen, s->file, s->F_line, "the mass matrix M = d2L/dy'dy' is not positive "
           "definite at the equilibrium%s (its leading minor of order %d is not positive): "
           "some coordinate has no kinetic energy, so there are no oscillations to compute",
           nc ? " along the constraints" : "", info - m);
    rc = SC_MODES_MASS;
    goto cleanup;
  }
  if (info != 0) {
    rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
              "the generalised eigenproblem K v = w2 M v did not converge (LAPACK dsygv)");
    goto cleanup;
  }
  double big = maxabs(m, md->omega2);
  for (int k = 0; k < m; k++) {
    double w2 = md->omega2[k] += 0.0;
    md->kind[k] = fabs(w2) <= SC_MODES_NEUTRAL_RTOL * big ? SC_MODE_NEUTRAL
                  : w2 > 0                                ? SC_MODE_STABLE
                                                          : SC_MODE_UNSTABLE;
    const double *w = Ka + (size_t)k * m;
    double *v = md->shape + (size_t)k * n;
    for (int i = 0; i < n; i++) {
      v[i] = 0;
      for (int a = 0; a < m; a++)
        v[i] += T[i + (size_t)a * n] * w[a];
    }
    /* Sign: the largest component positive, so the output is reproducible. */
    int imax = 0;
    for (int i = 1; i < n; i++)
      if (fabs(v[i]) > fabs(v[imax]))
        imax = i;
    double sg = v[imax] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < n; i++)
      v[i] = sg * v[i] + 0.0;
  }
  if (md->gyroscopic > 0) {
    int gm = gyro_modes(md, m, Mr, Kr, Cr);
    if (gm == -2)
      goto cleanup;
    if (gm < 0) {
      rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
                "the gyroscopic eigenproblem did not converge (LAPACK dggev)");
      goto cleanup;
    }
  }
  rc = SC_MODES_OK;
cleanup:
  if (rc == SC_MODES_NOMEM)
    sc_err(err, errlen, s->file, 0, "out of memory while computing the modes");
  cv_free(outs);
  cv_free(val);
  cv_free(work);
  cv_free(A);
  cv_free(Jk);
  cv_free(T);
  cv_free(Ag);
  if (rc != SC_MODES_OK)
    scene_modes_free(md);
  return rc;
}

void scene_modes_free(sc_modes *md)
{
  if (!md)
    return;
  cv_free(md->equilibrium);
  cv_free(md->omega2);
  cv_free(md->kind);
  cv_free(md->shape);
  cv_free(md->mass);
  cv_free(md->stiffness);
  cv_free(md->gyro_omega);
  cv_free(md->gyro_growth);
  cv_free(md->gyro_kind);
  cv_free(md->multipliers);
  memset(md, 0, sizeof *md);
}
