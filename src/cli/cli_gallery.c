/* src/cli/cli_gallery.c — `calcvar` with no arguments: solve the scenes of examples/scenes
 * (embedded at build time, src/cli/embed_scenes.py) and print one row each (title, status,
 * action, error, Morse index, time).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli/cli.h"

/* Width of the title column: the longest title of examples/scenes fits. */
enum { TITLE_W = 60 };

/* One gallery row; returns 0 when the scene converged. */
static int run_one(const cli_gallery_scene *g) {
  char err[SC_ERRLEN], name[64];
  snprintf(name, sizeof name, "gallery:%s", g->name);
  scene *s = scene_load_buffer(g->text, strlen(g->text), name, 0, NULL, err, sizeof err);
  cv_problem *p = s ? scene_problem_new(s, scene_method_need(s->method), err, sizeof err) : NULL;
  cv_status why;
  cv_solver *sv = p ? cv_solver_new(&why) : NULL;
  int rc = 1;
  if (!sv || scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK) {
    printf("%-*s  %s\n", TITLE_W, s ? s->title : g->name, err[0] ? err : "out of memory");
    goto done;
  }
  cv_status st = cv_solve(sv, p);
  cli_report r;
  if (cli_report_collect(&r, s, p, sv, s->method, st) < 0) {
    printf("%-*s  out of memory\n", TITLE_W, s->title);
    cli_report_free(&r);
    goto done;
  }
  int any_exact = 0;
  for (int i = 0; i < s->n; i++) any_exact |= s->exact[i] >= 0;
  if (!any_exact && !r.has_err_action && cli_report_estimate(&r, sv, p) < 0) {
    printf("%-*s  out of memory\n", TITLE_W, s->title);
    cli_report_free(&r);
    goto done;
  }
  char act[32] = "-", errs[32] = "-", morse[8] = "-", tm[16] = "-";
  if (r.has_action) snprintf(act, sizeof act, "%.12f", r.action);
  if (r.has_err_nodal)
    snprintf(errs, sizeof errs, "%.1e nodal", r.err_nodal);
  else if (r.has_err_action)
    snprintf(errs, sizeof errs, "%.1e action", r.err_action);
  else if (r.has_err_est)
    snprintf(errs, sizeof errs, "~%.1e est.", r.err_est); /* an estimate, marked as such */
  if (r.has_morse) snprintf(morse, sizeof morse, "%d", r.morse);
  if (r.has_time) snprintf(tm, sizeof tm, "%.4f", r.time_s);
  printf("%-*s %-14s %17s %16s %5s %9s\n", TITLE_W, s->title, r.status, act, errs, morse, tm);
  rc = st == CVAR_OK ? 0 : 1;
  cli_report_free(&r);
done:
  cv_solver_free(sv);
  cv_problem_free(p);
  scene_free(s);
  return rc;
}

int cli_gallery(void) {
  int failed = 0;
  printf("calcvar gallery: variational problems solved by direct discretisation\n"
         "(calcvar --help for the commands; calcvar solve SCENE for your own)\n\n");
  printf("%-*s %-14s %17s %16s %5s %9s\n", TITLE_W, "scene", "status", "action", "error", "Morse",
         "time [s]");
  for (int i = 0; i < cli_gallery_count; i++) failed += run_one(&cli_gallery_scenes[i]);
  if (failed) printf("\n%d scene%s did not converge.\n", failed, failed == 1 ? "" : "s");
  return failed ? EXIT_UNSOLVED : EXIT_SOLVED;
}
