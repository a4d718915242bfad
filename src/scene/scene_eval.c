/* src/scene/scene_eval.c — evaluate scene expressions over batches of points: exact
 * solutions, guesses and report integrands.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

/* Points per tape call: bounds the tape's scratch memory whatever m is. */
enum { BATCH = 256 };

/* out[o*m + k] = outs[o] at point k. y and dy (n*m each, y[i*m + k]) may be NULL when the
 * outputs do not use them. Compiles one tape for all outputs, so shared subexpressions
 * are computed once. */
int sc_eval_exprs(const scene *s, int nout, const ex_id *outs, int m, const double *x,
                  const double *y, const double *dy, double *out) {
  return sc_eval_exprs2(s, nout, outs, m, x, y, dy, NULL, out);
}

int sc_eval_exprs2(const scene *s, int nout, const ex_id *outs, int m, const double *x,
                   const double *y, const double *dy, const double *d2y, double *out) {
  int n = s->n, np = s->params_as_inputs ? s->nparams : 0, ns = 1 + 2 * n + np, rc = -1;
  if (s->c1) ns = sc_d2_slot(s, n); /* y'' after the parameters and the width */
  if (nout == 0 || m == 0) return 0;
  ex_tape *t = ex_tape_new(s->dag, ns, nout, outs);
  const double **in = cv_calloc((size_t)ns, sizeof *in);
  double **o = cv_malloc((size_t)nout * sizeof *o);
  double *work = t ? cv_malloc((ex_tape_work_size(t, BATCH) + 1) * sizeof *work) : NULL;
  /* parameters as inputs: one batch per parameter filled with its value */
  double *pb = cv_malloc(((size_t)np * BATCH + 1) * sizeof *pb);
  if (!t || !in || !o || !work || !pb) goto done;
  for (int j = 0; j < np; j++) {
    for (int k = 0; k < BATCH; k++) pb[(size_t)j * BATCH + k] = s->params[j].value;
    in[1 + 2 * n + j] = pb + (size_t)j * BATCH;
  }
  for (int k0 = 0; k0 < m; k0 += BATCH) {
    int b = m - k0 < BATCH ? m - k0 : BATCH;
    in[0] = x + k0;
    for (int i = 0; i < n; i++) {
      in[1 + i] = y ? y + (size_t)i * m + k0 : NULL;
      in[1 + n + i] = dy ? dy + (size_t)i * m + k0 : NULL;
      if (s->c1) in[sc_d2_slot(s, i)] = d2y ? d2y + (size_t)i * m + k0 : NULL;
    }
    for (int q = 0; q < nout; q++) o[q] = out + (size_t)q * m + k0;
    ex_tape_eval(t, b, (const double *const *)in, (double *const *)o, work);
  }
  rc = 0;
done:
  cv_free(pb);
  cv_free(work);
  cv_free(o);
  cv_free(in);
  ex_tape_free(t);
  return rc;
}

int scene_eval_exact(const scene *s, int m, const double *x, double *exact) {
  for (int i = 0; i < s->n; i++) {
    double *e = exact + (size_t)i * m;
    if (s->exact[i] < 0) {
      for (int k = 0; k < m; k++) e[k] = NAN;
    } else if (sc_eval_exprs(s, 1, &s->exact[i], m, x, NULL, NULL, e) < 0) {
      return -1;
    }
  }
  return 0;
}

/* The default guess of SCENES.md [guess]: the straight line between the end values; with
 * one free end, the constant fixed value; with both free, 0. */
int scene_eval_guess(const scene *s, int m, const double *x, double *y) {
  for (int i = 0; i < s->n; i++) {
    double *g = y + (size_t)i * m;
    const sc_boundary *bc = &s->bc[i];
    if (s->guess[i] >= 0) {
      if (sc_eval_exprs(s, 1, &s->guess[i], m, x, NULL, NULL, g) < 0) return -1;
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

int scene_F_depends_on_unknown(const scene *s, int i) { return ex_depends_on(s->dag, s->F, 1 + i); }

int scene_eval_reports(scene *s, int m, const double *x, const double *y, const double *dy,
                       double *out) {
  return scene_eval_reports2(s, m, x, y, dy, NULL, out);
}

int scene_eval_reports2(scene *s, int m, const double *x, const double *y, const double *dy,
                        const double *d2y, double *out) {
  int nr = s->nreports, rc;
  ex_id *outs = cv_malloc((size_t)(nr + 1) * sizeof *outs);
  if (!outs) return -1;
  for (int r = 0; r < nr; r++) outs[r] = s->reports[r].expr;
  rc = sc_eval_exprs2(s, nr, outs, m, x, y, dy, d2y, out);
  cv_free(outs);
  return rc;
}

/* Parameters as inputs: the values and everything computed from them, in the order the
 * loader computed them (scene.h). */
int scene_set_parameters(scene *s, const unsigned char *given, const double *vals, char *err,
                         size_t errlen) {
  if (err && errlen) err[0] = '\0';
  if (!s->params_as_inputs) {
    sc_err(err, errlen, s->file, 0, "the scene was loaded with its parameters folded");
    return -1;
  }
  for (int i = 0; i < s->nparams; i++) {
    double v = vals && given && given[i] ? vals[i] : NAN;
    if (!(given && given[i]) && sc_eval_params(s, s->params[i].expr2, &v) < 0) goto nomem;
    if (!isfinite(v)) {
      sc_err(err, errlen, s->file, 0, "parameter '%s' is not a finite number (%g)",
             s->params[i].name, v);
      return -1;
    }
    s->params[i].value = v;
  }
  if (sc_eval_params(s, s->a_expr, &s->a) < 0 || sc_eval_params(s, s->b_expr, &s->b) < 0)
    goto nomem;
  if (!(s->a < s->b)) { /* also false for NaN */
    sc_err(err, errlen, s->file, 0, "interval needs a < b, got a = %.17g, b = %.17g", s->a, s->b);
    return -1;
  }
  for (int i = 0; i < s->n; i++)
    for (int end = 0; end < 2; end++) {
      if (s->bc[i].free_end[end]) continue;
      if (sc_eval_params(s, s->bc[i].expr[end], &s->bc[i].value[end]) < 0) goto nomem;
      if (!isfinite(s->bc[i].value[end])) {
        sc_err(err, errlen, s->file, s->bc[i].line,
               "[boundary] %s at %s is not a finite "
               "number",
               s->unknowns[i], end ? "b" : "a");
        return -1;
      }
    }
  for (int i = 0; s->sbc && i < s->n; i++) /* slope lines (second derivatives) */
    for (int end = 0; end < 2 && s->sbc[i].line; end++) {
      if (s->sbc[i].free_end[end]) continue;
      if (sc_eval_params(s, s->sbc[i].expr[end], &s->sbc[i].value[end]) < 0) goto nomem;
      if (!isfinite(s->sbc[i].value[end])) {
        sc_err(err, errlen, s->file, s->sbc[i].line, "[boundary] %s' at %s is not a finite number",
               s->unknowns[i], end ? "b" : "a");
        return -1;
      }
    }
  for (int k = 0; k < s->nints; k++) {
    if (sc_eval_params(s, s->ints[k].expr2, &s->ints[k].value) < 0) goto nomem;
    if (!isfinite(s->ints[k].value)) {
      sc_err(err, errlen, s->file, s->ints[k].line,
             "[integrals] %s: the value c is not a "
             "finite number",
             s->ints[k].name);
      return -1;
    }
  }
  if (s->has_exact_action && sc_eval_params(s, s->exact_action_expr, &s->exact_action) < 0)
    goto nomem;
  return 0;
nomem:
  sc_err(err, errlen, s->file, 0, "out of memory");
  return -1;
}

scene *scene_instance_new(const scene *s) {
  scene *c = cv_malloc(sizeof *c);
  if (!c) return NULL;
  *c = *s;
  c->is_instance = 1;
  c->params = cv_malloc(((size_t)s->nparams + 1) * sizeof *c->params);
  c->bc = cv_malloc(((size_t)s->n + 1) * sizeof *c->bc);
  c->ints = cv_malloc(((size_t)s->nints + 1) * sizeof *c->ints);
  c->sbc = s->sbc ? cv_malloc((size_t)s->n * sizeof *c->sbc) : NULL; /* its own slopes */
  if (!c->params || !c->bc || !c->ints || (s->sbc && !c->sbc)) {
    scene_free(c);
    return NULL;
  }
  memcpy(c->params, s->params, (size_t)s->nparams * sizeof *c->params);
  memcpy(c->bc, s->bc, (size_t)s->n * sizeof *c->bc);
  memcpy(c->ints, s->ints, (size_t)s->nints * sizeof *c->ints);
  if (s->sbc) memcpy(c->sbc, s->sbc, (size_t)s->n * sizeof *c->sbc);
  return c;
}
