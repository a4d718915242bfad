/* src/scene/scene_contact.c — the contact set of each inequality constraint of a solved
 * scene for the report, from the core (cv_solver_get_contact, theory OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_report.h"

int cli_report_contact(cli_report *r, const scene *s, const cv_problem *p, const cv_solver *sv) {
  r->ncontact = cv_calloc((size_t)s->ncons + 1, sizeof *r->ncontact);
  r->contact = cv_calloc((size_t)s->ncons + 1, sizeof *r->contact);
  if (!r->ncontact || !r->contact) return -1;
  for (int c = 0; c < s->ncons; c++) {
    int cnt = 0;
    if (!s->cons[c].sense || cv_solver_get_contact(sv, p, c, NULL, 0, &cnt) != CVAR_OK) continue;
    r->contact[c] = cv_malloc(2 * (size_t)(cnt ? cnt : 1) * sizeof **r->contact);
    if (!r->contact[c]) return -1;
    if (cv_solver_get_contact(sv, p, c, r->contact[c], cnt, &r->ncontact[c]) != CVAR_OK)
      r->ncontact[c] = 0;
  }
  return 0;
}
