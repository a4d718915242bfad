/* src/scene/scene_load.c — load a scene: read, then interpret [scene], [parameters] and
 * [definitions], then the other sections (scene_sections.c, scene_options.c).
 * SPDX-License-Identifier: MIT */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "scene/scene_internal.h"

/* scene_sections.c, scene_options.c */
int sc_load_boundary(sc_loader *L);
int sc_load_guess_exact(sc_loader *L);
int sc_load_constraints(sc_loader *L);
int sc_load_report(sc_loader *L);
int sc_load_mesh(sc_loader *L);
int sc_load_solver(sc_loader *L);
int sc_load_plot(sc_loader *L);
int sc_load_ends(sc_loader *L);

static void items_free(sc_item *it, int n) {
  for (int i = 0; i < n; i++) cv_free(it[i].name);
  cv_free(it);
}

void scene_free(scene *s) {
  if (!s) return;
  if (s->is_instance) { /* only what scene_instance_new copied */
    cv_free(s->params);
    cv_free(s->bc);
    cv_free(s->ints);
    cv_free(s->sbc);
    cv_free(s);
    return;
  }
  cv_free(s->file);
  cv_free(s->title);
  cv_free(s->variable);
  for (int i = 0; i < s->n; i++) cv_free(s->unknowns[i]);
  cv_free(s->unknowns);
  cv_free(s->plot_down);
  cv_free(s->bc);
  cv_free(s->ends[0].Gy);
  cv_free(s->ends[1].Gy);
  cv_free(s->guess);
  cv_free(s->exact);
  items_free(s->params, s->nparams);
  items_free(s->defs, s->ndefs);
  items_free(s->cons, s->ncons);
  items_free(s->ints, s->nints);
  items_free(s->reports, s->nreports);
  cv_free(s->breakpoints);
  cv_free(s->order2);
  cv_free(s->sbc);
  ex_dag_free(s->dag);
  cv_free(s);
}

static const sc_entry *find_entry(const sc_loader *L, int sec, const char *key) {
  for (int i = 0; i < L->raw.ne[sec]; i++)
    if (strcmp(L->raw.e[sec][i].key, key) == 0) return &L->raw.e[sec][i];
  return NULL;
}

/* Keys of a fixed-key section must come from `keys` (NULL-terminated). */
int sc_check_keys(sc_loader *L, int sec, const char *const *keys, const char *list) {
  for (int i = 0; i < L->raw.ne[sec]; i++) {
    const sc_entry *e = &L->raw.e[sec][i];
    int ok = 0;
    for (int k = 0; keys[k]; k++) ok |= strcmp(e->key, keys[k]) == 0;
    if (!ok) {
      ex_nearest nr = {NULL, 0};
      for (int k = 0; keys[k]; k++) ex_name_consider(&nr, e->key, keys[k]);
      const char *near = nr.best;
      sc_err(L->err, L->errlen, L->file, e->line, "unknown key '%s' in [%s] (%s%s%sknown: %s)",
             e->key, sc_section_name(sec), near ? "did you mean '" : "", near ? near : "",
             near ? "'? " : "", list);
      return -1;
    }
  }
  return 0;
}

/* Is `name` already taken by the variable, an unknown, a parameter, a definition or a
 * table? (One lookup in the loader's map: a scene may define 10^5 names.) */
static const char *taken(const sc_loader *L, const char *name) {
  static const char *const what[SC_NAME_KINDS] = {"the variable", "an unknown", "a parameter",
                                                  "a definition"};
  int code = sc_namemap_get(&L->names, name);
  if (code >= 0) return what[code % SC_NAME_KINDS];
  if (ex_dag_find_table(L->s->dag, name) >= 0) return "a table";
  return NULL;
}

/* A new name for the variable, an unknown, a parameter or a definition. */
int sc_check_new_name(sc_loader *L, int line, const char *name, const char *role) {
  const char *t;
  if (!ex_is_identifier(name)) {
    sc_err(L->err, L->errlen, L->file, line,
           "'%s' is not a valid %s name (letters, digits and '_', starting with a letter)", name,
           role);
    return -1;
  }
  if (sc_is_reserved(name)) {
    sc_err(L->err, L->errlen, L->file, line, "'%s' is reserved and cannot name %s", name, role);
    return -1;
  }
  if ((t = taken(L, name)) != NULL) {
    sc_err(L->err, L->errlen, L->file, line, "'%s' is already %s", name, t);
    return -1;
  }
  return 0;
}

static int load_scene_section(sc_loader *L) {
  static const char *const keys[] = {"title",    "variable",  "interval",
                                     "unknowns", "integrand", NULL};
  scene *s = L->s;
  int hl = L->raw.sec_line[SEC_SCENE];
  if (!hl) {
    sc_err(L->err, L->errlen, L->file, 1, "the section [scene] is missing");
    return -1;
  }
  if (sc_check_keys(L, SEC_SCENE, keys, "title, variable, interval, unknowns, integrand") < 0)
    return -1;
  const sc_entry *e = find_entry(L, SEC_SCENE, "title");
  if (e && !sc_is_utf8(e->value)) { /* the JSON report (and Python) need UTF-8 text */
    sc_err(L->err, L->errlen, L->file, e->line, "the title is not UTF-8 text");
    return -1;
  }
  s->title = sc_strdup(e ? e->value : L->file);
  e = find_entry(L, SEC_SCENE, "variable");
  if (e && sc_check_new_name(L, e->line, e->value, "variable") < 0) return -1;
  s->variable = sc_strdup(e ? e->value : "x");
  if (!s->title || !s->variable) goto nomem;
  if (sc_name_add(L, hl, s->variable, SC_NAME_VARIABLE, 0) < 0) return -1;

  e = find_entry(L, SEC_SCENE, "unknowns");
  if (!e) {
    sc_err(L->err, L->errlen, L->file, hl, "[scene] needs 'unknowns = name, ...'");
    return -1;
  }
  ex_list list;
  if (ex_list_split(e->value, &list) < 0) goto nomem;
  if (list.n > SC_MAX_UNKNOWNS) {
    sc_err(L->err, L->errlen, L->file, e->line, "at most %d unknowns, got %d", SC_MAX_UNKNOWNS,
           list.n);
    ex_list_free(&list);
    return -1;
  }
  s->unknowns = cv_calloc((size_t)list.n, sizeof *s->unknowns);
  if (!s->unknowns) {
    ex_list_free(&list);
    goto nomem;
  }
  for (int i = 0; i < list.n; i++) {
    int line, col;
    sc_entry_locate(e, list.off[i], &line, &col);
    if (sc_check_new_name(L, line, list.item[i], "unknown") < 0) {
      ex_list_free(&list);
      return -1;
    }
    s->unknowns[s->n++] = list.item[i];
    list.item[i] = NULL;
    if (sc_name_add(L, line, s->unknowns[i], SC_NAME_UNKNOWN, i) < 0) {
      ex_list_free(&list);
      return -1;
    }
  }
  ex_list_free(&list);
  if (!find_entry(L, SEC_SCENE, "interval")) {
    sc_err(L->err, L->errlen, L->file, hl, "[scene] needs 'interval = a, b'");
    return -1;
  }
  if (!find_entry(L, SEC_SCENE, "integrand")) {
    sc_err(L->err, L->errlen, L->file, hl, "[scene] needs 'integrand = F(%s, ...)'", s->variable);
    return -1;
  }
  return 0;
nomem:
  sc_err(L->err, L->errlen, L->file, hl, "out of memory");
  return -1;
}

/* [parameters] in order; an override replaces a parameter's expression, so later
 * parameters built from it follow. */
static int load_parameters(sc_loader *L, int nset, const sc_set *set) {
  scene *s = L->s;
  int ne = L->raw.ne[SEC_PARAMETERS];
  s->params = cv_calloc((size_t)ne + 1, sizeof *s->params);
  if (!s->params) {
    sc_err(L->err, L->errlen, L->file, 0, "out of memory");
    return -1;
  }
  for (int i = 0; i < ne; i++) {
    const sc_entry *e = &L->raw.e[SEC_PARAMETERS][i];
    if (sc_check_new_name(L, e->line, e->key, "parameter") < 0) return -1;
    s->params[i].name = sc_strdup(e->key);
    s->params[i].line = e->line;
    s->params[i].expr2 = -1;
    s->nparams = i + 1;
    if (!s->params[i].name) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
    if (sc_name_add(L, e->line, s->params[i].name, SC_NAME_PARAMETER, i) < 0) return -1;
  }
  for (int k = 0; k < nset; k++) {
    if (sc_name_find(L, set[k].name, SC_NAME_PARAMETER) < 0) {
      sc_err(L->err, L->errlen, L->file, 0,
             "--set %s=%s: '%s' is not a parameter of this "
             "scene%s",
             set[k].name, set[k].value, set[k].name, ne ? "" : " (it has no [parameters])");
      return -1;
    }
  }
  L->mode = SC_R_PARAM;
  for (int i = 0; i < ne; i++) {
    const sc_entry *e = &L->raw.e[SEC_PARAMETERS][i];
    const sc_set *over = NULL;
    for (int k = 0; k < nset; k++)
      if (strcmp(set[k].name, e->key) == 0) over = &set[k]; /* the last --set of a name wins */
    L->limit = i;
    char what[160];
    ex_id *def = &s->params[i].expr2; /* kept only with parameters as inputs */
    if (over) {
      /* No line to point to: the value came from the command line. */
      sc_entry fake = {NULL, NULL, 0, 0, NULL};
      snprintf(what, sizeof what, "--set %s=%s", over->name, over->value);
      if (sc_parse_const_node(L, &fake, 0, over->value, what, &s->params[i].value, def) < 0)
        return -1;
    } else {
      snprintf(what, sizeof what, "parameter '%s'", e->key);
      if (sc_parse_const_node(L, e, 0, e->value, what, &s->params[i].value, def) < 0) return -1;
    }
    s->params[i].expr = s->params_as_inputs ? ex_slot(s->dag, 1 + 2 * s->n + i)
                                            : ex_num(s->dag, s->params[i].value);
    if (s->params[i].expr < 0) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
  }
  return 0;
}

static int load_definitions(sc_loader *L) {
  scene *s = L->s;
  int ne = L->raw.ne[SEC_DEFINITIONS];
  s->defs = cv_calloc((size_t)ne + 1, sizeof *s->defs);
  if (!s->defs) {
    sc_err(L->err, L->errlen, L->file, 0, "out of memory");
    return -1;
  }
  /* Names first, so that a use before the definition is told as such. */
  for (int i = 0; i < ne; i++) {
    const sc_entry *e = &L->raw.e[SEC_DEFINITIONS][i];
    if (sc_check_new_name(L, e->line, e->key, "definition") < 0) return -1;
    s->defs[i].name = sc_strdup(e->key);
    s->defs[i].line = e->line;
    s->defs[i].expr = s->defs[i].expr2 = -1;
    s->ndefs = i + 1;
    if (!s->defs[i].name) {
      sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
      return -1;
    }
    if (sc_name_add(L, e->line, s->defs[i].name, SC_NAME_DEFINITION, i) < 0) return -1;
  }
  L->mode = SC_R_FULL;
  for (int i = 0; i < ne; i++) {
    const sc_entry *e = &L->raw.e[SEC_DEFINITIONS][i];
    char what[160];
    snprintf(what, sizeof what, "definition '%s'", e->key);
    L->limit = i;
    if ((s->defs[i].expr = sc_parse(L, e, 0, e->value, what)) < 0) return -1;
  }
  L->limit = ne;
  return 0;
}

static int load_interval_integrand(sc_loader *L) {
  scene *s = L->s;
  const sc_entry *e = find_entry(L, SEC_SCENE, "interval");
  ex_list list;
  if (ex_list_split(e->value, &list) < 0) {
    sc_err(L->err, L->errlen, L->file, e->line, "out of memory");
    return -1;
  }
  int rc = -1;
  if (list.n != 2) {
    sc_err(L->err, L->errlen, L->file, e->line, "interval needs two values 'a, b', got %d", list.n);
    goto done;
  }
  if (sc_parse_const_node(L, e, list.off[0], list.item[0], "interval start a", &s->a, &s->a_expr) <
          0 ||
      sc_parse_const_node(L, e, list.off[1], list.item[1], "interval end b", &s->b, &s->b_expr) < 0)
    goto done;
  if (!(s->a < s->b)) {
    sc_err(L->err, L->errlen, L->file, e->line, "interval needs a < b, got a = %.17g, b = %.17g",
           s->a, s->b);
    goto done;
  }
  if (!isfinite(s->b - s->a)) { /* -1e308, 1e308: the length overflows */
    sc_err(L->err, L->errlen, L->file, e->line,
           "interval: the length b - a of [%g, %g] is larger than the largest double", s->a, s->b);
    goto done;
  }
  e = find_entry(L, SEC_SCENE, "integrand");
  s->F_line = e->line;
  if ((s->F = sc_parse(L, e, 0, e->value, "integrand")) < 0) goto done;
  rc = 0;
done:
  ex_list_free(&list);
  return rc;
}

static scene *load_buffer(const char *text, size_t len, const char *name, int nset,
                          const sc_set *set, int inputs, char *err, size_t errlen) {
  sc_loader L;
  memset(&L, 0, sizeof L);
  if (err && errlen) err[0] = '\0';
  scene *s = cv_calloc(1, sizeof *s);
  if (!s || !(s->file = sc_strdup(name ? name : "scene")) || !(s->dag = ex_dag_new())) {
    scene_free(s);
    sc_err(err, errlen, name ? name : "scene", 0, "out of memory");
    return NULL;
  }
  s->F = -1;
  s->params_as_inputs = inputs;
  s->a_expr = s->b_expr = s->exact_action_expr = -1;
  L.s = s;
  L.file = s->file;
  L.err = err;
  L.errlen = errlen;
  if (sc_raw_read(&L.raw, text, len, s->file, err, errlen) < 0) {
    scene_free(s);
    return NULL;
  }
  if (load_scene_section(&L) < 0 || sc_load_tables(&L) < 0 || load_parameters(&L, nset, set) < 0 ||
      load_definitions(&L) < 0 || load_interval_integrand(&L) < 0 || sc_load_boundary(&L) < 0 ||
      sc_load_guess_exact(&L) < 0 || sc_load_constraints(&L) < 0 || sc_load_ends(&L) < 0 ||
      sc_load_report(&L) < 0 || sc_load_mesh(&L) < 0 || sc_load_solver(&L) < 0 ||
      sc_load_plot(&L) < 0 || sc_load_order2(&L) < 0) {
    sc_raw_free(&L.raw);
    sc_namemap_free(&L.names);
    scene_free(s);
    return NULL;
  }
  sc_raw_free(&L.raw);
  sc_namemap_free(&L.names);
  return s;
}

scene *scene_load_buffer(const char *text, size_t len, const char *name, int nset,
                         const sc_set *set, char *err, size_t errlen) {
  return load_buffer(text, len, name, nset, set, 0, err, errlen);
}

scene *scene_load_buffer_inputs(const char *text, size_t len, const char *name, int nset,
                                const sc_set *set, char *err, size_t errlen) {
  return load_buffer(text, len, name, nset, set, 1, err, errlen);
}
