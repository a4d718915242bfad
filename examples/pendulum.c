/* examples/pendulum.c — the Cartesian pendulum with the rod as a constraint, and its tension.
 * SPDX-License-Identifier: MIT
 *
 * Problem: a mass m = 1 on a rod of length l = 1, g = 9.81, in Cartesian coordinates (x, y):
 * L = m (x'^2 + y'^2)/2 - m g y, with the pointwise constraint G = x^2 + y^2 - l^2 = 0 and its
 * multiplier field lambda(t) (Lagrangian L + lambda G), from t = 0 to T = 0.3
 * (scene: scenes/pendulum.scene). The motion chosen is the separatrix (energy m g l, the
 * pendulum creeps up to the top in infinite time), which has a closed form: with
 * w = sqrt(g/l),  th(t) = 4 atan(exp(w t)) - pi,  x = l sin(th),  y = -l cos(th).
 * Exact: action 4 m l^2 w tanh(w T) - m g l T = 6.2659905531549; rod tension
 * m l th'^2 + m g cos(th) = m g (2 + 3 cos th), which is -2 l lambda (docs/constraints.md).
 * The integrand is a formula, the constraint a callback. The program solves with 16 elements
 * of degree 4 and checks: exit 0 when the max nodal error is below 1e-10, the action within
 * 1e-10 of the exact value and the tension -2 l lambda within 1e-6 relative of
 * m g (2 + 3 cos th) at every node (at the two fixed ends lambda is extrapolated). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

#define PI 3.14159265358979323846

static const double m_ = 1.0, l_ = 1.0, g_ = 9.81, T_ = 0.3;

static double theta(double t) { return 4.0 * atan(exp(sqrt(g_ / l_) * t)) - PI; }

/* G = x^2 + y^2 - l^2: G_x = 2x, G_y = 2y, G_xx = G_yy = 2, G_xy = 0. */
static int rod(int m, const double *t, const double *y, unsigned need, double *G, double *Gy,
               double *Gyy, void *user) {
  (void)t;
  (void)user;
  for (int k = 0; k < m; k++) {
    double px = y[k], py = y[m + k];
    G[k] = px * px + py * py - l_ * l_;
    if ((need & CVAR_NEED_GRAD) && Gy) {
      Gy[k] = 2.0 * px;
      Gy[m + k] = 2.0 * py;
    }
    if ((need & CVAR_NEED_HESS) && Gyy) {
      Gyy[k] = Gyy[3 * m + k] = 2.0;
      Gyy[m + k] = Gyy[2 * m + k] = 0.0;
    }
  }
  return 0;
}

/* Initial guess: the angle growing linearly, on the circle. */
static int guess(int m, const double *t, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) {
    double th = theta(T_) * t[k] / T_;
    y[k] = l_ * sin(th);
    y[m + k] = -l_ * cos(th);
  }
  return 0;
}

int main(void) {
  const double w = sqrt(g_ / l_), th1 = theta(T_);
  const double exact_action = 4.0 * m_ * l_ * l_ * w * tanh(w * T_) - m_ * g_ * l_ * T_;
  char err_text[256] = "";
  cv_status st;
  cv_problem *p = cv_problem_new(2, 0.0, T_, &st);
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
  double *t = NULL, *y = NULL, *lambda = NULL;
  if ((st = cv_problem_set_integrand_expr(p, "t", "x, y", "m*(x'^2 + y'^2)/2 - m*g*y",
                                          "m = 1, g = 9.81", err_text, sizeof err_text)) ||
      (st = cv_problem_set_dirichlet(p, 0, 0.0, l_ * sin(th1))) ||
      (st = cv_problem_set_dirichlet(p, 1, -l_, -l_ * cos(th1))) ||
      (st = cv_problem_set_guess(p, guess, NULL)) ||
      (st = cv_problem_add_constraint(p, rod, NULL, NULL)) ||
      (st = cv_solver_set_elements(s, 16)) || (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s %s\n", cv_strerror(st), err_text);
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s);
  t = malloc(nn * sizeof *t);
  y = malloc(2 * nn * sizeof *y);
  lambda = malloc(nn * sizeof *lambda);
  if (!t || !y || !lambda || cv_solver_get_nodes(s, t) || cv_solver_get_values(s, y) ||
      cv_solver_get_multiplier_field(s, 0, lambda))
    goto cleanup;
  double err = 0.0, terr = 0.0;
  for (int j = 0; j < nn; j++) {
    double th = theta(t[j]), tension = m_ * g_ * (2.0 + 3.0 * cos(th));
    err = fmax(err, fmax(fabs(y[2 * j] - l_ * sin(th)), fabs(y[2 * j + 1] + l_ * cos(th))));
    terr = fmax(terr, fabs(-2.0 * l_ * lambda[j] - tension) / tension);
  }
  double action = cv_solver_get_action(s);
  printf("pendulum: %d nodes, %d Newton iterations, Morse index %d\n", nn,
         cv_solver_get_num_iterations(s), cv_solver_get_morse_index(s));
  printf("  action %.15f (exact %.15f), max nodal error %.2e\n", action, exact_action, err);
  printf("  tension -2 l lambda: %.6f at the bottom (exact 5 m g = %.6f), %.6f at T "
         "(exact %.6f); max relative error %.2e\n",
         -2.0 * l_ * lambda[0], 5.0 * m_ * g_, -2.0 * l_ * lambda[nn - 1],
         m_ * g_ * (2.0 + 3.0 * cos(th1)), terr);
  rc = (err < 1e-10 && fabs(action - exact_action) < 1e-10 && terr < 1e-6) ? 0 : 1;
  if (rc) fprintf(stderr, "pendulum: answer outside its stated tolerance\n");
cleanup:
  free(lambda);
  free(y);
  free(t);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
