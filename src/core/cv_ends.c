/* src/core/cv_ends.c — moving ends: the solve that finds a free end of the interval, or its
 * end point on a curve, around solves of the fixed interval (theory ME-1 .. ME-6).
 *
 * The fixed-interval solve (plain or adaptive) is the inner problem. Its reduced action
 * phi(s), s the position of the end along its motion, has phi'(s) from the end data of the
 * inner solution alone (envelope theorem, ME-1 .. ME-3); a safeguarded secant iteration
 * (bracketing once phi' changes sign) finds phi' = 0, each inner solve warm-started from the
 * last path, its mesh mapped affinely onto the new interval. The Morse index adds one when
 * phi'' < 0 (Haynsworth, ME-4). Both ends moving: Newton with Broyden's updates on the
 * pair of residuals (ME-6).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_ends.h"
#include "cv_internal.h"

struct cv_ends_state {
  cv_problem q; /* the fixed-interval problem at the solved ends (shares the problem's data) */
  int *fixed;   /* q's own end conditions */
  double *endval;
  int k[2]; /* per end: the unknown whose value follows its curve (-1: none; -2: fixed end) */
};

enum { MAX_OUTER = 60, MAX_HIST = MAX_OUTER + 4 };

/* One moving end: where it is and how it moves. */
typedef struct {
  int end, kind, k; /* 0 = a, 1 = b; CV_END_*; the value that follows the curve (-1: none) */
  double x, yk;     /* the end point: the interval's end and (k >= 0) y_k there */
  double *y;        /* the n values there (the curve's argument) */
  double otx, oty;  /* the last tangent, so that its orientation stays continuous */
} mover;

/* The state of one moving-end solve. */
typedef struct {
  cv_solver *s;
  const cv_problem *p;
  struct cv_ends_state *st;
  int n, m; /* unknowns; moving ends (1 or 2) */
  mover mv[2];
  double L0;          /* the starting interval's length */
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

/* q: p with its own copy of the end conditions and no moving end (the interval is p's). */
static void state_load(struct cv_ends_state *st, const cv_problem *p) {
  memcpy(st->fixed, p->fixed, 2 * (size_t)p->n * sizeof *st->fixed);
  memcpy(st->endval, p->endval, 2 * (size_t)p->n * sizeof *st->endval);
  st->q = *p;
  st->q.fixed = st->fixed, st->q.endval = st->endval;
  for (int e = 0; e < 2; e++) st->q.move[e] = (cv_end_motion){CV_END_FIXED, NULL, NULL, NULL};
}

const cv_problem *cv_ends_solved(const cv_solver *s, const cv_problem *p) {
  if (!s || !s->ends || !s->have || !cv_ends_moving(p) || p->n != s->disc.n) return p;
  /* p's own data (it may be another problem of the same scene: `solve --continue` reports
   * on a fresh one), at the interval and end value of the path the solver holds */
  struct cv_ends_state *st = s->ends;
  int n = p->n;
  state_load(st, p);
  st->q.a = s->disc.a, st->q.b = s->disc.b;
  for (int end = 0; end < 2; end++) {
    int k = st->k[end];
    if (k < 0) continue;
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
  state_load(st, p);
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

/* One solve of the fixed interval with the moving ends where their movers are. */
static cv_status solve_at(ends_run *R) {
  cv_solver *s = R->s;
  cv_problem *q = &R->st->q;
  for (int j = 0; j < R->m; j++) {
    const mover *M = &R->mv[j];
    if (M->end)
      q->b = M->x;
    else
      q->a = M->x;
    if (M->k >= 0) q->endval[2 * M->k + M->end] = M->yk;
  }
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
static cv_status outer_residual(ends_run *R, const mover *M, double tx, double ty, double *r,
                                double *scale) {
  double H, size;
  cv_status st = cv_ends_end_data(R->s, &R->st->q, M->end, 0, &H, R->P, R->ye, R->v, &size);
  if (st) {
    cv_set_msg(R->s->msg, sizeof R->s->msg,
               "the integrand cannot be evaluated at the moving end of the solution (%s)",
               cv_strerror(st));
    return st;
  }
  double sg = M->end ? -1.0 : 1.0, pk = M->k >= 0 ? R->P[M->k] : 0.0;
  *r = sg * (tx * H - ty * pk);
  *scale = size + fabs(pk);
  return CVAR_OK;
}

/* The unit tangent of the motion at (x, R->y), oriented as the last one (a closed curve is
 * followed round, not back and forth at its vertical tangents). 0, or -1 without one. */
static int tangent(ends_run *R, mover *M, double *tx, double *ty) {
  const cv_end_motion *m = &R->p->move[M->end];
  if (M->k >= 0) M->y[M->k] = M->yk;
  if (cv_ends_tangent(m->G, m->user, R->n, M->k, M->x, M->y, tx, ty) != 0) return -1;
  if (*tx * M->otx + *ty * M->oty < 0) *tx = -*tx, *ty = -*ty;
  M->otx = *tx, M->oty = *ty;
  return 0;
}

/* The point a step ds along the motion from (x, yk): on the curve, the tangent step then
 * Newton back onto it (a predictor-corrector on G = 0). *ds becomes the step taken. */
static cv_status move_along(ends_run *R, mover *M, double tx, double ty, double *ds) {
  double xn = M->x + *ds * tx, yn = M->yk + *ds * ty;
  if (M->kind == CV_END_CURVE) {
    const cv_end_motion *m = &R->p->move[M->end];
    if (M->k >= 0) M->y[M->k] = yn;
    cv_status st = cv_ends_project(m->G, m->user, R->n, M->k, &xn, M->y, 4.0 * fabs(*ds) + 1e-12,
                                   R->s->msg, sizeof R->s->msg);
    if (st) return st;
    if (M->k >= 0) yn = M->y[M->k];
  }
  *ds = (xn - M->x) * tx + (yn - M->yk) * ty;
  M->x = xn, M->yk = yn;
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
static cv_status curve_start(ends_run *R, mover *M) {
  cv_solver *s = R->s;
  const cv_end_motion *m = &R->p->move[M->end];
  int *fr = cv_malloc((size_t)R->n * sizeof *fr);
  if (!fr) return CVAR_ENOMEM;
  for (int i = 0; i < R->n; i++) fr[i] = !R->p->fixed[2 * i + M->end];
  int cnt = cv_ends_movers(m->G, m->user, R->n, fr, M->x, M->y, &M->k);
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
  cv_status st =
      cv_ends_project(m->G, m->user, R->n, M->k, &M->x, M->y, R->L0, s->msg, sizeof s->msg);
  if (st) return st;
  if (M->k >= 0) M->yk = M->y[M->k];
  if (M->end ? !(M->x > R->p->a) : !(M->x < R->p->b)) {
    cv_set_msg(s->msg, sizeof s->msg,
               "the end curve meets the start's end region at x = %.6g, beyond the other end "
               "of the interval",
               M->x);
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

/* The failure of an interval that collapses or runs away (0 when it does neither). */
static cv_status degenerate_interval(ends_run *R, double r) {
  double L = R->st->q.b - R->st->q.a;
  if (!(L < 1e-8 * R->L0 || L > 1e8 * R->L0)) return CVAR_OK;
  cv_set_msg(R->s->msg, sizeof R->s->msg,
             "no stationary end point: the interval %s (length %.3g from %.3g) while the "
             "transversality residual stays %.3g",
             L < R->L0 ? "collapses" : "runs away", L, R->L0, r);
  return L < R->L0 ? CVAR_ESTALL : CVAR_EDIVERGED;
}

/* The message of a converged moving-end solve, before the inner solve's own. */
static void say_converged(ends_run *R, double r, const char *curv) {
  cv_solver *s = R->s;
  char inner[sizeof s->msg], at[2][128] = {"", ""};
  memcpy(inner, s->msg, sizeof inner);
  inner[sizeof inner - 300] = '\0';
  for (int j = 0; j < R->m; j++) {
    const mover *M = &R->mv[j];
    if (M->k >= 0)
      cv_set_msg(at[j], sizeof at[j], "the %s moved to %.12g with the end value %.12g",
                 M->end ? "end" : "start", M->x, M->yk);
    else
      cv_set_msg(at[j], sizeof at[j], "the %s moved to %.12g", M->end ? "end" : "start", M->x);
  }
  cv_set_msg(s->msg, sizeof s->msg,
             "%s%s%s, where the transversality condition holds to %.1e (%s; %d solves of the "
             "interval, %ld Newton iterations in all); %s",
             at[0], R->m > 1 ? " and " : "", at[1], r, curv, R->solves, R->iters, inner);
}

/* The outer iteration (ME-1 .. ME-4) of one moving end, from where its mover is. */
static cv_status iterate(ends_run *R) {
  cv_solver *s = R->s;
  mover *M = &R->mv[0];
  double hs[MAX_HIST], hr[MAX_HIST], lo = NAN, hi = NAN, sc = 0.0, tx = 1.0, ty = 0.0;
  double gx = M->x, gy = M->yk, gs = 0.0, gtx = 1.0, gty = 0.0, step = 0.0, r = NAN;
  double scale = 0.0, stol = fmax(1e-2 * s->rtol, 1e-14) * R->L0;
  int nh = 0, good = 0;
  cv_status st = CVAR_OK;
  if (s->adapt_tol > 0) stol = fmin(stol, 1e-2 * s->adapt_tol);
  for (int it = 0; it < MAX_OUTER; it++) {
    st = solve_at(R);
    if (st == CVAR_ENOMEM || st == CVAR_ECANCELLED || st == CVAR_ECALLBACK) return st;
    if (st != CVAR_OK) {
      if (!good) return st; /* the start's own failure: said as it is */
      step *= 0.5;          /* back towards the last good point */
      if (fabs(step) <= stol) return st;
      M->x = gx, M->yk = gy, sc = gs;
      if ((st = move_along(R, M, gtx, gty, &step))) return st;
      sc += step;
      continue;
    }
    if (tangent(R, M, &tx, &ty) != 0) {
      cv_set_msg(s->msg, sizeof s->msg, "the end curve has no tangent at (%.6g, %.6g)", M->x,
                 M->yk);
      return CVAR_ESINGULAR;
    }
    if ((st = outer_residual(R, M, tx, ty, &r, &scale))) return st;
    good = 1, gx = M->x, gy = M->yk, gs = sc, gtx = tx, gty = ty;
    hs[nh] = sc, hr[nh] = r, nh++;
    if (r < 0) lo = sc;
    if (r > 0) hi = sc;
    double L = R->st->q.b - R->st->q.a;
    if (fabs(r) <= 8e-16 * scale) break; /* stationary to round-off */
    step = next_step(hs, hr, nh, lo, hi, L, tx, M->end);
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
                 M->x, r, scale);
      return CVAR_ESTALL;
    }
    if ((st = degenerate_interval(R, r))) return st;
    if ((st = move_along(R, M, tx, ty, &step))) return st;
    sc += step;
    if (it == MAX_OUTER - 1) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "the moving end did not settle in %d solves of the interval (last residual "
                 "%.3g at x = %.10g)",
                 MAX_OUTER, r, M->x);
      return CVAR_EMAXITER;
    }
  }
  /* The curvature of the reduced action (ME-4): from the residuals, or one probe. */
  double d2 = NAN, L = R->st->q.b - R->st->q.a;
  if (!curvature(hs, hr, nh, L, &d2)) {
    double x0 = M->x, y0 = M->yk, ds = 1e-3 * L, pr, psc, ptx, pty;
    if ((st = move_along(R, M, tx, ty, &ds)) || (st = solve_at(R))) return st;
    if (tangent(R, M, &ptx, &pty) != 0) return CVAR_ESINGULAR; /* the probe's own tangent */
    if ((st = outer_residual(R, M, ptx, pty, &pr, &psc))) return st;
    M->x = x0, M->yk = y0;
    if ((st = solve_at(R))) return st;
    d2 = (pr - r) / ds;
  }
  /* degenerate below 1e-9 of the action's scale, or below what the residuals' error (the
   * inner solves' tolerance) resolves over the secant's span */
  double span = nh > 1 ? fabs(hs[nh - 1] - hs[nh - 2]) : 1e-3 * L, noise = 0.0;
  for (int i = nh - 2; i >= 0; i--)
    if (fabs(hs[i] - hs[nh - 1]) >= 1e-4 * L) {
      span = fabs(hs[i] - hs[nh - 1]);
      break;
    }
  noise = fmax(s->rtol, 1e-13) * scale / span;
  int degenerate = !(fabs(d2) > fmax(1e-9 * fabs(s->action) / (L * L), noise));
  s->ends_neg = !degenerate && d2 < 0; /* added by cv_solver_get_morse_index (ME-4) */
  if (degenerate && s->method == CVAR_METHOD_NEWTON) s->degenerate = 1;
  s->ends_dim = 1;
  char curv[96];
  cv_set_msg(curv, sizeof curv, "second derivative of the action along the end's motion %.3g", d2);
  say_converged(R, fabs(r), curv);
  return CVAR_OK;
}

/* Both ends move (ME-6): the residuals r_j and tangents at the movers' points. */
static cv_status pair_residuals(ends_run *R, double *r, double *t, double *scale) {
  *scale = 0.0;
  for (int j = 0; j < 2; j++) {
    double sc;
    if (tangent(R, &R->mv[j], &t[2 * j], &t[2 * j + 1]) != 0) {
      cv_set_msg(R->s->msg, sizeof R->s->msg, "the end curve has no tangent at (%.6g, %.6g)",
                 R->mv[j].x, R->mv[j].yk);
      return CVAR_ESINGULAR;
    }
    cv_status st = outer_residual(R, &R->mv[j], t[2 * j], t[2 * j + 1], &r[j], &sc);
    if (st) return st;
    *scale = fmax(*scale, sc);
  }
  return CVAR_OK;
}

/* The Jacobian J[i*2 + j] = dr_i/ds_j by one-sided differences of step h along each motion,
 * from the residuals r at the movers' points (which are left as they were, solved again). */
static cv_status pair_jacobian(ends_run *R, const double *r, double h, double *J) {
  double x0[2] = {R->mv[0].x, R->mv[1].x}, y0[2] = {R->mv[0].yk, R->mv[1].yk}, t[4], rp[2], sc;
  cv_status st = CVAR_OK;
  for (int j = 0; j < 2 && !st; j++) {
    mover *M = &R->mv[j];
    double ds = h, tx, ty;
    if (tangent(R, M, &tx, &ty) != 0) return CVAR_ESINGULAR;
    if ((st = move_along(R, M, tx, ty, &ds)) || (st = solve_at(R)) ||
        (st = pair_residuals(R, rp, t, &sc)))
      break;
    for (int i = 0; i < 2; i++) J[i * 2 + j] = (rp[i] - r[i]) / ds;
    M->x = x0[j], M->yk = y0[j];
  }
  for (int j = 0; j < 2; j++) R->mv[j].x = x0[j], R->mv[j].yk = y0[j];
  if (!st) st = solve_at(R);
  return st;
}

/* The Newton step d of J d = -r; where J is (nearly) singular, the least-squares step
 * along J^T r (exact for a rank-one J: the shift of an autonomous problem, ME-6). */
static void pair_step(const double *J, const double *r, double *d) {
  double det = J[0] * J[3] - J[1] * J[2];
  double nJ = J[0] * J[0] + J[1] * J[1] + J[2] * J[2] + J[3] * J[3];
  if (fabs(det) > 1e-10 * nJ) {
    d[0] = -(J[3] * r[0] - J[1] * r[1]) / det;
    d[1] = -(-J[2] * r[0] + J[0] * r[1]) / det;
    return;
  }
  double g0 = J[0] * r[0] + J[2] * r[1], g1 = J[1] * r[0] + J[3] * r[1]; /* J^T r */
  double Jg0 = J[0] * g0 + J[1] * g1, Jg1 = J[2] * g0 + J[3] * g1;
  double a = (g0 * g0 + g1 * g1) / fmax(Jg0 * Jg0 + Jg1 * Jg1, 1e-300);
  d[0] = -a * g0, d[1] = -a * g1;
}

/* Both ends move: Newton on (r_a, r_b) = 0 with a difference Jacobian at the start and
 * Broyden's updates after (ME-6); steps at most a quarter of the interval, never shortening
 * it by more than half. The Morse index adds the negative eigenvalues of the symmetric part
 * of a difference Jacobian at the solution (the Hessian of the reduced action, ME-4). */
static cv_status iterate_pair(ends_run *R) {
  cv_solver *s = R->s;
  double r[2], t[4], J[4], d[2] = {0, 0}, scale, rold[2], dold[2];
  double stol = fmax(1e-2 * s->rtol, 1e-14) * R->L0;
  cv_status st;
  if (s->adapt_tol > 0) stol = fmin(stol, 1e-2 * s->adapt_tol);
  if ((st = solve_at(R)) || (st = pair_residuals(R, r, t, &scale))) return st;
  if ((st = pair_jacobian(R, r, 1e-3 * R->L0, J))) return st;
  for (int it = 0;; it++) {
    double rn = fmax(fabs(r[0]), fabs(r[1])), L = R->st->q.b - R->st->q.a;
    if (rn <= 8e-16 * scale) break;
    pair_step(J, r, d);
    double dn = fmax(fabs(d[0]), fabs(d[1]));
    double shrink = 0.0; /* how much shorter the interval gets */
    for (int j = 0; j < 2; j++) shrink += (R->mv[j].end ? -1.0 : 1.0) * d[j] * t[2 * j];
    double f = fmin(1.0, 0.25 * L / fmax(dn, 1e-300));
    if (shrink > 0.5 * L) f = fmin(f, 0.5 * L / shrink);
    d[0] *= f, d[1] *= f;
    if (dn * f <= stol) {
      if (rn <= 1e-6 * scale) break;
      cv_set_msg(s->msg, sizeof s->msg,
                 "no stationary end points found: the ends stopped moving at [%.10g, %.10g], "
                 "where the transversality residuals are still %.3g, %.3g",
                 R->st->q.a, R->st->q.b, r[0], r[1]);
      return CVAR_ESTALL;
    }
    if ((st = degenerate_interval(R, rn))) return st;
    if (it == MAX_OUTER) {
      cv_set_msg(s->msg, sizeof s->msg,
                 "the moving ends did not settle in %d steps (last residuals %.3g, %.3g)",
                 MAX_OUTER, r[0], r[1]);
      return CVAR_EMAXITER;
    }
    for (int j = 0; j < 2; j++)
      if ((st = move_along(R, &R->mv[j], t[2 * j], t[2 * j + 1], &d[j]))) return st;
    rold[0] = r[0], rold[1] = r[1], dold[0] = d[0], dold[1] = d[1];
    if ((st = solve_at(R)) || (st = pair_residuals(R, r, t, &scale))) return st;
    /* Broyden: J += (dr - J d) d^T / d^T d */
    double dd = dold[0] * dold[0] + dold[1] * dold[1];
    for (int i = 0; i < 2 && dd > 0; i++) {
      double u = (r[i] - rold[i]) - (J[i * 2] * dold[0] + J[i * 2 + 1] * dold[1]);
      for (int j = 0; j < 2; j++) J[i * 2 + j] += u * dold[j] / dd;
    }
  }
  double L = R->st->q.b - R->st->q.a, Hs[4];
  if ((st = pair_jacobian(R, r, 1e-4 * L, Hs))) return st;
  double a = Hs[0], b = 0.5 * (Hs[1] + Hs[2]), c = Hs[3];
  double mean = 0.5 * (a + c), rad = hypot(0.5 * (a - c), b), e0 = mean - rad, e1 = mean + rad;
  /* as in the single end's case: below the action's scale or the residuals' error over the
   * difference step, or below 1e-6 of the other eigenvalue */
  double tiny = fmax(1e-9 * fabs(s->action) / (L * L), fmax(s->rtol, 1e-13) * scale / (1e-4 * L));
  tiny = fmax(tiny, 1e-6 * fmax(fabs(e0), fabs(e1)));
  int degenerate = !(fabs(e0) > tiny && fabs(e1) > tiny);
  s->ends_neg = degenerate ? 0 : (e0 < 0) + (e1 < 0);
  if (degenerate && s->method == CVAR_METHOD_NEWTON) s->degenerate = 1;
  s->ends_dim = 2;
  char curv[128];
  cv_set_msg(curv, sizeof curv,
             "eigenvalues of the action's second derivatives along the ends' motions %.3g, %.3g",
             e0, e1);
  say_converged(R, fmax(fabs(r[0]), fabs(r[1])), curv);
  return CVAR_OK;
}

/* The start point moved `shift` along the motion, in steps of at most a tenth of the
 * interval so that a curve is followed (cv_solve_all's starts). */
static cv_status shift_start(ends_run *R, mover *M, double shift) {
  double left = shift, tx = 1.0, ty = 0.0;
  while (fabs(left) > 1e-12 * R->L0) {
    double ds = fabs(left) > 0.1 * R->L0 ? copysign(0.1 * R->L0, left) : left;
    left -= ds;
    if (tangent(R, M, &tx, &ty) != 0) return CVAR_EINVAL;
    cv_status st = move_along(R, M, tx, ty, &ds);
    if (st) return st;
  }
  double other = R->m > 1 ? R->mv[1 - (int)(M - R->mv)].x : M->end ? R->p->a : R->p->b;
  if (!(fabs(M->x - other) > 0.05 * R->L0) || (M->end ? M->x < other : M->x > other)) {
    cv_set_msg(R->s->msg, sizeof R->s->msg,
               "a start moved %.3g along the end's motion leaves no interval", shift);
    return CVAR_EINVAL;
  }
  return CVAR_OK;
}

/* A mover at its start point: the end values there, the value that follows a curve, and
 * the projection onto the curve (ME-3). */
static cv_status mover_start(ends_run *R, mover *M, int end, double *buf) {
  const cv_problem *p = R->p;
  M->end = end, M->kind = p->move[end].kind, M->k = -1, M->y = buf;
  M->x = end ? p->b : p->a;
  cv_status st = start_values(p, end, M->x, M->y);
  if (st) {
    cv_set_msg(R->s->msg, sizeof R->s->msg, "the initial guess failed at the moving end x = %g",
               M->x);
    return st;
  }
  if (M->kind == CV_END_CURVE && (st = curve_start(R, M))) return st;
  if (M->k >= 0) {
    R->st->fixed[2 * M->k + end] = 1; /* the curve sets it (ME-3) */
    M->yk = M->y[M->k];
  }
  R->st->k[end] = M->k;
  return CVAR_OK;
}

cv_status cv_ends_run(cv_solver *s, const cv_problem *p, double shift) {
  cv_status st = CVAR_OK;
  ends_run R;
  double *buf = NULL;
  memset(&R, 0, sizeof R);
  R.s = s, R.p = p, R.n = p->n;
  if (p->nc > 0) {
    cv_set_msg(s->msg, sizeof s->msg, "a moving end with pointwise constraints is not supported");
    return s->status = CVAR_EINVAL;
  }
  if (!p->F) {
    cv_set_msg(s->msg, sizeof s->msg, "no integrand set");
    return s->status = CVAR_EINVAL;
  }
  R.L0 = p->b - p->a;
  R.st = state_new(p);
  buf = cv_malloc(5 * (size_t)p->n * sizeof *buf);
  if (!R.st || !buf) {
    st = CVAR_ENOMEM;
    cv_set_msg(s->msg, sizeof s->msg, "out of memory");
    goto done;
  }
  R.P = buf, R.v = R.P + p->n, R.ye = R.v + p->n;
  R.st->k[0] = R.st->k[1] = -2;
  for (int end = 0; end < 2 && !st; end++)
    if (p->move[end].kind != CV_END_FIXED) {
      st = mover_start(&R, &R.mv[R.m], end, R.ye + (1 + R.m) * (size_t)p->n);
      R.m++;
    }
  if (st) goto done;
  if (shift != 0.0 && (st = shift_start(&R, &R.mv[R.m - 1], shift))) goto done;
  /* a curve that involves no free value fixes its end's position alone */
  int fixed0 = R.mv[0].kind == CV_END_CURVE && R.mv[0].k < 0;
  int fixed1 = R.m > 1 && R.mv[1].kind == CV_END_CURVE && R.mv[1].k < 0;
  if ((R.m == 1 && fixed0) || (fixed0 && fixed1)) {
    st = solve_at(&R);
  } else if (R.m == 1 || fixed0 || fixed1) {
    if (fixed0) { /* the one that moves is iterated (mover 0); the other stays */
      mover tmp = R.mv[0];
      R.mv[0] = R.mv[1], R.mv[1] = tmp;
    }
    st = iterate(&R);
  } else {
    st = iterate_pair(&R);
  }
done:
  restore_caller_settings(&R);
  cv_free(R.t), cv_free(R.Y), cv_free(R.deg), cv_free(buf);
  if (R.st) {
    s->ends = R.st;
    if (st != CVAR_OK) s->ends_dim = 0, s->ends_neg = 0;
  }
  if (R.solves > 1) s->iterations = (int)(R.iters > 2000000000L ? 2000000000L : R.iters);
  return st;
}
