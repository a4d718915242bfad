/* tests/scene/test_scene_nomem.c — allocation failures in the expression and scene layers:
 * fail the k-th allocation (and every one after it) of loading a scene, building its
 * problem, solving it and evaluating its energy and momenta, for every k until the step
 * succeeds. Each failing step must report a failure (NULL with a message, a status, -1),
 * never crash. (The scene's guess is a callback that compiles its expression when called:
 * an allocation failing there reaches the solver as CVAR_ECALLBACK, the status of a callback
 * that reported an error.) The mechanics (cv_equations_new, cv_modes_new: the constrained
 * equilibrium of the rod) must come back NULL with a status and a sentence. ASan (the sanitised CI run) checks that nothing leaks on any of these paths.
 * SPDX-License-Identifier: MIT
 */
#include <stdio.h>
#include <string.h>

#include "core/cv_memory.h"
#include "scene/scene.h"
#include "scene/scene_internal.h" /* struct cv_scene, to call cv_equations_new on s */

static int failures, checks;

static void truth(const char *what, int ok, const char *detail) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: %s\n", what, detail);
  }
}

/* Every section the loader knows, so that each of its allocations is on the path. */
static const char text[] = "[scene]\n"
                           "title     = Pendulum, Cartesian, every section\n"
                           "variable  = t\n"
                           "interval  = 0, 0.5\n"
                           "unknowns  = x, y\n"
                           "integrand = m*(x'^2 + y'^2)/2 - m*g*y +\n"
                           "            0*v2\n"
                           "[parameters]\n"
                           "m = 1\n"
                           "l = 1\n"
                           "g = 9.81\n"
                           "[definitions]\n"
                           "v2 = x'^2 + y'^2\n"
                           "[boundary]\n"
                           "x = 0, l*sin(1)\n"
                           "y = -l, -l*cos(1)\n"
                           "[guess]\n"
                           "x = l*sin(2*t)\n"
                           "y = -l*cos(2*t)\n"
                           "[constraints]\n"
                           "rod = x^2 + y^2 - l^2\n"
                           "[report]\n"
                           "speed2 = v2\n"
                           "[mesh]\n"
                           "elements = 6\n"
                           "degree = 3\n"
                           "breakpoints = 0.25\n";

static scene *load(char *err) {
  return scene_load_buffer(text, strlen(text), "t.scene", 0, NULL, err, SC_ERRLEN);
}

int main(void) {
  char err[SC_ERRLEN], what[64];
  int k, ok = 0;

  /* Loading. */
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

  /* Building the problem, solving, and the energy and momenta along the solution. */
  ok = 0;
  for (k = 0; k < 100000 && !ok; k++) {
    scene *s = load(err);
    cv_solver *sv = cv_solver_new(NULL);
    truth("load and solver without injection", s && sv, err);
    if (!s || !sv) {
      scene_free(s);
      cv_solver_free(sv);
      break;
    }
    double x[2] = {0.1, 0.3}, y[4] = {0.5, 0.6, -0.8, -0.7}, dy[4] = {1, 2, 3, 4}, H[2], p[4];
    err[0] = '\0';
    cv_debug_fail_alloc_after(k);
    cv_problem *pb =
        scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err);
    cv_status st = pb ? scene_solver_configure(s, sv, err, sizeof err) : CVAR_ENOMEM;
    if (pb && st == CVAR_OK) st = cv_solve(sv, pb);
    cv_status ev = st == CVAR_OK ? cv_problem_eval_energy(pb, 2, x, y, dy, H, p) : CVAR_ENOMEM;
    cv_debug_fail_alloc_after(-1);
    snprintf(what, sizeof what, "problem/solve/energy, allocation %d fails", k);
    if (!pb)
      truth(what, err[0] != '\0', "NULL problem without a message");
    else if (st != CVAR_OK)
      truth(what, st == CVAR_ENOMEM || st == CVAR_EDEPENDENCY || st == CVAR_ECALLBACK,
            cv_status_name(st));
    else if (ev == CVAR_OK)
      ok = 1;
    else
      truth(what, ev == CVAR_ENOMEM, cv_status_name(ev));
    cv_problem_free(pb);
    cv_solver_free(sv);
    scene_free(s);
  }
  truth("problem, solve and energy succeed once allocations do", ok, "never succeeded");
  printf("problem/solve/energy: %d injection points\n", k);

  /* The mechanics of the scene through the public handles. */
  for (int which = 0; which < 2; which++) {
    ok = 0;
    for (k = 0; k < 100000 && !ok; k++) {
      scene *s = load(err);
      truth("load without injection", s != NULL, err);
      if (!s) break;
      struct cv_scene sc = {s};
      cv_status why = CVAR_OK;
      err[0] = '\0';
      cv_debug_fail_alloc_after(k);
      void *h = which == 0 ? (void *)cv_equations_new(&sc, &why, err, sizeof err)
                           : (void *)cv_modes_new(&sc, &why, err, sizeof err);
      cv_debug_fail_alloc_after(-1);
      snprintf(what, sizeof what, "%s, allocation %d fails", which ? "modes" : "equations", k);
      if (h)
        ok = 1;
      else
        truth(what, err[0] != '\0' && why == CVAR_ENOMEM, cv_status_name(why));
      if (which == 0)
        cv_equations_free(h);
      else
        cv_modes_free(h);
      scene_free(s);
    }
    truth("mechanics succeeds once allocations do", ok, which ? "modes" : "equations");
    printf("%s: %d injection points\n", which ? "modes" : "equations", k);
  }

  printf("%d checks, %d failed\n", checks, failures);
  return failures ? 1 : 0;
}
