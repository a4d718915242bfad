/* src/core/cv_assemble.c — discrete action, its gradient and Hessian, theory (A-1)-(A-3).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

cv_status cv_assembler_init(cv_assembler *as, const cv_problem *p, const cv_disc *d) {
  /* A batch holds at most CV_BATCH points and never more than the mesh has: a small mesh's
   * buffers then share a page or two instead of one fresh page per output (the first
   * solve in a process pays a page fault for each, docs/performance.md). */
  long nq = cv_disc_num_qpoints(d);
  size_t n = (size_t)p->n, m = nq < 1 ? 1 : nq < CV_BATCH ? (size_t)nq : CV_BATCH;
  memset(as, 0, sizeof *as);
  as->prob = p;
  as->disc = d;
  size_t nl = (size_t)(d->p + 1) * n;
  /* x, y, y', the integrand's outputs, and for n > 1 the element matrix and gradient and
   * the element's free indices and a point's rows of (A-3) (batch_general), in one
   * allocation (the scalar kernels keep their element
   * sums in registers): the first solve of a small problem touches fewer heap bytes */
  size_t nbuf = (2 + 4 * n + 3 * n * n) * m, nK = n > 1 ? nl * nl + nl + 2 * n * nl : 0;
  as->buf = cv_malloc((nbuf + nK) * sizeof *as->buf + (n > 1 ? nl * sizeof *as->fl : 0));
  if (!as->buf) return CVAR_ENOMEM;
  if (n > 1) {
    as->K = as->buf + nbuf;
    as->fl = (int *)(as->K + nK);
  }
  double *w = as->buf;
  as->x = w, w += m;
  as->y = w, w += n * m;
  as->dy = w, w += n * m;
  as->out.F = w, w += m;
  as->out.Fy = w, w += n * m;
  as->out.Fp = w, w += n * m;
  as->out.Fyy = w, w += n * n * m;
  as->out.Fyp = w, w += n * n * m;
  as->out.Fpp = w;
  return d->herm ? cv_hermite_assembler_init(as) : CVAR_OK;
}

void cv_assembler_free(cv_assembler *as) {
  if (!as) return;
  cv_free(as->buf); /* K and fl live in it */
  cv_free(as->hbuf);
  as->hbuf = NULL;
  as->buf = as->K = NULL;
  as->fl = NULL;
}

/* Fill the batch of quadrature points of elements e0 .. e0+ne-1: x, and y, y' from the
 * nodal values through the basis tables, theory (E-3). Inlined with constant P1 and N
 * where they are small (the common scalar case), so the basis loops unroll. */
static inline __attribute__((always_inline)) void fill_batch(const int N, const int P1,
                                                             cv_assembler *as, const double *Y,
                                                             const cv_rule *r, int e0, int ne) {
  const cv_disc *d = as->disc;
  int q = r->q, m = ne * q;
  for (int el = 0; el < ne; el++) {
    int e = e0 + el;
    double x0 = d->xe[e], h = d->xe[e + 1] - x0, rh = 2.0 / h;
    const double *Ye = Y + (size_t)cv_disc_enode(d, e) * N;
    for (int k = 0; k < q; k++) {
      int idx = el * q + k;
      const double *Bk = r->B + k * P1, *Dk = r->D + k * P1;
      as->x[idx] = x0 + 0.5 * (r->tau[k] + 1.0) * h;
      for (int i = 0; i < N; i++) {
        double yv = 0.0, dv = 0.0;
#pragma GCC unroll 9
        for (int l = 0; l < P1; l++) {
          double c = Ye[l * N + i];
          yv += c * Bk[l];
          dv += c * Dk[l];
        }
        as->y[i * m + idx] = yv;
        as->dy[i * m + idx] = dv * rh;
      }
    }
  }
}

static void fill_points(cv_assembler *as, const double *Y, const cv_rule *r, int e0, int ne,
                        int p) {
  const cv_disc *d = as->disc;
  if (d->n == 1) {
    switch (p) {
    case 1: fill_batch(1, 2, as, Y, r, e0, ne); return;
    case 2: fill_batch(1, 3, as, Y, r, e0, ne); return;
    case 3: fill_batch(1, 4, as, Y, r, e0, ne); return;
    case 4: fill_batch(1, 5, as, Y, r, e0, ne); return;
    default: break;
    }
  }
  fill_batch(d->n, p + 1, as, Y, r, e0, ne);
}

void cv_assembler_points(cv_assembler *as, const double *Y, const cv_rule *r, int e0, int ne) {
  fill_points(as, Y, r, e0, ne, cv_disc_edeg(as->disc, e0));
}

/* v[0 .. len-1] = NaN by block copies (a plain loop stays scalar at -O2: 12 stores per
 * element of degree 1 were a tenth of the assembly, docs/performance.md). */
#define NAN4  NAN, NAN, NAN, NAN
#define NAN32 NAN4, NAN4, NAN4, NAN4, NAN4, NAN4, NAN4, NAN4
static const double nans[] = {NAN32, NAN32, NAN32, NAN32, NAN32, NAN32, NAN32, NAN32};
_Static_assert(sizeof nans / sizeof nans[0] == CV_BATCH, "one batch of NaNs");
static void nan_fill(double *v, size_t len) {
  for (size_t k = 0; k < len; k += CV_BATCH)
    memcpy(v + k, nans, (len - k < CV_BATCH ? len - k : CV_BATCH) * sizeof *v);
}

/* Call the integrand for m points; NaN-fill first so forgotten outputs are caught. */
static cv_status call_integrand(cv_assembler *as, cv_integrand_fn Fn, void *user, int m,
                                unsigned need) {
  size_t n = (size_t)as->disc->n;
  cv_partials o = {as->out.F, NULL, NULL, NULL, NULL, NULL};
  size_t len1 = n * m, len2 = n * n * m;
  if (need & CVAR_NEED_GRAD) o.Fy = as->out.Fy, o.Fp = as->out.Fp;
  if (need & CVAR_NEED_HESS) o.Fyy = as->out.Fyy, o.Fyp = as->out.Fyp, o.Fpp = as->out.Fpp;
  nan_fill(o.F, (size_t)m);
  if (o.Fy) nan_fill(o.Fy, len1), nan_fill(o.Fp, len1);
  if (o.Fyy) nan_fill(o.Fyy, len2), nan_fill(o.Fyp, len2), nan_fill(o.Fpp, len2);
  as->nevals += m;
  int rc = Fn(m, as->x, as->y, as->dy, need, &o, user);
  as->cb_status = rc;
  if (rc < 0) return CVAR_ECALLBACK;
  if (rc > 0) return CVAR_ENONFINITE;
  return CVAR_OK; /* finiteness is checked per element, see cv_assemble */
}

/* Kernel for one unknown (n = 1) over the elements e0 .. e0+ne-1 of a batch, inlined with
 * constant P1 basis functions and Q points (Q = 0: the rule's own q, not unrolled), so the
 * loops unroll and the element gradient and matrix stay in registers. The outputs are
 * restrict: a store into g or Ax then cannot force the tables to be reloaded. Same sums as the general loops in cv_assemble, (A-1)-(A-3).
 * Returns the batch's part of S; *bad collects 0 * (each entry), which is 0 unless an
 * entry is not finite. */
static inline __attribute__((always_inline)) double batch_scalar(
    const int P1, const int Q, const cv_disc *d, const cv_rule *r, int e0, int ne,
    const cv_partials *o, double *restrict g, const int *restrict colptr, double *restrict Ax,
    double hscale, double *bad) {
  enum { MAXB = CV_MAX_QUAD * (CV_MAX_DEGREE + 1) };
  const int q = Q ? Q : r->q;
  /* The kernels of a constant rule (degree <= 4, the default rule) read the tables in
   * place: copied, they were a 5 kB frame, the deepest of a solve, and the first solve in a
   * process paid a fresh stack page for it (docs/performance.md). The others copy them as
   * before (reading them in place, GCC unrolls their loop over a variable number of
   * points: 95 kB of code at degree 8). */
  double Bq[MAXB], Dq[MAXB], omq[CV_MAX_QUAD];
  const double *B = r->B, *D = r->D, *om = r->omega;
  if (!Q) {
    for (int k = 0; k < q * P1; k++) Bq[k] = r->B[k], Dq[k] = r->D[k];
    for (int k = 0; k < q; k++) omq[k] = r->omega[k];
    B = Bq, D = Dq, om = omq;
  }
  const double *restrict F = o->F, *restrict Fy = o->Fy, *restrict Fp = o->Fp;
  const double *restrict Fyy = o->Fyy, *restrict Fyp = o->Fyp, *restrict Fpp = o->Fpp;
  const double *restrict xe = d->xe;
  double S = 0.0, chk = 0.0;
  for (int el = 0; el < ne; el++) {
    int e = e0 + el, fl[CV_MAX_DEGREE + 1];
    double h = xe[e + 1] - xe[e], J = 0.5 * h, rh = 2.0 / h;
    /* Free indices: a shift of the global ones except on the two end elements (E-2). */
    if (e > 0 && e < d->E - 1) {
      int base = cv_disc_elem_first(d, e), st = d->stride;
      for (int l = 0; l < P1; l++) fl[l] = base + l * st;
    } else {
      for (int l = 0; l < P1; l++) fl[l] = cv_disc_fidx(d, cv_disc_enode(d, e) + l);
    }
    double gacc[CV_MAX_DEGREE + 1], Kacc[(CV_MAX_DEGREE + 1) * (CV_MAX_DEGREE + 1)];
#pragma GCC unroll 9
    for (int a = 0; a < P1; a++) gacc[a] = 0.0;
#pragma GCC unroll 81
    for (int a = 0; a < P1 * P1; a++) Kacc[a] = 0.0;
#pragma GCC unroll 16
    for (int k = 0; k < q; k++) {
      int idx = el * q + k;
      double wk = J * om[k];
      const double *Bk = B + k * P1, *Dk = D + k * P1;
      S += wk * F[idx];
      if (g) {
        double fy = wk * Fy[idx], fp = wk * rh * Fp[idx];
#pragma GCC unroll 9
        for (int l = 0; l < P1; l++) gacc[l] += fy * Bk[l] + fp * Dk[l];
      }
      if (Ax) {
        double yy = wk * Fyy[idx], yp = wk * rh * Fyp[idx], pp = wk * rh * rh * Fpp[idx];
#pragma GCC unroll 9
        for (int l = 0; l < P1; l++) {
          double cy = yy * Bk[l] + yp * Dk[l], cp = yp * Bk[l] + pp * Dk[l];
#pragma GCC unroll 9
          for (int rr = l; rr < P1; rr++) Kacc[l * P1 + rr] += cy * Bk[rr] + cp * Dk[rr];
        }
      }
    }
    /* scatter (E-2): gradient rows, and the upper triangle column by column */
    if (g)
#pragma GCC unroll 9
      for (int l = 0; l < P1; l++) {
        chk += 0.0 * gacc[l];
        if (fl[l] >= 0) g[fl[l]] += gacc[l];
      }
    if (Ax)
#pragma GCC unroll 9
      for (int bcol = 0; bcol < P1; bcol++) {
        int fb = fl[bcol];
        if (fb < 0) continue;
        long c0 = colptr[fb], rs = fb + 1 - (colptr[fb + 1] - c0);
#pragma GCC unroll 9
        for (int arow = 0; arow <= bcol; arow++) {
          chk += 0.0 * Kacc[arow * P1 + bcol];
          if (fl[arow] >= 0) Ax[c0 + fl[arow] - rs] += hscale * Kacc[arow * P1 + bcol];
        }
      }
  }
  *bad += chk;
  return S;
}

/* One function per degree (and per constant or any number of points), each contiguous in
 * the code: a solve runs one of them, so it touches the pages of one kernel and not of all
 * sixteen (the first solve in a process pays a page fault per fresh page, docs/performance.md).
 * The kernels of the default rule at degrees 1-4 (20 kB) lie with the rest of a solve's
 * code in .text.hot; those of other rules and higher degrees (36 kB) elsewhere. */
#define KERNEL(name, c, Q, attr)                                                                   \
  static __attribute__((noinline)) attr double name(                                               \
      const cv_disc *d, const cv_rule *r, int e0, int ne, const cv_partials *o, double *g,         \
      const int *colptr, double *Ax, double hscale, double *bad) {                                 \
    return batch_scalar(c, Q, d, r, e0, ne, o, g, colptr, Ax, hscale, bad);                        \
  }
/* clang-format off: a list of definitions, one per line */
KERNEL(kernel_2, 2, 2, CV_HOT)
KERNEL(kernel_3, 3, 3, CV_HOT)
KERNEL(kernel_4, 4, 4, CV_HOT)
KERNEL(kernel_5, 5, 5, CV_HOT)
KERNEL(kernel_2q, 2, 0, )
KERNEL(kernel_3q, 3, 0, )
KERNEL(kernel_4q, 4, 0, )
KERNEL(kernel_5q, 5, 0, )
KERNEL(kernel_6q, 6, 0, )
KERNEL(kernel_7q, 7, 0, )
KERNEL(kernel_8q, 8, 0, )
KERNEL(kernel_9q, 9, 0, )
/* clang-format on */
#undef KERNEL

static double batch_scalar_dispatch(const cv_disc *d, const cv_rule *r, int e0, int ne, int p,
                                    const cv_partials *o, double *g, const int *colptr, double *Ax,
                                    double hscale, double *bad) {
  /* constant points only up to degree 4: beyond, the fully unrolled kernel spills (p = 8
   * measured 1.5x slower than with the loop over points kept) */
  int P1 = p + 1, same = r->q == P1 && P1 <= 5;
  switch (P1) {
#define ARGS d, r, e0, ne, o, g, colptr, Ax, hscale, bad
  case 2: return same ? kernel_2(ARGS) : kernel_2q(ARGS);
  case 3: return same ? kernel_3(ARGS) : kernel_3q(ARGS);
  case 4: return same ? kernel_4(ARGS) : kernel_4q(ARGS);
  case 5: return same ? kernel_5(ARGS) : kernel_5q(ARGS);
  case 6: return kernel_6q(ARGS);
  case 7: return kernel_7q(ARGS);
  case 8: return kernel_8q(ARGS);
  case 9: return kernel_9q(ARGS);
#undef ARGS
  }
  return NAN; /* unreachable: 1 <= p <= 8 */
}

/* The general loops of (A-1)-(A-3) for n > 1 unknowns over the elements e0 .. e0+ne-1 of a
 * batch; out of line, so that the code a scalar solve runs stays compact (the first solve
 * in a process pays for every fresh page and cache line of code, docs/performance.md).
 * Returns the batch's part of S; *bad as in batch_scalar. */
/* GCC at -O2 vectorizes only loops whose trip count it knows to fit the vectors exactly;
 * the rows of below have any length (clang vectorizes them as they are). */
#if defined(__GNUC__) && !defined(__clang__)
#define CV_VECTORIZE __attribute__((optimize("vect-cost-model=cheap")))
#else
#define CV_VECTORIZE
#endif

/* Row a of a point's part of the element matrix, columns a .. nl-1 (see batch_general). */
static inline void k_row(double *restrict Ka, const double *restrict vy, const double *restrict vp,
                         double bl, double dl, int a, int nl) {
  for (int b = a; b < nl; b++) Ka[b] += bl * vy[b] + dl * vp[b];
}

static __attribute__((noinline)) CV_VECTORIZE double batch_general(cv_assembler *as,
                                                                   const cv_rule *r, int e0, int ne,
                                                                   int p, double *g,
                                                                   const int *colptr, double *Ax,
                                                                   double hscale, double *bad) {
  const cv_disc *d = as->disc;
  int n = d->n, P1 = p + 1, nl = P1 * n, q = r->q, m = ne * q;
  double Ssum = 0.0, chk = 0.0, *K = as->K;
  int *flp = as->fl;
  double *F = as->out.F, *gl = K + nl * nl, *V = gl + nl;
  const double *Fy = as->out.Fy, *Fp = as->out.Fp;
  const double *Fyy = as->out.Fyy, *Fyp = as->out.Fyp, *Fpp = as->out.Fpp;
  for (int el = 0; el < ne; el++) {
    int e = e0 + el;
    double h = d->xe[e + 1] - d->xe[e], J = 0.5 * h, rh = 2.0 / h;
    /* Free indices of the element's unknowns: a shift of the global ones except on the
     * two end elements (E-2); no integer division in the common case. */
    if (e > 0 && e < d->E - 1) {
      int base = cv_disc_elem_first(d, e), st = d->stride;
      for (int l = 0; l < P1; l++)
        for (int i = 0; i < n; i++) flp[l * n + i] = base + l * st + i;
    } else {
      for (int a = 0; a < nl; a++) flp[a] = cv_disc_fidx(d, cv_disc_enode(d, e) * n + a);
    }
    if (Ax) cv_dzero(K, (size_t)nl * nl);
    if (g) cv_dzero(gl, (size_t)nl);
    for (int k = 0; k < q; k++) {
      int idx = el * q + k;
      double wk = J * r->omega[k];
      const double *Bk = r->B + k * P1, *Dk = r->D + k * P1;
      Ssum += wk * F[idx];
      if (g) {
        for (int i = 0; i < n; i++) {
          double fy = wk * Fy[i * m + idx], fp = wk * rh * Fp[i * m + idx];
          for (int l = 0; l < P1; l++) gl[l * n + i] += fy * Bk[l] + fp * Dk[l];
        }
      }
      if (Ax) {
        /* Row a = (l, i) of the point's part of K is B_l Vy_i + D_l Vp_i over the columns
         * b = (r, j), with Vy_i[b] = yy_ij B_r + yp_ij D_r and Vp_i[b] = py_ij B_r + pp_ij
         * D_r: contiguous in b, and only b >= a (the scatter reads the upper triangle),
         * half the products of the loop over (i, j, l, r) and unit stride (n = 2, p = 8:
         * 3x faster, docs/performance.md). */
        for (int i = 0; i < n; i++) {
          double *vy = V + (size_t)i * 2 * nl, *vp = vy + nl;
          for (int j = 0; j < n; j++) {
            double yy = wk * Fyy[(i * n + j) * m + idx];
            double yp = wk * rh * Fyp[(i * n + j) * m + idx]; /* F_{y_i y'_j} */
            double py = wk * rh * Fyp[(j * n + i) * m + idx]; /* F_{y'_i y_j} */
            double pp = wk * rh * rh * Fpp[(i * n + j) * m + idx];
            for (int rr = 0; rr < P1; rr++) {
              vy[rr * n + j] = yy * Bk[rr] + yp * Dk[rr];
              vp[rr * n + j] = py * Bk[rr] + pp * Dk[rr];
            }
          }
        }
        for (int l = 0; l < P1; l++)
          for (int i = 0; i < n; i++) {
            int a = l * n + i;
            const double *vy = V + (size_t)i * 2 * nl, *vp = vy + nl;
            k_row(K + (size_t)a * nl, vy, vp, Bk[l], Dk[l], a, nl);
          }
      }
    }
    if (g)
      for (int a = 0; a < nl; a++) {
        chk += 0.0 * gl[a];
        if (flp[a] >= 0) g[flp[a]] += gl[a];
      }
    if (Ax) {
      /* Scatter the upper triangle; column c holds rows c+1-len(c) .. c (E-2). */
      for (int bcol = 0; bcol < nl; bcol++) {
        int fb = flp[bcol];
        if (fb < 0) continue;
        long c0 = colptr[fb], rs = fb + 1 - (colptr[fb + 1] - c0);
        for (int arow = 0; arow <= bcol; arow++) {
          int fa = flp[arow];
          chk += 0.0 * K[arow * nl + bcol];
          if (fa >= 0) Ax[c0 + fa - rs] += hscale * K[arow * nl + bcol];
        }
      }
    }
  }
  *bad += chk;
  return Ssum;
}

/* S_h = sum_e sum_k (h_e/2) w_k F(x_ek, y_ek, y'_ek)                         
 * dS_h/dY_{l,i} = sum (h/2) w_k (F_yi phi_l + F_y'i phi_l' (2/h))            
 * d2S_h/dY_{l,i}dY_{r,j} = sum (h/2) w_k (F_yiyj phi_l phi_r
 *     + F_yiy'j phi_l phi_r' (2/h) + F_yjy'i phi_l' phi_r (2/h) + F_y'iy'j phi_l' phi_r' (2/h)^2)
 *                                                                              (A-3)  */
cv_status cv_assemble(cv_assembler *as, cv_integrand_fn Fn, void *user, const double *Y, double *S,
                      double *g, const int *colptr, double *Ax, double hscale, int overwrite) {
  const cv_disc *d = as->disc;
  int n = d->n;
  if (d->herm) return cv_hermite_assemble(as, Fn, user, Y, S, g, colptr, Ax, hscale, overwrite);
  unsigned need = CVAR_NEED_F | (g ? CVAR_NEED_GRAD : 0u) | (Ax ? CVAR_NEED_HESS : 0u);
  double Ssum = 0.0, bad = 0.0;
  cv_status st;
  for (int e0 = 0, ne; e0 < d->E; e0 += ne) {
    cv_rule rule = cv_disc_rule(d, e0), *r = &rule;
    int p = cv_disc_edeg(d, e0), q = r->q;
    ne = cv_assembler_batch(d, e0, q);
    int m = ne * q;
    fill_points(as, Y, r, e0, ne, p);
    st = call_integrand(as, Fn, user, m, need);
    if (st) return st;
    if (overwrite) {
      /* Clear the columns of this batch's nodes not shared with the previous batch, just
       * before they are summed into: in cache, instead of a pass over all of g and Ax. */
      long J0 = cv_disc_enode(d, e0) + (e0 > 0), J1 = cv_disc_enode(d, e0 + ne);
      int cA = cv_disc_node_first(d, J0);
      int cB = J1 == d->nodes - 1 ? d->nu0 : cv_disc_node_first(d, J1 + 1);
      if (g) cv_dzero(g + cA, (size_t)(cB - cA));
      if (Ax) cv_dzero(Ax + colptr[cA], (size_t)(colptr[cB] - colptr[cA]));
    }
    if (n == 1)
      Ssum += batch_scalar_dispatch(d, r, e0, ne, p, &as->out, g, colptr, Ax, hscale, &bad);
    else
      Ssum += batch_general(as, r, e0, ne, p, g, colptr, Ax, hscale, &bad);
  }
  /* Every requested output enters S or an element's gradient or matrix multiplied by
   * weights and basis values, and NaN or Inf survives that (0 * Inf is NaN, Inf * 0 too),
   * so the element checks catch any non-finite output, including entries the callback
   * forgot (pre-filled with NaN). An entry that overflows only when elements are summed
   * shows as a non-finite pivot (cv_ldlt_factor). */
  *S = Ssum;
  if (!isfinite(Ssum) || !(bad == 0.0)) return CVAR_ENONFINITE;
  return CVAR_OK;
}
