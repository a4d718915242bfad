/* tests/scene/test_table_csv.c — the CSV number reader of [tables] (scene_table.c): every
 * value written with 17 significant digits (and in other forms) reads back as the very same
 * double, checked where the spline equals the data exactly (at the grid points); and
 * every allocation failure while reading a table, adding it to a problem, compiling a
 * formula that calls it and solving reports a failure instead of crashing (ASan checks
 * that nothing leaks on those paths).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "core/cv_memory.h"
#include "scene/scene_internal.h"

int main(void) {
  const int NX = 50, NY = 40;
  char path[] = "/tmp/test_table_csv_XXXXXX";
  int fd = mkstemp(path);
  FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
  if (!f) return 1;
  double *v = malloc((size_t)NX * NY * sizeof *v);
  uint64_t s = 88172645463325252ull;
  const char *fmts[] = {"%.17g", "%.16g", "%.15g", "%.17e", "%.3f", "%.20g", "%.25e"};
  fprintf(f, "u, w, value\n");
  for (int i = 0; i < NX; i++)
    for (int j = 0; j < NY; j++) {
      s ^= s << 13, s ^= s >> 7, s ^= s << 17;
      /* magnitudes from 1e-30 to 1e30, random significands */
      double x =
          ((double)(s >> 11) / 9007199254740992.0 + 0.1) * pow(10.0, (double)((int)(s % 61) - 30));
      if (s & 1) x = -x;
      char buf[64];
      snprintf(buf, sizeof buf, fmts[(i * NY + j) % 7], x);
      v[i * NY + j] = strtod(buf, NULL); /* the reference reading */
      fprintf(f, "%d, %d, %s\n", i, j, buf);
    }
  fclose(f);
  char err[SC_ERRLEN] = "";
  cv_table *t = sc_table_read(path, path, err, sizeof err);
  if (!t) {
    fprintf(stderr, "FAIL: %s\n", err);
    return 1;
  }
  int bad = 0;
  for (int i = 0; i < NX; i++)
    for (int j = 0; j < NY; j++) {
      double u[2] = {i, j}, got;
      cv_table_eval(t, u, NULL, &got);
      if (got != v[i * NY + j] && bad++ < 5) /* -0 reads as 0 through the spline */
        fprintf(stderr, "FAIL: point (%d, %d): read %.17g, strtod gives %.17g\n", i, j, got,
                v[i * NY + j]);
    }
  printf("%d of %d values read back differently from strtod\n", bad, NX * NY);
  cv_table_free(t);
  free(v);

  /* allocation failures: a 6 x 6 table of 1 + u^2 + w^2 */
  f = fopen(path, "w");
  if (!f) return 1;
  fprintf(f, "u,w,c\n");
  for (int i = 0; i < 6; i++)
    for (int j = 0; j < 6; j++)
      fprintf(f, "%g,%g,%g\n", 0.2 * i, 0.2 * j, 1 + 0.04 * (i * i + j * j));
  fclose(f);
  int steps = 0, solved = 0;
  for (long k = 0; k < 100000 && !solved; k++) {
    cv_debug_fail_alloc_after(k);
    err[0] = '\0';
    cv_table *tk = sc_table_read(path, path, err, sizeof err);
    cv_status why = CVAR_OK;
    cv_problem *p = tk ? cv_problem_new(1, 0.0, 1.0, &why) : NULL;
    cv_solver *sv = p ? cv_solver_new(&why) : NULL;
    char msg[300] = "";
    cv_status st = CVAR_ENOMEM;
    if (sv && cv_problem_add_table(p, "c", tk) == CVAR_OK) {
      cv_problem_set_dirichlet(p, 0, 0.2, 0.6);
      st = cv_problem_set_integrand_expr(p, "x", "y", "c(x, y)*sqrt(1 + y'^2)", NULL, msg,
                                         sizeof msg);
      if (st == CVAR_OK) st = cv_solve(sv, p);
    }
    cv_debug_fail_alloc_after(-1);
    if (!tk && !err[0]) {
      bad++;
      fprintf(stderr, "FAIL: allocation %ld: no table and no message\n", k);
    }
    solved = st == CVAR_OK;
    steps++;
    cv_solver_free(sv);
    cv_problem_free(p);
    cv_table_free(tk);
  }
  remove(path);
  printf("allocation failures: %d steps until the table scene solved (%s)\n", steps,
         solved ? "ok" : "never solved");
  if (!solved) bad++;
  return bad ? 1 : 0;
}
