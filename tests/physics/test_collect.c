/* tests/physics/test_collect.c — ex_collect, the display normal form used by `calcvar
 * equations`: equal values on the expression corpus and its derivatives, re-parseable
 * text, and the collections the mechanics output relies on.
 * SPDX-License-Identifier: MIT
 *
 * Tolerance: collecting combines coefficients and expands products, so a collected
 * expression may differ by rounding that grows with cancellation between terms:
 * 1e-10 relative to max(1, |value|) leaves a margin of 10^5 over the round-off observed
 * on the corpus, while any wrong rule is off by O(1).
 */
#include "../expr/ex_test.h"

#define NPOINTS 12
#define TOL     1e-10

static void same_values(const char *what, ex_dag *d, ex_id e) {
  ex_id c = ex_collect(d, e);
  CHECK(c >= 0, "%s: ex_collect failed", what);
  if (c < 0) return;
  /* The printed collected text parses back (to a node of equal value). */
  char text[4096];
  size_t len = ex_print(d, c, slot_names, text, sizeof text);
  ex_id r = -1;
  if (len < sizeof text) {
    char err[256];
    r = ex_parse(d, text, test_resolve, NULL, 0, err, sizeof err);
    CHECK(r >= 0, "%s: collected text '%s' does not parse: %s", what, text, err);
  }
  for (int k = 0; k < NPOINTS; k++) {
    double s[NSLOTS];
    random_point(s);
    double v = eval_at(d, e, s), w = eval_at(d, c, s);
    double sc = fmax(1.0, fabs(v));
    CHECK_CLOSE(what, w, v, TOL, sc);
    if (r >= 0) CHECK_CLOSE(what, eval_at(d, r, s), v, TOL, sc);
  }
}

static void corpus_values(void) {
  int n = 0;
  for (int c = 0; c < NCORPUS; c++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, corpus[c].src);
    if (e < 0) {
      ex_dag_free(d);
      continue;
    }
    char what[256];
    snprintf(what, sizeof what, "collect(%s)", corpus[c].src);
    same_values(what, d, e), n++;
    for (int i = 0; i < NSLOTS; i++) {
      ex_id di = ex_diff(d, e, i);
      snprintf(what, sizeof what, "collect(d/d%s %s)", slot_names[i], corpus[c].src);
      same_values(what, d, di), n++;
      for (int j = 0; j <= i; j++) {
        snprintf(what, sizeof what, "collect(d2/d%sd%s %s)", slot_names[i], slot_names[j],
                 corpus[c].src);
        same_values(what, d, ex_diff(d, di, j)), n++;
      }
    }
    ex_dag_free(d);
  }
  printf("collect: %d expressions of the corpus and their derivatives\n", n);
}

/* Expected printed forms of collected expressions. */
static void forms(void) {
  static const struct {
    const char *in, *out;
  } cases[] = {
      {"y'^2 - 0.5*y'^2", "0.5*y'^2"},
      {"(36*y')/2", "18*y'"},
      {"y'*(z'*sin(y)) - z'*(y'*sin(y))", "0"},
      {"sqrt(y)*sqrt(y)", "y"},
      {"sqrt(x^2)", "sqrt(x^2)"},
      {"(x + y)*(x - y)", "x^2 - y^2"},
      {"2*(x + y) - 2*x", "2*y"},
      {"x/y*y", "x"},
      {"y'*(2*y' + z'*cos(y - z)) - y'^2", "y'^2 + cos(y - z)*(y'*z')"},
      {"sin(x + x - x)", "sin(x)"},
      {"(y^2)^0.5", "sqrt(y^2)"},
      {"(2*y)^2 - 4*y^2", "0"},
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, cases[k].in);
    ex_id c = e >= 0 ? ex_collect(d, e) : -1;
    char text[512] = "";
    if (c >= 0) ex_print(d, c, slot_names, text, sizeof text);
    CHECK(strcmp(text, cases[k].out) == 0, "collect(%s): expected '%s', got '%s'", cases[k].in,
          cases[k].out, text);
    ex_dag_free(d);
  }
}

int main(void) {
  corpus_values();
  forms();
  return finish("test_collect");
}
