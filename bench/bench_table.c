/* bench/bench_table.c — tables (issue 16): (1) the solve time of a ray through a tabulated
 * medium against the same medium as a formula, same mesh, same run, with Newton's iteration
 * counts; (2) building a 200^3 table from arrays; (3) reading a 200^3 CSV grid (written to a
 * temporary file first). Prints figures and ratios (a benchmark, not a test).
 * usage: bench_table [N [CSV]]   (N^3 grid for (2) and (3), default 200; CSV: read this
 * file in (3) instead of writing one)
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calcvar.h"
#include "scene/scene_internal.h"

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static double fisheye(const double *u, int dim) {
  double r2 = 0;
  for (int k = 0; k < dim; k++) r2 += u[k] * u[k];
  return 2.0 / (1 + r2);
}

/* A table of the fish-eye index on [-0.8, 0.8] x [0.1, 0.7]^(dim-1), n points per axis. */
static cv_table *fisheye_table(int dim, int n) {
  double lo[3] = {-0.8, 0.1, 0.1}, hi[3] = {0.8, 0.7, 0.7};
  double *c[3];
  int nn[3] = {n, n, n};
  size_t size = 1;
  for (int k = 0; k < dim; k++) {
    c[k] = malloc((size_t)n * sizeof *c[k]);
    for (int i = 0; i < n; i++) c[k][i] = lo[k] + (hi[k] - lo[k]) * i / (n - 1);
    size *= (size_t)n;
  }
  double *v = calloc(size, sizeof *v);
  for (size_t idx = 0; idx < size; idx++) {
    double u[3];
    size_t r = idx;
    for (int k = dim - 1; k >= 0; k--) u[k] = c[k][r % (size_t)n], r /= (size_t)n;
    v[idx] = fisheye(u, dim);
  }
  cv_status why;
  cv_table *t = cv_table_new(dim, nn, (const double *const *)c, v, &why);
  for (int k = 0; k < dim; k++) free(c[k]);
  free(v);
  return t;
}

/* Best of 5 solves: seconds, iterations. */
static double solve_time(int nunk, const char *unk, const char *F, cv_table *t, int *iters,
                         int elements) {
  double best = INFINITY;
  for (int trial = 0; trial < 5; trial++) {
    cv_status why;
    cv_problem *p = cv_problem_new(nunk, -0.8, 0.8, &why);
    cv_solver *s = cv_solver_new(&why);
    char err[300];
    double Y = -0.5 + sqrt(0.61);
    for (int i = 0; i < nunk; i++)
      cv_problem_set_dirichlet(p, i, nunk == 1 ? Y : (i ? 0.6 : 0.8) * Y,
                               nunk == 1 ? Y : (i ? 0.6 : 0.8) * Y);
    if (t) cv_problem_add_table(p, "n", t);
    if (cv_problem_set_integrand_expr(p, "x", unk, F, NULL, err, sizeof err) != CVAR_OK) {
      fprintf(stderr, "%s\n", err);
      exit(1);
    }
    cv_solver_set_elements(s, elements);
    cv_solver_set_degree(s, 4);
    double t0 = now();
    cv_status st = cv_solve(s, p);
    double dt = now() - t0;
    if (st != CVAR_OK) {
      fprintf(stderr, "solve failed: %s\n", cv_solver_last_error(s));
      exit(1);
    }
    *iters = cv_solver_get_num_iterations(s);
    best = fmin(best, dt);
    cv_solver_free(s);
    cv_problem_free(p);
  }
  return best;
}

int main(int argc, char **argv) {
  int N = argc > 1 ? atoi(argv[1]) : 200;
  if (N < 4) N = 4;
  printf("timings on a shared machine are noisy; ratios are measured in the same run\n\n");
  printf("(1) ray through the fish-eye, 2000 elements of degree 4, best of 5 solves\n");
  struct {
    int dim, n;
    const char *unk, *formula, *table;
  } cases[] = {
      {2, 65, "y", "2/(1 + x^2 + y^2)*sqrt(1 + y'^2)", "n(x, y)*sqrt(1 + y'^2)"},
      {3, 33, "y, z", "2/(1 + x^2 + y^2 + z^2)*sqrt(1 + y'^2 + z'^2)",
       "n(x, y, z)*sqrt(1 + y'^2 + z'^2)"},
  };
  for (int c = 0; c < 2; c++) {
    cv_table *t = fisheye_table(cases[c].dim, cases[c].n);
    int itf, itt;
    double tf = solve_time(cases[c].dim - 1, cases[c].unk, cases[c].formula, NULL, &itf, 2000);
    double tt = solve_time(cases[c].dim - 1, cases[c].unk, cases[c].table, t, &itt, 2000);
    printf("  %d-D (%d^%d grid): formula %.4f s (%d it), table %.4f s (%d it), ratio %.2f\n",
           cases[c].dim, cases[c].n, cases[c].dim, tf, itf, tt, itt, tt / tf);
    cv_table_free(t);
  }

  printf("\n(2) cv_table_new, %d^3 grid from arrays (values + 7 derivative arrays)\n", N);
  double t0 = now();
  cv_table *big = fisheye_table(3, N);
  double t1 = now();
  printf("  sampling the function and building the table: %.3f s (%s)\n", t1 - t0,
         big ? "ok" : "FAILED");
  /* the build alone: values sampled first */
  {
    int nn[3] = {N, N, N};
    double *c = malloc((size_t)N * sizeof *c);
    for (int i = 0; i < N; i++) c[i] = (double)i / (N - 1);
    const double *cs[3] = {c, c, c};
    size_t size = (size_t)N * N * N;
    double *v = malloc(size * sizeof *v);
    for (size_t i = 0; i < size; i++) v[i] = sin(1e-6 * (double)i);
    cv_status why;
    t0 = now();
    cv_table *t = cv_table_new(3, nn, cs, v, &why);
    t1 = now();
    printf("  cv_table_new alone: %.3f s, %.0f MB of coefficients\n", t1 - t0,
           8.0 * 8.0 * (double)size / 1e6);
    cv_table_free(t);
    free(v);
    free(c);
  }
  cv_table_free(big);

  printf("\n(3) reading a %d^3 CSV grid (x, y, z, value; 17 significant digits)\n", N);
  char tmp[] = "/tmp/bench_table_XXXXXX", *path = argc > 2 ? argv[2] : tmp;
  if (argc <= 2) {
    int fd = mkstemp(path);
    FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
    if (!f) return 1;
    t0 = now();
    fprintf(f, "x,y,z,v\n");
    for (int i = 0; i < N; i++)
      for (int j = 0; j < N; j++)
        for (int k = 0; k < N; k++) {
          double u[3] = {(double)i / (N - 1), (double)j / (N - 1), (double)k / (N - 1)};
          fprintf(f, "%.17g,%.17g,%.17g,%.17g\n", u[0], u[1], u[2], fisheye(u, 3));
        }
    fclose(f);
    t1 = now();
    printf("  (writing it: %.2f s)\n", t1 - t0);
  }
  char err[SC_ERRLEN] = "";
  t0 = now();
  cv_table *rt = sc_table_read(path, path, err, sizeof err);
  t1 = now();
  printf("  read and built: %.3f s (%s)\n", t1 - t0, rt ? "ok" : err);
  cv_table_free(rt);
  if (argc <= 2) remove(path);
  return 0;
}
