/* src/core/cv_estimate.c — the one a-posteriori error estimate: a warm-started solve on the
 * p-enriched mesh (theory HP-2), checked to have stayed on the same path (HP-3), with the
 * per-element indicators the hp decisions use (HP-4).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <pthread.h>
#include <stdatomic.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

/* Legendre P_0..P_P at s, by the three-term recurrence. */
static void legendre_all(int P, double s, double *L) {
  L[0] = 1.0;
  if (P >= 1) L[1] = s;
  for (int k = 2; k <= P; k++) L[k] = ((2.0 * k - 1.0) * s * L[k - 1] - (k - 1.0) * L[k - 2]) / k;
}

/* The enriched mesh of s's last mesh (HP-2): an element of degree p <= 6 becomes one of
 * degree p + 2; one of degree 7 or 8 is halved, both halves degree 8. (Degree 7 to 8 alone
 * was measured to be too little: at the judged element's GLL nodes, which are not nodes of
 * the enriched element, the degree-8 solution was barely better than the degree-7 one, and
 * the estimate came out 10x below the true error on an oscillator.) */
static int enrich_split(int p) { return p >= CV_MAX_DEGREE - 1; }
static int enrich_deg(int p) { return p + 2 > CV_MAX_DEGREE ? CV_MAX_DEGREE : p + 2; }

/* Everything the estimate evaluates on an element of degree p depends on p alone: the
 * enriched element(s) made from it (degree P = enrich_deg(p), halved when enrich_split(p))
 * and the points where they are read. So the Lagrange and Legendre values are tables, one
 * per degree, computed once per process (like the rules of cv_quadrature.c) instead of at
 * every point of every element of every round (they were ~40 % of a --tol run's
 * instructions on a smooth problem). A row reads the enriched values F of the element:
 * F[0..P] those of its (first) enriched element, F[P+1..] of the second half's (split). */
#define NF (2 * (CV_MAX_DEGREE + 1)) /* enriched values of one element, at most */
#define NG (CV_MAX_DEGREE + 3)       /* Gauss points of the surplus, at most */
typedef struct {
  int P, split, G;
  /* rows of P + 1 weights, each with its offset into F (0, or P + 1 on a split's right half) */
  double nodes[CV_MAX_DEGREE + 1][CV_MAX_DEGREE + 1]; /* at the element's own GLL nodes */
  int nodes_off[CV_MAX_DEGREE + 1];
  double gll[CV_MAX_DEGREE + 1][CV_MAX_DEGREE + 1]; /* at the GLL points of degree P */
  int gll_off[CV_MAX_DEGREE + 1];
  double gauss[NG][CV_MAX_DEGREE + 1]; /* at the G Gauss points */
  int gauss_off[NG];
  double ip[NG][CV_MAX_DEGREE + 1];                 /* degree-p interpolant at the Gauss points */
  double leg[CV_MAX_DEGREE + 1][CV_MAX_DEGREE + 1]; /* Legendre coefficients from GLL_P values */
  double warm[NF][CV_MAX_DEGREE + 1]; /* the element's degree-p values at the enriched nodes */
  double self[CV_MAX_DEGREE + 1][CV_MAX_DEGREE + 1];   /* Legendre coefficients from GLL_p values */
  double xi[CV_MAX_DEGREE + 1], bw[CV_MAX_DEGREE + 1]; /* GLL_p nodes, barycentric weights */
  int nwarm;                                           /* enriched nodes (both halves when split) */
} est_table;

static pthread_mutex_t table_lock = PTHREAD_MUTEX_INITIALIZER;
static struct {
  atomic_int ready;
  est_table t;
} tables[CV_MAX_DEGREE + 1];

/* Weights of the enriched values at reference coordinate tau of the judged element: the
 * row and its offset into F (a split's halves: tau <= 0 the left one, as before). */
static int enriched_row(const est_table *T, double tau, double *row) {
  double xiP[CV_MAX_DEGREE + 1], wl[CV_MAX_DEGREE + 1];
  cv_gauss_lobatto(T->P, xiP, wl);
  int off = 0;
  if (T->split) {
    if (tau > 0)
      off = T->P + 1, tau = 2.0 * tau - 1.0;
    else
      tau = 2.0 * tau + 1.0;
  }
  cv_lagrange(T->P, xiP, tau, row, NULL);
  return off;
}

static void table_compute(est_table *T, int p) {
  double xi[CV_MAX_DEGREE + 1], wl[CV_MAX_DEGREE + 1], xiP[CV_MAX_DEGREE + 1],
      wP[CV_MAX_DEGREE + 1], tg[NG], wg[NG], L[CV_MAX_DEGREE + 1];
  memset(T, 0, sizeof *T);
  T->P = enrich_deg(p);
  T->split = enrich_split(p);
  T->G = p + 3; /* Gauss points of the surplus: none is a node of I_p */
  int P = T->P;
  cv_gauss_lobatto(p, xi, wl);
  cv_gauss_lobatto(P, xiP, wP);
  cv_gauss_legendre(T->G, tg, wg);
  for (int l = 0; l <= p; l++) T->nodes_off[l] = enriched_row(T, xi[l], T->nodes[l]);
  for (int l = 0; l <= P; l++) T->gll_off[l] = enriched_row(T, xiP[l], T->gll[l]);
  for (int l = 0; l < T->G; l++) {
    T->gauss_off[l] = enriched_row(T, tg[l], T->gauss[l]);
    cv_lagrange(p, xi, tg[l], T->ip[l], NULL);
  }
  /* a_k = (2k + 1)/2 sum_l w_l y_l P_k(x_l), a_P with the discrete norm 2/P of P_P */
  for (int l = 0; l <= P; l++) {
    legendre_all(P, xiP[l], L);
    for (int k = 0; k <= P; k++)
      T->leg[k][l] = wP[l] * L[k] * (k < P ? 0.5 * (2 * k + 1) : 0.5 * P);
  }
  for (int l = 0; l <= p; l++) {
    legendre_all(p, xi[l], L);
    for (int k = 0; k <= p; k++)
      T->self[k][l] = wl[l] * L[k] * (k < p ? 0.5 * (2 * k + 1) : 0.5 * p);
  }
  for (int l = 0; l <= p; l++) {
    double w = 1.0;
    for (int m = 0; m <= p; m++)
      if (m != l) w *= xi[l] - xi[m];
    T->xi[l] = xi[l];
    T->bw[l] = 1.0 / w;
  }
  T->nwarm = T->split ? 2 * (P + 1) : P + 1;
  for (int m = 0; m <= P; m++) {
    if (T->split) {
      cv_lagrange(p, xi, 0.5 * (xiP[m] - 1.0), T->warm[m], NULL);
      cv_lagrange(p, xi, 0.5 * (xiP[m] + 1.0), T->warm[P + 1 + m], NULL);
    } else {
      cv_lagrange(p, xi, xiP[m], T->warm[m], NULL);
    }
  }
}

static const est_table *table_get(int p) {
  if (!atomic_load_explicit(&tables[p].ready, memory_order_acquire)) {
    est_table tmp;
    table_compute(&tmp, p); /* outside the lock: the rules take their own */
    pthread_mutex_lock(&table_lock);
    if (!atomic_load_explicit(&tables[p].ready, memory_order_relaxed)) {
      tables[p].t = tmp;
      atomic_store_explicit(&tables[p].ready, 1, memory_order_release);
    }
    pthread_mutex_unlock(&table_lock);
  }
  return &tables[p].t;
}

/* The enriched values of the element(s) made from judged element e into F[l*n + i]
 * (f's first element for e is fe). */
static void gather(const cv_solver *f, long fe, const est_table *T, double *F) {
  int n = f->disc.n;
  size_t m = (size_t)(T->P + 1) * n;
  memcpy(F, f->y + (size_t)cv_disc_enode(&f->disc, fe) * n, m * sizeof *F);
  if (T->split) memcpy(F + m, f->y + (size_t)cv_disc_enode(&f->disc, fe + 1) * n, m * sizeof *F);
}

/* One row of weights (P + 1 of them from offset off) applied to F, unknown i. Evaluated
 * through the element's own basis, not through x: near an end x has an ulp of ~1e-16 and a
 * layer's y' of 1e8 would turn that into 1e-8 (measured: a floor of the estimate at 4e-9
 * for eps = 1e-8). */
static double apply_row(const double *row, int off, int P, const double *F, int n, int i) {
  double v = 0.0;
  for (int l = 0; l <= P; l++) v += F[(size_t)(off + l) * n + i] * row[l];
  return v;
}

/* Start solver s (its mesh set, about to be solved) from the solution held by `from`,
 * interpolated at s's nodes, through a discretisation of s's mesh and cv_solver_eval. */
static cv_status warm_start_generic(cv_solver *s, const cv_problem *p, const cv_solver *from) {
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

/* The degree-p Lagrange basis at GLL_p through the second barycentric formula (p + 1
 * divisions instead of p (p + 1)): phi_l = (w_l / (s - x_l)) / sum_k (w_k / (s - x_k)). */
static void bary_basis(const est_table *T, int p, double s, double *phi) {
  double sum = 0.0;
  for (int l = 0; l <= p; l++) {
    double ds = s - T->xi[l];
    if (ds == 0.0) { /* at a node */
      for (int k = 0; k <= p; k++) phi[k] = k == l;
      return;
    }
    phi[l] = T->bw[l] / ds;
    sum += phi[l];
  }
  for (int l = 0; l <= p; l++) phi[l] /= sum;
}

/* Start solver s (its mesh set, about to be solved) from the solution held by `from`,
 * interpolated at s's nodes. An hp mesh of the rounds (t on [0, 1] and degrees, no
 * breakpoints) is read directly and its nodes, in increasing order, met by one sweep over
 * `from`'s elements; other meshes are discretised first. */
cv_status cv_warm_start(cv_solver *s, const cv_problem *p, const cv_solver *from) {
  const cv_meshspec *m = &s->mesh;
  const cv_disc *fd = &from->disc;
  if (!(m->kind == CV_MESH_USER && m->t && m->degrees && m->nbreak == 0) || !from->have)
    return warm_start_generic(s, p, from);
  int n = p->n, E = m->elements;
  long N = 1;
  for (int e = 0; e < E; e++) N += m->degrees[e];
  double *y = cv_malloc((size_t)N * n * sizeof *y), a = p->a, L = p->b - p->a;
  if (!y) return CVAR_ENOMEM;
  long j = 0, lo = 0;
  for (int e = 0; e < E; e++) {
    int pe = m->degrees[e];
    const est_table *Te = table_get(pe);
    double x0 = a + L * m->t[e], h = a + L * m->t[e + 1] - x0;
    for (int l = 0; l < pe + (e == E - 1); l++, j++) {
      double x = l == pe ? a + L : x0 + 0.5 * (Te->xi[l] + 1.0) * h;
      while (lo < fd->E - 1 && fd->xe[lo + 1] <= x) lo++;
      int q = cv_disc_edeg(fd, lo);
      const est_table *Tq = table_get(q);
      double phi[CV_MAX_DEGREE + 1], hq = fd->xe[lo + 1] - fd->xe[lo];
      double tau = fmin(1.0, fmax(-1.0, 2.0 * (x - fd->xe[lo]) / hq - 1.0));
      bary_basis(Tq, q, tau, phi);
      const double *Y = from->y + (size_t)cv_disc_enode(fd, lo) * n;
      for (int i = 0; i < n; i++) {
        double v = 0.0;
        for (int k = 0; k <= q; k++) v += phi[k] * Y[(size_t)k * n + i];
        y[(size_t)j * n + i] = v;
      }
    }
  }
  cv_status st = cv_solver_set_start(s, (int)(N * n), y);
  cv_free(y);
  return st;
}

/* The enriched mesh (t on [0, 1], degrees) of d's mesh, as enrich_split/enrich_deg say. */
static cv_status enriched_mesh(const cv_disc *d, int *Ef, double **t, int **deg) {
  int E = d->E, n8 = 0;
  for (int e = 0; e < E; e++) n8 += enrich_split(cv_disc_edeg(d, e));
  int F = E + n8;
  *t = cv_malloc((size_t)(F + 1) * sizeof **t);
  *deg = cv_malloc((size_t)F * sizeof **deg);
  if (!*t || !*deg) return CVAR_ENOMEM;
  double a = d->xe[0], L = d->xe[E] - a;
  int k = 0;
  for (int e = 0; e < E; e++) {
    int pe = cv_disc_edeg(d, e);
    (*t)[k] = (d->xe[e] - a) / L;
    if (enrich_split(pe)) {
      (*deg)[k++] = CV_MAX_DEGREE;
      (*t)[k] = (0.5 * (d->xe[e] + d->xe[e + 1]) - a) / L;
    }
    (*deg)[k++] = pe + 2 > CV_MAX_DEGREE ? CV_MAX_DEGREE : pe + 2;
  }
  (*t)[0] = 0.0;
  (*t)[F] = 1.0;
  *Ef = F;
  return CVAR_OK;
}

/* Per-element indicators from the enriched solution f on the elements of d (HP-4): the
 * local surplus eta[e] = max |f - I_p f| over the GLL points of degree P = min(p + 2, 8)
 * of e (I_p: the degree-p interpolant of f at e's own GLL nodes), and the decay rate
 * sigma[e] of the Legendre coefficients of f's degree-P interpolant on e (least squares
 * slope of log |a_k|, k = 1..P, floored at round-off; the largest over components is not
 * used: the smallest rate, the least smooth component, decides), and where[e] the
 * reference coordinate in [-1, 1] at which the surplus is largest. */
/* Minus the least-squares slope of ln|a_k| against k for k = 1..P, the coefficients
 * floored at 1e-15 of the largest (HP-4). */
static double decay_rate(const double *a, int P) {
  double amax = 0.0;
  for (int k = 0; k <= P; k++) amax = fmax(amax, fabs(a[k]));
  double floor_ = 1e-15 * (amax > 0 ? amax : 1.0), sk = 0, sl = 0, skk = 0, skl = 0;
  int m = 0;
  for (int k = 1; k <= P; k++, m++) {
    double lk = log(fmax(fabs(a[k]), floor_));
    sk += k, sl += lk, skk += (double)k * k, skl += k * lk;
  }
  return -(m * skl - sk * sl) / (m * skk - sk * sk);
}

cv_status cv_estimate_pilot(const cv_solver *s, double *tail, double *sigma) {
  const cv_disc *d = &s->disc;
  int n = d->n;
  for (long e = 0; e < d->E; e++) {
    int pe = cv_disc_edeg(d, e);
    const est_table *T = table_get(pe);
    const double *Y = s->y + (size_t)cv_disc_enode(d, e) * n;
    double tl = 0.0, sg = INFINITY;
    for (int i = 0; i < n; i++) {
      double a[CV_MAX_DEGREE + 1];
      for (int k = 0; k <= pe; k++) {
        a[k] = 0.0;
        for (int l = 0; l <= pe; l++) a[k] += T->self[k][l] * Y[(size_t)l * n + i];
      }
      double rate = decay_rate(a, pe);
      sg = fmin(sg, rate);
      double next = fabs(a[pe]) * exp(-fmax(rate, 0.0)); /* a_{p+1}, extrapolated */
      if (!(next <= tl)) tl = next;                      /* NaN propagates */
    }
    tail[e] = tl;
    sigma[e] = sg;
  }
  return CVAR_OK;
}

cv_status cv_estimate_indicators(const cv_solver *s, const cv_solver *f, double *eta, double *sigma,
                                 double *where) {
  const cv_disc *d = &s->disc;
  int n = d->n;
  double *F = cv_malloc((size_t)n * NF * sizeof *F);
  double *ys = cv_malloc((size_t)n * (CV_MAX_DEGREE + 1) * sizeof *ys);
  double *yl = cv_malloc((size_t)n * (CV_MAX_DEGREE + 1) * sizeof *yl);
  cv_status st = F && ys && yl ? CVAR_OK : CVAR_ENOMEM;
  for (long e = 0, fe = 0; e < d->E && !st; e++) {
    int pe = cv_disc_edeg(d, e);
    const est_table *T = table_get(pe);
    int P = T->P, G = T->G;
    gather(f, fe, T, F);
    fe += 1 + T->split;
    /* f at e's own nodes (for I_p f) and at the P + 1 GLL points (Legendre coefficients) */
    for (int i = 0; i < n; i++) {
      for (int l = 0; l <= pe; l++)
        yl[i * (pe + 1) + l] = apply_row(T->nodes[l], T->nodes_off[l], P, F, n, i);
      for (int l = 0; l <= P; l++)
        ys[i * (P + 1) + l] = apply_row(T->gll[l], T->gll_off[l], P, F, n, i);
    }
    double eta_e = 0.0, sig_e = INFINITY, at = 0.0, tg[NG], wg[NG];
    cv_gauss_legendre(G, tg, wg);
    for (int i = 0; i < n; i++) {
      double a[CV_MAX_DEGREE + 1];
      for (int l = 0; l < G; l++) { /* the surplus at the Gauss points */
        double ip = 0.0;
        for (int m = 0; m <= pe; m++) ip += T->ip[l][m] * yl[i * (pe + 1) + m];
        double dlt = fabs(apply_row(T->gauss[l], T->gauss_off[l], P, F, n, i) - ip);
        if (!(dlt <= eta_e)) eta_e = dlt, at = tg[l]; /* NaN propagates */
      }
      for (int k = 0; k <= P; k++) {
        a[k] = 0.0;
        for (int l = 0; l <= P; l++) a[k] += T->leg[k][l] * ys[i * (P + 1) + l];
      }
      double rate = decay_rate(a, P);
      if (rate < sig_e) sig_e = rate;
    }
    eta[e] = eta_e;
    sigma[e] = sig_e;
    where[e] = at;
  }
  cv_free(F);
  cv_free(ys);
  cv_free(yl);
  return st;
}

/* Start f (its mesh the enriched mesh of s's) from s's solution: element by element, s's
 * degree-p values at the enriched nodes (est_table.warm), with no search for the element
 * of each node and no discretisation of f's mesh beforehand. */
static cv_status enriched_start(cv_solver *f, const cv_solver *s, int nodes_f) {
  const cv_disc *d = &s->disc;
  int n = d->n;
  double *y = cv_malloc((size_t)nodes_f * n * sizeof *y);
  if (!y) return CVAR_ENOMEM;
  long j = 0; /* f's first node of the enriched element(s) of e */
  for (long e = 0; e < d->E; e++) {
    int pe = cv_disc_edeg(d, e);
    const est_table *T = table_get(pe);
    const double *Y = s->y + (size_t)cv_disc_enode(d, e) * n;
    for (int m = 0; m < T->nwarm; m++) {
      if (T->split && m == T->P + 1) continue; /* the halves share their middle node */
      double *out = y + (size_t)(j + (m > T->P ? m - 1 : m)) * n;
      for (int i = 0; i < n; i++) {
        double v = 0.0;
        for (int l = 0; l <= pe; l++) v += T->warm[m][l] * Y[(size_t)l * n + i];
        out[i] = v;
      }
    }
    j += T->split ? 2 * T->P : T->P;
  }
  cv_status st = j + 1 == nodes_f ? cv_solver_set_start(f, nodes_f * n, y) : CVAR_EINVAL;
  cv_free(y);
  return st;
}

/* HP-3: the enriched solution f is of the same kind as s when the number of directions of
 * negative curvature agrees (the Morse index) or that of positive curvature does (the
 * co-index, free directions minus Morse index), or s's is not known (an NLopt answer: then
 * only the distance moved decides). The enriched mesh has more free directions,
 * so a maximum (co-index 0) has a larger Morse index there than on s's mesh, and a path of
 * small co-index likewise; a minimum or saddle of small index keeps its Morse index. */
static int same_kind(const cv_solver *s, const cv_solver *f) {
  if (f->morse == s->morse || s->morse < 0)
    return 1; /* < 0: not known (NLopt): the distance decides */
  int cs = cv_solver_get_num_free(s) - s->morse, cf = cv_solver_get_num_free(f) - f->morse;
  return s->morse >= 0 && f->morse >= 0 && cs == cf;
}

/* (HP-2, HP-3) Solve on the enriched mesh of s's last solution, warm-started from it, into
 * f (configured like s, continuation off); est = max over s's nodes of |y_s - y_f|. With
 * eta and sigma (E entries each, may be NULL) the indicators of HP-4. CVAR_OK, or an error
 * with a sentence in msg: the enriched solve failed, or it stopped on another stationary
 * path (other Morse index, or moved by more than the distance Newton was asked to trust),
 * which is then no error bound. */
cv_status cv_estimate_enriched(const cv_solver *s, const cv_problem *p, cv_solver *f, double *est,
                               double *est_vertex, double *floor_out, char *msg, size_t len) {
  const cv_disc *d = &s->disc;
  int Ef = 0, *deg = NULL, n = p->n;
  double *t = NULL, *yf = NULL;
  cv_status st = enriched_mesh(d, &Ef, &t, &deg);
  *est = NAN;
  if (est_vertex) *est_vertex = NAN;
  if (floor_out) *floor_out = NAN;
  if (s->smooth_w > 0) { /* HC-4: an enriched solve would miss the smoothing's own error */
    cv_free(t), cv_free(deg);
    cv_set_msg(msg, len,
               "the answer is of the integrand with its jumps smoothed over w = %.3g, whose "
               "error (first order in w) a solve with higher degrees cannot measure",
               s->smooth_w);
    return CVAR_ESTATE;
  }
  f->nq = 0;
  /* The enriched solve's Newton step test: the caller's, but not below 1e-12. y+ is wanted
   * to a fraction of the error it measures, and Newton's last step is the square of the one
   * before, so its error is far below the test's; a smaller test asks, next to a singular
   * end, for what round-off cannot give (the line search then fails: brachistochrone
   * --tol 1e-10 --tolerance 1e-14) (HP-2). */
  f->rtol = fmax(s->rtol, 1e-12);
  f->atol = fmax(s->atol, 1e-12);
  f->maxit = s->maxit;
  f->method = CVAR_METHOD_NEWTON;
  f->continuation = 0;
  f->adapt_tol = 0.0;
  f->polish = 1; /* HP-2a */
  f->ends_passed[0] = s->ends_ok[0], f->ends_passed[1] = s->ends_ok[1];
  if (!st) st = cv_solver_set_breakpoints(f, 0, NULL);
  if (!st) st = cv_solver_set_mesh_hp(f, Ef, t, deg);
  int nodes_f = 1;
  for (int k = 0; k < Ef; k++) nodes_f += deg ? deg[k] : 0;
  if (!st) st = enriched_start(f, s, nodes_f);
  if (st) {
    cv_set_msg(msg, len, "out of memory for the error estimate");
    goto cleanup;
  }
  st = cv_solve_mesh(f, p);
  cv_solver_set_start(f, 0, NULL);
  if (st) {
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate failed, so nothing confirms that this "
               "discrete path is near a stationary path of the integral: the mesh may not "
               "resolve it, or there may be none (ends at a conjugate point); check on a finer "
               "mesh or with higher degrees (the enriched solve: %s)",
               f->msg);
    goto cleanup;
  }
  if (!same_kind(s, f)) {
    st = CVAR_EDIVERGED;
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate stopped on another stationary path "
               "(Morse index %d of %d free directions, this one %d of %d): no error bound",
               f->morse, cv_solver_get_num_free(f), s->morse, cv_solver_get_num_free(s));
    goto cleanup;
  }
  yf = cv_malloc((size_t)NF * n * sizeof *yf);
  if (!yf) {
    st = CVAR_ENOMEM;
    cv_set_msg(msg, len, "out of memory for the error estimate");
    goto cleanup;
  }
  /* max over s's nodes of |y_s - y_f|, element by element through the reference
   * coordinates (est_table.nodes); the vertices alone too */
  double e = 0.0, ev = 0.0, scale = 0.0, rox = 0.0;
  for (long el = 0, fe = 0; el < d->E; el++) {
    int pe = cv_disc_edeg(d, el);
    const est_table *T = table_get(pe);
    long j0 = cv_disc_enode(d, el);
    /* HP-2: a node's abscissa is a double, within half an ulp, eps |x| / 2, of the node:
     * the value there carries |y'| times that (slopes between neighbouring nodes stand
     * for y') */
    const double *xi = cv_disc_eref(d, el)->xi;
    double h = d->xe[el + 1] - d->xe[el];
    double ulp = 0.5 * DBL_EPSILON * fmax(fabs(d->xe[el]), fabs(d->xe[el + 1]));
    for (int l = 0; l < pe; l++)
      for (int i = 0; i < n; i++) {
        double dy = s->y[(size_t)(j0 + l + 1) * n + i] - s->y[(size_t)(j0 + l) * n + i];
        rox = fmax(rox, fabs(dy) / (0.5 * h * (xi[l + 1] - xi[l])) * ulp);
      }
    gather(f, fe, T, yf);
    fe += 1 + T->split;
    for (int l = 0; l <= pe; l++)
      for (int i = 0; i < n; i++) {
        double v = apply_row(T->nodes[l], T->nodes_off[l], T->P, yf, n, i);
        double dl = fabs(s->y[(size_t)(j0 + l) * n + i] - v);
        if (!(dl <= e)) e = dl;
        if ((l == 0 || l == pe) && !(dl <= ev)) ev = dl;
        scale = fmax(scale, fabs(v));
      }
  }
  if (!isfinite(e)) {
    st = CVAR_ENONFINITE;
    cv_set_msg(msg, len, "the error estimate is not finite");
    goto cleanup;
  }
  /* HP-3: a Newton solve started within e of its answer that ends as far away as the path
   * is large has not refined this path but found another one */
  if (e > 0.5 * (scale > 0 ? scale : 1.0) && e > 1e-3) {
    st = CVAR_EDIVERGED;
    cv_set_msg(msg, len,
               "the enriched solve for the error estimate moved %.2g from this path (of size "
               "%.2g): another stationary path or an unresolved mesh, no error bound",
               e, scale);
    goto cleanup;
  }
  /* HP-2: never below the round-off of the values themselves (both solves carry it) */
  double ro = CV_ROUNDOFF_ULPS * DBL_EPSILON * fmax(scale, 1.0);
  *est = fmax(e, ro) + rox;
  if (est_vertex) *est_vertex = fmax(ev, ro) + rox;
  if (floor_out) *floor_out = ro + rox;
cleanup:
  cv_free(t);
  cv_free(deg);
  cv_free(yf);
  return st;
}

cv_status cv_solver_estimate_error(const cv_solver *s, const cv_problem *p, double *est,
                                   double *est_vertex, char *msg, size_t len) {
  if (!s || !p || !est) return CVAR_EINVAL;
  p = cv_ends_solved(s, p); /* a moving end: the interval solved last (ME-1) */
  *est = NAN;
  if (est_vertex) *est_vertex = NAN;
  if (!s->have || s->status != CVAR_OK) {
    cv_set_msg(msg, len, "no converged solve to estimate the error of");
    return CVAR_ESTATE;
  }
  cv_status st;
  cv_solver *f = cv_solver_new(&st);
  if (!f) return st;
  if (s->disc.herm)
    st = cv_hermite_estimate(s, p, f, est, est_vertex, NULL, msg, len);
  else
    st = cv_estimate_enriched(s, p, f, est, est_vertex, NULL, msg, len);
  if (!st && cv_kkt_has_inequalities(p)) *est = fmax(*est, cv_contact_gap_term(s, p, NULL));
  cv_solver_free(f);
  return st;
}
