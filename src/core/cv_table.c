/* src/core/cv_table.c — tabulated functions: the tensor-product not-a-knot cubic spline
 * through a rectilinear grid of values in 1, 2 or 3 coordinates, with exact partial
 * derivatives (theory TB-1 .. TB-4). SPDX-License-Identifier: MIT
 *
 * Representation (TB-2): per cell, the 1-D cubic on [x_i, x_i+1] is fixed by the values
 * f_i, f_i+1 and the second derivatives M_i, M_i+1. In d coordinates the tensor product
 * needs, at every grid point, the 2^d arrays G[mask] = (prod over the axes k in mask of
 * d^2/du_k^2) s: G[0] = f, G[1] = s_uu, G[2] = s_vv, G[3] = s_uuvv, ... Each array is one
 * pass of the per-axis not-a-knot solve (TB-3) over the array one bit below it, so memory
 * and set-up time are linear in the grid (2^d doubles per value). */
#include <math.h>
#include <stdatomic.h>
#include <string.h>

#include "cv_internal.h"

typedef struct {
  int n;
  double *x;     /* coordinates, strictly increasing */
  double *h;     /* h[i] = x[i+1] - x[i] */
  double *ih;    /* 1 / h[i] */
  double *lo;    /* sub-diagonal of the reduced system for M_1 .. M_n-2 (TB-3) */
  double *c, *r; /* its Thomas factors: c = super-diagonal / pivot, r = 1 / pivot */
  int uniform;   /* equal spacing within round-off: the cell is found in O(1) */
  double h0, ih0;
} tb_axis;

struct cv_table {
  atomic_int refs;
  int dim;
  size_t size;      /* number of grid values */
  size_t stride[3]; /* index of (i0, i1, i2) = i0*stride[0] + i1*stride[1] + i2 */
  tb_axis ax[3];
  double *G[8]; /* G[mask], each `size` doubles */
};

static void axis_free(tb_axis *a) {
  cv_free(a->x);
  cv_free(a->h);
  cv_free(a->ih);
  cv_free(a->lo);
  cv_free(a->c);
  cv_free(a->r);
}

/* The reduced tridiagonal system of TB-3 for M_1 .. M_n-2 after the not-a-knot rows
 * eliminate M_0 and M_n-1; factor it once (forward sweep of Thomas's algorithm on the
 * matrix): c[i] = super-diagonal / pivot, r[i] = 1 / pivot, for the rows i = 1 .. n-2. */
static int axis_init(tb_axis *a, int n, const double *x, char *msg, size_t len, int axis) {
  a->n = n;
  a->x = cv_malloc((size_t)n * sizeof *a->x);
  a->h = cv_malloc((size_t)n * sizeof *a->h);
  a->ih = cv_malloc((size_t)n * sizeof *a->ih);
  a->c = cv_malloc((size_t)n * sizeof *a->c);
  a->r = cv_malloc((size_t)n * sizeof *a->r);
  a->lo = cv_malloc((size_t)n * sizeof *a->lo);
  if (!a->x || !a->h || !a->ih || !a->c || !a->r || !a->lo) {
    cv_set_msg(msg, len, "out of memory");
    return -1;
  }
  for (int i = 0; i < n; i++) {
    if (!isfinite(x[i])) {
      cv_set_msg(msg, len, "coordinate %d: value %d is not finite", axis + 1, i + 1);
      return -1;
    }
    a->x[i] = x[i];
    if (i > 0 && !(x[i] > x[i - 1])) {
      cv_set_msg(msg, len, "coordinate %d: the values must increase strictly (%.17g after %.17g)",
                 axis + 1, x[i], x[i - 1]);
      return -1;
    }
  }
  for (int i = 0; i + 1 < n; i++) a->h[i] = x[i + 1] - x[i];
  a->h[n - 1] = a->h[n - 2];
  for (int i = 0; i < n; i++) a->ih[i] = 1.0 / a->h[i];
  double span = x[n - 1] - x[0];
  a->h0 = span / (n - 1);
  a->ih0 = 1.0 / a->h0;
  a->uniform = 1;
  for (int i = 0; i + 1 < n; i++)
    if (fabs(a->h[i] - a->h0) > 1e-12 * span) a->uniform = 0;
  /* Rows 1 .. n-2: lower l_i, diagonal d_i, upper u_i (TB-3). */
  const double *h = a->h;
  double prev_c = 0.0;
  for (int i = 1; i <= n - 2; i++) {
    double l = h[i - 1], dg = 2.0 * (h[i - 1] + h[i]), u = h[i];
    if (i == 1) { /* M_0 = ((h0 + h1) M_1 - h0 M_2) / h1 substituted */
      dg += h[0] * (h[0] + h[1]) / h[1];
      u -= h[0] * h[0] / h[1];
      l = 0.0;
    }
    if (i == n - 2) { /* M_n-1 = ((h_n-2 + h_n-3) M_n-2 - h_n-2 M_n-3) / h_n-3 */
      double hb = h[n - 2], ha = h[n - 3];
      dg += hb * (hb + ha) / ha;
      l -= hb * hb / ha;
      u = 0.0;
    }
    a->lo[i] = l;
    double piv = dg - l * prev_c;
    a->r[i] = 1.0 / piv;
    a->c[i] = u * a->r[i];
    prev_c = a->c[i];
  }
  return 0;
}

/* dst = second derivatives along one axis of the splines through src (TB-3), for every
 * line along that axis: element (o, i, k) at (o*n + i)*inner + k. The sweeps run over the
 * contiguous index k innermost, so strided axes stay cache friendly; a long k range is cut
 * into blocks of columns whose n rows fit in the cache, so the back substitution and the
 * ends re-read the forward sweep's output from the cache, not from memory. */
static void axis_solve(const tb_axis *a, const double *src, double *dst, size_t outer,
                       size_t inner) {
  const int n = a->n;
  const double *h = a->h;
  /* about 256 KiB of src and dst rows per block (at least 64 columns) */
  size_t blk = (size_t)16384 / (size_t)n;
  if (blk < 64) blk = 64;
  for (size_t o = 0; o < outer; o++)
    for (size_t k0 = 0; k0 < inner; k0 += blk) {
      const size_t kn = inner - k0 < blk ? inner - k0 : blk;
      const double *f = src + o * (size_t)n * inner + k0;
      double *M = dst + o * (size_t)n * inner + k0;
      /* forward sweep: M_i = (rhs_i - l_i M_i-1) * r_i (rows of one array never overlap,
       * hence restrict: the loops over k vectorise) */
      for (int i = 1; i <= n - 2; i++) {
        const double lr = i == 1 ? 0.0 : a->lo[i]; /* row 1 has no sub-diagonal */
        const double ia = a->ih[i - 1], ib = a->ih[i], r = a->r[i];
        const double *restrict fm = f + (size_t)(i - 1) * inner;
        const double *restrict f0 = fm + inner, *restrict fp = f0 + inner;
        double *restrict Mi = M + (size_t)i * inner;
        const double *restrict Mp = i == 1 ? f0 : Mi - inner; /* row 0 of M is not read */
        for (size_t k = 0; k < kn; k++) {
          double rhs = 6.0 * ((fp[k] - f0[k]) * ib - (f0[k] - fm[k]) * ia);
          Mi[k] = (rhs - lr * Mp[k]) * r;
        }
      }
      /* back substitution: M_i -= c_i M_i+1 */
      for (int i = n - 3; i >= 1; i--) {
        const double c = a->c[i];
        double *restrict Mi = M + (size_t)i * inner;
        const double *restrict Mn = Mi + inner;
        for (size_t k = 0; k < kn; k++) Mi[k] -= c * Mn[k];
      }
      /* the not-a-knot ends (TB-3) */
      double *M0 = M, *M1 = M + inner, *M2 = M + 2 * inner;
      double *Me = M + (size_t)(n - 1) * inner, *Ma = Me - inner, *Mb = Ma - inner;
      double h0 = h[0], h1 = h[1], hb = h[n - 2], ha = h[n - 3];
      for (size_t k = 0; k < kn; k++) {
        M0[k] = ((h0 + h1) * M1[k] - h0 * M2[k]) / h1;
        Me[k] = ((hb + ha) * Ma[k] - hb * Mb[k]) / ha;
      }
    }
}

static cv_table *table_build(int dim, const int *n, const double *const *coords,
                             const double *values, double *owned, cv_status *why, char *msg,
                             size_t len);

cv_table *cv_table_new(int dim, const int *n, const double *const *coords, const double *values,
                       cv_status *why) {
  return cv_table_new_msg(dim, n, coords, values, why, NULL, 0);
}

cv_table *cv_table_new_msg(int dim, const int *n, const double *const *coords, const double *values,
                           cv_status *why, char *msg, size_t len) {
  return table_build(dim, n, coords, values, NULL, why, msg, len);
}

cv_table *cv_table_new_owned(int dim, const int *n, const double *const *coords, double *values,
                             cv_status *why, char *msg, size_t len) {
  return table_build(dim, n, coords, NULL, values, why, msg, len);
}

/* The common body: the values are copied from `values`, or `owned` (cv_malloc'ed, in
 * grid order) becomes G[0] itself, no copy; `owned` is released on every failure. */
static cv_table *table_build(int dim, const int *n, const double *const *coords,
                             const double *values, double *owned, cv_status *why, char *msg,
                             size_t len) {
  cv_status st = CVAR_EINVAL;
  cv_table *t = NULL;
  if (msg && len) msg[0] = 0;
  if (owned) values = owned;
  if (dim < 1 || dim > 3 || !n || !coords || !values) {
    cv_set_msg(msg, len, "a table needs 1, 2 or 3 coordinates, their values and the data");
    goto fail;
  }
  size_t size = 1;
  for (int k = 0; k < dim; k++) {
    if (n[k] < 4) {
      cv_set_msg(msg, len, "coordinate %d has %d value%s; a cubic spline needs at least 4", k + 1,
                 n[k], n[k] == 1 ? "" : "s");
      goto fail;
    }
    if (!coords[k]) goto fail;
    if (size > ((size_t)1 << 40) / (size_t)n[k]) {
      cv_set_msg(msg, len, "the grid is too large");
      goto fail;
    }
    size *= (size_t)n[k];
  }
  t = cv_calloc(1, sizeof *t);
  if (!t) goto nomem;
  atomic_init(&t->refs, 1);
  t->dim = dim;
  t->size = size;
  for (int k = 0; k < dim; k++)
    if (axis_init(&t->ax[k], n[k], coords[k], msg, len, k) != 0) {
      if (!t->ax[k].x || !t->ax[k].h || !t->ax[k].ih || !t->ax[k].c || !t->ax[k].r || !t->ax[k].lo)
        goto nomem;
      goto fail;
    }
  for (size_t i = 0; i < size; i++)
    if (!isfinite(values[i])) {
      cv_set_msg(msg, len, "value %zu is not finite", i + 1);
      goto fail;
    }
  t->stride[dim - 1] = 1;
  for (int k = dim - 2; k >= 0; k--) t->stride[k] = t->stride[k + 1] * (size_t)n[k + 1];
  for (int mask = 0; mask < (1 << dim); mask++) {
    if (mask == 0 && owned) {
      t->G[0] = owned;
      owned = NULL;
      continue;
    }
    t->G[mask] = cv_malloc(size * sizeof(double));
    if (!t->G[mask]) goto nomem;
    if (mask == 0) {
      memcpy(t->G[0], values, size * sizeof(double));
      continue;
    }
    /* the lowest axis in mask: G[mask] from G[mask without it]. The axis with the longest
     * contiguous lines (the first) then does most of the 2^d - 1 solves; the order does
     * not matter otherwise, the per-axis operators commute (TB-2). */
    int k = 0;
    while (!(mask & (1 << k))) k++;
    size_t inner = t->stride[k], outer = size / (inner * (size_t)n[k]);
    axis_solve(&t->ax[k], t->G[mask & ~(1 << k)], t->G[mask], outer, inner);
  }
  if (why) *why = CVAR_OK;
  return t;
nomem:
  st = CVAR_ENOMEM;
  cv_set_msg(msg, len, "out of memory");
fail:
  cv_free(owned);
  cv_table_free(t);
  if (why) *why = st;
  return NULL;
}

cv_table *cv_table_ref(cv_table *t) {
  if (t) atomic_fetch_add(&t->refs, 1);
  return t;
}

void cv_table_free(cv_table *t) {
  if (!t || atomic_fetch_sub(&t->refs, 1) > 1) return;
  for (int k = 0; k < 3; k++) axis_free(&t->ax[k]);
  for (int m = 0; m < 8; m++) cv_free(t->G[m]);
  cv_free(t);
}

int cv_table_get_dim(const cv_table *t) { return t ? t->dim : 0; }

cv_status cv_table_get_range(const cv_table *t, int k, double *lo, double *hi) {
  if (!t || k < 0 || k >= t->dim) return CVAR_EINVAL;
  if (lo) *lo = t->ax[k].x[0];
  if (hi) *hi = t->ax[k].x[t->ax[k].n - 1];
  return CVAR_OK;
}

/* The cell of u on one axis: O(1) on a uniform grid, bisection otherwise (TB-4). -1 when u
 * is outside [x_0, x_n-1] (or NaN). */
static int find_cell(const tb_axis *a, double u) {
  const double *x = a->x;
  int n = a->n;
  if (!(u >= x[0] && u <= x[n - 1])) return -1;
  int i;
  if (a->uniform) {
    double s = (u - x[0]) * a->ih0;
    i = (int)s;
    if (i > n - 2) i = n - 2;
    /* round-off in s: step to the cell that really holds u */
    if (i > 0 && u < x[i])
      i--;
    else if (i < n - 2 && u >= x[i + 1])
      i++;
    return i;
  }
  int lo = 0, hi = n - 1; /* x[lo] <= u <= x[hi] */
  while (hi - lo > 1) {
    int mid = lo + (hi - lo) / 2;
    if (u < x[mid])
      hi = mid;
    else
      lo = mid;
  }
  return lo;
}

/* Weights of f_i, f_i+1, M_i, M_i+1 in the derivative of order o of the cubic on the cell
 * (TB-1), with t = (u - x_i) / h. */
static void weights(int o, double t, double h, double w[4]) {
  double s = 1.0 - t;
  switch (o) {
  case 0:
    w[0] = s, w[1] = t;
    w[2] = (s * s * s - s) * h * h / 6.0, w[3] = (t * t * t - t) * h * h / 6.0;
    break;
  case 1:
    w[0] = -1.0 / h, w[1] = 1.0 / h;
    w[2] = -(3.0 * s * s - 1.0) * h / 6.0, w[3] = (3.0 * t * t - 1.0) * h / 6.0;
    break;
  case 2: w[0] = 0.0, w[1] = 0.0, w[2] = s, w[3] = t; break;
  case 3: w[0] = 0.0, w[1] = 0.0, w[2] = -1.0 / h, w[3] = 1.0 / h; break;
  default: w[0] = w[1] = w[2] = w[3] = 0.0;
  }
}

/* The 4^d coefficients of the cell at `base` (dim 2 or 3), c[a_0 .. a_d-1] with a_k = 2 *
 * (second derivative along k) + (corner along k), the last axis fastest: the order of the
 * weights of TB-1. The last axis has stride 1, so each corner pair is adjacent. */
static void gather(const cv_table *t, size_t base, double *c) {
  const size_t s0 = t->stride[0], s1 = t->dim == 3 ? t->stride[1] : 0;
  if (t->dim == 2) {
    for (int mask = 0; mask < 4; mask++) {
      const double *G = t->G[mask] + base;
      int m0 = 2 * (mask & 1), m1 = mask & 2;
      for (int c0 = 0; c0 < 2; c0++) {
        const double *g = G + c0 * s0;
        double *d = c + 4 * (m0 + c0) + m1;
        d[0] = g[0], d[1] = g[1];
      }
    }
    return;
  }
  for (int mask = 0; mask < 8; mask++) {
    const double *G = t->G[mask] + base;
    int m0 = 2 * (mask & 1), m1 = mask & 2, m2 = (mask >> 1) & 2;
    for (int c0 = 0; c0 < 2; c0++)
      for (int c1 = 0; c1 < 2; c1++) {
        const double *g = G + c0 * s0 + c1 * s1;
        double *d = c + 16 * (m0 + c0) + 4 * (m1 + c1) + m2;
        d[0] = g[0], d[1] = g[1];
      }
  }
}

/* sum of w[a] r[a * stride] over a = 0..3 */
static inline double dot4(const double *w, const double *r, int stride) {
  return w[0] * r[0] + w[1] * r[stride] + w[2] * r[2 * stride] + w[3] * r[3 * stride];
}

/* TB-2 for several derivative orders at one point: the cell is found and the 4^d
 * coefficients (values and second-derivative arrays at the cell's corners) gathered once;
 * each order is then a contraction with per-axis weights, the first axis first. The
 * weights of each axis and order, and the contractions over the first axis (per order
 * along it) and over the first two (per pair of orders), are computed once and shared by
 * the orders that begin alike: the partials of an integrand v(x, y, z) up to the second
 * in y and z are all of order 0 in x, and six of them cost one contraction over x, three
 * over y and six over z instead of six of each. */
int cv_table_eval_multi(const cv_table *t, const double *u, int nord, const int (*ord)[3],
                        double *out) {
  int dim = t->dim;
  size_t base = 0;
  double tt[3] = {0, 0, 0}, hh[3] = {1, 1, 1};
  for (int k = 0; k < dim; k++) {
    const tb_axis *a = &t->ax[k];
    int i = find_cell(a, u[k]);
    if (i < 0) {
      for (int j = 0; j < nord; j++) out[j] = NAN;
      return k + 1;
    }
    hh[k] = a->h[i];
    tt[k] = (u[k] - a->x[i]) / hh[k];
    base += (size_t)i * t->stride[k];
  }
  double c[64];
  if (dim == 1) {
    c[0] = t->G[0][base], c[1] = t->G[0][base + 1];
    c[2] = t->G[1][base], c[3] = t->G[1][base + 1];
    for (int j = 0; j < nord; j++) {
      double w[4];
      weights(ord ? ord[j][0] : 0, tt[0], hh[0], w);
      out[j] = dot4(w, c, 1);
    }
    return 0;
  }
  gather(t, base, c);
  /* w[k][o]: the weights of axis k for order o (0..3; a higher order is zero), computed
   * when first asked for (bit o of wset[k]); c1[o0]: c contracted over axis 0 with order
   * o0 (4^(d-1) values); c2[4 o0 + o1]: over axes 0 and 1 (dim 3, 4 values) */
  double w[3][4][4], c1[4][16], c2[16][4];
  unsigned wset[3] = {0, 0, 0}, c1set = 0, c2set = 0;
  int inner = dim == 3 ? 16 : 4;
  for (int j = 0; j < nord; j++) {
    int o[3] = {0, 0, 0}, zero = 0;
    for (int k = 0; k < dim; k++) {
      o[k] = ord ? ord[j][k] : 0;
      if (o[k] < 0 || o[k] > 3) {
        zero = 1;
        break;
      }
      if (!(wset[k] >> o[k] & 1u)) {
        weights(o[k], tt[k], hh[k], w[k][o[k]]);
        wset[k] |= 1u << o[k];
      }
    }
    if (zero) {
      out[j] = 0.0;
      continue;
    }
    if (!(c1set >> o[0] & 1u)) {
      for (int q = 0; q < inner; q++) c1[o[0]][q] = dot4(w[0][o[0]], c + q, inner);
      c1set |= 1u << o[0];
    }
    if (dim == 2) {
      out[j] = dot4(w[1][o[1]], c1[o[0]], 1);
      continue;
    }
    int key = 4 * o[0] + o[1];
    if (!(c2set >> key & 1u)) {
      for (int r = 0; r < 4; r++) c2[key][r] = dot4(w[1][o[1]], c1[o[0]] + r, 4);
      c2set |= 1u << key;
    }
    out[j] = dot4(w[2][o[2]], c2[key], 1);
  }
  return 0;
}

int cv_table_eval(const cv_table *t, const double *u, const int *order, double *value) {
  if (!t || !u || !value) return -1;
  int o[1][3] = {{0, 0, 0}};
  for (int k = 0; k < t->dim && order; k++) o[0][k] = order[k];
  return cv_table_eval_multi(t, u, 1, (const int(*)[3])o, value);
}
