/* src/cli/cli_converge.c — `calcvar converge SCENE [options]`: error and run time over a
 * sequence of meshes, one sequence per degree (SCENES.md "calcvar converge").
 * SPDX-License-Identifier: MIT
 *
 * Its own options (--levels K, --degree P[,P...], --svg FILE) are taken out of argv here;
 * the rest are `solve`'s and go through cli_args_parse, so both commands check them the
 * same way. Order of work as in `solve`: flags, scene, output files (exit 2 before any
 * solving), then the solves, then the outputs are renamed into place.
 *
 * time_s of a row: solves under 20 ms are repeated (a fresh solver each time, up to 10
 * times) and the fastest kept, so the error-time curves are not timer noise.
 */
#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

enum { MAX_LEVELS = 24 };

typedef struct {
  int levels, ndeg, deg[8];
  const char *svg;
} conv_opts;

static void usage(FILE *f) {
  fputs("usage: calcvar converge SCENE [options]\n"
        "  --levels K           number of meshes, each with twice the elements (default 6)\n"
        "  --elements N         elements of the coarsest mesh (default: the scene's)\n"
        "  --degree P[,P...]    element degrees 1..8, one sequence each (--degree 1,2,4,8)\n"
        "  --svg FILE           error against run time, log-log, one line per degree\n"
        "  --json FILE          the rows as an array of reports ('-' for stdout)\n"
        "  --method M, --tolerance T, --max-iterations K, --set name=value   as for solve\n"
        "  --quiet              no table on stdout\n"
        "  -v, --verbose        one line per Newton iteration on stderr\n"
        "Errors are against [exact]; without it they are estimates from a finer mesh.\n"
        "exit status: 0 every mesh converged, 1 some did not, 2 bad input, 3 write error\n",
        f);
}

static int bad(const char *fmt, const char *v) {
  fprintf(stderr, "calcvar converge: ");
  fprintf(stderr, fmt, v);
  fputc('\n', stderr);
  return EXIT_BADINPUT;
}

static int parse_levels(const char *v, int *out) {
  char *end;
  errno = 0;
  long k = strtol(v, &end, 10);
  if (!(*v >= '0' && *v <= '9') || errno || *end || k < 1 || k > MAX_LEVELS) return -1;
  *out = (int)k;
  return 0;
}

/* "1,2,4,8": whole numbers 1..8, each once. */
static int parse_degrees(const char *v, conv_opts *c) {
  const char *q = v;
  c->ndeg = 0;
  for (;;) {
    char *end;
    if (!(*q >= '0' && *q <= '9')) return -1;
    errno = 0;
    long d = strtol(q, &end, 10);
    if (errno || d < 1 || d > 8 || (*end != ',' && *end != '\0')) return -1;
    for (int k = 0; k < c->ndeg; k++)
      if (c->deg[k] == d) return -1;
    c->deg[c->ndeg++] = (int)d;
    if (*end == '\0') return 0;
    q = end + 1;
  }
}

/* Take converge's own options out of argv (the rest is copied to rest[], *nrest). Values
 * of solve's options are skipped over, so "--set --svg=1" is not mistaken for --svg. */
static int split_args(int argc, char **argv, conv_opts *c, char **rest, int *nrest) {
  static const char *const valued[] = {"--elements", "--method", "--tolerance", "--max-iterations",
                                       "--set",      "--adapt",  "--tol",       "--continue",
                                       "--json",     "--csv",    "--plot",      "--max-elements",
                                       NULL};
  static const char *const mine[] = {"--levels", "--degree", "--svg"};
  c->levels = 6;
  *nrest = 0;
  for (int i = 0; i < argc; i++) {
    const char *a = argv[i], *v = NULL;
    int which = -1;
    for (int k = 0; k < 3; k++) {
      size_t l = strlen(mine[k]);
      if (strncmp(a, mine[k], l) == 0 && (a[l] == '\0' || a[l] == '=')) {
        which = k;
        v = a[l] == '=' ? a + l + 1 : NULL;
      }
    }
    if (which < 0) {
      rest[(*nrest)++] = argv[i];
      for (int k = 0; valued[k]; k++)
        if (strcmp(a, valued[k]) == 0 && i + 1 < argc) rest[(*nrest)++] = argv[++i];
      if (strcmp(a, "--") == 0)
        while (i + 1 < argc) rest[(*nrest)++] = argv[++i];
      continue;
    }
    if (!v) {
      if (i + 1 >= argc) return bad("%s needs a value", mine[which]);
      v = argv[++i];
    }
    if (which == 0 && parse_levels(v, &c->levels) < 0)
      return bad("--levels needs a whole number from 1 to 24, got '%s'", v);
    if (which == 1 && parse_degrees(v, c) < 0)
      return bad("--degree needs whole numbers from 1 to 8, comma separated, each once "
                 "(e.g. 1,2,4,8), got '%s'",
                 v);
    if (which == 2) {
      size_t l = strlen(v);
      if (l < 5 || strcmp(v + l - 4, ".svg") != 0)
        return bad("--svg needs a file name ending in .svg, got '%s'", v);
      c->svg = v;
    }
  }
  return 0;
}

/* Max |y_h - y_exact| over the element boundaries (nodes j with j % p == 0, p the nodes
 * per element: the degree, or (degree - 1)/2 for C1 elements), over the unknowns that
 * have an [exact] expression. */
static int vertex_error(const scene *s, const cli_report *r, double *e) {
  int n = s->n, p = (r->nodes - 1) / r->elements, nv = r->elements + 1;
  double *xv = malloc((size_t)nv * sizeof *xv), *ex = malloc((size_t)nv * n * sizeof *ex);
  int rc = -1;
  *e = NAN;
  if (!xv || !ex) goto done;
  for (int k = 0; k < nv; k++) xv[k] = r->x[(size_t)k * p];
  if (scene_eval_exact(s, nv, xv, ex) < 0) goto done;
  double m = 0;
  for (int i = 0; i < n; i++)
    if (s->exact[i] >= 0)
      for (int k = 0; k < nv; k++)
        m = fmax(m, fabs(r->y[(size_t)k * p * n + i] - ex[(size_t)i * nv + k]));
  *e = m;
  rc = 0;
done:
  free(xv);
  free(ex);
  return rc;
}

/* Solve the scene on one mesh (fastest of up to 10 fresh solves when a solve takes under
 * 20 ms) and fill the row. Returns 0, or -1 on allocation failure. */
static int solve_row(scene *s, const cv_problem *p, int any_exact, cli_conv_row *row) {
  cv_solver *best = NULL;
  double tbest = INFINITY, total = 0;
  cv_status st = CVAR_ENOMEM;
  char err[SC_ERRLEN];
  for (int rep = 0; rep < 10 && total < 0.02; rep++) {
    cv_status why;
    cv_solver *sv = cv_solver_new(&why);
    if (!sv) break;
    if (scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK) {
      cv_solver_free(sv);
      break;
    }
    cli_progress_attach(sv);
    cv_status sr = cv_solve(sv, p);
    cli_progress_end();
    double t = cv_solver_get_time(sv);
    total += isfinite(t) ? t : 1;
    if (!best || t < tbest) {
      cv_solver_free(best);
      best = sv;
      tbest = t;
      st = sr;
    } else {
      cv_solver_free(sv);
    }
    if (sr != CVAR_OK) break;
  }
  if (!best) return -1;
  int rc = cli_report_collect(&row->r, s, p, best, s->method, st);
  double ea = NAN, ev = NAN;
  char why[640] = "";
  row->no_est_at = -1;
  if (rc == 0 && !any_exact && row->r.nodes > 0 && st == CVAR_OK)
    rc = cli_estimate_error(best, p, &ea, &ev, why, sizeof why);
  cv_solver_free(best);
  if (rc < 0) return -1;
  const cli_report *r = &row->r;
  if (r->nodes <= 0 || st != CVAR_OK) return 0;
  if (any_exact) {
    double ev;
    if (vertex_error(s, r, &ev) < 0) return -1;
    row->has_err = r->has_err_nodal;
    row->err = r->err_nodal;
    row->has_err_v = isfinite(ev);
    row->err_v = ev;
  } else {
    row->estimated = 1;
    row->has_err = isfinite(ea);
    row->err = ea;
    row->has_err_v = isfinite(ev);
    row->err_v = ev;
    row->r.has_err_est = row->has_err;
    row->r.err_est = ea;
    if (!row->has_err && why[0]) { /* HP-3: say why, as solve does */
      size_t used = strlen(row->r.message);
      row->no_est_at = (int)(used + (used ? 1 : 0));
      snprintf(row->r.message + used, sizeof row->r.message - used, "%sno error estimate: %s.",
               used ? " " : "", why);
    }
  }
  return 0;
}

/* Observed order against the previous row of the same sequence: log(e0/e1) / log(E1/E0). */
static void orders(cli_conv_row *prev, cli_conv_row *row) {
  double ratio = (double)row->r.elements / prev->r.elements;
  if (!(ratio > 1)) return;
  if (prev->has_err && row->has_err && prev->err > 0 && row->err > 0) {
    row->has_order = 1;
    row->order = log(prev->err / row->err) / log(ratio);
  }
  if (prev->has_err_v && row->has_err_v && prev->err_v > 0 && row->err_v > 0) {
    row->has_order_v = 1;
    row->order_v = log(prev->err_v / row->err_v) / log(ratio);
  }
}

int cli_converge(int argc, char **argv) {
  conv_opts c;
  cli_opts o;
  char err[SC_ERRLEN];
  char **rest = malloc((size_t)(argc + 1) * sizeof *rest);
  int nrest = 0, rc, nrows = 0;
  memset(&c, 0, sizeof c);
  memset(&o, 0, sizeof o);
  if (!rest) {
    fprintf(stderr, "calcvar converge: out of memory\n");
    return EXIT_BADINPUT;
  }
  scene *s = NULL;
  cv_problem *p = NULL;
  cli_conv_row *rows = NULL;
  cli_outfile jf = {0}, gf = {0};
  if ((rc = split_args(argc, argv, &c, rest, &nrest)) != 0) goto done;
  if ((rc = cli_args_parse("converge", nrest, rest, &o)) != 0) goto done;
  if (o.help) {
    usage(stdout);
    goto done;
  }
  cli_progress_setup(o.verbose);
  const char *notmine = o.csv              ? "--csv"
                        : o.plot           ? "--plot"
                        : o.adapt > 0      ? "--adapt"
                        : o.tol > 0        ? "--tol"
                        : o.cont           ? "--continue"
                        : o.max_elements   ? "--max-elements"
                        : o.time_limit > 0 ? "--time-limit"
                        : o.max_nodes      ? "--max-nodes"
                                           : NULL;
  if (notmine) {
    rc = bad("%s is an option of solve, not of converge", notmine);
    goto done;
  }
  if (c.svg && o.json && cli_same_output(c.svg, o.json)) {
    rc = bad("--json and --svg name the same file '%s'", c.svg);
    goto done;
  }
  if (!(s = scene_load_file(o.scene_path, o.nset, o.set, err, sizeof err))) {
    fprintf(stderr, "%s\n", err);
    rc = EXIT_BADINPUT;
    goto done;
  }
  if (o.elements) s->elements = o.elements;
  if (c.ndeg == 0) c.deg[c.ndeg++] = s->degree;
  for (int d = 0; d < c.ndeg && s->c1; d++) /* y'': C1 elements (docs/beams.md) */
    if (c.deg[d] != 1 && (c.deg[d] % 2 == 0 || c.deg[d] > 7)) {
      char dv[16];
      snprintf(dv, sizeof dv, "%d", c.deg[d]);
      rc = bad("--degree %s: a scene with y'' is solved on C1 elements of degree 3, 5 or 7", dv);
      goto done;
    }
  cli_apply_solver_options(&o, s);
  s->adapt = 0; /* converge studies fixed meshes: a scene's adapt or tol does not apply */
  s->tol = 0;
  /* The finest mesh, and the reference mesh of an estimate (p^2 times the nodes), must
   * keep every node count an int. */
  if ((long long)s->elements << (c.levels - 1) > INT_MAX / 81) {
    fprintf(stderr,
            "calcvar converge: %d elements doubled %d times is too many (at most "
            "%d on the finest mesh)\n",
            s->elements, c.levels - 1, INT_MAX / 81);
    rc = EXIT_BADINPUT;
    goto done;
  }
  if (!(p = scene_problem_new(s, scene_method_need(s->method), err, sizeof err))) {
    fprintf(stderr, "%s\n", err[0] ? err : "calcvar converge: out of memory");
    rc = EXIT_BADINPUT;
    goto done;
  }
  if ((o.json && cli_outfile_open(&jf, o.json, o.scene_path) < 0) ||
      (c.svg && cli_outfile_open(&gf, c.svg, o.scene_path) < 0) ||
      cli_outfile_clash(&jf, &gf, "--json", "--svg") < 0) {
    rc = EXIT_BADINPUT;
    goto done;
  }

  int any_exact = 0, all_ok = 1, e0 = s->elements;
  for (int i = 0; i < s->n; i++) any_exact |= s->exact[i] >= 0;
  rows = calloc((size_t)c.ndeg * c.levels, sizeof *rows);
  if (!rows) goto oom;
  for (int d = 0; d < c.ndeg; d++)
    for (int l = 0; l < c.levels; l++) {
      cli_conv_row *row = &rows[nrows++];
      s->degree = c.deg[d];
      s->elements = e0 << l;
      if (solve_row(s, p, any_exact, row) < 0) goto oom;
      all_ok &= row->r.st == CVAR_OK;
      if (l > 0) orders(row - 1, row);
    }
  s->elements = e0;
  rc = all_ok ? EXIT_SOLVED : EXIT_UNSOLVED;
  if (jf.f && cli_outfile_finish(&jf, cli_converge_json(jf.f, rows, nrows)) < 0) {
    fprintf(stderr, "calcvar converge: the JSON report could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (gf.f && cli_plot_converge(&gf, rows, nrows) < 0) {
    fprintf(stderr, "calcvar converge: the SVG could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (!o.quiet && !(o.json && strcmp(o.json, "-") == 0)) cli_converge_text(stdout, rows, nrows);
  for (int k = 0; k < nrows; k++)
    if (rows[k].r.st != CVAR_OK)
      fprintf(stderr, "calcvar converge: %s: %d elements of degree %d: not solved (%s): %s\n",
              s->file, rows[k].r.elements, rows[k].r.degree, rows[k].r.status, rows[k].r.message);
  goto done;
oom:
  fprintf(stderr, "calcvar converge: out of memory\n");
  rc = EXIT_UNSOLVED;
done:
  cli_outfile_abandon(&jf);
  cli_outfile_abandon(&gf);
  for (int k = 0; k < nrows; k++) cli_report_free(&rows[k].r);
  free(rows);
  cv_problem_free(p);
  scene_free(s);
  cli_opts_free(&o);
  free(rest);
  return rc;
}
