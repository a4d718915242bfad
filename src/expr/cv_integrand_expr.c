/* src/expr/cv_integrand_expr.c — cv_problem_set_integrand_expr and the formula constraints
 * (cv_problem_add_constraint_expr, cv_problem_add_integral_expr): formula strings compiled
 * with exact symbolic partials. SPDX-License-Identifier: MIT */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "core/cv_table_internal.h"
#include "expr/ex_integrand.h"

/* Names known while parsing: the variable (slot 0), the unknowns (slots 1..n, primed
 * n+1..2n) and the parameters defined so far (numbers). */
typedef struct {
  const char *var;
  int n;
  char **unk;
  int np; /* parameters usable now */
  char **pname;
  double *pval;
  int const_only; /* parsing a parameter: only numbers, pi and earlier parameters */
} names;

static void msg(char *err, size_t errlen, const char *fmt, ...) {
  if (!err || !errlen) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err, errlen, fmt, ap);
  va_end(ap);
}

static ex_id resolve(ex_dag *d, const char *name, int primes, void *user, char *err,
                     size_t errlen) {
  const names *c = user;
  for (int i = 0; i < c->np; i++)
    if (strcmp(name, c->pname[i]) == 0) {
      if (primes) {
        msg(err, errlen, "a prime is only allowed on an unknown ('%s' is a parameter)", name);
        return -1;
      }
      return ex_num(d, c->pval[i]);
    }
  int slot = -1;
  if (strcmp(name, c->var) == 0) {
    if (primes) {
      msg(err, errlen, "a prime is only allowed on an unknown ('%s' is the variable)", name);
      return -1;
    }
    slot = 0;
  }
  for (int i = 0; i < c->n && slot < 0; i++) /* y'' after y': slot 1 + 2n + i */
    if (strcmp(name, c->unk[i]) == 0) slot = 1 + i + primes * c->n;
  if (slot < 0) { /* the nearest name usable here, if a slip away (ex_name_close) */
    ex_nearest nr = {NULL, 0};
    ex_name_consider(&nr, name, c->var);
    for (int i = 0; i < c->n; i++) ex_name_consider(&nr, name, c->unk[i]);
    for (int i = 0; i < c->np; i++) ex_name_consider(&nr, name, c->pname[i]);
    if (nr.best)
      msg(err, errlen, "unknown name '%s' (did you mean '%s'?)", name, nr.best);
    else
      msg(err, errlen, "unknown name '%s'", name);
    return -1;
  }
  if (c->const_only) {
    msg(err, errlen,
        "'%s' is not a constant (a parameter may use numbers, pi and earlier "
        "parameters)",
        name);
    return -1;
  }
  ex_id e = ex_slot(d, slot);
  if (e < 0) msg(err, errlen, "out of memory");
  return e;
}

/* A usable name: an identifier that is neither a function nor pi. Returns the reason
 * it is not, or NULL. */
static const char *bad_name(const char *s) {
  if (!s[0]) return "is empty";
  if (!(isalpha((unsigned char)s[0]) || s[0] == '_')) return "does not start with a letter";
  if (!ex_is_identifier(s)) return "is not a name (letters, digits, _)";
  if (ex_is_reserved(s)) return "is reserved (a function or pi)";
  return NULL;
}

/* The kinds of formula a problem takes: what the formula is called in messages. */
typedef enum { FORMULA_INTEGRAND, FORMULA_CONSTRAINT, FORMULA_INTEGRAL } formula_kind;
static const char *const formula_what[] = {"integrand", "constraint", "integral"};

/* Parse F (with its variable, unknowns and parameters) and hand the compiled formula to
 * the problem as the integrand, a pointwise constraint (no y' allowed) or an integral
 * constraint int K = c. */
static cv_status compile(cv_problem *p, const char *variable, const char *unknowns, const char *F,
                         const char *parameters, formula_kind kind, double c_rhs, int *index,
                         char *err, size_t errlen) {
  const char *what = formula_what[kind];
  if (err && errlen) err[0] = 0;
  if (!p || !unknowns || !F) {
    msg(err, errlen, "problem, unknowns and %s must not be NULL", what);
    return CVAR_EINVAL;
  }
  cv_status st = CVAR_EINVAL;
  names c = {variable ? variable : "x", 0, NULL, 0, NULL, NULL, 0};
  ex_list unk = {0, NULL, NULL}, plist = {0, NULL, NULL};
  ex_dag *d = NULL;
  int np = 0;
  const char *why;
  char perr[300];

  if ((why = bad_name(c.var))) {
    msg(err, errlen, "variable: '%s' %s", c.var, why);
    goto cleanup;
  }
  if ((c.n = ex_list_split(unknowns, &unk)) < 0) goto nomem;
  c.unk = unk.item;
  if (c.n != cv_problem_get_num_unknowns(p)) {
    msg(err, errlen, "unknowns: %d name%s given, but the problem has %d unknown%s", c.n,
        c.n == 1 ? "" : "s", cv_problem_get_num_unknowns(p),
        cv_problem_get_num_unknowns(p) == 1 ? "" : "s");
    goto cleanup;
  }
  for (int i = 0; i < c.n; i++) {
    if ((why = bad_name(c.unk[i]))) {
      msg(err, errlen, "unknowns: '%s' %s", c.unk[i], why);
      goto cleanup;
    }
    if (strcmp(c.unk[i], c.var) == 0) {
      msg(err, errlen, "unknowns: '%s' is also the variable", c.unk[i]);
      goto cleanup;
    }
    for (int j = 0; j < i; j++)
      if (strcmp(c.unk[i], c.unk[j]) == 0) {
        msg(err, errlen, "unknowns: '%s' is listed twice", c.unk[i]);
        goto cleanup;
      }
  }
  d = ex_dag_new();
  if (!d) goto nomem;
  for (int i = 0; i < cv_problem_num_tables(p); i++) {
    const char *tn = cv_problem_table_name(p, i);
    int clash = strcmp(tn, c.var) == 0;
    for (int j = 0; j < c.n; j++) clash |= strcmp(tn, c.unk[j]) == 0;
    if (clash || (why = bad_name(tn))) {
      msg(err, errlen, "table '%s': %s", tn, clash ? "the name is already used" : why);
      goto cleanup;
    }
    if (ex_dag_add_table(d, tn, (cv_table *)cv_problem_table(p, i)) < 0) goto nomem;
  }
  if (parameters && parameters[0]) {
    if ((np = ex_list_split(parameters, &plist)) < 0) goto nomem;
    c.pname = cv_calloc((size_t)np, sizeof *c.pname);
    c.pval = cv_calloc((size_t)np, sizeof *c.pval);
    if (!c.pname || !c.pval) goto nomem;
    for (int i = 0; i < np; i++) {
      char *eq = strchr(plist.item[i], '=');
      if (!eq) {
        msg(err, errlen, "parameters: '%s' is not of the form name = value", plist.item[i]);
        goto cleanup;
      }
      char *name = plist.item[i], *end = eq;
      *eq = 0;
      while (end > name && isspace((unsigned char)end[-1])) *--end = 0;
      if ((why = bad_name(name))) {
        msg(err, errlen, "parameters: '%s' %s", name, why);
        goto cleanup;
      }
      int clash = strcmp(name, c.var) == 0 || ex_dag_find_table(d, name) >= 0;
      for (int j = 0; j < c.n; j++) clash |= strcmp(name, c.unk[j]) == 0;
      for (int j = 0; j < i; j++) clash |= strcmp(name, c.pname[j]) == 0;
      if (clash) {
        msg(err, errlen, "parameters: the name '%s' is already used", name);
        goto cleanup;
      }
      c.const_only = 1;
      c.np = i;
      const char *value = eq + 1; /* columns count from the value's first character */
      while (isspace((unsigned char)*value)) value++;
      ex_id e = ex_parse(d, value, resolve, &c, 0, perr, sizeof perr);
      double v;
      if (e < 0) {
        msg(err, errlen, "parameter '%s': %s", name, perr);
        goto cleanup;
      }
      if (ex_eval_const(d, e, &v) != 0 || !isfinite(v)) {
        msg(err, errlen, "parameter '%s': the value is not a finite number", name);
        goto cleanup;
      }
      c.pname[i] = name;
      c.pval[i] = v;
    }
  }
  c.const_only = 0;
  c.np = np;
  /* y'' in an integrand or an integral: a second-order problem (theory H-1) */
  ex_id f = ex_parse(d, F, resolve, &c, kind != FORMULA_CONSTRAINT, perr, sizeof perr);
  if (f < 0) {
    msg(err, errlen, "%s: %s", what, perr);
    goto cleanup;
  }
  if (kind == FORMULA_CONSTRAINT)
    for (int i = 0; i < c.n; i++)
      if (ex_depends_on(d, f, 1 + c.n + i)) {
        msg(err, errlen, "constraint: a pointwise constraint G(%s, y) may not involve %s'", c.var,
            c.unk[i]);
        goto cleanup;
      }
  if (kind == FORMULA_INTEGRAL && !isfinite(c_rhs)) {
    msg(err, errlen, "integral: the constant is not a finite number");
    goto cleanup;
  }
  int order = 1;
  for (int i = 0; i < c.n; i++)
    if (ex_depends_on(d, f, 1 + 2 * c.n + i)) {
      order = 2;
      if ((st = cv_problem_set_second_order(p, i)) != CVAR_OK) goto nomem;
    }
  ex_integrand *g = ex_integrand_new_order(
      d, c.n, 0, order, f, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, perr, sizeof perr);
  if (!g) {
    msg(err, errlen, "%s: %s", what, perr);
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  /* The problem owns g from here on, also when the call fails (it releases it). */
  if (kind == FORMULA_INTEGRAND)
    st = cv_problem_set_integrand_owned(p, ex_integrand_eval, g, ex_integrand_release);
  else if (kind == FORMULA_CONSTRAINT)
    st = cv_problem_add_constraint_owned(p, ex_integrand_eval_constraint, g, ex_integrand_release,
                                         index);
  else
    st = cv_problem_add_integral_owned(p, ex_integrand_eval, g, ex_integrand_release, c_rhs, index);
  /* names the table whose grid a failing solve left (g lives as long as the problem) */
  if (st == CVAR_OK && ex_integrand_has_tables(g))
    st = cv_problem_add_note(p, ex_integrand_note, g);
  if (st != CVAR_OK) msg(err, errlen, "%s", cv_strerror(st));
  goto cleanup;
nomem:
  msg(err, errlen, "out of memory");
  st = CVAR_ENOMEM;
cleanup:
  ex_dag_free(d);
  ex_list_free(&unk);
  ex_list_free(&plist);
  cv_free(c.pname);
  cv_free(c.pval);
  return st;
}

cv_status cv_problem_set_integrand_expr(cv_problem *p, const char *variable, const char *unknowns,
                                        const char *F, const char *parameters, char *err,
                                        size_t errlen) {
  return compile(p, variable, unknowns, F, parameters, FORMULA_INTEGRAND, 0.0, NULL, err, errlen);
}

cv_status cv_problem_add_constraint_expr(cv_problem *p, const char *variable, const char *unknowns,
                                         const char *G, const char *parameters, int *index,
                                         char *err, size_t errlen) {
  return compile(p, variable, unknowns, G, parameters, FORMULA_CONSTRAINT, 0.0, index, err, errlen);
}

cv_status cv_problem_add_integral_expr(cv_problem *p, const char *variable, const char *unknowns,
                                       const char *K, double c, const char *parameters, int *index,
                                       char *err, size_t errlen) {
  return compile(p, variable, unknowns, K, parameters, FORMULA_INTEGRAL, c, index, err, errlen);
}
