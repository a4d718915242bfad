/* src/scene/scene_parse.c — expressions in scene values: lists, name resolution, messages.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

#ifndef M_PI
#define M_PI 3.14159265358979323846
#endif

/* The name of a slot for messages: the variable, y or y'. */
const char *sc_slot_name(const scene *s, int slot, char *buf, size_t cap) {
  if (slot == 0)
    snprintf(buf, cap, "%s", s->variable);
  else if (slot <= s->n)
    snprintf(buf, cap, "%s", s->unknowns[slot - 1]);
  else if (slot >= sc_d2_slot(s, 0) && slot < sc_d2_slot(s, s->n))
    snprintf(buf, cap, "%s''", s->unknowns[slot - sc_d2_slot(s, 0)]);
  else
    snprintf(buf, cap, "%s'", s->unknowns[slot - 1 - s->n]);
  return buf;
}

/* First slot in [from, to] that e depends on, or -1. */
int sc_first_slot(const scene *s, ex_id e, int from, int to) {
  return ex_first_slot(s->dag, e, from, to);
}

/* A hint for a name that resolves to nothing: a derivative written without its prime (yp,
 * yprime, ydot, y_x, dy, dydx: y'), or the nearest name usable here (ex_name_close: one or
 * two typing slips); "" when there is none. */
static void suggest(const sc_loader *L, const char *name, char *out, size_t cap) {
  static const char *const suffix[] = {"p", "prime", "dot", "_x", NULL};
  const scene *s = L->s;
  size_t ln = strlen(name);
  out[0] = '\0';
  for (int i = 0; i < s->n; i++) {
    const char *u = s->unknowns[i];
    size_t lu = strlen(u);
    int deriv =
        name[0] == 'd' && (strcmp(name + 1, u) == 0 ||
                           (ln == lu + 3 && strncmp(name + 1, u, lu) == 0 && name[lu + 1] == 'd' &&
                            strcmp(name + lu + 2, s->variable) == 0));
    for (int k = 0; suffix[k] && !deriv; k++)
      deriv = ln > lu && strncmp(name, u, lu) == 0 && strcmp(name + lu, suffix[k]) == 0;
    if (deriv) {
      snprintf(out, cap, " (did you mean %s'? a derivative is written with a prime)", u);
      return;
    }
  }
  ex_nearest nr = {NULL, 0};
  ex_name_consider(&nr, name, s->variable);
  ex_name_consider(&nr, name, "pi");
  for (int i = 0; i < s->n; i++) ex_name_consider(&nr, name, s->unknowns[i]);
  for (int i = 0; i < s->nparams && (L->mode != SC_R_PARAM || i < L->limit); i++)
    ex_name_consider(&nr, name, s->params[i].name);
  for (int i = 0; L->mode != SC_R_PARAM && i < s->ndefs && i < L->limit; i++)
    ex_name_consider(&nr, name, s->defs[i].name);
  if (nr.best) snprintf(out, cap, " (did you mean '%s'?)", nr.best);
}

/* Resolve a name for ex_parse. Parameters become their numbers and definitions their
 * nodes, so both are substituted where named (SCENES.md [definitions]). */
static ex_id resolve(ex_dag *d, const char *name, int primes, void *user, char *err,
                     size_t errlen) {
  sc_loader *L = user;
  scene *s = L->s;
  int i;

  if (strcmp(name, "pi") == 0 && primes == 0) return ex_num(d, M_PI);
  if ((i = sc_name_find(L, name, SC_NAME_PARAMETER)) >= 0) {
    if (L->mode == SC_R_PARAM && i >= L->limit) {
      snprintf(err, errlen,
               i == L->limit ? "parameter '%s' refers to itself"
                             : "parameter '%s' is used before it is defined "
                               "(line %d)",
               name, s->params[i].line);
      return -1;
    }
    if (primes) {
      snprintf(err, errlen, "a prime is only allowed on an unknown, not on '%s'", name);
      return -1;
    }
    if (s->params_as_inputs) {
      ex_id r = ex_slot(d, 1 + 2 * s->n + i); /* an input of the tape, not a number */
      if (r < 0) snprintf(err, errlen, "out of memory");
      return r;
    }
    return ex_num(d, s->params[i].value);
  }
  char hint[160]; /* computed only for a name that fails: the distances cost */
  if (L->mode == SC_R_PARAM) {
    suggest(L, name, hint, sizeof hint);
    snprintf(err, errlen,
             "unknown name '%s' (a parameter may use only numbers, pi and "
             "earlier parameters)%s",
             name, hint);
    return -1;
  }
  if ((i = sc_name_find(L, name, SC_NAME_DEFINITION)) >= 0) {
    if (i >= L->limit) {
      snprintf(err, errlen,
               i == L->limit ? "definition '%s' refers to itself"
                             : "definition '%s' is used before it is defined "
                               "(line %d)",
               name, s->defs[i].line);
      return -1;
    }
    if (primes) {
      snprintf(err, errlen, "a prime is only allowed on an unknown, not on '%s'", name);
      return -1;
    }
    return s->defs[i].expr;
  }
  if (strcmp(name, s->variable) == 0) {
    if (primes) {
      snprintf(err, errlen,
               "a prime is only allowed on an unknown, not on the variable "
               "'%s'",
               name);
      return -1;
    }
    return ex_slot(d, 0);
  }
  if ((i = sc_name_find(L, name, SC_NAME_UNKNOWN)) >= 0) {
    if (primes > 1 && !L->second) {
      snprintf(err, errlen,
               "%s'': a second derivative may appear only in the integrand, [definitions], "
               "[integrals] and [report]",
               name);
      return -1;
    }
    if (primes == 2) return ex_slot(d, sc_d2_slot(s, i));
    return ex_slot(d, primes ? 1 + s->n + i : 1 + i);
  }
  suggest(L, name, hint, sizeof hint);
  snprintf(err, errlen, "unknown name '%s'%s", name, hint);
  return -1;
}

/* Parse text, which starts at offset off of entry e's value. On failure the message
 * points at the physical line (and column) of the offending character. */
ex_id sc_parse(sc_loader *L, const sc_entry *e, int off, const char *text, const char *what) {
  char msg[400] = "";
  int line, col;
  if (text[0] == '\0') {
    sc_entry_locate(e, off, &line, &col);
    sc_err(L->err, L->errlen, L->file, line, "%s: a value is missing", what);
    return -1;
  }
  /* y'' where a second-order integrand may have it (SCENES.md): the integrand, definitions,
   * integrals and reports, named by the callers' `what` */
  L->second = strcmp(what, "integrand") == 0 || strncmp(what, "definition '", 12) == 0 ||
              strncmp(what, "[integrals] ", 12) == 0 || strncmp(what, "[report]", 8) == 0;
  ex_id r = ex_parse(L->s->dag, text, resolve, L, 1, msg, sizeof msg);
  if (r >= 0) {
    /* A constant that is not finite (0/0, log(0), sqrt(-1)*0) is bad input, never a NaN
     * carried into the solve (theory (EX-1)). */
    ex_id bad = ex_nonfinite_const(L->s->dag, r);
    if (bad == -1) return r;
    char sub[160] = "?";
    double v = NAN;
    if (bad >= 0) {
      ex_print(L->s->dag, bad, NULL, sub, sizeof sub);
      ex_eval_const(L->s->dag, bad, &v);
    }
    sc_entry_locate(e, off, &line, &col);
    if (bad == -2)
      sc_err(L->err, L->errlen, L->file, line, "%s: out of memory", what);
    else
      sc_err(L->err, L->errlen, L->file, line,
             "%s: the constant '%s' is not a finite number "
             "(%s)",
             what, sub,
             isnan(v) ? "NaN"
             : v > 0  ? "+inf"
                      : "-inf");
    return -1;
  }
  int c = 0, k = 0;
  if (sscanf(msg, "column %d: %n", &c, &k) >= 1 && k > 0 && c >= 1) {
    sc_entry_locate(e, off + c - 1, &line, &col);
    sc_err(L->err, L->errlen, L->file, line, "%s, column %d: %s", what, col, msg + k);
  } else {
    sc_entry_locate(e, off, &line, &col);
    sc_err(L->err, L->errlen, L->file, line, "%s: %s", what, msg[0] ? msg : "out of memory");
  }
  return -1;
}

/* A constant expression (numbers, pi, parameters, definitions built from those), which
 * must be finite. Returns 0, or -1 with a message. */
static double param_slot(void *user, int slot) {
  const scene *s = user;
  int i = slot - 1 - 2 * s->n;
  return i >= 0 && i < s->nparams ? s->params[i].value : 0.0;
}

int sc_eval_params(const scene *s, ex_id e, double *value) {
  return ex_eval_with(s->dag, e, NULL, param_slot, (void *)s, value);
}

int sc_parse_const(sc_loader *L, const sc_entry *e, int off, const char *text, const char *what,
                   double *value) {
  ex_id node;
  if (sc_parse_const_node(L, e, off, text, what, value, &node) < 0) return -1;
  /* A [mesh] or [solver] number: kept as a number even when it uses parameters (the
   * batch refuses such a scene when a row sets one, docs/cli.md). */
  if (L->s->params_as_inputs && !L->s->settings_line &&
      sc_first_slot(L->s, node, 1 + 2 * L->s->n, 2 * L->s->n + L->s->nparams) >= 0)
    L->s->settings_line = e->line ? e->line : -1;
  return 0;
}

int sc_parse_const_node(sc_loader *L, const sc_entry *e, int off, const char *text,
                        const char *what, double *value, ex_id *node) {
  char nb[128];
  int line, col;
  ex_id r = sc_parse(L, e, off, text, what);
  if (node) *node = -1;
  if (r < 0) return -1;
  sc_entry_locate(e, off, &line, &col);
  int slot = sc_first_slot(L->s, r, 0, 2 * L->s->n), k2;
  if (slot < 0 && sc_uses_second(L->s, r, &k2)) slot = sc_d2_slot(L->s, k2);
  int bad = slot >= 0;
  if (!bad && L->s->params_as_inputs) {
    if (sc_eval_params(L->s, r, value) < 0) {
      sc_err(L->err, L->errlen, L->file, line, "out of memory");
      return -1;
    }
  } else if (!bad) {
    bad = ex_eval_const(L->s->dag, r, value) != 0;
  }
  if (bad) {
    sc_err(L->err, L->errlen, L->file, line,
           "%s must be a constant expression, but '%s' depends on '%s'", what, text,
           slot >= 0 ? sc_slot_name(L->s, slot, nb, sizeof nb) : "?");
    return -1;
  }
  if (!isfinite(*value)) {
    sc_err(L->err, L->errlen, L->file, line, "%s '%s' is not a finite number (%s)", what, text,
           isnan(*value) ? "NaN"
           : *value > 0  ? "+inf"
                         : "-inf");
    return -1;
  }
  if (node) *node = r;
  return 0;
}
