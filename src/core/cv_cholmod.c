/* src/core/cv_cholmod.c — sparse symmetric LDL^T with CHOLMOD: analysis once, numeric
 * refactorisation per Newton step, inertia from the pivots. The only file with cholmod.h.
 * SPDX-License-Identifier: MIT */
#include <limits.h>
#include <pthread.h>
#include <math.h>
#include <string.h>

#include <cholmod.h>

#include "cv_internal.h"

struct cv_ldlt {
  /* CHOLMOD's state (2.6 kB), allocated only for systems above cv_ldlt_skyline_max: a
   * small solve's heap then fits in fewer pages (the first solve in a process pays a
   * page fault per fresh page, docs/performance.md) */
  cholmod_common *c;
  cholmod_sparse *A;
  cholmod_factor *L;
  long n;
  pthread_t th; /* the symbolic analysis, started by cv_ldlt_new on large systems */
  int running;  /* th has to be joined */
  int analysed; /* cholmod_analyze has run (L->L set, or NULL on its failure) */
  /* Small systems: the skyline LDL^T of this file instead (theory N-7); then c, A and L
   * are unused and the matrix, its factor and the pivots live here. */
  int sky;
  int *colp;      /* column pointers of the envelope (A and U share them) */
  double *ax, *u; /* A, and U = L^T with D(j) in place of U(j,j), column by column */
  long minor;     /* first zero pivot, n if none */
  long mono;      /* columns 0 .. mono - 1 have nondecreasing first rows */
  int tri;        /* every column has at most 2 entries: a tridiagonal matrix; 2 when
                   * every column but the first has exactly 2 (column j at 2j - 1, 2j) */
};

/* Up to this many unknowns the skyline factor is used (tests may lower it to 0 to
 * compare with CHOLMOD). Above it CHOLMOD: its analysis is paid once per mesh and its
 * numeric factor is as fast (docs/performance.md). */
int cv_ldlt_skyline_max = 512;
/* Above that, the skyline factor is still used when the envelope is narrow — at most this
 * many entries per column (degree 1 with one or two unknowns, degree 2 with one; theory
 * N-7): its factor is then the Thomas algorithm's work, while CHOLMOD's analysis and
 * factor allocation were a third of a degree-1 solve of 10^6 elements
 * (docs/performance.md). Tests set it to 0 to compare with CHOLMOD. */
int cv_ldlt_skyline_band = 4;

/* Below this many unknowns the analysis takes under ~3 ms and a thread is not worth it. */
#define ASYNC_ANALYSIS_MIN 50000

/* The analysis reads only the pattern of A (A->p, A->i; its transposes are made without
 * values), which is final once cv_ldlt_new returns; the caller meanwhile fills A->x,
 * evaluates the integrand and so on, and the first cv_ldlt_factor joins. No user callback
 * runs on this thread. */
static void *analyze_main(void *arg) {
  cv_ldlt *L = arg;
  L->L = cholmod_analyze(L->A, L->c);
  L->analysed = 1;
  return NULL;
}

static void join_analysis(cv_ldlt *L) {
  if (L->running) pthread_join(L->th, NULL);
  L->running = 0;
}

/* CHOLMOD's int interface: half the index memory of the long one, and every byte of a
 * large solve is a fresh page to fault in (docs/performance.md). 2^31 - 1 entries is far
 * beyond what fits in memory next to them (24 GB of values and indices alone). */
cv_status cv_ldlt_new(const cv_disc *d, int *gof, cv_ldlt **out, char *msg, size_t len) {
  int nfree = d->nfree;
  /* A column of a node holds at most the unknowns of p + 1 node blocks, an integral
   * multiplier's column all before it (E-2, C-3). Allocated to that bound, the pattern is
   * written in one pass; the pages past the true count are never touched, so they cost
   * nothing. Only near the 32-bit limit is the exact count taken first. */
  long nnz = (long)d->nu0 * (d->p + 1) * d->stride + (long)d->ni * d->nfree;
  if (nnz > INT_MAX) nnz = cv_disc_pattern(d, NULL, NULL);
  *out = NULL;
  if (nnz > INT_MAX) {
    cv_set_msg(msg, len,
               "the Hessian would have %ld entries, more than the 2^31 - 1 of the "
               "32-bit sparse matrix calcvar factors; use fewer elements or a lower degree",
               nnz);
    return CVAR_EINVAL;
  }
  cv_ldlt *L;
  if (nfree <= cv_ldlt_skyline_max ||
      (d->ni == 0 && nnz <= (long)cv_ldlt_skyline_band * (nfree > 0 ? nfree : 1))) {
    /* One block: the object, A, U and the column pointers, with the exact count of entries
     * (one more pass over the columns): one allocation instead of four, and fewer heap
     * bytes for the first solve in a process to touch (docs/performance.md). The object
     * and A are zeroed (a caller may sum into A before anything clears it); U is written
     * whole by every factorisation before it is read. */
    size_t nz = (size_t)cv_disc_pattern(d, NULL, NULL);
    if (nz < 1) nz = 1;
    L = cv_malloc(sizeof *L + 2 * nz * sizeof(double) + ((size_t)nfree + 1) * sizeof(int));
    if (!L) return CVAR_ENOMEM;
    memset(L, 0, sizeof *L + nz * sizeof(double));
    L->n = nfree;
    L->sky = 1;
    L->ax = (double *)(L + 1);
    L->u = L->ax + nz;
    L->colp = (int *)(L->u + nz);
    nnz = cv_disc_pattern(d, L->colp, gof);
    L->minor = nfree;
    L->mono = nfree;
    L->tri = 1;
    for (int c = 0; c < nfree && L->tri; c++) L->tri = L->colp[c + 1] - L->colp[c] <= 2;
    if (L->tri && nfree > 0 && nnz == 2L * nfree - 1) L->tri = 2; /* 1, 2, 2, ...: regular */
    for (int c = 1, f0 = 0; c < nfree; c++) {
      int f = c + 1 - (L->colp[c + 1] - L->colp[c]);
      if (f < f0) {
        L->mono = c;
        break;
      }
      f0 = f;
    }
    *out = L;
    return CVAR_OK;
  }
  L = cv_calloc(1, sizeof *L);
  if (!L) return CVAR_ENOMEM;
  L->n = nfree;
  L->c = cv_malloc(sizeof *L->c);
  if (!L->c) {
    cv_ldlt_free(L);
    return CVAR_ENOMEM;
  }
  cholmod_start(L->c);
  /* The Hessian is block-banded in node-major order, so the natural ordering has no
   * fill beyond the band; AMD would scramble it (DESIGN.md performance model). */
  L->c->nmethods = 1;
  L->c->method[0].ordering = CHOLMOD_NATURAL;
  L->c->postorder = 0;
  L->c->supernodal = CHOLMOD_SIMPLICIAL;
  L->c->final_ll = 0; /* keep LDL^T: the pivots give the inertia */
  L->c->quick_return_if_not_posdef = 0;
  L->c->print = 0;
  L->c->error_handler = NULL;
  L->n = nfree;
  size_t nz = (size_t)(nnz ? nnz : 1);
  L->A = cholmod_allocate_sparse((size_t)nfree, (size_t)nfree, nz, 1, 1, 1, CHOLMOD_REAL, L->c);
  if (!L->A) {
    cv_ldlt_free(L);
    return CVAR_ENOMEM;
  }
  int *Ap = L->A->p, *Ai = L->A->i;
  nz = (size_t)cv_disc_pattern(d, Ap, gof);
  for (int c = 0; c < nfree; c++) { /* column c: rows c + 1 - length .. c */
    int cl = Ap[c + 1] - Ap[c], r0 = c + 1 - cl;
    for (int k = 0; k < cl; k++) Ai[Ap[c] + k] = r0 + k;
  }
  memset(L->A->x, 0, (nz ? nz : 1) * sizeof(double));
  /* At 10^6 unknowns the analysis is about a tenth of a Newton solve, most of it faulting
   * in CHOLMOD's workspace: on the second core it overlaps the first assembly
   * (docs/performance.md). If no thread can be started it runs in cv_ldlt_factor. */
  if (nfree >= ASYNC_ANALYSIS_MIN && pthread_create(&L->th, NULL, analyze_main, L) == 0)
    L->running = 1;
  *out = L;
  return CVAR_OK;
}

void cv_ldlt_free(cv_ldlt *L) {
  if (!L) return;
  if (L->sky) {
    /* colp, ax and u live in L's block */
  } else if (L->c) {
    join_analysis(L);
    cholmod_free_sparse(&L->A, L->c);
    cholmod_free_factor(&L->L, L->c);
    cholmod_finish(L->c);
    cv_free(L->c);
  }
  cv_free(L);
}

CV_HOT const int *cv_ldlt_colptr(const cv_ldlt *L) { return L->sky ? L->colp : L->A->p; }

CV_HOT double *cv_ldlt_values(cv_ldlt *L) { return L->sky ? L->ax : L->A->x; }

int cv_ldlt_matches(const cv_ldlt *L, const cv_disc *d, const int *gof) {
  if (!L || !gof || L->n != d->nfree) return 0;
  size_t n = (size_t)d->nfree;
  int *cp = cv_malloc((2 * n + 1) * sizeof *cp), same = 0;
  if (!cp) return 0;
  cv_disc_pattern(d, cp, cp + n + 1);
  same = !memcmp(cp, cv_ldlt_colptr(L), (n + 1) * sizeof *cp) &&
         !memcmp(cp + n + 1, gof, n * sizeof *cp);
  cv_free(cp);
  return same;
}

/* Skyline (envelope) LDL^T, A = U^T D U with U unit upper triangular, in the envelope of
 * A: natural ordering of a matrix whose columns are contiguous from their first row fills
 * nothing outside it (theory N-7). Column j by the Crout (left-looking) rule:
 *   g_i = a_ij - sum_{k = max(f_i, f_j)}^{i-1} u_ki g_k,   u_ij = g_i / d_i,
 *   d_j = a_jj - sum_{i = f_j}^{j-1} u_ij g_i.
 * A zero pivot is treated as CHOLMOD treats it (N-5): the first sets minor, from there on
 * every pivot is 0 and no column with a zero pivot contributes, so inertia, pivot test and
 * solves see the same factor as with CHOLMOD. */
/* The same rule on a tridiagonal envelope (degree 1, one unknown): column j holds
 * A(j-1, j) and A(j, j), so g = A(j-1, j), u = g / d_{j-1}, d_j = A(j, j) - u g — the
 * Thomas algorithm's elimination, in the same operations as the general loop below. */
typedef struct {
  int neg;
  long bad;
  double lo, hi;
} pivot_stats;

/* The pivot statistics of cv_ldlt_factor for pivot d of the diagonal entry a (theory N-5). */
static inline void pivot_count(pivot_stats *ps, long j, double dj, double a_jj) {
  double ajj = fabs(a_jj);
  if (dj < 0) ps->neg++;
  if ((!isfinite(dj) || !isfinite(ajj)) && ps->bad < 0) ps->bad = j;
  double a = fabs(dj), rel = ajj > 0 ? a / ajj : (a > 0 ? 1.0 : 0.0);
  if (!(rel >= ps->lo)) ps->lo = rel; /* a NaN pivot makes lo NaN */
  if (a > ps->hi) ps->hi = a;
}

/* ... with the pivot statistics taken in the same pass (one pass over the factor's memory
 * instead of two: at 10^6 unknowns each pass streams 36 MB). */
/* The regular tridiagonal envelope (tri = 2): column j at 2j - 1 (row j - 1) and 2j, so the
 * column pointers are not read (at 10^6 unknowns a stream of 4 MB in each pass). */
static void skyline_factor_tri2(cv_ldlt *L, pivot_stats *ps) {
  const double *ax = L->ax;
  double *u = L->u;
  long n = L->n, minor = n;
  double dprev = 0.0;
  for (long j = 0; j < n; j++) {
    double dj = ax[2 * j];
    if (j > 0) {
      double g = ax[2 * j - 1];
      double uij = dprev == 0.0 ? 0.0 : g / dprev; /* a zero pivot contributes nothing */
      u[2 * j - 1] = uij;
      dj -= dprev == 0.0 ? 0.0 : uij * g;
    }
    if (j >= minor)
      dj = 0.0;
    else if (dj == 0.0)
      minor = j;
    u[2 * j] = dj;
    dprev = dj;
    pivot_count(ps, j, dj, ax[2 * j]);
  }
  L->minor = minor;
}

static void skyline_factor_tri(cv_ldlt *L, pivot_stats *ps) {
  const int *cp = L->colp;
  const double *ax = L->ax;
  double *u = L->u;
  long n = L->n, minor = n;
  double dprev = 0.0;
  for (long j = 0; j < n; j++) {
    int pj = cp[j], len = cp[j + 1] - pj;
    double dj = ax[pj + len - 1];
    if (len == 2) {
      double g = ax[pj];
      double uij = dprev == 0.0 ? 0.0 : g / dprev; /* a zero pivot contributes nothing */
      u[pj] = uij;
      dj -= dprev == 0.0 ? 0.0 : uij * g;
    }
    if (j >= minor)
      dj = 0.0;
    else if (dj == 0.0)
      minor = j;
    u[pj + len - 1] = dj;
    dprev = dj;
    pivot_count(ps, j, dj, ax[pj + len - 1]);
  }
  L->minor = minor;
}

static void skyline_factor(cv_ldlt *L) {
  const int *cp = L->colp;
  const double *ax = L->ax;
  double *u = L->u;
  long n = L->n;
  L->minor = n;
  for (long j = 0; j < n; j++) {
    int pj = cp[j], fj = (int)j + 1 - (cp[j + 1] - pj);
    double *uj = u + pj - fj; /* uj[i] = entry of row i in column j */
    const double *aj = ax + pj - fj;
    double dj = aj[j];
    for (int i = fj; i < j; i++) {
      int pi = cp[i], fi = i + 1 - (cp[i + 1] - pi), k0 = fi > fj ? fi : fj;
      const double *ui = u + pi - fi;
      double g = aj[i];
      for (int k = k0; k < i; k++) g -= ui[k] * uj[k]; /* uj[k] holds g_k until below */
      uj[i] = g;
    }
    for (int i = fj; i < j; i++) { /* g_i -> u_ij; d_j -= u_ij g_i */
      double di = u[cp[i + 1] - 1], g = uj[i];
      if (di == 0.0) { /* a zero pivot's column contributes nothing (CHOLMOD: L(k,i) = 0) */
        uj[i] = 0.0;
        continue;
      }
      double uij = g / di;
      uj[i] = uij;
      dj -= uij * g;
    }
    if (j >= L->minor)
      dj = 0.0;
    else if (dj == 0.0)
      L->minor = j;
    uj[j] = dj;
  }
}

static cv_status factor_cholmod(cv_ldlt *L, char *msg, size_t len) {
  join_analysis(L);
  if (!L->analysed) {
    L->L = cholmod_analyze(L->A, L->c);
    L->analysed = 1;
  }
  if (!L->L) {
    cv_set_msg(msg, len, "CHOLMOD analysis failed (status %d)", L->c->status);
    return L->c->status == CHOLMOD_OUT_OF_MEMORY ? CVAR_ENOMEM : CVAR_EDEPENDENCY;
  }
  int ok = cholmod_factorize(L->A, L->L, L->c);
  if (!ok || L->c->status < CHOLMOD_OK) {
    cv_set_msg(msg, len, "CHOLMOD factorisation failed (status %d)", L->c->status);
    return L->c->status == CHOLMOD_OUT_OF_MEMORY ? CVAR_ENOMEM : CVAR_EDEPENDENCY;
  }
  return CVAR_OK;
}

cv_status cv_ldlt_factor(cv_ldlt *L, int *neg, double *dmin, double *dmax, char *msg, size_t len) {
  pivot_stats ps = {0, -1, INFINITY, 0.0};
  if (L->sky && L->tri == 2) {
    skyline_factor_tri2(L, &ps);
  } else if (L->sky && L->tri) {
    skyline_factor_tri(L, &ps);
  } else {
    if (L->sky) {
      skyline_factor(L);
    } else {
      cv_status st = factor_cholmod(L, msg, len);
      if (st) return st;
    }
    const int *cp = cv_ldlt_colptr(L);
    const int *Lp = L->sky ? NULL : L->L->p;
    const double *Ax = cv_ldlt_values(L), *Lx = L->sky ? L->u : L->L->x;
    /* Simplicial LDL^T: D(j) is the first entry of column j of L (CHOLMOD), the last of
     * column j of U (skyline). The pivot is compared with the diagonal entry A(j,j) (the
     * last entry of column j of the upper triangle): |D(j)| / |A(j,j)| is dimensionless
     * and independent of the mesh width, so a small value marks a (nearly) degenerate
     * direction, not merely a small element (theory N-5). */
    for (long j = 0; j < L->n; j++)
      pivot_count(&ps, j, L->sky ? Lx[cp[j + 1] - 1] : Lx[Lp[j]], Ax[cp[j + 1] - 1]);
  }
  long bad = ps.bad;
  *neg = ps.neg;
  *dmin = L->n ? ps.lo : 1.0;
  *dmax = ps.hi;
  /* The assembly checks each element's entries; only a sum of finite ones that overflows
   * arrives here (cv_assemble). */
  if (bad >= 0) {
    cv_set_msg(msg, len,
               "the Hessian (or its factor) is not finite at unknown %ld: the "
               "integrand's second derivatives overflow",
               bad);
    return CVAR_ENONFINITE;
  }
  /* CHOLMOD stops LDL^T at an exactly zero pivot and reports it as "not positive
   * definite" with L->minor < n; a TRUE return alone does not mean success (STYLE.md 4). */
  long minor = L->sky ? L->minor : (long)L->L->minor;
  if (minor < L->n || (!L->sky && L->c->status == CHOLMOD_NOT_POSDEF)) {
    cv_set_msg(msg, len, "zero pivot in the LDL^T factorisation at unknown %ld", minor);
    return CVAR_ESINGULAR;
  }
  return CVAR_OK;
}

/* Triangular solves on the simplicial LDL^T factor itself: column j of L holds D(j) first,
 * then the sub-diagonal entries of the unit lower triangle (CHOLMOD user guide, "simplicial
 * factor"). The natural ordering leaves no permutation. cholmod_solve2 would do the same
 * but, for a simplicial factor, reallocates a 4-column workspace on every call (measured:
 * 32 bytes per unknown per Newton step, each page a fresh fault) and copies x twice;
 * these loops touch only L and x (docs/performance.md). */
/* Both solves are chains: x[j] needs x[j -+ 1], just computed. Passing that value in a
 * register instead of through memory (a store and a reload on the critical path) takes a
 * third off a tridiagonal solve; entries in other rows go through x as usual. */
static void forward_L(const cv_ldlt *L, double *x) { /* x <- L^{-1} x, L unit lower */
  const int *Lp = L->L->p, *Li = L->L->i, *Lnz = L->L->nz;
  const double *Lx = L->L->x;
  long n = L->n;
  double carry = n ? x[0] : 0.0; /* x[j] with every update from columns < j */
  for (long j = 0; j < n; j++) {
    double xj = carry, lnext = 0.0;
    int has_next = 0;
    x[j] = xj;
    for (int k = Lp[j] + 1, ke = Lp[j] + Lnz[j]; k < ke; k++) {
      if (Li[k] == j + 1)
        lnext = Lx[k], has_next = 1;
      else
        x[Li[k]] -= Lx[k] * xj;
    }
    if (j + 1 < n) carry = has_next ? x[j + 1] - lnext * xj : x[j + 1];
  }
}

/* x <- L^{-T} D^{-1} x (diag 1) or L^{-T} x (diag 0): one pass for both factors */
static inline __attribute__((always_inline)) void backward_Lt(const cv_ldlt *L, int diag,
                                                              double *x) {
  const int *Lp = L->L->p, *Li = L->L->i, *Lnz = L->L->nz;
  const double *Lx = L->L->x;
  double carry = 0.0; /* x[j + 1], final */
  for (long j = L->n - 1; j >= 0; j--) {
    double xj = diag ? x[j] / Lx[Lp[j]] : x[j];
    for (int k = Lp[j] + 1, ke = Lp[j] + Lnz[j]; k < ke; k++)
      xj -= Lx[k] * (Li[k] == j + 1 ? carry : x[Li[k]]);
    x[j] = carry = xj;
  }
}

/* The skyline factor's solves: row j of L is column j of U, so L^{-1} is a dot product per
 * row and U^{-1} an update per column. */
CV_HOT static void sky_forward(const cv_ldlt *L, double *x) { /* x <- U^{-T} x */
  const int *cp = L->colp;
  if (L->tri == 2) { /* the same operations without the column pointers */
    for (long j = 1; j < L->n; j++) x[j] -= L->u[2 * j - 1] * x[j - 1];
    return;
  }
  for (long j = 0; j < L->n; j++) {
    int fj = (int)j + 1 - (cp[j + 1] - cp[j]);
    const double *uj = L->u + cp[j] - fj;
    double s = x[j];
    for (int i = fj; i < j; i++) s -= uj[i] * x[i];
    x[j] = s;
  }
}

/* x <- U^{-1} D^{-1} x (diag 1) or U^{-1} x, as a dot product over row j of U in
 * increasing column order: the order of CHOLMOD's backward_Lt above, so that both give the
 * same round-off (a Newton step next to a singular leading block amplifies it, and the
 * deflation's search follows). Row j of U lies in the columns r > j whose first row
 * f_r <= j: a range j + 1 .. e over the columns with nondecreasing f_r (the node blocks,
 * e falling with j), then every later column (an integral multiplier's, f_r = 0). */
CV_HOT static void sky_backward(const cv_ldlt *L, int diag, double *x) {
  const int *cp = L->colp;
  const double *u = L->u;
  long n = L->n, mono = L->mono, e = mono - 1;
  if (L->tri == 2) {   /* the same operations without the column pointers */
    double next = 0.0; /* x[j + 1], final */
    for (long j = n - 1; j >= 0; j--) {
      double xj = diag ? x[j] / u[2 * j] : x[j];
      if (j + 1 < n) xj -= u[2 * j + 1] * next;
      x[j] = next = xj;
    }
    return;
  }
  for (long j = n - 1; j >= 0; j--) {
    double xj = diag ? x[j] / u[cp[j + 1] - 1] : x[j];
    if (j < mono) {
      while (e > j && e + 1 - (cp[e + 1] - cp[e]) > j) e--;
      for (long r = j + 1; r <= e; r++) xj -= u[cp[r + 1] - 1 - (r - j)] * x[r];
    }
    for (long r = j + 1 > mono ? j + 1 : mono; r < n; r++)
      if (r + 1 - (cp[r + 1] - cp[r]) <= j) xj -= u[cp[r + 1] - 1 - (r - j)] * x[r];
    x[j] = xj;
  }
}

cv_status cv_ldlt_solve_neg(cv_ldlt *L, const double *b, double *x) {
  if (L->sky && L->tri == 2 && L->n > 0) { /* x = -b fused into the forward pass */
    const double *u = L->u;
    double prev = x[0] = -b[0];
    for (long j = 1; j < L->n; j++) x[j] = prev = -b[j] - u[2 * j - 1] * prev;
    sky_backward(L, 1, x);
    return CVAR_OK;
  }
  for (long j = 0; j < L->n; j++) x[j] = -b[j];
  return cv_ldlt_solve(L, x);
}

cv_status cv_ldlt_solve(cv_ldlt *L, double *x) {
  if (L->sky) {
    sky_forward(L, x);
    sky_backward(L, 1, x);
    return CVAR_OK;
  }
  forward_L(L, x);
  backward_Lt(L, 1, x);
  return CVAR_OK;
}

cv_status cv_ldlt_solve_L(cv_ldlt *L, int transpose, double *x) {
  if (L->sky) {
    if (transpose)
      sky_backward(L, 0, x);
    else
      sky_forward(L, x);
    return CVAR_OK;
  }
  if (transpose)
    backward_Lt(L, 0, x);
  else
    forward_L(L, x);
  return CVAR_OK;
}

void cv_ldlt_diag(const cv_ldlt *L, double *D) {
  if (L->sky) {
    for (long j = 0; j < L->n; j++) D[j] = L->u[L->colp[j + 1] - 1];
    return;
  }
  const int *Lp = L->L->p;
  const double *Lx = L->L->x;
  for (long j = 0; j < L->n; j++) D[j] = Lx[Lp[j]];
}
