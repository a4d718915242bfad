/* src/cli/cli_all.c — `calcvar solve SCENE --all [--max K]`: every stationary path the
 * deflated search finds (cv_solve_all, theory DF-1..DF-5), one full report per path.
 * SPDX-License-Identifier: MIT
 *
 * Each path gets the report a plain solve writes (cli_report_collect), with its own error
 * estimate: the reference solve of scene_estimate.c starts from that path (the problem's guess
 * is pointed at the selected path), so it polishes the same path on the finer mesh rather
 * than whichever path the scene's guess leads to. Two paths whose nodal values differ by
 * at most the larger of their error estimates are one path (SCENES.md): the one of higher
 * action is dropped. Outputs: JSON {"solutions": [...], "search": {...}}, CSV with a first
 * column `solution`, a summary line per path, and one figure with every path.
 */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

enum { NPLOT = 801 };

/* The guess of the estimate's reference solve: the selected path, by interpolation. */
typedef struct {
  const cv_solver *sv;
  double a, b;
} path_guess;

static int guess_from_path(int m, const double *x, double *y, void *user) {
  const path_guess *g = user;
  double xc[256];
  for (int k = 0; k < m; k++) xc[k] = fmin(g->b, fmax(g->a, x[k]));
  return cv_solver_eval(g->sv, m, xc, y, NULL) == CVAR_OK ? 0 : 1;
}

/* Max difference of two paths at the nodes of the first (the second interpolated). */
static double path_distance(const cli_report *r1, cv_solver *sv, int k2, int n) {
  double *y = malloc((size_t)r1->nodes * n * sizeof *y), d = INFINITY;
  if (!y || cv_solver_select_solution(sv, k2) != CVAR_OK ||
      cv_solver_eval(sv, r1->nodes, r1->x, y, NULL) != CVAR_OK) {
    free(y);
    return d;
  }
  d = 0.0;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < r1->nodes; j++)
      d = fmax(d, fabs(r1->y[(size_t)j * n + i] - y[(size_t)i * r1->nodes + j]));
  free(y);
  return d;
}

static json_t *search_json(const cv_search_info *in, int listed) {
  json_t *o = json_object();
  if (!o) return NULL;
  json_object_set_new(o, "starts", json_integer(in->starts));
  json_object_set_new(o, "failed", json_integer(in->failed));
  json_object_set_new(o, "duplicates", json_integer(in->duplicates + (in->found - listed)));
  json_object_set_new(o, "found", json_integer(listed));
  json_object_set_new(o, "stopped", json_string(in->stop));
  return o;
}

static int write_json(FILE *f, cli_report *r, const int *keep, int np, const cv_search_info *in,
                      int listed) {
  json_t *o = json_object(), *a = json_array();
  if (!o || !a) {
    json_decref(o);
    json_decref(a);
    return -1;
  }
  for (int k = 0; k < np; k++)
    if (keep[k]) json_array_append_new(a, cli_report_json_object(&r[k]));
  json_object_set_new(o, "solutions", a);
  json_object_set_new(o, "search", search_json(in, listed));
  int rc = json_dumpf(o, f, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  if (rc == 0 && fputc('\n', f) == EOF) rc = -1;
  json_decref(o);
  return rc;
}

/* One table: the plain solve's CSV of each path with `solution` (1, 2, ...) in front. */
static int write_csv(FILE *f, cli_report *r, const int *keep, int np, const scene *s) {
  int num = 0, header = 0;
  for (int k = 0; k < np || !header; k++) {
    char *buf = NULL;
    size_t len = 0;
    FILE *m = open_memstream(&buf, &len);
    if (!m) return -1;
    int bad = 0;
    if (k < np && keep[k]) {
      bad = cli_report_csv(m, &r[k]) < 0;
    } else if (k >= np) { /* no path: the header alone */
      cli_report empty;
      memset(&empty, 0, sizeof empty);
      empty.sc = s;
      bad = cli_report_csv(m, &empty) < 0;
    }
    if (fclose(m) != 0 || bad) {
      free(buf);
      return -1;
    }
    if (len == 0) {
      free(buf);
      continue;
    }
    num++;
    char *line = buf, *nl;
    int first = 1;
    while (*line && (nl = strchr(line, '\n'))) {
      *nl = '\0';
      if (first) {
        if (!header) fprintf(f, "solution,%s\n", line);
        header = 1;
        first = 0;
      } else {
        fprintf(f, "%d,%s\n", num, line);
      }
      line = nl + 1;
    }
    free(buf);
    if (k >= np) break;
  }
  return ferror(f) ? -1 : 0;
}

static int write_plot(cli_outfile *o, cli_report *r, const int *keep, int np, cv_solver *sv,
                      const scene *s) {
  int n = s->n, nl = 0, rc = -1;
  double *xs = malloc(NPLOT * sizeof *xs);
  double *ys = malloc((size_t)NPLOT * n * (np ? np : 1) * sizeof *ys);
  cli_plot_line *lines = calloc((size_t)n * (np ? np : 1), sizeof *lines);
  char(*labels)[128] = calloc((size_t)n * (np ? np : 1), sizeof *labels);
  if (!xs || !ys || !lines || !labels) goto done;
  for (int k = 0; k < NPLOT; k++) xs[k] = s->a + (s->b - s->a) * k / (NPLOT - 1);
  xs[NPLOT - 1] = s->b;
  for (int k = 0, num = 0; k < np; k++) {
    if (!keep[k]) continue;
    num++;
    double *yk = ys + (size_t)k * NPLOT * n;
    if (cv_solver_select_solution(sv, k) != CVAR_OK || cv_solver_eval(sv, NPLOT, xs, yk, NULL))
      goto done;
    for (int i = 0; i < n; i++) {
      cli_plot_line *ln = &lines[nl];
      ln->n = NPLOT;
      ln->x = xs;
      ln->y = yk + (size_t)i * NPLOT;
      ln->colour = num - 1;
      ln->style = i > 0 ? 1 + i % 7 : 0; /* PLplot styles 0 and 1 are both solid */
      if (n > 1)
        snprintf(labels[nl], sizeof labels[nl], "%d %s: %s", num, s->unknowns[i],
                 r[k].kind ? r[k].kind : "?");
      else
        snprintf(labels[nl], sizeof labels[nl], "%d: %s", num, r[k].kind ? r[k].kind : "?");
      ln->label = labels[nl++];
    }
  }
  char yl[96];
  snprintf(yl, sizeof yl, n == 1 ? "%s(%s)" : "unknowns", s->unknowns[0], s->variable);
  cli_plot_panel pan;
  memset(&pan, 0, sizeof pan);
  pan.title = s->title;
  pan.xlabel = s->variable;
  pan.ylabel = yl;
  pan.nlines = nl;
  pan.lines = lines;
  rc = cli_plot_write(o, 1, &pan);
done:
  free(xs);
  free(ys);
  free(lines);
  free(labels);
  return rc;
}

int cli_all_run(const cli_opts *o, scene *s, cv_problem *p, cv_solver *sv, int adaptive,
                cli_outfile *jf, cli_outfile *cf, cli_outfile *pf) {
  int max = o->max_paths > 0 ? o->max_paths : 8, rc = EXIT_UNSOLVED;
  if (o->work > 0 && cv_solver_set_search_work(sv, o->work) != CVAR_OK) {
    fprintf(stderr, "calcvar solve: invalid --work %g\n", o->work);
    return EXIT_BADINPUT;
  }
  cv_status st = cv_solve_all(sv, p, max);
  if (st == CVAR_EINVAL) {
    fprintf(stderr, "%s: %s\n", s->file, cv_solver_last_error(sv));
    return EXIT_BADINPUT;
  }
  cv_search_info in;
  memset(&in, 0, sizeof in);
  cv_solver_get_search(sv, &in);
  int np = cv_solver_get_num_solutions(sv), listed = 0;
  cli_report *r = calloc((size_t)(np ? np : 1), sizeof *r);
  int *keep = calloc((size_t)(np ? np : 1), sizeof *keep);
  path_guess pg = {sv, s->a, s->b};
  if (!r || !keep) goto oom;
  /* every later solve on p (the estimates' reference solves) starts from the selected path */
  if (np > 0 && cv_problem_set_guess(p, guess_from_path, &pg) != CVAR_OK) goto oom;
  for (int k = 0; k < np; k++) {
    if (cv_solver_select_solution(sv, k) != CVAR_OK ||
        cli_report_build(&r[k], s, p, sv, CVAR_OK, adaptive) < 0)
      goto oom;
    keep[k] = 1;
  }
  /* distinct only beyond the error estimate of either (paths are in increasing action) */
  for (int k = 0; k < np; k++)
    for (int l = 0; l < k && keep[k]; l++) {
      if (!keep[l]) continue;
      double e = fmax(r[k].has_err_est ? r[k].err_est : 0.0, r[l].has_err_est ? r[l].err_est : 0.0);
      if (path_distance(&r[k], sv, l, s->n) <= e) keep[k] = 0;
    }
  for (int k = 0; k < np; k++) listed += keep[k];
  rc = listed > 0 ? EXIT_SOLVED : EXIT_UNSOLVED;
  if (jf->f && cli_outfile_finish(jf, write_json(jf->f, r, keep, np, &in, listed)) < 0) {
    fprintf(stderr, "calcvar solve: the JSON report could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (pf->f && write_plot(pf, r, keep, np, sv, s) < 0) {
    fprintf(stderr, "calcvar solve: the plot could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (cf->f && cli_outfile_finish(cf, write_csv(cf->f, r, keep, np, s)) < 0) {
    fprintf(stderr, "calcvar solve: the CSV table could not be written\n");
    rc = EXIT_IOERROR;
  }
  int stdout_taken = (o->json && strcmp(o->json, "-") == 0) || (o->csv && strcmp(o->csv, "-") == 0);
  if (!o->quiet && !stdout_taken) {
    printf("%s\n", s->title);
    printf("  search      %d stationary path%s from %d start%s (%d failed, %d duplicate%s); "
           "%s\n",
           listed, listed == 1 ? "" : "s", in.starts, in.starts == 1 ? "" : "s", in.failed,
           in.duplicates + (in.found - listed), in.duplicates + (in.found - listed) == 1 ? "" : "s",
           in.stop);
    for (int k = 0, num = 0; k < np; k++)
      if (keep[k]) {
        printf("  path %-6d action %.15g, Morse index %d, %s", ++num, r[k].action, r[k].morse,
               r[k].kind ? r[k].kind : "unknown");
        if (r[k].has_err_nodal)
          printf(", error %.3g", r[k].err_nodal);
        else if (r[k].has_err_est)
          printf(", estimate %.3g", r[k].err_est);
        if (r[k].has_interval) /* a moving end: where this path's ends are */
          printf(", interval [%.12g, %.12g]", r[k].interval[0], r[k].interval[1]);
        printf("\n");
      }
  }
  if (listed == 0)
    fprintf(stderr,
            "calcvar solve: %s: --all found no converged stationary path (%d start%s "
            "tried): %s\n",
            s->file, in.starts, in.starts == 1 ? "" : "s", cv_solver_last_error(sv));
  goto done;
oom:
  fprintf(stderr, "calcvar solve: out of memory while reporting the paths\n");
  rc = EXIT_UNSOLVED;
done:
  for (int k = 0; r && k < np; k++) cli_report_free(&r[k]);
  free(r);
  free(keep);
  return rc;
}
