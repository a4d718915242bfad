/* bench/bench_newton.c — catenary, p = 1, 10^3 .. 10^7 elements: nanoseconds per element per
 * Newton iteration for assembly and for the LDL^T factor+solve, and total time, next to the
 * floor of DESIGN.md measured in the same run: a hand-written Newton for the same
 * discretisation (2-point Gauss, analytic tridiagonal Hessian, Thomas algorithm).
 * Usage: bench_newton [max_exponent (default 7)] [degree (default 1)] [min_exponent (3)]
 * peak_B_el: the process's peak resident memory so far (getrusage) per element; sizes grow
 * down the table, so from 10^5 on it is that size's peak (below, the process's own few
 * MB dominate). Constant down the table = memory linear in N.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <sys/resource.h>

#include "core/cv_internal.h"

/* Hand-written Newton for the catenary with p = 1 on E elements; returns ns per element
 * per iteration. The floor of DESIGN.md's performance model. */
static double floor_ns(long E) {
  const double g1 = 0.5 - 0.5 / sqrt(3.0), g2 = 0.5 + 0.5 / sqrt(3.0), c = 2 * cosh(0.5);
  long N = E + 1;
  double h = 2.0 / E, *y = malloc(N * sizeof *y), *g = calloc(N, sizeof *g);
  double *dg = calloc(N, sizeof *dg), *od = calloc(N, sizeof *od);
  for (long j = 0; j < N; j++) y[j] = c;
  double t0 = cv_now();
  int it;
  for (it = 1; it <= 50; it++) {
    for (long j = 0; j < N; j++) g[j] = dg[j] = od[j] = 0;
    const double ih = 1.0 / h, w = 0.5 * h;
    for (long k = 0; k < E; k++) { /* element k: nodes k, k+1 */
      double p = (y[k + 1] - y[k]) * ih, s = sqrt(1 + p * p), is = 1.0 / s;
      double Fy = s, Fyp = p * is, Fppy = is * is * is, ga = 0, gb = 0, da = 0, db = 0, o = 0;
      for (int q = 0; q < 2; q++) {
        double t = q ? g2 : g1, yq = y[k] * (1 - t) + y[k + 1] * t;
        double Fp = yq * Fyp, Fpp = yq * Fppy;
        ga += w * (Fy * (1 - t) - Fp * ih);
        gb += w * (Fy * t + Fp * ih);
        da += w * (-2 * Fyp * (1 - t) * ih + Fpp * ih * ih);
        db += w * (2 * Fyp * t * ih + Fpp * ih * ih);
        o += w * (Fyp * (1 - 2 * t) * ih - Fpp * ih * ih);
      }
      g[k] += ga, g[k + 1] += gb, dg[k] += da, dg[k + 1] += db, od[k] += o;
    }
    double step = 0; /* Thomas on the interior nodes 1..N-2: H d = -g */
    for (long j = 2; j < N - 1; j++) {
      double m = od[j - 1] / dg[j - 1];
      dg[j] -= m * od[j - 1];
      g[j] -= m * g[j - 1];
    }
    g[N - 2] /= dg[N - 2];
    for (long j = N - 3; j >= 1; j--) g[j] = (g[j] - od[j] * g[j + 1]) / dg[j];
    for (long j = 1; j < N - 1; j++) {
      y[j] -= g[j];
      step = fmax(step, fabs(g[j]));
    }
    if (step < 1e-10 * c) break;
  }
  double t = cv_now() - t0;
  free(y);
  free(g);
  free(dg);
  free(od);
  return 1e9 * t / (E * (double)it);
}

static int catenary(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  /* one square root and one reciprocal per point, the arithmetic of the floor below */
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p), is = 1.0 / s;
    o->F[k] = y[k] * s;
    if (o->Fy) {
      o->Fy[k] = s;
      o->Fp[k] = y[k] * p * is;
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = p * is;
      o->Fpp[k] = y[k] * is * is * is;
    }
  }
  return 0;
}

int main(int argc, char **argv) {
  int maxexp = argc > 1 ? atoi(argv[1]) : 7, deg = argc > 2 ? atoi(argv[2]) : 1;
  int minexp = argc > 3 ? atoi(argv[3]) : 3;
  double c = 2 * cosh(0.5);
  printf("catenary, degree %d: per element per Newton iteration\n", deg);
  printf("%10s %6s %12s %12s %12s %10s %12s %10s %7s %10s\n", "elements", "iters", "assemble_ns",
         "ldlt_ns", "total_ns", "total_s", "max_err", "floor_ns", "ratio", "peak_B_el");
  /* One throwaway solve first: the first in a process also pays for resolving CHOLMOD's
   * symbols and growing the heap, which is not a cost per element. */
  {
    cv_problem *p = cv_problem_new(1, -1, 1, NULL);
    cv_problem_set_integrand(p, catenary, NULL);
    cv_problem_set_dirichlet(p, 0, c, c);
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, 1000);
    cv_solve(s, p);
    cv_solver_free(s);
    cv_problem_free(p);
  }
  for (int e = minexp; e <= maxexp; e++) {
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
    struct rusage ru;
    double peak = getrusage(RUSAGE_SELF, &ru) == 0 ? 1024.0 * ru.ru_maxrss / E : NAN;
    double fl = deg == 1 ? floor_ns(E) : NAN;
    printf("%10d %6d %12.1f %12.1f %12.1f %10.4f %12.3e %10.1f %7.2f %10.0f %s\n", E, it,
           s->t_assemble * per, s->t_factor * per, cv_solver_get_time(s) * per,
           cv_solver_get_time(s), err, fl, cv_solver_get_time(s) * per / fl, peak,
           st ? cv_status_name(st) : "");
    cv_solver_free(s);
    cv_problem_free(p);
  }
  return 0;
}
