/* src/scene/scene_contact.c — the contact set of each inequality constraint of a solved
 * scene for the report, from the core (cv_solver_get_contact, theory OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_report.h"

/* At an end whose values are all fixed the field has no multiplier of its own and is
 * extrapolated (docs/constraints.md); for an inequality that the end satisfies strictly,
 * complementarity says lambda = 0 there (OB-1), whatever the extrapolation gives. */
static void ends_off_obstacle(cli_report *r, const scene *s, int c) {
  int n = s->n, nn = r->nodes;
  for (int e = 0; e < 2; e++) {
    long j = e ? nn - 1 : 0;
    double x = r->x[j], y[64], g = NAN;
    if (n > 64) return;
    for (int i = 0; i < n; i++) y[i] = r->y[(size_t)j * n + i];
    if (sc_eval_exprs(s, 1, &s->cons[c].expr, 1, &x, y, NULL, &g) < 0) continue;
    if (s->cons[c].sense * g > 0) r->lam[(size_t)c * nn + j] = 0.0;
  }
}

int cli_report_contact(cli_report *r, const scene *s, const cv_problem *p, const cv_solver *sv) {
  r->ncontact = cv_calloc((size_t)s->ncons + 1, sizeof *r->ncontact);
  r->contact = cv_calloc((size_t)s->ncons + 1, sizeof *r->contact);
  if (!r->ncontact || !r->contact) return -1;
  for (int c = 0; c < s->ncons; c++) {
    int cnt = 0;
    if (!s->cons[c].sense || cv_solver_get_contact(sv, p, c, NULL, 0, &cnt) != CVAR_OK) continue;
    if (r->lam && r->nodes > 1) ends_off_obstacle(r, s, c);
    r->contact[c] = cv_malloc(2 * (size_t)(cnt ? cnt : 1) * sizeof **r->contact);
    if (!r->contact[c]) return -1;
    if (cv_solver_get_contact(sv, p, c, r->contact[c], cnt, &r->ncontact[c]) != CVAR_OK)
      r->ncontact[c] = 0;
  }
  return 0;
}
