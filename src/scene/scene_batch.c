/* src/scene/scene_batch.c — many parameter sets on one compiled scene (cv_batch of
 * calcvar.h): the engine of `calcvar batch`. SPDX-License-Identifier: MIT
 *
 * The scene is loaded once with its parameters as tape inputs (scene.h) and its integrand,
 * constraints, integrals and [report] integrands are compiled once. Each thread (a
 * "worker") owns a scene instance (its parameter values, interval and end values), clones
 * of the compiled integrands (their own work buffers over the shared read-only tapes) and
 * one cv_solver, reused from row to row. A row is then: set the parameters (re-evaluating
 * the constant expressions of them: interval, end values, integral constants), build a
 * cv_problem over the clones (no compilation), solve, read the results. No row touches
 * the expression DAG, so rows run concurrently (docs/scale-out.md).
 */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "expr/ex_integrand.h"
#include "scene/scene_batch.h"
#include "scene/scene_internal.h"

enum { QBATCH = EX_INTEGRAND_BATCH };

typedef struct {
  const struct cv_batch *owner;
  scene *inst;
  ex_integrand *F, **cons, **ints; /* clones of the batch's compiled objects */
  cv_solver *sv;
  double *pv;                      /* parameter values of the row */
  double *tw, *pb;                 /* report tape work; parameter batches */
  size_t cap;                      /* quadrature points the buffers below hold */
  double *qx, *qw, *qy, *qdy, *qv;
  double *prev;                    /* warm start: last converged nodal values */
  int prev_len, prev_row;
  double *prev_end;                /* its end values [2n] */
  double *rv, *rw;                 /* row tape outputs and work */
  double *gv, *gw;                 /* guess tape outputs (one batch each) and work */
} worker;

struct cv_batch {
  scene *s;
  int n, np;
  unsigned need;
  ex_integrand *F, **cons, **ints;
  ex_tape *rep;                    /* [report] integrands, nslots 1 + 2n + np */
  int nout;
  char **outname;
  int ncols;
  int *col;                        /* parameter index of each column */
  unsigned char *given;            /* given[i]: some column sets parameter i */
  int nthreads, warm, any_exact, nworkers;
  /* The row tape: every value that follows the parameters (their values, then a, b, the
   * fixed end values, the [integrals] constants, the exact action) as expressions of the
   * given parameters only, evaluated at one point per row (theory: none; plain algebra). */
  ex_tape *rowt;
  int nrowt;
  /* The [guess] expressions compiled once (unknowns without one: the default line). */
  ex_tape *guesst;
  int nguess;
  int *guess_of;                   /* tape output of unknown i's guess, or -1 */
  worker *w;
  scene *check;                    /* instance for cv_batch_check_row */
};

static double now(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void worker_free(cv_batch *b, worker *w)
{
  ex_integrand_free(w->F);
  for (int k = 0; w->cons && k < b->s->ncons; k++)
    ex_integrand_free(w->cons[k]);
  for (int k = 0; w->ints && k < b->s->nints; k++)
    ex_integrand_free(w->ints[k]);
  cv_free(w->cons);
  cv_free(w->ints);
  cv_solver_free(w->sv);
  scene_free(w->inst);
  cv_free(w->pv);
  cv_free(w->tw);
  cv_free(w->pb);
  cv_free(w->qx);
  cv_free(w->qw);
  cv_free(w->qy);
  cv_free(w->qdy);
  cv_free(w->qv);
  cv_free(w->prev);
  cv_free(w->prev_end);
  cv_free(w->rv);
  cv_free(w->rw);
  cv_free(w->gv);
  cv_free(w->gw);
  memset(w, 0, sizeof *w);
}

static int worker_init(cv_batch *b, worker *w)
{
  const scene *s = b->s;
  memset(w, 0, sizeof *w);
  w->owner = b;
  w->prev_row = -2;
  w->inst = scene_instance_new(s);
  w->F = ex_integrand_clone(b->F);
  w->cons = cv_calloc((size_t)s->ncons + 1, sizeof *w->cons);
  w->ints = cv_calloc((size_t)s->nints + 1, sizeof *w->ints);
  w->sv = cv_solver_new(NULL);
  w->pv = cv_calloc((size_t)b->np + 1, sizeof *w->pv);
  w->pb = cv_malloc(((size_t)b->np * QBATCH + 1) * sizeof *w->pb);
  w->tw = b->rep ? cv_malloc((ex_tape_work_size(b->rep, QBATCH) + 1) * sizeof *w->tw) : NULL;
  w->prev_end = cv_calloc(2 * (size_t)b->n, sizeof *w->prev_end);
  w->rv = cv_malloc(((size_t)b->nrowt + 1) * sizeof *w->rv);
  w->rw = b->rowt ? cv_malloc((ex_tape_work_size(b->rowt, 1) + 1) * sizeof *w->rw) : NULL;
  w->gv = cv_malloc(((size_t)b->nguess * QBATCH + 1) * sizeof *w->gv);
  w->gw = b->guesst ? cv_malloc((ex_tape_work_size(b->guesst, QBATCH) + 1) * sizeof *w->gw)
                    : NULL;
  if (!w->inst || !w->F || !w->cons || !w->ints || !w->sv || !w->pv || !w->pb ||
      (b->rep && !w->tw) || !w->prev_end || !w->rv || (b->rowt && !w->rw) || !w->gv ||
      (b->guesst && !w->gw))
    return -1;
  for (int k = 0; k < s->ncons; k++)
    if (!(w->cons[k] = ex_integrand_clone(b->cons[k])))
      return -1;
  for (int k = 0; k < s->nints; k++)
    if (!(w->ints[k] = ex_integrand_clone(b->ints[k])))
      return -1;
  return 0;
}

void cv_batch_free(cv_batch *b)
{
  if (!b)
    return;
  for (int t = 0; t < b->nworkers; t++)
    worker_free(b, &b->w[t]);
  cv_free(b->w);
  scene_free(b->check);
  ex_integrand_free(b->F);
  for (int k = 0; b->cons && k < b->s->ncons; k++)
    ex_integrand_free(b->cons[k]);
  for (int k = 0; b->ints && k < b->s->nints; k++)
    ex_integrand_free(b->ints[k]);
  cv_free(b->cons);
  cv_free(b->ints);
  ex_tape_free(b->rep);
  ex_tape_free(b->rowt);
  ex_tape_free(b->guesst);
  cv_free(b->guess_of);
  for (int k = 0; b->outname && k < b->nout; k++)
    cv_free(b->outname[k]);
  cv_free(b->outname);
  cv_free(b->col);
  cv_free(b->given);
  scene_free(b->s);
  cv_free(b);
}

cv_batch *scene_batch_new(scene *s, char *err, size_t errlen)
{
  char msg[400] = "";
  if (err && errlen)
    err[0] = '\0';
  if (!s)
    return NULL;
  if (!s->params_as_inputs) {
    snprintf(err, errlen, "%s: a batch needs the scene loaded with parameters as inputs",
             s->file);
    scene_free(s);
    return NULL;
  }
  cv_batch *b = cv_calloc(1, sizeof *b);
  if (!b) {
    scene_free(s);
    snprintf(err, errlen, "out of memory");
    return NULL;
  }
  b->s = s;
  b->n = s->n;
  b->np = s->nparams;
  b->nthreads = 1;
  b->need = scene_method_need(s->method);
  b->cons = cv_calloc((size_t)s->ncons + 1, sizeof *b->cons);
  b->ints = cv_calloc((size_t)s->nints + 1, sizeof *b->ints);
  b->nout = s->nreports + s->nints;
  b->outname = cv_calloc((size_t)b->nout + 1, sizeof *b->outname);
  b->given = cv_calloc((size_t)b->np + 1, 1);
  b->check = scene_instance_new(s);
  if (!b->cons || !b->ints || !b->outname || !b->given || !b->check)
    goto nomem;
  for (int i = 0; i < s->n; i++)
    b->any_exact |= s->exact[i] >= 0;
  /* Compile once: every expression of the problem with the parameters as inputs. */
  if (!(b->F = ex_integrand_new_params(s->dag, s->n, b->np, s->F, b->need, msg, sizeof msg))) {
    snprintf(err, errlen, "%s:%d: integrand: %s", s->file, s->F_line,
             msg[0] ? msg : "out of memory");
    goto fail;
  }
  for (int k = 0; k < s->ncons; k++)
    if (!(b->cons[k] = ex_integrand_new_params(s->dag, s->n, b->np, s->cons[k].expr, b->need,
                                               msg, sizeof msg))) {
      snprintf(err, errlen, "%s:%d: [constraints] %s: %s", s->file, s->cons[k].line,
               s->cons[k].name, msg[0] ? msg : "out of memory");
      goto fail;
    }
  for (int k = 0; k < s->nints; k++)
    if (!(b->ints[k] = ex_integrand_new_params(s->dag, s->n, b->np, s->ints[k].expr, b->need,
                                               msg, sizeof msg))) {
      snprintf(err, errlen, "%s:%d: [integrals] %s: %s", s->file, s->ints[k].line,
               s->ints[k].name, msg[0] ? msg : "out of memory");
      goto fail;
    }
  if (s->nreports > 0) {
    ex_id *outs = cv_malloc((size_t)s->nreports * sizeof *outs);
    if (!outs)
      goto nomem;
    for (int r = 0; r < s->nreports; r++)
      outs[r] = s->reports[r].expr;
    b->rep = ex_tape_new(s->dag, 1 + 2 * s->n + b->np, s->nreports, outs);
    cv_free(outs);
    if (!b->rep)
      goto nomem;
  }
  b->guess_of = cv_malloc(((size_t)s->n + 1) * sizeof *b->guess_of);
  if (!b->guess_of)
    goto nomem;
  {
    ex_id *outs = cv_malloc(((size_t)s->n + 1) * sizeof *outs);
    if (!outs)
      goto nomem;
    for (int i = 0; i < s->n; i++) {
      b->guess_of[i] = s->guess[i] >= 0 ? b->nguess : -1;
      if (s->guess[i] >= 0)
        outs[b->nguess++] = s->guess[i];
    }
    if (b->nguess > 0)
      b->guesst = ex_tape_new(s->dag, 1 + 2 * s->n + b->np, b->nguess, outs);
    cv_free(outs);
    if (b->nguess > 0 && !b->guesst)
      goto nomem;
  }
  if (cv_batch_set_columns(b, 0, NULL, err, errlen) != CVAR_OK)
    goto nomem;
  for (int r = 0; r < s->nreports; r++)
    if (!(b->outname[r] = sc_strdup(s->reports[r].name)))
      goto nomem;
  for (int k = 0; k < s->nints; k++) {
    size_t len = strlen(s->ints[k].name) + 4;
    if (!(b->outname[s->nreports + k] = cv_malloc(len)))
      goto nomem;
    snprintf(b->outname[s->nreports + k], len, "mu_%s", s->ints[k].name);
  }
  return b;
nomem:
  snprintf(err, errlen, "%s: out of memory", s->file);
fail:
  cv_batch_free(b);
  return NULL;
}

cv_batch *cv_batch_new(const char *scene_path, char *err, size_t errlen)
{
  if (!scene_path) {
    snprintf(err, errlen, "no scene file given");
    return NULL;
  }
  scene *s = scene_load_file_inputs(scene_path, 0, NULL, err, errlen);
  return s ? scene_batch_new(s, err, errlen) : NULL;
}

const scene *scene_batch_scene(const cv_batch *b) { return b ? b->s : NULL; }
int cv_batch_num_parameters(const cv_batch *b) { return b ? b->np : 0; }
const char *cv_batch_parameter_name(const cv_batch *b, int i)
{
  return b && i >= 0 && i < b->np ? b->s->params[i].name : NULL;
}
int cv_batch_num_outputs(const cv_batch *b) { return b ? b->nout : 0; }
const char *cv_batch_output_name(const cv_batch *b, int k)
{
  return b && k >= 0 && k < b->nout ? b->outname[k] : NULL;
}

/* The row tape (theory (B-1)) for the current given[]: a parameter that no column
 * gives is replaced by its definition, recursively, so the outputs depend only on the
 * given parameters' slots. Adds nodes to the DAG: single-threaded, before any worker. */
static int build_row_tape(cv_batch *b)
{
  scene *s = b->s;
  int n = s->n, np = b->np, rc = -1;
  int cap = np + 2 + 2 * n + s->nints + 1;
  ex_id *def = cv_malloc(((size_t)np + 1) * sizeof *def);
  ex_id *outs = cv_malloc((size_t)cap * sizeof *outs);
  if (!def || !outs)
    goto done;
  int k = 0;
  for (int j = 0; j < np; j++) {
    ex_id e = b->given[j] ? s->params[j].expr : s->params[j].expr2;
    for (int i = 0; i < j && e >= 0 && !b->given[j]; i++)
      if (!b->given[i] && ex_depends_on(s->dag, e, 1 + 2 * n + i))
        e = ex_subst(s->dag, e, 1 + 2 * n + i, def[i]);
    if ((def[j] = e) < 0)
      goto done;
    outs[k++] = e;
  }
  ex_id targets[2] = {s->a_expr, s->b_expr};
  int nt = 0;
  ex_id *t = outs + k;
  t[nt++] = targets[0];
  t[nt++] = targets[1];
  for (int i = 0; i < n; i++)
    for (int end = 0; end < 2; end++)
      if (!s->bc[i].free_end[end])
        t[nt++] = s->bc[i].expr[end];
  for (int q = 0; q < s->nints; q++)
    t[nt++] = s->ints[q].expr2;
  if (s->has_exact_action)
    t[nt++] = s->exact_action_expr;
  for (int q = 0; q < nt; q++)
    for (int i = 0; i < np && t[q] >= 0; i++)
      if (!b->given[i] && ex_depends_on(s->dag, t[q], 1 + 2 * n + i))
        t[q] = ex_subst(s->dag, t[q], 1 + 2 * n + i, def[i]);
  for (int q = 0; q < nt; q++)
    if (t[q] < 0)
      goto done;
  k += nt;
  ex_tape_free(b->rowt);
  b->rowt = ex_tape_new(s->dag, 1 + 2 * n + np, k, outs);
  b->nrowt = k;
  rc = b->rowt ? 0 : -1;
done:
  cv_free(def);
  cv_free(outs);
  return rc;
}

cv_status cv_batch_set_columns(cv_batch *b, int ncols, const char *const *names, char *err,
                               size_t errlen)
{
  if (err && errlen)
    err[0] = '\0';
  if (!b || ncols < 0 || (ncols > 0 && !names))
    return CVAR_EINVAL;
  if (b->nworkers > 0) { /* workers hold buffers sized for the current row tape */
    snprintf(err, errlen, "the columns are set before the first solve");
    return CVAR_EINVAL;
  }
  int *col = cv_malloc(((size_t)ncols + 1) * sizeof *col);
  if (!col)
    return CVAR_ENOMEM;
  memset(b->given, 0, (size_t)b->np + 1);
  for (int c = 0; c < ncols; c++) {
    col[c] = -1;
    for (int i = 0; i < b->np; i++)
      if (names[c] && strcmp(names[c], b->s->params[i].name) == 0)
        col[c] = i;
    if (col[c] < 0 || b->given[col[c]]) {
      snprintf(err, errlen, col[c] < 0 ? "'%s' is not a parameter of %s"
                                       : "'%s' is given twice", names[c] ? names[c] : "",
               b->s->file);
      cv_free(col);
      memset(b->given, 0, (size_t)b->np + 1);
      return CVAR_EINVAL;
    }
    b->given[col[c]] = 1;
  }
  if (build_row_tape(b) < 0) {
    cv_free(col);
    return CVAR_ENOMEM;
  }
  cv_free(b->col);
  b->col = col;
  b->ncols = ncols;
  return CVAR_OK;
}

cv_status cv_batch_set_threads(cv_batch *b, int nthreads)
{
  if (!b || nthreads < 0 || nthreads > 4096)
    return CVAR_EINVAL;
  if (nthreads == 0) {
    long c = sysconf(_SC_NPROCESSORS_ONLN);
    nthreads = c > 0 ? (int)(c < 4096 ? c : 4096) : 1;
  }
  b->nthreads = nthreads;
  return CVAR_OK;
}

cv_status cv_batch_set_warm_start(cv_batch *b, int on)
{
  if (!b)
    return CVAR_EINVAL;
  b->warm = on != 0;
  return CVAR_OK;
}

cv_status cv_batch_set_mesh(cv_batch *b, int elements, int degree)
{
  if (!b || elements < 0 || degree < 0 || degree > 8)
    return CVAR_EINVAL;
  if (elements)
    b->s->elements = elements;
  if (degree)
    b->s->degree = degree;
  return CVAR_OK;
}

/* Parameter values of a row into inst (every parameter: given ones from the row, the
 * others from their definitions) and everything computed from them, by the row tape.
 * rv, rw: the tape's outputs and work. The checks and messages of scene_set_parameters. */
static int set_row(const cv_batch *b, scene *inst, double *pv, double *rv, double *rw,
                   const double *row, char *err, size_t errlen)
{
  int n = inst->n, np = b->np;
  const double *in[1 + 2 * n + np];
  double *out[b->nrowt];
  for (int q = 0; q < 1 + 2 * n + np; q++)
    in[q] = NULL;
  for (int c = 0; c < b->ncols; c++) {
    pv[b->col[c]] = row[c];
    in[1 + 2 * n + b->col[c]] = &row[c];
  }
  for (int q = 0; q < b->nrowt; q++)
    out[q] = rv + q;
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
    snprintf(err, errlen, "%s: interval needs a < b, got a = %.17g, b = %.17g", inst->file,
             inst->a, inst->b);
    return -1;
  }
  for (int i = 0; i < n; i++)
    for (int end = 0; end < 2; end++)
      if (!inst->bc[i].free_end[end]) {
        inst->bc[i].value[end] = rv[k++];
        if (!isfinite(inst->bc[i].value[end])) {
          snprintf(err, errlen, "%s:%d: [boundary] %s at %s is not a finite number",
                   inst->file, inst->bc[i].line, inst->unknowns[i], end ? "b" : "a");
          return -1;
        }
      }
  for (int q = 0; q < inst->nints; q++) {
    inst->ints[q].value = rv[k++];
    if (!isfinite(inst->ints[q].value)) {
      snprintf(err, errlen, "%s:%d: [integrals] %s: the value c is not a finite number",
               inst->file, inst->ints[q].line, inst->ints[q].name);
      return -1;
    }
  }
  if (inst->has_exact_action)
    inst->exact_action = rv[k++];
  return 0;
}

cv_status cv_batch_check_row(cv_batch *b, const double *row, char *err, size_t errlen)
{
  if (!b || (b->ncols > 0 && !row))
    return CVAR_EINVAL;
  double *pv = cv_calloc((size_t)b->np + 1, sizeof *pv);
  double *rv = cv_malloc(((size_t)b->nrowt + 1) * sizeof *rv);
  double *rw = cv_malloc((ex_tape_work_size(b->rowt, 1) + 1) * sizeof *rw);
  int rc = pv && rv && rw ? set_row(b, b->check, pv, rv, rw, row, err, errlen) : -2;
  cv_free(pv);
  cv_free(rv);
  cv_free(rw);
  if (rc == -2)
    return CVAR_ENOMEM;
  return rc < 0 ? CVAR_EINVAL : CVAR_OK;
}

/* A problem over the worker's clones, ends and integral constants of its instance. */
static cv_problem *row_problem(const cv_batch *b, worker *w)
{
  const scene *s = w->inst;
  cv_problem *p = cv_problem_new(s->n, s->a, s->b, NULL);
  if (!p)
    return NULL;
  for (int i = 0; i < s->nparams; i++)
    w->pv[i] = s->params[i].value;
  ex_integrand_set_params(w->F, w->pv);
  int bad = cv_problem_set_integrand(p, ex_integrand_eval, w->F) != CVAR_OK;
  for (int i = 0; i < s->n && !bad; i++)
    for (int end = 0; end < 2 && !bad; end++)
      bad = (s->bc[i].free_end[end] ? cv_problem_set_free_end(p, i, end)
                                    : cv_problem_set_end_value(p, i, end,
                                                               s->bc[i].value[end])) != CVAR_OK;
  for (int k = 0; k < s->ncons && !bad; k++) {
    ex_integrand_set_params(w->cons[k], w->pv);
    bad = cv_problem_add_constraint(p, ex_integrand_eval_constraint, w->cons[k], NULL) !=
          CVAR_OK;
  }
  for (int k = 0; k < s->nints && !bad; k++) {
    ex_integrand_set_params(w->ints[k], w->pv);
    bad = cv_problem_add_integral(p, ex_integrand_eval, w->ints[k], s->ints[k].value, NULL) !=
          CVAR_OK;
  }
  (void)b;
  if (bad) {
    cv_problem_free(p);
    return NULL;
  }
  return p;
}

/* cv_guess_fn over the compiled [guess] tape; the default (the straight line between
 * fixed ends, SCENES.md [guess]) for unknowns without one. user: the worker's context. */
static int guess_cb(int m, const double *x, double *y, void *user)
{
  worker *w = user;
  const cv_batch *b = w->owner;
  const scene *s = w->inst;
  int n = s->n, np = b->np;
  const double *in[1 + 2 * n + np];
  double *out[b->nguess + 1];
  for (int q = 0; q < 1 + 2 * n + np; q++)
    in[q] = NULL;
  for (int j = 0; j < np; j++) {
    for (int k = 0; k < QBATCH; k++)
      w->pb[(size_t)j * QBATCH + k] = s->params[j].value;
    in[1 + 2 * n + j] = w->pb + (size_t)j * QBATCH;
  }
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
                : !bc->free_end[1] ? bc->value[1] : 0.0;
      }
    }
    if (b->guesst)
      ex_tape_eval(b->guesst, mm, in, out, w->gw);
  }
  return 0;
}

/* The [report] integrals (sum of w K over the quadrature points) into out[0..nreports-1]. */
static int eval_reports(const cv_batch *b, worker *w, double *out)
{
  const scene *s = w->inst;
  int n = s->n, np = b->np, nq = cv_solver_get_num_qpoints(w->sv);
  if (nq <= 0)
    return -1;
  size_t q = (size_t)nq;
  if (q > w->cap) {
    cv_free(w->qx), cv_free(w->qw), cv_free(w->qy), cv_free(w->qdy), cv_free(w->qv);
    w->qx = cv_malloc(q * sizeof *w->qx);
    w->qw = cv_malloc(q * sizeof *w->qw);
    w->qy = cv_malloc(q * n * sizeof *w->qy);
    w->qdy = cv_malloc(q * n * sizeof *w->qdy);
    w->qv = cv_malloc((size_t)QBATCH * s->nreports * sizeof *w->qv);
    w->cap = w->qx && w->qw && w->qy && w->qdy && w->qv ? q : 0;
    if (!w->cap)
      return -1;
  }
  if (cv_solver_get_qpoints(w->sv, w->qx, w->qw, w->qy, w->qdy) != CVAR_OK)
    return -1;
  int ns = 1 + 2 * n + np;
  const double *in[ns];
  double *o[s->nreports];
  for (int j = 0; j < np; j++) {
    for (int k = 0; k < QBATCH; k++)
      w->pb[(size_t)j * QBATCH + k] = s->params[j].value;
    in[1 + 2 * n + j] = w->pb + (size_t)j * QBATCH;
  }
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
    }
    ex_tape_eval(b->rep, m, in, o, w->tw);
    for (int r = 0; r < s->nreports; r++)
      for (int k = 0; k < m; k++)
        out[r] += w->qw[k0 + k] * o[r][k];
  }
  return 0;
}

/* Max nodal error against [exact]; NaN when it cannot be computed. */
static double nodal_error(worker *w)
{
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

/* The start of a warm row (theory (B-2)): the previous solution, shifted by the line that
 * moves its fixed end values onto this row's (node by node on the same layout). */
static int warm_start(worker *w)
{
  const scene *s = w->inst;
  int n = s->n, nn = w->prev_len / n;
  double *y = cv_malloc((size_t)w->prev_len * sizeof *y);
  if (!y)
    return -1;
  for (int j = 0; j < nn; j++) {
    double t = nn > 1 ? (double)j / (nn - 1) : 0.0; /* only the ends need to be exact */
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

static void keep_for_warm(worker *w, int row)
{
  const scene *s = w->inst;
  int len = cv_solver_get_num_nodes(w->sv) * s->n;
  if (len <= 0)
    return;
  if (len != w->prev_len) {
    cv_free(w->prev);
    w->prev = cv_malloc((size_t)len * sizeof *w->prev);
    w->prev_len = w->prev ? len : 0;
  }
  if (!w->prev || cv_solver_get_values(w->sv, w->prev) != CVAR_OK) {
    w->prev_row = -2;
    return;
  }
  for (int i = 0; i < s->n; i++) {
    w->prev_end[i] = s->bc[i].value[0];
    w->prev_end[s->n + i] = s->bc[i].value[1];
  }
  w->prev_row = row;
}

static void compose_message(cv_batch_result *r, const cv_solver *sv, int morse, int nfree,
                            int degenerate, const char *note)
{
  const char *detail = cv_solver_last_error(sv);
  size_t cap = sizeof r->message, k = 0;
  if (r->status != CVAR_OK) {
    k = (size_t)snprintf(r->message, cap, "%s", detail && detail[0] ? detail
                                                                    : cv_strerror(r->status));
  } else {
    k = (size_t)snprintf(r->message, cap, "Converged in %d iteration%s", r->iterations,
                         r->iterations == 1 ? "" : "s");
    const char *kind = degenerate ? "degenerate" : morse == 0 ? "minimum"
                       : morse == nfree ? "maximum" : "saddle";
    if (k < cap && morse >= 0 && degenerate)
      k += (size_t)snprintf(r->message + k, cap - k, "; the Hessian is degenerate there.");
    else if (k < cap && morse >= 0)
      k += (size_t)snprintf(r->message + k, cap - k, " to a %s of the action (Morse index %d).",
                            kind, morse);
    else if (k < cap)
      k += (size_t)snprintf(r->message + k, cap - k, ".");
    if (k < cap && detail && detail[0] && strncmp(detail, "converged in ", 13) != 0)
      k += (size_t)snprintf(r->message + k, cap - k, " %c%s.",
                            detail[0] >= 'a' && detail[0] <= 'z' ? detail[0] - 'a' + 'A'
                                                                 : detail[0],
                            detail + 1);
  }
  if (note && k < cap)
    snprintf(r->message + k, cap - k, " %s", note);
}

/* Solve row number `row` (its values `vals`) on worker w into r. */
static void solve_row(cv_batch *b, worker *w, int row, const double *vals, cv_batch_result *r)
{
  double t0 = now();
  double *outputs = r->outputs;
  memset(r, 0, sizeof *r);
  r->outputs = outputs;
  r->action = r->error_max_nodal = r->error_estimate = NAN;
  r->morse_index = -1;
  for (int k = 0; outputs && k < b->nout; k++)
    outputs[k] = NAN;
  char err[400];
  cv_problem *p = NULL;
  const char *note = NULL;
  if (set_row(b, w->inst, w->pv, w->rv, w->rw, vals, err, sizeof err) < 0) {
    r->status = CVAR_EINVAL;
    snprintf(r->message, sizeof r->message, "%s", err);
    goto done;
  }
  if (!(p = row_problem(b, w))) {
    r->status = CVAR_ENOMEM;
    snprintf(r->message, sizeof r->message, "out of memory while setting up the problem");
    goto done;
  }
  if (b->nguess > 0)
    cv_problem_set_guess(p, guess_cb, w);
  if (scene_solver_configure(w->inst, w->sv, err, sizeof err) != CVAR_OK) {
    r->status = CVAR_EINVAL;
    snprintf(r->message, sizeof r->message, "%s", err);
    goto done;
  }
  int warm = b->warm && w->inst->adapt <= 0 && w->prev_row == row - 1 && w->prev_len > 0;
  cv_solver_set_start(w->sv, 0, NULL);
  if (warm && warm_start(w) < 0)
    warm = 0;
  cv_status st = cv_solve(w->sv, p);
  if (warm && st != CVAR_OK) {
    /* the neighbour's solution led astray: the scene's own start, as `solve` would */
    char why[64];
    snprintf(why, sizeof why, "%s", cv_status_name(st));
    cv_solver_set_start(w->sv, 0, NULL);
    st = cv_solve(w->sv, p);
    warm = 0;
    static _Thread_local char nb[160];
    snprintf(nb, sizeof nb, "(The warm start from row %d failed (%s); solved from the "
             "scene's guess.)", row, why);
    note = nb;
  }
  r->warm = warm;
  r->status = st;
  r->iterations = cv_solver_get_num_iterations(w->sv);
  int morse = -1, nfree = 0, degenerate = 0;
  if (st == CVAR_OK) {
    r->has_result = 1;
    r->action = cv_solver_get_action(w->sv);
    if (w->inst->method == CVAR_METHOD_NEWTON) {
      morse = cv_solver_get_morse_index(w->sv);
      nfree = cv_solver_get_num_free(w->sv);
      degenerate = cv_solver_get_degenerate(w->sv);
      r->morse_index = morse;
    }
    if (b->any_exact)
      r->error_max_nodal = nodal_error(w);
    if (w->inst->adapt > 0)
      r->error_estimate = cv_solver_get_error_estimate(w->sv);
    if (outputs) {
      if (b->rep && eval_reports(b, w, outputs) < 0)
        for (int k = 0; k < w->inst->nreports; k++)
          outputs[k] = NAN;
      for (int k = 0; k < w->inst->nints; k++)
        if (cv_solver_get_multiplier(w->sv, k, &outputs[w->inst->nreports + k]) != CVAR_OK)
          outputs[w->inst->nreports + k] = NAN;
    }
    if (b->warm)
      keep_for_warm(w, row);
  }
  compose_message(r, w->sv, morse, nfree, degenerate, note);
done:
  cv_problem_free(p);
  r->time_s = now() - t0;
}

/* Make sure workers 0..T-1 exist. */
static cv_status workers(cv_batch *b, int T)
{
  if (T <= b->nworkers)
    return CVAR_OK;
  worker *nw = cv_realloc(b->w, (size_t)T * sizeof *nw);
  if (!nw)
    return CVAR_ENOMEM;
  b->w = nw;
  while (b->nworkers < T) {
    if (worker_init(b, &b->w[b->nworkers]) < 0) {
      worker_free(b, &b->w[b->nworkers]);
      return CVAR_ENOMEM;
    }
    b->nworkers++;
  }
  return CVAR_OK;
}

cv_problem *scene_batch_problem(cv_batch *b, const double *row, const scene **inst,
                                char *err, size_t errlen)
{
  if (err && errlen)
    err[0] = '\0';
  if (!b || workers(b, 1) != CVAR_OK) {
    snprintf(err, errlen, "out of memory");
    return NULL;
  }
  worker *w = &b->w[0];
  if (set_row(b, w->inst, w->pv, w->rv, w->rw, row, err, errlen) < 0)
    return NULL;
  cv_problem *p = row_problem(b, w);
  if (p && b->nguess > 0)
    cv_problem_set_guess(p, guess_cb, w);
  if (!p)
    snprintf(err, errlen, "%s: out of memory while setting up the problem", b->s->file);
  *inst = w->inst;
  return p;
}

typedef struct {
  cv_batch *b;
  int nrows, block;
  const double *rows;
  cv_batch_result *res;
  atomic_int next;
} job;

typedef struct {
  job *j;
  worker *w;
} task;

static void *run(void *arg)
{
  task *t = arg;
  job *j = t->j;
  for (;;) {
    int r0 = atomic_fetch_add(&j->next, j->block);
    if (r0 >= j->nrows)
      break;
    int r1 = r0 + j->block < j->nrows ? r0 + j->block : j->nrows;
    for (int r = r0; r < r1; r++)
      solve_row(j->b, t->w, r, j->rows + (size_t)r * j->b->ncols, &j->res[r]);
  }
  return NULL;
}

cv_status cv_batch_solve(cv_batch *b, int nrows, const double *rows, cv_batch_result *res)
{
  if (!b || nrows < 0 || (nrows > 0 && (!res || (b->ncols > 0 && !rows))))
    return CVAR_EINVAL;
  if (nrows == 0)
    return CVAR_OK;
  int T = b->nthreads < nrows ? b->nthreads : nrows;
  if (workers(b, T) != CVAR_OK)
    return CVAR_ENOMEM;
  /* Blocks of consecutive rows, claimed in turn: about 8 per thread keeps the threads
   * busy to the end; inside a block each row may warm-start from the one before. */
  job j = {b, nrows, nrows / (8 * T) > 0 ? nrows / (8 * T) : 1, rows, res, 0};
  task *tk = cv_malloc((size_t)T * sizeof *tk);
  pthread_t *th = cv_malloc((size_t)T * sizeof *th);
  if (!tk || !th) {
    cv_free(tk);
    cv_free(th);
    return CVAR_ENOMEM;
  }
  int started = 0;
  for (int t = 0; t < T; t++) {
    tk[t].j = &j;
    tk[t].w = &b->w[t];
  }
  for (int t = 1; t < T; t++) {
    if (pthread_create(&th[t], NULL, run, &tk[t]) != 0)
      break; /* fewer threads: the others take the rows */
    started = t;
  }
  run(&tk[0]);
  for (int t = 1; t <= started; t++)
    pthread_join(th[t], NULL);
  cv_free(tk);
  cv_free(th);
  return CVAR_OK;
}
