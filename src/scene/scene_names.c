/* src/scene/scene_names.c — the names a scene may not define.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "scene/scene_internal.h"

/* Names a scene may not define: the constant pi, the function names (a parameter called
 * `exp` would be shadowed by exp( ... ) or shadow it) and `free`, which [boundary] reads
 * as a natural end. */
int sc_is_reserved(const char *s) { return ex_is_reserved(s) || strcmp(s, "free") == 0; }
