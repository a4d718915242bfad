/* tests/scene/test_scene_load.c — the scene loader from strings: values, overrides,
 * definitions, comments, continuations, long lines, free ends, guesses, line numbers.
 * SPDX-License-Identifier: MIT
 *
 * Values are compared exactly where the loader only parses and folds constants (a
 * constant folded by the DAG may differ from libm's result in the last bit, hence
 * tolerance 4 eps relative there), and the messages' FILE:LINE: prefixes exactly.
 */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

static int failures, checks;

static void near(const char *what, double actual, double expected, double tol) {
  checks++;
  if (!(fabs(actual - expected) <= tol)) {
    failures++;
    printf("FAIL %s\n  expected: %.17g\n  actual:   %.17g\n  tolerance: %g\n", what, expected,
           actual, tol);
  }
}

static void truth(const char *what, int ok, const char *expected, const char *actual) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s\n  expected: %s\n  actual:   %s\n", what, expected, actual);
  }
}

static scene *load(const char *text, int nset, const sc_set *set, char *err) {
  return scene_load_buffer(text, strlen(text), "t.scene", nset, set, err, SC_ERRLEN);
}

/* Load must fail with a message starting with `prefix` and containing `part`. */
static void must_fail(const char *what, const char *text, size_t len, const char *prefix,
                      const char *part) {
  char err[SC_ERRLEN];
  scene *s = scene_load_buffer(text, len, "t.scene", 0, NULL, err, sizeof err);
  truth(what, !s && strncmp(err, prefix, strlen(prefix)) == 0 && strstr(err, part) != NULL, prefix,
        s ? "(loaded)" : err);
  scene_free(s);
}

/* H = sum_i y'_i dF/dy'_i - F of s's compiled problem at one point (NaN on failure). */
static double energy_at(const scene *s, double x, const double *y, const double *dy) {
  char err[SC_ERRLEN];
  double H = NAN;
  cv_problem *p = scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD, err, sizeof err);
  if (!p || cv_problem_eval_energy(p, 1, &x, y, dy, &H, NULL) != CVAR_OK) H = NAN;
  cv_problem_free(p);
  return H;
}

/* Evaluate report r of s at one point (x, y[], dy[]). */
static double report_at(scene *s, int r, double x, const double *y, const double *dy) {
  double *out = calloc((size_t)s->nreports, sizeof *out), v;
  if (scene_eval_reports(s, 1, &x, y, dy, out) < 0)
    v = NAN;
  else
    v = out[r];
  free(out);
  return v;
}

static const char *CATENARY =
    "# Catenary\n"
    "[scene]\n"
    "title     = Catenary between two rings\n"
    "variable  = x                       # independent variable name (default x)\n"
    "interval  = -1, 1                   ; a, b with a < b\n"
    "unknowns  = y\n"
    "integrand = y * sqrt(1 + y'^2)\n"
    "[parameters]\n"
    "c = 2\n"
    "d = 2*c\n"
    "[definitions]\n"
    "ends = c*cosh(1/c)\n"
    "[boundary]\n"
    "y = ends, ends\n"
    "[exact]\n"
    "y = c*cosh(x/c)\n"
    "action = 4.350402387287603\n";

static void test_catenary(void) {
  char err[SC_ERRLEN];
  scene *s = load(CATENARY, 0, NULL, err);
  truth("catenary loads", s != NULL, "a scene", err);
  if (!s) return;
  truth("title", strcmp(s->title, "Catenary between two rings") == 0, "Catenary between two rings",
        s->title);
  truth("variable", strcmp(s->variable, "x") == 0, "x", s->variable);
  near("a", s->a, -1, 0);
  near("b", s->b, 1, 0);
  near("n", s->n, 1, 0);
  near("parameter c", s->params[0].value, 2, 0);
  near("parameter d = 2c", s->params[1].value, 4, 0);
  near("y(a) = ends", s->bc[0].value[0], 2 * cosh(0.5), 4 * DBL_EPSILON * 2.3);
  near("y(b) = ends", s->bc[0].value[1], 2 * cosh(0.5), 4 * DBL_EPSILON * 2.3);
  near("exact action", s->exact_action, 4.350402387287603, 0);
  near("default elements", s->elements, 100, 0);
  near("default degree", s->degree, 1, 0);
  near("default method newton", s->method, CVAR_METHOD_NEWTON, 0);
  near("default tolerance", s->tolerance, 1e-10, 0);
  near("default max_iterations", s->max_iterations, 50, 0);
  truth("F has no explicit x", !scene_F_depends_on_variable(s), "0", "1");
  truth("F depends on y", scene_F_depends_on_unknown(s, 0), "1", "0");
  double x = 0.5, ex;
  scene_eval_exact(s, 1, &x, &ex);
  near("exact y(0.5)", ex, 2 * cosh(0.25), 4 * DBL_EPSILON * 2.1);
  double y[2] = {2.0, 0}, dy[1] = {0.75}, H = energy_at(s, x, y, dy);
  /* H = y' F_y' - F = -y / sqrt(1 + y'^2) = -2 / 1.25 */
  near("energy H", H, -1.6, 4 * DBL_EPSILON * 1.6);
  scene_free(s);

  sc_set set[2] = {{"c", "3"}, {"c", "pi"}};
  s = load(CATENARY, 1, set, err);
  truth("--set c=3 loads", s != NULL, "a scene", err);
  if (s) {
    near("--set c=3: c", s->params[0].value, 3, 0);
    near("--set c=3: d follows", s->params[1].value, 6, 0);
    near("--set c=3: ends follow", s->bc[0].value[0], 3 * cosh(1.0 / 3), 4 * DBL_EPSILON * 3.2);
    scene_free(s);
  }
  s = load(CATENARY, 2, set, err);
  if (s) {
    near("the last --set wins", s->params[0].value, M_PI, 0);
    scene_free(s);
  } else
    truth("two --set load", 0, "a scene", err);
  sc_set bad = {"e", "1"};
  s = load(CATENARY, 1, &bad, err);
  truth("--set of a non-parameter fails without a line",
        !s && strncmp(err, "t.scene: --set e=1: 'e' is not a parameter", 42) == 0,
        "t.scene: --set e=1: 'e' is not a parameter...", err);
  scene_free(s);
  sc_set nonconst = {"c", "x"};
  s = load(CATENARY, 1, &nonconst, err);
  truth("--set c=x fails", !s && strncmp(err, "t.scene: --set c=x", 18) == 0,
        "t.scene: --set c=x...", err);
  scene_free(s);
}

/* Continuations, comments of both kinds, CRLF, a byte order mark, definitions in order,
 * free ends, lists with commas inside parentheses, a 1000-character expression. */
static void test_format(void) {
  char err[SC_ERRLEN];
  const char *text = "\xEF\xBB\xBF[scene]\r\n"
                     "interval  = 0, atan2(1, 1)*4   # pi, with a comma inside parentheses\r\n"
                     "unknowns  = u, v\r\n"
                     "integrand = u'^2/2 +\r\n"
                     "    v'^2/2      # continued\r\n"
                     "\r\n"
                     "  ; a comment between continuation lines\r\n"
                     "    + k*u*v\r\n"
                     "[parameters]\r\n"
                     "k = 0.25\r\n"
                     "[definitions]\r\n"
                     "a = u + v\r\n"
                     "b = a*u'          # uses the earlier definition\r\n"
                     "[boundary]\r\n"
                     "u = free, 1\r\n"
                     "v = 0, free\r\n"
                     "[report]\r\n"
                     "r1 = b + x\r\n"
                     "r2 = k*u*v\r\n";
  scene *s = load(text, 0, NULL, err);
  truth("format scene loads", s != NULL, "a scene", err);
  if (!s) return;
  near("b = atan2(1, 1)*4", s->b, M_PI, 4 * DBL_EPSILON * M_PI);
  truth("unknown names", s->n == 2 && !strcmp(s->unknowns[0], "u") && !strcmp(s->unknowns[1], "v"),
        "u, v", "other");
  truth("u free at a", s->bc[0].free_end[0] && !s->bc[0].free_end[1], "free, fixed", "?");
  truth("v free at b", !s->bc[1].free_end[0] && s->bc[1].free_end[1], "fixed, free", "?");
  near("u(b) = 1", s->bc[0].value[1], 1, 0);
  double y[2] = {2, 3}, dy[2] = {5, 7}, x = 0.5;
  near("report b + x = (u + v) u' + x", report_at(s, 0, x, y, dy), 25.5, 0);
  near("report k u v", report_at(s, 1, x, y, dy), 1.5, 0);
  double g[2];
  scene_eval_guess(s, 1, &x, g);
  near("default guess with a free start: the fixed value", g[0], 1, 0);
  near("default guess with a free end: the fixed value", g[1], 0, 0);
  double H = energy_at(s, x, y, dy);
  /* F = u'^2/2 + v'^2/2 + k u v; H = u'^2/2 + v'^2/2 - k u v = 12.5 + 24.5 - 1.5 */
  near("energy of the continued integrand", H, 35.5, 4 * DBL_EPSILON * 36);
  scene_free(s);

  /* A 1000+ character integrand: sum_{k=1}^{150} y'^2/k, and a long [report] key. */
  size_t cap = 8192, len = 0;
  char *big = malloc(cap);
  len += (size_t)snprintf(big + len, cap - len,
                          "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = ");
  double hsum = 0;
  for (int k = 1; k <= 150; k++) {
    len += (size_t)snprintf(big + len, cap - len, "%sy'^2/%d", k > 1 ? " + " : "", k);
    hsum += 1.0 / k;
  }
  size_t line_len = len;
  len += (size_t)snprintf(big + len, cap - len, "\n[boundary]\ny = 0, 1\n[report]\nsame = ");
  for (int k = 1; k <= 150; k++)
    len += (size_t)snprintf(big + len, cap - len, "%sy'^2/%d", k > 1 ? " + " : "", k);
  len += (size_t)snprintf(big + len, cap - len, "\n");
  truth("the long line is longer than inih's 200", line_len > 1000, "> 1000", "shorter");
  s = load(big, 0, NULL, err);
  truth("long lines load", s != NULL, "a scene", err);
  if (s) {
    double yy = 0.3, d = 2;
    near("long report value", report_at(s, 0, 0.5, &yy, &d), 4 * hsum, 1e-13);
    scene_free(s);
  }
  /* An error near the end of the long line names line 4 and its real column. */
  char *p = strstr(big, "y'^2/150");
  p[0] = 'q';
  s = load(big, 0, NULL, err);
  truth("error on a long line: line 4, column > 1000",
        !s && !strncmp(err, "t.scene:4: ", 11) && strstr(err, "column 1") && strstr(err, "'q'"),
        "t.scene:4: integrand, column 1xxx", err);
  scene_free(s);
  free(big);
}

static void test_errors(void) {
  const char *H = "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2\n";
  char buf[1024];
  must_fail("NUL byte", "[scene]\ninterval = 0, 1\n\0x = 1\n", 25, "t.scene:3: ", "NUL");
  must_fail("empty text", "", 0, "t.scene:1: ", "[scene] is missing");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[integrals]\nL = 1, 2, 3\n", H);
  must_fail("integral with 3 values", buf, strlen(buf), "t.scene:8: ", "'K, c'");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[constraints]\ng = y - 1\n", H);
  must_fail("constraint failing at a", buf, strlen(buf), "t.scene:8: ", "does not hold");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[constraints]\ng = 2*x\n", H);
  must_fail("constraint without unknowns", buf, strlen(buf), "t.scene:8: ", "no unknown");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[constraints]\ng = y*(y - 1)\n", H);
  must_fail("a pointwise constraint on the only unknown", buf, strlen(buf),
            "t.scene:8: ", "no degree of freedom");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[mesh]\nbreakpoints = 0.5, 0.5\n", H);
  must_fail("breakpoint twice", buf, strlen(buf), "t.scene:8: ", "twice");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[mesh]\ngrading_at = middle\n", H);
  must_fail("grading_at", buf, strlen(buf), "t.scene:8: ", "a, b or both");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n  continued = 1\n", H);
  /* joined: "0, 1 continued = 1", so the error is at line 7, column 3 */
  must_fail("an indented line continues the value", buf, strlen(buf),
            "t.scene:7: ", "column 3: unexpected");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[%*s]\n", H, 300, "x");
  must_fail("a very long section name", buf, strlen(buf), "t.scene:7: ", "unknown section");
  snprintf(buf, sizeof buf, "%s[boundary]\n%0*d = 0, 1\n", H, 150, 7);
  must_fail("a very long key", buf, strlen(buf), "t.scene:6: ", "too long");
  snprintf(buf, sizeof buf, "%s[boundary]\ny = 0, 1\n[guess]\ny = 1 +\n    2 + w\n", H);
  must_fail("error on a continuation line", buf, strlen(buf), "t.scene:9: ", "'w'");
}

static void test_good_extras(void) {
  char err[SC_ERRLEN];
  const char *text =
      "[scene]\ninterval = 0, 2\nunknowns = y\nintegrand = if(x < 1, 1, 2)*y'^2\n"
      "[boundary]\ny = 0, 1\n[guess]\ny = x^2/4\n"
      "[constraints]\n[integrals]\nL = sqrt(1 + y'^2), 3\n"
      "[mesh]\nelements = 7\ndegree = 8\nbreakpoints = 1.5, 1\ngrading = 2\ngrading_at = both\n"
      "[solver]\nmethod = lbfgs\ntolerance = 1e-8\nmax_iterations = 12\n";
  scene *s = load(text, 0, NULL, err);
  truth("extras load", s != NULL, "a scene", err);
  if (!s) return;
  near("elements", s->elements, 7, 0);
  near("degree", s->degree, 8, 0);
  near("breakpoints sorted", s->nbreak == 2 ? s->breakpoints[0] : -1, 1, 0);
  near("grading", s->grading, 2, 0);
  near("grading_at both", s->graded_end, CVAR_GRADE_BOTH, 0);
  near("method lbfgs", s->method, CVAR_METHOD_LBFGS, 0);
  /* lbfgs itself needs F and the gradient; the second partials are for the error
   * estimate's Newton solve on the enriched mesh (issue 29) */
  near("lbfgs: F, the gradient and the second partials (for the estimate)",
       scene_method_need(s->method), CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, 0);
  near("tolerance", s->tolerance, 1e-8, 0);
  near("max_iterations", s->max_iterations, 12, 0);
  near("integral c", s->nints == 1 ? s->ints[0].value : -1, 3, 0);
  double x = 1.0, g;
  scene_eval_guess(s, 1, &x, &g);
  near("guess x^2/4 at 1", g, 0.25, 0);
  truth("F depends on x through if()", scene_F_depends_on_variable(s), "1", "0");
  truth("y is cyclic", !scene_F_depends_on_unknown(s, 0), "0", "1");
  scene_free(s);
}

int main(void) {
  test_catenary();
  test_format();
  test_errors();
  test_good_extras();
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? 1 : 0;
}
