/* src/core/cv_solver.c — the solver handle: options (setters), results (getters) and the
 * evaluation of the last solution. The solve itself is in cv_solve.c, its start in cv_start.c.
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

cv_solver *cv_solver_new(cv_status *why) {
  cv_solver *s = cv_calloc(1, sizeof *s);
  if (why) *why = s ? CVAR_OK : CVAR_ENOMEM;
  if (!s) return NULL;
  s->mesh.kind = CV_MESH_UNIFORM;
  s->mesh.elements = 100;
  s->mesh.grading = 1.0;
  s->degree = 1;
  s->rtol = s->atol = 1e-10;
  s->maxit = 50;
  s->continuation = 1;
  s->search_work = 2.0;
  s->adapt_max = 1000000;
  s->err_est = s->gfloor = NAN;
  s->status = CVAR_ESTATE;
  s->morse = -1;
  cv_set_msg(s->msg, sizeof s->msg, "no solve yet");
  return s;
}

CV_HOT void cv_solver_drop_factor(cv_solver *s) {
  cv_ldlt_free(s->ldlt);
  cv_free(s->gof);
  s->ldlt = NULL;
  s->gof = NULL;
}

void cv_solver_drop_results(cv_solver *s) {
  cv_free(s->y);
  cv_free(s->mult);
  s->y = s->mult = NULL;
  cv_disc_free(&s->disc); /* the factor stays: cv_newton_run checks it against the mesh */
  s->have = 0;
  s->ends_ok[0] = s->ends_ok[1] = 0;
}

void cv_solver_free(cv_solver *s) {
  if (!s) return;
  cv_solver_drop_factor(s);
  cv_free(s->mesh.t);
  cv_free(s->mesh.degrees);
  cv_free(s->mesh.breaks);
  cv_free(s->start);
  cv_solver_drop_results(s);
  cv_pathset_free(s->paths);
  cv_ends_state_free(s);
  cv_free(s);
}

static void mesh_reset(cv_solver *s, int kind, int elements) {
  cv_free(s->mesh.t);
  cv_free(s->mesh.degrees);
  s->mesh.t = NULL;
  s->mesh.degrees = NULL;
  s->mesh.kind = kind;
  s->mesh.elements = elements;
  s->handed_on = 0; /* a new mesh is no batch row's (cv_reuse_set_start marks one) */
}

cv_status cv_solver_set_elements(cv_solver *s, int elements) {
  if (!s || elements < 1) return CVAR_EINVAL;
  mesh_reset(s, CV_MESH_UNIFORM, elements);
  return CVAR_OK;
}

cv_status cv_solver_set_degree(cv_solver *s, int degree) {
  if (!s || degree < 1 || degree > CV_MAX_DEGREE) return CVAR_EINVAL;
  s->degree = degree;
  cv_free(s->mesh.degrees); /* every element: the hp degrees are dropped */
  s->mesh.degrees = NULL;
  return CVAR_OK;
}

cv_status cv_solver_set_quadrature_points(cv_solver *s, int q) {
  if (!s || q < 0 || q > CV_MAX_QUAD) return CVAR_EINVAL;
  s->nq = q;
  return CVAR_OK;
}

cv_status cv_solver_set_mesh_graded(cv_solver *s, int elements, double grading, int end) {
  if (!s || elements < 1 || !(grading >= 1.0 && grading <= 20.0) ||
      (end != CVAR_GRADE_A && end != CVAR_GRADE_B && end != CVAR_GRADE_BOTH))
    return CVAR_EINVAL;
  mesh_reset(s, CV_MESH_GRADED, elements);
  s->mesh.grading = grading;
  s->mesh.grade_end = end;
  return CVAR_OK;
}

cv_status cv_solver_set_mesh(cv_solver *s, int elements, const double *t) {
  if (!s || elements < 1 || !t || t[0] != 0.0 || t[elements] != 1.0) return CVAR_EINVAL;
  for (int i = 0; i < elements; i++)
    if (!(t[i + 1] > t[i])) return CVAR_EINVAL;
  double *c = cv_malloc((size_t)(elements + 1) * sizeof *c);
  if (!c) return CVAR_ENOMEM;
  memcpy(c, t, (size_t)(elements + 1) * sizeof *c);
  mesh_reset(s, CV_MESH_USER, elements);
  s->mesh.t = c;
  return CVAR_OK;
}

cv_status cv_solver_set_mesh_hp(cv_solver *s, int elements, const double *t, const int *degrees) {
  if (!s || elements < 1 || !degrees) return CVAR_EINVAL;
  int pmax = 1;
  for (int e = 0; e < elements; e++) {
    if (degrees[e] < 1 || degrees[e] > CV_MAX_DEGREE) return CVAR_EINVAL;
    if (degrees[e] > pmax) pmax = degrees[e];
  }
  int *c = cv_malloc((size_t)elements * sizeof *c);
  if (!c) return CVAR_ENOMEM;
  cv_status st = cv_solver_set_mesh(s, elements, t);
  if (st) {
    cv_free(c);
    return st;
  }
  memcpy(c, degrees, (size_t)elements * sizeof *c);
  s->mesh.degrees = c;
  s->degree = pmax;
  return CVAR_OK;
}

cv_status cv_solver_set_breakpoints(cv_solver *s, int nb, const double *xb) {
  if (!s || nb < 0 || (nb > 0 && !xb)) return CVAR_EINVAL;
  for (int i = 0; i < nb; i++)
    if (!isfinite(xb[i])) return CVAR_EINVAL;
  double *c = NULL;
  if (nb > 0) {
    c = cv_malloc((size_t)nb * sizeof *c);
    if (!c) return CVAR_ENOMEM;
    memcpy(c, xb, (size_t)nb * sizeof *c);
  }
  cv_free(s->mesh.breaks);
  s->mesh.breaks = c;
  s->mesh.nbreak = nb;
  return CVAR_OK;
}

cv_status cv_solver_set_tolerances(cv_solver *s, double rtol, double atol) {
  /* rtol below ~10 eps asks for more than double precision can give (STYLE 8). */
  if (!s || !(rtol >= 0) || !(atol >= 0) || !isfinite(rtol) || !isfinite(atol) ||
      (rtol == 0 && atol == 0) || (rtol > 0 && rtol < 10 * DBL_EPSILON) || rtol >= 1)
    return CVAR_EINVAL;
  s->rtol = rtol;
  s->atol = atol;
  return CVAR_OK;
}

static const char *const method_names[] = {"newton", "lbfgs", "tnewton", "mma",
                                           "ccsaq",  "slsqp", "auglag"};
#define NUM_METHODS (int)(sizeof method_names / sizeof method_names[0])

const char *cv_method_name(cv_method m) {
  return (int)m >= 0 && (int)m < NUM_METHODS ? method_names[m] : NULL;
}

cv_status cv_method_from_name(const char *name, cv_method *m) {
  for (int k = 0; name && k < NUM_METHODS; k++)
    if (strcmp(name, method_names[k]) == 0) {
      if (m) *m = (cv_method)k;
      return CVAR_OK;
    }
  return CVAR_EINVAL;
}

cv_status cv_solver_set_method(cv_solver *s, cv_method m) {
  if (!s || !cv_method_name(m)) return CVAR_EINVAL;
  s->method = m;
  return CVAR_OK;
}

cv_method cv_solver_get_method(const cv_solver *s) { return s ? s->method : CVAR_METHOD_NEWTON; }

cv_status cv_solver_set_progress(cv_solver *s, cv_progress_fn fn, void *user) {
  if (!s) return CVAR_EINVAL;
  s->progress = fn;
  s->progress_user = user;
  return CVAR_OK;
}

cv_status cv_solver_set_max_iterations(cv_solver *s, int maxit) {
  if (!s || maxit < 1) return CVAR_EINVAL;
  s->maxit = maxit;
  return CVAR_OK;
}

cv_status cv_solver_set_start(cv_solver *s, int len, const double *y) {
  if (!s || len < 0 || (len > 0 && !y)) return CVAR_EINVAL;
  double *c = NULL;
  if (len > 0) {
    c = cv_malloc((size_t)len * sizeof *c);
    if (!c) return CVAR_ENOMEM;
    memcpy(c, y, (size_t)len * sizeof *c);
  }
  cv_free(s->start);
  s->start = c;
  s->start_len = len;
  return CVAR_OK;
}

cv_status cv_solver_get_status(const cv_solver *s) { return s ? s->status : CVAR_EINVAL; }
const char *cv_solver_last_error(const cv_solver *s) { return s ? s->msg : "solver is NULL"; }
int cv_solver_get_num_nodes(const cv_solver *s) { return s && s->have ? s->disc.nodes : 0; }
int cv_solver_get_num_elements(const cv_solver *s) { return s && s->have ? s->disc.E : 0; }
int cv_solver_get_degree(const cv_solver *s) {
  return s && s->have ? s->disc.herm ? 2 * s->disc.p + 1 : s->disc.p : 0;
}
int cv_solver_get_degrees(const cv_solver *s, int *degrees) {
  if (!s || !s->have) return 0;
  if (degrees && s->disc.herm)
    for (long e = 0; e < s->disc.E; e++) degrees[e] = 2 * s->disc.p + 1;
  else if (degrees)
    for (long e = 0; e < s->disc.E; e++) degrees[e] = cv_disc_edeg(&s->disc, e);
  return s->disc.E;
}
int cv_solver_get_num_free(const cv_solver *s) {
  if (!s || !s->have) return 0;
  const cv_disc *d = &s->disc;
  long rows = d->ni; /* constraint rows: one per multiplier */
  for (long j = 0; j < d->nodes && d->nc > 0; j++) rows += cv_disc_lidx(d, j, 0) >= 0 ? d->nc : 0;
  /* free y unknowns minus constraints, and a moving end's position (ME-4) */
  return (int)(d->nfree - 2 * rows) + s->ends_dim;
}
cv_status cv_solver_get_interval(const cv_solver *s, double *a, double *b) {
  if (!s || !s->have) return s ? CVAR_ESTATE : CVAR_EINVAL;
  if (a) *a = s->disc.a;
  if (b) *b = s->disc.b;
  return CVAR_OK;
}
double cv_solver_get_action(const cv_solver *s) { return s ? s->action : NAN; }
double cv_solver_get_gradient_norm(const cv_solver *s) { return s ? s->gnorm : NAN; }
int cv_solver_get_num_iterations(const cv_solver *s) { return s ? s->iterations : 0; }
double cv_solver_get_time(const cv_solver *s) { return s ? s->time : 0.0; }
int cv_solver_get_morse_index(const cv_solver *s) {
  return !s ? -1 : s->morse >= 0 ? s->morse + s->ends_neg : s->morse; /* ends: ME-4 */
}
int cv_solver_get_degenerate(const cv_solver *s) { return s ? s->degenerate : 0; }

cv_status cv_solver_get_nodes(const cv_solver *s, double *x) {
  if (!s || !x) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  cv_disc_fill_nodes(&s->disc, x);
  return CVAR_OK;
}

cv_status cv_solver_get_values(const cv_solver *s, double *y) {
  if (!s || !y) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  if (s->disc.herm) return cv_hermite_nodal(s, 0, y);
  memcpy(y, s->y, (size_t)s->disc.ndof * sizeof *y);
  return CVAR_OK;
}

int cv_solver_get_num_qpoints(const cv_solver *s) {
  return s && s->have ? (int)cv_disc_num_qpoints(&s->disc) : 0;
}

/* The solution and its derivative on element e at reference coordinate t (E-3). */
static void eval_local(const cv_solver *s, long e, const double *phi, const double *dphi,
                       double *yv, double *dv) {
  const cv_disc *d = &s->disc;
  int n = d->n, P1 = cv_disc_edeg(d, e) + 1;
  double rh = 2.0 / (d->xe[e + 1] - d->xe[e]);
  const double *Ye = s->y + (size_t)cv_disc_enode(d, e) * n;
  for (int i = 0; i < n; i++) {
    double a = 0.0, b = 0.0;
    for (int l = 0; l < P1; l++) {
      a += Ye[l * n + i] * phi[l];
      b += Ye[l * n + i] * dphi[l];
    }
    yv[i] = a;
    dv[i] = b * rh;
  }
}

cv_status cv_solver_get_qpoints(const cv_solver *s, double *x, double *w, double *y, double *dy) {
  if (!s) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  const cv_disc *d = &s->disc;
  if (d->herm) return cv_hermite_qpoints(s, x, w, y, dy, NULL);
  int n = d->n;
  long nq = cv_disc_num_qpoints(d), idx = 0;
  double yv[64], dv[64];
  double *yb = yv, *db = dv, *big = NULL;
  if (n > 64) {
    big = cv_malloc(2 * (size_t)n * sizeof *big);
    if (!big) return CVAR_ENOMEM;
    yb = big;
    db = big + n;
  }
  for (long e = 0; e < d->E; e++) {
    double h = d->xe[e + 1] - d->xe[e];
    cv_rule R = cv_disc_rule(d, e), *r = &R;
    int P1 = cv_disc_edeg(d, e) + 1;
    for (int k = 0; k < r->q; k++, idx++) {
      if (x) x[idx] = d->xe[e] + 0.5 * (r->tau[k] + 1.0) * h;
      if (w) w[idx] = 0.5 * h * r->omega[k];
      if (y || dy) {
        eval_local(s, e, r->B + k * P1, r->D + k * P1, yb, db);
        for (int i = 0; i < n; i++) {
          if (y) y[i * nq + idx] = yb[i];
          if (dy) dy[i * nq + idx] = db[i];
        }
      }
    }
  }
  cv_free(big);
  return CVAR_OK;
}

cv_status cv_solver_eval(const cv_solver *s, int m, const double *x, double *y, double *dy) {
  if (!s || m < 0 || (m > 0 && (!x || !y))) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  const cv_disc *d = &s->disc;
  if (d->herm) return cv_hermite_eval(s, m, x, y, dy);
  int n = d->n;
  double phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
  double *buf = cv_malloc(2 * (size_t)n * sizeof *buf);
  if (!buf) return CVAR_ENOMEM;
  for (int k = 0; k < m; k++) {
    if (!(x[k] >= d->a && x[k] <= d->b)) {
      cv_free(buf);
      return CVAR_EINVAL;
    }
    long lo = 0, hi = d->E; /* find e with xe[e] <= x < xe[e+1] */
    while (hi - lo > 1) {
      long mid = (lo + hi) / 2;
      if (d->xe[mid] <= x[k])
        lo = mid;
      else
        hi = mid;
    }
    double h = d->xe[lo + 1] - d->xe[lo], t = 2.0 * (x[k] - d->xe[lo]) / h - 1.0;
    cv_lagrange(cv_disc_edeg(d, lo), cv_disc_eref(d, lo)->xi, t, phi, dphi);
    eval_local(s, lo, phi, dphi, buf, buf + n);
    for (int i = 0; i < n; i++) {
      y[i * m + k] = buf[i];
      if (dy) dy[i * m + k] = buf[n + i];
    }
  }
  cv_free(buf);
  return CVAR_OK;
}

cv_status cv_solver_get_multiplier_field(const cv_solver *s, int k, double *lambda) {
  if (!s || !lambda) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  const cv_disc *d = &s->disc;
  if (k < 0 || k >= d->nc) return CVAR_EINVAL;
  long N = d->nodes;
  for (long j = 0; j < N; j++) lambda[j] = s->mult[j * d->nc + k];
  /* An end node whose unknowns are all fixed has no multiplier: extrapolate with the
   * polynomial through the next K = max(2, p) nodes (error O(h^K) for a smooth field). */
  for (int end = 0; end < 2; end++) {
    if ((end ? d->lamL : d->lam0) >= 0) continue;
    int K = d->p > 2 ? d->p : 2;
    if (K > N - 1) K = (int)N - 1;
    long j0 = end ? N - 1 : 0, dir = end ? -1 : 1;
    double x0 = cv_disc_node_x(d, j0), v = 0.0;
    for (int a = 1; a <= K; a++) {
      double xa = cv_disc_node_x(d, j0 + dir * a), wgt = 1.0;
      for (int b = 1; b <= K; b++)
        if (b != a) {
          double xb = cv_disc_node_x(d, j0 + dir * b);
          wgt *= (x0 - xb) / (xa - xb);
        }
      v += wgt * lambda[j0 + dir * a];
    }
    lambda[j0] = v;
  }
  return CVAR_OK;
}

cv_status cv_solver_get_multiplier(const cv_solver *s, int k, double *mu) {
  if (!s || !mu) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  if (k < 0 || k >= s->disc.ni) return CVAR_EINVAL;
  *mu = s->mult[(size_t)s->disc.nodes * s->disc.nc + k];
  return CVAR_OK;
}

double cv_solver_get_error_estimate(const cv_solver *s) { return s ? s->err_est : NAN; }
int cv_solver_get_adapt_rounds(const cv_solver *s) { return s ? s->rounds : 0; }

cv_status cv_solver_set_continuation(cv_solver *s, int on) {
  if (!s) return CVAR_EINVAL;
  s->continuation = on != 0;
  return CVAR_OK;
}

int cv_solver_get_continuation_steps(const cv_solver *s) { return s ? s->csteps : 0; }

cv_status cv_solver_get_slopes(const cv_solver *s, double *dy) {
  if (!s || !dy) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  const cv_disc *d = &s->disc;
  if (d->herm) return cv_hermite_nodal(s, 1, dy);
  int n = d->n;
  double phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
  for (long j = 0; j < d->nodes; j++) { /* from the element on the node's left */
    long e = j == 0 ? 0 : cv_disc_node_elem(d, j - 1), j0 = cv_disc_enode(d, e);
    int pe = cv_disc_edeg(d, e), l = (int)(j - j0);
    const double *xi = cv_disc_eref(d, e)->xi;
    cv_lagrange(pe, xi, xi[l > pe ? pe : l], phi, dphi);
    double rh = 2.0 / (d->xe[e + 1] - d->xe[e]);
    for (int i = 0; i < n; i++) {
      double v = 0.0;
      for (int t = 0; t <= pe; t++) v += dphi[t] * s->y[(j0 + t) * n + i];
      dy[j * n + i] = v * rh;
    }
  }
  return CVAR_OK;
}

cv_status cv_solver_get_qpoints2(const cv_solver *s, double *x, double *w, double *y, double *dy,
                                 double *d2y) {
  if (!s) return CVAR_EINVAL;
  if (!s->have) return CVAR_ESTATE;
  if (s->disc.herm) return cv_hermite_qpoints(s, x, w, y, dy, d2y);
  if (d2y) return CVAR_EINVAL;
  return cv_solver_get_qpoints(s, x, w, y, dy);
}
