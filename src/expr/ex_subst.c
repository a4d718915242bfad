/* src/expr/ex_subst.c — substitution of a node for a slot, rebuilding through the
 * simplifying constructors. SPDX-License-Identifier: MIT */
#include <stdlib.h>

#include "expr/ex_internal.h"

ex_id ex_subst(ex_dag *d, ex_id e, int slot, ex_id by) {
  if (!d || e < 0 || e >= d->n || slot < 0 || by < 0 || by >= d->n) return -1;
  uint64_t bit = (uint64_t)1 << (slot & 63);
  if (!(d->nodes[e].dep & bit)) return e;
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  ex_id *map = cv_malloc(((size_t)e + 1) * sizeof *map);
  ex_id result = -1;
  if (!mark || !map) goto cleanup;
  ex_mark_reachable(d, e, mark, 0);
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    ex_node nd = d->nodes[id];
    if (!(nd.dep & bit)) {
      map[id] = id; /* untouched subtree: keep the node (and its sharing) as it is */
    } else if (nd.op == EX_SLOT) {
      map[id] = nd.a == slot ? by : id;
    } else {
      map[id] =
          ex_remake(d, &nd, map[nd.a], nd.b >= 0 ? map[nd.b] : -1, nd.c >= 0 ? map[nd.c] : -1);
      if (map[id] < 0) goto cleanup;
    }
  }
  result = map[e];
cleanup:
  cv_free(mark);
  cv_free(map);
  return result;
}
