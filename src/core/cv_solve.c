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
  s->action = s->gnorm = s->gfloor = NAN;
  s->t_assemble = s->t_factor = 0.0;
  s->csteps = 0;
  s->smooth_w = 0.0;
  s->note[0] = '\0';
}

/* The smallest end element automatic grading makes is 10^-CV_GRADE_MIN_DIGITS of the
 * interval: next to a singular end the Hessian's entries there are differences of nearly
 * equal large terms (theory M-2), and on smaller elements its inertia, the Morse index,
 * was measured wrong (brachistochrone, 1000 elements of degree 8 at k = 4: h = 1e-12). */
#define CV_GRADE_MIN_DIGITS 10.0

/* Negative directions of the Hessian on a mesh whose elements at a singular end are
 * smaller than automatic grading makes them (CV_GRADE_MIN_DIGITS): there the Hessian is a
 * difference of nearly equal large terms, and both a count too high (a minimum called a
 * saddle) and one that changes with the quadrature were measured. The count stays what the
 * discrete Hessian says; the message says it may be the mesh's. */
static __attribute__((noinline, cold)) void caution_tiny_end_elements(cv_solver *s) {
  const cv_disc *d = &s->disc;
  double L = d->b - d->a, h = INFINITY;
  if (d->E < 1 || !(L > 0)) return;
  if (d->sing_a) h = fmin(h, d->xe[1] - d->xe[0]);
  if (d->sing_b) h = fmin(h, d->xe[d->E] - d->xe[d->E - 1]);
  if (!(h < L * pow(10.0, -CV_GRADE_MIN_DIGITS))) return;
  size_t ln = strlen(s->note);
  cv_set_msg(s->note + ln, sizeof s->note - ln,
             "the element at the singular end is %.1e of the interval, below the 1e-%g "
             "down to which the Morse index was checked: its negative directions may belong "
             "to the mesh, not the path (compare a milder grading); ",
             h / L, CV_GRADE_MIN_DIGITS);
}

/* An integrand singular at an end on a plain uniform mesh: grade the mesh towards
 * that end, x_i = a + (b - a)(i/E)^k with k = min(4, 2 + p/2), lowered so that the end
 * element keeps at least 1e-10 of the interval, E^-k >= 1e-10 (theory M-2). */
static cv_status grade_singular_ends(cv_solver *s, const cv_problem *p) {
  if (!(s->disc.sing_a || s->disc.sing_b) || s->mesh.kind != CV_MESH_UNIFORM || s->start)
    return CVAR_OK;
  cv_meshspec keep = s->mesh;
  int both = s->disc.sing_a && s->disc.sing_b, at_a = s->disc.sing_a;
  double k = fmin(4.0, 2.0 + 0.5 * s->degree);
  int E = both ? (s->mesh.elements + 1) / 2 : s->mesh.elements; /* elements per side */
  if (E > 1) k = fmax(1.0, fmin(k, floor(100.0 * CV_GRADE_MIN_DIGITS / log10(E)) / 100.0));
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
static __attribute__((noinline, cold)) cv_status retry_straight_line(cv_solver *s,
                                                                     const cv_problem *p,
                                                                     cv_status first) {
  cv_status st = first;
  double *Y1 = cv_malloc((size_t)s->disc.ndof * sizeof *Y1);
  if (Y1 && !cv_start_values(s, p, &s->disc, Y1, 1)) {
    char keep[sizeof s->msg];
    int it = s->iterations, morse = s->morse, deg = s->degenerate;
    double act = s->action, gn = s->gnorm, gf = s->gfloor, *Yfail = s->y;
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
      s->action = act, s->gnorm = gn, s->gfloor = gf;
      memcpy(s->msg, keep, sizeof keep);
    }
  } else {
    cv_free(Y1);
  }
  return st;
}

/* Continuation from the start, computed again (theory HC-2). */
static __attribute__((noinline, cold)) cv_status continue_from_start(cv_solver *s,
                                                                     const cv_problem *p,
                                                                     cv_status first) {
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

/* One level of the smoothing homotopy: Newton from Yc on the integrand smoothed over w.
 * On success Yc holds the solution and *A its action. */
static cv_status smooth_level(cv_solver *s, const cv_problem *p, double w, double *Yc, double *Yt,
                              double *A) {
  size_t nd = (size_t)s->disc.ndof * sizeof *Yt;
  p->smooth(p->smooth_user, w);
  memcpy(Yt, Yc, nd);
  cv_status st = cv_newton_run(s, p, &s->disc, Yt, s->mult, NULL);
  if (st == CVAR_OK) {
    memcpy(Yc, Yt, nd);
    *A = s->action;
  }
  return st;
}

/* The first width of HC-4: half the largest spread of the values Y (1 if they are flat). */
static double first_width(const cv_solver *s, const double *Y) {
  double range = 0.0;
  for (int k = 0; k < s->n; k++) {
    double lo = INFINITY, hi = -INFINITY;
    for (int j = k; j < s->disc.ndof; j += s->n) lo = fmin(lo, Y[j]), hi = fmax(hi, Y[j]);
    range = fmax(range, hi - lo);
  }
  return range > 0 ? 0.5 * range : 1.0;
}

/* HC-4: does the converged path s->y cross a jump? The blend of X-6 is exact outside its
 * band, so the action with the jumps smoothed over w equals the sharp one bit for bit
 * unless some quadrature point lies in a band; where the path crosses a jump of size J
 * the change is ~ J w (first order), where it crosses a kink of a continuous `if` only
 * ~ w^2. So: a jump when the change at w is less than 3 times the change at w/2 (2 for a
 * jump, 4 for a kink). */
static __attribute__((noinline, cold)) int near_jump(cv_solver *s, const cv_problem *p, double w) {
  cv_assembler as;
  double S[3] = {NAN, NAN, NAN}, width[3] = {0.0, w, 0.5 * w};
  int ok = 1;
  if (cv_assembler_init(&as, p, &s->disc)) return 0;
  for (int k = 0; k < 3 && ok; k++) {
    p->smooth(p->smooth_user, width[k]);
    ok = cv_assemble(&as, p->F, p->user, s->y, &S[k], NULL, NULL, NULL, 0.0, 0) == CVAR_OK;
  }
  p->smooth(p->smooth_user, 0.0);
  cv_assembler_free(&as);
  double d1 = fabs(S[1] - S[0]), d2 = fabs(S[2] - S[0]);
  return ok && d1 > 0 && d1 < 3.0 * d2;
}

/* (HC-4) Jumps of the integrand in y: the discrete action jumps when a quadrature point
 * crosses one and its gradient never sees the interface (F_y is 0 on both sides), so Newton
 * cannot find the minimiser. Smooth the jumps over a width w, solve from the start,
 * and halve w with warm starts while the mesh resolves the band: there the action moves
 * like A(w) = A(0) + C w + O(w^2), each halving by half the change of the one before.
 * The last level whose change kept that ratio (within [0.3, 0.7]) is the answer; its
 * action differs from the sharp problem's by about its last change (first order in w). */
static __attribute__((noinline, cold)) cv_status smooth_homotopy(cv_solver *s, const cv_problem *p,
                                                                 cv_status first) {
  char firstmsg[sizeof s->msg];
  memcpy(firstmsg, s->msg, sizeof firstmsg);
  int nd = s->disc.ndof, levels = 0, total = s->iterations, ok = 0;
  double *Yc = cv_malloc((size_t)nd * sizeof *Yc), *Yt = cv_malloc((size_t)nd * sizeof *Yt);
  double *Yok = cv_malloc((size_t)nd * sizeof *Yok);
  cv_status st = Yc && Yt && Yok ? cv_start_values(s, p, &s->disc, Yc, 0) : CVAR_ENOMEM;
  double w, wok = 0.0, A = NAN, Aprev = NAN, dprev = NAN, dok = NAN;
  int morse0 = -1;
  if (st) goto cleanup;
  w = first_width(s, Yc);
  for (levels = 0; levels < 48; levels++, w *= 0.5) {
    st = smooth_level(s, p, w, Yc, Yt, &A);
    total += s->iterations;
    if (st == CVAR_ECALLBACK || st == CVAR_ENOMEM || st == CVAR_EINVAL || st == CVAR_ECANCELLED)
      goto cleanup;
    if (st != CVAR_OK) break;
    if (levels == 0) morse0 = s->morse;
    if (s->morse != morse0) break; /* an unresolved band makes spurious negative curvature */
    double dA = Aprev - A;         /* the change of this halving */
    if (levels >= 2) {
      double r = dA / dprev;
      if (!(r >= 0.3 && r <= 0.7)) break; /* the band is no longer resolved */
    }
    if (levels >= 1) {
      wok = w, dok = dA, ok = levels >= 2;
      memcpy(Yok, Yc, (size_t)nd * sizeof *Yok);
    }
    dprev = dA;
    Aprev = A;
  }
  if (!ok) {
    st = first == CVAR_OK ? CVAR_ESTALL : first;
    cv_set_msg(s->msg, sizeof s->msg,
               "%s; the integrand jumps in y (%d if%s on the unknowns), and smoothing the "
               "jumps did not help: %s after %d halvings of the width",
               firstmsg, p->nsmooth, p->nsmooth > 1 ? "s" : "",
               levels == 0 ? "the widest smoothing was not solved"
                           : "the action did not change in proportion to the width",
               levels);
    p->smooth(p->smooth_user, 0.0);
    goto cleanup;
  }
  /* one step of a factor sqrt(2) further (halving is coarse: the band is resolved down
   * to about half an element), kept when its Morse index and its change agree */
  double slope = dok / wok; /* C of A(w) = A(0) + C w */
  memcpy(Yc, Yok, (size_t)nd * sizeof *Yc);
  w = wok * 0.70710678118654752;
  st = smooth_level(s, p, w, Yc, Yt, &A);
  total += s->iterations;
  if (st == CVAR_OK && s->morse == morse0) {
    double r = (Aprev - A) / (slope * (wok - w)); /* Aprev is A(wok) */
    if (r >= 0.6 && r <= 1.4) wok = w, memcpy(Yok, Yc, (size_t)nd * sizeof *Yok);
  }
  /* the accepted level once more, for its own action, Morse index and message */
  p->smooth(p->smooth_user, wok);
  memcpy(s->y, Yok, (size_t)nd * sizeof *Yok);
  st = cv_newton_run(s, p, &s->disc, s->y, s->mult, NULL);
  total += s->iterations;
  if (st == CVAR_OK) {
    size_t ln = strlen(s->note);
    s->smooth_w = wok;
    cv_set_msg(s->note + ln, sizeof s->note - ln,
               "the integrand jumps in y and %s%s%s, so the jumps were smoothed over a "
               "width w down to %.3g, the finest the mesh resolves (theory HC-4): the answer "
               "is the smoothed problem's, its action ~%.2g from the sharp one's (extrapolated "
               "to w = 0: %.10g); ",
               first == CVAR_OK ? "Newton's path crosses one without its interface force"
                                : "Newton failed on them (",
               first == CVAR_OK ? "" : cv_strerror(first), first == CVAR_OK ? "" : ")", wok,
               fabs(slope * wok), s->action - slope * wok);
  } else {
    p->smooth(p->smooth_user, 0.0);
  }
cleanup:
  s->iterations = total;
  cv_free(Yc);
  cv_free(Yt);
  cv_free(Yok);
  return st;
}

/* The sharp solve converged on a path that meets a jump: the homotopy from the start; if
 * it fails, the sharp answer is kept with a warning in the note. */
static __attribute__((noinline, cold)) cv_status resmooth_converged(cv_solver *s,
                                                                    const cv_problem *p) {
  size_t nd = (size_t)s->disc.ndof * sizeof *s->y;
  double *keep = cv_malloc(nd), act = s->action, gn = s->gnorm;
  int it = s->iterations, morse = s->morse, deg = s->degenerate;
  char msg[sizeof s->msg];
  if (!keep) return CVAR_ENOMEM;
  memcpy(keep, s->y, nd);
  memcpy(msg, s->msg, sizeof msg);
  cv_status st = smooth_homotopy(s, p, CVAR_OK);
  if (st != CVAR_OK && st != CVAR_ENOMEM && st != CVAR_ECANCELLED) {
    memcpy(s->y, keep, nd);
    memcpy(s->msg, msg, sizeof msg);
    s->action = act, s->gnorm = gn, s->iterations = it, s->morse = morse, s->degenerate = deg;
    p->smooth(p->smooth_user, 0.0);
    size_t ln = strlen(s->note);
    cv_set_msg(s->note + ln, sizeof s->note - ln,
               "warning: the path crosses a jump of the integrand in y, where Newton's "
               "equations miss the interface force, and smoothing the jumps failed: this "
               "path may not be the minimiser (theory HC-4); ");
    st = CVAR_OK;
  }
  cv_free(keep);
  return st;
}

/* Prefix the solver's own decisions (s->note) to the message. */
static __attribute__((noinline)) void prefix_note(cv_solver *s) {
  char m[sizeof s->msg];
  size_t ln = strlen(s->note), lm = strlen(s->msg);
  if (ln + lm >= sizeof m) lm = sizeof m - 1 - ln;
  memcpy(m, s->note, ln);
  memcpy(m + ln, s->msg, lm);
  m[ln + lm] = '\0';
  memcpy(s->msg, m, sizeof m);
}

/* One solve on the mesh of s->mesh, with the singular ends known so far. */
CV_HOT static cv_status solve_once(cv_solver *s, const cv_problem *p) {
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
  lost = st == CVAR_ESTALL || st == CVAR_EDIVERGED || st == CVAR_ENONFINITE ||
         st == CVAR_ESINGULAR || (st == CVAR_EMAXITER && s->maxit >= 20);
  if (lost && p->smooth && unconstrained && s->continuation) st = smooth_homotopy(s, p, st);
  /* converged on the sharp jumps: a stationary point of the frozen problem (the wrong
   * law at an interface) when the path crosses one; smoothed again from the start, and
   * kept when that fails, with a sentence */
  else if (st == CVAR_OK && p->smooth && unconstrained && s->continuation &&
           near_jump(s, p, 0.25 * first_width(s, s->y)))
    st = resmooth_converged(s, p);
done:
  return st;
}

/* The graded retry (HC-3) changes the discretisation, and on it a problem without a
 * solution can have a discrete one (a conjugate point at the end: a huge multiple of the
 * nearly null direction). Its answer is kept only if the same retry on twice the elements
 * gives an action within 1e-2 of it (a real solution converges: the Poincare geodesic at
 * degree 1 moves by 2e-4; the artefact scales with the inverse of an O(h^2p) eigenvalue).
 * When that solve from the guess fails, s's elements halved are solved from s's own path
 * (HC-3a): a failed search is no refutation. Returns 1 (agrees), 0 (another action: *dev),
 * or -1 (no path on twice the elements: not confirmed, and not refuted either). */
static int halved_from_path(const cv_solver *s, const cv_problem *p, cv_solver *t, double *dev);
static int twice_agrees(const cv_solver *s, const cv_problem *p, double *dev) {
  cv_solver *t = cv_solver_new(NULL);
  int ok = -1;
  *dev = INFINITY;
  if (!t) return -1;
  t->degree = s->degree, t->nq = s->nq, t->maxit = s->maxit;
  t->rtol = s->rtol, t->atol = s->atol, t->continuation = s->continuation;
  t->mesh.elements = 2 * s->mesh.elements;
  if (t->mesh.elements > 0 &&
      cv_solver_set_breakpoints(t, s->mesh.nbreak, s->mesh.breaks) == CVAR_OK) {
    t->near_sing[0] = t->near_sing[1] = 1;
    if (solve_once(t, p) == CVAR_OK) {
      *dev = fabs(t->action - s->action) / fmax(fabs(s->action), DBL_MIN);
      ok = *dev <= 1e-2;
    } else {
      ok = halved_from_path(s, p, t, dev);
    }
  }
  cv_solver_free(t);
  return ok;
}

/* HC-3a: s's elements halved, both ends integrated as singular, Newton from s's path. */
static int halved_from_path(const cv_solver *s, const cv_problem *p, cv_solver *t, double *dev) {
  const cv_disc *d = &s->disc;
  int E2 = 2 * d->E, ok = -1;
  double *tt = cv_malloc((size_t)(E2 + 1) * sizeof *tt), a = d->xe[0], L = d->xe[d->E] - a;
  if (!tt) return -1;
  for (long e = 0; e < d->E; e++) {
    tt[2 * e] = (d->xe[e] - a) / L;
    tt[2 * e + 1] = (0.5 * (d->xe[e] + d->xe[e + 1]) - a) / L;
  }
  tt[0] = 0.0, tt[E2] = 1.0;
  if (cv_solver_set_mesh(t, E2, tt) == CVAR_OK && cv_solver_set_degree(t, d->p) == CVAR_OK &&
      cv_warm_start(t, p, s) == CVAR_OK) {
    t->near_sing[0] = t->near_sing[1] = 1;
    if (solve_once(t, p) == CVAR_OK) {
      *dev = fabs(t->action - s->action) / fmax(fabs(s->action), DBL_MIN);
      ok = *dev <= 1e-2;
    }
  }
  cv_free(tt);
  return ok;
}

/* The graded retry (HC-3) after Newton and continuation both failed on a uniform mesh;
 * out of line, with its message buffers, so that the frames of a plain solve stay small
 * (the first solve in a process pays a page fault per fresh stack page). */
static __attribute__((noinline, cold)) cv_status graded_retry(cv_solver *s, const cv_problem *p,
                                                              cv_status st) {
  char first[sizeof s->msg];
  memcpy(first, s->msg, sizeof first);
  s->near_sing[0] = s->near_sing[1] = 1;
  cv_status st2 = solve_once(s, p);
  s->near_sing[0] = s->near_sing[1] = 0;
  double dev = 0.0;
  int agrees = st2 == CVAR_OK ? twice_agrees(s, p, &dev) : 1;
  if (agrees == 0) {
    st2 = CVAR_ESTALL;
    cv_set_msg(s->msg, sizeof s->msg,
               "a stationary path of this mesh was found, but twice the elements moved its "
               "action by %.1e of itself: it is an artefact of the mesh, not a solution",
               dev);
  } else if (agrees < 0) { /* HC-3a: a confirmation that failed refutes nothing */
    st2 = CVAR_ESTALL;
    cv_set_msg(s->msg, sizeof s->msg,
               "a stationary path of this mesh was found (action %.15g), but its confirmation "
               "failed: on twice the elements Newton found no path, neither from the guess "
               "nor from this one, so it is neither confirmed nor refuted; solve on a finer "
               "or graded mesh (or with --tol) to settle it",
               s->action);
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
  return st;
}

/* A converged solve whose end element under-integrates: once more with that end
 * integrated as singular. Out of line, like graded_retry. */
static __attribute__((noinline, cold)) cv_status resolve_singular_ends(cv_solver *s,
                                                                       const cv_problem *p,
                                                                       const int un[2],
                                                                       const double rel[2]) {
  cv_status st;
  s->near_sing[0] = un[0], s->near_sing[1] = un[1];
  st = solve_once(s, p);
  char first[sizeof s->note];
  memcpy(first, s->note, sizeof first);
  /* Q-3a: the integrand itself, or only the path, varies below the end element */
  int integrand = un[0] == CV_END_INTEGRAND || un[1] == CV_END_INTEGRAND;
  cv_set_msg(s->note, sizeof s->note,
             "%s %s (the singular-end rule changed the action by %.1e of itself there), so "
             "%s integrated as singular; %s",
             integrand ? "the integrand is nearly singular at"
                       : "the path bends on a scale below the end element at",
             un[0] && un[1] ? "both ends"
             : un[0]        ? "the start"
                            : "the end",
             fmax(rel[0], rel[1]), un[0] && un[1] ? "they are" : "it is", first);
  s->near_sing[0] = s->near_sing[1] = 0;
  return st;
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
      !s->disc.sing_a && !s->disc.sing_b && s->maxit >= 20)
    st = graded_retry(s, p, st);
  for (int end = 0; end < 2 && st == CVAR_OK; end++)
    if (!s->ends_passed[end]) /* HP-2a: passed on a coarser end element */
      un[end] = cv_start_end_unresolved(p, &s->disc, s->y, end, s->action, &rel[end]);
  if (un[0] || un[1])
    st = resolve_singular_ends(s, p, un, rel);
  else if (st == CVAR_OK)
    s->ends_ok[0] = !s->disc.sing_a, s->ends_ok[1] = !s->disc.sing_b;
  if (st == CVAR_OK && s->morse > 0) caution_tiny_end_elements(s);
  if (s->note[0]) prefix_note(s);
  s->status = st;
  return st;
}

cv_status cv_solve_interval(cv_solver *s, const cv_problem *p) {
  return s->adapt_tol > 0 && p ? cv_adapt_run(s, p) : cv_solve_mesh(s, p);
}

/* The integrand's own explanation of a failure before the engine's (out of line). */
static __attribute__((noinline, cold)) void prefix_failure_note(cv_solver *s, const char *note) {
  char m[2 * sizeof s->msg];
  snprintf(m, sizeof m, "%s%s%s", note, s->msg[0] ? "; " : "", s->msg);
  memcpy(s->msg, m, sizeof s->msg - 1); /* truncated to the message buffer */
  s->msg[sizeof s->msg - 1] = '\0';
}

CV_HOT cv_status cv_solve(cv_solver *s, const cv_problem *p) { return cv_solve_at(s, p, 0.0); }

cv_status cv_solve_at(cv_solver *s, const cv_problem *p, double shift) {
  if (!s) return CVAR_EINVAL;
  double t0 = cv_now();
  cv_pathset_free(s->paths); /* a plain solve forgets the paths of cv_solve_all */
  s->paths = NULL;
  s->err_est = NAN;
  s->rounds = 0;
  for (int k = 0; p && k < p->nnotes; k++) p->notes[k].fn(p->notes[k].user, 1);
  if (p && p->smooth) p->smooth(p->smooth_user, 0.0); /* the integrand as written (HC-4) */
  cv_ends_state_free(s); /* the moving ends of the last solve (cv_ends.c) */
  cv_status st = cv_ends_moving(p) ? cv_ends_run(s, p, shift) : cv_solve_interval(s, p);
  s->status = st;
  /* A failure the integrand can explain (a table's grid left): the cause first, then what
   * the engine saw. */
  const char *note = NULL;
  for (int k = 0; st != CVAR_OK && p && k < p->nnotes && !(note && note[0]); k++)
    note = p->notes[k].fn(p->notes[k].user, 0);
  if (note && note[0]) prefix_failure_note(s, note);
  s->time = cv_now() - t0;
  return st;
}
