/* src/expr/expr.h — expressions: parser, hash-consed DAG, symbolic derivatives, tapes.
 * SPDX-License-Identifier: MIT
 *
 * Internal to the library (not installed). Used by src/scene and by the public string
 * integrand entry point. Never prints, never exits: errors come back as messages.
 *
 * Model: an ex_dag owns nodes. A node is a number, a *slot* (an input variable numbered
 * 0..nslots-1 by the caller: e.g. 0 = x, 1..n = y_i, n+1..2n = y'_i), or an operation on
 * earlier nodes. Equal subexpressions are one node (hash-consing). Nodes are built through
 * constructors that simplify on the fly (constant folding, 0 and 1 rules), so derivatives
 * come out without `0*`, `*1`, `+0`.
 */
#ifndef CV_EXPR_H
#define CV_EXPR_H

#include <stddef.h>

typedef struct ex_dag ex_dag;
typedef int ex_id; /* node index; negative means failure */

typedef enum {
  EX_NUM,
  EX_SLOT,
  EX_ADD,
  EX_SUB,
  EX_MUL,
  EX_DIV,
  EX_NEG,
  EX_POW,
  EX_SIN,
  EX_COS,
  EX_TAN,
  EX_ASIN,
  EX_ACOS,
  EX_ATAN,
  EX_SINH,
  EX_COSH,
  EX_TANH,
  EX_ASINH,
  EX_ACOSH,
  EX_ATANH,
  EX_EXP,
  EX_LOG,
  EX_SQRT,
  EX_ABS,
  EX_ATAN2,
  EX_MIN,
  EX_MAX,
  EX_LT,
  EX_LE,
  EX_GT,
  EX_GE,    /* comparisons: value 1.0 or 0.0 */
  EX_IF,    /* if(c, a, b): a where c != 0, else b */
  EX_TABLE, /* a table's spline (or a partial of it) at 1..3 arguments */
  EX_NUM_OPS
} ex_op;

ex_dag *ex_dag_new(void);
void ex_dag_free(ex_dag *d);

/* Constructors (simplifying, hash-consing). Return a node id, or -1 on allocation failure. */
ex_id ex_num(ex_dag *d, double v);
ex_id ex_slot(ex_dag *d, int slot);
ex_id ex_unary(ex_dag *d, ex_op op, ex_id a);           /* EX_NEG, EX_SIN..EX_ABS */
ex_id ex_binary(ex_dag *d, ex_op op, ex_id a, ex_id b); /* ADD..POW, ATAN2, MIN, MAX, LT..GE */
ex_id ex_if(ex_dag *d, ex_id c, ex_id a, ex_id b);

/* Inspection. */
ex_op ex_node_op(const ex_dag *d, ex_id e);
double ex_node_value(const ex_dag *d, ex_id e); /* EX_NUM only */
int ex_node_slot(const ex_dag *d, ex_id e);     /* EX_SLOT only */
int ex_is_const(const ex_dag *d, ex_id e);      /* depends on no slot */
int ex_depends_on(const ex_dag *d, ex_id e, int slot);
/* Value of a constant expression; returns 0 on success, -1 if it depends on a slot. */
int ex_eval_const(const ex_dag *d, ex_id e, double *value);
/* The innermost constant subexpression of e whose value is not finite (0/0, log(0), a
 * formula on such a constant), which the folder keeps as a formula (theory (EX-1)); -1
 * when there is none, -2 when out of memory. */
ex_id ex_nonfinite_const(const ex_dag *d, ex_id e);
/* The least slot in [from, to] that e depends on, or -1 (exact, and without a walk over
 * the DAG when the range holds e's least slot or misses all of e's slots). */
int ex_first_slot(const ex_dag *d, ex_id e, int from, int to);
/* used[k] = 1 for each slot from + k (0 <= k < count) that e depends on; other entries are
 * left as they are. One walk over the nodes e reaches, where count calls of ex_depends_on
 * would each walk them. Returns 0, or -1 out of memory. */
int ex_slots_used(const ex_dag *d, ex_id e, int from, int count, unsigned char *used);

/* The grammar's names (ex_names.c). An identifier is a letter or '_' followed by letters,
 * digits or '_' (a prime is not part of a name); the reserved names are pi and the
 * function names, which no parameter or unknown may take. */
int ex_is_identifier(const char *s);
int ex_is_reserved(const char *s);
/* Edit distance of two names (insert, delete, substitute, swap neighbours), and whether
 * known is close enough to typed to suggest it in a message ("did you mean ...?"): 1 edit
 * for names of up to 4 characters, 2 beyond, never all of them. */
int ex_name_distance(const char *a, const char *b);
int ex_name_close(const char *typed, const char *known);
/* The nearest close name among those offered one by one (start with {NULL, 0}): best is
 * NULL while none is close; of two equally near, the one of typed's length. */
typedef struct {
  const char *best;
  int score;
} ex_nearest;
void ex_name_consider(ex_nearest *nr, const char *typed, const char *known);

/* A value split at commas outside parentheses; off[i] is item i's offset in the value. */
typedef struct {
  int n;
  char **item;
  int *off;
} ex_list;
/* Split value into list (trimmed copies). Returns the item count, or -1 on allocation
 * failure (list is then empty). ex_list_free releases the items and empties the list. */
int ex_list_split(const char *value, ex_list *list);
void ex_list_free(ex_list *list);

/* Name resolution during parsing. `primes` is 0 for `name`, 1 for `name'` (2 for `name''`
 * only when the parse was started with allow_second = 1). Return a node id, or -1 with a
 * message in err (e.g. "unknown name 'q'", "a prime is only allowed on an unknown"). */
typedef ex_id (*ex_resolve_fn)(ex_dag *d, const char *name, int primes, void *user, char *err,
                               size_t errlen);

/* Parse src (grammar of SCENES.md "Expressions"): numbers, pi, names (via resolve),
 * + - * / unary -, ^ (right-assoc., tighter than unary minus), parentheses, the functions
 * of SCENES.md, if(cond, a, b) with < <= > >= in cond. Returns a node id, or -1 with
 * err = "column C: what is wrong" (1-based column). Nesting depth is bounded (no stack
 * overflow on hostile input): too deep gives an error, not a crash. */
ex_id ex_parse(ex_dag *d, const char *src, ex_resolve_fn resolve, void *user, int allow_second,
               char *err, size_t errlen);

/* Symbolic derivative d e / d slot. At kinks (abs, min, max, if) the derivative of the
 * branch taken. Comparisons have derivative 0. Returns -1 on allocation failure. */
ex_id ex_diff(ex_dag *d, ex_id e, int slot);

/* Replace slot `slot` by node `by` everywhere in e (for chain rules and substitution). */
ex_id ex_subst(ex_dag *d, ex_id e, int slot, ex_id by);

/* e with its jumps in the slots lo..hi smoothed over the width read from slot wslot
 * (theory X-6): every if(u cmp v, a, b) and every comparison used as a number whose
 * condition depends on one of those slots becomes a C^2 blend of its branches across
 * |t| < w, t the signed distance of the comparison's operands; w = 0 gives e's own
 * values. *count: the jumps smoothed (0: the result is e itself). -1 on allocation failure. */
ex_id ex_smooth_jumps(ex_dag *d, ex_id e, int lo, int hi, int wslot, int *count);

/* Print e in the SCENES.md grammar, fully re-parseable, minimal parentheses. Slot names
 * come from names[slot] (e.g. "th", "th'", "th''"). Returns the length that the full text
 * needs (like snprintf); writes at most len bytes including the terminating NUL. */
size_t ex_print(const ex_dag *d, ex_id e, const char *const *names, char *buf, size_t len);

/* A straight-line program evaluating nout expressions over batches of points. */
typedef struct ex_tape ex_tape;

/* Compile outs[0..nout-1] (nodes of d) into a tape with nslots inputs. Only the nodes the
 * outputs reach are compiled; shared subexpressions are computed once. NULL on failure. */
ex_tape *ex_tape_new(const ex_dag *d, int nslots, int nout, const ex_id *outs);
void ex_tape_free(ex_tape *t);
/* Scratch doubles ex_tape_eval needs for a batch of m points. */
size_t ex_tape_work_size(const ex_tape *t, int m);
/* Evaluate at m points: in[s][k] is slot s at point k (in[s] may be NULL for a slot the
 * outputs do not use); out[o][k] receives output o. work has ex_tape_work_size(t, m)
 * doubles. Non-finite results are written as they come (the caller checks). The in[],
 * out[] and work arrays must not overlap one another (the kernels are compiled with
 * restrict so they vectorise). */
void ex_tape_eval(const ex_tape *t, int m, const double *const *in, double *const *out,
                  double *work);
int ex_tape_num_instructions(const ex_tape *t);
/* After ex_tape_eval with the same m and work: 1 when a table call met a point outside its
 * grid (the outputs there are NaN), with a sentence naming the table in msg; else 0. */
int ex_tape_fault(const ex_tape *t, int m, const double *work, char *msg, size_t len);
/* Number of distinct tables the tape calls. */
int ex_tape_num_tables(const ex_tape *t);

/* The DAG node by node, and reference evaluation. */
/* Number of nodes in d; valid ids are 0 .. ex_dag_num_nodes(d) - 1. */
int ex_dag_num_nodes(const ex_dag *d);
/* Operand i (0, 1, 2) of node e, or -1 when the node has fewer operands. Operands always
 * have smaller ids than the node. For if(c, a, b) the operands are c, a, b in that order. */
ex_id ex_node_arg(const ex_dag *d, ex_id e, int i);
/* Value of e at one point: slots[s] is the value of slot s (only the slots e depends on are
 * read). Reference evaluation (straight from the DAG, libm for every operation); for many
 * points compile a tape. Returns 0, or -1 on allocation failure. */
int ex_eval(const ex_dag *d, ex_id e, const double *slots, double *value);
/* The same with each slot's value from slot_value(user, s) (when not NULL): no array as
 * long as the largest slot is needed. */
int ex_eval_with(const ex_dag *d, ex_id e, const double *slots,
                 double (*slot_value)(void *user, int slot), void *user, double *value);

/* Collect like terms (ex_collect.c): every sum in e becomes sum_k c_k t_k + c0 with each
 * distinct term once, numeric factors peeled off (2*t, t/2, -t). For display: combining
 * coefficients may change the value by rounding (a few ulps). -1 on allocation failure. */
ex_id ex_collect(ex_dag *d, ex_id e);

/* Tables (ex_table.c): a cv_table (calcvar.h) registered under a name becomes callable as
 * `name(u, ...)` and `name.K(u, ...)` in ex_parse (K: one digit 1..3 per derivative, e.g.
 * `h.1` = dh/du, `h.12` = d2h/du dv). The DAG keeps a reference to the table. A call node
 * has the arguments as operands and ex_table_orders() derivative orders; ex_diff gives
 * table-derivative nodes (chain rule), so every partial stays exact. */
struct cv_table;
/* Register t as `name` (an identifier, not a function or pi, not registered yet): its
 * index 0, 1, ..., or -1 (bad or taken name, allocation failure). */
int ex_dag_add_table(ex_dag *d, const char *name, struct cv_table *t);
/* Index of the table called `name`, or -1. */
int ex_dag_find_table(const ex_dag *d, const char *name);
int ex_dag_num_tables(const ex_dag *d);
const char *ex_dag_table_name(const ex_dag *d, int index);
/* The call node of table `index` with derivative orders ord[k] (NULL: 0) at args[0..dim-1]
 * (dim of the table). A call at numbers inside the grid folds to a number; an order above
 * 3 along some coordinate is the number 0 (the spline is cubic). -1 on failure. */
ex_id ex_table_call(ex_dag *d, int index, const int *ord, const ex_id *args);
/* For an EX_TABLE node: the table index, and the orders into ord[3]; -1 otherwise. */
int ex_table_of(const ex_dag *d, ex_id e, int ord[3]);

#endif /* CV_EXPR_H */
