/* src/expr/ex_diff.c — symbolic partial derivatives on the DAG (chain rule, one pass in
 * topological order: docs/theory.md, kinks ). SPDX-License-Identifier: MIT */
#include <stdlib.h>

#include "expr/ex_internal.h"

#define NUM(v)    ex_num(d, (v))
#define ADD(p, q) ex_binary(d, EX_ADD, (p), (q))
#define SUB(p, q) ex_binary(d, EX_SUB, (p), (q))
#define MUL(p, q) ex_binary(d, EX_MUL, (p), (q))
#define DIV(p, q) ex_binary(d, EX_DIV, (p), (q))
#define POW(p, q) ex_binary(d, EX_POW, (p), (q))
#define NEG(p)    ex_unary(d, EX_NEG, (p))
#define FN(op, p) ex_unary(d, (op), (p))
#define SQ(p)     POW((p), NUM(2.0))

/* d(node id)/d slot given the derivatives da, db, dc of its operands. The derivative of
 * a node reuses the node itself where the rule allows (exp, sqrt, tan, tanh, a^b, a/b), so
 * value and derivative share work in the compiled tape. At kinks the branch taken by the
 * value is differentiated: abs' = 1 at 0, min picks a on ties (see ex_apply). */
static ex_id rule(ex_dag *d, ex_id id, ex_node nd, int slot, ex_id da, ex_id db, ex_id dc) {
  ex_id a = nd.a, b = nd.b;
  switch (nd.op) {
  case EX_NUM: return NUM(0.0);
  case EX_SLOT: return NUM(nd.a == slot ? 1.0 : 0.0);
  case EX_ADD: return ADD(da, db);
  case EX_SUB: return SUB(da, db);
  case EX_NEG: return NEG(da);
  case EX_MUL: return ADD(MUL(da, b), MUL(a, db));
  case EX_DIV: return DIV(SUB(da, MUL(id, db)), b); /* (a' - (a/b) b') / b */
  case EX_POW:
    if (ex_is_const(d, b)) return MUL(MUL(b, POW(a, SUB(b, NUM(1.0)))), da);
    /* a^b (b' log a + b a'/a): valid where a > 0, the domain of a non-constant power */
    return MUL(id, ADD(MUL(db, FN(EX_LOG, a)), DIV(MUL(b, da), a)));
  case EX_SIN: return MUL(FN(EX_COS, a), da);
  case EX_COS: return NEG(MUL(FN(EX_SIN, a), da));
  case EX_TAN: return MUL(ADD(NUM(1.0), SQ(id)), da);
  case EX_ASIN: return DIV(da, FN(EX_SQRT, SUB(NUM(1.0), SQ(a))));
  case EX_ACOS: return NEG(DIV(da, FN(EX_SQRT, SUB(NUM(1.0), SQ(a)))));
  case EX_ATAN: return DIV(da, ADD(NUM(1.0), SQ(a)));
  case EX_SINH: return MUL(FN(EX_COSH, a), da);
  case EX_COSH: return MUL(FN(EX_SINH, a), da);
  case EX_TANH: return MUL(SUB(NUM(1.0), SQ(id)), da);
  case EX_ASINH: return DIV(da, FN(EX_SQRT, ADD(SQ(a), NUM(1.0))));
  case EX_ACOSH: return DIV(da, FN(EX_SQRT, SUB(SQ(a), NUM(1.0))));
  case EX_ATANH: return DIV(da, SUB(NUM(1.0), SQ(a)));
  case EX_EXP: return MUL(id, da);
  case EX_LOG: return DIV(da, a);
  case EX_SQRT: return DIV(da, MUL(NUM(2.0), id));
  case EX_ABS: return MUL(ex_if(d, ex_binary(d, EX_LT, a, NUM(0.0)), NUM(-1.0), NUM(1.0)), da);
  case EX_ATAN2: /* atan2(a, b) = angle of (b, a): (b a' - a b') / (a^2 + b^2) */
    return DIV(SUB(MUL(b, da), MUL(a, db)), ADD(SQ(a), SQ(b)));
  case EX_MIN: return ex_if(d, ex_binary(d, EX_LE, a, b), da, db);
  case EX_MAX: return ex_if(d, ex_binary(d, EX_GE, a, b), da, db);
  case EX_LT:
  case EX_LE:
  case EX_GT:
  case EX_GE: return NUM(0.0);
  case EX_IF: return ex_if(d, a, db, dc);
  case EX_TABLE: {
    ex_id dargs[3] = {da, db, dc};
    return ex_table_diff(d, &nd, dargs);
  }
  default: return -1;
  }
}

ex_id ex_diff(ex_dag *d, ex_id e, int slot) {
  if (!d || e < 0 || e >= d->n || slot < 0) return -1;
  uint64_t bit = (uint64_t)1 << (slot & 63);
  if (!(d->nodes[e].dep & bit)) return ex_num(d, 0.0);
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  ex_id *dv = cv_malloc(((size_t)e + 1) * sizeof *dv);
  ex_id zero = ex_num(d, 0.0), result = -1;
  if (!mark || !dv || zero < 0) goto cleanup;
  ex_mark_reachable(d, e, mark, 1);
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    ex_node nd = d->nodes[id]; /* a copy: constructors may move d->nodes */
    if (!(nd.dep & bit)) {
      dv[id] = zero;
      continue;
    }
    int skip_a = nd.op == EX_IF || (nd.op >= EX_LT && nd.op <= EX_GE);
    ex_id da = nd.a >= 0 && nd.op != EX_SLOT && !skip_a ? dv[nd.a] : zero;
    ex_id db = nd.b >= 0 && !(nd.op >= EX_LT && nd.op <= EX_GE) ? dv[nd.b] : zero;
    ex_id dc = nd.c >= 0 ? dv[nd.c] : zero;
    dv[id] = rule(d, id, nd, slot, da, db, dc);
    if (dv[id] < 0) goto cleanup;
  }
  result = dv[e];
cleanup:
  cv_free(mark);
  cv_free(dv);
  return result;
}
