/* src/core/cv_disc.c — the discretisation of one solve: mesh, reference element, dof map.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

/* Zero every field but the tables of the embedded reference element (4.6 kB, of which a
 * degree-4 element uses 50 entries; cv_refelem_init writes what the degree reads): zeroing
 * all of it twice per solve wrote 170 cache lines the solve never reads, each a miss in
 * the first solve of a process (docs/performance.md). */
_Static_assert(offsetof(cv_disc, fix0) == offsetof(cv_disc, ref) + sizeof(cv_refelem),
               "disc_clear zeroes the fields after ref from fix0 on");
static void disc_clear(cv_disc *d) {
  memset(d, 0, offsetof(cv_disc, ref));
  d->ref.p = d->ref.q = d->ref.qs = 0;
  memset(&d->fix0, 0, sizeof *d - offsetof(cv_disc, fix0));
}

void cv_disc_free(cv_disc *d) {
  if (!d) return;
  cv_free(d->xe);
  cv_free(d->fix0); /* fix1 lives in its block */
  cv_free(d->mass); /* imass lives in its block */
  cv_free(d->srule);
  cv_free(d->pe);
  cv_free(d->en);
  cv_free(d->refs);
  cv_free(d->herm);
  disc_clear(d);
}

void cv_disc_fill_nodes(const cv_disc *d, double *x) {
  for (long e = 0; e < d->E; e++) {
    double h = d->xe[e + 1] - d->xe[e];
    long j0 = cv_disc_enode(d, e);
    int pe = cv_disc_edeg(d, e);
    const double *xi = cv_disc_eref(d, e)->xi;
    x[j0] = d->xe[e];
    for (int l = 1; l < pe; l++) x[j0 + l] = d->xe[e] + 0.5 * (xi[l] + 1.0) * h;
  }
  x[d->nodes - 1] = d->xe[d->E];
}

long cv_disc_node_elem(const cv_disc *d, long j) {
  if (j >= d->nodes - 1) return d->E - 1;
  if (!d->en) return j / d->p;
  long lo = 0, hi = d->E; /* en[lo] <= j < en[hi] */
  while (hi - lo > 1) {
    long mid = (lo + hi) / 2;
    if (d->en[mid] <= j)
      lo = mid;
    else
      hi = mid;
  }
  return lo;
}

double cv_disc_node_x(const cv_disc *d, long j) {
  if (j >= d->nodes - 1) return d->xe[d->E];
  long e = cv_disc_node_elem(d, j);
  int l = (int)(j - cv_disc_enode(d, e));
  double h = d->xe[e + 1] - d->xe[e];
  return l == 0 ? d->xe[e] : d->xe[e] + 0.5 * (cv_disc_eref(d, e)->xi[l] + 1.0) * h;
}

/* Variable degrees (HP-1): per-element degrees from the mesh spec, first nodes, and one
 * reference element per degree. Sets d->p to the largest degree and d->nodes. */
static cv_status disc_init_hp(cv_disc *d, const cv_meshspec *m, int nq) {
  d->pe = cv_malloc((size_t)d->E * sizeof *d->pe);
  d->en = cv_malloc((size_t)(d->E + 1) * sizeof *d->en);
  d->refs = cv_malloc((CV_MAX_DEGREE + 1) * sizeof *d->refs);
  if (!d->pe || !d->en || !d->refs) return CVAR_ENOMEM;
  cv_mesh_degrees(m, d->a, d->b, d->E, d->xe, d->pe);
  int used[CV_MAX_DEGREE + 1] = {0};
  long j = 0;
  d->p = 1;
  for (long e = 0; e < d->E; e++) {
    d->en[e] = j;
    j += d->pe[e];
    used[d->pe[e]] = 1;
    if (d->pe[e] > d->p) d->p = d->pe[e];
  }
  d->en[d->E] = j;
  d->nodes = j > 2000000000L ? 2000000000 : (int)j + 1;
  for (int k = 1; k <= CV_MAX_DEGREE; k++)
    if (used[k]) cv_refelem_init(&d->refs[k], k, nq ? nq : k + 1);
  return CVAR_OK;
}

/* Whether component i of a node is fixed at an end: a value, or (C^1, odd i) a slope. */
static int disc_end_fixed(const cv_problem *p, int i, int end) {
  if (!p->c1) return p->fixed[2 * i + end];
  return i & 1 ? p->sfixed[2 * (i / 2) + end] : p->fixed[2 * (i / 2) + end];
}

/* Unknowns are node-major (theory E-2); fixed end values are removed, so free indices are
 * the global ones shifted by the fixed components of node 0, except at the two end nodes. */
cv_status cv_disc_init(cv_disc *d, const cv_problem *p, const cv_solver *s, char *msg, size_t len) {
  cv_status st;
  int n = p->c1 ? 2 * p->n : p->n; /* C^1: a value and a slope per unknown (H-2) */
  int r = p->c1 ? cv_hermite_node_degree(s->degree, msg, len) : 0;
  disc_clear(d);
  if (r < 0 || (p->c1 && s->mesh.degrees)) {
    if (r >= 0) cv_set_msg(msg, len, "C1 elements take one degree for every element");
    return CVAR_EINVAL;
  }
  st = cv_mesh_build(&s->mesh, p->a, p->b, &d->E, &d->xe, msg, len);
  if (st) return st;
  d->n = n;
  d->p = p->c1 ? r : s->degree;
  d->a = p->a;
  d->b = p->b;
  d->nodes = d->E * d->p + 1;
  if (s->mesh.degrees) {
    st = disc_init_hp(d, &s->mesh, s->nq);
    if (st) {
      cv_disc_free(d);
      return st;
    }
  }
  if ((double)d->nodes * n > 2.0e9) {
    cv_set_msg(msg, len, "%d elements of degree %d with %d unknowns exceed 2e9 unknowns", d->E,
               d->p, n);
    cv_disc_free(d);
    return CVAR_EINVAL;
  }
  d->ndof = d->nodes * n;
  cv_refelem_init(&d->ref, d->p, s->nq ? s->nq : p->c1 ? 2 * d->p + 2 : d->p + 1);
  if (p->c1 && cv_hermite_disc_init(d, s->nq)) {
    cv_disc_free(d);
    return CVAR_ENOMEM;
  }
  /* fix0 and fix1 in one block, mass and imass in another: fewer allocations, and fewer
   * heap bytes for the first solve in a process to touch (docs/performance.md) */
  d->fix0 = cv_malloc(2 * (size_t)n * sizeof *d->fix0);
  if (!d->fix0) {
    cv_disc_free(d);
    return CVAR_ENOMEM;
  }
  d->fix1 = d->fix0 + n;
  int f = 0, nc = p->nc;
  d->nc = nc;
  d->ni = p->ni;
  d->stride = n + nc;
  for (int i = 0; i < n; i++) d->fix0[i] = disc_end_fixed(p, i, 0) ? -1 : f++;
  d->nfree0 = f;
  d->lam0 = (f > 0 && nc > 0) ? f : -1;
  if (d->lam0 >= 0) f += nc;
  d->off0 = f;
  f += (d->nodes - 2) * d->stride;
  int f1 = f;
  for (int i = 0; i < n; i++) d->fix1[i] = disc_end_fixed(p, i, 1) ? -1 : f++;
  d->nfree1 = f - f1;
  d->lamL = (d->nfree1 > 0 && nc > 0) ? f : -1;
  if (d->lamL >= 0) f += nc;
  d->nu0 = f;
  f += d->ni;
  d->nfree = f;
  d->mass = cv_calloc(2 * (size_t)(f ? f : 1), sizeof *d->mass);
  if (!d->mass) {
    cv_disc_free(d);
    return CVAR_ENOMEM;
  }
  /* Lumped weight of a node: the integral of its basis function, (h/2) w_l^GLL (N-3); a
   * node's multipliers share it, integral multipliers get the interval length. */
  for (int e = 0; e < d->E; e++) {
    double h = d->xe[e + 1] - d->xe[e];
    const double *wl = cv_disc_eref(d, e)->wl;
    for (int l = 0, pe = cv_disc_edeg(d, e); l <= pe; l++) {
      long node = cv_disc_enode(d, e) + l;
      double m = 0.5 * h * wl[l];
      if (node > 0 && node < d->nodes - 1) { /* interior: the node's block, y then lambda */
        double *blk = d->mass + cv_disc_node_first(d, node);
        for (int t = 0; t < d->stride; t++) blk[t] += m;
        continue;
      }
      for (int i = 0; i < n; i++) {
        int fi = cv_disc_fidx(d, node * n + i);
        if (fi >= 0) d->mass[fi] += m;
      }
      for (int k = 0; k < nc; k++) {
        int li = cv_disc_lidx(d, node, k);
        if (li >= 0) d->mass[li] += m;
      }
    }
  }
  for (int r = 0; r < d->ni; r++) d->mass[d->nu0 + r] = d->b - d->a;
  d->imass = d->mass + (f ? f : 1);
  for (int k = 0; k < f; k++) d->imass[k] = 1.0 / d->mass[k];
  if (d->herm) cv_hermite_scale_mass(d);
  return CVAR_OK;
}

/* Per-element stride of the singular-end rules: room for the largest degree. */
static size_t srule_stride(const cv_disc *d) { return (size_t)d->ref.qs * (2 + 2 * (d->p + 1)); }

CV_HOT cv_rule cv_disc_rule(const cv_disc *d, long e) {
  const cv_refelem *r = cv_disc_eref(d, e);
  if (d->srule) {
    int qs = r->qs, P1 = r->p + 1;
    const double *base = d->srule + (size_t)e * srule_stride(d);
    return (cv_rule){qs, base, base + qs, base + 2 * qs, base + 2 * qs + qs * P1};
  }
  return (cv_rule){r->q, r->tau, r->omega, r->B, r->D};
}

CV_HOT long cv_disc_num_qpoints(const cv_disc *d) {
  if (!d->pe) return (long)d->E * (d->srule ? d->ref.qs : d->ref.q);
  long total = 0;
  for (long e = 0; e < d->E; e++) total += d->srule ? d->refs[d->pe[e]].qs : d->refs[d->pe[e]].q;
  return total;
}

/* Rules for an integrand singular at an end c (theory Q-2): on every element, Gauss in
 * u = sqrt(|x - c|), so x = c +- u^2 and dx = 2u du turn a factor |x - c|^(-1/2) into a
 * smooth one. On the element touching c this is the substitution x = c + h t^2; on the
 * others it removes what a graded mesh leaves of the singularity (measured: a fixed
 * Gauss rule on the second element still let the discrete brachistochrone exploit it).
 * With both ends singular each element uses the nearer one. */
CV_HOT cv_status cv_disc_build_singular_rules(cv_disc *d) {
  size_t per = srule_stride(d);
  double t[CV_MAX_QUAD], w[CV_MAX_QUAD];
  int qlast = 0;
  cv_free(d->srule);
  d->srule = NULL;
  if ((!d->sing_a && !d->sing_b) || d->herm) return CVAR_OK; /* C^1: Gauss rules only */
  d->srule = cv_malloc((size_t)d->E * per * sizeof *d->srule);
  if (!d->srule) return CVAR_ENOMEM;
  for (long e = 0; e < d->E; e++) {
    const cv_refelem *r = cv_disc_eref(d, e);
    int qs = r->qs, P1 = r->p + 1;
    if (qs != qlast) cv_gauss_legendre(qs, t, w), qlast = qs;
    double x0 = d->xe[e], x1 = d->xe[e + 1], h = x1 - x0, J = 0.5 * h;
    int at_a = d->sing_a && (!d->sing_b || x0 + x1 <= d->a + d->b);
    double c = at_a ? d->a : d->b;
    double u0 = sqrt(fabs(x0 - c)), u1 = sqrt(fabs(x1 - c));
    double *tau = d->srule + (size_t)e * per, *om = tau + qs, *B = om + qs, *D = B + qs * P1;
    for (int k = 0; k < qs; k++) {
      double u = u0 + (u1 - u0) * 0.5 * (t[k] + 1.0), wu = 0.5 * fabs(u1 - u0) * w[k];
      double x = at_a ? c + u * u : c - u * u;
      tau[k] = 2.0 * (x - x0) / h - 1.0;
      om[k] = wu * 2.0 * u / J; /* weight in x, divided by the element's J = h/2 */
      cv_lagrange(r->p, r->xi, tau[k], B + k * P1, D + k * P1);
    }
  }
  return CVAR_OK;
}

/* Column c of the upper triangle holds the rows from the first unknown of the first
 * element containing c's node up to c (block-banded pattern, theory E-2); an integral
 * multiplier's column is dense (C-3). */
long cv_disc_pattern(const cv_disc *d, int *colptr, int *gof) {
  int n = d->n, p = d->p, nc = d->nc;
  long nnz = 0;
  if (colptr) colptr[0] = 0;
  long since = 0; /* nodes since the last element boundary, without % */
  for (long J = 0, e = 0; J < d->nodes; J++) {
    /* e = first element containing node J */
    if (d->en)
      e += J > 1 && J - 1 == d->en[e + 1];
    else if (J > 1 && ++since == p)
      e++, since = 0;
    long r0 = cv_disc_elem_first(d, e);
    /* the node's unknowns in increasing order: y components, then multipliers (an
     * interior node's: its block's first index and on, cv_disc_fidx without its division) */
    int inner = J > 0 && J < d->nodes - 1, c0 = inner ? cv_disc_node_first(d, J) : 0;
    for (int t = 0; t < n + nc; t++) {
      int c = inner ? c0 + t : t < n ? cv_disc_fidx(d, J * n + t) : cv_disc_lidx(d, J, t - n);
      if (c < 0) continue;
      if (gof) gof[c] = t < n ? (int)(J * n + t) : -1 - (int)(J * nc + t - n);
      nnz += (long)c - r0 + 1;
      if (colptr) colptr[c + 1] = (int)nnz;
    }
  }
  for (int r = 0; r < d->ni; r++) {
    int c = d->nu0 + r;
    if (gof) gof[c] = -1 - (int)((long)d->nodes * nc + r);
    nnz += (long)c + 1;
    if (colptr) colptr[c + 1] = (int)nnz;
  }
  return nnz;
}
