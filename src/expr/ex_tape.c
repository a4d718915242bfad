/* src/expr/ex_tape.c — compile DAG outputs into a straight-line program over batches of
 * points (structure of arrays) and evaluate it. SPDX-License-Identifier: MIT */

/* Every instruction is one tight loop over the m points of a batch. GCC's -O2 default
 * ("very-cheap" vectoriser cost model) refuses loops whose trip count is not a known
 * multiple of the vector length, which is all of these; the dynamic model vectorises them
 * (measured about 2x on the arithmetic kernels). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("vect-cost-model=dynamic")
#endif

#define _GNU_SOURCE /* sincos */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "core/cv_table_internal.h"
#include "expr/ex_internal.h"

/* Tape operations. Suffix V = vector operand, K = the instruction's scalar constant. */
typedef enum {
  T_FILL,
  T_COPY,
  T_ADD_VV,
  T_ADD_KV,
  T_SUB_VV,
  T_SUB_KV,
  T_SUB_VK,
  T_MUL_VV,
  T_MUL_KV,
  T_DIV_VV,
  T_DIV_KV,
  T_DIV_VK,
  T_NEG,
  T_POW_VV,
  T_POW_KV,
  T_POW_VK,
  T_SQR,
  T_CUBE,
  T_POW4,
  T_RECIP,
  T_RECIP2,
  T_SQRT,
  T_RSQRT,
  T_ABS,
  T_FN1,
  T_ATAN2,
  T_MIN,
  T_MAX,
  T_LT,
  T_LE,
  T_GT,
  T_GE,
  T_IF,
  T_TABLE, /* a table's spline or partial at 1..3 operands (ex_table.c, theory TB-2) */
  T_SINCOS /* sin(a) into dst and cos(a) into c: one call for both (the partials of a
               sin or cos have the other) */
} tape_op;

/* A location: a work register, an input slot or an output buffer. */
enum { L_NONE, L_REG, L_IN, L_OUT };
typedef struct {
  int space, idx;
} loc;

typedef struct {
  tape_op op;
  double (*fn)(double); /* T_FN1: the libm function */
  double k;             /* scalar operand (K variants, T_FILL) */
  loc dst, a, b, c;
  int tab, multi;     /* T_TABLE: index in the tape's tables and in its call groups */
  int pd, pa, pb, pc; /* the locations as indices of ex_tape_eval's pointer table */
} instr;

/* One T_TABLE instruction computes every partial the tape needs of one table at the same
 * arguments (value, gradient, Hessian entries): one cell search and one gather per point
 * for all of them (cv_table_eval_multi). */
enum { EX_TABLE_FUSE = 10 };
typedef struct {
  int n;
  loc dst[EX_TABLE_FUSE];
  int ord[EX_TABLE_FUSE][3];
} table_group;

struct ex_tape {
  int nslots, nout, nins, nregs;
  instr *ins;
  int ntab; /* tables the tape calls, each with a reference, and their names */
  cv_table **tab;
  char **tabname;
  int ngroup;
  table_group *group;
};

/* T_TABLE records the first point outside a table's grid in the EX_TAPE_FAULT doubles
 * after the registers of the work array: [0] = table + 1 (0: none), [1] = coordinate + 1,
 * [2..4] = the point. */
enum { EX_TAPE_FAULT = 5 };

static double (*unary_fn(ex_op op))(double) {
  switch (op) {
  case EX_SIN: return sin;
  case EX_COS: return cos;
  case EX_TAN: return tan;
  case EX_ASIN: return asin;
  case EX_ACOS: return acos;
  case EX_ATAN: return atan;
  case EX_SINH: return sinh;
  case EX_COSH: return cosh;
  case EX_TANH: return tanh;
  case EX_ASINH: return asinh;
  case EX_ACOSH: return acosh;
  case EX_ATANH: return atanh;
  case EX_EXP: return exp;
  case EX_LOG: return log;
  default: return NULL;
  }
}

/* Per-node compile state. */
typedef struct {
  unsigned char live;  /* reachable from an output through non-constant nodes */
  unsigned char konst; /* constant: its value is cval */
  unsigned char needv; /* needs a vector location (computed or filled) */
  unsigned char fused; /* a table call (or a sin, cos) computed by an earlier instruction */
  double cval;
  int last; /* id of the last node reading it as a vector operand */
  loc home;
} cnode;

/* Operations with instruction variants taking a constant operand as a scalar. */
static int k_capable(ex_op op) {
  return op == EX_ADD || op == EX_SUB || op == EX_MUL || op == EX_DIV || op == EX_POW;
}

/* Reachability from the outputs; constant subtrees are not entered (they become scalars,
 * their values computed here). Returns -1 if a slot is out of range or a constant fails. */
static int mark_live(const ex_dag *d, cnode *cn, int nn, int nslots, int nout, const ex_id *outs) {
  for (int o = 0; o < nout; o++) cn[outs[o]].live = 1;
  for (int id = nn - 1; id >= 0; id--) {
    if (!cn[id].live) continue;
    const ex_node *nd = &d->nodes[id];
    if (nd->dep == 0) {
      cn[id].konst = 1;
      if (ex_eval_const(d, id, &cn[id].cval) != 0) return -1;
      continue;
    }
    if (nd->op == EX_SLOT) {
      if (nd->a >= nslots) return -1;
      continue;
    }
    if (nd->a >= 0) cn[nd->a].live = 1;
    if (nd->b >= 0) cn[nd->b].live = 1;
    if (nd->c >= 0) cn[nd->c].live = 1;
  }
  return 0;
}

/* Which constants need a register, and the last reader of every vector value. */
static void mark_readers(const ex_dag *d, cnode *cn, int nn) {
  for (int id = 0; id < nn; id++) {
    cn[id].last = -1;
    if (!cn[id].live || cn[id].konst || d->nodes[id].op == EX_SLOT) continue;
    const ex_node *nd = &d->nodes[id];
    ex_id ops[3] = {nd->a, nd->b, nd->c};
    for (int i = 0; i < 3; i++) {
      if (ops[i] < 0) continue;
      if (cn[ops[i]].konst && k_capable(nd->op)) continue;
      cn[ops[i]].needv = 1;
      cn[ops[i]].last = id;
    }
  }
}

/* Registers of the work area: a free list, and the count ever used (t->nregs). */
typedef struct {
  int *free, nfree;
} regpool;

/* The lowest free register (keeps the live set compact), or a new one. */
static int take_register(regpool *rp, ex_tape *t) {
  if (rp->nfree == 0) return t->nregs++;
  int best = 0;
  for (int i = 1; i < rp->nfree; i++)
    if (rp->free[i] < rp->free[best]) best = i;
  int r = rp->free[best];
  rp->free[best] = rp->free[--rp->nfree];
  return r;
}

/* Free the registers of node id's operands that id reads last (each register once). */
static void release_operands(regpool *rp, const cnode *cn, const ex_node *nd, int id) {
  ex_id ops[3] = {nd->a, nd->b, nd->c};
  for (int i = 0; i < 3; i++) {
    ex_id o = ops[i];
    if (o < 0 || cn[o].last != id || cn[o].home.space != L_REG) continue;
    if ((i > 0 && o == ops[0]) || (i > 1 && o == ops[1])) continue; /* freed already */
    rp->free[rp->nfree++] = cn[o].home.idx;
  }
}

/* T_TABLE for table call id: the tape's reference to the table, and one call group with
 * the later calls of the same table at the same arguments. Returns -1 on failure. */
static int select_table(const ex_dag *d, ex_tape *t, cnode *cn, int nn, int id, regpool *rp,
                        instr *in) {
  const ex_node *nd = &d->nodes[id];
  int index, ord[3];
  ex_table_decode(nd->v, &index, ord);
  if (index < 0 || index >= d->ntables) return -1;
  in->op = T_TABLE;
  in->tab = -1;
  for (int j = 0; j < t->ntab; j++)
    if (t->tab[j] == d->tabs[index]) in->tab = j;
  if (in->tab < 0) {
    cv_table **tabs = cv_realloc(t->tab, ((size_t)t->ntab + 1) * sizeof *tabs);
    if (tabs) t->tab = tabs;
    char **names = cv_realloc(t->tabname, ((size_t)t->ntab + 1) * sizeof *names);
    if (names) t->tabname = names;
    char *copy = cv_malloc(strlen(d->tab_name[index]) + 1);
    if (!tabs || !names || !copy) {
      cv_free(copy);
      return -1;
    }
    strcpy(copy, d->tab_name[index]);
    t->tab[t->ntab] = cv_table_ref(d->tabs[index]);
    t->tabname[t->ntab] = copy;
    in->tab = t->ntab++;
  }
  table_group *gr = cv_realloc(t->group, ((size_t)t->ngroup + 1) * sizeof *gr);
  if (!gr) return -1;
  t->group = gr;
  gr = &t->group[t->ngroup];
  in->multi = t->ngroup++;
  gr->n = 1;
  memcpy(gr->ord[0], ord, sizeof ord);
  /* the later calls of this table at the same arguments join the instruction; their
   * destinations are allocated now (after the operands', so never aliasing them) */
  for (int j = id + 1; j < nn && gr->n < EX_TABLE_FUSE; j++) {
    const ex_node *nj = &d->nodes[j];
    if (!cn[j].live || cn[j].konst || nj->op != EX_TABLE || nj->a != nd->a || nj->b != nd->b ||
        nj->c != nd->c)
      continue;
    int jindex, jord[3];
    ex_table_decode(nj->v, &jindex, jord);
    if (jindex != index) continue;
    if (cn[j].home.space < 0) cn[j].home = (loc){L_REG, take_register(rp, t)};
    cn[j].fused = 1;
    gr->dst[gr->n] = cn[j].home;
    memcpy(gr->ord[gr->n], jord, sizeof jord);
    gr->n++;
  }
  return 0;
}

/* The instruction computing non-constant node id from its operands' homes: the variant
 * taking a constant operand as the scalar k where there is one. Returns -1 for an
 * operation the tape cannot run (or a table call that fails). */
static int select_instr(const ex_dag *d, ex_tape *t, cnode *cn, int nn, int id, regpool *rp,
                        instr *in) {
  const ex_node *nd = &d->nodes[id];
  ex_id a = nd->a, b = nd->b;
  int kc = k_capable(nd->op);
  int ka = kc && cn[a].konst, kb = kc && cn[b].konst;
  if (a >= 0) in->a = cn[a].home;
  if (b >= 0) in->b = cn[b].home;
  if (nd->c >= 0) in->c = cn[nd->c].home;
  switch (nd->op) {
  case EX_ADD:
  case EX_MUL: /* commutative: the constant goes to k */
    in->op = nd->op == EX_ADD ? (ka || kb ? T_ADD_KV : T_ADD_VV) : (ka || kb ? T_MUL_KV : T_MUL_VV);
    if (ka)
      in->k = cn[a].cval, in->a = in->b;
    else if (kb)
      in->k = cn[b].cval;
    if (ka || kb) in->b = in->a;
    break;
  case EX_SUB:
    in->op = ka ? T_SUB_KV : kb ? T_SUB_VK : T_SUB_VV;
    if (ka) in->k = cn[a].cval, in->a = in->b;
    if (kb) in->k = cn[b].cval;
    break;
  case EX_DIV:
    in->op = ka ? T_DIV_KV : kb ? T_DIV_VK : T_DIV_VV;
    if (ka) in->k = cn[a].cval, in->a = in->b;
    if (kb) in->k = cn[b].cval;
    break;
  case EX_POW:
    if (ka) {
      in->op = T_POW_KV;
      in->k = cn[a].cval;
      in->a = in->b;
    } else if (kb) {
      /* Small integer and half-integer exponents by multiplication and sqrt: exact
       * or within an ulp of pow(), and several times faster. */
      double e = cn[b].cval;
      in->op = e == 2      ? T_SQR
               : e == 3    ? T_CUBE
               : e == 4    ? T_POW4
               : e == -1   ? T_RECIP
               : e == -2   ? T_RECIP2
               : e == 0.5  ? T_SQRT
               : e == -0.5 ? T_RSQRT
                           : T_POW_VK;
      in->k = e;
    } else {
      in->op = T_POW_VV;
    }
    break;
  case EX_NEG: in->op = T_NEG; break;
  case EX_SQRT: in->op = T_SQRT; break;
  case EX_ABS: in->op = T_ABS; break;
  case EX_ATAN2: in->op = T_ATAN2; break;
  case EX_MIN: in->op = T_MIN; break;
  case EX_MAX: in->op = T_MAX; break;
  case EX_LT: in->op = T_LT; break;
  case EX_LE: in->op = T_LE; break;
  case EX_GT: in->op = T_GT; break;
  case EX_GE: in->op = T_GE; break;
  case EX_IF: in->op = T_IF; break;
  case EX_TABLE: return select_table(d, t, cn, nn, id, rp, in);
  case EX_SIN:
  case EX_COS:
    /* the other of sin, cos at the same operand later on: one sincos for both */
    for (int j = id + 1; j < nn; j++) {
      const ex_node *nj = &d->nodes[j];
      if (!cn[j].live || cn[j].konst || cn[j].fused || nj->a != a ||
          nj->op != (nd->op == EX_SIN ? EX_COS : EX_SIN))
        continue;
      if (cn[j].home.space < 0) cn[j].home = (loc){L_REG, take_register(rp, t)};
      cn[j].fused = 1;
      in->op = T_SINCOS;
      in->c = cn[j].home;
      in->k = nd->op == EX_SIN ? 0.0 : 1.0; /* 1: dst takes the cos, c the sin */
      return 0;
    }
    in->op = T_FN1;
    in->fn = unary_fn(nd->op);
    break;
  default:
    in->op = T_FN1;
    in->fn = unary_fn(nd->op);
    if (!in->fn) return -1;
  }
  return 0;
}

/* A location's index in the pointer table of an evaluation: 0 NULL (no operand), then
 * the input slots, the outputs and the registers. */
static int ptr_index(const ex_tape *t, loc l) {
  switch (l.space) {
  case L_IN: return 1 + l.idx;
  case L_OUT: return 1 + t->nslots + l.idx;
  case L_REG: return 1 + t->nslots + t->nout + l.idx;
  default: return 0;
  }
}

ex_tape *ex_tape_new(const ex_dag *d, int nslots, int nout, const ex_id *outs) {
  if (!d || nslots < 0 || nout < 0 || (nout > 0 && !outs)) return NULL;
  int top = -1;
  for (int o = 0; o < nout; o++) {
    if (outs[o] < 0 || outs[o] >= d->n) return NULL;
    if (outs[o] > top) top = outs[o];
  }
  int nn = top + 1;
  ex_tape *t = cv_calloc(1, sizeof *t);
  cnode *cn = cv_calloc((size_t)(nn > 0 ? nn : 1), sizeof *cn);
  regpool rp = {NULL, 0};
  /* At most one instruction per node plus one per output (copies and fills). */
  instr *ins = cv_malloc(((size_t)nn + (size_t)nout + 1) * sizeof *ins);
  if (!t || !cn || !ins) goto fail;
  t->nslots = nslots;
  t->nout = nout;
  if (mark_live(d, cn, nn, nslots, nout, outs) < 0) goto fail;
  mark_readers(d, cn, nn);
  /* Homes: an output node is computed straight into the caller's buffer (its first
   * output); slots are read where the caller keeps them; the rest live in registers. */
  for (int id = 0; id < nn; id++) cn[id].home.space = -1;
  for (int o = 0; o < nout; o++) {
    cnode *c = &cn[outs[o]];
    if (c->home.space < 0 && !c->konst && d->nodes[outs[o]].op != EX_SLOT)
      c->home = (loc){L_OUT, o};
  }
  rp.free = cv_malloc(((size_t)nn + 1) * sizeof *rp.free);
  if (!rp.free) goto fail;

  int n = 0;
  for (int id = 0; id < nn; id++) {
    cnode *c = &cn[id];
    if (!c->live) continue;
    const ex_node *nd = &d->nodes[id];
    if (nd->op == EX_SLOT) {
      c->home = (loc){L_IN, nd->a};
      continue;
    }
    if (c->konst && !c->needv) continue; /* used only as a scalar (or output: filled later) */
    if (!c->fused) { /* a fused table call was computed by an earlier call's instruction */
      instr in;
      memset(&in, 0, sizeof in);
      if (c->konst) {
        in.op = T_FILL;
        in.k = c->cval;
      } else if (select_instr(d, t, cn, nn, id, &rp, &in) < 0) {
        goto fail;
      }
      /* Destination first, operands freed after: the destination never aliases an
       * operand, which keeps every kernel free of overlap (and vectorisable with
       * restrict). */
      if (c->home.space < 0) c->home = (loc){L_REG, take_register(&rp, t)};
      in.dst = c->home;
      if (in.op == T_TABLE) t->group[in.multi].dst[0] = c->home;
      ins[n++] = in;
    }
    if (!c->konst) release_operands(&rp, cn, nd, id);
  }
  /* Outputs not computed in place: constants, slots, repeated nodes. */
  for (int o = 0; o < nout; o++) {
    cnode *c = &cn[outs[o]];
    if (c->home.space == L_OUT && c->home.idx == o) continue;
    instr in;
    memset(&in, 0, sizeof in);
    in.dst = (loc){L_OUT, o};
    if (c->konst) { /* filled: a constant's register may be reused by now */
      in.op = T_FILL;
      in.k = c->cval;
    } else {
      in.op = T_COPY;
      in.a = c->home;
    }
    ins[n++] = in;
  }
  t->ins = ins;
  t->nins = n;
  for (int i = 0; i < n; i++) {
    ins[i].pd = ptr_index(t, ins[i].dst);
    ins[i].pa = ptr_index(t, ins[i].a);
    ins[i].pb = ptr_index(t, ins[i].b);
    ins[i].pc = ptr_index(t, ins[i].c);
  }
  cv_free(cn);
  cv_free(rp.free);
  return t;
fail:
  cv_free(cn);
  cv_free(rp.free);
  cv_free(ins);
  if (t) t->ins = NULL;
  ex_tape_free(t);
  return NULL;
}

void ex_tape_free(ex_tape *t) {
  if (!t) return;
  for (int j = 0; j < t->ntab; j++) {
    cv_table_free(t->tab[j]);
    cv_free(t->tabname[j]);
  }
  cv_free(t->tab);
  cv_free(t->tabname);
  cv_free(t->group);
  cv_free(t->ins);
  cv_free(t);
}

size_t ex_tape_work_size(const ex_tape *t, int m) {
  if (!t || m <= 0) return 0;
  return (size_t)t->nregs * (size_t)m + (t->ntab ? EX_TAPE_FAULT : 0);
}

int ex_tape_num_instructions(const ex_tape *t) { return t ? t->nins : 0; }

/* The kernels. restrict is sound: a destination is never an operand (see the register
 * allocation) and callers' inputs, outputs and work do not overlap (expr.h). */
#define LOOP(body)                                                                                 \
  for (int k = 0; k < m; k++) D[k] = (body)
typedef double *restrict dptr;
typedef const double *restrict cptr;

/* Inlined into the evaluation loop: a call per instruction (saving and restoring its
 * registers) costs as much as the loop of a few points. */
#if defined(__GNUC__)
#define EX_INLINE inline __attribute__((always_inline))
#else
#define EX_INLINE inline
#endif
static EX_INLINE void run(const instr *in, int m, dptr D, cptr A, cptr B, cptr C) {
  const double K = in->k;
  switch (in->op) {
  case T_FILL: LOOP(K); break;
  case T_COPY: LOOP(A[k]); break;
  case T_ADD_VV: LOOP(A[k] + B[k]); break;
  case T_ADD_KV: LOOP(K + A[k]); break;
  case T_SUB_VV: LOOP(A[k] - B[k]); break;
  case T_SUB_KV: LOOP(K - A[k]); break;
  case T_SUB_VK: LOOP(A[k] - K); break;
  case T_MUL_VV: LOOP(A[k] * B[k]); break;
  case T_MUL_KV: LOOP(K * A[k]); break;
  case T_DIV_VV: LOOP(A[k] / B[k]); break;
  case T_DIV_KV: LOOP(K / A[k]); break;
  case T_DIV_VK: LOOP(A[k] / K); break;
  case T_NEG: LOOP(-A[k]); break;
  case T_POW_VV: LOOP(pow(A[k], B[k])); break;
  case T_POW_KV: LOOP(pow(K, A[k])); break;
  case T_POW_VK: LOOP(pow(A[k], K)); break;
  case T_SQR: LOOP(A[k] * A[k]); break;
  case T_CUBE: LOOP(A[k] * A[k] * A[k]); break;
  case T_POW4:
    for (int k = 0; k < m; k++) {
      double s = A[k] * A[k];
      D[k] = s * s;
    }
    break;
  case T_RECIP: LOOP(1.0 / A[k]); break;
  case T_RECIP2: LOOP(1.0 / (A[k] * A[k])); break;
  case T_SQRT: LOOP(sqrt(A[k])); break;
  case T_RSQRT: LOOP(1.0 / sqrt(A[k])); break;
  case T_ABS: LOOP(fabs(A[k])); break;
  case T_FN1:
    for (int k = 0; k < m; k++) D[k] = in->fn(A[k]);
    break;
  case T_ATAN2: LOOP(atan2(A[k], B[k])); break;
  case T_MIN: LOOP((A[k] <= B[k] || A[k] != A[k]) ? A[k] : B[k]); break; /* = ex_apply */
  case T_MAX: LOOP((A[k] >= B[k] || A[k] != A[k]) ? A[k] : B[k]); break;
  case T_LT: LOOP(A[k] < B[k] ? 1.0 : 0.0); break;
  case T_LE: LOOP(A[k] <= B[k] ? 1.0 : 0.0); break;
  case T_GT: LOOP(A[k] > B[k] ? 1.0 : 0.0); break;
  case T_GE: LOOP(A[k] >= B[k] ? 1.0 : 0.0); break;
  case T_IF: LOOP(A[k] != 0 ? B[k] : C[k]); break;
  case T_TABLE:         /* run_table */
  case T_SINCOS: break; /* run_sincos */
  }
}

static double *where(loc l, int m, const double *const *in, double *const *out, double *work);

/* T_SINCOS: the node's own function into D, the fused other one into E. */
static void run_sincos(const instr *in, int m, dptr D, dptr E, cptr A) {
  double *s = in->k == 0.0 ? D : E, *c = in->k == 0.0 ? E : D;
  for (int k = 0; k < m; k++) sincos(A[k], &s[k], &c[k]);
}

/* T_TABLE over the m points: every partial of its group at once; a point outside the grid
 * gives NaN and, the first time in this evaluation, a fault record (EX_TAPE_FAULT). */
static void run_table(const ex_tape *t, const instr *in, int m, const double *const *inp,
                      double *const *out, double *work, const double *A, const double *B,
                      const double *C, double *fault) {
  const cv_table *tab = t->tab[in->tab];
  const table_group *g = &t->group[in->multi];
  double *D[EX_TABLE_FUSE], v[EX_TABLE_FUSE];
  for (int j = 0; j < g->n; j++) D[j] = where(g->dst[j], m, inp, out, work);
  for (int k = 0; k < m; k++) {
    double u[3] = {A[k], B ? B[k] : 0.0, C ? C[k] : 0.0};
    int rc = cv_table_eval_multi(tab, u, g->n, (const int(*)[3])g->ord, v);
    for (int j = 0; j < g->n; j++) D[j][k] = v[j];
    if (rc != 0 && fault[0] == 0) {
      fault[0] = in->tab + 1;
      fault[1] = rc;
      fault[2] = u[0], fault[3] = u[1], fault[4] = u[2];
    }
  }
}

static double *where(loc l, int m, const double *const *in, double *const *out, double *work) {
  switch (l.space) {
  case L_NONE: return NULL; /* operand absent */
  case L_REG: return work + (size_t)l.idx * (size_t)m;
  case L_IN: return (double *)in[l.idx]; /* read only: only ever an operand */
  default: return out[l.idx];
  }
}

/* Pointer tables up to this many entries live on the stack; larger tapes (rare) find
 * each location by its kind instead. */
enum { EX_TAPE_PTRS = 2048 };

void ex_tape_eval(const ex_tape *t, int m, const double *const *in, double *const *out,
                  double *work) {
  if (!t || m <= 0) return;
  double *fault = t->ntab ? work + (size_t)t->nregs * (size_t)m : NULL;
  if (fault) fault[0] = 0;
  int np = 1 + t->nslots + t->nout + t->nregs;
  if (np <= EX_TAPE_PTRS) {
    /* Every location's address once per evaluation, then each instruction finds its
     * operands by index: on the few points of a small mesh the per-instruction
     * overhead, not the arithmetic, is most of the cost (docs/performance.md). */
    double *P[EX_TAPE_PTRS];
    P[0] = NULL;
    for (int q = 0; q < t->nslots; q++) P[1 + q] = (double *)in[q]; /* read only */
    for (int o = 0; o < t->nout; o++) P[1 + t->nslots + o] = out[o];
    double *R = work;
    for (int r = 0; r < t->nregs; r++, R += m) P[1 + t->nslots + t->nout + r] = R;
    for (int i = 0; i < t->nins; i++) {
      const instr *p = &t->ins[i];
      if (p->op == T_TABLE)
        run_table(t, p, m, in, out, work, P[p->pa], P[p->pb], P[p->pc], fault);
      else if (p->op == T_SINCOS)
        run_sincos(p, m, P[p->pd], P[p->pc], P[p->pa]);
      else
        run(p, m, P[p->pd], P[p->pa], P[p->pb], P[p->pc]);
    }
    return;
  }
  for (int i = 0; i < t->nins; i++) {
    const instr *p = &t->ins[i];
    double *D = where(p->dst, m, in, out, work);
    const double *A = where(p->a, m, in, out, work);
    const double *B = where(p->b, m, in, out, work);
    const double *C = where(p->c, m, in, out, work);
    if (p->op == T_TABLE)
      run_table(t, p, m, in, out, work, A, B, C, fault);
    else if (p->op == T_SINCOS)
      run_sincos(p, m, D, (double *)C, A);
    else
      run(p, m, D, A, B, C);
  }
}

int ex_tape_num_tables(const ex_tape *t) { return t ? t->ntab : 0; }

int ex_tape_fault(const ex_tape *t, int m, const double *work, char *msg, size_t len) {
  if (!t || !t->ntab || m <= 0 || !work) return 0;
  const double *fault = work + (size_t)t->nregs * (size_t)m;
  if (fault[0] == 0) return 0;
  int j = (int)fault[0] - 1, k = (int)fault[1] - 1;
  const char *axis[3] = {"first", "second", "third"};
  double lo = 0, hi = 0;
  cv_table_get_range(t->tab[j], k, &lo, &hi);
  if (msg && len)
    snprintf(msg, len,
             "the path left the grid of table '%s': its %s argument was %.15g, "
             "outside [%.10g, %.10g] (tables are not extrapolated)",
             t->tabname[j],
             axis[k < 0   ? 0
                  : k > 2 ? 2
                          : k],
             fault[2 + (k < 0   ? 0
                        : k > 2 ? 2
                                : k)],
             lo, hi);
  return 1;
}
