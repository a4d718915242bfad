/* src/core/cv_kkt_active.c — inequality constraints (obstacles): the primal-dual active set
 * rule that decides, at every Newton evaluation, which rows of the KKT system impose
 * G = 0 and which impose lambda = 0, theory (OB-1), (OB-2).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

int cv_kkt_has_inequalities(const cv_problem *p) {
  for (int k = 0; k < p->nc; k++)
    if (p->pc[k].sense) return 1;
  return 0;
}

/* One decision and one weight per node and constraint; the weights start unknown (NaN)
 * and are set from the first Hessian (cv_kkt_eval). Nothing starts active: the first
 * evaluation, with lambda = 0, makes active exactly the nodes where G is violated. */
cv_status cv_kkt_active_init(cv_kkt *k) {
  size_t m = (size_t)k->d->nodes * (size_t)k->d->nc;
  k->active = cv_calloc(m ? m : 1, 1);
  k->cw = cv_malloc((m ? m : 1) * sizeof *k->cw);
  k->chg = cv_malloc((m ? m : 1) * sizeof *k->chg);
  k->chgcap = (long)m;
  if (!k->active || !k->cw || !k->chg) return CVAR_ENOMEM;
  for (size_t i = 0; i < m; i++) k->cw[i] = NAN;
  return CVAR_OK;
}

/* OB-2: with the constraint written as s G >= 0 (s = sense) and the multiplier of the
 * Lagrangian F + lambda G, the complementarity conditions s G >= 0, s lambda <= 0,
 * lambda G = 0 are min(c s G, -s lambda) = 0. The row imposes whichever of the two
 * arguments is the smaller: c s G (the constraint, active) or -s lambda (inactive).
 * OB-2b: a node where both are zero to round-off (inside a contact arc of a second-order
 * problem, where the path lies on the obstacle with no load) would flip at every step on
 * the sign of its round-off, and the iteration would never settle; so a node changes side
 * only when the quantity that moves it is beyond its margin: an active node is released
 * when -s lambda < -tl, an inactive one taken when s G < -tg (was: the node's side now). */
int cv_kkt_active_rule(int sense, double g, double lam, double c, double eps, int was, double tg,
                       double tl) {
  if (eps > 0) return sense * g < (was ? tg : -tg); /* OB-3: the penalty acts where G is violated */
  double v = -sense * lam - c * sense * g;
  return was ? v > -tl : v > c * tg;
}

/* An inactive node's multiplier row: -m_j lambda = 0 on the diagonal -m_j (a negative pivot,
 * as an active row's), no coupling to the y unknowns (their rows see lambda = 0). */
void cv_kkt_inactive_row(cv_kkt *k, long node, int kc, int row, double lam, double *G, double *Ax,
                         double *dreg) {
  (void)node, (void)kc;
  double mj = k->d->mass[row];
  G[row] = -mj * lam;
  if (Ax) {
    const int *cp = k->colptr;
    Ax[cp[row + 1] - 1] = -mj;
  }
  if (dreg) dreg[row] = 0.0;
}
