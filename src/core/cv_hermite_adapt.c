/* src/core/cv_hermite_adapt.c — automatic accuracy on C1 elements in rounds: solve,
 * estimate (H-7), then raise the one degree of the mesh where the solution is smooth or
 * halve the elements of the largest differences (H-8), until the estimate is at most the
 * tolerance or a cap says why not. SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_hermite.h"

#define H_MAX_ROUNDS 60
#define H_STALL      8 /* rounds without halving the best estimate */

double cv_hermite_smoothness(const cv_solver *s, long e) {
  const cv_disc *d = &s->disc;
  const cv_hermite *h = d->herm;
  int nc = d->n, n = nc / 2, nb = h->nb;
  double J = 0.5 * (d->xe[e + 1] - d->xe[e]), worst = 0.0;
  const double *Ye = s->y + (size_t)cv_disc_enode(d, e) * nc;
  for (int i = 0; i < n; i++) {
    double a[CV_HERMITE_NB];
    for (int k = 0; k < nb; k++) { /* a_k = sum_t C[k][t] c_t, slopes scaled by J (H-2) */
      a[k] = 0.0;
      for (int t = 0; t < nb; t++)
        a[k] += h->C[k * nb + t] * Ye[(t >> 1) * nc + 2 * i + (t & 1)] * (t & 1 ? J : 1.0);
    }
    int p = nb - 1;
    double top = fabs(a[p]) + fabs(a[p - 1]),
           low = fabs(a[p - 2]) + (p - 3 >= 1 ? fabs(a[p - 3]) : 0.0);
    double ratio = low > 0 ? top / low : top > 0 ? INFINITY : 0.0;
    worst = fmax(worst, ratio);
  }
  return worst;
}

/* The next mesh on [0, 1]: elements with eta >= thresh halved. */
static cv_status bisect(const cv_disc *d, const double *eta, double thresh, int *E, double **t) {
  int En = d->E;
  for (long e = 0; e < d->E; e++) En += eta[e] >= thresh;
  double *tn = cv_malloc((size_t)(En + 1) * sizeof *tn), a = d->a, L = d->b - d->a;
  if (!tn) return CVAR_ENOMEM;
  int k = 0;
  for (long e = 0; e < d->E; e++) {
    tn[k++] = (d->xe[e] - a) / L;
    if (eta[e] >= thresh) tn[k++] = (0.5 * (d->xe[e] + d->xe[e + 1]) - a) / L;
  }
  tn[0] = 0.0, tn[En] = 1.0;
  cv_free(*t);
  *t = tn;
  *E = En;
  return CVAR_OK;
}

/* The starting mesh on [0, 1] from the caller's settings. */
static cv_status start(cv_solver *s, const cv_problem *p, int *E, double **t) {
  double *xe = NULL;
  cv_status st = cv_mesh_build(&s->mesh, p->a, p->b, E, &xe, s->msg, sizeof s->msg);
  if (st) return st;
  *t = cv_malloc((size_t)(*E + 1) * sizeof **t);
  if (*t) {
    for (int k = 0; k <= *E; k++) (*t)[k] = (xe[k] - p->a) / (p->b - p->a);
    (*t)[0] = 0.0, (*t)[*E] = 1.0;
  }
  cv_free(xe);
  return *t ? CVAR_OK : CVAR_ENOMEM;
}

/* (H-8) One decision after an estimate above tol: raise the degree when every element
 * marked (eta >= thresh) is smooth and a higher degree exists (hp only); else halve the
 * marked ones. Returns 1 when the degree was raised, 0 when elements were halved. */
static int decide(cv_solver *s, const double *eta, double thresh, int *r) {
  if (!s->hp || *r >= CV_HERMITE_MAX_R) return 0;
  for (long e = 0; e < s->disc.E; e++)
    if (eta[e] >= thresh && !(cv_hermite_smoothness(s, e) <= 0.135)) return 0;
  (*r)++;
  return 1;
}

cv_status cv_hermite_adapt(cv_solver *s, const cv_problem *p) {
  cv_status st;
  cv_solver *w = cv_solver_new(&st); /* the last enriched solve: the next round's start */
  cv_meshspec spec0 = s->mesh;
  int degree0 = s->degree, E = 0, r = 1, stalled = 0, warm = 0;
  double tol = s->adapt_tol, best = INFINITY, t0 = cv_now(), *t = NULL, *eta = NULL;
  long iters = 0;
  if (!w) return CVAR_ENOMEM;
  /* the start: the caller's C1 degree (--adapt: it stays), else cubic (--tol raises it) */
  if (s->degree >= 3 && s->degree % 2 == 1 && s->degree <= 2 * CV_HERMITE_MAX_R + 1)
    r = (s->degree - 1) / 2;
  else if (!s->hp && cv_hermite_node_degree(s->degree, s->msg, sizeof s->msg) < 0) {
    st = CVAR_EINVAL;
    goto cleanup;
  }
  st = start(s, p, &E, &t);
  if (st) goto cleanup;
  s->mesh.t = NULL, s->mesh.degrees = NULL, s->mesh.nbreak = 0; /* spec0 keeps them */
  for (s->rounds = 1;; s->rounds++) {
    s->degree = 2 * r + 1;
    st = cv_solver_set_mesh(s, E, t);
    if (!st) st = cv_solver_set_degree(s, 2 * r + 1);
    if (!st && warm) st = cv_hermite_warm(s, p, w);
    if (st) goto cleanup;
    st = cv_solve_mesh(s, p);
    cv_solver_set_start(s, 0, NULL);
    iters += s->iterations;
    if (st) {
      char why[400];
      cv_set_msg(why, sizeof why, "%s", s->msg);
      cv_set_msg(s->msg, sizeof s->msg, "%s, round %d (%d elements of degree %d): %s",
                 s->hp ? "automatic accuracy" : "adaptive refinement", s->rounds, E, 2 * r + 1,
                 why);
      goto cleanup;
    }
    cv_free(eta);
    if (!(eta = cv_malloc((size_t)E * sizeof *eta))) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    double est;
    char why[400];
    cv_solver *tmp = cv_solver_new(&st);
    if (!tmp) goto cleanup;
    st = cv_hermite_estimate(s, p, tmp, &est, NULL, eta, why, sizeof why);
    cv_solver_free(w); /* the enriched solve starts the next round */
    w = tmp;
    if (st == CVAR_ENOMEM) goto cleanup;
    if (st) {
      s->err_est = NAN;
      cv_set_msg(s->msg, sizeof s->msg, "%s, round %d: %s",
                 s->hp ? "automatic accuracy" : "adaptive refinement", s->rounds, why);
      st = CVAR_EMAXITER;
      goto cleanup;
    }
    s->err_est = est;
    warm = 1;
    if (est <= tol) {
      cv_set_msg(
          s->msg, sizeof s->msg,
          "accuracy reached on %d elements of degree %d (%d nodes) after %d round%s, %ld "
          "Newton iterations in all; estimated max error (at the nodes and inside the elements) "
          "%.2g <= %.2g",
          E, 2 * r + 1, s->disc.nodes, s->rounds, s->rounds == 1 ? "" : "s", iters, est, tol);
      st = CVAR_OK;
      goto cleanup;
    }
    stalled = est <= 0.5 * best ? 0 : stalled + 1;
    best = fmin(best, est);
    double emax = 0.0;
    for (int e = 0; e < E; e++) emax = fmax(emax, eta[e]);
    double thresh = s->hp ? 0.25 * emax : fmin(0.25 * tol, emax);
    const char *stop = NULL;
    if (stalled >= H_STALL)
      stop = "the estimate stopped decreasing (round-off, or a solution the mesh cannot resolve)";
    else if (s->rounds >= H_MAX_ROUNDS)
      stop = "the number of rounds reached its cap";
    else if (s->time_limit > 0 && cv_now() - t0 > s->time_limit)
      stop = "the time limit was reached";
    if (!stop && !decide(s, eta, thresh, &r) && (st = bisect(&s->disc, eta, thresh, &E, &t)))
      goto cleanup;
    long size = s->hp ? (long)E * r + 1 : E;
    if (!stop && size > s->adapt_max) stop = "the next mesh would exceed the cap";
    if (stop) {
      cv_set_msg(
          s->msg, sizeof s->msg,
          "%s after %d round%s (cap %d %s): the estimated max error (at the nodes and inside the "
          "elements) reached is "
          "%.2g > %.2g",
          stop, s->rounds, s->rounds == 1 ? "" : "s", s->adapt_max, s->hp ? "nodes" : "elements",
          est, tol);
      st = CVAR_EMAXITER;
      goto cleanup;
    }
  }
cleanup:
  s->iterations = (int)(iters > 2000000000L ? 2000000000L : iters);
  cv_free(s->mesh.t);
  cv_free(s->mesh.degrees);
  s->mesh = spec0;
  s->degree = degree0;
  cv_free(t);
  cv_free(eta);
  cv_solver_free(w);
  return st;
}
