/* src/expr/ex_names.c — the grammar's words: its function table (name, operation, number
 * of arguments), reserved names, identifiers, and comma lists of values.
 * SPDX-License-Identifier: MIT */
#include <ctype.h>
#include <string.h>

#include "expr/ex_internal.h"

/* The one table of the grammar's functions: the parser looks names up in it, printing and
 * error messages name operations from it, and a name in it cannot be a parameter or an
 * unknown. */
static const ex_function functions[] = {
    {"sin", EX_SIN, 1},     {"cos", EX_COS, 1},     {"tan", EX_TAN, 1},     {"asin", EX_ASIN, 1},
    {"acos", EX_ACOS, 1},   {"atan", EX_ATAN, 1},   {"sinh", EX_SINH, 1},   {"cosh", EX_COSH, 1},
    {"tanh", EX_TANH, 1},   {"asinh", EX_ASINH, 1}, {"acosh", EX_ACOSH, 1}, {"atanh", EX_ATANH, 1},
    {"exp", EX_EXP, 1},     {"log", EX_LOG, 1},     {"sqrt", EX_SQRT, 1},   {"abs", EX_ABS, 1},
    {"atan2", EX_ATAN2, 2}, {"pow", EX_POW, 2},     {"min", EX_MIN, 2},     {"max", EX_MAX, 2},
    {"if", EX_IF, 3}};
#define NUM_FUNCTIONS (sizeof functions / sizeof functions[0])

const ex_function *ex_function_find(const char *name) {
  for (size_t i = 0; i < NUM_FUNCTIONS; i++)
    if (strcmp(functions[i].name, name) == 0) return &functions[i];
  return NULL;
}

/* Edit distance between two short names (insertions, deletions, substitutions and swaps of
 * neighbours: the usual typing slips); names longer than 31 characters count as far. */
int ex_name_distance(const char *a, const char *b) {
  enum { M = 32 };
  size_t la = strlen(a), lb = strlen(b);
  if (la >= M || lb >= M) return M;
  int d[M + 1][M + 1];
  for (size_t i = 0; i <= la; i++) d[i][0] = (int)i;
  for (size_t j = 0; j <= lb; j++) d[0][j] = (int)j;
  for (size_t i = 1; i <= la; i++)
    for (size_t j = 1; j <= lb; j++) {
      int c = d[i - 1][j - 1] + (a[i - 1] != b[j - 1]);
      if (d[i - 1][j] + 1 < c) c = d[i - 1][j] + 1;
      if (d[i][j - 1] + 1 < c) c = d[i][j - 1] + 1;
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < c)
        c = d[i - 2][j - 2] + 1;
      d[i][j] = c;
    }
  return d[la][lb];
}

int ex_name_close(const char *typed, const char *known) {
  int dist = ex_name_distance(typed, known), len = (int)strlen(typed);
  return dist > 0 && dist <= (len <= 4 ? 1 : 2) && dist < len;
}

void ex_name_consider(ex_nearest *nr, const char *typed, const char *known) {
  if (!known || !ex_name_close(typed, known)) return;
  /* ties: a name of the same length first (cohs: cosh, not cos) */
  int score = 2 * ex_name_distance(typed, known) + (strlen(typed) != strlen(known));
  if (!nr->best || score < nr->score) nr->best = known, nr->score = score;
}

const char *ex_function_nearest(const char *name) {
  ex_nearest nr = {NULL, 0};
  for (size_t i = 0; i < NUM_FUNCTIONS; i++) ex_name_consider(&nr, name, functions[i].name);
  return nr.best;
}

const char *ex_op_name(ex_op op) {
  for (size_t i = 0; i < NUM_FUNCTIONS; i++)
    if (functions[i].op == op) return functions[i].name;
  return NULL;
}

int ex_is_identifier(const char *s) {
  if (!(isalpha((unsigned char)s[0]) || s[0] == '_')) return 0;
  for (const char *p = s + 1; *p; p++)
    if (!(isalnum((unsigned char)*p) || *p == '_')) return 0;
  return 1;
}

int ex_is_reserved(const char *s) { return strcmp(s, "pi") == 0 || ex_function_find(s); }

void ex_list_free(ex_list *list) {
  for (int i = 0; i < list->n; i++) cv_free(list->item[i]);
  cv_free(list->item);
  cv_free(list->off);
  memset(list, 0, sizeof *list);
}

/* Split at commas outside parentheses (`atan2(1, 2), 0` is two values); each item is
 * trimmed of white space. Returns the item count, or -1 on allocation failure. */
int ex_list_split(const char *value, ex_list *list) {
  int depth = 0, cap = 0;
  const char *start = value;
  memset(list, 0, sizeof *list);
  for (const char *p = value;; p++) {
    if (*p == '(')
      depth++;
    else if (*p == ')' && depth > 0)
      depth--;
    if (*p == '\0' || (*p == ',' && depth == 0)) {
      const char *a = start, *b = p;
      while (a < b && isspace((unsigned char)*a)) a++;
      while (b > a && isspace((unsigned char)b[-1])) b--;
      if (list->n == cap) {
        cap = cap ? 2 * cap : 4;
        char **it = cv_realloc(list->item, (size_t)cap * sizeof *it);
        if (it) list->item = it;
        int *off = cv_realloc(list->off, (size_t)cap * sizeof *off);
        if (off) list->off = off;
        if (!it || !off) goto nomem;
      }
      size_t len = (size_t)(b - a);
      char *item = cv_malloc(len + 1);
      if (!item) goto nomem;
      memcpy(item, a, len);
      item[len] = '\0';
      list->item[list->n] = item;
      list->off[list->n++] = (int)(a - value);
      if (*p == '\0') break;
      start = p + 1;
    }
  }
  return list->n;
nomem:
  ex_list_free(list);
  return -1;
}
