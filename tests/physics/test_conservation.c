/* tests/physics/test_conservation.c — conservation laws along discrete solutions: the
 * momentum of a cyclic unknown (discrete Noether) and the energy of an autonomous
 * integrand, at the solver's quadrature points and as element averages.
 * SPDX-License-Identifier: MIT
 *
 * usage: test_conservation DATA_DIR   (DATA_DIR: copies of shared/problems)
 *
 * What is exact and what is not (docs/theory.md (P-7), (P-11)):
 * - For a cyclic unknown the discrete Euler–Lagrange equations say that the quadrature
 *   mean of p = dF/dy' over each element is one constant c for all elements, and that
 *   inside an element p - c is orthogonal to every polynomial of degree < p: at the p + 1
 *   Gauss points p - c is a multiple of the Legendre polynomial P_p. So the element means
 *   agree to round-off (tested at 1e-12), while the pointwise values spread by O(h^p)
 *   (measured, tested against the observed order).
 * - The energy is not conserved exactly by the discretisation; its spread at the
 *   quadrature points shrinks like h^p, the spread of its element means like h^(2p)
 *   (measured, tested).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene.h"

static int failures, checks;

static void truth(const char *what, int ok, const char *fmt, double a, double b) {
  checks++;
  if (!ok) {
    failures++;
    printf("FAIL %s: ", what);
    printf(fmt, a, b);
    printf("\n");
  }
}

/* Spreads of a quantity along one solve: pointwise over the quadrature points, of the
 * element means, and the distance of the means from `target`. */
typedef struct {
  double point, mean, target_err;
  int ok;
} spread;

enum { MOMENTUM, ENERGY };

static spread measure(const char *dir, const char *name, int what, int degree, int elements,
                      double target) {
  spread r = {NAN, NAN, NAN, 0};
  char path[1024], err[SC_ERRLEN] = "";
  snprintf(path, sizeof path, "%s/%s", dir, name);
  scene *s = scene_load_file(path, 0, NULL, err, sizeof err);
  cv_problem *p = NULL;
  cv_solver *sv = NULL;
  double *buf = NULL;
  if (!s) {
    printf("FAIL load %s: %s\n", path, err);
    failures++;
    return r;
  }
  s->elements = elements;
  s->degree = degree;
  s->tolerance = 1e-13;
  int n = s->n;
  if (!(p = scene_problem_new(s, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err)) ||
      !(sv = cv_solver_new(NULL)) || scene_solver_configure(s, sv, err, sizeof err) != CVAR_OK ||
      cv_solve(sv, p) != CVAR_OK) {
    printf("FAIL solve %s p=%d E=%d: %s\n", name, degree, elements, err);
    failures++;
    goto done;
  }
  int nq = cv_solver_get_num_qpoints(sv), ne = cv_solver_get_num_elements(sv);
  buf = malloc((size_t)(2 + 3 * n) * nq * sizeof *buf);
  if (!buf) goto done;
  double *x = buf, *w = x + nq, *y = w + nq, *dy = y + (size_t)n * nq, *q = dy + (size_t)n * nq;
  cv_solver_get_qpoints(sv, x, w, y, dy);
  if (what == MOMENTUM)
    cv_problem_eval_energy(p, nq, x, y, dy, NULL, q); /* unknown 0 */
  else
    cv_problem_eval_energy(p, nq, x, y, dy, q, NULL);
  int per = nq / ne;
  double lo = INFINITY, hi = -INFINITY, mlo = INFINITY, mhi = -INFINITY, terr = 0;
  for (int e = 0; e < ne; e++) {
    double sw = 0, sq = 0;
    for (int k = e * per; k < (e + 1) * per; k++) {
      lo = fmin(lo, q[k]);
      hi = fmax(hi, q[k]);
      sw += w[k];
      sq += w[k] * q[k];
    }
    mlo = fmin(mlo, sq / sw);
    mhi = fmax(mhi, sq / sw);
    terr = fmax(terr, fabs(sq / sw - target));
  }
  r.point = hi - lo;
  r.mean = mhi - mlo;
  r.target_err = terr;
  r.ok = per * ne == nq;
done:
  free(buf);
  cv_solver_free(sv);
  cv_problem_free(p);
  scene_free(s);
  return r;
}

int main(int argc, char **argv) {
  if (argc < 2) {
    fprintf(stderr, "usage: test_conservation DATA_DIR\n");
    return 2;
  }
  const char *dir = argv[1];
  char what[160];

  /* Discrete Noether on the graded-index ray: p = sqrt(1 + x) y'/sqrt(1 + y'^2) = 1/2. */
  printf("graded_index_ray momentum: degree elements | spread at qpoints | spread of "
         "element means | max |mean - 1/2|\n");
  for (int deg = 1; deg <= 4; deg++) {
    double prev = NAN;
    for (int E = 10; E <= 40; E *= 2) {
      spread r = measure(dir, "graded_index_ray.scene", MOMENTUM, deg, E, 0.5);
      printf("  %d %3d | %.3e | %.3e | %.3e\n", deg, E, r.point, r.mean, r.target_err);
      snprintf(what, sizeof what, "graded_index_ray p=%d E=%d element means equal", deg, E);
      truth(what, r.ok && r.mean <= 1e-12, "spread %.3g > %.3g", r.mean, 1e-12);
      /* The common mean approximates 1/2 to the accuracy of the solution. */
      snprintf(what, sizeof what, "graded_index_ray p=%d E=%d mean near 1/2", deg, E);
      truth(what, r.target_err <= 1e-3 * pow(10.0 / E, 2 * deg), "%.3g > %.3g", r.target_err,
            1e-3 * pow(10.0 / E, 2 * deg));
      if (E > 10) {
        /* Pointwise spread: order p in h (observed 1.0, 2.0, 3.0, 3.9 at E = 10 -> 40). */
        double order = log2(prev / r.point);
        snprintf(what, sizeof what, "graded_index_ray p=%d E=%d pointwise order", deg, E);
        truth(what, order > deg - 0.3, "observed %.3g, expected about %.3g", order, deg);
      }
      prev = r.point;
    }
  }
  /* The figure: min and max at the quadrature points within 1e-10 of 1/2 — true
   * once h^p is small enough (degree 4, 100 elements: 1.7e-11), not at degree 2. */
  spread r = measure(dir, "graded_index_ray.scene", MOMENTUM, 4, 100, 0.5);
  truth("graded_index_ray p=4 E=100 pointwise spread", r.point <= 1e-10, "%.3g > %.3g", r.point,
        1e-10);

  /* Energy drift at the quadrature points: order p (observed 1.0, 2.0, 3.0, 4.0 on both
   * scenes); of the element means: order 2p on the oscillator (observed 1.98, 3.95, 5.9
   * until round-off). */
  const char *escenes[] = {"harmonic_minimum.scene", "catenary.scene"};
  for (int sc = 0; sc < 2; sc++) {
    printf("%s energy drift: degree elements | at qpoints | of element means\n", escenes[sc]);
    for (int deg = 1; deg <= 4; deg++) {
      double prev = NAN, prevm = NAN;
      for (int E = 10; E <= 80; E *= 2) {
        spread e = measure(dir, escenes[sc], ENERGY, deg, E, 0);
        printf("  %d %3d | %.3e | %.3e\n", deg, E, e.point, e.mean);
        if (E > 10) {
          double order = log2(prev / e.point);
          snprintf(what, sizeof what, "%s p=%d E=%d energy drift order", escenes[sc], deg, E);
          truth(what, order > deg - 0.3 && order < deg + 0.7, "observed %.3g, expected %.3g", order,
                deg);
          /* Element means of H: order 2p on the oscillator while above round-off. */
          if (sc == 0 && e.mean > 1e-12) {
            order = log2(prevm / e.mean);
            snprintf(what, sizeof what, "%s p=%d E=%d element-mean drift order", escenes[sc], deg,
                     E);
            truth(what, order > 2 * deg - 0.3, "observed %.3g, expected %.3g", order, 2 * deg);
          }
        }
        prev = e.point;
        prevm = e.mean;
      }
    }
  }
  printf("%d checks, %d failures\n", checks, failures);
  return failures ? 1 : 0;
}
