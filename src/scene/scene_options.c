/* src/scene/scene_options.c — [mesh] and [solver]: discretisation and method settings.
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

int sc_load_mesh(sc_loader *L);
int sc_load_solver(sc_loader *L);

/* Every method needs the Hessian too: the NLopt minimisers use F and its gradient, but the
 * error estimate of their answer is a Newton solve on the enriched mesh (theory HP-2),
 * which without second partials aborted at its first step ("no error estimate"). */
unsigned scene_method_need(cv_method m) {
  (void)m;
  return CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS;
}

/* A whole number written in decimal digits (no expression: counts are not computed). */
static int parse_count(sc_loader *L, const sc_entry *e, long lo, long hi, int *out) {
  const char *p = e->value;
  char *end;
  if (*p == '+') p++;
  long v = (*p >= '0' && *p <= '9') ? strtol(p, &end, 10) : -1;
  if (v < 0 || *end != '\0' || v < lo || v > hi) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "%s must be a whole number from %ld to %ld, "
           "got '%s'",
           e->key, lo, hi, e->value);
    return -1;
  }
  *out = (int)v;
  return 0;
}

static int cmp_double(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

static int load_breakpoints(sc_loader *L, const sc_entry *e) {
  scene *s = L->s;
  ex_list list;
  if (ex_list_split(e->value, &list) < 0 ||
      !(s->breakpoints = cv_malloc((size_t)list.n * sizeof *s->breakpoints))) {
    ex_list_free(&list);
    sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
    return -1;
  }
  for (int i = 0; i < list.n; i++) {
    double v;
    if (sc_parse_const(L, e, list.off[i], list.item[i], "breakpoint", &v) < 0) {
      ex_list_free(&list);
      return -1;
    }
    if (!(v > s->a && v < s->b)) {
      sc_err(L->err, L->errlen, L->file, e->line,
             "breakpoint %.17g is not inside the interval (%.17g, %.17g)", v, s->a, s->b);
      ex_list_free(&list);
      return -1;
    }
    s->breakpoints[s->nbreak++] = v;
  }
  ex_list_free(&list);
  qsort(s->breakpoints, (size_t)s->nbreak, sizeof *s->breakpoints, cmp_double);
  for (int i = 1; i < s->nbreak; i++)
    if (s->breakpoints[i] == s->breakpoints[i - 1]) {
      sc_err(L->err, L->errlen, L->file, e->line, "breakpoint %.17g is given twice",
             s->breakpoints[i]);
      return -1;
    }
  return 0;
}

int sc_load_mesh(sc_loader *L) {
  static const char *const keys[] = {"elements", "degree",  "breakpoints", "adapt",
                                     "tol",      "grading", "grading_at",  NULL};
  scene *s = L->s;
  s->elements = 100;
  s->degree = 1;
  s->graded_end = CVAR_GRADE_A;
  if (sc_check_keys(L, SEC_MESH, keys,
                    "elements, degree, breakpoints, adapt, tol, grading, grading_at") < 0)
    return -1;
  for (int i = 0; i < L->raw.ne[SEC_MESH]; i++) {
    const sc_entry *e = &L->raw.e[SEC_MESH][i];
    const char *k = e->key;
    if (strcmp(k, "elements") == 0) {
      /* INT_MAX / 9: nodes = elements * degree + 1 must stay an int at degree 8. */
      if (parse_count(L, e, 1, INT_MAX / 9, &s->elements) < 0) return -1;
      s->elements_line = e->line;
    } else if (strcmp(k, "degree") == 0) {
      if (parse_count(L, e, 1, 8, &s->degree) < 0) return -1;
      s->degree_line = e->line;
    } else if (strcmp(k, "breakpoints") == 0) {
      if (load_breakpoints(L, e) < 0) return -1;
    } else if (strcmp(k, "adapt") == 0) {
      if (sc_parse_const(L, e, 0, e->value, "adapt", &s->adapt) < 0) return -1;
      if (!(s->adapt > 0)) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "adapt is the target max nodal error and must be > 0, got %g", s->adapt);
        return -1;
      }
      s->adapt_line = e->line;
    } else if (strcmp(k, "tol") == 0) {
      if (sc_parse_const(L, e, 0, e->value, "tol", &s->tol) < 0) return -1;
      if (!(s->tol > 0)) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "tol is the target max nodal error and must be > 0, got %g", s->tol);
        return -1;
      }
      s->tol_line = e->line;
    } else if (strcmp(k, "grading") == 0) {
      if (sc_parse_const(L, e, 0, e->value, "grading", &s->grading) < 0) return -1;
      if (!(s->grading >= 1 && s->grading <= 20)) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "grading is the exponent k of x = a + (b - a) t^k, from 1 to 20, got %g",
               s->grading);
        return -1;
      }
    } else { /* grading_at */
      const char *v = e->value;
      if (strcmp(v, "a") == 0)
        s->graded_end = CVAR_GRADE_A;
      else if (strcmp(v, "b") == 0)
        s->graded_end = CVAR_GRADE_B;
      else if (strcmp(v, "both") == 0)
        s->graded_end = CVAR_GRADE_BOTH;
      else {
        sc_err(L->err, L->errlen, L->file, e->line, "grading_at must be a, b or both, got '%s'", v);
        return -1;
      }
    }
  }
  if (s->tol > 0 && s->adapt > 0) {
    sc_err(L->err, L->errlen, L->file, s->tol_line > s->adapt_line ? s->tol_line : s->adapt_line,
           "tol and adapt cannot both be given (tol chooses the mesh and the degrees, adapt "
           "the mesh at one degree)");
    return -1;
  }
  return 0;
}

int sc_load_solver(sc_loader *L) {
  static const char *const keys[] = {"method", "tolerance", "max_iterations", NULL};
  scene *s = L->s;
  s->method = CVAR_METHOD_NEWTON;
  s->tolerance = 1e-10;
  s->max_iterations = 50;
  if (sc_check_keys(L, SEC_SOLVER, keys, "method, tolerance, max_iterations") < 0) return -1;
  for (int i = 0; i < L->raw.ne[SEC_SOLVER]; i++) {
    const sc_entry *e = &L->raw.e[SEC_SOLVER][i];
    if (strcmp(e->key, "method") == 0) {
      if (cv_method_from_name(e->value, &s->method) != CVAR_OK) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "unknown method '%s' (known: newton, "
               "lbfgs, tnewton, mma, ccsaq, slsqp, auglag)",
               e->value);
        return -1;
      }
      s->method_line = e->line;
    } else if (strcmp(e->key, "tolerance") == 0) {
      if (sc_parse_const(L, e, 0, e->value, "tolerance", &s->tolerance) < 0) return -1;
      /* The core rejects rtol below 10 eps: a step test cannot resolve less. */
      if (!(s->tolerance >= 10 * DBL_EPSILON && s->tolerance < 1)) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "tolerance must be at least 10 eps = %.3g and below 1, got %g", 10 * DBL_EPSILON,
               s->tolerance);
        return -1;
      }
    } else if (parse_count(L, e, 1, INT_MAX, &s->max_iterations) < 0) {
      return -1;
    }
  }
  return 0;
}

/* The slot of a name in [plot]: 0 for the variable, 1 + i for unknown i, -1 otherwise. */
static int plot_slot(const scene *s, const char *name) {
  if (strcmp(name, s->variable) == 0) return 0;
  for (int i = 0; i < s->n; i++)
    if (strcmp(name, s->unknowns[i]) == 0) return 1 + i;
  return -1;
}

/* [plot] (an addition): `path = U, V` draws V against U with equal scales (U and V the
 * variable or unknowns, distinct); `downward = names` draws those names increasing
 * downward (the brachistochrone's y is a depth). */
int sc_load_plot(sc_loader *L) {
  static const char *const keys[] = {"path", "downward", NULL};
  scene *s = L->s;
  s->plot_path[0] = s->plot_path[1] = -1;
  if (!(s->plot_down = cv_calloc((size_t)s->n + 1, sizeof *s->plot_down))) {
    sc_err(L->err, L->errlen, L->file, 0, "out of memory");
    return -1;
  }
  if (sc_check_keys(L, SEC_PLOT, keys, "path, downward") < 0) return -1;
  for (int i = 0; i < L->raw.ne[SEC_PLOT]; i++) {
    const sc_entry *e = &L->raw.e[SEC_PLOT][i];
    ex_list list;
    if (ex_list_split(e->value, &list) < 0) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
    int is_path = strcmp(e->key, "path") == 0, rc = 0;
    if (is_path && list.n != 2) {
      sc_err(L->err, L->errlen, L->file, e->line,
             "path needs two names (horizontal, "
             "vertical), got %d",
             list.n);
      rc = -1;
    }
    for (int k = 0; k < list.n && rc == 0; k++) {
      int slot = plot_slot(s, list.item[k]);
      if (slot < 0) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "%s: '%s' is neither the variable nor "
               "an unknown",
               e->key, list.item[k]);
        rc = -1;
      } else if (is_path) {
        s->plot_path[k] = slot;
      } else {
        s->plot_down[slot] = 1;
      }
    }
    if (rc == 0 && is_path && s->plot_path[0] == s->plot_path[1]) {
      sc_err(L->err, L->errlen, L->file, e->line, "path: '%s' against itself", list.item[0]);
      rc = -1;
    }
    ex_list_free(&list);
    if (rc < 0) return -1;
  }
  return 0;
}
