/* src/cli/report_csv.c — the CSV table of SCENES.md ("--csv"): a header, then one row per
 * mesh node in increasing order of the variable, ends included.
 * SPDX-License-Identifier: MIT
 *
 * Columns: the variable, each unknown, then lambda_NAME per pointwise constraint, then
 * NAME' (the nodal slope) per unknown whose y'' the scene uses. "%.17g" round-trips every double. A
 * non-finite value (the last iterate of a diverged solve) is written as an empty field,
 * never as "nan".
 */
#include <math.h>

#include "cli/cli.h"

static void field(FILE *f, double v) {
  if (isfinite(v)) fprintf(f, "%.17g", v);
}

int cli_report_csv(FILE *f, const cli_report *r) {
  const scene *s = r->sc;
  int n = s->n;
  fprintf(f, "%s", s->variable);
  for (int i = 0; i < n; i++) fprintf(f, ",%s", s->unknowns[i]);
  for (int c = 0; c < s->ncons; c++) fprintf(f, ",lambda_%s", s->cons[c].name);
  for (int i = 0; s->c1 && i < n; i++) /* the slope of each unknown with y'' */
    if (s->order2[i]) fprintf(f, ",%s'", s->unknowns[i]);
  fputc('\n', f);
  for (int j = 0; j < r->nodes; j++) {
    field(f, r->x[j]);
    for (int i = 0; i < n; i++) {
      fputc(',', f);
      field(f, r->y[(size_t)j * n + i]);
    }
    for (int c = 0; c < s->ncons; c++) {
      fputc(',', f);
      if (r->lam) field(f, r->lam[(size_t)c * r->nodes + j]);
    }
    for (int i = 0; s->c1 && i < n; i++)
      if (s->order2[i]) {
        fputc(',', f);
        if (r->dy) field(f, r->dy[(size_t)j * n + i]);
      }
    fputc('\n', f);
  }
  return ferror(f) ? -1 : 0;
}
