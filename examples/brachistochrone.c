/* examples/brachistochrone.c — the curve of fastest descent, callback with exact partials.
 * SPDX-License-Identifier: MIT
 *
 * Problem: a bead slides from (0, 0) to (pi, 2), y measured downward, with 2g = 1; the time
 * of descent is  I[y] = int_0^pi sqrt((1 + y'^2) / y) dx  (scene: scenes/brachistochrone.scene).
 * Exact solution: the cycloid x = phi - sin(phi), y = 1 - cos(phi), 0 <= phi <= pi, ending at
 * its lowest point; time pi sqrt(2) = 4.442882938158366. The slope is infinite at x = 0 and
 * F is singular there, so the mesh is graded towards a (elements of size ~ h^3).
 * The program solves with 100 elements of degree 4 graded with exponent 3 and checks: exit 0
 * when the time is within 1e-6 of pi sqrt(2) and the max nodal error (y against the cycloid,
 * phi from Newton on phi - sin(phi) = x) is below 1e-4. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

#define PI 3.14159265358979323846

/* F = sqrt(u / y), u = 1 + y'^2:  F_y = -F/(2y), F_y' = y' F/u,  F_yy = 3F/(4y^2),
 * F_yy' = -y' F/(2 u y),  F_y'y' = F/u^2. y <= 0 is outside the domain: return 1 and the
 * line search shortens the step. */
static int descent_time(int m, const double *x, const double *y, const double *dy, unsigned need,
                        cv_partials *out, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    if (!(y[k] > 0.0)) return 1;
    double p = dy[k], u = 1.0 + p * p, F = sqrt(u / y[k]);
    out->F[k] = F;
    if (out->Fy) {
      out->Fy[k] = -0.5 * F / y[k];
      out->Fp[k] = p * F / u;
    }
    if (out->Fyy) {
      out->Fyy[k] = 0.75 * F / (y[k] * y[k]);
      out->Fyp[k] = -0.5 * p * F / (u * y[k]);
      out->Fpp[k] = F / (u * u);
    }
  }
  return 0;
}

/* A guess with the cycloid's y ~ x^(2/3) at the start keeps Newton inside y > 0. */
static int guess(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = 2.0 * pow(x[k] / PI, 2.0 / 3.0);
  return 0;
}

/* The cycloid's y at abscissa x in [0, pi]: Newton on phi - sin(phi) = x, safeguarded by
 * bisection on [0, pi] (the derivative 1 - cos(phi) vanishes at phi = 0). */
static double cycloid_y(double x) {
  double lo = 0.0, hi = PI, phi = fmin(cbrt(6.0 * x), PI);
  for (int it = 0; it < 100; it++) {
    double f = phi - sin(phi) - x;
    if (f > 0.0)
      hi = phi;
    else
      lo = phi;
    double d = 1.0 - cos(phi), next = d > 0.0 ? phi - f / d : 0.5 * (lo + hi);
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    if (fabs(next - phi) < 1e-16 * (1.0 + phi)) break;
    phi = next;
  }
  return 1.0 - cos(phi);
}

int main(void) {
  const double exact_time = PI * sqrt(2.0);
  cv_status st;
  cv_problem *p = cv_problem_new(1, 0.0, PI, &st);
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
  if ((st = cv_problem_set_integrand(p, descent_time, NULL)) ||
      (st = cv_problem_set_dirichlet(p, 0, 0.0, 2.0)) ||
      (st = cv_problem_set_guess(p, guess, NULL)) ||
      (st = cv_solver_set_mesh_graded(s, 100, 3.0, CVAR_GRADE_A)) ||
      (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s\n", cv_strerror(st));
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
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - cycloid_y(x[j])));
  double time = cv_solver_get_action(s);
  printf("brachistochrone: %d nodes (graded), %d Newton iterations, Morse index %d\n", nn,
         cv_solver_get_num_iterations(s), cv_solver_get_morse_index(s));
  printf("  time %.15f (exact pi sqrt 2 = %.15f), error %.2e\n", time, exact_time,
         fabs(time - exact_time));
  printf("  max nodal error against the cycloid %.2e\n", err);
  rc = (fabs(time - exact_time) < 1e-6 && err < 1e-4) ? 0 : 1;
  if (rc) fprintf(stderr, "brachistochrone: answer outside its stated tolerance\n");
cleanup:
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
