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
static int eval_partials(const scene *s, const ex_id *outs, const double *y, double *out)
{
  int n = s->n;
  double x = s->a;
  double *dy = calloc((size_t)n, sizeof *dy);
  if (!dy)
    return -1;
  int rc = sc_eval_exprs(s, n + 3 * n * n, outs, 1, &x, y, dy, out);
  free(dy);
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

/* The gyroscopic problem (P-12): lambda^2 M v + lambda G v + K v = 0 as the pencil
 * [[0, I], [-K, -G]] z = lambda [[I, 0], [0, M]] z of order 2n (LAPACK dggev, no inverse
 * of M). Of each pair lambda, -conj(lambda) of a conservative system one is kept: the
 * eigenvalues with Im > 0 and Re >= 0 (up to round-off), the real ones with Re > 0, and
 * half of the zero ones. Returns 0, or -1 if LAPACK fails (or -2 out of memory). */
static int gyro_modes(sc_modes *md, const double *C)
{
  int n = md->n, N = 2 * n, info = 0, lw = -1;
  double q = 0;
  double *A = calloc((size_t)N * N * 2 + 3 * (size_t)N, sizeof *A);
  if (!A)
    return -2;
  double *B = A + (size_t)N * N, *ar = B + (size_t)N * N, *ai = ar + N, *be = ai + N;
  for (int i = 0; i < n; i++) {
    A[i + (size_t)(n + i) * N] = 1.0;
    B[i + (size_t)i * N] = 1.0;
    for (int j = 0; j < n; j++) {
      A[(n + i) + (size_t)j * N] = -md->stiffness[i * n + j];
      A[(n + i) + (size_t)(n + j) * N] = -(C[i * n + j] - C[j * n + i]);
      B[(n + i) + (size_t)(n + j) * N] = md->mass[i * n + j];
    }
  }
  dggev_("N", "N", &N, A, &N, B, &N, ar, ai, be, NULL, &N, NULL, &N, &q, &lw, &info);
  lw = (int)fmax(q, 8.0 * N);
  double *work = malloc((size_t)lw * sizeof *work);
  if (!work) {
    free(A);
    return -2;
  }
  dggev_("N", "N", &N, A, &N, B, &N, ar, ai, be, NULL, &N, NULL, &N, work, &lw, &info);
  free(work);
  if (info != 0) {
    free(A);
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
  free(A);
  return 0;
}

static int fail(const scene *s, char *err, size_t errlen, int code, const char *msg)
{
  sc_err(err, errlen, s->file, 0, "%s", msg);
  return code;
}

int scene_modes_new(scene *s, sc_modes *md, char *err, size_t errlen)
{
  int n = s->n, nn = n * n, rc = SC_MODES_NOMEM, info = 0;
  ex_dag *d = s->dag;
  ex_id *outs = NULL;
  double *val = NULL, *work = NULL, *A = NULL;
  memset(md, 0, sizeof *md);
  md->n = n;
  if (err && errlen)
    err[0] = '\0';
  if (scene_F_depends_on_variable(s)) {
    sc_err(err, errlen, s->file, s->F_line, "the integrand depends explicitly on %s; modes "
           "needs a Lagrangian L(y, y') without it", s->variable);
    return SC_MODES_EXPLICIT;
  }
  if (s->ncons > 0 || s->nints > 0) {
    sc_err(err, errlen, s->file, s->ncons ? s->cons[0].line : s->ints[0].line,
           "modes does not handle constraints: write the Lagrangian in generalised "
           "coordinates that satisfy them");
    return SC_MODES_CONSTRAINED;
  }
  int nout = n + 3 * nn;
  outs = malloc((size_t)nout * sizeof *outs);
  val = malloc((size_t)nout * sizeof *val);
  md->equilibrium = malloc((size_t)n * sizeof *md->equilibrium);
  md->omega2 = malloc((size_t)n * sizeof *md->omega2);
  md->kind = malloc((size_t)n * sizeof *md->kind);
  md->shape = malloc((size_t)nn * sizeof *md->shape);
  md->mass = malloc((size_t)nn * sizeof *md->mass);
  md->stiffness = malloc((size_t)nn * sizeof *md->stiffness);
  md->gyro_omega = malloc((size_t)n * sizeof *md->gyro_omega);
  md->gyro_growth = malloc((size_t)n * sizeof *md->gyro_growth);
  md->gyro_kind = malloc((size_t)n * sizeof *md->gyro_kind);
  A = malloc((size_t)(2 * nn + 2 * n) * sizeof *A);
  if (!outs || !val || !md->equilibrium || !md->omega2 || !md->kind || !md->shape ||
      !md->mass || !md->stiffness || !A || !md->gyro_omega || !md->gyro_growth ||
      !md->gyro_kind)
    goto cleanup;

  /* The expressions: L_y, L_yy, L_y'y', L_y'y (P-9). */
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

  /* Workspace: the larger of dsyev's and dsygv's optimal sizes. */
  int lw = -1, lw2 = -1;
  double q1 = 0, q2 = 0, dummy = 0;
  int one = 1;
  dsyev_("V", "U", &n, A, &n, &dummy, &q1, &lw, &info);
  dsygv_(&one, "V", "U", &n, A, &n, A + nn, &n, &dummy, &q2, &lw2, &info);
  lw = (int)fmax(fmax(q1, q2), 3.0 * n);
  if (!(work = malloc(((size_t)nn + n + (size_t)lw) * sizeof *work)))
    goto cleanup;

  /* Equilibrium: Newton from the guess at the start of the interval. */
  double *y = md->equilibrium, *step = A;
  const double *g = val, *J = val + n;
  if (scene_eval_guess(s, 1, &s->a, y) < 0)
    goto cleanup;
  int converged = 0;
  for (int it = 0; it <= MAX_NEWTON; it++) {
    if (eval_partials(s, outs, y, val) < 0)
      goto cleanup;
    if (!all_finite(nout, val) || !all_finite(n, y)) {
      rc = fail(s, err, errlen, SC_MODES_NONFINITE,
                it == 0 ? "the Lagrangian's derivatives are not finite at the guess (the "
                          "start values of the unknowns at y' = 0)"
                        : "Newton for the equilibrium reached a point where the "
                          "Lagrangian's derivatives are not finite");
      goto cleanup;
    }
    md->iterations = it;
    md->residual = maxabs(n, g);
    double tol = RES_RTOL * maxabs(nn, J) * fmax(1.0, maxabs(n, y));
    if (converged || md->residual == 0)
      break;
    if (it == MAX_NEWTON)
      break;
    if (newton_step(n, J, g, step, work, lw) < 0) {
      rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
                "the eigenvalues of the stiffness did not converge (LAPACK dsyev)");
      goto cleanup;
    }
    for (int i = 0; i < n; i++)
      y[i] += step[i];
    /* Converged steps: one more evaluation at the new point, then stop. */
    converged = maxabs(n, step) <= STEP_RTOL * fmax(1.0, maxabs(n, y)) &&
                md->residual <= 1e3 * tol;
  }
  double tol = RES_RTOL * maxabs(nn, J) * fmax(1.0, maxabs(n, y));
  if (!(md->residual <= tol)) {
    sc_err(err, errlen, s->file, 0, "no equilibrium found from the guess: after %d Newton "
           "iterations max |dL/dy| = %.3g at y' = 0 (a force that nothing balances?)",
           md->iterations, md->residual);
    rc = SC_MODES_NO_EQUILIBRIUM;
    goto cleanup;
  }

  /* M, K = -L_yy, gyroscopic part of C = L_y'y (P-10). */
  const double *Mv = val + n + nn, *C = val + n + 2 * nn;
  md->gyroscopic = 0;
  double cmax = maxabs(nn, C);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      md->mass[i * n + j] = Mv[i * n + j];
      md->stiffness[i * n + j] = 0.0 - J[i * n + j]; /* no -0 in the output */
      md->gyroscopic = fmax(md->gyroscopic, fabs(C[i * n + j] - C[j * n + i]));
    }
  /* G below round-off of C itself (the two mixed partials differ in their last bits) */
  if (md->gyroscopic <= 1e-13 * cmax)
    md->gyroscopic = 0;

  /* K v = omega2 M v: dsygv, type 1, eigenvectors with V^T M V = I, omega2 increasing. */
  double *Ka = A, *Mb = A + nn;
  memcpy(Ka, md->stiffness, (size_t)nn * sizeof *Ka);
  memcpy(Mb, md->mass, (size_t)nn * sizeof *Mb);
  dsygv_(&one, "V", "U", &n, Ka, &n, Mb, &n, md->omega2, work, &lw, &info);
  if (info > n) {
    sc_err(err, errlen, s->file, s->F_line, "the mass matrix M = d2L/dy'dy' is not positive "
           "definite at the equilibrium (its leading minor of order %d is not positive): "
           "some coordinate has no kinetic energy, so there are no oscillations to compute",
           info - n);
    rc = SC_MODES_MASS;
    goto cleanup;
  }
  if (info != 0) {
    rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
              "the generalised eigenproblem K v = w2 M v did not converge (LAPACK dsygv)");
    goto cleanup;
  }
  double big = maxabs(n, md->omega2);
  for (int k = 0; k < n; k++) {
    double w2 = md->omega2[k] += 0.0;
    md->kind[k] = fabs(w2) <= SC_MODES_NEUTRAL_RTOL * big ? SC_MODE_NEUTRAL
                  : w2 > 0                                ? SC_MODE_STABLE
                                                          : SC_MODE_UNSTABLE;
    /* Sign: the largest component positive, so the output is reproducible. */
    const double *v = Ka + (size_t)k * n;
    int imax = 0;
    for (int i = 1; i < n; i++)
      if (fabs(v[i]) > fabs(v[imax]))
        imax = i;
    double sg = v[imax] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < n; i++)
      md->shape[k * n + i] = sg * v[i] + 0.0;
  }
  if (md->gyroscopic > 0) {
    int g = gyro_modes(md, C);
    if (g == -2)
      goto cleanup;
    if (g < 0) {
      rc = fail(s, err, errlen, SC_MODES_NO_EQUILIBRIUM,
                "the gyroscopic eigenproblem did not converge (LAPACK dggev)");
      goto cleanup;
    }
  }
  rc = SC_MODES_OK;
cleanup:
  if (rc == SC_MODES_NOMEM)
    sc_err(err, errlen, s->file, 0, "out of memory while computing the modes");
  free(outs);
  free(val);
  free(work);
  free(A);
  if (rc != SC_MODES_OK)
    scene_modes_free(md);
  return rc;
}

void scene_modes_free(sc_modes *md)
{
  if (!md)
    return;
  free(md->equilibrium);
  free(md->omega2);
  free(md->kind);
  free(md->shape);
  free(md->mass);
  free(md->stiffness);
  free(md->gyro_omega);
  free(md->gyro_growth);
  free(md->gyro_kind);
  memset(md, 0, sizeof *md);
}
