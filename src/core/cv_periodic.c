/* src/core/cv_periodic.c — periodic unknowns: y(b) = y(a) + D as the linear integral
 * constraint  int_a^b y' dx = D  on an unknown with both ends free, theory (PB-1).
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "cv_internal.h"

typedef struct {
  int k, n;
} periodic_user;

/* K = y_k': value y_k', gradient e_k in y', every second partial zero. */
static int periodic_K(int m, const double *x, const double *y, const double *dy, unsigned need,
                      cv_partials *out, void *user) {
  const periodic_user *u = user;
  int n = u->n, k = u->k;
  (void)x, (void)y;
  if (need & CVAR_NEED_F)
    for (int t = 0; t < m; t++) out->F[t] = dy[(size_t)k * m + t];
  if (need & CVAR_NEED_GRAD) {
    cv_dzero(out->Fy, (size_t)n * m);
    cv_dzero(out->Fp, (size_t)n * m);
    for (int t = 0; t < m; t++) out->Fp[(size_t)k * m + t] = 1.0;
  }
  if (need & CVAR_NEED_HESS) {
    size_t nn = (size_t)n * n * m;
    cv_dzero(out->Fyy, nn);
    cv_dzero(out->Fyp, nn);
    cv_dzero(out->Fpp, nn);
  }
  return 0;
}

static void periodic_release(void *user) { cv_free(user); }

/* PB-1: with both ends of y_k free, the multiplier mu of  int y_k' dx = D  enters the
 * natural conditions as F_y'(a) + mu = 0 = F_y'(b) + mu: the momenta at the two ends are
 * equal, the condition of a closed (or rotating) path. */
cv_status cv_problem_set_periodic(cv_problem *p, int k, double D, int *index) {
  if (!p || k < 0 || k >= p->n || !(D == D) || D - D != 0.0) return CVAR_EINVAL;
  periodic_user *u = cv_malloc(sizeof *u);
  if (!u) return CVAR_ENOMEM;
  u->k = k;
  u->n = p->n;
  cv_status st = cv_problem_set_free_end(p, k, 0);
  if (!st) st = cv_problem_set_free_end(p, k, 1);
  if (st) {
    cv_free(u);
    return st;
  }
  return cv_problem_add_integral_owned(p, periodic_K, u, periodic_release, D, index);
}
