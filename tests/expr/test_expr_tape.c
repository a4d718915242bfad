/* tests/expr/test_expr_tape.c — compiled tapes against direct evaluation: the corpus with
 * first and second derivatives over a batch of 256 points; sharing, register reuse,
 * constant and repeated outputs. SPDX-License-Identifier: MIT */
#include "ex_test.h"

#define M 256

/* The tape evaluates x^2 as x*x, x^0.5 as sqrt and so on, where ex_eval calls pow():
 * these differ by at most an ulp or two, and derivative formulas with cancellation can
 * turn that into a small absolute error on O(1) intermediate values. Tolerance
 * 1e-12 * (1 + |value|). */
#define TOL 1e-12

static void check_corpus(void) {
  static double in[NSLOTS][M], pts[M][NSLOTS];
  const double *inp[NSLOTS];
  for (int k = 0; k < M; k++) {
    random_point(pts[k]);
    for (int s = 0; s < NSLOTS; s++) in[s][k] = pts[k][s];
  }
  for (int s = 0; s < NSLOTS; s++) inp[s] = in[s];
  int max_work = 0, total_ins = 0;
  for (int c = 0; c < NCORPUS; c++) {
    ex_dag *d = ex_dag_new();
    ex_id e = parse_ok(d, corpus[c].src);
    if (e < 0) {
      ex_dag_free(d);
      continue;
    }
    /* Outputs: f, the 5 first derivatives, the 15 distinct second derivatives. */
    ex_id outs[1 + NSLOTS + NSLOTS * (NSLOTS + 1) / 2];
    int n = 0;
    outs[n++] = e;
    for (int i = 0; i < NSLOTS; i++) outs[n++] = ex_diff(d, e, i);
    for (int i = 0; i < NSLOTS; i++)
      for (int j = i; j < NSLOTS; j++) outs[n++] = ex_diff(d, outs[1 + i], j);
    ex_tape *t = ex_tape_new(d, NSLOTS, n, outs);
    CHECK(t != NULL, "%s: tape", corpus[c].src);
    if (!t) {
      ex_dag_free(d);
      continue;
    }
    size_t w = ex_tape_work_size(t, M);
    double *work = malloc((w ? w : 1) * sizeof *work);
    double *outbuf = malloc((size_t)n * M * sizeof *outbuf);
    double *outp[1 + NSLOTS + NSLOTS * (NSLOTS + 1) / 2];
    for (int o = 0; o < n; o++) outp[o] = outbuf + (size_t)o * M;
    for (size_t i = 0; i < (size_t)n * M; i++) outbuf[i] = NAN;
    ex_tape_eval(t, M, inp, outp, work);
    for (int o = 0; o < n; o++)
      for (int k = 0; k < M; k++) {
        double ref = eval_at(d, outs[o], pts[k]);
        char what[160];
        snprintf(what, sizeof what, "%s output %d point %d", corpus[c].src, o, k);
        CHECK_CLOSE(what, outp[o][k], ref, TOL, 1 + fabs(ref));
        if (failures > 20) break;
      }
    /* The work buffer stays far smaller than one register per instruction. */
    if ((int)(w / M) > max_work) max_work = (int)(w / M);
    total_ins += ex_tape_num_instructions(t);
    CHECK((int)(w / M) <= ex_tape_num_instructions(t), "%s: %d registers for %d instructions",
          corpus[c].src, (int)(w / M), ex_tape_num_instructions(t));
    free(work);
    free(outbuf);
    ex_tape_free(t);
    ex_dag_free(d);
  }
  printf("corpus: %d instructions in all, at most %d registers in one tape\n", total_ins, max_work);
}

/* Shared subexpressions once; only reachable nodes; constants, slots and repeated nodes
 * as outputs; slots the outputs do not use may be NULL. */
static void check_structure(void) {
  ex_dag *d = ex_dag_new();
  ex_id a = parse_ok(d, "sin(x*y)");
  ex_id unused = parse_ok(d, "exp(z) + cos(z)*tan(z)");
  (void)unused;
  ex_id b = parse_ok(d, "sin(x*y)^2 + sin(x*y)");
  ex_id outs[] = {b, a, ex_num(d, 3.5), ex_slot(d, 1), b, parse_ok(d, "log(-1)")};
  ex_tape *t = ex_tape_new(d, NSLOTS, 6, outs);
  /* x*y, sin, ^2, +: 4 computing instructions; then sin(x*y) is its own output, copies
   * for the constant 3.5, the slot y, the repeated b and the NaN constant: 4 more. */
  CHECK(t && ex_tape_num_instructions(t) == 8, "instructions: %d, expected 8",
        t ? ex_tape_num_instructions(t) : -1);
  double x[3] = {0.1, 0.2, 0.3}, y[3] = {1, 2, 3};
  const double *in[NSLOTS] = {x, y, NULL, NULL, NULL}; /* z is not used by the outputs */
  double o[6][3], work[64];
  double *op[6] = {o[0], o[1], o[2], o[3], o[4], o[5]};
  CHECK(ex_tape_work_size(t, 3) <= 64, "work %zu", ex_tape_work_size(t, 3));
  ex_tape_eval(t, 3, in, op, work);
  for (int k = 0; k < 3; k++) {
    double s = sin(x[k] * y[k]);
    CHECK_CLOSE("b", o[0][k], s * s + s, 1e-15, 1);
    CHECK_CLOSE("a", o[1][k], s, 0, 1);
    CHECK_CLOSE("3.5", o[2][k], 3.5, 0, 1);
    CHECK_CLOSE("y", o[3][k], y[k], 0, 1);
    CHECK_CLOSE("b again", o[4][k], o[0][k], 0, 1);
    CHECK(isnan(o[5][k]), "log(-1) gives NaN, got %g", o[5][k]);
  }
  ex_tape_free(t);
  CHECK(ex_tape_new(d, 1, 1, &b) == NULL, "a slot beyond nslots is refused");
  ex_id bad = 1 << 20;
  CHECK(ex_tape_new(d, NSLOTS, 1, &bad) == NULL, "a bad id is refused");
  ex_dag_free(d);
}

/* Register reuse: a long chain needs a handful of registers, not one per node. */
static void check_registers(void) {
  ex_dag *d = ex_dag_new();
  char *buf = malloc(20000);
  size_t n = 0;
  for (int i = 0; i < 1000; i++) n += (size_t)sprintf(buf + n, i ? " + sin(%d*x)" : "sin(x)", i);
  ex_id e = parse_ok(d, buf);
  ex_tape *t = ex_tape_new(d, 1, 1, &e);
  CHECK(t && ex_tape_num_instructions(t) >= 2000, "instructions %d",
        t ? ex_tape_num_instructions(t) : -1);
  CHECK(t && ex_tape_work_size(t, 1) <= 3, "registers for a 1000-term sum: %zu",
        t ? ex_tape_work_size(t, 1) : 0);
  double x = 0.3, out, work[8], ref = 0;
  const double *in[1] = {&x};
  double *op[1] = {&out};
  for (int i = 0; i < 1000; i++) ref += sin((i ? i : 1) * x);
  if (t) ex_tape_eval(t, 1, in, op, work);
  CHECK_CLOSE("1000-term sum", out, ref, 1e-12, 100);
  ex_tape_free(t);
  free(buf);
  ex_dag_free(d);
}

/* sin and cos of one operand: one sincos instruction for both, whichever comes first in
 * the DAG, with the values of libm's sin and cos (bit for bit: glibc's sincos shares their
 * code); a sin or cos without its partner stays a plain call. */
static void check_sincos(void) {
  ex_dag *d = ex_dag_new();
  ex_id outs[4];
  outs[0] = parse_ok(d, "cos(x*y)*z");
  outs[1] = parse_ok(d, "sin(x*y)");
  outs[2] = parse_ok(d, "cos(x)");
  outs[3] = parse_ok(d, "sin(z) + cos(z)");
  ex_tape *t = ex_tape_new(d, NSLOTS, 4, outs);
  /* x*y, sincos, *z, cos(x), sincos(z), +: 6 instructions (8 without the fusion) */
  CHECK(t && ex_tape_num_instructions(t) == 6, "instructions: %d, expected 6",
        t ? ex_tape_num_instructions(t) : -1);
  double x[5] = {0.1, -2.0, 3.0, 1e5, 0.0}, y[5] = {1, 2, -3, 7, 4}, z[5] = {0.5, 9, -1, 2, 3};
  const double *in[NSLOTS] = {x, y, z, NULL, NULL};
  double o[4][5], work[64];
  double *op[4] = {o[0], o[1], o[2], o[3]};
  CHECK(t && ex_tape_work_size(t, 5) <= 64, "work %zu", t ? ex_tape_work_size(t, 5) : 0);
  if (t) ex_tape_eval(t, 5, in, op, work);
  for (int k = 0; t && k < 5; k++) {
    CHECK(o[0][k] == cos(x[k] * y[k]) * z[k], "cos(x*y)*z at %d", k);
    CHECK(o[1][k] == sin(x[k] * y[k]), "sin(x*y) at %d", k);
    CHECK(o[2][k] == cos(x[k]), "cos(x) at %d", k);
    CHECK(o[3][k] == sin(z[k]) + cos(z[k]), "sin(z) + cos(z) at %d", k);
  }
  ex_tape_free(t);
  ex_dag_free(d);
}

/* A tape with more locations than the evaluation's pointer table holds (2048) finds its
 * operands the other way: the same values. */
static void check_large_tape(void) {
  enum { NO = 2100 };
  ex_dag *d = ex_dag_new();
  ex_id *outs = malloc(NO * sizeof *outs);
  char src[64];
  for (int i = 0; i < NO; i++) {
    snprintf(src, sizeof src, "sin(%d*x) + y", i + 1);
    outs[i] = parse_ok(d, src);
  }
  ex_tape *t = ex_tape_new(d, NSLOTS, NO, outs);
  CHECK(t != NULL, "tape of %d outputs", NO);
  double x[2] = {0.3, -1.1}, y[2] = {2, 5}, *buf = malloc(2 * NO * sizeof *buf);
  double **op = malloc(NO * sizeof *op);
  size_t w = t ? ex_tape_work_size(t, 2) : 0;
  double *work = malloc((w + 1) * sizeof *work);
  for (int i = 0; i < NO; i++) op[i] = buf + 2 * i;
  const double *in[NSLOTS] = {x, y, NULL, NULL, NULL};
  if (t) ex_tape_eval(t, 2, in, op, work);
  for (int i = 0; t && i < NO; i++)
    for (int k = 0; k < 2; k++)
      CHECK_CLOSE("large tape", op[i][k], sin((i + 1) * x[k]) + y[k], 0, 1);
  ex_tape_free(t);
  free(work);
  free(op);
  free(buf);
  free(outs);
  ex_dag_free(d);
}

int main(void) {
  check_corpus();
  check_structure();
  check_registers();
  check_sincos();
  check_large_tape();
  return finish("test_expr_tape");
}
