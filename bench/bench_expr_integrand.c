/* bench/bench_expr_integrand.c — speed of the compiled catenary integrand (F, first and
 * second partials) against hand-written C over batches of 256 and 100 points; prints the
 * figures (a benchmark, not a test). DESIGN.md §6 asks for "a small factor" of hand-written
 * C; measured 1.2-1.4x on the development machine.
 * SPDX-License-Identifier: MIT */
#include <time.h>

#include "../tests/expr/ex_test.h"
#include "expr/ex_integrand.h"

static double now(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int hand(int m, const double *x, const double *y, const double *dy, unsigned need,
                cv_partials *o, void *u) {
  (void)x, (void)u, (void)need;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p), is = 1 / s;
    o->F[k] = y[k] * s;
    o->Fy[k] = s;
    o->Fp[k] = y[k] * p * is;
    o->Fyy[k] = 0;
    o->Fyp[k] = p * is;
    o->Fpp[k] = y[k] * is * is * is;
  }
  return 0;
}

static double best_time(cv_integrand_fn f, void *user, int m, const double *x, const double *y,
                        const double *dy, cv_partials *P) {
  double best = INFINITY;
  for (int trial = 0; trial < 5; trial++) {
    double t0 = now();
    for (int r = 0; r < 20000; r++) {
      f(m, x, y, dy, 7u, P, user);
      __asm__ volatile("" ::: "memory"); /* keep every call */
    }
    best = fmin(best, now() - t0);
  }
  return best;
}

int main(void) {
  ex_dag *d = ex_dag_new();
  char err[256];
  ex_id F = parse_ok(d, "y*sqrt(1 + y'^2)");
  /* test slots: y = 1, y' = 3; the integrand wants y' = 2 (n = 1) */
  F = ex_subst(d, F, 3, ex_slot(d, 2));
  ex_integrand *g = ex_integrand_new(d, 1, F, 7u, err, sizeof err);
  CHECK(g != NULL, "%s", err);
  static double x[256], y[256], dy[256], o[6][256];
  for (int k = 0; k < 256; k++) x[k] = k, y[k] = 1 + k * 1e-3, dy[k] = -1 + k * 3e-3;
  cv_partials P = {o[0], o[1], o[2], o[3], o[4], o[5]};
  const int ms[] = {256, 100};
  for (int i = 0; i < 2 && g; i++) {
    double th = best_time(hand, NULL, ms[i], x, y, dy, &P);
    double tt = best_time(ex_integrand_eval, g, ms[i], x, y, dy, &P);
    printf("m = %d: hand-written %.2f ns/point, compiled %.2f ns/point, ratio %.2f\n", ms[i],
           th / 20000 / ms[i] * 1e9, tt / 20000 / ms[i] * 1e9, tt / th);
  }
  ex_integrand_free(g);
  ex_dag_free(d);
  return finish("bench_expr_integrand");
}
