/* src/cli/cli.h — the calcvar command: shared declarations of its subcommands and reports.
 * SPDX-License-Identifier: MIT */
#ifndef CV_CLI_H
#define CV_CLI_H

#include <stdio.h>
#include <sys/types.h>

#include "calcvar.h"
#include "scene/scene.h"
#include "scene/scene_report.h"

/* Exit statuses of SCENES.md, and (an addition, docs/cli.md) 3 when a report or the
 * standard output could not be written. */
enum { EXIT_SOLVED = 0, EXIT_UNSOLVED = 1, EXIT_BADINPUT = 2, EXIT_IOERROR = 3 };

/* Options of `solve` (and later `converge`): zero / NULL / -1 mean "as the scene says". */
typedef struct {
  const char *scene_path;
  int elements, degree, max_iterations;
  int method; /* cv_method or -1 */
  double tolerance;
  double adapt;
  double tol;        /* --tol: automatic accuracy (hp) */
  int max_elements;  /* --max-elements: the adaptive cap (0: 2e6) */
  int max_nodes;     /* --max-nodes: the cap of --tol on the nodes (0: 1e6) */
  double time_limit; /* --time-limit S: a cap on the seconds of --tol / --adapt rounds */
  const char *cont;  /* --continue name=from:to */
  int nset;
  sc_set *set;
  const char *json, *csv, *plot;
  int quiet, help, verbose;
  int all, max_paths; /* --all, --max K (0: default 8) */
  double work;        /* --work F: the search's work limit (0: the default, 2) */
} cli_opts;

/* args.c: parse argv (after the command word). Returns 0, or EXIT_BADINPUT after printing
 * the reason. `cmd` names the command in messages. */
int cli_args_parse(const char *cmd, int argc, char **argv, cli_opts *o);
void cli_opts_free(cli_opts *o);
/* For commands that only read a scene: EXIT_BADINPUT (after a message) if a solve-only
 * option was given, else 0. */
int cli_only_scene_options(const char *cmd, const cli_opts *o);
/* --method, --tolerance and --max-iterations, where given, override the scene's [solver]. */
/* --tol and --adapt on a loaded scene: refuses (exit 2, with a message) a flag that
 * contradicts the scene's [mesh] tol/adapt, sets the target, and for --tol the starting mesh
 * when neither flags nor scene give one. Returns 0 or EXIT_BADINPUT. */
int cli_apply_accuracy(const cli_opts *o, scene *s);
void cli_apply_solver_options(const cli_opts *o, scene *s);

/* progress.c: --verbose lines and the terminal status line (see there). */
void cli_progress_setup(int verbose);
void cli_progress_attach(cv_solver *sv);
void cli_progress_end(void);

/* cli_continue.c: `solve --continue name=from:to` (see there). */
/* s0: the scene, loaded once with parameters as inputs (scene_load_file_inputs) and
 * owned from here on; it is compiled once. *bp owns it and *sp is its instance at the
 * reported value: free *pp and *svp, then cv_batch_free(*bp). */
int cli_continue_solve(const cli_opts *o, scene *s0, cv_batch **bp, const scene **sp,
                       cv_problem **pp, cv_solver **svp, cv_status *stp, char *cont_msg,
                       size_t cmlen, char *err, size_t errlen);

int cli_report_csv(FILE *f, const cli_report *r);
void cli_report_text(FILE *f, const cli_report *r);

/* outfile.c: output files written completely or not at all (a temporary file renamed at
 * the end), streamed into devices and FIFOs, links followed; a directory or the input scene
 * `input` (may be NULL or "-") is refused. open and both commits return 0, or -1 after
 * printing why (the file is then abandoned). */
typedef struct {
  const char *path; /* as given, for messages; "-" is stdout */
  char *dest;       /* path with symbolic links followed */
  char *tmp;        /* the temporary file beside dest (regular files) */
  char *scratch;    /* a rendering scratch file in $TMPDIR (streams) */
  int stream;       /* dest is a device, FIFO or socket: written through */
  FILE *f;
  int exists; /* identity (regular files): dest's device and inode, or, when dest */
  dev_t dev;  /* is not there yet, its directory's and base, its name there */
  ino_t ino;
  const char *base;
} cli_outfile;
int cli_outfile_open(cli_outfile *o, const char *path, const char *input);
/* The same with several files being read (inputs[k] may be NULL or "-"), all refused as
 * outputs (the first is called the scene in the message). */
int cli_outfile_open_inputs(cli_outfile *o, const char *path, const char *const *inputs,
                            int ninputs);
/* -1 after a message when two open outputs are one file (--json X --csv ./X), else 0. */
int cli_outfile_clash(const cli_outfile *a, const cli_outfile *b, const char *what_a,
                      const char *what_b);
int cli_outfile_commit(cli_outfile *o);
/* Commit when the writer succeeded (wrote >= 0), else say why (a write error) and abandon. */
int cli_outfile_finish(cli_outfile *o, int wrote);
/* For a library that writes a file by name (PLplot): a scratch file to write to, then
 * commit_rendered checks that it holds a whole picture (PNG, or SVG when svg) and copies
 * it into o with every write checked, and commits. */
int cli_outfile_render_name(cli_outfile *o, const char **name);
int cli_outfile_commit_rendered(cli_outfile *o, int svg);
void cli_outfile_abandon(cli_outfile *o);
/* Whether a failure to write standard output was already said (said once a run). */
int cli_stdout_reported(void);
void cli_stdout_set_reported(void);
/* cli_signals.c: temporary files removed when the run is interrupted. cli_mkstemp is
 * mkstemp that registers its file (and never returns a descriptor 0-2: they are held
 * open from the start, cli_signals_setup); cli_temp_forget drops a name once the file is
 * renamed or removed (NULL is ignored). cli_signals_setup also makes SIGPIPE a write error
 * (EPIPE: exit 3) and returns 1 when standard output was closed at the start. */
int cli_signals_setup(void);
int cli_mkstemp(char *tmpl);
void cli_temp_forget(const char *name);

/* args.c: the start of a command that reads one scene (equations, modes): parse the
 * arguments (--help prints usage), accept only the scene options, load the scene into *s
 * and open --json's file in *jf. Returns -1 to go on, else the exit status (after a
 * message); the caller releases o, *s and *jf in either case. */
int cli_scene_command_start(const char *cmd, int argc, char **argv, void (*usage)(FILE *),
                            cli_opts *o, scene **s, cli_outfile *jf);

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
  int equal;        /* one unit is as long on both axes (a path) */
  int xdown, ydown; /* the axis increases leftward / downward */
  int no_legend;    /* the axis labels say it all (one curve) */
  int legend_right; /* the legend right of the axes, not inside (leave room for it in vp) */
  double vp[4];     /* x0, x1, y0, y1 of the axes on the page (0..1); all 0: stacked */
  int nlines;
  const cli_plot_line *lines;
} cli_plot_panel;
int cli_plot_path_ok(const char *path); /* ends in .svg or .png */
/* Panels stacked top to bottom on a page 960 wide (the vp of each panel is set here). */
int cli_plot_write(cli_outfile *o, int npanels, cli_plot_panel *panels);
/* Panels where their vp says, on a page of width x height pixels. */
int cli_plot_write_page(cli_outfile *o, int width, int height, int npanels,
                        const cli_plot_panel *panels);

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
  int no_est_at; /* where r.message says why there is no estimate (HP-3), or -1 */
} cli_conv_row;
/* Whether two output paths name one file that writing both would clobber: the same path or
 * the same regular file under two names; a device such as /dev/null may take both. */
int cli_same_output(const char *a, const char *b);
int cli_converge_text(FILE *f, const cli_conv_row *rows, int nrows);
int cli_converge_json(FILE *f, const cli_conv_row *rows, int nrows);
int cli_plot_converge(cli_outfile *o, const cli_conv_row *rows, int nrows);

/* cli_all.c: `solve --all`: the deflated search, its reports; returns the exit status.
 * adaptive as cli_report_build's: 0 a fixed mesh, 1 --adapt, 2 --tol. */
int cli_all_run(const cli_opts *o, scene *s, cv_problem *p, cv_solver *sv, int adaptive,
                cli_outfile *jf, cli_outfile *cf, cli_outfile *pf);

/* Subcommands. */
int cli_converge(int argc, char **argv);
int cli_batch(int argc, char **argv); /* cli_batch.c */
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
