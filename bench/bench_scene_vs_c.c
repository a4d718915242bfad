/* bench/bench_scene_vs_c.c — whole Newton solves at 10^5 elements with the integrand as a
 * formula (cv_problem_set_integrand_expr: compiled symbolic derivatives) against the same
 * integrand as a hand-written C callback: the catenary, the sphere geodesic (2 unknowns)
 * and six coupled pendula (6 unknowns). Prints both times and their ratio.
 * Usage: bench_scene_vs_c [elements (default 100000)] [repetitions (default 3)]
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calcvar.h"

static int catenary(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p);
    o->F[k] = y[k] * s;
    if (o->Fy) o->Fy[k] = s, o->Fp[k] = y[k] * p / s;
    if (o->Fyy) o->Fyy[k] = 0, o->Fyp[k] = p / s, o->Fpp[k] = y[k] / (s * s * s);
  }
  return 0;
}

static int sphere(int m, const double *x, const double *y, const double *dy, unsigned need,
                  cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    double th = y[k], tp = dy[k], pp = dy[m + k], sn = sin(th), cs = cos(th);
    o->F[k] = tp * tp + sn * sn * pp * pp;
    if (o->Fy) {
      o->Fy[k] = 2 * sn * cs * pp * pp, o->Fy[m + k] = 0;
      o->Fp[k] = 2 * tp, o->Fp[m + k] = 2 * sn * sn * pp;
    }
    if (o->Fyy) {
      o->Fyy[k] = 2 * (cs * cs - sn * sn) * pp * pp;
      o->Fyy[m + k] = o->Fyy[2 * m + k] = o->Fyy[3 * m + k] = 0;
      o->Fyp[k] = 0, o->Fyp[m + k] = 4 * sn * cs * pp, o->Fyp[2 * m + k] = 0, o->Fyp[3 * m + k] = 0;
      o->Fpp[k] = 2, o->Fpp[m + k] = o->Fpp[2 * m + k] = 0, o->Fpp[3 * m + k] = 2 * sn * sn;
    }
  }
  return 0;
}

/* Six pendula coupled by springs: F = sum y_i'^2/2 - sum (1 - cos y_i)
 *                                     - sum_{i<5} (y_{i+1} - y_i)^2 / 2. */
#define NP 6
static int pendula(int m, const double *x, const double *y, const double *dy, unsigned need,
                   cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  const int n = NP;
  for (int k = 0; k < m; k++) {
    double F = 0;
    for (int i = 0; i < n; i++) {
      double yi = y[i * m + k], pi = dy[i * m + k];
      F += 0.5 * pi * pi - (1 - cos(yi));
      if (i + 1 < n) {
        double d = y[(i + 1) * m + k] - yi;
        F -= 0.5 * d * d;
      }
      if (o->Fy) {
        double f = -sin(yi);
        if (i > 0) f -= yi - y[(i - 1) * m + k];
        if (i + 1 < n) f += y[(i + 1) * m + k] - yi;
        o->Fy[i * m + k] = f;
        o->Fp[i * m + k] = pi;
      }
      if (o->Fyy)
        for (int j = 0; j < n; j++) {
          double h = 0;
          if (i == j)
            h = -cos(yi) - (i > 0) - (i + 1 < n);
          else if (j == i - 1 || j == i + 1)
            h = 1;
          o->Fyy[(i * n + j) * m + k] = h;
          o->Fyp[(i * n + j) * m + k] = 0;
          o->Fpp[(i * n + j) * m + k] = i == j;
        }
    }
    o->F[k] = F;
  }
  return 0;
}

static const char *pendula_formula =
    "(a'^2 + b'^2 + c'^2 + d'^2 + e'^2 + f'^2)/2"
    " - (6 - cos(a) - cos(b) - cos(c) - cos(d) - cos(e) - cos(f))"
    " - ((b - a)^2 + (c - b)^2 + (d - c)^2 + (e - d)^2 + (f - e)^2)/2";

/* Best of reps wall times of one solve. */
static double time_solve(cv_problem *p, int E, int reps, int *its) {
  double best = INFINITY;
  for (int r = 0; r < reps; r++) {
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, E);
    cv_status st = cv_solve(s, p);
    if (st) fprintf(stderr, "solve failed: %s\n", cv_solver_last_error(s));
    if (cv_solver_get_time(s) < best) best = cv_solver_get_time(s);
    *its = cv_solver_get_num_iterations(s);
    cv_solver_free(s);
  }
  return best;
}

static void row(const char *name, cv_problem *pc, cv_problem *pe, int E, int reps) {
  int ic, ie;
  double tc = time_solve(pc, E, reps, &ic), te = time_solve(pe, E, reps, &ie);
  printf("%-16s %8d %6d %10.4f %6d %10.4f %7.2f\n", name, E, ic, tc, ie, te, te / tc);
}

int main(int argc, char **argv) {
  int E = argc > 1 ? atoi(argv[1]) : 100000, reps = argc > 2 ? atoi(argv[2]) : 3;
  char err[256];
  printf("%-16s %8s %6s %10s %6s %10s %7s\n", "problem", "elements", "its_c", "c_s", "its_f",
         "formula_s", "ratio");
  double c = 2 * cosh(0.5);
  cv_problem *pc = cv_problem_new(1, -1, 1, NULL), *pe = cv_problem_new(1, -1, 1, NULL);
  cv_problem_set_integrand(pc, catenary, NULL);
  if (cv_problem_set_integrand_expr(pe, "x", "y", "y * sqrt(1 + y'^2)", NULL, err, sizeof err))
    return fprintf(stderr, "%s\n", err), 1;
  cv_problem_set_dirichlet(pc, 0, c, c);
  cv_problem_set_dirichlet(pe, 0, c, c);
  row("catenary", pc, pe, E, reps);
  cv_problem_free(pc);
  cv_problem_free(pe);

  pc = cv_problem_new(2, 0, 1, NULL), pe = cv_problem_new(2, 0, 1, NULL);
  cv_problem_set_integrand(pc, sphere, NULL);
  if (cv_problem_set_integrand_expr(pe, "s", "th, ph", "th'^2 + sin(th)^2 * ph'^2", NULL, err,
                                    sizeof err))
    return fprintf(stderr, "%s\n", err), 1;
  for (cv_problem *p = pc; p; p = p == pc ? pe : NULL) {
    cv_problem_set_dirichlet(p, 0, 3.14159265358979323846 / 3, 3.14159265358979323846 / 2);
    cv_problem_set_dirichlet(p, 1, 0, 3.14159265358979323846 / 2);
  }
  row("sphere geodesic", pc, pe, E, reps);
  cv_problem_free(pc);
  cv_problem_free(pe);

  pc = cv_problem_new(NP, 0, 1, NULL), pe = cv_problem_new(NP, 0, 1, NULL);
  cv_problem_set_integrand(pc, pendula, NULL);
  if (cv_problem_set_integrand_expr(pe, "t", "a, b, c, d, e, f", pendula_formula, NULL, err,
                                    sizeof err))
    return fprintf(stderr, "%s\n", err), 1;
  for (int i = 0; i < NP; i++) {
    cv_problem_set_dirichlet(pc, i, 0, 0.1 * (i + 1));
    cv_problem_set_dirichlet(pe, i, 0, 0.1 * (i + 1));
  }
  row("6 pendula", pc, pe, E, reps);
  cv_problem_free(pc);
  cv_problem_free(pe);
  return 0;
}
