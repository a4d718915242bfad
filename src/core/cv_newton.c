/* src/core/cv_newton.c — Newton's method on the discrete Euler-Lagrange (or, with
 * constraints, Lagrangian) system with a line search, theory (N-1)-(N-6), (C-4).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* OB-3b: a stage's start set, the nodes sunk by more than this fraction of the deepest */
#define OB_STAGE_START 0.5

/* A pivot below this fraction of its diagonal entry is treated as a degenerate direction.
 * Round-off in a pivot of a well-posed problem is ~ eps * (condition of the leading block);
 * 1e-11 leaves three orders of magnitude for that while still catching exact invariances,
 * whose pivots come out at the 1e-14..1e-16 level (theory N-5). */
#define DEGENERATE_PIVOT 1e-11
#define MAX_BACKTRACK    40
#define ARMIJO           1e-4
#define REFINE_STEPS     2
/* The shifted factorisations of (N-6): a pivot ratio below this is not trusted for the
 * inertia, and the refinement stops after this many sweeps. */
#define SHIFT_PIVOT      1e-13
#define SHIFT_REFINE_MAX 100
/* N-4a: the chord test is tried after a step of weighted norm (N-4) up to CHORD_STEP /
 * sqrt(rtol): relative to |y| at most 0.1 sqrt(rtol), so that Newton's next step, of the
 * order of its square (quadratic convergence), is about rtol / 100 */
#define CHORD_STEP 0.1

typedef struct {
  const cv_disc *d;
  int *gof;          /* y dof of each unknown, or -1 - (index into the multipliers) */
  const int *colptr; /* the pattern, owned by L */
  cv_ldlt *L;
  double *g, *gt, *delta, *Yt, *Mt, *dreg, *corr;
  double *block;      /* g, gt, delta, Yt and Mt live in it (they swap roles, not blocks) */
  double *dsave, *x0; /* diagonal of H and first solve of the shifted factor (N-6), lazily */
  double tau;         /* shift of the factor in L (0: L is the factor of H itself) */
  int borrowed;       /* L and gof belong to the solver (its mesh's factor) */
} newton_ws;

static void ws_free(newton_ws *w) {
  if (!w->borrowed) {
    cv_free(w->gof);
    cv_ldlt_free(w->L);
  }
  cv_free(w->block);
  cv_free(w->dreg);
  cv_free(w->corr);
  cv_free(w->dsave);
  cv_free(w->x0);
}

/* Every array here is a fresh page range of a large solve, and faulting it in is a large
 * part of the run time (docs/performance.md): the refinement arrays exist only with
 * multipliers. */
/* The factor of the solver's own mesh is the solver's: made on the first run, reused by
 * the next runs on the same mesh (a retry, every continuation step) with its CHOLMOD
 * common and symbolic analysis. */
static cv_status ws_init(newton_ws *w, cv_solver *s, const cv_disc *d, size_t nmult, char *msg,
                         size_t len) {
  size_t nf = (size_t)d->nfree, one = nf ? nf : 1;
  memset(w, 0, sizeof *w);
  w->d = d;
  w->borrowed = d == &s->disc;
  /* the solver keeps its factor from solve to solve (cv_solve_mesh); it is used while the
   * mesh's pattern is the same (batch rows, repeated solves) */
  if (w->borrowed && s->ldlt && !cv_ldlt_matches(s->ldlt, d, s->gof)) cv_solver_drop_factor(s);
  if (w->borrowed && s->ldlt) {
    w->gof = s->gof;
    w->L = s->ldlt;
  } else {
    if (w->borrowed) cv_solver_drop_factor(s); /* a gof left by a failed attempt */
    w->gof = cv_malloc(one * sizeof *w->gof);
    if (w->borrowed) s->gof = w->gof;
    if (!w->gof) return CVAR_ENOMEM;
    cv_status st = cv_ldlt_new(d, w->gof, &w->L, msg, len);
    if (w->borrowed) {
      s->gof = w->gof;
      s->ldlt = w->L; /* NULL on failure: s->gof is freed with the mesh */
    }
    if (st) return st;
  }
  w->colptr = cv_ldlt_colptr(w->L);
  /* one allocation for the five: fewer calls, and fewer heap bytes for the first solve in
   * a process to touch (docs/performance.md) */
  w->block = cv_malloc((3 * one + (size_t)d->ndof + (nmult ? nmult : 1)) * sizeof *w->block);
  if (!w->block) return CVAR_ENOMEM;
  w->g = w->block;
  w->gt = w->g + one;
  w->delta = w->gt + one;
  w->Yt = w->delta + one;
  w->Mt = w->Yt + d->ndof;
  if (nmult) {
    w->dreg = cv_malloc(one * sizeof *w->dreg);
    w->corr = cv_malloc(one * sizeof *w->corr);
    if (!w->dreg || !w->corr) return CVAR_ENOMEM;
  }
  return CVAR_OK;
}

/* The scaled residual r_f = g_f / m_f with lumped nodal weights m_f (N-3): returns the
 * merit phi = |r|^2 / 2 of the line search (N-2) and sets *norm = max |r_f|, the
 * mesh-independent residual that is reported. One pass, multiplications only. */
static double residual(const cv_disc *d, const double *g, double *norm) {
  double s = 0.0, r = 0.0;
  for (int f = 0; f < d->nfree; f++) {
    double v = g[f] * d->imass[f];
    s += v * v;
    v = fabs(v);
    if (!(v <= r)) r = v;
  }
  *norm = r;
  return 0.5 * s;
}

/* The round-off floor of the scaled residual (theory N-3a): storing the unknowns x in
 * doubles moves each by up to eps |x_j|, which moves g_f by up to eps sum_j |K_fj| |x_j|;
 * scaled as in residual(), floor = eps max_f (1/m_f) sum_j |K_fj| |x_j|. K is the matrix in
 * Ax (upper triangle, column c holds rows c + 1 - length .. c; the last factored one,
 * assembled at the iterate before the last step or at the last iterate); acc and xa are
 * scratch of nfree. The other part of the floor, the rounding of the terms summed into g_f, costs an
 * evaluation of the integrand and is added on demand by cv_solver_residual_floor. */
static double residual_floor(const newton_ws *w, const double *Ax, const double *Y, const double *M,
                             double *acc, double *xa) {
  const cv_disc *d = w->d;
  int nf = d->nfree;
  for (int f = 0; f < nf; f++) {
    int gi = w->gof[f];
    xa[f] = fabs(gi >= 0 ? Y[gi] : M[-1 - gi]);
    acc[f] = 0.0;
  }
  for (int c = 0; c < nf; c++) {
    int k0 = w->colptr[c], len = w->colptr[c + 1] - k0, r0 = c + 1 - len;
    double xc = xa[c], sum = 0.0;
    for (int k = 0; k < len - 1; k++) {
      double a = fabs(Ax[k0 + k]);
      acc[r0 + k] += a * xc;
      sum += a * xa[r0 + k];
    }
    acc[c] += sum + fabs(Ax[k0 + len - 1]) * xc;
  }
  double fl = 0.0;
  for (int f = 0; f < nf; f++) fl = cv_fmax(fl, acc[f] * d->imass[f]);
  return DBL_EPSILON * fl;
}

static const char *where_failed(cv_status st) {
  return st == CVAR_ECALLBACK ? "the integrand callback asked to abort"
                              : "the integrand (or a partial) is not finite";
}

/* The system Newton solves: the Lagrangian's gradient and Hessian (cv_kkt_eval), or with a
 * homotopy h (unconstrained problems only) the convex combination of theory (HC-1):
 *   G_t = t g(Y) + (1 - t) w M (Y - Y0),   H_t = t H(Y) + (1 - t) w M,
 * M the lumped weights, whose solution is Y0 at t = 0 and the problem's at t = 1. */
static cv_status eval_system(cv_kkt *kkt, const cv_homotopy *h, const newton_ws *w, const double *Y,
                             const double *M, double *S, double *G, double *Ax, double *dreg) {
  cv_status st = cv_kkt_eval(kkt, Y, M, S, G, Ax, dreg);
  if (st || !h) return st;
  const cv_disc *d = w->d;
  double t = h->t, c = (1.0 - t) * h->w, pen = 0.0;
  for (int f = 0; f < d->nfree; f++) {
    int gi = w->gof[f];
    double dy = Y[gi] - h->Y0[gi];
    G[f] = t * G[f] + c * d->mass[f] * dy;
    pen += d->mass[f] * dy * dy;
  }
  *S = t * *S + 0.5 * c * pen;
  if (Ax) {
    for (long k = 0; k < w->colptr[d->nfree]; k++) Ax[k] *= t;
    for (int f = 0; f < d->nfree; f++) Ax[w->colptr[f + 1] - 1] += c * d->mass[f];
  }
  return CVAR_OK;
}

/* x <- K^{-1} x for the unregularised K = Kd + diag(dreg) from the factor of Kd, the
 * regularised (quasi-definite) matrix, by iterative refinement (C-4):
 * x_{k+1} = x_k + Kd^{-1} (b - K x_k) = x_k - Kd^{-1} (dreg .* x_k). */
static cv_status solve_refined(newton_ws *w, int nf, int regularised) {
  cv_status st = cv_ldlt_solve(w->L, w->delta);
  int any = 0; /* no regularised row (a penalty stage, OB-3): K is Kd, nothing to refine */
  for (int f = 0; f < nf && regularised && !any; f++) any = w->dreg[f] != 0.0;
  regularised = any;
  for (int it = 0; it < REFINE_STEPS && regularised && !st; it++) {
    for (int f = 0; f < nf; f++) w->corr[f] = -w->dreg[f] * w->delta[f];
    st = cv_ldlt_solve(w->L, w->corr);
    for (int f = 0; f < nf && !st; f++) w->delta[f] += w->corr[f];
  }
  return st;
}

/* Set the diagonal of the y rows to dsave + tau m (the multiplier rows keep theirs). */
static void set_shift(newton_ws *w, double *Ax, double tau) {
  const cv_disc *d = w->d;
  for (int f = 0; f < d->nfree; f++)
    if (w->gof[f] >= 0) Ax[w->colptr[f + 1] - 1] = w->dsave[f] + tau * d->mass[f];
}

/* A tiny or zero pivot of H need not mean that H is singular: LDL^T without pivoting
 * meets one whenever a leading block of H is singular, which happens when a conjugate
 * point of the discrete path falls on a mesh node although H itself is regular (theory
 * N-6). Factor H + sigma M and H - sigma M (M the lumped weights of the y rows, sigma far
 * below the problem's own eigenvalues, far above round-off): by Sylvester's law their
 * negative pivots count the eigenvalues of the pencil (H, M) below -sigma and below
 * +sigma. Equal counts prove that no eigenvalue lies in [-sigma, sigma): H is regular and
 * its inertia is that count. L then holds the factor of H + (sigma/4) M, from which
 * solve_step refines the step of H itself. Returns CVAR_OK with *neg, or CVAR_ESINGULAR
 * (the counts differ: H is (nearly) singular, or a shifted pivot is itself tiny). */
static cv_status factor_shifted(newton_ws *w, double *Ax, int *neg, char *detail, size_t len) {
  const cv_disc *d = w->d;
  int nf = d->nfree, cnt[2] = {-1, -2};
  double lam = 0.0;
  if (!w->dsave) w->dsave = cv_malloc((size_t)nf * sizeof *w->dsave);
  if (!w->x0) w->x0 = cv_malloc((size_t)nf * sizeof *w->x0);
  if (!w->corr) w->corr = cv_malloc((size_t)nf * sizeof *w->corr);
  if (!w->dsave || !w->x0 || !w->corr) return CVAR_ENOMEM;
  for (int f = 0; f < nf; f++) {
    w->dsave[f] = Ax[w->colptr[f + 1] - 1];
    if (w->gof[f] >= 0) lam = cv_fmax(lam, fabs(w->dsave[f]) * d->imass[f]);
  }
  /* lam ~ c F_y'y' (p^2 / h)^2 is the top of the spectrum; lam / (E p^2)^2 is the scale
   * of its bottom (c F_y'y' / (b - a)^2); sigma is 10^-6 of that, and at least 10^3 eps
   * lam so that the shift survives the round-off of the diagonal. */
  double ep = (double)d->E * d->p * d->p;
  double sigma = cv_fmax(1e-6 * lam / (ep * ep), 1e3 * DBL_EPSILON * lam);
  if (!(sigma > 0.0) || !isfinite(sigma)) return CVAR_ESINGULAR;
  for (int k = 0; k < 2; k++) {
    double dmin, dmax;
    set_shift(w, Ax, k ? -sigma : sigma);
    cv_status st = cv_ldlt_factor(w->L, &cnt[k], &dmin, &dmax, detail, len);
    if (st == CVAR_ESINGULAR || (st == CVAR_OK && !(dmin > SHIFT_PIVOT)))
      cnt[k] = -1 - k;
    else if (st)
      return st;
  }
  cv_status st = CVAR_ESINGULAR;
  if (cnt[0] == cnt[1]) {
    double dmin, dmax;
    int nq;
    w->tau = 0.25 * sigma;
    set_shift(w, Ax, w->tau);
    st = cv_ldlt_factor(w->L, &nq, &dmin, &dmax, detail, len);
    if (st == CVAR_OK && !(dmin > SHIFT_PIVOT)) st = CVAR_ESINGULAR;
    *neg = cnt[0];
  }
  if (st) w->tau = 0.0;
  set_shift(w, Ax, 0.0); /* the factor stays in L; Ax is H again */
  return st;
}

/* r <- b - K x, K the unregularised matrix: the upper triangle in Ax (column c holds rows
 * c + 1 - length .. c) plus dreg on the multiplier rows. */
static void residual_of(const newton_ws *w, const double *Ax, int constrained, const double *b,
                        const double *x, double *r) {
  int nf = w->d->nfree;
  for (int f = 0; f < nf; f++) r[f] = b[f] - (constrained ? w->dreg[f] * x[f] : 0.0);
  for (int c = 0; c < nf; c++) {
    int k0 = w->colptr[c], len = w->colptr[c + 1] - k0, r0 = c + 1 - len;
    double xc = x[c], acc = 0.0;
    for (int k = 0; k < len - 1; k++) {
      r[r0 + k] -= Ax[k0 + k] * xc;
      acc += Ax[k0 + k] * x[r0 + k];
    }
    r[c] -= acc + Ax[k0 + len - 1] * xc;
  }
}

/* delta <- K^{-1} delta with L the factor of the shifted matrix (N-6), by iterative
 * refinement on the true residual: x_{k+1} = x_k + L^{-1} (b - K x_k). The shift and the
 * element growth of the shifted factor (a leading block close to singular) both enter its
 * rate, at most 1/3 from the shift for the pencil's eigenvalues outside [-4 tau, 4 tau).
 * Stops when a correction is below 4 eps of the step, or stops shrinking. */
static cv_status solve_shifted(newton_ws *w, const double *Ax, int constrained) {
  int nf = w->d->nfree;
  cv_dcopy(w->x0, w->delta, (size_t)nf); /* b */
  cv_status st = cv_ldlt_solve(w->L, w->delta);
  double last = INFINITY;
  for (int it = 0; it < SHIFT_REFINE_MAX && !st; it++) {
    residual_of(w, Ax, constrained, w->x0, w->delta, w->corr);
    st = cv_ldlt_solve(w->L, w->corr);
    double change = 0.0, size = 0.0;
    for (int f = 0; f < nf && !st; f++) {
      w->delta[f] += w->corr[f];
      change = cv_fmax(change, fabs(w->corr[f]));
      size = cv_fmax(size, fabs(w->delta[f]));
    }
    if (!st && !isfinite(size)) st = CVAR_ENONFINITE;
    if (!st && (!(change > 4 * DBL_EPSILON * size) || !(change < 0.5 * last)))
      return change <= 1e-8 * size ? CVAR_OK : CVAR_ESINGULAR;
    last = change;
  }
  return st ? st : CVAR_ESINGULAR;
}

/* Yt = Y + alpha delta on the free unknowns; the fixed values of Yt were set once. */
static void apply_step(newton_ws *w, const double *Y, const double *M, double alpha) {
  const cv_disc *d = w->d;
  for (int f = 0; f < d->nfree; f++) {
    int gi = w->gof[f];
    if (gi >= 0)
      w->Yt[gi] = Y[gi] + alpha * w->delta[f];
    else
      w->Mt[-1 - gi] = M[-1 - gi] + alpha * w->delta[f];
  }
}

/* Weighted RMS norm of the step in y, weights 1/(rtol |y| + atol) (N-4), in the same pass
 * as the full-step trial point (apply_step with alpha = 1) into w->Yt, w->Mt, the slope
 * g . delta, the merit phi and the reported residual s->gnorm of the current iterate
 * (as in residual()), and the largest |y|. */
static double step_norm(cv_solver *s, newton_ws *w, const double *Yc, const double *Mc, double atol,
                        double *slope, double *phi, double *ymax) {
  const cv_disc *d = w->d;
  double wn = 0.0, sl = 0.0, ym = 0.0, rs = 0.0, rmax = 0.0, rtol = s->rtol;
  /* in locals: the stores into Yt would otherwise reload them at every unknown */
  const int *gof = w->gof, nf = d->nfree;
  const double *delta = w->delta, *g = w->g, *imass = d->imass;
  double *Yt = w->Yt, *Mt = w->Mt;
  int ny = 0;
  for (int f = 0; f < nf; f++) {
    int gi = gof[f];
    double df = delta[f], gf = g[f], r = gf * imass[f]; /* as in residual() */
    sl += gf * df;
    rs += r * r;
    r = fabs(r);
    if (!(r <= rmax)) rmax = r;
    if (gi < 0) {
      Mt[-1 - gi] = Mc[-1 - gi] + df;
      continue;
    }
    double yf = Yc[gi], ay = fabs(yf), v = df / (rtol * ay + atol);
    Yt[gi] = yf + df;
    wn += v * v;
    ny++;
    if (!(ay <= ym)) ym = ay;
  }
  *slope = sl;
  *phi = 0.5 * rs;
  *ymax = ym;
  s->gnorm = rmax;
  return sqrt(wn / (ny ? ny : 1));
}

/* Factor the Hessian in Ax (N-1, N-5, N-6): *neg its negative pivots. A tiny pivot is
 * first tried as a singular leading block (factor_shifted); a Hessian that stays singular
 * sets the degenerate flag, the Morse index so far and the message. */
static cv_status factor_hessian(cv_solver *s, newton_ws *w, double *Ax, int ncon, int *neg) {
  char detail[200] = "";
  double dmin, dmax;
  cv_status st = cv_ldlt_factor(w->L, neg, &dmin, &dmax, detail, sizeof detail);
  if (st == CVAR_OK && !(dmin > DEGENERATE_PIVOT)) st = CVAR_ESINGULAR;
  w->tau = 0.0;
  if (st == CVAR_ESINGULAR) { /* a singular leading block, or H itself (N-6) */
    int negs = *neg;
    cv_status sst = factor_shifted(w, Ax, &negs, detail, sizeof detail);
    if (sst == CVAR_OK)
      st = CVAR_OK, *neg = negs;
    else if (sst != CVAR_ESINGULAR)
      st = sst;
  }
  if (st == CVAR_ESINGULAR) {
    s->degenerate = 1;
    s->morse = *neg - ncon;
    cv_set_msg(s->msg, sizeof s->msg,
               ncon > 0 ? "the Hessian of the Lagrangian is singular (pivot ratio %.1e at "
                          "iteration %d): the constraints may be dependent or the action flat "
                          "along them"
                        : "the Hessian is singular (pivot ratio %.1e at iteration %d): the "
                          "action is flat along some direction. Either the integrand is "
                          "invariant under reparametrisation, as arc length sqrt(x'^2 + y'^2) "
                          "is (use the energy form x'^2 + y'^2 instead), or one end is a "
                          "conjugate point of the other (then there is no stationary path "
                          "between these ends, or a whole family of them)",
               dmin, s->iterations);
  } else if (st) {
    cv_set_msg(s->msg, sizeof s->msg, "%s", detail);
  }
  return st;
}

/* The trial point of a line search and what it found (N-2). */
typedef struct {
  double alpha, St, phit, rnt;
  int stale; /* accepted on S alone: phi and the residual of the new iterate are owed */
} trial;

/* Backtracking along delta from (Yc, Mc): on S where the Hessian is positive definite and
 * nothing is constrained (use_S: the step descends S), else on the scaled residual merit
 * phi = |g/m|^2 / 2, for which the Newton step is always a descent direction (N-2). The
 * full-step trial point is already in w->Yt, w->Mt. Returns CVAR_OK with the accepted
 * point in w->Yt, w->Mt, w->gt and *t; CVAR_ESTALL when no step was accepted (no message);
 * an error of the integrand with its message. */
static cv_status line_search(cv_solver *s, cv_kkt *kkt, const cv_homotopy *h, newton_ws *w,
                             const double *Yc, const double *Mc, double *Ax, double S, double slope,
                             double phi, double wn, int use_S, int timed, int noH, const double *pm,
                             trial *t) {
  t->alpha = 1.0, t->St = t->phit = t->rnt = 0.0, t->stale = 0;
  for (int ls = 0; ls < MAX_BACKTRACK; ls++) {
    if (ls > 0) apply_step(w, Yc, Mc, t->alpha);
    if (kkt->active && cv_kkt_step_crosses(kkt, Yc, w->Yt)) { /* OB-5 */
      t->alpha *= 0.5;
      continue;
    }
    double ta = timed ? cv_now() : 0.0;
    /* A step within the tolerance is the last one (taken in full below): the Hessian
     * there would not be used, so only F and the gradient are evaluated. */
    /* (noH: N-4a, the chord test at the trial point needs its gradient alone) */
    double *Axt = (wn <= 1.0 || noH) && !kkt->active ? NULL : Ax; /* OB-2: the set may change */
    cv_status ast = eval_system(kkt, h, w, w->Yt, w->Mt, &t->St, w->gt, Axt, w->dreg);
    if (timed) s->t_assemble += cv_now() - ta;
    if (ast == CVAR_ECALLBACK || ast == CVAR_ENOMEM) {
      cv_set_msg(s->msg, sizeof s->msg, "%s",
                 ast == CVAR_ENOMEM ? "out of memory" : where_failed(ast));
      return ast;
    }
    if (ast == CVAR_OK) {
      /* Near the solution S changes by less than its round-off; a step within the
       * tolerance is then taken in full. */
      if ((use_S && t->St <= S + ARMIJO * t->alpha * slope) || wn <= 1.0) {
        t->stale = 1;
        return CVAR_OK;
      }
      if (pm) { /* OB-3a: the penalised action P, pm = {P at the iterate, its slope} */
        double pen;
        if (cv_kkt_penalty(kkt, w->Yt, w->Mt, NULL, &pen, NULL) == 0 &&
            t->St + pen <= pm[0] + ARMIJO * t->alpha * pm[1]) {
          t->stale = 1;
          return CVAR_OK;
        }
      }
      t->phit = residual(w->d, w->gt, &t->rnt);
      if (t->phit <= (1.0 - 2.0 * ARMIJO * t->alpha) * phi) return CVAR_OK;
    }
    t->alpha *= 0.5;
  }
  return CVAR_ESTALL;
}

/* N-4a: the weighted RMS norm (N-4) of the step in w->delta at the iterate Yc. */
static double chord_norm(const cv_solver *s, const newton_ws *w, const double *Yc, double atol) {
  double wn = 0.0;
  int ny = 0;
  for (int f = 0; f < w->d->nfree; f++) {
    int gi = w->gof[f];
    if (gi < 0) continue;
    double v = w->delta[f] / (s->rtol * fabs(Yc[gi]) + atol);
    wn += v * v;
    ny++;
  }
  return sqrt(wn / (ny ? ny : 1));
}

/* Workspace and constraint system of one Newton run from (Y, M): the trial buffers start
 * as copies (their fixed values are then set once), pointwise constraints are checked at
 * the fixed ends and the multipliers initialised (C-5). *ncon: constraint rows. */
static cv_status run_init(cv_solver *s, const cv_problem *p, cv_disc *d, newton_ws *w, cv_kkt *kkt,
                          const double *Y, double *M, size_t nmult, int *ncon) {
  int nf = d->nfree;
  memset(kkt, 0, sizeof *kkt);
  cv_status st = ws_init(w, s, d, nmult, s->msg, sizeof s->msg);
  if (!st) st = cv_kkt_init(kkt, p, d, w->colptr);
  if (st) {
    if (st == CVAR_ENOMEM)
      cv_set_msg(s->msg, sizeof s->msg, "out of memory setting up %d unknowns", nf);
    return st;
  }
  *ncon = 0;
  for (int f = 0; f < nf; f++) *ncon += w->gof[f] < 0;
  /* Two buffers swap roles as iterate and trial; the trial's fixed values are set once. */
  cv_dcopy(w->Yt, Y, (size_t)d->ndof);
  if (nmult) cv_dcopy(w->Mt, M, nmult);
  if (d->nc > 0) {
    st = cv_kkt_check_ends(kkt, Y, s->msg, sizeof s->msg);
    if (st) return st;
  }
  if (*ncon > 0) {
    st = cv_kkt_init_multipliers(kkt, Y, M);
    if (st) cv_set_msg(s->msg, sizeof s->msg, "%s at the initial guess", where_failed(st));
  }
  return st;
}

/* eps > 0: a penalty stage (OB-3); after_stage: one that follows a converged stage, which
 * starts from the deepest-sunk nodes (OB-3b). */
static cv_status newton_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y, double *M,
                            const cv_homotopy *h, double eps, int after_stage) {
  newton_ws w;
  cv_kkt kkt;
  cv_status st;
  int nf = d->nfree, ncon = 0;
  size_t nmult = (size_t)d->nodes * d->nc + d->ni;
  double S = 0.0, scale = 0.0;
  int stale = 0;           /* see the first residual below */
  double *Yc = Y, *Mc = M; /* the current iterate (see the swap below) */
  double *Ax = NULL;       /* the matrix, in the factor's storage */

  s->iterations = 0;
  s->morse = -1;
  s->degenerate = 0;
  s->gnorm = s->gfloor = NAN;
  s->action = NAN;
  int have_K = 0; /* Ax holds an assembled matrix (for the residual's floor) */
  st = run_init(s, p, d, &w, &kkt, Y, M, nmult, &ncon);
  if (st) goto cleanup;
  kkt.eps = eps;
  int constrained = ncon > 0;
  /* N-4a: in the rounds of --tol (whose answers the estimate judges), a full step small
   * enough to be Newton's next-to-last is followed by the chord step from its factor */
  int chord_ok = s->adapt_tol > 0 && s->hp && !s->polish && !constrained && !h && !kkt.active;
  /* Absolute floor of the step tolerance: atol times the size of the solution (STYLE 8). */
  for (long i = 0; i < d->ndof; i++)
    if (fabs(Y[i]) > scale) scale = fabs(Y[i]);
  if (scale == 0.0) scale = 1.0;
  double atol = s->atol * scale;
  Ax = cv_ldlt_values(w.L);

  /* Phase timers for bench/ (t_assemble, t_factor): on a system of a few unknowns the
   * clock reads were an eighth of the solve, so small systems are not split. */
  int timed = nf >= 512;
  double ta = timed ? cv_now() : 0.0;
  st = eval_system(&kkt, h, &w, Y, M, &S, w.g, Ax, w.dreg);
  if (timed) s->t_assemble += cv_now() - ta;
  if (st) {
    s->action = NAN;
    cv_set_msg(s->msg, sizeof s->msg,
               "%s at the initial guess; give a [guess] inside the "
               "integrand's domain",
               where_failed(st));
    goto cleanup;
  }
  s->action = S;
  have_K = 1;
  kkt.frozen = kkt.active != NULL; /* OB-2: set at the start, then by cv_kkt_update_active */
  if (kkt.active && cv_kkt_update_active(&kkt, Y, M) < 0) kkt.gscale = 0.0; /* its gscale */
  if (kkt.active && after_stage && eps > 0) {
    /* OB-3b: a stage after a converged one starts from the nodes sunk deepest into the
     * obstacle only (a set too small, which a step corrects at once where the path then
     * crosses the obstacle), not from all the nodes the softer penalty let it sink at
     * (a set too large, which steps shrink a few nodes at a time) */
    if (cv_kkt_stage_start(&kkt, Y, OB_STAGE_START) < 0) {
      st = CVAR_ENONFINITE;
      cv_set_msg(s->msg, sizeof s->msg, "an inequality constraint is not finite at the start");
      goto cleanup;
    }
    st = eval_system(&kkt, h, &w, Y, M, &S, w.g, Ax, w.dreg);
    if (st) {
      cv_set_msg(s->msg, sizeof s->msg, "%s at the start of a stage", where_failed(st));
      goto cleanup;
    }
  }
  double phi = residual(d, w.g, &s->gnorm);
  /* After a step accepted on S alone the merit phi and the reported residual of the new
   * iterate are left to the next pass over g (the step norm below), not computed in a pass
   * of their own; "stale" says they are owed (computed at any exit). */
  if (nf == 0) {
    s->morse = 0;
    cv_set_msg(s->msg, sizeof s->msg, "no free unknowns: the path is fixed by its end values");
    goto cleanup;
  }
  for (;;) {
    int neg;
    double tf = timed ? cv_now() : 0.0;
    st = factor_hessian(s, &w, Ax, ncon, &neg);
    if (st) goto cleanup;
    /* Each constraint row adds one negative pivot to a quasi-definite KKT matrix (N-1). */
    s->morse = neg - ncon;
    if (w.tau == 0.0 && !constrained) { /* the step -H^{-1} g, the negation in the solve */
      st = cv_ldlt_solve_neg(w.L, w.g, w.delta);
    } else {
      for (int f = 0; f < nf; f++) w.delta[f] = -w.g[f];
      st = w.tau != 0.0 ? solve_shifted(&w, Ax, constrained) : solve_refined(&w, nf, constrained);
    }
    if (timed) s->t_factor += cv_now() - tf;
    if (st) {
      cv_set_msg(s->msg, sizeof s->msg, "%s",
                 st == CVAR_ESINGULAR ? "the Hessian is nearly singular: the refinement of "
                                        "the step from its shifted factor did not converge"
                                      : "CHOLMOD solve failed");
      goto cleanup;
    }
    s->iterations++;
    double slope, ymax, wn = step_norm(s, &w, Yc, Mc, atol, &slope, &phi, &ymax);
    stale = 0;
    if (!(ymax <= 1e12 * scale)) {
      st = CVAR_EDIVERGED;
      cv_set_msg(s->msg, sizeof s->msg,
                 "the iterates diverged (|y| above 1e12 times its initial size at iteration "
                 "%d); there may be no stationary path, or the guess is too far from it",
                 s->iterations);
      goto cleanup;
    }
    if (!isfinite(wn)) {
      st = CVAR_ENONFINITE;
      cv_set_msg(s->msg, sizeof s->msg, "the Newton step is not finite");
      goto cleanup;
    }
    if (s->polish && wn <= 1.0 && !kkt.active) {
      /* HP-2a: an enriched solve's last step, within the tolerance from a start already
       * within it: taken in full (step_norm put it in w.Yt, w.Mt) without the evaluation
       * at its end, which would only confirm it; the action and residual reported are
       * those of the iterate it started from */
      double *tmp = Yc;
      Yc = w.Yt, w.Yt = tmp;
      tmp = Mc, Mc = w.Mt, w.Mt = tmp;
      have_K = 0; /* no residual floor: nothing reports it */
      st = CVAR_OK;
      cv_set_msg_converged(s->msg, sizeof s->msg, s->iterations);
      goto cleanup;
    }
    /* OB-3a: in a penalty stage at a minimum (the reduced Hessian positive definite) the
     * Newton step in y is the semismooth Newton step of the penalised action P, which is
     * then the merit: the residual's norm need not fall along a step that changes the
     * active set, and in a fourth-order problem it often does not */
    double pm[2], *pmp = NULL;
    if (kkt.active && kkt.eps > 0 && kkt.all_ineq && d->ni == 0 && neg == ncon) {
      double pen, dsl, sly = 0.0;
      for (int f = 0; f < nf; f++)
        if (w.gof[f] >= 0) sly += w.g[f] * w.delta[f];
      /* a decrease of P below its round-off cannot be seen: then the residual alone */
      if (cv_kkt_penalty(&kkt, Yc, Mc, w.Yt, &pen, &dsl) == 0 &&
          sly + dsl < -1e-10 * (fabs(S + pen) + 1.0))
        pm[0] = S + pen, pm[1] = sly + dsl, pmp = pm;
    }
    trial t;
    int chord = chord_ok && w.tau == 0.0 && wn > 1.0 && wn <= CHORD_STEP / sqrt(s->rtol);
    st = line_search(s, &kkt, h, &w, Yc, Mc, Ax, S, slope, phi, wn,
                     neg == 0 && !constrained && slope < 0, timed, chord, pmp, &t);
    if (st == CVAR_ESTALL)
      cv_set_msg(s->msg, sizeof s->msg,
                 "no progress: the line search found no decrease along the Newton step at "
                 "iteration %d (scaled residual %.3g); try a better [guess], more elements, or "
                 "continuation",
                 s->iterations, s->gnorm);
    if (st) goto cleanup;
    double alpha = t.alpha;
    stale = t.stale;
    if (s->progress) {
      /* after the step: the residual is the one of the iterate it started from */
      cv_progress info = {CVAR_PROGRESS_NEWTON,
                          s->iterations,
                          s->gnorm,
                          wn,
                          alpha,
                          t.St,
                          s->adapt_tol > 0 ? s->rounds : 0,
                          d->E,
                          NAN};
      if (s->progress(&info, s->progress_user) != 0) {
        st = CVAR_ECANCELLED;
        cv_set_msg(s->msg, sizeof s->msg,
                   "cancelled by the progress callback after iteration "
                   "%d",
                   s->iterations);
        goto cleanup; /* the iterate the step started from stays the result */
      }
    }
    double *tmp = w.g;
    w.g = w.gt;
    w.gt = tmp;
    tmp = Yc, Yc = w.Yt, w.Yt = tmp;
    tmp = Mc, Mc = w.Mt, w.Mt = tmp;
    S = t.St;
    s->action = S;
    if (!stale) phi = t.phit, s->gnorm = t.rnt;
    /* With inequalities, converged also means that the last evaluation kept the active set
     * of the one before (OB-2): the step was Newton's for the final set. */
    int done = wn <= 1.0 && alpha == 1.0;
    if (chord) {
      /* N-4a: the chord step -H_k^{-1} g(y_k+1) from the last factor; within the tolerance,
       * it is taken and the solve ends (its error is that of the Newton step there times
       * the relative change of H over the step before); else H at y_k+1 as usual */
      st = alpha == 1.0 ? cv_ldlt_solve_neg(w.L, w.g, w.delta) : CVAR_OK;
      if (!st && alpha == 1.0 && chord_norm(s, &w, Yc, atol) <= 1.0) {
        for (int f = 0; f < nf; f++) Yc[w.gof[f]] += w.delta[f];
        s->iterations++;
        done = 1;
      } else {
        st = eval_system(&kkt, h, &w, Yc, Mc, &S, w.g, Ax, w.dreg);
        if (st) {
          cv_set_msg(s->msg, sizeof s->msg, "%s", where_failed(st));
          goto cleanup;
        }
        s->action = S;
        phi = residual(d, w.g, &s->gnorm);
        stale = 0;
      }
    }
    if (kkt.active) {
      /* OB-2: the step was Newton's for the active set of the iterate it started from (the
       * line search kept it); the new iterate decides the set again, and a changed set
       * means a new system at the same point, and one more step at least. */
      long ch = cv_kkt_update_active(&kkt, Yc, Mc);
      if (ch < 0) {
        st = CVAR_ENONFINITE;
        cv_set_msg(s->msg, sizeof s->msg, "an inequality constraint is not finite at iteration %d",
                   s->iterations);
        goto cleanup;
      }
      if (ch > 0) {
        done = 0;
        if (!h && kkt.nchg <= kkt.chgcap) {
          st = cv_kkt_apply_changes(&kkt, Yc, Mc, w.g, Ax, w.dreg); /* OB-2c */
        } else {
          kkt.frozen = 0;
          st = eval_system(&kkt, h, &w, Yc, Mc, &S, w.g, Ax, w.dreg);
          kkt.frozen = 1;
        }
        if (st) {
          cv_set_msg(s->msg, sizeof s->msg, "%s", where_failed(st));
          goto cleanup;
        }
        s->action = S;
        phi = residual(d, w.g, &s->gnorm);
        stale = 0;
      }
    }
    if (done || s->iterations >= s->maxit) {
      phi = residual(d, w.g, &s->gnorm); /* reported */
      stale = 0;
    }
    if (done) {
      st = CVAR_OK;
      cv_set_msg_converged(s->msg, sizeof s->msg, s->iterations);
      goto cleanup;
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
  if (stale) residual(d, w.g, &s->gnorm);
  if (have_K && Ax && nf > 0 && w.delta && w.gt && isfinite(s->gnorm)) {
    double fl = residual_floor(&w, Ax, Yc, Mc, w.delta, w.gt); /* both free here */
    s->gfloor = isfinite(fl) ? fl : NAN;                       /* 0 when every unknown is 0 */
  }
  if (w.Yt && Yc != Y) { /* the latest iterate lives in our buffer: hand it back */
    cv_dcopy(Y, Yc, (size_t)d->ndof);
    w.Yt = Yc;
  }
  if (w.Mt && Mc != M) {
    if (nmult) cv_dcopy(M, Mc, nmult);
    w.Mt = Mc;
  }
  cv_kkt_free(&kkt);
  ws_free(&w);
  return st;
}

/* Obstacles (OB-3): the exact active-set iteration first, for a few iterations (a warm
 * start converges in them); otherwise, from the same start, the path-following in the
 * penalty eps = 1e-3 .. 1e-9 (relative to the path's stiffness on the whole interval),
 * whose active set (where G is violated) moves to the contact set in a few Newton steps
 * on any mesh, and the exact iteration from its end. The exact one alone from a poor
 * start removes one node per iteration from a contact set that is too large (measured:
 * 2 nodes per iteration out of 3189 at 10^4 elements). A softer start (eps = 1) let a path
 * sink through the unit disk, whose constraint gradient vanishes at its centre line. */
#define OB_DIRECT_ITERATIONS 12
static cv_status run_staged(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y, double *M) {
  static const double eps[] = {1e-3, 1e-6, 1e-9, 0.0};
  const size_t neps = sizeof eps / sizeof *eps;
  size_t ny = (size_t)d->ndof, nm = (size_t)d->nodes * d->nc + d->ni;
  double *save = cv_malloc((ny + nm + 1) * sizeof *save);
  if (!save) {
    cv_set_msg(s->msg, sizeof s->msg, "out of memory");
    return CVAR_ENOMEM;
  }
  cv_dcopy(save, Y, ny);
  cv_dcopy(save + ny, M, nm);
  int maxit = s->maxit, total = 0;
  s->maxit = maxit < OB_DIRECT_ITERATIONS ? maxit : OB_DIRECT_ITERATIONS;
  cv_status st = newton_run(s, p, d, Y, M, NULL, 0.0, 0);
  s->maxit = maxit;
  total = s->iterations;
  if (st == CVAR_EMAXITER || st == CVAR_ESTALL || st == CVAR_EDIVERGED) {
    cv_dcopy(Y, save, ny);
    cv_dcopy(M, save + ny, nm);
    int stages = 0; /* stages converged: their path saved */
    for (size_t k = 0; k < neps; k++) {
      st = newton_run(s, p, d, Y, M, NULL, eps[k], stages > 0);
      total += s->iterations;
      if (!st && eps[k] > 0) {
        cv_dcopy(save, Y, ny), cv_dcopy(save + ny, M, nm), stages++;
        continue;
      }
      int retry = st == CVAR_EMAXITER || st == CVAR_ESTALL || st == CVAR_EDIVERGED;
      if (!st || !stages || eps[k] == 0.0 || !retry) break;
      /* OB-3: a later stage that fails (a stiff penalty can make the active set of a
       * fourth-order problem wander): the exact iteration from the last stage that
       * converged */
      cv_dcopy(Y, save, ny), cv_dcopy(M, save + ny, nm);
      k = neps - 2;
    }
  }
  cv_free(save);
  s->iterations = total;
  if (st == CVAR_OK) {
    cv_set_msg_converged(s->msg, sizeof s->msg, total);
  } else if (st != CVAR_ENOMEM && st != CVAR_ECALLBACK) {
    size_t used = strlen(s->msg);
    cv_set_msg(s->msg + used, sizeof s->msg - used,
               "; the path-following in the obstacles' penalty failed: the inequality "
               "constraints may admit no path between these ends (an infeasible problem), or "
               "the guess is far from one that meets them");
  }
  return st;
}

cv_status cv_newton_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y, double *M,
                        const cv_homotopy *h) {
  if (h || !cv_kkt_has_inequalities(p)) return newton_run(s, p, d, Y, M, h, 0.0, 0);
  return run_staged(s, p, d, Y, M);
}
