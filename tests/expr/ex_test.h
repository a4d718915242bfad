/* tests/expr/ex_test.h — shared helpers of the expression tests: names, a corpus covering
 * every operator and function, random points, checks. SPDX-License-Identifier: MIT */
#ifndef EX_TEST_H
#define EX_TEST_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expr/expr.h"

/* Slots of the test expressions: x = 0, unknowns y = 1, z = 2, their primes 3, 4. */
#define NSLOTS 5
static const char *const slot_names[NSLOTS] = {"x", "y", "z", "y'", "z'"};

static int failures = 0;

#define CHECK(cond, ...)                                                                           \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      failures++;                                                                                  \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                                         \
      fprintf(stderr, __VA_ARGS__);                                                                \
      fprintf(stderr, "\n");                                                                       \
    }                                                                                              \
  } while (0)

/* |actual - expected| <= tol * scale, printed with all three on failure. */
#define CHECK_CLOSE(what, actual, expected, tol, scale)                                            \
  CHECK(fabs((actual) - (expected)) <= (tol) * (scale),                                            \
        "%s: expected %.17g, actual %.17g, tolerance %.3g (scale %.3g)", (what),                   \
        (double)(expected), (double)(actual), (double)(tol), (double)(scale))

static inline ex_id test_resolve(ex_dag *d, const char *name, int primes, void *user, char *err,
                                 size_t errlen) {
  (void)user;
  if (strcmp(name, "x") == 0) {
    if (primes) {
      snprintf(err, errlen, "a prime is only allowed on an unknown ('x' is the variable)");
      return -1;
    }
    return ex_slot(d, 0);
  }
  if (strcmp(name, "y") == 0 || strcmp(name, "z") == 0) {
    int u = name[0] == 'y' ? 1 : 2;
    if (primes == 2) return ex_slot(d, 5 + u - 1); /* y'' = 5, z'' = 6 (allow_second) */
    return ex_slot(d, u + (primes ? 2 : 0));
  }
  snprintf(err, errlen, "unknown name '%s'", name);
  return -1;
}

static inline ex_id parse_ok(ex_dag *d, const char *s) {
  char err[256];
  ex_id e = ex_parse(d, s, test_resolve, NULL, 0, err, sizeof err);
  CHECK(e >= 0, "parse of \"%s\" failed: %s", s, err);
  return e;
}

/* The corpus: every operator and function. kink (may be NULL) is an expression that
 * vanishes at the expression's kinks; points where |kink| < 0.01 are not used for finite
 * differences (the stencil would straddle the kink). The sampling box below keeps every
 * function inside its domain with margin. */
typedef struct {
  const char *src, *kink;
} corpus_entry;

static const corpus_entry corpus[] = {
    {"x + y", NULL},
    {"x - y*z", NULL},
    {"x*y*z", NULL},
    {"x/y", NULL},
    {"y/(x + z)", NULL},
    {"-x^2", NULL},
    {"x^3 - 2*x^2 + 5", NULL},
    {"y^-2", NULL},
    {"2^x", NULL},
    {"x^y", NULL},
    {"pow(z, x + 1)", NULL},
    {"y^0.5 + z^-0.5", NULL},
    {"sin(x*y)", NULL},
    {"cos(x + z^2)", NULL},
    {"tan(x)", NULL},
    {"asin(y)", NULL},
    {"acos(y*x)", NULL},
    {"atan(z*y')", NULL},
    {"sinh(y')", NULL},
    {"cosh(x*y)", NULL},
    {"tanh(2*z)", NULL},
    {"asinh(y' - x)", NULL},
    {"acosh(z)", NULL},
    {"atanh(x*y)", NULL},
    {"exp(-x^2)", NULL},
    {"log(y + z)", NULL},
    {"sqrt(1 + y'^2)", NULL},
    {"y*sqrt(1 + y'^2)", NULL},
    {"abs(y')", "y'"},
    {"abs(x - y)*z", "x - y"},
    {"atan2(y, x)", NULL},
    {"atan2(y', z - 2.5)", NULL},
    {"min(x, y)", "x - y"},
    {"max(x*z, y)", "x*z - y"},
    {"min(x, y)*max(y', z')", "(x - y)*(y' - z')"},
    {"if(x < 0.5, x^2, 1 - x)", "x - 0.5"},
    {"if(y' >= 0, y'^2, -y'^3)", "y'"},
    {"if(x*y <= z - 1, sin(x), cos(y))", "x*y - z + 1"},
    {"if(x > y, x, y)", "x - y"},
    {"(x + y)^2/(1 + z')", NULL},
    {"exp(sin(x))*log(z)", NULL},
    {"sqrt(x^2 + y^2 + z^2)", NULL},
    {"1/(1 + exp(-y'*z))", NULL},
    {"y'^2 + sin(y)^2*z'^2", NULL},
    {"--x*y", NULL},
    {"x - x + y*z'", NULL},
    {"0*x + 1*y + y/1 + z^1 + x^0", NULL},
    {"pi*x*y'", NULL},
    {"2*3*x*z", NULL},
    {"x*(y*z) - (x*y)*z + y'", NULL},
    {"1e-3*x^4 + .5*y^3", NULL},
    {"sqrt(z)*sqrt(z)", NULL},
    {"exp(x)^2 - 1/z^3", NULL},
    {"(1 + y'^2)^1.5/y", NULL},
    {"sqrt(1 + y'^2 + z'^2)/sqrt(y)", NULL},
    {"-(x - y)*(z' - y')", NULL},
    {"x^y^z'", NULL},
};
#define NCORPUS ((int)(sizeof corpus / sizeof corpus[0]))

/* Random numbers: a fixed-seed LCG so failures reproduce. */
static unsigned long long rng_state = 12345;
static inline double urand(void) {
  rng_state = rng_state * 6364136223846793005ull + 1442695040888963407ull;
  return (double)(rng_state >> 11) / 9007199254740992.0;
}

/* A point of the sampling box: x in [0.2, 0.8], y in [0.3, 0.9], z in [1.2, 2.0],
 * y' in [-0.7, 0.7], z' in [0.1, 0.6]. */
static inline void random_point(double *s) {
  static const double lo[NSLOTS] = {0.2, 0.3, 1.2, -0.7, 0.1};
  static const double hi[NSLOTS] = {0.8, 0.9, 2.0, 0.7, 0.6};
  for (int i = 0; i < NSLOTS; i++) s[i] = lo[i] + (hi[i] - lo[i]) * urand();
}

static inline double eval_at(const ex_dag *d, ex_id e, const double *s) {
  double v = NAN;
  if (ex_eval(d, e, s, &v) != 0) {
    failures++;
    fprintf(stderr, "FAIL: ex_eval out of memory\n");
  }
  return v;
}

static inline int finish(const char *name) {
  if (failures) {
    fprintf(stderr, "%s: %d failure%s\n", name, failures, failures == 1 ? "" : "s");
    return 1;
  }
  printf("%s: all checks passed\n", name);
  return 0;
}

#endif /* EX_TEST_H */
