/* tests/core/check.h — the failure counter and CHECK of the core's C tests: a failed
 * condition prints "FAIL: " and its message, and main returns fails != 0.
 * SPDX-License-Identifier: MIT */
#ifndef CV_TESTS_CORE_CHECK_H
#define CV_TESTS_CORE_CHECK_H
#include <stdio.h>

static int fails;
#define CHECK(c, ...)                                                                              \
  do {                                                                                             \
    if (!(c)) {                                                                                    \
      fails++;                                                                                     \
      printf("FAIL: " __VA_ARGS__);                                                                \
      printf("\n");                                                                                \
    }                                                                                              \
  } while (0)
#endif
