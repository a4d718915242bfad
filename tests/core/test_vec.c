/* tests/core/test_vec.c — the helpers that keep a small solve off libc and libm (issue 14,
 * item 10; docs/performance.md, "The first solve in a process"), against the libc and libm
 * functions they stand for:
 *   - cv_set_msg_converged(msg, len, k) writes exactly what snprintf(msg, len, "converged
 *     in %d iterations", k) writes, for k from INT_MIN to INT_MAX and every buffer length
 *     from 1 to 40 (truncation included), and nothing when len is 0;
 *   - cv_dzero and cv_dcopy set exactly n entries (both sides of the 512-entry switch to
 *     memset/memcpy) and leave the guard entries around them alone;
 *   - cv_fmax(a, b) is fmax(a, b) on numbers, infinities and NaN in either place.
 * SPDX-License-Identifier: MIT */
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/cv_internal.h"

#include "check.h"

static void test_converged_message(void) {
  const int ks[] = {0, 1, 4, 9, 10, 99, 100, 12345, INT_MAX, -1, -10, INT_MIN};
  for (size_t i = 0; i < sizeof ks / sizeof ks[0]; i++)
    for (size_t len = 1; len <= 40; len++) {
      char got[48], want[48];
      memset(got, 'x', sizeof got);
      memset(want, 'x', sizeof want);
      cv_set_msg_converged(got, len, ks[i]);
      snprintf(want, len, "converged in %d iterations", ks[i]);
      CHECK(memcmp(got, want, sizeof got) == 0, "k = %d, len = %zu: '%.*s' against '%.*s'", ks[i],
            len, (int)len, got, (int)len, want);
    }
  char keep[4] = "abc";
  cv_set_msg_converged(keep, 0, 5);
  CHECK(strcmp(keep, "abc") == 0, "len 0 wrote '%s'", keep);
}

static void test_zero_copy(void) {
  static double v[2100], src[2100];
  const size_t ns[] = {0, 1, 2, 7, 511, 512, 513, 2000};
  for (size_t k = 0; k < sizeof src / sizeof src[0]; k++) src[k] = 1.0 + k;
  for (size_t i = 0; i < sizeof ns / sizeof ns[0]; i++) {
    size_t n = ns[i];
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) v[k] = -7.0;
    cv_dzero(v + 1, n);
    int bad = v[0] != -7.0 || v[n + 1] != -7.0;
    for (size_t k = 1; k <= n; k++) bad |= v[k] != 0.0 || signbit(v[k]);
    CHECK(!bad, "cv_dzero, n = %zu", n);
    for (size_t k = 0; k < sizeof v / sizeof v[0]; k++) v[k] = -7.0;
    cv_dcopy(v + 1, src, n);
    bad = v[0] != -7.0 || v[n + 1] != -7.0;
    for (size_t k = 0; k < n; k++) bad |= v[k + 1] != src[k];
    CHECK(!bad, "cv_dcopy, n = %zu", n);
  }
}

static void test_fmax(void) {
  const double xs[] = {-INFINITY, -3.5, -1e-300, 1e-300, 2.0, 1e300, INFINITY, NAN};
  const size_t nx = sizeof xs / sizeof xs[0];
  for (size_t i = 0; i < nx; i++)
    for (size_t j = 0; j < nx; j++) {
      double a = xs[i], b = xs[j], got = cv_fmax(a, b), want = fmax(a, b);
      CHECK((isnan(got) && isnan(want)) || got == want, "cv_fmax(%g, %g) = %g, fmax %g", a, b, got,
            want);
    }
}

int main(void) {
  test_converged_message();
  test_zero_copy();
  test_fmax();
  if (fails) printf("%d failures\n", fails);
  return fails != 0;
}
