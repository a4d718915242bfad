/* src/expr/ex_subst.c — substitution of a node for a slot, rebuilding through the
 * simplifying constructors. SPDX-License-Identifier: MIT */
#include <stdlib.h>

#include "expr/ex_internal.h"

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

/* Over the nodes e reaches only (ex_reach), not every id below e: a batch substitutes the
 * parameters of a chain of 10^5 one after the other. */
ex_id ex_subst(ex_dag *d, ex_id e, int slot, ex_id by) {
  if (!d || e < 0 || e >= d->n || slot < 0 || by < 0 || by >= d->n) return -1;
  if (slot < d->nodes[e].lo || slot > d->nodes[e].hi) return e;
  uint64_t bit = (uint64_t)1 << (slot & 63);
  if (!(d->nodes[e].dep & bit)) return e;
  ex_id *ids = NULL, *map = NULL, result = -1;
  int n = ex_reach(d, e, &ids);
  if (n < 0 || !(map = cv_malloc((size_t)n * sizeof *map))) goto cleanup;
  for (int i = 0; i < n; i++) {
    ex_id id = ids[i];
    ex_node nd = d->nodes[id];
    if (!(nd.dep & bit) || slot < nd.lo || slot > nd.hi) {
      map[i] = id; /* untouched subtree: keep the node (and its sharing) as it is */
    } else if (nd.op == EX_SLOT) {
      map[i] = nd.a == slot ? by : id;
    } else {
      ex_id k[3] = {nd.a, nd.b, nd.c};
      for (int j = 0; j < 3; j++)
        if (k[j] >= 0) k[j] = map[position(ids, i, k[j])];
      map[i] = ex_remake(d, &nd, k[0], k[1], k[2]);
      if (map[i] < 0) goto cleanup;
    }
  }
  result = map[n - 1];
cleanup:
  if (n >= 0) cv_free(ids);
  cv_free(map);
  return result;
}
