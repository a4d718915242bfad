/* tests/scene/test_public_api.c — the public scene loader, report and formula constraints,
 * through calcvar.h only, linked against the shared library (so only exported names work).
 * SPDX-License-Identifier: MIT
 *
 * Exact answers:
 *  - catenary scene (text): y = 2 cosh(x/2) on [-1, 1]; degree 4, 32 elements: max nodal
 *    error < 1e-10 (the scene's own expectation), and the report's error.max_nodal agrees.
 *  - isoperimetric, by formulas: min int y'^2/2 with int y = 1, y(0) = y(1) = 0:
 *    y = 6 (x - x^2), mu = -12; quadratic, so degree 2 reproduces it to round-off (1e-10).
 *  - pointwise, by formulas: min int (u'^2 + v'^2)/2 + u with u = v, zero ends:
 *    u = v = (x^2 - x)/4; quadratic, degree 2 exact to round-off.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"

static int failures, checks;

static void truth(const char *what, int ok, const char *detail) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: %s\n", what, detail ? detail : "");
  }
}

static void near(const char *what, double actual, double expected, double tol) {
  char d[200];
  snprintf(d, sizeof d, "expected %.17g, actual %.17g, tolerance %g", expected, actual, tol);
  truth(what, fabs(actual - expected) <= tol, d);
}

static const char catenary[] = "[scene]\n"
                               "title = Catenary\n"
                               "interval = -1, 1\n"
                               "unknowns = y\n"
                               "integrand = y * sqrt(1 + y'^2)\n"
                               "[parameters]\n"
                               "c = 3\n"
                               "[boundary]\n"
                               "y = c*cosh(1/c), c*cosh(1/c)\n"
                               "[exact]\n"
                               "y = c*cosh(x/c)\n";

static void test_scene(void) {
  char err[1024];
  const char *set[] = {"c=2"};
  cv_scene *sc = cv_scene_load_text(catenary, "cat", 1, set, err, sizeof err);
  truth("catenary loads", sc != NULL, err);
  if (!sc) return;
  truth("unknown name", strcmp(cv_scene_get_unknown(sc, 0), "y") == 0, NULL);
  truth("title", strcmp(cv_scene_get_title(sc), "Catenary") == 0, cv_scene_get_title(sc));
  truth("elements option", cv_scene_set_option(sc, "elements", 32, err, sizeof err) == 0, err);
  truth("degree option", cv_scene_set_option(sc, "degree", 4, err, sizeof err) == 0, err);
  truth("bad degree refused",
        cv_scene_set_option(sc, "degree", 9, err, sizeof err) == CVAR_EINVAL &&
            strstr(err, "degree"),
        err);
  truth("unknown option refused",
        cv_scene_set_option(sc, "colour", 1, err, sizeof err) == CVAR_EINVAL &&
            strstr(err, "colour"),
        err);
  cv_status why;
  cv_problem *p = cv_scene_problem_new(sc, err, sizeof err);
  cv_solver *s = cv_solver_new(&why);
  truth("problem", p != NULL, err);
  if (p && s && cv_scene_configure_solver(sc, s, err, sizeof err) == CVAR_OK) {
    truth("report before a solve", cv_report_new(sc, p, s, &why) == NULL && why == CVAR_ESTATE,
          NULL);
    truth("solve converges", cv_solve(s, p) == CVAR_OK, cv_solver_last_error(s));
    int nn = cv_solver_get_num_nodes(s);
    truth("nodes 32*4+1", nn == 129, NULL);
    double *x = malloc((size_t)nn * sizeof *x), *y = malloc((size_t)nn * sizeof *y), e = 0;
    cv_solver_get_nodes(s, x);
    cv_solver_get_values(s, y);
    for (int j = 0; j < nn; j++) e = fmax(e, fabs(y[j] - 2 * cosh(x[j] / 2)));
    near("catenary max nodal error (c=2 from the override)", e, 0, 1e-10);
    cv_report *r = cv_report_new(sc, p, s, &why);
    truth("report", r != NULL, NULL);
    if (r) {
      const char *j = cv_report_json(r);
      truth("report: converged", strstr(j, "\"status\": \"converged\"") != NULL, j);
      truth("report: schema key", strstr(j, "\"schema\": 1") != NULL, j);
      const char *m = strstr(j, "\"max_nodal\": ");
      truth("report: max_nodal present", m != NULL, j);
      if (m) near("report: max_nodal equals ours", atof(m + 13), e, 1e-13 + 1e-6 * e);
    }
    cv_report_free(r);
    free(x);
    free(y);
  }
  cv_solver_free(s);
  cv_problem_free(p);
  cv_scene_free(sc);

  /* Bad input: FILE:LINE: sentences, NULL handles, nothing else. */
  sc = cv_scene_load_text("[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2 +\n", "bad", 0,
                          NULL, err, sizeof err);
  truth("bad integrand refused with bad:4:", !sc && strncmp(err, "bad:4:", 6) == 0, err);
  sc = cv_scene_load_text(catenary, "cat", 1, (const char *[]){"nosuch=1"}, err, sizeof err);
  truth("unknown override refused", !sc && strstr(err, "nosuch"), err);
  sc = cv_scene_load_file("/nonexistent/dir/x.scene", 0, NULL, err, sizeof err);
  truth("missing file refused", !sc && strstr(err, "x.scene"), err);
}

static void test_formula_constraints(void) {
  char err[512];
  cv_status why;
  /* isoperimetric */
  cv_problem *p = cv_problem_new(1, 0, 1, &why);
  cv_solver *s = cv_solver_new(&why);
  int idx = -1;
  truth("integrand",
        cv_problem_set_integrand_expr(p, NULL, "y", "y'^2/2", NULL, err, sizeof err) == CVAR_OK,
        err);
  truth("integral by formula",
        cv_problem_add_integral_expr(p, NULL, "y", "k*y", 1.0, "k = 1", &idx, err, sizeof err) ==
                CVAR_OK &&
            idx == 0,
        err);
  cv_problem_set_dirichlet(p, 0, 0, 0);
  cv_solver_set_elements(s, 8);
  cv_solver_set_degree(s, 2);
  truth("isoperimetric converges", cv_solve(s, p) == CVAR_OK, cv_solver_last_error(s));
  double xs[5] = {0.1, 0.33, 0.5, 0.71, 0.97}, ys[5], e = 0, mu = 0;
  cv_solver_eval(s, 5, xs, ys, NULL);
  for (int k = 0; k < 5; k++) e = fmax(e, fabs(ys[k] - 6 * (xs[k] - xs[k] * xs[k])));
  near("isoperimetric y = 6(x - x^2) between nodes", e, 0, 1e-10);
  cv_solver_get_multiplier(s, 0, &mu);
  near("isoperimetric |mu| = 12", fabs(mu), 12, 1e-8);
  cv_problem_free(p);

  /* pointwise u = v */
  p = cv_problem_new(2, 0, 1, &why);
  cv_problem_set_integrand_expr(p, "t", "u, v", "(u'^2 + v'^2)/2 + u", NULL, err, sizeof err);
  cv_problem_set_dirichlet(p, 0, 0, 0);
  cv_problem_set_dirichlet(p, 1, 0, 0);
  truth("constraint by formula",
        cv_problem_add_constraint_expr(p, "t", "u, v", "u - v", NULL, &idx, err, sizeof err) ==
                CVAR_OK &&
            idx == 0,
        err);
  truth("constraint with u' refused",
        cv_problem_add_constraint_expr(p, "t", "u, v", "u' - v", NULL, NULL, err, sizeof err) ==
                CVAR_EINVAL &&
            strstr(err, "u'"),
        err);
  truth("constraint syntax error refused",
        cv_problem_add_constraint_expr(p, "t", "u, v", "u - (v", NULL, NULL, err, sizeof err) ==
                CVAR_EINVAL &&
            strstr(err, "constraint"),
        err);
  truth("still one constraint", cv_problem_get_num_constraints(p) == 1, NULL);
  truth("pointwise converges", cv_solve(s, p) == CVAR_OK, cv_solver_last_error(s));
  double yy[10];
  cv_solver_eval(s, 5, xs, yy, NULL);
  e = 0;
  for (int i = 0; i < 2; i++)
    for (int k = 0; k < 5; k++) e = fmax(e, fabs(yy[i * 5 + k] - (xs[k] * xs[k] - xs[k]) / 4));
  near("pointwise u = v = (t^2 - t)/4", e, 0, 1e-10);
  cv_problem_free(p);
  cv_solver_free(s);
}

int main(void) {
  test_scene();
  test_formula_constraints();
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? 1 : 0;
}
