/* src/expr/ex_parse.c — recursive-descent parser of the scene expression grammar
 * (SCENES.md "Expressions") into the DAG, with bounded nesting. SPDX-License-Identifier: MIT
 *
 *   cond    = sum [ ("<" | "<=" | ">" | ">=") sum ]      (first argument of if only)
 *   sum     = term { ("+" | "-") term }
 *   term    = unary { ("*" | "/") unary }
 *   unary   = "-" unary | power
 *   power   = primary [ "^" unary ]                     (right-assoc.; -x^2 = -(x^2))
 *   primary = number | "pi" | name {"'"} | func "(" args ")" | "(" sum ")"
 */
#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "expr/ex_internal.h"

/* Nesting bound: each level costs a handful of small stack frames, so 200 levels is far
 * below any stack limit, and far above what a readable formula uses. */
#define MAX_DEPTH 200
#define MAX_NAME  128

typedef struct {
  ex_dag *d;
  const char *s;
  size_t pos;
  ex_resolve_fn resolve;
  void *user;
  int allow_second;
  char *err;
  size_t errlen;
  int depth;
  int failed;
} parser;

static ex_id fail(parser *p, size_t at, const char *fmt, ...) {
  if (p->failed) return -1; /* keep the first (innermost) message */
  p->failed = 1;
  if (p->err && p->errlen) {
    int k = snprintf(p->err, p->errlen, "column %zu: ", at + 1);
    if (k >= 0 && (size_t)k < p->errlen) {
      va_list ap;
      va_start(ap, fmt);
      vsnprintf(p->err + k, p->errlen - (size_t)k, fmt, ap);
      va_end(ap);
    }
  }
  return -1;
}

/* A node from a constructor: -1 there means memory ran out. */
static ex_id built(parser *p, ex_id e) { return e >= 0 ? e : fail(p, p->pos, "out of memory"); }

static void skip_ws(parser *p) {
  while (p->s[p->pos] && isspace((unsigned char)p->s[p->pos])) p->pos++;
}

static int is_name_start(int c) { return isalpha(c) || c == '_'; }
static int is_name_char(int c) { return isalnum(c) || c == '_'; }

/* What the parser found at pos, for messages. */
static const char *found(parser *p, char *buf, size_t len) {
  unsigned char c = (unsigned char)p->s[p->pos];
  if (!c) return "the end of the expression";
  if (isprint(c))
    snprintf(buf, len, "'%c'", c);
  else
    snprintf(buf, len, "byte 0x%02x", c);
  return buf;
}

static ex_id parse_sum(parser *p);
static ex_id parse_unary(parser *p);

static ex_id parse_number(parser *p) {
  size_t start = p->pos;
  const char *s = p->s;
  size_t i = start, digits = 0;
  while (isdigit((unsigned char)s[i])) i++, digits++;
  if (s[i] == '.') {
    i++;
    while (isdigit((unsigned char)s[i])) i++, digits++;
  }
  if (!digits) return fail(p, start, "malformed number");
  if (s[i] == 'e' || s[i] == 'E') {
    size_t j = i + 1;
    if (s[j] == '+' || s[j] == '-') j++;
    if (!isdigit((unsigned char)s[j])) return fail(p, i, "malformed exponent in number");
    while (isdigit((unsigned char)s[j])) j++;
    i = j;
  }
  if (is_name_start((unsigned char)s[i]) || s[i] == '.')
    return fail(p, i, "unexpected '%c' right after a number (write '*' to multiply)", s[i]);
  char buf[512];
  if (i - start >= sizeof buf) return fail(p, start, "number too long");
  memcpy(buf, s + start, i - start);
  buf[i - start] = 0;
  double v = strtod(buf, NULL);
  if (!isfinite(v)) return fail(p, start, "number '%s' is out of range", buf);
  p->pos = i;
  return built(p, ex_num(p->d, v));
}

/* sum [relop sum]: a condition's value is 1 or 0; a bare sum counts as true when != 0. */
static ex_id parse_cond(parser *p) {
  ex_id a = parse_sum(p);
  if (a < 0) return -1;
  skip_ws(p);
  const char *s = p->s + p->pos;
  ex_op op;
  size_t len = 1;
  if (s[0] == '<')
    op = s[1] == '=' ? (len = 2, EX_LE) : EX_LT;
  else if (s[0] == '>')
    op = s[1] == '=' ? (len = 2, EX_GE) : EX_GT;
  else
    return a;
  p->pos += len;
  ex_id b = parse_sum(p);
  if (b < 0) return -1;
  return built(p, ex_binary(p->d, op, a, b));
}

/* The arguments of a call, from its '(' at p->pos: up to 3 sums (the first a condition
 * when cond_first), separated by ',' and closed by ')'. Returns their number, -1 on a
 * failure (message set), or -2 when a fourth would begin (args holds three, p->pos is
 * after the third's ','). */
static int parse_args(parser *p, const char *name, int cond_first, ex_id *args) {
  int n = 0;
  p->pos++; /* '(' */
  for (;;) {
    if (n == 3) return -2;
    args[n] = (cond_first && n == 0) ? parse_cond(p) : parse_sum(p);
    if (args[n] < 0) return -1;
    n++;
    skip_ws(p);
    if (p->s[p->pos] == ',') {
      p->pos++;
      continue;
    }
    if (p->s[p->pos] == ')') {
      p->pos++;
      return n;
    }
    char buf[16];
    fail(p, p->pos, "expected ',' or ')' in the arguments of '%s' but found %s", name,
         found(p, buf, sizeof buf));
    return -1;
  }
}

static ex_id parse_call(parser *p, const ex_function *f, size_t at) {
  ex_id args[3];
  int n = parse_args(p, f->name, f->op == EX_IF, args);
  if (n == -2)
    return fail(p, at, "'%s' takes %d argument%s", f->name, f->nargs, f->nargs == 1 ? "" : "s");
  if (n < 0) return -1;
  if (n != f->nargs)
    return fail(p, at, "'%s' takes %d argument%s, not %d", f->name, f->nargs,
                f->nargs == 1 ? "" : "s", n);
  switch (f->nargs) {
  case 1: return built(p, ex_unary(p->d, f->op, args[0]));
  case 2: return built(p, ex_binary(p->d, f->op, args[0], args[1]));
  default: return built(p, ex_if(p->d, args[0], args[1], args[2]));
  }
}

/* A table call name(args) or name.K(args) (expr.h): K lists the coordinates (1..dim) to
 * differentiate by, e.g. h.12 = d2h/du dv. pos is at the '.' or '('. */
static ex_id parse_table_call(parser *p, int index, const char *name, size_t at) {
  const cv_table *t = p->d->tabs[index];
  int dim = cv_table_get_dim(t), ord[3] = {0, 0, 0};
  if (p->s[p->pos] == '.') {
    size_t k0 = ++p->pos;
    while (isdigit((unsigned char)p->s[p->pos])) {
      int k = p->s[p->pos] - '1';
      if (k < 0 || k >= dim)
        return fail(p, p->pos, "'%s' has %d coordinate%s: a derivative index is 1%s", name, dim,
                    dim == 1 ? "" : "s",
                    dim == 1   ? ""
                    : dim == 2 ? " or 2"
                               : ", 2 or 3");
      ord[k]++;
      p->pos++;
    }
    if (p->pos == k0 || p->pos - k0 > 6)
      return fail(p, k0, "after '%s.' write the coordinates to differentiate by (e.g. %s.1)", name,
                  name);
    skip_ws(p);
    if (p->s[p->pos] != '(') return fail(p, at, "'%s' is a table: write %s(...)", name, name);
  }
  ex_id args[3];
  int n = parse_args(p, name, 0, args);
  if (n == -2) n = 3; /* a fourth argument begins: refused below */
  if (n < 0) return -1;
  if (n != dim || (n == 3 && p->s[p->pos - 1] != ')'))
    return fail(p, at, "table '%s' has %d coordinate%s, so it takes %d argument%s%s", name, dim,
                dim == 1 ? "" : "s", dim, dim == 1 ? "" : "s",
                n == 3 && p->s[p->pos - 1] != ')' ? ", not more" : "");
  ex_id e = built(p, ex_table_call(p->d, index, ord, args));
  /* a call at numbers folds inside the grid (ex_table_call), so one that stays a call at
   * numbers lies outside: no extrapolation, say so now */
  if (e >= 0 && ex_node_op(p->d, e) == EX_TABLE) {
    for (int k = 0; k < dim; k++) {
      double lo, hi, v = ex_node_value(p->d, args[k]);
      cv_table_get_range(t, k, &lo, &hi);
      if (ex_node_op(p->d, args[k]) == EX_NUM && !(v >= lo && v <= hi))
        return fail(p, at,
                    "table '%s' is called outside its grid: argument %d is %.15g, "
                    "the grid spans [%.15g, %.15g] (tables are not extrapolated)",
                    name, k + 1, v, lo, hi);
    }
  }
  return e;
}

static ex_id parse_name(parser *p) {
  size_t at = p->pos, i = at;
  while (is_name_char((unsigned char)p->s[i])) i++;
  if (i - at >= MAX_NAME) return fail(p, at, "name too long (at most %d characters)", MAX_NAME - 1);
  char name[MAX_NAME];
  memcpy(name, p->s + at, i - at);
  name[i - at] = 0;
  int primes = 0;
  while (p->s[i] == '\'') i++, primes++;
  p->pos = i;
  skip_ws(p);
  const ex_function *f = ex_function_find(name);
  int table = f ? -1 : ex_dag_find_table(p->d, name);
  if (table >= 0 && !primes && (p->s[p->pos] == '(' || (p->s[p->pos] == '.' && p->pos == i)))
    return parse_table_call(p, table, name, at);
  if (table >= 0) return fail(p, at, "'%s' is a table: write %s(...)", name, name);
  if (p->s[p->pos] == '(' && !primes) {
    if (!f) {
      const char *near = ex_function_nearest(name);
      if (near) return fail(p, at, "unknown function '%s' (did you mean '%s'?)", name, near);
      return fail(p, at, "unknown function '%s'", name);
    }
    return parse_call(p, f, at);
  }
  if (primes > 2 && p->allow_second)
    return fail(p, at, "%s%.*s: at most the second derivative %s'' may be written", name,
                primes > 16 ? 16 : primes, "''''''''''''''''", name);
  if (primes > 2 || (primes == 2 && !p->allow_second))
    return fail(p, at, "%s%.*s: only the first derivative %s' may be written here", name, primes,
                "''''''''''''''''", name);
  if (strcmp(name, "pi") == 0) {
    if (primes) return fail(p, at + 2, "a prime is only allowed on an unknown, not on 'pi'");
    return built(p, ex_num(p->d, EX_PI));
  }
  if (f) return fail(p, at, "'%s' is a function: write %s(...)", name, name);
  char msg[256] = "";
  ex_id e = p->resolve ? p->resolve(p->d, name, primes, p->user, msg, sizeof msg) : -1;
  if (e < 0) {
    if (msg[0]) return fail(p, at, "%s", msg);
    return fail(p, at, "unknown name '%s'", name);
  }
  return e;
}

static ex_id parse_primary(parser *p) {
  skip_ws(p);
  size_t at = p->pos;
  char c = p->s[at];
  ex_id e;
  if (isdigit((unsigned char)c) || c == '.') {
    e = parse_number(p);
  } else if (is_name_start((unsigned char)c)) {
    return parse_name(p); /* primes handled there */
  } else if (c == '(') {
    p->pos++;
    e = parse_sum(p);
    if (e < 0) return -1;
    skip_ws(p);
    if (p->s[p->pos] != ')') {
      char buf[16];
      if (p->s[p->pos] == '<' || p->s[p->pos] == '>')
        return fail(p, p->pos,
                    "a comparison is only allowed as the condition of if(...), or as "
                    "'G >= 0' / 'G <= 0' for a whole [constraints] line");
      return fail(p, p->pos, "missing ')' to close the '(' at column %zu (found %s)", at + 1,
                  found(p, buf, sizeof buf));
    }
    p->pos++;
  } else if (c == ')') {
    return fail(p, at, "unexpected ')' where a number, name or '(' was expected");
  } else {
    char buf[16];
    return fail(p, at, "expected a number, name or '(' but found %s", found(p, buf, sizeof buf));
  }
  if (e >= 0 && p->s[p->pos] == '\'')
    return fail(p, p->pos, "a prime is only allowed right after the name of an unknown");
  return e;
}

static ex_id parse_power(parser *p) {
  ex_id base = parse_primary(p);
  if (base < 0) return -1;
  skip_ws(p);
  if (p->s[p->pos] != '^') return base;
  p->pos++;
  ex_id ex = parse_unary(p); /* right-associative, and allows x^-2 */
  if (ex < 0) return -1;
  return built(p, ex_binary(p->d, EX_POW, base, ex));
}

static ex_id parse_unary(parser *p) {
  skip_ws(p);
  if (++p->depth > MAX_DEPTH) {
    p->depth--;
    return fail(p, p->pos, "expression nested too deeply (more than %d levels)", MAX_DEPTH);
  }
  ex_id e;
  if (p->s[p->pos] == '-') {
    p->pos++;
    e = parse_unary(p);
    if (e >= 0) e = built(p, ex_unary(p->d, EX_NEG, e));
  } else {
    e = parse_power(p);
  }
  p->depth--;
  return e;
}

/* One left-associative level of binary operators: operand {op operand}, op the character
 * c1 (operation o1) or c2 (o2). */
static ex_id parse_level(parser *p, ex_id (*operand)(parser *), char c1, ex_op o1, char c2,
                         ex_op o2) {
  ex_id a = operand(p);
  while (a >= 0) {
    skip_ws(p);
    char c = p->s[p->pos];
    if (c != c1 && c != c2) break;
    p->pos++;
    ex_id b = operand(p);
    if (b < 0) return -1;
    a = built(p, ex_binary(p->d, c == c1 ? o1 : o2, a, b));
  }
  return a;
}

static ex_id parse_term(parser *p) { return parse_level(p, parse_unary, '*', EX_MUL, '/', EX_DIV); }

static ex_id parse_sum(parser *p) { return parse_level(p, parse_term, '+', EX_ADD, '-', EX_SUB); }

ex_id ex_parse(ex_dag *d, const char *src, ex_resolve_fn resolve, void *user, int allow_second,
               char *err, size_t errlen) {
  parser p = {d, src ? src : "", 0, resolve, user, allow_second, err, errlen, 0, 0};
  if (err && errlen) err[0] = 0;
  if (!d) return fail(&p, 0, "no expression DAG");
  skip_ws(&p);
  if (!p.s[p.pos]) return fail(&p, p.pos, "empty expression");
  ex_id e = parse_sum(&p);
  if (e < 0) return -1;
  skip_ws(&p);
  char c = p.s[p.pos];
  if (c) {
    char buf[16];
    if (c == ')') return fail(&p, p.pos, "unmatched ')'");
    if (c == '<' || c == '>')
      return fail(&p, p.pos,
                  "a comparison is only allowed as the condition of if(...), or as "
                  "'G >= 0' / 'G <= 0' for a whole [constraints] line");
    if (c == '\'')
      return fail(&p, p.pos, "a prime is only allowed right after the name of an unknown");
    return fail(&p, p.pos, "unexpected %s after a complete expression (missing operator?)",
                found(&p, buf, sizeof buf));
  }
  return e;
}
