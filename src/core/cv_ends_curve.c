/* src/core/cv_ends_curve.c — a moving end on a curve G(x, y) = 0: evaluation, which free
 * end value follows the curve, projection onto it and its tangent (theory ME-3).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>

#include "cv_ends.h"
#include "cv_internal.h"

int cv_ends_curve_eval(cv_end_curve_fn G, void *user, int n, double x, const double *y, double *g,
                       double *gx, double *gy) {
  *g = *gx = NAN;
  for (int i = 0; i < n; i++) gy[i] = NAN;
  if (G(x, y, g, gx, gy, user) != 0 || !isfinite(*g) || !isfinite(*gx)) return -1;
  for (int i = 0; i < n; i++)
    if (!isfinite(gy[i])) return -1;
  return 0;
}

int cv_ends_movers(cv_end_curve_fn G, void *user, int n, const int *free_at_end, double x,
                   const double *y, int *k) {
  double g, gx, *gy = cv_malloc(2 * (size_t)n * sizeof *gy), *yt = gy ? gy + n : NULL;
  int count = 0;
  *k = -1;
  if (!gy) return -1;
  for (int i = 0; i < n; i++) yt[i] = y[i];
  for (int i = 0; i < n && count >= 0; i++) {
    if (!free_at_end[i]) continue;
    /* at the point and at a nearby value: a dependence whose slope vanishes at the point
     * itself (the circle at its leftmost point) still counts */
    int dep = 0;
    if (cv_ends_curve_eval(G, user, n, x, yt, &g, &gx, gy) != 0) count = -1;
    dep = count >= 0 && gy[i] != 0.0;
    yt[i] = y[i] + 1e-3 * (1.0 + fabs(y[i]));
    if (count >= 0 && cv_ends_curve_eval(G, user, n, x, yt, &g, &gx, gy) != 0) count = -1;
    dep |= count >= 0 && gy[i] != 0.0;
    yt[i] = y[i];
    if (dep && count >= 0 && count++ == 0) *k = i;
  }
  cv_free(gy);
  return count;
}

cv_status cv_ends_project(cv_end_curve_fn G, void *user, int n, int k, double *x, double *y,
                          double reach, char *msg, size_t len) {
  double g, gx, *gy = cv_malloc((size_t)n * sizeof *gy), x0 = *x, y0 = k >= 0 ? y[k] : 0.0;
  cv_status st = CVAR_EINVAL;
  if (!gy) return CVAR_ENOMEM;
  for (int it = 0; it < 60; it++) {
    if (cv_ends_curve_eval(G, user, n, *x, y, &g, &gx, gy) != 0) {
      cv_set_msg(msg, len, "the end curve cannot be evaluated at (%.6g, %.6g)", *x,
                 k >= 0 ? y[k] : 0.0);
      break;
    }
    double gk = k >= 0 ? gy[k] : 0.0, nn = gx * gx + gk * gk;
    if (g == 0.0) {
      st = CVAR_OK;
      break;
    }
    if (!(nn > 0.0)) {
      cv_set_msg(msg, len, "the end curve has a zero gradient at (%.6g, %.6g), where G = %.3g", *x,
                 k >= 0 ? y[k] : 0.0, g);
      break;
    }
    double dx = -g * gx / nn, dy = -g * gk / nn; /* the minimum-norm Newton step */
    *x += dx;
    if (k >= 0) y[k] += dy;
    double dist = hypot(*x - x0, k >= 0 ? y[k] - y0 : 0.0);
    if (!(dist <= reach)) {
      cv_set_msg(msg, len,
                 "the end curve does not meet the start's end region: from (%.6g, %.6g) it "
                 "was not reached within %.3g",
                 x0, y0, reach);
      break;
    }
    if (hypot(dx, dy) <= 1e-15 * (1.0 + fabs(*x) + (k >= 0 ? fabs(y[k]) : 0.0))) {
      st = CVAR_OK;
      break;
    }
    if (it == 59)
      cv_set_msg(msg, len,
                 "the end curve was not reached from (%.6g, %.6g): Newton's steps onto it did "
                 "not converge",
                 x0, y0);
  }
  cv_free(gy);
  return st;
}

int cv_ends_tangent(cv_end_curve_fn G, void *user, int n, int k, double x, const double *y,
                    double *tx, double *ty) {
  *tx = 1.0, *ty = 0.0;
  if (k < 0) return 0;
  double g, gx, *gy = cv_malloc((size_t)n * sizeof *gy);
  int rc = gy ? cv_ends_curve_eval(G, user, n, x, y, &g, &gx, gy) : -1;
  if (rc == 0) {
    double a = -gy[k], b = gx, nn = hypot(a, b);
    if (!(nn > 0.0)) {
      rc = -1;
    } else {
      if (a < 0.0 || (a == 0.0 && b < 0.0)) a = -a, b = -b;
      *tx = a / nn, *ty = b / nn;
    }
  }
  cv_free(gy);
  return rc;
}
