/* src/core/cv_internal_owned.h — library-internal hook: an integrand whose user data the
 * problem owns and releases (used by the string-integrand entry point).
 * SPDX-License-Identifier: MIT */
#ifndef CV_INTERNAL_OWNED_H
#define CV_INTERNAL_OWNED_H
#include "calcvar.h"
/* Like cv_problem_set_integrand, but cv_problem_free (or the next set_integrand) calls
 * release(user). On failure release(user) is called before returning. */
cv_status cv_problem_set_integrand_owned(cv_problem *p, cv_integrand_fn F, void *user,
                                         void (*release)(void *));
/* Constraints whose user data the problem owns, as above. */
cv_status cv_problem_add_constraint_owned(cv_problem *p, cv_constraint_fn G, void *user,
                                          void (*release)(void *), int *index);
cv_status cv_problem_add_integral_owned(cv_problem *p, cv_integrand_fn K, void *user,
                                        void (*release)(void *), double c, int *index);
/* Tables (cv_table.c): another reference to t (returned); a constructor that also writes
 * a sentence on failure (msg may be NULL). */
cv_table *cv_table_ref(cv_table *t);
cv_table *cv_table_new_msg(int dim, const int *n, const double *const *coords,
                           const double *values, cv_status *why, char *msg, size_t len);
/* Several partials of t at the point u at once (one cell search): out[j] has the orders
 * ord[j][0..dim-1]. Returns 0, or k + 1 when u is outside the grid along axis k (all NaN). */
int cv_table_eval_multi(const cv_table *t, const double *u, int nord, const int (*ord)[3],
                        double *out);
/* Tables added to a problem (cv_problem_add_table), for the formula compiler: count and
 * the i-th name and table (borrowed). */
int cv_problem_num_tables(const cv_problem *p);
const char *cv_problem_table_name(const cv_problem *p, int i);
const cv_table *cv_problem_table(const cv_problem *p, int i);
/* A note on the integrand's last failure (e.g. "the path left the grid of table 'c' ..."),
 * appended by cv_solve to its message when a solve fails; `reset` nonzero clears it (called
 * when a solve starts). Returns the note or NULL. */
typedef const char *(*cv_note_fn)(void *user, int reset);
cv_status cv_problem_set_integrand_note(cv_problem *p, cv_note_fn note);
#endif
