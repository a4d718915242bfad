/* src/mech/mech_equations.c — momenta, Euler–Lagrange equations, Hamiltonian and
 * conservation laws of an integrand, built symbolically (docs/theory.md part P).
 * SPDX-License-Identifier: MIT */
#include <stdio.h>
#include <string.h>

#include "core/cv_memory.h"
#include "mech/mech.h"

/* Slots of mech.h: 0 = x, 1..n = y, n+1..2n = y', 2n+1..3n = y''. */
static int slot_y(int n, int i) {
  (void)n;
  return 1 + i;
}
static int slot_dy(int n, int i) { return 1 + n + i; }
static int slot_ddy(int n, int i) { return 1 + 2 * n + i; }
/* y''' and y'''' of a second-order Lagrangian (P-14): after the multipliers' slots; 0 (no
 * such slot) for a first-order one, whose expressions never read them. */
static int slot_d3(const mech_problem *s, int i) {
  return s->order2 ? 1 + 3 * s->n + s->ncons + s->nints + i : -1;
}
static int slot_d4(const mech_problem *s, int i) { return s->order2 ? slot_d3(s, i) + s->n : -1; }

static ex_id add(ex_dag *d, ex_id a, ex_id b) {
  return a >= 0 && b >= 0 ? ex_binary(d, EX_ADD, a, b) : -1;
}

static ex_id mul(ex_dag *d, ex_id a, ex_id b) {
  return a >= 0 && b >= 0 ? ex_binary(d, EX_MUL, a, b) : -1;
}

/* d/dx G(x, y, y') along a path, by the chain rule (P-4):
 * G_x + sum_j G_{y_j} y'_j + sum_j G_{y'_j} y''_j (+ G_{y''_j} y'''_j + G_{y'''_j} y''''_j
 * for a second-order Lagrangian, P-14). */
static ex_id total_derivative(ex_dag *d, ex_id G, const mech_problem *s) {
  int n = s->n;
  ex_id r = ex_diff(d, G, 0);
  for (int j = 0; j < n && r >= 0; j++) {
    r = add(d, r, mul(d, ex_diff(d, G, slot_y(n, j)), ex_slot(d, slot_dy(n, j))));
    r = add(d, r, mul(d, ex_diff(d, G, slot_dy(n, j)), ex_slot(d, slot_ddy(n, j))));
    if (!s->order2) continue;
    r = add(d, r, mul(d, ex_diff(d, G, slot_ddy(n, j)), ex_slot(d, slot_d3(s, j))));
    r = add(d, r, mul(d, ex_diff(d, G, slot_d3(s, j)), ex_slot(d, slot_d4(s, j))));
  }
  return r;
}

static char *cat(const char *a, const char *b) {
  size_t la = strlen(a), lb = strlen(b);
  char *s = cv_malloc(la + lb + 1);
  if (s) {
    memcpy(s, a, la);
    memcpy(s + la, b, lb + 1);
  }
  return s;
}

static int make_names(const mech_problem *s, mech_equations *eq) {
  int n = s->n;
  eq->nslots = 1 + 3 * n + s->ncons + s->nints + (s->order2 ? 2 * n : 0);
  if (!(eq->names = cv_calloc((size_t)eq->nslots, sizeof *eq->names))) return -1;
  eq->names[0] = cat(s->variable, "");
  for (int i = 0; i < n; i++) {
    eq->names[slot_y(n, i)] = cat(s->unknowns[i], "");
    eq->names[slot_dy(n, i)] = cat(s->unknowns[i], "'");
    eq->names[slot_ddy(n, i)] = cat(s->unknowns[i], "''");
  }
  for (int c = 0; c < s->ncons; c++) eq->names[1 + 3 * n + c] = cat("lambda_", s->cons_names[c]);
  for (int r = 0; r < s->nints; r++)
    eq->names[1 + 3 * n + s->ncons + r] = cat("mu_", s->int_names[r]);
  for (int i = 0; i < n && s->order2; i++) {
    eq->names[slot_d3(s, i)] = cat(s->unknowns[i], "'''");
    eq->names[slot_d4(s, i)] = cat(s->unknowns[i], "''''");
  }
  for (int k = 0; k < eq->nslots; k++)
    if (!eq->names[k]) return -1;
  return 0;
}

/* Ostrogradsky's first momentum of unknown i (P-14): G_{y'_i} - d/dx G_{y''_i}; G_{y'_i}
 * for a first-order Lagrangian. */
static ex_id momentum_of(ex_dag *d, ex_id G, const mech_problem *s, int i) {
  ex_id p = ex_diff(d, G, slot_dy(s->n, i));
  if (!s->order2 || p < 0) return p;
  ex_id q = ex_diff(d, G, slot_ddy(s->n, i)), dq = q >= 0 ? total_derivative(d, q, s) : -1;
  return dq >= 0 ? ex_binary(d, EX_SUB, p, dq) : -1;
}

/* Euler–Lagrange expression of unknown i for integrand G, in the sign of (P-4):
 * d/dx G_{y'_i} - G_{y_i}; of a second-order one (P-14) d/dx of the first momentum. */
static ex_id el_of(ex_dag *d, ex_id G, const mech_problem *s, int i) {
  ex_id p = momentum_of(d, G, s, i);
  ex_id dp = p >= 0 ? total_derivative(d, p, s) : -1;
  ex_id gy = ex_diff(d, G, slot_y(s->n, i));
  return dp >= 0 && gy >= 0 ? ex_binary(d, EX_SUB, dp, gy) : -1;
}

cv_status mech_equations_new(const mech_problem *s, mech_equations *eq, char *err, size_t errlen) {
  int n = s->n;
  ex_dag *d = s->dag;
  memset(eq, 0, sizeof *eq);
  eq->n = n;
  eq->hamiltonian = -1;
  if (make_names(s, eq) < 0 || !(eq->momentum = cv_malloc((size_t)n * sizeof *eq->momentum)) ||
      !(eq->el = cv_malloc((size_t)n * sizeof *eq->el)) ||
      !(eq->cyclic = cv_malloc((size_t)n * sizeof *eq->cyclic)) ||
      (s->order2 && !(eq->momentum2 = cv_malloc((size_t)n * sizeof *eq->momentum2))))
    goto nomem;
  eq->F = s->F;
  eq->autonomous = !ex_depends_on(d, s->F, 0);
  ex_id H = ex_unary(d, EX_NEG, s->F);
  for (int i = 0; i < n; i++) {
    eq->cyclic[i] = !ex_depends_on(d, s->F, slot_y(n, i));
    ex_id p = momentum_of(d, s->F, s, i);
    H = add(d, H, mul(d, ex_slot(d, slot_dy(n, i)), p));
    if (s->order2) { /* the second momentum q_i = F_y''_i and its term of H (P-14) */
      ex_id q = ex_diff(d, s->F, slot_ddy(n, i));
      H = add(d, H, mul(d, ex_slot(d, slot_ddy(n, i)), q));
      if (q < 0 || (eq->momentum2[i] = ex_collect(d, q)) < 0) goto nomem;
    }
    ex_id E = el_of(d, s->F, s, i);
    /* Multipliers (P-8): L + sum_c lambda_c G_c + sum_r mu_r K_r. */
    for (int c = 0; c < s->ncons && E >= 0; c++) {
      ex_id gy = ex_diff(d, s->cons[c], slot_y(n, i));
      E = gy >= 0 ? ex_binary(d, EX_SUB, E, mul(d, ex_slot(d, 1 + 3 * n + c), gy)) : -1;
    }
    for (int r = 0; r < s->nints && E >= 0; r++) {
      ex_id ek = el_of(d, s->ints[r], s, i);
      E = add(d, E, mul(d, ex_slot(d, 1 + 3 * n + s->ncons + r), ek));
    }
    if (p < 0 || E < 0 || (p = ex_collect(d, p)) < 0 || (E = ex_collect(d, E)) < 0) goto nomem;
    /* Sign: a positive constant coefficient of y_i'' (y_i'''' for a second-order
     * Lagrangian) when it is a negative constant. */
    ex_id c = ex_diff(d, E, s->order2 ? slot_d4(s, i) : slot_ddy(n, i));
    double cv;
    if (c < 0) goto nomem;
    if (ex_eval_const(d, c, &cv) == 0 && cv < 0 && (E = ex_unary(d, EX_NEG, E)) < 0) goto nomem;
    eq->momentum[i] = p;
    eq->el[i] = E;
  }
  if (H < 0 || (eq->hamiltonian = ex_collect(d, H)) < 0) goto nomem;
  return CVAR_OK;
nomem:
  if (err && errlen) snprintf(err, errlen, "out of memory while building the equations");
  mech_equations_free(eq);
  return CVAR_ENOMEM;
}

void mech_equations_free(mech_equations *eq) {
  if (!eq) return;
  if (eq->names)
    for (int k = 0; k < eq->nslots; k++) cv_free(eq->names[k]);
  cv_free(eq->names);
  cv_free(eq->momentum);
  cv_free(eq->el);
  cv_free(eq->cyclic);
  cv_free(eq->momentum2);
  memset(eq, 0, sizeof *eq);
  eq->hamiltonian = -1;
}
