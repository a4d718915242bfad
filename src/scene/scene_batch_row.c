/* src/scene/scene_batch_row.c — one row of a batch (cv_batch of calcvar.h): its values
 * through the row tape (theory (B-1)), a problem over the worker's compiled clones, the
 * solve (warm start, theory (B-2)), and what the row reports. Runs on the worker's
 * thread: it reads the shared DAG and tapes and writes only the worker's own state.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cv_reuse.h"
#include "core/cv_table_internal.h"
#include "scene/scene_batch_internal.h"

/* Parameter values of a row into inst (every parameter: given ones from the row, the
 * others from their definitions) and everything computed from them, by the row tape.
 * rv, rw: the tape's outputs and work. The checks and messages of scene_set_parameters. */
int sc_batch_set_row(const cv_batch *b, scene *inst, double *pv, double *rv, double *rw,
                     const double *row, char *err, size_t errlen) {
  int n = inst->n, np = b->np;
  const double *in[1 + 2 * n + np];
  double *out[b->nrowt];
  for (int q = 0; q < 1 + 2 * n + np; q++) in[q] = NULL;
  for (int c = 0; c < b->ncols; c++) {
    pv[b->col[c]] = row[c];
    in[1 + 2 * n + b->col[c]] = &row[c];
  }
  for (int q = 0; q < b->nrowt; q++) out[q] = rv + q;
  ex_tape_eval(b->rowt, 1, in, out, rw);
  int k = 0;
  for (int j = 0; j < np; j++) {
    inst->params[j].value = rv[k++];
    if (!isfinite(inst->params[j].value)) {
      snprintf(err, errlen, "%s: parameter '%s' is not a finite number (%g)", inst->file,
               inst->params[j].name, inst->params[j].value);
      return -1;
    }
  }
  inst->a = rv[k++];
  inst->b = rv[k++];
  if (!(inst->a < inst->b)) {
    snprintf(err, errlen, "%s: interval needs a < b, got a = %.17g, b = %.17g", inst->file, inst->a,
             inst->b);
    return -1;
  }
  for (int i = 0; i < n; i++)
    for (int end = 0; end < 2; end++)
      if (!inst->bc[i].free_end[end]) {
        inst->bc[i].value[end] = rv[k++];
        if (!isfinite(inst->bc[i].value[end])) {
          snprintf(err, errlen, "%s:%d: [boundary] %s at %s is not a finite number", inst->file,
                   inst->bc[i].line, inst->unknowns[i], end ? "b" : "a");
          return -1;
        }
      }
  for (int q = 0; q < inst->nints; q++) {
    inst->ints[q].value = rv[k++];
    if (!isfinite(inst->ints[q].value)) {
      snprintf(err, errlen, "%s:%d: [integrals] %s: the value c is not a finite number", inst->file,
               inst->ints[q].line, inst->ints[q].name);
      return -1;
    }
  }
  if (inst->has_exact_action) inst->exact_action = rv[k++];
  for (int i = 0; inst->sbc && i < n; i++) /* slopes (the row tape's last outputs) */
    for (int end = 0; end < 2 && inst->sbc[i].line; end++)
      if (!inst->sbc[i].free_end[end] && !isfinite(inst->sbc[i].value[end] = rv[k++])) {
        snprintf(err, errlen, "%s:%d: [boundary] %s' at %s is not a finite number", inst->file,
                 inst->sbc[i].line, inst->unknowns[i], end ? "b" : "a");
        return -1;
      }
  return 0;
}

cv_status cv_batch_check_row(cv_batch *b, const double *row, char *err, size_t errlen) {
  if (!b || (b->ncols > 0 && !row)) return CVAR_EINVAL;
  double *pv = cv_calloc((size_t)b->np + 1, sizeof *pv);
  double *rv = cv_malloc(((size_t)b->nrowt + 1) * sizeof *rv);
  double *rw = cv_malloc((ex_tape_work_size(b->rowt, 1) + 1) * sizeof *rw);
  int rc = pv && rv && rw ? sc_batch_set_row(b, b->check, pv, rv, rw, row, err, errlen) : -2;
  cv_free(pv);
  cv_free(rv);
  cv_free(rw);
  if (rc == -2) return CVAR_ENOMEM;
  return rc < 0 ? CVAR_EINVAL : CVAR_OK;
}

/* The phase condition's constant takes the guess of at most this many unknowns at once. */
#define CV_BATCH_MAX_UNKNOWNS 64

/* A problem over the worker's clones, ends and integral constants of its instance. */
cv_problem *sc_batch_row_problem(const cv_batch *b, worker *w) {
  const scene *s = w->inst;
  cv_problem *p = cv_problem_new(s->n, s->a, s->b, NULL);
  if (!p) return NULL;
  for (int i = 0; i < s->nparams; i++) w->pv[i] = s->params[i].value;
  ex_integrand_set_params(w->F, w->pv);
  int bad = cv_problem_set_integrand(p, ex_integrand_eval, w->F) != CVAR_OK;
  /* a table's note ("the path left the grid of table ...") leads a failed row's message,
   * as in scene_problem.c */
  if (!bad && ex_integrand_has_tables(w->F))
    bad = cv_problem_add_note(p, ex_integrand_note, w->F) != CVAR_OK;
  if (!bad && b->njumps > 0)
    bad = cv_problem_set_smoothing(p, sc_set_smoothing_width, w->F, b->njumps) != CVAR_OK;
  for (int i = 0; i < s->n && !bad; i++)
    for (int end = 0; end < 2 && !bad; end++)
      bad = (s->bc[i].free_end[end]
                 ? cv_problem_set_free_end(p, i, end)
                 : cv_problem_set_end_value(p, i, end, s->bc[i].value[end])) != CVAR_OK;
  for (int i = 0; i < s->n && !bad && s->c1; i++) { /* second order: C1 elements, slopes */
    bad = s->order2[i] && cv_problem_set_second_order(p, i) != CVAR_OK;
    for (int end = 0; end < 2 && !bad && s->sbc && s->sbc[i].line; end++)
      bad = !s->sbc[i].free_end[end] &&
            cv_problem_set_end_slope(p, i, end, s->sbc[i].value[end]) != CVAR_OK;
  }
  for (int k = 0; k < s->ncons && !bad; k++) {
    ex_integrand_set_params(w->cons[k], w->pv);
    bad = cv_problem_add_constraint(p, ex_integrand_eval_constraint, w->cons[k], NULL) != CVAR_OK ||
          cv_problem_set_constraint_sense(p, k, s->cons[k].sense) != CVAR_OK;
    if (!bad && ex_integrand_has_tables(w->cons[k]))
      bad = cv_problem_add_note(p, ex_integrand_note, w->cons[k]) != CVAR_OK;
  }
  for (int k = 0; k < s->nints && !bad; k++) {
    ex_integrand_set_params(w->ints[k], w->pv);
    bad = cv_problem_add_integral(p, ex_integrand_eval, w->ints[k], s->ints[k].value, NULL) !=
          CVAR_OK;
    if (!bad && ex_integrand_has_tables(w->ints[k]))
      bad = cv_problem_add_note(p, ex_integrand_note, w->ints[k]) != CVAR_OK;
  }
  /* periodic unknowns and the phase condition, after [integrals] as in scene_problem.c
   * (PB-1, PB-2); the condition's constant from this row's guess at the ends */
  for (int i = 0; i < s->n && !bad; i++)
    bad = s->bc[i].periodic && cv_problem_set_periodic(p, i, s->bc[i].shift, NULL) != CVAR_OK;
  if (w->phase && !bad) {
    double ab[2] = {s->a, s->b}, g[2 * CV_BATCH_MAX_UNKNOWNS], c = 0.0;
    ex_integrand_set_params(w->phase, w->pv);
    bad = s->n > CV_BATCH_MAX_UNKNOWNS || sc_batch_guess(2, ab, g, w) != 0;
    for (int i = 0; i < s->n && !bad; i++)
      c += 0.5 * (g[2 * i + 1] * g[2 * i + 1] - g[2 * i] * g[2 * i]);
    bad = bad || cv_problem_add_integral(p, ex_integrand_eval, w->phase, c, NULL) != CVAR_OK;
  }
  if (!bad) bad = scene_problem_set_ends(s, p, NULL, 0) < 0; /* [ends] (scene_ends.c) */
  if (bad) {
    cv_problem_free(p);
    return NULL;
  }
  return p;
}

/* The parameter batches w->pb (one per parameter, each its value repeated) of the
 * parameters a tape reads (used[j]), filled for the first min(m, QBATCH) points only: a
 * row's reports need a few points of a few parameters, not whole batches of all. */
static void fill_params(worker *w, int m, const unsigned char *used) {
  const scene *s = w->inst;
  int mm = m < QBATCH ? m : QBATCH;
  for (int j = 0; j < s->nparams; j++)
    if (used[j])
      for (int k = 0; k < mm; k++) w->pb[(size_t)j * QBATCH + k] = s->params[j].value;
}

/* cv_guess_fn over the compiled [guess] tape; the default (the straight line between
 * fixed ends, SCENES.md [guess]) for unknowns without one. user: the worker's context. */
int sc_batch_guess(int m, const double *x, double *y, void *user) {
  worker *w = user;
  const cv_batch *b = w->owner;
  const scene *s = w->inst;
  int n = s->n, np = b->np;
  const double *in[1 + 2 * n + np];
  double *out[b->nguess + 1];
  for (int q = 0; q < 1 + 2 * n + np; q++) in[q] = NULL;
  fill_params(w, m, b->guess_used);
  for (int j = 0; j < np; j++) in[1 + 2 * n + j] = w->pb + (size_t)j * QBATCH;
  for (int k0 = 0; k0 < m; k0 += QBATCH) {
    int mm = m - k0 < QBATCH ? m - k0 : QBATCH;
    in[0] = x + k0;
    for (int i = 0; i < n; i++) {
      double *yi = y + (size_t)i * m + k0;
      if (b->guess_of[i] >= 0) {
        out[b->guess_of[i]] = yi;
        continue;
      }
      const sc_boundary *bc = &s->bc[i];
      for (int k = 0; k < mm; k++) {
        double t = (x[k0 + k] - s->a) / (s->b - s->a);
        yi[k] = !bc->free_end[0] && !bc->free_end[1]
                    ? bc->value[0] + t * (bc->value[1] - bc->value[0])
                : !bc->free_end[0] ? bc->value[0]
                : !bc->free_end[1] ? bc->value[1]
                                   : 0.0;
      }
    }
    if (b->guesst) ex_tape_eval(b->guesst, mm, in, out, w->gw);
  }
  return 0;
}

/* The [report] integrals (sum of w K over the quadrature points) into out[0..nreports-1]. */
static int eval_reports(const cv_batch *b, worker *w, double *out) {
  const scene *s = w->inst;
  int n = s->n, np = b->np, nq = cv_solver_get_num_qpoints(w->sv);
  if (nq <= 0) return -1;
  size_t q = (size_t)nq;
  if (q > w->cap) {
    cv_free(w->qx), cv_free(w->qw), cv_free(w->qy), cv_free(w->qdy), cv_free(w->qv);
    cv_free(w->qd2y);
    w->qd2y = s->c1 ? cv_malloc(q * n * sizeof *w->qd2y) : NULL;
    w->qx = cv_malloc(q * sizeof *w->qx);
    w->qw = cv_malloc(q * sizeof *w->qw);
    w->qy = cv_malloc(q * n * sizeof *w->qy);
    w->qdy = cv_malloc(q * n * sizeof *w->qdy);
    w->qv = cv_malloc((size_t)QBATCH * s->nreports * sizeof *w->qv);
    w->cap = w->qx && w->qw && w->qy && w->qdy && w->qv && (!s->c1 || w->qd2y) ? q : 0;
    if (!w->cap) return -1;
  }
  if (cv_solver_get_qpoints2(w->sv, w->qx, w->qw, w->qy, w->qdy, w->qd2y) != CVAR_OK) return -1;
  int ns = s->c1 ? sc_d2_slot(s, n) : 1 + 2 * n + np;
  const double *in[ns];
  for (int k = 0; k < ns; k++) in[k] = NULL;
  double *o[s->nreports];
  fill_params(w, nq, b->rep_used);
  for (int j = 0; j < np; j++) in[1 + 2 * n + j] = w->pb + (size_t)j * QBATCH;
  for (int r = 0; r < s->nreports; r++) {
    out[r] = 0.0;
    o[r] = w->qv + (size_t)r * QBATCH;
  }
  for (int k0 = 0; k0 < nq; k0 += QBATCH) {
    int m = nq - k0 < QBATCH ? nq - k0 : QBATCH;
    in[0] = w->qx + k0;
    for (int i = 0; i < n; i++) {
      in[1 + i] = w->qy + (size_t)i * q + k0;
      in[1 + n + i] = w->qdy + (size_t)i * q + k0;
      if (s->c1) in[sc_d2_slot(s, i)] = w->qd2y + (size_t)i * q + k0;
    }
    ex_tape_eval(b->rep, m, in, o, w->tw);
    for (int r = 0; r < s->nreports; r++)
      for (int k = 0; k < m; k++) out[r] += w->qw[k0 + k] * o[r][k];
  }
  return 0;
}

/* Max nodal error against [exact]; NaN when it cannot be computed. */
static double nodal_error(worker *w) {
  const scene *s = w->inst;
  int nn = cv_solver_get_num_nodes(w->sv), n = s->n;
  double *x = cv_malloc((size_t)nn * sizeof *x), *y = cv_malloc((size_t)nn * n * sizeof *y);
  double *ex = cv_malloc((size_t)nn * n * sizeof *ex), e = 0.0;
  if (!x || !y || !ex || cv_solver_get_nodes(w->sv, x) != CVAR_OK ||
      cv_solver_get_values(w->sv, y) != CVAR_OK || scene_eval_exact(s, nn, x, ex) < 0)
    e = NAN;
  for (int i = 0; i < n && isfinite(e); i++)
    if (s->exact[i] >= 0)
      for (int j = 0; j < nn; j++) {
        double d = fabs(y[(size_t)j * n + i] - ex[(size_t)i * nn + j]);
        e = d > e || !isfinite(d) ? d : e;
      }
  cv_free(x);
  cv_free(y);
  cv_free(ex);
  return e;
}

/* A row solved without --tol, --adapt or [exact] gets the estimate `solve` reports (theory
 * HP-2: one enriched solve from the row's solution), or, when that gives no bound (HP-3),
 * none and the reason in why. */
static void plain_estimate(worker *w, const cv_problem *p, cv_batch_result *r, char *why,
                           size_t len) {
  double ev;
  if (cv_solver_estimate_error(w->sv, p, &r->error_estimate, &ev, why, len) != CVAR_OK ||
      !isfinite(r->error_estimate)) {
    r->error_estimate = NAN;
    if (!why[0]) snprintf(why, len, "the error estimate is not finite");
  } else {
    why[0] = '\0';
  }
}

/* The start of a warm row (theory (B-2)): the previous solution, shifted by the line that
 * moves its fixed end values onto this row's (node by node on the same layout, the line
 * taken at each node's place: a line in the node's number instead bends the shift
 * wherever the nodes are not evenly spaced — Gauss-Lobatto nodes of degree 8 crowd at the
 * element ends — and a large shift, a ray fan turning from one side to the other, then
 * started Newton from a wavy path that left the velocity grid). */
static int warm_start(worker *w) {
  const scene *s = w->inst;
  int n = s->n, nn = w->prev_len / n;
  double *y = cv_malloc((size_t)w->prev_len * sizeof *y);
  if (!y) return -1;
  for (int j = 0; j < nn; j++) {
    double t = w->prev_u ? w->prev_u[j] : nn > 1 ? (double)j / (nn - 1) : 0.0;
    for (int i = 0; i < n; i++) {
      double da = s->bc[i].free_end[0] ? 0.0 : s->bc[i].value[0] - w->prev_end[i];
      double db = s->bc[i].free_end[1] ? 0.0 : s->bc[i].value[1] - w->prev_end[n + i];
      y[(size_t)j * n + i] = w->prev[(size_t)j * n + i] + (1 - t) * da + t * db;
    }
  }
  cv_status st = cv_solver_set_start(w->sv, w->prev_len, y);
  cv_free(y);
  return st == CVAR_OK ? 0 : -1;
}

/* --tol (theory HP-9): keep the mesh this row hands to the next one on this worker (its
 * own final mesh, or a coarser one when it is finer than tol needs) and, for --warm, the
 * solution at that mesh's nodes. Without them the next row starts as `solve` does. */
static void keep_mesh(const cv_batch *b, worker *w, int row) {
  int E = 0, *deg = NULL, coarsened = 0;
  double *t = NULL, *y = NULL;
  cv_free(w->hp_t);
  cv_free(w->hp_deg);
  w->hp_t = NULL, w->hp_deg = NULL, w->hp_E = 0;
  w->prev_row = -2;
  if (cv_reuse_mesh(w->sv, &E, &t, &deg, b->warm ? &y : NULL, &coarsened) != CVAR_OK) return;
  w->hp_E = E, w->hp_t = t, w->hp_deg = deg;
  if (!y) return;
  const scene *s = w->inst;
  int len = 1;
  for (int e = 0; e < E; e++) len += deg[e];
  cv_free(w->prev);
  cv_free(w->prev_u);
  w->prev = y;
  w->prev_len = len * s->n;
  if ((w->prev_u = cv_malloc((size_t)len * sizeof *w->prev_u)))
    cv_reuse_node_fractions(E, t, deg, w->prev_u);
  for (int i = 0; i < s->n; i++) {
    w->prev_end[i] = s->bc[i].value[0];
    w->prev_end[s->n + i] = s->bc[i].value[1];
  }
  w->prev_row = row;
}

static void keep_for_warm(worker *w, int row) {
  const scene *s = w->inst;
  int len = cv_solver_get_num_nodes(w->sv) * s->n;
  if (len <= 0) return;
  if (len != w->prev_len || !w->prev_u) {
    cv_free(w->prev);
    cv_free(w->prev_u);
    w->prev = cv_malloc((size_t)len * sizeof *w->prev);
    w->prev_u = cv_malloc((size_t)(len / s->n) * sizeof *w->prev_u);
    w->prev_len = w->prev ? len : 0;
  }
  if (!w->prev || cv_solver_get_values(w->sv, w->prev) != CVAR_OK) {
    w->prev_row = -2;
    return;
  }
  if (w->prev_u && cv_solver_get_nodes(w->sv, w->prev_u) == CVAR_OK) {
    int nn = len / s->n;
    double a = w->prev_u[0], L = w->prev_u[nn - 1] - a;
    for (int j = 0; j < nn; j++) w->prev_u[j] = L > 0 ? (w->prev_u[j] - a) / L : 0.0;
    w->prev_u[0] = 0.0, w->prev_u[nn - 1] = 1.0;
  } else {
    cv_free(w->prev_u);
    w->prev_u = NULL;
  }
  for (int i = 0; i < s->n; i++) {
    w->prev_end[i] = s->bc[i].value[0];
    w->prev_end[s->n + i] = s->bc[i].value[1];
  }
  w->prev_row = row;
}

/* Append text to buf (capacity cap, length *k), truncating; buf stays terminated. */
static void put(char *buf, size_t cap, size_t *k, const char *text) {
  size_t len = strlen(text);
  if (*k + 1 >= cap) return;
  if (len > cap - 1 - *k) len = cap - 1 - *k;
  memcpy(buf + *k, text, len);
  *k += len;
  buf[*k] = '\0';
}

static void put_int(char *buf, size_t cap, size_t *k, int v) {
  char d[16];
  int i = (int)sizeof d - 1;
  unsigned u = v < 0 ? 0U - (unsigned)v : (unsigned)v;
  d[i] = '\0';
  do d[--i] = (char)('0' + u % 10);
  while ((u /= 10) > 0);
  if (v < 0) d[--i] = '-';
  put(buf, cap, k, d + i);
}

/* The row's sentence, as `solve` words it. Built by copies: snprintf costs a few thousand
 * instructions a call, a noticeable part of a small row. */
static void compose_message(cv_batch_result *r, const cv_solver *sv, int morse, int nfree,
                            int degenerate, const char *note) {
  const char *detail = cv_solver_last_error(sv);
  size_t cap = sizeof r->message, k = 0;
  r->message[0] = '\0';
  if (r->status != CVAR_OK) {
    put(r->message, cap, &k, detail && detail[0] ? detail : cv_strerror(r->status));
  } else {
    put(r->message, cap, &k, "Converged in ");
    put_int(r->message, cap, &k, r->iterations);
    put(r->message, cap, &k, r->iterations == 1 ? " iteration" : " iterations");
    const char *kind = degenerate       ? "degenerate"
                       : morse == 0     ? "minimum"
                       : morse == nfree ? "maximum"
                                        : "saddle";
    if (morse >= 0 && degenerate) {
      put(r->message, cap, &k, "; the Hessian is degenerate there.");
    } else if (morse >= 0) {
      put(r->message, cap, &k, " to a ");
      put(r->message, cap, &k, kind);
      put(r->message, cap, &k, " of the action (Morse index ");
      put_int(r->message, cap, &k, morse);
      put(r->message, cap, &k, ").");
    } else {
      put(r->message, cap, &k, ".");
    }
    if (detail && detail[0] && strncmp(detail, "converged in ", 13) != 0) {
      char first[3] = {
          ' ', detail[0] >= 'a' && detail[0] <= 'z' ? detail[0] - 'a' + 'A' : detail[0], '\0'};
      put(r->message, cap, &k, first);
      put(r->message, cap, &k, detail + 1);
      put(r->message, cap, &k, ".");
    }
  }
  if (note) {
    put(r->message, cap, &k, " ");
    put(r->message, cap, &k, note);
  }
}

/* Solve row number `row` (its values `vals`) on worker w into r. */
void sc_batch_solve_row(cv_batch *b, worker *w, int row, const double *vals, cv_batch_result *r) {
  double t0 = sc_batch_now();
  double *outputs = r->outputs;
  memset(r, 0, sizeof *r);
  r->outputs = outputs;
  r->action = r->error_max_nodal = r->error_estimate = NAN;
  r->morse_index = -1;
  for (int k = 0; outputs && k < b->nout; k++) outputs[k] = NAN;
  char err[400], why[400] = "";
  cv_problem *p = NULL;
  const char *note = NULL;
  if (sc_batch_set_row(b, w->inst, w->pv, w->rv, w->rw, vals, err, sizeof err) < 0) {
    r->status = CVAR_EINVAL;
    snprintf(r->message, sizeof r->message, "%s", err);
    goto done;
  }
  if (!(p = sc_batch_row_problem(b, w))) {
    r->status = CVAR_ENOMEM;
    snprintf(r->message, sizeof r->message, "out of memory while setting up the problem");
    goto done;
  }
  if (b->nguess > 0) cv_problem_set_guess(p, sc_batch_guess, w);
  if (scene_solver_configure(w->inst, w->sv, err, sizeof err) != CVAR_OK) {
    r->status = CVAR_EINVAL;
    snprintf(r->message, sizeof r->message, "%s", err);
    goto done;
  }
  int tol = w->inst->tol > 0, reuse = tol && w->hp_E > 0;
  if (reuse && cv_reuse_set_start(w->sv, w->hp_E, w->hp_t, w->hp_deg) != CVAR_OK) {
    reuse = 0; /* the scene's own start mesh, as configured */
    if (scene_solver_configure(w->inst, w->sv, err, sizeof err) != CVAR_OK) {
      r->status = CVAR_EINVAL;
      snprintf(r->message, sizeof r->message, "%s", err);
      goto done;
    }
  }
  /* a warm start follows the previous row on this worker; under --tol on the mesh that row
   * handed on (HP-9), whose nodes its values are at */
  int warm = b->warm && w->inst->adapt <= 0 && (!tol || reuse) && w->prev_row == row - 1 &&
             w->prev_len > 0;
  cv_solver_set_start(w->sv, 0, NULL);
  if (warm && warm_start(w) < 0) warm = 0;
  cv_status st = cv_solve(w->sv, p);
  if ((warm || reuse) && st != CVAR_OK) {
    /* the neighbour's solution or mesh led astray: the scene's own start, as `solve` would */
    char failed[64];
    snprintf(failed, sizeof failed, "%s", cv_status_name(st));
    cv_solver_set_start(w->sv, 0, NULL);
    if (reuse && scene_solver_configure(w->inst, w->sv, err, sizeof err) != CVAR_OK) {
      r->status = CVAR_EINVAL;
      snprintf(r->message, sizeof r->message, "%s", err);
      goto done;
    }
    st = cv_solve(w->sv, p);
    static _Thread_local char nb[200];
    snprintf(nb, sizeof nb,
             "(Started from the previous row's %s, the solve failed (%s); "
             "solved from the scene's %s.)",
             warm ? "solution" : "mesh", failed, reuse ? "mesh and guess" : "guess");
    warm = 0, reuse = 0;
    note = nb;
  }
  r->warm = warm;
  r->status = st;
  r->iterations = cv_solver_get_num_iterations(w->sv);
  int morse = -1, nfree = 0, degenerate = 0;
  double xs, alpha;
  if (st == CVAR_OK &&
      scene_interior_singularity_of(w->inst, w->sv, b->nsing, b->sing, &xs, &alpha) == 1) {
    /* as `solve` does: a finite discrete action of an infinite one (theory (SG-1)) */
    r->status = CVAR_ENONFINITE;
    snprintf(r->message, sizeof r->message,
             "the integrand is singular at %s = %.6g inside "
             "the interval: along the path |F| grows like |%s - %.6g|^(-%.2f), so the "
             "action is infinite and the discrete answer (which changes with the mesh) is "
             "no stationary path",
             w->inst->variable, xs, w->inst->variable, xs, alpha);
    goto done;
  }
  if (st == CVAR_OK) {
    r->has_result = 1;
    r->action = cv_solver_get_action(w->sv);
    if (w->inst->method == CVAR_METHOD_NEWTON) {
      morse = cv_solver_get_morse_index(w->sv);
      nfree = cv_solver_get_num_free(w->sv);
      degenerate = cv_solver_get_degenerate(w->sv);
      r->morse_index = morse;
    }
    if (b->any_exact) r->error_max_nodal = nodal_error(w);
    if (w->inst->adapt > 0 || w->inst->tol > 0)
      r->error_estimate = cv_solver_get_error_estimate(w->sv);
    else if (!b->any_exact)
      plain_estimate(w, p, r, why, sizeof why);
    if (outputs) {
      if (b->rep && eval_reports(b, w, outputs) < 0)
        for (int k = 0; k < w->inst->nreports; k++) outputs[k] = NAN;
      for (int k = 0; k < w->inst->nints; k++)
        if (cv_solver_get_multiplier(w->sv, k, &outputs[w->inst->nreports + k]) != CVAR_OK)
          outputs[w->inst->nreports + k] = NAN;
    }
    if (tol)
      keep_mesh(b, w, row);
    else if (b->warm)
      keep_for_warm(w, row);
  }
  compose_message(r, w->sv, morse, nfree, degenerate, note);
  if (why[0]) { /* as `solve` says it (HP-3) */
    size_t k = strlen(r->message);
    put(r->message, sizeof r->message, &k, " no error estimate: ");
    put(r->message, sizeof r->message, &k, why);
    put(r->message, sizeof r->message, &k, ".");
  }
done:
  cv_problem_free(p);
  r->time_s = sc_batch_now() - t0;
}

cv_problem *scene_batch_problem(cv_batch *b, const double *row, const scene **inst, char *err,
                                size_t errlen) {
  if (err && errlen) err[0] = '\0';
  if (!b || sc_batch_workers(b, 1) != CVAR_OK) {
    snprintf(err, errlen, "out of memory");
    return NULL;
  }
  worker *w = &b->w[0];
  if (sc_batch_set_row(b, w->inst, w->pv, w->rv, w->rw, row, err, errlen) < 0) return NULL;
  cv_problem *p = sc_batch_row_problem(b, w);
  if (p && b->nguess > 0) cv_problem_set_guess(p, sc_batch_guess, w);
  if (!p) snprintf(err, errlen, "%s: out of memory while setting up the problem", b->s->file);
  *inst = w->inst;
  return p;
}
