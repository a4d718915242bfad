/* src/scene/scene_estimate.c — the nodal error of a solve without [exact], from a reference solve.
 * SPDX-License-Identifier: MIT
 *
 * Why not plain Richardson between the mesh and its double: the interior GLL nodes of a
 * degree-p mesh are not nodes of the doubled mesh, so the finer solution has to be
 * interpolated there, and its interpolation error, O((h/2)^(p+1)), exceeds the coarse
 * solution's own error at those nodes, O(h^(p+1))..O(h^(p+2)) (theory (E-4)), once h is
 * small: measured, the doubled-mesh estimate overstated the degree-4 error by 3x to 12x.
 * The reference mesh used here has every node of the mesh as an element boundary instead
 * (each element is split at its interior GLL nodes; degree 1: at its midpoint), same
 * degree. Element boundaries converge as O(h^(2p)), so at the compared points the reference
 * is far more accurate than the solution being judged, and
 *
 *   e ~ max_j |y_h(x_j) - y_ref(x_j)|           (p >= 2: the reference error is
 *                                                 O((h/p)^(2p)), negligible)
 *   e ~ max_j |y_h(x_j) - y_ref(x_j)| / (1 - 2^(-2)) (p = 1: the reference is the doubled
 *                                                 mesh, Richardson for order 2)
 *
 * docs/cli.md and docs/performance.md give the measured accuracy of the estimate. Costs one
 * solve on p times the nodes of this one (p = 1: twice). Where the solution is not smooth
 * enough for the orders above (singular ends, a layer not yet resolved) it can miss.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>

#include "scene/scene_report.h"

/* The reference mesh on [0, 1]: every node x[0..nn-1] of the judged mesh becomes an
 * element boundary; with degree 1, each element is also halved. Returns the element
 * count, or -1 (allocation); *t is malloc'ed. */
static int reference_mesh(const scene *s, int nn, const double *x, int degree, double **t)
{
  int ne = degree == 1 ? 2 * (nn - 1) : nn - 1;
  double *u = cv_malloc((size_t)(ne + 1) * sizeof *u), L = s->b - s->a;
  if (!u)
    return -1;
  for (int j = 0, k = 0; j < nn; j++) {
    u[k++] = (x[j] - s->a) / L;
    if (degree == 1 && j + 1 < nn)
      u[k++] = (0.5 * (x[j] + x[j + 1]) - s->a) / L;
  }
  u[0] = 0.0; /* exactly, as cv_solver_set_mesh demands */
  u[ne] = 1.0;
  *t = u;
  return ne;
}

int cli_estimate_error(const scene *s, const cv_problem *p, int nn, int degree,
                       const double *x, const double *y, double *e_all, double *e_vertex)
{
  int n = s->n, rc = -1;
  *e_all = *e_vertex = NAN;
  if (nn < 2 || degree < 1 || (size_t)nn > (size_t)INT_MAX / 18)
    return 0;
  char err[SC_ERRLEN];
  cv_status why;
  double *t = NULL;
  cv_solver *f = cv_solver_new(&why);
  double *yf = cv_malloc((size_t)nn * n * sizeof *yf);
  int ne = reference_mesh(s, nn, x, degree, &t);
  if (!f || !yf || ne < 0)
    goto done;
  rc = 0;
  if (scene_solver_configure(s, f, err, sizeof err) != CVAR_OK ||
      cv_solver_set_mesh(f, ne, t) != CVAR_OK || cv_solve(f, p) != CVAR_OK ||
      cv_solver_eval(f, nn, x, yf, NULL) != CVAR_OK)
    goto done;
  double ea = 0, ev = 0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < nn; j++) {
      double d = fabs(y[(size_t)j * n + i] - yf[(size_t)i * nn + j]);
      ea = fmax(ea, d);
      if (j % degree == 0)
        ev = fmax(ev, d);
    }
  if (degree == 1) {
    ea /= 0.75;
    ev /= 0.75;
  }
  if (isfinite(ea) && isfinite(ev)) {
    *e_all = ea;
    *e_vertex = ev;
  }
done:
  cv_solver_free(f);
  cv_free(yf);
  cv_free(t);
  return rc;
}

int cli_report_estimate(cli_report *r, const scene *s, const cv_problem *p)
{
  double ea, ev;
  if (r->nodes <= 0 || r->st != CVAR_OK)
    return 0;
  if (cli_estimate_error(s, p, r->nodes, r->degree, r->x, r->y, &ea, &ev) < 0)
    return -1;
  if (isfinite(ea)) {
    r->has_err_est = 1;
    r->err_est = ea;
  }
  return 0;
}
