/* src/expr/ex_dag.c — node storage, hash-consing, inspection and pointwise evaluation.
 * SPDX-License-Identifier: MIT */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "expr/ex_internal.h"

ex_dag *ex_dag_new(void) {
  ex_dag *d = cv_calloc(1, sizeof *d);
  if (!d) return NULL;
  d->cap = 64;
  d->tcap = 128;
  d->nodes = cv_malloc((size_t)d->cap * sizeof *d->nodes);
  d->table = cv_malloc(d->tcap * sizeof *d->table);
  if (!d->nodes || !d->table) {
    ex_dag_free(d);
    return NULL;
  }
  memset(d->table, 0xff, d->tcap * sizeof *d->table); /* all -1 */
  d->max_slot = -1;
  return d;
}

void ex_dag_free(ex_dag *d) {
  if (!d) return;
  ex_dag_free_tables(d);
  cv_free(d->nodes);
  cv_free(d->table);
  cv_free(d);
}

int ex_dag_num_nodes(const ex_dag *d) { return d->n; }

/* FNV-style mix of the node's identity; the value enters by its bits so that every
 * distinct double (including each NaN payload) is its own node. */
static size_t node_hash(ex_op op, ex_id a, ex_id b, ex_id c, double v) {
  uint64_t bits;
  memcpy(&bits, &v, sizeof bits);
  uint64_t h = 1469598103934665603ull;
  uint64_t parts[5] = {(uint64_t)op, (uint64_t)(uint32_t)a, (uint64_t)(uint32_t)b,
                       (uint64_t)(uint32_t)c, bits};
  for (int i = 0; i < 5; i++) {
    h ^= parts[i];
    h *= 1099511628211ull;
    h ^= h >> 29;
  }
  return (size_t)h;
}

static int node_equal(const ex_node *nd, ex_op op, ex_id a, ex_id b, ex_id c, double v) {
  return nd->op == op && nd->a == a && nd->b == b && nd->c == c &&
         memcmp(&nd->v, &v, sizeof v) == 0;
}

static int grow_table(ex_dag *d) {
  size_t ncap = d->tcap * 2;
  int *t = cv_malloc(ncap * sizeof *t);
  if (!t) return -1;
  memset(t, 0xff, ncap * sizeof *t);
  for (int id = 0; id < d->n; id++) {
    const ex_node *nd = &d->nodes[id];
    size_t h = node_hash(nd->op, nd->a, nd->b, nd->c, nd->v) & (ncap - 1);
    while (t[h] >= 0) h = (h + 1) & (ncap - 1);
    t[h] = id;
  }
  cv_free(d->table);
  d->table = t;
  d->tcap = ncap;
  return 0;
}

ex_id ex_intern(ex_dag *d, ex_op op, ex_id a, ex_id b, ex_id c, double v) {
  if (!d) return -1;
  size_t mask = d->tcap - 1, h = node_hash(op, a, b, c, v) & mask;
  while (d->table[h] >= 0) {
    if (node_equal(&d->nodes[d->table[h]], op, a, b, c, v)) return d->table[h];
    h = (h + 1) & mask;
  }
  if (d->n == d->cap) {
    if (d->cap > (1 << 28)) return -1;
    ex_node *nn = cv_realloc(d->nodes, (size_t)d->cap * 2 * sizeof *nn);
    if (!nn) return -1;
    d->nodes = nn;
    d->cap *= 2;
  }
  ex_node *nd = &d->nodes[d->n];
  nd->op = op;
  nd->a = a;
  nd->b = b;
  nd->c = c;
  nd->v = v;
  if (op == EX_SLOT) {
    nd->dep = (uint64_t)1 << (a & 63);
    if (a > d->max_slot) d->max_slot = a;
  } else {
    nd->dep = 0;
    if (a >= 0) nd->dep |= d->nodes[a].dep;
    if (b >= 0) nd->dep |= d->nodes[b].dep;
    if (c >= 0) nd->dep |= d->nodes[c].dep;
  }
  nd->lo = INT_MAX, nd->hi = -1;
  if (op == EX_SLOT) nd->lo = nd->hi = a;
  for (int k = 0; k < 3 && op != EX_SLOT && op != EX_NUM; k++) {
    ex_id o = k == 0 ? a : k == 1 ? b : c;
    if (o >= 0 && d->nodes[o].lo < nd->lo) nd->lo = d->nodes[o].lo;
    if (o >= 0 && d->nodes[o].hi > nd->hi) nd->hi = d->nodes[o].hi;
  }
  nd->nonfinite = nd->dep == 0 && op != EX_SLOT && (op != EX_NUM || !isfinite(v));
  if (op != EX_SLOT && op != EX_NUM)
    for (int k = 0; k < 3; k++) {
      ex_id o = k == 0 ? a : k == 1 ? b : c;
      if (o >= 0) nd->nonfinite |= d->nodes[o].nonfinite;
    }
  d->table[h] = d->n;
  ex_id id = d->n++;
  /* Keep the load factor at most 1/2 so probes stay short. */
  if ((size_t)d->n * 2 > d->tcap && grow_table(d) != 0) {
    d->n--; /* undo: the node is not findable, so it must not exist */
    d->table[h] = -1;
    return -1;
  }
  return id;
}

static int valid(const ex_dag *d, ex_id e) { return d && e >= 0 && e < d->n; }

ex_op ex_node_op(const ex_dag *d, ex_id e) { return valid(d, e) ? d->nodes[e].op : EX_NUM_OPS; }

double ex_node_value(const ex_dag *d, ex_id e) {
  return valid(d, e) && d->nodes[e].op == EX_NUM ? d->nodes[e].v : NAN;
}

int ex_node_slot(const ex_dag *d, ex_id e) {
  return valid(d, e) && d->nodes[e].op == EX_SLOT ? d->nodes[e].a : -1;
}

ex_id ex_node_arg(const ex_dag *d, ex_id e, int i) {
  if (!valid(d, e) || d->nodes[e].op == EX_SLOT) return -1;
  switch (i) {
  case 0: return d->nodes[e].a;
  case 1: return d->nodes[e].b;
  case 2: return d->nodes[e].c;
  default: return -1;
  }
}

int ex_is_const(const ex_dag *d, ex_id e) { return valid(d, e) && d->nodes[e].dep == 0; }

int ex_depends_on(const ex_dag *d, ex_id e, int slot) {
  if (!valid(d, e) || slot < 0) return 0;
  if (slot < d->nodes[e].lo || slot > d->nodes[e].hi) return 0;
  if (slot == d->nodes[e].lo || slot == d->nodes[e].hi) return 1;
  if (!(d->nodes[e].dep & ((uint64_t)1 << (slot & 63)))) return 0;
  if (d->max_slot < 64) return 1; /* the bit mask is exact */
  /* Slots alias modulo 64: look through the nodes below e (ex_reach: those only). */
  ex_id *ids;
  int n = ex_reach(d, e, &ids);
  if (n < 0) return 1; /* conservative answer: may depend */
  int found = 0;
  for (int i = 0; i < n && !found; i++)
    found = d->nodes[ids[i]].op == EX_SLOT && d->nodes[ids[i]].a == slot;
  cv_free(ids);
  return found;
}

int ex_first_slot(const ex_dag *d, ex_id e, int from, int to) {
  if (!valid(d, e) || to < from) return -1;
  const ex_node *nd = &d->nodes[e];
  if (nd->hi < from || nd->lo > to) return -1;
  if (nd->lo >= from) return nd->lo;              /* lo <= to: the least slot is in the range */
  for (int k = from; k <= to && k <= nd->hi; k++) /* lo < from <= hi: rare */
    if (ex_depends_on(d, e, k)) return k;
  return -1;
}

ex_id ex_nonfinite_const(const ex_dag *d, ex_id e) {
  if (!valid(d, e) || !d->nodes[e].nonfinite) return -1; /* the common case: no walk */
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  if (!mark) return -2;
  ex_mark_reachable(d, e, mark, 0);
  ex_id found = -1;
  /* Increasing ids: operands come first, so the first hit is innermost. A constant formula
   * left unfolded, or a number that is not finite, is what the folder refused. */
  for (int id = 0; id <= e && found < 0; id++) {
    const ex_node *nd = &d->nodes[id];
    if (mark[id] && nd->dep == 0 && nd->op != EX_SLOT && (nd->op != EX_NUM || !isfinite(nd->v)))
      found = id;
  }
  cv_free(mark);
  return found;
}

int ex_op_arity(ex_op op) {
  switch (op) {
  case EX_NUM:
  case EX_SLOT: return 0;
  case EX_ADD:
  case EX_SUB:
  case EX_MUL:
  case EX_DIV:
  case EX_POW:
  case EX_ATAN2:
  case EX_MIN:
  case EX_MAX:
  case EX_LT:
  case EX_LE:
  case EX_GT:
  case EX_GE: return 2;
  case EX_IF:
  case EX_TABLE: return 3; /* a table call: 1 to 3 (absent ones are -1) */
  default: return 1;
  }
}

/* min/max pick the first operand on ties (the branch whose derivative ex_diff uses) and
 * propagate NaN from either operand instead of hiding it as fmin/fmax would. */
double ex_apply(ex_op op, double a, double b, double c) {
  switch (op) {
  case EX_ADD: return a + b;
  case EX_SUB: return a - b;
  case EX_MUL: return a * b;
  case EX_DIV: return a / b;
  case EX_NEG: return -a;
  case EX_POW: return pow(a, b);
  case EX_SIN: return sin(a);
  case EX_COS: return cos(a);
  case EX_TAN: return tan(a);
  case EX_ASIN: return asin(a);
  case EX_ACOS: return acos(a);
  case EX_ATAN: return atan(a);
  case EX_SINH: return sinh(a);
  case EX_COSH: return cosh(a);
  case EX_TANH: return tanh(a);
  case EX_ASINH: return asinh(a);
  case EX_ACOSH: return acosh(a);
  case EX_ATANH: return atanh(a);
  case EX_EXP: return exp(a);
  case EX_LOG: return log(a);
  case EX_SQRT: return sqrt(a);
  case EX_ABS: return fabs(a);
  case EX_ATAN2: return atan2(a, b);
  case EX_MIN: return (a <= b || a != a) ? a : b;
  case EX_MAX: return (a >= b || a != a) ? a : b;
  case EX_LT: return a < b ? 1.0 : 0.0;
  case EX_LE: return a <= b ? 1.0 : 0.0;
  case EX_GT: return a > b ? 1.0 : 0.0;
  case EX_GE: return a >= b ? 1.0 : 0.0;
  case EX_IF: return a != 0 ? b : c;
  default: return NAN;
  }
}

void ex_mark_reachable(const ex_dag *d, ex_id e, unsigned char *mark, int skip_conditions) {
  mark[e] = 1;
  for (int id = e; id >= 0; id--) {
    if (!mark[id]) continue;
    const ex_node *nd = &d->nodes[id];
    if (nd->op == EX_SLOT || nd->op == EX_NUM) continue;
    if (skip_conditions && nd->op >= EX_LT && nd->op <= EX_GE) continue;
    if (nd->a >= 0 && !(skip_conditions && nd->op == EX_IF)) mark[nd->a] = 1;
    if (nd->b >= 0) mark[nd->b] = 1;
    if (nd->c >= 0) mark[nd->c] = 1;
  }
}

/* ex_eval: ex_reach.c (a walk over the reachable nodes only). */

int ex_eval_const(const ex_dag *d, ex_id e, double *value) {
  if (!ex_is_const(d, e)) return -1;
  if (d->nodes[e].op == EX_NUM) {
    *value = d->nodes[e].v;
    return 0;
  }
  return ex_eval(d, e, NULL, value);
}
