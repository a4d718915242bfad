/* tests/core/test_ends.c — moving ends through the C API (theory ME-1 .. ME-4), against
 * closed forms: the shortest path from a point to a circle (both stationary ends), a free
 * final time, the brachistochrone from the origin to a line (the cycloid meets it at a
 * right angle), and a free end that can never be stationary (the interval collapses).
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "refproblems.h"

/* Arc length F = sqrt(1 + y'^2). */
static int length_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *o, void *user) {
  (void)x, (void)y, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p);
    o->F[k] = s;
    if (o->Fy) o->Fy[k] = 0, o->Fp[k] = p / s;
    if (o->Fyy) o->Fyy[k] = 0, o->Fyp[k] = 0, o->Fpp[k] = 1 / (s * s * s);
  }
  return 0;
}

/* A trajectory with a cost of time: F = (y'^2 + y^2)/2 + 1/2. */
static int timed_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * (dy[k] * dy[k] + y[k] * y[k]) + 0.5;
    if (o->Fy) o->Fy[k] = y[k], o->Fp[k] = dy[k];
    if (o->Fyy) o->Fyy[k] = 1, o->Fyp[k] = 0, o->Fpp[k] = 1;
  }
  return 0;
}

/* The circle (x - 3)^2 + (y - 2)^2 = 1. */
static int circle_G(double x, const double *y, double *G, double *Gx, double *Gy, void *user) {
  (void)user;
  *G = (x - 3) * (x - 3) + (y[0] - 2) * (y[0] - 2) - 1;
  *Gx = 2 * (x - 3);
  Gy[0] = 2 * (y[0] - 2);
  return 0;
}

/* The line x + y = c (c in *user). */
static int line_G(double x, const double *y, double *G, double *Gx, double *Gy, void *user) {
  *G = x + y[0] - *(const double *)user;
  *Gx = 1;
  Gy[0] = 1;
  return 0;
}

static void point_to_circle(int elements, int degree, double tol, double bound) {
  cv_problem *p = cv_problem_new(1, 0, 2, NULL);
  cv_problem_set_integrand(p, length_F, NULL);
  cv_problem_set_end_value(p, 0, 0, 0.0);
  cv_problem_set_free_end(p, 0, 1);
  CHECK(cv_problem_set_end_curve(p, 1, circle_G, NULL) == CVAR_OK, "set_end_curve");
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, elements);
  cv_solver_set_degree(s, degree);
  if (tol > 0) cv_solver_set_tol(s, tol, 100000);
  cv_status st = cv_solve(s, p);
  double a = NAN, b = NAN, bx = 3 * (1 - 1 / sqrt(13));
  cv_solver_get_interval(s, &a, &b);
  int nn = cv_solver_get_num_nodes(s);
  double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), err = 0;
  cv_solver_get_nodes(s, x);
  cv_solver_get_values(s, y);
  for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - 2 * x[j] / 3));
  printf("point to circle E=%d p=%d tol=%g: %s; b - b* = %.2e, action error %.2e, nodal %.2e, "
         "Morse %d\n  %s\n",
         elements, degree, tol, cv_strerror(st), b - bx, cv_solver_get_action(s) - (sqrt(13) - 1),
         err, cv_solver_get_morse_index(s), cv_solver_last_error(s));
  CHECK(st == CVAR_OK, "point to circle: %s", cv_solver_last_error(s));
  CHECK(a == 0.0, "the fixed start stays at 0: %g", a);
  CHECK_NEAR("point to circle: end", b, bx, bound);
  CHECK_NEAR("point to circle: length", cv_solver_get_action(s), sqrt(13) - 1, bound);
  CHECK(err <= bound, "point to circle: nodal error %.3g > %.3g", err, bound);
  CHECK(cv_solver_get_morse_index(s) == 0, "point to circle: Morse index %d, a minimum has 0",
        cv_solver_get_morse_index(s));
  free(x);
  free(y);
  cv_solver_free(s);
  cv_problem_free(p);
}

/* Free final time: y(0) = 0, y(T) = 1 for F = (y'^2 + y^2)/2 + 1/2. The extremals are
 * A sinh t with H = A^2/2 - 1/2; H(T) = 0 (ME-1) gives A = 1, T = asinh(1), action
 * sinh(2T)/4 + T/2 = sqrt(2)/2 + asinh(1)/2. */
static double sinh_exact(double x) { return sinh(x); }
static void free_final_time(int elements, int degree, double tol, double bound) {
  cv_problem *p = cv_problem_new(1, 0, 2, NULL);
  cv_problem_set_integrand(p, timed_F, NULL);
  cv_problem_set_dirichlet(p, 0, 0.0, 1.0);
  CHECK(cv_problem_set_end_free(p, 1) == CVAR_OK, "set_end_free");
  CHECK(cv_problem_get_end_kind(p, 1) == 1 && cv_problem_get_end_kind(p, 0) == 0, "end kinds");
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, elements);
  cv_solver_set_degree(s, degree);
  if (tol > 0) cv_solver_set_tol(s, tol, 100000);
  cv_status st = cv_solve(s, p);
  double b = NAN, T = asinh(1.0), A = sqrt(2) / 2 + asinh(1.0) / 2;
  cv_solver_get_interval(s, NULL, &b);
  double err = max_nodal_error(s, sinh_exact);
  printf("free final time E=%d p=%d tol=%g: %s; T - T* = %.2e, action error %.2e, nodal %.2e, "
         "Morse %d\n  %s\n",
         elements, degree, tol, cv_strerror(st), b - T, cv_solver_get_action(s) - A, err,
         cv_solver_get_morse_index(s), cv_solver_last_error(s));
  CHECK(st == CVAR_OK, "free final time: %s", cv_solver_last_error(s));
  CHECK_NEAR("free final time: T", b, T, bound);
  CHECK_NEAR("free final time: action", cv_solver_get_action(s), A, bound);
  CHECK(err <= bound, "free final time: nodal error %.3g > %.3g", err, bound);
  CHECK(cv_solver_get_morse_index(s) == 0, "free final time: Morse index %d",
        cv_solver_get_morse_index(s));
  cv_solver_free(s);
  cv_problem_free(p);
}

/* The cycloid x = R (f - sin f), y = R (1 - cos f) at x: f by Newton (independent of the
 * solver), y returned. */
static double cycloid_R = 1;
static double cycloid_y(double x) {
  double R = cycloid_R, f = cbrt(6 * x / R);
  for (int it = 0; it < 100 && x > 0; it++) {
    double g = R * (f - sin(f)) - x, dg = R * (1 - cos(f));
    double df = g / dg;
    f -= df;
    if (fabs(df) < 1e-16 * f) break;
  }
  return x > 0 ? R * (1 - cos(f)) : 0;
}
static int brach_guess(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = 1.3 * sqrt(x[k]);
  return 0;
}

/* Brachistochrone (2g = 1, y downward) from the origin to the line x + y = pi/2: the
 * cycloid of radius R = 1 meets it at a right angle at f = pi/2, at (pi/2 - 1, 1), after
 * the time (pi/2) sqrt(2). */
static void brachistochrone_to_line(int elements, int degree, double tol, double bound) {
  static double c = PI / 2;
  cv_problem *p = cv_problem_new(1, 0, 1, NULL);
  cv_problem_set_integrand(p, brach_F, NULL);
  cv_problem_set_end_value(p, 0, 0, 0.0);
  cv_problem_set_free_end(p, 0, 1);
  cv_problem_set_guess(p, brach_guess, NULL);
  cv_problem_set_end_curve(p, 1, line_G, &c);
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, elements);
  cv_solver_set_degree(s, degree);
  if (tol > 0) cv_solver_set_tol(s, tol, 200000);
  cv_status st = cv_solve(s, p);
  double b = NAN, T = PI / 2 * sqrt(2);
  cv_solver_get_interval(s, NULL, &b);
  cycloid_R = 1;
  double err = max_nodal_error(s, cycloid_y);
  printf("brachistochrone to x + y = pi/2, E=%d p=%d tol=%g: %s; b - b* = %.2e, time error "
         "%.2e, nodal %.2e, Morse %d\n  %s\n",
         elements, degree, tol, cv_strerror(st), b - (PI / 2 - 1), cv_solver_get_action(s) - T, err,
         cv_solver_get_morse_index(s), cv_solver_last_error(s));
  CHECK(st == CVAR_OK, "brachistochrone to a line: %s", cv_solver_last_error(s));
  CHECK_NEAR("brachistochrone to a line: end", b, PI / 2 - 1, bound);
  CHECK_NEAR("brachistochrone to a line: time", cv_solver_get_action(s), T, bound);
  CHECK(err <= bound, "brachistochrone to a line: nodal error %.3g > %.3g", err, bound);
  CHECK(cv_solver_get_morse_index(s) == 0, "brachistochrone to a line: Morse index %d",
        cv_solver_get_morse_index(s));
  cv_solver_free(s);
  cv_problem_free(p);
}

/* A free end whose values are free too, for the arc length: F = 1 > 0 at every end point
 * (ME-1), so the action only decreases as the interval shrinks: no stationary end point. */
static void collapse(void) {
  cv_problem *p = cv_problem_new(1, 0, 2, NULL);
  cv_problem_set_integrand(p, length_F, NULL);
  cv_problem_set_end_value(p, 0, 0, 1.0);
  cv_problem_set_free_end(p, 0, 1);
  cv_problem_set_end_free(p, 1);
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, 10);
  cv_status st = cv_solve(s, p);
  printf("collapse: %s\n  %s\n", cv_strerror(st), cv_solver_last_error(s));
  CHECK(st != CVAR_OK, "a collapsing interval must not converge");
  CHECK(strstr(cv_solver_last_error(s), "collapses") != NULL, "the message says why: %s",
        cv_solver_last_error(s));
  cv_solver_free(s);
  cv_problem_free(p);
}

/* Internal (src/core/cv_ends_data.c, in the core library this test links): the end data
 * the transversality condition uses (ME-2). */
cv_status cv_ends_end_data(const cv_solver *s, const cv_problem *q, int end, int mode, double *H,
                           double *P, double *y, double *v, double *size);

/* Which end data are accurate (ME-2): on the fixed interval [0, 3/2] with y(0) = 0,
 * y(3/2) = 1 the timed trajectory is y = sinh t / sinh(3/2), with H = 1/(2 sinh^2(3/2)) - 1/2
 * everywhere. The reaction of the fixed end value gives H to O(h^2p), like the action; the
 * end element's y' only to O(h^p). Measured (E = 8, 16): p = 1 reaction 1.3e-3, 3.1e-4
 * (order 2.0), element 9.2e-2, 4.9e-2 (order 0.9); p = 2 reaction 1.4e-6, 8.5e-8 (order 4.0),
 * element 3.3e-3, 8.6e-4 (order 1.9). */
static void end_data_orders(void) {
  double T = 1.5, Hx = 1 / (2 * sinh(T) * sinh(T)) - 0.5;
  cv_problem *p = cv_problem_new(1, 0, T, NULL);
  cv_problem_set_integrand(p, timed_F, NULL);
  cv_problem_set_dirichlet(p, 0, 0.0, 1.0);
  for (int deg = 1; deg <= 2; deg++) {
    double prev[2] = {NAN, NAN};
    for (int E = 4; E <= 16; E *= 2) {
      cv_solver *s = cv_solver_new(NULL);
      cv_solver_set_elements(s, E);
      cv_solver_set_degree(s, deg);
      CHECK(cv_solve(s, p) == CVAR_OK, "fixed interval: %s", cv_solver_last_error(s));
      double err[2];
      for (int mode = 0; mode < 2; mode++) {
        double H = NAN, P, y, v, size;
        CHECK(cv_ends_end_data(s, p, 1, mode, &H, &P, &y, &v, &size) == CVAR_OK, "end data");
        err[mode] = fabs(H - Hx);
        if (E > 4) {
          double order = log2(prev[mode] / err[mode]), want = mode == 0 ? 2 * deg : deg;
          printf("  p=%d E=%2d %s: H error %.2e, order %.2f\n", deg, E,
                 mode ? "end element" : "reaction   ", err[mode], order);
          CHECK(order >= want - 0.3, "p=%d E=%d %s: order %.2f < %g", deg, E,
                mode ? "end element" : "reaction", order, want);
        }
        prev[mode] = err[mode];
      }
      CHECK(err[0] < err[1], "p=%d E=%d: the reaction (%.2e) is not the more accurate (%.2e)", deg,
            E, err[0], err[1]);
      cv_solver_free(s);
    }
  }
  cv_problem_free(p);
}

int main(void) {
  setvbuf(stdout, NULL, _IONBF, 0);
  end_data_orders();
  point_to_circle(20, 4, 0, 1e-10);
  point_to_circle(4, 4, 1e-10, 1e-9);
  free_final_time(20, 4, 0, 1e-10);
  free_final_time(4, 4, 1e-10, 1e-9);
  brachistochrone_to_line(100, 4, 0, 1e-3);
  brachistochrone_to_line(4, 4, 1e-10, 1e-9);
  collapse();
  return n_failed != 0;
}
