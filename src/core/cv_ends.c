/* src/core/cv_ends.c — moving ends: the solve that finds a free end of the interval, or its
 * end point on a curve, around solves of the fixed interval (theory ME-1 .. ME-4).
 *
 * The fixed-interval solve (plain or adaptive) is the inner problem. Its reduced action
 * phi(s), s the position of the end along its motion, has phi'(s) from the end data of the
 * inner solution alone (envelope theorem, ME-1 .. ME-3); a safeguarded secant iteration
 * (bracketing once phi' changes sign) finds phi' = 0, each inner solve warm-started from the
 * last path, its mesh mapped affinely onto the new interval. The Morse index adds one when
 * phi'' < 0 (Haynsworth, ME-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_ends.h"
#include "cv_internal.h"

struct cv_ends_state {
  const cv_problem *src; /* the problem whose end moved */
  cv_problem q;          /* its fixed-interval problem at the solved end (shares src's data) */
  int *fixed;            /* q's own end conditions */
  double *endval;
  int end, k; /* the moving end; the unknown whose end value follows the curve (-1: none) */
};

enum { MAX_OUTER = 60, MAX_HIST = MAX_OUTER + 4 };

/* The state of one moving-end solve. */
typedef struct {
  cv_solver *s;
  const cv_problem *p;
  struct cv_ends_state *st;
  int end, kind, k, n;
  double L0;          /* the starting interval's length */
  double *y;          /* the n values at the moving end (the curve's argument) */
  double *P, *v, *ye; /* end data (n each) */
  /* the warm start of the next inner solve: the last converged mesh on [0, 1], its degrees
   * and nodal values */
  int E, detached;
  double *t, *Y;
  int *deg, ny;
  cv_meshspec spec0; /* the caller's mesh and start, restored at the end */
  int degree0;
  double *start0;
  int start_len0;
  long iters;
  int solves;
  double otx, oty; /* the last tangent, so that its orientation stays continuous */
} ends_run;

int cv_ends_moving(const cv_problem *p) {
  return p && (p->move[0].kind != CV_END_FIXED || p->move[1].kind != CV_END_FIXED);
}

void cv_ends_state_free(cv_solver *s) {
  if (!s) return;
  s->ends_dim = 0;
  s->ends_neg = 0;
  if (!s->ends) return;
  cv_free(s->ends->fixed);
  cv_free(s->ends->endval);
  cv_free(s->ends);
  s->ends = NULL;
}

const cv_problem *cv_ends_solved(const cv_solver *s, const cv_problem *p) {
  if (!s || !s->ends || !s->have || !cv_ends_moving(p) || p->n != s->disc.n) return p;
  /* p's own data (it may be another problem of the same scene: `solve --continue` reports
   * on a fresh one), at the interval and end value of the path the solver holds */
  struct cv_ends_state *st = s->ends;
  int n = p->n, k = st->k, end = st->end;
  memcpy(st->fixed, p->fixed, 2 * (size_t)n * sizeof *st->fixed);
  memcpy(st->endval, p->endval, 2 * (size_t)n * sizeof *st->endval);
  st->src = p;
  st->q = *p;
  st->q.fixed = st->fixed, st->q.endval = st->endval;
  for (int e = 0; e < 2; e++) st->q.move[e] = (cv_end_motion){CV_END_FIXED, NULL, NULL, NULL};
  st->q.a = s->disc.a, st->q.b = s->disc.b;
  if (k >= 0) {
    st->fixed[2 * k + end] = 1;
    st->endval[2 * k + end] = s->y[(size_t)(end ? s->disc.nodes - 1 : 0) * n + k];
  }
  return &st->q;
}

/* The fixed-interval problem: p's integrand, guess and end conditions, no moving end. */
static struct cv_ends_state *state_new(const cv_problem *p) {
  struct cv_ends_state *st = cv_calloc(1, sizeof *st);
  if (!st) return NULL;
  st->fixed = cv_malloc(2 * (size_t)p->n * sizeof *st->fixed);
  st->endval = cv_malloc(2 * (size_t)p->n * sizeof *st->endval);
  if (!st->fixed || !st->endval) {
    cv_free(st->fixed);
    cv_free(st->endval);
    cv_free(st);
    return NULL;
  }
  memcpy(st->fixed, p->fixed, 2 * (size_t)p->n * sizeof *st->fixed);
  memcpy(st->endval, p->endval, 2 * (size_t)p->n * sizeof *st->endval);
  st->src = p;
  st->q = *p;
  st->q.fixed = st->fixed;
  st->q.endval = st->endval;
  for (int e = 0; e < 2; e++) st->q.move[e] = (cv_end_motion){CV_END_FIXED, NULL, NULL, NULL};
  return st;
}

/* Keep the converged inner solve's mesh (on [0, 1]) and values for the next warm start. */
static cv_status keep_warm(ends_run *R) {
  const cv_disc *d = &R->s->disc;
  int E = (int)d->E;
  double *t = cv_malloc((size_t)(E + 1) * sizeof *t), *Y = cv_malloc((size_t)d->ndof * sizeof *Y);
  int *deg = cv_malloc((size_t)E * sizeof *deg);
  if (!t || !Y || !deg) {
    cv_free(t), cv_free(Y), cv_free(deg);
    return CVAR_ENOMEM;
  }
  for (int e = 0; e <= E; e++) t[e] = (d->xe[e] - d->a) / (d->b - d->a);
  t[0] = 0.0, t[E] = 1.0;
  for (int e = 0; e < E; e++) deg[e] = cv_disc_edeg(d, e);
  memcpy(Y, R->s->y, (size_t)d->ndof * sizeof *Y);
  cv_free(R->t), cv_free(R->Y), cv_free(R->deg);
  R->t = t, R->Y = Y, R->deg = deg, R->E = E, R->ny = d->ndof;
  return CVAR_OK;
}

/* The caller's mesh and start are set aside after the first inner solve: the next ones
 * start from the last path on its own mesh, mapped onto the new interval. */
static void detach_caller_settings(ends_run *R) {
  cv_solver *s = R->s;
  if (R->detached) return;
  R->detached = 1;
  R->spec0 = s->mesh;
  R->degree0 = s->degree;
  R->start0 = s->start, R->start_len0 = s->start_len;
  s->start = NULL, s->start_len = 0;
  s->mesh.t = NULL, s->mesh.degrees = NULL, s->mesh.breaks = NULL, s->mesh.nbreak = 0;
}

static void restore_caller_settings(ends_run *R) {
  cv_solver *s = R->s;
  if (!R->detached) return;
  cv_free(s->mesh.t), cv_free(s->mesh.degrees), cv_free(s->start);
  s->mesh = R->spec0;
  s->degree = R->degree0;
  s->start = R->start0, s->start_len = R->start_len0;
}

/* One solve of the fixed interval with the moving end at x (and y_k = yk there). */
static cv_status solve_at(ends_run *R, double x, double yk) {
  cv_solver *s = R->s;
  cv_problem *q = &R->st->q;
  if (R->end)
    q->b = x;
  else
    q->a = x;
  if (R->k >= 0) q->endval[2 * R->k + R->end] = yk;
  if (!(q->a < q->b)) {
    cv_set_msg(s->msg, sizeof s->msg, "the interval collapsed to [%.17g, %.17g]", q->a, q->b);
    return CVAR_ESTALL;
  }
  if (R->E > 0) {
    detach_caller_settings(R);
    cv_status st = cv_solver_set_mesh_hp(s, R->E, R->t, R->deg);
    if (!st) st = cv_solver_set_start(s, R->ny, R->Y);
    if (st) return st;
  }
  cv_status st = cv_solve_interval(s, q);
  R->iters += s->iterations;
  R->solves++;
  if (st == CVAR_OK) st = keep_warm(R);
  return st;
}

/* phi'(s) along the motion (tx, ty) in the (x, y_k) plane from the end data (ME-1 .. ME-3):
 * the first variation of the action under a move (dx, dy_k) of the end point is
 * -H dx + P_k dy_k at b and H dx - P_k dy_k at a. *scale: the size of its terms. */
static cv_status outer_residual(ends_run *R, double tx, double ty, double *r, double *scale) {
  double H, size;
  cv_status st = cv_ends_end_data(R->s, &R->st->q, R->end, 0, &H, R->P, R->ye, R->v, &size);
  if (st) {
    cv_set_msg(R->s->msg, sizeof R->s->msg,
               "the integrand cannot be evaluated at the moving end of the solution (%s)",
               cv_strerror(st));
    return st;
  }
  double sg = R->end ? -1.0 : 1.0, pk = R->k >= 0 ? R->P[R->k] : 0.0;
  *r = sg * (tx * H - ty * pk);
  *scale = size + fabs(pk);
  return CVAR_OK;
}

/* The unit tangent of the motion at (x, R->y), oriented as the last one (a closed curve is
 * followed round, not back and forth at its vertical tangents). 0, or -1 without one. */
static int tangent(ends_run *R, double x, double *tx, double *ty) {
  const cv_end_motion *m = &R->p->move[R->end];
  if (cv_ends_tangent(m->G, m->user, R->n, R->k, x, R->y, tx, ty) != 0) return -1;
  if (*tx * R->otx + *ty * R->oty < 0) *tx = -*tx, *ty = -*ty;
  R->otx = *tx, R->oty = *ty;
  return 0;
}

/* The point a step ds along the motion from (x, yk): on the curve, the tangent step then
 * Newton back onto it (a predictor-corrector on G = 0). *ds becomes the step taken. */
static cv_status move_along(ends_run *R, double *x, double *yk, double tx, double ty, double *ds) {
  double xn = *x + *ds * tx, yn = *yk + *ds * ty;
  if (R->kind == CV_END_CURVE) {
    if (R->k >= 0) R->y[R->k] = yn;
    cv_status st = cv_ends_project(R->p->move[R->end].G, R->p->move[R->end].user, R->n, R->k, &xn,
                                   R->y, 4.0 * fabs(*ds) + 1e-12, R->s->msg, sizeof R->s->msg);
    if (st) return st;
    if (R->k >= 0) yn = R->y[R->k];
  }
  *ds = (xn - *x) * tx + (yn - *yk) * ty;
  *x = xn, *yk = yn;
  return CVAR_OK;
}

/* The end values at the start: the fixed ones, the free ones from the guess there. */
static cv_status start_values(const cv_problem *p, int end, double x, double *y) {
  if (p->guess) {
    if (p->guess(1, &x, y, p->guess_user) != 0) return CVAR_ECALLBACK;
  } else {
    cv_start_line(p, end ? 1.0 : 0.0, y);
  }
  for (int i = 0; i < p->n; i++)
    if (p->fixed[2 * i + end]) y[i] = p->endval[2 * i + end];
  return CVAR_OK;
}

/* The curve end's start point: the free value that follows the curve, and the projection
 * of the start's end point onto the curve (ME-3). */
static cv_status curve_start(ends_run *R, double *x) {
  cv_solver *s = R->s;
  const cv_end_motion *m = &R->p->move[R->end];
  int *fr = cv_malloc((size_t)R->n * sizeof *fr);
  if (!fr) return CVAR_ENOMEM;
  for (int i = 0; i < R->n; i++) fr[i] = !R->p->fixed[2 * i + R->end];
  int cnt = cv_ends_movers(m->G, m->user, R->n, fr, *x, R->y, &R->k);
  cv_free(fr);
  if (cnt < 0) {
    cv_set_msg(s->msg, sizeof s->msg, "the end curve cannot be evaluated at the start's end point");
    return CVAR_EINVAL;
  }
  if (cnt > 1) {
    cv_set_msg(s->msg, sizeof s->msg,
               "the end curve depends on %d end values the problem leaves free there; at most "
               "one may follow the curve (fix the others)",
               cnt);
    return CVAR_EINVAL;
  }
  cv_status st = cv_ends_project(m->G, m->user, R->n, R->k, x, R->y, R->L0, s->msg, sizeof s->msg);
  if (st) return st;
  if (R->end ? !(*x > R->p->a) : !(*x < R->p->b)) {
    cv_set_msg(s->msg, sizeof s->msg,
               "the end curve meets the start's end region at x = %.6g, beyond the other end "
               "of the interval",
               *x);
    return CVAR_EINVAL;
  }
  return CVAR_OK;
}

/* The next step of the secant iteration on phi'(s) = 0, safeguarded: the secant of the
 * last two points, inside the bracket once phi' changed sign (else its midpoint), at most
 * 4 times the last step and half the interval, and shortening the interval by at most
 * half. */
static double next_step(const double *hs, const double *hr, int nh, double lo, double hi, double L,
                        double tx, int end) {
  double s = hs[nh - 1], r = hr[nh - 1], ds;
  if (nh == 1) {
    ds = (r > 0 ? -0.1 : 0.1) * L;
  } else {
    double slope = (r - hr[nh - 2]) / (s - hs[nh - 2]), last = fabs(s - hs[nh - 2]);
    ds = -r / slope;
    int bracket = isfinite(lo) && isfinite(hi);
    if (!isfinite(ds) || slope == 0.0) ds = (r > 0 ? -2.0 : 2.0) * last;
    if (!bracket && fabs(ds) > 4.0 * last) ds = copysign(4.0 * last, ds);
    if (bracket) {
      double a = fmin(lo, hi), b = fmax(lo, hi), t = s + ds;
      if (!(t > a && t < b)) ds = 0.5 * (a + b) - s;
    }
  }
  if (fabs(ds) > 0.5 * L) ds = copysign(0.5 * L, ds);
  double shrink = (end ? -1.0 : 1.0) * ds * tx; /* how much shorter the interval gets */
  if (shrink > 0.5 * L) ds *= 0.5 * L / shrink;
  return ds;
}

/* phi'' at the solution from the recorded residuals: the secant slope to the nearest point
 * at least 1e-4 of the interval away (the residuals' round-off then costs little). */
static int curvature(const double *hs, const double *hr, int nh, double L, double *d2) {
  for (int i = nh - 2; i >= 0; i--)
    if (fabs(hs[i] - hs[nh - 1]) >= 1e-4 * L) {
      *d2 = (hr[nh - 1] - hr[i]) / (hs[nh - 1] - hs[i]);
      return 1;
    }
  return 0;
}

/* The outer iteration (ME-1 .. ME-3) from the start point (x, yk). */
static cv_status iterate(ends_run *R, double x, double yk) {
  cv_solver *s = R->s;
  double hs[MAX_HIST], hr[MAX_HIST], lo = NAN, hi = NAN, sc = 0.0, tx = 1.0, ty = 0.0;
  double gx = x, gy = yk, gs = 0.0, gtx = 1.0, gty = 0.0, step = 0.0, r = NAN, scale = 0.0;
  double stol = fmax(1e-2 * s->rtol, 1e-14) * R->L0;
  int nh = 0, good = 0;
  cv_status st = CVAR_OK;
  if (s->adapt_tol > 0) stol = fmin(stol, 1e-2 * s->adapt_tol);
  for (int it = 0; it < MAX_OUTER; it++) {
    if (R->k >= 0) R->y[R->k] = yk;
    st = solve_at(R, x, yk);
    if (st == CVAR_ENOMEM || st == CVAR_ECANCELLED || st == CVAR_ECALLBACK) return st;
    if (st != CVAR_OK) {
      if (!good) return st; /* the start's own failure: said as it is */
      step *= 0.5;          /* back towards the last good point */
      if (fabs(step) <= stol) return st;
      x = gx, yk = gy, sc = gs;
      if (R->k >= 0) R->y[R->k] = yk;
      if ((st = move_along(R, &x, &yk, gtx, gty, &step))) return st;
      sc += step;
      continue;
    }
    if (tangent(R, x, &tx, &ty) != 0) {
      cv_set_msg(s->msg, sizeof s->msg, "the end curve has no tangent at (%.6g, %.6g)", x, yk);
      return CVAR_ESINGULAR;
    }
    if ((st = outer_residual(R, tx, ty, &r, &scale))) return st;
    good = 1, gx = x, gy = yk, gs = sc, gtx = tx, gty = ty;
    hs[nh] = sc, hr[nh] = r, nh++;
    if (r < 0) lo = sc;
    if (r > 0) hi = sc;
    double L = R->st->q.b - R->st->q.a;
    if (fabs(r) <= 8e-16 * scale) break; /* stationary to round-off */
    step = next_step(hs, hr, nh, lo, hi, L, tx, R->end);
    /* done when the step is below the tolerance, or below what the residual's round-off
     * (some 1e3 eps of its terms) can resolve at the secant's slope */
    double slope = nh > 1 ? fabs((r - hr[nh - 2]) / (sc - hs[nh - 2])) : 0.0;
    double noise = slope > 0 ? 1e3 * 2.2e-16 * scale / slope : 0.0;
    if (nh > 1 && fabs(step) <= fmax(stol, noise)) {
      if (fabs(r) <= 1e-6 * scale) break;
      /* the end stopped moving where the residual does not vanish: a jump of phi' */
      cv_set_msg(s->msg, sizeof s->msg,
                 "no stationary end point found: the end stopped moving at x = %.10g, where "
                 "the transversality residual is still %.3g (of terms of size %.3g)",
                 x, r, scale);
      return CVAR_ESTALL;
    }
    if (L < 1e-8 * R->L0 || L > 1e8 * R->L0) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "no stationary end point: the interval %s (length %.3g from %.3g) while the "
                 "transversality residual stays %.3g",
                 L < R->L0 ? "collapses" : "runs away", L, R->L0, r);
      return L < R->L0 ? CVAR_ESTALL : CVAR_EDIVERGED;
    }
    if ((st = move_along(R, &x, &yk, tx, ty, &step))) return st;
    sc += step;
    if (it == MAX_OUTER - 1) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "the moving end did not settle in %d solves of the interval (last residual "
                 "%.3g at x = %.10g)",
                 MAX_OUTER, r, x);
      return CVAR_EMAXITER;
    }
  }
  /* The curvature of the reduced action (ME-4): from the residuals, or one probe. */
  double d2 = NAN, L = R->st->q.b - R->st->q.a;
  if (!curvature(hs, hr, nh, L, &d2)) {
    double px = x, py = yk, ds = 1e-3 * L, pr, psc, ptx, pty;
    if ((st = move_along(R, &px, &py, tx, ty, &ds)) || (st = solve_at(R, px, py))) return st;
    if (tangent(R, px, &ptx, &pty) != 0) return CVAR_ESINGULAR; /* the probe's own tangent */
    if ((st = outer_residual(R, ptx, pty, &pr, &psc))) return st;
    if (R->k >= 0) R->y[R->k] = yk;
    if ((st = solve_at(R, x, yk))) return st;
    d2 = (pr - r) / ds;
  }
  int degenerate = !(fabs(d2) * L * L > 1e-9 * fmax(fabs(s->action), 1e-300));
  s->ends_neg = !degenerate && d2 < 0; /* added by cv_solver_get_morse_index (ME-4) */
  if (degenerate && s->method == CVAR_METHOD_NEWTON) s->degenerate = 1;
  s->ends_dim = 1;
  char inner[sizeof s->msg], at[96] = "";
  memcpy(inner, s->msg, sizeof inner);
  inner[sizeof inner - 240] = '\0';
  if (R->k >= 0) cv_set_msg(at, sizeof at, " with the end value %.12g", yk);
  cv_set_msg(s->msg, sizeof s->msg,
             "the %s moved to %.12g%s, where the transversality condition holds to %.1e "
             "(second derivative of the action along the end's motion %.3g; %d solves of the "
             "interval, %ld Newton iterations in all); %s",
             R->end ? "end" : "start", x, at, fabs(r), d2, R->solves, R->iters, inner);
  return CVAR_OK;
}

/* The start point moved `shift` along the motion, in steps of at most a tenth of the
 * interval so that a curve is followed (cv_solve_all's starts). */
static cv_status shift_start(ends_run *R, double *x, double shift) {
  double yk = R->k >= 0 ? R->y[R->k] : 0.0, left = shift, tx = 1.0, ty = 0.0;
  while (fabs(left) > 1e-12 * R->L0) {
    double ds = fabs(left) > 0.1 * R->L0 ? copysign(0.1 * R->L0, left) : left;
    left -= ds;
    if (tangent(R, *x, &tx, &ty) != 0) return CVAR_EINVAL;
    cv_status st = move_along(R, x, &yk, tx, ty, &ds);
    if (st) return st;
    if (R->k >= 0) R->y[R->k] = yk;
  }
  double other = R->end ? R->p->a : R->p->b;
  if (!(fabs(*x - other) > 0.05 * R->L0) || (R->end ? *x < other : *x > other)) {
    cv_set_msg(R->s->msg, sizeof R->s->msg,
               "a start moved %.3g along the end's motion leaves no interval", shift);
    return CVAR_EINVAL;
  }
  return CVAR_OK;
}

cv_status cv_ends_run(cv_solver *s, const cv_problem *p, double shift) {
  cv_status st = CVAR_OK;
  ends_run R;
  memset(&R, 0, sizeof R);
  R.s = s, R.p = p, R.n = p->n, R.k = -1;
  if (p->move[0].kind != CV_END_FIXED && p->move[1].kind != CV_END_FIXED) {
    cv_set_msg(s->msg, sizeof s->msg,
               "both ends of the interval move; one moving end at a time "
               "is supported");
    return s->status = CVAR_EINVAL;
  }
  if (p->nc > 0 || p->ni > 0) {
    cv_set_msg(s->msg, sizeof s->msg,
               "a moving end with pointwise or integral constraints is not supported");
    return s->status = CVAR_EINVAL;
  }
  if (!p->F) {
    cv_set_msg(s->msg, sizeof s->msg, "no integrand set");
    return s->status = CVAR_EINVAL;
  }
  R.end = p->move[1].kind != CV_END_FIXED;
  R.kind = p->move[R.end].kind;
  R.L0 = p->b - p->a;
  R.st = state_new(p);
  R.y = cv_malloc(4 * (size_t)p->n * sizeof *R.y);
  if (!R.st || !R.y) {
    st = CVAR_ENOMEM;
    cv_set_msg(s->msg, sizeof s->msg, "out of memory");
    goto done;
  }
  R.P = R.y + p->n, R.v = R.P + p->n, R.ye = R.v + p->n;
  double x = R.end ? p->b : p->a;
  if ((st = start_values(p, R.end, x, R.y))) {
    cv_set_msg(s->msg, sizeof s->msg, "the initial guess failed at the moving end x = %g", x);
    goto done;
  }
  if (R.kind == CV_END_CURVE && (st = curve_start(&R, &x))) goto done;
  if (R.k >= 0) R.st->fixed[2 * R.k + R.end] = 1; /* the curve sets it (ME-3) */
  R.st->end = R.end, R.st->k = R.k;
  if (shift != 0.0 && (st = shift_start(&R, &x, shift))) goto done;
  if (R.kind == CV_END_CURVE && R.k < 0) {
    st = solve_at(&R, x, 0.0); /* the curve fixes the end's position alone */
  } else {
    st = iterate(&R, x, R.k >= 0 ? R.y[R.k] : 0.0);
  }
done:
  restore_caller_settings(&R);
  cv_free(R.t), cv_free(R.Y), cv_free(R.deg), cv_free(R.y);
  if (R.st) {
    s->ends = R.st;
    if (st != CVAR_OK) s->ends_dim = 0, s->ends_neg = 0;
  }
  if (R.solves > 1) s->iterations = (int)(R.iters > 2000000000L ? 2000000000L : R.iters);
  return st;
}
