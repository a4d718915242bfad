/* src/cli/plot_solution.c — `solve --plot FILE`: the solution curves and multiplier fields.
 * SPDX-License-Identifier: MIT
 *
 * Top panel: every unknown against the variable, drawn from the degree-p interpolant
 * (cv_solver_eval at 801 points, so high-degree elements show as the curves they are),
 * with the [exact] solution dashed where the scene gives one. Bottom panel, when the scene
 * has [constraints]: each multiplier field lambda_NAME at the nodes.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

enum { NPLOT = 801 };

int cli_plot_solution(cli_outfile *o, const cli_report *r, const cv_solver *sv)
{
  const scene *s = r->sc;
  int n = s->n, nn = r->nodes, nc = r->lam ? s->ncons : 0, rc = -1, nl = 0;
  double *xs = malloc(NPLOT * sizeof *xs), *ys = malloc((size_t)NPLOT * n * sizeof *ys);
  double *ex = malloc((size_t)NPLOT * n * sizeof *ex);
  double *yn = malloc((size_t)(nn > 0 ? nn : 1) * n * sizeof *yn);
  cli_plot_line *lines = calloc((size_t)(2 * n + nc), sizeof *lines);
  char (*labels)[96] = calloc((size_t)(2 * n + nc), sizeof *labels);
  if (!xs || !ys || !ex || !yn || !lines || !labels)
    goto done;
  for (int k = 0; k < NPLOT; k++)
    xs[k] = s->a + (s->b - s->a) * k / (NPLOT - 1);
  xs[NPLOT - 1] = s->b;
  /* the interpolant; after a failed solve it may not evaluate: then the nodal values */
  int dense = cv_solver_eval(sv, NPLOT, xs, ys, NULL) == CVAR_OK;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < nn; j++)
      yn[(size_t)i * nn + j] = r->y[(size_t)j * n + i];
  int any_exact = 0;
  for (int i = 0; i < n; i++)
    any_exact |= s->exact[i] >= 0;
  if (any_exact && scene_eval_exact(s, NPLOT, xs, ex) < 0)
    goto done;
  for (int i = 0; i < n; i++) {
    cli_plot_line *ln = &lines[nl];
    ln->n = dense ? NPLOT : nn;
    ln->x = dense ? xs : r->x;
    ln->y = dense ? ys + (size_t)i * NPLOT : yn + (size_t)i * nn;
    ln->colour = i;
    ln->symbol = !dense;
    snprintf(labels[nl], sizeof labels[nl], "%s(%s)", s->unknowns[i], s->variable);
    ln->label = labels[nl++];
    if (s->exact[i] >= 0) {
      ln = &lines[nl];
      ln->n = NPLOT;
      ln->x = xs;
      ln->y = ex + (size_t)i * NPLOT;
      ln->colour = -1;
      ln->style = 2;
      snprintf(labels[nl], sizeof labels[nl], "%s exact", s->unknowns[i]);
      ln->label = labels[nl++];
    }
  }
  char xl[256];
  snprintf(xl, sizeof xl, "%s   (%d elements of degree %s%d, %s)", s->variable, r->elements,
           r->has_degrees ? "up to " : "", r->degree, r->status);
  cli_plot_panel pan[2];
  memset(pan, 0, sizeof pan);
  pan[0].title = s->title;
  pan[0].xlabel = xl;
  pan[0].ylabel = n == 1 ? labels[0] : "unknowns";
  pan[0].nlines = nl;
  pan[0].lines = lines;
  for (int c = 0; c < nc; c++) {
    cli_plot_line *ln = &lines[nl + c];
    ln->n = nn;
    ln->x = r->x;
    ln->y = r->lam + (size_t)c * nn;
    ln->colour = n + c;
    snprintf(labels[nl + c], sizeof labels[nl + c], "lambda_%s(%s)", s->cons[c].name,
             s->variable);
    ln->label = labels[nl + c];
  }
  pan[1].title = "Multiplier fields of the pointwise constraints (at the nodes)";
  pan[1].xlabel = s->variable;
  pan[1].ylabel = "multiplier";
  pan[1].nlines = nc;
  pan[1].lines = lines + nl;
  rc = cli_plot_write(o, nc > 0 ? 2 : 1, pan);
done:
  free(xs);
  free(ys);
  free(ex);
  free(yn);
  free(lines);
  free(labels);
  return rc;
}
