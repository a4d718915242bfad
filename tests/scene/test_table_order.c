/* tests/scene/test_table_order.c — the CSV reader of [tables] (scene_table.c) takes the rows
 * in any order: a 3-D grid written in grid order (the fast path that keeps the values as
 * the table's array), with one coordinate decreasing, with two rows swapped in the middle
 * (the order check fails half-way), shuffled, and with two spellings of one coordinate
 * ("0.5" and "0.50") must all give a table equal to the data at every grid point
 * (exactly: the spline interpolates). A repeated row and a missing row must be reported
 * at the right lines.
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "scene/scene_internal.h"

enum { NX = 5, NY = 4, NZ = 6, NP = NX * NY * NZ };

static double data(int i, int j, int k) { return 1.0 + i + 0.1 * j * j + 0.01 * k * k * k; }

/* Write the rows in the order perm[0..nrows) (indices i*NY*NZ + j*NZ + k); fmt_y spells
 * the y coordinate (j / 2.0) of row r. */
static int write_csv(const char *path, const int *perm, int nrows, int desc_x, int spell) {
  FILE *f = fopen(path, "w");
  if (!f) return -1;
  fprintf(f, "x, y, z, v\n\n"); /* a blank line: rows are not lines */
  for (int r = 0; r < nrows; r++) {
    int p = perm[r], i = p / (NY * NZ), j = p / NZ % NY, k = p % NZ;
    if (desc_x) i = NX - 1 - i;
    const char *yfmt = spell && (r & 1) ? "%.2f" : "%g";
    char y[32];
    snprintf(y, sizeof y, yfmt, j / 2.0);
    fprintf(f, "%d,%s,%g,%.17g\n", i, y, k * 0.25, data(i, j, k));
  }
  return fclose(f);
}

static int check(const char *what, const char *path) {
  char err[SC_ERRLEN] = "";
  cv_table *t = sc_table_read(path, path, err, sizeof err);
  if (!t) {
    fprintf(stderr, "FAIL %s: %s\n", what, err);
    return 1;
  }
  int bad = 0;
  for (int i = 0; i < NX; i++)
    for (int j = 0; j < NY; j++)
      for (int k = 0; k < NZ; k++) {
        double u[3] = {i, j / 2.0, k * 0.25}, got;
        if (cv_table_eval(t, u, NULL, &got) != 0 || got != data(i, j, k)) bad++;
      }
  cv_table_free(t);
  if (bad)
    fprintf(stderr, "FAIL %s: %d of %d grid points differ from the data\n", what, bad, NP);
  else
    printf("ok %s\n", what);
  return bad != 0;
}

static int check_err(const char *what, const char *path, const char *expect) {
  char err[SC_ERRLEN] = "";
  cv_table *t = sc_table_read(path, path, err, sizeof err);
  cv_table_free(t);
  char want[SC_ERRLEN + 64];
  snprintf(want, sizeof want, "%s:%s", path, expect);
  if (t || strncmp(err, want, strlen(want)) != 0) {
    fprintf(stderr, "FAIL %s:\n  expected: %s...\n  actual:   %s\n", what, want,
            t ? "(a table)" : err);
    return 1;
  }
  printf("ok %s\n", what);
  return 0;
}

int main(void) {
  char path[] = "/tmp/test_table_order_XXXXXX";
  int fd = mkstemp(path);
  if (fd < 0) return 1;
  int perm[NP + 1], fails = 0;
  for (int r = 0; r < NP; r++) perm[r] = r;
  fails += write_csv(path, perm, NP, 0, 0) || check("grid order", path);
  fails += write_csv(path, perm, NP, 1, 0) || check("x decreasing", path);
  fails += write_csv(path, perm, NP, 0, 1) || check("two spellings of y", path);
  int a = NP / 2, tmp = perm[a];
  perm[a] = perm[a + 1], perm[a + 1] = tmp;
  fails += write_csv(path, perm, NP, 0, 0) || check("two rows swapped half-way", path);
  unsigned s = 12345;
  for (int r = NP - 1; r > 0; r--) { /* Fisher-Yates with a fixed LCG */
    s = s * 1103515245u + 12345u;
    int q = (int)((s >> 8) % (unsigned)(r + 1));
    tmp = perm[r], perm[r] = perm[q], perm[q] = tmp;
  }
  fails += write_csv(path, perm, NP, 0, 0) || check("shuffled", path);

  /* in grid order, then row 10 again at the end: lines are 3 + row (header, blank) */
  for (int r = 0; r < NP; r++) perm[r] = r;
  perm[NP] = 10;
  fails += write_csv(path, perm, NP + 1, 0, 0) ||
           check_err("repeated row", path, "123: repeated grid point (also on line 13)");
  /* row 7 missing: reported at the last row's line with the missing point */
  for (int r = 7; r < NP - 1; r++) perm[r] = r + 1;
  fails += write_csv(path, perm, NP - 1, 0, 0) ||
           check_err("missing row", path,
                     "121: the grid is not complete: 1 of 120 points are missing, e.g. x = 0, "
                     "y = 0.5, z = 0.25");
  remove(path);
  return fails ? 1 : 0;
}
