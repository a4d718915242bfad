/* src/core/cv_hermite_solution.c — the solution of a solve on C^1 elements: nodal values
 * and slopes, quadrature points with y'', evaluation anywhere (theory H-2).
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_hermite.h"

cv_status cv_hermite_nodal(const cv_solver *s, int slopes, double *out) {
  const cv_disc *d = &s->disc;
  int nc = d->n, n = nc / 2;
  for (long j = 0; j < d->nodes; j++)
    for (int i = 0; i < n; i++) out[j * n + i] = s->y[j * nc + 2 * i + (slopes != 0)];
  return CVAR_OK;
}

cv_status cv_hermite_qpoints(const cv_solver *s, double *x, double *w, double *y, double *dy,
                             double *d2y) {
  const cv_disc *d = &s->disc;
  const cv_hermite *h = d->herm;
  int n = d->n / 2;
  long nq = (long)d->E * h->q, idx = 0;
  double yv[64], dv[64], ddv[64];
  if (n > 64) return CVAR_EINVAL;
  for (long e = 0; e < d->E; e++) {
    double hl = d->xe[e + 1] - d->xe[e];
    for (int k = 0; k < h->q; k++, idx++) {
      if (x) x[idx] = d->xe[e] + 0.5 * (h->tau[k] + 1.0) * hl;
      if (w) w[idx] = 0.5 * hl * h->omega[k];
      if (!y && !dy && !d2y) continue;
      cv_hermite_eval_local(d, s->y, e, h->tau[k], yv, dv, ddv);
      for (int i = 0; i < n; i++) {
        if (y) y[i * nq + idx] = yv[i];
        if (dy) dy[i * nq + idx] = dv[i];
        if (d2y) d2y[i * nq + idx] = ddv[i];
      }
    }
  }
  return CVAR_OK;
}

cv_status cv_hermite_eval(const cv_solver *s, int m, const double *x, double *y, double *dy) {
  const cv_disc *d = &s->disc;
  int n = d->n / 2;
  double yv[64], dv[64];
  if (n > 64) return CVAR_EINVAL;
  for (int k = 0; k < m; k++) {
    if (!(x[k] >= d->a && x[k] <= d->b)) return CVAR_EINVAL;
    long lo = 0, hi = d->E; /* xe[lo] <= x < xe[lo + 1] */
    while (hi - lo > 1) {
      long mid = (lo + hi) / 2;
      if (d->xe[mid] <= x[k])
        lo = mid;
      else
        hi = mid;
    }
    double hl = d->xe[lo + 1] - d->xe[lo], t = 2.0 * (x[k] - d->xe[lo]) / hl - 1.0;
    cv_hermite_eval_local(d, s->y, lo, t, yv, dv, NULL);
    for (int i = 0; i < n; i++) {
      y[i * m + k] = yv[i];
      if (dy) dy[i * m + k] = dv[i];
    }
  }
  return CVAR_OK;
}
