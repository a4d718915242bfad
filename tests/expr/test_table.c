/* tests/expr/test_table.c — tabulated functions (cv_table, theory TB-1 .. TB-5): the
 * spline reproduces cubics exactly, its partials match finite differences of itself, it
 * converges at h^4 to a smooth function; tables called in cv_problem_set_integrand_expr
 * give rays that converge at h^4 in the grid spacing to the analytic rays of 1-D, 2-D and
 * 3-D media, with Newton's iteration count that of the same medium as a formula; a path
 * outside the grid fails with a message naming the table. SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "expr/expr.h"

static int failures = 0;
#define CHECK(cond, ...)                                                                           \
  do {                                                                                             \
    if (!(cond)) {                                                                                 \
      failures++;                                                                                  \
      fprintf(stderr, "FAIL %s:%d: ", __FILE__, __LINE__);                                         \
      fprintf(stderr, __VA_ARGS__);                                                                \
      fprintf(stderr, "\n");                                                                       \
    }                                                                                              \
  } while (0)

typedef double (*fn3)(const double *u);

/* A table of f on the grid lo[k] + (hi[k] - lo[k]) i / (n - 1), or with stretched (non-
 * uniform) spacing t + 0.15 sin(pi t) of the uniform t when nonuniform. */
static cv_table *sample(int dim, int n, const double *lo, const double *hi, fn3 f, int nonuniform) {
  double *c[3] = {NULL, NULL, NULL};
  int nn[3] = {n, n, n};
  size_t size = 1;
  for (int k = 0; k < dim; k++) {
    c[k] = malloc((size_t)n * sizeof *c[k]);
    for (int i = 0; i < n; i++) {
      double t = (double)i / (n - 1);
      if (nonuniform) t += 0.15 * sin(3.14159265358979323846 * t) * (k % 2 ? -1 : 1);
      c[k][i] = lo[k] + (hi[k] - lo[k]) * t;
    }
    size *= (size_t)n;
  }
  double *v = malloc(size * sizeof *v);
  for (size_t idx = 0; idx < size; idx++) {
    double u[3] = {0, 0, 0};
    size_t r = idx;
    for (int k = dim - 1; k >= 0; k--) {
      u[k] = c[k][r % (size_t)n];
      r /= (size_t)n;
    }
    v[idx] = f(u);
  }
  cv_status why;
  cv_table *t = cv_table_new(dim, nn, (const double *const *)c, v, &why);
  CHECK(t && why == CVAR_OK, "cv_table_new failed (%d)", (int)why);
  for (int k = 0; k < dim; k++) free(c[k]);
  free(v);
  return t;
}

static double cubic3(const double *u) {
  return 1 + u[0] - 2 * u[0] * u[0] * u[0] + u[0] * u[1] * u[1] * u[1] -
         0.5 * u[2] * u[2] * u[2] * u[1] + u[0] * u[0] * u[1] * u[2];
}
/* its exact partials: grad and a few second/third orders */
static double cubic3_d(const double *u, const int *o) {
  double x = u[0], y = u[1], z = u[2];
  int a = o[0], b = o[1], c = o[2];
  if (a == 0 && b == 0 && c == 0) return cubic3(u);
  if (a == 1 && b == 0 && c == 0) return 1 - 6 * x * x + y * y * y + 2 * x * y * z;
  if (a == 0 && b == 1 && c == 0) return 3 * x * y * y - 0.5 * z * z * z + x * x * z;
  if (a == 0 && b == 0 && c == 1) return -1.5 * z * z * y + x * x * y;
  if (a == 2 && b == 0 && c == 0) return -12 * x + 2 * y * z;
  if (a == 1 && b == 1 && c == 0) return 3 * y * y + 2 * x * z;
  if (a == 0 && b == 1 && c == 1) return -1.5 * z * z + x * x;
  if (a == 1 && b == 1 && c == 1) return 2 * x;
  if (a == 3 && b == 0 && c == 0) return -12;
  return NAN;
}

/* The not-a-knot spline reproduces cubics (in each coordinate) exactly, partials included,
 * on uniform and non-uniform grids. */
static void test_cubic_exact(void) {
  double lo[3] = {-1, 0, 0.5}, hi[3] = {1, 2, 1.5};
  const int ords[][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {2, 0, 0},
                         {1, 1, 0}, {0, 1, 1}, {1, 1, 1}, {3, 0, 0}};
  for (int nu = 0; nu < 2; nu++) {
    cv_table *t = sample(3, 6, lo, hi, cubic3, nu);
    double worst = 0;
    for (int s = 0; s < 50; s++) {
      double u[3];
      for (int k = 0; k < 3; k++)
        u[k] = lo[k] + (hi[k] - lo[k]) * fmod(0.6180339887 * (s + 1) * (k + 1.3), 1.0);
      for (size_t j = 0; j < sizeof ords / sizeof ords[0]; j++) {
        double v;
        CHECK(cv_table_eval(t, u, ords[j], &v) == 0, "eval inside the grid failed");
        double e = fabs(v - cubic3_d(u, ords[j])) / (1 + fabs(cubic3_d(u, ords[j])));
        if (e > worst) worst = e;
      }
    }
    printf("cubic reproduced (%s grid): worst relative error %.2e\n",
           nu ? "non-uniform" : "uniform", worst);
    CHECK(worst < 1e-11, "a cubic is not reproduced: %.3g", worst);
    double out[3] = {0.5, 2.5, 1.0}, v;
    CHECK(cv_table_eval(t, out, NULL, &v) == 2 && isnan(v), "outside along axis 2 not reported");
    cv_table_free(t);
  }
}

static double smooth3(const double *u) { return sin(u[0] + 0.5 * u[1]) * exp(0.3 * u[2]); }

/* h^4 convergence of the value, and the partials equal to finite differences of the
 * spline itself (so they are the spline's exact derivatives, not approximations of f's). */
static void test_order_and_partials(void) {
  double lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, err[2];
  for (int l = 0; l < 2; l++) {
    cv_table *t = sample(3, l ? 17 : 9, lo, hi, smooth3, 0);
    err[l] = 0;
    for (int s = 0; s < 200; s++) {
      double u[3], v;
      for (int k = 0; k < 3; k++) u[k] = fmod(0.7548776662 * (s + 1) * (k + 1.1), 1.0);
      cv_table_eval(t, u, NULL, &v);
      if (fabs(v - smooth3(u)) > err[l]) err[l] = fabs(v - smooth3(u));
    }
    if (l == 1) { /* partials of the spline vs central differences of the spline */
      double u[3] = {0.37, 0.52, 0.61}, worst = 0, eps = 1e-5;
      const int ords[][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}, {0, 1, 1}, {1, 0, 1}};
      for (int j = 0; j < 6; j++) {
        int lower[3] = {ords[j][0], ords[j][1], ords[j][2]}, k = 0;
        while (!lower[k]) k++;
        lower[k]--;
        double up[3] = {u[0], u[1], u[2]}, dn[3] = {u[0], u[1], u[2]}, vp, vm, v;
        up[k] += eps, dn[k] -= eps;
        cv_table_eval(t, up, lower, &vp);
        cv_table_eval(t, dn, lower, &vm);
        cv_table_eval(t, u, ords[j], &v);
        double e = fabs(v - (vp - vm) / (2 * eps));
        if (e > worst) worst = e;
      }
      printf("partials vs central differences of the spline: %.2e\n", worst);
      CHECK(worst < 1e-8, "spline partials disagree with its differences: %.3g", worst);
    }
    cv_table_free(t);
  }
  double order = log2(err[0] / err[1]);
  printf("3-D interpolation error: h=1/8 %.3e, h=1/16 %.3e, observed order %.2f\n", err[0], err[1],
         order);
  CHECK(order > 3.6 && order < 4.6, "interpolation order %.2f, expected 4", order);
}

/* ---- rays through tabulated media against analytic rays ---- */

/* 1-D: n(y) = 1/y (the Poincare half-plane); rays are circles centred on the x axis:
 * y = sqrt(4 - x^2) on [-1.2, 1.2], through y from 1.6 to 2. */
static double n1(const double *u) { return 1.0 / u[0]; }
static double ray1(double x, int i) {
  (void)i;
  return sqrt(4 - x * x);
}
/* 2-D: Maxwell's fish-eye n = 2/(1 + x^2 + y^2): rays are circles through antipodal points
 * of the unit circle, here y = -0.5 + sqrt(1.25 - x^2) on [-0.8, 0.8] (not antipodal). */
static double n2(const double *u) { return 2.0 / (1 + u[0] * u[0] + u[1] * u[1]); }
static double ray2(double x, int i) {
  (void)i;
  return -0.5 + sqrt(1.25 - x * x);
}
/* 3-D fish-eye: rays are planar through the origin; the 2-D ray in the plane spanned by
 * e_x and (0, 0.8, 0.6): y = 0.8 Y(x), z = 0.6 Y(x). */
static double n3(const double *u) { return 2.0 / (1 + u[0] * u[0] + u[1] * u[1] + u[2] * u[2]); }
static double ray3(double x, int i) { return (i ? 0.6 : 0.8) * ray2(x, 0); }

typedef struct {
  const char *name;
  int dim, nunk;
  double xa, xb; /* the interval */
  double lo[3], hi[3];
  fn3 f;
  double (*ray)(double x, int i);
  const char *unknowns, *table_F, *formula_F;
} ray_case;

static const ray_case cases[] = {
    {"1-D n(y)",
     1,
     1,
     -1.2,
     1.2,
     {1.5},
     {2.05},
     n1,
     ray1,
     "y",
     "n(y)*sqrt(1 + y'^2)",
     "sqrt(1 + y'^2)/y"},
    {"2-D n(x, y)",
     2,
     1,
     -0.8,
     0.8,
     {-0.8, 0.2},
     {0.8, 0.65},
     n2,
     ray2,
     "y",
     "n(x, y)*sqrt(1 + y'^2)",
     "2/(1 + x^2 + y^2)*sqrt(1 + y'^2)"},
    {"3-D n(x, y, z)",
     3,
     2,
     -0.8,
     0.8,
     {-0.8, 0.2, 0.15},
     {0.8, 0.52, 0.39},
     n3,
     ray3,
     "y, z",
     "n(x, y, z)*sqrt(1 + y'^2 + z'^2)",
     "2/(1 + x^2 + y^2 + z^2)*sqrt(1 + y'^2 + z'^2)"},
};

/* Solve; max nodal error against the analytic ray, iterations. table NULL: the formula. */
static double solve_ray(const ray_case *c, cv_table *t, int *iters, char *msg, size_t len,
                        double shift) {
  cv_status why;
  cv_problem *p = cv_problem_new(c->nunk, c->xa, c->xb, &why);
  cv_solver *s = cv_solver_new(&why);
  char err[300] = "";
  double worst = NAN;
  for (int i = 0; i < c->nunk; i++)
    cv_problem_set_dirichlet(p, i, c->ray(c->xa, i) + shift, c->ray(c->xb, i) + shift);
  if (t) CHECK(cv_problem_add_table(p, "n", t) == CVAR_OK, "cv_problem_add_table failed");
  cv_status st = cv_problem_set_integrand_expr(p, "x", c->unknowns, t ? c->table_F : c->formula_F,
                                               NULL, err, sizeof err);
  CHECK(st == CVAR_OK, "%s: set_integrand_expr: %s", c->name, err);
  cv_solver_set_elements(s, 16);
  cv_solver_set_degree(s, 6);
  cv_solver_set_tolerances(s, 1e-14, 1e-14); /* far below the table's error */
  st = cv_solve(s, p);
  if (msg) snprintf(msg, len, "%s", cv_solver_last_error(s));
  *iters = cv_solver_get_num_iterations(s);
  if (st == CVAR_OK) {
    int nn = cv_solver_get_num_nodes(s);
    double *x = malloc((size_t)nn * sizeof *x), *y = malloc((size_t)nn * c->nunk * sizeof *y);
    cv_solver_get_nodes(s, x);
    cv_solver_get_values(s, y);
    worst = 0;
    for (int j = 0; j < nn; j++)
      for (int i = 0; i < c->nunk; i++) {
        double e = fabs(y[j * c->nunk + i] - c->ray(x[j], i));
        if (e > worst) worst = e;
      }
    free(x);
    free(y);
  }
  cv_solver_free(s);
  cv_problem_free(p);
  return st == CVAR_OK ? worst : -1.0;
}

static void test_rays(void) {
  for (size_t ci = 0; ci < sizeof cases / sizeof cases[0]; ci++) {
    const ray_case *c = &cases[ci];
    int it_formula, it_table;
    double e_formula = solve_ray(c, NULL, &it_formula, NULL, 0, 0.0);
    const int grids[4] = {9, 17, 33, 65}; /* h = range/8 .. range/64 */
    double e[4];
    for (int l = 0; l < 4; l++) {
      cv_table *t = sample(c->dim, grids[l], c->lo, c->hi, c->f, 0);
      e[l] = solve_ray(c, t, &it_table, NULL, 0, 0.0);
      cv_table_free(t); /* the problem held its own reference while it lived */
      CHECK(e[l] >= 0, "%s: grid %d did not converge", c->name, grids[l]);
      if (l == 3)
        CHECK(it_table == it_formula,
              "%s: Newton took %d iterations with the table, %d with "
              "the formula",
              c->name, it_table, it_formula);
    }
    /* Least-squares slope of log e against log h over the four grids: the ray error must
     * fall at least like h^4 (the pointwise error of the spline's order; the ray, an
     * integral of that error, may do better: docs/theory.md TB-6). */
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int l = 0; l < 4; l++) {
      double lx = -l * log(2.0), ly = log(e[l]);
      sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
    }
    double slope = (4 * sxy - sx * sy) / (4 * sxx - sx * sx);
    printf("%s: formula error %.2e (%d it); table error %.3e %.3e %.3e %.3e at h = range/8, "
           "/16, /32, /64; pairwise orders %.2f %.2f %.2f, fitted order %.2f (%d it)\n",
           c->name, e_formula, it_formula, e[0], e[1], e[2], e[3], log2(e[0] / e[1]),
           log2(e[1] / e[2]), log2(e[2] / e[3]), slope, it_table);
    CHECK(e_formula < 1e-10, "%s: the formula's ray is off by %.3g", c->name, e_formula);
    CHECK(slope > 3.7, "%s: fitted order %.2f, expected at least 4", c->name, slope);
    for (int l = 1; l < 4; l++)
      CHECK(e[l] < e[l - 1] / 4, "%s: the error did not fall on grid %d", c->name, grids[l]);
  }
}

/* End values outside the grid: the solve fails (no extrapolation) and says which table. */
static void test_outside(void) {
  const ray_case *c = &cases[1];
  cv_table *t = sample(2, 8, c->lo, c->hi, c->f, 0);
  char msg[700];
  int it;
  /* ends at y = 0.48, inside; the ray's middle would be at 0.82 > 0.65 */
  double e = solve_ray(c, t, &it, msg, sizeof msg, 0.2);
  printf("outside the grid: %s\n", msg);
  CHECK(e < 0, "a solve with its ends outside the grid succeeded");
  CHECK(strstr(msg, "table 'n'") != NULL, "the message does not name the table: %s", msg);
  cv_table_free(t);
}

/* Bad input to the C API. */
static void test_api_errors(void) {
  cv_status why = CVAR_OK;
  double x[4] = {0, 1, 2, 3}, xbad[4] = {0, 2, 1, 3}, v[4] = {1, 2, 3, 4};
  const double *c[1] = {x}, *cbad[1] = {xbad};
  int n4 = 4, n3 = 3;
  CHECK(!cv_table_new(1, &n3, c, v, &why) && why == CVAR_EINVAL, "3 points accepted");
  CHECK(!cv_table_new(1, &n4, cbad, v, &why) && why == CVAR_EINVAL, "unsorted accepted");
  CHECK(!cv_table_new(4, &n4, c, v, &why) && why == CVAR_EINVAL, "dim 4 accepted");
  double vn[4] = {1, NAN, 3, 4};
  CHECK(!cv_table_new(1, &n4, c, vn, &why) && why == CVAR_EINVAL, "NaN value accepted");
  cv_table *t = cv_table_new(1, &n4, c, v, &why);
  CHECK(t != NULL, "a valid table refused");
  cv_problem *p = cv_problem_new(1, 0, 1, &why);
  CHECK(cv_problem_add_table(p, "1a", t) == CVAR_EINVAL, "bad name accepted");
  CHECK(cv_problem_add_table(p, "c", t) == CVAR_OK, "good name refused");
  CHECK(cv_problem_add_table(p, "c", t) == CVAR_EINVAL, "name added twice");
  char err[300];
  CHECK(cv_problem_set_integrand_expr(p, "x", "y", "c(x, y)*y'^2", NULL, err, sizeof err) ==
                CVAR_EINVAL &&
            strstr(err, "takes 1 argument"),
        "wrong argument count: %s", err);
  CHECK(cv_problem_set_integrand_expr(p, "x", "y", "c.2(x)*y'^2", NULL, err, sizeof err) ==
            CVAR_EINVAL,
        "derivative along a missing coordinate accepted");
  CHECK(cv_problem_set_integrand_expr(p, "x", "y", "(1 + c.1(x)^2)*y'^2", NULL, err, sizeof err) ==
            CVAR_OK,
        "a derivative call refused: %s", err);
  cv_table *s = cv_table_new(1, &n4, c, v, &why);
  CHECK(cv_problem_add_table(p, "sin", s) == CVAR_OK, "core refused an identifier");
  CHECK(cv_problem_set_integrand_expr(p, "x", "y", "y'^2", NULL, err, sizeof err) == CVAR_EINVAL &&
            strstr(err, "reserved"),
        "a table named sin: %s", err);
  cv_table_free(s);
  cv_problem_free(p);
  cv_table_free(t);
}

/* Table calls in the DAG: printing parses back to the same node; d/dy of n(x, y) is the
 * node n.2(x, y), of n(x, y^2) is 2*y*n.2(x, y^2); derivative orders above 3 are 0. */
static ex_id xy(ex_dag *d, const char *name, int primes, void *user, char *err, size_t len) {
  (void)user, (void)primes, (void)err, (void)len;
  return strcmp(name, "x") == 0 ? ex_slot(d, 0) : strcmp(name, "y") == 0 ? ex_slot(d, 1) : -1;
}
static void test_dag(void) {
  double lo[2] = {0, 0}, hi[2] = {1, 1};
  cv_table *t = sample(2, 6, lo, hi, n2, 0);
  ex_dag *d = ex_dag_new();
  CHECK(ex_dag_add_table(d, "n", t) == 0, "ex_dag_add_table failed");
  CHECK(ex_dag_add_table(d, "exp", t) < 0, "a table named like a function was accepted");
  cv_table_free(t); /* the DAG keeps its own reference */
  char err[200], buf[400];
  const char *src = "n.12(x, y)*n(y, x) + n.2(x, 2*y)/n.111(0.5, y)";
  ex_id e = ex_parse(d, src, xy, NULL, 0, err, sizeof err);
  CHECK(e >= 0, "parse: %s", err);
  const char *names[2] = {"x", "y"};
  ex_print(d, e, names, buf, sizeof buf);
  ex_id back = ex_parse(d, buf, xy, NULL, 0, err, sizeof err);
  printf("printed: %s\n", buf);
  CHECK(back == e, "'%s' printed as '%s' does not parse back to the same node", src, buf);
  ex_id f = ex_parse(d, "n(x, y^2)", xy, NULL, 0, err, sizeof err);
  ex_id df = ex_diff(d, f, 1);
  ex_id expect = ex_parse(d, "n.2(x, y^2)*(2*y)", xy, NULL, 0, err, sizeof err);
  double sl[2] = {0.3, 0.6}, v1, v2;
  ex_eval(d, df, sl, &v1);
  ex_eval(d, expect, sl, &v2);
  CHECK(fabs(v1 - v2) < 1e-15 * fabs(v2), "d/dy n(x, y^2) = %.17g, expected %.17g", v1, v2);
  ex_id d4 = ex_parse(d, "n.2222(x, y)", xy, NULL, 0, err, sizeof err);
  CHECK(d4 >= 0 && ex_node_op(d, d4) == EX_NUM && ex_node_value(d, d4) == 0,
        "a fourth derivative of the cubic is not 0");
  ex_id c = ex_parse(d, "n(0.5, 0.25)", xy, NULL, 0, err, sizeof err);
  double u[2] = {0.5, 0.25}, tv;
  cv_table_eval(t, u, NULL, &tv); /* t is still alive: the DAG holds it */
  CHECK(c >= 0 && ex_node_op(d, c) == EX_NUM && ex_node_value(d, c) == tv,
        "a call at numbers inside the grid did not fold to the spline's value");
  ex_dag_free(d);
}

int main(void) {
  test_dag();
  test_cubic_exact();
  test_order_and_partials();
  test_rays();
  test_outside();
  test_api_errors();
  if (failures) fprintf(stderr, "%d failure(s)\n", failures);
  return failures ? 1 : 0;
}
