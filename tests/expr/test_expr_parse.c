/* tests/expr/test_expr_parse.c — parser: precedence and associativity against C, every
 * function, error messages with columns, hostile input. SPDX-License-Identifier: MIT */
#include "ex_test.h"

/* Values at the point x = 0.7, y = 0.4, z = 1.5, y' = -0.3, z' = 0.25. */
static const double X = 0.7, Y = 0.4, Z = 1.5, YP = -0.3, ZP = 0.25;

typedef struct {
  const char *src;
  double expected;
} value_case;

static void check_values(void) {
  const double pi = 3.14159265358979323846;
  const value_case cases[] = {
      {"2 + 3*4", 2 + 3 * 4},
      {"(2 + 3)*4", (2 + 3) * 4},
      {"2*3^2", 2 * 9},
      {"-2^2", -4}, /* ^ binds tighter than unary minus */
      {"-x^2", -(X * X)},
      {"(-x)^2", X * X},
      {"2^3^2", 512}, /* right-associative: 2^(3^2) */
      {"(2^3)^2", 64},
      {"2^-1", 0.5},
      {"x^-y^2", pow(X, -(Y * Y))},
      {"8/4/2", 1}, /* left-associative */
      {"8-4-2", 2},
      {"2*-3", -6},
      {"--x", X},
      {"-(x + y)", -(X + Y)},
      {"x - y*z", X - Y * Z},
      {"x/y/z", X / Y / Z},
      {"x/(y*z)", X / (Y * Z)},
      {"1e-3*1e3", 1e-3 * 1e3},
      {".5 + .25", 0.75},
      {"1.5e+2 - 2E1", 150 - 20},
      {"pi", pi},
      {"2*pi*x", 2 * pi * X},
      {"y' * z'", YP * ZP},
      {"  x\t+\n y ", X + Y},
      {"sin(x)", sin(X)},
      {"cos(x)", cos(X)},
      {"tan(x)", tan(X)},
      {"asin(y)", asin(Y)},
      {"acos(y)", acos(Y)},
      {"atan(z)", atan(Z)},
      {"sinh(x)", sinh(X)},
      {"cosh(x)", cosh(X)},
      {"tanh(x)", tanh(X)},
      {"asinh(y')", asinh(YP)},
      {"acosh(z)", acosh(Z)},
      {"atanh(y)", atanh(Y)},
      {"exp(x)", exp(X)},
      {"log(z)", log(Z)},
      {"sqrt(z)", sqrt(Z)},
      {"abs(y')", fabs(YP)},
      {"atan2(y, x)", atan2(Y, X)},
      {"atan2(1, -1)", atan2(1, -1)},
      {"pow(z, x)", pow(Z, X)},
      {"pow(2, 10)", 1024},
      {"min(x, y)", fmin(X, Y)},
      {"max(x, y)", fmax(X, Y)},
      {"min(3, 2)", 2},
      {"if(x < y, 1, 2)", X < Y ? 1 : 2},
      {"if(x <= y, 1, 2)", X <= Y ? 1 : 2},
      {"if(x > y, 1, 2)", X > Y ? 1 : 2},
      {"if(x >= y, 1, 2)", X >= Y ? 1 : 2},
      {"if(x <= x, 3, 4)", 3},
      {"if(y' > 0, y', -y')", fabs(YP)},
      {"if(x + y < z*2, x - y, x*y)", X + Y < Z * 2 ? X - Y : X * Y},
      {"if(x, 5, 6)", 5}, /* a bare condition is true when nonzero */
      {"sin(x)^2 + cos(x)^2", sin(X) * sin(X) + cos(X) * cos(X)},
      {"exp(-x^2/2)/sqrt(2*pi)", exp(-(X * X) / 2) / sqrt(2 * pi)},
      {"y*sqrt(1 + y'^2)", Y * sqrt(1 + YP * YP)},
      {"-x*-y", X * Y},
      {"x^2^-1", pow(X, 0.5)},
  };
  const double s[NSLOTS] = {X, Y, Z, YP, ZP};
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, cases[i].src);
    if (e >= 0) {
      double v = eval_at(d, e, s);
      /* libm on both sides; only the order of rounding differs (a few ulps). */
      CHECK_CLOSE(cases[i].src, v, cases[i].expected, 1e-14, fmax(1, fabs(cases[i].expected)));
    }
    ex_dag_free(d);
  }
}

typedef struct {
  const char *src;
  int allow_second;
  int column;           /* expected column in the message */
  const char *contains; /* expected substring */
} error_case;

static void check_errors(void) {
  const error_case cases[] = {
      {"", 0, 1, "empty expression"},
      {"   ", 0, 4, "empty expression"},
      {"(x + 1", 0, 7, "missing ')' to close the '(' at column 1"},
      {"((x)", 0, 5, "missing ')'"},
      {"x + 1)", 0, 6, "unmatched ')'"},
      {"x +", 0, 4, "found the end of the expression"},
      {"x * ", 0, 5, "expected a number, name or '('"},
      {"x ^", 0, 4, "expected a number"},
      {"foo(x)", 0, 1, "unknown function 'foo'"},
      {"exq(x)", 0, 1, "unknown function 'exq' (did you mean 'exp'?)"},
      {"1 + cohs(x)", 0, 5, "unknown function 'cohs' (did you mean 'cosh'?)"},
      {"1 + q", 0, 5, "unknown name 'q'"},
      {"x'", 0, 1, "prime is only allowed on an unknown"},
      {"2 + y''", 0, 5, "y'': only the first derivative y' may be written here"},
      {"y'''", 1, 1, "at most the second derivative"},
      {"(x)'", 0, 4, "prime is only allowed"},
      {"2'", 0, 2, "prime is only allowed"},
      {"pi'", 0, 3, "prime is only allowed"},
      {"sin x", 0, 1, "'sin' is a function"},
      {"sin(x, y)", 0, 1, "'sin' takes 1 argument"},
      {"atan2(x)", 0, 1, "'atan2' takes 2 arguments, not 1"},
      {"if(x < 1, 2)", 0, 1, "'if' takes 3 arguments"},
      {"min(1, 2, 3, 4)", 0, 1, "'min' takes 2 arguments"},
      {"sin(x", 0, 6, "expected ',' or ')'"},
      {"2x", 0, 2, "right after a number"},
      {"x y", 0, 3, "missing operator"},
      {"x < 1", 0, 3, "comparison is only allowed as the condition of if"},
      {"(x < 1)", 0, 4, "comparison is only allowed"},
      {"1e", 0, 2, "malformed exponent"},
      {"1e999", 0, 1, "out of range"},
      {"x $ y", 0, 3, "unexpected '$'"},
      {".", 0, 1, "malformed number"},
      {"1.2.3", 0, 4, "right after a number"},
      {"x + + y", 0, 5, "expected a number"},
      {"if(x < 1 < 2, 1, 0)", 0, 10, "expected ',' or ')'"},
  };
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    ex_dag *d = ex_dag_new();
    char err[256] = "unchanged";
    ex_id e = ex_parse(d, cases[i].src, test_resolve, NULL, cases[i].allow_second, err, sizeof err);
    char want[32];
    snprintf(want, sizeof want, "column %d: ", cases[i].column);
    CHECK(e < 0, "\"%s\" parsed but should fail", cases[i].src);
    CHECK(strncmp(err, want, strlen(want)) == 0 && strstr(err, cases[i].contains),
          "\"%s\": expected message starting \"%s\" containing \"%s\", actual \"%s\"", cases[i].src,
          want, cases[i].contains, err);
    ex_dag_free(d);
  }
  /* y'' is accepted where allowed. */
  ex_dag *d = ex_dag_new();
  char err[256];
  ex_id e = ex_parse(d, "y'' + z''", test_resolve, NULL, 1, err, sizeof err);
  CHECK(e >= 0 && ex_depends_on(d, e, 5) && ex_depends_on(d, e, 6), "y'' with allow_second: %s",
        e < 0 ? err : "wrong slots");
  /* A tiny error buffer is truncated, never overrun (ASan would catch it). */
  char tiny[8];
  CHECK(ex_parse(d, "(((", test_resolve, NULL, 0, tiny, sizeof tiny) < 0 &&
            strlen(tiny) == sizeof tiny - 1,
        "truncated message \"%s\"", tiny);
  CHECK(ex_parse(d, "(((", test_resolve, NULL, 0, NULL, 0) < 0, "NULL err buffer");
  CHECK(ex_parse(d, NULL, test_resolve, NULL, 0, err, sizeof err) < 0, "NULL source");
  ex_dag_free(d);
}

/* Long and hostile input: a 1000-character sum parses and is right; 10000 nested
 * parentheses, unary minus signs or powers are refused with a message, not a crash. */
static void check_hostile(void) {
  ex_dag *d = ex_dag_new();
  char err[256];
  char *buf = malloc(50001);
  /* "x + x + ... + x": 250 terms, 999 characters. */
  size_t n = 0;
  for (int i = 0; i < 250; i++) n += (size_t)sprintf(buf + n, i ? " + x" : "x");
  CHECK(n == 997, "length %zu", n);
  ex_id e = ex_parse(d, buf, test_resolve, NULL, 0, err, sizeof err);
  double s[NSLOTS] = {0.7, 0.4, 1.5, -0.3, 0.25};
  CHECK(e >= 0, "1000-character sum: %s", err);
  if (e >= 0) CHECK_CLOSE("250 x", eval_at(d, e, s), 250 * 0.7, 1e-13, 250 * 0.7);
  /* 1000 characters of nested function calls within the depth limit (190 levels). */
  n = 0;
  for (int i = 0; i < 190; i++) n += (size_t)sprintf(buf + n, "abs(");
  n += (size_t)sprintf(buf + n, "x");
  for (int i = 0; i < 190; i++) buf[n++] = ')';
  buf[n] = 0;
  e = ex_parse(d, buf, test_resolve, NULL, 0, err, sizeof err);
  CHECK(e >= 0, "190 nested calls: %s", err);

  const char *opens[] = {"(", "-", "x^", "sin("};
  for (int k = 0; k < 4; k++) {
    n = 0;
    for (int i = 0; i < 10000; i++) n += (size_t)sprintf(buf + n, "%s", opens[k]);
    buf[n] = 0;
    strcat(buf, "x");
    e = ex_parse(d, buf, test_resolve, NULL, 0, err, sizeof err);
    CHECK(e < 0 && strstr(err, "nested too deeply"), "10000 x \"%s\": %s", opens[k],
          e < 0 ? err : "accepted");
  }
  /* A long left-associative chain is depth 1 for the parser: accepted (40000 chars). */
  n = 0;
  for (int i = 0; i < 10000; i++) n += (size_t)sprintf(buf + n, i ? "-x*y" : "x");
  e = ex_parse(d, buf, test_resolve, NULL, 0, err, sizeof err);
  CHECK(e >= 0, "10000-term chain: %s", err);
  if (e >= 0) {
    double want = 0.7 - 9999 * 0.7 * 0.4;
    CHECK_CLOSE("10000-term chain", eval_at(d, e, s), want, 1e-12, fabs(want));
    ex_id de = ex_diff(d, e, 0);
    CHECK(de >= 0, "derivative of the chain");
    char out[64];
    size_t len = ex_print(d, e, slot_names, out, sizeof out);
    CHECK(len > 30000 && strlen(out) == sizeof out - 1, "print of the chain: %zu", len);
  }
  free(buf);
  ex_dag_free(d);
}

/* Hash-consing: equal expressions are one node. */
static void check_sharing(void) {
  ex_dag *d = ex_dag_new();
  ex_id a = parse_ok(d, "y*sqrt(1 + y'^2) + sin(x)");
  int nodes = ex_dag_num_nodes(d);
  ex_id b = parse_ok(d, "y*sqrt(1 + y'^2) + sin(x)");
  CHECK(a == b && ex_dag_num_nodes(d) == nodes, "same expression twice: ids %d %d", a, b);
  CHECK(parse_ok(d, "x*y") == parse_ok(d, "y*x"), "commutative product");
  CHECK(parse_ok(d, "x + y") == parse_ok(d, "y + x"), "commutative sum");
  CHECK(parse_ok(d, "2*x") == parse_ok(d, "x*2"), "number first");
  CHECK(parse_ok(d, "x - x") == ex_num(d, 0), "x - x = 0");
  CHECK(parse_ok(d, "--x") == ex_slot(d, 0), "-(-x) = x");
  CHECK(parse_ok(d, "x^1*1 + 0") == ex_slot(d, 0), "x^1*1 + 0 = x");
  CHECK(parse_ok(d, "x^0") == ex_num(d, 1), "x^0 = 1");
  CHECK(parse_ok(d, "0*sin(x)") == ex_num(d, 0), "0*x = 0");
  CHECK(parse_ok(d, "x/1") == ex_slot(d, 0), "x/1 = x");
  CHECK(parse_ok(d, "2*3 + 1") == ex_num(d, 7), "constant folding");
  CHECK(parse_ok(d, "pow(x, 2)") == parse_ok(d, "x^2"), "pow(a, b) = a^b");
  CHECK(parse_ok(d, "x*x") == parse_ok(d, "x^2"), "x*x = x^2");
  CHECK(parse_ok(d, "-0") == ex_num(d, 0) && ex_num(d, -0.0) == ex_num(d, 0.0), "-0 = 0");
  CHECK(ex_is_const(d, parse_ok(d, "sin(pi/7)*2")), "constant expression");
  CHECK(!ex_is_const(d, parse_ok(d, "sin(pi/7)*x")), "non-constant expression");
  double v;
  CHECK(ex_eval_const(d, parse_ok(d, "log(-1)"), &v) == 0 && isnan(v), "log(-1) kept, NaN");
  CHECK(ex_eval_const(d, parse_ok(d, "x"), &v) == -1, "ex_eval_const on x");
  ex_id e = parse_ok(d, "sin(x) + z*y'");
  CHECK(ex_depends_on(d, e, 0) && !ex_depends_on(d, e, 1) && ex_depends_on(d, e, 2) &&
            ex_depends_on(d, e, 3) && !ex_depends_on(d, e, 4),
        "ex_depends_on");
  /* Substitution: y' -> 2*x in sin(x) + z*y' gives sin(x) + 2*x*z. */
  ex_id s = ex_subst(d, e, 3, parse_ok(d, "2*x"));
  CHECK(s == parse_ok(d, "sin(x) + z*(2*x)"), "ex_subst");
  CHECK(ex_subst(d, e, 1, ex_num(d, 5)) == e, "ex_subst of an absent slot");
  ex_dag_free(d);
}

/* Slots above 63 share dependency bits; ex_depends_on must still be exact. */
static void check_many_slots(void) {
  ex_dag *d = ex_dag_new();
  ex_id a = ex_binary(d, EX_ADD, ex_slot(d, 1), ex_slot(d, 70));
  CHECK(ex_depends_on(d, a, 70) && ex_depends_on(d, a, 1) && !ex_depends_on(d, a, 6) &&
            !ex_depends_on(d, a, 65),
        "slots beyond 64");
  ex_id da = ex_diff(d, a, 65);
  CHECK(da == ex_num(d, 0), "d/d slot 65 of s1 + s70 is 0");
  ex_dag_free(d);
}

/* The distance behind "did you mean" (insert, delete, substitute, swap neighbours), against
 * values counted by hand, and which names are close enough to suggest. */
static void check_name_distance(void) {
  struct {
    const char *a, *b;
    int d, close;
  } c[] = {{"sqrt", "sqrt", 0, 0},    {"sqr", "sqrt", 1, 1},
           {"alpah", "alpha", 1, 1},  {"kitten", "sitting", 3, 0},
           {"ab", "ba", 1, 1},        {"", "abc", 3, 0},
           {"z", "y", 1, 0},          {"epps", "eps", 1, 1},
           {"lambda", "lamda", 1, 1}, {"gama", "gamma", 1, 1},
           {"omegaa", "omega", 1, 1}, {"xyz", "abc", 3, 0}};
  for (size_t k = 0; k < sizeof c / sizeof c[0]; k++) {
    CHECK(ex_name_distance(c[k].a, c[k].b) == c[k].d, "distance('%s', '%s') = %d, expected %d",
          c[k].a, c[k].b, ex_name_distance(c[k].a, c[k].b), c[k].d);
    CHECK(ex_name_close(c[k].a, c[k].b) == c[k].close, "close('%s', '%s') should be %d", c[k].a,
          c[k].b, c[k].close);
  }
}

int main(void) {
  check_name_distance();
  check_values();
  check_errors();
  check_hostile();
  check_sharing();
  check_many_slots();
  return finish("test_expr_parse");
}
