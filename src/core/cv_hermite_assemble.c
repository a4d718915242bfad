/* src/core/cv_hermite_assemble.c — the discrete action of a second-order integrand on C^1
 * elements, its gradient and Hessian, theory (H-3).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_hermite.h"

/* Buffers beyond cv_assembler_init's (which are sized for the problem's n unknowns and one
 * batch): y'' and the partials in y'' at the batch's points, the element matrix, its
 * gradient and free indices. */
cv_status cv_hermite_assembler_init(cv_assembler *as) {
  const cv_disc *d = as->disc;
  size_t n = (size_t)d->n / 2, m = CV_BATCH, nl = (size_t)d->herm->nb * n;
  size_t len = (2 * n + 3 * n * n) * m + nl * nl + nl;
  as->hbuf = cv_malloc(len * sizeof *as->hbuf + nl * sizeof(int));
  return as->hbuf ? CVAR_OK : CVAR_ENOMEM;
}

/* Batch layout of hbuf: d2y, Fq (n*m each), Fyq, Fpq, Fqq (n*n*m each), K, gl, fl. */
typedef struct {
  double *d2y, *Fq, *Fyq, *Fpq, *Fqq, *K, *gl;
  int *fl;
} hbufs;
static hbufs layout(const cv_assembler *as) {
  size_t n = (size_t)as->disc->n / 2, m = CV_BATCH, nl = (size_t)as->disc->herm->nb * n;
  hbufs b;
  b.d2y = as->hbuf, b.Fq = b.d2y + n * m, b.Fyq = b.Fq + n * m, b.Fpq = b.Fyq + n * n * m;
  b.Fqq = b.Fpq + n * n * m, b.K = b.Fqq + n * n * m, b.gl = b.K + nl * nl;
  b.fl = (int *)(b.gl + nl);
  return b;
}

/* x, y, y', y'' at the q points of elements e0 .. e0+ne-1 (H-3: the slope unknown's basis
 * function is J = h/2 times the reference one). */
static void fill(cv_assembler *as, const hbufs *hb, const double *Y, int e0, int ne) {
  const cv_disc *d = as->disc;
  const cv_hermite *h = d->herm;
  int nc = d->n, n = nc / 2, q = h->q, nb = h->nb, m = ne * q;
  for (int el = 0; el < ne; el++) {
    int e = e0 + el;
    double x0 = d->xe[e], hl = d->xe[e + 1] - x0, J = 0.5 * hl, rh = 2.0 / hl;
    const double *Ye = Y + (size_t)cv_disc_enode(d, e) * nc;
    for (int k = 0; k < q; k++) {
      int idx = el * q + k;
      const double *B = h->B + k * nb, *D = h->D + k * nb, *E = h->E + k * nb;
      as->x[idx] = x0 + 0.5 * (h->tau[k] + 1.0) * hl;
      for (int i = 0; i < n; i++) {
        double a = 0.0, b = 0.0, c = 0.0;
        for (int l = 0; l <= h->r; l++) {
          double v = Ye[l * nc + 2 * i], t = Ye[l * nc + 2 * i + 1] * J;
          a += v * B[2 * l] + t * B[2 * l + 1];
          b += v * D[2 * l] + t * D[2 * l + 1];
          c += v * E[2 * l] + t * E[2 * l + 1];
        }
        as->y[i * m + idx] = a;
        as->dy[i * m + idx] = b * rh;
        hb->d2y[i * m + idx] = c * rh * rh;
      }
    }
  }
}

static void nan_fill(double *v, size_t len) {
  for (size_t k = 0; k < len; k++) v[k] = NAN;
}

static cv_status call(cv_assembler *as, const hbufs *hb, cv_integrand_fn Fn, void *user, int m,
                      unsigned need) {
  size_t n = (size_t)as->disc->n / 2, l1 = n * m, l2 = n * n * m;
  cv_partials2 o;
  memset(&o, 0, sizeof o);
  o.d1.F = as->out.F;
  o.d2y = hb->d2y;
  if (need & CVAR_NEED_GRAD) o.d1.Fy = as->out.Fy, o.d1.Fp = as->out.Fp, o.Fq = hb->Fq;
  if (need & CVAR_NEED_HESS) {
    o.d1.Fyy = as->out.Fyy, o.d1.Fyp = as->out.Fyp, o.d1.Fpp = as->out.Fpp;
    o.Fyq = hb->Fyq, o.Fpq = hb->Fpq, o.Fqq = hb->Fqq;
  }
  nan_fill(o.d1.F, (size_t)m);
  if (o.d1.Fy) nan_fill(o.d1.Fy, l1), nan_fill(o.d1.Fp, l1), nan_fill(o.Fq, l1);
  if (o.d1.Fyy) {
    nan_fill(o.d1.Fyy, l2), nan_fill(o.d1.Fyp, l2), nan_fill(o.d1.Fpp, l2);
    nan_fill(o.Fyq, l2), nan_fill(o.Fpq, l2), nan_fill(o.Fqq, l2);
  }
  as->nevals += m;
  int rc = Fn(m, as->x, as->y, as->dy, need | CVAR_NEED_Y2, &o.d1, user);
  as->cb_status = rc;
  return rc < 0 ? CVAR_ECALLBACK : rc > 0 ? CVAR_ENONFINITE : CVAR_OK;
}

/* Element e's gradient (gl) and matrix (K, nl x nl, full) from the batch's outputs at its
 * q points (index el*q + k of m), theory (H-3). Returns its part of S. */
static double element(const cv_assembler *as, const hbufs *hb, int e, int el, int m, int grad,
                      int hess) {
  const cv_disc *d = as->disc;
  const cv_hermite *h = d->herm;
  int n = d->n / 2, nb = h->nb, q = h->q, nl = nb * n;
  double hl = d->xe[e + 1] - d->xe[e], J = 0.5 * hl, rh = 2.0 / hl, S = 0.0;
  double ph[CV_HERMITE_NB], dph[CV_HERMITE_NB], d2ph[CV_HERMITE_NB];
  const cv_partials *o = &as->out;
  if (grad) cv_dzero(hb->gl, (size_t)nl);
  if (hess) cv_dzero(hb->K, (size_t)nl * nl);
  for (int k = 0; k < q; k++) {
    int idx = el * q + k;
    double wk = J * h->omega[k];
    const double *B = h->B + k * nb, *D = h->D + k * nb, *E = h->E + k * nb;
    for (int t = 0; t < nb; t++) { /* physical basis: value (c = 0) and slope (c = 1) */
      int c = t & 1;
      ph[t] = c ? J * B[t] : B[t];
      dph[t] = c ? D[t] : D[t] * rh;
      d2ph[t] = c ? E[t] * rh : E[t] * rh * rh;
    }
    S += wk * o->F[idx];
    if (grad)
      for (int i = 0; i < n; i++) {
        double fy = wk * o->Fy[i * m + idx], fp = wk * o->Fp[i * m + idx];
        double fq = wk * hb->Fq[i * m + idx];
        for (int t = 0; t < nb; t++)
          hb->gl[(t >> 1) * 2 * n + 2 * i + (t & 1)] += fy * ph[t] + fp * dph[t] + fq * d2ph[t];
      }
    if (hess)
      for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++) {
          size_t ij = (size_t)(i * n + j) * m + idx, ji = (size_t)(j * n + i) * m + idx;
          double yy = wk * o->Fyy[ij], yp = wk * o->Fyp[ij], yq = wk * hb->Fyq[ij];
          double py = wk * o->Fyp[ji], pp = wk * o->Fpp[ij], pq = wk * hb->Fpq[ij];
          double qy = wk * hb->Fyq[ji], qp = wk * hb->Fpq[ji], qq = wk * hb->Fqq[ij];
          for (int t = 0; t < nb; t++) {
            double cy = yy * ph[t] + py * dph[t] + qy * d2ph[t];
            double cp = yp * ph[t] + pp * dph[t] + qp * d2ph[t];
            double cq = yq * ph[t] + pq * dph[t] + qq * d2ph[t];
            double *Krow = hb->K + (size_t)((t >> 1) * 2 * n + 2 * i + (t & 1)) * nl + 2 * j;
            for (int u = 0; u < nb; u++)
              Krow[(u >> 1) * 2 * n + (u & 1)] += cy * ph[u] + cp * dph[u] + cq * d2ph[u];
          }
        }
  }
  return S;
}

/* Add element e's gradient and upper triangle to g and Ax (E-2); returns 0 * each entry. */
static double scatter(const cv_assembler *as, const hbufs *hb, int e, double *g, const int *colptr,
                      double *Ax, double hscale) {
  const cv_disc *d = as->disc;
  int nl = d->herm->nb * (d->n / 2);
  long g0 = cv_disc_enode(d, e) * d->n;
  double chk = 0.0;
  for (int a = 0; a < nl; a++) hb->fl[a] = cv_disc_fidx(d, g0 + a);
  if (g)
    for (int a = 0; a < nl; a++) {
      chk += 0.0 * hb->gl[a];
      if (hb->fl[a] >= 0) g[hb->fl[a]] += hb->gl[a];
    }
  if (Ax)
    for (int bc = 0; bc < nl; bc++) {
      int fb = hb->fl[bc];
      if (fb < 0) continue;
      long c0 = colptr[fb], rs = fb + 1 - (colptr[fb + 1] - c0);
      for (int ar = 0; ar <= bc; ar++) {
        chk += 0.0 * hb->K[(size_t)ar * nl + bc];
        if (hb->fl[ar] >= 0) Ax[c0 + hb->fl[ar] - rs] += hscale * hb->K[(size_t)ar * nl + bc];
      }
    }
  return chk;
}

/* S_h = sum_e sum_k (h/2) w_k F(x, y, y', y'') with y from values and slopes at the nodes;
 * gradient and Hessian as, (A-3) with the terms of F_y'' (H-3). */
cv_status cv_hermite_assemble(cv_assembler *as, cv_integrand_fn Fn, void *user, const double *Y,
                              double *S, double *g, const int *colptr, double *Ax, double hscale,
                              int overwrite) {
  const cv_disc *d = as->disc;
  int q = d->herm->q;
  unsigned need = CVAR_NEED_F | (g ? CVAR_NEED_GRAD : 0u) | (Ax ? CVAR_NEED_HESS : 0u);
  double Ssum = 0.0, bad = 0.0;
  hbufs hb = layout(as);
  for (int e0 = 0, ne; e0 < d->E; e0 += ne) {
    ne = d->E - e0 < CV_BATCH / q ? d->E - e0 : CV_BATCH / q;
    int m = ne * q;
    fill(as, &hb, Y, e0, ne);
    cv_status st = call(as, &hb, Fn, user, m, need);
    if (st) return st;
    if (overwrite) { /* as cv_assemble: this batch's nodes not shared with the last one */
      long J0 = cv_disc_enode(d, e0) + (e0 > 0), J1 = cv_disc_enode(d, e0 + ne);
      int cA = cv_disc_node_first(d, J0);
      int cB = J1 == d->nodes - 1 ? d->nu0 : cv_disc_node_first(d, J1 + 1);
      if (g) cv_dzero(g + cA, (size_t)(cB - cA));
      if (Ax) cv_dzero(Ax + colptr[cA], (size_t)(colptr[cB] - colptr[cA]));
    }
    for (int el = 0; el < ne; el++) {
      Ssum += element(as, &hb, e0 + el, el, m, g != NULL, Ax != NULL);
      bad += scatter(as, &hb, e0 + el, g, colptr, Ax, hscale);
    }
  }
  *S = Ssum;
  if (!isfinite(Ssum) || !(bad == 0.0)) return CVAR_ENONFINITE;
  return CVAR_OK;
}
