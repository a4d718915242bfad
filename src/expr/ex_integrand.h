/* src/expr/ex_integrand.h — a compiled expression F(x, y, y') served through the core's
 * integrand callback (cv_integrand_fn). SPDX-License-Identifier: MIT
 *
 * Slots of the DAG: 0 = the variable, 1..n = y_i, n+1..2n = y'_i. The object holds up to
 * three tapes: F; F and first partials; F, first and second partials, compiled only as far
 * as max_need asks, and evaluates the smallest one covering a call's `need`. The same
 * object serves any expression of (x, y, y'): integrands, pointwise constraints G(x, y)
 * (whose y' partials come out as exact zeros), integral constraints, report integrals.
 * After ex_integrand_new the DAG may be freed: the tapes keep no reference to it.
 */
#ifndef CV_EX_INTEGRAND_H
#define CV_EX_INTEGRAND_H

#include <stddef.h>

#include "calcvar.h"
#include "core/cv_memory.h"
#include "expr/expr.h"

typedef struct ex_integrand ex_integrand;

/* Points per internal batch: calls with more points are evaluated batch by batch. */
#define EX_INTEGRAND_BATCH 256

/* Build the partials of F (nodes are added to d) and compile the tapes. max_need is an OR
 * of CVAR_NEED_* bits; second derivatives are formed and compiled only when it contains
 * CVAR_NEED_HESS. Returns NULL with a sentence in err (errlen bytes, may be NULL/0). */
ex_integrand *ex_integrand_new(ex_dag *d, int n, ex_id F, unsigned max_need, char *err,
                               size_t errlen);

/* The same with np parameters as tape inputs (slots 2n+1 .. 2n+np, see scene.h): the
 * tapes read them like the variable, so one compiled object serves any parameter values
 * (set with ex_integrand_set_params; all zero until then). np = 0 is ex_integrand_new. */
ex_integrand *ex_integrand_new_params(ex_dag *d, int n, int np, ex_id F, unsigned max_need,
                                      char *err, size_t errlen);

/* The same for an integrand of order 1 (as above) or 2 (theory X-7): F may read y''_i at
 * slot 1+2n+np+i, and the object evaluates with CVAR_NEED_Y2 only (out is then the d1 of
 * a cv_partials2; the partials in y'' are filled as the groups ask). A first-order object
 * called with CVAR_NEED_Y2 (an integral constraint without y'' in a second-order problem)
 * writes exact zeros for its partials in y''. */
ex_integrand *ex_integrand_new_order(ex_dag *d, int n, int np, int order, ex_id F,
                                     unsigned max_need, char *err, size_t errlen);

/* A second evaluator over the same compiled tapes: its own work buffers and parameter
 * values, the tapes shared read-only (so one object per thread, compiled once). The
 * clone must be freed before the object it was cloned from. NULL on allocation failure. */
ex_integrand *ex_integrand_clone(const ex_integrand *g);

/* Parameter values p[0..np-1] for the following evaluations. */
void ex_integrand_set_params(ex_integrand *g, const double *p);
/* Parameter j alone (0 <= j < np; ignored otherwise). */
void ex_integrand_set_param(ex_integrand *g, int j, double v);
int ex_integrand_num_params(const ex_integrand *g);

/* A cv_integrand_fn: user is the ex_integrand. Fills every requested group (NULL members
 * of out are groups not asked for), including both triangles of Fyy and Fpp. Values are
 * written as computed; the core checks finiteness. Returns 0, or -1 when `need` asks for
 * a group beyond max_need (a programming error) or m < 1. Not re-entrant on one object
 * (it owns its work buffer), as calcvar.h promises for callbacks. */
int ex_integrand_eval(int m, const double *x, const double *y, const double *dy, unsigned need,
                      cv_partials *out, void *user);

/* A cv_constraint_fn (calcvar.h) for a pointwise constraint G(x, y): the same object,
 * with G = F, Gy = F_y, Gyy = F_yy. Returns -1 when the expression depends on some y'
 * (the caller should have refused it), when `need` exceeds max_need, or when m < 1. */
int ex_integrand_eval_constraint(int m, const double *x, const double *y, unsigned need, double *G,
                                 double *Gy, double *Gyy, void *user);

/* Number of unknowns n, and the max_need it was built with. */
int ex_integrand_num_unknowns(const ex_integrand *g);
unsigned ex_integrand_max_need(const ex_integrand *g);

void ex_integrand_free(ex_integrand *g);
/* ex_integrand_free with the signature of a release callback (void *). */
void ex_integrand_release(void *g);
/* A cv_note_fn (core/cv_table_internal.h): the sentence of the last evaluation that failed
 * because a table was called outside its grid ("" if none); reset clears it. */
const char *ex_integrand_note(void *user, int reset);
/* Whether the expression calls a table (only then can ex_integrand_note say anything). */
int ex_integrand_has_tables(const ex_integrand *g);

#endif /* CV_EX_INTEGRAND_H */
