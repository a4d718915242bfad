/* tests/fuzz/fuzz_scene.c — libFuzzer harness: arbitrary bytes into the scene loader, and
 * whatever loads into the problem builder and the evaluators. Built by scripts/fuzz.sh
 * (clang -fsanitize=fuzzer,address,undefined), not by the default meson build.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "expr/expr.h"
#include "scene/scene.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  char err[SC_ERRLEN];
  /* A --set override of the first parameter, if the scene has one, exercises overrides. */
  sc_set set = {"c", "1.5"};
  scene *s = scene_load_buffer((const char *)data, size, "fuzz", size % 2, &set, err, sizeof err);
  if (!s) {
    /* Every failure must come with a message. */
    if (err[0] == '\0') abort();
    return 0;
  }
  /* Constant folding keeps IEEE values and the loader refuses what is not finite: no
   * expression of a loaded scene holds a non-finite constant (theory (EX-1)). */
  if (ex_nonfinite_const(s->dag, s->F) != -1) abort();
  for (int i = 0; i < s->ndefs; i++)
    if (ex_nonfinite_const(s->dag, s->defs[i].expr) != -1) abort();
  for (int i = 0; i < s->nparams; i++)
    if (!isfinite(s->params[i].value)) abort();
  cv_problem *p =
      scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err);
  int n = s->n, m = 5;
  double x[5], *y = calloc((size_t)(4 * n + 4) * (size_t)m, sizeof *y);
  if (y) {
    double *dy = y + (size_t)n * m, *out = dy + (size_t)n * m;
    for (int k = 0; k < m; k++) x[k] = s->a + (s->b - s->a) * (k + 0.5) / m;
    scene_eval_guess(s, m, x, y);
    scene_eval_exact(s, m, x, dy);
    if (p) cv_problem_eval_energy(p, m, x, y, dy, out, out + m);
    if (s->nreports <= 2 * n + 3) scene_eval_reports(s, m, x, y, dy, out);
    free(y);
  }
  cv_problem_free(p);
  scene_free(s);
  return 0;
}
