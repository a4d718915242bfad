/* bench/bench_newton.c — catenary, p = 1, 10^3 .. 10^7 elements: nanoseconds per element per
 * Newton iteration for assembly and for the LDL^T factor+solve, and total time. Compare with
 * the floor of DESIGN.md (a hand-written tridiagonal Newton: ~23 ns/element/iteration).
 * Usage: bench_newton [max_exponent (default 7)] [degree (default 1)]
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "core/cv_internal.h"

static int catenary(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *o, void *user) {
  (void)x; (void)need; (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p);
    o->F[k] = y[k] * s;
    if (o->Fy) { o->Fy[k] = s; o->Fp[k] = y[k] * p / s; }
    if (o->Fyy) { o->Fyy[k] = 0; o->Fyp[k] = p / s; o->Fpp[k] = y[k] / (s * s * s); }
  }
  return 0;
}

int main(int argc, char **argv) {
  int maxexp = argc > 1 ? atoi(argv[1]) : 7, deg = argc > 2 ? atoi(argv[2]) : 1;
  double c = 2 * cosh(0.5);
  printf("catenary, degree %d: per element per Newton iteration\n", deg);
  printf("%10s %6s %12s %12s %12s %10s %12s\n", "elements", "iters", "assemble_ns", "ldlt_ns",
         "total_ns", "total_s", "max_err");
  for (int e = 3; e <= maxexp; e++) {
    int E = (int)lround(pow(10, e));
    cv_problem *p = cv_problem_new(1, -1, 1, NULL);
    cv_problem_set_integrand(p, catenary, NULL);
    cv_problem_set_dirichlet(p, 0, c, c);
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, E);
    cv_solver_set_degree(s, deg);
    cv_status st = cv_solve(s, p);
    int it = cv_solver_get_num_iterations(s);
    double per = 1e9 / ((double)E * (it ? it : 1));
    double err = 0;
    long nn = cv_solver_get_num_nodes(s);
    for (long j = 0; j < nn; j += 1 + nn / 1000) {
      double x = cv_disc_node_x(&s->disc, j);
      err = fmax(err, fabs(s->y[j] - 2 * cosh(x / 2)));
    }
    printf("%10d %6d %12.1f %12.1f %12.1f %10.4f %12.3e %s\n", E, it, s->t_assemble * per,
           s->t_factor * per, cv_solver_get_time(s) * per, cv_solver_get_time(s), err,
           st ? cv_status_name(st) : "");
    cv_solver_free(s);
    cv_problem_free(p);
  }
  return 0;
}
