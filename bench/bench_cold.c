/* bench/bench_cold.c — the first solve in a fresh process against a warm solve (issue 14,
 * item 10; docs/performance.md). The parent runs itself N times as a child process that
 * times its first cv_solve (problem and solver made before the clock starts, as a program
 * would), then times N warm solves in its own process, each with a fresh solver, and
 * prints medians and their ratio: both measured in the same run, and the median of the
 * minor page faults counted by getrusage around each cold solve.
 *   bench_cold [N]    (default 41)
 *   bench_cold --child K        one cold solve of problem K (0 fish-eye, 1 catenary)
 *   bench_cold --child-warm K   one solve of K, then the timed one: the same process
 *                               with one warm solve more, for `perf stat` and callgrind
 *                               (the difference of the two is the first solve's extra)
 * Timings on a shared machine are noisy: compare the ratio, not absolute figures.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "calcvar.h"
#include "refproblems.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* The problems are two of the tests' reference problems (tests/core/refproblems.h, hand-
 * derived partials): the fish-eye ray n = 2 / (1 + x^2 + y^2) on [0, 1], 2 elements of
 * degree 4, and the catenary y sqrt(1 + y'^2) on [-1, 1], 3 elements of degree 4. */
static long minor_faults(void) {
  struct rusage ru;
  return getrusage(RUSAGE_SELF, &ru) == 0 ? ru.ru_minflt : 0;
}
static long faults; /* minor page faults in the last timed solve */

/* One timed solve of problem `which` with a fresh solver; returns seconds (NAN on failure). */
static double timed_solve(int which) {
  cv_problem *p = which == 0 ? cv_problem_new(1, 0, 1, NULL) : cv_problem_new(1, -1, 1, NULL);
  if (which == 0) {
    cv_problem_set_integrand(p, fisheye_F, NULL);
    cv_problem_set_dirichlet(p, 0, -2 + sqrt(5), -2 + sqrt(4));
  } else {
    cv_problem_set_integrand(p, catenary_F, NULL);
    cv_problem_set_dirichlet(p, 0, 2 * cosh(0.5), 2 * cosh(0.5));
  }
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, which == 0 ? 2 : 3);
  cv_solver_set_degree(s, 4);
  /* the clock read once first: the first call binds clock_gettime (and may fault), which
   * happened before t0 was read anyway; now it is also outside the fault count */
  (void)now();
  long f0 = minor_faults();
  double t0 = now();
  cv_status st = cv_solve(s, p);
  double t = now() - t0;
  faults = minor_faults() - f0;
  cv_solver_free(s);
  cv_problem_free(p);
  return st == CVAR_OK ? t : NAN;
}

static int cmp(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

int main(int argc, char **argv) {
  if (argc == 3 && strcmp(argv[1], "--child") == 0) {
    double t = timed_solve(atoi(argv[2]));
    printf("%.9e %ld page faults\n", t, faults);
    return 0;
  }
  if (argc == 3 && strcmp(argv[1], "--child-warm") == 0) {
    timed_solve(atoi(argv[2]));
    double t = timed_solve(atoi(argv[2]));
    printf("%.9e %ld page faults\n", t, faults);
    return 0;
  }
  int N = argc > 1 ? atoi(argv[1]) : 41;
  if (N < 1) N = 1;
  double *cold = malloc((size_t)N * sizeof *cold), *warm = malloc((size_t)N * sizeof *warm);
  double *nf = malloc((size_t)N * sizeof *nf); /* page faults of each cold solve */
  const char *names[2] = {"fish-eye, 2 elements of degree 4", "catenary, 3 elements of degree 4"};
  printf("%-34s %12s %12s %7s %7s\n", "problem (median of N)", "cold [us]", "warm [us]", "ratio",
         "faults");
  for (int which = 0; which < 2; which++) {
    for (int i = 0; i < N; i++) {
      char cmd[4096];
      snprintf(cmd, sizeof cmd, "'%s' --child %d", argv[0], which);
      FILE *f = popen(cmd, "r");
      cold[i] = nf[i] = NAN;
      if (!f || fscanf(f, "%lf %lf", &cold[i], &nf[i]) != 2) cold[i] = nf[i] = NAN;
      if (f) pclose(f);
    }
    timed_solve(which); /* the first in this process is a cold one: not counted */
    for (int i = 0; i < N; i++) warm[i] = timed_solve(which);
    qsort(cold, (size_t)N, sizeof *cold, cmp);
    qsort(warm, (size_t)N, sizeof *warm, cmp);
    qsort(nf, (size_t)N, sizeof *nf, cmp);
    double c = cold[N / 2], w = warm[N / 2];
    printf("%-34s %12.1f %12.1f %7.2f %7.0f   (cold min %.1f max %.1f)\n", names[which], 1e6 * c,
           1e6 * w, c / w, nf[N / 2], 1e6 * cold[0], 1e6 * cold[N - 1]);
  }
  free(cold);
  free(warm);
  free(nf);
  return 0;
}
