/* src/core/cv_problem_order2.c — second-order unknowns of a problem: which unknowns have
 * y'' in the integrand, and their slopes at the ends (theory H-1).
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_internal.h"

/* The arrays of a problem's second-order unknowns, made on first use: slopes free. */
static cv_status order2_alloc(cv_problem *p) {
  if (p->order2) return CVAR_OK;
  size_t n = (size_t)p->n;
  p->order2 = cv_calloc(3 * n, sizeof *p->order2); /* order2, then sfixed (2n) */
  p->sendval = cv_calloc(2 * n, sizeof *p->sendval);
  if (!p->order2 || !p->sendval) {
    cv_free(p->order2);
    cv_free(p->sendval);
    p->order2 = NULL;
    p->sendval = NULL;
    return CVAR_ENOMEM;
  }
  p->sfixed = p->order2 + n;
  return CVAR_OK;
}

void cv_problem_order2_free(cv_problem *p) {
  cv_free(p->order2); /* sfixed lives in its block */
  cv_free(p->sendval);
  p->order2 = p->sfixed = NULL;
  p->sendval = NULL;
  p->c1 = 0;
}

cv_status cv_problem_set_second_order(cv_problem *p, int k) {
  if (!p || k < 0 || k >= p->n) return CVAR_EINVAL;
  cv_status st = order2_alloc(p);
  if (st) return st;
  p->order2[k] = 1;
  p->c1 = 1;
  return CVAR_OK;
}

int cv_problem_get_second_order(const cv_problem *p, int k) {
  return p && k >= 0 && k < p->n && p->order2 ? p->order2[k] : 0;
}

cv_status cv_problem_set_end_slope(cv_problem *p, int k, int end, double value) {
  if (!p || k < 0 || k >= p->n || (end != 0 && end != 1) || !isfinite(value)) return CVAR_EINVAL;
  if (!cv_problem_get_second_order(p, k)) return CVAR_EINVAL;
  p->sfixed[2 * k + end] = 1;
  p->sendval[2 * k + end] = value;
  return CVAR_OK;
}

cv_status cv_problem_set_free_slope(cv_problem *p, int k, int end) {
  if (!p || k < 0 || k >= p->n || (end != 0 && end != 1)) return CVAR_EINVAL;
  if (!cv_problem_get_second_order(p, k)) return CVAR_EINVAL;
  p->sfixed[2 * k + end] = 0;
  p->sendval[2 * k + end] = 0.0;
  return CVAR_OK;
}
