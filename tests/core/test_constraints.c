/* tests/core/test_constraints.c — multipliers: the hanging chain (integral constraint),
 * the Cartesian pendulum (pointwise constraint, rod tension) against the angle form, the
 * sphere as an implicit surface, and an isoperimetric arc; all with exact answers.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "refproblems.h"

#define GRAV 9.81

/* K = sqrt(1 + y'^2): arc length (hanging chain, isoperimetric arc). */
static int length_K(int m, const double *x, const double *y, const double *dy, unsigned need,
                    cv_partials *o, void *user) {
  return line_F(m, x, y, dy, need, o, user);
}

/* F = -y: minus the area under the curve. */
static int minus_area_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                        cv_partials *o, void *user) {
  (void)x;
  (void)y;
  (void)dy;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = -y[k];
    if (o->Fy) {
      o->Fy[k] = -1;
      o->Fp[k] = 0;
    }
    if (o->Fyy) {
      o->Fyy[k] = 0;
      o->Fyp[k] = 0;
      o->Fpp[k] = 0;
    }
  }
  return 0;
}

static int chain_guess(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = 0.6 * (x[k] * x[k] - 1);
  return 0;
}

static int bulge_guess(int m, const double *x, double *y, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) y[k] = 0.3 * (1 - x[k] * x[k]);
  return 0;
}

/* Pendulum, m = l = 1: angle form F = th'^2/2 + g cos th. */
static int pend_angle_F(int m, const double *x, const double *y, const double *dy, unsigned need,
                        cv_partials *o, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * dy[k] * dy[k] + GRAV * cos(y[k]);
    if (o->Fy) {
      o->Fy[k] = -GRAV * sin(y[k]);
      o->Fp[k] = dy[k];
    }
    if (o->Fyy) {
      o->Fyy[k] = -GRAV * cos(y[k]);
      o->Fyp[k] = 0;
      o->Fpp[k] = 1;
    }
  }
  return 0;
}

/* Cartesian form F = (x'^2 + y'^2)/2 - g y (n = 2); constraint x^2 + y^2 - 1 = 0. */
static int pend_cart_F(int m, const double *t, const double *q, const double *dq, unsigned need,
                       cv_partials *o, void *user) {
  (void)t;
  (void)need;
  (void)user;
  const int n = 2;
  for (int k = 0; k < m; k++) {
    o->F[k] = 0.5 * (dq[k] * dq[k] + dq[m + k] * dq[m + k]) - GRAV * q[m + k];
    SET1(o->Fy, 0, k, 0);
    SET1(o->Fy, 1, k, -GRAV);
    SET1(o->Fp, 0, k, dq[k]);
    SET1(o->Fp, 1, k, dq[m + k]);
    for (int i = 0; i < 2; i++)
      for (int j = 0; j < 2; j++) {
        SET2(o->Fyy, i, j, k, 0);
        SET2(o->Fyp, i, j, k, 0);
        SET2(o->Fpp, i, j, k, i == j ? 1.0 : 0.0);
      }
  }
  return 0;
}

/* |q|^2 - 1 for n = *(int *)user unknowns. */
static int unit_sphere_G(int m, const double *t, const double *q, unsigned need, double *G,
                         double *Gy, double *Gyy, void *user) {
  (void)t;
  (void)need;
  int n = *(const int *)user;
  for (int k = 0; k < m; k++) {
    double r2 = 0;
    for (int i = 0; i < n; i++) {
      r2 += q[i * m + k] * q[i * m + k];
      if (Gy) Gy[i * m + k] = 2 * q[i * m + k];
      if (Gyy)
        for (int j = 0; j < n; j++) Gyy[(i * n + j) * m + k] = i == j ? 2.0 : 0.0;
    }
    G[k] = r2 - 1;
  }
  return 0;
}

static int pend_guess(int m, const double *t, double *q, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) {
    q[k] = sin(2 * t[k]);
    q[m + k] = -cos(2 * t[k]);
  }
  return 0;
}

/* Energy x'^2 + y'^2 + z'^2 (n = 3). */
static int energy3_F(int m, const double *t, const double *q, const double *dq, unsigned need,
                     cv_partials *o, void *user) {
  (void)t;
  (void)q;
  (void)need;
  (void)user;
  const int n = 3;
  for (int k = 0; k < m; k++) {
    double e = 0;
    for (int i = 0; i < 3; i++) {
      e += dq[i * m + k] * dq[i * m + k];
      SET1(o->Fy, i, k, 0);
      SET1(o->Fp, i, k, 2 * dq[i * m + k]);
      for (int j = 0; j < 3; j++) {
        SET2(o->Fyy, i, j, k, 0);
        SET2(o->Fyp, i, j, k, 0);
        SET2(o->Fpp, i, j, k, i == j ? 2.0 : 0.0);
      }
    }
    o->F[k] = e;
  }
  return 0;
}

/* Great-circle guess between A = (sqrt3/2, 0, 1/2) and B = (0, 1, 0), bent off the sphere. */
static int sphere3_guess(int m, const double *t, double *q, void *user) {
  (void)user;
  for (int k = 0; k < m; k++) {
    double s = t[k];
    q[k] = (1 - s) * sqrt(3) / 2;
    q[m + k] = s;
    q[2 * m + k] = (1 - s) * 0.5;
  }
  return 0;
}

int main(void) {
  /* Hanging chain: |mu| = cosh 1 and y = cosh x - cosh 1, degree 2 and 4. */
  for (int deg = 2; deg <= 4; deg += 2) {
    cv_problem *p = cv_problem_new(1, -1, 1, NULL);
    cv_problem_set_integrand(p, catenary_F, NULL);
    cv_problem_set_dirichlet(p, 0, 0, 0);
    cv_problem_set_guess(p, chain_guess, NULL);
    cv_problem_add_integral(p, length_K, NULL, 2 * sinh(1.0), NULL);
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, 64);
    cv_solver_set_degree(s, deg);
    cv_status st = cv_solve(s, p);
    CHECK(st == CVAR_OK, "hanging chain p=%d: %s", deg, cv_solver_last_error(s));
    double mu = NAN;
    cv_solver_get_multiplier(s, 0, &mu);
    int nn = cv_solver_get_num_nodes(s);
    double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), err = 0;
    cv_solver_get_nodes(s, x);
    cv_solver_get_values(s, y);
    for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - (cosh(x[j]) - cosh(1.0))));
    printf("hanging chain p=%d: mu %.15f (|mu| exact %.15f) err %.2e action %.15f morse %d it %d\n",
           deg, mu, cosh(1.0), err, cv_solver_get_action(s), cv_solver_get_morse_index(s),
           cv_solver_get_num_iterations(s));
    CHECK_NEAR("hanging chain |multiplier|", fabs(mu), cosh(1.0), 1e-8);
    CHECK_NEAR("hanging chain nodal error", err, 0, 1e-8);
    CHECK_NEAR("hanging chain action", cv_solver_get_action(s), -0.8134302039235093, 1e-8);
    free(x);
    free(y);
    cv_solver_free(s);
    cv_problem_free(p);
  }

  /* Isoperimetric arc: max area for length pi/sqrt2 through (+-1, 0): the arc of the
   * circle of radius sqrt 2 centred at (0, -1); multiplier magnitude = radius. */
  {
    cv_problem *p = cv_problem_new(1, -1, 1, NULL);
    cv_problem_set_integrand(p, minus_area_F, NULL);
    cv_problem_set_dirichlet(p, 0, 0, 0);
    /* An upward bulge; from a downward one Newton finds the mirror arc (mu = -sqrt 2), the
     * other stationary point, equally valid. */
    cv_problem_set_guess(p, bulge_guess, NULL);
    cv_problem_add_integral(p, length_K, NULL, PI / sqrt(2.0), NULL);
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, 32);
    cv_solver_set_degree(s, 4);
    cv_status st = cv_solve(s, p);
    CHECK(st == CVAR_OK, "isoperimetric: %s", cv_solver_last_error(s));
    double mu = NAN;
    cv_solver_get_multiplier(s, 0, &mu);
    int nn = cv_solver_get_num_nodes(s);
    double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y), err = 0;
    cv_solver_get_nodes(s, x);
    cv_solver_get_values(s, y);
    for (int j = 0; j < nn; j++) err = fmax(err, fabs(y[j] - (sqrt(2 - x[j] * x[j]) - 1)));
    printf("isoperimetric: mu %.15f (exact sqrt2) err %.2e morse %d\n", mu, err,
           cv_solver_get_morse_index(s));
    CHECK_NEAR("isoperimetric |multiplier|", fabs(mu), sqrt(2.0), 1e-9);
    CHECK_NEAR("isoperimetric nodal error", err, 0, 1e-9);
    free(x);
    free(y);
    cv_solver_free(s);
    cv_problem_free(p);
  }

  /* Pendulum: Cartesian with the rod constraint against the angle form on the same mesh. */
  {
    const int E = 64, deg = 4;
    cv_problem *pa = cv_problem_new(1, 0, 0.5, NULL);
    cv_problem_set_integrand(pa, pend_angle_F, NULL);
    cv_problem_set_dirichlet(pa, 0, 0, 1);
    cv_solver *sa = cv_solver_new(NULL);
    cv_solver_set_elements(sa, E);
    cv_solver_set_degree(sa, deg);
    cv_solver_set_tolerances(sa, 1e-13, 1e-13);
    CHECK(cv_solve(sa, pa) == CVAR_OK, "pendulum angle: %s", cv_solver_last_error(sa));

    int two = 2;
    cv_problem *pc = cv_problem_new(2, 0, 0.5, NULL);
    cv_problem_set_integrand(pc, pend_cart_F, NULL);
    cv_problem_set_dirichlet(pc, 0, 0, sin(1.0));
    cv_problem_set_dirichlet(pc, 1, -1, -cos(1.0));
    cv_problem_set_guess(pc, pend_guess, NULL);
    cv_problem_add_constraint(pc, unit_sphere_G, &two, NULL);
    cv_solver *sc = cv_solver_new(NULL);
    cv_solver_set_elements(sc, E);
    cv_solver_set_degree(sc, deg);
    cv_solver_set_tolerances(sc, 1e-13, 1e-13);
    cv_status st = cv_solve(sc, pc);
    CHECK(st == CVAR_OK, "pendulum cartesian: %s", cv_solver_last_error(sc));
    int nn = cv_solver_get_num_nodes(sc);
    double *t = malloc(nn * sizeof *t), *th = malloc(nn * sizeof *th);
    double *q = malloc(2 * nn * sizeof *q), *lam = malloc(nn * sizeof *lam);
    double *dth = malloc(nn * sizeof *dth), eth = 0, elam = 0;
    cv_solver_get_nodes(sc, t);
    cv_solver_get_values(sc, q);
    cv_solver_get_values(sa, th);
    cv_solver_get_multiplier_field(sc, 0, lam);
    cv_solver_eval(sa, nn, t, th, dth);
    /* L + lam G: m x'' = 2 lam x, so the tension T = m l th'^2 + m g cos th equals
     * -2 l lam (docs/constraints.md); here m = l = 1. */
    for (int j = 0; j < nn; j++) {
      eth = fmax(eth, fabs(atan2(q[2 * j], -q[2 * j + 1]) - th[j]));
      double T = dth[j] * dth[j] + GRAV * cos(th[j]);
      elam = fmax(elam, fabs(-2 * lam[j] - T));
    }
    printf("pendulum: max |theta diff| %.2e, max |tension diff| %.2e (T(0) = %.6f), morse %d\n",
           eth, elam, -2 * lam[0], cv_solver_get_morse_index(sc));
    CHECK_NEAR("pendulum angle agreement", eth, 0, 1e-8);
    CHECK_NEAR("pendulum tension from multiplier", elam, 0, 1e-6);
    CHECK(cv_solver_get_morse_index(sc) == cv_solver_get_morse_index(sa),
          "pendulum Morse index %d (cartesian) vs %d (angle)", cv_solver_get_morse_index(sc),
          cv_solver_get_morse_index(sa));
    free(t);
    free(th);
    free(q);
    free(lam);
    free(dth);
    cv_solver_free(sc);
    cv_problem_free(pc);
    cv_solver_free(sa);
    cv_problem_free(pa);
  }

  /* Geodesic on the unit sphere as an implicit surface: length pi/2. */
  {
    int three = 3;
    cv_problem *p = cv_problem_new(3, 0, 1, NULL);
    cv_problem_set_integrand(p, energy3_F, NULL);
    cv_problem_set_dirichlet(p, 0, sqrt(3) / 2, 0);
    cv_problem_set_dirichlet(p, 1, 0, 1);
    cv_problem_set_dirichlet(p, 2, 0.5, 0);
    cv_problem_set_guess(p, sphere3_guess, NULL);
    cv_problem_add_constraint(p, unit_sphere_G, &three, NULL);
    cv_solver *s = cv_solver_new(NULL);
    cv_solver_set_elements(s, 32);
    cv_solver_set_degree(s, 4);
    cv_status st = cv_solve(s, p);
    CHECK(st == CVAR_OK, "implicit sphere: %s", cv_solver_last_error(s));
    int nq = cv_solver_get_num_qpoints(s);
    double *w = malloc(nq * sizeof *w), *dq = malloc(3 * nq * sizeof *dq), len = 0;
    cv_solver_get_qpoints(s, NULL, w, NULL, dq);
    for (int k = 0; k < nq; k++)
      len += w[k] * sqrt(dq[k] * dq[k] + dq[nq + k] * dq[nq + k] + dq[2 * nq + k] * dq[2 * nq + k]);
    printf("implicit sphere: length %.15f (pi/2 = %.15f), energy %.15f, morse %d\n", len, PI / 2,
           cv_solver_get_action(s), cv_solver_get_morse_index(s));
    CHECK_NEAR("implicit sphere length", len, PI / 2, 1e-9);
    CHECK_NEAR("implicit sphere energy", cv_solver_get_action(s), PI * PI / 4, 1e-9);
    free(w);
    free(dq);
    cv_solver_free(s);
    cv_problem_free(p);
  }

  /* A constraint violated at a fixed end is rejected before solving. */
  {
    int two = 2;
    cv_problem *p = cv_problem_new(2, 0, 0.5, NULL);
    cv_problem_set_integrand(p, pend_cart_F, NULL);
    cv_problem_set_dirichlet(p, 0, 0, 0.5);
    cv_problem_set_dirichlet(p, 1, -1, -0.5);
    cv_problem_add_constraint(p, unit_sphere_G, &two, NULL);
    cv_solver *s = cv_solver_new(NULL);
    cv_status st = cv_solve(s, p);
    CHECK(st == CVAR_EINVAL && strstr(cv_solver_last_error(s), "does not hold"),
          "violated end: %s: %s", cv_status_name(st), cv_solver_last_error(s));
    cv_solver_free(s);
    cv_problem_free(p);
  }
  if (n_failed) fprintf(stderr, "%d check(s) failed\n", n_failed);
  return n_failed ? 1 : 0;
}
