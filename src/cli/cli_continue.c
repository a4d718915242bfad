/* src/cli/cli_continue.c — `solve --continue name=from:to`: reach the scene's problem by
 * continuation in one of its parameters (docs/cli.md).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "scene/scene_batch.h"

#define FIRST_STEPS  10
#define MIN_FRACTION (1.0 / 4096)

/* The scene (read once by the caller) compiled once, its parameters as inputs (issue 18):
 * every step only sets the continued parameter and builds a problem over the compiled integrand. */
static cv_batch *load_once(const cli_opts *o, scene *s, const char *name, char *err,
                           size_t errlen) {
  int found = 0;
  for (int i = 0; i < s->nparams; i++) found |= strcmp(s->params[i].name, name) == 0;
  if (!found) {
    snprintf(err, errlen, "calcvar solve: --continue: '%s' is not a parameter of %s", name,
             o->scene_path);
    scene_free(s);
    return NULL;
  }
  cv_batch *b = scene_batch_new(s, err, errlen);
  const char *col[1] = {name};
  if (b && cv_batch_set_columns(b, 1, col, err, errlen) != CVAR_OK) {
    cv_batch_free(b);
    return NULL;
  }
  return b;
}

/* Keep the mesh and nodal values of `from` as the mesh and start of `to`. */
static int carry_over(cv_solver *from, cv_solver *to, int n) {
  int E = cv_solver_get_num_elements(from), deg = cv_solver_get_degree(from);
  int nn = cv_solver_get_num_nodes(from), rc = -1;
  double *x = malloc((size_t)nn * sizeof *x), *y = malloc((size_t)nn * n * sizeof *y);
  double *t = malloc((size_t)(E + 1) * sizeof *t);
  if (x && y && t && cv_solver_get_nodes(from, x) == CVAR_OK &&
      cv_solver_get_values(from, y) == CVAR_OK) {
    int per = E > 0 ? (nn - 1) / E : 1; /* nodes per element: deg, or (deg - 1)/2 for C1 */
    for (int i = 0; i <= E; i++) t[i] = (x[(size_t)i * per] - x[0]) / (x[nn - 1] - x[0]);
    t[0] = 0.0;
    t[E] = 1.0;
    if (cv_solver_set_mesh(to, E, t) == CVAR_OK && cv_solver_set_degree(to, deg) == CVAR_OK &&
        cv_solver_set_start(to, nn * n, y) == CVAR_OK)
      rc = 0;
  }
  free(x);
  free(y);
  free(t);
  return rc;
}

/* Solve by continuation. On return *sp, *pp, *svp hold the last scene, problem and solver
 * (the one to report); the return value is the status of the last solve, or -1 with err
 * set when the input is bad (exit 2). cont_msg receives what was done. */
int cli_continue_solve(const cli_opts *o, scene *s0, cv_batch **bp, const scene **sp,
                       cv_problem **pp, cv_solver **svp, cv_status *stp, char *cont_msg,
                       size_t cmlen, char *err, size_t errlen) {
  char name[128];
  const char *e = strchr(o->cont, '='), *c = strchr(e, ':');
  size_t ln = (size_t)(e - o->cont) < sizeof name ? (size_t)(e - o->cont) : sizeof name - 1;
  memcpy(name, o->cont, ln);
  name[ln] = '\0';
  double from = strtod(e + 1, NULL), to = strtod(c + 1, NULL), v = from;
  double step = (to - from) / FIRST_STEPS, done_at = from;
  int steps = 0, failures = 0;
  const scene *s = NULL;
  cv_problem *p = NULL;
  cv_solver *sv = NULL, *last = NULL;
  cv_status st = CVAR_OK;
  cv_batch *b = load_once(o, s0, name, err, errlen);
  if (!b) return -1;
  for (;;) {
    const scene *s2 = NULL;
    /* p references the compiled clones only: free it before they change */
    cv_problem_free(p);
    p = NULL;
    cv_problem *p2 = scene_batch_problem(b, &v, &s2, err, errlen);
    if (!p2) goto bad;
    cv_solver *sv2 = cv_solver_new(NULL);
    if (!sv2 || scene_solver_configure(s2, sv2, err, errlen) != CVAR_OK ||
        (last && carry_over(last, sv2, s2->n) < 0)) {
      cv_solver_free(sv2);
      cv_problem_free(p2);
      goto bad;
    }
    cli_progress_attach(sv2);
    st = cv_solve(sv2, p2);
    cv_problem_free(p2);
    if (st == CVAR_OK || !last) {
      /* accepted (or the very first solve, reported as it is if it failed) */
      cv_solver_free(sv);
      s = s2, sv = sv2, last = sv2;
      if (st != CVAR_OK) break;
      done_at = v;
      steps++;
      if (v == to) break;
      v = (to - v) / step <= 1.0 ? to : v + step;
      if (failures == 0) step *= 1.5;
      failures = 0;
    } else {
      cv_solver_free(sv2);
      failures++;
      /* half the step that failed (it may have been cut short at the target): the next
       * value lies between the last accepted one and the failed one, never past `to` */
      step = 0.5 * (v - done_at);
      if (fabs(step) < fabs(to - from) * MIN_FRACTION) break;
      v = done_at + step;
    }
  }
  if (st == CVAR_OK)
    snprintf(cont_msg, cmlen, "reached by continuation in %s from %g to %g in %d steps", name, from,
             to, steps);
  else if (steps > 0)
    snprintf(cont_msg, cmlen,
             "continuation in %s from %g to %g stalled at %s = %.6g after %d steps: no "
             "stationary path found beyond it",
             name, from, to, name, done_at, steps);
  else
    snprintf(cont_msg, cmlen, "continuation in %s could not start at %s = %g", name, name, from);
  if (st == CVAR_OK || steps == 0) {
    *stp = st;
  } else {
    *stp = CVAR_ESTALL; /* the target value was not reached */
  }
  /* The problem to report on: the instance back at the accepted value (a rejected step
   * may have set another). */
  double acc = steps > 0 ? done_at : from;
  if (!(p = scene_batch_problem(b, &acc, &s, err, errlen))) goto bad;
  *bp = b, *sp = s, *pp = p, *svp = sv;
  return 0;
bad:
  cv_solver_free(sv);
  cv_problem_free(p);
  cv_batch_free(b);
  return -1;
}
