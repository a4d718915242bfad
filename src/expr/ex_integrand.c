/* src/expr/ex_integrand.c — partials of F(x, y, y') compiled to tapes, evaluated through
 * the core's integrand callback (docs/theory.md ). SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expr/ex_integrand.h"

struct ex_integrand {
  int n;
  int np;              /* parameters: tape slots 2n+1 .. 2n+np */
  int n2;              /* n for a second-order F (y''_i is slot 1+2n+np+i, X-7), else 0 */
  int owns_tapes;      /* 0 for a clone (ex_integrand_clone) */
  double *pbuf;        /* np batches, each filled with one parameter's value ... */
  int pfill;           /* ... in its first pfill points (filled as evaluations need) */
  double *pval;        /* the parameter values (np) */
  unsigned char *used; /* used[j]: the expression reads parameter j (shared by clones) */
  unsigned max_need;
  ex_tape *tape[3]; /* level 0: F; 1: F, Fy, Fp; 2: also Fyy (upper), Fyp, Fpp (upper) */
  int nout[3];
  int depends_on_dy; /* F reads some y'_i: not usable as a constraint G(x, y) */
  double *work;      /* registers of the largest tape, one batch */
  double *scratch;   /* one batch per output, for groups the caller did not ask for */
  const double **in;
  double **outp;
  char note[320]; /* why the last failing evaluation failed (a table's grid left) */
};

static void set_err(char *err, size_t errlen, const char *msg) {
  if (err && errlen) snprintf(err, errlen, "%s", msg);
}

/* Upper-triangle index of (i, j), i <= j, in row-major order. */
static int tri(int n, int i, int j) { return i * n - i * (i - 1) / 2 + (j - i); }

/* Work buffers of g (tapes and sizes already set). 0, or -1 on allocation failure. */
static int alloc_buffers(ex_integrand *g) {
  size_t work = 0;
  for (int l = 0; l < 3; l++)
    if (g->tape[l]) {
      size_t w = ex_tape_work_size(g->tape[l], EX_INTEGRAND_BATCH);
      if (w > work) work = w;
    }
  int nout = g->tape[2] ? g->nout[2] : g->tape[1] ? g->nout[1] : 1;
  g->work = cv_malloc((work ? work : 1) * sizeof *g->work);
  g->scratch = cv_malloc((size_t)nout * EX_INTEGRAND_BATCH * sizeof *g->scratch);
  g->in = cv_malloc((size_t)(2 * g->n + 1 + g->np + g->n2) * sizeof *g->in);
  g->outp = cv_malloc((size_t)nout * sizeof *g->outp);
  g->pbuf = cv_calloc((size_t)(g->np ? g->np : 1) * EX_INTEGRAND_BATCH, sizeof *g->pbuf);
  g->pval = cv_calloc((size_t)g->np + 1, sizeof *g->pval);
  g->pfill = 0;
  if (!(g->work && g->scratch && g->in && g->outp && g->pbuf && g->pval)) return -1;
  /* the parameter slots read their batches, at every evaluation */
  for (int j = 0; j < g->np; j++)
    g->in[1 + 2 * g->n + j] = g->pbuf + (size_t)j * EX_INTEGRAND_BATCH;
  return 0;
}

ex_integrand *ex_integrand_new(ex_dag *d, int n, ex_id F, unsigned max_need, char *err,
                               size_t errlen) {
  return ex_integrand_new_params(d, n, 0, F, max_need, err, errlen);
}

ex_integrand *ex_integrand_clone(const ex_integrand *g) {
  ex_integrand *c = g ? cv_malloc(sizeof *c) : NULL;
  if (!c) return NULL;
  *c = *g;
  c->owns_tapes = 0;
  c->work = c->scratch = c->pbuf = c->pval = NULL;
  c->in = NULL;
  c->outp = NULL;
  if (alloc_buffers(c) < 0) {
    ex_integrand_free(c);
    return NULL;
  }
  return c;
}

/* The batches are filled lazily (fill_params): a batch solve sets new values for every
 * row, and a small mesh evaluates a few points, not EX_INTEGRAND_BATCH. */
void ex_integrand_set_params(ex_integrand *g, const double *p) {
  for (int j = 0; j < g->np; j++) g->pval[j] = p[j];
  g->pfill = 0;
}

/* The parameter batches valid for the first m points. */
static void fill_params(ex_integrand *g, int m) {
  if (m <= g->pfill) return;
  for (int j = 0; j < g->np; j++)
    if (g->used[j])
      for (int k = g->pfill; k < m; k++) g->pbuf[(size_t)j * EX_INTEGRAND_BATCH + k] = g->pval[j];
  g->pfill = m;
}

int ex_integrand_num_params(const ex_integrand *g) { return g->np; }

void ex_integrand_set_param(ex_integrand *g, int j, double v) {
  if (j < 0 || j >= g->np || !g->used[j]) return;
  for (int k = 0; k < EX_INTEGRAND_BATCH; k++) g->pbuf[(size_t)j * EX_INTEGRAND_BATCH + k] = v;
}

ex_integrand *ex_integrand_new_params(ex_dag *d, int n, int np, ex_id F, unsigned max_need,
                                      char *err, size_t errlen) {
  return ex_integrand_new_order(d, n, np, 1, F, max_need, err, errlen);
}

/* The outputs of level 1 and 2: F; Fy, Fp (and Fq); then Fyy (upper), Fyp, Fpp
 * (upper) (and Fyq, Fpq, Fqq (upper)). Returns 0 or -1 out of memory. */
static int partials(ex_dag *d, int n, int n2, int np, int level, ex_id *outs) {
  int ntri = n * (n + 1) / 2, q0 = 1 + 2 * n + np;
  int n1 = n2 ? 3 : 2; /* first partials per unknown */
  if (level >= 1)
    for (int i = 0; i < n; i++) {
      outs[1 + i] = ex_diff(d, outs[0], 1 + i);
      outs[1 + n + i] = ex_diff(d, outs[0], 1 + n + i);
      if (n2) outs[1 + 2 * n + i] = ex_diff(d, outs[0], q0 + i);
      if (outs[1 + i] < 0 || outs[1 + n + i] < 0 || (n2 && outs[1 + 2 * n + i] < 0)) return -1;
    }
  if (level < 2) return 0;
  ex_id *yy = outs + 1 + n1 * n, *yp = yy + ntri, *pp = yp + n * n;
  ex_id *yq = pp + ntri, *pq = yq + n * n, *qq = pq + n * n;
  for (int i = 0; i < n; i++) {
    ex_id Fy = outs[1 + i], Fp = outs[1 + n + i], Fq = n2 ? outs[1 + 2 * n + i] : -1;
    for (int j = 0; j < n; j++) {
      if (j >= i) {
        yy[tri(n, i, j)] = ex_diff(d, Fy, 1 + j);
        pp[tri(n, i, j)] = ex_diff(d, Fp, 1 + n + j);
        if (yy[tri(n, i, j)] < 0 || pp[tri(n, i, j)] < 0) return -1;
        if (n2 && (qq[tri(n, i, j)] = ex_diff(d, Fq, q0 + j)) < 0) return -1;
      }
      yp[i * n + j] = ex_diff(d, Fy, 1 + n + j); /* d2F / dy_i dy'_j */
      if (yp[i * n + j] < 0) return -1;
      if (n2 && ((yq[i * n + j] = ex_diff(d, Fy, q0 + j)) < 0 ||
                 (pq[i * n + j] = ex_diff(d, Fp, q0 + j)) < 0))
        return -1;
    }
  }
  return 0;
}

ex_integrand *ex_integrand_new_order(ex_dag *d, int n, int np, int order, ex_id F,
                                     unsigned max_need, char *err, size_t errlen) {
  if (!d || n < 1 || np < 0 || F < 0 || F >= ex_dag_num_nodes(d) || n > 1000 ||
      (order != 1 && order != 2)) {
    set_err(err, errlen, "invalid argument to ex_integrand_new");
    return NULL;
  }
  int n2 = order == 2 ? n : 0, ntri = n * (n + 1) / 2;
  int level = max_need & CVAR_NEED_HESS ? 2 : max_need & CVAR_NEED_GRAD ? 1 : 0;
  int nout1 = 1 + (n2 ? 3 : 2) * n, nout2 = nout1 + 2 * ntri + n * n;
  if (n2) nout2 += ntri + 2 * n * n;
  int nout = level == 2 ? nout2 : level == 1 ? nout1 : 1;
  ex_integrand *g = cv_calloc(1, sizeof *g);
  ex_id *outs = cv_malloc((size_t)nout * sizeof *outs);
  if (!g || !outs) goto nomem;
  g->n = n;
  g->np = np;
  g->n2 = n2;
  g->owns_tapes = 1;
  /* the partials read no slot that F does not */
  if (!(g->used = cv_calloc((size_t)np + 1, 1))) goto nomem;
  if (ex_slots_used(d, F, 1 + 2 * n, np, g->used) < 0) goto nomem;
  g->max_need = max_need | CVAR_NEED_F | (n2 ? CVAR_NEED_Y2 : 0u);
  for (int i = 0; i < n; i++) g->depends_on_dy |= ex_depends_on(d, F, 1 + n + i);
  for (int i = 0; i < n2; i++) g->depends_on_dy |= ex_depends_on(d, F, 1 + 2 * n + np + i);
  outs[0] = F;
  if (partials(d, n, n2, np, level, outs) < 0) goto nomem;
  g->nout[0] = 1;
  g->nout[1] = nout1;
  g->nout[2] = nout2;
  for (int l = 0; l <= level; l++) {
    g->tape[l] = ex_tape_new(d, 2 * n + 1 + np + n2, g->nout[l], outs);
    if (!g->tape[l]) goto nomem;
  }
  if (alloc_buffers(g) < 0) goto nomem;
  cv_free(outs);
  return g;
nomem:
  set_err(err, errlen, "out of memory while compiling the expression");
  cv_free(outs);
  ex_integrand_free(g);
  return NULL;
}

void ex_integrand_free(ex_integrand *g) {
  if (!g) return;
  if (g->owns_tapes) {
    for (int l = 0; l < 3; l++) ex_tape_free(g->tape[l]);
    cv_free(g->used);
  }
  cv_free(g->pbuf);
  cv_free(g->pval);
  cv_free(g->work);
  cv_free(g->scratch);
  cv_free(g->in);
  cv_free(g->outp);
  cv_free(g);
}

void ex_integrand_release(void *g) { ex_integrand_free(g); }

int ex_integrand_has_tables(const ex_integrand *g) {
  int any = 0;
  for (int l = 0; g && l < 3; l++) any |= ex_tape_num_tables(g->tape[l]) > 0;
  return any;
}

const char *ex_integrand_note(void *user, int reset) {
  ex_integrand *g = user;
  if (!g) return NULL;
  if (reset) g->note[0] = 0;
  return g->note;
}

int ex_integrand_num_unknowns(const ex_integrand *g) { return g ? g->n : 0; }
unsigned ex_integrand_max_need(const ex_integrand *g) { return g ? g->max_need : 0; }

/* Output pointer for output o of a batch starting at point k0: the caller's buffer when
 * the group was asked for, else this output's scratch batch. */
static double *dest(ex_integrand *g, double *buf, size_t offset, int o) {
  return buf ? buf + offset : g->scratch + (size_t)o * EX_INTEGRAND_BATCH;
}

/* The caller's output buffers of one evaluation (NULL: not wanted). */
typedef struct {
  double *F, *Fy, *Fp, *Fyy, *Fyp, *Fpp, *Fq, *Fyq, *Fpq, *Fqq;
} outbufs;

/* Point the tape's outputs of level `level` at the buffers (offset k0, M points). */
static void set_outputs(ex_integrand *g, int level, const outbufs *b, size_t M, int k0) {
  int n = g->n, o;
  g->outp[0] = dest(g, b->F, (size_t)k0, 0);
  if (level < 1) return;
  for (int i = 0; i < n; i++) {
    g->outp[1 + i] = dest(g, b->Fy, i * M + k0, 1 + i);
    g->outp[1 + n + i] = dest(g, b->Fp, i * M + k0, 1 + n + i);
    if (g->n2) g->outp[1 + 2 * n + i] = dest(g, b->Fq, i * M + k0, 1 + 2 * n + i);
  }
  if (level < 2) return;
  o = 1 + (g->n2 ? 3 : 2) * n;
  for (int i = 0; i < n; i++)
    for (int j = i; j < n; j++, o++) g->outp[o] = dest(g, b->Fyy, (i * n + j) * M + k0, o);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++, o++) g->outp[o] = dest(g, b->Fyp, (i * n + j) * M + k0, o);
  for (int i = 0; i < n; i++)
    for (int j = i; j < n; j++, o++) g->outp[o] = dest(g, b->Fpp, (i * n + j) * M + k0, o);
  if (!g->n2) return;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++, o++) g->outp[o] = dest(g, b->Fyq, (i * n + j) * M + k0, o);
  for (int i = 0; i < n; i++)
    for (int j = 0; j < n; j++, o++) g->outp[o] = dest(g, b->Fpq, (i * n + j) * M + k0, o);
  for (int i = 0; i < n; i++)
    for (int j = i; j < n; j++, o++) g->outp[o] = dest(g, b->Fqq, (i * n + j) * M + k0, o);
}

/* Evaluate the smallest tape covering `need` into the given buffers; d2y: y'' (NULL for a
 * first-order F). */
static int eval_into(ex_integrand *g, int m, const double *x, const double *y, const double *dy,
                     const double *d2y, unsigned need, const outbufs *b) {
  int level = need & CVAR_NEED_HESS ? 2 : need & CVAR_NEED_GRAD ? 1 : 0;
  if (!g->tape[level] || (g->n2 && !d2y)) return -1;
  int n = g->n;
  size_t M = (size_t)m;
  fill_params(g, m < EX_INTEGRAND_BATCH ? m : EX_INTEGRAND_BATCH);
  for (int k0 = 0; k0 < m; k0 += EX_INTEGRAND_BATCH) {
    int mm = m - k0 < EX_INTEGRAND_BATCH ? m - k0 : EX_INTEGRAND_BATCH;
    g->in[0] = x + k0;
    for (int i = 0; i < n; i++) {
      g->in[1 + i] = y + i * M + k0;
      g->in[1 + n + i] = dy ? dy + i * M + k0 : NULL; /* NULL: a constraint G(x, y) */
    }
    for (int i = 0; i < g->n2; i++) g->in[1 + 2 * n + g->np + i] = d2y + i * M + k0;
    set_outputs(g, level, b, M, k0);
    ex_tape_eval(g->tape[level], mm, g->in, g->outp, g->work);
    /* A table met a point outside its grid: "cannot evaluate here" (the line search
     * shortens the step), and the note names the table. */
    if (ex_tape_fault(g->tape[level], mm, g->work, g->note, sizeof g->note)) return 1;
  }
  /* Symmetric blocks: the lower triangle is a copy of the upper. */
  for (int i = 0; i < n; i++)
    for (int j = 0; j < i; j++) {
      if (b->Fyy) memcpy(b->Fyy + (i * n + j) * M, b->Fyy + (j * n + i) * M, M * sizeof *b->Fyy);
      if (b->Fpp) memcpy(b->Fpp + (i * n + j) * M, b->Fpp + (j * n + i) * M, M * sizeof *b->Fpp);
      if (b->Fqq) memcpy(b->Fqq + (i * n + j) * M, b->Fqq + (j * n + i) * M, M * sizeof *b->Fqq);
    }
  return 0;
}

int ex_integrand_eval(int m, const double *x, const double *y, const double *dy, unsigned need,
                      cv_partials *out, void *user) {
  ex_integrand *g = user;
  if (!g || !out || m < 1) return -1;
  int grad = (need & CVAR_NEED_GRAD) != 0, hess = (need & CVAR_NEED_HESS) != 0;
  outbufs b = {need & CVAR_NEED_F ? out->F : NULL,
               grad ? out->Fy : NULL,
               grad ? out->Fp : NULL,
               hess ? out->Fyy : NULL,
               hess ? out->Fyp : NULL,
               hess ? out->Fpp : NULL,
               NULL,
               NULL,
               NULL,
               NULL};
  const double *d2y = NULL;
  if (need & CVAR_NEED_Y2) { /* out is the d1 member of a cv_partials2 (calcvar.h) */
    cv_partials2 *o2 = cv_partials_y2(out);
    d2y = o2->d2y;
    if (g->n2) {
      b.Fq = grad ? o2->Fq : NULL;
      b.Fyq = hess ? o2->Fyq : NULL, b.Fpq = hess ? o2->Fpq : NULL, b.Fqq = hess ? o2->Fqq : NULL;
    } else { /* a first-order F in a second-order problem: its partials in y'' are 0 */
      size_t l1 = (size_t)g->n * m, l2 = l1 * g->n;
      for (size_t k = 0; grad && k < l1; k++) o2->Fq[k] = 0.0;
      for (size_t k = 0; hess && k < l2; k++) o2->Fyq[k] = o2->Fpq[k] = o2->Fqq[k] = 0.0;
    }
  }
  return eval_into(g, m, x, y, dy, d2y, need, &b);
}

int ex_integrand_eval_constraint(int m, const double *x, const double *y, unsigned need, double *G,
                                 double *Gy, double *Gyy, void *user) {
  ex_integrand *g = user;
  if (!g || m < 1 || g->depends_on_dy) return -1;
  outbufs b = {need & CVAR_NEED_F ? G : NULL,
               need & CVAR_NEED_GRAD ? Gy : NULL,
               NULL,
               need & CVAR_NEED_HESS ? Gyy : NULL,
               NULL,
               NULL,
               NULL,
               NULL,
               NULL,
               NULL};
  return eval_into(g, m, x, y, NULL, NULL, need, &b);
}
