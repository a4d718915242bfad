/* src/core/cv_continuation.c — continuation from the starting path to the problem when Newton
 * alone fails, theory (HC-1), (HC-2).
 * SPDX-License-Identifier: MIT */
#include <limits.h>
#include <math.h>
#include <string.h>

#include "cv_internal.h"

#define MIN_STEP        1e-6
#define STEP_ITERATIONS 15
#define MAX_STEPS       400

/* Weight w of the homotopy term: the mean diagonal of the Hessian at Y0 per unit lumped
 * weight, so that both terms of H_t have the same size (HC-1). */
static cv_status homotopy_weight(const cv_problem *p, const cv_disc *d, const double *Y0,
                                 double *w) {
  cv_kkt kkt;
  /* unconstrained, so the pattern is the band: far below INT_MAX entries whenever the
   * Newton solve before this one could be set up */
  int *cp = cv_malloc((size_t)(d->nfree + 1) * sizeof *cp);
  double *g = cv_malloc((size_t)(d->nfree ? d->nfree : 1) * sizeof *g), *Ax = NULL, S;
  double M0 = 0.0;
  cv_status st = (cp && g) ? CVAR_OK : CVAR_ENOMEM;
  memset(&kkt, 0, sizeof kkt);
  if (!st && cv_disc_pattern(d, NULL, NULL) > INT_MAX) st = CVAR_EINVAL;
  if (!st) {
    cv_disc_pattern(d, cp, NULL);
    Ax = cv_malloc((size_t)(cp[d->nfree] ? cp[d->nfree] : 1) * sizeof *Ax);
    st = Ax ? cv_kkt_init(&kkt, p, d, cp) : CVAR_ENOMEM;
  }
  if (!st) st = cv_kkt_eval(&kkt, Y0, &M0, &S, g, Ax, NULL);
  if (!st) {
    double hs = 0.0, ms = 0.0;
    for (int f = 0; f < d->nfree; f++) {
      hs += fabs(Ax[cp[f + 1] - 1]);
      ms += d->mass[f];
    }
    *w = ms > 0 && hs > 0 ? hs / ms : 1.0;
  }
  cv_kkt_free(&kkt);
  cv_free(cp);
  cv_free(g);
  cv_free(Ax);
  return st;
}

/* (HC-2) Follow G_t = 0 from t = 0 (solution Y0) to t = 1 with Newton as the corrector,
 * starting each step from the last solution; the step in t doubles after an easy step and
 * shrinks fourfold after a failed one. Failure to advance below MIN_STEP means the path
 * turns back or ends: the problem may have no stationary path near the start. */
cv_status cv_continuation_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y, double *M,
                              const double *Y0) {
  double w, t = 0.0, dt = 0.1;
  int steps = 0, total = s->iterations, maxit = s->maxit;
  size_t nd = (size_t)d->ndof * sizeof *Y;
  double *Yc = cv_malloc(nd), *Yt = cv_malloc(nd);
  cv_status st = (Yc && Yt) ? homotopy_weight(p, d, Y0, &w) : CVAR_ENOMEM;
  if (st) {
    cv_set_msg(s->msg, sizeof s->msg,
               "Newton did not converge and continuation could not "
               "start (%s)",
               cv_strerror(st));
    goto cleanup;
  }
  memcpy(Yc, Y0, nd);
  s->maxit = maxit < STEP_ITERATIONS ? maxit : STEP_ITERATIONS;
  while (t < 1.0) {
    double tn = t + dt > 1.0 ? 1.0 : t + dt;
    cv_homotopy h = {tn, w, Y0};
    memcpy(Yt, Yc, nd);
    st = cv_newton_run(s, p, d, Yt, M, &h);
    total += s->iterations;
    if (st == CVAR_ECALLBACK || st == CVAR_ENOMEM || st == CVAR_EINVAL || st == CVAR_ECANCELLED)
      goto cleanup;
    if (st == CVAR_OK) {
      memcpy(Yc, Yt, nd);
      t = tn;
      steps++;
      if (s->iterations <= 4) dt *= 2.0;
    } else {
      dt *= 0.25;
    }
    if (dt < MIN_STEP || steps >= MAX_STEPS) {
      st = CVAR_ESTALL;
      memcpy(Y, Yc, nd);
      cv_set_msg(s->msg, sizeof s->msg,
                 "no stationary path found: Newton from the start did not converge, and "
                 "continuation from the start stalled at t = %.6g of 1 after %d steps (the "
                 "path of solutions from the start turns back or ends there)",
                 t, steps);
      goto cleanup;
    }
  }
  /* t = 1 is the problem itself; one plain Newton pass for its own Morse index. */
  s->maxit = maxit;
  memcpy(Y, Yc, nd);
  st = cv_newton_run(s, p, d, Y, M, NULL);
  total += s->iterations;
  if (st == CVAR_OK)
    cv_set_msg(s->msg, sizeof s->msg,
               "converged by continuation from the start in %d steps (%d Newton iterations "
               "in all) after Newton alone did not converge",
               steps, total);
cleanup:
  s->maxit = maxit;
  s->iterations = total;
  s->csteps = steps;
  cv_free(Yc);
  cv_free(Yt);
  return st;
}
