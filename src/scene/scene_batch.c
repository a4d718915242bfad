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

#include "scene/scene_batch_internal.h"

double sc_batch_now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void worker_free(cv_batch *b, worker *w) {
  ex_integrand_free(w->F);
  for (int k = 0; w->cons && k < b->s->ncons; k++) ex_integrand_free(w->cons[k]);
  for (int k = 0; w->ints && k < b->s->nints; k++) ex_integrand_free(w->ints[k]);
  cv_free(w->cons);
  cv_free(w->ints);
  ex_integrand_free(w->phase);
  cv_solver_free(w->sv);
  scene_free(w->inst);
  cv_free(w->pv);
  cv_free(w->tw);
  cv_free(w->pb);
  cv_free(w->qx);
  cv_free(w->qw);
  cv_free(w->qy);
  cv_free(w->qdy);
  cv_free(w->qd2y);
  cv_free(w->qv);
  cv_free(w->prev);
  cv_free(w->prev_end);
  cv_free(w->prev_u);
  cv_free(w->hp_t);
  cv_free(w->hp_deg);
  cv_free(w->rv);
  cv_free(w->rw);
  cv_free(w->gv);
  cv_free(w->gw);
  memset(w, 0, sizeof *w);
}

static int worker_init(cv_batch *b, worker *w) {
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
  w->gw = b->guesst ? cv_malloc((ex_tape_work_size(b->guesst, QBATCH) + 1) * sizeof *w->gw) : NULL;
  if (!w->inst || !w->F || !w->cons || !w->ints || !w->sv || !w->pv || !w->pb ||
      (b->rep && !w->tw) || !w->prev_end || !w->rv || (b->rowt && !w->rw) || !w->gv ||
      (b->guesst && !w->gw))
    return -1;
  for (int k = 0; k < s->ncons; k++)
    if (!(w->cons[k] = ex_integrand_clone(b->cons[k]))) return -1;
  for (int k = 0; k < s->nints; k++)
    if (!(w->ints[k] = ex_integrand_clone(b->ints[k]))) return -1;
  if (b->phase && !(w->phase = ex_integrand_clone(b->phase))) return -1;
  return 0;
}

void cv_batch_free(cv_batch *b) {
  if (!b) return;
  for (int t = 0; t < b->nworkers; t++) worker_free(b, &b->w[t]);
  cv_free(b->w);
  scene_free(b->check);
  cv_free(b->sing);
  cv_free(b->rep_used);
  cv_free(b->guess_used);
  ex_integrand_free(b->F);
  for (int k = 0; b->cons && k < b->s->ncons; k++) ex_integrand_free(b->cons[k]);
  for (int k = 0; b->ints && k < b->s->nints; k++) ex_integrand_free(b->ints[k]);
  cv_free(b->cons);
  cv_free(b->ints);
  ex_integrand_free(b->phase);
  ex_tape_free(b->rep);
  ex_tape_free(b->rowt);
  ex_tape_free(b->guesst);
  cv_free(b->guess_of);
  for (int k = 0; b->outname && k < b->nout; k++) cv_free(b->outname[k]);
  cv_free(b->outname);
  cv_free(b->col);
  cv_free(b->given);
  scene_free(b->s);
  cv_free(b);
}

cv_batch *scene_batch_new(scene *s, char *err, size_t errlen) {
  char msg[400] = "";
  if (err && errlen) err[0] = '\0';
  if (!s) return NULL;
  if (!s->params_as_inputs) {
    snprintf(err, errlen, "%s: a batch needs the scene loaded with parameters as inputs", s->file);
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
  if (!b->cons || !b->ints || !b->outname || !b->given || !b->check) goto nomem;
  for (int i = 0; i < s->n; i++) b->any_exact |= s->exact[i] >= 0;
  if ((b->nsing = scene_singular_candidates(s, &b->sing)) < 0) goto nomem;
  b->rep_used = cv_calloc((size_t)b->np + 1, 1);
  b->guess_used = cv_calloc((size_t)b->np + 1, 1);
  if (!b->rep_used || !b->guess_used) goto nomem;
  for (int r = 0; r < s->nreports; r++)
    if (ex_slots_used(s->dag, s->reports[r].expr, 1 + 2 * s->n, b->np, b->rep_used) < 0) goto nomem;
  for (int i = 0; i < s->n; i++)
    if (s->guess[i] >= 0 &&
        ex_slots_used(s->dag, s->guess[i], 1 + 2 * s->n, b->np, b->guess_used) < 0)
      goto nomem;
  /* Compile once: every expression of the problem with the parameters as inputs (y'' after
   * them and the width's slot, X-7). */
  /* An integrand that jumps in y is compiled with the jumps smoothable, the width one more
   * input after the parameters, as a solve compiles it (scene_problem.c, theory HC-4), so
   * that each row is solved as `calcvar solve` would solve it. */
  ex_id Fs =
      s->c1 ? s->F : ex_smooth_jumps(s->dag, s->F, 1, 2 * s->n, 2 * s->n + 1 + b->np, &b->njumps);
  if (Fs < 0) goto nomem;
  if (!(b->F =
            s->c1
                ? ex_integrand_new_order(s->dag, s->n, b->np + 1, 2, s->F, b->need, msg, sizeof msg)
            : b->njumps
                ? ex_integrand_new_params(s->dag, s->n, b->np + 1, Fs, b->need, msg, sizeof msg)
                : ex_integrand_new_params(s->dag, s->n, b->np, s->F, b->need, msg, sizeof msg))) {
    snprintf(err, errlen, "%s:%d: integrand: %s", s->file, s->F_line,
             msg[0] ? msg : "out of memory");
    goto fail;
  }
  for (int k = 0; k < s->ncons; k++)
    if (!(b->cons[k] = ex_integrand_new_params(s->dag, s->n, b->np, s->cons[k].expr, b->need, msg,
                                               sizeof msg))) {
      snprintf(err, errlen, "%s:%d: [constraints] %s: %s", s->file, s->cons[k].line,
               s->cons[k].name, msg[0] ? msg : "out of memory");
      goto fail;
    }
  for (int k = 0; k < s->nints; k++)
    if (!(b->ints[k] = s->c1 ? ex_integrand_new_order(s->dag, s->n, b->np + 1, 2, s->ints[k].expr,
                                                      b->need, msg, sizeof msg)
                             : ex_integrand_new_params(s->dag, s->n, b->np, s->ints[k].expr,
                                                       b->need, msg, sizeof msg))) {
      snprintf(err, errlen, "%s:%d: [integrals] %s: %s", s->file, s->ints[k].line, s->ints[k].name,
               msg[0] ? msg : "out of memory");
      goto fail;
    }
  if (scene_pins_shift(s)) { /* PB-2: its constant is the guess's, per row */
    ex_id K;
    double c;
    if (scene_phase_condition(s, &K, &c) < 0) goto nomem;
    if (!(b->phase = ex_integrand_new_params(s->dag, s->n, b->np, K, b->need, msg, sizeof msg))) {
      snprintf(err, errlen, "%s: the phase condition: %s", s->file, msg[0] ? msg : "out of memory");
      goto fail;
    }
  }
  if (s->nreports > 0) {
    ex_id *outs = cv_malloc((size_t)s->nreports * sizeof *outs);
    if (!outs) goto nomem;
    for (int r = 0; r < s->nreports; r++) outs[r] = s->reports[r].expr;
    b->rep =
        ex_tape_new(s->dag, s->c1 ? sc_d2_slot(s, s->n) : 1 + 2 * s->n + b->np, s->nreports, outs);
    cv_free(outs);
    if (!b->rep) goto nomem;
  }
  b->guess_of = cv_malloc(((size_t)s->n + 1) * sizeof *b->guess_of);
  if (!b->guess_of) goto nomem;
  {
    ex_id *outs = cv_malloc(((size_t)s->n + 1) * sizeof *outs);
    if (!outs) goto nomem;
    for (int i = 0; i < s->n; i++) {
      b->guess_of[i] = s->guess[i] >= 0 ? b->nguess : -1;
      if (s->guess[i] >= 0) outs[b->nguess++] = s->guess[i];
    }
    if (b->nguess > 0) b->guesst = ex_tape_new(s->dag, 1 + 2 * s->n + b->np, b->nguess, outs);
    cv_free(outs);
    if (b->nguess > 0 && !b->guesst) goto nomem;
  }
  if (cv_batch_set_columns(b, 0, NULL, err, errlen) != CVAR_OK) goto nomem;
  for (int r = 0; r < s->nreports; r++)
    if (!(b->outname[r] = sc_strdup(s->reports[r].name))) goto nomem;
  for (int k = 0; k < s->nints; k++) {
    size_t len = strlen(s->ints[k].name) + 4;
    if (!(b->outname[s->nreports + k] = cv_malloc(len))) goto nomem;
    snprintf(b->outname[s->nreports + k], len, "mu_%s", s->ints[k].name);
  }
  return b;
nomem:
  snprintf(err, errlen, "%s: out of memory", s->file);
fail:
  cv_batch_free(b);
  return NULL;
}

cv_batch *cv_batch_new(const char *scene_path, char *err, size_t errlen) {
  if (!scene_path) {
    snprintf(err, errlen, "no scene file given");
    return NULL;
  }
  scene *s = scene_load_file_inputs(scene_path, 0, NULL, err, errlen);
  return s ? scene_batch_new(s, err, errlen) : NULL;
}

const scene *scene_batch_scene(const cv_batch *b) { return b ? b->s : NULL; }
int cv_batch_num_parameters(const cv_batch *b) { return b ? b->np : 0; }
const char *cv_batch_parameter_name(const cv_batch *b, int i) {
  return b && i >= 0 && i < b->np ? b->s->params[i].name : NULL;
}
int cv_batch_num_outputs(const cv_batch *b) { return b ? b->nout : 0; }
const char *cv_batch_output_name(const cv_batch *b, int k) {
  return b && k >= 0 && k < b->nout ? b->outname[k] : NULL;
}

/* The row tape (theory (B-1)) for the current given[]: a parameter that no column
 * gives is replaced by its definition, recursively, so the outputs depend only on the
 * given parameters' slots. Adds nodes to the DAG: single-threaded, before any worker. */
static int build_row_tape(cv_batch *b) {
  scene *s = b->s;
  int n = s->n, np = b->np, rc = -1;
  int cap = np + 2 + 4 * n + s->nints + 1;
  ex_id *def = cv_malloc(((size_t)np + 1) * sizeof *def);
  ex_id *outs = cv_malloc((size_t)cap * sizeof *outs);
  if (!def || !outs) goto done;
  int k = 0;
  for (int j = 0; j < np; j++) {
    ex_id e = b->given[j] ? s->params[j].expr : s->params[j].expr2;
    /* the earlier parameters e uses, found by slot (not one test per parameter: 10^5) */
    for (int from = 1 + 2 * n, sl; e >= 0 && !b->given[j]; from = sl + 1) {
      if ((sl = ex_first_slot(s->dag, e, from, 2 * n + j)) < 0) break;
      if (!b->given[sl - 1 - 2 * n]) e = ex_subst(s->dag, e, sl, def[sl - 1 - 2 * n]);
    }
    if ((def[j] = e) < 0) goto done;
    outs[k++] = e;
  }
  ex_id targets[2] = {s->a_expr, s->b_expr};
  int nt = 0;
  ex_id *t = outs + k;
  t[nt++] = targets[0];
  t[nt++] = targets[1];
  for (int i = 0; i < n; i++)
    for (int end = 0; end < 2; end++)
      if (!s->bc[i].free_end[end]) t[nt++] = s->bc[i].expr[end];
  for (int q = 0; q < s->nints; q++) t[nt++] = s->ints[q].expr2;
  if (s->has_exact_action) t[nt++] = s->exact_action_expr;
  for (int i = 0; s->sbc && i < n; i++) /* slopes of the slope lines, after the rest */
    for (int end = 0; end < 2 && s->sbc[i].line; end++)
      if (!s->sbc[i].free_end[end]) t[nt++] = s->sbc[i].expr[end];
  for (int q = 0; q < nt; q++)
    for (int from = 1 + 2 * n, sl; t[q] >= 0; from = sl + 1) {
      if ((sl = ex_first_slot(s->dag, t[q], from, 2 * n + np)) < 0) break;
      if (!b->given[sl - 1 - 2 * n]) t[q] = ex_subst(s->dag, t[q], sl, def[sl - 1 - 2 * n]);
    }
  for (int q = 0; q < nt; q++)
    if (t[q] < 0) goto done;
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
                               size_t errlen) {
  if (err && errlen) err[0] = '\0';
  if (!b || ncols < 0 || (ncols > 0 && !names)) return CVAR_EINVAL;
  if (b->nworkers > 0) { /* workers hold buffers sized for the current row tape */
    snprintf(err, errlen, "the columns are set before the first solve");
    return CVAR_EINVAL;
  }
  int *col = cv_malloc(((size_t)ncols + 1) * sizeof *col);
  if (!col) return CVAR_ENOMEM;
  memset(b->given, 0, (size_t)b->np + 1);
  for (int c = 0; c < ncols; c++) {
    col[c] = -1;
    for (int i = 0; i < b->np; i++)
      if (names[c] && strcmp(names[c], b->s->params[i].name) == 0) col[c] = i;
    if (col[c] < 0 || b->given[col[c]]) {
      snprintf(err, errlen, col[c] < 0 ? "'%s' is not a parameter of %s" : "'%s' is given twice",
               names[c] ? names[c] : "", b->s->file);
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

cv_status cv_batch_set_threads(cv_batch *b, int nthreads) {
  if (!b || nthreads < 0 || nthreads > 4096) return CVAR_EINVAL;
  if (nthreads == 0) {
    long c = sysconf(_SC_NPROCESSORS_ONLN);
    nthreads = c > 0 ? (int)(c < 4096 ? c : 4096) : 1;
  }
  b->nthreads = nthreads;
  return CVAR_OK;
}

cv_status cv_batch_set_warm_start(cv_batch *b, int on) {
  if (!b) return CVAR_EINVAL;
  b->warm = on != 0;
  return CVAR_OK;
}

cv_status cv_batch_set_mesh(cv_batch *b, int elements, int degree) {
  if (!b || elements < 0 || degree < 0 || degree > 8) return CVAR_EINVAL;
  if (elements) b->s->elements = elements;
  if (degree) b->s->degree = degree;
  return CVAR_OK;
}

/* Make sure workers 0..T-1 exist. */
cv_status sc_batch_workers(cv_batch *b, int T) {
  if (T <= b->nworkers) return CVAR_OK;
  worker *nw = cv_realloc(b->w, (size_t)T * sizeof *nw);
  if (!nw) return CVAR_ENOMEM;
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

typedef struct {
  cv_batch *b;
  int n, block;
  scene_batch_item_fn fn;
  void *user;
  atomic_int next;
} job;

typedef struct {
  job *j;
  int t; /* worker index */
} task;

static void *run(void *arg) {
  task *t = arg;
  job *j = t->j;
  for (;;) {
    int i0 = atomic_fetch_add(&j->next, j->block);
    if (i0 >= j->n) break;
    int i1 = i0 + j->block < j->n ? i0 + j->block : j->n;
    for (int i = i0; i < i1; i++) j->fn(j->b, t->t, i, j->user);
  }
  return NULL;
}

cv_status scene_batch_for_each(cv_batch *b, int n, int block, scene_batch_item_fn fn, void *user) {
  if (!b || n < 0 || !fn) return CVAR_EINVAL;
  if (n == 0) return CVAR_OK;
  int T = b->nthreads < n ? b->nthreads : n;
  if (sc_batch_workers(b, T) != CVAR_OK) return CVAR_ENOMEM;
  if (block < 1) block = 1;
  job j = {b, n, block, fn, user, 0};
  task *tk = cv_malloc((size_t)T * sizeof *tk);
  pthread_t *th = cv_malloc((size_t)T * sizeof *th);
  if (!tk || !th) {
    cv_free(tk);
    cv_free(th);
    return CVAR_ENOMEM;
  }
  int started = 0;
  for (int t = 0; t < T; t++) tk[t] = (task){&j, t};
  for (int t = 1; t < T; t++) {
    if (pthread_create(&th[t], NULL, run, &tk[t]) != 0)
      break; /* fewer threads: the others take the items */
    started = t;
  }
  run(&tk[0]);
  for (int t = 1; t <= started; t++) pthread_join(th[t], NULL);
  cv_free(tk);
  cv_free(th);
  return CVAR_OK;
}

int scene_batch_block(const cv_batch *b, int n) {
  int T = b->nthreads < n ? b->nthreads : n;
  if (T < 1) T = 1;
  /* Warm starts and --tol's handed-on meshes (theory HP-9) follow the previous row on the
   * same thread: blocks of consecutive rows, about 8 per thread (the threads still finish
   * together). Without them, small blocks: the last ones even out the threads' ends (a
   * claim is one atomic add, a row tens of microseconds). */
  int per = b->warm || b->s->tol > 0 ? 8 * T : 64 * T;
  return n / per > 0 ? n / per : 1;
}

void scene_batch_solve_row(cv_batch *b, int t, int row, const double *vals, cv_batch_result *r) {
  sc_batch_solve_row(b, &b->w[t], row, vals, r);
}

cv_status scene_batch_check_row(cv_batch *b, int t, const double *row, char *err, size_t errlen) {
  worker *w = &b->w[t];
  return sc_batch_set_row(b, w->inst, w->pv, w->rv, w->rw, row, err, errlen) < 0 ? CVAR_EINVAL
                                                                                 : CVAR_OK;
}

typedef struct {
  const double *rows;
  cv_batch_result *res;
} solve_job;

static int solve_item(cv_batch *b, int t, int i, void *user) {
  solve_job *sj = user;
  sc_batch_solve_row(b, &b->w[t], i, sj->rows + (size_t)i * b->ncols, &sj->res[i]);
  return 0;
}

cv_status cv_batch_solve(cv_batch *b, int nrows, const double *rows, cv_batch_result *res) {
  if (!b || nrows < 0 || (nrows > 0 && (!res || (b->ncols > 0 && !rows)))) return CVAR_EINVAL;
  solve_job sj = {rows, res};
  return scene_batch_for_each(b, nrows, scene_batch_block(b, nrows), solve_item, &sj);
}
