/* src/core/cv_contact.c — the contact set of an inequality constraint in the last solve:
 * runs of active nodes, their ends placed between nodes from the gap (theory OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* OB-4 (two nodes): the end of a contact run whose outermost active node is xa, next to
 * the free node xo (gap go > 0), from the gap at the next free node xoo (goo). A path that
 * leaves a smooth obstacle does so with its first derivative continuous (a first-order
 * integrand: the gap grows like C (x - x0)^2) or, for a second-order integrand on C^1
 * elements, with its second derivative continuous too (like C |x - x0|^3): gap^(1/k),
 * k = 2 or 3, is linear in x near x0, and x0 is its zero. Used when the free side has too
 * few nodes for the fit below. Without a usable second free node: xa. */
static double contact_end2(double xa, double xo, double go, double xoo, double goo, double k) {
  if (!(go > 0) || !(goo > go) || !isfinite(xoo)) return xa;
  double so = pow(go, 1.0 / k), soo = pow(goo, 1.0 / k);
  return xo - so * (xoo - xo) / (soo - so);
}

/* LAPACK's least-squares solver (Fortran calling convention, as in mech_dense.c). */
void dgels_(const char *trans, const int *m, const int *n, const int *nrhs, double *a,
            const int *lda, double *b, const int *ldb, double *work, const int *lwork, int *info);

enum { FIT_MAXN = 500, FIT_MAXM = 8 };

/* x0 from the polynomial of degree m fitted by least squares to the gap at the n free
 * nodes x[1..n] (x[0] = xa, the outermost active node; gap at the same offsets), in
 * t = (x - xa) / L, L = |x[n] - xa|: the zero of its (k-1)-th derivative nearest xa, by
 * Newton from t = 0. NAN when the fit or Newton fails. w: (n + 1) (m + 2) + 64 doubles. */
static double fit_root(const double *x, const double *gap, int n, int m, int k, double *w) {
  int rows = n, cols = m + 1, one = 1, lw = 64, info = 0;
  double xa = x[0], L = x[n] - xa, *A = w, *b = A + (size_t)rows * cols, *wk = b + rows;
  for (int i = 0; i < rows; i++) {
    double t = (x[i + 1] - xa) / L, tp = 1.0;
    for (int c = 0; c < cols; c++, tp *= t) A[(size_t)c * rows + i] = tp;
    b[i] = gap[i + 1];
  }
  dgels_("N", &rows, &cols, &one, A, &rows, b, &rows, wk, &lw, &info);
  if (info) return NAN;
  /* the (k-1)-th and k-th derivatives of sum b_c t^c at t */
  double t = 0.0;
  for (int it = 0; it < 40; it++) {
    double p = 0.0, dp = 0.0;
    for (int c = m; c >= k - 1; c--) {
      double f = 1.0; /* c! / (c - k + 1)! */
      for (int q = 0; q < k - 1; q++) f *= c - q;
      dp = dp * t + p;
      p = p * t + f * b[c];
    }
    /* p = P^(k-1)(t) by Horner on the shifted coefficients; dp its derivative */
    if (!(fabs(dp) > 0)) return NAN;
    double dt = p / dp;
    t -= dt;
    if (!isfinite(t) || fabs(t) > 4.0) return NAN;
    if (fabs(dt) <= 1e-15 * (1.0 + fabs(t))) return xa + t * L;
  }
  return NAN;
}

/* OB-4: the end of a contact run. xs[0] is the run's outermost active node, xs[1..nf] the
 * free nodes beyond it (in order away from the run), g the gap at the same nodes, xin the
 * next active node inwards. The free path is smooth up to x0, where the gap has a zero of
 * order k (k = 2, or 3 for a second-order integrand on C^1 elements): x0 is the zero of
 * the (k-1)-th derivative of a polynomial fitted to the gap at the free nodes nearest the
 * run. The fit has two errors that pull opposite ways: the path's error, divided by the
 * window's width, and the polynomial's, which grows with it; among degrees k..8 and
 * windows of widths growing by sqrt(2), the estimate is the one that changed least from
 * the next smaller window. Kept between the first free node and xin (the outermost active
 * node may lie just outside the true contact, its gap below the solve's accuracy). */
static double contact_end(const double *xs, const double *g, int nf, double xin, double k,
                          double *w) {
  double xa = xs[0], xo = nf >= 1 ? xs[1] : NAN;
  if (nf < 1) return xa;
  double x0 = contact_end2(xa, xo, g[1], nf >= 2 ? xs[2] : NAN, nf >= 2 ? g[2] : NAN, k);
  /* the windows: every distinct node count within L of xa, L = the farthest free node's
   * distance divided by sqrt(2) repeatedly (the nodes are graded towards the end, so
   * counts growing by a fixed factor would jump from the graded nodes to far ones) */
  int nw = 0, ns[128];
  double L = fabs(xs[nf] - xa), d1 = fabs(xo - xa);
  for (int n = nf; L >= d1 && nw < 128; L *= 0.70710678118654752) { /* 1/sqrt(2) */
    while (n > 0 && fabs(xs[n] - xa) > L) n--;
    if (n && (!nw || ns[nw - 1] != n)) ns[nw++] = n;
  }
  double best = INFINITY;
  for (int m = (int)k; m <= FIT_MAXM && w; m += m < 6 ? 1 : 2) {
    double prev = NAN;
    for (int i = nw - 1; i >= 0; i--) {
      if (ns[i] < m + 3) continue;
      double e = fit_root(xs, g, ns[i], m, (int)k, w);
      if (isfinite(e) && isfinite(prev) && fabs(e - prev) < best) best = fabs(e - prev), x0 = e;
      prev = e;
    }
  }
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
  /* the free nodes beside a run's end, in order away from it, and the fit's workspace */
  double *buf =
      cv_malloc((2 * (FIT_MAXN + 1) + (size_t)(FIT_MAXN + 1) * (FIT_MAXM + 2) + 64) * sizeof *buf);
  double *xs = buf, *gs = buf ? buf + FIT_MAXN + 1 : NULL, *w = buf ? gs + FIT_MAXN + 1 : NULL;
  if (!buf) st = CVAR_ENOMEM;
  /* active: a node with a multiplier that is nonzero (an inactive row ends with lambda = 0
   * exactly) or, for a second-order problem, that sits on the obstacle (its multiplier is a
   * point load at each end of a contact arc and zero inside it). Not for a first-order one:
   * there the free nodes next to a contact end have gaps C (x - x0)^2 that can be below any
   * fixed threshold, and counting them in would move the end outwards by their spacing. */
  double gmax = 0.0, kexp = d->herm ? 3.0 : 2.0;
  for (long j = 0; j < N; j++) gmax = cv_fmax(gmax, fabs(gap[j]));
#define ACTIVE(j)                                                                                  \
  (cv_disc_lidx(d, (j), k) >= 0 &&                                                                 \
   (s->mult[(j)*d->nc + k] != 0.0 || (d->herm && fabs(gap[(j)]) <= 1e-12 * cv_fmax(gmax, 1.0))))
  for (long j = 0; j < N && !st;) {
    if (!ACTIVE(j)) {
      j++;
      continue;
    }
    long j1 = j;
    while (j1 + 1 < N && ACTIVE(j1 + 1)) j1++;
    double x0 = x[j], x1 = x[j1];
    for (int side = 0; side < 2; side++) {
      long ja = side ? j1 : j, dir = side ? 1 : -1, in = j1 > j ? ja - dir : ja;
      int nf = 0;
      xs[0] = x[ja], gs[0] = gap[ja];
      for (long i = ja + dir; i >= 0 && i < N && nf < FIT_MAXN && !ACTIVE(i); i += dir)
        ++nf, xs[nf] = x[i], gs[nf] = gap[i];
      double e = contact_end(xs, gs, nf, x[in], kexp, w);
      if (side)
        x1 = e;
      else
        x0 = e;
    }
    if (x0 > x1) x0 = x1 = 0.5 * (x0 + x1); /* ends fitted past each other: one point */
    if (*count < cap) iv[2 * *count] = x0, iv[2 * *count + 1] = x1;
    ++*count;
    j = j1 + 1;
  }
#undef ACTIVE
  cv_free(buf);
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
