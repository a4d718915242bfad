/* src/core/cv_ends_data.c — what the transversality condition of a moving end needs from
 * the fixed-interval solution: the momenta and the energy at that end (theory ME-2).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* x <- A^{-1} x for the dense n x n matrix A (row-major, overwritten): Gaussian elimination
 * with partial pivoting. -1 when A is singular. */
static int dense_solve(int n, double *A, double *x) {
  for (int c = 0; c < n; c++) {
    int piv = c;
    for (int r = c + 1; r < n; r++)
      if (fabs(A[r * n + c]) > fabs(A[piv * n + c])) piv = r;
    if (!(fabs(A[piv * n + c]) > 0.0)) return -1;
    if (piv != c) {
      for (int j = 0; j < n; j++) {
        double t = A[c * n + j];
        A[c * n + j] = A[piv * n + j], A[piv * n + j] = t;
      }
      double t = x[c];
      x[c] = x[piv], x[piv] = t;
    }
    for (int r = c + 1; r < n; r++) {
      double f = A[r * n + c] / A[c * n + c];
      for (int j = c; j < n; j++) A[r * n + j] -= f * A[c * n + j];
      x[r] -= f * x[c];
    }
  }
  for (int c = n - 1; c >= 0; c--) {
    for (int j = c + 1; j < n; j++) x[c] -= A[c * n + j] * x[j];
    x[c] /= A[c * n + c];
  }
  return 0;
}

/* The Lagrangian L = F + sum_r mu_r K_r of the integral constraints (theory C-2) and the
 * partials `need` asks for at m <= CV_BATCH points, into o (laid out as the callbacks'). */
static int eval_lagrangian(const cv_problem *q, const double *mu, int m, const double *x,
                           const double *y, const double *v, unsigned need, cv_partials *o) {
  int n = q->n;
  if (q->F(m, x, y, v, need, o, q->user) != 0) return -1;
  if (q->ni == 0) return 0;
  size_t nm = (size_t)n * m, nnm = (size_t)n * nm;
  double *buf = cv_malloc(((size_t)m + 2 * nm + 3 * nnm) * sizeof *buf);
  if (!buf) return -1;
  int rc = 0;
  for (int r = 0; r < q->ni && rc == 0; r++) {
    cv_partials k = {buf, NULL, NULL, NULL, NULL, NULL};
    if (need & CVAR_NEED_GRAD) k.Fy = buf + m, k.Fp = k.Fy + nm;
    if (need & CVAR_NEED_HESS) k.Fyy = buf + m + 2 * nm, k.Fyp = k.Fyy + nnm, k.Fpp = k.Fyp + nnm;
    if (q->ic[r].K(m, x, y, v, need, &k, q->ic[r].user) != 0) {
      rc = -1;
      break;
    }
    for (int j = 0; j < m; j++) o->F[j] += mu[r] * k.F[j];
    for (size_t j = 0; (need & CVAR_NEED_GRAD) && j < nm; j++)
      o->Fy[j] += mu[r] * k.Fy[j], o->Fp[j] += mu[r] * k.Fp[j];
    for (size_t j = 0; (need & CVAR_NEED_HESS) && j < nnm; j++)
      o->Fyy[j] += mu[r] * k.Fyy[j], o->Fyp[j] += mu[r] * k.Fyp[j], o->Fpp[j] += mu[r] * k.Fpp[j];
  }
  cv_free(buf);
  return rc;
}

/* L and its partials at one point (x, y, v). */
static int eval_point(const cv_problem *q, const double *mu, double x, const double *y,
                      const double *v, unsigned need, cv_partials *o) {
  if (eval_lagrangian(q, mu, 1, &x, y, v, need, o) != 0 || !isfinite(o->F[0])) return -1;
  return 0;
}

/* The reaction of the end node: the derivative of the discrete action with respect to its
 * values, R[i] = sum_k (h/2) w_k (F_y_i phi + F_y'_i phi') over the end element. */
static cv_status end_reaction(const cv_solver *s, const cv_problem *q, int end, double *R,
                              double *buf) {
  const cv_disc *d = &s->disc;
  int n = q->n;
  long e = end ? d->E - 1 : 0;
  int pe = cv_disc_edeg(d, e), P1 = pe + 1, l = end ? pe : 0;
  cv_rule r = cv_disc_rule(d, e);
  int m = r.q;
  double x0 = d->xe[e], h = d->xe[e + 1] - x0;
  double *x = buf, *y = x + m, *dy = y + (size_t)n * m, *F = dy + (size_t)n * m;
  double *Fy = F + m, *Fp = Fy + (size_t)n * m;
  const double *Ye = s->y + (size_t)cv_disc_enode(d, e) * n;
  for (int k = 0; k < m; k++) {
    x[k] = x0 + 0.5 * (r.tau[k] + 1.0) * h;
    for (int i = 0; i < n; i++) {
      double a = 0.0, b = 0.0;
      for (int j = 0; j < P1; j++) {
        a += Ye[j * n + i] * r.B[k * P1 + j];
        b += Ye[j * n + i] * r.D[k * P1 + j];
      }
      y[i * m + k] = a, dy[i * m + k] = b * 2.0 / h;
    }
  }
  cv_partials o = {F, Fy, Fp, NULL, NULL, NULL};
  const double *mu = s->mult + (size_t)d->nodes * q->nc; /* the integrals' multipliers */
  if (eval_lagrangian(q, mu, m, x, y, dy, CVAR_NEED_F | CVAR_NEED_GRAD, &o) != 0)
    return CVAR_ENONFINITE;
  for (int i = 0; i < n; i++) {
    double sum = 0.0;
    for (int k = 0; k < m; k++)
      sum += 0.5 * h * r.omega[k] *
             (Fy[i * m + k] * r.B[k * P1 + l] + Fp[i * m + k] * r.D[k * P1 + l] * 2.0 / h);
    if (!isfinite(sum)) return CVAR_ENONFINITE;
    R[i] = sum;
  }
  return CVAR_OK;
}

/* y' at the end from the momenta: Newton on F_y'(x, y, v) = P from v (the end element's
 * derivative). 0, or -1 when it does not converge (v then unchanged). */
static int slope_from_momenta(const cv_problem *q, const double *mu, double x, const double *y,
                              const double *P, double *v, double *buf) {
  int n = q->n;
  double *w = buf, *F = w + n, *Fy = F + 1, *Fp = Fy + n, *Fyy = Fp + n, *Fyp = Fyy + n * n;
  double *Fpp = Fyp + n * n, *r = Fpp + n * n;
  memcpy(w, v, (size_t)n * sizeof *w);
  for (int it = 0; it < 40; it++) {
    cv_partials o = {F, Fy, Fp, Fyy, Fyp, Fpp};
    if (eval_point(q, mu, x, y, w, CVAR_NEED_F | CVAR_NEED_GRAD | CVAR_NEED_HESS, &o) != 0)
      return -1;
    double dn = 0.0, vn = 0.0;
    for (int i = 0; i < n; i++) r[i] = Fp[i] - P[i];
    if (dense_solve(n, Fpp, r) != 0) return -1;
    for (int i = 0; i < n; i++) {
      w[i] -= r[i];
      dn = fmax(dn, fabs(r[i])), vn = fmax(vn, fabs(w[i]));
    }
    if (!isfinite(dn)) return -1;
    if (dn <= 4e-16 * (1.0 + vn)) {
      memcpy(v, w, (size_t)n * sizeof *v);
      return 0;
    }
  }
  return -1;
}

cv_status cv_ends_end_data(const cv_solver *s, const cv_problem *q, int end, int mode, double *H,
                           double *P, double *y, double *v, double *size) {
  const cv_disc *d = &s->disc;
  int n = q->n;
  long e = end ? d->E - 1 : 0, node = end ? d->nodes - 1 : 0;
  int pe = cv_disc_edeg(d, e), m = cv_disc_rule(d, e).q;
  double x = end ? d->b : d->a, h = d->xe[e + 1] - d->xe[e];
  double phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
  size_t need = (size_t)m * (4 * (size_t)n + 2) + 4 * (size_t)n * n + 8 * (size_t)n + 4;
  double *buf = cv_malloc(need * sizeof *buf), *R = buf ? buf + need - 2 * (size_t)n : NULL;
  cv_status st = CVAR_OK;
  const double *mu = s->mult + (size_t)d->nodes * q->nc; /* the integrals' multipliers */
  if (!buf) return CVAR_ENOMEM;
  /* the end values, and y' of the end element there */
  cv_lagrange(pe, cv_disc_eref(d, e)->xi, end ? 1.0 : -1.0, phi, dphi);
  for (int i = 0; i < n; i++) {
    double dv = 0.0;
    for (int l = 0; l <= pe; l++) dv += s->y[(size_t)(cv_disc_enode(d, e) + l) * n + i] * dphi[l];
    y[i] = s->y[(size_t)node * n + i];
    v[i] = dv * 2.0 / h;
  }
  if (mode == 0) {
    st = end_reaction(s, q, end, R, buf);
    for (int i = 0; i < n && !st; i++)
      P[i] = !q->fixed[2 * i + end] ? 0.0 : end ? R[i] : -R[i];           /* free: natural */
    if (!st && slope_from_momenta(q, mu, x, y, P, v, buf) != 0) mode = 1; /* element's y' */
  }
  double *F = buf, *Fy = F + 1, *Fp = Fy + n;
  cv_partials o = {F, Fy, Fp, NULL, NULL, NULL};
  if (!st && eval_point(q, mu, x, y, v, CVAR_NEED_F | CVAR_NEED_GRAD, &o) != 0)
    st = CVAR_ENONFINITE;
  if (!st) {
    double sum = -F[0], mag = fabs(F[0]);
    for (int i = 0; i < n; i++) {
      if (mode == 1) P[i] = Fp[i];
      sum += v[i] * P[i];
      mag += fabs(v[i] * P[i]);
    }
    *H = sum;
    *size = mag;
    if (!isfinite(sum)) st = CVAR_ENONFINITE;
  }
  cv_free(buf);
  return st;
}
