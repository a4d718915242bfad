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
#endif
