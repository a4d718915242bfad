/* src/scene/scene_estimate.c — the error estimate of a report without [exact]: the core's one
 * estimator (cv_solver_estimate_error, theory HP-2 and HP-3), and what to say when it gives
 * no bound. docs/cli.md and docs/performance.md give its measured accuracy.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "scene/scene_report.h"

int cli_estimate_error(const cv_solver *sv, const cv_problem *p, double *e_all, double *e_vertex,
                       char *why, size_t len) {
  cv_status st = cv_solver_estimate_error(sv, p, e_all, e_vertex, why, len);
  if (st == CVAR_ENOMEM) return -1;
  if (st != CVAR_OK || !isfinite(*e_all)) {
    *e_all = *e_vertex = NAN;
    if (st == CVAR_OK) snprintf(why, len, "the error estimate is not finite");
  }
  return 0;
}

int cli_report_estimate(cli_report *r, const cv_solver *sv, const cv_problem *p) {
  double ea, ev;
  char why[640] = "";
  if (r->nodes <= 0 || r->st != CVAR_OK) return 0;
  cv_status st = cv_solver_estimate_error(sv, p, &ea, &ev, why, sizeof why);
  if (st == CVAR_ENOMEM) return -1;
  if (st != CVAR_OK) ea = NAN;
  if (st == CVAR_ESINGULAR && r->has_morse) {
    /* the enriched solve, closer to the integral, finds the Hessian singular: a family of
     * stationary paths (a resonance, a symmetry left unpinned), not an isolated minimum
     * or saddle, whatever the pivots of this mesh say (theory N-5) */
    r->kind = "degenerate";
    snprintf(r->message, sizeof r->message,
             "Converged in %d iterations on this mesh, but the Hessian is singular on the "
             "enriched mesh (%s): the path is one of a family of stationary paths (degenerate), "
             "not an isolated %s.",
             r->iterations, why, r->morse == 0 ? "minimum" : "saddle");
    return 0;
  }
  if (isfinite(ea)) {
    r->has_err_est = 1;
    r->err_est = ea;
  } else if (why[0]) { /* HP-3: say why there is no estimate rather than give a false one */
    size_t used = strlen(r->message);
    snprintf(r->message + used, sizeof r->message - used, "%sno error estimate: %s.",
             used ? " " : "", why);
  }
  return 0;
}
