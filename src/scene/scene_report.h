/* src/scene/scene_report.h — what `solve` reports, built by the library from a solver and
 * its scene, so that the command and the public call cv_scene_report_json (the Python
 * module's report) share one implementation.
 * SPDX-License-Identifier: MIT
 *
 * Internal (not installed). The cli_ prefix is historical: the command built these before
 * they moved into the library; the names are kept so that work in progress on them merges.
 */
#ifndef CV_SCENE_REPORT_H
#define CV_SCENE_REPORT_H

#include <stdio.h>

#include "calcvar.h"
#include "core/cv_memory.h"
#include "scene/scene.h"

/* The version of the JSON report's layout, written as its "schema" key; raised when a key
 * changes meaning or goes away (new keys are additions and keep it). */
#define CVAR_REPORT_SCHEMA 1

/* What `solve` reports; has_* flags say which keys apply (SCENES.md: keys that do not
 * apply are left out). report.c fills it from a solver and its scene. */
typedef struct {
  const scene *sc;
  cv_method method;
  cv_status st;
  const char *status;
  char message[1024];
  int elements, degree, nodes, n;
  int *degrees; /* degree of each element (written with --tol), or NULL */
  int has_degrees;
  int has_interval; /* a moving end ([ends]): the solved interval */
  double interval[2];
  int has_action, has_gradient_norm, has_time;
  double action, gradient_norm, time_s;
  int has_residual_floor; /* Newton: the residual's round-off floor (theory N-3a) */
  double residual_floor;
  int iterations;
  int has_morse;
  int morse;
  const char *kind;
  int has_err_nodal, has_err_action, has_err_est;
  double err_nodal, err_action, err_est;
  int has_energy;
  double emin, emax;
  int e_skipped;               /* elements left out of energy and momenta (theory P-6a) */
  double e_skip_lo, e_skip_hi; /* the extent of those elements */
  int *has_mom;
  double *mom_min, *mom_max;
  int *has_rep;
  double *rep;
  double *x, *y; /* nodes and node-major values y[j*n + i] */
  double *lam;   /* multiplier fields lam[c*nodes + j] of [constraints], or NULL */
  double *dy;    /* y'' in the scene: node-major nodal slopes dy[j*n + i] (CSV NAME'), or NULL */
  int *has_mu;   /* [integrals] multipliers */
  double *mu;
  int *ncontact;    /* per [constraints] entry: its contact intervals (inequalities), or NULL */
  double **contact; /* contact[c][2k], contact[c][2k + 1]: interval k of constraint c */
} cli_report;

const char *cli_status_string(cv_status st);
int cli_report_collect(cli_report *r, scene *s, const cv_problem *p, cv_solver *sv, cv_method m,
                       cv_status st);
/* scene_estimate.c: the max nodal error of the solver's last solve, from the core's
 * estimator (theory HP-2, HP-3; docs/cli.md). cli_estimate_error gives the max over all
 * nodes and over the element boundaries (NaN, and the reason in why, when there is no
 * bound); cli_report_estimate puts it into r (or the reason into its message). Both return
 * 0, or -1 on allocation failure. */
int cli_report_estimate(cli_report *r, const cv_solver *sv, const cv_problem *p);
int cli_estimate_error(const cv_solver *sv, const cv_problem *p, double *e_all, double *e_vertex,
                       char *why, size_t len);
void cli_report_free(cli_report *r);
/* scene_contact.c: the contact intervals of the inequalities (theory OB-4) of the last
 * solve; 0, or -1 on allocation failure. */
int cli_report_contact(cli_report *r, const scene *s, const cv_problem *p, const cv_solver *sv);

/* Collect and, without [exact], estimate the error: the rounds' own estimate when
 * `adaptive` (1: --adapt; 2: --tol, then always, with the degrees), else
 * cli_report_estimate. Returns 0, or -1 on allocation failure. */
int cli_report_build(cli_report *r, scene *s, const cv_problem *p, cv_solver *sv, cv_status st,
                     int adaptive);

int cli_report_json(FILE *f, const cli_report *r);
/* The report as JSON text (2-space indent, 17 digits), malloc'ed; NULL when out of memory. */
char *cli_report_json_text(const cli_report *r);
struct json_t *cli_report_json_object(const cli_report *r);

#endif /* CV_SCENE_REPORT_H */
