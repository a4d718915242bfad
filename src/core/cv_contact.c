/* src/core/cv_contact.c — the contact set of an inequality constraint in the last solve:
 * runs of active nodes, their ends placed between nodes from the gap (theory OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* OB-4: the end of a contact run whose outermost active node is xa, next to the free node
 * xo (gap go > 0), from the gap at the next free node xoo (goo). A path that leaves a smooth
 * obstacle does so with its first derivative continuous (a first-order integrand: the gap
 * grows like C (x - x0)^2) or, for a second-order integrand on C^1 elements, with its
 * second derivative continuous too (like C |x - x0|^3): gap^(1/k), k = 2 or 3, is linear in
 * x near x0, and x0 is its zero. The active node itself may lie just outside the true
 * contact (its gap is then below the solve's accuracy), so x0 is kept between xo and xin,
 * the next active node inwards (xa when there is none). Without a usable second free
 * node: xa. */
static double contact_end(double xa, double xin, double xo, double go, double xoo, double goo,
                          double k) {
  if (!(go > 0) || !(goo > go) || !isfinite(xoo)) return xa;
  double so = pow(go, 1.0 / k), soo = pow(goo, 1.0 / k);
  double x0 = xo - so * (xoo - xo) / (soo - so);
  double lo = xin < xo ? xin : xo, hi = xin < xo ? xo : xin;
  return x0 < lo ? lo : x0 > hi ? hi : x0;
}

/* s G_k at every node into gap (>= 0 where the constraint holds); with gn != NULL the
 * gap in units of the unknowns, gap / |grad G|, into gn. */
static cv_status node_gaps2(const cv_solver *s, const cv_problem *p, int k, const double *x,
                            double *gap, double *gn);
static cv_status node_gaps(const cv_solver *s, const cv_problem *p, int k, const double *x,
                           double *gap) {
  return node_gaps2(s, p, k, x, gap, NULL);
}

static cv_status node_gaps2(const cv_solver *s, const cv_problem *p, int k, const double *x,
                            double *gap, double *gn) {
  const cv_disc *d = &s->disc;
  int n = d->herm ? d->n / 2 : d->n, step = d->herm ? 2 : 1; /* C^1: values, not slopes */
  double *y = cv_malloc(2 * (size_t)n * CV_BATCH * sizeof *y), *gy = y + (size_t)n * CV_BATCH;
  if (!y) return CVAR_ENOMEM;
  const cv_pconstraint *c = &p->pc[k];
  cv_status st = CVAR_OK;
  unsigned need = CVAR_NEED_F | (gn ? CVAR_NEED_GRAD : 0u);
  for (long j0 = 0; j0 < d->nodes && !st; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int t = 0; t < m; t++)
      for (int i = 0; i < n; i++) y[i * m + t] = s->y[(j0 + t) * d->n + step * i];
    if (c->G(m, x + j0, y, need, gap + j0, gn ? gy : NULL, NULL, c->user)) st = CVAR_ENONFINITE;
    for (int t = 0; t < m; t++) {
      gap[j0 + t] *= c->sense;
      if (!gn) continue;
      double g2 = 0.0;
      for (int i = 0; i < n; i++) g2 += gy[i * m + t] * gy[i * m + t];
      gn[j0 + t] = g2 > 0 ? gap[j0 + t] / sqrt(g2) : INFINITY;
    }
  }
  cv_free(y);
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
  /* active: a node with a multiplier that is nonzero (an inactive row ends with lambda = 0
   * exactly) or that sits on the obstacle (a second-order problem's multiplier is a point
   * load at each end of a contact arc and zero inside it) */
  double gmax = 0.0, kexp = d->herm ? 3.0 : 2.0;
  for (long j = 0; j < N; j++) gmax = cv_fmax(gmax, fabs(gap[j]));
#define ACTIVE(j)                                                                                  \
  (cv_disc_lidx(d, (j), k) >= 0 &&                                                                 \
   (s->mult[(j)*d->nc + k] != 0.0 || fabs(gap[(j)]) <= 1e-12 * cv_fmax(gmax, 1.0)))
  for (long j = 0; j < N && !st;) {
    if (!ACTIVE(j)) {
      j++;
      continue;
    }
    long j1 = j;
    while (j1 + 1 < N && ACTIVE(j1 + 1)) j1++;
    double xs = x[j], xe = x[j1];
    if (j >= 1)
      xs = contact_end(x[j], x[j1 > j ? j + 1 : j], x[j - 1], gap[j - 1], j >= 2 ? x[j - 2] : NAN,
                       j >= 2 ? gap[j - 2] : NAN, kexp);
    if (j1 + 1 < N)
      xe = contact_end(x[j1], x[j1 > j ? j1 - 1 : j1], x[j1 + 1], gap[j1 + 1],
                       j1 + 2 < N ? x[j1 + 2] : NAN, j1 + 2 < N ? gap[j1 + 2] : NAN, kexp);
    if (*count < cap) iv[2 * *count] = xs, iv[2 * *count + 1] = xe;
    ++*count;
    j = j1 + 1;
  }
#undef ACTIVE
  cv_free(x);
  return st;
}

/* OB-8: what the error estimate of a solve with obstacles cannot see. The enriched solve
 * of HP-2 puts its contact ends at or next to the same nodes, so a contact end misplaced
 * by up to the spacing d of the nodes next to it moves both solves alike; the path's error
 * from it is of the order of the gap C d^2 (C d^3 on C^1 elements) that the first free node
 * beside each contact run keeps. Returns the largest such gap, in units of the unknowns
 * (gap / |grad G|), and (eta not NULL) raises the indicator of the elements on either side
 * of that node to it, so that --tol refines there. */
double cv_contact_gap_term(const cv_solver *s, const cv_problem *p, double *eta) {
  const cv_disc *d = &s->disc;
  long N = d->nodes;
  double term = 0.0;
  double *x = cv_malloc(3 * (size_t)N * sizeof *x), *gap = x + N, *gn = gap + N;
  if (!x) return INFINITY;
  cv_disc_fill_nodes(d, x);
  for (int k = 0; k < p->nc; k++) {
    if (!p->pc[k].sense || node_gaps2(s, p, k, x, gap, gn)) continue;
    for (long j = 1; j < N; j++) {
      int act = s->mult[j * d->nc + k] != 0.0, prev = s->mult[(j - 1) * d->nc + k] != 0.0;
      if (act == prev || cv_disc_lidx(d, j, k) < 0 || cv_disc_lidx(d, j - 1, k) < 0) continue;
      long free_node = act ? j - 1 : j; /* the free node beside a run's end */
      double t = gn[free_node] > 0 ? gn[free_node] : 0.0;
      term = cv_fmax(term, t);
      if (!eta) continue;
      long e0 = cv_disc_node_elem(d, j - 1), e1 = cv_disc_node_elem(d, j);
      eta[e0] = cv_fmax(eta[e0], t);
      eta[e1] = cv_fmax(eta[e1], t);
    }
  }
  cv_free(x);
  return term;
}
