/* tests/c1/test_c1_nomem.c — allocation failures on the paths of second derivatives: fail
 * the k-th allocation (and every one after it) of loading a scene with y'' (slope line,
 * definition, integral, report), building its problem, solving it on C1 elements (plain,
 * and --tol's rounds with their enriched solves), gathering its report (slopes, y'' at the
 * quadrature points) and building its fourth-order equations, for every k until the step
 * succeeds. Each failing step must report a failure, never crash; ASan (the sanitised CI
 * run) checks that nothing leaks on any of these paths. SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <string.h>

#include "core/cv_memory.h"
#include "scene/scene.h"
#include "scene/scene_internal.h"
#include "scene/scene_report.h"

static int failures, checks;

static void truth(const char *what, int ok, const char *detail) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: %s\n", what, detail);
  }
}

static const char text[] = "[scene]\n"
                           "title     = Cantilever with a shortening\n"
                           "interval  = 0, 1\n"
                           "unknowns  = w\n"
                           "integrand = EI/2*k2 - q*w\n"
                           "[parameters]\n"
                           "EI = 2\n"
                           "q = 3\n"
                           "[definitions]\n"
                           "k2 = w''^2\n"
                           "[boundary]\n"
                           "w = 0, free\n"
                           "w' = 0, free\n"
                           "[guess]\n"
                           "w = 0.1*x^2\n"
                           "[integrals]\n"
                           "short = w'^2/2, 0.01\n"
                           "[report]\n"
                           "bending = EI/2*w''^2\n"
                           "[mesh]\n"
                           "elements = 3\n"
                           "degree = 5\n";

static scene *load(char *err) {
  return scene_load_buffer(text, strlen(text), "c1.scene", 0, NULL, err, SC_ERRLEN);
}

/* Problem, solve (tol > 0: the rounds of H-8) and report, allocation k failing. Returns 1
 * when everything succeeded. */
static int step(int k, double tol) {
  char err[SC_ERRLEN] = "", what[80];
  scene *s = load(err);
  cv_solver *sv = cv_solver_new(NULL);
  truth("load and solver without injection", s && sv, err);
  if (!s || !sv) {
    scene_free(s);
    cv_solver_free(sv);
    return -1;
  }
  s->tol = tol;
  cli_report r;
  memset(&r, 0, sizeof r);
  int ok = 0;
  cv_debug_fail_alloc_after(k);
  cv_problem *pb =
      scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err);
  cv_status st = pb ? scene_solver_configure(s, sv, err, sizeof err) : CVAR_ENOMEM;
  if (pb && st == CVAR_OK) st = cv_solve(sv, pb);
  int rc = st == CVAR_OK ? cli_report_build(&r, s, pb, sv, st, tol > 0 ? 2 : 0) : -1;
  cv_debug_fail_alloc_after(-1);
  snprintf(what, sizeof what, "problem/solve/report (tol %g), allocation %d fails", tol, k);
  if (!pb)
    truth(what, err[0] != '\0', "NULL problem without a message");
  else if (st != CVAR_OK)
    truth(what,
          st == CVAR_ENOMEM || st == CVAR_EDEPENDENCY || st == CVAR_ECALLBACK ||
              st == CVAR_EMAXITER,
          cv_status_name(st));
  else
    ok = rc == 0;
  cli_report_free(&r);
  cv_problem_free(pb);
  cv_solver_free(sv);
  scene_free(s);
  return ok;
}

int main(void) {
  char err[SC_ERRLEN], what[64];
  int k, ok = 0;
  for (k = 0; k < 100000 && !ok; k++) {
    err[0] = '\0';
    cv_debug_fail_alloc_after(k);
    scene *s = load(err);
    cv_debug_fail_alloc_after(-1);
    snprintf(what, sizeof what, "load, allocation %d fails", k);
    if (s)
      ok = 1;
    else
      truth(what, err[0] != '\0', "NULL without a message");
    scene_free(s);
  }
  truth("load succeeds once allocations do", ok, "never loaded");
  printf("load: %d injection points\n", k);
  for (int t = 0; t < 2; t++) {
    double tol = t ? 1e-6 : 0.0;
    for (ok = 0, k = 0; k < 100000 && ok == 0; k++) ok = step(k, tol);
    truth("problem, solve and report succeed once allocations do", ok == 1, "never succeeded");
    printf("problem/solve/report (tol %g): %d injection points\n", tol, k);
  }
  for (ok = 0, k = 0; k < 100000 && !ok; k++) {
    scene *s = load(err);
    truth("load without injection", s != NULL, err);
    if (!s) break;
    struct cv_scene sc = {s};
    cv_status why = CVAR_OK;
    err[0] = '\0';
    cv_debug_fail_alloc_after(k);
    cv_equations *h = cv_equations_new(&sc, &why, err, sizeof err);
    cv_debug_fail_alloc_after(-1);
    snprintf(what, sizeof what, "equations, allocation %d fails", k);
    if (h)
      ok = 1;
    else
      truth(what, err[0] != '\0' && why == CVAR_ENOMEM, cv_status_name(why));
    cv_equations_free(h);
    scene_free(s);
  }
  truth("equations succeed once allocations do", ok, "never succeeded");
  printf("equations: %d injection points\n", k);
  printf("%d checks, %d failed\n", checks, failures);
  return failures ? 1 : 0;
}
