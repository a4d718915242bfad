/* src/core/cv_memory.h — the one allocator of the library (core, expressions, scenes).
 * Every allocation goes through it, so that the allocation-failure tests reach every layer.
 * SPDX-License-Identifier: MIT */
#ifndef CV_MEMORY_H
#define CV_MEMORY_H

#include <stddef.h>

void *cv_malloc(size_t n);
void *cv_calloc(size_t count, size_t size);
/* Like realloc: on failure returns NULL and leaves ptr allocated. */
void *cv_realloc(void *ptr, size_t n);
void cv_free(void *ptr);
/* Fail the k-th allocation from now on (k >= 0); -1 disables. For tests only. */
void cv_debug_fail_alloc_after(long k);

#endif
