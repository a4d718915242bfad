/* src/scene/scene_ends.c — the [ends] section: a free end of the interval, or an end point
 * on a curve G(x, y) = 0 (docs/scenes.md, theory ME-1 .. ME-3), and its curve as the core's
 * callback.
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <string.h>

#include "core/cv_ends.h"
#include "scene/scene_internal.h"

int sc_load_ends(sc_loader *L);

/* The curve of one end as the core's cv_end_curve_fn. */
typedef struct {
  const scene *s;
  int end;
} end_curve;

static int end_curve_eval(double x, const double *y, double *G, double *Gx, double *Gy,
                          void *user) {
  const end_curve *c = user;
  const scene *s = c->s;
  const sc_end *e = &s->ends[c->end];
  int n = s->n;
  ex_id *outs = cv_malloc((size_t)(n + 2) * sizeof *outs);
  double *out = cv_malloc((size_t)(n + 2) * sizeof *out);
  int rc = -1;
  if (outs && out) {
    outs[0] = e->G, outs[1] = e->Gx;
    for (int i = 0; i < n; i++) outs[2 + i] = e->Gy[i];
    if (sc_eval_exprs(s, n + 2, outs, 1, &x, y, NULL, out) == 0) {
      *G = out[0], *Gx = out[1];
      for (int i = 0; i < n; i++) Gy[i] = out[2 + i];
      rc = 0;
    }
  }
  cv_free(outs);
  cv_free(out);
  return rc;
}

static void release_curve(void *user) { cv_free(user); }

int scene_has_moving_end(const scene *s) { return s && (s->ends[0].kind || s->ends[1].kind); }

int scene_problem_set_ends(const scene *s, cv_problem *p, char *err, size_t errlen) {
  for (int end = 0; end < 2; end++) {
    const sc_end *e = &s->ends[end];
    cv_status st = CVAR_OK;
    if (e->kind == 1) {
      st = cv_problem_set_end_free(p, end);
    } else if (e->kind == 2) {
      end_curve *c = cv_malloc(sizeof *c);
      if (!c) {
        st = CVAR_ENOMEM;
      } else {
        c->s = s, c->end = end;
        st = cv_problem_set_end_curve_owned(p, end, end_curve_eval, c, release_curve);
      }
    }
    if (st != CVAR_OK) {
      sc_err(err, errlen, s->file, e->line, "[ends] %s: %s", end ? "end" : "start",
             cv_strerror(st));
      return -1;
    }
  }
  return 0;
}

/* The names of the unknowns left free at `end` on which G depends: their number, the first
 * in *k (-1 when none) and a list for messages. */
static int curve_movers(const scene *s, ex_id G, int end, int *k, char *names, size_t len) {
  int count = 0;
  *k = -1;
  names[0] = '\0';
  for (int i = 0; i < s->n; i++)
    if (s->bc[i].free_end[end] && ex_depends_on(s->dag, G, 1 + i)) {
      size_t used = strlen(names);
      snprintf(names + used, len - used, "%s%s", count ? ", " : "", s->unknowns[i]);
      if (count++ == 0) *k = i;
    }
  return count;
}

/* The start's end point must reach the curve nearby (SCENES.md): its projection onto
 * G = 0 (the core's, ME-3) from the fixed end values and the guess, within the interval's
 * length, and inside the interval. */
static int check_meets(sc_loader *L, const sc_entry *en, int end, int k) {
  scene *s = L->s;
  int n = s->n, rc = -1;
  double x = end ? s->b : s->a, *y = cv_malloc((size_t)n * sizeof *y);
  char msg[400];
  end_curve c = {s, end};
  if (!y || scene_eval_guess(s, 1, &x, y) < 0) {
    cv_free(y);
    sc_err(L->err, L->errlen, L->file, en->line, "out of memory");
    return -1;
  }
  for (int i = 0; i < n; i++)
    if (!s->bc[i].free_end[end]) y[i] = s->bc[i].value[end];
  if (cv_ends_project(end_curve_eval, &c, n, k, &x, y, s->b - s->a, msg, sizeof msg) != CVAR_OK)
    sc_err(L->err, L->errlen, L->file, en->line, "[ends] %s: %s", en->key, msg);
  else if (end ? !(x > s->a) : !(x < s->b))
    sc_err(L->err, L->errlen, L->file, en->line,
           "[ends] %s: the curve meets the start's end region at %s = %.6g, beyond the other "
           "end of the interval",
           en->key, s->variable, x);
  else
    rc = 0;
  cv_free(y);
  return rc;
}

/* One `start = ...` or `end = ...` line. */
static int load_end(sc_loader *L, const sc_entry *en, int end) {
  scene *s = L->s;
  sc_end *e = &s->ends[end];
  char nb[128], names[256];
  e->line = en->line;
  if (strcmp(en->value, "free") == 0) {
    e->kind = 1;
    return 0;
  }
  char what[64];
  snprintf(what, sizeof what, "[ends] %s", en->key);
  if ((e->G = sc_parse(L, en, 0, en->value, what)) < 0) return -1;
  int slot = sc_first_slot(s, e->G, 1 + s->n, 2 * s->n);
  if (slot >= 0) {
    sc_err(L->err, L->errlen, L->file, en->line,
           "[ends] %s is a curve G(%s, y) and may not use '%s' (or write 'free')", en->key,
           s->variable, sc_slot_name(s, slot, nb, sizeof nb));
    return -1;
  }
  int k, count = curve_movers(s, e->G, end, &k, names, sizeof names);
  if (count > 1) {
    sc_err(L->err, L->errlen, L->file, en->line,
           "[ends] %s: the curve involves %d end values left free at %s (%s); at most one "
           "may move along it: fix the others in [boundary]",
           en->key, count, end ? "b" : "a", names);
    return -1;
  }
  if (count == 0 && !ex_depends_on(s->dag, e->G, 0)) {
    sc_err(L->err, L->errlen, L->file, en->line,
           "[ends] %s: the curve involves neither %s nor an end value left free at %s, so "
           "nothing can move along it (write 'free' in [boundary] for the value that moves "
           "with the end)",
           en->key, s->variable, end ? "b" : "a");
    return -1;
  }
  e->kind = 2;
  e->Gy = cv_malloc((size_t)s->n * sizeof *e->Gy);
  if (!e->Gy || (e->Gx = ex_diff(s->dag, e->G, 0)) < 0) {
    sc_err(L->err, L->errlen, L->file, en->line, "out of memory");
    return -1;
  }
  for (int i = 0; i < s->n; i++)
    if ((e->Gy[i] = ex_diff(s->dag, e->G, 1 + i)) < 0) {
      sc_err(L->err, L->errlen, L->file, en->line, "out of memory");
      return -1;
    }
  return check_meets(L, en, end, k);
}

int sc_load_ends(sc_loader *L) {
  static const char *const keys[] = {"start", "end", NULL};
  scene *s = L->s;
  for (int end = 0; end < 2; end++) s->ends[end].G = s->ends[end].Gx = -1;
  if (sc_check_keys(L, SEC_ENDS, keys, "start, end") < 0) return -1;
  int seen[2] = {0, 0};
  for (int i = 0; i < L->raw.ne[SEC_ENDS]; i++) {
    const sc_entry *en = &L->raw.e[SEC_ENDS][i];
    int end = strcmp(en->key, "end") == 0;
    if (seen[end]) {
      sc_err(L->err, L->errlen, L->file, en->line,
             "[ends] has a second '%s' line (first on line %d)", en->key, seen[end]);
      return -1;
    }
    seen[end] = en->line;
    if (s->ncons > 0) {
      sc_err(L->err, L->errlen, L->file, en->line,
             "[ends] %s: a moving end with [constraints] is not supported", en->key);
      return -1;
    }
    if (load_end(L, en, end) < 0) return -1;
  }
  return 0;
}
