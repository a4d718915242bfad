/* src/core/cv_table_internal.h — library-internal hooks of tables (cv_table.c) and of the
 * integrand's failure note (cv_problem.c, cv_solve.c), used by src/expr and src/scene.
 * SPDX-License-Identifier: MIT */
#ifndef CV_TABLE_INTERNAL_H
#define CV_TABLE_INTERNAL_H
#include <stddef.h>

#include "calcvar.h"

/* Another reference to t (returned); cv_table_free releases each. */
cv_table *cv_table_ref(cv_table *t);
/* cv_table_new that also writes a sentence on failure (msg may be NULL). */
cv_table *cv_table_new_msg(int dim, const int *n, const double *const *coords, const double *values,
                           cv_status *why, char *msg, size_t len);
/* cv_table_new_msg that takes `values` (cv_malloc'ed, grid order) as the table's own array
 * of values instead of copying it; `values` is released on failure too. */
cv_table *cv_table_new_owned(int dim, const int *n, const double *const *coords, double *values,
                             cv_status *why, char *msg, size_t len);
/* Several partials of t at the point u at once (one cell search, theory TB-2): out[j] has
 * the orders ord[j][0..dim-1]. Returns 0, or k + 1 when u is outside the grid along axis k
 * (then every out[j] is NaN). */
int cv_table_eval_multi(const cv_table *t, const double *u, int nord, const int (*ord)[3],
                        double *out);
/* Tables added to a problem (cv_problem_add_table), for the formula compiler: count and
 * the i-th name and table (borrowed). */
int cv_problem_num_tables(const cv_problem *p);
const char *cv_problem_table_name(const cv_problem *p, int i);
const cv_table *cv_problem_table(const cv_problem *p, int i);
/* A note on the last failure of a callback's evaluation ("the path left the grid of table
 * 'c' ..."): fn(user, 1) clears it (cv_solve calls it when a solve starts), fn(user, 0)
 * returns it ("" or NULL when none). When a solve fails, cv_solve puts the first non-empty
 * note of the problem's sources at the front of its message. `user` is the user data of
 * the integrand, a constraint or an integral; a source whose user is the integrand's is
 * dropped when the integrand is replaced or released. */
typedef const char *(*cv_note_fn)(void *user, int reset);
typedef struct {
  cv_note_fn fn;
  void *user;
} cv_note_source;
cv_status cv_problem_add_note(cv_problem *p, cv_note_fn fn, void *user);
/* An integrand with jumps (a formula's if on y): fn(user, w) makes it the integrand with
 * its `count` jumps smoothed over a width w > 0 (w = 0: the integrand as written). The
 * solve policy uses it when Newton fails on the jumps (theory HC-4); `user` must be the
 * integrand's user data, and the hook goes when the integrand is replaced or released. */
typedef void (*cv_smooth_fn)(void *user, double w);
cv_status cv_problem_set_smoothing(cv_problem *p, cv_smooth_fn fn, void *user, int count);
#endif
