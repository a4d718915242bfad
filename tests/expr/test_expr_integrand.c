/* tests/expr/test_expr_integrand.c — ex_integrand against hand-written partials: the
 * catenary y*sqrt(1 + y'^2) (n = 1) and th'^2 + sin(th)^2*ph'^2 (n = 2, the sphere's
 * geodesic energy); every `need`, batches above 256 points, symmetric blocks.
 * SPDX-License-Identifier: MIT */
#include "ex_test.h"
#include "expr/ex_integrand.h"

/* Hand formulas and the tape round differently (x*x for ^2, operation order): a few ulps
 * on O(1) values. Tolerance 1e-13 * (1 + |value|). */
#define TOL 1e-13
#define M   300 /* more than one internal batch of 256 */

static ex_id resolve2(ex_dag *d, const char *name, int primes, void *user, char *err,
                      size_t errlen) {
  const char *const *names = user; /* variable, then n unknowns, NULL-terminated */
  int n = 0;
  while (names[1 + n]) n++;
  if (strcmp(name, names[0]) == 0 && !primes) return ex_slot(d, 0);
  for (int i = 0; i < n; i++)
    if (strcmp(name, names[1 + i]) == 0) return ex_slot(d, 1 + i + (primes ? n : 0));
  snprintf(err, errlen, "unknown name '%s'", name);
  return -1;
}

/* Buffers as the core hands them over: NaN-filled, NULL for groups not asked for. */
typedef struct {
  double F[M], Fy[2 * M], Fp[2 * M], Fyy[4 * M], Fyp[4 * M], Fpp[4 * M];
} buffers;

static void prefill(buffers *b, unsigned need, cv_partials *p) {
  double *all = (double *)b;
  for (size_t i = 0; i < sizeof *b / sizeof(double); i++) all[i] = NAN;
  p->F = need & CVAR_NEED_F ? b->F : NULL;
  p->Fy = need & CVAR_NEED_GRAD ? b->Fy : NULL;
  p->Fp = need & CVAR_NEED_GRAD ? b->Fp : NULL;
  p->Fyy = need & CVAR_NEED_HESS ? b->Fyy : NULL;
  p->Fyp = need & CVAR_NEED_HESS ? b->Fyp : NULL;
  p->Fpp = need & CVAR_NEED_HESS ? b->Fpp : NULL;
}

typedef void (*hand_fn)(double x, const double *y, const double *p, double *F, double *Fy,
                        double *Fp, double *Fyy, double *Fyp, double *Fpp);

static void catenary(double x, const double *y, const double *p, double *F, double *Fy, double *Fp,
                     double *Fyy, double *Fyp, double *Fpp) {
  (void)x;
  double s = sqrt(1 + p[0] * p[0]);
  *F = y[0] * s;
  Fy[0] = s;
  Fp[0] = y[0] * p[0] / s;
  Fyy[0] = 0;
  Fyp[0] = p[0] / s;
  Fpp[0] = y[0] / (s * s * s);
}

static void sphere(double x, const double *y, const double *p, double *F, double *Fy, double *Fp,
                   double *Fyy, double *Fyp, double *Fpp) {
  (void)x;
  double th = y[0], s = sin(th), c = cos(th), tp = p[0], pp = p[1];
  *F = tp * tp + s * s * pp * pp;
  Fy[0] = 2 * s * c * pp * pp;
  Fy[1] = 0;
  Fp[0] = 2 * tp;
  Fp[1] = 2 * s * s * pp;
  Fyy[0] = 2 * (c * c - s * s) * pp * pp, Fyy[1] = Fyy[2] = Fyy[3] = 0;
  Fyp[0] = 0, Fyp[1] = 4 * s * c * pp, Fyp[2] = Fyp[3] = 0; /* d2F/dy_i dy'_j, row i */
  Fpp[0] = 2, Fpp[1] = Fpp[2] = 0, Fpp[3] = 2 * s * s;
}

static void check_case(const char *F, const char *const *names, int n, hand_fn hand) {
  static double x[M], y[2 * M], dy[2 * M];
  for (int k = 0; k < M; k++) {
    x[k] = -1 + 2.0 * k / (M - 1);
    for (int i = 0; i < n; i++) {
      y[i * M + k] = 0.5 + urand();
      dy[i * M + k] = -2 + 4 * urand();
    }
  }
  ex_dag *d = ex_dag_new();
  char err[256];
  ex_id f = ex_parse(d, F, resolve2, (void *)names, 0, err, sizeof err);
  CHECK(f >= 0, "%s: %s", F, err);
  ex_integrand *g =
      ex_integrand_new(d, n, f, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, err, sizeof err);
  ex_dag_free(d); /* the compiled integrand needs no DAG */
  CHECK(g != NULL, "%s: %s", F, err);
  if (!g) return;
  static buffers b;
  const unsigned needs[] = {CVAR_NEED_F,
                            CVAR_NEED_F | CVAR_NEED_GRAD,
                            CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS,
                            CVAR_NEED_HESS,
                            CVAR_NEED_GRAD,
                            CVAR_NEED_GRAD | CVAR_NEED_HESS};
  for (size_t t = 0; t < sizeof needs / sizeof needs[0]; t++) {
    unsigned need = needs[t];
    cv_partials p;
    prefill(&b, need, &p);
    int rc = ex_integrand_eval(M, x, y, dy, need, &p, g);
    CHECK(rc == 0, "%s: eval returned %d", F, rc);
    for (int k = 0; k < M; k++) {
      double yk[2], pk[2], hF, hFy[2], hFp[2], hFyy[4], hFyp[4], hFpp[4];
      for (int i = 0; i < n; i++) yk[i] = y[i * M + k], pk[i] = dy[i * M + k];
      hand(x[k], yk, pk, &hF, hFy, hFp, hFyy, hFyp, hFpp);
      char what[128];
#define CMP(name, buf, idx, ref)                                                                   \
  do {                                                                                             \
    snprintf(what, sizeof what, "%s need %u %s[%d] point %d", F, need, name, idx, k);              \
    CHECK_CLOSE(what, (buf)[(size_t)(idx)*M + k], ref, TOL, 1 + fabs(ref));                        \
  } while (0)
      if (need & CVAR_NEED_F) CMP("F", b.F, 0, hF);
      if (need & CVAR_NEED_GRAD)
        for (int i = 0; i < n; i++) {
          CMP("Fy", b.Fy, i, hFy[i]);
          CMP("Fp", b.Fp, i, hFp[i]);
        }
      if (need & CVAR_NEED_HESS)
        for (int i = 0; i < n * n; i++) {
          CMP("Fyy", b.Fyy, i, hFyy[i]);
          CMP("Fyp", b.Fyp, i, hFyp[i]);
          CMP("Fpp", b.Fpp, i, hFpp[i]);
        }
      if (failures > 20) return;
    }
  }
  ex_integrand_free(g);
}

/* A pointwise constraint G(x, y) through the same object: y' partials are exact zeros;
 * built for first derivatives only, it refuses a Hessian request. */
static void check_constraint(void) {
  const char *names[] = {"x", "y", NULL};
  ex_dag *d = ex_dag_new();
  char err[256];
  ex_id G = ex_parse(d, "x^2 + y^2 - 1", resolve2, (void *)names, 0, err, sizeof err);
  ex_integrand *g = ex_integrand_new(d, 1, G, CVAR_NEED_F | CVAR_NEED_GRAD, err, sizeof err);
  CHECK(g && ex_integrand_num_unknowns(g) == 1, "constraint: %s", err);
  double x[3] = {0, 0.5, 1}, y[3] = {1, 2, 3}, dy[3] = {7, 8, 9}, F[3], Fy[3], Fp[3];
  cv_partials p = {F, Fy, Fp, NULL, NULL, NULL};
  CHECK(ex_integrand_eval(3, x, y, dy, CVAR_NEED_F | CVAR_NEED_GRAD, &p, g) == 0, "eval");
  for (int k = 0; k < 3; k++) {
    CHECK_CLOSE("G", F[k], x[k] * x[k] + y[k] * y[k] - 1, 1e-15, 10);
    CHECK_CLOSE("G_y", Fy[k], 2 * y[k], 0, 1);
    CHECK_CLOSE("G_y'", Fp[k], 0, 0, 1);
  }
  double H[3];
  cv_partials ph = {F, Fy, Fp, H, H, H};
  CHECK(ex_integrand_eval(3, x, y, dy, 7u, &ph, g) < 0, "Hessian beyond max_need refused");
  ex_integrand_free(g);
  CHECK(ex_integrand_new(d, 0, G, 1u, err, sizeof err) == NULL && err[0], "n = 0 refused");
  ex_dag_free(d);
}

/* The constraint form (cv_constraint_fn): G = a^2*b + sin(a) - x with n = 2; Gyy is
 * symmetric with both triangles filled. An expression with a y' is refused. */
static void check_constraint_fn(void) {
  const char *names[] = {"x", "a", "b", NULL};
  ex_dag *d = ex_dag_new();
  char err[256];
  ex_id G = ex_parse(d, "a^2*b + sin(a) - x", resolve2, (void *)names, 0, err, sizeof err);
  ex_integrand *g = ex_integrand_new(d, 2, G, 7u, err, sizeof err);
  CHECK(g != NULL, "constraint G: %s", err);
  enum { K = 3 };
  double x[K] = {0.1, 0.2, 0.3}, y[2 * K] = {1, 2, 3, 0.5, 0.25, -1};
  double Gv[K], Gy[2 * K], Gyy[4 * K];
  for (int i = 0; i < 4 * K; i++) Gyy[i] = NAN;
  CHECK(ex_integrand_eval_constraint(K, x, y, 7u, Gv, Gy, Gyy, g) == 0, "constraint eval");
  for (int k = 0; k < K; k++) {
    double a = y[k], b = y[K + k];
    CHECK_CLOSE("G", Gv[k], a * a * b + sin(a) - x[k], 1e-14, 10);
    CHECK_CLOSE("G_a", Gy[k], 2 * a * b + cos(a), 1e-14, 10);
    CHECK_CLOSE("G_b", Gy[K + k], a * a, 1e-14, 10);
    CHECK_CLOSE("G_aa", Gyy[0 * K + k], 2 * b - sin(a), 1e-14, 10);
    CHECK_CLOSE("G_ab", Gyy[1 * K + k], 2 * a, 1e-14, 10);
    CHECK_CLOSE("G_ba", Gyy[2 * K + k], 2 * a, 1e-14, 10);
    CHECK_CLOSE("G_bb", Gyy[3 * K + k], 0, 0, 1);
  }
  ex_integrand_free(g);
  ex_id H = ex_parse(d, "a*b'", resolve2, (void *)names, 0, err, sizeof err);
  g = ex_integrand_new(d, 2, H, 1u, err, sizeof err);
  CHECK(g && ex_integrand_eval_constraint(K, x, y, 1u, Gv, NULL, NULL, g) < 0,
        "a constraint with y' is refused");
  ex_integrand_free(g);
  ex_dag_free(d);
}

int main(void) {
  check_constraint_fn();
  const char *cat[] = {"x", "y", NULL}, *sph[] = {"t", "th", "ph", NULL};
  check_case("y*sqrt(1 + y'^2)", cat, 1, catenary);
  check_case("th'^2 + sin(th)^2*ph'^2", sph, 2, sphere);
  check_constraint();
  return finish("test_expr_integrand");
}
