/* src/scene/scene_problem.c — a cv_problem and solver settings from a loaded scene.
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>

#include "core/cv_table_internal.h"
#include "expr/ex_integrand.h"
#include "scene/scene_internal.h"

/* cv_guess_fn over the scene's [guess] (and the default for unknowns without one). */
static int guess_cb(int m, const double *x, double *y, void *user) {
  return scene_eval_guess(user, m, x, y) < 0 ? -1 : 0;
}

/* An integrand object for e; with parameters as inputs they are set to their values. */
static ex_integrand *compile_order(const scene *s, ex_id e, unsigned max_need, int order, char *msg,
                                   size_t len) {
  int np = s->params_as_inputs ? s->nparams : 0;
  /* second order: y'' after the parameters and the width's slot, which F never reads
   * when the parameters are numbers; a pointwise constraint is of order 1 on that layout */
  ex_integrand *g =
      s->c1 ? ex_integrand_new_order(s->dag, s->n, s->nparams + 1, order, e, max_need, msg, len)
            : ex_integrand_new_params(s->dag, s->n, np, e, max_need, msg, len);
  if (g && np) {
    double *v = cv_malloc((size_t)np * sizeof *v);
    if (!v) {
      ex_integrand_free(g);
      return NULL;
    }
    for (int i = 0; i < np; i++) v[i] = s->params[i].value;
    ex_integrand_set_params(g, v);
    cv_free(v);
  }
  return g;
}

static ex_integrand *compile(const scene *s, ex_id e, unsigned max_need, char *msg, size_t len) {
  return compile_order(s, e, max_need, 2, msg, len);
}

/* The smoothing hook of the core (theory HC-4): the width is the integrand's last input. */
void sc_set_smoothing_width(void *user, double w) {
  ex_integrand *g = user;
  ex_integrand_set_param(g, ex_integrand_num_params(g) - 1, w);
}

/* The integrand: when it jumps in y or y' (an if or a comparison on the unknowns), compiled
 * with the jumps smoothable, the width one more input after the parameters, 0 (the
 * integrand as written) until the solve policy sets it. *count: the jumps, 0 for none. */
static ex_integrand *compile_integrand(const scene *s, unsigned max_need, int *count, char *msg,
                                       size_t len) {
  int np = s->params_as_inputs ? s->nparams : 0;
  *count = 0;
  if (s->c1) return compile(s, s->F, max_need, msg, len); /* C^1: no smoothing of jumps */
  ex_id Fs = ex_smooth_jumps(s->dag, s->F, 1, 2 * s->n, 2 * s->n + 1 + np, count);
  if (Fs < 0) return NULL;
  if (*count == 0) return compile(s, s->F, max_need, msg, len);
  ex_integrand *g = ex_integrand_new_params(s->dag, s->n, np + 1, Fs, max_need, msg, len);
  if (g) {
    for (int i = 0; i < np; i++) ex_integrand_set_param(g, i, s->params[i].value);
    ex_integrand_set_param(g, np, 0.0);
  }
  return g;
}

cv_problem *scene_problem_new(const scene *s, unsigned max_need, char *err, size_t errlen) {
  cv_status why;
  char msg[512] = "";
  if (err && errlen) err[0] = '\0';
  cv_problem *p = cv_problem_new(s->n, s->a, s->b, &why);
  if (!p) {
    sc_err(err, errlen, s->file, 0, "cannot create the problem: %s", cv_strerror(why));
    return NULL;
  }
  int njumps = 0;
  ex_integrand *ig = compile_integrand(s, max_need, &njumps, msg, sizeof msg);
  if (!ig) {
    sc_err(err, errlen, s->file, s->F_line, "integrand: %s", msg[0] ? msg : "out of memory");
    goto fail;
  }
  why = cv_problem_set_integrand_owned(p, ex_integrand_eval, ig, ex_integrand_release);
  if (why == CVAR_OK && ex_integrand_has_tables(ig)) /* names a table whose grid was left */
    why = cv_problem_add_note(p, ex_integrand_note, ig);
  if (why == CVAR_OK && njumps > 0)
    why = cv_problem_set_smoothing(p, sc_set_smoothing_width, ig, njumps);
  if (why != CVAR_OK) {
    sc_err(err, errlen, s->file, s->F_line, "integrand: %s", cv_strerror(why));
    goto fail;
  }
  for (int i = 0; i < s->n; i++)
    for (int end = 0; end < 2; end++) {
      why = s->bc[i].free_end[end] ? cv_problem_set_free_end(p, i, end)
                                   : cv_problem_set_end_value(p, i, end, s->bc[i].value[end]);
      if (why != CVAR_OK) {
        sc_err(err, errlen, s->file, s->bc[i].line, "[boundary] %s: %s", s->unknowns[i],
               cv_strerror(why));
        goto fail;
      }
    }
  for (int i = 0; i < s->n && s->c1; i++) { /* second order: C^1 elements, slopes (H-1) */
    why = s->order2[i] ? cv_problem_set_second_order(p, i) : CVAR_OK;
    for (int end = 0; end < 2 && why == CVAR_OK && s->sbc && s->sbc[i].line; end++)
      if (!s->sbc[i].free_end[end]) why = cv_problem_set_end_slope(p, i, end, s->sbc[i].value[end]);
    if (why != CVAR_OK) {
      sc_err(err, errlen, s->file, s->sbc && s->sbc[i].line ? s->sbc[i].line : s->F_line,
             "%s'': %s", s->unknowns[i], cv_strerror(why));
      goto fail;
    }
  }
  /* [constraints] G(x, y) = 0 and [integrals] int K = c (theory C-1, C-2), compiled with
   * the derivatives the method needs. */
  for (int k = 0; k < s->ncons; k++) {
    const sc_item *it = &s->cons[k];
    ex_integrand *g = compile_order(s, it->expr, max_need, 1, msg, sizeof msg);
    if (!g) {
      sc_err(err, errlen, s->file, it->line, "[constraints] %s: %s", it->name,
             msg[0] ? msg : "out of memory");
      goto fail;
    }
    why = cv_problem_add_constraint_owned(p, ex_integrand_eval_constraint, g, ex_integrand_release,
                                          NULL);
    if (why == CVAR_OK) why = cv_problem_set_constraint_sense(p, k, it->sense);
    if (why == CVAR_OK && ex_integrand_has_tables(g))
      why = cv_problem_add_note(p, ex_integrand_note, g);
    if (why != CVAR_OK) {
      sc_err(err, errlen, s->file, it->line, "[constraints] %s: %s", it->name, cv_strerror(why));
      goto fail;
    }
  }
  for (int k = 0; k < s->nints; k++) {
    const sc_item *it = &s->ints[k];
    ex_integrand *g = compile(s, it->expr, max_need, msg, sizeof msg);
    if (!g) {
      sc_err(err, errlen, s->file, it->line, "[integrals] %s: %s", it->name,
             msg[0] ? msg : "out of memory");
      goto fail;
    }
    why = cv_problem_add_integral_owned(p, ex_integrand_eval, g, ex_integrand_release, it->value,
                                        NULL);
    if (why == CVAR_OK && ex_integrand_has_tables(g))
      why = cv_problem_add_note(p, ex_integrand_note, g);
    if (why != CVAR_OK) {
      sc_err(err, errlen, s->file, it->line, "[integrals] %s: %s", it->name, cv_strerror(why));
      goto fail;
    }
  }
  /* periodic unknowns (PB-1), after [integrals] so that those keep their numbers, and the
   * phase condition that pins the shift (PB-2) */
  for (int i = 0; i < s->n; i++)
    if (s->bc[i].periodic && (why = cv_problem_set_periodic(p, i, s->bc[i].shift, NULL))) {
      sc_err(err, errlen, s->file, s->bc[i].line, "[boundary] %s: %s", s->unknowns[i],
             cv_strerror(why));
      goto fail;
    }
  if (scene_pins_shift(s)) {
    ex_id K;
    double c;
    ex_integrand *g = NULL;
    if (scene_phase_condition(s, &K, &c) == 0) g = compile(s, K, max_need, msg, sizeof msg);
    if (!g) {
      sc_err(err, errlen, s->file, s->bc[0].line, "[boundary]: the phase condition: %s",
             msg[0] ? msg : "out of memory");
      goto fail;
    }
    why = cv_problem_add_integral_owned(p, ex_integrand_eval, g, ex_integrand_release, c, NULL);
    if (why != CVAR_OK) {
      sc_err(err, errlen, s->file, s->bc[0].line, "[boundary]: the phase condition: %s",
             cv_strerror(why));
      goto fail;
    }
  }
  if (scene_problem_set_ends(s, p, err, errlen) < 0) goto fail;
  int any_guess = 0;
  for (int i = 0; i < s->n; i++) any_guess |= s->guess[i] >= 0;
  /* Without [guess] the core's default is the same as ours (SCENES.md). */
  if (any_guess && (why = cv_problem_set_guess(p, guess_cb, (void *)s)) != CVAR_OK) {
    sc_err(err, errlen, s->file, 0, "[guess]: %s", cv_strerror(why));
    goto fail;
  }
  return p;
fail:
  cv_problem_free(p);
  return NULL;
}

void scene_tol_start(scene *s) {
  if (!(s->tol > 0)) return;
  if (!s->elements_line && s->grading <= 0) s->elements = SCENE_TOL_START_ELEMENTS;
  if (!s->degree_line) s->degree = SCENE_TOL_START_DEGREE;
}

cv_status scene_solver_configure(const scene *s, cv_solver *sv, char *err, size_t errlen) {
  const char *what = "elements";
  if (err && errlen) err[0] = '\0';
  cv_status st = s->grading > 0
                     ? cv_solver_set_mesh_graded(sv, s->elements, s->grading, s->graded_end)
                     : cv_solver_set_elements(sv, s->elements);
  if (st == CVAR_OK) {
    what = "degree";
    st = cv_solver_set_degree(sv, s->degree);
  }
  if (st == CVAR_OK && s->nbreak > 0) {
    what = "breakpoints";
    st = cv_solver_set_breakpoints(sv, s->nbreak, s->breakpoints);
  }
  if (st == CVAR_OK) {
    what = "tolerance";
    st = cv_solver_set_tolerances(sv, s->tolerance, s->tolerance);
  }
  if (st == CVAR_OK) {
    what = "max_iterations";
    st = cv_solver_set_max_iterations(sv, s->max_iterations);
  }
  if (st == CVAR_OK && s->adapt > 0) {
    what = "adapt"; /* [mesh] adapt; the command caps the mesh at 2e6 elements */
    st = cv_solver_set_adapt(sv, s->adapt, 2000000);
  }
  if (st == CVAR_OK && s->tol > 0) {
    what = "tol"; /* [mesh] tol or --tol: automatic accuracy, capped at 1e6 nodes or --max-nodes */
    st = cv_solver_set_tol(sv, s->tol,
                           s->tol_max_nodes > 0 ? s->tol_max_nodes : SCENE_TOL_MAX_NODES);
  }
  if (st == CVAR_OK && s->time_limit > 0) {
    what = "time limit"; /* --time-limit: a cap on the rounds' wall-clock time (HP-6) */
    st = cv_solver_set_time_limit(sv, s->time_limit);
  }
  if (st == CVAR_OK) {
    what = "method";
    st = cv_solver_set_method(sv, s->method);
  }
  if (st != CVAR_OK)
    sc_err(err, errlen, s->file, 0, "%s: %s (%s)", what, cv_solver_last_error(sv), cv_strerror(st));
  return st;
}
