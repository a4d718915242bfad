/* src/core/cv_quadrature.c — Gauss-Legendre rules, Gauss-Lobatto-Legendre nodes, Lagrange basis.
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_internal.h"

/* Legendre P_n(s) and P_n'(s) by the three-term recurrence. */
static void legendre(int n, double s, double *P, double *dP) {
  double p0 = 1.0, p1 = s;
  if (n == 0) {
    *P = 1.0;
    *dP = 0.0;
    return;
  }
  for (int k = 2; k <= n; k++) {
    double p2 = ((2.0 * k - 1.0) * s * p1 - (k - 1.0) * p0) / k;
    p0 = p1;
    p1 = p2;
  }
  *P = p1;
  /* P_n' = n (s P_n - P_{n-1}) / (s^2 - 1); only used away from s = +-1 */
  *dP = n * (s * p1 - p0) / (s * s - 1.0);
}

/* q-point Gauss-Legendre rule on [-1, 1], theory: roots of P_q by Newton from
 * the Chebyshev-like guess cos(pi (k + 3/4) / (q + 1/2)), weights 2 / ((1 - t^2) P_q'^2). */
void cv_gauss_legendre(int q, double *t, double *w) {
  for (int k = 0; k < q; k++) {
    double s = cos(CV_PI * (k + 0.75) / (q + 0.5)), P, dP;
    for (int it = 0; it < 100; it++) {
      legendre(q, s, &P, &dP);
      double ds = P / dP;
      s -= ds;
      if (fabs(ds) < 1e-16) break;
    }
    legendre(q, s, &P, &dP);
    t[q - 1 - k] = s;
    w[q - 1 - k] = 2.0 / ((1.0 - s * s) * dP * dP);
  }
}

/* Gauss-Lobatto-Legendre nodes: +-1 and the roots of P_p'; weights 2/(p(p+1) P_p^2),
 * theory (E-1). Interior roots by Newton on P_p' using P_p'' from the Legendre ODE:
 * (1 - s^2) P'' = 2 s P' - p (p + 1) P. */
void cv_gauss_lobatto(int p, double *xi, double *w) {
  xi[0] = -1.0;
  xi[p] = 1.0;
  for (int j = 1; j < p; j++) {
    double s = -cos(CV_PI * j / p), P, dP;
    for (int it = 0; it < 100; it++) {
      legendre(p, s, &P, &dP);
      double d2P = (2.0 * s * dP - p * (p + 1.0) * P) / (1.0 - s * s);
      double ds = dP / d2P;
      s -= ds;
      if (fabs(ds) < 1e-16) break;
    }
    xi[j] = s;
  }
  for (int j = 0; j <= p; j++) {
    double P, dP;
    if (j == 0 || j == p) P = (j == 0 && (p % 2)) ? -1.0 : 1.0;
    else legendre(p, xi[j], &P, &dP);
    w[j] = 2.0 / (p * (p + 1.0) * P * P);
  }
}

void cv_lagrange(int p, const double *xi, double s, double *phi, double *dphi) {
  for (int l = 0; l <= p; l++) {
    double v = 1.0, dv = 0.0;
    for (int m = 0; m <= p; m++) {
      if (m == l) continue;
      double den = xi[l] - xi[m], f = (s - xi[m]) / den;
      dv = dv * f + v / den; /* product rule, accumulated */
      v *= f;
    }
    phi[l] = v;
    if (dphi) dphi[l] = dv;
  }
}

void cv_refelem_init(cv_refelem *r, int p, int q) {
  r->p = p;
  r->q = q;
  cv_gauss_lobatto(p, r->xi, r->wl);
  cv_gauss_legendre(q, r->tau, r->omega);
  for (int k = 0; k < q; k++)
    cv_lagrange(p, r->xi, r->tau[k], r->B + k * (p + 1), r->D + k * (p + 1));
  /* Singular-end rules: twice the regular points plus four, capped; the
   * transformed integrand is smooth but not polynomial. */
  r->qs = 2 * q + 4 > CV_MAX_QUAD ? CV_MAX_QUAD : 2 * q + 4;
}
