/* src/cli/cli_solve.c — `calcvar solve SCENE [options]`: load, solve, report.
 * SPDX-License-Identifier: MIT
 *
 * Order matters for the exit-status contract: flags and the scene are checked completely
 * before any output file is opened (bad input: exit 2, nothing written); output files are
 * opened before the solve (an unwritable path is bad input too, found before the work);
 * after the solve the reports are written whatever the status (exit 1 keeps its JSON).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"
#include "scene/scene_batch.h"

static void usage(FILE *f) {
  fputs("usage: calcvar solve SCENE [options]\n"
        "  --elements N         uniform elements (scene's [mesh] elements, default 100)\n"
        "  --degree P           polynomial degree 1..8 of the elements\n"
        "  --method M           newton (default); lbfgs tnewton mma ccsaq slsqp auglag\n"
        "  --tolerance T        Newton step tolerance (default 1e-10)\n"
        "  --max-iterations K   iteration limit (default 50)\n"
        "  --set name=value     override a parameter (repeatable)\n"
        "  --adapt TOL          refine until the estimated max nodal error < TOL\n"
        "  --max-elements N     cap of adaptive refinement (default 2000000)\n"
        "  --tol T              choose mesh and degrees until the estimated max nodal\n"
        "                       error <= T (elements/degree, if given, are the start)\n"
        "  --max-nodes N        cap of --tol on the nodes (default 1000000)\n"
        "  --time-limit S       stop the rounds of --tol / --adapt after S seconds (exit 1,\n"
        "                       with the estimate reached)\n"
        "  --continue name=from:to   continuation in a parameter\n"
        "  --all                every stationary path that can be found (deflation)\n"
        "  --max K              at most K paths with --all (default 8)\n"
        "  --work F             --all's work limit: F times the first solve's, renewed\n"
        "                       by every path found (default 2)\n"
        "  --json FILE          JSON report ('-' for stdout)\n"
        "  --csv FILE           nodal table ('-' for stdout)\n"
        "  --plot FILE          picture of the solution (.png or .svg)\n"
        "  --quiet              no summary on stdout\n"
        "  -v, --verbose        one line per Newton iteration and adaptive round on stderr\n"
        "  -h, --help           this text\n"
        "exit status: 0 converged, 1 not solved, 2 bad input, 3 write error\n",
        f);
}

/* Combinations that cannot be honoured: refuse (exit 2, nothing written) rather than
 * ignore a request. */
static int unsupported(const cli_opts *o, const scene *s) {
  if (o->cont && (o->adapt > 0 || s->adapt > 0 || o->tol > 0 || s->tol > 0)) {
    fprintf(stderr, "calcvar solve: --continue and adaptive refinement cannot be combined "
                    "(continuation keeps one mesh)\n");
    return EXIT_BADINPUT;
  }
  if (o->max_elements > 0 && !(o->adapt > 0 || s->adapt > 0)) {
    fprintf(stderr, "calcvar solve: --max-elements applies to adaptive refinement only "
                    "(--adapt TOL or [mesh] adapt)\n");
    return EXIT_BADINPUT;
  }
  if (o->all && o->cont) {
    fprintf(stderr, "calcvar solve: --all and --continue cannot be combined (the search "
                    "keeps one scene)\n");
    return EXIT_BADINPUT;
  }
  if (o->all && s->method != CVAR_METHOD_NEWTON) {
    fprintf(stderr,
            "calcvar solve: --all needs the Newton engine (method %s finds minima "
            "only, not the saddles the search is for)\n",
            cv_method_name(s->method));
    return EXIT_BADINPUT;
  }
  if ((s->method == CVAR_METHOD_LBFGS || s->method == CVAR_METHOD_TNEWTON) &&
      (s->ncons > 0 || s->nints > 0)) {
    /* an unconstrained minimiser cannot impose [constraints] or [integrals] */
    if (o->method >= 0)
      fprintf(stderr,
              "calcvar solve: --method %s cannot impose constraints; use mma, ccsaq, "
              "slsqp, auglag or newton\n",
              cv_method_name(s->method));
    else
      fprintf(stderr,
              "%s:%d: method %s cannot impose constraints; use mma, ccsaq, slsqp, "
              "auglag or newton\n",
              s->file, s->method_line, cv_method_name(s->method));
    return EXIT_BADINPUT;
  }
  return 0;
}

int cli_solve(int argc, char **argv) {
  cli_opts o;
  char err[SC_ERRLEN];
  int rc = cli_args_parse("solve", argc, argv, &o);
  if (rc != 0 || o.help) {
    if (o.help) usage(stdout);
    cli_opts_free(&o);
    return rc;
  }
  /* --continue: read once with the parameters as inputs, compiled once (issue 18) */
  scene *s = o.cont ? scene_load_file_inputs(o.scene_path, o.nset, o.set, err, sizeof err)
                    : scene_load_file(o.scene_path, o.nset, o.set, err, sizeof err);
  cv_problem *p = NULL;
  cv_solver *sv = NULL;
  cv_batch *cb = NULL; /* --continue: the compiled scene */
  cli_outfile jf = {0}, cf = {0}, pf = {0};
  cli_report r;
  memset(&r, 0, sizeof r);
  if (!s) {
    fprintf(stderr, "%s\n", err);
    rc = EXIT_BADINPUT;
    goto done;
  }
  if (o.elements) s->elements = o.elements;
  if (o.degree) s->degree = o.degree;
  cli_apply_solver_options(&o, s);
  if ((rc = unsupported(&o, s)) != 0) goto done;
  if ((rc = cli_apply_accuracy(&o, s)) != 0) goto done;
  double tol = s->tol;
  cv_status why;
  if ((!o.cont && !(p = scene_problem_new(s, scene_method_need(s->method), err, sizeof err))) ||
      !(sv = cv_solver_new(&why)) || scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK) {
    fprintf(stderr, "%s\n", err[0] ? err : "calcvar solve: out of memory");
    rc = EXIT_BADINPUT;
    goto done;
  }
  if ((o.json && cli_outfile_open(&jf, o.json, o.scene_path) < 0) ||
      (o.csv && cli_outfile_open(&cf, o.csv, o.scene_path) < 0) ||
      (o.plot && cli_outfile_open(&pf, o.plot, o.scene_path) < 0) ||
      cli_outfile_clash(&jf, &cf, "--json", "--csv") < 0 ||
      cli_outfile_clash(&jf, &pf, "--json", "--plot") < 0 ||
      cli_outfile_clash(&cf, &pf, "--csv", "--plot") < 0) {
    rc = EXIT_BADINPUT;
    goto done;
  }

  /* Adaptive refinement: [mesh] adapt or --adapt, capped at --max-elements, default 2e6
   * elements (theory AD-1). */
  double adapt = o.adapt > 0 ? o.adapt : s->adapt;
  int cap = o.max_elements > 0 ? o.max_elements : 2000000;
  if (adapt > 0 && cv_solver_set_adapt(sv, adapt, cap) != CVAR_OK) {
    fprintf(stderr, "calcvar solve: invalid adaptive tolerance %g\n", adapt);
    rc = EXIT_BADINPUT;
    goto done;
  }
  cv_status st;
  char cont_msg[256] = "";
  cli_progress_setup(o.verbose);
  cli_progress_attach(sv);
  if (o.all) {
    rc = cli_all_run(&o, s, p, sv, tol > 0 ? 2 : adapt > 0, &jf, &cf, &pf);
    cli_progress_end();
    goto done;
  }
  if (o.cont) {
    /* continuation replaces scene, problem and solver by those of its last step */
    cv_solver_free(sv);
    scene *s0 = s;
    s = NULL, sv = NULL;
    const scene *si = NULL;
    if (cli_continue_solve(&o, s0, &cb, &si, &p, &sv, &st, cont_msg, sizeof cont_msg, err,
                           sizeof err) < 0) {
      fprintf(stderr, "%s\n", err);
      rc = EXIT_BADINPUT;
      goto done;
    }
    s = (scene *)si; /* the batch's instance: cb owns it (its DAG may grow for the report) */
  } else {
    st = cv_solve(sv, p);
  }
  cli_progress_end();
  if (st == CVAR_EINVAL) {
    /* Input the core refused before solving (e.g. a dense NLopt Jacobian too large). */
    fprintf(stderr, "%s: %s\n", s->file, cv_solver_last_error(sv));
    rc = EXIT_BADINPUT;
    goto done;
  }
  if (cli_report_build(&r, s, p, sv, st, tol > 0 ? 2 : adapt > 0) < 0) {
    fprintf(stderr, "calcvar solve: out of memory while reporting\n");
    rc = EXIT_UNSOLVED;
    goto done;
  }
  double xs, alpha;
  if (st == CVAR_OK && scene_interior_singularity(s, sv, &xs, &alpha) == 1) {
    /* a finite discrete action of an infinite one: not a solution (theory (SG-1)) */
    st = r.st = CVAR_ENONFINITE;
    r.status = cli_status_string(st);
    r.has_morse = 0;
    r.has_err_est = 0; /* an estimate of a path that is no solution would be a claim */
    r.kind = NULL;
    snprintf(r.message, sizeof r.message,
             "the integrand is singular at %s = %.6g inside the interval: along the path "
             "|F| grows like |%s - %.6g|^(-%.2f), so the action is infinite and the discrete "
             "answer (which changes with the mesh) is no stationary path; split the interval "
             "there or remove the singularity",
             s->variable, xs, s->variable, xs, alpha);
  }
  if (cont_msg[0]) {
    size_t used = st == CVAR_OK ? strlen(r.message) : 0;
    char c0 =
        cont_msg[0] >= 'a' && cont_msg[0] <= 'z' ? (char)(cont_msg[0] - 'a' + 'A') : cont_msg[0];
    snprintf(r.message + used, sizeof r.message - used, "%s%c%s.", used ? " " : "", c0,
             cont_msg + 1);
  }
  rc = st == CVAR_OK ? EXIT_SOLVED : EXIT_UNSOLVED;
  if (jf.f && cli_outfile_finish(&jf, cli_report_json(jf.f, &r)) < 0) {
    fprintf(stderr, "calcvar solve: the JSON report could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (pf.f && cli_plot_solution(&pf, &r, sv) < 0) {
    fprintf(stderr, "calcvar solve: the plot could not be written\n");
    rc = EXIT_IOERROR;
  }
  if (cf.f && cli_outfile_finish(&cf, cli_report_csv(cf.f, &r)) < 0) {
    fprintf(stderr, "calcvar solve: the CSV table could not be written\n");
    rc = EXIT_IOERROR;
  }
  /* stdout carries the data when a report goes there; the summary would corrupt it. */
  int stdout_taken = (o.json && strcmp(o.json, "-") == 0) || (o.csv && strcmp(o.csv, "-") == 0);
  if (!o.quiet && !stdout_taken) cli_report_text(stdout, &r);
  if (st != CVAR_OK)
    fprintf(stderr, "calcvar solve: %s: not solved (%s): %s\n", s->file, r.status, r.message);
done:
  cli_outfile_abandon(&jf);
  cli_outfile_abandon(&cf);
  cli_outfile_abandon(&pf);
  cli_report_free(&r);
  cv_solver_free(sv);
  cv_problem_free(p);
  if (!cb) scene_free(s);
  cv_batch_free(cb);
  cli_opts_free(&o);
  return rc;
}
