/* bench/bench_adapt.c — boundary layers eps = 1e-2 .. 1e-8 with adaptive refinement (theory
 * AD-1) at degrees 1, 2 and 4: elements used, rounds, estimated and true max nodal error,
 * time. Usage: bench_adapt [tolerance (default 1e-7)]
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calcvar.h"

static int layer(int m, const double *x, const double *y, const double *dy, unsigned need,
                 cv_partials *o, void *user) {
  double e2 = *(const double *)user * *(const double *)user;
  (void)x;
  (void)need;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * (e2 * dy[k] * dy[k] + (y[k] - 1) * (y[k] - 1));
    if (o->Fy) {
      o->Fy[k] = y[k] - 1;
      o->Fp[k] = e2 * dy[k];
    }
    if (o->Fyy) {
      o->Fyy[k] = 1;
      o->Fyp[k] = 0;
      o->Fpp[k] = e2;
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  double tol = argc > 1 ? atof(argv[1]) : 1e-7;
  printf("boundary layer, adaptive to %.0e from 10 uniform elements\n", tol);
  printf("%8s %4s %9s %7s %11s %11s %9s %s\n", "eps", "p", "elements", "rounds", "estimate",
         "true_err", "time_s", "status");
  for (int deg = 1; deg <= 4; deg *= 2)
    for (double eps = 1e-2; eps >= 0.99e-8; eps /= 100) {
      cv_problem *p = cv_problem_new(1, 0, 1, NULL);
      cv_problem_set_integrand(p, layer, &eps);
      cv_problem_set_dirichlet(p, 0, 0, 0);
      cv_solver *s = cv_solver_new(NULL);
      cv_solver_set_elements(s, 10);
      cv_solver_set_degree(s, deg);
      cv_solver_set_adapt(s, tol, 4000000);
      cv_status st = cv_solve(s, p);
      int nn = cv_solver_get_num_nodes(s);
      double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), err = 0;
      cv_solver_get_nodes(s, x);
      cv_solver_get_values(s, y);
      for (int j = 0; j < nn; j++) {
        double ex = 1 - (exp((x[j] - 1) / eps) + exp(-x[j] / eps)) / (1 + exp(-1 / eps));
        err = fmax(err, fabs(y[j] - ex));
      }
      printf("%8.0e %4d %9d %7d %11.2e %11.2e %9.4f %s\n", eps, deg, cv_solver_get_num_elements(s),
             cv_solver_get_adapt_rounds(s), cv_solver_get_error_estimate(s), err,
             cv_solver_get_time(s), st ? cv_status_name(st) : "converged");
      free(x);
      free(y);
      cv_solver_free(s);
      cv_problem_free(p);
    }
  return 0;
}
