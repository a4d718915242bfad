/* tests/core/test_hp.c — per-element degrees (theory HP-1), the error estimate (HP-2,
 * HP-3) and the --tol rounds (HP-4 .. HP-6) through the public C API, against exact
 * answers.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "refproblems.h"

/* y'^2/2 - w^2 y^2/2, w = 2 pi, on [0, 1.7], y = 0, 1: exact sin(w x) / sin(1.7 w), a
 * saddle of Morse index 3 (conjugate points at 0.5, 1, 1.5; none is a node below). */
static const double W = 2 * PI, L_OSC = 1.7;
static int osc_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                 cv_partials *o, void *user) {
  (void)x, (void)need, (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k] - 0.5 * W * W * y[k] * y[k];
    if (o->Fy) o->Fy[k] = -W * W * y[k], o->Fp[k] = dy[k];
    if (o->Fyy) o->Fyy[k] = -W * W, o->Fyp[k] = 0, o->Fpp[k] = 1;
  }
  return 0;
}
static double osc_exact(double x) { return sin(W * x) / sin(W * L_OSC); }

static cv_problem *catenary(void) {
  cv_problem *p = cv_problem_new(1, -1, 1, NULL);
  cv_problem_set_integrand(p, catenary_F, NULL);
  cv_problem_set_dirichlet(p, 0, catenary_exact(-1), catenary_exact(1));
  return p;
}

static cv_problem *oscillator(void) {
  cv_problem *p = cv_problem_new(1, 0, L_OSC, NULL);
  cv_problem_set_integrand(p, osc_F, NULL);
  cv_problem_set_dirichlet(p, 0, 0, 1);
  return p;
}

/* 1. Degrees all equal through set_mesh_hp: the same discretisation as set_degree. */
static void same_as_uniform(void) {
  cv_problem *p = catenary();
  cv_solver *a = cv_solver_new(NULL), *b = cv_solver_new(NULL);
  double t[7];
  int deg[6];
  for (int i = 0; i <= 6; i++) t[i] = i / 6.0;
  for (int e = 0; e < 6; e++) deg[e] = 4;
  cv_solver_set_mesh(a, 6, t);
  cv_solver_set_degree(a, 4);
  cv_solver_set_mesh_hp(b, 6, t, deg);
  CHECK(cv_solve(a, p) == CVAR_OK && cv_solve(b, p) == CVAR_OK, "uniform solves");
  int N = cv_solver_get_num_nodes(a);
  CHECK(N == 25 && cv_solver_get_num_nodes(b) == 25, "nodes %d", N);
  double ya[25], yb[25];
  cv_solver_get_values(a, ya);
  cv_solver_get_values(b, yb);
  double d = 0;
  for (int j = 0; j < 25; j++) d = fmax(d, fabs(ya[j] - yb[j]));
  CHECK_NEAR("hp with equal degrees vs uniform", d, 0, 1e-14);
  CHECK_NEAR("action", cv_solver_get_action(b), cv_solver_get_action(a), 1e-14);
  cv_solver_free(a);
  cv_solver_free(b);
  cv_problem_free(p);
}

/* 2. Degrees 1..8 on 8 elements: node layout, getters, and convergence when every element
 * is halved (the degree-1 element limits it to order 2 at the nodes: error / >= 3). */
static double mixed_error(int halvings, cv_solver **keep) {
  cv_problem *p = catenary();
  cv_solver *s = cv_solver_new(NULL);
  int E = 8 << halvings, deg[64];
  double t[65];
  for (int e = 0; e < E; e++) deg[e] = 1 + (e >> halvings);
  for (int i = 0; i <= E; i++) t[i] = (double)i / E;
  cv_solver_set_mesh_hp(s, E, t, deg);
  cv_status st = cv_solve(s, p);
  CHECK(st == CVAR_OK, "mixed degrees: %s", cv_solver_last_error(s));
  double err = max_nodal_error(s, catenary_exact);
  cv_problem_free(p);
  if (keep)
    *keep = s;
  else
    cv_solver_free(s);
  return err;
}

static void mixed_degrees(void) {
  cv_solver *s;
  double e0 = mixed_error(0, &s), e1 = mixed_error(1, NULL), e2 = mixed_error(2, NULL);
  int deg[8] = {0};
  CHECK(cv_solver_get_num_nodes(s) == 37, "nodes %d, expected 1 + 36", cv_solver_get_num_nodes(s));
  CHECK(cv_solver_get_degrees(s, deg) == 8, "element count");
  for (int e = 0; e < 8; e++) CHECK(deg[e] == e + 1, "degree of element %d: %d", e, deg[e]);
  CHECK(cv_solver_get_degree(s) == 8, "largest degree %d", cv_solver_get_degree(s));
  double x[37];
  cv_solver_get_nodes(s, x);
  /* element 1 (degree 2) is [-0.75, -0.5]: nodes 1, 2, 3 = -0.75, its midpoint, -0.5 */
  CHECK_NEAR("node 1", x[1], -0.75, 1e-15);
  CHECK_NEAR("node 2 (midpoint)", x[2], -0.625, 1e-15);
  CHECK_NEAR("node 3", x[3], -0.5, 1e-15);
  printf("mixed degrees 1..8: max nodal error %.3e, %.3e, %.3e (halved twice)\n", e0, e1, e2);
  CHECK(e1 <= e0 / 3 && e2 <= e1 / 3, "order below 2: %.3g %.3g %.3g", e0, e1, e2);
  /* the estimate is honest on this mesh */
  cv_problem *p = catenary();
  double est, ev;
  char msg[256];
  CHECK(cv_solver_estimate_error(s, p, &est, &ev, msg, sizeof msg) == CVAR_OK, "%s", msg);
  CHECK(est >= 0.1 * e0 && est <= 10 * e0, "estimate %.3g vs true %.3g", est, e0);
  cv_problem_free(p);
  cv_solver_free(s);
}

/* 3. Morse index on mixed degrees, and an estimate that is no bound (HP-3). */
static void morse_and_no_bound(void) {
  cv_problem *p = oscillator();
  cv_solver *s = cv_solver_new(NULL);
  double t[9];
  int deg[8] = {8, 8, 7, 6, 5, 6, 7, 8};
  for (int i = 0; i <= 8; i++) t[i] = i / 8.0;
  cv_solver_set_mesh_hp(s, 8, t, deg);
  CHECK(cv_solve(s, p) == CVAR_OK, "oscillator: %s", cv_solver_last_error(s));
  CHECK(cv_solver_get_morse_index(s) == 3, "Morse index %d, expected 3",
        cv_solver_get_morse_index(s));
  double err = max_nodal_error(s, osc_exact), est, ev;
  char msg[320] = "";
  CHECK(cv_solver_estimate_error(s, p, &est, &ev, msg, sizeof msg) == CVAR_OK, "%s", msg);
  CHECK(est >= 0.1 * err && est <= 10 * err + 1e-13, "estimate %.3g vs true %.3g", est, err);
  /* two linear elements: one unknown, Morse index 1; the enriched solve has another */
  cv_solver_set_elements(s, 2);
  cv_solver_set_degree(s, 1);
  CHECK(cv_solve(s, p) == CVAR_OK, "coarse oscillator");
  cv_status st = cv_solver_estimate_error(s, p, &est, &ev, msg, sizeof msg);
  CHECK(st != CVAR_OK && isnan(est), "coarse oscillator: estimate %.3g given", est);
  CHECK(strstr(msg, "another stationary path") != NULL, "message: %s", msg);
  cv_solver_free(s);
  cv_problem_free(p);
}

/* 4. The rounds: --tol 1e-10 on the catenary and the oscillator; 1e-17 ends at the floor;
 * the caller's mesh settings are back afterwards. */
static void tol_rounds(void) {
  cv_problem *p = catenary(), *q = oscillator();
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, 10);
  cv_solver_set_degree(s, 2);
  cv_solver_set_tol(s, 1e-10, 100000);
  for (int k = 0; k < 2; k++) {
    cv_problem *pr = k ? q : p;
    double (*ex)(double) = k ? osc_exact : catenary_exact;
    CHECK(cv_solve(s, pr) == CVAR_OK, "--tol 1e-10: %s", cv_solver_last_error(s));
    double est = cv_solver_get_error_estimate(s), err = max_nodal_error(s, ex);
    int E = cv_solver_get_degrees(s, NULL), deg[4096], sum = 0, dmax = 0;
    CHECK(E > 0 && E <= 4096, "elements %d", E);
    cv_solver_get_degrees(s, deg);
    for (int e = 0; e < E; e++) sum += deg[e], dmax = deg[e] > dmax ? deg[e] : dmax;
    printf("--tol 1e-10 (%s): %d elements, %d nodes, estimate %.2e, true %.2e\n",
           k ? "oscillator" : "catenary", E, cv_solver_get_num_nodes(s), est, err);
    CHECK(cv_solver_get_num_nodes(s) == 1 + sum, "nodes %d, 1 + sum %d", cv_solver_get_num_nodes(s),
          1 + sum);
    CHECK(cv_solver_get_degree(s) == dmax, "degree %d, largest %d", cv_solver_get_degree(s), dmax);
    CHECK(est <= 1e-10, "estimate %.3g", est);
    CHECK(err <= 1e-9, "true error %.3g", err);
    CHECK(est >= 0.1 * err, "estimate %.3g vs true %.3g", est, err);
  }
  CHECK(cv_solver_get_morse_index(s) == 3, "oscillator under --tol: Morse %d",
        cv_solver_get_morse_index(s));
  cv_solver_set_tol(s, 1e-17, 100000);
  CHECK(cv_solve(s, p) == CVAR_EMAXITER, "1e-17 must not converge");
  CHECK(strstr(cv_solver_last_error(s), "round-off floor") != NULL, "message: %s",
        cv_solver_last_error(s));
  CHECK(isfinite(cv_solver_get_error_estimate(s)), "1e-17: estimate reached is reported");
  cv_solver_set_tol(s, 0, 100000);
  CHECK(cv_solve(s, p) == CVAR_OK, "plain solve after --tol");
  CHECK(cv_solver_get_num_elements(s) == 10 && cv_solver_get_num_nodes(s) == 21,
        "caller's mesh back: %d elements, %d nodes", cv_solver_get_num_elements(s),
        cv_solver_get_num_nodes(s));
  cv_solver_free(s);
  cv_problem_free(p);
  cv_problem_free(q);
}

/* 5. HP-1's degree-8 start and HP-6's time cap. A uniform start of degree 2 on the catenary
 * (no singular end) becomes the same nodes at degree 8, which reach 1e-12 in one round.
 * A cap of 1 ns ends the oscillator's rounds after the first: max_iterations, a sentence
 * naming the cap, the estimate reached (finite, above the target), which is said. */
static void start_and_time_cap(void) {
  cv_problem *p = catenary(), *q = oscillator();
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_elements(s, 10);
  cv_solver_set_degree(s, 2);
  cv_solver_set_tol(s, 1e-12, 100000);
  CHECK(cv_solve(s, p) == CVAR_OK, "catenary 1e-12: %s", cv_solver_last_error(s));
  int deg[64], E = cv_solver_get_degrees(s, NULL);
  CHECK(E > 0 && E <= 64, "elements %d", E);
  cv_solver_get_degrees(s, deg);
  int all8 = 1;
  for (int e = 0; e < E && e < 64; e++) all8 &= deg[e] == 8;
  CHECK(cv_solver_get_adapt_rounds(s) == 1 && all8 && E == 3,
        "degree-8 start: %d rounds, %d elements", cv_solver_get_adapt_rounds(s), E);
  double err = max_nodal_error(s, catenary_exact);
  CHECK(err <= 1e-11 && cv_solver_get_error_estimate(s) >= 0.1 * err, "true %.3g, estimate %.3g",
        err, cv_solver_get_error_estimate(s));
  /* a graded start is kept (no degree-8 start, and degree 2 gives no pilot, HP-7): the
   * first round ends with an estimate */
  cv_solver_set_mesh_graded(s, 10, 2.0, CVAR_GRADE_A);
  CHECK(cv_solver_set_time_limit(s, 1e-9) == CVAR_OK, "time limit 1e-9 refused");
  CHECK(cv_solve(s, q) == CVAR_EMAXITER, "1 ns must stop the rounds");
  const char *m = cv_solver_last_error(s);
  double est = cv_solver_get_error_estimate(s);
  CHECK(strstr(m, "time limit of 1e-09 s was reached after 1 round") != NULL, "message: %s", m);
  CHECK(cv_solver_get_adapt_rounds(s) == 1, "rounds %d", cv_solver_get_adapt_rounds(s));
  CHECK(isfinite(est) && est > 1e-12, "estimate reached %.3g", est);
  char want[32];
  snprintf(want, sizeof want, "reached is %.2g", est);
  CHECK(strstr(m, want) != NULL, "message gives the estimate: %s", m);
  CHECK(cv_solver_set_time_limit(s, -1) == CVAR_EINVAL, "negative time limit accepted");
  CHECK(cv_solver_set_time_limit(s, NAN) == CVAR_EINVAL, "NaN time limit accepted");
  CHECK(cv_solver_set_time_limit(s, INFINITY) == CVAR_EINVAL, "infinite time limit accepted");
  CHECK(cv_solver_set_time_limit(NULL, 1) == CVAR_EINVAL, "NULL solver accepted");
  CHECK(cv_solver_set_time_limit(s, 0) == CVAR_OK, "time limit 0 (off) refused");
  CHECK(cv_solve(s, q) == CVAR_OK, "no cap: %s", cv_solver_last_error(s));
  cv_solver_free(s);
  cv_problem_free(p);
  cv_problem_free(q);
}

/* 6. HP-7a: from the uniform degree-8 start of the command (2 elements, each 0.85 of a
 * period: Legendre rates 0.96, below HP-4's smooth 1 but above HP-7a's 0.75), the pilot
 * lays the mesh of the final round in one go: on the oscillator at 1e-12, two rounds (the
 * pilot's and the one it lays), at most 3 elements more than the fewest uniform degree-8
 * elements whose true max nodal error (against the exact solution) is within 1e-12 (before
 * HP-7a: three rounds, 19 elements against 11), and honest. */
static void pilot_lands(void) {
  cv_problem *q = oscillator();
  cv_solver *s = cv_solver_new(NULL);
  cv_solver_set_degree(s, 8);
  int fewest = 0;
  for (int m = 2; m <= 40 && !fewest; m++) {
    cv_solver_set_elements(s, m);
    CHECK(cv_solve(s, q) == CVAR_OK, "%d x p8: %s", m, cv_solver_last_error(s));
    if (max_nodal_error(s, osc_exact) <= 1e-12) fewest = m;
  }
  CHECK(fewest > 2, "fewest uniform degree-8 elements for 1e-12: %d", fewest);
  cv_solver_set_elements(s, 2);
  cv_solver_set_tol(s, 1e-12, 100000);
  CHECK(cv_solve(s, q) == CVAR_OK, "oscillator 1e-12: %s", cv_solver_last_error(s));
  int E = cv_solver_get_num_elements(s), rounds = cv_solver_get_adapt_rounds(s);
  double est = cv_solver_get_error_estimate(s), err = max_nodal_error(s, osc_exact);
  printf("pilot (HP-7a): oscillator 1e-12 from 2 x p8: %d rounds, %d elements, %d nodes "
         "(fewest uniform: %d x p8), estimate %.2e, true %.2e\n",
         rounds, E, cv_solver_get_num_nodes(s), fewest, est, err);
  CHECK(rounds == 2, "rounds %d", rounds);
  CHECK(E <= fewest + 3, "%d elements, fewest uniform %d", E, fewest);
  CHECK(err <= 1e-11 && est >= 0.1 * err, "true %.3g, estimate %.3g", err, est);
  cv_solver_free(s);
  cv_problem_free(q);
}

int main(void) {
  start_and_time_cap();
  pilot_lands();
  same_as_uniform();
  mixed_degrees();
  morse_and_no_bound();
  tol_rounds();
  /* invalid degrees are refused */
  cv_solver *s = cv_solver_new(NULL);
  double t[3] = {0, 0.5, 1};
  int bad[2] = {2, 9};
  CHECK(cv_solver_set_mesh_hp(s, 2, t, bad) == CVAR_EINVAL, "degree 9 accepted");
  CHECK(cv_solver_set_tol(s, -1, 10) == CVAR_EINVAL, "negative tol accepted");
  cv_solver_free(s);
  if (n_failed) fprintf(stderr, "%d check(s) failed\n", n_failed);
  return n_failed ? 1 : 0;
}
