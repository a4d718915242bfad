/* src/core/cv_adapt.c — adaptive h-refinement driven by a two-mesh error estimate, theory
 * (AD-1).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

#define MAX_ROUNDS 80

/* Point solver s at the mesh with boundaries xe[0..E] (a user mesh on [0, 1]). */
static cv_status use_mesh(cv_solver *s, const double *xe, int E, double *t) {
  double a = xe[0], L = xe[E] - xe[0];
  for (int i = 0; i <= E; i++) t[i] = (xe[i] - a) / L;
  t[0] = 0.0;
  t[E] = 1.0;
  return cv_solver_set_mesh(s, E, t);
}

/* Start s (about to be solved on its mesh) from the solution held by `from`. */
static cv_status warm_start(cv_solver *s, const cv_problem *p, const cv_solver *from) {
  cv_disc d;
  char msg[160];
  cv_status st = cv_disc_init(&d, p, s, msg, sizeof msg);
  if (st) return st;
  int n = p->n, N = d.nodes;
  double *x = cv_malloc((size_t)N * sizeof *x), *ys = cv_malloc((size_t)N * n * sizeof *ys);
  double *y = cv_malloc((size_t)N * n * sizeof *y);
  if (!x || !ys || !y) st = CVAR_ENOMEM;
  if (!st) {
    cv_disc_fill_nodes(&d, x);
    st = cv_solver_eval(from, N, x, ys, NULL);
  }
  if (!st) {
    for (int j = 0; j < N; j++)
      for (int i = 0; i < n; i++) y[(size_t)j * n + i] = ys[(size_t)i * N + j];
    st = cv_solver_set_start(s, N * n, y);
  }
  cv_free(x);
  cv_free(ys);
  cv_free(y);
  cv_disc_free(&d);
  return st;
}

/* (AD-1) Solve on the current mesh and on a reference mesh whose element boundaries are
 * all its nodes (degree 1: every element halved). Element boundaries converge as O(h^2p),
 * so at the nodes the reference is far more accurate than the solution judged, and the
 * error of element e is estimated as max over its nodes of |y_h - y_ref| (degree 1: times
 * 4/3, Richardson for order 2). Elements above tol/4 are bisected. */
cv_status cv_adapt_run(cv_solver *s, const cv_problem *p) {
  cv_status st;
  cv_solver *f = cv_solver_new(&st);
  double *xe = NULL, *t = NULL, *xn = NULL, *yf = NULL, *eta = NULL;
  cv_meshspec spec0 = s->mesh;
  int E = 0, n = p->n;
  /* Newton iterations summed over the rounds (working meshes; the reference solves apart):
   * what the report gives, not the last round's count alone. */
  int it_work = 0, it_ref = 0;
  double tol = s->adapt_tol;
  if (!f) return CVAR_ENOMEM;
  f->degree = s->degree;
  f->nq = s->nq;
  f->rtol = s->rtol;
  f->atol = s->atol;
  f->maxit = s->maxit;
  f->method = s->method;
  /* the starting mesh, as the other setters describe it */
  st = cv_mesh_build(&s->mesh, p->a, p->b, &E, &xe, s->msg, sizeof s->msg);
  if (st) goto cleanup;
  s->mesh.t = NULL; /* spec0 keeps the caller's user mesh; restored at the end */
  s->mesh.nbreak = 0; /* breakpoints are already boundaries of xe, and stay so */
  for (s->rounds = 1; s->rounds <= MAX_ROUNDS; s->rounds++) {
    cv_free(t);
    /* room for the reference mesh too: E p elements (degree 1: 2E) >= E */
    t = cv_malloc((size_t)((s->degree == 1 ? 2 : s->degree) * E + 1) * sizeof *t);
    if (!t) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    st = use_mesh(s, xe, E, t);
    if (!st && s->rounds > 1) st = warm_start(s, p, f);
    if (st) goto cleanup;
    st = cv_solve_mesh(s, p);
    it_work += s->iterations;
    cv_solver_set_start(s, 0, NULL);
    if (st) {
      char why[320];
      memcpy(why, s->msg, sizeof why);
      why[sizeof why - 1] = '\0';
      cv_set_msg(s->msg, sizeof s->msg, "adaptive refinement, round %d (%d elements): %s",
                 s->rounds, E, why);
      goto cleanup;
    }
    /* the reference mesh: every node an element boundary (degree 1: halved) */
    int pd = s->disc.p, Nc = s->disc.nodes, Ef = pd == 1 ? 2 * E : Nc - 1;
    double *xf = cv_malloc((size_t)(Ef + 1) * sizeof *xf), *xc = cv_malloc((size_t)Nc * sizeof *xc);
    if (!xf || !xc) {
      cv_free(xf);
      cv_free(xc);
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    cv_disc_fill_nodes(&s->disc, xc);
    for (int j = 0, k = 0; j < Nc; j++) {
      xf[k++] = xc[j];
      if (pd == 1 && j + 1 < Nc) xf[k++] = 0.5 * (xc[j] + xc[j + 1]);
    }
    cv_free(xc);
    st = use_mesh(f, xf, Ef, t);
    cv_free(xf);
    if (!st) st = warm_start(f, p, s);
    if (!st) st = cv_solve_mesh(f, p);
    it_ref += f->iterations;
    cv_solver_set_start(f, 0, NULL);
    if (st) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "adaptive refinement, round %d: the solve on the reference mesh (%d "
                 "elements) failed: %s",
                 s->rounds, Ef, f->msg);
      s->status = st;
      goto cleanup;
    }
    /* indicators */
    int N = s->disc.nodes, pdeg = s->disc.p;
    cv_free(xn);
    cv_free(yf);
    cv_free(eta);
    xn = cv_malloc((size_t)N * sizeof *xn);
    yf = cv_malloc((size_t)N * n * sizeof *yf);
    eta = cv_calloc((size_t)E, sizeof *eta);
    if (!xn || !yf || !eta) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    cv_disc_fill_nodes(&s->disc, xn);
    st = cv_solver_eval(f, N, xn, yf, NULL);
    if (st) goto cleanup;
    /* degree >= 2: the reference's error at these points is O((h/p)^2p), negligible;
     * degree 1: Richardson for order 2 against the halved mesh */
    double factor = pdeg == 1 ? 4.0 / 3.0 : 1.0, est = 0.0;
    for (int e = 0; e < E; e++)
      for (int l = 0; l <= pdeg; l++) {
        long j = (long)e * pdeg + l;
        for (int i = 0; i < n; i++) {
          double d = factor * fabs(s->y[j * n + i] - yf[(size_t)i * N + j]);
          if (!(d <= eta[e])) eta[e] = d; /* NaN propagates */
        }
      }
    for (int e = 0; e < E; e++)
      if (!(eta[e] <= est)) est = eta[e];
    s->err_est = est;
    if (!isfinite(est)) {
      st = CVAR_ENONFINITE;
      cv_set_msg(s->msg, sizeof s->msg, "adaptive refinement: the error estimate is not finite");
      goto cleanup;
    }
    if (s->progress) {
      cv_progress info = {CVAR_PROGRESS_ROUND, s->iterations, s->gnorm, NAN, NAN, s->action,
                          s->rounds, E, est};
      if (s->progress(&info, s->progress_user) != 0) {
        st = CVAR_ECANCELLED;
        cv_set_msg(s->msg, sizeof s->msg, "cancelled by the progress callback after adaptive "
                   "round %d (%d elements, estimated max nodal error %.2g)", s->rounds, E, est);
        goto cleanup;
      }
    }
    if (est <= tol) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "converged on an adapted mesh of %d elements after %d round%s, %d Newton "
                 "iterations in all (and %d on the reference meshes); estimated max nodal "
                 "error %.2g <= %.2g",
                 E, s->rounds, s->rounds == 1 ? "" : "s", it_work, it_ref, est, tol);
      st = CVAR_OK;
      goto cleanup;
    }
    int marked = 0;
    for (int e = 0; e < E; e++) marked += eta[e] > 0.25 * tol;
    if (E + marked > s->adapt_max) {
      st = CVAR_EMAXITER;
      cv_set_msg(s->msg, sizeof s->msg,
                 "adaptive refinement reached the cap of %d elements after %d rounds with an "
                 "estimated max nodal error of %.2g > %.2g; use a higher degree or a looser "
                 "tolerance (or raise the cap: --max-elements, or the max_elements argument "
                 "of cv_solver_set_adapt)",
                 s->adapt_max, s->rounds, est, tol);
      goto cleanup;
    }
    double *xn2 = cv_malloc((size_t)(E + marked + 1) * sizeof *xn2);
    if (!xn2) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    int k = 0;
    for (int e = 0; e < E; e++) {
      xn2[k++] = xe[e];
      if (eta[e] > 0.25 * tol) xn2[k++] = 0.5 * (xe[e] + xe[e + 1]);
    }
    xn2[k] = xe[E];
    cv_free(xe);
    xe = xn2;
    E = k;
  }
  st = CVAR_EMAXITER;
  cv_set_msg(s->msg, sizeof s->msg,
             "adaptive refinement did not reach %.2g in %d rounds (estimated error %.2g)", tol,
             MAX_ROUNDS, s->err_est);
cleanup:
  if (it_work > 0) s->iterations = it_work; /* the total over the rounds */
  cv_free(s->mesh.t);
  s->mesh = spec0; /* the caller's mesh settings, for the next solve */
  cv_free(xe);
  cv_free(t);
  cv_free(xn);
  cv_free(yf);
  cv_free(eta);
  cv_solver_free(f);
  return st;
}
