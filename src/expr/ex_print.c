/* src/expr/ex_print.c — printing in the scene grammar with minimal parentheses; the text
 * re-parses to the same DAG. SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "expr/ex_internal.h"

/* Binding strength of a node's printed form; a child is parenthesised when it binds less
 * tightly than its position needs. */
enum { P_SUM = 1, P_PROD = 2, P_NEG = 3, P_POW = 4, P_ATOM = 5 };

typedef struct {
  const ex_dag *d;
  const char *const *names;
  int measure;  /* 1: count this node's text with children taken from lens[] */
  size_t count; /* measure mode: characters so far (saturating) */
  size_t *lens; /* printed length of each node, valid for nodes measured so far */
  char *buf;
  size_t cap, pos; /* write mode: at most cap characters go to buf */
} printer;

/* Shortest decimal that reads back as the same double ("0.1", not "0.10000000000000001"). */
static void fmt_num(double v, char *buf, size_t len) {
  if (v == EX_PI) {
    snprintf(buf, len, "pi");
  } else if (isnan(v)) {
    snprintf(buf, len, "(0/0)");
  } else if (isinf(v)) {
    snprintf(buf, len, v > 0 ? "(1/0)" : "(-1/0)");
  } else {
    for (int prec = 1; prec <= 17; prec++) {
      snprintf(buf, len, "%.*g", prec, v);
      if (strtod(buf, NULL) == v) break;
    }
  }
}

static int prec(const ex_dag *d, ex_id e) {
  const ex_node *nd = &d->nodes[e];
  switch (nd->op) {
  case EX_NUM: return nd->v < 0 ? P_NEG : P_ATOM;
  case EX_ADD:
  case EX_SUB: return P_SUM;
  case EX_MUL:
  case EX_DIV: return P_PROD;
  case EX_NEG: return P_NEG;
  case EX_POW: return P_POW;
  default: return P_ATOM;
  }
}

static int is_negative(const ex_dag *d, ex_id e) {
  const ex_node *nd = &d->nodes[e];
  return nd->op == EX_NEG || (nd->op == EX_NUM && nd->v < 0);
}

/* A factor whose text neither starts with a number nor contains a top-level operator of
 * product level: a name, a call, or a power of those. "2*x*y" is only written for
 * 2*(x*y) when x is such a factor, because then (2*x)*y is re-associated by the
 * constructor to the same node; "2*3^x*y" or "2*1/z*y" would fold or group differently. */
static int plain_factor(const ex_dag *d, ex_id e) {
  const ex_node *nd = &d->nodes[e];
  if (nd->op == EX_POW) nd = &d->nodes[nd->a];
  return nd->op == EX_SLOT || (nd->op >= EX_SIN && nd->op <= EX_ABS) || nd->op == EX_ATAN2 ||
         nd->op == EX_MIN || nd->op == EX_MAX || nd->op == EX_IF || nd->op == EX_TABLE;
}

static void put(printer *o, const char *s, size_t n) {
  if (o->measure) {
    o->count = o->count + n < o->count ? (size_t)-1 : o->count + n;
    return;
  }
  size_t room = o->cap - o->pos;
  if (n > room) n = room;
  memcpy(o->buf + o->pos, s, n);
  o->pos += n;
}

static void puts_(printer *o, const char *s) { put(o, s, strlen(s)); }

static void emit(printer *o, ex_id e);

static void child(printer *o, ex_id c, int paren) {
  if (paren) put(o, "(", 1);
  if (o->measure) {
    size_t n = o->lens[c];
    o->count = o->count + n < o->count ? (size_t)-1 : o->count + n;
  } else {
    emit(o, c);
  }
  if (paren) put(o, ")", 1);
}

static void comparison(printer *o, const ex_node *nd) {
  static const char *const rel[] = {" < ", " <= ", " > ", " >= "};
  child(o, nd->a, 0);
  puts_(o, rel[nd->op - EX_LT]);
  child(o, nd->b, 0);
}

/* The text of node e. In measure mode children are not visited (their lengths are known),
 * so measuring the whole DAG is linear even when the printed tree is exponentially large. */
static void emit(printer *o, ex_id e) {
  if (!o->measure && o->pos >= o->cap) return; /* buffer full: the rest is only counted */
  const ex_dag *d = o->d;
  const ex_node *nd = &d->nodes[e];
  char tmp[64];
  switch (nd->op) {
  case EX_NUM:
    fmt_num(nd->v, tmp, sizeof tmp);
    puts_(o, tmp);
    break;
  case EX_SLOT:
    if (o->names && o->names[nd->a]) {
      puts_(o, o->names[nd->a]);
    } else {
      snprintf(tmp, sizeof tmp, "s%d", nd->a);
      puts_(o, tmp);
    }
    break;
  case EX_ADD:
  case EX_SUB:
    child(o, nd->a, 0);
    puts_(o, nd->op == EX_ADD ? " + " : " - ");
    /* a + (b - c) keeps its parentheses: the text then parses back to this very node
     * (floating-point addition is not associative). */
    child(o, nd->b, is_negative(d, nd->b) || prec(d, nd->b) <= P_SUM);
    break;
  case EX_MUL:
  case EX_DIV: {
    int pb = prec(d, nd->b) <= P_PROD || is_negative(d, nd->b);
    /* c*(x*y) prints as c*x*y: the constructor re-associates (c*x)*y to c*(x*y), so the
     * text still parses back to this node. */
    if (nd->op == EX_MUL && d->nodes[nd->a].op == EX_NUM && d->nodes[nd->b].op == EX_MUL &&
        plain_factor(d, d->nodes[nd->b].a))
      pb = 0;
    child(o, nd->a, prec(d, nd->a) < P_PROD);
    put(o, nd->op == EX_MUL ? "*" : "/", 1);
    child(o, nd->b, pb);
    break;
  }
  case EX_NEG:
    put(o, "-", 1);
    child(o, nd->a, prec(d, nd->a) < P_PROD || is_negative(d, nd->a));
    break;
  case EX_POW:
    child(o, nd->a, prec(d, nd->a) < P_ATOM);
    put(o, "^", 1);
    child(o, nd->b, prec(d, nd->b) < P_POW || is_negative(d, nd->b));
    break;
  case EX_LT:
  case EX_LE:
  case EX_GT:
  case EX_GE: /* a comparison used as a number */
    puts_(o, "if(");
    comparison(o, nd);
    puts_(o, ", 1, 0)");
    break;
  case EX_IF: {
    puts_(o, "if(");
    const ex_node *c = &d->nodes[nd->a];
    if (c->op >= EX_LT && c->op <= EX_GE)
      comparison(o, c);
    else
      child(o, nd->a, 0);
    puts_(o, ", ");
    child(o, nd->b, 0);
    puts_(o, ", ");
    child(o, nd->c, 0);
    put(o, ")", 1);
    break;
  }
  case EX_TABLE: { /* name(u, v) or name.K(u, v), K the axes differentiated (1-based) */
    int index, ord[3], at = 0;
    ex_table_decode(nd->v, &index, ord);
    const char *name = ex_dag_table_name(d, index);
    puts_(o, name ? name : "table?");
    if (ord[0] + ord[1] + ord[2] > 0) {
      tmp[at++] = '.';
      for (int k = 0; k < 3; k++)
        for (int r = 0; r < ord[k]; r++) tmp[at++] = (char)('1' + k);
      tmp[at] = 0;
      puts_(o, tmp);
    }
    put(o, "(", 1);
    child(o, nd->a, 0);
    if (nd->b >= 0) puts_(o, ", "), child(o, nd->b, 0);
    if (nd->c >= 0) puts_(o, ", "), child(o, nd->c, 0);
    put(o, ")", 1);
    break;
  }
  default: /* functions */
    puts_(o, ex_op_name(nd->op));
    put(o, "(", 1);
    child(o, nd->a, 0);
    if (nd->b >= 0) {
      puts_(o, ", ");
      child(o, nd->b, 0);
    }
    put(o, ")", 1);
  }
}

size_t ex_print(const ex_dag *d, ex_id e, const char *const *names, char *buf, size_t len) {
  if (buf && len) buf[0] = 0;
  if (!d || e < 0 || e >= d->n) return 0;
  unsigned char *mark = cv_calloc((size_t)e + 1, 1);
  size_t *lens = cv_malloc(((size_t)e + 1) * sizeof *lens);
  size_t total = 0;
  if (!mark || !lens) goto cleanup; /* returns 0: nothing could be printed */
  ex_mark_reachable(d, e, mark, 0);
  printer o = {d, names, 1, 0, lens, NULL, 0, 0};
  for (ex_id id = 0; id <= e; id++) {
    if (!mark[id]) continue;
    o.count = 0;
    emit(&o, id);
    lens[id] = o.count;
  }
  total = lens[e];
  if (buf && len) {
    o.measure = 0;
    o.buf = buf;
    o.cap = len - 1;
    emit(&o, e);
    buf[o.pos] = 0;
  }
cleanup:
  cv_free(mark);
  cv_free(lens);
  return total;
}
