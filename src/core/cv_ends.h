/* src/core/cv_ends.h — the geometry of a moving end on a curve G(x, y) = 0 (cv_ends_curve.c),
 * shared by the solve that moves the end (cv_ends.c) and the scene loader's check that the
 * curve meets the start's end region.
 * SPDX-License-Identifier: MIT */
#ifndef CV_ENDS_H
#define CV_ENDS_H

#include <stddef.h>

#include "calcvar.h"

/* G, dG/dx and dG/dy (n values) at (x, y): 0, or nonzero when G fails or is not finite. */
int cv_ends_curve_eval(cv_end_curve_fn G, void *user, int n, double x, const double *y, double *g,
                       double *gx, double *gy);
/* The unknowns left free at the end (free_at_end[i] nonzero) on which G depends at (x, y)
 * (a nonzero dG/dy_i there or at a nearby value): their number, the first in *k (-1 when
 * none). -1 when G fails. */
int cv_ends_movers(cv_end_curve_fn G, void *user, int n, const int *free_at_end, double x,
                   const double *y, int *k);
/* Move (x, y_k) (only x when k < 0) onto G = 0 by minimum-norm Newton steps (ME-3):
 * CVAR_OK, or CVAR_EINVAL with a sentence when the steps do not converge, G fails, or the
 * point would move farther than `reach`. y holds all n values; only y[k] changes. */
cv_status cv_ends_project(cv_end_curve_fn G, void *user, int n, int k, double *x, double *y,
                          double reach, char *msg, size_t len);
/* The unit tangent (tx, ty) of G = 0 in the (x, y_k) plane at (x, y), oriented with
 * tx > 0 (or ty > 0 when tx = 0); (1, 0) for k < 0. 0, or -1 when G fails or its gradient
 * vanishes. */
int cv_ends_tangent(cv_end_curve_fn G, void *user, int n, int k, double x, const double *y,
                    double *tx, double *ty);

#endif /* CV_ENDS_H */
