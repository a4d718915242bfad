/* examples/hanging_chain.c — a chain of fixed length: an integral constraint and its multiplier.
 * SPDX-License-Identifier: MIT
 *
 * Problem: a uniform chain of length 2 sinh 1 hangs between (-1, 0) and (1, 0); it minimises
 * its potential energy  I[y] = int_{-1}^{1} y sqrt(1 + y'^2) dx  subject to the integral
 * constraint  int sqrt(1 + y'^2) dx = 2 sinh 1 (scene: scenes/hanging_chain.scene).
 * Exact solution: the Lagrangian F + mu K = (y + mu) sqrt(1 + y'^2) is a catenary in y + mu,
 * y + mu = cosh(x), so y = cosh(x) - cosh(1), mu = cosh(1) = 1.5430806348152437; energy
 * int (cosh x - cosh 1) cosh x dx = 1 - sinh(2)/2 = -0.8134302039235093.
 * Integrand and constraint are callbacks with exact partials. The program solves with 32
 * elements of degree 4 and checks: exit 0 when the max nodal error is below 1e-10, the energy
 * within 1e-12 and the multiplier within 1e-9 of the exact values. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

/* F = y s, s = sqrt(1 + y'^2): F_y = s, F_y' = y y'/s, F_yy = 0, F_yy' = y'/s,
 * F_y'y' = y/s^3. */
static int potential(int m, const double *x, const double *y, const double *dy, unsigned need,
                     cv_partials *out, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1.0 + p * p);
    out->F[k] = y[k] * s;
    if (out->Fy) {
      out->Fy[k] = s;
      out->Fp[k] = y[k] * p / s;
    }
    if (out->Fyy) {
      out->Fyy[k] = 0.0;
      out->Fyp[k] = p / s;
      out->Fpp[k] = y[k] / (s * s * s);
    }
  }
  return 0;
}

/* K = s = sqrt(1 + y'^2) (arc length): K_y = 0, K_y' = y'/s, K_yy = K_yy' = 0,
 * K_y'y' = 1/s^3. */
static int length(int m, const double *x, const double *y, const double *dy, unsigned need,
                  cv_partials *out, void *user) {
  (void)x;
  (void)y;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1.0 + p * p);
    out->F[k] = s;
    if (out->Fy) {
      out->Fy[k] = 0.0;
      out->Fp[k] = p / s;
    }
    if (out->Fyy) {
      out->Fyy[k] = 0.0;
      out->Fyp[k] = 0.0;
      out->Fpp[k] = 1.0 / (s * s * s);
    }
  }
  return 0;
}

/* A sagging guess: the straight line y = 0 would have the wrong length. */
static int guess(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = 0.6 * (x[k] * x[k] - 1.0);
  return 0;
}

int main(void) {
  const double exact_energy = -0.8134302039235093, exact_mu = cosh(1.0);
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
  double *x = NULL, *y = NULL, mu = 0.0;
  if ((st = cv_problem_set_integrand(p, potential, NULL)) ||
      (st = cv_problem_set_dirichlet(p, 0, 0.0, 0.0)) ||
      (st = cv_problem_set_guess(p, guess, NULL)) ||
      (st = cv_problem_add_integral(p, length, NULL, 2.0 * sinh(1.0), NULL)) ||
      (st = cv_solver_set_elements(s, 32)) || (st = cv_solver_set_degree(s, 4))) {
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
  if (!x || !y || cv_solver_get_nodes(s, x) || cv_solver_get_values(s, y) ||
      cv_solver_get_multiplier(s, 0, &mu))
    goto cleanup;
  double err = 0.0;
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - (cosh(x[j]) - cosh(1.0))));
  double energy = cv_solver_get_action(s);
  printf("hanging_chain: %d nodes, %d Newton iterations\n", nn, cv_solver_get_num_iterations(s));
  printf("  energy %.15f (exact %.15f), max nodal error %.2e\n", energy, exact_energy, err);
  printf("  multiplier mu %.15f (exact cosh 1 = %.15f)\n", mu, exact_mu);
  rc = (err < 1e-10 && fabs(energy - exact_energy) < 1e-12 && fabs(mu - exact_mu) < 1e-9) ? 0 : 1;
  if (rc) fprintf(stderr, "hanging_chain: answer outside its stated tolerance\n");
cleanup:
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
