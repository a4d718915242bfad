/* tests/core/test_api.c — bad input and failure paths: statuses and messages, never a crash
 * or a claimed success; derivative checker; version; allocation failures.
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <string.h>

#include "refproblems.h"
#include "core/cv_internal.h"

static int nan_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                 cv_partials *o, void *user) {
  (void)x;
  (void)y;
  (void)dy;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) o->F[k] = NAN;
  return 0;
}

static int abort_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  (void)m;
  (void)x;
  (void)y;
  (void)dy;
  (void)need;
  (void)o;
  (void)user;
  return -1;
}

/* Catenary with a deliberately wrong F_y'y' (factor 1.1), for the derivative checker. */
static int wrong_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  catenary_F(m, x, y, dy, need, o, user);
  if (o->Fpp)
    for (int k = 0; k < m; k++) o->Fpp[k] *= 1.1;
  return 0;
}

static void check_status(const char *what, cv_status got, cv_status want) {
  CHECK(got == want, "%s: got %s, expected %s", what, cv_status_name(got), cv_status_name(want));
}

int main(void) {
  cv_status why = CVAR_OK;
  /* Constructors. */
  CHECK(cv_problem_new(1, 1, 1, &why) == NULL && why == CVAR_EINVAL, "a = b accepted");
  CHECK(cv_problem_new(1, 2, 1, &why) == NULL && why == CVAR_EINVAL, "a > b accepted");
  CHECK(cv_problem_new(0, 0, 1, &why) == NULL && why == CVAR_EINVAL, "zero unknowns accepted");
  CHECK(cv_problem_new(1, 0, INFINITY, &why) == NULL && why == CVAR_EINVAL, "b = inf accepted");
  CHECK(cv_problem_new(1, NAN, 1, &why) == NULL && why == CVAR_EINVAL, "a = NaN accepted");

  cv_problem *p = cv_problem_new(1, 0, 1, &why);
  cv_solver *s = cv_solver_new(&why);
  check_status("set_degree 0", cv_solver_set_degree(s, 0), CVAR_EINVAL);
  check_status("set_degree 9", cv_solver_set_degree(s, 9), CVAR_EINVAL);
  check_status("set_elements 0", cv_solver_set_elements(s, 0), CVAR_EINVAL);
  check_status("tolerances negative", cv_solver_set_tolerances(s, -1e-3, 1e-10), CVAR_EINVAL);
  check_status("tolerances both zero", cv_solver_set_tolerances(s, 0, 0), CVAR_EINVAL);
  check_status("rtol below 10 eps", cv_solver_set_tolerances(s, 1e-17, 0), CVAR_EINVAL);
  check_status("tolerance NaN", cv_solver_set_tolerances(s, NAN, 1e-10), CVAR_EINVAL);
  check_status("dirichlet NaN", cv_problem_set_dirichlet(p, 0, NAN, 1), CVAR_EINVAL);
  check_status("dirichlet inf", cv_problem_set_dirichlet(p, 0, 0, INFINITY), CVAR_EINVAL);
  check_status("end index", cv_problem_set_end_value(p, 1, 0, 0.0), CVAR_EINVAL);
  check_status("end side", cv_problem_set_free_end(p, 0, 2), CVAR_EINVAL);
  double bad_mesh[3] = {0, 0.7, 0.5};
  check_status("user mesh not increasing", cv_solver_set_mesh(s, 2, bad_mesh), CVAR_EINVAL);
  check_status("graded k < 1", cv_solver_set_mesh_graded(s, 10, 0.5, CVAR_GRADE_A), CVAR_EINVAL);
  check_status("max iterations 0", cv_solver_set_max_iterations(s, 0), CVAR_EINVAL);

  /* Results before any solve. */
  check_status("status before solve", cv_solver_get_status(s), CVAR_ESTATE);
  double xbuf[4];
  check_status("nodes before solve", cv_solver_get_nodes(s, xbuf), CVAR_ESTATE);
  check_status("solve without integrand", cv_solve(s, p), CVAR_EINVAL);

  /* A callback that returns NaN everywhere: a clean status, NaN never reported as success. */
  cv_problem_set_integrand(p, nan_F, NULL);
  cv_problem_set_dirichlet(p, 0, 0, 1);
  cv_status st = cv_solve(s, p);
  check_status("NaN integrand", st, CVAR_ENONFINITE);
  CHECK(strlen(cv_solver_last_error(s)) > 10, "no message for NaN integrand");
  cv_problem_set_integrand(p, abort_F, NULL);
  check_status("aborting callback", cv_solve(s, p), CVAR_ECALLBACK);

  /* Breakpoint outside the interval. */
  cv_problem_set_integrand(p, harmonic_F, NULL);
  double bp = 2.0;
  cv_solver_set_breakpoints(s, 1, &bp);
  check_status("breakpoint outside", cv_solve(s, p), CVAR_EINVAL);
  CHECK(strstr(cv_solver_last_error(s), "breakpoint") != NULL, "message: %s",
        cv_solver_last_error(s));
  /* A breakpoint inside must become a node. */
  bp = 0.3183;
  cv_solver_set_breakpoints(s, 1, &bp);
  cv_solver_set_elements(s, 10);
  check_status("breakpoint inside", cv_solve(s, p), CVAR_OK);
  {
    int nn = cv_solver_get_num_nodes(s), found = 0;
    double *x = malloc(nn * sizeof *x);
    cv_solver_get_nodes(s, x);
    for (int j = 0; j < nn; j++) found |= x[j] == bp;
    CHECK(found, "breakpoint %g is not a node", bp);
    free(x);
  }
  cv_solver_set_breakpoints(s, 0, NULL);

  /* Max iterations: one Newton step cannot solve the catenary to 1e-10. */
  cv_problem_set_integrand(p, catenary_F, NULL);
  cv_problem_set_dirichlet(p, 0, 1, 2);
  cv_solver_set_max_iterations(s, 1);
  check_status("max iterations", cv_solve(s, p), CVAR_EMAXITER);
  CHECK(cv_solver_get_status(s) == CVAR_EMAXITER, "status getter disagrees");
  cv_solver_set_max_iterations(s, 50);

  /* Derivative checker: exact partials pass at the eps^(2/3) level, a 10% error is named. */
  {
    double x[3] = {-0.5, 0.1, 0.7}, y[3] = {2.1, 2.3, 1.9}, dy[3] = {-0.3, 0.2, 0.5};
    cv_derivcheck rep;
    st = cv_problem_check_derivatives(p, 3, x, y, dy, &rep);
    CHECK(st == CVAR_OK && rep.worst < 1e-8, "exact partials: worst %.3g at %s", rep.worst,
          rep.which);
    cv_problem_set_integrand(p, wrong_F, NULL);
    st = cv_problem_check_derivatives(p, 3, x, y, dy, &rep);
    CHECK(st == CVAR_OK && rep.worst > 0.05 && strcmp(rep.which, "Fpp[0][0]") == 0,
          "wrong F_y'y' not found: worst %.3g at %s", rep.worst, rep.which);
    /* Vector case (sphere, n = 2): exact partials pass. */
    cv_problem *q = cv_problem_new(2, 0, 1, NULL);
    cv_problem_set_integrand(q, sphere_F, NULL);
    double y2[6] = {1.0, 1.2, 0.8, 0.1, 0.5, 0.9}, d2[6] = {0.3, -0.2, 0.6, 1.0, 1.5, 0.4};
    st = cv_problem_check_derivatives(q, 3, x, y2, d2, &rep);
    CHECK(st == CVAR_OK && rep.worst < 1e-8, "sphere partials: worst %.3g at %s", rep.worst,
          rep.which);
    cv_problem_free(q);
  }

  /* Version: header and library agree. */
  {
    int a, b, c;
    cv_version(&a, &b, &c);
    CHECK(a == CVAR_VERSION_MAJOR && b == CVAR_VERSION_MINOR && c == CVAR_VERSION_PATCH,
          "library version %d.%d.%d differs from header", a, b, c);
    for (int k = 0; k < CVAR_NUM_STATUS; k++)
      CHECK(strlen(cv_strerror((cv_status)k)) > 3, "empty message for status %d", k);
    CHECK(strcmp(cv_strerror((cv_status)999), "unknown status") == 0, "unknown status text");
  }

  /* Energy and momenta at more points than one callback batch (256): for the catenary
   * F = y sqrt(1 + y'^2), p = y y'/sqrt(1 + y'^2) and H = y' p - F = -y/sqrt(1 + y'^2),
   * compared with those closed forms: p to 8 eps relative, H to 4 eps (1 + y'^2) relative
   * (y'p and F are each (1 + y'^2) times larger than H and cancel); a failing callback is
   * reported. */
  {
    enum { M = 600 };
    static double xs[M], ys[M], ds[M], H[M], P[M];
    for (int k = 0; k < M; k++) {
      xs[k] = -1 + 2.0 * k / (M - 1);
      ys[k] = 1.5 + 0.25 * sin(3 * xs[k]);
      ds[k] = -2 + 4.0 * k / (M - 1);
    }
    cv_problem_set_integrand(p, catenary_F, NULL);
    st = cv_problem_eval_energy(p, M, xs, ys, ds, H, P);
    double worst = 0;
    for (int k = 0; k < M; k++) {
      double r = sqrt(1 + ds[k] * ds[k]);
      double eh = fabs(H[k] + ys[k] / r) / (ys[k] / r) / (4 * (1 + ds[k] * ds[k]));
      double ep = fabs(P[k] - ys[k] * ds[k] / r) / fmax(1e-300, fabs(ys[k] * ds[k] / r)) / 8;
      worst = fmax(worst, fmax(eh, ep));
    }
    CHECK(st == CVAR_OK && worst <= DBL_EPSILON,
          "energy/momenta at %d points: %s, worst "
          "error %.3g eps of its tolerance",
          M, cv_status_name(st), worst / DBL_EPSILON);
    CHECK(cv_problem_eval_energy(p, M, xs, NULL, ds, H, P) == CVAR_EINVAL, "NULL y accepted");
    cv_problem_set_integrand(p, abort_F, NULL);
    st = cv_problem_eval_energy(p, M, xs, ys, ds, H, NULL);
    CHECK(st == CVAR_ECALLBACK, "failing callback gave %s", cv_status_name(st));
  }

  /* Allocation failures: fail the k-th allocation of a whole solve, for every k, and expect
   * CVAR_ENOMEM (or success once k passes the number of allocations); ASan checks leaks. */
  cv_problem_set_integrand(p, catenary_F, NULL);
  cv_solver_set_elements(s, 8);
  cv_solver_set_degree(s, 2);
  int k, saw_ok = 0;
  for (k = 0; k < 200 && !saw_ok; k++) {
    cv_debug_fail_alloc_after(k);
    st = cv_solve(s, p);
    cv_debug_fail_alloc_after(-1);
    if (st == CVAR_OK)
      saw_ok = 1;
    else
      CHECK(st == CVAR_ENOMEM || st == CVAR_EDEPENDENCY, "allocation failure %d gave %s", k,
            cv_status_name(st));
  }
  CHECK(saw_ok, "solve never succeeded within 200 allocations");
  printf("allocation-failure sweep: %d injection points\n", k);

  cv_solver_free(s);
  cv_problem_free(p);
  cv_solver_free(NULL);
  cv_problem_free(NULL);
  if (n_failed)
    fprintf(stderr, "%d check(s) failed\n", n_failed);
  else
    printf("all API checks passed\n");
  return n_failed ? 1 : 0;
}
