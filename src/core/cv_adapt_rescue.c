/* src/core/cv_adapt_rescue.c — a round of --tol / --adapt whose solve failed is not the end
 * of the rounds (theory HP-9): once more from the guess on the same mesh, then from the
 * guess on uniform meshes finer than it, each a plain solve with its own policies
 * (continuation, the graded retry, singular ends); the first that converges is the round's
 * answer and its mesh the rounds' mesh.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* Finer uniform starts tried, each RESCUE_GROWTH times the elements of the one before. */
#define RESCUE_MESHES 4
#define RESCUE_GROWTH 4

/* Failures of the search for a path (not of the input, memory or the caller's cancel; not a
 * non-finite or singular start, which no mesh changes), with the iteration limit counted
 * only when the caller did not choose it below 20. */
static int rescuable(const cv_solver *s, cv_status st) {
  return st == CVAR_ESTALL || st == CVAR_EDIVERGED ||
         ((st == CVAR_ENONFINITE || st == CVAR_ESINGULAR) && s->iterations > 0) ||
         (st == CVAR_EMAXITER && s->maxit >= 20);
}

/* s's last mesh as the rounds hold one: boundaries on [0, 1] and a degree per element. */
static cv_status mesh_of(const cv_solver *s, int *E, double **t, int **deg) {
  const cv_disc *d = &s->disc;
  double *tn = cv_malloc((size_t)(d->E + 1) * sizeof *tn);
  int *dn = cv_malloc((size_t)d->E * sizeof *dn);
  if (!tn || !dn) {
    cv_free(tn);
    cv_free(dn);
    return CVAR_ENOMEM;
  }
  double a = d->xe[0], L = d->xe[d->E] - a;
  for (long e = 0; e <= d->E; e++) tn[e] = (d->xe[e] - a) / L;
  tn[0] = 0.0, tn[d->E] = 1.0;
  for (long e = 0; e < d->E; e++) dn[e] = cv_disc_edeg(d, e);
  cv_free(*t);
  cv_free(*deg);
  *t = tn, *deg = dn, *E = d->E;
  return CVAR_OK;
}

/* One plain solve from the guess on the caller's mesh kind (spec0) with E elements of
 * degree p; the rounds' mesh is left for cv_solver_set_mesh_hp to set again. */
static cv_status solve_uniform(cv_solver *s, const cv_problem *p, const cv_meshspec *spec0, int E,
                               int deg) {
  cv_status st = cv_solver_set_elements(s, E);
  if (st) return st;
  s->mesh.kind = spec0->kind; /* uniform or graded, with the caller's breakpoints */
  s->mesh.grading = spec0->grading;
  s->mesh.grade_end = spec0->grade_end;
  s->mesh.nbreak = spec0->nbreak; /* s->mesh.breaks is spec0's (cv_adapt_run) */
  s->degree = deg;
  st = cv_solve_mesh(s, p);
  s->mesh.nbreak = 0;
  return st;
}

cv_status cv_adapt_rescue(cv_solver *s, const cv_problem *p, const cv_rescue *r, cv_status first,
                          int *E, double **t, int **deg, char *note, size_t len) {
  note[0] = '\0';
  if (!rescuable(s, first)) return first;
  long nodes0 = 1;
  for (int e = 0; e < *E; e++) nodes0 += (*deg)[e];
  cv_status st = first;
  if (r->warm) { /* the same mesh from the guess: the warm start may be the trouble */
    st = cv_solve_mesh(s, p);
    *r->iters += s->iterations;
    if (!st) {
      cv_set_msg(note, len,
                 "round %d: from the last round's solution Newton failed (%s), from the guess "
                 "on the same mesh it converged; ",
                 s->rounds, cv_strerror(first));
      return CVAR_OK;
    }
    if (!rescuable(s, st)) return first;
  }
  const cv_meshspec *spec0 = r->spec0;
  int tried = 0, Elast = 0;
  if (spec0->kind != CV_MESH_USER && spec0->elements > 0)
    for (long Ek = spec0->elements; tried < RESCUE_MESHES && Ek < 100000000L; Ek *= RESCUE_GROWTH) {
      long nodes = Ek * r->degree0 + 1;
      if (nodes < nodes0) continue;
      if (nodes > s->adapt_max) break;
      if (s->time_limit > 0 && cv_now() - r->t0 >= s->time_limit) break;
      tried++;
      Elast = (int)Ek;
      st = solve_uniform(s, p, spec0, (int)Ek, r->degree0);
      *r->iters += s->iterations;
      if (st == CVAR_OK) {
        st = mesh_of(s, E, t, deg);
        if (st) return st;
        cv_set_msg(note, len,
                   "round %d on %ld nodes failed (%s), so the rounds started again from the "
                   "guess on %d uniform elements of degree %d, where the solve converged; ",
                   s->rounds, nodes0, cv_strerror(first), Elast, r->degree0);
        return CVAR_OK;
      }
      if (!rescuable(s, st)) break;
    }
  if (tried > 0 || r->warm) {
    char last[300];
    memcpy(last, s->msg, sizeof last);
    last[sizeof last - 1] = '\0';
    if (tried > 0)
      cv_set_msg(note, len,
                 "; from the guess on %s%d uniform start%s of up to %d elements of degree %d "
                 "it failed too (the last: %s)",
                 r->warm ? "the same mesh and " : "", tried, tried == 1 ? "" : "s", Elast,
                 r->degree0, last);
    else
      cv_set_msg(note, len, "; from the guess on the same mesh it failed too (%s)", last);
  }
  return first;
}
