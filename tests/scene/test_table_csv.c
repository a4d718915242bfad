/* tests/scene/test_table_csv.c — the CSV number reader of [tables] (scene_table.c): every
 * value written with 17 significant digits (and in other forms) reads back as the very same
 * double, checked where the spline equals the data exactly (at the grid points).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
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
      double x = ((double)(s >> 11) / 9007199254740992.0 + 0.1) *
                 pow(10.0, (double)((int)(s % 61) - 30));
      if (s & 1) x = -x;
      char buf[64];
      snprintf(buf, sizeof buf, fmts[(i * NY + j) % 7], x);
      v[i * NY + j] = strtod(buf, NULL); /* the reference reading */
      fprintf(f, "%d, %d, %s\n", i, j, buf);
    }
  fclose(f);
  char err[SC_ERRLEN] = "";
  cv_table *t = sc_table_read(path, path, err, sizeof err);
  remove(path);
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
  return bad ? 1 : 0;
}
