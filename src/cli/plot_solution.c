/* src/cli/plot_solution.c — `solve --plot FILE`: the path, the solution curves, their errors
 * and the multiplier fields.
 * SPDX-License-Identifier: MIT
 *
 * Curves are drawn from the degree-p interpolant (cv_solver_eval at 801 points, so
 * high-degree elements show as the curves they are), the [exact] solution dashed where the
 * scene gives one. Panels:
 *  - the path: one unknown (or the variable) against another with equal scales, for two or
 *    more unknowns (the first two) or as [plot] path says (docs/scenes.md); axes named in
 *    [plot] downward increase downward;
 *  - the components: every unknown against the variable (left out when the path is the
 *    graph of the only unknown, as for the brachistochrone);
 *  - with [exact]: |y_h - y_exact| of each unknown that has one, on a logarithmic scale
 *    (the nodes show as dips: they are more accurate than the points between them);
 *  - with [constraints]: each multiplier field lambda_NAME at the nodes.
 * With a path beside other panels the path takes the left half of the page.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli/cli.h"

enum { NPLOT = 801, MAXPANELS = 4 };

/* The exact values of a slot at the NPLOT abscissae xs (the variable: xs itself), or NULL
 * when the scene gives no [exact] for it. */
static const double *exact_slot(const scene *s, int slot, const double *xs, const double *ex) {
  if (slot == 0) return xs;
  return s->exact[slot - 1] >= 0 ? ex + (size_t)(slot - 1) * NPLOT : NULL;
}

int cli_plot_solution(cli_outfile *o, const cli_report *r, const cv_solver *sv) {
  const scene *s = r->sc;
  int n = s->n, nn = r->nodes, nc = r->lam ? s->ncons : 0, rc = -1, nl = 0;
  int nmax = 4 * n + nc + 2;
  double *xs = malloc(NPLOT * sizeof *xs), *ys = malloc((size_t)NPLOT * n * sizeof *ys);
  double *ex = malloc((size_t)NPLOT * n * sizeof *ex);
  double *er = malloc((size_t)NPLOT * n * sizeof *er);
  double *yn = malloc((size_t)(nn > 0 ? nn : 1) * n * sizeof *yn);
  cli_plot_line *lines = calloc((size_t)nmax, sizeof *lines);
  char(*labels)[96] = calloc((size_t)nmax, sizeof *labels);
  if (!xs || !ys || !ex || !er || !yn || !lines || !labels) goto done;
  for (int k = 0; k < NPLOT; k++) xs[k] = s->a + (s->b - s->a) * k / (NPLOT - 1);
  xs[NPLOT - 1] = s->b;
  /* the interpolant; after a failed solve it may not evaluate: then the nodal values */
  int dense = cv_solver_eval(sv, NPLOT, xs, ys, NULL) == CVAR_OK;
  for (int i = 0; i < n; i++)
    for (int j = 0; j < nn; j++) yn[(size_t)i * nn + j] = r->y[(size_t)j * n + i];
  int any_exact = 0;
  for (int i = 0; i < n; i++) any_exact |= s->exact[i] >= 0;
  if (any_exact && scene_eval_exact(s, NPLOT, xs, ex) < 0) goto done;
  int np = dense ? NPLOT : nn;
  const double *xv = dense ? xs : r->x;
  /* slot 0 is the variable, 1 + i unknown i: the drawn values, the exact ones or NULL */
#define SLOT_Y(slot)    ((slot) == 0 ? xv : (dense ? ys : yn) + (size_t)((slot)-1) * np)
#define SLOT_NAME(slot) ((slot) == 0 ? s->variable : s->unknowns[(slot)-1])

  cli_plot_panel pan[MAXPANELS];
  memset(pan, 0, sizeof pan);
  int npan = 0, path = -1;
  int pu = s->plot_path[0], pv = s->plot_path[1];
  if (pu < 0 && n >= 2) pu = 1, pv = 2;
  int components = !(pu >= 0 && n == 1 && (pu == 0 || pv == 0));
  char pathlabel[2][64];
  if (pu >= 0) {
    path = npan++;
    cli_plot_panel *P = &pan[path];
    P->lines = lines + nl;
    cli_plot_line *ln = &lines[nl];
    ln->n = np;
    ln->x = SLOT_Y(pu);
    ln->y = SLOT_Y(pv);
    ln->colour = 0;
    ln->symbol = !dense;
    snprintf(labels[nl], sizeof labels[nl], "computed");
    ln->label = labels[nl++];
    if (exact_slot(s, pu, xs, ex) && exact_slot(s, pv, xs, ex)) {
      ln = &lines[nl];
      ln->n = NPLOT;
      ln->x = exact_slot(s, pu, xs, ex);
      ln->y = exact_slot(s, pv, xs, ex);
      ln->colour = -1;
      ln->style = 2;
      snprintf(labels[nl], sizeof labels[nl], "exact");
      ln->label = labels[nl++];
    }
    P->nlines = (int)(lines + nl - P->lines);
    P->no_legend = P->nlines == 1;
    snprintf(pathlabel[0], sizeof pathlabel[0], "%s", SLOT_NAME(pu));
    snprintf(pathlabel[1], sizeof pathlabel[1], "%s", SLOT_NAME(pv));
    P->xlabel = pathlabel[0];
    P->ylabel = pathlabel[1];
    P->title = components ? "Path" : s->title;
    P->equal = 1;
    P->xdown = s->plot_down[pu];
    P->ydown = s->plot_down[pv];
  }
  char xl[256];
  snprintf(xl, sizeof xl, "%s   (%d elements of degree %s%d, %s)", s->variable, r->elements,
           r->has_degrees ? "up to " : "", r->degree, r->status);
  if (path >= 0 && !components)
    pan[path].xlabel = xl; /* the only panel but errors: it carries the mesh line */
  if (components) {
    cli_plot_panel *P = &pan[npan++];
    P->lines = lines + nl;
    int all_down = 1;
    for (int i = 0; i < n; i++) {
      cli_plot_line *ln = &lines[nl];
      ln->n = np;
      ln->x = xv;
      ln->y = SLOT_Y(1 + i);
      ln->colour = i;
      ln->symbol = !dense;
      snprintf(labels[nl], sizeof labels[nl], "%s(%s)", s->unknowns[i], s->variable);
      ln->label = labels[nl++];
      all_down &= s->plot_down[1 + i] != 0;
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
    P->nlines = (int)(lines + nl - P->lines);
    P->title = path >= 0 ? "Components" : s->title;
    P->xlabel = xl;
    P->ylabel = n == 1 ? P->lines[0].label : "unknowns";
    P->no_legend = P->nlines == 1;
    P->ydown = all_down;
    P->xdown = s->plot_down[0];
  }
  if (any_exact && dense) {
    cli_plot_panel *P = &pan[npan++];
    P->lines = lines + nl;
    for (int i = 0; i < n; i++) {
      if (s->exact[i] < 0) continue;
      for (int k = 0; k < NPLOT; k++)
        er[(size_t)i * NPLOT + k] = fabs(ys[(size_t)i * NPLOT + k] - ex[(size_t)i * NPLOT + k]);
      cli_plot_line *ln = &lines[nl];
      ln->n = NPLOT;
      ln->x = xs;
      ln->y = er + (size_t)i * NPLOT;
      ln->colour = i;
      snprintf(labels[nl], sizeof labels[nl], "|%s - %s exact|", s->unknowns[i], s->unknowns[i]);
      ln->label = labels[nl++];
    }
    P->nlines = (int)(lines + nl - P->lines);
    P->title = "Error against [exact]";
    P->xlabel = s->variable;
    P->ylabel = "error";
    P->logy = 1;
  }
  if (nc > 0) {
    cli_plot_panel *P = &pan[npan++];
    P->lines = lines + nl;
    for (int c = 0; c < nc; c++) {
      cli_plot_line *ln = &lines[nl];
      ln->n = nn;
      ln->x = r->x;
      ln->y = r->lam + (size_t)c * nn;
      ln->colour = n + c;
      snprintf(labels[nl], sizeof labels[nl], "lambda_%s(%s)", s->cons[c].name, s->variable);
      ln->label = labels[nl++];
    }
    P->nlines = nc;
    P->title = "Multiplier fields of the pointwise constraints (at the nodes)";
    P->xlabel = s->variable;
    P->ylabel = "multiplier";
  }
  if (path >= 0 && components) {
    /* the path on the left half, the other panels stacked on the right */
    int right = npan - 1, height = right > 1 ? 120 + 400 * right : 640;
    double m = 60.0 / height; /* room for a title and a label line, in page units */
    pan[path].vp[0] = 0.07;
    pan[path].vp[1] = 0.45;
    pan[path].vp[2] = 1.5 * m;
    pan[path].vp[3] = 1.0 - m;
    for (int k = 0, q = 0; k < npan; k++) {
      if (k == path) continue;
      double top = 1.0 - (double)q / right, bot = 1.0 - (double)(q + 1) / right;
      pan[k].vp[0] = 0.55;
      pan[k].vp[1] = 0.97;
      pan[k].vp[2] = bot + 1.5 * m;
      pan[k].vp[3] = top - m;
      q++;
    }
    rc = cli_plot_write_page(o, 1500, height, npan, pan);
  } else {
    rc = cli_plot_write(o, npan, pan);
  }
#undef SLOT_Y
#undef SLOT_NAME
done:
  free(xs);
  free(ys);
  free(ex);
  free(er);
  free(yn);
  free(lines);
  free(labels);
  return rc;
}
