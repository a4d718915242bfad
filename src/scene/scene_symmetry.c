/* src/scene/scene_symmetry.c — continuous symmetries of a closed-path scene that leave its
 * Hessian singular besides the shift: translations of the periodic unknowns, found from
 * the integrand's gradient, named with the [integrals] line that pins each (theory PB-3).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mech/mech.h"
#include "scene/scene_internal.h"

enum { SAMPLES = 48 };

/* A deterministic spread in [-1, 1]: the samples are the same on every run. */
static double spread(unsigned *state) {
  *state = *state * 1103515245u + 12345u;
  return ((*state >> 8) & 0xffff) / 32767.5 - 1.0;
}

/* The k directions (rows of V, n each) in reduced row echelon form, so that each names a
 * few unknowns with simple weights (x1 + x2 + x3) instead of a rotation of the basis. */
static void echelon(double *V, int k, int n) {
  int r = 0;
  for (int c = 0; c < n && r < k; c++) {
    int piv = r;
    for (int i = r + 1; i < k; i++)
      if (fabs(V[(size_t)i * n + c]) > fabs(V[(size_t)piv * n + c])) piv = i;
    double p = V[(size_t)piv * n + c];
    if (!(fabs(p) > 1e-8)) continue;
    for (int j = 0; j < n; j++) {
      double t = V[(size_t)r * n + j];
      V[(size_t)r * n + j] = V[(size_t)piv * n + j] / p;
      if (piv != r) V[(size_t)piv * n + j] = t;
    }
    for (int i = 0; i < k; i++) {
      double f = V[(size_t)i * n + c];
      if (i == r || f == 0.0) continue;
      for (int j = 0; j < n; j++) V[(size_t)i * n + j] -= f * V[(size_t)r * n + j];
    }
    r++;
  }
}

/* PB-3: y -> y + c v leaves F unchanged for every c exactly when sum_i v_i F_y_i = 0 at every
 * (x, y, y'): v is a null direction of the matrix of F_y at sample points (the [guess] at
 * 48 points of the interval, moved by up to 0.1 of its size, and slopes in [-1, 1]). Only
 * periodic unknowns can move so (a fixed end forbids it), and only without pointwise
 * constraints (which would have to be invariant as well). */
int scene_translations(const scene *s, char *out, size_t len) {
  int n = s->n, np = 0, idx[64], found = 0;
  out[0] = '\0';
  if (s->ncons > 0 || n > 64) return 0;
  for (int i = 0; i < n; i++)
    if (s->bc[i].periodic) idx[np++] = i;
  if (np == 0) return 0;
  ex_id outs[64];
  double *x = cv_malloc(SAMPLES * sizeof *x), *y = cv_malloc((size_t)n * SAMPLES * sizeof *y);
  double *dy = cv_malloc((size_t)n * SAMPLES * sizeof *dy);
  double *g = cv_malloc((size_t)np * SAMPLES * sizeof *g),
         *R = cv_malloc((size_t)np * SAMPLES * sizeof *R);
  double *V = cv_malloc((size_t)np * np * sizeof *V);
  if (!x || !y || !dy || !g || !R || !V) goto done;
  for (int k = 0; k < np; k++)
    if ((outs[k] = ex_diff(s->dag, s->F, 1 + idx[k])) < 0) goto done;
  unsigned state = 12345u;
  for (int j = 0; j < SAMPLES; j++) x[j] = s->a + (s->b - s->a) * (j + 0.5) / SAMPLES;
  for (int i = 0; i < n; i++) {
    double *yi = y + (size_t)i * SAMPLES;
    if (s->guess[i] < 0 || sc_eval_exprs(s, 1, &s->guess[i], SAMPLES, x, NULL, NULL, yi) < 0)
      for (int j = 0; j < SAMPLES; j++) yi[j] = 0.0;
    double size = 1.0;
    for (int j = 0; j < SAMPLES; j++) size = fmax(size, fabs(yi[j]));
    for (int j = 0; j < SAMPLES; j++) {
      yi[j] += 0.1 * size * spread(&state);
      dy[(size_t)i * SAMPLES + j] = spread(&state);
    }
  }
  if (sc_eval_exprs(s, np, outs, SAMPLES, x, y, dy, g) < 0) goto done;
  for (int j = 0; j < SAMPLES; j++)
    for (int k = 0; k < np; k++) R[(size_t)j * np + k] = g[(size_t)k * SAMPLES + j];
  for (int k = 0; k < np * SAMPLES; k++)
    if (!isfinite(R[k])) goto done;
  /* the eigenvalues of R^T R are known to eps times the largest: a null direction's is at
   * that round-off, every other at least ~1e-3 of the largest on these samples */
  found = mech_null_directions(np, SAMPLES, R, 1e-10, V);
  echelon(V, found, np);
  size_t used = 0;
  for (int d = 0; d < found && used + 120 < len; d++) {
    const double *v = V + (size_t)d * np;
    char term[200] = "", names[200] = "", weights[200] = "";
    size_t tl = 0, nl = 0, wl = 0;
    for (int k = 0; k < np; k++) {
      double c = v[k];
      if (fabs(c) < 1e-9) continue;
      const char *u = s->unknowns[idx[k]];
      int w = fabs(c - 1.0) < 1e-9
                  ? snprintf(term + tl, sizeof term - tl, "%s%s", tl ? " + " : "", u)
                  : snprintf(term + tl, sizeof term - tl, "%s%.6g*%s", tl ? " + " : "", c, u);
      if (w > 0 && (size_t)w < sizeof term - tl) tl += (size_t)w;
      w = snprintf(names + nl, sizeof names - nl, "%s%s", nl ? ", " : "", u);
      if (w > 0 && (size_t)w < sizeof names - nl) nl += (size_t)w;
      w = snprintf(weights + wl, sizeof weights - wl, "%s%.6g", wl ? ", " : "", c);
      if (w > 0 && (size_t)w < sizeof weights - wl) wl += (size_t)w;
    }
    int w = snprintf(out + used, len - used,
                     "%sthe translation (%s) += c (%s) leaves the action unchanged: pin it with "
                     "[integrals] t%d = %s, 0",
                     d ? "; " : "", names, weights, d + 1, term);
    if (w > 0 && (size_t)w < len - used) used += (size_t)w;
  }
done:
  cv_free(x), cv_free(y), cv_free(dy), cv_free(g), cv_free(R), cv_free(V);
  return found > 0 ? found : 0;
}
