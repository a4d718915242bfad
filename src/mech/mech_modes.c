/* src/mech/mech_modes.c — small oscillations about an equilibrium of a Lagrangian
 * L(y, y'): M and K there, K v = omega2 M v on the constraints' tangent space, and with
 * gyroscopic terms the motions of M y'' + G y' + K y = 0 (docs/theory.md (P-9), (P-10),
 * (P-12), (P-13)). The equilibrium itself: mech_equilibrium.c; LAPACK: mech_dense.c.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mech/mech_internal.h"

/* Modes apply to L(y, y') with holonomic constraints G(y) that hold still, fewer than the
 * unknowns, and no integral constraints. */
static cv_status applicable(const mech_problem *mp, int *at, char *err, size_t errlen) {
  if (ex_depends_on(mp->dag, mp->F, 0)) {
    *at = MECH_AT_F;
    if (err && errlen)
      snprintf(err, errlen,
               "the integrand depends explicitly on %s; modes needs a "
               "Lagrangian L(y, y') without it",
               mp->variable);
    return CVAR_EINVAL;
  }
  if (mp->nints > 0) {
    *at = MECH_AT_CONS + mp->ncons;
    if (err && errlen)
      snprintf(err, errlen,
               "modes does not handle integral constraints: they constrain the "
               "whole path, not the positions near an equilibrium");
    return CVAR_EINVAL;
  }
  for (int c = 0; c < mp->ncons; c++)
    if (ex_depends_on(mp->dag, mp->cons[c], 0)) {
      *at = MECH_AT_CONS + c;
      if (err && errlen)
        snprintf(err, errlen,
                 "the constraint '%s' depends on %s (it moves): modes needs "
                 "constraints G(y) that hold still",
                 mp->cons_names[c], mp->variable);
      return CVAR_EINVAL;
    }
  if (mp->ncons >= mp->n) {
    *at = MECH_AT_CONS;
    if (err && errlen)
      snprintf(err, errlen, "%d constraints on %d unknowns leave nothing to oscillate", mp->ncons,
               mp->n);
    return CVAR_EINVAL;
  }
  return CVAR_OK;
}

/* The expressions of c->val (exact symbolic derivatives) and their tape. */
static int build_partials(mech_ctx *c) {
  const mech_problem *mp = c->mp;
  ex_dag *d = mp->dag;
  int n = c->n, nn = c->nn;
  ex_id *outs = c->outs;
  for (int i = 0; i < n; i++) {
    ex_id gi = ex_diff(d, mp->F, 1 + i), pi = ex_diff(d, mp->F, 1 + n + i);
    if (gi < 0 || pi < 0) return -1;
    outs[i] = gi;
    for (int j = 0; j < n; j++) {
      if ((outs[n + i * n + j] = ex_diff(d, gi, 1 + j)) < 0 ||
          (outs[n + nn + i * n + j] = ex_diff(d, pi, 1 + n + j)) < 0 ||
          (outs[n + 2 * nn + i * n + j] = ex_diff(d, pi, 1 + j)) < 0)
        return -1;
    }
  }
  for (int k = 0; k < c->nc; k++) {
    ex_id *o = outs + n + 3 * nn + k * c->per, G = mp->cons[k];
    o[0] = G;
    for (int i = 0; i < n; i++) {
      if ((o[1 + i] = ex_diff(d, G, 1 + i)) < 0) return -1;
      for (int j = 0; j < n; j++)
        if ((o[1 + n + i * n + j] = ex_diff(d, o[1 + i], 1 + j)) < 0) return -1;
    }
  }
  if (!(c->tape = ex_tape_new(d, 1 + 2 * n, c->nout, outs)) ||
      !(c->tape_work = cv_malloc((ex_tape_work_size(c->tape, 1) + 1) * sizeof *c->tape_work)))
    return -1;
  return 0;
}

int mech_eval_partials(mech_ctx *c, const double *y) {
  int n = c->n;
  const double **in = cv_malloc((size_t)(1 + 2 * n) * sizeof *in);
  double **o = cv_malloc((size_t)c->nout * sizeof *o);
  if (!in || !o) {
    cv_free(in);
    cv_free(o);
    return -1;
  }
  in[0] = &c->mp->start_x;
  for (int i = 0; i < n; i++) {
    in[1 + i] = y + i;
    in[1 + n + i] = c->zero + i;
  }
  for (int q = 0; q < c->nout; q++) o[q] = c->val + q;
  ex_tape_eval(c->tape, 1, (const double *const *)in, (double *const *)o, c->tape_work);
  cv_free(in);
  cv_free(o);
  return 0;
}

/* M, K = -(L_yy + sum_c lam_c G_c,yy) and C = L_y'y at the equilibrium (P-10, P-13), and
 * on the constraints' tangent space T (n x m, orthonormal): M_r = T'MT, K_r = T'KT,
 * C_r = T'CT; without constraints T = I and these are M, K, C. T, Mr, Kr, Cr are n*n
 * each. */
static cv_status reduced_matrices(mech_ctx *c, mech_modes *md, double *T, double *Mr, double *Kr,
                                  double *Cr, char *err, size_t errlen) {
  int n = c->n, nn = c->nn, N = c->N, nc = c->nc, m = n - nc;
  const double *Mv = c->val + n + nn, *C = c->val + n + 2 * nn;
  md->gyroscopic = 0;
  double cmax = mech_maxabs(nn, C);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++) {
      md->mass[i * n + j] = Mv[i * n + j];
      md->stiffness[i * n + j] = 0.0 - c->J[i * N + j]; /* no -0 in the output */
    }
  if (nc > 0) {
    double *Ag = c->step + N; /* constraint gradients, n x nc column-major */
    for (int k = 0; k < nc; k++)
      for (int i = 0; i < n; i++) Ag[i + (size_t)k * n] = c->val[n + 3 * nn + k * c->per + 1 + i];
    int t = mech_tangent_basis(n, nc, Ag, T);
    if (t == -2) return CVAR_ENOMEM;
    if (t != 0) {
      if (err && errlen)
        snprintf(err, errlen, "%s",
                 t == 1 ? "the constraints' gradients are dependent at the equilibrium: "
                          "their tangent space is not defined there"
                        : "the constraints' tangent space could not be computed (LAPACK "
                          "dgeqrf/dorgqr)");
      return t == 1 ? CVAR_ESINGULAR : CVAR_EDEPENDENCY;
    }
    mech_project(n, m, T, md->mass, Mr);
    mech_project(n, m, T, md->stiffness, Kr);
    mech_project(n, m, T, C, Cr);
  } else {
    memset(T, 0, (size_t)nn * sizeof *T);
    for (int i = 0; i < n; i++) T[i + (size_t)i * n] = 1.0;
    memcpy(Mr, md->mass, (size_t)nn * sizeof *Mr);
    memcpy(Kr, md->stiffness, (size_t)nn * sizeof *Kr);
    memcpy(Cr, C, (size_t)nn * sizeof *Cr);
  }
  md->nmodes = m;
  for (int i = 0; i < m; i++)
    for (int j = 0; j < m; j++)
      md->gyroscopic = fmax(md->gyroscopic, fabs(Cr[i * m + j] - Cr[j * m + i]));
  /* G below round-off of C itself (the two mixed partials differ in their last bits) */
  if (md->gyroscopic <= 1e-13 * cmax) md->gyroscopic = 0;
  return CVAR_OK;
}

/* K_r w = omega2 M_r w: eigenvectors with w^T M_r w = 1, omega2 increasing; the shape is
 * v = T w (so v^T M v = 1), its largest component positive so the output is reproducible.
 * Ka and Mb hold m*m doubles each. */
static cv_status normal_modes(mech_ctx *c, mech_modes *md, const double *T, const double *Mr,
                              const double *Kr, double *Ka, double *Mb, int *at, char *err,
                              size_t errlen) {
  int n = c->n, m = md->nmodes;
  memcpy(Ka, Kr, (size_t)m * m * sizeof *Ka);
  memcpy(Mb, Mr, (size_t)m * m * sizeof *Mb);
  int info = mech_sygv(m, Ka, Mb, md->omega2, c->work, c->lw);
  if (info > m) {
    *at = MECH_AT_F;
    if (err && errlen)
      snprintf(err, errlen,
               "the mass matrix M = d2L/dy'dy' is not positive definite at the "
               "equilibrium%s (its leading minor of order %d is not positive): some "
               "coordinate has no kinetic energy, so there are no oscillations to compute",
               c->nc ? " along the constraints" : "", info - m);
    return CVAR_ESINGULAR;
  }
  if (info != 0) {
    if (err && errlen)
      snprintf(err, errlen,
               "the generalised eigenproblem K v = w2 M v did not converge "
               "(LAPACK dsygv)");
    return CVAR_EDEPENDENCY;
  }
  double big = mech_maxabs(m, md->omega2);
  for (int k = 0; k < m; k++) {
    double w2 = md->omega2[k] += 0.0;
    md->kind[k] = fabs(w2) <= MECH_NEUTRAL_RTOL * big ? MECH_MODE_NEUTRAL
                  : w2 > 0                            ? MECH_MODE_STABLE
                                                      : MECH_MODE_UNSTABLE;
    const double *w = Ka + (size_t)k * m;
    double *v = md->shape + (size_t)k * n;
    for (int i = 0; i < n; i++) {
      v[i] = 0;
      for (int a = 0; a < m; a++) v[i] += T[i + (size_t)a * n] * w[a];
    }
    int imax = 0;
    for (int i = 1; i < n; i++)
      if (fabs(v[i]) > fabs(v[imax])) imax = i;
    double sg = v[imax] < 0 ? -1.0 : 1.0;
    for (int i = 0; i < n; i++) v[i] = sg * v[i] + 0.0;
  }
  return CVAR_OK;
}

/* The gyroscopic motions (P-12) of order m from the 2m eigenvalues of the pencil. Of each
 * pair lambda, -conj(lambda) of a conservative system one is kept: the eigenvalues with
 * Im > 0 and Re >= 0 (up to round-off), the real ones with Re > 0, and half of the zero
 * ones; then ordered: neutral and stable by omega, then unstable by growth. */
static void gyro_motions(mech_modes *md, int m, const double *re, const double *im) {
  int N = 2 * m;
  double big = 0;
  for (int k = 0; k < N; k++) big = fmax(big, hypot(re[k], im[k]));
  /* A free direction is a double zero with a Jordan block, computed as two eigenvalues of
   * size sqrt(eps) |lambda|: "zero" is 1e-6 of the largest. Re lambda of a stable pair is
   * round-off of a non-normal eigenproblem: "zero" is 1e-7 of the largest. */
  double tol0 = 1e-6 * big, tolre = 1e-7 * big;
  int nzero = 0, g = 0;
  for (int k = 0; k < N; k++) {
    if (hypot(re[k], im[k]) <= tol0) {
      nzero++;
      continue;
    }
    if (im[k] < 0 || re[k] < -tolre || (fabs(im[k]) <= tolre && re[k] <= tolre))
      continue; /* the partner of a kept one */
    md->gyro_kind[g] = re[k] > tolre ? MECH_MODE_UNSTABLE : MECH_MODE_STABLE;
    md->gyro_growth[g] = re[k] > tolre ? re[k] : 0.0;
    md->gyro_omega[g] = im[k] > tolre ? im[k] : 0.0;
    g++;
  }
  for (int k = 0; k < nzero / 2 && g < m; k++, g++) {
    md->gyro_kind[g] = MECH_MODE_NEUTRAL;
    md->gyro_omega[g] = md->gyro_growth[g] = 0.0;
  }
  for (int a = 1; a < g; a++) /* insertion sort, g <= m */
    for (int b = a; b > 0; b--) {
      int ub = md->gyro_kind[b] == MECH_MODE_UNSTABLE;
      int ua = md->gyro_kind[b - 1] == MECH_MODE_UNSTABLE;
      double kb = ub ? md->gyro_growth[b] : md->gyro_omega[b];
      double ka = ua ? md->gyro_growth[b - 1] : md->gyro_omega[b - 1];
      if (ua < ub || (ua == ub && ka <= kb)) break;
      double t = md->gyro_omega[b];
      md->gyro_omega[b] = md->gyro_omega[b - 1], md->gyro_omega[b - 1] = t;
      t = md->gyro_growth[b];
      md->gyro_growth[b] = md->gyro_growth[b - 1], md->gyro_growth[b - 1] = t;
      mech_mode_kind kk = md->gyro_kind[b];
      md->gyro_kind[b] = md->gyro_kind[b - 1], md->gyro_kind[b - 1] = kk;
    }
  md->ngyro = g;
}

static int alloc_modes(mech_modes *md, int n, int nc) {
  size_t nn = (size_t)n * n;
  md->equilibrium = cv_malloc((size_t)n * sizeof *md->equilibrium);
  md->multipliers = cv_malloc((size_t)(nc ? nc : 1) * sizeof *md->multipliers);
  md->omega2 = cv_malloc((size_t)n * sizeof *md->omega2);
  md->kind = cv_malloc((size_t)n * sizeof *md->kind);
  md->shape = cv_malloc(nn * sizeof *md->shape);
  md->mass = cv_malloc(nn * sizeof *md->mass);
  md->stiffness = cv_malloc(nn * sizeof *md->stiffness);
  md->gyro_omega = cv_malloc((size_t)n * sizeof *md->gyro_omega);
  md->gyro_growth = cv_malloc((size_t)n * sizeof *md->gyro_growth);
  md->gyro_kind = cv_malloc((size_t)n * sizeof *md->gyro_kind);
  return md->equilibrium && md->multipliers && md->omega2 && md->kind && md->shape && md->mass &&
                 md->stiffness && md->gyro_omega && md->gyro_growth && md->gyro_kind
             ? 0
             : -1;
}

cv_status mech_modes_new(const mech_problem *mp, mech_modes *md, int *at, char *err,
                         size_t errlen) {
  int n = mp->n, nn = n * n, nc = mp->ncons, N = n + nc, where = MECH_AT_NONE;
  mech_ctx c = {.mp = mp, .n = n, .nc = nc, .nn = nn, .N = N, .per = 1 + n + nn};
  double *mats = NULL, *eig = NULL;
  cv_status st = CVAR_ENOMEM;
  memset(md, 0, sizeof *md);
  md->n = n;
  if (err && errlen) err[0] = '\0';
  if (!at) at = &where;
  *at = MECH_AT_NONE;
  if ((st = applicable(mp, at, err, errlen)) != CVAR_OK) return st;
  st = CVAR_ENOMEM;
  c.nout = n + 3 * nn + nc * c.per;
  c.lw = mech_workspace(N, n);
  c.outs = cv_malloc((size_t)c.nout * sizeof *c.outs);
  c.val = cv_malloc((size_t)c.nout * sizeof *c.val);
  c.zero = cv_calloc((size_t)n, sizeof *c.zero);
  c.J = cv_malloc((size_t)(N * N + N) * sizeof *c.J);
  c.step = cv_malloc((size_t)(N + nn) * sizeof *c.step); /* then the gradients, n x nc */
  c.work = cv_malloc(((size_t)N * N + N + (size_t)c.lw) * sizeof *c.work);
  mats = cv_malloc((size_t)(4 * nn + 2 * nn) * sizeof *mats); /* T, Mr, Kr, Cr, Ka, Mb */
  eig = cv_malloc((size_t)(4 * n + 1) * sizeof *eig);
  if (!c.outs || !c.val || !c.zero || !c.J || !c.step || !c.work || !mats || !eig ||
      alloc_modes(md, n, nc) < 0)
    goto cleanup;
  md->nc = nc;
  c.r = c.J + (size_t)N * N;
  if (build_partials(&c) < 0) goto cleanup;
  if ((st = mech_equilibrium(&c, md, at, err, errlen)) != CVAR_OK) goto cleanup;
  double *T = mats, *Mr = T + nn, *Kr = Mr + nn, *Cr = Kr + nn, *Ka = Cr + nn, *Mb = Ka + nn;
  if ((st = reduced_matrices(&c, md, T, Mr, Kr, Cr, err, errlen)) != CVAR_OK ||
      (st = normal_modes(&c, md, T, Mr, Kr, Ka, Mb, at, err, errlen)) != CVAR_OK)
    goto cleanup;
  if (md->gyroscopic > 0) {
    int gm = mech_gyro_eigenvalues(md->nmodes, Mr, Kr, Cr, eig, eig + 2 * n);
    if (gm == -2) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    if (gm < 0) {
      if (err && errlen)
        snprintf(err, errlen, "the gyroscopic eigenproblem did not converge (LAPACK dggev)");
      st = CVAR_EDEPENDENCY;
      goto cleanup;
    }
    gyro_motions(md, md->nmodes, eig, eig + 2 * n);
  }
  st = CVAR_OK;
cleanup:
  if (st == CVAR_ENOMEM && err && errlen)
    snprintf(err, errlen, "out of memory while computing the modes");
  cv_free(c.outs);
  cv_free(c.val);
  cv_free(c.zero);
  cv_free(c.J);
  cv_free(c.step);
  cv_free(c.work);
  cv_free(c.tape_work);
  ex_tape_free(c.tape);
  cv_free(mats);
  cv_free(eig);
  if (st != CVAR_OK) mech_modes_free(md);
  return st;
}

void mech_modes_free(mech_modes *md) {
  if (!md) return;
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
