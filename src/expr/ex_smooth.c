/* src/expr/ex_smooth.c — jumps of a formula in chosen slots replaced by smooth steps of a
 * width read from another slot (docs/theory.md ). SPDX-License-Identifier: MIT */
#include <stdlib.h>

#include "expr/ex_internal.h"

#define NUM(v)    ex_num(d, (v))
#define ADD(p, q) ex_binary(d, EX_ADD, (p), (q))
#define SUB(p, q) ex_binary(d, EX_SUB, (p), (q))
#define MUL(p, q) ex_binary(d, EX_MUL, (p), (q))
#define DIV(p, q) ex_binary(d, EX_DIV, (p), (q))

static int is_cmp(ex_op op) { return op >= EX_LT && op <= EX_GE; }

/* The signed distance t of a comparison's operands, positive where it holds: v - u for
 * u < v and u <= v, u - v for u > v and u >= v. */
static ex_id distance(ex_dag *d, ex_op op, ex_id u, ex_id v) {
  return op == EX_LT || op == EX_LE ? SUB(v, u) : SUB(u, v);
}

/* The blend b + (a - b) sigma(t/w), sigma(s) = 1/2 + s (15 - 10 s^2 + 3 s^4)/16 on
 * |s| < 1 (C^2: sigma' = 15 (1 - s^2)^2 / 16), and exactly a (t >= w) or b (t <= -w)
 * outside the band, so a branch undefined on the other side is never blended there. */
static ex_id blend(ex_dag *d, ex_id t, ex_id w, ex_id a, ex_id b) {
  ex_id s = DIV(t, w), s2 = MUL(s, s);
  ex_id poly = SUB(NUM(15.0), MUL(s2, SUB(NUM(10.0), MUL(NUM(3.0), s2))));
  ex_id sigma = ADD(NUM(0.5), DIV(MUL(s, poly), NUM(16.0)));
  ex_id mid = ADD(b, MUL(SUB(a, b), sigma));
  ex_id inner = ex_if(d, ex_binary(d, EX_LE, t, ex_unary(d, EX_NEG, w)), b, mid);
  return ex_if(d, ex_binary(d, EX_GE, t, w), a, inner);
}

ex_id ex_smooth_jumps(ex_dag *d, ex_id e, int lo, int hi, int wslot, int *count) {
  if (count) *count = 0;
  if (!d || e < 0 || e >= d->n || lo < 0 || hi < lo || wslot < 0) return -1;
  uint64_t bits = 0;
  for (int s = lo; s <= hi; s++) bits |= (uint64_t)1 << (s & 63);
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  ex_id *map = cv_malloc(((size_t)e + 1) * sizeof *map);
  ex_id result = -1, w = ex_slot(d, wslot);
  int n = 0;
  if (!mark || !map || w < 0) goto cleanup;
  ex_mark_reachable(d, e, mark, 0);
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    ex_node nd = d->nodes[id]; /* a copy: constructors may move d->nodes */
    ex_id a = nd.a >= 0 && nd.op != EX_SLOT ? map[nd.a] : -1;
    ex_id b = nd.b >= 0 ? map[nd.b] : -1, c = nd.c >= 0 ? map[nd.c] : -1;
    if (nd.op == EX_NUM || nd.op == EX_SLOT) {
      map[id] = id;
    } else if (nd.op == EX_IF && (d->nodes[nd.a].dep & bits) && is_cmp(d->nodes[nd.a].op)) {
      /* if(u cmp v, a, b): the blend on the comparison's own (smoothed) operands */
      const ex_node *cn = &d->nodes[nd.a];
      map[id] = blend(d, distance(d, cn->op, map[cn->a], map[cn->b]), w, b, c);
      n++;
    } else if (is_cmp(nd.op) && (nd.dep & bits)) {
      /* a comparison used as a number (1 or 0): the step itself */
      map[id] = blend(d, distance(d, nd.op, a, b), w, NUM(1.0), NUM(0.0));
      n++;
    } else {
      map[id] = ex_remake(d, &nd, a, b, c);
    }
    if (map[id] < 0) goto cleanup;
  }
  /* w = 0 is the formula as written (its ifs select, so the blend's 0/0 is never used) */
  result = n ? ex_if(d, ex_binary(d, EX_GT, w, NUM(0.0)), map[e], e) : e;
  if (count) *count = n;
cleanup:
  cv_free(mark);
  cv_free(map);
  return result;
}
