/* src/cli/progress.c — what the command says while it works (--verbose, terminals).
 * SPDX-License-Identifier: MIT
 *
 * With --verbose, one line on stderr per Newton iteration (residual, step, line-search
 * factor) and per adaptive round (elements, estimate). Without it, when stderr is a
 * terminal, a solve that has run for more than a second shows one status line, rewritten
 * in place at most five times a second and erased at the end. Otherwise nothing: pipes
 * and logs stay clean. One state per process: the command runs one solve at a time.
 */
#include <stdio.h>
#include <time.h>
#include <unistd.h>

#include "cli/cli.h"

static struct {
  int verbose, tty, shown;
  double t0, last;
} pg;

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_progress_setup(int verbose) {
  pg.verbose = verbose;
  pg.tty = !verbose && isatty(STDERR_FILENO);
  pg.shown = 0;
  pg.t0 = now();
  pg.last = 0;
}

static int report(const cv_progress *info, void *user) {
  (void)user;
  if (pg.verbose) {
    if (info->kind == CVAR_PROGRESS_ROUND)
      fprintf(stderr, "round %d: %d elements, estimated max nodal error %.3g\n", info->round,
              info->elements, info->estimate);
    else
      fprintf(stderr,
              "  iteration %d: residual %.3e, step %.3e, line search %g, action "
              "%.15g\n",
              info->iteration, info->residual, info->step, info->alpha, info->action);
    return 0;
  }
  double t = now();
  if (t - pg.t0 < 1.0 || t - pg.last < 0.2) return 0;
  pg.last = t;
  pg.shown = 1;
  if (info->kind == CVAR_PROGRESS_ROUND)
    fprintf(stderr, "\r\033[Kcalcvar: %.1f s, adaptive round %d, %d elements, estimate %.2g",
            t - pg.t0, info->round, info->elements, info->estimate);
  else
    fprintf(stderr, "\r\033[Kcalcvar: %.1f s, %d elements, iteration %d, residual %.2e", t - pg.t0,
            info->elements, info->iteration, info->residual);
  fflush(stderr);
  return 0;
}

void cli_progress_attach(cv_solver *sv) {
  if (sv && (pg.verbose || pg.tty)) cv_solver_set_progress(sv, report, NULL);
}

void cli_progress_end(void) {
  if (pg.shown) fputs("\r\033[K", stderr);
  pg.shown = 0;
}
