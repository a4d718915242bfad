/* tests/scene/test_mechanics_api.c — the public mechanics (cv_equations_*, cv_modes_*)
 * through calcvar.h only, linked against the shared library (so only exported names work).
 * SPDX-License-Identifier: MIT
 *
 * Exact answers:
 *  - pendulum L = m l^2 th'^2/2 + m g l cos th with m = l = 1, g = 9.81: p = th',
 *    E = th'' + 9.81 sin th, H = th'^2/2 - 9.81 cos th (theory (P-3)..(P-5)), as the exact
 *    printed strings (the parameters are printed as their shortest decimals).
 *  - double pendulum, equal masses and lengths, g = 4, l = 1/2: omega^2 = (g/l)(2 -+ sqrt 2)
 *    with shapes b = +-sqrt(2) a; the eigenproblem is 2x2, so to 1e-10 relative; and the
 *    getters agree with each other: v^T M v = 1, K v = omega^2 M v to 1e-10.
 *  - bad input: an integrand with the variable in it (modes do not apply: CVAR_EINVAL,
 *    "NAME:4:"), a force nothing balances (CVAR_EMAXITER), NULL arguments.
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

static void same(const char *what, const char *actual, const char *expected) {
  char d[300];
  snprintf(d, sizeof d, "expected \"%s\", actual \"%s\"", expected, actual ? actual : "(null)");
  truth(what, actual && strcmp(actual, expected) == 0, d);
}

static const char pendulum[] = "[scene]\n"
                               "variable = t\n"
                               "interval = 0, 0.5\n"
                               "unknowns = th\n"
                               "integrand = m*l^2*th'^2/2 + m*g*l*cos(th)\n"
                               "[parameters]\n"
                               "m = 1\n"
                               "l = 1\n"
                               "g = 9.81\n"
                               "[boundary]\n"
                               "th = 0, 1\n";

static const char double_pendulum[] =
    "[scene]\n"
    "variable = t\n"
    "interval = 0, 1\n"
    "unknowns = a, b\n"
    "integrand = m*l^2*(2*a'^2 + b'^2 + 2*a'*b'*cos(a - b))/2 + m*g*l*(2*cos(a) + cos(b))\n"
    "[parameters]\n"
    "m = 1\n"
    "l = 1\n"
    "g = 9.81\n"
    "[boundary]\n"
    "a = 0, 0\n"
    "b = 0, 0\n";

static void test_equations(void) {
  char err[1024];
  cv_status why = CVAR_ENOMEM;
  cv_scene *sc = cv_scene_load_text(pendulum, "pendulum", 0, NULL, err, sizeof err);
  truth("pendulum loads", sc != NULL, err);
  if (!sc) return;
  cv_equations *e = cv_equations_new(sc, &why, err, sizeof err);
  cv_scene_free(sc); /* the handle does not refer to the scene */
  truth("equations made", e != NULL && why == CVAR_OK, err);
  if (!e) return;
  truth("one unknown", cv_equations_get_num_unknowns(e) == 1, NULL);
  same("momentum", cv_equations_get_momentum(e, 0), "th'");
  same("Euler-Lagrange", cv_equations_get_euler_lagrange(e, 0), "th'' + 9.81*sin(th)");
  same("Hamiltonian", cv_equations_get_hamiltonian(e), "0.5*th'^2 - 9.81*cos(th)");
  truth("integrand printed",
        cv_equations_get_integrand(e) != NULL &&
            strstr(cv_equations_get_integrand(e), "cos(th)") != NULL,
        NULL);
  truth("not cyclic", cv_equations_is_cyclic(e, 0) == 0, NULL);
  truth("autonomous", cv_equations_is_autonomous(e) == 1, NULL);
  truth("out of range",
        cv_equations_get_momentum(e, 1) == NULL && cv_equations_get_euler_lagrange(e, -1) == NULL &&
            cv_equations_is_cyclic(e, 7) == 0,
        NULL);
  const char *json = cv_equations_json(e);
  truth("JSON has the equation",
        json[0] == '{' && strstr(json, "\"th\": \"th'' + 9.81*sin(th)\"") != NULL &&
            strstr(json, "\"autonomous\": true") != NULL,
        json);
  cv_equations_free(e);
}

static void test_modes(void) {
  char err[1024];
  cv_status why = CVAR_ENOMEM;
  const char *set[] = {"g=4", "l=0.5"};
  double g = 4, l = 0.5;
  cv_scene *sc = cv_scene_load_text(double_pendulum, "dp", 2, set, err, sizeof err);
  truth("double pendulum loads", sc != NULL, err);
  if (!sc) return;
  cv_modes *m = cv_modes_new(sc, &why, err, sizeof err);
  cv_scene_free(sc);
  truth("modes made", m != NULL && why == CVAR_OK, err);
  if (!m) return;
  int n = cv_modes_get_num_unknowns(m), nm = cv_modes_get_num_modes(m);
  truth("sizes", n == 2 && nm == 2 && cv_modes_get_num_constraints(m) == 0, NULL);
  if (n != 2 || nm != 2) {
    cv_modes_free(m);
    return;
  }
  double y[2], w2[2], v[4], M[4], K[4];
  truth("getters",
        cv_modes_get_equilibrium(m, y) == CVAR_OK && cv_modes_get_omega2(m, w2) == CVAR_OK &&
            cv_modes_get_shapes(m, v) == CVAR_OK && cv_modes_get_matrices(m, M, K) == CVAR_OK &&
            cv_modes_get_multipliers(m, NULL) == CVAR_OK,
        NULL);
  near("equilibrium a", y[0], 0, 1e-12);
  near("equilibrium b", y[1], 0, 1e-12);
  double exact[2] = {g / l * (2 - sqrt(2)), g / l * (2 + sqrt(2))};
  for (int k = 0; k < 2; k++) {
    const double *vk = v + 2 * k;
    near("omega2", w2[k], exact[k], 1e-10 * exact[k]);
    truth("stable", cv_modes_get_kind(m, k) == CVAR_MODE_STABLE, NULL);
    near("shape b/a", vk[1] / vk[0], k == 0 ? sqrt(2) : -sqrt(2), 1e-10);
    double Mv[2], Kv[2];
    for (int i = 0; i < 2; i++) {
      Mv[i] = M[2 * i] * vk[0] + M[2 * i + 1] * vk[1];
      Kv[i] = K[2 * i] * vk[0] + K[2 * i + 1] * vk[1];
    }
    near("v'Mv = 1", vk[0] * Mv[0] + vk[1] * Mv[1], 1, 1e-10);
    for (int i = 0; i < 2; i++) near("K v = w2 M v", Kv[i], w2[k] * Mv[i], 1e-10 * exact[1]);
  }
  truth("kind out of range", cv_modes_get_kind(m, 2) == CVAR_MODE_NEUTRAL, NULL);
  const char *json = cv_modes_json(m);
  truth("JSON",
        json[0] == '{' && strstr(json, "\"omega2\"") != NULL &&
            strstr(json, "\"kind\": \"stable\"") != NULL && json[strlen(json) - 1] == '}',
        json);
  cv_modes_free(m);
}

static void expect_failure(const char *what, const char *text, cv_status status,
                           const char *prefix) {
  char err[1024];
  cv_status why = CVAR_OK;
  cv_scene *sc = cv_scene_load_text(text, "bad", 0, NULL, err, sizeof err);
  truth(what, sc != NULL, err);
  if (!sc) return;
  cv_modes *m = cv_modes_new(sc, &why, err, sizeof err);
  truth(what, m == NULL && why == status, err);
  truth(what, strncmp(err, prefix, strlen(prefix)) == 0, err);
  cv_modes_free(m);
  cv_scene_free(sc);
}

static void test_errors(void) {
  char err[64] = "x";
  cv_status why = CVAR_OK;
  truth("NULL scene",
        cv_equations_new(NULL, &why, err, sizeof err) == NULL && why == CVAR_EINVAL && err[0], err);
  why = CVAR_OK;
  truth("NULL scene (modes)", cv_modes_new(NULL, &why, NULL, 0) == NULL && why == CVAR_EINVAL,
        NULL);
  truth("NULL handles",
        cv_equations_json(NULL)[0] == '\0' && cv_modes_json(NULL)[0] == '\0' &&
            cv_modes_get_equilibrium(NULL, NULL) == CVAR_EINVAL &&
            cv_equations_get_hamiltonian(NULL) == NULL,
        NULL);
  cv_equations_free(NULL);
  cv_modes_free(NULL);
  expect_failure("depends on x",
                 "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2/2 + x*y\n"
                 "[boundary]\ny = 0, 1\n",
                 CVAR_EINVAL, "bad:4:");
  expect_failure("no equilibrium",
                 "[scene]\ninterval = 0, 1\nunknowns = y\nintegrand = y'^2/2 + y\n"
                 "[boundary]\ny = 0, 1\n",
                 CVAR_EMAXITER, "bad");
}

int main(void) {
  test_equations();
  test_modes();
  test_errors();
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? EXIT_FAILURE : EXIT_SUCCESS;
}
