/* src/core/cv_hp.c — the hp decisions of one refinement round (theory HP-4, HP-5): for each
 * marked element, raise its degree (smooth) or split it (not smooth, or degree 8),
 * geometrically towards a singular end.
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "cv_internal.h"

/* Legendre coefficients decaying at least like e^(-sigma k) with sigma >= this count as
 * smooth: each extra degree then gains a factor e or more (HP-4). */
#define SMOOTH_RATE 1.0
/* Geometric split ratio towards a singular end or a layer (HP-5). */
#define GEOM_RATIO 0.15

static int clamp_deg(int p) { return p > CV_MAX_DEGREE ? CV_MAX_DEGREE : p < 1 ? 1 : p; }

/* A split point u of [x0, x1] on the reference interval, or -1 when round-off would
 * leave one of the two parts empty (an element near an end of ~1e-16 relative size). */
static double split_at(double x0, double x1, double u, double a, double L) {
  double t0 = (x0 - a) / L, t1 = (x1 - a) / L, tu = (u - a) / L;
  return tu > t0 && tu < t1 && a + L * tu > a + L * t0 && a + L * tu < a + L * t1 ? tu : -1.0;
}

/* HP-4: the degree at which a smooth element's surplus eta, falling like e^(-sigma k),
 * would be below a tenth of the target: p + ceil(ln(eta / (target / 10)) / sigma), at
 * least p + 1, at most 8. */
static int predicted_degree(int p, double eta, double sigma, double target) {
  double k = log(eta / (0.1 * target)) / sigma;
  if (!(k >= 1)) return clamp_deg(p + 1);
  return k > CV_MAX_DEGREE ? CV_MAX_DEGREE : clamp_deg(p + (int)ceil(k));
}

/* HP-4: an element is refined when its surplus is within the marking threshold thresh (a
 * quarter of the largest), or, under hp, when it is smooth and its surplus is above the
 * target and above 1/100 of the largest: raising the degree of every smooth element that
 * misses the target costs few nodes and saves the rounds that would raise them one at a
 * time. Elements that are not smooth keep the factor-4 rule (a layer's neighbours are
 * split only when the layer's own element no longer dominates). */
int cv_hp_marked(double eta, double sigma, double thresh, double target, int hp) {
  if (eta >= thresh) return 1;
  return hp && sigma >= SMOOTH_RATE && eta > target && eta >= 0.04 * thresh;
}

/* HP-4: whether degree 8 is predicted to bring a smooth element's surplus eta (falling like
 * e^(-sigma k)) below a tenth of the target with a degree to spare; if not, the element is
 * halved as well as raised to 8 in the same round instead of one round later. */
static int degree_suffices(int p, double eta, double sigma, double target) {
  double k = log(eta / (0.1 * target)) / sigma;
  return !(k > CV_MAX_DEGREE - p + 1);
}

/* HP-5: where piece j of m of [x0, x1] starts: equal pieces, or, with a singular end that
 * the element does not touch, pieces whose distances from that end grow geometrically,
 * u_j = d0 (d1 / d0)^(j/m) from it (halving: the geometric mean of the element's distances
 * d0, d1). Each piece then has the same ratio of distance to length, so the same rate of
 * convergence in p, instead of the piece nearer the end lagging behind. */
static double piece_start(const cv_disc *d, double x0, double x1, int j, int m) {
  double a = d->xe[0], b = d->xe[d->E];
  if ((d->sing_a || d->sing_b) && x0 > a && x1 < b) {
    int at_a = d->sing_a && (!d->sing_b || x0 - a <= b - x1);
    /* distances from the end of the piece starts, left to right: growing from a,
     * shrinking towards b (from b - x0 at j = 0 to b - x1 at j = m) */
    double d0 = at_a ? x0 - a : b - x0, d1 = at_a ? x1 - a : b - x1;
    double u = d0 * pow(d1 / d0, (double)j / m);
    return at_a ? a + u : b - u;
  }
  return x0 + (x1 - x0) * j / m;
}

/* HP-4: the number of equal degree-8 pieces for a smooth element that degree 8 alone would
 * leave above a tenth of the target: raising p to 8 gains e^(-sigma (8 - p)), and m pieces
 * another m^-(8+1) (the asymptotic h-rate at degree 8), so
 * m = ceil((eta e^(-sigma (8 - p)) / (target / 10))^(1/9)), 2..MAX_PIECES. */
#define MAX_PIECES 16
static int smooth_pieces(int p, double eta, double sigma, double target) {
  double r = eta * exp(-sigma * (CV_MAX_DEGREE - p)) / (0.1 * target);
  double m = ceil(pow(r, 1.0 / (CV_MAX_DEGREE + 1)));
  return !(m >= 2) ? 2 : m > MAX_PIECES ? MAX_PIECES : (int)m;
}

/* HP-8: the degree q of one element replacing elements e and e + 1 (0: no merge): both
 * unmarked, smooth and of degree p, neither touching a singular end. On the union, r_i =
 * (h_e + h_e+1) / h_i times element i, the Legendre rate falls to sigma_i - ln r_i (the
 * ellipse of analyticity shrinks by r_i), so the surplus at degree q is predicted as
 * eta_i e^(-sigma_i (q - p)) r_i^(q+1); q is the least degree from p to min(8, 2p - 1) (fewer
 * nodes than the two) at which both predictions are below a tenth of the target. A
 * start finer than the tolerance needs (a scene's own [mesh]) is so coarsened, round by
 * round, where the solution is smooth, in the first MERGE_ROUNDS rounds only (hp = 2): later
 * merges could undo the refinements of a solution that is only piecewise smooth (a
 * tabulated spline) and the rounds would go round in circles. */
#define MERGE_AIM 0.1 /* merged surplus predicted at most this x target (HP-8) */
static int merged_degree(const cv_disc *d, const double *eta, const double *sigma, double thresh,
                         double target, long e) {
  int p = cv_disc_edeg(d, e);
  if (cv_disc_edeg(d, e + 1) != p || (e == 0 && d->sing_a) || (e + 2 == d->E && d->sing_b))
    return 0;
  double h0 = d->xe[e + 1] - d->xe[e], h1 = d->xe[e + 2] - d->xe[e + 1];
  for (int i = 0; i < 2; i++) {
    double r = (h0 + h1) / (i ? h1 : h0);
    if (cv_hp_marked(eta[e + i], sigma[e + i], thresh, target, 1) ||
        !(sigma[e + i] - log(r) >= SMOOTH_RATE))
      return 0;
  }
  int qmax = 2 * p - 1 < CV_MAX_DEGREE ? 2 * p - 1 : CV_MAX_DEGREE;
  for (int q = p; q <= qmax; q++) {
    int ok = 1;
    for (int i = 0; i < 2 && ok; i++) {
      double r = (h0 + h1) / (i ? h1 : h0);
      ok = eta[e + i] * exp(-sigma[e + i] * (q - p)) * pow(r, q + 1) <= MERGE_AIM * target;
    }
    if (ok) return q;
  }
  return 0;
}

cv_status cv_hp_refine(const cv_disc *d, const double *eta, const double *sigma,
                       const double *where, double thresh, double target, int hp, int *Enew,
                       double **t, int **deg) {
  int E = d->E, F = 0;
  for (int e = 0; e < E; e++)
    F += cv_hp_marked(eta[e], sigma[e], thresh, target, hp) ? MAX_PIECES : 1; /* at most */
  *t = cv_malloc((size_t)(F + 1) * sizeof **t);
  *deg = cv_malloc((size_t)F * sizeof **deg);
  if (!*t || !*deg) {
    cv_free(*t);
    cv_free(*deg);
    *t = NULL;
    *deg = NULL;
    return CVAR_ENOMEM;
  }
  double a = d->xe[0], L = d->xe[E] - a;
  int k = 0;
  for (int e = 0; e < E; e++) {
    int pe = cv_disc_edeg(d, e);
    double x0 = d->xe[e], x1 = d->xe[e + 1];
    (*t)[k] = (x0 - a) / L;
    int q = hp == 2 && e + 1 < E ? merged_degree(d, eta, sigma, thresh, target, e) : 0;
    if (q) { /* HP-8 */
      (*deg)[k++] = q;
      e++;
      continue;
    }
    double tm = split_at(x0, x1, 0.5 * (x0 + x1), a, L);
    double tl = split_at(x0, x1, x0 + GEOM_RATIO * (x1 - x0), a, L);
    double tr = split_at(x0, x1, x1 - GEOM_RATIO * (x1 - x0), a, L);
    int marked = cv_hp_marked(eta[e], sigma[e], thresh, target, hp);
    if (!marked || tm < 0 || tl < 0 || tr < 0) { /* unmarked, or too small */
      (*deg)[k++] = marked ? clamp_deg(pe + 1) : pe;
      continue;
    }
    if (!hp) { /* fixed degree (--adapt): bisect */
      (*deg)[k++] = pe;
      (*t)[k] = tm;
      (*deg)[k++] = pe;
      continue;
    }
    int sing_left = (e == 0 && d->sing_a) ||
                    (!(e == E - 1 && d->sing_b) && where[e] < -0.5 && sigma[e] < SMOOTH_RATE);
    int sing_right = (e == E - 1 && d->sing_b) ||
                     (!(e == 0 && d->sing_a) && where[e] > 0.5 && sigma[e] < SMOOTH_RATE);
    if (sing_left && !sing_right) { /* small element at x0 keeps p, the rest p + 1 (HP-5) */
      (*deg)[k++] = pe;
      (*t)[k] = tl;
      (*deg)[k++] = clamp_deg(pe + 1);
      continue;
    }
    if (sing_right && !sing_left) {
      (*deg)[k++] = clamp_deg(pe + 1);
      (*t)[k] = tr;
      (*deg)[k++] = pe;
      continue;
    }
    if (sigma[e] >= SMOOTH_RATE && pe < CV_MAX_DEGREE) {    /* smooth: raise p (HP-4) */
      if (!degree_suffices(pe, eta[e], sigma[e], target)) { /* and split, in one round */
        int m = smooth_pieces(pe, eta[e], sigma[e], target);
        for (int j = 0; j < m; j++) {
          double tj = split_at(x0, x1, piece_start(d, x0, x1, j, m), a, L);
          if (j > 0 && tj < 0) continue; /* round-off: fewer pieces */
          if (j > 0) (*t)[k] = tj;
          (*deg)[k++] = CV_MAX_DEGREE;
        }
        continue;
      }
      (*deg)[k++] = predicted_degree(pe, eta[e], sigma[e], target);
      continue;
    }
    if (sigma[e] >= SMOOTH_RATE) { /* smooth at degree 8: m pieces (HP-4, HP-5) */
      int m = smooth_pieces(pe, eta[e], sigma[e], target);
      for (int j = 0; j < m; j++) {
        double tj = split_at(x0, x1, piece_start(d, x0, x1, j, m), a, L);
        if (j > 0 && tj < 0) continue;
        if (j > 0) (*t)[k] = tj;
        (*deg)[k++] = pe;
      }
      continue;
    }
    double tsplit = split_at(x0, x1, piece_start(d, x0, x1, 1, 2), a, L);
    (*deg)[k++] = pe; /* not smooth: halve (HP-5: geometrically with a singular end) */
    (*t)[k] = tsplit >= 0 ? tsplit : tm;
    (*deg)[k++] = pe;
  }
  (*t)[0] = 0.0;
  (*t)[k] = 1.0;
  *Enew = k;
  return CVAR_OK;
}

cv_status cv_hp_pilot_mesh(const cv_disc *d, const double *tail, double aim, int *Enew, double **t,
                           int **deg) {
  int E = d->E;
  double total = 0.0;
  for (int e = 0; e < E; e++) total += fmax(1.0, pow(tail[e] / aim, 1.0 / (CV_MAX_DEGREE + 1)));
  double Mr = ceil(total - 1e-9); /* the h-rate at degree 8: tail ~ h^9 */
  int M = !(Mr <= MAX_PIECES * (double)E) ? MAX_PIECES * E : Mr < E + 1 ? E + 1 : (int)Mr;
  *t = cv_malloc((size_t)(M + 1) * sizeof **t);
  *deg = cv_malloc((size_t)M * sizeof **deg);
  if (!*t || !*deg) {
    cv_free(*t);
    cv_free(*deg);
    *t = NULL;
    *deg = NULL;
    return CVAR_ENOMEM;
  }
  /* the k-th boundary where the cumulative share reaches k total / M */
  double a = d->xe[0], L = d->xe[E] - a, cum = 0.0;
  int k = 1, e = 0;
  (*t)[0] = 0.0;
  for (; e < E && k < M; e++) {
    double r = fmax(1.0, pow(tail[e] / aim, 1.0 / (CV_MAX_DEGREE + 1)));
    double t0 = (d->xe[e] - a) / L, t1 = (d->xe[e + 1] - a) / L;
    while (k < M && cum + r >= total * k / M) {
      double u = t0 + (t1 - t0) * (total * k / M - cum) / r;
      if (u > (*t)[k - 1] && u < 1.0)
        (*t)[k++] = u;
      else
        break; /* round-off: fewer elements */
    }
    cum += r;
  }
  (*t)[k] = 1.0;
  for (int j = 0; j < k; j++) (*deg)[j] = CV_MAX_DEGREE;
  *Enew = k;
  return CVAR_OK;
}
