/* tests/core/refproblems.h — the reference problems of shared/problems as C callbacks with
 * hand-derived partials, and their exact solutions.
 * SPDX-License-Identifier: MIT */
#ifndef REFPROBLEMS_H
#define REFPROBLEMS_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "calcvar.h"

#ifndef PI
#define PI 3.14159265358979323846
#endif

/* Shorthands for the SoA layout of cv_partials (n unknowns, m points). */
#define SET1(arr, i, k, v)                                                                         \
  do {                                                                                             \
    if (arr) (arr)[(i)*m + (k)] = (v);                                                             \
  } while (0)
#define SET2(arr, i, j, k, v)                                                                      \
  do {                                                                                             \
    if (arr) (arr)[((i)*n + (j)) * m + (k)] = (v);                                                 \
  } while (0)

/* Catenary F = y sqrt(1 + y'^2); exact y = c cosh(x/c) on [-1, 1], c = 2. */
static inline int catenary_F(int m, const double *x, const double *y, const double *dy,
                             unsigned need, cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p);
    o->F[k] = y[k] * s;
    if (o->Fy) {
      o->Fy[k] = s;
      o->Fp[k] = y[k] * p / s;
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = p / s;
      o->Fpp[k] = y[k] / (s * s * s);
    }
  }
  return 0;
}
static inline double catenary_exact(double x) { return 2 * cosh(x / 2); }
#define CATENARY_ACTION 4.350402387287603

/* Harmonic oscillator F = q'^2/2 - q^2/2 on [0, T], q(0) = 0, q(T) = 1. */
static inline int harmonic_F(int m, const double *x, const double *y, const double *dy,
                             unsigned need, cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k] - 0.5 * y[k] * y[k];
    if (o->Fy) {
      o->Fy[k] = -y[k];
      o->Fp[k] = dy[k];
    }
    if (o->Fyy) {
      o->Fyy[k] = -1;
      o->Fyp[k] = 0;
      o->Fpp[k] = 1;
    }
  }
  return 0;
}

/* Maxwell's fish-eye ray, F = 2/(1 + x^2 + y^2) sqrt(1 + y'^2); exact -2 + sqrt(5 - x^2). */
static inline int fisheye_F(int m, const double *x, const double *y, const double *dy,
                            unsigned need, cv_partials *o, void *user) {
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p), r = 1 + x[k] * x[k] + y[k] * y[k];
    double nn = 2 / r, ny = -4 * y[k] / (r * r);
    double nyy = -4 / (r * r) + 16 * y[k] * y[k] / (r * r * r);
    o->F[k] = nn * s;
    if (o->Fy) {
      o->Fy[k] = ny * s;
      o->Fp[k] = nn * p / s;
    }
    if (o->Fyy) {
      o->Fyy[k] = nyy * s;
      o->Fyp[k] = ny * p / s;
      o->Fpp[k] = nn / (s * s * s);
    }
  }
  return 0;
}
static inline double fisheye_exact(double x) { return -2 + sqrt(5 - x * x); }
#define FISHEYE_ACTION 1.7890384119508238

/* Graded index n = sqrt(1 + x): F = n sqrt(1 + y'^2); exact sqrt(0.75 + x) - sqrt(0.75). */
static inline int graded_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                           cv_partials *o, void *user) {
  (void)y;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p), nn = sqrt(1 + x[k]);
    o->F[k] = nn * s;
    if (o->Fy) {
      o->Fy[k] = 0;
      o->Fp[k] = nn * p / s;
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = 0;
      o->Fpp[k] = nn / (s * s * s);
    }
  }
  return 0;
}
static inline double graded_exact(double x) { return sqrt(0.75 + x) - sqrt(0.75); }
#define GRADED_ACTION 1.3387673554360535

/* Straight line F = sqrt(1 + y'^2); exact y = 2x. */
static inline int line_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                         cv_partials *o, void *user) {
  (void)x;
  (void)y;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double p = dy[k], s = sqrt(1 + p * p);
    o->F[k] = s;
    if (o->Fy) {
      o->Fy[k] = 0;
      o->Fp[k] = p / s;
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = 0;
      o->Fpp[k] = 1 / (s * s * s);
    }
  }
  return 0;
}

/* Boundary layers F = (eps^2 y'^2 + (y - 1)^2)/2, y(0) = y(1) = 0; user = &eps. */
static inline int layer_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                          cv_partials *o, void *user) {
  (void)x;
  (void)need;
  double e2 = *(const double *)user * *(const double *)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * (e2 * dy[k] * dy[k] + (y[k] - 1) * (y[k] - 1));
    if (o->Fy) {
      o->Fy[k] = y[k] - 1;
      o->Fp[k] = e2 * dy[k];
    }
    if (o->Fyy) {
      o->Fyy[k] = 1;
      o->Fyp[k] = 0;
      o->Fpp[k] = e2;
    }
  }
  return 0;
}
static inline double layer_exact(double x, double eps) {
  return 1 - (exp((x - 1) / eps) + exp(-x / eps)) / (1 + exp(-1 / eps));
}

/* Brachistochrone F = sqrt((1 + y'^2)/y); y > 0 required (else "cannot evaluate"). */
static inline int brach_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                          cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    if (!(y[k] > 0)) return 1;
    double p = dy[k], s = sqrt(1 + p * p), r = sqrt(y[k]), y32 = y[k] * r;
    o->F[k] = s / r;
    if (o->Fy) {
      o->Fy[k] = -s / (2 * y32);
      o->Fp[k] = p / (s * r);
    }
    if (o->Fyy) {
      o->Fyy[k] = 0.75 * s / (y32 * y[k]);
      o->Fyp[k] = -p / (2 * s * y32);
      o->Fpp[k] = 1 / (s * s * s * r);
    }
  }
  return 0;
}
#define BRACH_TIME 4.442882938158366

/* Sphere geodesic, energy form F = th'^2 + sin(th)^2 ph'^2 (n = 2). */
static inline int sphere_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                           cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  const int n = 2;
  for (int k = 0; k < m; k++) {
    double th = y[k], tp = dy[k], pp = dy[m + k], sn = sin(th), cs = cos(th);
    o->F[k] = tp * tp + sn * sn * pp * pp;
    SET1(o->Fy, 0, k, 2 * sn * cs * pp * pp);
    SET1(o->Fy, 1, k, 0);
    SET1(o->Fp, 0, k, 2 * tp);
    SET1(o->Fp, 1, k, 2 * sn * sn * pp);
    if (o->Fyy) {
      SET2(o->Fyy, 0, 0, k, 2 * cos(2 * th) * pp * pp);
      SET2(o->Fyy, 0, 1, k, 0);
      SET2(o->Fyy, 1, 0, k, 0);
      SET2(o->Fyy, 1, 1, k, 0);
      SET2(o->Fyp, 0, 0, k, 0);
      SET2(o->Fyp, 0, 1, k, 2 * sin(2 * th) * pp);
      SET2(o->Fyp, 1, 0, k, 0);
      SET2(o->Fyp, 1, 1, k, 0);
      SET2(o->Fpp, 0, 0, k, 2);
      SET2(o->Fpp, 0, 1, k, 0);
      SET2(o->Fpp, 1, 0, k, 0);
      SET2(o->Fpp, 1, 1, k, 2 * sn * sn);
    }
  }
  return 0;
}
static inline void sphere_exact(double s, double *th, double *ph) {
  double c = cos(PI * s / 2), sn = sin(PI * s / 2);
  *th = acos(c / 2);
  *ph = atan2(sn, sqrt(3) / 2 * c);
}
#define SPHERE_ACTION 2.4674011002723395

/* Parametric arc length F = sqrt(x'^2 + y'^2) (n = 2): reparametrisation invariant. */
static inline int arclen_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                           cv_partials *o, void *user) {
  (void)x;
  (void)y;
  (void)need;
  (void)user;
  const int n = 2;
  for (int k = 0; k < m; k++) {
    double a = dy[k], b = dy[m + k], s = sqrt(a * a + b * b);
    if (!(s > 0)) return 1;
    o->F[k] = s;
    SET1(o->Fy, 0, k, 0);
    SET1(o->Fy, 1, k, 0);
    SET1(o->Fp, 0, k, a / s);
    SET1(o->Fp, 1, k, b / s);
    if (o->Fyy) {
      double s3 = s * s * s;
      for (int i = 0; i < 2; i++)
        for (int j = 0; j < 2; j++) {
          SET2(o->Fyy, i, j, k, 0);
          SET2(o->Fyp, i, j, k, 0);
        }
      SET2(o->Fpp, 0, 0, k, b * b / s3);
      SET2(o->Fpp, 1, 1, k, a * a / s3);
      SET2(o->Fpp, 0, 1, k, -a * b / s3);
      SET2(o->Fpp, 1, 0, k, -a * b / s3);
    }
  }
  return 0;
}

/* Free end: F = y'^2/2 + y, y(0) = 0, y(1) free; exact y = x^2/2 - x, action -1/6. */
static inline int freeend_F(int m, const double *x, const double *y, const double *dy,
                            unsigned need, cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k] + y[k];
    if (o->Fy) {
      o->Fy[k] = 1;
      o->Fp[k] = dy[k];
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = 0;
      o->Fpp[k] = 1;
    }
  }
  return 0;
}

/* ---- test helpers ---- */
static int n_failed __attribute__((unused)) = 0; /* unused where only the problems are */

#define CHECK(cond, ...)                                                                           \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      n_failed++;                                                                                  \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                                         \
      fprintf(stderr, __VA_ARGS__);                                                                \
      fputc('\n', stderr);                                                                         \
    }                                                                                              \
  } while (0)

/* |actual - expected| <= tol, printing expected, actual and tolerance on failure. */
#define CHECK_NEAR(what, actual, expected, tol)                                                    \
  do {                                                                                             \
    double a_ = (actual), e_ = (expected), t_ = (tol);                                             \
    CHECK(fabs(a_ - e_) <= t_, "%s: expected %.17g, got %.17g (|diff| %.3g > tol %.3g)", what, e_, \
          a_, fabs(a_ - e_), t_);                                                                  \
  } while (0)

/* Max error of a scalar solution against exact(x) over every stride-th node (1: all nodes;
 * p: the element boundaries, where Galerkin superconvergence O(h^2p) holds). */
static inline double max_error_stride(const cv_solver *s, double (*exact)(double), int stride) {
  int nn = cv_solver_get_num_nodes(s);
  double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), err = 0;
  cv_solver_get_nodes(s, x);
  cv_solver_get_values(s, y);
  for (int j = 0; j < nn; j += stride) {
    double e = fabs(y[j] - exact(x[j]));
    if (!(e <= err)) err = e;
  }
  free(x);
  free(y);
  return err;
}

static inline double max_nodal_error(const cv_solver *s, double (*exact)(double)) {
  return max_error_stride(s, exact, 1);
}

#endif
