/* src/core/cv_deflation.c — every stationary path that can be found: deflated Newton from
 * several starts (theory DF-1..DF-5), each path polished by plain Newton, the paths kept in
 * the solver and selected one at a time so the usual getters read them.
 * SPDX-License-Identifier: MIT
 *
 * Deflation (Farrell, Birkisson & Funke 2015): once paths u_1..u_k are known, Newton is run
 * on G(u) = M(u) g(u) with M(u) = prod_i (|u - u_i|^-P + SIGMA), which has the remaining
 * stationary points of S as roots but not the known ones. Its Jacobian M H + g (grad M)^T is a
 * rank-one update of M H; by Sherman-Morrison its Newton step is the plain Newton step
 * scaled by 1 / (1 - r.delta0), r = grad M / M (DF-3): one LDL^T solve per iteration, the
 * same as plain Newton.
 */
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_internal.h"

#define DEFL_P        2.0  /* power of the distance (DF-1) */
#define DEFL_SIGMA    1.0  /* shift: M -> 1 far from every known path (DF-1) */
#define DEFL_MAXIT    25   /* deflated Newton iterations per start */
#define WORK_FLOOR    8    /* the first solve counts as at least this many iterations */
#define EIG_DIRS      3    /* lowest Hessian eigen-directions per path (DF-4) */
#define HARM_DIRS     3    /* harmonics sin(k pi t), k = 1..3, per unknown and path (DF-6) */
#define MIN_TRIES     2    /* perturbations every path gets before the work limit may stop (DF-4) */
#define EIG_STEPS     4    /* block inverse-iteration steps */
#define MAX_BACKTRACK 12   /* deflated line search: a step cut below 2^-12 is no progress */
#define TAU_BIG       10.0 /* |1 / (1 - r.delta0)| above this: deflation dominates (DF-3) */
#define STALL_DROP    0.9  /* ... and |G| fell by less than 10% over two such steps: abandon */
#define CRAWL_ALPHA   0.0625 /* a step cut to this or less is a crawl ... */
#define CRAWL_RUN     8      /* ... and this many in a row that did not halve |G|: abandon */
#define ARMIJO        1e-4
#define SAME_FLOOR    1e-6 /* paths closer than this times their size are one (DF-5) */

/* One path: the results of its polishing solve, moved out of the solver. */
typedef struct {
  cv_disc disc;
  double *y, *mult;
  double action, gnorm, gfloor, err_est, time;
  int iterations, morse, degenerate, rounds, csteps, ends_neg;
  char msg[640];
} cv_path;

struct cv_pathset {
  int n, sel; /* paths; the one whose results the solver holds (its slot is empty) */
  cv_path *v;
  cv_search_info info;
};

static void path_free(cv_path *q) {
  cv_disc_free(&q->disc);
  cv_free(q->y);
  cv_free(q->mult);
  memset(q, 0, sizeof *q);
}

CV_HOT void cv_pathset_free(struct cv_pathset *ps) {
  if (!ps) return;
  for (int k = 0; k < ps->n; k++) path_free(&ps->v[k]);
  cv_free(ps->v);
  cv_free(ps);
}

/* Move the solver's results into q (the solver holds none afterwards), and back. */
static void path_take(cv_path *q, cv_solver *s) {
  cv_solver_drop_factor(s); /* the factor belongs to the mesh that leaves */
  q->disc = s->disc;
  q->y = s->y;
  q->mult = s->mult;
  q->action = s->action, q->gnorm = s->gnorm, q->gfloor = s->gfloor, q->err_est = s->err_est,
  q->time = s->time;
  q->iterations = s->iterations, q->morse = s->morse, q->degenerate = s->degenerate;
  q->rounds = s->rounds, q->csteps = s->csteps, q->ends_neg = s->ends_neg;
  memcpy(q->msg, s->msg, sizeof q->msg);
  memset(&s->disc, 0, sizeof s->disc);
  s->y = s->mult = NULL;
  s->have = 0;
}

static void path_give(cv_solver *s, cv_path *q) {
  cv_solver_drop_factor(s);
  cv_solver_drop_results(s);
  s->disc = q->disc;
  s->y = q->y;
  s->mult = q->mult;
  s->action = q->action, s->gnorm = q->gnorm, s->gfloor = q->gfloor, s->err_est = q->err_est,
  s->time = q->time;
  s->iterations = q->iterations, s->morse = q->morse, s->degenerate = q->degenerate;
  s->rounds = q->rounds, s->csteps = q->csteps, s->ends_neg = q->ends_neg;
  memcpy(s->msg, q->msg, sizeof s->msg);
  s->status = CVAR_OK;
  s->have = 1;
  memset(q, 0, sizeof *q);
}

/* ---- the deflated Newton iteration on one fixed mesh ---- */
typedef struct {
  const cv_problem *p;
  cv_disc *d;
  cv_kkt kkt;
  cv_ldlt *L;
  int *gof;
  const int *colptr;
  int nf, ncon;
  size_t nmult;
  double *g, *gt, *delta, *corr, *dreg, *r, *Yt, *Mt, *M;
  int nknown, cap;
  double **known; /* known paths' nodal values on this mesh (ndof each) */
  double len;     /* b - a */
} defl;

static void defl_free(defl *w) {
  cv_kkt_free(&w->kkt);
  cv_ldlt_free(w->L);
  cv_free(w->gof);
  cv_free(w->g);
  cv_free(w->gt);
  cv_free(w->delta);
  cv_free(w->corr);
  cv_free(w->dreg);
  cv_free(w->r);
  cv_free(w->Yt);
  cv_free(w->Mt);
  cv_free(w->M);
  for (int k = 0; k < w->nknown; k++) cv_free(w->known[k]);
  cv_free(w->known);
}

static cv_status defl_init(defl *w, const cv_problem *p, cv_disc *d, char *msg, size_t len) {
  size_t nf = (size_t)(d->nfree ? d->nfree : 1);
  memset(w, 0, sizeof *w);
  w->p = p;
  w->d = d;
  w->nf = d->nfree;
  w->nmult = (size_t)d->nodes * d->nc + d->ni;
  w->len = d->b - d->a;
  w->gof = cv_malloc(nf * sizeof *w->gof);
  if (!w->gof) return CVAR_ENOMEM;
  cv_status st = cv_ldlt_new(d, w->gof, &w->L, msg, len);
  if (st) return st;
  w->colptr = cv_ldlt_colptr(w->L);
  st = cv_kkt_init(&w->kkt, p, d, w->colptr);
  if (st) return st;
  w->g = cv_malloc(nf * sizeof *w->g);
  w->gt = cv_malloc(nf * sizeof *w->gt);
  w->delta = cv_malloc(nf * sizeof *w->delta);
  w->corr = cv_malloc(nf * sizeof *w->corr);
  w->dreg = cv_calloc(nf, sizeof *w->dreg);
  w->r = cv_malloc(nf * sizeof *w->r);
  w->Yt = cv_malloc((size_t)d->ndof * sizeof *w->Yt);
  w->Mt = cv_calloc(w->nmult + 1, sizeof *w->Mt);
  w->M = cv_calloc(w->nmult + 1, sizeof *w->M);
  if (!w->g || !w->gt || !w->delta || !w->corr || !w->dreg || !w->r || !w->Yt || !w->Mt || !w->M)
    return CVAR_ENOMEM;
  for (int f = 0; f < w->nf; f++) w->ncon += w->gof[f] < 0;
  return CVAR_OK;
}

static cv_status defl_add_known(defl *w, const double *Y) {
  if (w->nknown == w->cap) {
    int cap = w->cap ? 2 * w->cap : 8;
    double **k = cv_malloc((size_t)cap * sizeof *k);
    if (!k) return CVAR_ENOMEM;
    if (w->nknown) memcpy(k, w->known, (size_t)w->nknown * sizeof *k);
    cv_free(w->known);
    w->known = k;
    w->cap = cap;
  }
  double *c = cv_malloc((size_t)w->d->ndof * sizeof *c);
  if (!c) return CVAR_ENOMEM;
  memcpy(c, Y, (size_t)w->d->ndof * sizeof *c);
  w->known[w->nknown++] = c;
  return CVAR_OK;
}

/* The deflation factor M(Y) of (DF-1) and, if r != NULL, r = grad M / M (DF-2) on the free
 * unknowns (0 on multiplier rows: only the primal part is deflated). The distance is the
 * lumped-mass L2 norm divided by the interval's length, |u|^2 = sum_f m_f u_f^2 / (b - a). */
static double deflation(defl *w, const double *Y, double *r) {
  const cv_disc *d = w->d;
  double Mv = 1.0;
  if (r) memset(r, 0, (size_t)w->nf * sizeof *r);
  for (int k = 0; k < w->nknown; k++) {
    const double *K = w->known[k];
    double d2 = 0.0;
    for (int f = 0; f < w->nf; f++) {
      int gi = w->gof[f];
      if (gi < 0) continue;
      double e = Y[gi] - K[gi];
      d2 += d->mass[f] * e * e;
    }
    d2 /= w->len;
    double dp = pow(d2, -0.5 * DEFL_P), mk = dp + DEFL_SIGMA;
    Mv *= mk;
    if (!r) continue;
    /* grad m_k / m_k = -(P/2) d^(-P-2) grad(d^2) / m_k, grad(d^2)_f = 2 m_f e_f / (b - a) */
    double c = -DEFL_P * dp / d2 / mk / w->len;
    for (int f = 0; f < w->nf; f++) {
      int gi = w->gof[f];
      if (gi >= 0) r[f] += c * d->mass[f] * (Y[gi] - K[gi]);
    }
  }
  return Mv;
}

/* Merit of the line search (DF-3): |M g / m|^2 / 2 with the lumped weights m (N-3). */
static double merit(const defl *w, const double *g, double Mv) {
  double s = 0.0;
  for (int f = 0; f < w->nf; f++) {
    double v = Mv * g[f] * w->d->imass[f];
    s += v * v;
  }
  return 0.5 * s;
}

/* delta <- K^{-1} delta with iterative refinement for the regularised KKT matrix (C-4). */
static cv_status solve_refined(defl *w) {
  cv_status st = cv_ldlt_solve(w->L, w->delta);
  for (int it = 0; it < 2 && w->ncon && !st; it++) {
    for (int f = 0; f < w->nf; f++) w->corr[f] = -w->dreg[f] * w->delta[f];
    st = cv_ldlt_solve(w->L, w->corr);
    for (int f = 0; f < w->nf && !st; f++) w->delta[f] += w->corr[f];
  }
  return st;
}

static void put(defl *w, const double *Y, const double *M, double a, const double *dx, double *Yt,
                double *Mt) {
  for (int f = 0; f < w->nf; f++) {
    int gi = w->gof[f];
    if (gi >= 0)
      Yt[gi] = Y[gi] + a * dx[f];
    else
      Mt[-1 - gi] = M[-1 - gi] + a * dx[f];
  }
}

/* Deflated Newton from Y (DF-3). Returns CVAR_OK when the undeflated Newton step there is
 * within the tolerance (the point is then handed to plain Newton to polish), else a
 * failure. Y holds the last iterate. */
static cv_status defl_run(defl *w, const cv_solver *s, double *Y, int maxit, int *iters) {
  const cv_disc *d = w->d;
  cv_status st;
  double S, *Ax = cv_ldlt_values(w->L), scale = 0.0;
  *iters = 0;
  for (long i = 0; i < d->ndof; i++) scale = fmax(scale, fabs(Y[i]));
  if (scale == 0.0) scale = 1.0;
  double atol = s->atol * scale;
  memcpy(w->Yt, Y, (size_t)d->ndof * sizeof *Y);
  memset(w->M, 0, (w->nmult + 1) * sizeof *w->M);
  if (w->ncon && cv_kkt_init_multipliers(&w->kkt, Y, w->M)) return CVAR_ENONFINITE;
  memcpy(w->Mt, w->M, (w->nmult + 1) * sizeof *w->M);
  st = cv_kkt_eval(&w->kkt, Y, w->M, &S, w->g, Ax, w->dreg);
  if (st) return st;
  double Mv = deflation(w, Y, w->r), phi = merit(w, w->g, Mv), phi_big = phi;
  int big = 0;            /* consecutive iterations with |tau| > TAU_BIG */
  int crawl = 0;          /* consecutive steps cut to CRAWL_ALPHA or less */
  double phi_crawl = phi; /* the merit before the first of them */
  for (int it = 0; it < maxit; it++) {
    int neg;
    double dmin, dmax;
    char detail[200];
    st = cv_ldlt_factor(w->L, &neg, &dmin, &dmax, detail, sizeof detail);
    if (st) return st;
    for (int f = 0; f < w->nf; f++) w->delta[f] = -w->g[f];
    st = solve_refined(w);
    if (st) return st;
    (*iters)++;
    /* the plain Newton step delta0 and its weighted norm (N-4) */
    double wn = 0.0, rd = 0.0;
    int ny = 0;
    for (int f = 0; f < w->nf; f++) {
      int gi = w->gof[f];
      rd += w->r[f] * w->delta[f];
      if (gi < 0) continue;
      double v = w->delta[f] / (s->rtol * fabs(Y[gi]) + atol);
      wn += v * v;
      ny++;
    }
    wn = sqrt(wn / (ny ? ny : 1));
    if (!isfinite(wn)) return CVAR_ENONFINITE;
    if (wn <= 1.0) return CVAR_OK;
    /* Sherman-Morrison (DF-3): the deflated step is the Newton step times tau */
    double den = 1.0 - rd;
    if (!(fabs(den) > 1e-14)) return CVAR_ESINGULAR;
    double tau = 1.0 / den, alpha = 1.0, St, Mt = 0.0, phit = 0.0;
    /* Abandon (DF-3) when the deflation term has dominated the step for two iterations
     * running and the deflated residual |G| has not fallen by a tenth over them: the
     * iterate circles a pole of M's gradient rather than approaching a root. */
    if (fabs(tau) > TAU_BIG) {
      if (big++ >= 1 && phi > STALL_DROP * STALL_DROP * phi_big) return CVAR_ESTALL;
      if (big == 1) phi_big = phi;
    } else {
      big = 0;
    }
    int ok = 0;
    for (int ls = 0; ls < MAX_BACKTRACK; ls++, alpha *= 0.5) {
      put(w, Y, w->M, alpha * tau, w->delta, w->Yt, w->Mt);
      /* trials without the Hessian: a failing search backtracks often */
      cv_status ast = cv_kkt_eval(&w->kkt, w->Yt, w->Mt, &St, w->gt, NULL, NULL);
      if (ast == CVAR_ECALLBACK || ast == CVAR_ENOMEM) return ast;
      if (ast) continue;
      Mt = deflation(w, w->Yt, NULL);
      phit = merit(w, w->gt, Mt);
      if (phit <= (1.0 - 2.0 * ARMIJO * alpha) * phi) {
        ok = 1;
        break;
      }
    }
    if (!ok) return CVAR_ESTALL;
    /* a crawl: CRAWL_RUN cut steps in a row that have not halved |G| (DF-3) */
    if (alpha > CRAWL_ALPHA) {
      crawl = 0;
    } else {
      if (crawl++ == 0) phi_crawl = phi;
      if (crawl >= CRAWL_RUN && phit > 0.25 * phi_crawl) return CVAR_ESTALL;
    }
    memcpy(Y, w->Yt, (size_t)d->ndof * sizeof *Y);
    memcpy(w->M, w->Mt, (w->nmult + 1) * sizeof *w->M);
    if (s->progress) { /* a deflated step is a Newton step too: the caller may cancel */
      cv_progress info = {
          CVAR_PROGRESS_NEWTON, it + 1, sqrt(2.0 * phi), wn, alpha, St, 0, d->E, NAN};
      if (s->progress(&info, s->progress_user) != 0) return CVAR_ECANCELLED;
    }
    st = cv_kkt_eval(&w->kkt, Y, w->M, &St, w->g, Ax, w->dreg); /* and its Hessian */
    if (st) return st;
    phi = phit;
    Mv = deflation(w, Y, w->r);
    double ymax = 0.0;
    for (long i = 0; i < d->ndof; i++) ymax = fmax(ymax, fabs(Y[i]));
    if (!(ymax <= 1e6 * scale)) return CVAR_EDIVERGED;
    (void)Mv;
  }
  return CVAR_EMAXITER;
}

/* The EIG_DIRS eigenvectors of H v = lambda m v (m the lumped weights) nearest 0, by block
 * inverse iteration on the LDL^T of H at Y with mass-orthonormalisation (DF-4); only the
 * primal part of each vector is kept. V: EIG_DIRS x nf. Returns the count found. */
static int low_modes(defl *w, const double *Y, double *V) {
  const cv_disc *d = w->d;
  double S, *Ax = cv_ldlt_values(w->L);
  int neg, nv = 0, nf = w->nf;
  double dmin, dmax;
  char detail[200];
  memset(w->M, 0, (w->nmult + 1) * sizeof *w->M);
  if (w->ncon && cv_kkt_init_multipliers(&w->kkt, Y, w->M)) return 0;
  if (cv_kkt_eval(&w->kkt, Y, w->M, &S, w->g, Ax, w->dreg)) return 0;
  if (cv_ldlt_factor(w->L, &neg, &dmin, &dmax, detail, sizeof detail)) return 0;
  int ny = 0;
  for (int f = 0; f < nf; f++) ny += w->gof[f] >= 0;
  nv = ny < EIG_DIRS ? ny : EIG_DIRS;
  /* start: smooth, distinct vectors sin(k pi t) of the position t in [0, 1] of each dof */
  for (int k = 0; k < nv; k++)
    for (int f = 0; f < nf; f++) {
      int gi = w->gof[f];
      double t = gi < 0 ? 0.0 : (cv_disc_node_x(d, gi / d->n) - d->a) / w->len;
      V[(size_t)k * nf + f] = gi < 0 ? 0.0 : sin((k + 1) * CV_PI * t) + 0.1 * (gi % d->n);
    }
  for (int step = 0; step <= EIG_STEPS; step++) {
    for (int k = 0; k < nv; k++) {
      double *v = V + (size_t)k * nf;
      if (step > 0) { /* v <- H^{-1} m v, primal part */
        for (int f = 0; f < nf; f++) w->delta[f] = w->gof[f] >= 0 ? d->mass[f] * v[f] : 0.0;
        if (solve_refined(w)) return 0;
        for (int f = 0; f < nf; f++) v[f] = w->gof[f] >= 0 ? w->delta[f] : 0.0;
      }
      for (int j = 0; j < k; j++) { /* Gram-Schmidt in the mass inner product */
        const double *u = V + (size_t)j * nf;
        double c = 0.0;
        for (int f = 0; f < nf; f++) c += d->mass[f] * u[f] * v[f];
        for (int f = 0; f < nf; f++) v[f] -= c * u[f];
      }
      double nrm = 0.0;
      for (int f = 0; f < nf; f++) nrm += d->mass[f] * v[f] * v[f];
      nrm = sqrt(nrm);
      if (!(nrm > 0.0) || !isfinite(nrm)) return k;
      for (int f = 0; f < nf; f++) v[f] /= nrm;
    }
  }
  return nv;
}

/* DF-6: after the nv soft modes in V, the harmonics sin(k pi t) (k = 1..HARM_DIRS) of each
 * unknown alone, mass-normalised: directions that do not depend on the path's Hessian, so
 * that a path whose soft modes all lead back to it is still left in several shapes. Returns
 * the total count. */
static int add_harmonics(const defl *w, double *V, int nv) {
  const cv_disc *d = w->d;
  int nf = w->nf;
  for (int i = 0; i < d->n; i++)
    for (int k = 1; k <= HARM_DIRS; k++) {
      double *v = V + (size_t)nv * nf, nrm = 0.0;
      for (int f = 0; f < nf; f++) {
        int gi = w->gof[f];
        double t = gi < 0 ? 0.0 : (cv_disc_node_x(d, gi / d->n) - d->a) / w->len;
        v[f] = gi >= 0 && gi % d->n == i ? sin(k * CV_PI * t) : 0.0;
        nrm += d->mass[f] * v[f] * v[f];
      }
      if (!(nrm > 0.0)) continue; /* that unknown has no free value */
      nrm = sqrt(nrm);
      for (int f = 0; f < nf; f++) v[f] /= nrm;
      nv++;
    }
  return nv;
}

/* ---- the search ---- */

/* Max nodal difference of the solver's current solution from A (values on the search mesh
 * dsearch), evaluated at the search mesh's nodes into buffer E. */
static cv_status values_on(const cv_solver *s, const cv_disc *ds, double *xs, double *ev,
                           double *E) {
  int n = ds->n, N = ds->nodes;
  cv_disc_fill_nodes(ds, xs);
  if (ds->herm) { /* C1 elements: values and slopes, the unknowns of the mesh (H-2) */
    int nu = n / 2;
    double *dv = ev + (size_t)N * nu; /* ev holds ndof = 2 N nu values */
    cv_status st = cv_solver_eval(s, N, xs, ev, dv);
    for (int j = 0; j < N && !st; j++)
      for (int i = 0; i < nu; i++) {
        E[(size_t)j * n + 2 * i] = ev[(size_t)i * N + j];
        E[(size_t)j * n + 2 * i + 1] = dv[(size_t)i * N + j];
      }
    return st;
  }
  cv_status st = cv_solver_eval(s, N, xs, ev, NULL);
  if (st) return st;
  for (int j = 0; j < N; j++)
    for (int i = 0; i < n; i++) E[(size_t)j * n + i] = ev[(size_t)i * N + j];
  return CVAR_OK;
}

/* Max difference of the values (of C1 elements: every other entry, not the slopes). */
static double maxdiff(const double *a, const double *b, long n, int herm) {
  double m = 0.0;
  for (long i = 0; i < n; i += herm ? 2 : 1) m = fmax(m, fabs(a[i] - b[i]));
  return m;
}

static int by_action(const void *a, const void *b) {
  double x = ((const cv_path *)a)->action, y = ((const cv_path *)b)->action;
  return (x > y) - (x < y);
}

/* Add the solver's current (converged) result as a path unless it equals a known one
 * (DF-5). Returns 1 when added, 0 for a duplicate, < 0 on allocation failure. */
static int keep_path(cv_solver *s, struct cv_pathset *ps, defl *w, double *xs, double *ev,
                     double *E, double *ests) {
  if (values_on(s, w->d, xs, ev, E)) return -1;
  long nd = w->d->ndof;
  double size = 0.0, est = isfinite(s->err_est) ? s->err_est : 0.0;
  int herm = w->d->herm != NULL;
  for (long i = 0; i < nd; i += herm ? 2 : 1) size = fmax(size, fabs(E[i]));
  for (int k = 0; k < w->nknown; k++) {
    double tol = fmax(fmax(est, ests[k]), SAME_FLOOR * fmax(size, 1.0));
    if (maxdiff(E, w->known[k], nd, herm) <= tol) return 0;
  }
  if (defl_add_known(w, E)) return -1;
  ests[w->nknown - 1] = est;
  path_take(&ps->v[ps->n++], s);
  return 1;
}

/* The end point (x and the n end values) of the solver's current path at its moving end. */
static void end_point(const cv_solver *s, int end, double *pt) {
  const cv_disc *d = &s->disc;
  long node = end ? d->nodes - 1 : 0;
  pt[0] = end ? d->b : d->a;
  for (int i = 0; i < d->n; i++) pt[1 + i] = s->y[node * d->n + i];
}

/* The end of a search by a fan of starts (ME-5, OB-7): the stop sentence (covered: what
 * the starts covered), the paths by increasing action with the first selected, or the
 * first start's failure when none converged. Returns the search's status. */
static cv_status fan_finish(cv_solver *s, struct cv_pathset *ps, int max, cv_status st,
                            cv_status first, const char *msg0, const char *covered, double t0) {
  cv_search_info *info = &ps->info;
  if (st == CVAR_ENOMEM || st == CVAR_ECANCELLED || st == CVAR_ECALLBACK)
    cv_set_msg(info->stop, sizeof info->stop, "the search stopped: %s", s->msg);
  else if (ps->n >= max)
    cv_set_msg(info->stop, sizeof info->stop, "found the %d path%s asked for", max,
               max == 1 ? "" : "s");
  else
    cv_set_msg(info->stop, sizeof info->stop, "%s", covered);
  info->found = ps->n;
  if (ps->n > 0) {
    qsort(ps->v, (size_t)ps->n, sizeof *ps->v, by_action);
    ps->sel = 0;
    path_give(s, &ps->v[0]);
    st = CVAR_OK;
  } else if (st == CVAR_OK || st == first) {
    st = first == CVAR_OK ? CVAR_EMAXITER : first;
    memcpy(s->msg, msg0, sizeof s->msg);
  }
  s->paths = ps;
  s->status = st;
  s->time = cv_now() - t0;
  return st;
}

/* Every stationary path of a problem with a moving end (theory ME-5): the moving-end solve
 * from the start's end point and from points moved +-1/2, +-1, ... +-2 intervals along the
 * end's motion (the free end or the curve); paths are one when their end points agree to
 * 1e-6 of the interval (the fixed-interval path through an end point is found from there). */
static cv_status all_moving_ends(cv_solver *s, const cv_problem *p, int max) {
  static const double shifts[] = {0.0, 0.5, -0.5, 1.0, -1.0, 1.5, -1.5, 2.0, -2.0};
  int nshift = (int)(sizeof shifts / sizeof shifts[0]), n = p->n;
  int end = p->move[1].kind != CV_END_FIXED;
  double t0 = cv_now(), L0 = p->b - p->a;
  struct cv_pathset *ps = cv_calloc(1, sizeof *ps);
  cv_path *v = cv_calloc((size_t)max, sizeof *v);
  double *pts = cv_malloc((size_t)max * (n + 1) * sizeof *pts);
  double *pt = cv_malloc(((size_t)n + 1) * sizeof *pt);
  cv_status st = CVAR_OK, first = CVAR_OK;
  char msg0[sizeof s->msg] = "";
  if (!ps || !v || !pts || !pt) {
    cv_free(ps), cv_free(v), cv_free(pts), cv_free(pt);
    cv_set_msg(s->msg, sizeof s->msg, "out of memory for the list of paths");
    return s->status = CVAR_ENOMEM;
  }
  ps->v = v;
  cv_search_info *info = &ps->info;
  for (int k = 0; k < nshift && ps->n < max; k++) {
    info->starts++;
    st = cv_solve_at(s, p, shifts[k] * L0);
    if (k == 0) first = st, memcpy(msg0, s->msg, sizeof msg0);
    if (st == CVAR_ENOMEM || st == CVAR_ECANCELLED || st == CVAR_ECALLBACK) break;
    if (st != CVAR_OK) {
      info->failed++;
      continue;
    }
    end_point(s, end, pt);
    int same = 0;
    for (int j = 0; j < ps->n && !same; j++) {
      double dist = 0.0;
      for (int i = 0; i <= n; i++) dist = fmax(dist, fabs(pt[i] - pts[(size_t)j * (n + 1) + i]));
      same = dist <= 1e-6 * L0;
    }
    if (same) {
      info->duplicates++;
      continue;
    }
    memcpy(pts + (size_t)ps->n * (n + 1), pt, ((size_t)n + 1) * sizeof *pt);
    path_take(&ps->v[ps->n++], s);
  }
  char covered[200];
  cv_set_msg(covered, sizeof covered,
             "every start was tried (the start's end point and %d points along the end's motion)",
             nshift - 1);
  cv_free(pts);
  cv_free(pt);
  st = fan_finish(s, ps, max, st, first, msg0, covered, t0);
  if (ps->n > 0) s->ends_dim = 1;
  return st;
}

/* The starts of the search among obstacles (OB-7): y0 + k (g - y0) for the guess g and the
 * line y0 between the end values (free ends: the other end's value, or 0), and when the
 * guess is that line, y0 + k (b - a)/2 sin(pi (x - a)/(b - a)) for every unknown. */
typedef struct {
  const cv_problem *p;
  double k;
  int bump;
} ob_start;

static double end_line(const cv_problem *p, int i, double x) {
  int fa = p->fixed[2 * i], fb = p->fixed[2 * i + 1];
  double ya = p->endval[2 * i], yb = p->endval[2 * i + 1];
  if (fa && fb) return ya + (yb - ya) * (x - p->a) / (p->b - p->a);
  return fa ? ya : fb ? yb : 0.0;
}

static int ob_guess(int m, const double *x, double *y, void *user) {
  const ob_start *o = user;
  const cv_problem *p = o->p;
  int n = p->n;
  if (!o->bump && p->guess(m, x, y, p->guess_user)) return 1;
  for (int i = 0; i < n; i++)
    for (int k = 0; k < m; k++) {
      double l = end_line(p, i, x[k]), L = p->b - p->a;
      double g = o->bump ? l + 0.5 * L * sin(CV_PI * (x[k] - p->a) / L) : y[(size_t)i * m + k];
      y[(size_t)i * m + k] = l + o->k * (g - l);
    }
  return 0;
}

/* Every stationary path among obstacles (OB-7). Deflation does not suit the active set
 * (a deflated residual has no complementarity structure), so the search solves from a fan
 * of starts on both sides of the line between the ends — the obstacle solve (OB-3) from
 * each — and keeps the distinct paths: two paths are one when their values at 65 points
 * agree within 1e-6 of their size plus their error estimates. */
static cv_status all_obstacles(cv_solver *s, const cv_problem *p, int max) {
  static const double ks[] = {1.0, -1.0, 2.0, -2.0, 0.5, -0.5, 3.0, -3.0};
  enum { NS = 65 };
  int nk = (int)(sizeof ks / sizeof ks[0]), n = p->n;
  double t0 = cv_now(), xs[NS];
  struct cv_pathset *ps = cv_calloc(1, sizeof *ps);
  cv_path *v = cv_calloc((size_t)max, sizeof *v);
  double *seen = cv_malloc((size_t)max * NS * n * sizeof *seen);
  double *ests = cv_malloc((size_t)max * sizeof *ests);
  double *cur = cv_malloc((size_t)NS * n * sizeof *cur);
  cv_status st = CVAR_OK, first = CVAR_OK;
  char msg0[sizeof s->msg] = "";
  if (!ps || !v || !seen || !ests || !cur) {
    cv_free(ps), cv_free(v), cv_free(seen), cv_free(ests), cv_free(cur);
    cv_set_msg(s->msg, sizeof s->msg, "out of memory for the list of paths");
    return s->status = CVAR_ENOMEM;
  }
  ps->v = v;
  cv_search_info *info = &ps->info;
  for (int j = 0; j < NS; j++) xs[j] = p->a + (p->b - p->a) * j / (NS - 1);
  /* with the default guess (the line), the fan is of sine bumps */
  int bump = p->guess == NULL;
  for (int k = 0; k < nk && ps->n < max; k++) {
    ob_start o = {p, ks[k], bump};
    cv_problem pk = *p; /* the same problem with this start as its guess; nothing is freed */
    pk.guess = ob_guess;
    pk.guess_user = &o;
    info->starts++;
    st = k == 0 && !bump ? cv_solve(s, p) : cv_solve(s, &pk);
    if (k == 0) first = st, memcpy(msg0, s->msg, sizeof msg0);
    if (st == CVAR_ENOMEM || st == CVAR_ECANCELLED || st == CVAR_ECALLBACK) break;
    if (st != CVAR_OK || cv_solver_eval(s, NS, xs, cur, NULL) != CVAR_OK) {
      info->failed++;
      continue;
    }
    double size = 1.0, est = isfinite(s->err_est) ? s->err_est : 0.0;
    for (int j = 0; j < NS * n; j++) size = fmax(size, fabs(cur[j]));
    int same = 0;
    for (int q = 0; q < ps->n && !same; q++) {
      double d = 0.0;
      for (int j = 0; j < NS * n; j++) d = fmax(d, fabs(cur[j] - seen[(size_t)q * NS * n + j]));
      same = d <= 1e-6 * size + est + ests[q];
    }
    if (same) {
      info->duplicates++;
      continue;
    }
    memcpy(seen + (size_t)ps->n * NS * n, cur, (size_t)NS * n * sizeof *cur);
    ests[ps->n] = est;
    path_take(&ps->v[ps->n++], s);
  }
  char covered[300];
  cv_set_msg(covered, sizeof covered,
             "with obstacles the search tries %d starts: the %s scaled by 1, -1, 2, -2, 1/2, "
             "-1/2, 3 and -3 about the line between the ends (no deflation)",
             nk, bump ? "sine bump (b - a)/2 sin(pi (x - a)/(b - a))" : "guess");
  cv_free(seen);
  cv_free(ests);
  cv_free(cur);
  return fan_finish(s, ps, max, st, first, msg0, covered, t0);
}

cv_status cv_solve_all(cv_solver *s, const cv_problem *p, int max) {
  if (!s) return CVAR_EINVAL;
  cv_pathset_free(s->paths);
  s->paths = NULL;
  if (!p || max < 1 || s->method != CVAR_METHOD_NEWTON) {
    s->status = CVAR_EINVAL;
    cv_set_msg(s->msg, sizeof s->msg, "%s",
               !p        ? "problem is NULL"
               : max < 1 ? "the number of paths to find must be at least 1"
                         : "the search for every stationary path needs the Newton engine "
                           "(the minimisers find minima only)");
    return CVAR_EINVAL;
  }
  if (cv_ends_moving(p)) return all_moving_ends(s, p, max);
  if (cv_kkt_has_inequalities(p)) return all_obstacles(s, p, max);
  double t0 = cv_now();
  struct cv_pathset *ps = cv_calloc(1, sizeof *ps);
  cv_path *v = cv_calloc((size_t)max, sizeof *v);
  double *ests = cv_calloc((size_t)max, sizeof *ests);
  defl w;
  memset(&w, 0, sizeof w);
  cv_disc ds;
  memset(&ds, 0, sizeof ds);
  double *Y = NULL, *xs = NULL, *ev = NULL, *E = NULL, **V = NULL;
  int *nmodes = NULL, *cursor = NULL;
  cv_meshspec spec0 = s->mesh;
  double *t = NULL, adapt_tol = s->adapt_tol, *start0 = s->start;
  int start_len0 = s->start_len, cont0 = s->continuation;
  cv_status st, first;
  char msg0[sizeof s->msg];
  if (!ps || !v || !ests) {
    cv_free(ps);
    cv_free(v);
    cv_free(ests);
    cv_set_msg(s->msg, sizeof s->msg, "out of memory for the list of paths");
    return s->status = CVAR_ENOMEM;
  }
  ps->v = v;
  cv_search_info *info = &ps->info;

  /* 1. The plain solve from the guess (retries, continuation, adaptation as usual). */
  first = st = cv_solve(s, p);
  info->starts = 1;
  /* Bounded work (DF-4): the search stops once its Newton iterations (deflated and
   * polishing) since the last new path (or since it began) reach search_work times those
   * of the first solve (counted as at least WORK_FLOOR): each path found renews it. */
  int work = 0, found_at = 0;
  int budget = (int)fmin(1e9, s->search_work * fmax(WORK_FLOOR, s->iterations));
  memcpy(msg0, s->msg, sizeof msg0);
  if (!s->have) goto finish; /* bad input: nothing to search around */
  /* 2. The search mesh: the mesh of that solve, frozen (DF-5); adaptation only polishes. */
  ds.n = 0;
  {
    const cv_disc *d0 = &s->disc;
    t = cv_malloc((size_t)(d0->E + 1) * sizeof *t);
    if (!t) goto nomem;
    for (int e = 0; e <= d0->E; e++) t[e] = (d0->xe[e] - d0->a) / (d0->b - d0->a);
    t[0] = 0.0, t[d0->E] = 1.0;
    s->mesh.kind = CV_MESH_USER;
    s->mesh.elements = d0->E;
    s->mesh.t = t;
    s->mesh.nbreak = 0;
    s->adapt_tol = 0.0;
    st = cv_disc_init(&ds, p, s, s->msg, sizeof s->msg);
    if (st) goto fail;
    ds.sing_a = d0->sing_a, ds.sing_b = d0->sing_b;
    if (cv_disc_build_singular_rules(&ds)) goto nomem;
  }
  if (ds.nfree == 0) {
    if (first == CVAR_OK) path_take(&ps->v[ps->n++], s);
    cv_set_msg(info->stop, sizeof info->stop,
               "no free unknowns: the path is fixed by its end values");
    st = CVAR_OK;
    goto finish;
  }
  st = defl_init(&w, p, &ds, s->msg, sizeof s->msg);
  if (st) goto fail;
  size_t nd = (size_t)ds.ndof;
  Y = cv_malloc(nd * sizeof *Y);
  xs = cv_malloc((size_t)ds.nodes * sizeof *xs);
  ev = cv_malloc(nd * sizeof *ev);
  E = cv_malloc(nd * sizeof *E);
  V = cv_calloc((size_t)max, sizeof *V);
  nmodes = cv_malloc((size_t)max * sizeof *nmodes);
  cursor = cv_calloc((size_t)max, sizeof *cursor);
  if (!Y || !xs || !ev || !E || !V || !nmodes || !cursor) goto nomem;
  for (int k = 0; k < max; k++) nmodes[k] = -1;
  s->start = NULL; /* restored below; the polishing solves set their own */
  s->start_len = 0;
  s->continuation = 0;
  if (first == CVAR_OK && keep_path(s, ps, &w, xs, ev, E, ests) < 0) goto nomem;
  if (first != CVAR_OK) info->failed++;

  /* 3. Starts (DF-4): the guess and the straight line, deflated; then perturbations along
   * the EIG_DIRS softest Hessian directions of the paths found, by promise: the next start
   * is the least-tried path's next perturbation (a new path's first ones come at once),
   * ties to the lower Morse index; on each path all +-1/2 ones before the +-3/2 ones. */
  static const double amp[] = {0.0625, 0.25, 0.5, 1.5};
  int namp = 2 * (int)(sizeof amp / sizeof amp[0]);
  int phase = 0;
  for (;;) {
    if (ps->n >= max) {
      cv_set_msg(info->stop, sizeof info->stop, "found the %d path%s asked for", max,
                 max == 1 ? "" : "s");
      break;
    }
    int least = INT_MAX; /* the fewest perturbations tried on a path not yet exhausted */
    for (int j = 0; j < w.nknown; j++)
      if ((nmodes[j] < 0 || cursor[j] < namp * nmodes[j]) && cursor[j] < least) least = cursor[j];
    if (work - found_at >= budget && least >= MIN_TRIES) {
      int planned = 0; /* DF-6: how much of the planned starts the search covered */
      for (int j = 0; j < w.nknown; j++)
        planned += namp * (nmodes[j] >= 0 ? nmodes[j] : EIG_DIRS + HARM_DIRS * ds.n);
      cv_set_msg(info->stop, sizeof info->stop,
                 "the work limit (%d Newton iterations) stopped it after %d of the %d starts "
                 "planned around the paths found; a larger --work searches further",
                 work, info->starts, planned + 1 + (p->guess || start0 ? 1 : 0));
      break;
    }
    /* the next start into Y */
    if (phase < 2) {
      /* nothing known yet: the plain solve already tried both (its straight-line retry);
       * without a guess or start the straight line is the guess: not twice */
      int line = phase++;
      if (w.nknown == 0 || (line && !p->guess && !start0)) continue;
      s->start = line ? NULL : start0;
      s->start_len = line ? 0 : start_len0;
      st = cv_start_values(s, p, &ds, Y, line);
      s->start = NULL;
      s->start_len = 0;
      if (st) continue;
    } else {
      if (w.nknown == 0) {
        cv_set_msg(info->stop, sizeof info->stop,
                   "no path converged from the guess, so there was none to deflate or to "
                   "perturb");
        break;
      }
      int k = -1; /* the path to perturb next */
      for (int j = 0; j < w.nknown; j++) {
        if (nmodes[j] >= 0 && cursor[j] >= namp * nmodes[j]) continue; /* exhausted */
        if (k < 0 || cursor[j] < cursor[k] ||
            (cursor[j] == cursor[k] && ps->v[j].morse < ps->v[k].morse))
          k = j;
      }
      if (k < 0) { /* DF-6: every planned start, which is not every start there is */
        int dirs = 0;
        for (int j = 0; j < w.nknown; j++) dirs += nmodes[j];
        cv_set_msg(info->stop, sizeof info->stop,
                   "all %d planned starts were tried: the guess, and around the %d paths found "
                   "%d directions (soft modes, harmonics) at %d amplitudes, 1/16 to 3/2 of the "
                   "path's size, both signs",
                   info->starts, w.nknown, dirs, namp / 2);
        break;
      }
      if (nmodes[k] < 0) {
        V[k] = cv_malloc((size_t)(EIG_DIRS + HARM_DIRS * ds.n) * ds.nfree * sizeof **V);
        if (!V[k]) goto nomem;
        nmodes[k] = add_harmonics(&w, V[k], low_modes(&w, w.known[k], V[k]));
        continue;
      }
      int c = cursor[k]++, grp = c / (2 * nmodes[k]), mode = c % (2 * nmodes[k]) / 2;
      const double *K = w.known[k], *vm = V[k] + (size_t)mode * ds.nfree;
      double size = 1.0, vmax = 0.0;
      for (size_t i = 0; i < nd; i++) size = fmax(size, fabs(K[i]));
      for (int f = 0; f < ds.nfree; f++) vmax = fmax(vmax, fabs(vm[f]));
      memcpy(Y, K, nd * sizeof *Y);
      double a = vmax > 0 ? (c % 2 ? -amp[grp] : amp[grp]) * size / vmax : 0.0;
      for (int f = 0; f < ds.nfree; f++)
        if (w.gof[f] >= 0) Y[w.gof[f]] += a * vm[f];
    }
    info->starts++;
    int it = 0;
    /* a start that begins within the limit runs to its end (at most DEFL_MAXIT) */
    st = w.nknown ? defl_run(&w, s, Y, DEFL_MAXIT, &it) : CVAR_OK;
    work += it;
    if (st == CVAR_ECANCELLED || st == CVAR_ECALLBACK || st == CVAR_ENOMEM) goto stop;
    if (st) {
      info->failed++;
      continue;
    }
    /* polish by plain Newton (adaptive when asked), from the deflated iterate */
    s->adapt_tol = adapt_tol;
    st = cv_solver_set_start(s, (int)nd, Y);
    if (!st) st = cv_solve(s, p);
    work += s->iterations;
    s->adapt_tol = 0.0;
    cv_solver_set_start(s, 0, NULL);
    if (st == CVAR_ECANCELLED || st == CVAR_ECALLBACK || st == CVAR_ENOMEM) goto stop;
    if (st) {
      info->failed++;
      continue;
    }
    int added = keep_path(s, ps, &w, xs, ev, E, ests);
    if (added < 0) goto nomem;
    if (!added)
      info->duplicates++;
    else
      found_at = work; /* a new path renews the allowance */
  }
  st = CVAR_OK;
  goto finish;
stop: /* cancelled by the progress callback, or a callback's or the memory's failure: the
       * search ends with the paths found so far and that status */
  if (st == CVAR_ENOMEM) goto nomem;
  if (st == CVAR_ECANCELLED)
    cv_set_msg(s->msg, sizeof s->msg, "cancelled by the progress callback after %d starts",
               info->starts);
  goto fail;
nomem:
  st = CVAR_ENOMEM;
  cv_set_msg(s->msg, sizeof s->msg, "out of memory in the search for stationary paths");
fail:
  cv_set_msg(info->stop, sizeof info->stop, "the search stopped: %s", s->msg);
finish:
  s->mesh = spec0;
  s->adapt_tol = adapt_tol;
  s->continuation = cont0;
  cv_free(s->start);
  s->start = start0;
  s->start_len = start_len0;
  cv_free(t);
  cv_free(Y);
  cv_free(xs);
  cv_free(ev);
  cv_free(E);
  for (int k = 0; V && k < max; k++) cv_free(V[k]);
  cv_free(V);
  cv_free(nmodes);
  cv_free(cursor);
  cv_free(ests);
  defl_free(&w);
  cv_disc_free(&ds);
  info->found = ps->n;
  if (ps->n > 0) {
    qsort(ps->v, (size_t)ps->n, sizeof *ps->v, by_action);
    ps->sel = 0;
    path_give(s, &ps->v[0]);
    st = CVAR_OK;
  } else if (st == CVAR_OK) {
    /* nothing converged: the first solve's outcome is what the solver reports */
    st = first;
    if (!s->have || s->status != CVAR_OK) memcpy(s->msg, msg0, sizeof s->msg);
    if (st == CVAR_OK) st = CVAR_EMAXITER;
  }
  if (!info->stop[0]) cv_set_msg(info->stop, sizeof info->stop, "no search was possible");
  s->paths = ps;
  s->status = st;
  s->time = cv_now() - t0;
  return st;
}

cv_status cv_solver_set_search_work(cv_solver *s, double factor) {
  if (!s || !(factor >= 1.0) || !isfinite(factor)) return CVAR_EINVAL;
  s->search_work = factor;
  return CVAR_OK;
}

int cv_solver_get_num_solutions(const cv_solver *s) { return s && s->paths ? s->paths->n : 0; }

cv_status cv_solver_select_solution(cv_solver *s, int k) {
  if (!s) return CVAR_EINVAL;
  if (!s->paths) return CVAR_ESTATE;
  struct cv_pathset *ps = s->paths;
  if (k < 0 || k >= ps->n) return CVAR_EINVAL;
  if (k == ps->sel) return CVAR_OK;
  path_take(&ps->v[ps->sel], s);
  path_give(s, &ps->v[k]);
  ps->sel = k;
  return CVAR_OK;
}

cv_status cv_solver_get_search(const cv_solver *s, cv_search_info *info) {
  if (!s || !info) return CVAR_EINVAL;
  if (!s->paths) return CVAR_ESTATE;
  *info = s->paths->info;
  return CVAR_OK;
}
