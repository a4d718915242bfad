/* bench/bench_ends.c — moving ends (theory ME-1 .. ME-6) on the scenes of tests/ends: the
 * solve's wall time (best of 5, solve only, scene and problem made once), the end point's
 * error against the closed form, and the action's, plain and with --tol 1e-10.
 * Usage: bench_ends [REPETITIONS (default 50)]
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "calcvar.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

typedef struct {
  const char *scene;
  double a, b, action; /* the exact solved interval and action */
} bench_case;

static void run(const bench_case *c, double tol, int reps) {
  char err[1024], path[1024];
  snprintf(path, sizeof path, "%s/%s", CV_ENDS_DIR, c->scene);
  cv_scene *sc = cv_scene_load_file(path, 0, NULL, err, sizeof err);
  cv_problem *p = NULL;
  cv_solver *s = NULL;
  if (!sc || (tol > 0 && cv_scene_set_option(sc, "tol", tol, err, sizeof err)) ||
      !(p = cv_scene_problem_new(sc, err, sizeof err)) || !(s = cv_solver_new(NULL)) ||
      cv_scene_configure_solver(sc, s, err, sizeof err)) {
    printf("%-26s %s\n", c->scene, err);
    goto done;
  }
  double best = 1e30;
  cv_status st = CVAR_OK;
  for (int round = 0; round < 5; round++) {
    double t0 = now();
    for (int r = 0; r < reps; r++) st = cv_solve(s, p);
    best = fmin(best, (now() - t0) / reps);
  }
  double a = NAN, b = NAN;
  cv_solver_get_interval(s, &a, &b);
  printf("%-26s %-8s %-10s %10.3f  %9.1e  %9.1e  %6d\n", c->scene, tol > 0 ? "1e-10" : "plain",
         st == CVAR_OK ? "converged" : cv_strerror(st), 1e3 * best,
         fmax(fabs(a - c->a), fabs(b - c->b)), fabs(cv_solver_get_action(s) - c->action),
         cv_solver_get_num_nodes(s));
done:
  cv_solver_free(s);
  cv_problem_free(p);
  cv_scene_free(sc);
}

int main(int argc, char **argv) {
  int reps = argc > 1 ? atoi(argv[1]) : 50;
  double s13 = sqrt(13.0), pi = 3.14159265358979323846;
  const bench_case cases[] = {
      {"point_to_circle.scene", 0, 3 * (1 - 1 / s13), s13 - 1},
      {"free_time.scene", 0, asinh(1.0), sqrt(2.0) / 2 + asinh(1.0) / 2},
      {"brachistochrone_line.scene", 0, pi / 2 - 1, pi / sqrt(2.0)},
      {"brachistochrone_wall.scene", 0, pi, pi * sqrt(2.0)},
      {"two_circles.scene", 2 / sqrt(5.0), 6 - 2 / sqrt(5.0), sqrt(45.0) - 2},
  };
  printf("%-26s %-8s %-10s %10s  %9s  %9s  %6s\n", "scene", "tol", "status", "ms/solve",
         "end error", "action err", "nodes");
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    run(&cases[k], 0.0, reps);
    run(&cases[k], 1e-10, reps);
  }
  return 0;
}
