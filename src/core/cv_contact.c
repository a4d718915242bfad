/* src/core/cv_contact.c — the contact set of an inequality constraint in the last solve:
 * runs of active nodes, their ends placed between nodes from the gap (theory OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* OB-4: the end of a contact run whose outermost active node is xa, next to the free node
 * xo (gap go > 0), from the gap at the next free node xoo (goo): a path that leaves a smooth
 * obstacle tangentially has a gap ~ C (x - x0)^2, so sqrt(gap) is linear in x; its zero.
 * The active node itself may lie just outside the true contact (its gap, ~ C (xa - x0)^2,
 * is then below the solve's tolerance), so x0 is kept between xo and xin, the next active
 * node inwards (xa when there is none). Without a usable second free node: xa. */
static double contact_end(double xa, double xin, double xo, double go, double xoo, double goo) {
  if (!(go > 0) || !(goo > go) || !isfinite(xoo)) return xa;
  double so = sqrt(go), soo = sqrt(goo);
  double x0 = xo - so * (xoo - xo) / (soo - so);
  double lo = xin < xo ? xin : xo, hi = xin < xo ? xo : xin;
  return x0 < lo ? lo : x0 > hi ? hi : x0;
}

/* s G_k at every node into gap (>= 0 where the constraint holds). */
static cv_status node_gaps(const cv_solver *s, const cv_problem *p, int k, const double *x,
                           double *gap) {
  const cv_disc *d = &s->disc;
  int n = d->n;
  double yb[CV_BATCH * 8], *y = n <= 8 ? yb : cv_malloc((size_t)n * CV_BATCH * sizeof *y);
  if (!y) return CVAR_ENOMEM;
  const cv_pconstraint *c = &p->pc[k];
  cv_status st = CVAR_OK;
  for (long j0 = 0; j0 < d->nodes && !st; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int t = 0; t < m; t++)
      for (int i = 0; i < n; i++) y[i * m + t] = s->y[(j0 + t) * n + i];
    if (c->G(m, x + j0, y, CVAR_NEED_F, gap + j0, NULL, NULL, c->user)) st = CVAR_ENONFINITE;
    for (int t = 0; t < m; t++) gap[j0 + t] *= c->sense;
  }
  if (y != yb) cv_free(y);
  return st;
}

cv_status cv_solver_get_contact(const cv_solver *s, const cv_problem *p, int k, double *iv, int cap,
                                int *count) {
  if (!s || !p || !count || k < 0 || k >= p->nc || (cap > 0 && !iv)) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  *count = 0;
  if (!p->pc[k].sense) return CVAR_EINVAL;
  const cv_disc *d = &s->disc;
  long N = d->nodes;
  double *x = cv_malloc(2 * (size_t)N * sizeof *x), *gap = x + N;
  if (!x) return CVAR_ENOMEM;
  cv_disc_fill_nodes(d, x);
  cv_status st = node_gaps(s, p, k, x, gap);
  /* active: a nonzero multiplier (an inactive row ends with lambda = 0 exactly) */
  for (long j = 0; j < N && !st;) {
    double lj = s->mult[j * d->nc + k];
    if (lj == 0.0 || cv_disc_lidx(d, j, k) < 0) {
      j++;
      continue;
    }
    long j1 = j;
    while (j1 + 1 < N && s->mult[(j1 + 1) * d->nc + k] != 0.0) j1++;
    double xs = x[j], xe = x[j1];
    if (j >= 1)
      xs = contact_end(x[j], x[j1 > j ? j + 1 : j], x[j - 1], gap[j - 1], j >= 2 ? x[j - 2] : NAN,
                       j >= 2 ? gap[j - 2] : NAN);
    if (j1 + 1 < N)
      xe = contact_end(x[j1], x[j1 > j ? j1 - 1 : j1], x[j1 + 1], gap[j1 + 1],
                       j1 + 2 < N ? x[j1 + 2] : NAN, j1 + 2 < N ? gap[j1 + 2] : NAN);
    if (*count < cap) iv[2 * *count] = xs, iv[2 * *count + 1] = xe;
    ++*count;
    j = j1 + 1;
  }
  cv_free(x);
  return st;
}
