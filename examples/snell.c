/* examples/snell.c — refraction at an interface: Fermat's principle gives Snell's law.
 * SPDX-License-Identifier: MIT
 *
 * Problem: a ray from (0, 0) to (2, 229/120) through air (n1 = 1) for x < 0.7 and water
 * (n2 = 4/3) for x > 0.7 makes I[y] = int_0^2 n(x) sqrt(1 + y'^2) dx stationary
 * (scene: scenes/snell.scene).
 * Exact solution: two segments with n1 sin(t1) = n2 sin(t2), t the angle from the interface's
 * normal (the x axis): sin t1 = 4/5, sin t2 = 3/5, slopes 4/3 and 3/4:
 *   y = 4x/3 (x <= 0.7),  y = 14/15 + 3(x - 0.7)/4 (x >= 0.7);  optical path 10/3.
 * The index jumps at x = 0.7, so cv_solver_set_breakpoints puts a node there; the
 * piecewise-linear ray is then reproduced to round-off. The program also solves without the
 * breakpoint (the jump inside an element: error of order h) to show the difference.
 * It solves with 10 elements of degree 2 and checks: exit 0 when, with the breakpoint, the
 * max nodal error is below 1e-12, the optical path within 1e-12 of 10/3 and the Snell
 * invariant n sin t within 1e-12 of 4/5 on both sides (at the quadrature points). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

static double exact_y(double x) { return x < 0.7 ? 4.0 * x / 3.0 : 14.0 / 15.0 + 0.75 * (x - 0.7); }

/* Solve on 10 elements of degree 2, with or without the breakpoint; report the max nodal
 * error, the optical path and the worst deviation of n sin t from 4/5. */
static cv_status solve(cv_problem *p, int with_breakpoint, double *err, double *path,
                       double *snell) {
  const double xb = 0.7;
  double *x = NULL, *y = NULL, *xq = NULL, *dyq = NULL;
  cv_status st;
  cv_solver *s = cv_solver_new(&st);
  if (!s) return st;
  if ((st = cv_solver_set_elements(s, 10)) || (st = cv_solver_set_degree(s, 2)) ||
      (with_breakpoint && (st = cv_solver_set_breakpoints(s, 1, &xb))))
    goto cleanup;
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s), nq = cv_solver_get_num_qpoints(s);
  x = malloc(nn * sizeof *x);
  y = malloc(nn * sizeof *y);
  xq = malloc(nq * sizeof *xq);
  dyq = malloc(nq * sizeof *dyq);
  st = CVAR_ENOMEM;
  if (!x || !y || !xq || !dyq) goto cleanup;
  if ((st = cv_solver_get_nodes(s, x)) || (st = cv_solver_get_values(s, y)) ||
      (st = cv_solver_get_qpoints(s, xq, NULL, NULL, dyq)))
    goto cleanup;
  *err = 0.0;
  for (int j = 0; j < nn; j++) *err = fmax(*err, fabs(y[j] - exact_y(x[j])));
  *snell = 0.0;
  for (int k = 0; k < nq; k++) {
    double n = xq[k] < xb ? 1.0 : 4.0 / 3.0;
    *snell = fmax(*snell, fabs(n * dyq[k] / sqrt(1.0 + dyq[k] * dyq[k]) - 0.8));
  }
  *path = cv_solver_get_action(s);
  printf("  %-18s %2d elements, %d Newton iterations: path %.15f, nodal error %.2e, "
         "|n sin t - 4/5| <= %.2e\n",
         with_breakpoint ? "breakpoint at 0.7:" : "no breakpoint:", cv_solver_get_num_elements(s),
         cv_solver_get_num_iterations(s), *path, *err, *snell);
cleanup:
  free(dyq);
  free(xq);
  free(y);
  free(x);
  cv_solver_free(s);
  return st;
}

int main(void) {
  char err_text[256] = "";
  cv_status st;
  cv_problem *p = cv_problem_new(1, 0.0, 2.0, &st);
  if (!p) {
    fprintf(stderr, "cv_problem_new: %s\n", cv_strerror(st));
    return 1;
  }
  if ((st = cv_problem_set_integrand_expr(p, "x", "y", "if(x < xi, n1, n2) * sqrt(1 + y'^2)",
                                          "n1 = 1, n2 = 4/3, xi = 0.7", err_text,
                                          sizeof err_text)) ||
      (st = cv_problem_set_dirichlet(p, 0, 0.0, 229.0 / 120.0))) {
    fprintf(stderr, "setup: %s %s\n", cv_strerror(st), err_text);
    cv_problem_free(p);
    return 1;
  }
  double err, path, snell, err0, path0, snell0;
  printf("snell: air (n = 1) to water (n = 4/3) at x = 0.7, exact optical path 10/3\n");
  int rc = 1;
  if (solve(p, 1, &err, &path, &snell) == CVAR_OK && solve(p, 0, &err0, &path0, &snell0) == CVAR_OK)
    rc = (err < 1e-12 && fabs(path - 10.0 / 3.0) < 1e-12 && snell < 1e-12) ? 0 : 1;
  if (rc) fprintf(stderr, "snell: answer outside its stated tolerance\n");
  cv_problem_free(p);
  return rc;
}
