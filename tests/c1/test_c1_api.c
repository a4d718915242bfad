/* tests/c1/test_c1_api.c — second derivatives through the C API: an integrand callback
 * with the partials in y'' (cv_partials2), C1 elements of degrees 3, 5, 7 against closed
 * forms (cantilever: nodal values, slopes and y'' at the quadrature points), the Morse
 * index of Euler buckling against the exact count of unstable modes, the derivative
 * checker, and the setters' bad input. SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>

#include "../core/check.h"
#include "calcvar.h"

typedef struct {
  double EI, q, P, bad; /* bad: a wrong factor on Fqq for the checker */
} beam;

/* F = EI/2 y''^2 - P/2 y'^2 - q y (a beam under a load q and an axial compression P). */
static int beam_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                  cv_partials *o, void *user) {
  const beam *b = user;
  (void)x;
  if (!(need & CVAR_NEED_Y2)) return -1; /* a second-order problem always asks for y'' */
  cv_partials2 *o2 = cv_partials_y2(o);
  for (int k = 0; k < m; k++) {
    double q = o2->d2y[k];
    o->F[k] = 0.5 * b->EI * q * q - 0.5 * b->P * dy[k] * dy[k] - b->q * y[k];
    if (need & CVAR_NEED_GRAD) o->Fy[k] = -b->q, o->Fp[k] = -b->P * dy[k], o2->Fq[k] = b->EI * q;
    if (need & CVAR_NEED_HESS) {
      o->Fyy[k] = o->Fyp[k] = 0.0, o->Fpp[k] = -b->P;
      o2->Fyq[k] = o2->Fpq[k] = 0.0, o2->Fqq[k] = b->EI * b->bad;
    }
  }
  return 0;
}

/* The cantilever's exact deflection and derivatives (clamped at 0, free at L). */
static double cant(double x, double EI, double q, double L, int d) {
  double c = q / (24 * EI);
  if (d == 0) return c * x * x * (6 * L * L - 4 * L * x + x * x);
  if (d == 1) return c * (12 * L * L * x - 12 * L * x * x + 4 * x * x * x);
  return c * (12 * L * L - 24 * L * x + 12 * x * x);
}

static void cantilever(int degree) {
  beam b = {2.0, 3.0, 0.0, 1.0};
  double L = 1.5;
  cv_status why;
  cv_problem *p = cv_problem_new(1, 0.0, L, &why);
  cv_solver *s = cv_solver_new(&why);
  cv_problem_set_integrand(p, beam_F, &b);
  CHECK(cv_problem_set_second_order(p, 0) == CVAR_OK, "set_second_order");
  cv_problem_set_free_end(p, 0, 1);
  cv_problem_set_end_value(p, 0, 0, 0.0);
  CHECK(cv_problem_set_end_slope(p, 0, 0, 0.0) == CVAR_OK, "set_end_slope");
  cv_solver_set_elements(s, 4);
  cv_solver_set_degree(s, degree);
  cv_status st = cv_solve(s, p);
  CHECK(st == CVAR_OK, "cantilever degree %d: %s", degree, cv_solver_last_error(s));
  CHECK(cv_solver_get_degree(s) == degree, "degree %d reported %d", degree,
        cv_solver_get_degree(s));
  int nn = cv_solver_get_num_nodes(s), nq = cv_solver_get_num_qpoints(s);
  CHECK(nn == 4 * (degree - 1) / 2 + 1, "degree %d: %d nodes", degree, nn);
  double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), *dy = malloc(nn * sizeof *dy);
  double *qx = malloc(nq * sizeof *qx), *qd2 = malloc(nq * sizeof *qd2);
  cv_solver_get_nodes(s, x);
  cv_solver_get_values(s, y);
  cv_solver_get_slopes(s, dy);
  double ev = 0, es = 0, e2 = 0;
  for (int j = 0; j < nn; j++) {
    ev = fmax(ev, fabs(y[j] - cant(x[j], b.EI, b.q, L, 0)));
    es = fmax(es, fabs(dy[j] - cant(x[j], b.EI, b.q, L, 1)));
  }
  CHECK(cv_solver_get_qpoints2(s, qx, NULL, NULL, NULL, qd2) == CVAR_OK, "get_qpoints2");
  for (int k = 0; k < nq; k++) e2 = fmax(e2, fabs(qd2[k] - cant(qx[k], b.EI, b.q, L, 2)));
  /* cubic: exact at the nodes (the Green's function of y'''' is a piecewise cubic); quintic
   * and septic hold the quartic itself, so y'' too, to round-off */
  CHECK(ev < 1e-13 && es < 1e-13, "degree %d: nodal errors %.3g (values) %.3g (slopes)", degree, ev,
        es);
  if (degree > 3) CHECK(e2 < 1e-11, "degree %d: y'' error %.3g at the Gauss points", degree, e2);
  double A = -b.q * b.q * pow(L, 5) / (40 * b.EI);
  CHECK(fabs(cv_solver_get_action(s) - A) < (degree > 3 ? 1e-13 : 1e-2) * fabs(A),
        "degree %d: action %.17g, exact %.17g", degree, cv_solver_get_action(s), A);
  CHECK(cv_solver_get_morse_index(s) == 0, "cantilever: Morse index %d",
        cv_solver_get_morse_index(s));
  free(x), free(y), free(dy), free(qx), free(qd2);
  cv_solver_free(s);
  cv_problem_free(p);
}

/* Euler buckling of a pinned column (y = 0 at both ends, slopes free): the straight column
 * is stationary for every P, with as many unstable modes as n with n^2 pi^2 EI < P (L = 1). */
static void buckling(double P, int expect) {
  beam b = {1.0, 0.0, P, 1.0};
  cv_status why;
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, &why);
  cv_solver *s = cv_solver_new(&why);
  cv_problem_set_integrand(p, beam_F, &b);
  cv_problem_set_second_order(p, 0);
  cv_problem_set_dirichlet(p, 0, 0.0, 0.0);
  cv_solver_set_elements(s, 16);
  cv_solver_set_degree(s, 5);
  cv_status st = cv_solve(s, p);
  CHECK(st == CVAR_OK && cv_solver_get_morse_index(s) == expect,
        "buckling P = %g: status %s, Morse index %d, expected %d", P, cv_status_name(st),
        cv_solver_get_morse_index(s), expect);
  cv_solver_free(s);
  cv_problem_free(p);
}

static void derivatives(void) {
  beam good = {1.5, 0.5, 2.0, 1.0}, bad = {1.5, 0.5, 2.0, 1.1};
  double x[2] = {0.2, 0.7}, y[2] = {0.1, -0.3}, dy[2] = {0.5, 1.0}, d2y[2] = {2.0, -1.0};
  cv_derivcheck rep;
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, NULL);
  cv_problem_set_integrand(p, beam_F, &good);
  CHECK(cv_problem_check_derivatives2(p, 2, x, y, dy, d2y, &rep) == CVAR_EINVAL,
        "check_derivatives2 on a first-order problem");
  cv_problem_set_second_order(p, 0);
  CHECK(cv_problem_check_derivatives2(p, 2, x, y, dy, d2y, &rep) == CVAR_OK && rep.worst < 1e-8,
        "correct partials: worst %.3g in %s", rep.worst, rep.which);
  cv_problem_set_integrand(p, beam_F, &bad);
  CHECK(cv_problem_check_derivatives2(p, 2, x, y, dy, d2y, &rep) == CVAR_OK && rep.worst > 0.05,
        "a wrong Fqq (x 1.1) passed: worst %.3g in %s", rep.worst, rep.which);
  cv_problem_free(p);
}

static void bad_input(void) {
  cv_problem *p = cv_problem_new(2, 0.0, 1.0, NULL);
  CHECK(cv_problem_set_second_order(p, 2) == CVAR_EINVAL, "unknown 2 of 2 accepted");
  CHECK(cv_problem_set_end_slope(p, 0, 0, 1.0) == CVAR_EINVAL,
        "a slope of a first-order unknown accepted");
  cv_problem_set_second_order(p, 1);
  CHECK(cv_problem_set_end_slope(p, 1, 0, NAN) == CVAR_EINVAL, "a NaN slope accepted");
  CHECK(cv_problem_get_second_order(p, 1) && !cv_problem_get_second_order(p, 0),
        "get_second_order");
  beam b = {1.0, 1.0, 0.0, 1.0};
  cv_problem *q = cv_problem_new(1, 0.0, 1.0, NULL);
  cv_problem_set_integrand(q, beam_F, &b);
  cv_problem_set_second_order(q, 0);
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_degree(s, 4);
  CHECK(cv_solve(s, q) == CVAR_EINVAL, "degree 4 accepted for C1 elements: %s",
        cv_solver_last_error(s));
  cv_solver_free(s);
  cv_problem_free(q);
  cv_problem_free(p);
}

/* A formula with y'' (cv_problem_set_integrand_expr) makes its unknown second order: the
 * simply supported beam y''^2/2 - y on [0, 1], exact y = x (1 - 2x^2 + x^3)/24. */
static void formula(void) {
  char err[256] = "";
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, NULL);
  cv_status st =
      cv_problem_set_integrand_expr(p, NULL, "y", "EI/2*y''^2 - y", "EI = 1", err, sizeof err);
  CHECK(st == CVAR_OK && cv_problem_get_second_order(p, 0), "formula with y'': %s", err);
  cv_problem_set_dirichlet(p, 0, 0.0, 0.0);
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, 3);
  cv_solver_set_degree(s, 5);
  CHECK(cv_solve(s, p) == CVAR_OK, "formula beam: %s", cv_solver_last_error(s));
  double x[7], y[7], e = 0;
  CHECK(cv_solver_get_num_nodes(s) == 7, "formula beam nodes %d", cv_solver_get_num_nodes(s));
  cv_solver_get_nodes(s, x);
  cv_solver_get_values(s, y);
  for (int j = 0; j < 7; j++)
    e = fmax(e, fabs(y[j] - x[j] * (1 - 2 * x[j] * x[j] + x[j] * x[j] * x[j]) / 24));
  CHECK(e < 1e-15, "formula beam: nodal error %.3g", e);
  cv_solver_free(s);
  cv_problem_free(p);
}

int main(void) {
  formula();
  cantilever(3);
  cantilever(5);
  cantilever(7);
  buckling(5.0, 0);  /* below pi^2 */
  buckling(20.0, 1); /* between pi^2 and 4 pi^2 */
  buckling(50.0, 2); /* between 4 pi^2 and 9 pi^2 */
  derivatives();
  bad_input();
  printf("%d failure(s)\n", fails);
  return fails != 0;
}
