/* examples/graded_index.c — a ray in a graded-index medium and its conserved momentum.
 * SPDX-License-Identifier: MIT
 *
 * Problem: Fermat's principle with index n(x) = sqrt(1 + x): the ray from (0, 0) to
 * (1, sqrt(1.75) - sqrt(0.75)) makes I[y] = int_0^1 n(x) sqrt(1 + y'^2) dx stationary
 * (scene: scenes/graded_index.scene). y is cyclic, so p = n y'/sqrt(1 + y'^2) — n times the
 * sine of the angle between ray and x axis — is constant along the ray (Snell's law in graded
 * form, Noether); here p = 1/2.
 * Exact solution: y = sqrt(0.75 + x) - sqrt(0.75); optical path 1.3387673554360535.
 * The integrand is a formula (cv_problem_set_integrand_expr); p is evaluated at the solver's
 * quadrature points (cv_solver_get_qpoints). The program solves with 16 elements of degree 4
 * and checks: exit 0 when the max nodal error is below 1e-10, the optical path is within
 * 1e-12 of the exact value and p is within 1e-7 of 1/2 at every quadrature point. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

int main(void) {
  const double exact_path = 1.3387673554360535;
  char err_text[256] = "";
  cv_status st;
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, &st);
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
  double *x = NULL, *y = NULL, *xq = NULL, *dyq = NULL;
  if ((st = cv_problem_set_integrand_expr(p, "x", "y", "sqrt(1 + x) * sqrt(1 + y'^2)", NULL,
                                          err_text, sizeof err_text)) ||
      (st = cv_problem_set_dirichlet(p, 0, 0.0, sqrt(1.75) - sqrt(0.75))) ||
      (st = cv_solver_set_elements(s, 16)) || (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s %s\n", cv_strerror(st), err_text);
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s), nq = cv_solver_get_num_qpoints(s);
  x = malloc(nn * sizeof *x);
  y = malloc(nn * sizeof *y);
  xq = malloc(nq * sizeof *xq);
  dyq = malloc(nq * sizeof *dyq);
  if (!x || !y || !xq || !dyq || cv_solver_get_nodes(s, x) || cv_solver_get_values(s, y) ||
      cv_solver_get_qpoints(s, xq, NULL, NULL, dyq))
    goto cleanup;
  double err = 0.0, perr = 0.0;
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - (sqrt(0.75 + x[j]) - sqrt(0.75))));
  for (int k = 0; k < nq; k++) {
    double mom = sqrt(1.0 + xq[k]) * dyq[k] / sqrt(1.0 + dyq[k] * dyq[k]);
    perr = fmax(perr, fabs(mom - 0.5));
  }
  double path = cv_solver_get_action(s);
  printf("graded_index: %d nodes, %d Newton iterations, Morse index %d\n", nn,
         cv_solver_get_num_iterations(s), cv_solver_get_morse_index(s));
  printf("  optical path %.15f (exact %.15f), max nodal error %.2e\n", path, exact_path, err);
  printf("  momentum n sin(angle) = 1/2 to %.2e at %d quadrature points\n", perr, nq);
  rc = (err < 1e-10 && fabs(path - exact_path) < 1e-12 && perr < 1e-7) ? 0 : 1;
  if (rc) fprintf(stderr, "graded_index: answer outside its stated tolerance\n");
cleanup:
  free(dyq);
  free(xq);
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
