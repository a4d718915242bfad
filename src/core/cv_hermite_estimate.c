/* src/core/cv_hermite_estimate.c — the error estimate of a solve on C1 elements: an
 * enriched solve (degree + 2, or the elements halved at degree 7) warm-started from the
 * solution, and the largest difference at the solution's nodes (theory H-7).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>

#include "cv_hermite.h"

/* The enriched mesh of d (H-7): the same elements at node degree r + 1, or at the largest
 * degree each element halved. */
static cv_status enriched(const cv_disc *d, cv_solver *f, int *E) {
  int split = d->p >= CV_HERMITE_MAX_R, Ef = d->E * (split ? 2 : 1);
  double *t = cv_malloc((size_t)(Ef + 1) * sizeof *t), a = d->a, L = d->b - d->a;
  if (!t) return CVAR_ENOMEM;
  for (long e = 0, k = 0; e < d->E; e++) {
    t[k++] = (d->xe[e] - a) / L;
    if (split) t[k++] = (0.5 * (d->xe[e] + d->xe[e + 1]) - a) / L;
  }
  t[0] = 0.0, t[Ef] = 1.0;
  cv_status st = cv_solver_set_mesh(f, Ef, t);
  cv_free(t);
  if (!st) st = cv_solver_set_degree(f, 2 * (split ? d->p : d->p + 1) + 1);
  *E = Ef;
  return st;
}

/* f's start: s's values and slopes at f's nodes (node-major, 2n per node). */
cv_status cv_hermite_warm(cv_solver *f, const cv_problem *p, const cv_solver *s) {
  cv_disc d;
  char msg[160];
  cv_status st = cv_disc_init(&d, p, f, msg, sizeof msg);
  if (st) return st;
  int n = p->n, N = d.nodes;
  double *x = cv_malloc((size_t)N * sizeof *x), *y = cv_malloc(4 * (size_t)N * n * sizeof *y);
  if (!x || !y) st = CVAR_ENOMEM;
  if (!st) {
    double *ys = y + 2 * (size_t)N * n, *dys = ys + (size_t)N * n;
    cv_disc_fill_nodes(&d, x);
    st = cv_solver_eval(s, N, x, ys, dys);
    for (int j = 0; j < N && !st; j++)
      for (int i = 0; i < n; i++) {
        y[(size_t)j * 2 * n + 2 * i] = ys[(size_t)i * N + j];
        y[(size_t)j * 2 * n + 2 * i + 1] = dys[(size_t)i * N + j];
      }
    if (!st) st = cv_solver_set_start(f, 2 * N * n, y);
  }
  cv_free(x);
  cv_free(y);
  cv_disc_free(&d);
  return st;
}

/* max over s's nodes and points inside its elements of |y_s - y_f| (*ev: over the element
 * ends; eta[e], if not NULL, over element e's), and the largest |y_f|. */
static cv_status difference(const cv_solver *s, const cv_solver *f, int n, double *e, double *ev,
                            double *scale, double *eta) {
  const cv_disc *d = &s->disc;
  int N = d->nodes;
  double *x = cv_malloc((size_t)N * sizeof *x), *yf = cv_malloc((size_t)N * n * sizeof *yf);
  cv_status st = x && yf ? CVAR_OK : CVAR_ENOMEM;
  *e = *ev = *scale = 0.0;
  if (!st) {
    cv_disc_fill_nodes(d, x);
    st = cv_solver_eval(f, N, x, yf, NULL);
  }
  for (int j = 0; j < N && !st; j++)
    for (int i = 0; i < n; i++) {
      double v = yf[(size_t)i * N + j], dl = fabs(s->y[(size_t)j * 2 * n + 2 * i] - v);
      if (!(dl <= *e)) *e = dl;
      if (j % d->p == 0 && !(dl <= *ev)) *ev = dl;
      *scale = fmax(*scale, fabs(v));
      long el = j / d->p; /* the elements sharing node j */
      if (eta && el < d->E) eta[el] = fmax(eta[el], dl);
      if (eta && j % d->p == 0 && el > 0) eta[el - 1] = fmax(eta[el - 1], dl);
    }
  cv_free(x);
  cv_free(yf);
  /* H-7a: and at H7_SAMPLES points inside each element. The nodal values of a C^1 solution
   * can be exact where the path between them is not (a beam under a polynomial load: the
   * cubic elements' vertex values are the exact quartic's, the path between them is off by
   * h^4 / 384), and the report's path is drawn from the elements' polynomials */
  enum { H7_SAMPLES = 3 };
  long M = (long)d->E * H7_SAMPLES;
  x = cv_malloc((size_t)M * sizeof *x);
  double *ys = cv_malloc(2 * (size_t)M * n * sizeof *ys);
  if (!st && (!x || !ys)) st = CVAR_ENOMEM;
  for (long e0 = 0; e0 < d->E && !st; e0++)
    for (int k = 0; k < H7_SAMPLES; k++)
      x[e0 * H7_SAMPLES + k] =
          d->xe[e0] + (k + 1.0) / (H7_SAMPLES + 1.0) * (d->xe[e0 + 1] - d->xe[e0]);
  if (!st) st = cv_solver_eval(s, (int)M, x, ys, NULL);
  if (!st) st = cv_solver_eval(f, (int)M, x, ys + (size_t)M * n, NULL);
  for (long j = 0; j < M && !st; j++)
    for (int i = 0; i < n; i++) {
      double v = ys[(size_t)M * n + (size_t)i * M + j], dl = fabs(ys[(size_t)i * M + j] - v);
      if (!(dl <= *e)) *e = dl;
      *scale = fmax(*scale, fabs(v));
      if (eta) eta[j / H7_SAMPLES] = fmax(eta[j / H7_SAMPLES], dl);
    }
  cv_free(x);
  cv_free(ys);
  return st;
}

cv_status cv_hermite_estimate(const cv_solver *s, const cv_problem *p, cv_solver *f, double *est,
                              double *est_vertex, double *eta, char *msg, size_t len) {
  int Ef;
  double e, ev, scale;
  f->rtol = fmax(s->rtol, 1e-12), f->atol = fmax(s->atol, 1e-12), f->maxit = s->maxit;
  f->method = CVAR_METHOD_NEWTON, f->continuation = 0, f->adapt_tol = 0.0;
  cv_status st = enriched(&s->disc, f, &Ef);
  if (!st) st = cv_hermite_warm(f, p, s);
  if (st) {
    cv_set_msg(msg, len, "out of memory for the error estimate");
    return st;
  }
  st = cv_solve_mesh(f, p);
  cv_solver_set_start(f, 0, NULL);
  if (st) {
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate failed, so nothing confirms that this "
               "discrete path is near a stationary path of the integral (the enriched solve: %s)",
               f->msg);
    return st;
  }
  if (f->morse != s->morse) {
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate stopped on another stationary path "
               "(Morse index %d, this one %d): no error bound",
               f->morse, s->morse);
    return CVAR_EDIVERGED;
  }
  for (long k = 0; eta && k < s->disc.E; k++) eta[k] = 0.0;
  st = difference(s, f, p->n, &e, &ev, &scale, eta);
  if (st) return st;
  if (!isfinite(e) || (e > 0.5 * (scale > 0 ? scale : 1.0) && e > 1e-3)) {
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate moved %.2g from this path (of size "
               "%.2g): another stationary path or an unresolved mesh, no error bound",
               e, scale);
    return CVAR_EDIVERGED;
  }
  double ro = CV_ROUNDOFF_ULPS * DBL_EPSILON * fmax(scale, 1.0); /* as HP-2 */
  *est = fmax(e, ro);
  if (est_vertex) *est_vertex = fmax(ev, ro);
  return CVAR_OK;
}
