/* src/core/cv_solve.c — the solve driver: singular-end grading, the engine, and the retry
 * and continuation policy when Newton fails from the start.
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "cv_internal.h"

double cv_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

/* Reset the results of the previous solve. */
static void results_reset(cv_solver *s) {
  cv_solver_drop_results(s);
  s->iterations = 0;
  s->morse = -1;
  s->degenerate = 0;
  s->action = s->gnorm = NAN;
  s->t_assemble = s->t_factor = 0.0;
  s->csteps = 0;
  s->note[0] = '\0';
}

/* An integrand singular at an end on a plain uniform mesh: grade the mesh towards
 * that end, x_i = a + (b - a)(i/E)^k with k = min(4, 2 + p/2) (theory M-2). */
static cv_status grade_singular_ends(cv_solver *s, const cv_problem *p) {
  if (!(s->disc.sing_a || s->disc.sing_b) || s->mesh.kind != CV_MESH_UNIFORM || s->start)
    return CVAR_OK;
  cv_meshspec keep = s->mesh;
  int both = s->disc.sing_a && s->disc.sing_b, at_a = s->disc.sing_a;
  double k = fmin(4.0, 2.0 + 0.5 * s->degree);
  s->mesh.kind = CV_MESH_GRADED;
  s->mesh.grading = k;
  s->mesh.grade_end = both ? CVAR_GRADE_BOTH : at_a ? CVAR_GRADE_A : CVAR_GRADE_B;
  cv_status st = cv_start_setup(s, p);
  s->mesh = keep;
  if (st) return st;
  if (s->near_sing[0] || s->near_sing[1]) /* set by cv_solve_mesh, which says why */
    cv_set_msg(s->note, sizeof s->note, "the mesh was graded towards %s (k = %g); ",
               both   ? "both ends"
               : at_a ? "the start"
                      : "the end",
               k);
  else
    cv_set_msg(s->note, sizeof s->note,
               "the integrand is singular at %s, so the mesh was graded towards %s (k = %g); ",
               both   ? "both ends"
               : at_a ? "the start"
                      : "the end",
               both ? "them" : "it", k);
  return CVAR_OK;
}

/* A given start or guess that leads nowhere: once more from the straight line between
 * the end values (a guess steeper than the solution at a singular end starts Newton
 * where the Hessian is indefinite, docs/faq.md): one Newton run, cheaper than the
 * continuation. Returns CVAR_OK when it converged (the note says so); otherwise the
 * first attempt's results are restored and what continues is that attempt. */
static cv_status retry_straight_line(cv_solver *s, const cv_problem *p, cv_status first) {
  cv_status st = first;
  double *Y1 = cv_malloc((size_t)s->disc.ndof * sizeof *Y1);
  if (Y1 && !cv_start_values(s, p, &s->disc, Y1, 1)) {
    char keep[sizeof s->msg];
    int it = s->iterations, morse = s->morse, deg = s->degenerate;
    double act = s->action, gn = s->gnorm, *Yfail = s->y;
    memcpy(keep, s->msg, sizeof keep);
    s->y = Y1;
    if (cv_newton_run(s, p, &s->disc, s->y, s->mult, NULL) == CVAR_OK) {
      size_t ln = strlen(s->note);
      cv_set_msg(s->note + ln, sizeof s->note - ln,
                 "from the given start Newton failed after %d iterations (%s), from the "
                 "straight line it converged; ",
                 it, cv_strerror(first));
      cv_free(Yfail);
      st = CVAR_OK;
    } else {
      cv_free(s->y);
      s->y = Yfail;
      s->iterations = it, s->morse = morse, s->degenerate = deg;
      s->action = act, s->gnorm = gn;
      memcpy(s->msg, keep, sizeof keep);
    }
  } else {
    cv_free(Y1);
  }
  return st;
}

/* Continuation from the start, computed again (theory HC-2). */
static cv_status continue_from_start(cv_solver *s, const cv_problem *p, cv_status first) {
  cv_status st = first;
  double *Y0 = cv_malloc((size_t)s->disc.ndof * sizeof *Y0);
  char keep[sizeof s->msg];
  memcpy(keep, s->msg, sizeof keep);
  cv_status st0 = Y0 ? cv_start_values(s, p, &s->disc, Y0, 0) : CVAR_ENOMEM;
  if (!st0)
    st = cv_continuation_run(s, p, &s->disc, s->y, s->mult, Y0);
  else
    memcpy(s->msg, keep, sizeof keep); /* report Newton's failure */
  cv_free(Y0);
  return st;
}

/* Prefix the solver's own decisions (s->note) to the message. */
static void prefix_note(cv_solver *s) {
  if (!s->note[0]) return;
  char m[sizeof s->msg];
  size_t ln = strlen(s->note), lm = strlen(s->msg);
  if (ln + lm >= sizeof m) lm = sizeof m - 1 - ln;
  memcpy(m, s->note, ln);
  memcpy(m + ln, s->msg, lm);
  m[ln + lm] = '\0';
  memcpy(s->msg, m, sizeof m);
}

/* One solve on the mesh of s->mesh, with the singular ends known so far. */
static cv_status solve_once(cv_solver *s, const cv_problem *p) {
  cv_status st;
  results_reset(s);
  if (!p || !p->F) {
    st = CVAR_EINVAL;
    cv_set_msg(s->msg, sizeof s->msg, p ? "no integrand set" : "problem is NULL");
    goto done;
  }
  s->n = p->n;
  st = cv_start_setup(s, p);
  if (!st) st = grade_singular_ends(s, p);
  if (st) goto done;
  if (s->method != CVAR_METHOD_NEWTON) {
    st = cv_nlopt_run(s, p, &s->disc, s->y);
    goto done;
  }
  /* Newton from the start; if it fails to converge (not on bad input or a callback's
   * abort), Newton from the straight line when the start was given, then continuation
   * from the start, computed again, before giving up (theory HC-2). */
  st = cv_newton_run(s, p, &s->disc, s->y, s->mult, NULL);
  /* Globalisation failures only: not a Hessian singular at the start itself (continuation
   * cannot cure an invariance; one met on the way is the wandering iterate's), not an
   * integrand failing at the start, and not an iteration limit the caller chose below 20
   * (then the limit is what they asked for). */
  int lost = st == CVAR_ESTALL || st == CVAR_EDIVERGED ||
             ((st == CVAR_ENONFINITE || st == CVAR_ESINGULAR) && s->iterations > 0) ||
             (st == CVAR_EMAXITER && s->maxit >= 20);
  int unconstrained = p->nc == 0 && p->ni == 0;
  if (lost && (s->start || p->guess) && unconstrained) {
    st = retry_straight_line(s, p, st);
    lost = st != CVAR_OK;
  }
  if (lost && unconstrained && s->continuation) st = continue_from_start(s, p, st);
done:
  return st;
}

/* The graded retry (HC-3) changes the discretisation, and on it a problem without a
 * solution can have a discrete one (a conjugate point at the end: a huge multiple of the
 * nearly null direction). Its answer is kept only if the same retry on twice the elements
 * gives an action within 1e-2 of it (a real solution converges: the Poincare geodesic at
 * degree 1 moves by 2e-4; the artefact scales with the inverse of an O(h^2p) eigenvalue). */
static int twice_agrees(const cv_solver *s, const cv_problem *p, double *dev) {
  cv_solver *t = cv_solver_new(NULL);
  int ok = 0;
  *dev = INFINITY;
  if (!t) return 0;
  t->degree = s->degree, t->nq = s->nq, t->maxit = s->maxit;
  t->rtol = s->rtol, t->atol = s->atol, t->continuation = s->continuation;
  t->mesh.elements = 2 * s->mesh.elements;
  if (t->mesh.elements > 0 &&
      cv_solver_set_breakpoints(t, s->mesh.nbreak, s->mesh.breaks) == CVAR_OK) {
    t->near_sing[0] = t->near_sing[1] = 1;
    if (solve_once(t, p) == CVAR_OK) {
      *dev = fabs(t->action - s->action) / fmax(fabs(s->action), DBL_MIN);
      ok = *dev <= 1e-2;
    }
  }
  cv_solver_free(t);
  return ok;
}

/* One solve on the mesh of s->mesh (no adaptation). A converged solve whose end element
 * under-integrates a nearly singular integrand (theory Q-3) is solved again with that end
 * treated as singular (Q-2 rule, and grading on a uniform mesh, M-2). */
cv_status cv_solve_mesh(cv_solver *s, const cv_problem *p) {
  s->near_sing[0] = s->near_sing[1] = 0;
  cv_status st = solve_once(s, p);
  double rel[2] = {0.0, 0.0};
  int un[2] = {0, 0};
  /* Newton and continuation both lost on a uniform mesh, with no end flagged singular:
   * once more with both ends integrated as singular and the mesh graded towards them
   * (HC-3; the Poincare half-plane geodesic between (+-1, 0.01) rises from its ends at
   * slope 100, which the uniform mesh does not resolve). */
  if ((st == CVAR_ESTALL || st == CVAR_EDIVERGED || st == CVAR_EMAXITER) &&
      s->method == CVAR_METHOD_NEWTON && s->mesh.kind == CV_MESH_UNIFORM && !s->start && s->have &&
      !s->disc.sing_a && !s->disc.sing_b && s->maxit >= 20) {
    char first[sizeof s->msg];
    memcpy(first, s->msg, sizeof first);
    s->near_sing[0] = s->near_sing[1] = 1;
    cv_status st2 = solve_once(s, p);
    s->near_sing[0] = s->near_sing[1] = 0;
    double dev = 0.0;
    if (st2 == CVAR_OK && !twice_agrees(s, p, &dev)) {
      st2 = CVAR_ESTALL;
      if (isfinite(dev))
        cv_set_msg(s->msg, sizeof s->msg,
                   "a stationary path of this mesh was found, but twice the elements moved its "
                   "action by %.1e of itself: it is an artefact of the mesh, not a solution",
                   dev);
      else
        cv_set_msg(s->msg, sizeof s->msg,
                   "a stationary path of this mesh was found, but none on twice the elements: "
                   "it is an artefact of the mesh, not a solution");
    }
    if (st2 == CVAR_OK) {
      char keep[sizeof s->note];
      memcpy(keep, s->note, sizeof keep);
      cv_set_msg(s->note, sizeof s->note,
                 "on the uniform mesh Newton and continuation failed (%s), so both ends were "
                 "integrated as singular; %s",
                 cv_strerror(st), keep);
      st = CVAR_OK;
    } else {
      /* both attempts failed: say what was tried, with the first attempt's detail */
      char second[sizeof s->msg];
      memcpy(second, s->msg, sizeof second);
      s->note[0] = '\0';
      cv_set_msg(s->msg, sizeof s->msg,
                 "%s; with the mesh graded towards both ends and both integrated as singular: "
                 "%s",
                 first, strcmp(first, second) ? second : "the same again");
      st = st2;
    }
  }
  for (int end = 0; end < 2 && st == CVAR_OK; end++)
    un[end] = cv_start_end_unresolved(p, &s->disc, s->y, end, s->action, &rel[end]);
  if (un[0] || un[1]) {
    s->near_sing[0] = un[0], s->near_sing[1] = un[1];
    st = solve_once(s, p);
    char first[sizeof s->note];
    memcpy(first, s->note, sizeof first);
    cv_set_msg(s->note, sizeof s->note,
               "the integrand is nearly singular at %s (the singular-end rule changed the "
               "action by %.1e of itself there), so it is integrated as singular; %s",
               un[0] && un[1] ? "both ends"
               : un[0]        ? "the start"
                              : "the end",
               fmax(rel[0], rel[1]), first);
    s->near_sing[0] = s->near_sing[1] = 0;
  }
  prefix_note(s);
  s->status = st;
  return st;
}

cv_status cv_solve(cv_solver *s, const cv_problem *p) {
  if (!s) return CVAR_EINVAL;
  double t0 = cv_now();
  cv_pathset_free(s->paths); /* a plain solve forgets the paths of cv_solve_all */
  s->paths = NULL;
  s->err_est = NAN;
  s->rounds = 0;
  for (int k = 0; p && k < p->nnotes; k++) p->notes[k].fn(p->notes[k].user, 1);
  cv_status st = s->adapt_tol > 0 && p ? cv_adapt_run(s, p) : cv_solve_mesh(s, p);
  s->status = st;
  /* A failure the integrand can explain (a table's grid left): the cause first, then what
   * the engine saw. */
  const char *note = NULL;
  for (int k = 0; st != CVAR_OK && p && k < p->nnotes && !(note && note[0]); k++)
    note = p->notes[k].fn(p->notes[k].user, 0);
  if (note && note[0]) {
    char m[2 * sizeof s->msg];
    snprintf(m, sizeof m, "%s%s%s", note, s->msg[0] ? "; " : "", s->msg);
    memcpy(s->msg, m, sizeof s->msg - 1); /* truncated to the message buffer */
    s->msg[sizeof s->msg - 1] = '\0';
  }
  s->time = cv_now() - t0;
  return st;
}
