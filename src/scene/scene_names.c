/* src/scene/scene_names.c — the names a scene may not define, and those it has defined.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "scene/scene_internal.h"

/* Names a scene may not define: the constant pi, the function names (a parameter called
 * `exp` would be shadowed by exp( ... ) or shadow it) and `free`, which [boundary] reads
 * as a natural end. */
int sc_is_reserved(const char *s) { return ex_is_reserved(s) || strcmp(s, "free") == 0; }

int sc_name_find(const sc_loader *L, const char *name, int kind) {
  int code = sc_namemap_get(&L->names, name);
  return code >= 0 && code % SC_NAME_KINDS == kind ? code / SC_NAME_KINDS : -1;
}

int sc_name_add(sc_loader *L, int line, const char *name, int kind, int index) {
  if (sc_namemap_put(&L->names, name, SC_NAME_CODE(kind, index)) == 0) return 0;
  sc_err(L->err, L->errlen, L->file, line, "out of memory");
  return -1;
}

int sc_is_utf8(const char *s) {
  const unsigned char *p = (const unsigned char *)s;
  while (*p) {
    int more = *p < 0x80             ? 0
               : (*p & 0xe0) == 0xc0 ? 1
               : (*p & 0xf0) == 0xe0 ? 2
               : (*p & 0xf8) == 0xf0 ? 3
                                     : -1;
    if (more < 0 || (more == 1 && *p < 0xc2) || (more == 3 && *p > 0xf4)) return 0;
    p++;
    for (int k = 0; k < more; k++, p++)
      if ((*p & 0xc0) != 0x80) return 0;
  }
  return 1;
}
