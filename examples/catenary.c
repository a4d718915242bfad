/* examples/catenary.c — the catenary through the public C API.
 * SPDX-License-Identifier: MIT
 *
 * Problem: the surface of revolution of least area between two coaxial rings of radius
 * 2 cosh(1/2) at x = -1 and x = 1 minimises  I[y] = int_{-1}^{1} y sqrt(1 + y'^2) dx.
 * Exact solution: y = 2 cosh(x/2); I = 2 + 2 sinh(1) = 4.350402387287603.
 * The program solves with 32 elements of degree 4, prints the result and checks it: exit 0
 * when the max nodal error is below 1e-10 and the action within 1e-12 of the exact value. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

/* F = y sqrt(1 + y'^2) and the partials the solver asks for (SoA layout, see calcvar.h). */
static int catenary(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *out, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1.0 + p * p);
    out->F[k] = y[k] * s;
    if (out->Fy) { /* first partials requested */
      out->Fy[k] = s;
      out->Fp[k] = y[k] * p / s;
    }
    if (out->Fyy) { /* second partials requested */
      out->Fyy[k] = 0.0;
      out->Fyp[k] = p / s;
      out->Fpp[k] = y[k] / (s * s * s);
    }
  }
  return 0;
}

int main(void) {
  const double exact_action = 4.350402387287603;
  cv_status st;
  cv_problem *p = cv_problem_new(1, -1.0, 1.0, &st);
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
  double ring = 2.0 * cosh(0.5);
  if ((st = cv_problem_set_integrand(p, catenary, NULL)) ||
      (st = cv_problem_set_dirichlet(p, 0, ring, ring)) || (st = cv_solver_set_elements(s, 32)) ||
      (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s\n", cv_strerror(st));
    goto cleanup;
  }
  st = cv_solve(s, p);
  if (st != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s);
  x = malloc(nn * sizeof *x);
  y = malloc(nn * sizeof *y);
  if (!x || !y || cv_solver_get_nodes(s, x) || cv_solver_get_values(s, y)) goto cleanup;
  double err = 0.0;
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - 2.0 * cosh(x[j] / 2.0)));
  double action = cv_solver_get_action(s);
  printf("catenary: %d nodes, %d Newton iterations, %.3f ms, Morse index %d\n", nn,
         cv_solver_get_num_iterations(s), 1e3 * cv_solver_get_time(s),
         cv_solver_get_morse_index(s));
  printf("  action %.15f (exact %.15f), max nodal error %.2e\n", action, exact_action, err);
  printf("  y(0) = %.15f (exact 2)\n", y[(nn - 1) / 2]);
  rc = (err < 1e-10 && fabs(action - exact_action) < 1e-12) ? 0 : 1;
  if (rc) fprintf(stderr, "catenary: answer outside its stated tolerance\n");
cleanup:
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
