/* src/expr/ex_collect.c — collect like terms: a sum is rewritten as Σ c_k t_k + c₀ with
 * each distinct term t_k once. SPDX-License-Identifier: MIT
 *
 * The constructors of ex_build.c simplify one node at a time, so th'^2 - 0.5*th'^2 or
 * (36*th')/2 stay as written. This pass looks through a whole sum: numeric factors
 * (c*t, t/c, -t) are peeled off each summand, equal terms (one node, by hash-consing) are
 * merged, and the sum is rebuilt through the constructors. Children are collected first,
 * so sums inside function arguments and products are collected too.
 *
 * Unlike the constructors this may change a value by rounding: coefficients are combined
 * in floating point (c1 + c2, c/d), so a collected expression can differ from the original
 * by a few ulps. Use it for display (calcvar equations), not inside the solver's tapes.
 */
#include <stdlib.h>

#include "expr/ex_internal.h"

typedef struct {
  ex_id node;
  double coef;
} term;

typedef struct {
  term *t;
  int n, cap;
} terms;

static int push(term **a, int *n, int *cap, ex_id node, double coef) {
  if (*n == *cap) {
    int nc = *cap ? 2 * *cap : 16;
    term *p = realloc(*a, (size_t)nc * sizeof *p);
    if (!p) return -1;
    *a = p;
    *cap = nc;
  }
  (*a)[(*n)++] = (term){node, coef};
  return 0;
}

/* Is e a node the linear walk looks through? */
static int linear(const ex_dag *d, ex_id e) {
  const ex_node *nd = &d->nodes[e];
  switch (nd->op) {
  case EX_ADD: case EX_SUB: case EX_NEG: return 1;
  case EX_MUL: return d->nodes[nd->a].op == EX_NUM; /* numbers come first in products */
  case EX_DIV: return d->nodes[nd->b].op == EX_NUM;
  default: return 0;
  }
}

/* Gather e (a sum of already collected children) into out as coefficient × term, merging
 * equal terms; numbers go to *c0. An explicit stack: long sums are left-leaning chains. */
static int gather(const ex_dag *d, ex_id e, terms *out, double *c0) {
  term *st = NULL;
  int ns = 0, cs = 0, rc = -1;
  if (push(&st, &ns, &cs, e, 1.0) < 0) return -1;
  while (ns > 0) {
    term cur = st[--ns];
    const ex_node *nd = &d->nodes[cur.node];
    if (nd->op == EX_NUM) {
      *c0 += cur.coef * nd->v;
      continue;
    }
    if (linear(d, cur.node)) {
      int ok = 0;
      switch (nd->op) {
      case EX_ADD: /* pushed b first so a is walked first: terms keep their written order */
        ok = push(&st, &ns, &cs, nd->b, cur.coef) == 0 &&
             push(&st, &ns, &cs, nd->a, cur.coef) == 0;
        break;
      case EX_SUB:
        ok = push(&st, &ns, &cs, nd->b, -cur.coef) == 0 &&
             push(&st, &ns, &cs, nd->a, cur.coef) == 0;
        break;
      case EX_NEG: ok = push(&st, &ns, &cs, nd->a, -cur.coef) == 0; break;
      case EX_MUL: ok = push(&st, &ns, &cs, nd->b, cur.coef * d->nodes[nd->a].v) == 0; break;
      default: ok = push(&st, &ns, &cs, nd->a, cur.coef / d->nodes[nd->b].v) == 0; break;
      }
      if (!ok) goto cleanup;
      continue;
    }
    int k = 0;
    while (k < out->n && out->t[k].node != cur.node) k++;
    if (k < out->n)
      out->t[k].coef += cur.coef;
    else if (push(&out->t, &out->n, &out->cap, cur.node, cur.coef) < 0)
      goto cleanup;
  }
  rc = 0;
cleanup:
  free(st);
  return rc;
}

/* Rebuild Σ c_k t_k + c₀ through the constructors. */
static ex_id rebuild(ex_dag *d, const terms *ts, double c0) {
  ex_id acc = ex_num(d, 0.0);
  for (int k = 0; k < ts->n && acc >= 0; k++) {
    double c = ts->t[k].coef;
    if (c == 0) continue;
    ex_id t = ts->t[k].node;
    if (c == -1) t = ex_unary(d, EX_NEG, t);
    else if (c != 1) t = ex_binary(d, EX_MUL, ex_num(d, c), t);
    acc = t >= 0 ? ex_binary(d, EX_ADD, acc, t) : -1;
  }
  if (acc >= 0 && c0 != 0) acc = ex_binary(d, EX_ADD, acc, ex_num(d, c0));
  return acc;
}

ex_id ex_collect(ex_dag *d, ex_id e) {
  if (!d || e < 0 || e >= d->n) return -1;
  unsigned char *mark = calloc((size_t)e + 1, 1);
  ex_id *map = malloc(((size_t)e + 1) * sizeof *map);
  terms ts = {NULL, 0, 0};
  ex_id result = -1;
  if (!mark || !map) goto cleanup;
  ex_mark_reachable(d, e, mark, 0);
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    ex_node nd = d->nodes[id];
    if (nd.op == EX_NUM || nd.op == EX_SLOT) {
      map[id] = id;
      continue;
    }
    ex_id r = ex_make(d, nd.op, map[nd.a], nd.b >= 0 ? map[nd.b] : -1,
                      nd.c >= 0 ? map[nd.c] : -1);
    if (r >= 0 && linear(d, r)) {
      double c0 = 0.0;
      ts.n = 0;
      r = gather(d, r, &ts, &c0) < 0 ? -1 : rebuild(d, &ts, c0);
    }
    if (r < 0) goto cleanup;
    map[id] = r;
  }
  result = map[e];
cleanup:
  free(ts.t);
  free(mark);
  free(map);
  return result;
}
