/* src/scene/scene_singular.c — an integrand singular inside the interval (theory (SG-1)).
 * SPDX-License-Identifier: MIT
 *
 * The quadrature never evaluates F at an interior point where a denominator vanishes, so a
 * non-integrable singularity there (y'^2 + y^2/(x - 0.5)) gives a finite discrete action
 * that depends on the mesh, and Newton "converges" to a path of an action that diverges.
 * Candidates: the parts of F that depend on x alone and are divided by, taken the log of,
 * or raised to a negative constant power; a zero of one strictly inside (a, b) (a sign
 * change or an exact zero on a fine grid, then bisection) is a singular point x*. Along
 * the solution, F is then sampled at x* +- d for d = 1e-3 and 1e-5 (times b - a): growth
 * like |x - x*|^(-alpha) with alpha >= 0.85 (a ratio >= 50 over the factor 100) means the
 * action diverges there.
 *
 * A pole that the syntax does not show (tan(pi x), 1/cos, a table, a callback) is found
 * from the values (scene_interior_singularity only, the command's `solve`): |F| along the
 * solution on the same grid, its largest interior value narrowed by zooming in (64 samples
 * between the neighbours of the largest, six times), then the same growth test there. A
 * smooth peak (a boundary layer) is flat near its top and grows by a factor near 1, far
 * below 50; y'^2 + y^2 tan(pi x) on [0, 1] grows like |x - 1/2|^(-1) and is caught.
 */
#include <float.h>
#include <math.h>

#include "scene/scene_internal.h"

enum { GRID = 4096 };

/* Depends on the variable x (slot 0) and on no unknown or derivative. */
static int x_only(const scene *s, ex_id e) {
  if (!ex_depends_on(s->dag, e, 0)) return 0;
  for (int k = 1; k <= 2 * s->n; k++)
    if (ex_depends_on(s->dag, e, k)) return 0;
  return 1;
}

static double eval_at(const scene *s, ex_id e, double x) {
  double v = NAN;
  if (sc_eval_exprs(s, 1, &e, 1, &x, NULL, NULL, &v) < 0) return NAN;
  return v;
}

/* A zero of e (x only) strictly inside (a, b): 1 and *xs, else 0 (-1 out of memory). */
static int interior_zero(const scene *s, ex_id e, double *xs) {
  double a = s->a, b = s->b, h = (b - a) / GRID;
  double *x = cv_malloc((GRID + 1) * sizeof *x), *v = cv_malloc((GRID + 1) * sizeof *v);
  int found = 0;
  if (!x || !v) {
    found = -1;
    goto done;
  }
  for (int k = 0; k <= GRID; k++) x[k] = a + h * k;
  if (sc_eval_exprs(s, 1, &e, GRID + 1, x, NULL, NULL, v) < 0) {
    found = -1;
    goto done;
  }
  found = 0;
  for (int k = 1; k < GRID && !found; k++) {
    if (v[k] == 0) {
      *xs = x[k];
      found = 1;
    }
  }
  for (int k = 0; k < GRID && !found; k++) {
    if (!(v[k] * v[k + 1] < 0)) continue;
    double lo = x[k], hi = x[k + 1], flo = v[k];
    for (int it = 0; it < 80 && hi - lo > 4 * DBL_EPSILON * fabs(hi); it++) {
      double mid = 0.5 * (lo + hi), fm = eval_at(s, e, mid);
      if (!isfinite(fm) || fm == 0) {
        lo = hi = mid;
        break;
      }
      if ((fm < 0) == (flo < 0))
        lo = mid, flo = fm;
      else
        hi = mid;
    }
    double m = 0.5 * (lo + hi);
    if (m > a + 1e-9 * (b - a) && m < b - 1e-9 * (b - a)) {
      *xs = m;
      found = 1;
    }
  }
done:
  cv_free(x);
  cv_free(v);
  return found;
}

/* max |F| at x* - d and x* + d along the solution (NaN when it cannot be evaluated). */
static double f_near(const scene *s, cv_solver *sv, double xs, double d) {
  int n = s->n;
  double x[2] = {xs - d, xs + d}, out[2] = {NAN, NAN};
  double *y = cv_malloc((size_t)4 * n * sizeof *y), *dy = y ? y + 2 * n : NULL;
  int ok = y && cv_solver_eval(sv, 2, x, y, dy) == CVAR_OK &&
           sc_eval_exprs(s, 1, &s->F, 2, x, y, dy, out) == 0;
  cv_free(y);
  if (!ok) return NAN;
  if (isnan(out[0]) || isnan(out[1])) return INFINITY;
  return fabs(out[0]) > fabs(out[1]) ? fabs(out[0]) : fabs(out[1]);
}

int scene_singular_candidates(const scene *s, ex_id **cands) {
  ex_dag *d = s->dag;
  int N = s->F + 1, nc = 0;
  unsigned char *mark = cv_calloc((size_t)N, 1);
  ex_id *c = cv_malloc(((size_t)N + 1) * sizeof *c);
  *cands = NULL;
  if (!mark || !c) {
    cv_free(mark);
    cv_free(c);
    return -1;
  }
  mark[s->F] = 1;
  /* the nodes of F (children have smaller ids: one pass downwards) */
  for (ex_id e = s->F; e >= 0; e--) {
    if (!mark[e]) continue;
    for (int i = 0; i < 3; i++) {
      ex_id ch = ex_node_arg(d, e, i);
      if (ch >= 0 && ch < N) mark[ch] = 1;
    }
    ex_op op = ex_node_op(d, e);
    ex_id cand = -1;
    if (op == EX_DIV)
      cand = ex_node_arg(d, e, 1);
    else if (op == EX_LOG)
      cand = ex_node_arg(d, e, 0);
    else if (op == EX_POW && ex_node_op(d, ex_node_arg(d, e, 1)) == EX_NUM &&
             ex_node_value(d, ex_node_arg(d, e, 1)) < 0)
      cand = ex_node_arg(d, e, 0);
    if (cand >= 0 && x_only(s, cand)) c[nc++] = cand;
  }
  cv_free(mark);
  *cands = c;
  return nc;
}

int scene_interior_singularity_of(const scene *s, cv_solver *sv, int nc, const ex_id *cands,
                                  double *xs, double *alpha) {
  for (int k = 0; k < nc; k++) {
    double x0;
    int z = interior_zero(s, cands[k], &x0);
    if (z < 0) return -1;
    if (z == 0) continue;
    double L = s->b - s->a, g1 = f_near(s, sv, x0, 1e-3 * L), g2 = f_near(s, sv, x0, 1e-5 * L);
    if (isnan(g1) || isnan(g2)) continue;
    double al = g1 > 0 && isfinite(g2) ? log(g2 / g1) / log(100.0) : INFINITY;
    if (!(al < 0.85)) {
      *xs = x0;
      *alpha = al;
      return 1;
    }
  }
  return 0;
}

/* |F| along the solution at the npts points x (NaN where it cannot be evaluated: a pole
 * hit exactly is infinite). 0, or -1 out of memory. */
static int f_along(const scene *s, cv_solver *sv, int npts, const double *x, double *v) {
  int n = s->n;
  double *y = cv_malloc((size_t)2 * n * (size_t)npts * sizeof *y);
  int ok = y && cv_solver_eval(sv, npts, x, y, y + (size_t)n * npts) == CVAR_OK &&
           sc_eval_exprs(s, 1, &s->F, npts, x, y, y + (size_t)n * npts, v) == 0;
  cv_free(y);
  for (int k = 0; ok && k < npts; k++) v[k] = isnan(v[k]) ? INFINITY : fabs(v[k]);
  return ok ? 0 : -1;
}

/* Index of the largest of v[from..to] (the first). */
static int argmax(const double *v, int from, int to) {
  int best = from;
  for (int k = from + 1; k <= to; k++)
    if (v[k] > v[best]) best = k;
  return best;
}

/* Where |F| along the solution is largest strictly inside (a, b), narrowed down: 1 and *xs,
 * 0 when F cannot be evaluated along it, -1 out of memory. */
static int value_peak(const scene *s, cv_solver *sv, double *xs) {
  enum { ZOOM = 64 };
  double a = s->a, b = s->b, h = (b - a) / GRID;
  double *x = cv_malloc((GRID + 1) * sizeof *x), *v = cv_malloc((GRID + 1) * sizeof *v);
  int rc = x && v ? 0 : -1;
  for (int k = 0; rc == 0 && k <= GRID; k++) x[k] = a + h * k;
  if (rc == 0 && f_along(s, sv, GRID + 1, x, v) < 0) rc = -2;
  if (rc == 0) {
    int k = argmax(v, 1, GRID - 1);
    double lo = x[k - 1], hi = x[k + 1];
    for (int round = 0; round < 6 && rc == 0; round++) { /* ZOOM + 1 points in (lo, hi) */
      double step = (hi - lo) / ZOOM;
      for (int j = 0; j <= ZOOM; j++) x[j] = lo + step * j;
      if (f_along(s, sv, ZOOM + 1, x, v) < 0) rc = -2;
      int j = rc == 0 ? argmax(v, 0, ZOOM) : 0;
      lo = x[j > 0 ? j - 1 : 0], hi = x[j < ZOOM ? j + 1 : ZOOM];
      *xs = x[j];
    }
    if (rc == 0) rc = *xs > a + 1e-9 * (b - a) && *xs < b - 1e-9 * (b - a);
  }
  cv_free(x);
  cv_free(v);
  return rc == -2 ? 0 : rc;
}

int scene_interior_singularity(const scene *s, cv_solver *sv, double *xs, double *alpha) {
  ex_id *c = NULL;
  int nc = scene_singular_candidates(s, &c);
  int rc = nc < 0 ? -1 : scene_interior_singularity_of(s, sv, nc, c, xs, alpha);
  cv_free(c);
  if (rc != 0) return rc;
  /* the value scan evaluates F(x, y, y') along the path: not for a second-order integrand,
   * whose F needs y'' too (C1 scenes have only the poles the syntax shows) */
  if (s->c1) return 0;
  double x0; /* no pole the syntax shows: look for one in the values */
  int z = value_peak(s, sv, &x0);
  if (z <= 0) return z;
  double L = s->b - s->a, g1 = f_near(s, sv, x0, 1e-3 * L), g2 = f_near(s, sv, x0, 1e-5 * L);
  if (isnan(g1) || isnan(g2)) return 0;
  double al = g1 > 0 && isfinite(g2) ? log(g2 / g1) / log(100.0) : INFINITY;
  if (!(al < 0.85)) {
    *xs = x0;
    *alpha = al;
    return 1;
  }
  return 0;
}
