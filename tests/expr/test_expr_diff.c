/* tests/expr/test_expr_diff.c — symbolic first and second derivatives of the corpus
 * against central finite differences; the branch-taken rule at kinks.
 * SPDX-License-Identifier: MIT */
#include "ex_test.h"

/* Step sizes and tolerances. Values and derivatives in the sampling box are O(1) to
 * O(100).
 * First derivatives: central difference with h = 1e-5 has truncation error h^2 f'''/6
 * ~ 2e-11 f''' and round-off ~ eps |f| / h ~ 2e-11 |f|; tolerance 1e-6 * max(1, |f|,
 * |f'|) leaves a margin of 10^4 while any wrong rule is off by O(1).
 * Second derivatives: second differences of f itself (not of the symbolic first
 * derivative, so the check is independent) with h = 1e-4: truncation h^2 f''''/12 ~ 1e-9
 * f'''', round-off ~ 4 eps |f| / h^2 ~ 1e-7 |f|; tolerance 1e-4 * max(1, |f|, |f''|). */
#define H1      1e-5
#define H2      1e-4
#define TOL1    1e-6
#define TOL2    1e-4
#define NPOINTS 12

static double f_at(const ex_dag *d, ex_id e, const double *s, int i, double hi, int j, double hj) {
  double p[NSLOTS];
  memcpy(p, s, sizeof p);
  p[i] += hi;
  p[j] += hj;
  return eval_at(d, e, p);
}

static void check_corpus(void) {
  int checked1 = 0, checked2 = 0, skipped = 0;
  for (int c = 0; c < NCORPUS; c++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, corpus[c].src);
    ex_id kink = corpus[c].kink ? parse_ok(d, corpus[c].kink) : -1;
    if (e < 0 || (corpus[c].kink && kink < 0)) {
      ex_dag_free(d);
      continue;
    }
    ex_id d1[NSLOTS], d2[NSLOTS][NSLOTS];
    for (int i = 0; i < NSLOTS; i++) {
      d1[i] = ex_diff(d, e, i);
      CHECK(d1[i] >= 0, "%s: d/d%s failed", corpus[c].src, slot_names[i]);
      if (!ex_depends_on(d, e, i))
        CHECK(d1[i] == ex_num(d, 0), "%s: d/d%s of an absent slot is not the node 0", corpus[c].src,
              slot_names[i]);
    }
    for (int i = 0; i < NSLOTS; i++)
      for (int j = 0; j < NSLOTS; j++) d2[i][j] = ex_diff(d, d1[i], j);
    for (int pt = 0; pt < NPOINTS; pt++) {
      double s[NSLOTS];
      random_point(s);
      if (kink >= 0 && fabs(eval_at(d, kink, s)) < 0.01) {
        skipped++;
        continue;
      }
      double f = eval_at(d, e, s);
      for (int i = 0; i < NSLOTS; i++) {
        double sym = eval_at(d, d1[i], s);
        double fd = (f_at(d, e, s, i, H1, i, 0) - f_at(d, e, s, i, -H1, i, 0)) / (2 * H1);
        char what[160];
        snprintf(what, sizeof what, "d(%s)/d%s at point %d", corpus[c].src, slot_names[i], pt);
        CHECK_CLOSE(what, sym, fd, TOL1, fmax(1, fmax(fabs(f), fabs(sym))));
        checked1++;
        for (int j = i; j < NSLOTS; j++) {
          double sym2 = eval_at(d, d2[i][j], s), fd2;
          if (i == j) {
            fd2 = (f_at(d, e, s, i, H2, i, 0) - 2 * f + f_at(d, e, s, i, -H2, i, 0)) / (H2 * H2);
          } else {
            fd2 = (f_at(d, e, s, i, H2, j, H2) - f_at(d, e, s, i, H2, j, -H2) -
                   f_at(d, e, s, i, -H2, j, H2) + f_at(d, e, s, i, -H2, j, -H2)) /
                  (4 * H2 * H2);
          }
          snprintf(what, sizeof what, "d2(%s)/d%s d%s at point %d", corpus[c].src, slot_names[i],
                   slot_names[j], pt);
          CHECK_CLOSE(what, sym2, fd2, TOL2, fmax(1, fmax(fabs(f), fabs(sym2))));
          /* Mixed partials agree symbolically up to rounding. */
          double sym2t = eval_at(d, d2[j][i], s);
          CHECK_CLOSE(what, sym2t, sym2, 1e-12, fmax(1, fabs(sym2)));
          checked2++;
        }
      }
    }
    ex_dag_free(d);
  }
  printf("corpus: %d expressions, %d first and %d second derivative values checked, "
         "%d points skipped near kinks\n",
         NCORPUS, checked1, checked2, skipped);
  CHECK(NCORPUS >= 40, "corpus has %d expressions", NCORPUS);
  CHECK(skipped < NCORPUS * NPOINTS / 20, "too many skipped points: %d", skipped);
}

/* At a kink the derivative of the branch the value takes. */
static void check_kinks(void) {
  struct {
    const char *src;
    int slot;
    double at[NSLOTS];
    double expected;
  } cases[] = {
      {"abs(y')", 3, {0, 0, 0, 0, 0}, 1}, /* abs(u) = u for u >= 0 */
      {"abs(y')", 3, {0, 0, 0, -1, 0}, -1},
      {"min(x, y)", 0, {0.5, 0.5, 0, 0, 0}, 1}, /* tie: min takes x */
      {"min(x, y)", 1, {0.5, 0.5, 0, 0, 0}, 0},
      {"max(x, y)", 0, {0.5, 0.5, 0, 0, 0}, 1},
      {"max(x, y)", 0, {0.4, 0.5, 0, 0, 0}, 0},
      {"if(x < 0.5, x^2, 1 - x)", 0, {0.5, 0, 0, 0, 0}, -1}, /* condition false at 0.5 */
      {"if(x <= 0.5, x^2, 1 - x)", 0, {0.5, 0, 0, 0, 0}, 1},
      {"x*(x > 0.5)", 0, {0.6, 0, 0, 0, 0}, 1}, /* comparison: derivative 0 */
  };
  for (size_t k = 0; k < sizeof cases / sizeof cases[0]; k++) {
    ex_dag *d = ex_dag_new();
    char err[256];
    ex_id e = ex_parse(d, cases[k].src, test_resolve, NULL, 0, err, sizeof err);
    if (e < 0) { /* "x*(x > 0.5)" is not in the grammar: build it directly */
      e = ex_binary(d, EX_MUL, ex_slot(d, 0), ex_binary(d, EX_GT, ex_slot(d, 0), ex_num(d, 0.5)));
    }
    ex_id de = ex_diff(d, e, cases[k].slot);
    CHECK_CLOSE(cases[k].src, eval_at(d, de, cases[k].at), cases[k].expected, 0, 1);
    ex_dag_free(d);
  }
}

/* Derivative shapes: reuse of the node itself and no leftover 0/1 factors. */
static void check_shapes(void) {
  ex_dag *d = ex_dag_new();
  ex_id s = parse_ok(d, "sqrt(1 + y'^2)");
  ex_id ds = ex_diff(d, s, 3);
  /* d sqrt(u) = u'/(2 sqrt(u)): y'/sqrt(1 + y'^2) after 2*y'/(2*s) ... the sqrt node is
   * reused: the derivative references s itself. */
  int reuses = 0;
  for (int id = 0; id <= ds; id++)
    for (int a = 0; a < 3; a++)
      if (ex_node_arg(d, id, a) == s) reuses = 1;
  CHECK(reuses, "derivative of sqrt does not reuse the sqrt node");
  CHECK(ex_diff(d, parse_ok(d, "x^3"), 0) == parse_ok(d, "3*x^2"), "d x^3 = 3*x^2");
  CHECK(ex_diff(d, parse_ok(d, "x^2"), 0) == parse_ok(d, "2*x"), "d x^2 = 2*x");
  CHECK(ex_diff(d, parse_ok(d, "5*x"), 0) == ex_num(d, 5), "d 5x = 5");
  CHECK(ex_diff(d, parse_ok(d, "exp(2*x)"), 0) == parse_ok(d, "2*exp(2*x)"), "d exp(2x)");
  CHECK(ex_diff(d, parse_ok(d, "x*y"), 0) == ex_slot(d, 1), "d xy/dx = y");
  CHECK(ex_diff(d, -1, 0) == -1 && ex_diff(NULL, 0, 0) == -1, "bad arguments");
  ex_dag_free(d);
}

int main(void) {
  check_corpus();
  check_kinks();
  check_shapes();
  return finish("test_expr_diff");
}
