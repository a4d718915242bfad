/* examples/kepler.c — an arc of a Kepler ellipse by least action.
 * SPDX-License-Identifier: MIT
 *
 * Problem: a planet of unit mass in the field of a sun of strength mu = 1 at the origin,
 * L = (x'^2 + y'^2)/2 + mu/r, r = sqrt(x^2 + y^2); the path from perihelion (1 - e, 0) at
 * t = 0 to (-e, sqrt(1 - e^2)) at t1 = pi/2 - e that makes the action int L dt stationary
 * (scene: scenes/kepler.scene), e = 1/2.
 * Exact solution: the ellipse of semi-major axis 1 and eccentricity e (period 2 pi), in the
 * eccentric anomaly E: x = cos E - e, y = sqrt(1 - e^2) sin E, t = E - e sin E (Kepler's
 * equation, solved here by Newton for each node), from E = 0 to E = pi/2. Action: the energy
 * is -1/2, so L = -1/2 + 2/r, and dt = r dE: S = -t1/2 + 2 (pi/2) = 3 pi/4 + e/2
 * = 2.606194490192345. The arc is a quarter of the ellipse in E, short of any conjugate
 * point: a minimum (Morse index 0).
 * Callback with exact partials. The program solves with 16 elements of degree 4 and checks:
 * exit 0 when the max nodal error is below 1e-9, the action within 1e-11 of the exact value,
 * and the Morse index is 0. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

#define PI 3.14159265358979323846

static const double e_ = 0.5, mu_ = 1.0;

/* Unknowns 0 = x, 1 = y. F = (x'^2 + y'^2)/2 + mu/r:  F_x = -mu x/r^3, F_y = -mu y/r^3,
 * F_x' = x', F_y' = y';  F_xx = mu (3x^2 - r^2)/r^5, F_xy = 3 mu x y/r^5,
 * F_yy = mu (3y^2 - r^2)/r^5;  F_y'y' is the identity; no mixed partials. r = 0 (the sun)
 * cannot be evaluated: return 1 and the line search shortens the step. */
static int lagrangian(int m, const double *t, const double *y, const double *dy, unsigned need,
                      cv_partials *out, void *user) {
  (void)t;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double px = y[k], py = y[m + k], vx = dy[k], vy = dy[m + k];
    double r2 = px * px + py * py, r = sqrt(r2);
    if (!(r > 0.0)) return 1;
    double r3 = r2 * r, r5 = r3 * r2;
    out->F[k] = 0.5 * (vx * vx + vy * vy) + mu_ / r;
    if (out->Fy) {
      out->Fy[k] = -mu_ * px / r3;
      out->Fy[m + k] = -mu_ * py / r3;
      out->Fp[k] = vx;
      out->Fp[m + k] = vy;
    }
    if (out->Fyy) {
      out->Fyy[k] = mu_ * (3.0 * px * px - r2) / r5;
      out->Fyy[m + k] = out->Fyy[2 * m + k] = 3.0 * mu_ * px * py / r5;
      out->Fyy[3 * m + k] = mu_ * (3.0 * py * py - r2) / r5;
      for (int ij = 0; ij < 4; ij++) out->Fyp[ij * m + k] = 0.0;
      out->Fpp[k] = out->Fpp[3 * m + k] = 1.0;
      out->Fpp[m + k] = out->Fpp[2 * m + k] = 0.0;
    }
  }
  return 0;
}

/* The eccentric anomaly at time t: Newton on E - e sin E = t (converges from E = t for
 * e < 1, the function being increasing and convex-concave about its inflection at 0). */
static double anomaly(double t) {
  double E = t;
  for (int it = 0; it < 50; it++) {
    double dE = (E - e_ * sin(E) - t) / (1.0 - e_ * cos(E));
    E -= dE;
    if (fabs(dE) < 1e-16) break;
  }
  return E;
}

int main(void) {
  const double t1 = PI / 2.0 - e_, b = sqrt(1.0 - e_ * e_);
  const double exact_action = 3.0 * PI / 4.0 + e_ / 2.0;
  cv_status st;
  cv_problem *p = cv_problem_new(2, 0.0, t1, &st);
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
  double *t = NULL, *y = NULL;
  if ((st = cv_problem_set_integrand(p, lagrangian, NULL)) ||
      (st = cv_problem_set_dirichlet(p, 0, 1.0 - e_, -e_)) ||
      (st = cv_problem_set_dirichlet(p, 1, 0.0, b)) || (st = cv_solver_set_elements(s, 16)) ||
      (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s\n", cv_strerror(st));
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s);
  t = malloc(nn * sizeof *t);
  y = malloc(2 * nn * sizeof *y);
  if (!t || !y || cv_solver_get_nodes(s, t) || cv_solver_get_values(s, y)) goto cleanup;
  double err = 0.0;
  for (int j = 0; j < nn; j++) {
    double E = anomaly(t[j]);
    err = fmax(err, fmax(fabs(y[2 * j] - (cos(E) - e_)), fabs(y[2 * j + 1] - b * sin(E))));
  }
  double action = cv_solver_get_action(s);
  int morse = cv_solver_get_morse_index(s);
  printf("kepler: e = %.2f, %d nodes, %d Newton iterations, Morse index %d\n", e_, nn,
         cv_solver_get_num_iterations(s), morse);
  printf("  action %.15f (exact 3 pi/4 + e/2 = %.15f), max nodal error %.2e\n", action,
         exact_action, err);
  rc = (err < 1e-9 && fabs(action - exact_action) < 1e-11 && morse == 0) ? 0 : 1;
  if (rc) fprintf(stderr, "kepler: answer outside its stated tolerance\n");
cleanup:
  free(y);
  free(t);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
