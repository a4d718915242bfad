/* src/scene/scene_report.c — gather what `solve` reports from a solver and its scene.
 * SPDX-License-Identifier: MIT
 *
 * Energy, momenta and [report] integrals are evaluated at the solver's quadrature points
 * (cv_solver_get_qpoints), so a report integral is the same sum the action is; energy and
 * momenta are reported as the range of their element averages (docs/cli.md). A quantity that comes out non-finite is
 * left out of the report rather than printed as NaN.
 */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_report.h"

const char *cli_status_string(cv_status st) {
  switch (st) {
  case CVAR_OK: return "converged";
  case CVAR_EMAXITER: return "max_iterations";
  case CVAR_ENONFINITE:
  case CVAR_EDIVERGED: return "diverged";
  case CVAR_ESINGULAR: return "singular";
  default: return "no_progress";
  }
}

void cli_report_free(cli_report *r) {
  cv_free(r->has_mom);
  cv_free(r->mom_min);
  cv_free(r->mom_max);
  cv_free(r->has_rep);
  cv_free(r->rep);
  cv_free(r->x);
  cv_free(r->y);
  cv_free(r->lam);
  for (int c = 0; r->contact && r->sc && c < r->sc->ncons; c++) cv_free(r->contact[c]);
  cv_free(r->contact);
  cv_free(r->ncontact);
  cv_free(r->dy);
  cv_free(r->has_mu);
  cv_free(r->mu);
  cv_free(r->degrees);
  memset(r, 0, sizeof *r);
}

/* min and max of v[0..m-1]; returns 0 when every value is finite, else -1. */
static int range(const double *v, int m, double *lo, double *hi) {
  *lo = INFINITY;
  *hi = -INFINITY;
  for (int k = 0; k < m; k++) {
    if (!isfinite(v[k])) return -1;
    *lo = v[k] < *lo ? v[k] : *lo;
    *hi = v[k] > *hi ? v[k] : *hi;
  }
  return m > 0 ? 0 : -1;
}

/* Max over nodes and unknowns of |y_h - y_exact| at the nodes, over the unknowns that
 * have an [exact] expression. */
static int nodal_error(cli_report *r, const scene *s) {
  int nn = r->nodes, n = s->n, any = 0;
  for (int i = 0; i < n; i++) any |= s->exact[i] >= 0;
  if (!any) return 0;
  double *ex = cv_malloc((size_t)nn * n * sizeof *ex);
  if (!ex || scene_eval_exact(s, nn, r->x, ex) < 0) {
    cv_free(ex);
    return -1;
  }
  double e = 0;
  int finite = 1;
  for (int i = 0; i < n; i++)
    if (s->exact[i] >= 0)
      for (int j = 0; j < nn; j++) {
        double d = fabs(r->y[(size_t)j * n + i] - ex[(size_t)i * nn + j]);
        finite &= isfinite(d);
        e = d > e ? d : e;
      }
  cv_free(ex);
  if (finite) {
    r->has_err_nodal = 1;
    r->err_nodal = e;
  }
  return 0;
}

/* min and max over the elements of the element average of v (quadrature weights w; the
 * nq points come element by element, in increasing x; element e holds those between its
 * boundaries xb[e] and xb[e + 1], E + 1 of them: the number of points differs between
 * elements of different degrees). The discrete Euler-Lagrange
 * equation of a cyclic unknown makes exactly these averages of its momentum equal
 * (discrete Noether, docs/theory.md), whereas inside an element the momentum varies by
 * O(h^p); energy averages drift at O(h^2p) on smooth problems (docs/cli.md). */
static int elem_avg_range(const double *v, const double *w, const double *x, int nq,
                          const double *xb, const unsigned char *skip, int E, double *lo,
                          double *hi) {
  if (E <= 0) return range(v, nq, lo, hi);
  *lo = INFINITY;
  *hi = -INFINITY;
  int k = 0;
  for (int e = 0; e < E; e++) {
    double sv = 0.0, sw = 0.0;
    for (; k < nq && (e == E - 1 || x[k] < xb[e + 1]); k++) {
      sv += w[k] * v[k];
      sw += w[k];
    }
    if (!(sw > 0) || (skip && skip[e])) continue; /* no point in it, or not meaningful */
    double a = sv / sw;
    if (!isfinite(a)) return -1;
    *lo = a < *lo ? a : *lo;
    *hi = a > *hi ? a : *hi;
  }
  return isfinite(*lo) ? 0 : -1;
}

/* Whether any [constraints] or [integrals] expression depends on the slot. */
static int constraints_depend_on(const scene *s, int slot) {
  for (int k = 0; k < s->ncons; k++)
    if (ex_depends_on(s->dag, s->cons[k].expr, slot)) return 1;
  for (int k = 0; k < s->nints; k++)
    if (ex_depends_on(s->dag, s->ints[k].expr, slot)) return 1;
  return 0;
}

/* The element boundaries xb[0..E] of the report's mesh, from its nodes and degrees; 0 when
 * they do not add up. */
/* Node steps of element e: its degree for GLL elements; (p - 1) / 2 for the C^1 elements
 * of degree p (values and slopes at those nodes, theory H-2). */
static long element_step(const cli_report *r, int c1, int e) {
  int p = r->degrees[e];
  return c1 ? (p <= 3 ? 1 : (p - 1) / 2) : p;
}

static int element_bounds(const cli_report *r, int c1, double *xb) {
  long j = 0;
  if (!r->degrees || r->elements <= 0) return 0;
  for (int e = 0; e <= r->elements; e++) {
    if (j >= r->nodes) return 0;
    xb[e] = r->x[j];
    if (e < r->elements) j += element_step(r, c1, e);
  }
  return j == r->nodes - 1;
}

/* P-6a: the elements on which y' (so H and the momenta) is not known: where the estimated
 * max nodal error est of the rounds exceeds MEANINGFUL times the change of y across the
 * element (y' there is the change over the width, known only to est / change). Next to a
 * singular end the rounds make elements of 1e-13 of the interval whose values change by
 * less than 1e-8: their averages of H were off by O(1) (brachistochrone --tol 1e-10: H
 * from -24.4 to -0.68). Sets skip[e], r->e_skipped and the extent of the skipped elements;
 * none when there is no estimate, and never every element. */
#define MEANINGFUL 1e-3
static void unknown_slopes(cli_report *r, const cv_solver *sv, int c1, const double *xb,
                           unsigned char *skip) {
  double est = cv_solver_get_error_estimate(sv);
  int n = r->n, E = r->elements, count = 0;
  long j = 0;
  r->e_skipped = 0;
  if (!(est > 0) || !isfinite(est)) return;
  for (int e = 0; e < E; e++) {
    long j1 = j + element_step(r, c1, e);
    double change = 0.0;
    for (int i = 0; i < n; i++)
      change = fmax(change, fabs(r->y[(size_t)j1 * n + i] - r->y[(size_t)j * n + i]));
    skip[e] = est > MEANINGFUL * change;
    count += skip[e];
    j = j1;
  }
  if (count == E) {
    for (int e = 0; e < E; e++) skip[e] = 0;
    return;
  }
  r->e_skipped = count;
  r->e_skip_lo = INFINITY, r->e_skip_hi = -INFINITY;
  for (int e = 0; e < E; e++)
    if (skip[e])
      r->e_skip_lo = fmin(r->e_skip_lo, xb[e]), r->e_skip_hi = fmax(r->e_skip_hi, xb[e + 1]);
}

/* Energy, momenta and report integrals at the quadrature points. Energy and momenta come
 * from the problem's compiled integrand (the partials the solver used). */
static int qpoint_quantities(cli_report *r, scene *s, const cv_problem *p, cv_solver *sv) {
  int n = s->n, nq = cv_solver_get_num_qpoints(sv), rc = -1;
  if (nq <= 0) return 0;
  size_t q = (size_t)nq;
  double *x = cv_malloc(q * sizeof *x), *w = cv_malloc(q * sizeof *w);
  double *y = cv_malloc(q * n * sizeof *y), *dy = cv_malloc(q * n * sizeof *dy);
  size_t nv = q * (size_t)(n > s->nreports ? n : s->nreports);
  double *v = cv_malloc((nv > q ? nv : q) * sizeof *v);
  double *H = cv_malloc(q * sizeof *H), *mom = cv_malloc(q * n * sizeof *mom);
  double *xb = cv_malloc(((size_t)r->elements + 1) * sizeof *xb);
  unsigned char *skip = cv_calloc((size_t)r->elements + 1, 1);
  double *d2y = s->c1 ? cv_malloc(q * n * sizeof *d2y) : NULL;
  if (!x || !w || !y || !dy || !v || !H || !mom || !xb || !skip || (s->c1 && !d2y)) goto done;
  if (!element_bounds(r, s->c1, xb) || cv_solver_get_qpoints2(sv, x, w, y, dy, d2y) != CVAR_OK) {
    rc = 0; /* nothing to evaluate on: leave the keys out */
    goto done;
  }
  unknown_slopes(r, sv, s->c1, xb, skip);
  /* With constraints, H of F alone is conserved only when no constraint depends on the
   * variable and there is no integral constraint (whose multiplier enters the conserved
   * quantity); a momentum only when no constraint involves that unknown (docs/cli.md). */
  /* y'' in F: the first-order energy and momenta do not apply (Ostrogradsky's are in
   * `equations`), so their keys are left out */
  cv_status st = s->c1 ? CVAR_EINVAL : cv_problem_eval_energy(p, nq, x, y, dy, H, mom);
  if (st == CVAR_ENOMEM) goto done;
  /* A callback that fails here leaves energy and momenta out, as non-finite values do. */
  int have = st == CVAR_OK;
  if (have && !scene_F_depends_on_variable(s) && s->nints == 0 && !constraints_depend_on(s, 0))
    r->has_energy = elem_avg_range(H, w, x, nq, xb, skip, r->elements, &r->emin, &r->emax) == 0;
  for (int i = 0; i < n && have; i++)
    if (!scene_F_depends_on_unknown(s, i) && !constraints_depend_on(s, 1 + i))
      r->has_mom[i] = elem_avg_range(mom + (size_t)i * q, w, x, nq, xb, skip, r->elements,
                                     &r->mom_min[i], &r->mom_max[i]) == 0;
  if (s->nreports > 0 && scene_eval_reports2(s, nq, x, y, dy, d2y, v) < 0) goto done;
  for (int k = 0; k < s->nreports; k++) {
    double sum = 0;
    for (int j = 0; j < nq; j++) sum += w[j] * v[(size_t)k * q + j];
    r->rep[k] = sum;
    r->has_rep[k] = isfinite(sum);
  }
  rc = 0;
done:
  cv_free(xb);
  cv_free(skip);
  cv_free(x);
  cv_free(w);
  cv_free(y);
  cv_free(dy);
  cv_free(v);
  cv_free(H);
  cv_free(mom);
  cv_free(d2y);
  return rc;
}

/* A closed path whose Hessian is singular: name the symmetry (PB-3). */
static void singular_closed_path(cli_report *r, size_t used) {
  const scene *s = r->sc;
  int periodic = 0;
  for (int i = 0; i < s->n; i++) periodic |= s->bc[i].periodic;
  if (!periodic) return;
  char sym[600];
  int nt = scene_translations(s, sym, sizeof sym);
  snprintf(r->message + used, sizeof r->message - used,
           ". On closed paths a continuous symmetry of the action leaves the Hessian singular "
           "%s%s%s; a rotation of the unknowns (as in an N-body problem) would too: pin it "
           "with an [integrals] line of the angular offset against the guess, "
           "sum (y_k gx_k - x_k gy_k), 0 (docs/periodic.md)",
           scene_pins_shift(s) ? "besides the shift, which calcvar pinned"
                               : "(the shift along "
                                 "the variable is "
                                 "pinned only when every "
                                 "unknown is periodic "
                                 "and the guess moves)",
           nt ? ": " : "", nt ? sym : "");
}

static void compose_message(cli_report *r, cv_solver *sv) {
  const char *detail = cv_solver_last_error(sv);
  if (r->st != CVAR_OK) {
    int k = snprintf(r->message, sizeof r->message, "%s",
                     detail && detail[0] ? detail : cv_strerror(r->st));
    if (r->st == CVAR_ESINGULAR && k > 0 && (size_t)k < sizeof r->message)
      singular_closed_path(r, (size_t)k);
    return;
  }
  int k = snprintf(r->message, sizeof r->message, "Converged in %d iteration%s", r->iterations,
                   r->iterations == 1 ? "" : "s");
  if (r->kind && k > 0 && (size_t)k < sizeof r->message) {
    if (strcmp(r->kind, "degenerate") == 0)
      snprintf(r->message + k, sizeof r->message - (size_t)k,
               "; the Hessian is degenerate there%s%s.", detail && detail[0] ? ": " : "",
               detail ? detail : "");
    else
      snprintf(r->message + k, sizeof r->message - (size_t)k,
               " to a %s of the action (Morse index %d).", r->kind, r->morse);
  } else if (k > 0 && (size_t)k < sizeof r->message) {
    snprintf(r->message + k, sizeof r->message - (size_t)k, ".");
  }
  /* What the solver decided on its own (graded mesh, continuation, adaptation) follows. */
  size_t used = strlen(r->message);
  if (detail && detail[0] && strncmp(detail, "converged in ", 13) != 0 &&
      used + 2 < sizeof r->message)
    snprintf(r->message + used, sizeof r->message - used, " %c%s.",
             detail[0] >= 'a' && detail[0] <= 'z' ? detail[0] - 'a' + 'A' : detail[0], detail + 1);
  used = strlen(r->message);
  if (r->e_skipped > 0 && used + 2 < sizeof r->message) /* P-6a */
    snprintf(r->message + used, sizeof r->message - used,
             " The energy and momenta leave out %d element%s in [%.3g, %.3g], where the "
             "estimated nodal error is above %g of the change of the values across the "
             "element, so that y' (and H) are not known there.",
             r->e_skipped, r->e_skipped == 1 ? "" : "s", r->e_skip_lo, r->e_skip_hi, MEANINGFUL);
}

/* Fill r after cv_solve returned st. Returns 0, or -1 on allocation failure. */
int cli_report_collect(cli_report *r, scene *s, const cv_problem *p, cv_solver *sv, cv_method m,
                       cv_status st) {
  int n = s->n;
  memset(r, 0, sizeof *r);
  r->sc = s;
  r->method = m;
  r->st = st;
  r->status = cli_status_string(st);
  r->n = n;
  r->elements = cv_solver_get_num_elements(sv);
  r->degree = cv_solver_get_degree(sv);
  r->nodes = cv_solver_get_num_nodes(sv);
  if (r->elements > 0) {
    r->degrees = cv_malloc((size_t)r->elements * sizeof *r->degrees);
    if (!r->degrees) return -1;
    cv_solver_get_degrees(sv, r->degrees);
  }
  r->has_interval = scene_has_moving_end(s) && r->nodes > 0 &&
                    cv_solver_get_interval(sv, &r->interval[0], &r->interval[1]) == CVAR_OK;
  r->iterations = cv_solver_get_num_iterations(sv);
  r->action = cv_solver_get_action(sv);
  r->has_action = isfinite(r->action);
  r->gradient_norm = cv_solver_get_gradient_norm(sv);
  r->has_gradient_norm = isfinite(r->gradient_norm);
  r->has_residual_floor = m == CVAR_METHOD_NEWTON && r->has_gradient_norm &&
                          cv_solver_residual_floor(sv, p, &r->residual_floor) == CVAR_OK &&
                          r->residual_floor > 0;
  r->time_s = cv_solver_get_time(sv);
  r->has_time = isfinite(r->time_s);

  r->has_mom = cv_calloc((size_t)n, sizeof *r->has_mom);
  r->mom_min = cv_calloc((size_t)n, sizeof *r->mom_min);
  r->mom_max = cv_calloc((size_t)n, sizeof *r->mom_max);
  r->has_rep = cv_calloc((size_t)s->nreports + 1, sizeof *r->has_rep);
  r->rep = cv_calloc((size_t)s->nreports + 1, sizeof *r->rep);
  int nn = r->nodes > 0 ? r->nodes : 0;
  r->x = cv_calloc((size_t)nn + 1, sizeof *r->x);
  r->y = cv_calloc((size_t)nn * n + 1, sizeof *r->y);
  if (!r->has_mom || !r->mom_min || !r->mom_max || !r->has_rep || !r->rep || !r->x || !r->y)
    return -1;
  if (nn > 0 &&
      (cv_solver_get_nodes(sv, r->x) != CVAR_OK || cv_solver_get_values(sv, r->y) != CVAR_OK))
    r->nodes = nn = 0;

  /* The Morse index describes a stationary point: reported only when Newton converged to
   * one (an unconverged iterate's inertia says nothing about the answer). */
  if (m == CVAR_METHOD_NEWTON && st == CVAR_OK) {
    int morse = cv_solver_get_morse_index(sv), nfree = cv_solver_get_num_free(sv);
    if (morse >= 0) {
      r->has_morse = 1;
      r->morse = morse;
      if (cv_solver_get_degenerate(sv))
        r->kind = "degenerate";
      else if (morse == 0)
        r->kind = "minimum";
      else if (morse == nfree)
        r->kind = "maximum";
      else
        r->kind = "saddle";
    }
  }
  if (nn > 0 && nodal_error(r, s) < 0) return -1;
  if (nn > 0 && s->c1) { /* the slopes are unknowns of the C^1 elements (CSV NAME') */
    if (!(r->dy = cv_malloc((size_t)nn * n * sizeof *r->dy))) return -1;
    if (cv_solver_get_slopes(sv, r->dy) != CVAR_OK) {
      cv_free(r->dy);
      r->dy = NULL;
    }
  }
  /* Multiplier fields (CSV lambda_NAME) and integral multipliers (JSON multipliers). */
  if (nn > 0 && s->ncons > 0) {
    r->lam = cv_malloc((size_t)nn * s->ncons * sizeof *r->lam);
    if (!r->lam) return -1;
    for (int c = 0; c < s->ncons; c++)
      if (cv_solver_get_multiplier_field(sv, c, r->lam + (size_t)c * nn) != CVAR_OK)
        for (int j = 0; j < nn; j++) r->lam[(size_t)c * nn + j] = NAN;
    if (cli_report_contact(r, s, p, sv) < 0) return -1;
  }
  r->has_mu = cv_calloc((size_t)s->nints + 1, sizeof *r->has_mu);
  r->mu = cv_calloc((size_t)s->nints + 1, sizeof *r->mu);
  if (!r->has_mu || !r->mu) return -1;
  for (int k = 0; k < s->nints; k++)
    r->has_mu[k] = cv_solver_get_multiplier(sv, k, &r->mu[k]) == CVAR_OK && isfinite(r->mu[k]);
  if (s->has_exact_action && r->has_action) {
    r->has_err_action = 1;
    r->err_action = fabs(r->action - s->exact_action);
  }
  if (nn > 0 && qpoint_quantities(r, s, p, sv) < 0) return -1;
  compose_message(r, sv);
  return 0;
}

int cli_report_build(cli_report *r, scene *s, const cv_problem *p, cv_solver *sv, cv_status st,
                     int adaptive) {
  if (cli_report_collect(r, s, p, sv, cv_solver_get_method(sv), st) < 0) return -1;
  int any_exact = 0;
  for (int i = 0; i < s->n; i++) any_exact |= s->exact[i] >= 0;
  if (adaptive) {
    /* the rounds' own estimate (theory HP-2); with --tol always, and the degrees */
    double est = cv_solver_get_error_estimate(sv);
    r->has_err_est = (adaptive == 2 || !any_exact) && isfinite(est);
    r->err_est = est;
    r->has_degrees = adaptive == 2;
    return 0;
  }
  return any_exact ? 0 : cli_report_estimate(r, sv, p);
}
