/* src/expr/ex_build.c — simplifying constructors: constant folding, 0/1 rules, canonical
 * operand order, sign normalisation (docs/theory.md ). SPDX-License-Identifier: MIT
 * Every rule replaces a node by one that is equal as a real function; none changes the
 * floating-point value except where noted (x - x = 0, 0*x = 0 also at x = inf).
 * Constants keep IEEE semantics (theory (EX-1)): a constant whose value is not finite
 * (0/0, 1/0, sqrt(-1)) is not folded and takes part in no rule, so 0/0, (1/0)-(1/0) and
 * sqrt(-1)*0 stay formulas whose value is NaN, never 0; the loader then refuses them. The
 * rules x*0 = 0, x - x = 0 ... still apply to every x that depends on a slot (the
 * derivative machinery relies on them). */
#include <math.h>

#include "expr/ex_internal.h"

static int ok(const ex_dag *d, ex_id e) { return d && e >= 0 && e < d->n; }
static int is_num(const ex_dag *d, ex_id e) { return d->nodes[e].op == EX_NUM; }
static int is_val(const ex_dag *d, ex_id e, double v) {
  return d->nodes[e].op == EX_NUM && d->nodes[e].v == v;
}
static int is_neg_num(const ex_dag *d, ex_id e) { return is_num(d, e) && d->nodes[e].v < 0; }
static int is_op(const ex_dag *d, ex_id e, ex_op op) { return d->nodes[e].op == op; }
static ex_id arg(const ex_dag *d, ex_id e) { return d->nodes[e].a; }
static double val(const ex_dag *d, ex_id e) { return d->nodes[e].v; }
/* A constant that did not fold to a finite number: a formula on no slot, or a non-finite
 * number node. */
static int bad_const(const ex_dag *d, ex_id e) {
  const ex_node *nd = &d->nodes[e];
  return nd->dep == 0 && nd->op != EX_SLOT && (nd->op != EX_NUM || !isfinite(nd->v));
}

ex_id ex_num(ex_dag *d, double v) {
  if (v == 0) v = 0.0; /* one zero: -0 and +0 are the same node */
  return ex_intern(d, EX_NUM, -1, -1, -1, v);
}

ex_id ex_slot(ex_dag *d, int slot) {
  if (slot < 0) return -1;
  return ex_intern(d, EX_SLOT, slot, -1, -1, 0.0);
}

/* Fold an operation whose operands are all numbers, when the result is finite (a
 * non-finite constant stays a formula, so printed text re-parses and a domain error like
 * log(-1) stays visible). Returns -2 when an operand is not a number. */
static ex_id fold(ex_dag *d, ex_op op, ex_id a, ex_id b, ex_id c) {
  if (!is_num(d, a) || (b >= 0 && !is_num(d, b)) || (c >= 0 && !is_num(d, c))) return -2;
  double r = ex_apply(op, val(d, a), b >= 0 ? val(d, b) : 0.0, c >= 0 ? val(d, c) : 0.0);
  /* not finite: kept as the formula itself, untouched by any rule (IEEE: 0/0 is NaN) */
  return isfinite(r) ? ex_num(d, r) : ex_intern(d, op, a, b, c, 0.0);
}

/* Canonical order of product operands: numbers first, then by id, so a*b and b*a are one
 * node. */
static void order(const ex_dag *d, ex_id *a, ex_id *b) {
  int na = is_num(d, *a), nb = is_num(d, *b);
  if ((nb && !na) || (na == nb && *b < *a)) {
    ex_id t = *a;
    *a = *b;
    *b = t;
  }
}

static ex_id neg(ex_dag *d, ex_id a) {
  if (a < 0) return -1;
  return ex_unary(d, EX_NEG, a);
}

ex_id ex_unary(ex_dag *d, ex_op op, ex_id a) {
  if (!ok(d, a) || ex_op_arity(op) != 1) return -1;
  ex_id f = fold(d, op, a, -1, -1);
  if (f != -2) return f;
  if (bad_const(d, a)) return ex_intern(d, op, a, -1, -1, 0.0); /* IEEE: no rule */
  switch (op) {
  case EX_NEG:
    if (is_op(d, a, EX_NEG)) return arg(d, a);                                      /* -(-x) = x */
    if (is_op(d, a, EX_SUB)) return ex_binary(d, EX_SUB, d->nodes[a].b, arg(d, a)); /* -(p-q) */
    /* -((p-q)/r) = (q-p)/r and -(c*(p-q)) = c*(q-p): the sign goes into a difference
     * rather than staying outside, the same form "-(p - q)/r" parses to. */
    if ((is_op(d, a, EX_DIV) || is_op(d, a, EX_MUL)) && is_op(d, arg(d, a), EX_SUB))
      return ex_binary(d, d->nodes[a].op, neg(d, arg(d, a)), d->nodes[a].b);
    if (is_op(d, a, EX_MUL) && is_op(d, d->nodes[a].b, EX_SUB))
      return ex_binary(d, EX_MUL, arg(d, a), neg(d, d->nodes[a].b));
    break;
  case EX_ABS:
    if (is_op(d, a, EX_NEG) || is_op(d, a, EX_ABS)) return ex_unary(d, EX_ABS, arg(d, a));
    break;
  case EX_COS:
  case EX_COSH: /* even functions */
    if (is_op(d, a, EX_NEG)) return ex_unary(d, op, arg(d, a));
    break;
  default: break;
  }
  return ex_intern(d, op, a, -1, -1, 0.0);
}

static ex_id add(ex_dag *d, ex_id a, ex_id b) {
  if (is_val(d, a, 0)) return b;
  if (is_val(d, b, 0)) return a;
  if (is_op(d, a, EX_NEG) && is_op(d, b, EX_NEG))
    return neg(d, ex_binary(d, EX_ADD, arg(d, a), arg(d, b)));
  if (is_op(d, b, EX_NEG)) return ex_binary(d, EX_SUB, a, arg(d, b));
  if (is_op(d, a, EX_NEG)) return ex_binary(d, EX_SUB, b, arg(d, a));
  if (is_neg_num(d, b)) return ex_binary(d, EX_SUB, a, ex_num(d, -val(d, b)));
  if (is_neg_num(d, a)) return ex_binary(d, EX_SUB, b, ex_num(d, -val(d, a)));
  if (a == b) return ex_binary(d, EX_MUL, ex_num(d, 2.0), a);
  /* Canonical order for sums: a sum operand first, numbers last, otherwise by id, so that
   * a left-leaning chain prints without parentheses ("x^3 - 2*x^2 + 5"). */
  int ka = is_op(d, a, EX_ADD) || is_op(d, a, EX_SUB) ? 0 : is_num(d, a) ? 2 : 1;
  int kb = is_op(d, b, EX_ADD) || is_op(d, b, EX_SUB) ? 0 : is_num(d, b) ? 2 : 1;
  if (kb < ka || (ka == kb && b < a)) {
    ex_id t = a;
    a = b;
    b = t;
  }
  return ex_intern(d, EX_ADD, a, b, -1, 0.0);
}

static ex_id sub(ex_dag *d, ex_id a, ex_id b) {
  if (a == b) return ex_num(d, 0.0);
  if (is_val(d, b, 0)) return a;
  if (is_val(d, a, 0)) return neg(d, b);
  if (is_op(d, b, EX_NEG)) return ex_binary(d, EX_ADD, a, arg(d, b));
  if (is_neg_num(d, b)) return ex_binary(d, EX_ADD, a, ex_num(d, -val(d, b)));
  if (is_op(d, a, EX_NEG)) return neg(d, ex_binary(d, EX_ADD, arg(d, a), b));
  return ex_intern(d, EX_SUB, a, b, -1, 0.0);
}

/* Products keep at most one number, in front, and carry signs outwards as a NEG node, so
 * that printing needs no "2*-x" and equal products hash equal. */
static ex_id mul(ex_dag *d, ex_id a, ex_id b) {
  if (is_val(d, a, 0) || is_val(d, b, 0)) return ex_num(d, 0.0);
  if (is_val(d, a, 1)) return b;
  if (is_val(d, b, 1)) return a;
  int na = is_op(d, a, EX_NEG), nb = is_op(d, b, EX_NEG);
  if (na || nb) {
    ex_id p = ex_binary(d, EX_MUL, na ? arg(d, a) : a, nb ? arg(d, b) : b);
    return na && nb ? p : neg(d, p);
  }
  if (is_neg_num(d, a)) return neg(d, ex_binary(d, EX_MUL, ex_num(d, -val(d, a)), b));
  if (is_neg_num(d, b)) return neg(d, ex_binary(d, EX_MUL, a, ex_num(d, -val(d, b))));
  order(d, &a, &b);
  if (a == b) return ex_binary(d, EX_POW, a, ex_num(d, 2.0));
  if (is_num(d, a) && is_op(d, b, EX_MUL) && is_num(d, arg(d, b))) { /* c1*(c2*x) */
    double c = val(d, a) * val(d, arg(d, b));
    if (isfinite(c)) return ex_binary(d, EX_MUL, ex_num(d, c), d->nodes[b].b);
  }
  if (!is_num(d, a)) { /* float a number factor to the front: x*(c*y) = c*(x*y) */
    if (is_op(d, b, EX_MUL) && is_num(d, arg(d, b)))
      return ex_binary(d, EX_MUL, arg(d, b), ex_binary(d, EX_MUL, a, d->nodes[b].b));
    if (is_op(d, a, EX_MUL) && is_num(d, arg(d, a)))
      return ex_binary(d, EX_MUL, arg(d, a), ex_binary(d, EX_MUL, d->nodes[a].b, b));
  }
  return ex_intern(d, EX_MUL, a, b, -1, 0.0);
}

static ex_id divide(ex_dag *d, ex_id a, ex_id b) {
  if (is_val(d, b, 1)) return a;
  if (is_val(d, a, 0)) return a;
  if (a == b) return ex_num(d, 1.0);
  int na = is_op(d, a, EX_NEG), nb = is_op(d, b, EX_NEG);
  if (na || nb) {
    ex_id q = ex_binary(d, EX_DIV, na ? arg(d, a) : a, nb ? arg(d, b) : b);
    return na && nb ? q : neg(d, q);
  }
  if (is_op(d, a, EX_MUL) && is_op(d, b, EX_MUL) && is_num(d, arg(d, a)) &&
      arg(d, a) == arg(d, b)) /* (c*p)/(c*q) = p/q, as in sqrt's (2*u)/(2*sqrt(u)) */
    return ex_binary(d, EX_DIV, d->nodes[a].b, d->nodes[b].b);
  if (is_neg_num(d, a)) return neg(d, ex_binary(d, EX_DIV, ex_num(d, -val(d, a)), b));
  if (is_neg_num(d, b)) return neg(d, ex_binary(d, EX_DIV, a, ex_num(d, -val(d, b))));
  return ex_intern(d, EX_DIV, a, b, -1, 0.0);
}

ex_id ex_binary(ex_dag *d, ex_op op, ex_id a, ex_id b) {
  if (!ok(d, a) || !ok(d, b) || ex_op_arity(op) != 2) return -1;
  ex_id f = fold(d, op, a, b, -1);
  if (f != -2) return f;
  if (bad_const(d, a) || bad_const(d, b)) return ex_intern(d, op, a, b, -1, 0.0);
  switch (op) {
  case EX_ADD: return add(d, a, b);
  case EX_SUB: return sub(d, a, b);
  case EX_MUL: return mul(d, a, b);
  case EX_DIV: return divide(d, a, b);
  case EX_POW:
    if (is_val(d, b, 1)) return a;
    if (is_val(d, b, 0) || is_val(d, a, 1)) return ex_num(d, 1.0);
    break;
  case EX_MIN:
  case EX_MAX:
    /* Operands keep their written order: on a tie the first is the branch taken. */
    if (a == b) return a;
    break;
  case EX_LT:
  case EX_GT:
    if (a == b) return ex_num(d, 0.0);
    break;
  case EX_LE:
  case EX_GE:
    if (a == b) return ex_num(d, 1.0);
    break;
  default: break;
  }
  return ex_intern(d, op, a, b, -1, 0.0);
}

ex_id ex_if(ex_dag *d, ex_id c, ex_id a, ex_id b) {
  if (!ok(d, c) || !ok(d, a) || !ok(d, b)) return -1;
  if (bad_const(d, c) || bad_const(d, a) || bad_const(d, b))
    return ex_intern(d, EX_IF, c, a, b, 0.0);
  if (is_num(d, c)) return val(d, c) != 0 ? a : b;
  if (a == b) return a;
  return ex_intern(d, EX_IF, c, a, b, 0.0);
}

ex_id ex_make(ex_dag *d, ex_op op, ex_id a, ex_id b, ex_id c) {
  if (op == EX_TABLE) return -1; /* its identity is not in (op, a, b, c): ex_remake */
  switch (ex_op_arity(op)) {
  case 1: return ex_unary(d, op, a);
  case 2: return ex_binary(d, op, a, b);
  case 3: return ex_if(d, a, b, c);
  default: return -1;
  }
}
