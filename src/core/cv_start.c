/* src/core/cv_start.c — the start of a solve: discretisation of the current mesh spec,
 * starting values (given, guessed or the straight line) and singular-end detection.
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

/* The default start at fraction t of the interval: the straight line between the end
 * values (a free end takes the other end's value; both free: 0). */
CV_HOT void cv_start_line(const cv_problem *p, double t, double *y) {
  for (int i = 0; i < p->n; i++) {
    int fa = p->fixed[2 * i], fb = p->fixed[2 * i + 1];
    double ya = p->endval[2 * i], yb = p->endval[2 * i + 1];
    if (!fa) ya = fb ? yb : 0.0;
    if (!fb) yb = ya;
    y[i] = ya + (yb - ya) * t;
  }
}

/* Starting values from the guess callback, batch by batch (out of line, with its batch of
 * abscissae, so that the frame of a solve without a guess stays small). */
static __attribute__((noinline)) cv_status guess_values(cv_solver *s, const cv_problem *p,
                                                        const cv_disc *d, double *Y) {
  int n = p->n;
  double xb[CV_BATCH], *yb = cv_malloc((size_t)n * CV_BATCH * sizeof *yb);
  if (!yb) return CVAR_ENOMEM;
  for (long j0 = 0; j0 < d->nodes; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int k = 0; k < m; k++) xb[k] = cv_disc_node_x(d, j0 + k);
    int rc = p->guess(m, xb, yb, p->guess_user), bad = -1, comp = 0;
    for (int k = 0; k < m && rc == 0 && bad < 0; k++)
      for (int i = 0; i < n; i++) {
        if (!isfinite(yb[i * m + k]) && bad < 0) bad = k, comp = i;
        Y[(j0 + k) * n + i] = yb[i * m + k];
      }
    if (rc || bad >= 0) { /* the abscissa itself: the core knows no variable's name */
      if (rc)
        cv_set_msg(s->msg, sizeof s->msg,
                   "the initial guess's callback failed (returned %d) on the nodes from %.17g "
                   "to %.17g",
                   rc, xb[0], xb[m - 1]);
      else
        cv_set_msg(
            s->msg, sizeof s->msg,
            "the initial guess of unknown number %d is %g at the node %.17g of the interval; "
            "give a [guess] that is finite on the whole interval",
            comp + 1, yb[comp * m + bad], xb[bad]);
      cv_free(yb);
      return rc ? CVAR_ECALLBACK : CVAR_ENONFINITE;
    }
  }
  cv_free(yb);
  return CVAR_OK;
}

/* Initial nodal values: user start, guess callback, or (always with line = 1) the
 * straight line. Fixed ends always win. */
cv_status cv_start_values(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y,
                          int line) {
  int n = p->n;
  if (d->herm) return cv_hermite_start_values(s, p, d, Y, line);
  if (s->start && !line) {
    if (s->start_len != d->ndof) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "start vector has %d values but the mesh has %d nodes x %d unknowns", s->start_len,
                 d->nodes, n);
      return CVAR_EINVAL;
    }
    cv_dcopy(Y, s->start, (size_t)d->ndof);
  } else if (p->guess && !line) {
    cv_status st = guess_values(s, p, d, Y);
    if (st) return st;
  } else {
    /* node by node, element by element: no array of abscissae (a large solve faults in
     * every page it allocates, docs/performance.md) */
    double rl = 1.0 / (d->b - d->a);
    for (long e = 0; e < d->E; e++) {
      double x0 = d->xe[e], h = d->xe[e + 1] - x0;
      const double *xi = cv_disc_eref(d, e)->xi;
      for (int l = 0, pe = cv_disc_edeg(d, e); l < pe; l++) {
        double x = l ? x0 + 0.5 * (xi[l] + 1.0) * h : x0;
        cv_start_line(p, (x - d->a) * rl, Y + (cv_disc_enode(d, e) + l) * n);
      }
    }
    cv_start_line(p, 1.0, Y + (d->nodes - 1) * n);
    for (int i = 0; i < n; i++) { /* exactly, so that no blend below is needed */
      if (p->fixed[2 * i]) Y[i] = p->endval[2 * i];
      if (p->fixed[2 * i + 1]) Y[(d->nodes - 1) * n + i] = p->endval[2 * i + 1];
    }
  }
  /* A start or guess that misses the fixed end values is shifted onto them by a linear
   * blend, da (1 - t) + db t, rather than having its end nodes overwritten: a kink in the
   * end elements makes a poor Newton start (measured: a catenary warm-started from its
   * neighbour in a continuation diverged with the end nodes overwritten). */
  long last = d->nodes - 1;
  for (int i = 0; i < n; i++) {
    double da = p->fixed[2 * i] ? p->endval[2 * i] - Y[i] : 0.0;
    double db = p->fixed[2 * i + 1] ? p->endval[2 * i + 1] - Y[last * n + i] : 0.0;
    if (da == 0.0 && db == 0.0) continue;
    for (long j = 0; j <= last; j++) {
      double t = (cv_disc_node_x(d, j) - d->a) / (d->b - d->a);
      Y[j * n + i] += da * (1.0 - t) + db * t;
    }
    if (p->fixed[2 * i]) Y[i] = p->endval[2 * i];
    if (p->fixed[2 * i + 1]) Y[last * n + i] = p->endval[2 * i + 1];
  }
  return CVAR_OK;
}

/* An end where F itself is not finite at the end value (the brachistochrone's 1/sqrt(y) at
 * y = 0) gets the singular-end rule on its element; Gauss points avoid the end, but a
 * fixed Gauss rule under-integrates there and the discrete minimiser exploits it. */
static void detect_singular_ends(const cv_problem *p, cv_disc *d, const double *Y) {
  int n = p->n;
  /* y, y' and F at one point: on the stack for up to 8 unknowns (one allocation fewer in
   * every solve, docs/performance.md) */
  double x, local[17], *buf = n <= 8 ? local : cv_malloc((2 * (size_t)n + 1) * sizeof *buf);
  if (!buf) return;
  for (int end = 0; end < 2; end++) {
    long node = end ? d->nodes - 1 : 0;
    long e = end ? d->E - 1 : 0;
    double h = d->xe[e + 1] - d->xe[e], phi[CV_MAX_DEGREE + 1], dphi[CV_MAX_DEGREE + 1];
    int pe = cv_disc_edeg(d, e);
    cv_lagrange(pe, cv_disc_eref(d, e)->xi, end ? 1.0 : -1.0, phi, dphi);
    for (int i = 0; i < n; i++) {
      double dv = 0.0;
      for (int l = 0; l <= pe; l++) dv += Y[(cv_disc_enode(d, e) + l) * n + i] * dphi[l];
      buf[i] = Y[node * n + i];
      buf[n + i] = dv * 2.0 / h;
    }
    x = end ? d->b : d->a;
    cv_partials o = {buf + 2 * n, NULL, NULL, NULL, NULL, NULL};
    int rc = p->F(1, &x, buf, buf + n, CVAR_NEED_F, &o, p->user);
    /* infinite (or "cannot evaluate here"), not NaN: a NaN end is undefined, not singular */
    int singular = rc > 0 || (rc == 0 && isinf(o.F[0]));
    if (end)
      d->sing_b = singular;
    else
      d->sing_a = singular;
  }
  if (buf != local) cv_free(buf);
}

/* Discretisation, starting values and singular-end detection for the current mesh spec. */
cv_status cv_start_setup(cv_solver *s, const cv_problem *p) {
  cv_status st;
  cv_solver_drop_results(s);
  st = cv_disc_init(&s->disc, p, s, s->msg, sizeof s->msg);
  if (st) {
    if (st == CVAR_ENOMEM) cv_set_msg(s->msg, sizeof s->msg, "out of memory building the mesh");
    return st;
  }
  s->y = cv_malloc((size_t)s->disc.ndof * sizeof *s->y);
  s->mult = cv_calloc((size_t)s->disc.nodes * p->nc + p->ni + 1, sizeof *s->mult);
  if (!s->y || !s->mult) {
    cv_set_msg(s->msg, sizeof s->msg, "out of memory for %d nodal values", s->disc.ndof);
    return CVAR_ENOMEM;
  }
  st = cv_start_values(s, p, &s->disc, s->y, 0);
  if (st) return st;
  s->have = 1;
  if (!s->disc.herm) detect_singular_ends(p, &s->disc, s->y); /* C^1: Gauss rules only */
  s->disc.sing_a |= s->near_sing[0];
  s->disc.sing_b |= s->near_sing[1];
  st = cv_disc_build_singular_rules(&s->disc);
  if (st) cv_set_msg(s->msg, sizeof s->msg, "out of memory for the singular-end quadrature");
  return st;
}

/* The discrete integral of F over element e with rule r (reference points, weights and
 * basis tables), from the element's nodal values Ye. buf: q (2 n + 2) doubles. Returns 0
 * when F fails or is not finite. */
CV_HOT static int element_integral(const cv_problem *p, const cv_disc *d, const double *Ye, long e,
                                   const cv_rule *r, double *buf, double *S) {
  int n = p->n, P1 = cv_disc_edeg(d, e) + 1, q = r->q;
  double x0 = d->xe[e], h = d->xe[e + 1] - x0, *x = buf, *y = x + q, *dy = y + (size_t)n * q;
  double *F = dy + (size_t)n * q;
  for (int k = 0; k < q; k++) {
    x[k] = x0 + 0.5 * (r->tau[k] + 1.0) * h;
    for (int i = 0; i < n; i++) {
      double a = 0.0, b = 0.0;
      for (int l = 0; l < P1; l++) {
        a += Ye[l * n + i] * r->B[k * P1 + l];
        b += Ye[l * n + i] * r->D[k * P1 + l];
      }
      y[i * q + k] = a;
      dy[i * q + k] = b * 2.0 / h;
    }
  }
  cv_partials o = {F, NULL, NULL, NULL, NULL, NULL};
  int rc = p->F(q, x, y, dy, CVAR_NEED_F, &o, p->user);
  double sum = 0.0;
  for (int k = 0; k < q; k++) sum += 0.5 * h * r->omega[k] * F[k];
  *S = sum;
  return rc == 0 && isfinite(sum);
}

/* The gap of element e (nodal values Ye) between its own rule and r1 (see rule_gap). */
CV_HOT static double gap_with(const cv_problem *p, const cv_disc *d, const double *Ye, long e,
                              const cv_rule *r1, double *buf, double *own) {
  double S0, S1;
  cv_rule r0 = cv_disc_rule(d, e);
  int ok =
      element_integral(p, d, Ye, e, &r0, buf, &S0) && element_integral(p, d, Ye, e, r1, buf, &S1);
  *own = ok ? fabs(S0) : 0.0;
  return ok ? fabs(S1 - S0) : INFINITY;
}

/* The singular-end rule on an element not touching the end, built here (rarely needed:
 * out of line with its tables, so that the frames of a plain solve stay small). */
static __attribute__((noinline, cold)) double gap_inner(const cv_problem *p, const cv_disc *d,
                                                        const double *Ye, long e, int end,
                                                        double *buf, double *own) {
  const cv_refelem *re = cv_disc_eref(d, e); /* the element's own degree (HP-1) */
  int qs = re->qs, P1 = re->p + 1;
  double tau[CV_MAX_QUAD], om[CV_MAX_QUAD], t[CV_MAX_QUAD], w[CV_MAX_QUAD];
  double B[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)], D[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)];
  cv_gauss_legendre(qs, t, w);
  double x0 = d->xe[e], x1 = d->xe[e + 1], h = x1 - x0, J = 0.5 * h, c = end ? d->b : d->a;
  double u0 = sqrt(fabs(x0 - c)), u1 = sqrt(fabs(x1 - c));
  for (int k = 0; k < qs; k++) {
    double u = u0 + (u1 - u0) * 0.5 * (t[k] + 1.0), x = end ? c - u * u : c + u * u;
    tau[k] = 2.0 * (x - x0) / h - 1.0;
    om[k] = 0.5 * fabs(u1 - u0) * w[k] * 2.0 * u / J;
    cv_lagrange(re->p, re->xi, tau[k], B + k * P1, D + k * P1);
  }
  cv_rule r1 = {qs, tau, om, B, D};
  return gap_with(p, d, Ye, e, &r1, buf, own);
}

/* |integral under the element's own rule - under the singular-end rule at the end| over
 * element e (Q-2: x = c +- u^2, qs Gauss points in u); INFINITY if F fails. *own: the
 * element's integral under its own rule. */
CV_HOT static double rule_gap(const cv_problem *p, const cv_disc *d, const double *Y, long e,
                              int end, double *buf, double *own) {
  const double *Ye = Y + (size_t)cv_disc_enode(d, e) * d->n;
  if (e != (end ? d->E - 1 : 0)) return gap_inner(p, d, Ye, e, end, buf, own);
  const cv_refelem *re = cv_disc_eref(d, e);
  cv_rule r1 = cv_end_rule(re->p, re->qs, end); /* the element touching the end: constants */
  return gap_with(p, d, Ye, e, &r1, buf, own);
}

/* how many elements next to the end element a smooth integrand's gaps are compared
 * with (on coarse elements the gaps of a smooth F differ between neighbours by orders of
 * magnitude, as its quadrature errors cancel or not: the Caldirola-Kanai oscillator on 4
 * elements of degree 2 had 1.2e-5 at one end element, 7.6e-10 at its neighbour and 1.2e-5
 * at the other end's) */
#define Q3_NEIGHBOURS 16

/* The largest gap of the up to Q3_NEIGHBOURS elements next to the end element, short of the
 * other end's element (out of line: only when the end element's gap is large). */
static __attribute__((noinline, cold)) double neighbours_gap(const cv_problem *p, const cv_disc *d,
                                                             const double *Y, int end,
                                                             double *buf) {
  double m = 0.0, own;
  for (long k = 1; k <= Q3_NEIGHBOURS && k < d->E - 1; k++) { /* not the other end's */
    double g = rule_gap(p, d, Y, end ? d->E - 1 - k : k, end, buf, &own);
    if (isfinite(g) && g > m) m = g;
  }
  return m;
}

/* Q-3a: relative gap on the end piece [c, c + frac h] of element e (values Ye) between the
 * element's Gauss rule laid on the piece and the singular-end substitution x = c +- u^2
 * laid on it; INFINITY when F fails. */
static double piece_gap(const cv_problem *p, const cv_disc *d, const double *Ye, long e, int end,
                        double frac, double *buf) {
  const cv_refelem *re = cv_disc_eref(d, e);
  int P1 = re->p + 1, q = re->q, qs = re->qs;
  double t[CV_MAX_QUAD], w[CV_MAX_QUAD], tau[CV_MAX_QUAD], om[CV_MAX_QUAD], S[2];
  double B[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)], D[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)];
  double sf = sqrt(frac), sgn = end ? -1.0 : 1.0, c = end ? 1.0 : -1.0;
  for (int k = 0; k < 2; k++) {
    int m = k ? qs : q;
    cv_gauss_legendre(m, t, w);
    for (int j = 0; j < m; j++) {
      if (k) { /* tau = c +- 2 v^2, v in [0, sqrt(frac)] */
        double v = 0.5 * sf * (t[j] + 1.0);
        tau[j] = c + sgn * 2.0 * v * v, om[j] = 2.0 * v * sf * w[j];
      } else { /* Gauss on [c, c +- 2 frac] */
        tau[j] = c + sgn * frac * (t[j] + 1.0), om[j] = frac * w[j];
      }
      cv_lagrange(re->p, re->xi, tau[j], B + j * P1, D + j * P1);
    }
    cv_rule r = {m, tau, om, B, D};
    if (!element_integral(p, d, Ye, e, &r, buf, &S[k])) return INFINITY;
  }
  return fabs(S[1] - S[0]) / (fabs(S[0]) > DBL_MIN ? fabs(S[0]) : DBL_MIN);
}

/* Q-3a: is it the integrand that varies below the end element, or only the path? Along the
 * straight path between the end element's end values (the integrand alone, without the
 * path's bending), the relative gap of the whole element and of its end sixteenth: an
 * integrand nearly singular at the end (on a scale far below the element) keeps much of its
 * gap on the piece (measured: 1e-4 to 5e-3 of it on the brachistochrone's far ends), a
 * smooth one loses the q-point rule's 16^(2q). CV_END_INTEGRAND when the straight path has
 * at least a tenth of the path's gap and keeps more than 16^(-q) of it on the piece; else
 * CV_END_PATH (out of line: only for an unresolved end). Yl: (p + 1) n values. */
static __attribute__((noinline, cold)) int end_kind(const cv_problem *p, const cv_disc *d,
                                                    const double *Y, int end, double rel,
                                                    double *buf, double *Yl) {
  long e = end ? d->E - 1 : 0;
  int n = d->n, pe = cv_disc_edeg(d, e);
  const double *Ye = Y + (size_t)cv_disc_enode(d, e) * n, *xi = cv_disc_eref(d, e)->xi;
  for (int l = 0; l <= pe; l++)
    for (int i = 0; i < n; i++) {
      double t = 0.5 * (xi[l] + 1.0);
      Yl[l * n + i] = (1.0 - t) * Ye[i] + t * Ye[pe * n + i];
    }
  double whole = piece_gap(p, d, Yl, e, end, 1.0, buf);
  double tip = piece_gap(p, d, Yl, e, end, 1.0 / 16.0, buf);
  double keeps = pow(16.0, -cv_disc_eref(d, e)->q); /* half-way, in orders, to 16^(-2q) */
  return !(whole < 0.1 * rel) && !(tip < keeps * whole) ? CV_END_INTEGRAND : CV_END_PATH;
}

/* A nearly singular end (theory Q-3): F finite at the end value but varying on a scale
 * far below the end element (the brachistochrone to (10, 0.01): 1/sqrt(y) with y coming
 * up to 0.01 at slope -18). The element's rule then under-integrates it and the minimiser
 * exploits that. The end element's integral under its own rule is compared with the
 * singular-end rule at that end, and so are its neighbours': the end is unresolved
 * when the end element's gap exceeds 1e-8 of the action (or of the element's own integral,
 * for an action near zero) and 100 times the largest of the Q3_NEIGHBOURS next elements'
 * (a smooth F on coarse elements has gaps of one size near the end), or F cannot be
 * evaluated at the finer points. Returns 0 (resolved), CV_END_INTEGRAND (the integrand
 * varies on that scale along the straight path between the element's end values too:
 * Q-3a) or CV_END_PATH (only the path does: it bends on a scale below the element, as a
 * ray leaving nearly vertically; the integrand is smooth). *rel: the end element's gap
 * relative to the action. */
CV_HOT int cv_start_end_unresolved(const cv_problem *p, const cv_disc *d, const double *Y, int end,
                                   double action, double *rel) {
  *rel = 0.0;
  if ((end ? d->sing_b : d->sing_a) || d->herm) return 0; /* C^1: Gauss rules only */
  long e = end ? d->E - 1 : 0;
  int q = d->ref.qs > d->ref.q ? d->ref.qs : d->ref.q;
  /* The points of one element: on the stack for one or a few unknowns (the check of every
   * solve runs after Newton, whose deeper frames have touched these stack pages; a heap
   * buffer was a fresh page in the first solve of a process, docs/performance.md). */
  size_t len = (size_t)q * (2 * (size_t)p->n + 2);
  double local[4 * CV_MAX_QUAD], *buf = len <= sizeof local / sizeof *local ? local : NULL;
  if (!buf) buf = cv_malloc(len * sizeof *buf);
  if (!buf) return 0;
  double own;
  double gap = rule_gap(p, d, Y, e, end, buf, &own), next = 0.0;
  /* no libm call on the path of every solve (each first call binds a symbol) */
  double scale = fabs(action) > own ? fabs(action) : own;
  *rel = gap / (scale > DBL_MIN ? scale : DBL_MIN);
  int kind = 0;
  /* the neighbours only when the end element's gap is large (rarely: a few solves' cost) */
  if (!(*rel <= 1e-8) && d->E > 1 && isfinite(gap)) next = neighbours_gap(p, d, Y, end, buf);
  if (!(*rel <= 1e-8) && !(gap <= 100.0 * next)) {
    kind = CV_END_INTEGRAND; /* F fails at the finer points: the integrand's */
    double *Yl = isfinite(gap) ? cv_malloc((size_t)(CV_MAX_DEGREE + 1) * d->n * sizeof *Yl) : NULL;
    if (Yl) kind = end_kind(p, d, Y, end, gap / (own > DBL_MIN ? own : DBL_MIN), buf, Yl);
    cv_free(Yl);
  }
  if (buf != local) cv_free(buf);
  return kind;
}
