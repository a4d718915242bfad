/* src/core/cv_derivcheck.c — finite-difference check of a user integrand's partials.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cv_internal.h"

/* One point at a time, so a failing point is named. Workspace holds inputs and outputs. */
typedef struct {
  const cv_problem *p;
  double x, *y, *dy;
  cv_partials o;
} probe;

static cv_status eval_at(probe *pr, unsigned need) {
  int rc = pr->p->F(1, &pr->x, pr->y, pr->dy, need, &pr->o, pr->p->user);
  if (rc < 0) return CVAR_ECALLBACK;
  if (rc > 0) return CVAR_ENONFINITE;
  return CVAR_OK;
}

static void consider(cv_derivcheck *rep, int point, const char *name, int i, int j, double an,
                     double fd) {
  double err = fabs(an - fd) / fmax(1.0, fabs(an));
  if (!isfinite(an) || !isfinite(fd)) err = INFINITY;
  if (!(err <= rep->worst)) {
    rep->worst = err;
    rep->point = point;
    rep->analytic = an;
    rep->fd = fd;
    if (j >= 0)
      snprintf(rep->which, sizeof rep->which, "%s[%d][%d]", name, i, j);
    else
      snprintf(rep->which, sizeof rep->which, "%s[%d]", name, i);
  }
}

/* Central differences with step h = eps^(1/3) max(1, |v|), error O(h^2) ~ eps^(2/3) relative
 * for the first partials (of F) and for the second partials (of the first ones). */
cv_status cv_problem_check_derivatives(const cv_problem *p, int m, const double *x, const double *y,
                                       const double *dy, cv_derivcheck *rep) {
  if (!p || !p->F || m < 1 || m > CV_BATCH || !x || !y || !dy || !rep) return CVAR_EINVAL;
  int n = p->n;
  size_t nn = (size_t)n * n;
  cv_status st = CVAR_OK;
  double *buf = cv_malloc((4 * (size_t)n + 3 + 2 * (2 * (size_t)n + 1 + 3 * nn)) * sizeof *buf);
  if (!buf) return CVAR_ENOMEM;
  memset(rep, 0, sizeof *rep);
  probe base, pl;
  double *w = buf;
  base.p = pl.p = p;
  base.y = w, w += n;
  base.dy = w, w += n;
  pl.y = w, w += n;
  pl.dy = w, w += n;
  base.o.F = w++;
  base.o.Fy = w, w += n;
  base.o.Fp = w, w += n;
  base.o.Fyy = w, w += nn;
  base.o.Fyp = w, w += nn;
  base.o.Fpp = w, w += nn;
  pl.o.F = w++;
  pl.o.Fy = w, w += n;
  pl.o.Fp = w, w += n;
  pl.o.Fyy = pl.o.Fyp = pl.o.Fpp = NULL;
  const double h3 = cbrt(2.220446049250313e-16);
  unsigned all = CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS;
  for (int k = 0; k < m; k++) {
    base.x = pl.x = x[k];
    for (int i = 0; i < n; i++) base.y[i] = y[i * m + k], base.dy[i] = dy[i * m + k];
    st = eval_at(&base, all);
    if (st) goto cleanup;
    /* perturb each of the 2n inputs: v = 0..n-1 are y_i, n..2n-1 are y'_i */
    for (int v = 0; v < 2 * n; v++) {
      double fp[64 * 2 + 1], fm[64 * 2 + 1]; /* F, Fy, Fp at +h and -h (n <= 64) */
      if (n > 64) break;
      double *slot = v < n ? &pl.y[v] : &pl.dy[v - n];
      double v0 = v < n ? base.y[v] : base.dy[v - n], hh = h3 * fmax(1.0, fabs(v0));
      for (int s = 0; s < 2; s++) {
        memcpy(pl.y, base.y, (size_t)n * sizeof *pl.y);
        memcpy(pl.dy, base.dy, (size_t)n * sizeof *pl.dy);
        *slot = v0 + (s ? -hh : hh);
        st = eval_at(&pl, CVAR_NEED_F | CVAR_NEED_GRAD);
        if (st) goto cleanup;
        double *dst = s ? fm : fp;
        dst[0] = pl.o.F[0];
        memcpy(dst + 1, pl.o.Fy, (size_t)n * sizeof *dst);
        memcpy(dst + 1 + n, pl.o.Fp, (size_t)n * sizeof *dst);
      }
      int i = v < n ? v : v - n;
      double dF = (fp[0] - fm[0]) / (2 * hh);
      consider(rep, k, v < n ? "Fy" : "Fp", i, -1, v < n ? base.o.Fy[i] : base.o.Fp[i], dF);
      for (int r = 0; r < n; r++) {
        double dFy = (fp[1 + r] - fm[1 + r]) / (2 * hh); /* d/dv of F_{y_r} */
        double dFp = (fp[1 + n + r] - fm[1 + n + r]) / (2 * hh);
        if (v < n) {
          consider(rep, k, "Fyy", r, i, base.o.Fyy[r * n + i], dFy);
          consider(rep, k, "Fyp", i, r, base.o.Fyp[i * n + r], dFp); /* F_{y_i y'_r} */
        } else {
          consider(rep, k, "Fyp", r, i, base.o.Fyp[r * n + i], dFy); /* F_{y_r y'_i} */
          consider(rep, k, "Fpp", r, i, base.o.Fpp[r * n + i], dFp);
        }
      }
    }
  }
cleanup:
  cv_free(buf);
  return st;
}
