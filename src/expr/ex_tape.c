/* src/expr/ex_tape.c — compile DAG outputs into a straight-line program over batches of
 * points (structure of arrays) and evaluate it. SPDX-License-Identifier: MIT */

/* Every instruction is one tight loop over the m points of a batch. GCC's -O2 default
 * ("very-cheap" vectoriser cost model) refuses loops whose trip count is not a known
 * multiple of the vector length, which is all of these; the dynamic model vectorises them
 * (measured about 2x on the arithmetic kernels). */
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC optimize("vect-cost-model=dynamic")
#endif

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "expr/ex_internal.h"

/* Tape operations. Suffix V = vector operand, K = the instruction's scalar constant. */
typedef enum {
  T_FILL, T_COPY,
  T_ADD_VV, T_ADD_KV, T_SUB_VV, T_SUB_KV, T_SUB_VK, T_MUL_VV, T_MUL_KV,
  T_DIV_VV, T_DIV_KV, T_DIV_VK, T_NEG,
  T_POW_VV, T_POW_KV, T_POW_VK, T_SQR, T_CUBE, T_POW4, T_RECIP, T_RECIP2, T_SQRT, T_RSQRT,
  T_ABS, T_FN1, T_ATAN2, T_MIN, T_MAX, T_LT, T_LE, T_GT, T_GE, T_IF
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
} instr;

struct ex_tape {
  int nslots, nout, nins, nregs;
  instr *ins;
};

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
  unsigned char live;   /* reachable from an output through non-constant nodes */
  unsigned char konst;  /* constant: its value is cval */
  unsigned char needv;  /* needs a vector location (computed or filled) */
  double cval;
  int last;             /* id of the last node reading it as a vector operand */
  loc home;
} cnode;

/* Operations with instruction variants taking a constant operand as a scalar. */
static int k_capable(ex_op op) {
  return op == EX_ADD || op == EX_SUB || op == EX_MUL || op == EX_DIV || op == EX_POW;
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
  int *freeregs = NULL, nfree = 0;
  /* At most one instruction per node plus one per output (copies and fills). */
  instr *ins = cv_malloc(((size_t)nn + (size_t)nout + 1) * sizeof *ins);
  if (!t || !cn || !ins) goto fail;
  t->nslots = nslots;
  t->nout = nout;

  /* Reachability; constant subtrees are not entered (they become scalars). */
  for (int o = 0; o < nout; o++) cn[outs[o]].live = 1;
  for (int id = nn - 1; id >= 0; id--) {
    if (!cn[id].live) continue;
    const ex_node *nd = &d->nodes[id];
    if (nd->dep == 0) {
      cn[id].konst = 1;
      if (ex_eval_const(d, id, &cn[id].cval) != 0) goto fail;
      continue;
    }
    if (nd->op == EX_SLOT) {
      if (nd->a >= nslots) goto fail;
      continue;
    }
    if (nd->a >= 0) cn[nd->a].live = 1;
    if (nd->b >= 0) cn[nd->b].live = 1;
    if (nd->c >= 0) cn[nd->c].live = 1;
  }
  /* Which constants need a register, and the last reader of every vector value. */
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
  /* Homes: an output node is computed straight into the caller's buffer (its first
   * output); slots are read where the caller keeps them; the rest live in registers. */
  for (int id = 0; id < nn; id++) cn[id].home.space = -1;
  for (int o = 0; o < nout; o++) {
    cnode *c = &cn[outs[o]];
    if (c->home.space < 0 && !c->konst && d->nodes[outs[o]].op != EX_SLOT)
      c->home = (loc){L_OUT, o};
  }
  freeregs = cv_malloc(((size_t)nn + 1) * sizeof *freeregs);
  if (!freeregs) goto fail;

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
    instr in;
    memset(&in, 0, sizeof in);
    if (c->konst) {
      in.op = T_FILL;
      in.k = c->cval;
    } else {
      ex_id a = nd->a, b = nd->b;
      int kc = k_capable(nd->op);
      int ka = kc && cn[a].konst, kb = kc && cn[b].konst;
      if (a >= 0) in.a = cn[a].home;
      if (b >= 0) in.b = cn[b].home;
      if (nd->c >= 0) in.c = cn[nd->c].home;
      switch (nd->op) {
      case EX_ADD: case EX_MUL: /* commutative: the constant goes to k */
        in.op = nd->op == EX_ADD ? (ka || kb ? T_ADD_KV : T_ADD_VV)
                                 : (ka || kb ? T_MUL_KV : T_MUL_VV);
        if (ka) in.k = cn[a].cval, in.a = in.b;
        else if (kb) in.k = cn[b].cval;
        if (ka || kb) in.b = in.a;
        break;
      case EX_SUB:
        in.op = ka ? T_SUB_KV : kb ? T_SUB_VK : T_SUB_VV;
        if (ka) in.k = cn[a].cval, in.a = in.b;
        if (kb) in.k = cn[b].cval;
        break;
      case EX_DIV:
        in.op = ka ? T_DIV_KV : kb ? T_DIV_VK : T_DIV_VV;
        if (ka) in.k = cn[a].cval, in.a = in.b;
        if (kb) in.k = cn[b].cval;
        break;
      case EX_POW:
        if (ka) {
          in.op = T_POW_KV;
          in.k = cn[a].cval;
          in.a = in.b;
        } else if (kb) {
          /* Small integer and half-integer exponents by multiplication and sqrt: exact
           * or within an ulp of pow(), and several times faster. */
          double e = cn[b].cval;
          in.op = e == 2 ? T_SQR : e == 3 ? T_CUBE : e == 4 ? T_POW4 : e == -1 ? T_RECIP
                : e == -2 ? T_RECIP2 : e == 0.5 ? T_SQRT : e == -0.5 ? T_RSQRT : T_POW_VK;
          in.k = e;
        } else {
          in.op = T_POW_VV;
        }
        break;
      case EX_NEG: in.op = T_NEG; break;
      case EX_SQRT: in.op = T_SQRT; break;
      case EX_ABS: in.op = T_ABS; break;
      case EX_ATAN2: in.op = T_ATAN2; break;
      case EX_MIN: in.op = T_MIN; break;
      case EX_MAX: in.op = T_MAX; break;
      case EX_LT: in.op = T_LT; break;
      case EX_LE: in.op = T_LE; break;
      case EX_GT: in.op = T_GT; break;
      case EX_GE: in.op = T_GE; break;
      case EX_IF: in.op = T_IF; break;
      default:
        in.op = T_FN1;
        in.fn = unary_fn(nd->op);
        if (!in.fn) goto fail;
      }
    }
    /* Destination first, operands freed after: the destination never aliases an operand,
     * which keeps every kernel free of overlap (and vectorisable with restrict). */
    if (c->home.space < 0) {
      int r;
      if (nfree > 0) {
        int best = 0; /* lowest free register: keeps the live set compact */
        for (int i = 1; i < nfree; i++)
          if (freeregs[i] < freeregs[best]) best = i;
        r = freeregs[best];
        freeregs[best] = freeregs[--nfree];
      } else {
        r = t->nregs++;
      }
      c->home = (loc){L_REG, r};
    }
    in.dst = c->home;
    ins[n++] = in;
    if (!c->konst) {
      ex_id ops[3] = {nd->a, nd->b, nd->c};
      for (int i = 0; i < 3; i++) {
        ex_id o = ops[i];
        if (o < 0 || cn[o].last != id || cn[o].home.space != L_REG) continue;
        if ((i > 0 && o == ops[0]) || (i > 1 && o == ops[1])) continue; /* freed already */
        freeregs[nfree++] = cn[o].home.idx;
      }
    }
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
  cv_free(cn);
  cv_free(freeregs);
  return t;
fail:
  cv_free(cn);
  cv_free(freeregs);
  cv_free(ins);
  cv_free(t);
  return NULL;
}

void ex_tape_free(ex_tape *t) {
  if (!t) return;
  cv_free(t->ins);
  cv_free(t);
}

size_t ex_tape_work_size(const ex_tape *t, int m) {
  return t && m > 0 ? (size_t)t->nregs * (size_t)m : 0;
}

int ex_tape_num_instructions(const ex_tape *t) { return t ? t->nins : 0; }

/* The kernels. restrict is sound: a destination is never an operand (see the register
 * allocation) and callers' inputs, outputs and work do not overlap (expr.h). */
#define LOOP(body) for (int k = 0; k < m; k++) D[k] = (body)
typedef double *restrict dptr;
typedef const double *restrict cptr;

static void run(const instr *in, int m, dptr D, cptr A, cptr B, cptr C) {
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
  case T_POW4: for (int k = 0; k < m; k++) { double s = A[k] * A[k]; D[k] = s * s; } break;
  case T_RECIP: LOOP(1.0 / A[k]); break;
  case T_RECIP2: LOOP(1.0 / (A[k] * A[k])); break;
  case T_SQRT: LOOP(sqrt(A[k])); break;
  case T_RSQRT: LOOP(1.0 / sqrt(A[k])); break;
  case T_ABS: LOOP(fabs(A[k])); break;
  case T_FN1: for (int k = 0; k < m; k++) D[k] = in->fn(A[k]); break;
  case T_ATAN2: LOOP(atan2(A[k], B[k])); break;
  case T_MIN: LOOP((A[k] <= B[k] || A[k] != A[k]) ? A[k] : B[k]); break; /* = ex_apply */
  case T_MAX: LOOP((A[k] >= B[k] || A[k] != A[k]) ? A[k] : B[k]); break;
  case T_LT: LOOP(A[k] < B[k] ? 1.0 : 0.0); break;
  case T_LE: LOOP(A[k] <= B[k] ? 1.0 : 0.0); break;
  case T_GT: LOOP(A[k] > B[k] ? 1.0 : 0.0); break;
  case T_GE: LOOP(A[k] >= B[k] ? 1.0 : 0.0); break;
  case T_IF: LOOP(A[k] != 0 ? B[k] : C[k]); break;
  }
}

static double *where(loc l, int m, const double *const *in, double *const *out,
                     double *work) {
  switch (l.space) {
  case L_NONE: return NULL; /* operand absent */
  case L_REG: return work + (size_t)l.idx * (size_t)m;
  case L_IN: return (double *)in[l.idx]; /* read only: only ever an operand */
  default: return out[l.idx];
  }
}

void ex_tape_eval(const ex_tape *t, int m, const double *const *in, double *const *out,
                  double *work) {
  if (!t || m <= 0) return;
  for (int i = 0; i < t->nins; i++) {
    const instr *p = &t->ins[i];
    double *D = where(p->dst, m, in, out, work);
    const double *A = where(p->a, m, in, out, work);
    const double *B = where(p->b, m, in, out, work);
    const double *C = where(p->c, m, in, out, work);
    run(p, m, D, A, B, C);
  }
}
