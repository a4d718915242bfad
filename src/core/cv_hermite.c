/* src/core/cv_hermite.c — C^1 elements: the reference element, the discretisation's
 * tables and weights, starting values and evaluation (theory H-2, H-5).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_hermite.h"

/* Legendre polynomials P_0 .. P_{nb-1} at s with first and second derivatives. */
static void legendre(int nb, double s, double *P, double *dP, double *d2P) {
  P[0] = 1.0, dP[0] = 0.0, d2P[0] = 0.0;
  if (nb > 1) P[1] = s, dP[1] = 1.0, d2P[1] = 0.0;
  for (int k = 1; k + 1 < nb; k++) {
    P[k + 1] = ((2 * k + 1) * s * P[k] - k * P[k - 1]) / (k + 1);
    dP[k + 1] = dP[k - 1] + (2 * k + 1) * P[k];
    d2P[k + 1] = d2P[k - 1] + (2 * k + 1) * dP[k];
  }
}

/* C = A^{-1} by Gauss-Jordan with partial pivoting, A nb x nb (A is overwritten). */
static void invert(int nb, double *A, double *C) {
  for (int i = 0; i < nb; i++)
    for (int j = 0; j < nb; j++) C[i * nb + j] = i == j;
  for (int c = 0; c < nb; c++) {
    int piv = c;
    for (int i = c + 1; i < nb; i++)
      if (fabs(A[i * nb + c]) > fabs(A[piv * nb + c])) piv = i;
    for (int j = 0; j < nb; j++) {
      double t = A[c * nb + j];
      A[c * nb + j] = A[piv * nb + j], A[piv * nb + j] = t;
      t = C[c * nb + j];
      C[c * nb + j] = C[piv * nb + j], C[piv * nb + j] = t;
    }
    double d = 1.0 / A[c * nb + c];
    for (int j = 0; j < nb; j++) A[c * nb + j] *= d, C[c * nb + j] *= d;
    for (int i = 0; i < nb; i++) {
      double f = A[i * nb + c];
      if (i == c || f == 0.0) continue;
      for (int j = 0; j < nb; j++)
        A[i * nb + j] -= f * A[c * nb + j], C[i * nb + j] -= f * C[c * nb + j];
    }
  }
}

/* (H-2) Rows of A: P_k(xi_l) (row 2l) and P_k'(xi_l) (row 2l + 1); the coefficients of
 * basis function t in the Legendre basis are column t of A^{-1}. */
void cv_hermite_init(cv_hermite *h, int r, int q) {
  double A[CV_HERMITE_NB * CV_HERMITE_NB], P[CV_HERMITE_NB], dP[CV_HERMITE_NB], d2P[CV_HERMITE_NB];
  double w[CV_MAX_DEGREE + 1];
  h->r = r, h->nb = 2 * (r + 1), h->q = q;
  int nb = h->nb;
  cv_gauss_lobatto(r, h->xi, w);
  for (int l = 0; l <= r; l++) {
    legendre(nb, h->xi[l], P, dP, d2P);
    for (int k = 0; k < nb; k++) A[2 * l * nb + k] = P[k], A[(2 * l + 1) * nb + k] = dP[k];
  }
  invert(nb, A, h->C);
  cv_gauss_legendre(q, h->tau, h->omega);
  for (int k = 0; k < q; k++)
    cv_hermite_basis(h, h->tau[k], h->B + k * nb, h->D + k * nb, h->E + k * nb);
}

void cv_hermite_basis(const cv_hermite *h, double s, double *B, double *D, double *E) {
  double P[CV_HERMITE_NB], dP[CV_HERMITE_NB], d2P[CV_HERMITE_NB];
  int nb = h->nb;
  legendre(nb, s, P, dP, d2P);
  for (int t = 0; t < nb; t++) {
    double b = 0.0, d = 0.0, e = 0.0;
    for (int k = 0; k < nb; k++) {
      double c = h->C[k * nb + t];
      b += c * P[k], d += c * dP[k], e += c * d2P[k];
    }
    if (B) B[t] = b;
    if (D) D[t] = d;
    if (E) E[t] = e;
  }
}

int cv_hermite_node_degree(int degree, char *msg, size_t len) {
  if (degree == 1) return 1;
  if (degree >= 3 && degree <= 2 * CV_HERMITE_MAX_R + 1 && degree % 2 == 1) return (degree - 1) / 2;
  cv_set_msg(msg, len,
             "degree %d: the C1 elements of an integrand with y'' have degree 3, 5 or 7 (values "
             "and slopes at the nodes)",
             degree);
  return -1;
}

cv_status cv_hermite_disc_init(cv_disc *d, int nq) {
  d->herm = cv_malloc(sizeof *d->herm);
  if (!d->herm) return CVAR_ENOMEM;
  cv_hermite_init(d->herm, d->p, nq ? nq : 2 * d->p + 2);
  return CVAR_OK;
}

/* (H-5) A slope unknown moves y by about h/(2r+1) times itself near its node: its lumped
 * weight is the node's value weight times (hbar / (2r + 1))^2, hbar the mean length of the
 * elements at the node. */
void cv_hermite_scale_mass(cv_disc *d) {
  int n = d->n;
  for (long j = 0; j < d->nodes; j++) {
    long e = cv_disc_node_elem(d, j);
    double h = d->xe[e + 1] - d->xe[e];
    if (j == cv_disc_enode(d, e) && e > 0) h = 0.5 * (h + d->xe[e] - d->xe[e - 1]);
    double sc = h / (2 * d->p + 1);
    sc *= sc;
    for (int i = 1; i < n; i += 2) {
      int f = cv_disc_fidx(d, j * n + i);
      if (f >= 0) d->mass[f] *= sc, d->imass[f] = 1.0 / d->mass[f];
    }
  }
}

void cv_hermite_eval_local(const cv_disc *d, const double *Y, long e, double s, double *y,
                           double *dy, double *d2y) {
  const cv_hermite *h = d->herm;
  double B[CV_HERMITE_NB], D[CV_HERMITE_NB], E[CV_HERMITE_NB];
  double hl = d->xe[e + 1] - d->xe[e], J = 0.5 * hl, rh = 2.0 / hl;
  int nc = d->n, n = nc / 2;
  const double *Ye = Y + (size_t)cv_disc_enode(d, e) * nc;
  cv_hermite_basis(h, s, B, D, E);
  for (int i = 0; i < n; i++) {
    double a = 0.0, b = 0.0, c = 0.0;
    for (int l = 0; l <= h->r; l++) {
      double v = Ye[l * nc + 2 * i], t = Ye[l * nc + 2 * i + 1] * J;
      a += v * B[2 * l] + t * B[2 * l + 1];
      b += v * D[2 * l] + t * D[2 * l + 1];
      c += v * E[2 * l] + t * E[2 * l + 1];
    }
    if (y) y[i] = a;
    if (dy) dy[i] = b * rh;
    if (d2y) d2y[i] = c * rh * rh;
  }
}

/* The guess at the nodes, with slopes by central differences of the guess (one-sided at
 * the ends); 0 or a failure sentence in s->msg. */
static cv_status guess_nodes(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y) {
  int n = p->n, nc = d->n;
  double x3[3], y3[3 * 64];
  if (n > 64) {
    cv_set_msg(s->msg, sizeof s->msg, "a guess for more than 64 second-order unknowns");
    return CVAR_EINVAL;
  }
  double dx = 1e-5 * (d->b - d->a);
  for (long j = 0; j < d->nodes; j++) {
    double x = cv_disc_node_x(d, j), lo = fmax(d->a, x - dx), hi = fmin(d->b, x + dx);
    x3[0] = x, x3[1] = lo, x3[2] = hi;
    int rc = p->guess(3, x3, y3, p->guess_user);
    for (int i = 0; i < n && rc == 0; i++) {
      Y[j * nc + 2 * i] = y3[i * 3];
      Y[j * nc + 2 * i + 1] = (y3[i * 3 + 2] - y3[i * 3 + 1]) / (hi - lo);
      if (!isfinite(Y[j * nc + 2 * i]) || !isfinite(Y[j * nc + 2 * i + 1])) rc = 1;
    }
    if (rc) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "the initial guess is not finite (or its callback failed) near x = %g", x);
      return CVAR_ECALLBACK;
    }
  }
  return CVAR_OK;
}

/* A start of nodes*n values (cv_solver_set_start's layout): slopes from the derivative of
 * the degree-r interpolant of the values, from the element on the node's left. */
static void start_from_values(const cv_solver *s, const cv_disc *d, double *Y) {
  int nc = d->n, n = nc / 2, r = d->p;
  double phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
  for (long j = 0; j < d->nodes; j++)
    for (int i = 0; i < n; i++) Y[j * nc + 2 * i] = s->start[j * n + i];
  for (long j = 0; j < d->nodes; j++) {
    long e = j == 0 ? 0 : cv_disc_node_elem(d, j - 1);
    long j0 = cv_disc_enode(d, e);
    cv_lagrange(r, d->ref.xi, d->ref.xi[j - j0 > r ? r : j - j0], phi, dphi);
    double rh = 2.0 / (d->xe[e + 1] - d->xe[e]);
    for (int i = 0; i < n; i++) {
      double v = 0.0;
      for (int l = 0; l <= r; l++) v += dphi[l] * Y[(j0 + l) * nc + 2 * i];
      Y[j * nc + 2 * i + 1] = v * rh;
    }
  }
}

/* The cubic Hermite basis on [0, 1] at t: values h[0..3] (value at 0, slope at 0, value at
 * 1, slope at 1, slopes per unit t) and derivatives d[0..3]. */
static void cubic(double t, double *h, double *d) {
  double t2 = t * t, t3 = t2 * t;
  h[0] = 1 - 3 * t2 + 2 * t3, h[1] = t - 2 * t2 + t3, h[2] = 3 * t2 - 2 * t3, h[3] = t3 - t2;
  d[0] = -6 * t + 6 * t2, d[1] = 1 - 4 * t + 3 * t2, d[2] = 6 * t - 6 * t2, d[3] = 3 * t2 - 2 * t;
}

/* Add to unknown i of Y the cubic with values va, vb and slopes sa, sb at the ends. */
static void add_cubic(const cv_disc *d, double *Y, int i, double va, double sa, double vb,
                      double sb) {
  int nc = d->n;
  double L = d->b - d->a, h[4], dh[4];
  if (va == 0.0 && sa == 0.0 && vb == 0.0 && sb == 0.0) return;
  for (long j = 0; j < d->nodes; j++) {
    double t = (cv_disc_node_x(d, j) - d->a) / L;
    cubic(t, h, dh);
    Y[j * nc + 2 * i] += va * h[0] + sa * L * h[1] + vb * h[2] + sb * L * h[3];
    Y[j * nc + 2 * i + 1] += (va * dh[0] + sa * L * dh[1] + vb * dh[2] + sb * L * dh[3]) / L;
  }
}

/* (H-9) Without a start or guess: the cubic through the end values and slopes (a free
 * value takes the other end's, a free slope the chord's: with no slope fixed, the straight
 * line of cv_start_values). A start or guess that misses fixed end values or slopes is
 * moved onto them by adding the cubic with the misses at the ends (smooth, unlike an
 * overwritten end node: a kink there is a poor Newton start, cv_start_values). */
cv_status cv_hermite_start_values(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y,
                                  int line) {
  int n = p->n, nc = d->n;
  long last = d->nodes - 1;
  if (s->start && !line) {
    if (s->start_len == d->ndof)
      cv_dcopy(Y, s->start, (size_t)d->ndof);
    else if (s->start_len == d->nodes * n)
      start_from_values(s, d, Y);
    else {
      cv_set_msg(s->msg, sizeof s->msg,
                 "start vector has %d values but the mesh has %d nodes x %d unknowns (or x %d "
                 "with slopes)",
                 s->start_len, d->nodes, n, 2 * n);
      return CVAR_EINVAL;
    }
  } else if (p->guess && !line) {
    cv_status st = guess_nodes(s, p, d, Y);
    if (st) return st;
  } else {
    cv_dzero(Y, (size_t)d->ndof);
    for (int i = 0; i < n; i++) {
      int fa = p->fixed[2 * i], fb = p->fixed[2 * i + 1];
      double ya = p->endval[2 * i], yb = p->endval[2 * i + 1], L = d->b - d->a;
      if (!fa) ya = fb ? yb : 0.0;
      if (!fb) yb = ya;
      double chord = (yb - ya) / L;
      add_cubic(d, Y, i, ya, p->sfixed[2 * i] ? p->sendval[2 * i] : chord, yb,
                p->sfixed[2 * i + 1] ? p->sendval[2 * i + 1] : chord);
    }
  }
  for (int i = 0; i < n; i++) {
    double va = p->fixed[2 * i] ? p->endval[2 * i] - Y[2 * i] : 0.0;
    double vb = p->fixed[2 * i + 1] ? p->endval[2 * i + 1] - Y[last * nc + 2 * i] : 0.0;
    double sa = p->sfixed[2 * i] ? p->sendval[2 * i] - Y[2 * i + 1] : 0.0;
    double sb = p->sfixed[2 * i + 1] ? p->sendval[2 * i + 1] - Y[last * nc + 2 * i + 1] : 0.0;
    add_cubic(d, Y, i, va, sa, vb, sb);
    if (p->fixed[2 * i]) Y[2 * i] = p->endval[2 * i]; /* exactly */
    if (p->fixed[2 * i + 1]) Y[last * nc + 2 * i] = p->endval[2 * i + 1];
    if (p->sfixed[2 * i]) Y[2 * i + 1] = p->sendval[2 * i];
    if (p->sfixed[2 * i + 1]) Y[last * nc + 2 * i + 1] = p->sendval[2 * i + 1];
  }
  return CVAR_OK;
}
