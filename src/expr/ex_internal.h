/* src/expr/ex_internal.h — private layout of the expression DAG, shared by src/expr/ only.
 * SPDX-License-Identifier: MIT */
#ifndef CV_EX_INTERNAL_H
#define CV_EX_INTERNAL_H

#include <stdint.h>

#include "core/cv_memory.h"
#include "expr/expr.h"

/* pi to more digits than a double holds (M_PI is not ISO C). */
#define EX_PI 3.14159265358979323846

/* One node. Children always have smaller ids than their parent (a node is created after
 * its operands), so increasing id order is a topological order: every pass over a DAG
 * (derivative, substitution, evaluation, compilation) is a loop, never a deep recursion. */
typedef struct {
  ex_op op;
  ex_id a, b, c;           /* operands, -1 when absent; for EX_SLOT, a is the slot number */
  double v;                /* EX_NUM: the value */
  uint64_t dep;            /* bit (s & 63) set when the node depends on slot s: 0 means constant */
  int lo, hi;              /* the least and the greatest slot the node depends on (lo > hi: none),
                  * exact where `dep` aliases (ex_depends_on, ex_first_slot) */
  unsigned char nonfinite; /* the node is, or reaches, a constant that is not a finite number
                            * (ex_nonfinite_const): set once here, so the loader's check of
                            * each parsed value costs nothing when there is none */
} ex_node;

struct ex_dag {
  ex_node *nodes;
  int n, cap;
  int *table; /* open-addressing hash of node ids, -1 = empty */
  size_t tcap;
  int max_slot; /* largest slot used, so `dep` is exact when max_slot < 64 */
  int ntables;  /* registered tables (ex_table.c), each with a reference */
  char **tab_name;
  struct cv_table **tabs;
};

/* Number of operands of an operation (0..3). */
int ex_op_arity(ex_op op);
/* One function of the grammar: its name, operation and number of arguments (ex_names.c). */
typedef struct {
  const char *name;
  ex_op op;
  int nargs;
} ex_function;
/* The function called `name`, or NULL. */
const ex_function *ex_function_find(const char *name);
/* The grammar function nearest to a mistyped name (ex_name_close), or NULL. */
const char *ex_function_nearest(const char *name);
/* Name of a function as written in the grammar ("sin"), or NULL for operators. */
const char *ex_op_name(ex_op op);
/* Value of op applied to numbers (the pointwise semantics shared by constant folding and
 * ex_eval; the tape implements the same). */
double ex_apply(ex_op op, double a, double b, double c);
/* Intern a node exactly as given (no simplification): the hash-consing primitive. */
ex_id ex_intern(ex_dag *d, ex_op op, ex_id a, ex_id b, ex_id c, double v);
/* Simplifying constructor dispatching on op (numbers and slots excluded). */
ex_id ex_make(ex_dag *d, ex_op op, ex_id a, ex_id b, ex_id c);
/* Mark (mark[id] = 1) the nodes reachable from e; mark must hold d->n zeros. When
 * skip_conditions, the conditions of `if` and comparison operands are not entered (they
 * have zero derivative). */
/* ex_reach.c: the ids of the nodes e reaches (e included), increasing, in a malloc'd array
 * (*out, cv_free it); returns their number, or -1 out of memory. */
int ex_reach(const ex_dag *d, ex_id e, ex_id **out);
void ex_mark_reachable(const ex_dag *d, ex_id e, unsigned char *mark, int skip_conditions);

/* Rebuild a node like nd on new operands through the simplifying constructors (all ops,
 * including table calls, whose identity lives in nd->v). */
ex_id ex_remake(ex_dag *d, const ex_node *nd, ex_id a, ex_id b, ex_id c);
/* Table calls (ex_table.c): value of an EX_TABLE node at argument values u[0..dim-1];
 * 0, or k + 1 when u is outside the grid along coordinate k (value NaN). */
int ex_table_apply(const ex_dag *d, const ex_node *nd, const double *u, double *value);
/* d(call)/d slot = sum_k call_{+e_k} * dargs[k] (TB-5). */
ex_id ex_table_diff(ex_dag *d, const ex_node *nd, const ex_id *dargs);
/* Encoding of a call in the node's v: index*64 + 16*o0 + 4*o1 + o2. */
#define EX_TABLE_CODE(index, o0, o1, o2) ((double)((index)*64 + (o0)*16 + (o1)*4 + (o2)))
void ex_table_decode(double v, int *index, int ord[3]);
/* Free the registry (ex_dag_free). */
void ex_dag_free_tables(ex_dag *d);

#endif /* CV_EX_INTERNAL_H */
