/* tests/core/test_residual_floor.c — cv_solver_residual_floor (theory N-3a) against a floor
 * computed by hand, and its refusals.
 *
 * F = y'^2/2 on [0, 1], y(0) = 0, y(1) = s, E uniform elements of degree 1 (h = 1/E): the
 * solution is y = s x at the nodes; the Hessian is tridiag(-1, 2, -1)/h over the free
 * nodes, the lumped weights are h, and the gradient's terms at a node are, per element, the
 * two Gauss points' |w (2/h) F_y' phi'| = (h/2)(2/h)|s|(1/2): |s| per element. So
 *   unknowns' part  eps max_f (1/h) sum_j |K_fj| |y_j| = eps s (4 - 8h) / h^2 (at node E-2;
 *                   node E-1 has the fixed end, which is not an unknown, as a neighbour),
 *   terms' part     eps (1/h) 2|s| = 2 eps s / h,
 * and the floor is their sum, eps s (4 - 6h) / h^2, to round-off (1e-12 relative here).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <stdio.h>

#include "calcvar.h"

#include "check.h"

static int quad(int m, const double *x, const double *y, const double *dy, unsigned need,
                cv_partials *o, void *user) {
  (void)x, (void)need, (void)user, (void)y;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k];
    if (o->Fy) o->Fy[k] = 0, o->Fp[k] = dy[k];
    if (o->Fyy) o->Fyy[k] = 0, o->Fyp[k] = 0, o->Fpp[k] = 1;
  }
  return 0;
}

/* y'^2/2 + y^4/4: nonlinear, so one Newton step from the straight line is not the answer. */
static int quartic(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    double v = y[k];
    o->F[k] = 0.5 * dy[k] * dy[k] + 0.25 * v * v * v * v;
    if (o->Fy) o->Fy[k] = v * v * v, o->Fp[k] = dy[k];
    if (o->Fyy) o->Fyy[k] = 3 * v * v, o->Fyp[k] = 0, o->Fpp[k] = 1;
  }
  return 0;
}

int main(void) {
  double fl = 0;
  /* the hand-computed floor */
  for (int E = 5; E <= 40; E *= 2) {
    const double s = 3.0, h = 1.0 / E;
    cv_problem *p = cv_problem_new(1, 0.0, 1.0, NULL);
    cv_solver *sv = cv_solver_new(NULL);
    cv_problem_set_integrand(p, quad, NULL);
    cv_problem_set_dirichlet(p, 0, 0.0, s);
    cv_solver_set_elements(sv, E);
    cv_solver_set_degree(sv, 1);
    CHECK(cv_solver_residual_floor(sv, p, &fl) == CVAR_ESTATE && isnan(fl),
          "E=%d: no floor before a solve", E);
    CHECK(cv_solve(sv, p) == CVAR_OK, "E=%d: solved", E);
    double want = DBL_EPSILON * s * (4.0 - 6.0 * h) / (h * h);
    CHECK(cv_solver_residual_floor(sv, p, &fl) == CVAR_OK && fabs(fl - want) <= 1e-12 * want,
          "E=%d: floor %.17g, by hand %.17g", E, fl, want);
    double r = cv_solver_get_gradient_norm(sv);
    CHECK(r <= 100 * fl, "E=%d: converged residual %.3g at most 100 x its floor %.3g", E, r, fl);
    CHECK(cv_solver_residual_floor(NULL, p, &fl) == CVAR_EINVAL &&
              cv_solver_residual_floor(sv, NULL, &fl) == CVAR_EINVAL &&
              cv_solver_residual_floor(sv, p, NULL) == CVAR_EINVAL,
          "NULL arguments refused");
    cv_problem *p2 = cv_problem_new(2, 0.0, 1.0, NULL);
    CHECK(cv_solver_residual_floor(sv, p2, &fl) == CVAR_ESTATE && isnan(fl),
          "a problem with another number of unknowns refused");
    cv_problem_free(p2);
    /* an NLopt engine has no Newton matrix */
    cv_solver_set_method(sv, CVAR_METHOD_LBFGS);
    cv_status st = cv_solve(sv, p);
    CHECK(cv_solver_residual_floor(sv, p, &fl) == CVAR_ESTATE && isnan(fl),
          "E=%d: no floor after lbfgs (status %s)", E, cv_status_name(st));
    cv_solver_free(sv);
    cv_problem_free(p);
  }
  /* stopped early: far above its floor; converged: at it */
  for (int maxit = 1; maxit <= 50; maxit += 49) {
    cv_problem *p = cv_problem_new(1, 0.0, 1.0, NULL);
    cv_solver *sv = cv_solver_new(NULL);
    cv_problem_set_integrand(p, quartic, NULL);
    cv_problem_set_dirichlet(p, 0, 0.0, 4.0);
    cv_solver_set_elements(sv, 20);
    cv_solver_set_degree(sv, 4);
    cv_solver_set_max_iterations(sv, maxit);
    cv_solver_set_continuation(sv, 0);
    cv_status st = cv_solve(sv, p);
    double r = cv_solver_get_gradient_norm(sv);
    CHECK(cv_solver_residual_floor(sv, p, &fl) == CVAR_OK && fl > 0, "quartic: a floor");
    if (maxit == 1)
      CHECK(st == CVAR_EMAXITER && r > 1e6 * fl,
            "quartic after 1 iteration: %s, residual %.3g far above its floor %.3g",
            cv_status_name(st), r, fl);
    else
      CHECK(st == CVAR_OK && r <= 100 * fl, "quartic converged: %s, residual %.3g, floor %.3g",
            cv_status_name(st), r, fl);
    cv_solver_free(sv);
    cv_problem_free(p);
  }
  printf("test_residual_floor: %d failures\n", fails);
  return fails != 0;
}
