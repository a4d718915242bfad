/* bench/bench_tol.c — automatic accuracy (--tol, theory HP-1..HP-6) on the reference
 * problems: time of one whole --tol solve (fresh solver: configure, all rounds, free; the
 * fastest of repeats filling 50 ms), nodes, rounds, the estimate and the true error, and, in
 * the same run, the time of one solve on the best hand-picked mesh of docs/performance.md
 * for that accuracy (the baseline), with the ratio, and of that solve followed by its error
 * estimate (+est: what certifying the hand mesh costs, the least a --tol run that ends on
 * that mesh can cost), with the ratio to it; then the brachistochrone's action error
 * against sqrt(nodes) as the tolerance falls (HP-5: exp(-b sqrt(N))). The brachistochrone
 * runs twice: from --tol's own start, and from the example scene's [mesh] (100 graded
 * elements of degree 4) as the start.
 * Usage: bench_tol [scene_dir (default: the tests' copy of the reference problems)
 *                  [name: only the scenes whose file name contains it
 *                  [tol | hand: only that side, 200 repeats (for a profiler)]]]
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "calcvar.h"
#include "scene/scene.h"

#ifndef CV_EXAMPLES_DIR
#define CV_EXAMPLES_DIR "examples/scenes"
#endif
#ifndef CV_SCENE_DIR
#define CV_SCENE_DIR "tests/scene/data"
#endif

typedef struct {
  const char *scene, *set; /* set: one name=value override or NULL */
  double tol;
  int elements, degree; /* the hand-picked baseline mesh (0: none) */
  int own_mesh;         /* 1: the scene in examples/scenes, its own [mesh] as the start */
} bench_case;

static const bench_case cases[] = {
    {"brachistochrone.scene", NULL, 1e-10, 0, 0, 0},
    {"brachistochrone.scene", NULL, 1e-10, 0, 0, 1},
    {"boundary_layer.scene", "eps=1e-8", 1e-9, 0, 0, 0},
    {"boundary_layer.scene", "eps=1e-8", 2e-8, 0, 0, 0},
    {"catenary.scene", NULL, 1e-12, 2, 8, 0},
    {"fisheye_ray.scene", NULL, 1e-12, 3, 8, 0},
    {"harmonic_saddle.scene", NULL, 1e-12, 5, 8, 0},
    {"boundary_layer.scene", NULL, 1e-12, 98, 8, 0},
    {"sphere_geodesic.scene", NULL, 1e-12, 5, 8, 0},
};

typedef struct {
  cv_status st;
  double t, est, err, errA;
  double t_cert; /* hand mesh: the solve and its error estimate (HP-2), fastest of repeats */
  int nodes, rounds;
} bench_result;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* One timed solve of scene s (tol > 0: --tol from the CLI's start; else the given mesh),
 * the fastest of repeats filling 50 ms; errors against [exact] from the last one. */
static int profile_reps; /* > 0: exactly this many repeats (argv[3]) */
static int run(scene *s, const cv_problem *p, double tol, int elements, int degree, int own,
               bench_result *r) {
  int E0 = s->elements, P0 = s->degree; /* the scene's own mesh */
  double best = INFINITY, total = 0.0, best_cert = INFINITY;
  char err[SC_ERRLEN];
  for (int rep = 0; profile_reps ? rep < profile_reps : rep < 200 && (rep < 3 || total < 0.05);
       rep++) {
    cv_solver *sv = cv_solver_new(NULL);
    s->tol = tol;
    s->elements = own ? E0 : tol > 0 ? SCENE_TOL_START_ELEMENTS : elements;
    s->degree = own ? P0 : tol > 0 ? SCENE_TOL_START_DEGREE : degree;
    if (!sv || scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK) {
      fprintf(stderr, "%s\n", err);
      cv_solver_free(sv);
      return -1;
    }
    double t0 = now();
    r->st = cv_solve(sv, p);
    double t = cv_solver_get_time(sv);
    total += t;
    best = fmin(best, t);
    if (tol <= 0 && r->st == CVAR_OK) { /* the hand mesh certified: + its estimate */
      double e;
      if (cv_solver_estimate_error(sv, p, &e, NULL, err, sizeof err) == CVAR_OK)
        best_cert = fmin(best_cert, now() - t0);
    }
    r->nodes = cv_solver_get_num_nodes(sv);
    r->rounds = cv_solver_get_adapt_rounds(sv);
    r->est = cv_solver_get_error_estimate(sv);
    r->err = NAN;
    r->errA = s->has_exact_action ? fabs(cv_solver_get_action(sv) - s->exact_action) /
                                        fmax(1, fabs(s->exact_action))
                                  : NAN;
    int N = r->nodes, n = s->n, any = 0;
    for (int i = 0; i < n; i++) any |= s->exact[i] >= 0;
    double *x = malloc((size_t)N * sizeof *x), *y = malloc((size_t)N * n * sizeof *y);
    double *ex = malloc((size_t)N * n * sizeof *ex);
    if (any && x && y && ex && cv_solver_get_nodes(sv, x) == CVAR_OK &&
        cv_solver_get_values(sv, y) == CVAR_OK && scene_eval_exact(s, N, x, ex) == 0) {
      double m = 0;
      for (int i = 0; i < n; i++)
        if (s->exact[i] >= 0)
          for (int j = 0; j < N; j++)
            m = fmax(m, fabs(y[(size_t)j * n + i] - ex[(size_t)i * N + j]));
      r->err = m;
    }
    free(x);
    free(y);
    free(ex);
    cv_solver_free(sv);
  }
  r->t = best;
  r->t_cert = best_cert;
  return 0;
}

int main(int argc, char **argv) {
  const char *dir = argc > 1 ? argv[1] : CV_SCENE_DIR;
  int only = argc > 3 ? (strcmp(argv[3], "tol") == 0    ? 1
                         : strcmp(argv[3], "hand") == 0 ? 2
                                                        : 0)
                      : 0;
  if (only) profile_reps = 200;
  printf("--tol on the reference problems (timings on a shared machine: noisy; the baseline\n"
         "is measured in the same run)\n");
  printf("%-22s %-9s %7s %-9s %6s %6s %9s %9s %9s %9s | %-10s %9s %9s %6s | %9s %6s\n", "problem",
         "set", "tol", "status", "nodes", "rounds", "estimate", "true_max", "true_act", "time_s",
         "hand mesh", "time_s", "true_max", "ratio", "+est_s", "ratio");
  for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
    const bench_case *bc = &cases[c];
    if (argc > 2 && !strstr(bc->scene, argv[2])) continue; /* only the scenes named so */
    char path[1024], err[SC_ERRLEN], nm[64] = "", val[64] = "";
    snprintf(path, sizeof path, "%s/%s", bc->own_mesh ? CV_EXAMPLES_DIR : dir, bc->scene);
    sc_set set = {nm, val};
    if (bc->set) {
      const char *eq = strchr(bc->set, '=');
      snprintf(nm, sizeof nm, "%.*s", (int)(eq - bc->set), bc->set);
      snprintf(val, sizeof val, "%s", eq + 1);
    }
    scene *s = scene_load_file(path, bc->set ? 1 : 0, &set, err, sizeof err);
    cv_problem *p = s ? scene_problem_new(s, scene_method_need(s->method), err, sizeof err) : NULL;
    if (!p) {
      fprintf(stderr, "%s\n", err);
      scene_free(s);
      return 1;
    }
    bench_result a, b = {0};
    b.t = b.err = NAN;
    a = b;
    if ((only != 2 && run(s, p, bc->tol, 0, 0, bc->own_mesh, &a) < 0) ||
        (only != 1 && bc->elements && run(s, p, 0, bc->elements, bc->degree, 0, &b) < 0)) {
      cv_problem_free(p);
      scene_free(s);
      return 1;
    }
    char hand[16] = "-";
    if (bc->elements) snprintf(hand, sizeof hand, "%dx p%d", bc->elements, bc->degree);
    printf("%-22s %-9s %7.0e %-9s %6d %6d %9.2e %9.2e %9.2e %9.2e | %-10s %9.2e %9.2e %6.1f | "
           "%9.2e %6.1f\n",
           bc->scene,
           bc->own_mesh ? "own mesh"
           : bc->set    ? bc->set
                        : "-",
           bc->tol, a.st == CVAR_OK ? "converged" : cv_status_name(a.st) + 5, a.nodes, a.rounds,
           a.est, a.err, a.errA, a.t, hand, b.t, b.err, bc->elements ? a.t / b.t : NAN,
           bc->elements ? b.t_cert : NAN, bc->elements ? a.t / b.t_cert : NAN);
    cv_problem_free(p);
    scene_free(s);
  }
  /* Exponential convergence in sqrt(unknowns) (HP-5): the brachistochrone's action error
   * against the nodes as T falls; b from the least-squares line ln(err) = c - b sqrt(N). */
  char path[1024], err[SC_ERRLEN];
  if (only || (argc > 2 && !strstr("brachistochrone.scene", argv[2]))) return 0;
  snprintf(path, sizeof path, "%s/brachistochrone.scene", dir);
  scene *s = scene_load_file(path, 0, NULL, err, sizeof err);
  cv_problem *p = s ? scene_problem_new(s, scene_method_need(s->method), err, sizeof err) : NULL;
  if (!p) {
    fprintf(stderr, "%s\n", err);
    scene_free(s);
    return 1;
  }
  printf("\nbrachistochrone: action error against sqrt(nodes) under --tol\n%8s %6s %10s %10s\n",
         "tol", "nodes", "sqrt(N)", "act_err");
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int m = 0;
  for (double T = 1e-3; T >= 0.99e-12; T /= 10) {
    bench_result a;
    if (run(s, p, T, 0, 0, 0, &a) < 0) break;
    double r = sqrt((double)a.nodes), e = fmax(a.errA, 1e-16);
    printf("%8.0e %6d %10.2f %10.2e\n", T, a.nodes, r, a.errA);
    if (a.errA > 1e-14) { /* above round-off */
      sx += r, sy += log(e), sxx += r * r, sxy += r * log(e);
      m++;
    }
  }
  if (m >= 3)
    printf("fit ln(err) = c - b sqrt(N): b = %.3f (%d points above round-off)\n",
           -(m * sxy - sx * sy) / (m * sxx - sx * sx), m);
  cv_problem_free(p);
  scene_free(s);
  return 0;
}
