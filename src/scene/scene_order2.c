/* src/scene/scene_order2.c — second derivatives in a scene: the slope lines of [boundary]
 * and which unknowns are second order (SCENES.md "Second derivatives in the integrand",
 * theory H-1). SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <string.h>

#include "scene/scene_internal.h"

int sc_uses_second(const scene *s, ex_id e, int *which) {
  for (int i = 0; i < s->n; i++)
    if (ex_depends_on(s->dag, e, sc_d2_slot(s, i))) {
      if (which) *which = i;
      return 1;
    }
  return 0;
}

/* `y' = a, b`: each a constant expression or `free` (with the parameters as inputs, the
 * expression is kept and evaluated again for each parameter set, as the values' are). */
int sc_load_slope_line(sc_loader *L, const sc_entry *e, int k) {
  scene *s = L->s;
  if (!s->sbc && !(s->sbc = cv_calloc((size_t)s->n, sizeof *s->sbc))) {
    sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
    return -1;
  }
  sc_boundary *b = &s->sbc[k];
  if (b->line) {
    sc_err(L->err, L->errlen, L->file, e->line, "[boundary] has a second line for %s (line %d)",
           e->key, b->line);
    return -1;
  }
  ex_list list;
  if (ex_list_split(e->value, &list) < 0) {
    sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
    return -1;
  }
  int rc = 0;
  if (list.n != 2) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "[boundary] %s needs two values 'slope_at_a, slope_at_b', got %d", e->key, list.n);
    rc = -1;
  }
  b->line = e->line;
  b->expr[0] = b->expr[1] = -1;
  for (int end = 0; end < 2 && rc == 0; end++) {
    const char *t = list.item[end];
    char what[160];
    if (strcmp(t, "free") == 0) {
      b->free_end[end] = 1;
      continue;
    }
    snprintf(what, sizeof what, "[boundary] %s at %s", e->key, end ? "b" : "a");
    rc = sc_parse_const_node(L, e, list.off[end], t, what, &b->value[end], &b->expr[end]);
  }
  ex_list_free(&list);
  return rc;
}

/* After every section: an unknown is second order when its y'' appears in the integrand,
 * a definition, an integral or a report; a slope line for any other unknown is bad input. */
int sc_load_order2(sc_loader *L) {
  scene *s = L->s;
  if (!(s->order2 = cv_calloc((size_t)s->n, sizeof *s->order2))) {
    sc_err(L->err, L->errlen, L->file, 0, "out of memory");
    return -1;
  }
  for (int i = 0; i < s->n; i++) {
    int slot = sc_d2_slot(s, i), any = ex_depends_on(s->dag, s->F, slot);
    for (int k = 0; k < s->ndefs && !any; k++) any = ex_depends_on(s->dag, s->defs[k].expr, slot);
    for (int k = 0; k < s->nints && !any; k++) any = ex_depends_on(s->dag, s->ints[k].expr, slot);
    for (int k = 0; k < s->nreports && !any; k++)
      any = ex_depends_on(s->dag, s->reports[k].expr, slot);
    s->order2[i] = any;
    s->c1 |= any;
  }
  if (s->c1 && s->degree != 1 && (s->degree % 2 == 0 || s->degree > 7)) {
    sc_err(L->err, L->errlen, L->file, s->degree_line > 0 ? s->degree_line : 0,
           "[mesh] degree %d: a scene with y'' is solved on C1 elements (values and slopes at "
           "the nodes) of degree 3, 5 or 7",
           s->degree);
    return -1;
  }
  for (int i = 0; s->sbc && i < s->n; i++)
    if (s->sbc[i].line && !s->order2[i]) {
      sc_err(L->err, L->errlen, L->file, s->sbc[i].line,
             "[boundary] %s': %s has no second derivative in the scene, so its path is only "
             "continuous and its slope at an end is not a condition (write %s'' in the "
             "integrand, or drop this line)",
             s->unknowns[i], s->unknowns[i], s->unknowns[i]);
      return -1;
    }
  return 0;
}
