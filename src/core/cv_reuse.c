/* src/core/cv_reuse.c — the mesh a --tol solve hands to the next problem of a batch
 * (theory HP-9): its own final mesh, or a coarser one when that one is finer than the
 * tolerance needs, laid by the pilot's rule (HP-7a) from the solution's own Legendre tails.
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_internal.h"
#include "cv_reuse.h"

/* HP-7a's trusted rate (PILOT_RATE8); the aim is the pilot's (cv_pilot_aim: HP-7a's
 * PILOT_AIM8, a tail at 10 tol giving a nodal error of 0.04 .. 0.7 tol on degree 8, or
 * what HP-7b learnt), and the next row's pilot treats only a tail above it as a miss */
#define REUSE_RATE 0.75
/* An element whose tail is far below the aim still counts as this share of one element
 * (the h^9 rule would merge it with many neighbours, which its rate does not promise). */
#define REUSE_MIN_SHARE 0.125

/* HP-9: pieces r_e = max(1/8, (tail_e / (AIM tol))^(1/9)) of each element and their total,
 * or -1 when the solution does not allow coarsening (an element not of degree 8, not
 * smooth, or a singular end or breakpoint to keep). */
static double shares(const cv_solver *s, double *r) {
  const cv_disc *d = &s->disc;
  double tol = s->adapt_tol, total = 0.0, aim = cv_pilot_aim(s);
  if (!s->hp || !(tol > 0) || d->sing_a || d->sing_b || s->mesh.nbreak > 0) return -1.0;
  for (long e = 0; e < d->E; e++)
    if (cv_disc_edeg(d, e) != CV_MAX_DEGREE) return -1.0;
  double *sigma = cv_malloc((size_t)d->E * sizeof *sigma);
  if (!sigma) return -1.0;
  cv_estimate_pilot(s, r, sigma);
  for (long e = 0; e < d->E && total >= 0; e++) {
    if (!(sigma[e] >= REUSE_RATE) || !isfinite(r[e])) {
      total = -1.0;
      break;
    }
    r[e] = fmax(REUSE_MIN_SHARE, pow(r[e] / (aim * tol), 1.0 / (CV_MAX_DEGREE + 1)));
    total += r[e];
  }
  cv_free(sigma);
  return total;
}

/* M degree-8 elements, boundary k where the cumulative share reaches k total / M (r_e
 * spread evenly over element e, HP-7a). Returns the elements laid (fewer when round-off
 * leaves no room). */
static int lay(const cv_disc *d, const double *r, double total, int M, double *t, int *deg) {
  double a = d->xe[0], L = d->xe[d->E] - a, cum = 0.0;
  int k = 1;
  t[0] = 0.0;
  for (long e = 0; e < d->E && k < M; e++) {
    double t0 = (d->xe[e] - a) / L, t1 = (d->xe[e + 1] - a) / L;
    while (k < M && cum + r[e] >= total * k / M) {
      double u = t0 + (t1 - t0) * (total * k / M - cum) / r[e];
      if (!(u > t[k - 1] && u < 1.0)) break;
      t[k++] = u;
    }
    cum += r[e];
  }
  t[k] = 1.0;
  for (int j = 0; j < k; j++) deg[j] = CV_MAX_DEGREE;
  return k;
}

/* s's solution at the nodes of the mesh (E, t, deg) on s's interval, node-major. */
static cv_status values_at(const cv_solver *s, int E, const double *t, const int *deg, double **y) {
  const cv_disc *d = &s->disc;
  int n = d->n, m = 1;
  for (int e = 0; e < E; e++) m += deg[e];
  double a = d->xe[0], L = d->xe[d->E] - a, xi[CV_MAX_DEGREE + 1], w[CV_MAX_DEGREE + 1];
  double *x = cv_malloc((size_t)m * sizeof *x), *v = cv_malloc((size_t)m * n * sizeof *v);
  *y = cv_malloc((size_t)m * n * sizeof **y);
  cv_status st = x && v && *y ? CVAR_OK : CVAR_ENOMEM;
  for (int e = 0, j = 0; e < E && !st; e++) {
    cv_gauss_lobatto(deg[e], xi, w);
    for (int l = 0; l < deg[e]; l++, j++)
      x[j] = a + L * (t[e] + 0.5 * (t[e + 1] - t[e]) * (xi[l] + 1.0));
  }
  if (!st) {
    x[0] = a, x[m - 1] = d->xe[d->E];
    st = cv_solver_eval(s, m, x, v, NULL);
  }
  for (int j = 0; j < m && !st; j++)
    for (int i = 0; i < n; i++) (*y)[(size_t)j * n + i] = v[(size_t)i * m + j];
  cv_free(x);
  cv_free(v);
  if (st) {
    cv_free(*y);
    *y = NULL;
  }
  return st;
}

void cv_reuse_node_fractions(int E, const double *t, const int *deg, double *u) {
  double xi[CV_MAX_DEGREE + 1], w[CV_MAX_DEGREE + 1];
  int j = 0;
  for (int e = 0; e < E; e++) {
    cv_gauss_lobatto(deg[e], xi, w);
    for (int l = 0; l < deg[e]; l++) u[j++] = t[e] + 0.5 * (t[e + 1] - t[e]) * (xi[l] + 1.0);
  }
  u[0] = 0.0, u[j] = 1.0;
}

cv_status cv_reuse_set_start(cv_solver *s, int E, const double *t, const int *deg) {
  cv_status st = cv_solver_set_mesh_hp(s, E, t, deg);
  if (s) s->handed_on = st == CVAR_OK;
  return st;
}

cv_status cv_reuse_mesh(const cv_solver *s, int *E, double **t, int **deg, double **y,
                        int *coarsened) {
  if (!s || !E || !t || !deg || !coarsened) return CVAR_EINVAL;
  *t = NULL, *deg = NULL, *coarsened = 0;
  if (y) *y = NULL;
  const cv_disc *d = &s->disc;
  if (!s->have || s->status != CVAR_OK || d->E < 1) return CVAR_ESTATE;
  int E0 = (int)d->E, M = E0;
  double *r = cv_malloc((size_t)E0 * sizeof *r);
  if (!r) return CVAR_ENOMEM;
  double total = E0 > 2 ? shares(s, r) : -1.0;
  if (total > 0) {
    double Mr = ceil(total - 1e-9);
    M = Mr < 2 ? 2 : Mr < E0 ? (int)Mr : E0;
  }
  *t = cv_malloc((size_t)(E0 + 1) * sizeof **t);
  *deg = cv_malloc((size_t)E0 * sizeof **deg);
  cv_status st = *t && *deg ? CVAR_OK : CVAR_ENOMEM;
  if (!st && M < E0) {
    *E = lay(d, r, total, M, *t, *deg);
    *coarsened = 1;
  } else if (!st) {
    double a = d->xe[0], L = d->xe[E0] - a;
    for (int e = 0; e <= E0; e++) (*t)[e] = (d->xe[e] - a) / L;
    (*t)[0] = 0.0, (*t)[E0] = 1.0;
    for (int e = 0; e < E0; e++) (*deg)[e] = cv_disc_edeg(d, e);
    *E = E0;
  }
  if (!st && y) st = values_at(s, *E, *t, *deg, y);
  cv_free(r);
  if (st) {
    cv_free(*t);
    cv_free(*deg);
    *t = NULL, *deg = NULL;
  }
  return st;
}
