/* src/core/cv_kkt.c — the stationarity system of the discrete Lagrangian: the action plus
 * pointwise constraints at the nodes and integral constraints, with its gradient and
 * (quasi-definite) Hessian, theory (C-1)-(C-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_internal.h"

/* Pointwise constraints act on the values of the problem's unknowns at the nodes: with C^1
 * elements (theory H-2) a node holds a value and a slope per unknown, and the constraint
 * sees the values (the unknowns of the problem are half the disc's components). */
static inline int cn_of(const cv_disc *d) { return d->herm ? d->n / 2 : d->n; }
static inline long vdof(const cv_disc *d, long node, int i) {
  return node * d->n + (d->herm ? 2 * i : i);
}

cv_status cv_kkt_init(cv_kkt *k, const cv_problem *p, const cv_disc *d, const int *colptr) {
  size_t n = (size_t)d->n, B = CV_BATCH;
  memset(k, 0, sizeof *k);
  k->prob = p;
  k->d = d;
  k->colptr = colptr;
  cv_status st = cv_assembler_init(&k->as, p, d);
  if (st) return st;
  if (p->nc > 0) {
    k->xn = cv_malloc((size_t)d->nodes * sizeof *k->xn);
    k->cbuf = cv_malloc((2 + 2 * n + n * n) * B * sizeof *k->cbuf);
    if (!k->xn || !k->cbuf) return CVAR_ENOMEM;
    cv_disc_fill_nodes(d, k->xn);
  }
  if (p->ni > 0) {
    k->gK = cv_malloc((size_t)d->nfree * sizeof *k->gK);
    if (!k->gK) return CVAR_ENOMEM;
  }
  k->all_ineq = 1;
  for (int kc = 0; kc < p->nc; kc++) k->all_ineq &= p->pc[kc].sense != 0;
  if (cv_kkt_has_inequalities(p)) return cv_kkt_active_init(k);
  return CVAR_OK;
}

void cv_kkt_free(cv_kkt *k) {
  cv_assembler_free(&k->as);
  cv_free(k->xn);
  cv_free(k->cbuf);
  cv_free(k->gK);
  cv_free(k->active);
  cv_free(k->cw);
  cv_free(k->chg);
}

/* Position of entry (r, c), r <= c, in the upper-triangle column layout (E-2). */
static inline long pos(const int *colptr, long r, long c) {
  return colptr[c] + r - (c + 1 - (colptr[c + 1] - colptr[c]));
}

/* Evaluate pointwise constraint kc at nodes j0 .. j0+m-1 into the batch buffers. */
static cv_status eval_constraint(cv_kkt *k, int kc, const double *Y, long j0, int m, unsigned need,
                                 double **G, double **Gy, double **Gyy) {
  const cv_disc *d = k->d;
  int n = cn_of(d);
  double *x = k->cbuf, *y = x + CV_BATCH, *g = y + (size_t)n * CV_BATCH;
  double *gy = g + CV_BATCH, *gyy = gy + (size_t)n * CV_BATCH;
  for (int t = 0; t < m; t++) {
    x[t] = k->xn[j0 + t];
    for (int i = 0; i < n; i++) y[i * m + t] = Y[vdof(d, j0 + t, i)];
  }
  const cv_pconstraint *c = &k->prob->pc[kc];
  int rc = c->G(m, x, y, need, g, (need & CVAR_NEED_GRAD) ? gy : NULL,
                (need & CVAR_NEED_HESS) ? gyy : NULL, c->user);
  if (rc < 0) return CVAR_ECALLBACK;
  if (rc > 0) return CVAR_ENONFINITE;
  *G = g;
  *Gy = gy;
  *Gyy = gyy;
  return CVAR_OK;
}

cv_status cv_kkt_check_ends(cv_kkt *k, const double *Y, char *msg, size_t len) {
  const cv_disc *d = k->d;
  int n = cn_of(d);
  for (int end = 0; end < 2; end++) {
    long node = end ? d->nodes - 1 : 0;
    if (cv_disc_lidx(d, node, 0) >= 0) continue; /* has multipliers: imposed by Newton */
    for (int kc = 0; kc < d->nc; kc++) {
      double *G, *Gy, *Gyy;
      cv_status st =
          eval_constraint(k, kc, Y, node, 1, CVAR_NEED_F | CVAR_NEED_GRAD, &G, &Gy, &Gyy);
      /* Scale of G near the end values: |grad G| |y| (or 1), so the test is relative. */
      double sc = 0.0;
      for (int i = 0; i < n && !st; i++) sc += fabs(Gy[i]) * fabs(Y[vdof(d, node, i)]);
      int sense = k->prob->pc[kc].sense;
      double viol = sense ? cv_fmax(0.0, -sense * (st ? NAN : G[0])) : fabs(st ? NAN : G[0]);
      if (st || !(viol <= 1e-9 * cv_fmax(1.0, sc))) {
        cv_set_msg(msg, len,
                   "pointwise constraint %d does not hold at the fixed end x = %g (G = %.3g); "
                   "choose end values that satisfy it",
                   kc, k->xn[node], st ? NAN : G[0]);
        return CVAR_EINVAL;
      }
    }
  }
  return CVAR_OK;
}

/* The active-set decision of inequality kc at a node (OB-2). Its weight
 * c = h m_j / (|grad G|^4 (b - a)^2), h the Hessian's diagonal along grad G, is set at the first evaluation with a Hessian (Ax: the
 * action's part is assembled, the constraints' not yet) and kept for the run, so that
 * every evaluation of one Newton run decides by the same rule. */
static int decide(cv_kkt *k, const double *Ax, long node, int kc, int sense, double g,
                  const double *gy, int m, double lam) {
  const cv_disc *d = k->d;
  size_t at = (size_t)node * d->nc + kc;
  if (k->frozen) return k->active[at];
  double c = k->cw[at];
  if (isnan(c)) {
    double hd = 0.0, g2 = 0.0;
    for (int i = 0; i < cn_of(d) && Ax; i++) {
      int fi = cv_disc_fidx(d, vdof(d, node, i));
      double gi = gy[(size_t)i * m];
      if (fi < 0) continue;
      hd += fabs(Ax[k->colptr[fi + 1] - 1]) * gi * gi;
      g2 += gi * gi;
    }
    double mj = d->mass[cv_disc_lidx(d, node, kc)];
    /* the node's stiffness along grad G, hd / m_j ~ F_y'y' / h^2, brought to the scale of
     * the whole interval, F_y'y' / (b - a)^2: the penalty of OB-3 at eps = 1 is then as soft
     * as the path is stiff on the whole interval, on any mesh */
    double L = d->b - d->a, r = mj / L; /* a second-order integrand (C^1 elements): the
                                         * diagonal is F_y''y'' / h^3, the interval's
                                         * stiffness F_y''y'' / (b - a)^4 */
    c = g2 > 0 && hd > 0 ? hd * mj / (g2 * g2 * L * L) * (d->herm ? r * r : 1.0) : 1.0;
    if (Ax) k->cw[at] = c;
  }
  int a = cv_kkt_active_rule(sense, g, lam, c, k->eps, k->active[at], k->tg, k->tl);
  k->active[at] = (unsigned char)a;
  return a;
}

int cv_kkt_step_crosses(cv_kkt *k, const double *Y, const double *Yt) {
  const cv_disc *d = k->d;
  int nc = d->nc;
  for (long j0 = 0; j0 < d->nodes; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int kc = 0; kc < nc; kc++) {
      int sense = k->prob->pc[kc].sense;
      double *g, *gy, *gyy, g0[CV_BATCH];
      if (!sense) continue;
      if (eval_constraint(k, kc, Y, j0, m, CVAR_NEED_F, &g, &gy, &gyy)) return 0;
      cv_dcopy(g0, g, (size_t)m);
      if (eval_constraint(k, kc, Yt, j0, m, CVAR_NEED_F, &g, &gy, &gyy)) return 0;
      for (int t = 0; t < m; t++) {
        long node = j0 + t;
        if (cv_disc_lidx(d, node, kc) < 0 || k->active[(size_t)node * nc + kc]) continue;
        double before = sense * g0[t], after = sense * g[t];
        if (before > 0 && after < -OB_CROSS * before && after < -OB_CROSS * k->gscale) return 1;
      }
    }
  }
  return 0;
}

/* One inequality row at a node, as a sweep visits it: G_k there (g; its gradient gy with
 * stride m when asked for), the row and the node * nc + k index of its decision. */
typedef struct {
  long node;
  int kc, sense, row, m;
  size_t at;
  double g;
  const double *gy;
} ineq_row;

/* Visit every inequality row at Y (constraints evaluated a batch of nodes at a time, with
 * need); fn returns nonzero to stop. Returns 0, or -1 when a constraint fails to evaluate
 * or fn stops. */
static int sweep_inequalities(cv_kkt *k, const double *Y, unsigned need,
                              int (*fn)(cv_kkt *, const ineq_row *, void *), void *ctx) {
  const cv_disc *d = k->d;
  int nc = d->nc;
  for (long j0 = 0; j0 < d->nodes; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int kc = 0; kc < nc; kc++) {
      double *g, *gy, *gyy;
      if (!k->prob->pc[kc].sense) continue;
      if (eval_constraint(k, kc, Y, j0, m, need, &g, &gy, &gyy)) return -1;
      for (int t = 0; t < m; t++) {
        ineq_row r = {j0 + t,
                      kc,
                      k->prob->pc[kc].sense,
                      cv_disc_lidx(d, j0 + t, kc),
                      m,
                      (size_t)(j0 + t) * nc + kc,
                      g[t],
                      gy + t};
        if (r.row >= 0 && fn(k, &r, ctx)) return -1;
      }
    }
  }
  return 0;
}

typedef struct {
  const double *M;
  long changed;
  double gmax;
} update_ctx;

static int update_one(cv_kkt *k, const ineq_row *r, void *ctx) {
  update_ctx *u = ctx;
  size_t at = r->at;
  double c = isnan(k->cw[at]) ? 1.0 : k->cw[at];
  int a = cv_kkt_active_rule(r->sense, r->g, u->M[at], c, k->eps, k->active[at], k->tg, k->tl);
  u->gmax = cv_fmax(u->gmax, fabs(r->g));
  if (a != k->active[at] && k->chg && k->nchg < k->chgcap) k->chg[k->nchg] = at;
  if (a != k->active[at]) k->nchg++, u->changed++;
  k->active[at] = (unsigned char)a;
  return 0;
}

long cv_kkt_update_active(cv_kkt *k, const double *Y, const double *M) {
  const cv_disc *d = k->d;
  int nc = d->nc;
  double lmax = 0.0;
  k->nchg = 0;
  for (long j = 0; j < d->nodes; j++)
    for (int kc = 0; kc < nc; kc++)
      if (k->prob->pc[kc].sense) lmax = cv_fmax(lmax, fabs(M[(size_t)j * nc + kc]));
  /* OB-2b: the margins, round-off of the largest |G| (last pass) and the largest |lambda| */
  k->tg = 1e-10 * k->gscale, k->tl = 1e-10 * lmax; /* gscale: 1e-2 max |G| */
  update_ctx u = {M, 0, 0.0};
  if (sweep_inequalities(k, Y, CVAR_NEED_F, update_one, &u)) return -1;
  k->gscale = 1e-2 * u.gmax;
  return u.changed;
}

typedef struct {
  const double *Y, *M, *Yt;
  double P, sl;
} penalty_ctx;

static int penalty_one(cv_kkt *k, const ineq_row *r, void *ctx) {
  penalty_ctx *q = ctx;
  const cv_disc *d = k->d;
  double c = isnan(k->cw[r->at]) ? 1.0 : k->cw[r->at], mj = d->mass[r->row];
  double v = r->sense * r->g < 0 ? r->sense * r->g : 0.0;
  q->P += mj * c / (2.0 * k->eps) * v * v;
  if (!q->Yt) return 0;
  double dg = 0.0;
  for (int i = 0; i < cn_of(d); i++) {
    long di = vdof(d, r->node, i);
    dg += r->gy[(size_t)i * r->m] * (q->Yt[di] - q->Y[di]);
  }
  q->sl += mj * (c / k->eps * r->sense * v - q->M[r->at]) * dg;
  return 0;
}

/* OB-3a: the penalised action's extra term at Y, P - S = sum_j m_j c_j / (2 eps)
 * min(0, s G_j)^2 over the inequality rows, into *pen; with Yt (not NULL) also, into
 * *dslope, the part of the slope of P along Yt - Y that the Lagrangian's gradient at
 * (Y, M) lacks: sum_j m_j (lam*_j - lam_j) grad G_j . (Yt - Y), lam*_j = (c_j / eps) s
 * min(0, s G_j) the multiplier that makes that gradient P's. Returns 0, or -1 when a
 * constraint fails to evaluate. */
int cv_kkt_penalty(cv_kkt *k, const double *Y, const double *M, const double *Yt, double *pen,
                   double *dslope) {
  penalty_ctx q = {Y, M, Yt, 0.0, 0.0};
  if (sweep_inequalities(k, Y, CVAR_NEED_F | (Yt ? CVAR_NEED_GRAD : 0u), penalty_one, &q))
    return -1;
  *pen = q.P;
  if (dslope) *dslope = q.sl;
  return isfinite(q.P) && isfinite(q.sl) ? 0 : -1;
}

/* Row lam_jk of node j and constraint kc (C-1, OB-2, OB-3), and its terms in the y rows,
 * from G_k at the node (g, its gradient gy and Hessian gyy with stride m): on = 1 an
 * imposing row (m_j G, or m_j (G - eps lam / c) in a penalty stage), 0 an inactive one
 * (lambda = 0). With sgn = -1 the y-row terms are taken out again (the row's own entries
 * are written either way). */
static cv_status constraint_row(cv_kkt *k, long node, int kc, int row, int on, double sgn, double g,
                                const double *gy, const double *gyy, int m, double lam, double *G,
                                double *Ax, double *dreg) {
  const cv_disc *d = k->d;
  const int *cp = k->colptr;
  int n = cn_of(d), nc = d->nc, sense = k->prob->pc[kc].sense;
  double mj = d->mass[row], gg = 0.0;
  if (!on) {
    if (sgn > 0) cv_kkt_inactive_row(k, node, kc, row, lam, G, Ax, dreg);
    return CVAR_OK;
  }
  /* OB-3: an active row of the path-following imposes G = eps lambda / c */
  double cw = sense ? k->cw[(size_t)node * nc + kc] : 1.0;
  double pen = sense && k->eps > 0 ? k->eps / (isnan(cw) ? 1.0 : cw) : 0.0;
  if (sgn > 0) G[row] = mj * (g - pen * lam);
  for (int i = 0; i < n; i++) {
    int fi = cv_disc_fidx(d, vdof(d, node, i));
    double gi = gy[(size_t)i * m];
    if (!isfinite(gi)) return CVAR_ENONFINITE;
    if (fi < 0) continue;
    G[fi] += sgn * mj * lam * gi;
    gg += mj * mj * gi * gi;
    if (!Ax) continue;
    Ax[pos(cp, fi, row)] = sgn > 0 ? mj * gi : 0.0;
    for (int i2 = i; i2 < n; i2++) { /* upper triangle: fi <= fi2 */
      int fi2 = cv_disc_fidx(d, vdof(d, node, i2));
      double h2 = gyy[(size_t)(i * n + i2) * m];
      if (!isfinite(h2)) return CVAR_ENONFINITE;
      if (fi2 >= 0) Ax[pos(cp, fi, fi2)] += sgn * mj * lam * h2;
    }
  }
  if (Ax && sgn > 0) {
    double delta = 1e-12 * gg / k->hmax;
    Ax[pos(cp, row, row)] = pen > 0 ? -mj * pen : -delta;
    if (dreg) dreg[row] = pen > 0 ? 0.0 : delta;
  }
  return CVAR_OK;
}

typedef struct {
  int pass;
  double frac, pmax;
  long na;
} start_ctx;

static int start_one(cv_kkt *k, const ineq_row *r, void *ctx) {
  start_ctx *q = ctx;
  double sink = -r->sense * r->g;
  if (!q->pass)
    q->pmax = cv_fmax(q->pmax, sink);
  else
    q->na += k->active[r->at] = sink > q->frac * q->pmax;
  return 0;
}

/* OB-3b: the start set of a penalty stage after another: active exactly where the path
 * sinks into the obstacle by more than frac of its deepest sinking, -s G > frac max(-s G).
 * Returns the number of active nodes, or -1 when a constraint fails to evaluate. */
long cv_kkt_stage_start(cv_kkt *k, const double *Y, double frac) {
  start_ctx q = {0, frac, 0.0, 0};
  for (q.pass = 0; q.pass < 2; q.pass++)
    if (sweep_inequalities(k, Y, CVAR_NEED_F, start_one, &q)) return -1;
  return q.na;
}

/* Gradient and Hessian of the discrete Lagrangian
 *   L_h = S_h(Y) + sum_j m_j sum_k lam_jk G_k(x_j, Y_j) + sum_r nu_r (I_r(Y) - c_r)
 * with respect to all unknowns (C-3); *S is S_h alone. The multiplier rows' diagonal gets
 * -delta (quasi-definite regularisation, C-4), also written to dreg (length nfree, zero on
 * the other rows) so that the solve can refine it away. */
cv_status cv_kkt_eval(cv_kkt *k, const double *Y, const double *M, double *S, double *G, double *Ax,
                      double *dreg) {
  const cv_disc *d = k->d;
  const cv_problem *p = k->prob;
  const int *cp = k->colptr;
  int nc = d->nc, nf = d->nfree;
  cv_status st;
  /* The assembly clears the node rows and columns as it goes; the integral multipliers'
   * rows and columns (the last ni, dense, C-3) are cleared here. */
  for (int c = d->nu0; c < nf; c++) {
    G[c] = 0.0;
    if (Ax) cv_dzero(Ax + cp[c], (size_t)(cp[c + 1] - cp[c]));
  }
  if (dreg) cv_dzero(dreg, (size_t)nf);
  st = cv_assemble(&k->as, p->F, p->user, Y, S, G, cp, Ax, 1.0, 1);
  if (st) return st;
  double hmax = 0.0; /* largest diagonal entry of the action's Hessian, for delta */
  if (Ax && (nc > 0 || d->ni > 0))
    for (int c = 0; c < nf; c++) hmax = cv_fmax(hmax, fabs(Ax[cp[c + 1] - 1]));
  if (!(hmax > 0)) hmax = 1.0;

  /* Integral constraints (C-2): row nu0+r holds I_r - c_r, column its gradient. */
  for (int r = 0; r < d->ni; r++) {
    const cv_iconstraint *ic = &p->ic[r];
    double I, nu = M[(size_t)d->nodes * nc + r];
    int row = d->nu0 + r;
    cv_dzero(k->gK, (size_t)nf);
    st = cv_assemble(&k->as, ic->K, ic->user, Y, &I, k->gK, cp, Ax, nu, 0);
    if (st) return st;
    G[row] = I - ic->c;
    double gg = 0.0;
    for (int f = 0; f < d->nu0; f++) {
      G[f] += nu * k->gK[f];
      gg += k->gK[f] * k->gK[f];
      if (Ax) Ax[pos(cp, f, row)] = k->gK[f];
    }
    if (Ax) {
      double delta = 1e-12 * gg / hmax;
      Ax[pos(cp, row, row)] = -delta;
      if (dreg) dreg[row] = delta;
    }
  }

  /* Pointwise constraints at the nodes (C-1): row lam_jk holds m_j G_k(x_j, Y_j). */
  if (Ax) k->hmax = hmax;
  unsigned need = CVAR_NEED_F | CVAR_NEED_GRAD | (Ax ? CVAR_NEED_HESS : 0u);
  for (long j0 = 0; j0 < d->nodes && nc > 0; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int kc = 0; kc < nc; kc++) {
      double *g, *gy, *gyy;
      st = eval_constraint(k, kc, Y, j0, m, need, &g, &gy, &gyy);
      if (st) return st;
      int sense = p->pc[kc].sense;
      for (int t = 0; t < m; t++) {
        long node = j0 + t;
        int row = cv_disc_lidx(d, node, kc);
        if (row < 0) continue;
        double lam = M[node * nc + kc];
        if (!isfinite(g[t])) return CVAR_ENONFINITE;
        int on = !sense || decide(k, Ax, node, kc, sense, g[t], gy + t, m, lam);
        st = constraint_row(k, node, kc, row, on, 1.0, g[t], gy + t, gyy + t, m, lam, G, Ax, dreg);
        if (st) return st;
      }
    }
  }
  return CVAR_OK;
}

/* OB-2c: after cv_kkt_update_active changed the set at the point (Y, M) whose system
 * (G, Ax, dreg) was evaluated with the old set, only the changed nodes' rows and their
 * terms in the y rows differ: those are swapped in place (the old row's terms taken out,
 * the new row's put in) instead of evaluating the whole system again. */
cv_status cv_kkt_apply_changes(cv_kkt *k, const double *Y, const double *M, double *G, double *Ax,
                               double *dreg) {
  const cv_disc *d = k->d;
  int nc = d->nc;
  unsigned need = CVAR_NEED_F | CVAR_NEED_GRAD | (Ax ? CVAR_NEED_HESS : 0u);
  for (long c = 0; c < k->nchg; c++) {
    size_t at = k->chg[c];
    long node = (long)(at / (size_t)nc);
    int kc = (int)(at % (size_t)nc), row = cv_disc_lidx(d, node, kc);
    double *g, *gy, *gyy, lam = M[at];
    cv_status st = eval_constraint(k, kc, Y, node, 1, need, &g, &gy, &gyy);
    if (st) return st;
    if (!isfinite(g[0])) return CVAR_ENONFINITE;
    int on = k->active[at];
    st = constraint_row(k, node, kc, row, !on, -1.0, g[0], gy, gyy, 1, lam, G, Ax, dreg);
    if (!st) st = constraint_row(k, node, kc, row, on, 1.0, g[0], gy, gyy, 1, lam, G, Ax, dreg);
    if (st) return st;
  }
  k->nchg = 0;
  return CVAR_OK;
}

/* Starting multipliers by least squares from the stationarity condition at Y (C-5):
 * mu_r = -<g, grad I_r> / <grad I_r, grad I_r> in the inner product weighted by 1/m_f^2
 * (the scaled residual of N-3), then at each node lam_jk = -<g_j, grad G_k> / (m_j |grad
 * G_k|^2) over its free components, each with g updated by the previous ones. Starting
 * from zero multipliers leaves the Hessian of F alone, which for a chain or an area
 * functional is indefinite or zero. */
cv_status cv_kkt_init_multipliers(cv_kkt *k, const double *Y, double *M) {
  const cv_disc *d = k->d;
  const cv_problem *p = k->prob;
  int n = cn_of(d), nc = d->nc, nf = d->nfree;
  double S, *g = cv_calloc((size_t)(nf ? nf : 1), sizeof *g);
  if (!g) return CVAR_ENOMEM;
  cv_status st = cv_assemble(&k->as, p->F, p->user, Y, &S, g, k->colptr, NULL, 0.0, 0);
  for (int r = 0; r < d->ni && !st; r++) {
    double I, num = 0.0, den = 0.0;
    cv_dzero(k->gK, (size_t)nf);
    st = cv_assemble(&k->as, p->ic[r].K, p->ic[r].user, Y, &I, k->gK, k->colptr, NULL, 0.0, 0);
    for (int f = 0; f < d->nu0 && !st; f++) {
      double w = 1.0 / (d->mass[f] * d->mass[f]);
      num += w * g[f] * k->gK[f];
      den += w * k->gK[f] * k->gK[f];
    }
    double mu = den > 0 ? -num / den : 0.0;
    M[(size_t)d->nodes * nc + r] = mu;
    for (int f = 0; f < d->nu0; f++) g[f] += mu * k->gK[f];
  }
  for (long j0 = 0; j0 < d->nodes && nc > 0 && !st; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int kc = 0; kc < nc && !st; kc++) {
      double *G, *gy, *gyy;
      st = eval_constraint(k, kc, Y, j0, m, CVAR_NEED_F | CVAR_NEED_GRAD, &G, &gy, &gyy);
      for (int t = 0; t < m && !st; t++) {
        long node = j0 + t;
        int row = cv_disc_lidx(d, node, kc);
        if (row < 0) continue;
        double num = 0.0, den = 0.0, mj = d->mass[row], sc = 1.0;
        for (int i = 0; i < n; i++) {
          int fi = cv_disc_fidx(d, vdof(d, node, i));
          sc += fabs(gy[i * m + t] * Y[vdof(d, node, i)]);
          if (fi < 0) continue;
          num += g[fi] * gy[i * m + t];
          den += gy[i * m + t] * gy[i * m + t];
        }
        double lam = den > 0 && isfinite(num) ? -num / (mj * den) : 0.0;
        /* OB-2: an inequality starts inactive (lambda = 0) except at a node already on its
         * obstacle (|G| within 1e-12 of its scale: a node of a solved path), where
         * the least-squares force is kept if it pushes away from the obstacle, so that the
         * first evaluation finds the contact set of the path it starts from */
        int sense = p->pc[kc].sense;
        double on = k->on_tol > 0 ? k->on_tol : 1e-12;
        if (sense && !(fabs(G[t]) <= on * sc && sense * lam <= 0)) lam = 0.0;
        M[node * nc + kc] = lam;
        for (int i = 0; i < n; i++) {
          int fi = cv_disc_fidx(d, vdof(d, node, i));
          if (fi >= 0) g[fi] += mj * lam * gy[i * m + t];
        }
      }
    }
  }
  cv_free(g);
  return st;
}

/* Constraint values and their dense Jacobian for the NLopt engine (C-1, C-2): for each
 * unknown index f of a multiplier row, vals[f] = G_k(x_j, Y_j) or I_r - c_r; when jac is
 * given, row lrow[f] of jac (leading dimension ld) receives the derivatives with respect
 * to the variables, variable var[f'] for the y unknown f' (var[f'] < 0: not a variable). */
cv_status cv_kkt_constraint_values(cv_kkt *k, const double *Y, double *vals, double *jac, int ld,
                                   const int *lrow, const int *var) {
  const cv_disc *d = k->d;
  const cv_problem *p = k->prob;
  int n = cn_of(d), nc = d->nc;
  cv_status st = CVAR_OK;
  for (int r = 0; r < d->ni && !st; r++) {
    double I;
    int row = d->nu0 + r;
    cv_dzero(k->gK, (size_t)d->nfree);
    st = cv_assemble(&k->as, p->ic[r].K, p->ic[r].user, Y, &I, jac ? k->gK : NULL, k->colptr, NULL,
                     0.0, 0);
    vals[row] = I - p->ic[r].c;
    if (jac && !st)
      for (int f = 0; f < d->nu0; f++)
        if (var[f] >= 0) jac[(size_t)lrow[row] * ld + var[f]] = k->gK[f];
  }
  unsigned need = CVAR_NEED_F | (jac ? CVAR_NEED_GRAD : 0u);
  for (long j0 = 0; j0 < d->nodes && nc > 0 && !st; j0 += CV_BATCH) {
    int m = d->nodes - j0 < CV_BATCH ? (int)(d->nodes - j0) : CV_BATCH;
    for (int kc = 0; kc < nc && !st; kc++) {
      double *g, *gy, *gyy;
      st = eval_constraint(k, kc, Y, j0, m, need, &g, &gy, &gyy);
      for (int t = 0; t < m && !st; t++) {
        long node = j0 + t;
        int row = cv_disc_lidx(d, node, kc);
        if (row < 0) continue;
        if (!isfinite(g[t])) st = CVAR_ENONFINITE;
        vals[row] = g[t];
        for (int i = 0; i < n && jac; i++) {
          int fi = cv_disc_fidx(d, vdof(d, node, i));
          if (fi >= 0 && var[fi] >= 0) jac[(size_t)lrow[row] * ld + var[fi]] = gy[i * m + t];
        }
      }
    }
  }
  return st;
}
