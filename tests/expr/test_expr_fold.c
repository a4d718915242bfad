/* tests/expr/test_expr_fold.c — constant folding keeps IEEE semantics (theory (EX-1)):
 * constants that are not finite are never taken for 0 (0/0, (1/0)-(1/0), sqrt(-1)*0 ...),
 * ex_nonfinite_const finds them, and the simplifications the derivatives rely on
 * (x*0 = 0, x - x = 0, ...) still apply to expressions in a slot. A random fuzz compares the
 * folded value of 20000 constant expressions with a direct IEEE evaluation in C, bit for bit.
 * SPDX-License-Identifier: MIT */
#include <stdint.h>

#include "ex_test.h"

/* Same value: both NaN, or equal with the same sign (so -0 and +0 differ, inf signs too). */
static int same(double a, double b) {
  if (isnan(a) || isnan(b)) return isnan(a) && isnan(b);
  return a == b && signbit(a) == signbit(b);
}

static void check_constants(void) {
  const double inf = INFINITY;
  volatile double zero = 0.0, one = 1.0, two = 2.0; /* C's own IEEE results, at run time */
  const struct {
    const char *text;
    double value;
  } cases[] = {
      {"0/0", zero / zero},
      {"(1/0) - (1/0)", one / zero - one / zero},
      {"sqrt(-1)*0", sqrt(-one) * 0.0},
      {"0*sqrt(-1)", 0.0 * sqrt(-one)},
      {"0*(1/0)", 0.0 * inf},
      {"(1/0)*0", inf * 0.0},
      {"0/(0/0)", zero / (zero / zero)},
      {"(0/0)/(0/0)", NAN},
      {"(0/0) - (0/0)", NAN},
      {"log(0)", log(zero)},
      {"-log(0)", -log(zero)},
      {"exp(1000)", exp(1000 * one)},
      {"exp(1000) - exp(1000)", exp(1000 * one) - exp(1000 * one)},
      {"acos(2)*0", acos(two) * 0.0},
      {"atanh(1) - atanh(1)", atanh(one) - atanh(one)},
      {"(1/0)^0", pow(inf, 0.0)}, /* C's pow: 1, an IEEE result like any other */
      {"1/(1/0)", one / inf},     /* 0, computed from a non-finite constant */
      {"1e308 + 1e308", 1e308 + 1e308},
      {"0/0 + 1", NAN},
      {"2*0.5", 1.0}, /* a finite constant still folds */
  };
  for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, cases[i].text);
    double v = 12345;
    if (e >= 0) {
      CHECK(ex_eval_const(d, e, &v) == 0, "%s: not a constant", cases[i].text);
      CHECK(same(v, cases[i].value), "%s: folded to %.17g, IEEE gives %.17g", cases[i].text, v,
            cases[i].value);
      /* every case but the last contains a non-finite constant: it must be found */
      int nonfinite = strcmp(cases[i].text, "2*0.5") != 0;
      ex_id bad = ex_nonfinite_const(d, e);
      CHECK((bad >= 0) == nonfinite, "%s: ex_nonfinite_const = %d", cases[i].text, bad);
      if (nonfinite)
        CHECK(ex_node_op(d, e) != EX_NUM || !isfinite(ex_node_value(d, e)),
              "%s: folded to the number %g", cases[i].text, ex_node_value(d, e));
    }
    ex_dag_free(d);
  }
}

/* The symbolic rules stay for expressions in a slot (they are exact as real functions). */
static void check_symbolic(void) {
  const char *zero_cases[] = {"x*0", "0*y", "y - y", "0/x", "sin(x)*0"};
  for (size_t i = 0; i < sizeof zero_cases / sizeof *zero_cases; i++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, zero_cases[i]);
    CHECK(ex_node_op(d, e) == EX_NUM && ex_node_value(d, e) == 0, "%s: not folded to 0",
          zero_cases[i]);
    ex_dag_free(d);
  }
  const char *one_cases[] = {"x/x", "y^0", "1^x"};
  for (size_t i = 0; i < sizeof one_cases / sizeof *one_cases; i++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, one_cases[i]);
    CHECK(ex_node_op(d, e) == EX_NUM && ex_node_value(d, e) == 1, "%s: not folded to 1",
          one_cases[i]);
    ex_dag_free(d);
  }
  /* d/dy of y'^2 is the number 0: the derivative machinery's x*0 = 0 */
  ex_dag *d = ex_dag_new();
  ex_id e = parse_ok(d, "y'^2 + x");
  ex_id g = ex_diff(d, e, 1);
  CHECK(ex_node_op(d, g) == EX_NUM && ex_node_value(d, g) == 0, "d(y'^2 + x)/dy is not 0");
  CHECK(ex_nonfinite_const(d, e) == -1, "y'^2 + x has no non-finite constant");
  /* a slot expression times a non-finite constant keeps the constant (it is not x*0) */
  e = parse_ok(d, "x*(0/0)");
  CHECK(ex_nonfinite_const(d, e) >= 0, "x*(0/0): the 0/0 must be found");
  ex_dag_free(d);
}

/* Random constant expressions: text and direct C value built together. A subtree whose
 * every operation is finite is what the folder turns into one number, and a number node has
 * one zero (+0); the reference does the same, so the comparison can be bit for bit. */
static uint64_t rng = 0x9E3779B97F4A7C15ull;
static unsigned next(void) {
  rng ^= rng << 13;
  rng ^= rng >> 7;
  rng ^= rng << 17;
  return (unsigned)(rng >> 11);
}

typedef struct {
  double v;
  int folded; /* every operation finite: one number node */
} ref;

static ref gen(char *buf, size_t len, int depth) {
  static const char *const leaves[] = {"0", "1", "2", "0.5", "3", "1e300", "1e-300"};
  static const double leafv[] = {0, 1, 2, 0.5, 3, 1e300, 1e-300};
  ref r;
  if (depth == 0 || next() % 4 == 0) {
    unsigned k = next() % 7;
    snprintf(buf, len, "%s", leaves[k]);
    r.v = leafv[k];
    r.folded = 1;
    return r;
  }
  char a[512], b[512];
  unsigned op = next() % 9;
  ref x = gen(a, sizeof a, depth - 1);
  ref y = {0, 1};
  if (op < 5) y = gen(b, sizeof b, depth - 1);
  switch (op) {
  case 0:
    r.v = x.v + y.v;
    snprintf(buf, len, "(%s) + (%s)", a, b);
    break;
  case 1:
    r.v = x.v - y.v;
    snprintf(buf, len, "(%s) - (%s)", a, b);
    break;
  case 2:
    r.v = x.v * y.v;
    snprintf(buf, len, "(%s)*(%s)", a, b);
    break;
  case 3:
    r.v = x.v / y.v;
    snprintf(buf, len, "(%s)/(%s)", a, b);
    break;
  case 4:
    r.v = pow(x.v, y.v);
    snprintf(buf, len, "(%s)^(%s)", a, b);
    break;
  case 5:
    r.v = sqrt(x.v);
    snprintf(buf, len, "sqrt(%s)", a);
    break;
  case 6:
    r.v = log(x.v);
    snprintf(buf, len, "log(%s)", a);
    break;
  case 7:
    r.v = -x.v;
    snprintf(buf, len, "-(%s)", a);
    break;
  default:
    r.v = exp(x.v);
    snprintf(buf, len, "exp(%s)", a);
    break;
  }
  r.folded = x.folded && y.folded && isfinite(r.v);
  if (r.folded && r.v == 0) r.v = 0.0; /* the one zero of a number node */
  return r;
}

static void check_fuzz(void) {
  int nonfinite = 0, n = 20000;
  char text[2048];
  for (int i = 0; i < n; i++) {
    ex_dag *d = ex_dag_new();
    ref r = gen(text, sizeof text, 3);
    char err[256];
    ex_id e = ex_parse(d, text, test_resolve, NULL, 0, err, sizeof err);
    CHECK(e >= 0, "fuzz parse of \"%s\": %s", text, err);
    double v;
    if (e >= 0 && ex_eval_const(d, e, &v) == 0) {
      CHECK(same(v, r.v), "fuzz \"%s\": folded %.17g, IEEE %.17g", text, v, r.v);
      /* the loader's test: a non-finite constant somewhere iff some operation was not */
      CHECK((ex_nonfinite_const(d, e) >= 0) == !r.folded, "fuzz \"%s\": nonfinite_const %d", text,
            ex_nonfinite_const(d, e));
      nonfinite += !r.folded;
    }
    ex_dag_free(d);
  }
  printf("fuzz: %d constant expressions, %d with a non-finite part, all equal to C's IEEE "
         "values\n",
         n, nonfinite);
}

int main(void) {
  check_constants();
  check_symbolic();
  check_fuzz();
  if (failures)
    fprintf(stderr, "test_expr_fold: %d failures\n", failures);
  else
    printf("test_expr_fold: all checks passed\n");
  return failures ? 1 : 0;
}
