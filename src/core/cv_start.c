/* src/core/cv_start.c — the start of a solve: discretisation of the current mesh spec,
 * starting values (given, guessed or the straight line) and singular-end detection.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* The default start at fraction t of the interval: the straight line between the end
 * values (a free end takes the other end's value; both free: 0). */
static void straight_line(const cv_problem *p, double t, double *y) {
  for (int i = 0; i < p->n; i++) {
    int fa = p->fixed[2 * i], fb = p->fixed[2 * i + 1];
    double ya = p->endval[2 * i], yb = p->endval[2 * i + 1];
    if (!fa) ya = fb ? yb : 0.0;
    if (!fb) yb = ya;
    y[i] = ya + (yb - ya) * t;
  }
}

/* Initial nodal values: user start, guess callback, or (always with line = 1) the
 * straight line. Fixed ends always win. */
cv_status cv_start_values(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y,
                          int line) {
  int n = p->n;
  if (s->start && !line) {
    if (s->start_len != d->ndof) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "start vector has %d values but the mesh has %d nodes x %d unknowns",
                 s->start_len, d->nodes, n);
      return CVAR_EINVAL;
    }
    memcpy(Y, s->start, (size_t)d->ndof * sizeof *Y);
  } else if (p->guess && !line) {
    double xb[CV_BATCH], *yb = cv_malloc((size_t)n * CV_BATCH * sizeof *yb);
    if (!yb) return CVAR_ENOMEM;
    for (long j0 = 0; j0 < d->nodes; j0 += CV_BATCH) {
      int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
      for (int k = 0; k < m; k++) xb[k] = cv_disc_node_x(d, j0 + k);
      int rc = p->guess(m, xb, yb, p->guess_user);
      for (int k = 0; k < m && rc == 0; k++)
        for (int i = 0; i < n; i++) {
          if (!isfinite(yb[i * m + k])) rc = 1;
          Y[(j0 + k) * n + i] = yb[i * m + k];
        }
      if (rc) {
        cv_free(yb);
        cv_set_msg(s->msg, sizeof s->msg,
                   "the initial guess is not finite (or its callback failed) near x = %g",
                   xb[0]);
        return CVAR_ECALLBACK;
      }
    }
    cv_free(yb);
  } else {
    /* node by node, element by element: no array of abscissae (a large solve faults in
     * every page it allocates, docs/performance.md) */
    double rl = 1.0 / (d->b - d->a);
    for (long e = 0; e < d->E; e++) {
      double x0 = d->xe[e], h = d->xe[e + 1] - x0;
      for (int l = 0; l < d->p; l++) {
        double x = l ? x0 + 0.5 * (d->ref.xi[l] + 1.0) * h : x0;
        straight_line(p, (x - d->a) * rl, Y + (e * d->p + l) * n);
      }
    }
    straight_line(p, 1.0, Y + (d->nodes - 1) * n);
    for (int i = 0; i < n; i++) { /* exactly, so that no blend below is needed */
      if (p->fixed[2 * i]) Y[i] = p->endval[2 * i];
      if (p->fixed[2 * i + 1]) Y[(d->nodes - 1) * n + i] = p->endval[2 * i + 1];
    }
  }
  /* A start or guess that misses the fixed end values is shifted onto them by a linear
   * blend, da (1 - t) + db t, rather than having its end nodes overwritten: a kink in the
   * end elements makes a poor Newton start (measured: a catenary warm-started from its
   * neighbour in a continuation diverged with the end nodes overwritten). */
  long last = d->nodes - 1;
  for (int i = 0; i < n; i++) {
    double da = p->fixed[2 * i] ? p->endval[2 * i] - Y[i] : 0.0;
    double db = p->fixed[2 * i + 1] ? p->endval[2 * i + 1] - Y[last * n + i] : 0.0;
    if (da == 0.0 && db == 0.0) continue;
    for (long j = 0; j <= last; j++) {
      double t = (cv_disc_node_x(d, j) - d->a) / (d->b - d->a);
      Y[j * n + i] += da * (1.0 - t) + db * t;
    }
    if (p->fixed[2 * i]) Y[i] = p->endval[2 * i];
    if (p->fixed[2 * i + 1]) Y[last * n + i] = p->endval[2 * i + 1];
  }
  return CVAR_OK;
}

/* An end where F itself is not finite at the end value (the brachistochrone's 1/sqrt(y) at
 * y = 0) gets the singular-end rule on its element; Gauss points avoid the end, but a
 * fixed Gauss rule under-integrates there and the discrete minimiser exploits it. */
static void detect_singular_ends(const cv_problem *p, cv_disc *d, const double *Y) {
  int n = p->n;
  double x, *buf = cv_malloc((2 * (size_t)n + 1) * sizeof *buf);
  if (!buf) return;
  for (int end = 0; end < 2; end++) {
    long node = end ? d->nodes - 1 : 0;
    long e = end ? d->E - 1 : 0;
    double h = d->xe[e + 1] - d->xe[e], phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
    cv_lagrange(d->p, d->ref.xi, end ? 1.0 : -1.0, phi, dphi);
    for (int i = 0; i < n; i++) {
      double dv = 0.0;
      for (int l = 0; l <= d->p; l++) dv += Y[(e * d->p + l) * n + i] * dphi[l];
      buf[i] = Y[node * n + i];
      buf[n + i] = dv * 2.0 / h;
    }
    x = end ? d->b : d->a;
    cv_partials o = {buf + 2 * n, NULL, NULL, NULL, NULL, NULL};
    int rc = p->F(1, &x, buf, buf + n, CVAR_NEED_F, &o, p->user);
    /* infinite (or "cannot evaluate here"), not NaN: a NaN end is undefined, not singular */
    int singular = rc > 0 || (rc == 0 && isinf(o.F[0]));
    if (end) d->sing_b = singular;
    else d->sing_a = singular;
  }
  cv_free(buf);
}

/* Discretisation, starting values and singular-end detection for the current mesh spec. */
cv_status cv_start_setup(cv_solver *s, const cv_problem *p) {
  cv_status st;
  cv_free(s->y);
  cv_free(s->mult);
  s->y = s->mult = NULL;
  cv_disc_free(&s->disc);
  s->have = 0;
  st = cv_disc_init(&s->disc, p, s, s->msg, sizeof s->msg);
  if (st) {
    if (st == CVAR_ENOMEM) cv_set_msg(s->msg, sizeof s->msg, "out of memory building the mesh");
    return st;
  }
  s->y = cv_malloc((size_t)s->disc.ndof * sizeof *s->y);
  s->mult = cv_calloc((size_t)s->disc.nodes * p->nc + p->ni + 1, sizeof *s->mult);
  if (!s->y || !s->mult) {
    cv_set_msg(s->msg, sizeof s->msg, "out of memory for %d nodal values", s->disc.ndof);
    return CVAR_ENOMEM;
  }
  st = cv_start_values(s, p, &s->disc, s->y, 0);
  if (st) return st;
  s->have = 1;
  detect_singular_ends(p, &s->disc, s->y);
  st = cv_disc_build_singular_rules(&s->disc);
  if (st) cv_set_msg(s->msg, sizeof s->msg, "out of memory for the singular-end quadrature");
  return st;
}
