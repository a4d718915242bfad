/* examples/sphere_geodesic.c — a great circle on the unit sphere, two unknowns, callback.
 * SPDX-License-Identifier: MIT
 *
 * Problem: the geodesic from colatitude/longitude (th, ph) = (pi/3, 0) to (pi/2, pi/2) in
 * energy form  I = int_0^1 th'^2 + sin(th)^2 ph'^2 ds, whose stationary paths are geodesics
 * traversed at constant speed (scene: scenes/sphere_geodesic.scene). The length form
 * int sqrt(th'^2 + sin(th)^2 ph'^2) ds is invariant under reparametrisation and has a
 * singular Hessian (docs/faq.md).
 * Exact solution: a quarter great circle, th = acos(cos(pi s/2)/2),
 * ph = atan2(sin(pi s/2), (sqrt 3/2) cos(pi s/2)); energy pi^2/4 = 2.4674011002723395,
 * length pi/2 (computed here from the quadrature points).
 * The program checks the callback's partials against finite differences
 * (cv_problem_check_derivatives), solves with 16 elements of degree 4 and checks: exit 0 when
 * the max nodal error is below 1e-9, the energy within 1e-11 of pi^2/4 and the length within
 * 1e-11 of pi/2. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <calcvar.h>

#define PI 3.14159265358979323846

/* Unknowns 0 = th, 1 = ph; with n = 2 the partials are laid out [(i*2 + j)*m + k].
 * F = th'^2 + sin^2(th) ph'^2:  F_th = sin(2 th) ph'^2, F_ph = 0, F_th' = 2 th',
 * F_ph' = 2 sin^2(th) ph';  F_th,th = 2 cos(2 th) ph'^2, F_th,ph' = 2 sin(2 th) ph',
 * F_th'th' = 2, F_ph'ph' = 2 sin^2(th); every other second partial is 0. */
static int energy(int m, const double *x, const double *y, const double *dy, unsigned need,
                  cv_partials *out, void *user) {
  (void)x;
  (void)need;
  (void)user;
  for (int k = 0; k < m; k++) {
    double th = y[k], dth = dy[k], dph = dy[m + k];
    double s = sin(th), s2 = sin(2.0 * th), c2 = cos(2.0 * th);
    out->F[k] = dth * dth + s * s * dph * dph;
    if (out->Fy) {
      out->Fy[k] = s2 * dph * dph;
      out->Fy[m + k] = 0.0;
      out->Fp[k] = 2.0 * dth;
      out->Fp[m + k] = 2.0 * s * s * dph;
    }
    if (out->Fyy) {
      for (int ij = 0; ij < 4; ij++) out->Fyy[ij * m + k] = out->Fyp[ij * m + k] = 0.0;
      out->Fyy[k] = 2.0 * c2 * dph * dph;   /* (th, th) */
      out->Fyp[1 * m + k] = 2.0 * s2 * dph; /* (th, ph') */
      out->Fpp[0 * m + k] = 2.0;            /* (th', th') */
      out->Fpp[1 * m + k] = 0.0;            /* (th', ph') */
      out->Fpp[2 * m + k] = 0.0;            /* (ph', th') */
      out->Fpp[3 * m + k] = 2.0 * s * s;    /* (ph', ph') */
    }
  }
  return 0;
}

int main(void) {
  const double exact_energy = PI * PI / 4.0, exact_length = PI / 2.0;
  cv_status st;
  cv_problem *p = cv_problem_new(2, 0.0, 1.0, &st);
  if (!p) {
    fprintf(stderr, "cv_problem_new: %s\n", cv_strerror(st));
    return 1;
  }
  cv_solver *s = cv_solver_new(&st);
  if (!s) {
    fprintf(stderr, "cv_solver_new: %s\n", cv_strerror(st));
    cv_problem_free(p);
    return 1;
  }
  int rc = 1;
  double *x = NULL, *y = NULL, *w = NULL, *yq = NULL, *dyq = NULL;
  if ((st = cv_problem_set_integrand(p, energy, NULL)) ||
      (st = cv_problem_set_dirichlet(p, 0, PI / 3.0, PI / 2.0)) ||
      (st = cv_problem_set_dirichlet(p, 1, 0.0, PI / 2.0)) ||
      (st = cv_solver_set_elements(s, 16)) || (st = cv_solver_set_degree(s, 4))) {
    fprintf(stderr, "setup: %s\n", cv_strerror(st));
    goto cleanup;
  }
  /* Partials against central differences at three points (th, ph; th', ph'). */
  const double xc[3] = {0.1, 0.5, 0.9}, yc[6] = {1.1, 1.3, 1.5, 0.1, 0.8, 1.4},
               dyc[6] = {0.7, -0.2, 0.4, 1.6, 1.2, 2.0};
  cv_derivcheck dc;
  if ((st = cv_problem_check_derivatives(p, 3, xc, yc, dyc, &dc)) || dc.worst > 1e-6) {
    fprintf(stderr, "derivative check: %s, worst %s = %g against %g\n", cv_strerror(st), dc.which,
            dc.analytic, dc.fd);
    goto cleanup;
  }
  if ((st = cv_solve(s, p)) != CVAR_OK) {
    fprintf(stderr, "not solved: %s: %s\n", cv_strerror(st), cv_solver_last_error(s));
    goto cleanup;
  }
  int nn = cv_solver_get_num_nodes(s), nq = cv_solver_get_num_qpoints(s);
  x = malloc(nn * sizeof *x);
  y = malloc(2 * nn * sizeof *y);
  w = malloc(nq * sizeof *w);
  yq = malloc(2 * nq * sizeof *yq);
  dyq = malloc(2 * nq * sizeof *dyq);
  if (!x || !y || !w || !yq || !dyq || cv_solver_get_nodes(s, x) || cv_solver_get_values(s, y) ||
      cv_solver_get_qpoints(s, NULL, w, yq, dyq))
    goto cleanup;
  double err = 0.0, length = 0.0;
  for (int j = 0; j < nn; j++) { /* node-major: y[j*2 + i] */
    double c = cos(PI * x[j] / 2.0), sn = sin(PI * x[j] / 2.0);
    err = fmax(err, fabs(y[2 * j] - acos(c / 2.0)));
    err = fmax(err, fabs(y[2 * j + 1] - atan2(sn, sqrt(3.0) / 2.0 * c)));
  }
  for (int k = 0; k < nq; k++) { /* structure of arrays: yq[i*nq + k] */
    double st_ = sin(yq[k]);
    length += w[k] * sqrt(dyq[k] * dyq[k] + st_ * st_ * dyq[nq + k] * dyq[nq + k]);
  }
  double e = cv_solver_get_action(s);
  printf("sphere_geodesic: derivative check worst %.1e (%s); %d nodes, %d Newton iterations, "
         "Morse index %d\n",
         dc.worst, dc.which, nn, cv_solver_get_num_iterations(s), cv_solver_get_morse_index(s));
  printf("  energy %.15f (exact pi^2/4 = %.15f), length %.15f (exact pi/2)\n", e, exact_energy,
         length);
  printf("  max nodal error %.2e\n", err);
  rc =
      (err < 1e-9 && fabs(e - exact_energy) < 1e-11 && fabs(length - exact_length) < 1e-11) ? 0 : 1;
  if (rc) fprintf(stderr, "sphere_geodesic: answer outside its stated tolerance\n");
cleanup:
  free(dyq);
  free(yq);
  free(w);
  free(y);
  free(x);
  cv_solver_free(s);
  cv_problem_free(p);
  return rc;
}
