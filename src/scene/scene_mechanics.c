/* src/scene/scene_mechanics.c — a scene as a mech_problem (src/mech): its DAG, integrand,
 * constraints and names, the guess at the start as Newton's start for the equilibrium;
 * and the line of the entry a failure is about.
 * SPDX-License-Identifier: MIT */
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_mechanics.h"

/* The arrays a mech_problem points to. */
typedef struct {
  mech_problem mp;
  ex_id *ids;         /* [ncons + nints] */
  const char **names; /* [n + ncons + nints] */
  double *start;      /* [n] */
} adapter;

static void adapter_free(adapter *a) {
  cv_free(a->ids);
  cv_free(a->names);
  cv_free(a->start);
}

/* e with the scene's y''_i slots moved to mech's 2n+1+i (mech.h); -1 out of memory. */
static ex_id to_mech_slots(const scene *s, ex_id e) {
  for (int i = 0; i < s->n && e >= 0 && s->c1; i++)
    e = ex_subst(s->dag, e, sc_d2_slot(s, i), ex_slot(s->dag, 1 + 2 * s->n + i));
  return e;
}

static int adapter_new(const scene *s, int with_start, adapter *a) {
  int n = s->n, nc = s->ncons, ni = s->nints;
  memset(a, 0, sizeof *a);
  a->ids = cv_malloc((size_t)(nc + ni + 1) * sizeof *a->ids);
  a->names = cv_malloc((size_t)(n + nc + ni) * sizeof *a->names);
  a->start = cv_malloc((size_t)n * sizeof *a->start);
  if (!a->ids || !a->names || !a->start ||
      (with_start && scene_eval_guess(s, 1, &s->a, a->start) < 0)) {
    adapter_free(a);
    return -1;
  }
  for (int i = 0; i < n; i++) a->names[i] = s->unknowns[i];
  for (int c = 0; c < nc; c++) {
    a->ids[c] = s->cons[c].expr;
    a->names[n + c] = s->cons[c].name;
  }
  for (int r = 0; r < ni; r++) {
    if ((a->ids[nc + r] = to_mech_slots(s, s->ints[r].expr)) < 0) {
      adapter_free(a);
      return -1;
    }
    a->names[n + nc + r] = s->ints[r].name;
  }
  mech_problem *mp = &a->mp;
  mp->dag = s->dag;
  mp->n = n;
  mp->F = to_mech_slots(s, s->F);
  mp->order2 = s->c1;
  if (mp->F < 0 || (s->c1 && s->params_as_inputs)) { /* mech's y'' slots are parameters' */
    adapter_free(a);
    return -1;
  }
  mp->ncons = nc;
  mp->cons = a->ids;
  mp->nints = ni;
  mp->ints = a->ids + nc;
  mp->variable = s->variable;
  mp->unknowns = a->names;
  mp->cons_names = a->names + n;
  mp->int_names = a->names + n + nc;
  mp->start = a->start;
  mp->start_x = s->a;
  return 0;
}

/* The scene line of a mech_problem entry (MECH_AT_*), 0 for none. */
static int line_of(const scene *s, int at) {
  if (at == MECH_AT_F) return s->F_line;
  int k = at - MECH_AT_CONS;
  if (k >= 0 && k < s->ncons) return s->cons[k].line;
  if (k >= s->ncons && k < s->ncons + s->nints) return s->ints[k - s->ncons].line;
  return 0;
}

cv_status scene_equations_new(const scene *s, mech_equations *eq, char *err, size_t errlen) {
  char why[SC_ERRLEN] = "";
  adapter a;
  memset(eq, 0, sizeof *eq);
  eq->hamiltonian = -1;
  if (err && errlen) err[0] = '\0';
  if (adapter_new(s, 0, &a) < 0) {
    sc_err(err, errlen, s->file, 0, "out of memory while building the equations");
    return CVAR_ENOMEM;
  }
  cv_status st = mech_equations_new(&a.mp, eq, why, sizeof why);
  adapter_free(&a);
  if (st != CVAR_OK) sc_err(err, errlen, s->file, 0, "%s", why);
  return st;
}

cv_status scene_modes_new(const scene *s, mech_modes *md, char *err, size_t errlen) {
  char why[SC_ERRLEN] = "";
  int at = MECH_AT_NONE;
  adapter a;
  memset(md, 0, sizeof *md);
  if (err && errlen) err[0] = '\0';
  if (s->c1) {
    sc_err(err, errlen, s->file, s->F_line,
           "modes: the integrand has y'', and small oscillations are computed for a "
           "Lagrangian L(y, y') only");
    return CVAR_EINVAL;
  }
  if (adapter_new(s, 1, &a) < 0) {
    sc_err(err, errlen, s->file, 0, "out of memory while computing the modes");
    return CVAR_ENOMEM;
  }
  cv_status st = mech_modes_new(&a.mp, md, &at, why, sizeof why);
  adapter_free(&a);
  if (st != CVAR_OK) sc_err(err, errlen, s->file, line_of(s, at), "%s", why);
  return st;
}
