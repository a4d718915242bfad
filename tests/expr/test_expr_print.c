/* tests/expr/test_expr_print.c — printing: exact texts, no leftover 0/1 factors or terms in
 * derivatives, and print -> parse gives back the same node (so the same values) for the
 * whole corpus and its first and second derivatives. SPDX-License-Identifier: MIT */
#include <ctype.h>

#include "ex_test.h"

static void print_to(const ex_dag *d, ex_id e, char *buf, size_t len) {
  size_t need = ex_print(d, e, slot_names, buf, len);
  CHECK(need == strlen(buf), "ex_print returned %zu for \"%s\" (%zu characters)", need, buf,
        strlen(buf));
}

/* Exact printed forms: minimal parentheses and safe signs. */
static void check_texts(void) {
  const char *cases[][2] = {
      {"-x^2", "-x^2"},
      {"(-x)^2", "(-x)^2"},
      {"(-2)^x", "(-2)^x"},
      {"x^-1", "x^(-1)"},
      {"x^(-y)", "x^(-y)"},
      {"2^3^x", "2^3^x"},
      {"(x^2)^y", "(x^2)^y"},
      {"x - (y - z)", "x - (y - z)"},
      {"x - (y + z)", "x - (y + z)"},
      {"(x - y) - z", "x - y - z"},
      {"x/(y*z)", "x/(y*z)"},
      {"x/y/z", "x/y/z"},
      {"(x*y)/z", "x*y/z"},
      {"-(x + y)", "-(x + y)"},
      {"x*-y", "-x*y"},
      {"x + -y", "x - y"},
      {"x - -y", "x + y"},
      {"x + (-2)", "x - 2"},
      {"2*x*y", "2*x*y"},
      {"x*(y*z)", "x*(y*z)"},
      {"(x + y)*z", "(x + y)*z"},
      {"sin(x)^2", "sin(x)^2"},
      {"1e-5*x", "1e-05*x"},
      {"0.1 + x", "x + 0.1"},
      {"pi*x", "pi*x"},
      {"if(x < 1, x, -x)", "if(x < 1, x, -x)"},
      {"if(x + 1 >= y*2, 1, 0)", "if(x + 1 >= 2*y, 1, 0)"},
      {"atan2(y, x) + min(x, y) + pow(x, y)", "atan2(y, x) + min(x, y) + x^y"},
      {"x^3 - 2*x^2 + 5", "x^3 - 2*x^2 + 5"},
      {"1 + x", "x + 1"},
      {"x + (y - z)", "y - z + x"},
      {"-(-x)", "x"},
      {"y'^2", "y'^2"},
  };
  char buf[256];
  for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, cases[i][0]);
    if (e >= 0) {
      print_to(d, e, buf, sizeof buf);
      CHECK(strcmp(buf, cases[i][1]) == 0, "print of \"%s\": expected \"%s\", actual \"%s\"",
            cases[i][0], cases[i][1], buf);
    }
    ex_dag_free(d);
  }
  /* Comparisons as values and non-finite constants print re-parseably. */
  ex_dag *d = ex_dag_new();
  ex_id lt = ex_binary(d, EX_LT, ex_slot(d, 0), ex_slot(d, 1));
  print_to(d, lt, buf, sizeof buf);
  CHECK(strcmp(buf, "if(x < y, 1, 0)") == 0, "comparison as a value: \"%s\"", buf);
  print_to(d, ex_binary(d, EX_ADD, ex_num(d, INFINITY), ex_slot(d, 0)), buf, sizeof buf);
  /* a non-finite constant takes part in no rewriting rule (theory (EX-1)), not even the
   * canonical order of a sum */
  CHECK(strcmp(buf, "(1/0) + x") == 0, "infinity: \"%s\"", buf);
  /* Truncation: like snprintf. */
  char small[5];
  size_t n = ex_print(d, parse_ok(d, "sin(x) + cos(y)"), slot_names, small, sizeof small);
  CHECK(n == 15 && strcmp(small, "sin(") == 0, "truncated: %zu \"%s\"", n, small);
  CHECK(ex_print(d, parse_ok(d, "x"), slot_names, NULL, 0) == 1, "length only");
  ex_dag_free(d);
}

/* Leftover identities in printed text: a number token 0 next to an arithmetic operator,
 * or 1 as a factor, divisor or exponent. "10*x" or "x*0.1" are fine. */
static const char *leftover(const char *s) {
  for (size_t i = 0; s[i]; i++) {
    if (!(isdigit((unsigned char)s[i]) || s[i] == '.')) continue;
    if (i > 0 && (isalnum((unsigned char)s[i - 1]) || s[i - 1] == '_' || s[i - 1] == '.'))
      continue; /* inside a name or number */
    char *end;
    double v = strtod(s + i, &end);
    size_t j = (size_t)(end - s);
    size_t b = i;
    while (b > 0 && s[b - 1] == ' ') b--;
    char prev = b > 0 ? s[b - 1] : 0;
    while (s[j] == ' ') j++;
    char next = s[j];
    if (v == 0 && (strchr("*/^+-", prev) && prev)) return "0 as an operand";
    if (v == 0 && next && strchr("*/^+-", next)) return "0 as an operand";
    if (v == 1 && prev && strchr("*/^", prev)) return "1 as a factor, divisor or exponent";
    if (v == 1 && next == '*') return "1 as a factor";
    i = (size_t)(end - s) - 1;
  }
  return NULL;
}

static void check_roundtrip(void) {
  size_t cap = 1 << 16;
  char *buf = malloc(cap);
  int printed = 0;
  for (int c = 0; c < NCORPUS; c++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, corpus[c].src);
    if (e < 0) {
      ex_dag_free(d);
      continue;
    }
    ex_id list[1 + NSLOTS + NSLOTS * NSLOTS];
    int n = 0;
    list[n++] = e;
    for (int i = 0; i < NSLOTS; i++) {
      ex_id di = ex_diff(d, e, i);
      list[n++] = di;
      for (int j = 0; j < NSLOTS; j++) list[n++] = ex_diff(d, di, j);
    }
    for (int k = 0; k < n; k++) {
      if (list[k] < 0) continue;
      size_t need = ex_print(d, list[k], slot_names, buf, cap);
      CHECK(need < cap, "text too long: %zu", need);
      if (k > 0) {
        const char *why = leftover(buf);
        CHECK(!why, "derivative of \"%s\" prints as \"%s\": %s", corpus[c].src, buf, why);
      }
      char err[256];
      ex_id back = ex_parse(d, buf, test_resolve, NULL, 0, err, sizeof err);
      CHECK(back >= 0, "\"%s\" (from \"%s\") does not re-parse: %s", buf, corpus[c].src, err);
      if (back < 0) continue;
      /* Same node, hence the same value at every point; the values are compared too, at
       * random points, exactly (the same DAG evaluates bit for bit the same). */
      CHECK(back == list[k], "\"%s\" re-parses to a different node", buf);
      for (int pt = 0; pt < 3; pt++) {
        double s[NSLOTS];
        random_point(s);
        double v0 = eval_at(d, list[k], s), v1 = eval_at(d, back, s);
        CHECK(v0 == v1 || (isnan(v0) && isnan(v1)), "\"%s\": %.17g vs re-parsed %.17g", buf, v0,
              v1);
      }
      printed++;
    }
    ex_dag_free(d);
  }
  printf("round trip: %d expressions printed and re-parsed\n", printed);
  free(buf);
}

int main(void) {
  check_texts();
  check_roundtrip();
  return finish("test_expr_print");
}
