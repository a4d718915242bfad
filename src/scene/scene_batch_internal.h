/* src/scene/scene_batch_internal.h — the batch engine's private types, shared by
 * scene_batch.c (the object, its workers and threads) and scene_batch_row.c (one row).
 * SPDX-License-Identifier: MIT */
#ifndef CV_SCENE_BATCH_INTERNAL_H
#define CV_SCENE_BATCH_INTERNAL_H

#include "expr/ex_integrand.h"
#include "scene/scene_batch.h"
#include "scene/scene_internal.h"

enum { QBATCH = EX_INTEGRAND_BATCH };

typedef struct {
  const struct cv_batch *owner;
  scene *inst;
  ex_integrand *F, **cons, **ints; /* clones of the batch's compiled objects */
  ex_integrand *phase;             /* the phase condition's clone (PB-2), or NULL */
  cv_solver *sv;
  double *pv;      /* parameter values of the row */
  double *tw, *pb; /* report tape work; parameter batches */
  size_t cap;      /* quadrature points the buffers below hold */
  double *qx, *qw, *qy, *qdy, *qv;
  double *qd2y; /* y'' at the quadrature points (second-order scenes), else NULL */
  double *prev; /* warm start: last converged nodal values */
  int prev_len, prev_row;
  double *prev_end; /* its end values [2n] */
  double *prev_u;   /* where its nodes are, as fractions of its interval [prev_len / n] */
  /* --tol: the mesh the last converged row handed on (theory HP-9), on [0, 1] */
  int hp_E;
  double *hp_t;
  int *hp_deg;
  double *rv, *rw; /* row tape outputs and work */
  double *gv, *gw; /* guess tape outputs (one batch each) and work */
} worker;

struct cv_batch {
  scene *s;
  int n, np;
  unsigned need;
  ex_integrand *F, **cons, **ints;
  int njumps;          /* F's jumps in y, smoothable over a width after the parameters (HC-4) */
  ex_integrand *phase; /* K of the phase condition when the scene pins the shift (PB-2) */
  ex_tape *rep;        /* [report] integrands, nslots 1 + 2n + np */
  int nout;
  char **outname;
  int ncols;
  int *col;             /* parameter index of each column */
  unsigned char *given; /* given[i]: some column sets parameter i */
  int nthreads, warm, any_exact, nworkers;
  /* The row tape: every value that follows the parameters (their values, then a, b, the
   * fixed end values, the [integrals] constants, the exact action) as expressions of the
   * given parameters only, evaluated at one point per row (theory: none; plain algebra). */
  ex_tape *rowt;
  int nrowt;
  /* The [guess] expressions compiled once (unknowns without one: the default line). */
  ex_tape *guesst;
  int nguess;
  int *guess_of; /* tape output of unknown i's guess, or -1 */
  worker *w;
  scene *check;                         /* instance for cv_batch_check_row */
  unsigned char *rep_used, *guess_used; /* parameters the report / guess tapes read */
  ex_id *sing;                          /* scene_singular_candidates, found once */
  int nsing;
};

/* scene_batch.c */
double sc_batch_now(void);
cv_status sc_batch_workers(cv_batch *b, int T);

/* scene_batch_row.c: a row's values into inst (theory (B-1)): 0, or -1 with a sentence. */
int sc_batch_set_row(const cv_batch *b, scene *inst, double *pv, double *rv, double *rw,
                     const double *row, char *err, size_t errlen);
/* A problem over worker w's clones and instance (no compilation); NULL on allocation
 * failure. */
cv_problem *sc_batch_row_problem(const cv_batch *b, worker *w);
/* cv_guess_fn over the compiled [guess]; user is the worker. */
int sc_batch_guess(int m, const double *x, double *y, void *user);
/* Solve row number `row` (values vals) on worker w into r. */
void sc_batch_solve_row(cv_batch *b, worker *w, int row, const double *vals, cv_batch_result *r);

#endif /* CV_SCENE_BATCH_INTERNAL_H */
