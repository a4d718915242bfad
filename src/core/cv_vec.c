/* src/core/cv_vec.c — zeroing and copying the short vectors of a solve without calls into
 * libc. The first call of memset or memcpy from calcvar's code in a process binds the
 * symbol lazily (a lookup through every loaded library's tables, and the resolver saves
 * the vector registers on a fresh stack page): about 1 us each in a first solve that
 * takes 10 us (docs/performance.md, "The first solve in a process"). Long vectors still
 * go to libc, where its vector code is faster and one binding is nothing beside the work.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "cv_internal.h"

/* Up to this many doubles (4 kB) a plain loop. */
#define VEC_LOOP_MAX 512

/* GCC turns a zeroing or copying loop back into a call of memset or memcpy (loop
 * distribution); these two loops must stay loops (glibc builds its own string functions
 * the same way); clang's no_builtin says the same. Other compilers: plain loops, whatever
 * they make of them. */
#if defined(__GNUC__) && !defined(__clang__)
#define CV_NO_LIBCALL __attribute__((optimize("no-tree-loop-distribute-patterns")))
#elif defined(__clang__)
#define CV_NO_LIBCALL __attribute__((no_builtin("memset", "memcpy")))
#else
#define CV_NO_LIBCALL
#endif

CV_HOT CV_NO_LIBCALL void cv_dzero(double *v, size_t n) {
  if (n > VEC_LOOP_MAX) {
    memset(v, 0, n * sizeof *v);
    return;
  }
  for (size_t i = 0; i < n; i++) v[i] = 0.0;
}

CV_HOT CV_NO_LIBCALL void cv_dcopy(double *restrict dst, const double *restrict src, size_t n) {
  if (n > VEC_LOOP_MAX) {
    memcpy(dst, src, n * sizeof *dst);
    return;
  }
  for (size_t i = 0; i < n; i++) dst[i] = src[i];
}
