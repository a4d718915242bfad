/* src/scene/scene_mechanics_json.c — the mechanics of a scene as text and JSON: the printed
 * expressions of the equations and the JSON documents of `calcvar equations --json` and
 * `calcvar modes --json` (docs/cli.md, docs/mechanics.md). One builder for the command and
 * the public API (cv_equations_json, cv_modes_json), so both give the same bytes.
 * SPDX-License-Identifier: MIT
 *
 * The expressions are printed in the scene grammar (ex_print), with parameters as numbers,
 * so the JSON strings parse and evaluate without the scene.
 */
#include <jansson.h>
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_mechanics.h"

/* e printed in the scene grammar; NULL on allocation failure. */
static char *print_expr(const scene *s, const mech_equations *eq, ex_id e) {
  const char *const *names = (const char *const *)eq->names;
  size_t len = ex_print(s->dag, e, names, NULL, 0) + 1;
  char *buf = cv_malloc(len);
  if (buf) ex_print(s->dag, e, names, buf, len);
  return buf;
}

int scene_eq_texts_make(scene_eq_texts *t, const scene *s, const mech_equations *eq) {
  int n = s->n;
  memset(t, 0, sizeof *t);
  t->n = n;
  t->mom = cv_calloc((size_t)n + 1, sizeof *t->mom);
  t->el = cv_calloc((size_t)n + 1, sizeof *t->el);
  if (!t->mom || !t->el) return -1;
  for (int i = 0; i < n; i++)
    if (!(t->mom[i] = print_expr(s, eq, eq->momentum[i])) ||
        !(t->el[i] = print_expr(s, eq, eq->el[i])))
      return -1;
  if (eq->momentum2) {
    if (!(t->mom2 = cv_calloc((size_t)n + 1, sizeof *t->mom2))) return -1;
    for (int i = 0; i < n; i++)
      if (!(t->mom2[i] = print_expr(s, eq, eq->momentum2[i]))) return -1;
  }
  ex_id F = ex_collect(s->dag, eq->F >= 0 ? eq->F : s->F); /* in mech's slots */
  if (F < 0 || !(t->H = print_expr(s, eq, eq->hamiltonian)) || !(t->F = print_expr(s, eq, F)))
    return -1;
  return 0;
}

void scene_eq_texts_free(scene_eq_texts *t) {
  for (int i = 0; i < t->n; i++) {
    if (t->mom) cv_free(t->mom[i]);
    if (t->el) cv_free(t->el[i]);
    if (t->mom2) cv_free(t->mom2[i]);
  }
  cv_free(t->mom2);
  cv_free(t->mom);
  cv_free(t->el);
  cv_free(t->H);
  cv_free(t->F);
  memset(t, 0, sizeof *t);
}

char *scene_equations_json(const scene *s, const mech_equations *eq, const scene_eq_texts *t) {
  json_t *o = json_object(), *mom = json_object(), *el = json_object(), *cyc = json_array();
  char *text = NULL;
  if (!o || !mom || !el || !cyc) {
    json_decref(mom);
    json_decref(el);
    json_decref(cyc);
    goto done;
  }
  for (int i = 0; i < s->n; i++) {
    json_object_set_new(mom, s->unknowns[i], json_string(t->mom[i]));
    json_object_set_new(el, s->unknowns[i], json_string(t->el[i]));
    if (eq->cyclic[i]) json_array_append_new(cyc, json_string(s->unknowns[i]));
  }
  json_object_set_new(o, "momenta", mom);
  if (t->mom2) { /* a second-order Lagrangian: Ostrogradsky's second momenta dF/dy'' */
    json_t *m2 = json_object();
    for (int i = 0; m2 && i < s->n; i++)
      json_object_set_new(m2, s->unknowns[i], json_string(t->mom2[i]));
    if (m2) json_object_set_new(o, "momenta_second", m2);
  }
  json_object_set_new(o, "euler_lagrange", el);
  json_object_set_new(o, "hamiltonian", json_string(t->H));
  json_object_set_new(o, "cyclic", cyc);
  json_object_set_new(o, "autonomous", json_boolean(eq->autonomous));
  text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER);
done:
  json_decref(o);
  return text;
}

const char *scene_mode_kind_name(mech_mode_kind k) {
  return k == MECH_MODE_STABLE ? "stable" : k == MECH_MODE_UNSTABLE ? "unstable" : "neutral";
}

char *scene_modes_json(const scene *s, const mech_modes *md) {
  int n = s->n;
  json_t *o = json_object(), *eqm = json_object(), *modes = json_array();
  char *text = NULL;
  if (!o || !eqm || !modes) {
    json_decref(eqm);
    json_decref(modes);
    goto done;
  }
  for (int i = 0; i < n; i++)
    json_object_set_new(eqm, s->unknowns[i], json_real(md->equilibrium[i]));
  for (int k = 0; k < md->nmodes; k++) {
    json_t *m = json_object(), *sh = json_object();
    if (!m || !sh) {
      json_decref(m);
      json_decref(sh);
      json_decref(eqm);
      json_decref(modes);
      goto done;
    }
    json_object_set_new(m, "omega2", json_real(md->omega2[k]));
    json_object_set_new(m, "kind", json_string(scene_mode_kind_name(md->kind[k])));
    for (int i = 0; i < n; i++)
      json_object_set_new(sh, s->unknowns[i], json_real(md->shape[k * n + i]));
    json_object_set_new(m, "shape", sh);
    json_array_append_new(modes, m);
  }
  json_object_set_new(o, "equilibrium", eqm);
  json_object_set_new(o, "modes", modes);
  /* Addition to the contract: the multipliers of [constraints] at the equilibrium. */
  if (md->nc > 0) {
    json_t *mu = json_object();
    if (!mu) goto done;
    for (int c = 0; c < md->nc; c++)
      json_object_set_new(mu, s->cons[c].name, json_real(md->multipliers[c]));
    json_object_set_new(o, "multipliers", mu);
  }
  /* Addition to the contract: with gyroscopic terms, the motions of M y'' + G y' + K y = 0
   * (docs/mechanics.md); absent when G = 0. */
  if (md->ngyro > 0) {
    json_t *g = json_object(), *gm = json_array();
    if (!g || !gm) {
      json_decref(g);
      json_decref(gm);
      goto done;
    }
    json_object_set_new(g, "max_abs_G", json_real(md->gyroscopic));
    for (int k = 0; k < md->ngyro; k++) {
      json_t *m = json_object();
      if (!m) {
        json_decref(g);
        json_decref(gm);
        goto done;
      }
      json_object_set_new(m, "kind", json_string(scene_mode_kind_name(md->gyro_kind[k])));
      json_object_set_new(m, "omega", json_real(md->gyro_omega[k]));
      json_object_set_new(m, "growth", json_real(md->gyro_growth[k]));
      json_array_append_new(gm, m);
    }
    json_object_set_new(g, "modes", gm);
    json_object_set_new(o, "gyroscopic", g);
  }
  text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
done:
  json_decref(o);
  return text;
}
