/* tests/deflation/test_deflation.c — the C API of the deflated search (cv_solve_all):
 * Bratu's two paths against the closed form through the getters, selection, the search
 * record, states and bad arguments, and a later cv_solve forgetting the paths.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calcvar.h"
#include "core/cv_memory.h"

static int fails;
#define CHECK(c, ...)                                                                              \
  do {                                                                                             \
    if (!(c)) {                                                                                    \
      fails++;                                                                                     \
      printf("FAIL %s:%d: ", __FILE__, __LINE__);                                                  \
      printf(__VA_ARGS__);                                                                         \
      printf("\n");                                                                                \
    }                                                                                              \
  } while (0)

/* the root of th = sqrt(2) cosh(th/4) in [lo, hi] by bisection */
static double theta(double lo, double hi) {
  for (int i = 0; i < 200; i++) {
    double m = 0.5 * (lo + hi);
    if ((lo - sqrt(2.0) * cosh(lo / 4)) * (m - sqrt(2.0) * cosh(m / 4)) <= 0)
      hi = m;
    else
      lo = m;
  }
  return 0.5 * (lo + hi);
}

int main(void) {
  cv_status why;
  char err[256];
  cv_problem *p = cv_problem_new(1, 0.0, 1.0, &why);
  cv_solver *s = cv_solver_new(&why);
  cv_search_info in;
  if (!p || !s) return 1;
  CHECK(cv_problem_set_integrand_expr(p, "x", "y", "y'^2/2 - exp(y)", NULL, err, sizeof err) ==
            CVAR_OK,
        "%s", err);
  cv_problem_set_dirichlet(p, 0, 0.0, 0.0);
  cv_solver_set_elements(s, 24);
  cv_solver_set_degree(s, 8);
  CHECK(cv_solver_get_num_solutions(s) == 0, "no paths before a search");
  CHECK(cv_solver_select_solution(s, 0) == CVAR_ESTATE, "select before a search");
  CHECK(cv_solver_get_search(s, &in) == CVAR_ESTATE, "search info before a search");
  CHECK(cv_solve_all(s, p, 0) == CVAR_EINVAL, "max 0");
  CHECK(cv_solver_set_search_work(s, 0.5) == CVAR_EINVAL, "work below 1");
  cv_solver_set_method(s, CVAR_METHOD_LBFGS);
  CHECK(cv_solve_all(s, p, 4) == CVAR_EINVAL, "a minimiser cannot search for saddles");
  cv_solver_set_method(s, CVAR_METHOD_NEWTON);

  CHECK(cv_solve_all(s, p, 8) == CVAR_OK, "%s", cv_solver_last_error(s));
  CHECK(cv_solver_get_num_solutions(s) == 2, "%d paths", cv_solver_get_num_solutions(s));
  CHECK(cv_solver_get_search(s, &in) == CVAR_OK && in.found == 2 && in.starts >= 2 && in.stop[0],
        "search record: %d found, %d starts", in.found, in.starts);
  double th[2] = {theta(0.5, 4.0), theta(4.0, 20.0)}, prev = -INFINITY;
  for (int k = 0; k < cv_solver_get_num_solutions(s); k++) {
    CHECK(cv_solver_select_solution(s, k) == CVAR_OK, "select %d", k);
    int nn = cv_solver_get_num_nodes(s);
    double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), e = 0.0;
    cv_solver_get_nodes(s, x);
    cv_solver_get_values(s, y);
    for (int j = 0; j < nn; j++) {
      double ex = -2 * log(cosh((x[j] - 0.5) * th[k] / 2) / cosh(th[k] / 4));
      e = fmax(e, fabs(y[j] - ex));
    }
    CHECK(e < 1e-10, "path %d: max nodal error %.3g against the closed form", k, e);
    CHECK(cv_solver_get_morse_index(s) == k, "path %d: Morse index %d", k,
          cv_solver_get_morse_index(s));
    CHECK(cv_solver_get_status(s) == CVAR_OK, "path %d status", k);
    CHECK(cv_solver_get_action(s) > prev, "ordered by action");
    prev = cv_solver_get_action(s);
    free(x);
    free(y);
  }
  CHECK(cv_solver_select_solution(s, 2) == CVAR_EINVAL, "select out of range");
  CHECK(cv_solver_select_solution(s, 0) == CVAR_OK && cv_solver_get_morse_index(s) == 0,
        "back to the first path");
  /* --max 1: the search stops at one path, the plain solve's from the guess */
  CHECK(cv_solve_all(s, p, 1) == CVAR_OK && cv_solver_get_num_solutions(s) == 1, "max 1");
  /* a plain solve forgets the paths */
  CHECK(cv_solve(s, p) == CVAR_OK && cv_solver_get_num_solutions(s) == 0 &&
            cv_solver_get_search(s, &in) == CVAR_ESTATE,
        "cv_solve forgets the paths");
  /* every allocation of a small search fails once in turn: a status, never a crash or a
   * leak (the ASan build checks the leaks); the search succeeds once allocations do */
  cv_solver_set_elements(s, 4);
  cv_solver_set_degree(s, 3);
  int k, done = 0;
  for (k = 0; k < 3000; k++) { /* a small search makes fewer allocations than that */
    cv_debug_fail_alloc_after(k);
    cv_status st = cv_solve_all(s, p, 2);
    cv_debug_fail_alloc_after(-1);
    int np = cv_solver_get_num_solutions(s);
    CHECK(st == CVAR_OK ? np >= 1 : np == 0, "allocation %d: status %d with %d paths", k, st, np);
    done |= st == CVAR_OK && np == 2;
  }
  CHECK(done, "the search never completed");
  CHECK(cv_solve_all(s, p, 2) == CVAR_OK && cv_solver_get_num_solutions(s) == 2, "after the sweep");
  printf("allocation failures injected at %d points\n", k);
  cv_solver_free(s);
  cv_problem_free(p);
  printf("%s\n", fails ? "FAILED" : "ok");
  return fails != 0;
}
