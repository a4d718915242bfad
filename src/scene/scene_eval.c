/* src/scene/scene_eval.c — evaluate scene expressions over batches of points: exact
 * solutions, guesses and report integrands.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>

#include "scene/scene_internal.h"

/* Points per tape call: bounds the tape's scratch memory whatever m is. */
enum { BATCH = 256 };

/* out[o*m + k] = outs[o] at point k. y and dy (n*m each, y[i*m + k]) may be NULL when the
 * outputs do not use them. Compiles one tape for all outputs, so shared subexpressions
 * are computed once. */
int sc_eval_exprs(const scene *s, int nout, const ex_id *outs, int m, const double *x,
                  const double *y, const double *dy, double *out)
{
  int n = s->n, ns = 1 + 2 * n, rc = -1;
  if (nout == 0 || m == 0)
    return 0;
  ex_tape *t = ex_tape_new(s->dag, ns, nout, outs);
  const double **in = cv_malloc((size_t)ns * sizeof *in);
  double **o = cv_malloc((size_t)nout * sizeof *o);
  double *work = t ? cv_malloc((ex_tape_work_size(t, BATCH) + 1) * sizeof *work) : NULL;
  if (!t || !in || !o || !work)
    goto done;
  for (int k0 = 0; k0 < m; k0 += BATCH) {
    int b = m - k0 < BATCH ? m - k0 : BATCH;
    in[0] = x + k0;
    for (int i = 0; i < n; i++) {
      in[1 + i] = y ? y + (size_t)i * m + k0 : NULL;
      in[1 + n + i] = dy ? dy + (size_t)i * m + k0 : NULL;
    }
    for (int q = 0; q < nout; q++)
      o[q] = out + (size_t)q * m + k0;
    ex_tape_eval(t, b, (const double *const *)in, (double *const *)o, work);
  }
  rc = 0;
done:
  cv_free(work);
  cv_free(o);
  cv_free(in);
  ex_tape_free(t);
  return rc;
}

int scene_eval_exact(const scene *s, int m, const double *x, double *exact)
{
  for (int i = 0; i < s->n; i++) {
    double *e = exact + (size_t)i * m;
    if (s->exact[i] < 0) {
      for (int k = 0; k < m; k++)
        e[k] = NAN;
    } else if (sc_eval_exprs(s, 1, &s->exact[i], m, x, NULL, NULL, e) < 0) {
      return -1;
    }
  }
  return 0;
}

/* The default guess of SCENES.md [guess]: the straight line between the end values; with
 * one free end, the constant fixed value; with both free, 0. */
int scene_eval_guess(const scene *s, int m, const double *x, double *y)
{
  for (int i = 0; i < s->n; i++) {
    double *g = y + (size_t)i * m;
    const sc_boundary *bc = &s->bc[i];
    if (s->guess[i] >= 0) {
      if (sc_eval_exprs(s, 1, &s->guess[i], m, x, NULL, NULL, g) < 0)
        return -1;
      continue;
    }
    for (int k = 0; k < m; k++) {
      double t = (x[k] - s->a) / (s->b - s->a);
      if (!bc->free_end[0] && !bc->free_end[1])
        g[k] = bc->value[0] + t * (bc->value[1] - bc->value[0]);
      else if (!bc->free_end[0])
        g[k] = bc->value[0];
      else if (!bc->free_end[1])
        g[k] = bc->value[1];
      else
        g[k] = 0.0;
    }
  }
  return 0;
}

int scene_F_depends_on_variable(const scene *s) { return ex_depends_on(s->dag, s->F, 0); }

int scene_F_depends_on_unknown(const scene *s, int i)
{
  return ex_depends_on(s->dag, s->F, 1 + i);
}

int scene_eval_reports(scene *s, int m, const double *x, const double *y, const double *dy,
                       double *out)
{
  int nr = s->nreports, rc;
  ex_id *outs = cv_malloc((size_t)(nr + 1) * sizeof *outs);
  if (!outs)
    return -1;
  for (int r = 0; r < nr; r++)
    outs[r] = s->reports[r].expr;
  rc = sc_eval_exprs(s, nr, outs, m, x, y, dy, out);
  cv_free(outs);
  return rc;
}
