/* src/scene/scene_error.c — "FILE:LINE: what is wrong" messages and small string helpers.
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

/* Only the first error matters to a person (later ones are often consequences), so a
 * message already in err is kept. line <= 0 means there is no line to point to. */
void sc_err(char *err, size_t errlen, const char *file, int line, const char *fmt, ...) {
  if (!err || errlen == 0 || err[0]) return;
  int k =
      line > 0 ? snprintf(err, errlen, "%s:%d: ", file, line) : snprintf(err, errlen, "%s: ", file);
  if (k < 0 || (size_t)k >= errlen) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(err + k, errlen - (size_t)k, fmt, ap);
  va_end(ap);
}

char *sc_strndup(const char *s, size_t n) {
  char *r = cv_malloc(n + 1);
  if (r) {
    memcpy(r, s, n);
    r[n] = '\0';
  }
  return r;
}

char *sc_strdup(const char *s) { return sc_strndup(s, strlen(s)); }
