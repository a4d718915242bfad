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
  if (cli_estimate_error(sv, p, &ea, &ev, why, sizeof why) < 0) return -1;
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
