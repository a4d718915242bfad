/* src/core/cv_problem_eval.c — energy and momenta at any number of points (e.g. along a
 * solution), from the integrand's own partials: p_i = dF/dy'_i (P-3) and
 * H = sum_i y'_i p_i - F (P-5), docs/theory.md.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

cv_status cv_problem_eval_energy(const cv_problem *p, int m, const double *x, const double *y,
                                 const double *dy, double *H, double *P) {
  if (!p || !p->F || m < 0 || (m > 0 && (!x || !y || !dy))) return CVAR_EINVAL;
  if (m == 0) return CVAR_OK;
  int n = p->n, mb = m < CV_BATCH ? m : CV_BATCH;
  size_t b = (size_t)mb, M = (size_t)m;
  /* Scratch per batch: y, y' (n*b each), then F (b), F_y and F_y' (n*b each). */
  double *buf = cv_malloc((4 * (size_t)n + 1) * b * sizeof *buf);
  if (!buf) return CVAR_ENOMEM;
  double *yb = buf, *db = yb + n * b, *fb = db + n * b, *gy = fb + b, *gp = gy + n * b;
  cv_status st = CVAR_OK;
  for (int k0 = 0; k0 < m && st == CVAR_OK; k0 += mb) {
    int mm = m - k0 < mb ? m - k0 : mb;
    for (int i = 0; i < n; i++) {
      memcpy(yb + i * (size_t)mm, y + i * M + k0, (size_t)mm * sizeof *yb);
      memcpy(db + i * (size_t)mm, dy + i * M + k0, (size_t)mm * sizeof *db);
    }
    for (size_t j = 0; j < (2 * (size_t)n + 1) * b; j++) fb[j] = NAN; /* forgotten: NaN */
    cv_partials out = {fb, gy, gp, NULL, NULL, NULL};
    int rc = p->F(mm, x + k0, yb, db, CVAR_NEED_F | CVAR_NEED_GRAD, &out, p->user);
    if (rc != 0) {
      st = rc < 0 ? CVAR_ECALLBACK : CVAR_ENONFINITE;
      break;
    }
    for (int k = 0; H && k < mm; k++) { /* (P-5), summed in this order */
      double h = -fb[k];
      for (int i = 0; i < n; i++) h += db[i * (size_t)mm + k] * gp[i * (size_t)mm + k];
      H[k0 + k] = h;
    }
    for (int i = 0; P && i < n; i++)
      memcpy(P + i * M + k0, gp + i * (size_t)mm, (size_t)mm * sizeof *P);
  }
  cv_free(buf);
  return st;
}
