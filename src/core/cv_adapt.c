/* src/core/cv_adapt.c — automatic accuracy in rounds: solve, estimate (HP-2), decide (HP-4,
 * HP-5), until the estimate is at most the tolerance or a stop rule says why not (HP-6).
 * --tol chooses degrees and elements (hp); --adapt the elements at a fixed degree (AD-1).
 * SPDX-License-Identifier: MIT */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"
#include "cv_reuse.h"

#define MAX_ROUNDS 80
/* Rounds without halving the best estimate before the loop counts as stalled (HP-6): few
 * near the round-off floor, many before it (bisecting towards a thin layer leaves the
 * estimate flat for as many rounds as the layer is halvings thin). */
#define STALL_ROUNDS_FLOOR 3
#define STALL_ROUNDS       40
/* ... unless those rounds multiplied the nodes by STALL_GROWTH: refinement everywhere that
 * buys nothing is a floor of the integrand's own values (a table's rounding), not a layer
 * being approached (HP-6). */
#define STALL_GROWTH 8

cv_status cv_solver_set_tol(cv_solver *s, double tol, int max_nodes) {
  if (!s || !(tol >= 0) || !isfinite(tol) || max_nodes < 2) return CVAR_EINVAL;
  s->adapt_tol = tol;
  s->adapt_max = max_nodes;
  s->hp = 1;
  return CVAR_OK;
}

cv_status cv_solver_set_time_limit(cv_solver *s, double seconds) {
  if (!s || !(seconds >= 0) || !isfinite(seconds)) return CVAR_EINVAL;
  s->time_limit = seconds;
  return CVAR_OK;
}

cv_status cv_solver_set_adapt(cv_solver *s, double tol, int max_elements) {
  if (!s || !(tol >= 0) || !isfinite(tol) || max_elements < 1) return CVAR_EINVAL;
  s->adapt_tol = tol;
  s->adapt_max = max_elements;
  s->hp = 0;
  return CVAR_OK;
}

/* The starting mesh of the rounds on [0, 1] with its degrees, from the caller's settings. */
static cv_status start_mesh(cv_solver *s, const cv_problem *p, int *E, double **t, int **deg) {
  double *xe = NULL;
  cv_status st = cv_mesh_build(&s->mesh, p->a, p->b, E, &xe, s->msg, sizeof s->msg);
  if (st) return st;
  *t = cv_malloc((size_t)(*E + 1) * sizeof **t);
  *deg = cv_malloc((size_t)*E * sizeof **deg);
  if (!*t || !*deg) {
    cv_free(xe);
    return CVAR_ENOMEM;
  }
  for (int i = 0; i <= *E; i++) (*t)[i] = (xe[i] - p->a) / (p->b - p->a);
  (*t)[0] = 0.0;
  (*t)[*E] = 1.0;
  if (s->mesh.degrees)
    cv_mesh_degrees(&s->mesh, p->a, p->b, *E, xe, *deg);
  else
    for (int e = 0; e < *E; e++) (*deg)[e] = s->degree;
  cv_free(xe);
  return CVAR_OK;
}

/* HP-1: a plain uniform start of one degree p < 8 on a problem with no singular end is
 * replaced by the same number of nodes at degree 8, at least 2 elements: a smooth solution
 * is resolved to 1e-12 by a few degree-8 elements, and starting there saves the rounds that
 * raise the degrees one prediction at a time (2 rounds -> 1 on the smooth reference
 * problems). Next to a singular end the degree must stay low (HP-5), so such a start is
 * kept. The singular ends are those the start's discretisation finds (cv_start_setup). */
static cv_status start_at_degree8(cv_solver *s, const cv_problem *p, const cv_meshspec *spec0,
                                  int *E, double **t, int **deg) {
  if (!s->hp || spec0->kind != CV_MESH_UNIFORM || spec0->nbreak > 0 || spec0->degrees ||
      (*deg)[0] >= CV_MAX_DEGREE)
    return CVAR_OK;
  for (int e = 1; e < *E; e++)
    if ((*deg)[e] != (*deg)[0]) return CVAR_OK;
  cv_status st = cv_solver_set_mesh_hp(s, *E, *t, *deg);
  if (!st) st = cv_start_setup(s, p);
  if (st) return st == CVAR_ENOMEM ? st : CVAR_OK; /* the first round says what is wrong */
  if (s->disc.sing_a || s->disc.sing_b) return CVAR_OK;
  int E8 = (*E * (*deg)[0] + CV_MAX_DEGREE - 1) / CV_MAX_DEGREE;
  if (E8 < 2) E8 = 2;
  double *t8 = cv_malloc((size_t)(E8 + 1) * sizeof *t8);
  int *d8 = cv_malloc((size_t)E8 * sizeof *d8);
  if (!t8 || !d8) {
    cv_free(t8);
    cv_free(d8);
    return CVAR_ENOMEM;
  }
  for (int e = 0; e <= E8; e++) t8[e] = (double)e / E8;
  for (int e = 0; e < E8; e++) d8[e] = CV_MAX_DEGREE;
  cv_free(*t);
  cv_free(*deg);
  *t = t8, *deg = d8, *E = E8;
  return CVAR_OK;
}

/* Largest nodal value of the solution (at least 1): the scale of its round-off floor. */
static double value_scale(const cv_solver *s) {
  double m = 1.0;
  for (long k = 0; k < s->disc.ndof; k++) m = fmax(m, fabs(s->y[k]));
  return m;
}

/* HP-6: the next mesh would exceed the cap on nodes (hp) or elements (--adapt). */
static void say_cap(cv_solver *s, double est) {
  cv_set_msg(s->msg, sizeof s->msg,
             "the next refinement would exceed the cap of %d %s after %d round%s; the "
             "estimated max nodal error reached is %.2g > %.2g; %s",
             s->adapt_max, s->hp ? "nodes" : "elements", s->rounds, s->rounds == 1 ? "" : "s", est,
             s->adapt_tol,
             s->hp ? "ask for a larger tolerance (or raise the cap: --max-nodes, or the "
                     "max_nodes argument of cv_solver_set_tol)"
                   : "use a higher degree or a looser tolerance (or raise the cap: "
                     "--max-elements, or the max_elements argument of cv_solver_set_adapt)");
}

/* Where a floor that refinement does not lower comes from (HP-6): a table's rounding when
 * the integrand reads tables, else round-off amplified by the conditioning. */
static const char *floor_cause(int tables) {
  return tables ? "noise in the integrand's values, such as a table's rounding"
                : "round-off amplified by the conditioning of the problem: a nearly singular "
                  "Hessian, as next to a conjugate point, multiplies the round-off of the "
                  "equations";
}

/* HP-6: why the rounds must stop before reaching tol, as a sentence in s->msg, or 0 to go
 * on. best: smallest estimate so far; floor_: the estimate's round-off part (HP-2);
 * stalled: rounds since the best last halved, at halved_nodes nodes; tables: the integrand
 * reads tables. */
static int stop_rule(cv_solver *s, double est, double best, double floor_, int stalled,
                     int halved_nodes, int next_size, double elapsed, int tables) {
  double tol = s->adapt_tol;
  if ((best <= floor_ && tol < floor_) ||
      (stalled >= STALL_ROUNDS_FLOOR && best <= 10.0 * floor_)) {
    if (est <= 10.0 * floor_)
      cv_set_msg(s->msg, sizeof s->msg,
                 "the error estimate reached %.2g > %.2g and can go no lower: that is the "
                 "round-off floor of double precision for this solution (about %.1g, from "
                 "values of size %.2g and the slope times the spacing of doubles at the "
                 "nodes); ask for a larger tolerance",
                 est, tol, floor_, value_scale(s));
    else /* the last estimate is far above the floor the best one reached (HP-6) */
      cv_set_msg(s->msg, sizeof s->msg,
                 "the error estimate stopped decreasing: its smallest, %.2g, was within 10 "
                 "times the round-off floor of the values (about %.1g, values of size %.2g), "
                 "and the last rounds gave up to %.2g > %.2g, above that floor: %s; ask for a "
                 "larger tolerance",
                 best, floor_, value_scale(s), est, tol, floor_cause(tables));
    return 1;
  }
  if (s->hp && stalled >= STALL_ROUNDS_FLOOR &&
      s->disc.nodes >= (double)STALL_GROWTH * halved_nodes) {
    cv_set_msg(s->msg, sizeof s->msg,
               "the error estimate stopped decreasing at %.2g > %.2g: %d rounds multiplied the "
               "nodes by %.0f (%d to %d) without halving it, a floor that refinement does not "
               "lower (%s); ask for a larger tolerance",
               best, tol, stalled, (double)s->disc.nodes / halved_nodes, halved_nodes,
               s->disc.nodes, floor_cause(tables));
    return 1;
  }
  if (stalled >= STALL_ROUNDS) {
    cv_set_msg(s->msg, sizeof s->msg,
               "the error estimate stopped decreasing at %.2g > %.2g (%d rounds without "
               "halving it, %d elements, %d nodes)",
               best, tol, stalled, s->disc.E, s->disc.nodes);
    return 1;
  }
  if (s->time_limit > 0 && elapsed >= s->time_limit) {
    char reached[96];
    if (isfinite(est))
      cv_set_msg(reached, sizeof reached, "the estimated max nodal error reached is %.2g > %.2g",
                 est, tol);
    else if (isfinite(best))
      cv_set_msg(reached, sizeof reached,
                 "the last round gave no error bound (HP-3), the best estimate was %.2g", best);
    else
      cv_set_msg(reached, sizeof reached, "no round has given an error bound yet (HP-3)");
    cv_set_msg(s->msg, sizeof s->msg,
               "the time limit of %.3g s was reached after %d round%s (%.3g s, %d elements, %d "
               "nodes); %s; allow more time or ask for a larger tolerance",
               s->time_limit, s->rounds, s->rounds == 1 ? "" : "s", elapsed, s->disc.E,
               s->disc.nodes, reached);
    return 1;
  }
  if (next_size > s->adapt_max) {
    say_cap(s, est);
    return 1;
  }
  if (s->rounds >= MAX_ROUNDS) {
    cv_set_msg(s->msg, sizeof s->msg,
               "no estimate below %.2g after %d refinement rounds (estimate %.2g)", tol, MAX_ROUNDS,
               est);
    return 1;
  }
  return 0;
}

/* Nodes (hp) or elements (--adapt) after refining d's elements with eta >= thresh. */
static int next_size(const cv_disc *d, const double *eta, const double *sigma, double thresh,
                     double tol, int hp) {
  long size = hp ? d->nodes : d->E;
  for (long e = 0; e < d->E; e++)
    if (cv_hp_marked(eta[e], sigma[e], thresh, tol, hp)) size += hp ? cv_disc_edeg(d, e) + 1 : 1;
  return size > 2000000000L ? 2000000000 : (int)size;
}

/* HP-7: the pilot refines when its largest predicted coefficient is above PILOT_MISS x tol
 * (it over-states the enriched estimate by ~3, measured on the reference problems: 3.3e-12
 * against 1.2e-12, 5.1e-13 against 1.3e-13), and aims its predictions at tol rather than
 * HP-4's tol / 10 for the same reason (PILOT_AIM x tol as HP-4's target). */
#define MERGE_ROUNDS 3 /* HP-8: merges in the first rounds only */
#define PILOT_MISS   1.0
#define PILOT_AIM    10.0
/* HP-7a: on a mesh of degree 8 alone, the pilot's tails are aimed at PILOT_AIM8 x tol: the
 * nodal error, which the estimate measures and compares with tol, was measured at 0.004 to
 * 0.07 of the largest predicted tail on the smooth reference problems (tails 1e-9..1e-14) */
#define PILOT_AIM8 10.0
/* HP-7b: the aim learnt from the rounds of this solver's earlier solves: a round laid by the
 * pilot whose estimate missed tol by a factor x lowers it by 2x (at most 10x at a time), one
 * within tol / 10 raises it by 1.25, between PILOT_AIM8 / 100 and PILOT_AIM8 */
#define AIM_MISS_MARGIN 0.5
#define AIM_RELAX       1.25
double cv_pilot_aim(const cv_solver *s) {
  return s->pilot_aim > 0 && s->aim_tol == s->adapt_tol ? s->pilot_aim : PILOT_AIM8;
}

static void pilot_learn(cv_solver *s, double est, double tol) {
  double aim = cv_pilot_aim(s);
  if (est > tol)
    aim *= fmax(0.1, AIM_MISS_MARGIN * tol / est);
  else if (est < 0.1 * tol)
    aim *= AIM_RELAX;
  s->pilot_aim = fmin(PILOT_AIM8, fmax(0.01 * PILOT_AIM8, aim));
  s->aim_tol = tol;
}

/* ... and trusted from a Legendre rate of 0.75 (HP-4's smooth is 1): an oscillation of 0.85
 * periods per degree-8 element decays at 0.96, and the h^9 of HP-7a over-states what
 * halving such an element gains (its rate also grows by ln 2), so it is not too few */
#define PILOT_RATE8 0.75
/* HP-7: after the first solve, when every element has degree >= 4 and decays smoothly
 * (sigma >= 1) and the largest predicted next coefficient is above tol, refine by those
 * predictions (HP-4 with eta = the tail) without the estimate: the enriched solve of a mesh
 * predicted to be too coarse is skipped. On a degree-8 mesh a batch row handed on (HP-9),
 * laid for tails of cv_pilot_aim x tol, only a tail above that aim is a miss: the estimate
 * decides the rest. 1 when it refined (E, t, deg replaced), 0 when not, -1 out of memory. */
static int pilot_refine(cv_solver *s, double *tail, double *sigma, double *where, double tol,
                        int keep_bounds, int handed_on, int *E, double **t, int **deg) {
  const cv_disc *d = &s->disc;
  double tmax = 0.0;
  /* HP-7a lays new boundaries: not with breakpoints, which must stay boundaries */
  int En = 0, *dn = NULL, all8 = !d->sing_a && !d->sing_b && !keep_bounds;
  double *tn = NULL;
  for (long e = 0; e < d->E && all8; e++) all8 = cv_disc_edeg(d, e) == CV_MAX_DEGREE;
  cv_estimate_pilot(s, tail, sigma);
  for (long e = 0; e < d->E; e++) {
    if (cv_disc_edeg(d, e) < 4 || !(sigma[e] >= (all8 ? PILOT_RATE8 : 1.0)) || !isfinite(tail[e]))
      return 0;
    tmax = fmax(tmax, tail[e]);
    where[e] = 0.0;
  }
  if (!(tmax > (all8 && handed_on ? cv_pilot_aim(s) : PILOT_MISS) * tol)) return 0;
  if (all8 ? cv_hp_pilot_mesh(d, tail, cv_pilot_aim(s) * tol, &En, &tn, &dn)
           : cv_hp_refine(d, tail, sigma, where, 0.25 * tmax, PILOT_AIM * tol, 1, &En, &tn, &dn))
    return -1;
  long nodes = 1;
  for (int e = 0; e < En; e++) nodes += dn[e];
  if (nodes > s->adapt_max) { /* the cap: leave it to the estimated rounds to say */
    cv_free(tn);
    cv_free(dn);
    return 0;
  }
  cv_free(*t);
  cv_free(*deg);
  *t = tn, *deg = dn, *E = En;
  return 1;
}

/* HP-2a: whether each end of the next mesh (t, deg) lies in the end element of s's last
 * solve, at no lower degree, and that solve passed the near-singular end check
 * there: then the next solve need not check it again (a smaller element of the same or a
 * higher degree integrates the same integrand at least as well). */
static void ends_inherited(cv_solver *s, int E, const double *t, const int *deg) {
  const cv_disc *d = &s->disc;
  s->ends_passed[0] = s->ends_passed[1] = 0;
  if (s->rounds < 2 || !s->have || d->E < 1 || E < 1) return; /* this run's rounds only */
  double a = d->xe[0], L = d->xe[d->E] - a;
  s->ends_passed[0] = s->ends_ok[0] && t[1] <= (d->xe[1] - a) / L && deg[0] >= cv_disc_edeg(d, 0);
  s->ends_passed[1] = s->ends_ok[1] && t[E - 1] >= (d->xe[d->E - 1] - a) / L &&
                      deg[E - 1] >= cv_disc_edeg(d, d->E - 1);
}

static int cmp_desc(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x < y) - (x > y);
}

/* HP-4: the least surplus to mark so that the unmarked surpluses sum to at most frac of all
 * (the largest first): a marked element's contribution is taken to vanish (a degree-8 split
 * divides it by ~500), and the nodal error to grow like the sum of the elements' surpluses
 * (each element's residual propagates to every node). frac = tol / (2 est): close to the
 * target, only the few largest are refined, instead of every element within a factor 4 of
 * the largest (which, on a mesh that already spreads the error evenly, is all of them and
 * doubles the nodes to gain a factor 1.2). 0 when there is nothing to sort. */
static double dorfler_threshold(const double *eta, int E, double frac) {
  if (!(frac > 0) || E < 2) return 0.0;
  double *v = cv_malloc((size_t)E * sizeof *v), sum = 0.0, th = 0.0;
  if (!v) return 0.0;
  for (int e = 0; e < E; e++) sum += (v[e] = isfinite(eta[e]) ? eta[e] : 0.0);
  qsort(v, (size_t)E, sizeof *v, cmp_desc);
  double rest = sum;
  for (int e = 0; e < E && rest > frac * sum; e++) rest -= v[e], th = v[e];
  cv_free(v);
  return th;
}

/* Prefix a sentence to s's message (truncated to its buffer). */
static void prefix_msg(cv_solver *s, const char *pre) {
  char m[sizeof s->msg];
  cv_set_msg(m, sizeof m, "%s%s", pre, s->msg);
  memcpy(s->msg, m, sizeof m);
}

/* Rounds (HP-1): solve on the current mesh warm-started from the last enriched solution,
 * estimate, refine. Ends with s holding the last round's solution and s->err_est. */
cv_status cv_adapt_run(cv_solver *s, const cv_problem *p) {
  cv_status st;
  int handed_on = s->handed_on; /* the start is a mesh a batch row handed on (HP-9) */
  s->handed_on = 0;
  if (p->c1) return cv_hermite_adapt(s, p); /* C^1 elements: H-7, H-8 */
  cv_solver *f = cv_solver_new(&st);
  double *t = NULL, *eta = NULL, *sigma = NULL, *where = NULL;
  int *deg = NULL, E = 0, stalled = 0, warm = 0, misses = 0, halved_nodes = 1, piloted = 0;
  long iters = 0, iters_ref = 0; /* Newton iterations of all rounds; of the enriched solves */
  double tol = s->adapt_tol, best = INFINITY, t0 = cv_now();
  cv_meshspec spec0 = s->mesh;
  int degree0 = s->degree;
  char rescued[400] = ""; /* what the rescues of failed rounds did (HP-9) */
  if (!f) return CVAR_ENOMEM;
  st = start_mesh(s, p, &E, &t, &deg);
  if (st) {
    if (st == CVAR_ENOMEM) cv_set_msg(s->msg, sizeof s->msg, "out of memory");
    goto cleanup;
  }
  s->mesh.t = NULL; /* spec0 keeps the caller's mesh; restored at the end */
  s->mesh.degrees = NULL;
  s->mesh.nbreak = 0; /* breakpoints are already boundaries, and stay so */
  st = start_at_degree8(s, p, &spec0, &E, &t, &deg);
  if (st) {
    cv_set_msg(s->msg, sizeof s->msg, "out of memory");
    goto cleanup;
  }
  for (s->rounds = 1;; s->rounds++) {
    ends_inherited(s, E, t, deg);
    st = cv_solver_set_mesh_hp(s, E, t, deg);
    if (!st && warm) st = cv_warm_start(s, p, warm == 1 ? f : s);
    if (st) goto cleanup;
    st = cv_solve_mesh(s, p);
    cv_solver_set_start(s, 0, NULL);
    iters += s->iterations;
    if (st) { /* HP-9: from the guess, on this mesh and on finer uniform ones */
      char why[400], add[400];
      int E0 = E, nodes = s->disc.nodes;
      memcpy(why, s->msg, sizeof why);
      why[sizeof why - 1] = '\0';
      cv_rescue r = {&spec0, degree0, warm, t0, &iters};
      st = cv_adapt_rescue(s, p, &r, st, &E, &t, &deg, add, sizeof add);
      if (st == CVAR_OK) {
        size_t ln = strlen(rescued);
        cv_set_msg(rescued + ln, sizeof rescued - ln, "%s", add);
      } else {
        cv_set_msg(s->msg, sizeof s->msg, "%s, round %d (%d elements, %d nodes): %s%s",
                   s->hp ? "automatic accuracy" : "adaptive refinement", s->rounds, E0, nodes, why,
                   add);
        goto cleanup;
      }
    }
    cv_free(eta);
    cv_free(sigma);
    cv_free(where);
    eta = cv_malloc((size_t)E * sizeof *eta);
    sigma = cv_malloc((size_t)E * sizeof *sigma);
    where = cv_malloc((size_t)E * sizeof *where);
    if (!eta || !sigma || !where) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    if (s->hp && s->rounds == 1) { /* HP-7: the first solve's own coefficients */
      int r = pilot_refine(s, eta, sigma, where, tol, spec0.nbreak > 0, handed_on, &E, &t, &deg);
      if (r < 0) {
        st = CVAR_ENOMEM;
        goto cleanup;
      }
      if (r > 0) {
        warm = 2;
        piloted = 1; /* the next round's estimate judges the pilot's aim (HP-7b) */
        continue;
      }
    }
    double est, floor_ = 0.0;
    int done = 0;
    char why[400];
    st = cv_estimate_enriched(s, p, f, &est, NULL, &floor_, why, sizeof why);
    int obstacles = cv_kkt_has_inequalities(p);
    if (!st && obstacles) est = fmax(est, cv_contact_gap_term(s, p, NULL)); /* OB-8 */
    /* the indicators only when another round may follow */
    if (!st && est > tol) st = cv_estimate_indicators(s, f, eta, sigma, where);
    if (!st && est > tol && obstacles) cv_contact_gap_term(s, p, eta);
    iters_ref += f->iterations;
    if (!st && piloted) pilot_learn(s, est, tol);
    piloted = 0;
    if (st == CVAR_ENOMEM) goto cleanup;
    if (st) {
      /* HP-3: no bound from this mesh; halve every element and start the next round from
       * this solution. Three such rounds in a row end the search. */
      s->err_est = NAN;
      if (++misses >= 3) {
        cv_set_msg(s->msg, sizeof s->msg, "%s, round %d: %s",
                   s->hp ? "automatic accuracy" : "adaptive refinement", s->rounds, why);
        st = CVAR_EMAXITER;
        goto cleanup;
      }
      for (int e = 0; e < E; e++) eta[e] = 1.0, sigma[e] = 0.0, where[e] = 0.0;
      est = INFINITY;
      warm = 2;
    } else {
      misses = 0;
      warm = 1;
      s->err_est = est;
      if (est <= tol) {
        cv_set_msg(s->msg, sizeof s->msg,
                   "accuracy reached on %d elements (%d nodes) after %d round%s, %ld Newton "
                   "iterations in all (and %ld on the reference meshes); estimated max nodal "
                   "error %.2g <= %.2g",
                   E, s->disc.nodes, s->rounds, s->rounds == 1 ? "" : "s", iters, iters_ref, est,
                   tol);
        st = CVAR_OK;
        done = 1; /* leaves after the progress report below */
      }
      if (est <= 0.5 * best)
        stalled = 0, halved_nodes = s->disc.nodes;
      else
        stalled++;
      if (est < best) best = est;
    }
    if (s->progress) {
      cv_progress info = {CVAR_PROGRESS_ROUND, s->iterations, s->gnorm, NAN,       NAN,
                          s->action,           s->rounds,     E,        s->err_est};
      if (s->progress(&info, s->progress_user) != 0) {
        st = CVAR_ECANCELLED;
        cv_set_msg(s->msg, sizeof s->msg,
                   "cancelled by the progress callback after adaptive "
                   "round %d (%d elements, estimated max nodal error %.2g)",
                   s->rounds, E, s->err_est);
        goto cleanup;
      }
    }
    if (done) goto cleanup; /* converged (above), reported to the callback */
    double emax = 0.0;
    for (int e = 0; e < E; e++) emax = fmax(emax, eta[e]);
    /* mark: hp, the elements within a factor 4 of the largest surplus and the smooth ones
     * above tol (HP-4); --adapt, those above tol / 4 (AD-1), and always the largest */
    double thresh = s->hp ? 0.25 * emax : fmin(0.25 * tol, emax);
    if (s->hp) {
      double td = dorfler_threshold(eta, E, 0.5 * tol / est);
      if (td > thresh) thresh = td;
    }
    if (stop_rule(s, est, best, floor_, stalled, halved_nodes,
                  next_size(&s->disc, eta, sigma, thresh, tol, s->hp), cv_now() - t0,
                  p->nnotes > 0)) {
      st = CVAR_EMAXITER;
      goto cleanup;
    }
    cv_free(t);
    cv_free(deg);
    int mode = s->hp ? (s->rounds <= MERGE_ROUNDS ? 2 : 1) : 0;
    st = cv_hp_refine(&s->disc, eta, sigma, where, thresh, tol, mode, &E, &t, &deg);
    if (st) goto cleanup;
    long size = s->hp ? 1 : E; /* next_size predicted it; the refined mesh is what counts */
    for (int e = 0; s->hp && e < E; e++) size += deg[e];
    if (size > s->adapt_max) { /* the solution and estimate of this round stay the answer */
      say_cap(s, est);
      st = CVAR_EMAXITER;
      goto cleanup;
    }
  }
cleanup:
  /* a failed allocation between solves leaves the last solve's "converged in N
   * iterations" in the message: say what happened instead (issue 27, item 15) */
  if (st == CVAR_ENOMEM && !strstr(s->msg, "out of memory"))
    cv_set_msg(s->msg, sizeof s->msg, "out of memory in %s, round %d (%d elements)",
               s->hp ? "automatic accuracy" : "adaptive refinement", s->rounds, E);
  if (rescued[0]) prefix_msg(s, rescued);
  s->ends_passed[0] = s->ends_passed[1] = 0; /* the next plain solve checks its ends */
  s->iterations = (int)(iters > 2000000000L ? 2000000000L : iters); /* all rounds */
  cv_free(s->mesh.t);
  cv_free(s->mesh.degrees);
  s->mesh = spec0; /* the caller's mesh settings, for the next solve */
  s->degree = degree0;
  cv_free(t);
  cv_free(deg);
  cv_free(eta);
  cv_free(sigma);
  cv_free(where);
  cv_solver_free(f);
  return st;
}
