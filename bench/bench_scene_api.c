/* bench/bench_scene_api.c — one whole scene solve through the public C API, as the Python
 * module makes it: load the scene file, set elements and degree, make the problem and the
 * solver, configure, solve, copy nodes and values out, free. The baseline of
 * bench_python.py (the module's overhead is its time less this one).
 * Usage: bench_scene_api SCENE ELEMENTS DEGREE [REPETITIONS (default 2000)]
 * Prints the best of 5 rounds: "C: <microseconds> us per solve".
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#include "calcvar.h"

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int one(const char *path, int elements, int degree) {
  char err[1024];
  cv_scene *sc = cv_scene_load_file(path, 0, NULL, err, sizeof err);
  if (!sc) {
    fprintf(stderr, "%s\n", err);
    return -1;
  }
  int rc = -1;
  cv_problem *p = NULL;
  cv_solver *s = NULL;
  double *x = NULL, *y = NULL;
  if (cv_scene_set_option(sc, "elements", elements, err, sizeof err) ||
      cv_scene_set_option(sc, "degree", degree, err, sizeof err) ||
      !(p = cv_scene_problem_new(sc, err, sizeof err)) || !(s = cv_solver_new(NULL)) ||
      cv_scene_configure_solver(sc, s, err, sizeof err) || cv_solve(s, p) != CVAR_OK)
    goto done;
  int nn = cv_solver_get_num_nodes(s), n = cv_scene_get_num_unknowns(sc);
  x = malloc((size_t)nn * sizeof *x);
  y = malloc((size_t)nn * n * sizeof *y);
  if (x && y && cv_solver_get_nodes(s, x) == CVAR_OK && cv_solver_get_values(s, y) == CVAR_OK)
    rc = 0;
done:
  free(x);
  free(y);
  cv_solver_free(s);
  cv_problem_free(p);
  cv_scene_free(sc);
  return rc;
}

int main(int argc, char **argv) {
  if (argc < 4) {
    fprintf(stderr, "usage: bench_scene_api SCENE ELEMENTS DEGREE [REPETITIONS]\n");
    return 2;
  }
  int elements = atoi(argv[2]), degree = atoi(argv[3]);
  int reps = argc > 4 ? atoi(argv[4]) : 2000;
  double best = 1e30;
  for (int round = 0; round < 5; round++) {
    double t0 = now();
    for (int r = 0; r < reps; r++)
      if (one(argv[1], elements, degree) < 0) return 1;
    double t = (now() - t0) / reps;
    best = t < best ? t : best;
  }
  printf("C: %.2f us per solve\n", 1e6 * best);
  return 0;
}
