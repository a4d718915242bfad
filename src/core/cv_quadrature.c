/* src/core/cv_quadrature.c — Gauss-Legendre rules, Gauss-Lobatto-Legendre nodes, Lagrange basis.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

#include "cv_internal.h"
#include "cv_rules_table.h"

/* The rules depend only on (p, q) and are the same for every solver. Gauss-Legendre rules
 * up to CV_MAX_QUAD points, the GLL nodes of every degree, and each degree's default
 * element (q = p + 1) with its end rules are constants (cv_rules_table.h, generated
 * by scripts/gen_rules.py, checked by tests/core/test_rules.c): no rule is computed on the
 * first solve of a process (docs/performance.md). Other (p, q) are computed once per
 * process, on first use, and copied from then on (theory Q-1, E-1). Writers hold the
 * lock; a reader sees a slot only after its ready flag is set with release order, so the
 * copy is never torn. */
static pthread_mutex_t rule_lock = PTHREAD_MUTEX_INITIALIZER;

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
void cv_gauss_legendre_compute(int q, double *t, double *w) {
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
void cv_gauss_lobatto_compute(int p, double *xi, double *w) {
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
    if (j == 0 || j == p)
      P = (j == 0 && (p % 2)) ? -1.0 : 1.0;
    else
      legendre(p, xi[j], &P, &dP);
    w[j] = 2.0 / (p * (p + 1.0) * P * P);
  }
}

void cv_gauss_legendre(int q, double *t, double *w) {
  if (q < 1 || q > CV_MAX_QUAD) {
    cv_gauss_legendre_compute(q, t, w);
    return;
  }
  memcpy(t, gl_t + q * (q - 1) / 2, (size_t)q * sizeof *t);
  memcpy(w, gl_w + q * (q - 1) / 2, (size_t)q * sizeof *w);
}

void cv_gauss_lobatto(int p, double *xi, double *w) {
  if (p < 1 || p > CV_MAX_DEGREE) {
    cv_gauss_lobatto_compute(p, xi, w);
    return;
  }
  memcpy(xi, gll_x + p * (p + 1) / 2 - 1, (size_t)(p + 1) * sizeof *xi);
  memcpy(w, gll_w + p * (p + 1) / 2 - 1, (size_t)(p + 1) * sizeof *w);
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

static void refelem_compute(cv_refelem *r, int p, int q) {
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

static struct {
  atomic_int ready;
  cv_refelem r;
} ref_cache[CV_MAX_DEGREE + 1][CV_MAX_QUAD + 1];

/* A (p, q) other than the default: computed once per process (out of line, with its
 * temporary, so that the default's frame stays small). */
static __attribute__((noinline)) void refelem_other(cv_refelem *r, int p, int q) {
  if (p < 1 || p > CV_MAX_DEGREE || q < 1 || q > CV_MAX_QUAD) {
    refelem_compute(r, p, q);
    return;
  }
  if (!atomic_load_explicit(&ref_cache[p][q].ready, memory_order_acquire)) {
    cv_refelem tmp;
    refelem_compute(&tmp, p, q); /* outside the lock: it takes the lock itself */
    pthread_mutex_lock(&rule_lock);
    if (!atomic_load_explicit(&ref_cache[p][q].ready, memory_order_relaxed)) {
      ref_cache[p][q].r = tmp;
      atomic_store_explicit(&ref_cache[p][q].ready, 1, memory_order_release);
    }
    pthread_mutex_unlock(&rule_lock);
  }
  *r = ref_cache[p][q].r;
}

/* Offsets of degree p's default element and end rules in cv_rules_table.h. */
static int ref_offset(int p) {
  int o = 0;
  for (int r = 1; r < p; r++) o += (r + 1) * (r + 1);
  return o;
}
static void end_offsets(int p, int *pts, int *tab) {
  *pts = *tab = 0;
  for (int r = 1; r < p; r++) *pts += 2 * r + 6, *tab += (2 * r + 6) * (r + 1);
}

void cv_refelem_init(cv_refelem *r, int p, int q) {
  if (p >= 1 && p <= CV_MAX_DEGREE && q == p + 1) { /* the default: constants */
    size_t nb = (size_t)q * (p + 1) * sizeof *r->B;
    r->p = p;
    r->q = q;
    cv_gauss_lobatto(p, r->xi, r->wl);
    cv_gauss_legendre(q, r->tau, r->omega);
    memcpy(r->B, ref_B + ref_offset(p), nb);
    memcpy(r->D, ref_D + ref_offset(p), nb);
    r->qs = 2 * q + 4;
    return;
  }
  refelem_other(r, p, q);
}

/* The singular-end rule on the element touching an end, in reference coordinates:
 * x = c +- u^2 with u from 0 to sqrt(h) maps Gauss point t_k in u to
 * tau_k = -+(1 - (t_k + 1)^2 / 2) whatever h, with weight omega_k = w_k (t_k + 1) in tau
 * (the end check of Q-3 uses it; the element rules of cv_disc.c are built per element). */
static struct {
  atomic_int ready;
  double tau[CV_MAX_QUAD], om[CV_MAX_QUAD];
  double B[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)], D[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)];
} end_cache[2][CV_MAX_DEGREE + 1][CV_MAX_QUAD + 1];

/* An end rule other than the default element's: computed once per process (out of line). */
static __attribute__((noinline)) void end_rule_compute(int p, int qs, int end) {
  if (!atomic_load_explicit(&end_cache[end][p][qs].ready, memory_order_acquire)) {
    double t[CV_MAX_QUAD], w[CV_MAX_QUAD], xi[CV_MAX_DEGREE + 1], wl[CV_MAX_DEGREE + 1];
    cv_gauss_legendre(qs, t, w);
    cv_gauss_lobatto(p, xi, wl);
    pthread_mutex_lock(&rule_lock);
    if (!atomic_load_explicit(&end_cache[end][p][qs].ready, memory_order_relaxed)) {
      for (int k = 0; k < qs; k++) {
        double s = 0.5 * (t[k] + 1.0) * (t[k] + 1.0) - 1.0;
        end_cache[end][p][qs].tau[k] = end ? -s : s;
        end_cache[end][p][qs].om[k] = w[k] * (t[k] + 1.0);
        cv_lagrange(p, xi, end ? -s : s, end_cache[end][p][qs].B + k * (p + 1),
                    end_cache[end][p][qs].D + k * (p + 1));
      }
      atomic_store_explicit(&end_cache[end][p][qs].ready, 1, memory_order_release);
    }
    pthread_mutex_unlock(&rule_lock);
  }
}

cv_rule cv_end_rule(int p, int qs, int end) {
  end = end != 0;
  if (qs == 2 * (p + 1) + 4) { /* the default element's: constants */
    int o, ot;
    end_offsets(p, &o, &ot);
    return end ? (cv_rule){qs, end1_t + o, end1_w + o, end1_B + ot, end1_D + ot}
               : (cv_rule){qs, end0_t + o, end0_w + o, end0_B + ot, end0_D + ot};
  }
  end_rule_compute(p, qs, end);
  return (cv_rule){qs, end_cache[end][p][qs].tau, end_cache[end][p][qs].om, end_cache[end][p][qs].B,
                   end_cache[end][p][qs].D};
}
