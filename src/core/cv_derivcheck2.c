/* src/core/cv_derivcheck2.c — finite-difference check of a second-order integrand's
 * partials in (y, y', y''), through the cv_partials2 outputs (theory H-1).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cv_internal.h"

/* One point's inputs z = (y, y', y'') (3n) and outputs: F, the first partials
 * g = (Fy, Fp, Fq) (3n) and the nine blocks of second partials. */
typedef struct {
  int n;
  double x, *z, *F, *g, *h2[6]; /* Fyy, Fyp, Fpp, Fyq, Fpq, Fqq */
} point2;

static cv_status eval2(const cv_problem *p, point2 *q, int hess) {
  int n = q->n;
  cv_partials2 o;
  memset(&o, 0, sizeof o);
  o.d1.F = q->F;
  o.d1.Fy = q->g, o.d1.Fp = q->g + n, o.Fq = q->g + 2 * n;
  if (hess) {
    o.d1.Fyy = q->h2[0], o.d1.Fyp = q->h2[1], o.d1.Fpp = q->h2[2];
    o.Fyq = q->h2[3], o.Fpq = q->h2[4], o.Fqq = q->h2[5];
  }
  o.d2y = q->z + 2 * n;
  unsigned need = CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_Y2 | (hess ? CVAR_NEED_HESS : 0u);
  int rc = p->F(1, &q->x, q->z, q->z + n, need, &o.d1, p->user);
  return rc < 0 ? CVAR_ECALLBACK : rc > 0 ? CVAR_ENONFINITE : CVAR_OK;
}

/* The second partial d2F/dz_a dz_b from the blocks (a, b < 3n), and its printed name. */
static double hess_entry(const point2 *q, int a, int b, char *name, size_t len) {
  static const char *const nm[3][3] = {
      {"Fyy", "Fyp", "Fyq"}, {"Fyp", "Fpp", "Fpq"}, {"Fyq", "Fpq", "Fqq"}};
  static const int blk[3][3] = {{0, 1, 3}, {1, 2, 4}, {3, 4, 5}};
  int n = q->n, A = a / n, B = b / n, i = a % n, j = b % n;
  if (A > B) { /* the stored block has the lower kind first: F_{z_A z_B} = F_{z_B z_A}^T */
    int t = A;
    A = B, B = t, t = i, i = j, j = t;
  }
  snprintf(name, len, "%s[%d][%d]", nm[A][B], i, j);
  return q->h2[blk[A][B]][i * n + j];
}

static void consider(cv_derivcheck *rep, int point, const char *name, double an, double fd) {
  double err = fabs(an - fd) / fmax(1.0, fabs(an));
  if (!isfinite(an) || !isfinite(fd)) err = INFINITY;
  if (!(err <= rep->worst)) {
    rep->worst = err;
    rep->point = point;
    rep->analytic = an;
    rep->fd = fd;
    snprintf(rep->which, sizeof rep->which, "%s", name);
  }
}

cv_status cv_problem_check_derivatives2(const cv_problem *p, int m, const double *x,
                                        const double *y, const double *dy, const double *d2y,
                                        cv_derivcheck *rep) {
  if (!p || !p->F || !p->c1 || m < 1 || m > CV_BATCH || !x || !y || !dy || !d2y || !rep ||
      p->n > 64)
    return CVAR_EINVAL;
  int n = p->n, N = 3 * n;
  size_t nn = (size_t)n * n;
  double *buf = cv_malloc((3 * ((size_t)2 * N + 1) + 6 * nn) * sizeof *buf);
  if (!buf) return CVAR_ENOMEM;
  memset(rep, 0, sizeof *rep);
  point2 base = {n, 0, buf, buf + N, buf + N + 1, {NULL}}, pl, mi;
  for (int k = 0; k < 6; k++) base.h2[k] = buf + 2 * N + 1 + k * nn;
  double *w = buf + 2 * N + 1 + 6 * nn;
  pl = (point2){n, 0, w, w + N, w + N + 1, {NULL}};
  w += 2 * N + 1;
  mi = (point2){n, 0, w, w + N, w + N + 1, {NULL}};
  const double h3 = cbrt(2.220446049250313e-16);
  cv_status st = CVAR_OK;
  char name[32];
  for (int k = 0; k < m && !st; k++) {
    base.x = pl.x = mi.x = x[k];
    for (int i = 0; i < n; i++)
      base.z[i] = y[i * m + k], base.z[n + i] = dy[i * m + k], base.z[2 * n + i] = d2y[i * m + k];
    st = eval2(p, &base, 1);
    for (int v = 0; v < N && !st; v++) { /* central differences in z_v */
      double hh = h3 * fmax(1.0, fabs(base.z[v]));
      memcpy(pl.z, base.z, (size_t)N * sizeof *pl.z);
      memcpy(mi.z, base.z, (size_t)N * sizeof *mi.z);
      pl.z[v] += hh, mi.z[v] -= hh;
      if ((st = eval2(p, &pl, 0)) || (st = eval2(p, &mi, 0))) break;
      snprintf(name, sizeof name, "%s[%d]", v < n ? "Fy" : v < 2 * n ? "Fp" : "Fq", v % n);
      consider(rep, k, name, base.g[v], (pl.F[0] - mi.F[0]) / (2 * hh));
      for (int r = 0; r < N; r++) {
        double an = hess_entry(&base, r, v, name, sizeof name);
        consider(rep, k, name, an, (pl.g[r] - mi.g[r]) / (2 * hh));
      }
    }
  }
  cv_free(buf);
  return st;
}
