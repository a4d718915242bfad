/* src/scene/scene_namemap.c — a hash map from names to small integers, for the loader's
 * lookups: every name a scene defines, and the keys of a section already seen.
 * SPDX-License-Identifier: MIT
 *
 * Open addressing with linear probing, the load factor kept at most 1/2, FNV-1a hashes.
 * The names are borrowed (they must outlive the map). Before this map the loader compared
 * each new name with every earlier one, and a scene of 10^5 parameters took a minute
 * (docs/robustness.md, "Hostile input").
 */
#include <stdint.h>
#include <string.h>

#include "scene/scene_internal.h"

static size_t name_hash(const char *s) {
  uint64_t h = 1469598103934665603ull;
  for (; *s; s++) {
    h ^= (unsigned char)*s;
    h *= 1099511628211ull;
  }
  return (size_t)(h ^ (h >> 32));
}

/* The bucket of name, or of the empty slot where it would go. */
static size_t probe(const sc_namemap *m, const char *name) {
  size_t mask = m->cap - 1, h = name_hash(name) & mask;
  while (m->key[h] && strcmp(m->key[h], name) != 0) h = (h + 1) & mask;
  return h;
}

static int grow(sc_namemap *m) {
  size_t ncap = m->cap ? 2 * m->cap : 64;
  sc_namemap n = {cv_calloc(ncap, sizeof *n.key), cv_malloc(ncap * sizeof *n.val), ncap, 0};
  if (!n.key || !n.val) {
    cv_free(n.key);
    cv_free(n.val);
    return -1;
  }
  for (size_t i = 0; i < m->cap; i++)
    if (m->key[i]) {
      size_t h = probe(&n, m->key[i]);
      n.key[h] = m->key[i];
      n.val[h] = m->val[i];
      n.n++;
    }
  sc_namemap_free(m);
  *m = n;
  return 0;
}

int sc_namemap_get(const sc_namemap *m, const char *name) {
  if (!m->cap) return -1;
  size_t h = probe(m, name);
  return m->key[h] ? m->val[h] : -1;
}

int sc_namemap_put(sc_namemap *m, const char *name, int val) {
  if ((m->n + 1) * 2 > m->cap && grow(m) < 0) return -1;
  size_t h = probe(m, name);
  if (!m->key[h]) m->n++;
  m->key[h] = name;
  m->val[h] = val;
  return 0;
}

void sc_namemap_free(sc_namemap *m) {
  cv_free(m->key);
  cv_free(m->val);
  memset(m, 0, sizeof *m);
}
