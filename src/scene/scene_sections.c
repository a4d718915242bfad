/* src/scene/scene_sections.c — [boundary], [guess], [exact], [constraints], [integrals],
 * [report]: the sections keyed by unknowns or by free names.
 * SPDX-License-Identifier: MIT */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

int sc_load_boundary(sc_loader *L);
int sc_load_guess_exact(sc_loader *L);
int sc_load_constraints(sc_loader *L);
int sc_load_report(sc_loader *L);

static int unknown_index(const scene *s, const char *name) {
  for (int i = 0; i < s->n; i++)
    if (strcmp(s->unknowns[i], name) == 0) return i;
  return -1;
}

static int nomem(sc_loader *L, int line) {
  sc_err(L->err, L->errlen, L->file, line, "out of memory");
  return -1;
}

/* Levenshtein distance of two short words, capped: for "did you mean 'free'?". */
static int distance(const char *a, const char *b) {
  size_t na = strlen(a), nb = strlen(b);
  if (na > 12 || nb > 12) return 99;
  int d[13][13];
  for (size_t i = 0; i <= na; i++) d[i][0] = (int)i;
  for (size_t j = 0; j <= nb; j++) d[0][j] = (int)j;
  for (size_t i = 1; i <= na; i++)
    for (size_t j = 1; j <= nb; j++) {
      int c = d[i - 1][j - 1] + (tolower((unsigned char)a[i - 1]) != b[j - 1]);
      int u = d[i - 1][j] + 1, l = d[i][j - 1] + 1;
      d[i][j] = c < u ? (c < l ? c : l) : (u < l ? u : l);
    }
  return d[na][nb];
}

/* Is this item a misspelt `free` (Free, FREE, fre, frее...)? Only bare words that are not
 * names of the scene qualify, so a parameter called `fee` still works. */
static int looks_like_free(const scene *s, const char *t) {
  if (!ex_is_identifier(t) || strcmp(t, "free") == 0 || distance(t, "free") > 1) return 0;
  if (unknown_index(s, t) >= 0 || strcmp(t, s->variable) == 0) return 0;
  for (int i = 0; i < s->nparams; i++)
    if (strcmp(t, s->params[i].name) == 0) return 0;
  for (int i = 0; i < s->ndefs; i++)
    if (strcmp(t, s->defs[i].name) == 0) return 0;
  return 1;
}

/* Does a [boundary] value start with the word 'periodic'? */
static int is_periodic(const char *v) {
  return strncmp(v, "periodic", 8) == 0 && !(isalnum((unsigned char)v[8]) || v[8] == '_');
}

/* 'periodic' or 'periodic + D' (D a constant expression): y(b) = y(a) + D, both end values
 * free (SCENES.md; theory PB-1). */
static int load_periodic(sc_loader *L, const sc_entry *e, sc_boundary *bc) {
  const char *rest = e->value + 8;
  while (*rest == ' ' || *rest == '\t') rest++;
  bc->line = e->line;
  bc->periodic = 1;
  bc->free_end[0] = bc->free_end[1] = 1;
  bc->shift = 0.0;
  if (*rest == '\0') return 0;
  char what[160];
  snprintf(what, sizeof what, "[boundary] %s = periodic + D: D", e->key);
  if (*rest == ',') {
    sc_err(L->err, L->errlen, L->file, e->line,
           "[boundary] %s: 'periodic' replaces both end values; write '%s = periodic' (or "
           "'periodic + D' for y(b) = y(a) + D) alone on the line",
           e->key, e->key);
    return -1;
  }
  if (*rest != '+' && *rest != '-') {
    sc_err(L->err, L->errlen, L->file, e->line,
           "[boundary] %s: after 'periodic' only '+ D' may follow (y(b) = y(a) + D), got '%s'",
           e->key, rest);
    return -1;
  }
  int neg = *rest == '-';
  rest++;
  ex_id node;
  if (sc_parse_const_node(L, e, (int)(rest - e->value), rest, what, &bc->shift, &node) < 0)
    return -1;
  if (neg) bc->shift = -bc->shift;
  return 0;
}

int sc_load_boundary(sc_loader *L) {
  scene *s = L->s;
  s->bc = cv_calloc((size_t)s->n, sizeof *s->bc);
  if (!s->bc) return nomem(L, 0);
  for (int k = 0; k < s->n; k++) s->bc[k].expr[0] = s->bc[k].expr[1] = -1;
  for (int i = 0; i < L->raw.ne[SEC_BOUNDARY]; i++) {
    const sc_entry *e = &L->raw.e[SEC_BOUNDARY][i];
    int k = unknown_index(s, e->key);
    size_t kl = strlen(e->key);
    if (k < 0 && kl > 1 && e->key[kl - 1] == '\'') { /* y' = a, b: a slope line (H-1) */
      char base[128];
      snprintf(base, sizeof base, "%.*s", (int)(kl - 1), e->key);
      if ((k = unknown_index(s, base)) >= 0) {
        if (sc_load_slope_line(L, e, k) < 0) return -1;
        continue;
      }
    }
    if (k < 0) {
      sc_err(L->err, L->errlen, L->file, e->line, "'%s' in [boundary] is not an unknown", e->key);
      return -1;
    }
    if (is_periodic(e->value)) {
      if (load_periodic(L, e, &s->bc[k]) < 0) return -1;
      continue;
    }
    ex_list list;
    if (ex_list_split(e->value, &list) < 0) return nomem(L, e->line);
    for (int end = 0; end < list.n; end++)
      if (is_periodic(list.item[end])) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "[boundary] %s: 'periodic' replaces both end values; write '%s = periodic' "
               "(or 'periodic + D' for y(b) = y(a) + D) alone on the line",
               e->key, e->key);
        ex_list_free(&list);
        return -1;
      }
    if (list.n != 2) {
      sc_err(L->err, L->errlen, L->file, e->line,
             "[boundary] %s needs two values 'value_at_a, value_at_b', got %d", e->key, list.n);
      ex_list_free(&list);
      return -1;
    }
    s->bc[k].line = e->line;
    for (int end = 0; end < 2; end++) {
      const char *t = list.item[end];
      char what[160];
      if (strcmp(t, "free") == 0) {
        s->bc[k].free_end[end] = 1;
        continue;
      }
      if (looks_like_free(s, t)) {
        sc_err(L->err, L->errlen, L->file, e->line,
               "[boundary] %s: '%s' is not a value; did you mean 'free' (lower case)?", e->key, t);
        ex_list_free(&list);
        return -1;
      }
      snprintf(what, sizeof what, "[boundary] %s at %s", e->key, end ? "b" : "a");
      if (sc_parse_const_node(L, e, list.off[end], t, what, &s->bc[k].value[end],
                              &s->bc[k].expr[end]) < 0) {
        ex_list_free(&list);
        return -1;
      }
    }
    ex_list_free(&list);
  }
  for (int k = 0; k < s->n; k++)
    if (!s->bc[k].line) {
      int line = L->raw.sec_line[SEC_BOUNDARY];
      if (!line) /* no [boundary] at all: point at the unknowns line */
        for (int i = 0; i < L->raw.ne[SEC_SCENE]; i++)
          if (strcmp(L->raw.e[SEC_SCENE][i].key, "unknowns") == 0)
            line = L->raw.e[SEC_SCENE][i].line;
      sc_err(L->err, L->errlen, L->file, line,
             "[boundary] has no line for the unknown '%s' (write '%s = value_at_a, "
             "value_at_b', either may be 'free')",
             s->unknowns[k], s->unknowns[k]);
      return -1;
    }
  return 0;
}

/* An expression of the variable alone (a [guess] or an [exact] solution). */
static ex_id parse_of_variable(sc_loader *L, const sc_entry *e, const char *what) {
  char nb[128];
  ex_id r = sc_parse(L, e, 0, e->value, what);
  if (r < 0) return -1;
  int slot = sc_first_slot(L->s, r, 1, 2 * L->s->n), k2;
  if (slot < 0 && sc_uses_second(L->s, r, &k2)) slot = sc_d2_slot(L->s, k2);
  if (slot >= 0) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "%s may depend only on the variable '%s', not on '%s'", what, L->s->variable,
           sc_slot_name(L->s, slot, nb, sizeof nb));
    return -1;
  }
  return r;
}

int sc_load_guess_exact(sc_loader *L) {
  scene *s = L->s;
  s->guess = cv_malloc((size_t)s->n * sizeof *s->guess);
  s->exact = cv_malloc((size_t)s->n * sizeof *s->exact);
  if (!s->guess || !s->exact) return nomem(L, 0);
  for (int i = 0; i < s->n; i++) s->guess[i] = s->exact[i] = -1;
  for (int sec = SEC_GUESS; sec <= SEC_EXACT; sec += SEC_EXACT - SEC_GUESS) {
    for (int i = 0; i < L->raw.ne[sec]; i++) {
      const sc_entry *e = &L->raw.e[sec][i];
      char what[160];
      snprintf(what, sizeof what, "[%s] %s", sc_section_name(sec), e->key);
      if (sec == SEC_EXACT && strcmp(e->key, "action") == 0) {
        if (sc_parse_const_node(L, e, 0, e->value, "[exact] action", &s->exact_action,
                                &s->exact_action_expr) < 0)
          return -1;
        s->has_exact_action = 1;
        continue;
      }
      int k = unknown_index(s, e->key);
      if (k < 0) {
        sc_err(L->err, L->errlen, L->file, e->line, "'%s' in [%s] is not an unknown%s", e->key,
               sc_section_name(sec), sec == SEC_EXACT ? " (nor 'action')" : "");
        return -1;
      }
      ex_id r = parse_of_variable(L, e, what);
      if (r < 0) return -1;
      (sec == SEC_GUESS ? s->guess : s->exact)[k] = r;
    }
  }
  return 0;
}

/* The comparison at the top level of a [constraints] value (outside parentheses), or -1:
 * *sense +1 for '>=', -1 for '<=', 2 for a strict '>' or '<'; *oplen its length. */
static long top_comparison(const char *v, int *sense, int *oplen) {
  int depth = 0;
  for (long i = 0; v[i]; i++) {
    char c = v[i];
    depth += (c == '(') - (c == ')');
    if (depth != 0 || (c != '<' && c != '>')) continue;
    *oplen = v[i + 1] == '=' ? 2 : 1;
    *sense = *oplen == 1 ? 2 : c == '>' ? 1 : -1;
    return i;
  }
  return -1;
}

/* A [constraints] line: 'G' (an equality G = 0), 'G >= 0' or 'G <= 0' (an inequality,
 * SCENES.md; theory OB-1). The right-hand side must be 0. */
static int load_constraint(sc_loader *L, const sc_entry *e, sc_item *it, const char *what) {
  int sense = 0, oplen = 0;
  const char *typo = strstr(e->value, "=>") ? "=>" : strstr(e->value, "=<") ? "=<" : NULL;
  if (typo) {
    sc_err(L->err, L->errlen, L->file, e->line, "%s: '%s' is not an operator; write '%s'", what,
           typo, typo[1] == '>' ? ">=" : "<=");
    return -1;
  }
  if (strstr(e->value, "==")) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "%s: an equality is written 'name = G' (it imposes G = 0), without '=='", what);
    return -1;
  }
  long at = top_comparison(e->value, &sense, &oplen);
  if (at < 0) return (it->expr = sc_parse(L, e, 0, e->value, what)) < 0 ? -1 : 0;
  if (sense == 2) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "%s: a strict comparison cannot be imposed; write 'G >= 0' or 'G <= 0'", what);
    return -1;
  }
  const char *rhs = e->value + at + oplen;
  while (*rhs == ' ' || *rhs == '\t') rhs++;
  double zero = 0.0;
  char *lhs = cv_malloc((size_t)at + 1);
  if (!lhs) return nomem(L, e->line);
  memcpy(lhs, e->value, (size_t)at);
  lhs[at] = '\0';
  while (at > 0 && (lhs[at - 1] == ' ' || lhs[at - 1] == '\t')) lhs[--at] = '\0';
  int rc = (it->expr = sc_parse(L, e, 0, lhs, what)) < 0 ? -1 : 0;
  ex_id rnode = rc ? -1 : sc_parse(L, e, (int)(rhs - e->value), rhs, what);
  if (rnode < 0) rc = -1;
  /* the right side must be the number 0: anything else (a number, x, an unknown, a
   * parameter) belongs in G */
  if (rc == 0 && (ex_eval_const(L->s->dag, rnode, &zero) != 0 || zero != 0.0)) {
    sc_err(L->err, L->errlen, L->file, e->line,
           "%s: an inequality is written 'G >= 0' or 'G <= 0' with 0 on the right; move '%s' "
           "into G: %s - (%s) %s 0",
           what, rhs, lhs, rhs, sense > 0 ? ">=" : "<=");
    rc = -1;
  }
  cv_free(lhs);
  it->sense = sense;
  return rc;
}

/* Items of [constraints], [integrals] and [report]: a name and one expression. */
static int load_named(sc_loader *L, int sec, sc_item **out, int *nout) {
  int ne = L->raw.ne[sec];
  *out = cv_calloc((size_t)ne + 1, sizeof **out);
  if (!*out) return nomem(L, 0);
  for (int i = 0; i < ne; i++) {
    const sc_entry *e = &L->raw.e[sec][i];
    sc_item *it = &(*out)[i];
    char what[160];
    if (!ex_is_identifier(e->key)) {
      sc_err(L->err, L->errlen, L->file, e->line, "'%s' is not a valid name in [%s]", e->key,
             sc_section_name(sec));
      return -1;
    }
    it->name = sc_strdup(e->key);
    it->line = e->line;
    it->expr = it->expr2 = -1;
    *nout = i + 1;
    if (!it->name) return nomem(L, e->line);
    snprintf(what, sizeof what, "[%s] %s", sc_section_name(sec), e->key);
    if (sec == SEC_CONSTRAINTS) {
      if (load_constraint(L, e, it, what) < 0) return -1;
      continue;
    }
    if (sec != SEC_INTEGRALS) {
      if ((it->expr = sc_parse(L, e, 0, e->value, what)) < 0) return -1;
      continue;
    }
    ex_list list;
    if (ex_list_split(e->value, &list) < 0) return nomem(L, e->line);
    int rc = -1;
    if (list.n != 2)
      sc_err(L->err, L->errlen, L->file, e->line,
             "[integrals] %s needs 'K, c' (the integral of K equals c), got %d values", e->key,
             list.n);
    else if ((it->expr = sc_parse(L, e, list.off[0], list.item[0], what)) >= 0 &&
             sc_parse_const_node(L, e, list.off[1], list.item[1], "[integrals] value c", &it->value,
                                 &it->expr2) == 0) {
      if (!L->s->params_as_inputs) it->expr2 = ex_num(L->s->dag, it->value);
      rc = 0;
    }
    ex_list_free(&list);
    if (rc < 0) return -1;
  }
  return 0;
}

/* A pointwise constraint must hold at the fixed end values (SCENES.md). Tolerance: the
 * first-order effect of rounding the ends, |G| <= 1e-8 (1 + sum_i |y_i dG/dy_i|), so that
 * x^2 + y^2 - l^2 passes at (l sin 1, -l cos 1) for any scale of l. */
static int check_constraint_ends(sc_loader *L, const sc_item *c) {
  scene *s = L->s;
  int n = s->n;
  for (int end = 0; end < 2; end++) {
    int fixed = 1;
    for (int i = 0; i < n; i++)
      if (ex_depends_on(s->dag, c->expr, 1 + i) && s->bc[i].free_end[end]) fixed = 0;
    if (!fixed) continue;
    int ns = 1 + 2 * n;
    ex_id *outs = cv_malloc((size_t)(n + 1) * sizeof *outs);
    double x = end ? s->b : s->a, *y = cv_calloc((size_t)(ns + n + 1), sizeof *y);
    double *v = y ? y + ns : NULL;
    if (!outs || !y) {
      cv_free(outs);
      cv_free(y);
      return nomem(L, c->line);
    }
    outs[0] = c->expr;
    int rc = 0;
    for (int i = 0; i < n; i++)
      if ((outs[1 + i] = ex_diff(s->dag, c->expr, 1 + i)) < 0) rc = -1;
    for (int i = 0; i < n; i++) y[i] = s->bc[i].free_end[end] ? 0.0 : s->bc[i].value[end];
    if (rc == 0) rc = sc_eval_exprs(s, n + 1, outs, 1, &x, y, y + n, v);
    double scale = 1.0, g = v[0];
    for (int i = 0; i < n; i++) scale += fabs(y[i] * v[1 + i]);
    cv_free(outs);
    cv_free(y);
    if (rc < 0) return nomem(L, c->line);
    double viol = c->sense ? (c->sense * g < 0 ? fabs(g) : 0.0) : fabs(g);
    if (!(viol <= 1e-8 * scale)) {
      sc_err(L->err, L->errlen, L->file, c->line,
             c->sense ? "[constraints] %s is violated at the fixed end %s = %.17g: it is %.6g "
                        "there"
                      : "[constraints] %s does not hold at the fixed end %s = %.17g: it is "
                        "%.6g there",
             c->name, s->variable, x, g);
      return -1;
    }
  }
  return 0;
}

int sc_load_constraints(sc_loader *L) {
  scene *s = L->s;
  char nb[128];
  if (load_named(L, SEC_CONSTRAINTS, &s->cons, &s->ncons) < 0 ||
      load_named(L, SEC_INTEGRALS, &s->ints, &s->nints) < 0)
    return -1;
  for (int i = 0; i < s->ncons; i++) {
    const sc_item *c = &s->cons[i];
    int slot = sc_first_slot(s, c->expr, 1 + s->n, 2 * s->n), k2;
    if (slot < 0 && sc_uses_second(s, c->expr, &k2)) slot = sc_d2_slot(s, k2);
    if (slot >= 0) {
      sc_err(L->err, L->errlen, L->file, c->line,
             "[constraints] %s is a pointwise constraint G(%s, y) and may not use '%s'", c->name,
             s->variable, sc_slot_name(s, slot, nb, sizeof nb));
      return -1;
    }
    if (sc_first_slot(s, c->expr, 1, s->n) < 0) {
      sc_err(L->err, L->errlen, L->file, c->line,
             "[constraints] %s involves no unknown, so it cannot be imposed", c->name);
      return -1;
    }
    if (check_constraint_ends(L, c) < 0) return -1;
  }
  int neq = 0; /* inequalities leave the path free where they are not active */
  for (int i = 0; i < s->ncons; i++)
    if (!s->cons[i].sense && ++neq >= s->n) {
      sc_err(L->err, L->errlen, L->file, s->cons[i].line,
             "%d pointwise equality constraints on %d unknowns leave no degree of freedom", neq,
             s->n);
      return -1;
    }
  return 0;
}

int sc_load_report(sc_loader *L) {
  return load_named(L, SEC_REPORT, &L->s->reports, &L->s->nreports);
}
