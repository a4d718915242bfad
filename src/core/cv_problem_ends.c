/* src/core/cv_problem_ends.c — the moving ends of a problem: which end of the interval is
 * free or bound to a curve (the solve that finds it is cv_ends.c).
 * SPDX-License-Identifier: MIT */
#include "cv_internal.h"

static void release_end(cv_end_motion *m) {
  if (m->release) m->release(m->user);
  *m = (cv_end_motion){CV_END_FIXED, NULL, NULL, NULL};
}

void cv_problem_ends_release(cv_problem *p) {
  for (int end = 0; p && end < 2; end++) release_end(&p->move[end]);
}

cv_status cv_problem_set_end_fixed(cv_problem *p, int end) {
  if (!p || (end != 0 && end != 1)) return CVAR_EINVAL;
  release_end(&p->move[end]);
  return CVAR_OK;
}

cv_status cv_problem_set_end_free(cv_problem *p, int end) {
  if (!p || (end != 0 && end != 1)) return CVAR_EINVAL;
  release_end(&p->move[end]);
  p->move[end].kind = CV_END_FREE;
  return CVAR_OK;
}

cv_status cv_problem_set_end_curve_owned(cv_problem *p, int end, cv_end_curve_fn G, void *user,
                                         cv_release_fn release) {
  if (!p || !G || (end != 0 && end != 1)) {
    if (release) release(user);
    return CVAR_EINVAL;
  }
  release_end(&p->move[end]);
  p->move[end] = (cv_end_motion){CV_END_CURVE, G, user, release};
  return CVAR_OK;
}

cv_status cv_problem_set_end_curve(cv_problem *p, int end, cv_end_curve_fn G, void *user) {
  return cv_problem_set_end_curve_owned(p, end, G, user, NULL);
}

int cv_problem_get_end_kind(const cv_problem *p, int end) {
  return p && (end == 0 || end == 1) ? p->move[end].kind : -1;
}
