/* src/cli/cli.h — the calcvar command: shared declarations of its subcommands and reports.
 * SPDX-License-Identifier: MIT */
#ifndef CV_CLI_H
#define CV_CLI_H

#include <stdio.h>

#include "calcvar.h"
#include "scene/scene.h"
#include "scene/scene_report.h"

/* Exit statuses of SCENES.md. */
enum { EXIT_SOLVED = 0, EXIT_UNSOLVED = 1, EXIT_BADINPUT = 2 };

/* Options of `solve` (and later `converge`): zero / NULL / -1 mean "as the scene says". */
typedef struct {
  const char *scene_path;
  int elements, degree, max_iterations;
  int method; /* cv_method or -1 */
  double tolerance;
  double adapt;
  double tol; /* --tol: automatic accuracy (hp) */
  const char *cont; /* --continue name=from:to */
  int nset;
  sc_set *set;
  const char *json, *csv, *plot;
  int quiet, help;
  int all, max_paths; /* --all, --max K (0: default 8) */
  double work;        /* --work F: the search's work limit (0: default 8) */
} cli_opts;

/* args.c: parse argv (after the command word). Returns 0, or EXIT_BADINPUT after printing
 * the reason. `cmd` names the command in messages. */
int cli_args_parse(const char *cmd, int argc, char **argv, cli_opts *o);
void cli_opts_free(cli_opts *o);
/* For commands that only read a scene: EXIT_BADINPUT (after a message) if a solve-only
 * option was given, else 0. */
int cli_only_scene_options(const char *cmd, const cli_opts *o);

/* cli_continue.c: `solve --continue name=from:to` (see there). */
int cli_continue_solve(const cli_opts *o, scene **sp, cv_problem **pp, cv_solver **svp,
                       cv_status *stp, char *cont_msg, size_t cmlen, char *err, size_t errlen);

int cli_report_csv(FILE *f, const cli_report *r);
void cli_report_text(FILE *f, const cli_report *r);

/* outfile.c: all-or-nothing output files (a temporary file renamed at the end). */
typedef struct {
  const char *path; /* "-" is stdout */
  char *tmp;
  FILE *f;
} cli_outfile;
int cli_outfile_open(cli_outfile *o, const char *path);
int cli_outfile_commit(cli_outfile *o);
void cli_outfile_abandon(cli_outfile *o);

/* plot.c: curves on panels stacked top to bottom, written with PLplot to the temporary
 * file of an open cli_outfile (.svg or .png by its path) and renamed into place. */
typedef struct {
  int n;
  const double *x, *y; /* non-finite points (and <= 0 on a log axis) break the line */
  const char *label;   /* legend text */
  int colour, style;   /* colour 0, 1, ... (-1: black); PLplot line style 1..8 (0: solid) */
  int symbol;          /* nonzero: mark the points too */
} cli_plot_line;
typedef struct {
  const char *title, *xlabel, *ylabel;
  int logx, logy;
  int nlines;
  const cli_plot_line *lines;
} cli_plot_panel;
int cli_plot_path_ok(const char *path); /* ends in .svg or .png */
int cli_plot_write(cli_outfile *o, int npanels, const cli_plot_panel *panels);

int cli_plot_solution(cli_outfile *o, const cli_report *r, const cv_solver *sv);

/* `converge`: one row per mesh. The errors are against [exact] (estimated = 0) or, without
 * it, estimates (cli_estimate_error). "_v" is the max over the element boundaries (mesh
 * vertices), which converge as h^(2p), faster than the interior nodes (theory (E-4)). The
 * orders compare with the previous row of the same degree. */
typedef struct {
  cli_report r;
  int estimated;
  int has_err, has_err_v, has_order, has_order_v;
  double err, err_v, order, order_v;
} cli_conv_row;
int cli_converge_text(FILE *f, const cli_conv_row *rows, int nrows);
int cli_converge_json(FILE *f, const cli_conv_row *rows, int nrows);
int cli_plot_converge(cli_outfile *o, const cli_conv_row *rows, int nrows);

/* cli_all.c: `solve --all`: the deflated search, its reports; returns the exit status. */
int cli_all_run(const cli_opts *o, scene *s, cv_problem *p, cv_solver *sv, double adapt,
                cli_outfile *jf, cli_outfile *cf, cli_outfile *pf);

/* Subcommands. */
int cli_converge(int argc, char **argv);
int cli_gallery(void);
int cli_solve(int argc, char **argv);
int cli_check(int argc, char **argv);
int cli_equations(int argc, char **argv); /* cli_equations.c */
int cli_modes(int argc, char **argv);     /* cli_modes.c */
int cli_unsupported(const char *cmd);

/* gallery_scenes.c, generated from examples/scenes by src/cli/embed_scenes.py */
typedef struct {
  const char *name;
  const char *text;
} cli_gallery_scene;
extern const cli_gallery_scene cli_gallery_scenes[];
extern const int cli_gallery_count;

#endif /* CV_CLI_H */
