/* tests/expr/test_expr_string_integrand.c — cv_problem_set_integrand_expr: values and
 * partials of the installed callback against hand formulas, the finite-difference check,
 * a catenary solve, and the error sentences. SPDX-License-Identifier: MIT */
#include "ex_test.h"
#include "core/cv_internal.h" /* p->F and p->user: call the installed callback directly */

static void check_catenary_values(void) {
  cv_status why;
  cv_problem *p = cv_problem_new(1, -1.0, 1.0, &why);
  char err[256];
  cv_status st =
      cv_problem_set_integrand_expr(p, NULL, " y ", "c*y*sqrt(1 + y'^2) + 0*x",
                                    "c = 2, half = c/4*atan2(1, 1)/atan(1)", err, sizeof err);
  CHECK(st == CVAR_OK, "set_integrand_expr: %s (%s)", cv_strerror(st), err);
  if (st != CVAR_OK) {
    cv_problem_free(p);
    return;
  }
  enum { M = 5 };
  double x[M], y[M], dy[M], F[M], Fy[M], Fp[M], Fyy[M], Fyp[M], Fpp[M];
  for (int k = 0; k < M; k++) x[k] = -1 + 0.5 * k, y[k] = 1 + 0.3 * k, dy[k] = -1 + 0.45 * k;
  cv_partials o = {F, Fy, Fp, Fyy, Fyp, Fpp};
  CHECK(p->F(M, x, y, dy, 7u, &o, p->user) == 0, "callback failed");
  for (int k = 0; k < M; k++) {
    double s = sqrt(1 + dy[k] * dy[k]);
    /* Hand formulas; a few ulps apart from the tape. */
    CHECK_CLOSE("F", F[k], 2 * y[k] * s, 1e-14, 10);
    CHECK_CLOSE("Fy", Fy[k], 2 * s, 1e-14, 10);
    CHECK_CLOSE("Fp", Fp[k], 2 * y[k] * dy[k] / s, 1e-14, 10);
    CHECK_CLOSE("Fyy", Fyy[k], 0, 0, 1);
    CHECK_CLOSE("Fyp", Fyp[k], 2 * dy[k] / s, 1e-14, 10);
    CHECK_CLOSE("Fpp", Fpp[k], 2 * y[k] / (s * s * s), 1e-14, 10);
  }
  /* The core's own check: central differences, error O(eps^(2/3)) ~ 1e-10 relative. */
  cv_derivcheck rep;
  st = cv_problem_check_derivatives(p, M, x, y, dy, &rep);
  CHECK(st == CVAR_OK && rep.worst < 1e-7, "derivative check: %s, worst %g at %s", cv_strerror(st),
        rep.worst, rep.which);
  /* Replacing the integrand releases the first compiled one (ASan: no leak). */
  st = cv_problem_set_integrand_expr(p, "s", "y", "y^2 + y'^2 + s", NULL, err, sizeof err);
  CHECK(st == CVAR_OK, "second integrand: %s", err);
  cv_problem_free(p);
}

static void check_two_unknowns(void) {
  cv_status why;
  cv_problem *p = cv_problem_new(2, 0.0, 1.0, &why);
  char err[256];
  cv_status st = cv_problem_set_integrand_expr(p, "t", "th, ph", "th'^2 + sin(th)^2*ph'^2", NULL,
                                               err, sizeof err);
  CHECK(st == CVAR_OK, "sphere: %s", err);
  double x[2] = {0.1, 0.2}, y[4] = {0.3, 1.1, 0.0, 2.0}, dy[4] = {0.5, -0.2, 1.5, 0.7};
  cv_derivcheck rep;
  st = cv_problem_check_derivatives(p, 2, x, y, dy, &rep);
  CHECK(st == CVAR_OK && rep.worst < 1e-7, "sphere derivative check: worst %g at %s", rep.worst,
        rep.which);
  cv_problem_free(p);
}

/* The catenary solved from its formula: y = c cosh(x/c), c = 2, on [-1, 1]. Degree 2 and
 * 32 elements give nodal errors ~1e-8 (O(h^4)); tolerance 1e-6. */
static void check_solve(void) {
  cv_status why;
  cv_problem *p = cv_problem_new(1, -1.0, 1.0, &why);
  char err[256];
  cv_problem_set_integrand_expr(p, NULL, "y", "y*sqrt(1 + y'^2)", NULL, err, sizeof err);
  double end = 2 * cosh(0.5);
  cv_problem_set_dirichlet(p, 0, end, end);
  cv_solver *s = cv_solver_new(&why);
  cv_solver_set_elements(s, 32);
  cv_solver_set_degree(s, 2);
  cv_status st = cv_solve(s, p);
  CHECK(st == CVAR_OK, "solve: %s: %s", cv_strerror(st), cv_solver_last_error(s));
  if (st == CVAR_OK) {
    int nn = cv_solver_get_num_nodes(s);
    double *xs = malloc((size_t)nn * sizeof *xs), *ys = malloc((size_t)nn * sizeof *ys);
    cv_solver_get_nodes(s, xs);
    cv_solver_get_values(s, ys);
    double worst = 0;
    for (int j = 0; j < nn; j++) worst = fmax(worst, fabs(ys[j] - 2 * cosh(xs[j] / 2)));
    CHECK_CLOSE("max nodal error", worst, 0, 1e-6, 1);
    free(xs);
    free(ys);
  }
  cv_solver_free(s);
  cv_problem_free(p);
}

static void check_errors(void) {
  struct {
    const char *var, *unk, *F, *par, *contains;
  } cases[] = {
      {NULL, "y", "y*q", NULL, "integrand: column 3: unknown name 'q'"},
      {NULL, "y", "y'''", NULL, "integrand: column 1: y''': at most the second derivative"},
      {NULL, "y", "x' + y", NULL, "integrand: column 1: a prime is only allowed on an unknown"},
      {NULL, "y", "c'*y", "c = 1", "'c' is a parameter"},
      {NULL, "y, z", "y", NULL, "2 names given, but the problem has 1 unknown"},
      {NULL, "y", "y", "c = y", "parameter 'c': column 1: 'y' is not a constant"},
      {NULL, "y", "y", "c = 1, d", "'d' is not of the form name = value"},
      {NULL, "y", "y", "c = log(-1)", "parameter 'c': the value is not a finite number"},
      {NULL, "y", "y", "c = 1, c = 2", "the name 'c' is already used"},
      {NULL, "y", "y", "y = 2", "the name 'y' is already used"},
      {NULL, "x", "x", NULL, "'x' is also the variable"},
      {NULL, "sin", "1", NULL, "'sin' is reserved"},
      {"2t", "y", "y", NULL, "variable: '2t' does not start with a letter"},
      {NULL, "y", "", NULL, "integrand: column 1: empty expression"},
      {NULL, "y", "(y", NULL, "missing ')'"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    cv_status why;
    cv_problem *p = cv_problem_new(1, 0.0, 1.0, &why);
    char err[256] = "";
    cv_status st = cv_problem_set_integrand_expr(p, cases[i].var, cases[i].unk, cases[i].F,
                                                 cases[i].par, err, sizeof err);
    CHECK(st == CVAR_EINVAL && strstr(err, cases[i].contains),
          "case %zu (\"%s\"): expected EINVAL with \"%s\", actual %s \"%s\"", i, cases[i].F,
          cases[i].contains, cv_status_name(st), err);
    cv_problem_free(p);
  }
  CHECK(cv_problem_set_integrand_expr(NULL, NULL, "y", "y", NULL, NULL, 0) == CVAR_EINVAL,
        "NULL problem");
}

int main(void) {
  check_catenary_values();
  check_two_unknowns();
  check_errors();
  check_solve();
  return finish("test_expr_string_integrand");
}
