/* src/expr/ex_collect.c — a normal form for display: sums of monomials c·Π bᵢ^pᵢ with
 * like terms and like factors collected (docs/theory.md ). SPDX-License-Identifier: MIT
 *
 * The constructors of ex_build.c simplify one node at a time, so th'^2 - 0.5*th'^2,
 * a'*(b'*s) - b'*(a'*s) or (36*th')/2 stay as written. This pass looks through whole
 * sums and products. Every reachable node (in id order, so children first) becomes a
 * polynomial: a list of monomials, each a coefficient times factors base^p with a numeric
 * exponent p, the bases sorted by node id. Sums add, products multiply (distributing over
 * sums while the result has at most MAX_TERMS terms), division by a monomial negates its
 * exponents, an integer power of a monomial multiplies them, sqrt(u) is u^(1/2). Anything
 * else (a function, a sum too big to distribute, a non-integer power of a product) is an
 * atom: its operands are rebuilt from their normal forms and the node is one factor.
 *
 * The rules are identities wherever both sides are defined; the one identity used that
 * needs a sign is u^p·u^q = u^(p+q) with fractional p, q, which holds because a
 * fractional power (from sqrt) of u is only defined for u >= 0. A power of a product is
 * only split for integer exponents ((x^2)^(1/2) stays as written: it is |x|).
 *
 * Unlike the constructors this changes values by rounding (coefficients are combined in
 * floating point, products expanded), so a collected expression can differ from the
 * original by a few ulps, more where terms cancel. It is for display (calcvar equations),
 * not for the solver's tapes.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "expr/ex_internal.h"

/* A product is distributed over sums only while it has at most this many terms. */
enum { MAX_TERMS = 64, MAX_INT_POWER = 16 };

typedef struct {
  ex_id base;
  double p;
} factor;

typedef struct {
  double c;
  int nf;
  factor *f; /* sorted by base */
} mono;

typedef struct {
  int n, cap;
  mono *m;
} poly;

static void poly_free(poly *P) {
  for (int k = 0; k < P->n; k++) cv_free(P->m[k].f);
  cv_free(P->m);
  memset(P, 0, sizeof *P);
}

static int same_factors(const mono *a, const mono *b) {
  if (a->nf != b->nf) return 0;
  for (int k = 0; k < a->nf; k++)
    if (a->f[k].base != b->f[k].base || a->f[k].p != b->f[k].p) return 0;
  return 1;
}

/* P += s·m (m copied); like terms merge. */
static int add_mono(poly *P, const mono *m, double s) {
  for (int k = 0; k < P->n; k++)
    if (same_factors(&P->m[k], m)) {
      P->m[k].c += s * m->c;
      return 0;
    }
  if (P->n == P->cap) {
    int nc = P->cap ? 2 * P->cap : 4;
    mono *q = cv_realloc(P->m, (size_t)nc * sizeof *q);
    if (!q) return -1;
    P->m = q;
    P->cap = nc;
  }
  mono *d = &P->m[P->n];
  d->c = s * m->c;
  d->nf = m->nf;
  d->f = NULL;
  if (m->nf) {
    if (!(d->f = cv_malloc((size_t)m->nf * sizeof *d->f))) return -1;
    memcpy(d->f, m->f, (size_t)m->nf * sizeof *d->f);
  }
  P->n++;
  return 0;
}

static int add_poly(poly *P, const poly *A, double s) {
  for (int k = 0; k < A->n; k++)
    if (add_mono(P, &A->m[k], s) < 0) return -1;
  return 0;
}

/* The monomial c·Π f, exponents scaled by q (q = 1: as given; q = -1: reciprocal). */
static int add_scaled(poly *P, double c, int nf, const factor *f, double q) {
  factor *g = nf ? cv_malloc((size_t)nf * sizeof *g) : NULL;
  if (nf && !g) return -1;
  for (int k = 0; k < nf; k++) g[k] = (factor){f[k].base, f[k].p * q};
  mono m = {c, nf, g};
  int rc = add_mono(P, &m, 1.0);
  cv_free(g);
  return rc;
}

/* a·b, factor lists merged (exponents of equal bases added, zero exponents dropped). */
static int mul_mono(poly *P, const mono *a, const mono *b) {
  factor *f = cv_malloc(((size_t)a->nf + b->nf + 1) * sizeof *f);
  int i = 0, j = 0, n = 0;
  if (!f) return -1;
  while (i < a->nf || j < b->nf) {
    if (j >= b->nf || (i < a->nf && a->f[i].base < b->f[j].base))
      f[n++] = a->f[i++];
    else if (i >= a->nf || b->f[j].base < a->f[i].base)
      f[n++] = b->f[j++];
    else {
      double p = a->f[i].p + b->f[j].p;
      if (p != 0) f[n++] = (factor){a->f[i].base, p};
      i++, j++;
    }
  }
  mono m = {a->c * b->c, n, f};
  int rc = add_mono(P, &m, 1.0);
  cv_free(f);
  return rc;
}

static int mul_poly(poly *P, const poly *A, const poly *B) {
  for (int i = 0; i < A->n; i++)
    for (int j = 0; j < B->n; j++)
      if (mul_mono(P, &A->m[i], &B->m[j]) < 0) return -1;
  return 0;
}

/* One atom base^p. */
static int atom(poly *P, ex_id base, double p) {
  factor f = {base, p};
  return add_scaled(P, 1.0, 1, &f, 1.0);
}

/* Monomials with a zero coefficient contribute nothing. */
static int live_terms(const poly *P) {
  int n = 0;
  for (int k = 0; k < P->n; k++) n += P->m[k].c != 0;
  return n;
}

static const mono *single(const poly *P) {
  const mono *s = NULL;
  for (int k = 0; k < P->n; k++)
    if (P->m[k].c != 0) {
      if (s) return NULL;
      s = &P->m[k];
    }
  return s;
}

/* base^p as a node: sqrt for 1/2, the base itself for 1. */
static ex_id power(ex_dag *d, ex_id base, double p) {
  if (p == 1) return base;
  if (p == 0.5) return ex_unary(d, EX_SQRT, base);
  ex_id e = ex_num(d, p);
  return e >= 0 ? ex_binary(d, EX_POW, base, e) : -1;
}

/* Σ c·(Π positive powers)/(Π negative powers), through the constructors. */
static ex_id rebuild(ex_dag *d, const poly *P) {
  ex_id acc = ex_num(d, 0.0);
  for (int k = 0; k < P->n && acc >= 0; k++) {
    const mono *m = &P->m[k];
    if (m->c == 0) continue;
    ex_id num = ex_num(d, 1.0), den = ex_num(d, 1.0);
    for (int j = 0; j < m->nf && num >= 0 && den >= 0; j++) {
      if (m->f[j].p > 0) {
        ex_id t = power(d, m->f[j].base, m->f[j].p);
        num = t >= 0 ? ex_binary(d, EX_MUL, num, t) : -1;
      } else {
        ex_id t = power(d, m->f[j].base, -m->f[j].p);
        den = t >= 0 ? ex_binary(d, EX_MUL, den, t) : -1;
      }
    }
    ex_id c = ex_num(d, m->c);
    ex_id t = num >= 0 && c >= 0 ? ex_binary(d, EX_MUL, c, num) : -1;
    t = t >= 0 && den >= 0 ? ex_binary(d, EX_DIV, t, den) : -1;
    acc = t >= 0 ? ex_binary(d, EX_ADD, acc, t) : -1;
  }
  return acc;
}

/* Normal form of node id into P, from the normal forms of its operands (pl[]) and their
 * rebuilt nodes (map[]). */
static int normal(ex_dag *d, ex_id id, poly *pl, const ex_id *map, poly *P) {
  ex_node nd = d->nodes[id];
  switch (nd.op) {
  case EX_NUM: {
    mono m = {nd.v, 0, NULL};
    return add_mono(P, &m, 1.0);
  }
  case EX_SLOT: return atom(P, id, 1.0);
  case EX_ADD: return add_poly(P, &pl[nd.a], 1.0) < 0 ? -1 : add_poly(P, &pl[nd.b], 1.0);
  case EX_SUB: return add_poly(P, &pl[nd.a], 1.0) < 0 ? -1 : add_poly(P, &pl[nd.b], -1.0);
  case EX_NEG: return add_poly(P, &pl[nd.a], -1.0);
  case EX_MUL: {
    const poly *A = &pl[nd.a], *B = &pl[nd.b];
    poly a1 = {0, 0, NULL}, b1 = {0, 0, NULL};
    int rc = 0;
    if (live_terms(A) * live_terms(B) > MAX_TERMS) { /* keep the bigger sum(s) whole */
      if (live_terms(A) > 1) rc |= atom(&a1, map[nd.a], 1.0), A = &a1;
      if (live_terms(B) > 1) rc |= atom(&b1, map[nd.b], 1.0), B = &b1;
    }
    rc = rc < 0 ? -1 : mul_poly(P, A, B);
    poly_free(&a1);
    poly_free(&b1);
    return rc;
  }
  case EX_DIV: {
    const mono *b = single(&pl[nd.b]);
    poly inv = {0, 0, NULL};
    int rc = b && b->c != 0 && isfinite(1 / b->c) ? add_scaled(&inv, 1 / b->c, b->nf, b->f, -1.0)
                                                  : atom(&inv, map[nd.b], -1.0);
    rc = rc < 0 ? -1 : mul_poly(P, &pl[nd.a], &inv);
    poly_free(&inv);
    return rc;
  }
  case EX_POW:
    if (d->nodes[nd.b].op == EX_NUM) {
      double p = d->nodes[nd.b].v;
      const mono *a = single(&pl[nd.a]);
      if (a && p == floor(p) && fabs(p) <= MAX_INT_POWER && isfinite(pow(a->c, p)) &&
          pow(a->c, p) != 0)
        return add_scaled(P, pow(a->c, p), a->nf, a->f, p);
      return atom(P, map[nd.a], p);
    }
    break;
  case EX_SQRT: return atom(P, map[nd.a], 0.5);
  default: break;
  }
  /* An atom: the node rebuilt over normalised operands. */
  ex_id r = ex_remake(d, &nd, map[nd.a], nd.b >= 0 ? map[nd.b] : -1, nd.c >= 0 ? map[nd.c] : -1);
  if (r < 0) return -1;
  if (d->nodes[r].op == EX_NUM) {
    mono m = {d->nodes[r].v, 0, NULL};
    return add_mono(P, &m, 1.0);
  }
  return atom(P, r, 1.0);
}

ex_id ex_collect(ex_dag *d, ex_id e) {
  if (!d || e < 0 || e >= d->n) return -1;
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  ex_id *map = cv_malloc(((size_t)e + 1) * sizeof *map);
  poly *pl = cv_calloc((size_t)e + 1, sizeof *pl);
  ex_id result = -1;
  if (!mark || !map || !pl) goto cleanup;
  ex_mark_reachable(d, e, mark, 0);
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    if (normal(d, id, pl, map, &pl[id]) < 0) goto cleanup;
    if ((map[id] = rebuild(d, &pl[id])) < 0) goto cleanup;
  }
  result = map[e];
cleanup:
  if (pl)
    for (ex_id id = 0; id <= e; id++) poly_free(&pl[id]);
  cv_free(pl);
  cv_free(mark);
  cv_free(map);
  return result;
}
