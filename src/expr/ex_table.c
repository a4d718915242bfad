/* src/expr/ex_table.c — table calls in the DAG: registry of named cv_tables, the call
 * node, its folding, evaluation and derivative (theory TB-5). SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "core/cv_memory.h"
#include "core/cv_table_internal.h"
#include "expr/ex_internal.h"

int ex_dag_add_table(ex_dag *d, const char *name, struct cv_table *t) {
  if (!d || !name || !t || ex_dag_find_table(d, name) >= 0 || strcmp(name, "pi") == 0) return -1;
  if (!(name[0] == '_' || (name[0] >= 'a' && name[0] <= 'z') || (name[0] >= 'A' && name[0] <= 'Z')))
    return -1;
  for (int op = 0; op < EX_NUM_OPS; op++) {
    const char *fn = ex_op_name((ex_op)op);
    if (fn && strcmp(fn, name) == 0) return -1;
  }
  size_t len = strlen(name);
  char *copy = cv_malloc(len + 1);
  char **names = cv_realloc(d->tab_name, ((size_t)d->ntables + 1) * sizeof *names);
  if (names) d->tab_name = names;
  struct cv_table **tabs = cv_realloc(d->tabs, ((size_t)d->ntables + 1) * sizeof *tabs);
  if (tabs) d->tabs = tabs;
  if (!copy || !names || !tabs) {
    cv_free(copy);
    return -1;
  }
  memcpy(copy, name, len + 1);
  d->tab_name[d->ntables] = copy;
  d->tabs[d->ntables] = cv_table_ref(t);
  return d->ntables++;
}

void ex_dag_free_tables(ex_dag *d) {
  for (int i = 0; i < d->ntables; i++) {
    cv_free(d->tab_name[i]);
    cv_table_free(d->tabs[i]);
  }
  cv_free(d->tab_name);
  cv_free(d->tabs);
  d->tab_name = NULL;
  d->tabs = NULL;
  d->ntables = 0;
}

int ex_dag_find_table(const ex_dag *d, const char *name) {
  if (!d || !name) return -1;
  for (int i = 0; i < d->ntables; i++)
    if (strcmp(d->tab_name[i], name) == 0) return i;
  return -1;
}

int ex_dag_num_tables(const ex_dag *d) { return d ? d->ntables : 0; }

const char *ex_dag_table_name(const ex_dag *d, int index) {
  return d && index >= 0 && index < d->ntables ? d->tab_name[index] : NULL;
}

void ex_table_decode(double v, int *index, int ord[3]) {
  int code = (int)v;
  *index = code / 64;
  ord[0] = (code / 16) % 4;
  ord[1] = (code / 4) % 4;
  ord[2] = code % 4;
}

int ex_table_of(const ex_dag *d, ex_id e, int ord[3]) {
  if (!d || e < 0 || e >= d->n || d->nodes[e].op != EX_TABLE) return -1;
  int index, o[3];
  ex_table_decode(d->nodes[e].v, &index, o);
  if (ord) memcpy(ord, o, sizeof o);
  return index;
}

int ex_table_apply(const ex_dag *d, const ex_node *nd, const double *u, double *value) {
  int index, ord[3];
  ex_table_decode(nd->v, &index, ord);
  if (index < 0 || index >= d->ntables) {
    *value = NAN;
    return -1;
  }
  return cv_table_eval(d->tabs[index], u, ord, value);
}

ex_id ex_table_call(ex_dag *d, int index, const int *ord, const ex_id *args) {
  if (!d || index < 0 || index >= d->ntables || !args) return -1;
  int dim = cv_table_get_dim(d->tabs[index]), o[3] = {0, 0, 0};
  ex_id a[3] = {-1, -1, -1};
  int all_num = 1;
  for (int k = 0; k < dim; k++) {
    if (args[k] < 0 || args[k] >= d->n) return -1;
    a[k] = args[k];
    o[k] = ord ? ord[k] : 0;
    if (o[k] < 0) return -1;
    if (o[k] > 3) return ex_num(d, 0.0); /* the fourth derivative of a cubic */
    all_num &= d->nodes[a[k]].op == EX_NUM;
  }
  ex_node nd = {EX_TABLE, a[0], a[1], a[2], EX_TABLE_CODE(index, o[0], o[1], o[2]), 0, 0, 0, 0};
  if (all_num) { /* fold inside the grid; outside, the call stays and fails when used */
    double u[3], v;
    for (int k = 0; k < dim; k++) u[k] = d->nodes[a[k]].v;
    if (ex_table_apply(d, &nd, u, &v) == 0 && isfinite(v)) return ex_num(d, v);
  }
  return ex_intern(d, EX_TABLE, a[0], a[1], a[2], nd.v);
}

/* TB-5: the chain rule through the spline, d/ds T_o(a) = sum_k T_{o + e_k}(a) a_k'. */
ex_id ex_table_diff(ex_dag *d, const ex_node *nd, const ex_id *dargs) {
  int index, ord[3];
  ex_table_decode(nd->v, &index, ord);
  ex_id args[3] = {nd->a, nd->b, nd->c};
  ex_id sum = ex_num(d, 0.0);
  for (int k = 0; k < 3 && args[k] >= 0 && sum >= 0; k++) {
    if (d->nodes[dargs[k]].op == EX_NUM && d->nodes[dargs[k]].v == 0) continue;
    int o[3] = {ord[0], ord[1], ord[2]};
    o[k]++;
    ex_id part = ex_table_call(d, index, o, args);
    sum = ex_binary(d, EX_ADD, sum, ex_binary(d, EX_MUL, part, dargs[k]));
  }
  return sum;
}

ex_id ex_remake(ex_dag *d, const ex_node *nd, ex_id a, ex_id b, ex_id c) {
  if (nd->op != EX_TABLE) return ex_make(d, nd->op, a, b, c);
  int index, ord[3];
  ex_table_decode(nd->v, &index, ord);
  ex_id args[3] = {a, b, c};
  return ex_table_call(d, index, ord, args);
}
