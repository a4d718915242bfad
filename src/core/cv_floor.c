/* src/core/cv_floor.c — the round-off floor of the scaled residual, theory (N-3a).
 * SPDX-License-Identifier: MIT
 *
 * Newton stops on the step (N-4), and at convergence the scaled residual g/m (N-3) is
 * whatever round-off leaves of sums whose terms cancel. How large that is has two parts:
 * the rounding of the unknowns (eps sum_j |K_fj| |x_j|, computed by cv_newton.c from the
 * matrix it already holds, s->gfloor) and the rounding of the terms summed into g_f
 * (eps sum over points |w F_y phi_f| + |w F_y' phi_f'|), computed here on demand: one
 * evaluation of the integrand's gradient at the quadrature points, a fraction of a solve,
 * paid only by callers who ask (the report), not by every solve. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* acc[f] += sum over the points of f's elements of |w F_y phi_f| + |w F_y' phi_f'| (the
 * terms of the gradient's sum, A-2) for the integrand F of p. */
static cv_status term_sums(const cv_problem *p, const cv_disc *d, const double *Y, double *acc) {
  cv_assembler as;
  cv_status st = cv_assembler_init(&as, p, d);
  if (st) return st;
  int n = d->n;
  for (int e0 = 0, ne; e0 < d->E && !st; e0 += ne) {
    cv_rule rule = cv_disc_rule(d, e0), *r = &rule;
    int P1 = cv_disc_edeg(d, e0) + 1, q = r->q;
    ne = cv_assembler_batch(d, e0, q);
    int m = ne * q;
    cv_assembler_points(&as, Y, r, e0, ne); /* the points cv_assemble evaluates F at */
    cv_partials o = {as.out.F, as.out.Fy, as.out.Fp, NULL, NULL, NULL};
    int rc = p->F(m, as.x, as.y, as.dy, CVAR_NEED_F | CVAR_NEED_GRAD, &o, p->user);
    if (rc != 0) {
      st = rc < 0 ? CVAR_ECALLBACK : CVAR_ENONFINITE;
      break;
    }
    for (int el = 0; el < ne; el++) {
      int e = e0 + el;
      double h = d->xe[e + 1] - d->xe[e], J = 0.5 * h, rh = 2.0 / h;
      long g0 = cv_disc_enode(d, e) * n;
      for (int k = 0; k < q; k++) {
        int idx = el * q + k;
        double wk = fabs(J * r->omega[k]);
        for (int i = 0; i < n; i++) {
          double fy = wk * fabs(o.Fy[i * m + idx]), fp = wk * rh * fabs(o.Fp[i * m + idx]);
          for (int l = 0; l < P1; l++) {
            int f = cv_disc_fidx(d, g0 + (long)l * n + i);
            if (f >= 0) acc[f] += fy * fabs(r->B[k * P1 + l]) + fp * fabs(r->D[k * P1 + l]);
          }
        }
      }
    }
  }
  cv_assembler_free(&as);
  return st;
}

cv_status cv_solver_residual_floor(const cv_solver *s, const cv_problem *p, double *floor) {
  if (floor) *floor = NAN;
  if (!s || !p || !floor) return CVAR_EINVAL;
  p = cv_ends_solved(s, p); /* a moving end: the interval solved last (ME-1) */
  if (!s->have || !s->y || !(s->gfloor >= 0.0) || p->n != s->disc.n) return CVAR_ESTATE;
  const cv_disc *d = &s->disc;
  double *acc = cv_calloc((size_t)(d->nfree > 0 ? d->nfree : 1), sizeof *acc);
  if (!acc) return CVAR_ENOMEM;
  cv_status st = term_sums(p, d, s->y, acc);
  if (st == CVAR_OK) {
    double t = 0.0;
    for (int f = 0; f < d->nfree; f++) t = fmax(t, acc[f] * d->imass[f]);
    t *= DBL_EPSILON;
    if (isfinite(t)) /* the two parts of (N-3a) */
      *floor = s->gfloor + t;
    else
      st = CVAR_ENONFINITE;
  }
  cv_free(acc);
  return st;
}
