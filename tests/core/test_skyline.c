/* tests/core/test_skyline.c — the skyline LDL^T of small systems (theory N-7) against
 * CHOLMOD on the same matrices: block-banded Hessians, pointwise and integral multipliers,
 * definite and indefinite, and a matrix with an exactly zero pivot. Both factor without
 * pivoting in the natural order, so the pivots agree to round-off (1e-10 relative here, the
 * matrices being well conditioned), the inertia exactly, and a zero pivot is met at the same
 * unknown by both. Also: a solver keeps its factor across cv_solve calls on one mesh.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/cv_internal.h"

#include "check.h"

static int F2(int m, const double *x, const double *y, const double *dy, unsigned need,
              cv_partials *o, void *user) {
  (void)x, (void)need, (void)user, (void)y;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k];
    if (o->Fy) o->Fy[k] = 0, o->Fp[k] = dy[k];
    if (o->Fyy) o->Fyy[k] = 0, o->Fyp[k] = 0, o->Fpp[k] = 1;
  }
  return 0;
}

static unsigned long rng = 12345;
static double urand(void) { /* in [-1, 1) */
  rng = rng * 6364136223846793005UL + 1442695040888963407UL;
  return (double)(rng >> 11) / 9007199254740992.0 * 2.0 - 1.0;
}

/* One disc: n unknowns, E elements of degree p, with an integral constraint if integ. */
static void compare(int n, int E, int p, int integ, int zero_at) {
  cv_problem *pr = cv_problem_new(n, 0, 1, NULL);
  cv_solver *s = cv_solver_new(NULL);
  cv_problem_set_integrand(pr, F2, NULL);
  for (int k = 0; k < n; k++) cv_problem_set_dirichlet(pr, k, 0, 1);
  if (integ) cv_problem_add_integral(pr, F2, NULL, 1.0, NULL);
  cv_solver_set_elements(s, E);
  cv_solver_set_degree(s, p);
  cv_disc d;
  char msg[200];
  memset(&d, 0, sizeof d);
  if (cv_disc_init(&d, pr, s, msg, sizeof msg)) {
    CHECK(0, "disc n=%d E=%d p=%d: %s", n, E, p, msg);
    goto out;
  }
  int nf = d.nfree, *g1 = malloc(nf * sizeof *g1), *g2 = malloc(nf * sizeof *g2);
  cv_ldlt *A = NULL, *B = NULL;
  int keep = cv_ldlt_skyline_max, keep_band = cv_ldlt_skyline_band;
  cv_ldlt_skyline_max = 1 << 30;
  cv_ldlt_new(&d, g1, &A, msg, sizeof msg);
  cv_ldlt_skyline_max = 0, cv_ldlt_skyline_band = 0; /* CHOLMOD, narrow band or not */
  cv_ldlt_new(&d, g2, &B, msg, sizeof msg);
  cv_ldlt_skyline_max = keep, cv_ldlt_skyline_band = keep_band;
  const int *ca = cv_ldlt_colptr(A), *cb = cv_ldlt_colptr(B);
  CHECK(!memcmp(ca, cb, (nf + 1) * sizeof *ca) && !memcmp(g1, g2, nf * sizeof *g1), "same pattern");
  CHECK(cv_ldlt_matches(A, &d, g1) && cv_ldlt_matches(B, &d, g2), "matches its own disc");
  for (int trial = 0; trial < 3; trial++) {
    double *xa = cv_ldlt_values(A), *xb = cv_ldlt_values(B);
    for (int c = 0; c < nf; c++) /* random entries; the diagonal decides the inertia */
      for (int q = ca[c]; q < ca[c + 1]; q++) {
        double v = urand();
        if (q == ca[c + 1] - 1) v = (trial == 0 ? 4.0 : 2.0 * urand()) * (ca[c + 1] - ca[c]);
        if (zero_at >= 0 && c == zero_at && q == ca[c + 1] - 1) v = 0.0;
        if (zero_at >= 0 && c == zero_at && q != ca[c + 1] - 1) v = 0.0;
        if (zero_at >= 0 && c > zero_at && ca[c + 1] - ca[c] > c - zero_at &&
            q == ca[c] + zero_at - (c + 1 - (ca[c + 1] - ca[c])))
          v = 0.0; /* row zero_at empty: an exactly zero pivot there */
        xa[q] = xb[q] = v;
      }
    int na, nb;
    double lo_a, hi_a, lo_b, hi_b;
    cv_status sa = cv_ldlt_factor(A, &na, &lo_a, &hi_a, msg, sizeof msg);
    cv_status sb = cv_ldlt_factor(B, &nb, &lo_b, &hi_b, msg, sizeof msg);
    CHECK(sa == sb, "n=%d E=%d p=%d integ=%d trial %d: status %d vs CHOLMOD %d", n, E, p, integ,
          trial, sa, sb);
    CHECK(na == nb, "n=%d E=%d p=%d trial %d: %d negative pivots vs CHOLMOD %d", n, E, p, trial, na,
          nb);
    CHECK(fabs(lo_a - lo_b) <= 1e-10 * fmax(lo_b, 1e-300) + 1e-300 &&
              fabs(hi_a - hi_b) <= 1e-10 * hi_b,
          "pivot ratio %g vs %g, largest pivot %g vs %g", lo_a, lo_b, hi_a, hi_b);
    if (zero_at >= 0) CHECK(sa == CVAR_ESINGULAR, "zero pivot found");
    if (sa) continue;
    double *D1 = malloc(nf * sizeof *D1), *D2 = malloc(nf * sizeof *D2);
    double *b1 = malloc(nf * sizeof *b1), *b2 = malloc(nf * sizeof *b2);
    cv_ldlt_diag(A, D1);
    cv_ldlt_diag(B, D2);
    double e = 0;
    for (int f = 0; f < nf; f++) e = fmax(e, fabs(D1[f] - D2[f]) / fabs(D2[f]));
    CHECK(e < 1e-10, "pivots differ by %g", e);
    for (int mode = 0; mode < 3; mode++) {
      for (int f = 0; f < nf; f++) b1[f] = b2[f] = urand();
      if (mode == 0)
        cv_ldlt_solve(A, b1), cv_ldlt_solve(B, b2);
      else
        cv_ldlt_solve_L(A, mode - 1, b1), cv_ldlt_solve_L(B, mode - 1, b2);
      double m = 0, sc = 0;
      for (int f = 0; f < nf; f++) m = fmax(m, fabs(b1[f] - b2[f])), sc = fmax(sc, fabs(b2[f]));
      CHECK(m <= 1e-9 * sc, "n=%d E=%d p=%d trial %d solve mode %d differs by %g of %g", n, E, p,
            trial, mode, m, sc);
    }
    free(D1), free(D2), free(b1), free(b2);
  }
  cv_ldlt_free(A);
  cv_ldlt_free(B);
  free(g1), free(g2);
out:
  cv_disc_free(&d);
  cv_solver_free(s);
  cv_problem_free(pr);
}

/* The solver keeps its factor while the mesh's pattern stays, and replaces it when the
 * pattern changes: y'^2/2 on [0, 1], y(0) = 0, y(1) = 1 has y = x, action 1/2 exactly; with
 * the end at 1 free, y = 0, action 0. */
static void keeps_factor(void) {
  cv_problem *pr = cv_problem_new(1, 0, 1, NULL);
  cv_solver *s = cv_solver_new(NULL);
  cv_problem_set_integrand(pr, F2, NULL);
  cv_problem_set_dirichlet(pr, 0, 0, 1);
  cv_solver_set_elements(s, 3);
  cv_solver_set_degree(s, 2);
  CHECK(cv_solve(s, pr) == CVAR_OK && fabs(cv_solver_get_action(s) - 0.5) < 1e-13,
        "first solve: action %.17g", cv_solver_get_action(s));
  const void *f1 = s->ldlt;
  CHECK(cv_solve(s, pr) == CVAR_OK && fabs(cv_solver_get_action(s) - 0.5) < 1e-13, "second solve");
  CHECK(f1 && s->ldlt == f1, "the second solve on the same mesh keeps the factor");
  cv_solver_set_elements(s, 5); /* new pattern: the factor must be replaced */
  cv_solver_set_degree(s, 3);
  CHECK(cv_solve(s, pr) == CVAR_OK && fabs(cv_solver_get_action(s) - 0.5) < 1e-13,
        "after a mesh change: action %.17g", cv_solver_get_action(s));
  CHECK(cv_ldlt_matches(s->ldlt, &s->disc, s->gof), "factor of the new mesh");
  cv_problem_set_free_end(pr, 0, 1); /* same mesh, one more unknown */
  double y[16];
  CHECK(cv_solve(s, pr) == CVAR_OK && fabs(cv_solver_get_action(s)) < 1e-13,
        "free end: action %.17g", cv_solver_get_action(s));
  cv_solver_get_values(s, y);
  CHECK(fabs(y[15]) < 1e-12, "free end: y(1) = %g, not 0", y[15]);
  CHECK(cv_ldlt_matches(s->ldlt, &s->disc, s->gof), "factor of the new unknowns");
  cv_solver_free(s);
  cv_problem_free(pr);
}

int main(void) {
  keeps_factor();
  compare(1, 1, 1, 0, -1);
  compare(1, 6, 3, 0, -1);
  compare(3, 1, 8, 0, -1);
  compare(2, 5, 4, 1, -1);
  compare(1, 24, 6, 1, -1);
  compare(2, 4, 2, 0, 3);
  printf("%s\n", fails ? "FAILED" : "ok");
  return fails != 0;
}
