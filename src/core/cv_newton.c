/* src/core/cv_newton.c — Newton's method on the discrete Euler-Lagrange system with a line
 * search, theory (N-1)-(N-5).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* A pivot below this fraction of its diagonal entry is treated as a degenerate direction.
 * Round-off in a pivot of a well-posed problem is ~ eps * (condition of the leading block);
 * 1e-11 leaves three orders of magnitude for that while still catching exact invariances,
 * whose pivots come out at the 1e-14..1e-16 level (theory N-5). */
#define DEGENERATE_PIVOT 1e-11
#define MAX_BACKTRACK 40
#define ARMIJO 1e-4

typedef struct {
  const cv_disc *d;
  int *gof;      /* global dof of each free unknown */
  long *colptr;
  cv_ldlt *L;
  double *g, *gt, *delta, *Yt;
} newton_ws;

static void ws_free(newton_ws *w) {
  cv_free(w->gof);
  cv_free(w->colptr);
  cv_ldlt_free(w->L);
  cv_free(w->g);
  cv_free(w->gt);
  cv_free(w->delta);
  cv_free(w->Yt);
}

/* Column c of the upper triangle holds the rows from the first free unknown of the first
 * element containing c's node up to c (block-banded pattern, theory E-2). */
static cv_status ws_init(newton_ws *w, const cv_disc *d) {
  size_t nf = (size_t)d->nfree;
  memset(w, 0, sizeof *w);
  w->d = d;
  w->gof = cv_malloc((nf ? nf : 1) * sizeof *w->gof);
  w->colptr = cv_malloc((nf + 1) * sizeof *w->colptr);
  w->g = cv_malloc((nf ? nf : 1) * sizeof *w->g);
  w->gt = cv_malloc((nf ? nf : 1) * sizeof *w->gt);
  w->delta = cv_malloc((nf ? nf : 1) * sizeof *w->delta);
  w->Yt = cv_malloc((size_t)d->ndof * sizeof *w->Yt);
  if (!w->gof || !w->colptr || !w->g || !w->gt || !w->delta || !w->Yt) return CVAR_ENOMEM;
  /* gof: interior free indices are a shift of the global ones (E-2); ends by table. */
  int n = d->n, p = d->p;
  for (int i = 0; i < n; i++) {
    if (d->fix0[i] >= 0) w->gof[d->fix0[i]] = i;
    if (d->fix1[i] >= 0) w->gof[d->fix1[i]] = (d->nodes - 1) * n + i;
  }
  for (long f = d->nfree0, end = d->nfree0 + (long)(d->nodes - 2) * n; f < end; f++)
    w->gof[f] = (int)(f - d->nfree0 + n);
  w->colptr[0] = 0;
  for (long J = 0, e = 0; J < d->nodes; J++) {
    if (J > 1 && (J - 1) % p == 0) e++; /* e = first element containing node J */
    long r0 = e == 0 ? 0 : cv_disc_fidx(d, e * p * n);
    for (int i = 0; i < n; i++) {
      int c = cv_disc_fidx(d, J * n + i);
      if (c >= 0) w->colptr[c + 1] = w->colptr[c] + ((long)c - r0 + 1);
    }
  }
  w->L = cv_ldlt_new(d->nfree, w->colptr);
  return w->L ? CVAR_OK : CVAR_ENOMEM;
}

/* Mesh-independent residual: max |g_f| / m_f with lumped nodal weights m_f (N-3). */
static double residual_norm(const cv_disc *d, const double *g) {
  double r = 0.0;
  for (int f = 0; f < d->nfree; f++) {
    double v = fabs(g[f]) / d->mass[f];
    if (!(v <= r)) r = v;
  }
  return r;
}

static double residual_merit(const cv_disc *d, const double *g) {
  double s = 0.0;
  for (int f = 0; f < d->nfree; f++) {
    double v = g[f] / d->mass[f];
    s += v * v;
  }
  return 0.5 * s;
}

static const char *where_failed(cv_status st) {
  return st == CVAR_ECALLBACK ? "the integrand callback asked to abort"
                              : "the integrand (or a partial) is not finite";
}

cv_status cv_newton_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y) {
  newton_ws w;
  cv_assembler as;
  cv_status st;
  int nf = d->nfree;
  double S = 0.0, scale = 0.0;
  char detail[200] = "";

  s->iterations = 0;
  s->morse = -1;
  s->degenerate = 0;
  s->gnorm = NAN;
  s->action = NAN;
  memset(&as, 0, sizeof as);
  st = ws_init(&w, d);
  if (!st) st = cv_assembler_init(&as, p, d);
  if (st) {
    cv_set_msg(s->msg, sizeof s->msg, "out of memory setting up %d unknowns", nf);
    goto cleanup;
  }
  /* Absolute floor of the step tolerance: atol times the size of the solution (STYLE 8). */
  for (long i = 0; i < d->ndof; i++)
    if (fabs(Y[i]) > scale) scale = fabs(Y[i]);
  if (scale == 0.0) scale = 1.0;
  double atol = s->atol * scale, *Ax = cv_ldlt_values(w.L);

  st = cv_assemble(&as, Y, &S, w.g, w.colptr, Ax);
  if (st) {
    s->action = NAN;
    cv_set_msg(s->msg, sizeof s->msg, "%s at the initial guess; give a [guess] inside the "
               "integrand's domain", where_failed(st));
    goto cleanup;
  }
  s->action = S;
  s->gnorm = residual_norm(d, w.g);
  if (nf == 0) {
    s->morse = 0;
    cv_set_msg(s->msg, sizeof s->msg, "no free unknowns: the path is fixed by its end values");
    goto cleanup;
  }
  for (;;) {
    int neg;
    double dmin, dmax;
    double tf = cv_now();
    st = cv_ldlt_factor(w.L, &neg, &dmin, &dmax, detail, sizeof detail);
    if (st == CVAR_OK && !(dmin > DEGENERATE_PIVOT)) st = CVAR_ESINGULAR;
    if (st) {
      if (st == CVAR_ESINGULAR) {
        s->degenerate = 1;
        s->morse = neg;
        cv_set_msg(s->msg, sizeof s->msg,
                   "the Hessian is singular (pivot ratio %.1e at iteration %d): the action is "
                   "flat along some direction, as for an integrand invariant under "
                   "reparametrisation such as arc length sqrt(x'^2 + y'^2); use the energy "
                   "form x'^2 + y'^2 instead",
                   dmin, s->iterations);
      } else {
        cv_set_msg(s->msg, sizeof s->msg, "%s", detail);
      }
      goto cleanup;
    }
    s->morse = neg;
    for (int f = 0; f < nf; f++) w.delta[f] = -w.g[f];
    st = cv_ldlt_solve(w.L, w.delta);
    s->t_factor += cv_now() - tf;
    if (st) {
      cv_set_msg(s->msg, sizeof s->msg, "CHOLMOD solve failed");
      goto cleanup;
    }
    s->iterations++;
    /* Weighted RMS norm of the step, weights 1/(rtol |y| + atol) (N-4). */
    double wn = 0.0, slope = 0.0;
    for (int f = 0; f < nf; f++) {
      double v = w.delta[f] / (s->rtol * fabs(Y[w.gof[f]]) + atol);
      wn += v * v;
      slope += w.g[f] * w.delta[f];
    }
    wn = sqrt(wn / nf);
    if (!isfinite(wn)) {
      st = CVAR_ENONFINITE;
      cv_set_msg(s->msg, sizeof s->msg, "the Newton step is not finite");
      goto cleanup;
    }
    /* Line search: on S where the Hessian is positive definite (the step descends S),
     * else on the scaled residual merit phi = |g/m|^2 / 2, for which the Newton step is
     * always a descent direction (N-2). */
    double phi = residual_merit(d, w.g), alpha = 1.0, St = 0.0;
    int accepted = 0;
    for (int ls = 0; ls < MAX_BACKTRACK; ls++) {
      for (long i = 0; i < d->ndof; i++) w.Yt[i] = Y[i];
      for (int f = 0; f < nf; f++) w.Yt[w.gof[f]] += alpha * w.delta[f];
      double ta = cv_now();
      cv_status ast = cv_assemble(&as, w.Yt, &St, w.gt, w.colptr, Ax);
      s->t_assemble += cv_now() - ta;
      if (ast == CVAR_ECALLBACK) {
        st = ast;
        cv_set_msg(s->msg, sizeof s->msg, "%s", where_failed(ast));
        goto cleanup;
      }
      if (ast == CVAR_ENOMEM) {
        st = ast;
        cv_set_msg(s->msg, sizeof s->msg, "out of memory");
        goto cleanup;
      }
      if (ast == CVAR_OK) {
        double phit = residual_merit(d, w.gt);
        int ok_res = phit <= (1.0 - 2.0 * ARMIJO * alpha) * phi;
        int ok_S = neg == 0 && slope < 0 && St <= S + ARMIJO * alpha * slope;
        /* Near the solution S changes by less than its round-off; a step within the
         * tolerance is then taken in full. */
        if (ok_res || ok_S || wn <= 1.0) {
          accepted = 1;
          break;
        }
      }
      alpha *= 0.5;
    }
    if (!accepted) {
      st = CVAR_ESTALL;
      s->gnorm = residual_norm(d, w.g);
      cv_set_msg(s->msg, sizeof s->msg,
                 "no progress: the line search found no decrease along the Newton step at "
                 "iteration %d (scaled residual %.3g); try a better [guess], more elements, or "
                 "continuation",
                 s->iterations, s->gnorm);
      goto cleanup;
    }
    double *tmp = w.g;
    w.g = w.gt;
    w.gt = tmp;
    for (long i = 0; i < d->ndof; i++) Y[i] = w.Yt[i];
    S = St;
    s->action = S;
    s->gnorm = residual_norm(d, w.g);
    if (wn <= 1.0 && alpha == 1.0) {
      st = CVAR_OK;
      cv_set_msg(s->msg, sizeof s->msg, "converged in %d iterations", s->iterations);
      goto cleanup;
    }
    for (long i = 0; i < d->ndof; i++) {
      if (!(fabs(Y[i]) <= 1e12 * scale)) {
        st = CVAR_EDIVERGED;
        cv_set_msg(s->msg, sizeof s->msg,
                   "the iterates diverged (|y| above 1e12 times its initial size at iteration "
                   "%d); there may be no stationary path, or the guess is too far from it",
                   s->iterations);
        goto cleanup;
      }
    }
    if (s->iterations >= s->maxit) {
      st = CVAR_EMAXITER;
      cv_set_msg(s->msg, sizeof s->msg,
                 "not converged after %d iterations (last weighted step %.3g, scaled residual "
                 "%.3g); raise max_iterations or improve the guess",
                 s->iterations, wn, s->gnorm);
      goto cleanup;
    }
  }
cleanup:
  cv_assembler_free(&as);
  ws_free(&w);
  return st;
}
