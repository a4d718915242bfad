/* examples/ball.c — the tutorial's ball thrown straight up, from C in two ways.
 * SPDX-License-Identifier: MIT
 *
 * Problem: least action for a ball of unit mass in gravity g = 9.81 that leaves y = 0 at
 * t = 0 and is back at y = 0 at t = 1:  S[y] = int_0^1 y'^2/2 - g y dt
 * (scene: scenes/ball.scene; docs/tutorial.md).
 * Exact solution: y = g t (1 - t)/2, action -g^2/24 = -4.0098375. The solution is a
 * polynomial of degree 2, so elements of degree 2 reproduce it to round-off.
 * The program solves it twice: with the integrand as a formula (cv_problem_set_integrand_expr)
 * and as a C callback with exact partials (cv_problem_set_integrand); 4 elements of degree 2.
 * It checks: exit 0 when both give a max nodal error below 1e-13 and an action within 1e-13
 * of -g^2/24. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

static const double g = 9.81;

/* F = y'^2/2 - g y at m points: F_y = -g, F_y' = y', F_yy = F_yy' = 0, F_y'y' = 1. */
static int ball(int m, const double *t, const double *y, const double *dy, unsigned need,
                cv_partials *out, void *user) {
  (void)t;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    out->F[k] = 0.5 * dy[k] * dy[k] - g * y[k];
    if (out->Fy) { /* first partials asked for */
      out->Fy[k] = -g;
      out->Fp[k] = dy[k];
    }
    if (out->Fyy) { /* second partials asked for */
      out->Fyy[k] = 0.0;
      out->Fyp[k] = 0.0;
      out->Fpp[k] = 1.0;
    }
  }
  return 0;
}

/* Solve on 4 elements of degree 2 and print the action, the height at t = 1/2 and the max
 * nodal error against g t (1 - t)/2. Returns 0 when the answer is within tolerance. */
static int solve_and_check(const char *how, cv_problem *p) {
  int rc = 1;
  double *t = NULL, *y = NULL;
  cv_status st;
  cv_solver *s = cv_solver_new(&st);
  if (!s || (st = cv_solver_set_elements(s, 4)) || (st = cv_solver_set_degree(s, 2))) {
    fprintf(stderr, "solver: %s\n", cv_strerror(st));
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s);
  t = malloc(nn * sizeof *t);
  y = malloc(nn * sizeof *y);
  if (!t || !y || cv_solver_get_nodes(s, t) || cv_solver_get_values(s, y)) goto cleanup;
  double err = 0.0, action = cv_solver_get_action(s), exact = -g * g / 24.0;
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - g * t[j] * (1.0 - t[j]) / 2.0));
  printf("%-9s action %.15f (exact %.15f), y(1/2) = %.15f, max nodal error %.1e\n", how, action,
         exact, y[nn / 2], err);
  rc = (err < 1e-13 && fabs(action - exact) < 1e-13) ? 0 : 1;
cleanup:
  free(y);
  free(t);
  cv_solver_free(s);
  return rc;
}

int main(void) {
  char err[256] = "";
  int rc = 0;

  /* 1. The integrand as a formula: derivatives are exact and symbolic. */
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, NULL);
  if (!p ||
      cv_problem_set_integrand_expr(p, "t", "y", "y'^2/2 - g*y", "g = 9.81", err, sizeof err) ||
      cv_problem_set_dirichlet(p, 0, 0.0, 0.0)) {
    fprintf(stderr, "formula: %s\n", err);
    rc = 1;
  } else {
    rc |= solve_and_check("formula", p);
  }
  cv_problem_free(p);

  /* 2. The integrand as a callback with exact partials. */
  p = cv_problem_new(1, 0.0, 1.0, NULL);
  if (!p || cv_problem_set_integrand(p, ball, NULL) || cv_problem_set_dirichlet(p, 0, 0.0, 0.0)) {
    fprintf(stderr, "callback: setup failed\n");
    rc = 1;
  } else {
    rc |= solve_and_check("callback", p);
  }
  cv_problem_free(p);

  if (rc) fprintf(stderr, "ball: answer outside its stated tolerance\n");
  return rc;
}
