/* src/mech/mech_equilibrium.c — the equilibrium of a Lagrangian L(y, y') with holonomic
 * constraints G_c(y) = 0: Newton on the stationarity of L + lambda.G at y' = 0,
 * (L_y + sum_c lambda_c G_c,y, G) = 0, with a pseudo-inverse step so that neutral directions
 * do not move (docs/theory.md (P-9), (P-13)).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mech/mech_internal.h"

enum { MAX_NEWTON = 100 };

/* Newton steps stop when max|step| <= STEP_RTOL max(1, max|y|). */
static const double STEP_RTOL = 1e-14;
/* The equilibrium is accepted when max|dL/dy| <= RES_RTOL max|d2L/dy2| max(1, max|y|):
 * the residual is round-off of the force against the stiffness scale. */
static const double RES_RTOL = 1e-10;

static cv_status fail(char *err, size_t errlen, cv_status st, const char *msg) {
  if (err && errlen) snprintf(err, errlen, "%s", msg);
  return st;
}

/* The residual r = (L_y + sum_c lam_c G_c,y, G) and its symmetric Jacobian J at the point
 * whose partials are in c->val. */
static void residual(mech_ctx *c, const double *lam) {
  int n = c->n, nn = c->nn, N = c->N;
  const double *g = c->val, *Lyy = c->val + n;
  double *J = c->J, *r = c->r;
  memset(J, 0, (size_t)N * N * sizeof *J);
  for (int i = 0; i < n; i++) {
    r[i] = g[i];
    for (int j = 0; j < n; j++) J[i * N + j] = Lyy[i * n + j];
  }
  for (int k = 0; k < c->nc; k++) {
    const double *gc = c->val + n + 3 * nn + k * c->per;
    r[n + k] = gc[0];
    for (int i = 0; i < n; i++) {
      r[i] += lam[k] * gc[1 + i];
      J[i * N + n + k] = J[(n + k) * N + i] = gc[1 + i];
      for (int j = 0; j < n; j++) J[i * N + j] += lam[k] * gc[1 + n + i * n + j];
    }
  }
}

cv_status mech_equilibrium(mech_ctx *c, mech_modes *md, int *at, char *err, size_t errlen) {
  int n = c->n, nc = c->nc, N = c->N;
  double *y = md->equilibrium, *lam = md->multipliers, *step = c->step;
  memcpy(y, c->mp->start, (size_t)n * sizeof *y);
  for (int k = 0; k < nc; k++) lam[k] = 0;
  *at = MECH_AT_NONE;
  int converged = 0;
  double tol = 0;
  for (int it = 0; it <= MAX_NEWTON; it++) {
    if (mech_eval_partials(c, y) < 0) return CVAR_ENOMEM;
    if (!mech_all_finite(c->nout, c->val) || !mech_all_finite(n, y) || !mech_all_finite(nc, lam))
      return fail(err, errlen, CVAR_ENONFINITE,
                  it == 0 ? "the Lagrangian's derivatives are not finite at the guess (the "
                            "start values of the unknowns at y' = 0)"
                          : "Newton for the equilibrium reached a point where the "
                            "Lagrangian's derivatives are not finite");
    residual(c, lam);
    md->iterations = it;
    md->residual = mech_maxabs(N, c->r);
    tol = RES_RTOL * mech_maxabs(N * N, c->J) * fmax(1.0, mech_maxabs(n, y));
    if (converged || md->residual == 0) break;
    if (it == MAX_NEWTON) break;
    if (mech_pinv_step(N, c->J, c->r, step, c->work, c->lw) < 0)
      return fail(err, errlen, CVAR_EDEPENDENCY,
                  "the eigenvalues of the stiffness did not converge (LAPACK dsyev)");
    for (int i = 0; i < n; i++) y[i] += step[i];
    for (int k = 0; k < nc; k++) lam[k] += step[n + k];
    /* Converged steps: one more evaluation at the new point, then stop. */
    converged = mech_maxabs(n, step) <= STEP_RTOL * fmax(1.0, mech_maxabs(n, y)) &&
                md->residual <= 1e3 * tol;
  }
  if (!(md->residual <= tol)) {
    if (err && errlen)
      snprintf(err, errlen,
               "no equilibrium found from the guess: after %d Newton "
               "iterations max |dL/dy%s| = %.3g at y' = 0 (a force that nothing balances?)",
               md->iterations, nc ? " + lambda.dG/dy|, |G" : "", md->residual);
    return CVAR_EMAXITER;
  }
  return CVAR_OK;
}
