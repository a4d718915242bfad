/* src/expr/ex_reach.c — the nodes an expression reaches, found by a walk over them only.
 * SPDX-License-Identifier: MIT
 *
 * ex_mark_reachable marks into an array of e + 1 bytes and scans every id below e: its cost
 * is the size of the DAG, not of the expression. The loader evaluates one small expression
 * per parameter in a DAG that grows with the scene, so that scan made 10^5 parameters
 * quadratic. Here a depth-first walk with a hash set of the ids seen costs O(r log r) for
 * r nodes reached.
 */
#include <math.h>
#include <stdint.h>
#include <stdlib.h>

#include "expr/ex_internal.h"

typedef struct {
  ex_id *slot; /* -1: empty */
  size_t cap, n;
} idset;

static size_t id_hash(ex_id id, size_t mask) {
  return (size_t)(((uint64_t)(uint32_t)id * 0x9E3779B97F4A7C15ull) >> 20) & mask;
}

/* 1 when id was added, 0 when it was there, -1 out of memory. */
static int idset_add(idset *s, ex_id id) {
  if ((s->n + 1) * 2 > s->cap) {
    size_t ncap = s->cap ? 2 * s->cap : 64;
    ex_id *ns = cv_malloc(ncap * sizeof *ns);
    if (!ns) return -1;
    for (size_t i = 0; i < ncap; i++) ns[i] = -1;
    for (size_t i = 0; i < s->cap; i++)
      if (s->slot[i] >= 0) {
        size_t h = id_hash(s->slot[i], ncap - 1);
        while (ns[h] >= 0) h = (h + 1) & (ncap - 1);
        ns[h] = s->slot[i];
      }
    cv_free(s->slot);
    s->slot = ns;
    s->cap = ncap;
  }
  size_t h = id_hash(id, s->cap - 1);
  while (s->slot[h] >= 0) {
    if (s->slot[h] == id) return 0;
    h = (h + 1) & (s->cap - 1);
  }
  s->slot[h] = id;
  s->n++;
  return 1;
}

static int cmp_id(const void *a, const void *b) {
  ex_id x = *(const ex_id *)a, y = *(const ex_id *)b;
  return (x > y) - (x < y);
}

int ex_reach(const ex_dag *d, ex_id e, ex_id **out) {
  idset seen = {NULL, 0, 0};
  size_t n = 0, cap = 16, top = 0, scap = 16;
  ex_id *ids = cv_malloc(cap * sizeof *ids), *stack = cv_malloc(scap * sizeof *stack);
  int ok = ids && stack && idset_add(&seen, e) == 1;
  if (ok) stack[top++] = e;
  while (ok && top > 0) {
    ex_id id = stack[--top];
    if (n == cap) {
      ex_id *ni = cv_realloc(ids, 2 * cap * sizeof *ni);
      if (!(ok = ni != NULL)) break;
      ids = ni, cap *= 2;
    }
    ids[n++] = id;
    const ex_node *nd = &d->nodes[id];
    if (nd->op == EX_SLOT || nd->op == EX_NUM) continue;
    ex_id kids[3] = {nd->a, nd->b, nd->c};
    for (int k = 0; k < 3 && ok; k++) {
      if (kids[k] < 0) continue;
      int added = idset_add(&seen, kids[k]);
      if (added < 0) ok = 0;
      if (added <= 0) continue;
      if (top == scap) {
        ex_id *ns = cv_realloc(stack, 2 * scap * sizeof *ns);
        if (!(ok = ns != NULL)) break;
        stack = ns, scap *= 2;
      }
      stack[top++] = kids[k];
    }
  }
  cv_free(seen.slot);
  cv_free(stack);
  if (!ok) {
    cv_free(ids);
    return -1;
  }
  qsort(ids, n, sizeof *ids, cmp_id); /* operands before the nodes that use them */
  *out = ids;
  return (int)n;
}

/* The position of id in the sorted ids (it is there). */
static int position(const ex_id *ids, int n, ex_id id) {
  int lo = 0, hi = n - 1;
  while (lo < hi) {
    int mid = lo + (hi - lo) / 2;
    if (ids[mid] < id)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo;
}

int ex_eval(const ex_dag *d, ex_id e, const double *slots, double *value) {
  return ex_eval_with(d, e, slots, NULL, NULL, value);
}

int ex_eval_with(const ex_dag *d, ex_id e, const double *slots,
                 double (*slot_value)(void *user, int slot), void *user, double *value) {
  if (!d || e < 0 || e >= d->n) return -1;
  ex_id *ids;
  int n = ex_reach(d, e, &ids);
  double *val = n > 0 ? cv_malloc((size_t)n * sizeof *val) : NULL;
  if (!val) {
    if (n > 0) cv_free(ids);
    return -1;
  }
  for (int i = 0; i < n; i++) {
    const ex_node *nd = &d->nodes[ids[i]];
    double u[3] = {0.0, 0.0, 0.0};
    if (nd->op != EX_NUM && nd->op != EX_SLOT) {
      ex_id kids[3] = {nd->a, nd->b, nd->c};
      for (int k = 0; k < 3; k++)
        if (kids[k] >= 0) u[k] = val[position(ids, i, kids[k])];
    }
    switch (nd->op) {
    case EX_NUM: val[i] = nd->v; break;
    case EX_SLOT: val[i] = slot_value ? slot_value(user, nd->a) : slots ? slots[nd->a] : NAN; break;
    case EX_TABLE: ex_table_apply(d, nd, u, &val[i]); break; /* NaN outside the grid */
    default: val[i] = ex_apply(nd->op, u[0], u[1], u[2]);
    }
  }
  *value = val[n - 1];
  cv_free(ids);
  cv_free(val);
  return 0;
}

int ex_slots_used(const ex_dag *d, ex_id e, int from, int count, unsigned char *used) {
  if (!d || e < 0 || e >= d->n) return 0;
  const ex_node *top = &d->nodes[e];
  if (top->hi < from || top->lo >= from + count) return 0; /* none in the range: no walk */
  ex_id *ids;
  int n = ex_reach(d, e, &ids);
  if (n < 0) return -1;
  for (int i = 0; i < n; i++) {
    const ex_node *nd = &d->nodes[ids[i]];
    if (nd->op == EX_SLOT && nd->a >= from && nd->a < from + count) used[nd->a - from] = 1;
  }
  cv_free(ids);
  return 0;
}
