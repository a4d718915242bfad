/* src/core/cv_memory.c — the one allocator of the library, with failure injection for tests.
 * SPDX-License-Identifier: MIT */
#include <stdlib.h>

#include "cv_memory.h"

/* Called in every solve: with the solve's code in .text.hot (CV_HOT, cv_internal.h). */
#define CV_MEM_HOT __attribute__((hot))

/* Countdown to an injected failure; -1 = never. Only tests set it (single-threaded). */
static long fail_after = -1;

void cv_debug_fail_alloc_after(long k) { fail_after = k; }

static int should_fail(void) {
  if (fail_after < 0) return 0;
  if (fail_after == 0) return 1;
  fail_after--;
  return 0;
}

CV_MEM_HOT void *cv_malloc(size_t n) {
  if (should_fail()) return NULL;
  return malloc(n ? n : 1);
}

CV_MEM_HOT void *cv_calloc(size_t count, size_t size) {
  if (should_fail()) return NULL;
  return calloc(count ? count : 1, size ? size : 1);
}

void *cv_realloc(void *ptr, size_t n) {
  if (should_fail()) return NULL;
  return realloc(ptr, n ? n : 1);
}

CV_MEM_HOT void cv_free(void *ptr) { free(ptr); }
