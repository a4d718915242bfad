/* src/core/cv_problem.c — the problem object: interval, unknowns, end values, integrand, guess.
 * SPDX-License-Identifier: MIT */
#include <ctype.h>
#include <math.h>
#include <string.h>

#include "cv_internal.h"

cv_problem *cv_problem_new(int n, double a, double b, cv_status *why) {
  cv_status st = CVAR_OK;
  cv_problem *p = NULL;
  /* !(a < b) also rejects NaN ends. */
  if (n < 1 || !isfinite(a) || !isfinite(b) || !(a < b)) {
    st = CVAR_EINVAL;
    goto cleanup;
  }
  p = cv_calloc(1, sizeof *p);
  if (!p) {
    st = CVAR_ENOMEM;
    goto cleanup;
  }
  p->n = n;
  p->a = a;
  p->b = b;
  p->fixed = cv_malloc(2 * (size_t)n * sizeof *p->fixed);
  p->endval = cv_calloc(2 * (size_t)n, sizeof *p->endval);
  if (!p->fixed || !p->endval) {
    st = CVAR_ENOMEM;
    cv_problem_free(p);
    p = NULL;
    goto cleanup;
  }
  for (int k = 0; k < 2 * n; k++) p->fixed[k] = 1;
cleanup:
  if (why) *why = st;
  return p;
}

static void release_integrand(cv_problem *p) {
  int kept = 0; /* the integrand's notes go with it */
  for (int k = 0; k < p->nnotes; k++)
    if (!p->user || p->notes[k].user != p->user) p->notes[kept++] = p->notes[k];
  p->nnotes = kept;
  if (p->smooth_user == p->user) p->smooth = NULL, p->smooth_user = NULL, p->nsmooth = 0;
  if (p->release) p->release(p->user);
  p->release = NULL;
  p->user = NULL;
  p->F = NULL;
}

void cv_problem_free(cv_problem *p) {
  if (!p) return;
  release_integrand(p);
  cv_problem_ends_release(p);
  for (int k = 0; k < p->nc; k++)
    if (p->pc[k].release) p->pc[k].release(p->pc[k].user);
  for (int k = 0; k < p->ni; k++)
    if (p->ic[k].release) p->ic[k].release(p->ic[k].user);
  for (int k = 0; k < p->ntables; k++) {
    cv_free(p->table_name[k]);
    cv_table_free(p->table[k]);
  }
  cv_free(p->notes);
  cv_free(p->table_name);
  cv_free(p->table);
  cv_free(p->pc);
  cv_free(p->ic);
  cv_free(p->fixed);
  cv_free(p->endval);
  cv_problem_order2_free(p);
  cv_free(p);
}

cv_status cv_problem_set_integrand_owned(cv_problem *p, cv_integrand_fn F, void *user,
                                         cv_release_fn release) {
  if (!p || !F) {
    if (release) release(user);
    return CVAR_EINVAL;
  }
  release_integrand(p);
  p->F = F;
  p->user = user;
  p->release = release;
  return CVAR_OK;
}

cv_status cv_problem_set_integrand(cv_problem *p, cv_integrand_fn F, void *user) {
  return cv_problem_set_integrand_owned(p, F, user, NULL);
}

cv_status cv_problem_set_end_value(cv_problem *p, int k, int end, double value) {
  if (!p || k < 0 || k >= p->n || (end != 0 && end != 1) || !isfinite(value)) return CVAR_EINVAL;
  p->fixed[2 * k + end] = 1;
  p->endval[2 * k + end] = value;
  return CVAR_OK;
}

cv_status cv_problem_set_dirichlet(cv_problem *p, int k, double ya, double yb) {
  if (!p || !isfinite(ya) || !isfinite(yb)) return CVAR_EINVAL;
  cv_status st = cv_problem_set_end_value(p, k, 0, ya);
  return st ? st : cv_problem_set_end_value(p, k, 1, yb);
}

cv_status cv_problem_set_free_end(cv_problem *p, int k, int end) {
  if (!p || k < 0 || k >= p->n || (end != 0 && end != 1)) return CVAR_EINVAL;
  p->fixed[2 * k + end] = 0;
  p->endval[2 * k + end] = 0.0;
  return CVAR_OK;
}

cv_status cv_problem_set_guess(cv_problem *p, cv_guess_fn g, void *user) {
  if (!p) return CVAR_EINVAL;
  p->guess = g;
  p->guess_user = g ? user : NULL;
  return CVAR_OK;
}

int cv_problem_get_num_unknowns(const cv_problem *p) { return p ? p->n : 0; }

void cv_problem_get_interval(const cv_problem *p, double *a, double *b) {
  if (!p) return;
  if (a) *a = p->a;
  if (b) *b = p->b;
}

cv_status cv_problem_add_constraint_owned(cv_problem *p, cv_constraint_fn G, void *user,
                                          cv_release_fn release, int *index) {
  cv_pconstraint *grown;
  if (!p || !G) {
    if (release) release(user);
    return CVAR_EINVAL;
  }
  grown = cv_malloc((size_t)(p->nc + 1) * sizeof *grown);
  if (!grown) {
    if (release) release(user);
    return CVAR_ENOMEM;
  }
  for (int k = 0; k < p->nc; k++) grown[k] = p->pc[k];
  grown[p->nc] = (cv_pconstraint){G, user, release, 0};
  cv_free(p->pc);
  p->pc = grown;
  if (index) *index = p->nc;
  p->nc++;
  return CVAR_OK;
}

cv_status cv_problem_add_constraint(cv_problem *p, cv_constraint_fn G, void *user, int *index) {
  return cv_problem_add_constraint_owned(p, G, user, NULL, index);
}

cv_status cv_problem_add_integral_owned(cv_problem *p, cv_integrand_fn K, void *user,
                                        cv_release_fn release, double c, int *index) {
  cv_iconstraint *grown;
  if (!p || !K || !isfinite(c)) {
    if (release) release(user);
    return CVAR_EINVAL;
  }
  grown = cv_malloc((size_t)(p->ni + 1) * sizeof *grown);
  if (!grown) {
    if (release) release(user);
    return CVAR_ENOMEM;
  }
  for (int k = 0; k < p->ni; k++) grown[k] = p->ic[k];
  grown[p->ni] = (cv_iconstraint){K, user, release, c};
  cv_free(p->ic);
  p->ic = grown;
  if (index) *index = p->ni;
  p->ni++;
  return CVAR_OK;
}

cv_status cv_problem_add_integral(cv_problem *p, cv_integrand_fn K, void *user, double c,
                                  int *index) {
  return cv_problem_add_integral_owned(p, K, user, NULL, c, index);
}

int cv_problem_get_num_constraints(const cv_problem *p) { return p ? p->nc : 0; }

cv_status cv_problem_set_constraint_sense(cv_problem *p, int k, int sense) {
  if (!p || k < 0 || k >= p->nc || sense < -1 || sense > 1) return CVAR_EINVAL;
  p->pc[k].sense = sense;
  return CVAR_OK;
}

int cv_problem_get_constraint_sense(const cv_problem *p, int k) {
  return p && k >= 0 && k < p->nc ? p->pc[k].sense : 0;
}
int cv_problem_get_num_integrals(const cv_problem *p) { return p ? p->ni : 0; }

cv_status cv_problem_add_note(cv_problem *p, cv_note_fn fn, void *user) {
  if (!p || !fn) return CVAR_EINVAL;
  cv_note_source *grown = cv_realloc(p->notes, ((size_t)p->nnotes + 1) * sizeof *grown);
  if (!grown) return CVAR_ENOMEM;
  p->notes = grown;
  p->notes[p->nnotes++] = (cv_note_source){fn, user};
  return CVAR_OK;
}

cv_status cv_problem_set_smoothing(cv_problem *p, cv_smooth_fn fn, void *user, int count) {
  if (!p || !fn || !user || user != p->user || count < 1) return CVAR_EINVAL;
  p->smooth = fn, p->smooth_user = user, p->nsmooth = count;
  return CVAR_OK;
}

cv_status cv_problem_add_table(cv_problem *p, const char *name, cv_table *t) {
  if (!p || !name || !t || !(isalpha((unsigned char)name[0]) || name[0] == '_')) return CVAR_EINVAL;
  for (const char *q = name; *q; q++)
    if (!(isalnum((unsigned char)*q) || *q == '_')) return CVAR_EINVAL;
  for (int k = 0; k < p->ntables; k++)
    if (strcmp(p->table_name[k], name) == 0) return CVAR_EINVAL;
  size_t len = strlen(name);
  char *copy = cv_malloc(len + 1);
  char **names = cv_malloc(((size_t)p->ntables + 1) * sizeof *names);
  cv_table **tabs = cv_malloc(((size_t)p->ntables + 1) * sizeof *tabs);
  if (!copy || !names || !tabs) {
    cv_free(copy);
    cv_free(names);
    cv_free(tabs);
    return CVAR_ENOMEM;
  }
  memcpy(copy, name, len + 1);
  if (p->ntables) {
    memcpy(names, p->table_name, (size_t)p->ntables * sizeof *names);
    memcpy(tabs, p->table, (size_t)p->ntables * sizeof *tabs);
  }
  names[p->ntables] = copy;
  tabs[p->ntables] = cv_table_ref(t);
  cv_free(p->table_name);
  cv_free(p->table);
  p->table_name = names;
  p->table = tabs;
  p->ntables++;
  return CVAR_OK;
}

int cv_problem_num_tables(const cv_problem *p) { return p ? p->ntables : 0; }
const char *cv_problem_table_name(const cv_problem *p, int i) {
  return p && i >= 0 && i < p->ntables ? p->table_name[i] : NULL;
}
const cv_table *cv_problem_table(const cv_problem *p, int i) {
  return p && i >= 0 && i < p->ntables ? p->table[i] : NULL;
}
