/* bench/work_precision.c — minimum run time to reach a max nodal error, per problem and
 * element degree (issue 6); optional work-precision pictures with solve_bvp's points.
 * SPDX-License-Identifier: MIT
 *
 * usage: work_precision [--quick] [--no-tol] [--json FILE] [--bvp FILE] [--svg-dir DIR]
 *                       [SCENE_DIR]
 *
 * For catenary, fisheye_ray, harmonic_saddle, boundary_layer (eps = 1e-2) and
 * sphere_geodesic (the scenes of tests/scene/data, with their [exact]) and degrees 1, 2, 4,
 * 8, the element count runs over 1, 2, 3, 4, 5, 6, 8, 10, 13, 16, ... (ratio ~2^(1/3)),
 * from the first with at least 8 node intervals (elements * degree >= 8: with fewer, a
 * lucky node placement can make the max nodal error meaningless; one element of degree 1
 * has no free node at all and an "error" of 0), until
 * the error is below 1e-12/2, stops improving (round-off), or one solve takes over 1 s.
 * Time of one mesh: a fresh solver is created, configured, solved and freed (wall clock,
 * CLOCK_MONOTONIC), repeated until 50 ms have passed (at most 200 times), fastest kept —
 * so small solves are not timer noise and the figure is a warm, single-core solve.
 * Error: max over nodes and unknowns of |y_h - y_exact| (the contract's error.max_nodal).
 * For each target 1e-4, 1e-6, 1e-8, 1e-10, 1e-12 the table gives the least time over the
 * meshes whose error is at or below it.
 *
 * --tol (unless --no-tol): the same problems solved with automatic accuracy, no mesh chosen
 * by hand — the scene configured as `calcvar solve SCENE --tol T` does (start: 4 elements of
 * degree 4, cap 10^6 nodes) — for T = 10^-2, 10^-2.5, ..., 10^-13 (solve_bvp's tolerances in
 * work_precision.py), each timed as above (fresh solver, fastest of repeats) with the true
 * max nodal error of the first; an unconverged --tol (exit 1: round-off floor or a cap) is
 * listed with its status and error but left out of the picture. The sweep stops after a
 * solve that took over 1 s.
 *
 * --json FILE writes every measured point; --bvp FILE reads solve_bvp's points
 * ({"problem": [[error, time_s], ...]}, written by work_precision.py) and --svg-dir DIR then
 * draws DIR/work_precision_PROBLEM.svg: error against time, a line per degree and one
 * for solve_bvp. Not a test: run it by hand (docs/performance.md).
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli/cli.h"

#ifndef CV_SCENE_DIR
#define CV_SCENE_DIR "tests/scene/data"
#endif

static const char *const problems[] = {"catenary", "fisheye_ray", "harmonic_saddle",
                                       "boundary_layer", "sphere_geodesic"};
enum { NPROB = 5, NDEG = 4, NTARGET = 5, MAXPTS = 128 };
static const int degrees[NDEG] = {1, 2, 4, 8};
static const double targets[NTARGET] = {1e-4, 1e-6, 1e-8, 1e-10, 1e-12};

typedef struct {
  int elements, nodes;
  double err, time;
  double tol; /* --tol's requested T (0: a mesh chosen by hand) */
  cv_status st;
} point;
enum { NTOL = 23 }; /* T = 10^(-k/2), k = 4 .. 26 */

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* One mesh (or one --tol solve): fastest of repeated fresh solves, and the max nodal error
 * of the first. A solve that does not converge is -1, unless any_status (--tol: its status,
 * time and error are kept when it ended with a mesh). */
static int measure(const scene *s, const cv_problem *p, point *pt, double budget, int any_status) {
  double best = INFINITY, spent = 0;
  int reps = 0;
  pt->err = NAN;
  pt->nodes = 0;
  pt->st = CVAR_OK;
  char err[SC_ERRLEN];
  while (reps < 200 && (reps == 0 || spent < budget)) {
    double t0 = now();
    cv_solver *sv = cv_solver_new(NULL);
    if (!sv || scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK) {
      cv_solver_free(sv);
      return -1;
    }
    cv_status st = cv_solve(sv, p);
    int nn = cv_solver_get_num_nodes(sv), n = s->n;
    int keep = st == CVAR_OK || (any_status && nn > 0);
    if (keep && reps == 0) { /* the error (outside the timed part) */
      double t1 = now();
      double *x = malloc((size_t)nn * sizeof *x);
      double *y = malloc((size_t)nn * n * sizeof *y);
      double *ex = malloc((size_t)nn * n * sizeof *ex);
      pt->nodes = nn;
      pt->st = st;
      if (x && y && ex && cv_solver_get_nodes(sv, x) == CVAR_OK &&
          cv_solver_get_values(sv, y) == CVAR_OK && scene_eval_exact(s, nn, x, ex) == 0) {
        double e = 0;
        for (int i = 0; i < n; i++)
          for (int j = 0; j < nn; j++)
            e = fmax(e, fabs(y[(size_t)j * n + i] - ex[(size_t)i * nn + j]));
        pt->err = e;
      }
      free(x);
      free(y);
      free(ex);
      t0 += now() - t1;
    }
    cv_solver_free(sv);
    double t = now() - t0;
    if (!keep) return -1;
    best = fmin(best, t);
    spent += t;
    reps++;
  }
  pt->time = best;
  return 0;
}

/* The element counts: 1, 2, 3, 4, 5, 6, 8, 10, 13, 16, 20, 25, 32, ... */
static int next_elements(int e) {
  int f = (int)lround(e * 1.2599210498948732); /* 2^(1/3) */
  return f > e ? f : e + 1;
}

static int sweep(const scene *s0, const cv_problem *p, int degree, point *pts, int quick) {
  scene s = *s0;
  int np = 0, stale = 0;
  double best = INFINITY;
  s.degree = degree;
  for (int e = 1; np < MAXPTS && e <= (1 << 20); e = next_elements(e)) {
    if (e * degree < 8)
      continue; /* too few nodes to judge by: 1 element of degree 1 has no free node */
    s.elements = e;
    point *pt = &pts[np];
    pt->elements = e;
    pt->tol = 0;
    if (measure(&s, p, pt, quick ? 0.005 : 0.05, 0) < 0 || !isfinite(pt->err))
      continue; /* e.g. too coarse for Newton from the guess */
    np++;
    /* stop at the target floor, at round-off (no gain over 3 meshes once below 1e-9:
     * before that a layer may still be unresolved, with errors that do not fall yet), or
     * when slow */
    stale = pt->err < 0.5 * best || best > 1e-9 ? 0 : stale + 1;
    best = fmin(best, pt->err);
    if (pt->err < 0.5e-12 || stale >= 3 || pt->time > (quick ? 0.1 : 1.0)) break;
  }
  return np;
}

/* --tol T for T = 10^-2 .. 10^-13 (half decades) as `calcvar solve SCENE --tol T` sets it
 * up: no mesh given, so the start is SCENE_TOL_START_ELEMENTS of SCENE_TOL_START_DEGREE, and
 * the cap SCENE_TOL_MAX_NODES (scene_solver_configure). */
static int tol_sweep(const scene *s0, const cv_problem *p, point *pts, int quick) {
  scene s = *s0;
  int np = 0;
  s.elements = SCENE_TOL_START_ELEMENTS;
  s.degree = SCENE_TOL_START_DEGREE;
  for (int k = 4; k < 4 + NTOL; k++) {
    point *pt = &pts[np];
    s.tol = pt->tol = pow(10.0, -0.5 * k);
    pt->elements = 0;
    if (measure(&s, p, pt, quick ? 0.005 : 0.05, 1) < 0 || !isfinite(pt->err)) continue;
    np++;
    if (pt->time > 1.0) break;
  }
  return np;
}

/* Least time over the points at or below the target error; NAN if none. */
static double time_to(const point *pts, int np, double target, int *elements) {
  double t = NAN;
  *elements = 0;
  for (int k = 0; k < np; k++)
    if (pts[k].err <= target && !(pts[k].time >= t)) {
      t = pts[k].time;
      *elements = pts[k].elements;
    }
  return t;
}

/* The Pareto front of solve_bvp's points for the picture: sorted by time, each point kept
 * only when its error is below every faster one's. */
static int bvp_front(json_t *arr, double *x, double *y, int max) {
  int n = 0;
  size_t m = json_array_size(arr);
  double *t = malloc((m + 1) * sizeof *t), *e = malloc((m + 1) * sizeof *e);
  if (!t || !e) {
    free(t);
    free(e);
    return 0;
  }
  for (size_t k = 0; k < m; k++) {
    e[k] = json_number_value(json_array_get(json_array_get(arr, k), 0));
    t[k] = json_number_value(json_array_get(json_array_get(arr, k), 1));
  }
  for (size_t i = 1; i < m; i++) /* insertion sort by time: m is small */
    for (size_t j = i; j > 0 && t[j] < t[j - 1]; j--) {
      double a = t[j], b = e[j];
      t[j] = t[j - 1];
      e[j] = e[j - 1];
      t[j - 1] = a;
      e[j - 1] = b;
    }
  double best = INFINITY;
  for (size_t k = 0; k < m && n < max; k++)
    if (e[k] < best) {
      best = e[k];
      x[n] = t[k];
      y[n++] = e[k];
    }
  free(t);
  free(e);
  return n;
}

static int draw(const char *dir, const char *name, const char *title, point pts[][MAXPTS],
                const int *np, const point *tp, int ntp, json_t *bvp) {
  char path[4096];
  snprintf(path, sizeof path, "%s/work_precision_%s.svg", dir, name);
  double x[NDEG + 2][MAXPTS], y[NDEG + 2][MAXPTS];
  char labels[NDEG + 2][40];
  cli_plot_line lines[NDEG + 2];
  memset(lines, 0, sizeof lines);
  int nl = 0;
  for (int d = 0; d < NDEG; d++) {
    for (int k = 0; k < np[d]; k++) {
      x[d][k] = pts[d][k].time;
      y[d][k] = pts[d][k].err;
    }
    snprintf(labels[nl], sizeof labels[nl], "calcvar p = %d", degrees[d]);
    lines[nl] = (cli_plot_line){np[d], x[d], y[d], labels[nl], d, 0, 1};
    nl++;
  }
  int nt = 0; /* --tol: the converged solves, in the order of T */
  for (int k = 0; k < ntp; k++)
    if (tp[k].st == CVAR_OK) {
      x[NDEG + 1][nt] = tp[k].time;
      y[NDEG + 1][nt++] = tp[k].err;
    }
  if (nt > 0) {
    snprintf(labels[nl], sizeof labels[nl], "calcvar --tol (no mesh given)");
    lines[nl] = (cli_plot_line){nt, x[NDEG + 1], y[NDEG + 1], labels[nl], 4, 3, 1};
    nl++;
  }
  json_t *b = bvp ? json_object_get(bvp, name) : NULL;
  if (b) {
    int n = bvp_front(b, x[NDEG], y[NDEG], MAXPTS);
    snprintf(labels[nl], sizeof labels[nl], "scipy solve_bvp");
    lines[nl] = (cli_plot_line){n, x[NDEG], y[NDEG], labels[nl], -1, 2, 1};
    nl++;
  }
  char t[256];
  snprintf(t, sizeof t, "%s: work against precision", title);
  cli_plot_panel pan = {.title = t,
                        .xlabel = "run time of one solve [s]",
                        .ylabel = "max nodal error",
                        .logx = 1,
                        .logy = 1,
                        .legend_right = 1, /* six curves: no corner of the axes is free */
                        .vp = {0.075, 0.68, 0.12, 0.9},
                        .nlines = nl,
                        .lines = lines};
  cli_outfile o;
  if (cli_outfile_open(&o, path, NULL) < 0) return -1;
  if (cli_plot_write_page(&o, 1120, 560, 1, &pan) < 0) {
    cli_outfile_abandon(&o);
    return -1;
  }
  printf("wrote %s\n", path);
  return 0;
}

int main(int argc, char **argv) {
  const char *dir = CV_SCENE_DIR, *json_out = NULL, *bvp_in = NULL, *svg_dir = NULL;
  int quick = 0, with_tol = 1;
  for (int i = 1; i < argc; i++) {
    if (strcmp(argv[i], "--quick") == 0)
      quick = 1;
    else if (strcmp(argv[i], "--no-tol") == 0)
      with_tol = 0;
    else if (strcmp(argv[i], "--json") == 0 && i + 1 < argc)
      json_out = argv[++i];
    else if (strcmp(argv[i], "--bvp") == 0 && i + 1 < argc)
      bvp_in = argv[++i];
    else if (strcmp(argv[i], "--svg-dir") == 0 && i + 1 < argc)
      svg_dir = argv[++i];
    else if (argv[i][0] != '-')
      dir = argv[i];
    else {
      fprintf(stderr, "usage: work_precision [--quick] [--no-tol] [--json FILE] [--bvp FILE] "
                      "[--svg-dir DIR] [SCENE_DIR]\n");
      return 2;
    }
  }
  json_t *bvp = NULL, *all = json_object(), *alltol = json_object();
  if (bvp_in) {
    json_error_t je;
    if (!(bvp = json_load_file(bvp_in, 0, &je))) {
      fprintf(stderr, "work_precision: %s: %s\n", bvp_in, je.text);
      return 2;
    }
  }
  static point pts[NDEG][MAXPTS], tp[NTOL];
  printf("minimum time [s] of one solve to reach a max nodal error (elements in brackets)\n");
  printf("%-16s %7s", "problem", "error");
  for (int d = 0; d < NDEG; d++) printf("   p = %-13d", degrees[d]);
  printf("   best\n");
  for (int k = 0; k < NPROB; k++) {
    char path[4096], err[SC_ERRLEN];
    snprintf(path, sizeof path, "%s/%s.scene", dir, problems[k]);
    scene *s = scene_load_file(path, 0, NULL, err, sizeof err);
    cv_problem *p =
        s ? scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err)
          : NULL;
    if (!p) {
      fprintf(stderr, "work_precision: %s\n", err);
      scene_free(s);
      return 1;
    }
    int np[NDEG];
    json_t *jp = json_object();
    for (int d = 0; d < NDEG; d++) {
      np[d] = sweep(s, p, degrees[d], pts[d], quick);
      json_t *a = json_array();
      for (int q = 0; q < np[d]; q++)
        json_array_append_new(
            a, json_pack("[i,f,f]", pts[d][q].elements, pts[d][q].err, pts[d][q].time));
      char key[8];
      snprintf(key, sizeof key, "%d", degrees[d]);
      json_object_set_new(jp, key, a);
    }
    json_object_set_new(all, problems[k], jp);
    for (int t = 0; t < NTARGET; t++) {
      printf("%-16s %7.0e", t == 0 ? problems[k] : "", targets[t]);
      double best = INFINITY;
      int bd = 0;
      for (int d = 0; d < NDEG; d++) {
        int e;
        double tt = time_to(pts[d], np[d], targets[t], &e);
        if (isfinite(tt)) {
          char cell[32];
          snprintf(cell, sizeof cell, "%.2e (%d)", tt, e);
          printf("   %-17s", cell);
          if (tt < best) {
            best = tt;
            bd = degrees[d];
          }
        } else {
          printf("   %-17s", "-");
        }
      }
      if (bd)
        printf("   p=%d\n", bd);
      else
        printf("   -\n");
    }
    int ntp = with_tol ? tol_sweep(s, p, tp, quick) : 0;
    if (with_tol) {
      json_t *a = json_array();
      printf("%-16s --tol T: status, nodes, max nodal error, time [s]\n", "");
      for (int q = 0; q < ntp; q++) {
        const char *stn = cli_status_string(tp[q].st); /* as the report's "status" */
        printf("%-16s %9.1e  %-16s %7d  %9.2e  %9.2e\n", "", tp[q].tol, stn, tp[q].nodes, tp[q].err,
               tp[q].time);
        json_array_append_new(
            a, json_pack("[f,f,f,i,s]", tp[q].tol, tp[q].err, tp[q].time, tp[q].nodes, stn));
      }
      json_object_set_new(alltol, problems[k], a);
    }
    if (svg_dir && draw(svg_dir, problems[k], s->title, pts, np, tp, ntp, bvp) < 0)
      fprintf(stderr, "work_precision: the picture for %s could not be written\n", problems[k]);
    cv_problem_free(p);
    scene_free(s);
    fflush(stdout);
  }
  if (with_tol)
    json_object_set_new(all, "tol", alltol);
  else
    json_decref(alltol);
  if (json_out && json_dump_file(all, json_out, JSON_INDENT(1) | JSON_REAL_PRECISION(6)) < 0)
    fprintf(stderr, "work_precision: cannot write %s\n", json_out);
  json_decref(all);
  json_decref(bvp);
  return 0;
}
