/* examples/fisheye.c — a light ray in Maxwell's fish-eye, integrand given as a formula.
 * SPDX-License-Identifier: MIT
 *
 * Problem: Fermat's principle in the lens of index n = 2/(1 + x^2 + y^2): the ray from
 * (-1/2, y0) to (1/2, y0), y0 = -2 + sqrt(4.75), makes the optical path
 * I[y] = int n sqrt(1 + y'^2) dx stationary (scene: scenes/fisheye.scene).
 * Exact solution: rays are circles that cut the unit circle at antipodal points; here the one
 * with centre (0, -2): y = -2 + sqrt(5 - x^2); optical path 1.7890384119508238.
 * The integrand is a string (cv_problem_set_integrand_expr: exact symbolic derivatives, no
 * callback). The program solves with 16 elements of degree 4 and checks: exit 0 when the max
 * nodal error is below 1e-10 and the optical path within 1e-12 of the exact value. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

int main(void) {
  const double exact_path = 1.7890384119508238, y0 = -2.0 + sqrt(4.75);
  char err_text[256];
  cv_status st;
  cv_problem *p = cv_problem_new(1, -0.5, 0.5, &st);
  if (!p) {
    fprintf(stderr, "cv_problem_new: %s\n", cv_strerror(st));
    return 1;
  }
  cv_solver *s = cv_solver_new(&st);
  if (!s) {
    fprintf(stderr, "cv_solver_new: %s\n", cv_strerror(st));
    cv_problem_free(p);
    return 1;
  }
  int rc = 1;
  double *x = NULL, *y = NULL;
  if ((st = cv_problem_set_integrand_expr(p, "x", "y", "2/(1 + x^2 + y^2) * sqrt(1 + y'^2)", NULL,
                                          err_text, sizeof err_text)) ||
      (st = cv_problem_set_dirichlet(p, 0, y0, y0)) || (st = cv_solver_set_elements(s, 16)) ||
      (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s (%s)\n", cv_strerror(st), err_text);
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s);
  x = malloc(nn * sizeof *x);
  y = malloc(nn * sizeof *y);
  if (!x || !y || cv_solver_get_nodes(s, x) || cv_solver_get_values(s, y)) goto cleanup;
  double err = 0.0;
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - (-2.0 + sqrt(5.0 - x[j] * x[j]))));
  double path = cv_solver_get_action(s);
  printf("fisheye: %d nodes, %d Newton iterations, Morse index %d\n", nn,
         cv_solver_get_num_iterations(s), cv_solver_get_morse_index(s));
  printf("  optical path %.15f (exact %.15f), max nodal error %.2e\n", path, exact_path, err);
  rc = (err < 1e-10 && fabs(path - exact_path) < 1e-12) ? 0 : 1;
  if (rc) fprintf(stderr, "fisheye: answer outside its stated tolerance\n");
cleanup:
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
