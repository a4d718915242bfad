/* bench/bench_all.c — the cost of the deflated search (cv_solve_all, theory DF-1..DF-5)
 * against one plain solve of the same problem, measured in the same run: Bratu (lambda = 1,
 * 24 elements of degree 8, both paths to 1e-10), the catenary between rings at R = 2 and the
 * pendulum from 0 to 0.5 in time 10, all at the default work limit. Medians of R repetitions; the machine may be shared,
 * so the ratios are the figures to read, not the absolute times.
 * Usage: bench_all [repetitions (default 21)]
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "calcvar.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static double median(double *v, int n) {
  qsort(v, (size_t)n, sizeof *v, cmp);
  return v[n / 2];
}

typedef struct {
  const char *name, *F;
  double a, b, ya, yb;
  int E, P, max;
  double work;
} bench_case;

int main(int argc, char **argv) {
  int R = argc > 1 ? atoi(argv[1]) : 21;
  if (R < 1 || R > 1000) R = 21;
  static const bench_case cases[] = {
      {"bratu", "y'^2/2 - exp(y)", 0, 1, 0, 0, 24, 8, 8, 0},
      {"bratu --max 2", "y'^2/2 - exp(y)", 0, 1, 0, 0, 24, 8, 2, 0},
      {"catenary R=2", "y*sqrt(1 + y'^2)", -1, 1, 2, 2, 32, 6, 8, 0},
      {"pendulum T=10", "y'^2/2 + cos(y)", 0, 10, 0, 0.5, 40, 6, 8, 0},
  };
  double *t1 = malloc(R * sizeof *t1), *ta = malloc(R * sizeof *ta);
  if (!t1 || !ta) return 1;
  printf("%-16s %6s %6s %7s %11s %11s %7s  %s\n", "problem", "paths", "starts", "failed", "solve_s",
         "all_s", "ratio", "stopped");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    const bench_case *k = &cases[c];
    char err[256];
    cv_problem *p = cv_problem_new(1, k->a, k->b, NULL);
    cv_solver *s = cv_solver_new(NULL);
    if (!p || !s || cv_problem_set_integrand_expr(p, "x", "y", k->F, NULL, err, sizeof err))
      return 1;
    cv_problem_set_dirichlet(p, 0, k->ya, k->yb);
    cv_solver_set_elements(s, k->E);
    cv_solver_set_degree(s, k->P);
    if (k->work > 0) cv_solver_set_search_work(s, k->work);
    cv_search_info in = {0};
    int np = 0;
    for (int r = 0; r < R; r++) {
      double t0 = now();
      cv_solve(s, p);
      t1[r] = now() - t0;
      t0 = now();
      cv_solve_all(s, p, k->max);
      ta[r] = now() - t0;
      np = cv_solver_get_num_solutions(s);
      cv_solver_get_search(s, &in);
    }
    double m1 = median(t1, R), ma = median(ta, R);
    printf("%-16s %6d %6d %7d %11.3e %11.3e %7.1f  %s\n", k->name, np, in.starts, in.failed, m1, ma,
           ma / m1, in.stop);
    cv_solver_free(s);
    cv_problem_free(p);
  }
  free(t1);
  free(ta);
  return 0;
}
