/* src/core/cv_assemble.c — discrete action, its gradient and Hessian, theory (A-1)-(A-3).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "cv_hermite.h"
#include "cv_internal.h"

/* The points of the rule of d's highest degree (Gauss, Q-1): those whose rows of
 * batch_general keeps for one element; a rule with more (a singular end's, Q-2) takes the
 * untiled loop. (The reference elements of degrees the mesh does not use are not set.) */
static int max_points(const cv_disc *d) {
  int q = d->pe ? d->refs[d->p].q : d->ref.q;
  return q > 0 ? q : 1;
}

cv_status cv_assembler_init(cv_assembler *as, const cv_problem *p, const cv_disc *d) {
  /* A batch holds at most CV_BATCH points and never more than the mesh has: a small mesh's
   * buffers then share a page or two instead of one fresh page per output (the first
   * solve in a process pays a page fault for each, docs/performance.md). */
  long nq = cv_disc_num_qpoints(d);
  size_t n = (size_t)p->n, m = nq < 1 ? 1 : nq < CV_BATCH ? (size_t)nq : CV_BATCH;
  memset(as, 0, sizeof *as);
  as->prob = p;
  as->disc = d;
  size_t nl = (size_t)(d->p + 1) * n, ldk = (nl + 3) & ~(size_t)3;
  /* x, y, y', the integrand's outputs, and for n > 1 the element matrix (rows of ldk, a
   * multiple of 4, for the tiled kernel) and gradient, the element's free indices, the
   * rows of at every point of an element and the expanded basis tables
   * (batch_general), in one allocation (the scalar kernels keep their element sums in
   * registers): the first solve of a small problem touches fewer heap bytes */
  size_t qv = (size_t)max_points(d);
  as->qv = (int)qv;
  size_t nbuf = (2 + 4 * n + 3 * n * n) * m;
  size_t nK = n > 1 ? nl * ldk + ldk + 2 * n * ldk * qv + 2 * ldk * qv : 0;
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

/* Two unknowns at degrees 5-8 (the hp rounds' degrees, paths in the plane), out of line:
 * the code of a scalar solve stays as it was. */
static __attribute__((noinline)) void fill_points2(cv_assembler *as, const double *Y,
                                                   const cv_rule *r, int e0, int ne, int p) {
  switch (p) {
  case 5: fill_batch(2, 6, as, Y, r, e0, ne); return;
  case 6: fill_batch(2, 7, as, Y, r, e0, ne); return;
  case 7: fill_batch(2, 8, as, Y, r, e0, ne); return;
  default: fill_batch(2, 9, as, Y, r, e0, ne); return;
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
  if (d->n == 2 && p >= 5) {
    fill_points2(as, Y, r, e0, ne, p);
    return;
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
    /* scatter (E-2): gradient rows, and the upper triangle column by column; the element's
     * check in a sum of its own, added to chk once (one addition per element on the chain
     * that runs through the batch, not one per entry: a latency the elements waited on) */
    double ce = 0.0;
    if (g)
#pragma GCC unroll 9
      for (int l = 0; l < P1; l++) {
        ce += 0.0 * gacc[l];
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
          ce += 0.0 * Kacc[arow * P1 + bcol];
          if (fl[arow] >= 0) Ax[c0 + fl[arow] - rs] += hscale * Kacc[arow * P1 + bcol];
        }
      }
    chk += ce;
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

/* GCC at -O2 vectorizes only loops whose trip count it knows to fit the vectors exactly;
 * the rows of of batch_general's point-by-point loop have any length (clang
 * vectorizes them as they are). */
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

/* Four doubles, operated on as one: AVX registers where the CPU has them (the clone
 * below), pairs of SSE2 registers otherwise. No FMA in either: both clones round every
 * product and sum alike, and as the per-point loops of, (A-3) did (k_row). */
typedef double cv_v4 __attribute__((vector_size(32)));
#define CV_INLINE static inline __attribute__((always_inline))
#define V4(x)     ((cv_v4){(x), (x), (x), (x)})

/* One element's sums for batch_general: its terms added to S, its gradient gl and
 * matrix K (A-3, rows of ldk), from the integrand's outputs at its q points (index idx0 +
 * k in batches of m). With n = 2 the basis values are read expanded, Bx[k ldk + b] =
 * B_k,b/2 (zero past nl), so that a point's row of the gradient and of Vy_i, Vp_i is a
 * product of vectors; other n as the per-point loops. */
typedef struct {
  int n, P1, ldk, q, m, idx0;
  double J, rh;
  const double *omega, *B, *D, *Bx, *Dx;
  const double *F, *Fy, *Fp, *Fyy, *Fyp, *Fpp;
  double *gl, *V, *K; /* NULL gl: no gradient; NULL K: no matrix */
  double S, chk;
} elem_args;

/* Rows a0 = l0 n + i and (R = 2) a0 + n of K, columns c .. c + 4 C - 1: over the q points,
 * K_ab += B_kl vy_k[b] + D_kl vp_k[b] (A-3; the rows Vy_i, Vp_i of point k at Vi + k vs),
 * each point's term summed first as in k_row, in registers; *chk collects 0 times each. */
CV_INLINE void k_tile(const int R, const int C, double *restrict K, int ldk,
                      const double *restrict Vi, size_t vs, const double *restrict B,
                      const double *restrict D, int P1, int q, int l0, int a0, int n, int c,
                      cv_v4 *chk) {
  cv_v4 s[2][2] = {{{0}}};
  for (int k = 0; k < q; k++) {
    const double *vy = Vi + k * vs + c, *vp = vy + ldk;
    cv_v4 y[2], p[2];
    for (int cc = 0; cc < C; cc++) { /* unaligned loads */
      memcpy(&y[cc], vy + 4 * cc, sizeof y[cc]);
      memcpy(&p[cc], vp + 4 * cc, sizeof p[cc]);
    }
    for (int r = 0; r < R; r++) {
      cv_v4 b = V4(B[k * P1 + l0 + r]), d = V4(D[k * P1 + l0 + r]);
      for (int cc = 0; cc < C; cc++) s[r][cc] += b * y[cc] + d * p[cc];
    }
  }
  for (int r = 0; r < R; r++)
    for (int cc = 0; cc < C; cc++) {
      *chk += V4(0.0) * s[r][cc];
      memcpy(K + (size_t)(a0 + r * n) * ldk + c + 4 * cc, &s[r][cc], sizeof s[r][cc]);
    }
}

CV_INLINE void elem_body(elem_args *A) {
  const int n = A->n, P1 = A->P1, ldk = A->ldk, q = A->q, m = A->m;
  const double J = A->J, rh = A->rh;
  double *gl = A->gl, *V = A->V, *K = A->K, S = A->S; /* the batch's sum so far */
  size_t vs = (size_t)2 * n * ldk;
  cv_v4 chk = V4(0.0);
  if (gl)
    for (int b = 0; b < ldk; b++) gl[b] = 0.0;
  for (int k = 0; k < q; k++) {
    int idx = A->idx0 + k;
    double wk = J * A->omega[k];
    const double *Bk = A->B + k * P1, *Dk = A->D + k * P1;
    S += wk * A->F[idx];
    if (n == 2) {
      const double *bx = A->Bx + (size_t)k * ldk, *dx = A->Dx + (size_t)k * ldk;
      if (gl) {
        double fy0 = wk * A->Fy[idx], fy1 = wk * A->Fy[m + idx];
        double fp0 = wk * rh * A->Fp[idx], fp1 = wk * rh * A->Fp[m + idx];
        cv_v4 fy = {fy0, fy1, fy0, fy1}, fp = {fp0, fp1, fp0, fp1};
        for (int c = 0; c < ldk; c += 4) {
          cv_v4 gv, bv, dv;
          memcpy(&gv, gl + c, sizeof gv);
          memcpy(&bv, bx + c, sizeof bv);
          memcpy(&dv, dx + c, sizeof dv);
          gv += fy * bv + fp * dv;
          memcpy(gl + c, &gv, sizeof gv);
        }
      }
      if (K)
        for (int i = 0; i < 2; i++) {
          double *vy = V + k * vs + (size_t)i * 2 * ldk, *vp = vy + ldk, w[4][2];
          for (int j = 0; j < 2; j++) {
            w[0][j] = wk * A->Fyy[(i * 2 + j) * m + idx];
            w[1][j] = wk * rh * A->Fyp[(i * 2 + j) * m + idx]; /* F_{y_i y'_j} */
            w[2][j] = wk * rh * A->Fyp[(j * 2 + i) * m + idx]; /* F_{y'_i y_j} */
            w[3][j] = wk * rh * rh * A->Fpp[(i * 2 + j) * m + idx];
          }
          cv_v4 yy = {w[0][0], w[0][1], w[0][0], w[0][1]},
                yp = {w[1][0], w[1][1], w[1][0], w[1][1]};
          cv_v4 py = {w[2][0], w[2][1], w[2][0], w[2][1]},
                pp = {w[3][0], w[3][1], w[3][0], w[3][1]};
          for (int c = 0; c < ldk; c += 4) {
            cv_v4 bv, dv, ry, rp;
            memcpy(&bv, bx + c, sizeof bv);
            memcpy(&dv, dx + c, sizeof dv);
            ry = yy * bv + yp * dv;
            rp = py * bv + pp * dv;
            memcpy(vy + c, &ry, sizeof ry);
            memcpy(vp + c, &rp, sizeof rp);
          }
        }
      continue;
    }
    if (gl)
      for (int i = 0; i < n; i++) {
        double fy = wk * A->Fy[i * m + idx], fp = wk * rh * A->Fp[i * m + idx];
        for (int l = 0; l < P1; l++) gl[l * n + i] += fy * Bk[l] + fp * Dk[l];
      }
    if (K)
      for (int i = 0; i < n; i++) {
        double *vy = V + k * vs + (size_t)i * 2 * ldk, *vp = vy + ldk;
        cv_v4 zero = V4(0.0); /* the columns past nl (ldk - 4 < nl) */
        memcpy(vy + ldk - 4, &zero, sizeof zero);
        memcpy(vp + ldk - 4, &zero, sizeof zero);
        for (int j = 0; j < n; j++) {
          double yy = wk * A->Fyy[(i * n + j) * m + idx];
          double yp = wk * rh * A->Fyp[(i * n + j) * m + idx]; /* F_{y_i y'_j} */
          double py = wk * rh * A->Fyp[(j * n + i) * m + idx]; /* F_{y'_i y_j} */
          double pp = wk * rh * rh * A->Fpp[(i * n + j) * m + idx];
          for (int rr = 0; rr < P1; rr++) {
            vy[rr * n + j] = yy * Bk[rr] + yp * Dk[rr];
            vp[rr * n + j] = py * Bk[rr] + pp * Dk[rr];
          }
        }
      }
  }
  if (gl)
    for (int c = 0; c < ldk; c += 4) {
      cv_v4 gv;
      memcpy(&gv, gl + c, sizeof gv);
      chk += V4(0.0) * gv;
    }
  /* The matrix, rows a = l n + i two l at a time, columns from a's multiple of 4 below it
   * (the scatter reads b >= a only; the entries left of a are the products of the same
   * finite rows, so their check adds nothing but overflow) */
  if (K)
    for (int i = 0; i < n; i++) {
      const double *Vi = V + (size_t)i * 2 * ldk, *B = A->B, *D = A->D;
      for (int l0 = 0; l0 < P1; l0 += 2) {
        int a0 = l0 * n + i, c = a0 & ~3;
        if (l0 + 1 < P1) {
          for (; c + 8 <= ldk; c += 8)
            k_tile(2, 2, K, ldk, Vi, vs, B, D, P1, q, l0, a0, n, c, &chk);
          if (c < ldk) k_tile(2, 1, K, ldk, Vi, vs, B, D, P1, q, l0, a0, n, c, &chk);
        } else {
          for (; c + 8 <= ldk; c += 8)
            k_tile(1, 2, K, ldk, Vi, vs, B, D, P1, q, l0, a0, n, c, &chk);
          if (c < ldk) k_tile(1, 1, K, ldk, Vi, vs, B, D, P1, q, l0, a0, n, c, &chk);
        }
      }
    }
  A->S = S;
  A->chk = chk[0] + chk[1] + chk[2] + chk[3];
}

static void elem_base(elem_args *A) { elem_body(A); }
#if defined(__x86_64__) && defined(__GNUC__)
#define CV_AVX2_CLONE 1
static __attribute__((target("avx2"))) void elem_avx2(elem_args *A) { elem_body(A); }
#endif

/* The tiled element sums, AVX where the CPU has it (same results, theory A-3a). */
static void elem_sums(elem_args *A) {
#ifdef CV_AVX2_CLONE
  if (__builtin_cpu_supports("avx2")) {
    elem_avx2(A);
    return;
  }
#endif
  elem_base(A);
}

/* The scatter of one element's gradient and upper triangle into g and Ax (E-2): column c
 * of Ax holds rows c + 1 - len(c) .. c. An interior element without multipliers (the free
 * indices base + a) adds whole runs of a column. */
static void scatter(const int *flp, int nl, int ldk, int interior, const double *gl,
                    const double *K, double *g, const int *colptr, double *Ax, double hscale) {
  if (g)
    for (int a = 0; a < nl; a++)
      if (flp[a] >= 0) g[flp[a]] += gl[a];
  if (!Ax) return;
  for (int bcol = 0; bcol < nl; bcol++) {
    int fb = flp[bcol];
    if (fb < 0) continue;
    long c0 = colptr[fb], rs = fb + 1 - (colptr[fb + 1] - c0);
    if (interior && hscale == 1.0) { /* the product by 1 is exact: left out */
      double *col = Ax + c0 + flp[0] - rs;
      for (int arow = 0; arow <= bcol; arow++) col[arow] += K[(size_t)arow * ldk + bcol];
      continue;
    }
    if (interior) {
      double *col = Ax + c0 + flp[0] - rs;
      for (int arow = 0; arow <= bcol; arow++) col[arow] += hscale * K[(size_t)arow * ldk + bcol];
      continue;
    }
    for (int arow = 0; arow <= bcol; arow++) {
      int fa = flp[arow];
      if (fa >= 0) Ax[c0 + fa - rs] += hscale * K[(size_t)arow * ldk + bcol];
    }
  }
}

/* The general loops of (A-1)-(A-3) for n > 1 unknowns over the elements e0 .. e0+ne-1 of a
 * batch; out of line, so that the code a scalar solve runs stays compact (the first solve
 * in a process pays for every fresh page and cache line of code, docs/performance.md).
 * Row a = (l, i) of a point's part of K is B_l Vy_i + D_l Vp_i over the columns b = (r, j),
 * with Vy_i[b] = yy_ij B_r + yp_ij D_r and Vp_i[b] = py_ij B_r + pp_ij D_r: contiguous in
 * b, and only b >= a (the scatter reads the upper triangle), half the products of the loop
 * over (i, j, l, r) and unit stride (n = 2, p = 8: 3x faster, docs/performance.md). The rows
 * of all the element's points are made first and K summed over them a tile of rows and
 * columns at a time in registers (elem_sums, theory A-3a: n = 2, p = 8 another 3x fewer
 * instructions, docs/performance.md); a rule with more points than the buffer holds (a
 * singular end's) goes point by point.
 * Returns the batch's part of S; *bad as in batch_scalar. */
static __attribute__((noinline)) CV_VECTORIZE double batch_general(cv_assembler *as,
                                                                   const cv_rule *r, int e0, int ne,
                                                                   int p, double *g,
                                                                   const int *colptr, double *Ax,
                                                                   double hscale, double *bad) {
  const cv_disc *d = as->disc;
  int n = d->n, P1 = p + 1, nl = P1 * n, ldk = (nl + 3) & ~3, q = r->q, m = ne * q;
  double Ssum = 0.0, chk = 0.0, *K = as->K;
  int *flp = as->fl;
  double *gl = K + (size_t)nl * ldk, *V = gl + ldk, *Bx = V + (size_t)2 * n * ldk * as->qv;
  double *Dx = Bx + (size_t)ldk * as->qv;
  elem_args A = {n,           P1,
                 ldk,         q,
                 m,           0,
                 0.0,         0.0,
                 r->omega,    r->B,
                 r->D,        Bx,
                 Dx,          as->out.F,
                 as->out.Fy,  as->out.Fp,
                 as->out.Fyy, as->out.Fyp,
                 as->out.Fpp, g ? gl : NULL,
                 V,           Ax ? K : NULL,
                 0.0,         0.0};
  int tiled = q <= as->qv;
  if (tiled && n == 2)
    for (int k = 0; k < q; k++)
      for (int b = 0; b < ldk; b++) {
        Bx[k * ldk + b] = b < nl ? r->B[k * P1 + b / 2] : 0.0;
        Dx[k * ldk + b] = b < nl ? r->D[k * P1 + b / 2] : 0.0;
      }
  for (int el = 0; el < ne; el++) {
    int e = e0 + el, interior = e > 0 && e < d->E - 1 && d->stride == n;
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
    if (tiled) {
      A.idx0 = el * q, A.J = J, A.rh = rh, A.S = Ssum;
      elem_sums(&A);
      Ssum = A.S;
      chk += A.chk;
      scatter(flp, nl, ldk, interior, gl, K, g, colptr, Ax, hscale);
      continue;
    }
    if (Ax) cv_dzero(K, (size_t)nl * ldk);
    if (g) cv_dzero(gl, (size_t)nl);
    for (int k = 0; k < q; k++) {
      int idx = el * q + k;
      double wk = J * r->omega[k];
      const double *Bk = r->B + k * P1, *Dk = r->D + k * P1;
      Ssum += wk * as->out.F[idx];
      if (g)
        for (int i = 0; i < n; i++) {
          double fy = wk * as->out.Fy[i * m + idx], fp = wk * rh * as->out.Fp[i * m + idx];
          for (int l = 0; l < P1; l++) gl[l * n + i] += fy * Bk[l] + fp * Dk[l];
        }
      if (!Ax) continue;
      for (int i = 0; i < n; i++) {
        double *vy = V + (size_t)i * 2 * ldk, *vp = vy + ldk;
        for (int j = 0; j < n; j++) {
          double yy = wk * as->out.Fyy[(i * n + j) * m + idx];
          double yp = wk * rh * as->out.Fyp[(i * n + j) * m + idx]; /* F_{y_i y'_j} */
          double py = wk * rh * as->out.Fyp[(j * n + i) * m + idx]; /* F_{y'_i y_j} */
          double pp = wk * rh * rh * as->out.Fpp[(i * n + j) * m + idx];
          for (int rr = 0; rr < P1; rr++) {
            vy[rr * n + j] = yy * Bk[rr] + yp * Dk[rr];
            vp[rr * n + j] = py * Bk[rr] + pp * Dk[rr];
          }
        }
      }
      for (int l = 0; l < P1; l++)
        for (int i = 0; i < n; i++) {
          const double *vy = V + (size_t)i * 2 * ldk, *vp = vy + ldk;
          k_row(K + (size_t)(l * n + i) * ldk, vy, vp, Bk[l], Dk[l], l * n + i, nl);
        }
    }
    for (int a = 0; g && a < nl; a++) chk += 0.0 * gl[a];
    for (int b = 0; Ax && b < nl; b++)
      for (int a = 0; a <= b; a++) chk += 0.0 * K[(size_t)a * ldk + b];
    scatter(flp, nl, ldk, interior, gl, K, g, colptr, Ax, hscale);
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
