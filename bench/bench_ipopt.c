/* bench/bench_ipopt.c — obstacles (issue 24): calcvar's primal-dual active set iteration
 * against IPOPT's interior-point method on the same discrete problem, in the same run.
 *
 * The problem (examples/scenes/disk_detour.scene): y(x) on [-2, 2], F = sqrt(1 + y'^2),
 * y(-2) = y(2) = 0, the constraint G = x^2 + y^2 - 1 >= 0 (stay outside the unit disk), the
 * guess 1.5 (1 - x^2/4). The shortest path is the tangent from (-2, 0) to the circle, the
 * arc over the top and the mirror tangent: length 2 sqrt(3) + pi/3, contact [-1/2, 1/2].
 *
 * The same discretisation for both: a uniform mesh of E elements of degree p (1 or 2),
 * Gauss-Lobatto-Legendre nodes (for p <= 2 the ends and the midpoint), p + 1 Gauss points
 * per element (calcvar's default rule), the constraint at every node. IPOPT's variables are
 * the interior nodal values Y_1 .. Y_{N-1} (N = pE), its objective is calcvar's discrete
 * action S_h(Y) = sum_e sum_q w_q (h/2) F(y'_h(x_q)), written out here by hand with its
 * exact gradient and exact (banded) Hessian, and its constraints are g_j = x_j^2 + Y_j^2 - 1
 * >= 0 at the interior nodes (exact diagonal Jacobian 2 Y_j, Hessian of the Lagrangian
 * obj_factor * hess(S_h) + diag(2 lambda_j)). At p = 1 the slope y'_h = (Y_{e+1} - Y_e)/h is
 * constant on each element and F depends on y' only, so the Gauss rule is exact and
 * S_h(Y) = sum_e h sqrt(1 + ((Y_{e+1} - Y_e)/h)^2) — exactly calcvar's discrete action,
 * with a tridiagonal Hessian. At p = 2 the rule is the 3-point Gauss rule calcvar uses, not
 * exact for this F, and the Hessian has bandwidth 2. calcvar imposes G at the nodes with
 * lumped weights (KKT rows m_j lambda_j grad G); the weights scale its multipliers, not the
 * feasible set, so both solve the same finite-dimensional problem: the bench prints the
 * largest difference between their two discrete paths.
 *
 * calcvar: the problem made through the public C API from the formulas
 * (cv_problem_set_integrand_expr, cv_problem_add_constraint_expr,
 * cv_problem_set_constraint_sense +1), cv_solver_set_elements/degree, default tolerances
 * (rtol = atol = 1e-10 on the Newton step), cv_solve. IPOPT: C interface
 * (IpStdCInterface.h), tol = 1e-10, mu_strategy = adaptive, exact Hessian (the default
 * hessian_approximation), print_level 0, sb = yes; all other options at their defaults
 * (Debian's build has MUMPS as its linear solver). The clock covers, for each, building
 * the problem and solving it (for calcvar: problem, solver, cv_solve; for IPOPT: the
 * starting point, CreateIpoptProblem, options, IpoptSolve); the median of 3 runs.
 * A third row per mesh runs IPOPT again with obj_scaling_factor = 1/h (see run_ipopt_h):
 * with the defaults IPOPT's absolute complementarity test leaves the path on the contact
 * wrong by about tol/h, because the nodal multipliers are O(h).
 *
 * Columns: time (ms), iterations (calcvar: cv_solver_get_num_iterations, all its stages;
 * IPOPT: the last iter_count its intermediate callback saw), |length - exact|, the largest
 * nodal error against the exact path, the time over calcvar's, and the largest nodal
 * difference from calcvar's discrete path.
 *
 * Usage: bench_ipopt [--degree P] [--check] [E ...]
 *   default: E = 1000 10000 100000 at degrees 1 and 2 (only the given degree with --degree).
 *   --check: a correctness check, not a timing (the meson test ipopt_disk, E = 100): one
 *   run per solver; exit 1 unless both converge to the exact length within 1e-4, and the
 *   two discrete paths agree (and calcvar's action equals this file's S_h at its path).
 *
 * IPOPT is EPL-2.0 and only this bench links it (docs/dependencies.md).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <IpStdCInterface.h>
#include <IpoptConfig.h>

#include "calcvar.h"

#define A (-2.0)
#define B 2.0
/* A bound on one IPOPT solve (its option max_cpu_time), so that the bench ends. */
#define IPOPT_MAX_CPU 60.0
#define GUESS(x)      (1.5 * (1.0 - (x) * (x) / 4.0))

static double exact_length(void) { return 2.0 * sqrt(3.0) + acos(-1.0) / 3.0; }

static double exact_path(double x) {
  if (x < -0.5) return (x + 2.0) / sqrt(3.0);
  if (x > 0.5) return (2.0 - x) / sqrt(3.0);
  return sqrt(fmax(0.0, 1.0 - x * x));
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---- The discrete action S_h of degree p (1 or 2) on E uniform elements ---- */

typedef struct {
  int E, p, N;     /* elements, degree, N = pE: nodes 0 .. N, unknowns 1 .. N-1 */
  double h;        /* element length */
  int nq;          /* Gauss points per element, p + 1 */
  double dl[3][3]; /* dl[q][k] = L_k'(xi_q) on the reference element [-1, 1] */
  double w[3];     /* Gauss weights on [-1, 1] */
  double *Y;       /* workspace: all N + 1 nodal values (ends 0) */
  int iters;       /* IPOPT: the last iteration count seen by the intermediate callback */
} disc;

static void disc_init(disc *d, int E, int p) {
  d->E = E;
  d->p = p;
  d->N = p * E;
  d->h = (B - A) / E;
  d->nq = p + 1;
  if (p == 1) {
    /* Nodes -1, 1: L_0' = -1/2, L_1' = 1/2 at both Gauss points +-1/sqrt(3) (weights 1). */
    for (int q = 0; q < 2; q++) {
      d->w[q] = 1.0;
      d->dl[q][0] = -0.5;
      d->dl[q][1] = 0.5;
    }
  } else {
    /* Nodes -1, 0, 1: L_0' = xi - 1/2, L_1' = -2 xi, L_2' = xi + 1/2; 3-point Gauss. */
    const double g = sqrt(0.6);
    double xi[3] = {-g, 0.0, g}, w[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
    for (int q = 0; q < 3; q++) {
      d->w[q] = w[q];
      d->dl[q][0] = xi[q] - 0.5;
      d->dl[q][1] = -2.0 * xi[q];
      d->dl[q][2] = xi[q] + 0.5;
    }
  }
  d->Y = calloc((size_t)d->N + 1, sizeof *d->Y);
  d->iters = 0;
}

static double node_x(const disc *d, int j) { return A + (B - A) * (double)j / (double)d->N; }

/* All nodal values from the n = N - 1 unknowns (the ends are 0). */
static void disc_fill(disc *d, const double *v) {
  d->Y[0] = 0.0;
  d->Y[d->N] = 0.0;
  memcpy(d->Y + 1, v, (size_t)(d->N - 1) * sizeof *v);
}

/* y'_h at Gauss point q of element e: (2/h) sum_k Y_{pe+k} L_k'(xi_q). */
static double slope(const disc *d, int e, int q) {
  double s = 0.0;
  for (int k = 0; k <= d->p; k++) s += d->Y[d->p * e + k] * d->dl[q][k];
  return 2.0 * s / d->h;
}

static double action(const disc *d) {
  double S = 0.0;
  for (int e = 0; e < d->E; e++)
    for (int q = 0; q < d->nq; q++) {
      double s = slope(d, e, q);
      S += d->w[q] * 0.5 * d->h * sqrt(1.0 + s * s);
    }
  return S;
}

/* ---- IPOPT's callbacks ---- */

static Bool ip_f(Index n, Number *x, Bool new_x, Number *obj, UserDataPtr u) {
  (void)n;
  (void)new_x;
  disc *d = u;
  disc_fill(d, x);
  *obj = action(d);
  return TRUE;
}

/* dS/dY_i = sum_q w_q (h/2) F'(s_q) (2/h) L_k'(xi_q) = sum_q w_q F'(s_q) L_k'(xi_q). */
static Bool ip_grad(Index n, Number *x, Bool new_x, Number *grad, UserDataPtr u) {
  (void)new_x;
  disc *d = u;
  disc_fill(d, x);
  memset(grad, 0, (size_t)n * sizeof *grad);
  for (int e = 0; e < d->E; e++)
    for (int q = 0; q < d->nq; q++) {
      double s = slope(d, e, q), t = d->w[q] * s / sqrt(1.0 + s * s);
      for (int k = 0; k <= d->p; k++) {
        int j = d->p * e + k;
        if (j > 0 && j < d->N) grad[j - 1] += t * d->dl[q][k];
      }
    }
  return TRUE;
}

static Bool ip_g(Index n, Number *x, Bool new_x, Index m, Number *g, UserDataPtr u) {
  (void)n;
  (void)new_x;
  disc *d = u;
  for (Index j = 0; j < m; j++) {
    double xj = node_x(d, j + 1);
    g[j] = xj * xj + x[j] * x[j] - 1.0;
  }
  return TRUE;
}

static Bool ip_jac(Index n, Number *x, Bool new_x, Index m, Index nele, Index *iRow, Index *jCol,
                   Number *values, UserDataPtr u) {
  (void)n;
  (void)new_x;
  (void)nele;
  (void)u;
  if (!values) {
    for (Index j = 0; j < m; j++) iRow[j] = jCol[j] = j;
  } else {
    for (Index j = 0; j < m; j++) values[j] = 2.0 * x[j];
  }
  return TRUE;
}

/* The lower triangle of the band |i - j| <= p, row by row: (i, i-p), ..., (i, i). At p = 2
 * the entry (i, i-2) is zero where i is an element's midpoint; it is kept in the pattern
 * (its value 0), which costs IPOPT nothing worth measuring. */
static Index band_count(const disc *d, int n) {
  Index c = 0;
  for (int i = 0; i < n; i++) c += (Index)(i < d->p ? i + 1 : d->p + 1);
  return c;
}

/* d2S/dY_k dY_l = sum_q w_q (2/h) F''(s_q) L_k' L_l', F'' = (1 + s^2)^(-3/2). */
static Bool ip_hess(Index n, Number *x, Bool new_x, Number obj_factor, Index m, Number *lambda,
                    Bool new_lambda, Index nele, Index *iRow, Index *jCol, Number *values,
                    UserDataPtr u) {
  (void)new_x;
  (void)new_lambda;
  (void)m;
  disc *d = u;
  int p = d->p;
  if (!values) {
    Index c = 0;
    for (int i = 0; i < n; i++)
      for (int j = i - p; j <= i; j++)
        if (j >= 0) {
          iRow[c] = i;
          jCol[c] = j;
          c++;
        }
    return c == nele;
  }
  /* values[] in the pattern's order: row i starts at off(i), entry (i, j) at
   * off(i) + j - max(0, i - p). */
  memset(values, 0, (size_t)nele * sizeof *values);
  disc_fill(d, x);
#define OFF(i)                                                                                     \
  ((i) < p ? (Index)((i) * ((i) + 1) / 2) : (Index)(p * (p + 1) / 2 + ((i)-p) * (p + 1)))
  for (int e = 0; e < d->E; e++)
    for (int q = 0; q < d->nq; q++) {
      double s = slope(d, e, q), r = 1.0 + s * s;
      double c = obj_factor * d->w[q] * (2.0 / d->h) / (r * sqrt(r));
      for (int k = 0; k <= p; k++) {
        int gk = p * e + k;
        if (gk <= 0 || gk >= d->N) continue;
        for (int l = 0; l <= k; l++) {
          int gl = p * e + l;
          if (gl <= 0 || gl >= d->N) continue;
          int i = gk - 1, j = gl - 1, lo = i - p > 0 ? i - p : 0;
          values[OFF(i) + (j - lo)] += c * d->dl[q][k] * d->dl[q][l];
        }
      }
    }
  for (int i = 0; i < n; i++) values[OFF(i) + (i - (i - p > 0 ? i - p : 0))] += 2.0 * lambda[i];
#undef OFF
  return TRUE;
}

static Bool ip_iter(Index alg_mod, Index iter_count, Number obj_value, Number inf_pr, Number inf_du,
                    Number mu, Number d_norm, Number regularization_size, Number alpha_du,
                    Number alpha_pr, Index ls_trials, UserDataPtr u) {
  (void)alg_mod;
  (void)obj_value;
  (void)inf_pr;
  (void)inf_du;
  (void)mu;
  (void)d_norm;
  (void)regularization_size;
  (void)alpha_du;
  (void)alpha_pr;
  (void)ls_trials;
  ((disc *)u)->iters = iter_count;
  return TRUE;
}

/* One IPOPT solve; the path's N + 1 nodal values into Yout. Returns IPOPT's status. */
typedef struct {
  double t, length;
  int iters, status, runs;
} run_result;

static run_result run_ipopt_scaled(int E, int p, double obj_scaling, double *Yout) {
  run_result r = {0};
  double t0 = now();
  disc d;
  disc_init(&d, E, p);
  int n = d.N - 1, m = n;
  double *xL = malloc((size_t)n * sizeof *xL), *xU = malloc((size_t)n * sizeof *xU);
  double *gL = malloc((size_t)m * sizeof *gL), *gU = malloc((size_t)m * sizeof *gU);
  double *v = malloc((size_t)n * sizeof *v);
  for (int i = 0; i < n; i++) {
    xL[i] = -2e19; /* no bounds on the variables (nlp_lower_bound_inf = -1e19) */
    xU[i] = 2e19;
    gL[i] = 0.0; /* g_j >= 0 */
    gU[i] = 2e19;
    v[i] = GUESS(node_x(&d, i + 1));
  }
  IpoptProblem ip = CreateIpoptProblem(n, xL, xU, m, gL, gU, m, band_count(&d, n), 0, ip_f, ip_g,
                                       ip_grad, ip_jac, ip_hess);
  AddIpoptNumOption(ip, "tol", 1e-10);
  AddIpoptStrOption(ip, "mu_strategy", "adaptive");
  const char *pl = getenv("BENCH_IPOPT_PRINT_LEVEL"); /* diagnosis: IPOPT's own log */
  AddIpoptIntOption(ip, "print_level", pl ? atoi(pl) : 0);
  AddIpoptNumOption(ip, "max_cpu_time", IPOPT_MAX_CPU);
  AddIpoptStrOption(ip, "sb", "yes");
  if (obj_scaling != 1.0) AddIpoptNumOption(ip, "obj_scaling_factor", obj_scaling);
  SetIntermediateCallback(ip, ip_iter);
  double obj = 0.0;
  r.status = IpoptSolve(ip, v, NULL, &obj, NULL, NULL, NULL, &d);
  r.t = now() - t0;
  r.iters = d.iters;
  /* S_h at the point IPOPT returns (its last iterate when it stopped early; obj is then
   * not set). */
  disc_fill(&d, v);
  r.length = action(&d);
  (void)obj;
  FreeIpoptProblem(ip);
  if (Yout) {
    Yout[0] = Yout[d.N] = 0.0;
    memcpy(Yout + 1, v, (size_t)n * sizeof *v);
  }
  free(xL);
  free(xU);
  free(gL);
  free(gU);
  free(v);
  free(d.Y);
  return r;
}

static run_result run_ipopt(int E, int p, double *Yout) {
  return run_ipopt_scaled(E, p, 1.0, Yout);
}

/* The variant: IPOPT's objective scaled by 1/h = E/(b - a) (option obj_scaling_factor).
 * S_h is O(1) but its gradient entries, and so the multipliers of the nodal constraints,
 * are O(h); IPOPT's complementarity test lambda_j g_j <= tol is absolute, so with
 * multipliers O(h) it leaves g_j (and the path on the contact) wrong by O(tol / h).
 * Scaling the objective by 1/h makes the multipliers O(1). */
static run_result run_ipopt_h(int E, int p, double *Yout) {
  return run_ipopt_scaled(E, p, (double)E / (B - A), Yout);
}

/* IPOPT's ApplicationReturnStatus (IpReturnCodes_inc.h) other than Solve_Succeeded. */
static const char *ipopt_status_name(int st) {
  switch (st) {
  case Solved_To_Acceptable_Level: return "  Solved_To_Acceptable_Level";
  case Search_Direction_Becomes_Too_Small: return "  Search_Direction_Becomes_Too_Small";
  case Maximum_Iterations_Exceeded: return "  Maximum_Iterations_Exceeded";
  case Maximum_CpuTime_Exceeded: return "  Maximum_CpuTime_Exceeded (60 s)";
  case Restoration_Failed: return "  Restoration_Failed";
  default: return "  IPOPT failed";
  }
}

static int guess_fn(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = GUESS(x[k]);
  return 0;
}

/* One calcvar solve through the public C API; nodal values into Yout (N + 1 of them). */
static run_result run_calcvar(int E, int p, double *Yout) {
  run_result r = {0};
  char err[512] = "";
  double t0 = now();
  cv_status why = CVAR_OK;
  cv_problem *pb = cv_problem_new(1, A, B, &why);
  cv_solver *s = NULL;
  int k = -1;
  r.status = -1;
  if (!pb || cv_problem_set_integrand_expr(pb, "x", "y", "sqrt(1 + y'^2)", NULL, err, sizeof err) ||
      cv_problem_set_dirichlet(pb, 0, 0.0, 0.0) ||
      cv_problem_add_constraint_expr(pb, "x", "y", "x^2 + y^2 - 1", NULL, &k, err, sizeof err) ||
      cv_problem_set_constraint_sense(pb, k, +1) || cv_problem_set_guess(pb, guess_fn, NULL) ||
      !(s = cv_solver_new(&why)) || cv_solver_set_elements(s, E) || cv_solver_set_degree(s, p)) {
    fprintf(stderr, "bench_ipopt: calcvar setup failed: %s\n", err);
    cv_solver_free(s);
    cv_problem_free(pb);
    return r;
  }
  r.status = cv_solve(s, pb);
  r.t = now() - t0;
  if (r.status != CVAR_OK) fprintf(stderr, "bench_ipopt: calcvar: %s\n", cv_solver_last_error(s));
  r.iters = cv_solver_get_num_iterations(s);
  r.length = cv_solver_get_action(s);
  if (Yout && cv_solver_get_num_nodes(s) == p * E + 1) cv_solver_get_values(s, Yout);
  cv_solver_free(s);
  cv_problem_free(pb);
  return r;
}

static double max_nodal_error(int E, int p, const double *Y) {
  double e = 0.0;
  for (int j = 0; j <= p * E; j++) {
    double x = A + (B - A) * (double)j / (double)(p * E);
    e = fmax(e, fabs(Y[j] - exact_path(x)));
  }
  return e;
}

static int cmp_run(const void *a, const void *b) {
  double x = ((const run_result *)a)->t, y = ((const run_result *)b)->t;
  return (x > y) - (x < y);
}

/* The median of reps runs; a run longer than 20 s is not repeated (the row says "1 run"). */
static run_result median3(run_result (*f)(int, int, double *), int E, int p, double *Y, int reps) {
  run_result r[3];
  r[0] = f(E, p, Y);
  r[0].runs = 1;
  if (reps == 1 || r[0].t > 20.0) return r[0];
  for (int i = 1; i < 3; i++) r[i] = f(E, p, NULL);
  qsort(r, 3, sizeof *r, cmp_run);
  r[1].runs = 3;
  return r[1];
}

int main(int argc, char **argv) {
  int check = 0, only = 0, nE = 0, Es[16];
  for (int i = 1; i < argc; i++) {
    if (!strcmp(argv[i], "--check")) {
      check = 1;
    } else if (!strcmp(argv[i], "--degree") && i + 1 < argc) {
      only = atoi(argv[++i]);
    } else if (nE < 16 && atoi(argv[i]) >= 2) {
      Es[nE++] = atoi(argv[i]);
    } else {
      fprintf(stderr, "usage: bench_ipopt [--degree 1|2] [--check] [E ...]\n");
      return 2;
    }
  }
  if (only != 0 && only != 1 && only != 2) {
    fprintf(stderr, "bench_ipopt: --degree must be 1 or 2\n");
    return 2;
  }
  if (nE == 0) {
    Es[nE++] = 1000;
    Es[nE++] = 10000;
    Es[nE++] = 100000;
  }
  setvbuf(stdout, NULL, _IOLBF, 0); /* rows appear as they are measured */
  int reps = check ? 1 : 3, bad = 0;
  double L = exact_length();
  printf("disk detour: exact length %.14f; %s\n", L,
         check ? "check run (one run each)" : "times: median of 3 runs");
  printf("IPOPT %s: tol 1e-10, mu_strategy adaptive, exact Hessian, MUMPS; calcvar: Newton,"
         " active set, rtol = atol = 1e-10\n",
         IPOPT_VERSION);
  printf("%2s %7s  %-14s %10s %5s %9s %9s %8s %10s\n", "p", "E", "solver", "ms", "iter", "len err",
         "nodal err", "t/calcvar", "|Y - Ycv|");
  static const char *names[3] = {"calcvar", "IPOPT", "IPOPT obj/h"};
  run_result (*fns[3])(int, int, double *) = {run_calcvar, run_ipopt, run_ipopt_h};
  for (int deg = 1; deg <= 2; deg++) {
    if (only && deg != only) continue;
    for (int i = 0; i < nE; i++) {
      int E = Es[i], N = deg * E;
      double *Y[3];
      run_result r[3];
      for (int k = 0; k < 3; k++) {
        Y[k] = calloc((size_t)N + 1, sizeof *Y[k]);
        r[k] = median3(fns[k], E, deg, Y[k], reps);
        double diff = 0.0;
        for (int j = 0; j <= N; j++) diff = fmax(diff, fabs(Y[k][j] - Y[0][j]));
        int ok = k == 0 ? r[k].status == CVAR_OK : r[k].status == Solve_Succeeded;
        double el = fabs(r[k].length - L);
        printf("%2d %7d  %-14s %10.2f %5d %9.1e %9.1e %8.2f %10.1e%s%s\n", deg, E, names[k],
               1e3 * r[k].t, r[k].iters, el, max_nodal_error(E, deg, Y[k]), r[k].t / r[0].t, diff,
               ok ? "" : (k == 0 ? "  not converged" : ipopt_status_name(r[k].status)),
               r[k].runs == 1 && reps > 1 ? "  (1 run)" : "");
        if (check && k < 2 && (!ok || el > 1e-4)) bad |= 1 << k;
        if (check && k > 0 && diff > 1e-6) bad |= 4;
      }
      if (check) {
        /* calcvar's own action at its path against this file's S_h at the same path. */
        disc d;
        disc_init(&d, E, deg);
        memcpy(d.Y, Y[0], ((size_t)N + 1) * sizeof *Y[0]);
        double same = fabs(action(&d) - r[0].length);
        free(d.Y);
        printf("   check: |S_h(Ycv) here - calcvar's action| = %.1e\n", same);
        if (same > 1e-12 * L) bad |= 4;
      }
      for (int k = 0; k < 3; k++) free(Y[k]);
    }
  }
  if (bad)
    fprintf(stderr, "bench_ipopt: check failed:%s%s%s\n", bad & 1 ? " calcvar" : "",
            bad & 2 ? " IPOPT" : "", bad & 4 ? " (the two discretisations differ)" : "");
  return bad ? 1 : 0;
}
