/* tests/batch/test_batch_api.c — the C API of the batch engine (cv_batch, issue 18): one
 * compiled scene, many parameter sets, on two threads, with and without warm starts; every
 * row against its closed form; --tol rows on reused meshes against rows solved from scratch
 * (issue 28). Usage: test_batch_api DATA_DIR [WGS84_SCENE]. SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"

static int failures, checks;

static void check(const char *what, int ok, double expected, double actual) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: expected %.17g, got %.17g\n", what, expected, actual);
  }
}

/* y = A + s x + (c/4) x (x - L) on [0, L], F = y'^2 + c y (data/line.scene). */
static double exact_action(double A, double B, double L, double c) {
  double s = (B - A) / L;
  return L * s * s + c * A * L + c * s * L * L / 2 - c * c * L * L * L / 48;
}

enum { ROWS = 64 };

/* --tol through the C API (the scene's [mesh] tol = 1e-10): a sweep of WGS84 geodesics on
 * one thread, each row starting from the mesh the row before handed on (theory HP-9), and
 * the same rows each solved from scratch by a batch of one row: lengths to 1e-6 m (both
 * within the tolerance of the path; the length is stationary), estimates at most 1e-10,
 * the same with warm starts. */
enum { SWEEP = 16 };
static void tol_reuse(const char *scene) {
  char err[512];
  const char *cols[] = {"lat1", "lon1", "lat2", "lon2"};
  double rows[SWEEP * 4], len[3][SWEEP];
  cv_batch_result res[SWEEP];
  for (int r = 0; r < SWEEP; r++) {
    rows[4 * r] = 60, rows[4 * r + 1] = 0, rows[4 * r + 3] = 120;
    rows[4 * r + 2] = -60 + 126 * fabs(sin(3.141592653589793 * r / SWEEP));
  }
  for (int mode = 0; mode < 3; mode++) { /* from scratch, reused, reused and warm */
    cv_batch *b = cv_batch_new(scene, err, sizeof err);
    if (!b || cv_batch_set_columns(b, 4, cols, err, sizeof err) != CVAR_OK) {
      printf("FAIL %s: %s\n", scene, err);
      failures++;
      cv_batch_free(b);
      return;
    }
    cv_batch_set_warm_start(b, mode == 2);
    for (int r = 0; r < SWEEP; r++) res[r].outputs = &len[mode][r];
    if (mode == 0) /* one row per call on a new batch: nothing to reuse */
      for (int r = 0; r < SWEEP; r++) {
        cv_batch *one = cv_batch_new(scene, err, sizeof err);
        check("one-row batch",
              one && cv_batch_set_columns(one, 4, cols, err, sizeof err) == CVAR_OK &&
                  cv_batch_solve(one, 1, rows + 4 * r, &res[r]) == CVAR_OK,
              0, r);
        cv_batch_free(one);
      }
    else
      check("solve returns OK", cv_batch_solve(b, SWEEP, rows, res) == CVAR_OK, 0, mode);
    for (int r = 0; r < SWEEP; r++) {
      check("tol row converged", res[r].status == CVAR_OK && res[r].has_result, CVAR_OK,
            res[r].status);
      check("tol row estimate <= 1e-10", res[r].error_estimate <= 1e-10, 1e-10,
            res[r].error_estimate);
      if (mode > 0)
        check("reused mesh: length as from scratch to 1e-6 m",
              fabs(len[mode][r] - len[0][r]) <= 1e-6, len[0][r], len[mode][r]);
    }
    cv_batch_free(b);
  }
}

int main(int argc, char **argv) {
  char path[4096], err[512];
  snprintf(path, sizeof path, "%s/line.scene", argc > 1 ? argv[1] : ".");
  cv_batch *b = cv_batch_new(path, err, sizeof err);
  if (!b) {
    printf("FAIL cv_batch_new: %s\n", err);
    return 1;
  }
  check("five parameters", cv_batch_num_parameters(b) == 5, 5, cv_batch_num_parameters(b));
  check("one output (len)",
        cv_batch_num_outputs(b) == 1 && strcmp(cv_batch_output_name(b, 0), "len") == 0, 1,
        cv_batch_num_outputs(b));
  const char *bad[] = {"A", "nosuch"};
  check("unknown column refused",
        cv_batch_set_columns(b, 2, bad, err, sizeof err) == CVAR_EINVAL &&
            strstr(err, "nosuch") != NULL,
        CVAR_EINVAL, 0);
  const char *cols[] = {"A", "B", "L", "c"};
  if (cv_batch_set_columns(b, 4, cols, err, sizeof err) != CVAR_OK) {
    printf("FAIL set_columns: %s\n", err);
    return 1;
  }
  double neg[4] = {0, 1, -1, 0};
  check("a >= b refused by check_row",
        cv_batch_check_row(b, neg, err, sizeof err) == CVAR_EINVAL && strstr(err, "a < b") != NULL,
        CVAR_EINVAL, 0);
  /* a smooth sweep: neighbouring rows are close, so warm starts apply */
  double rows[ROWS * 4], outs[2][ROWS];
  cv_batch_result res[2][ROWS];
  for (int r = 0; r < ROWS; r++) {
    double t = (double)r / (ROWS - 1);
    rows[4 * r + 0] = 1 - t, rows[4 * r + 1] = 2 + t, rows[4 * r + 2] = 0.5 + 2 * t;
    rows[4 * r + 3] = 3 * sin(4 * t);
  }
  cv_batch_set_threads(b, 2);
  for (int warm = 0; warm < 2; warm++) {
    cv_batch_set_warm_start(b, warm);
    for (int r = 0; r < ROWS; r++) res[warm][r].outputs = &outs[warm][r];
    check("solve returns OK", cv_batch_solve(b, ROWS, rows, res[warm]) == CVAR_OK, 0, 0);
    int nwarm = 0;
    for (int r = 0; r < ROWS; r++) {
      const double *v = rows + 4 * r;
      double act = exact_action(v[0], v[1], v[2], v[3]);
      cv_batch_result *q = &res[warm][r];
      check("converged", q->status == CVAR_OK && q->has_result, CVAR_OK, q->status);
      check("action to 1e-10", fabs(q->action - act) <= 1e-10 * fmax(1, fabs(act)), act, q->action);
      check("nodal error < 1e-11", q->error_max_nodal < 1e-11, 0, q->error_max_nodal);
      check("Morse index 0", q->morse_index == 0, 0, q->morse_index);
      check("no estimate without adapt", isnan(q->error_estimate), NAN, q->error_estimate);
      check("time measured", q->time_s > 0, 1, q->time_s);
      nwarm += q->warm;
    }
    if (warm) {
      /* 64 rows on 2 threads in blocks of 4: the first row of every block starts cold */
      check("most rows warm-started", nwarm >= ROWS / 2, ROWS / 2, nwarm);
      for (int r = 0; r < ROWS; r++)
        check("warm and cold agree (len)",
              fabs(outs[0][r] - outs[1][r]) <= 1e-12 * fabs(outs[0][r]), outs[0][r], outs[1][r]);
    } else {
      check("no row warm-started when off", nwarm == 0, 0, nwarm);
    }
  }
  cv_batch_free(b);
  if (argc > 2) tol_reuse(argv[2]);
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? 1 : 0;
}
