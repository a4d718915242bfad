/* src/scene/scene_report_json.c — the JSON report of SCENES.md ("--json"), with jansson.
 * SPDX-License-Identifier: MIT
 *
 * Keys that do not apply are left out (never placeholders); so is any number that came
 * out non-finite, since JSON has no NaN. Reals are written with 17 significant digits, so
 * they read back to the same double.
 */
#include <jansson.h>
#include <math.h>

#include "scene/scene_report.h"

/* Set key to a real only when it is finite (json_real refuses NaN and infinities). */
static int set_real(json_t *o, const char *key, double v) {
  if (!isfinite(v)) return 0;
  return json_object_set_new(o, key, json_real(v));
}

static json_t *min_max(double lo, double hi, int drift) {
  json_t *o = json_object();
  if (!o) return NULL;
  set_real(o, "min", lo);
  set_real(o, "max", hi);
  if (drift) set_real(o, "drift", hi - lo);
  return o;
}

/* The report as a jansson object (NULL when out of memory); `converge` adds its keys. */
json_t *cli_report_json_object(const cli_report *r) {
  const scene *s = r->sc;
  json_t *o = json_object(), *a;
  if (!o) return NULL;
  json_object_set_new(o, "schema", json_integer(CVAR_REPORT_SCHEMA)); /* an addition */
  json_object_set_new(o, "title", json_string(s->title));
  json_object_set_new(o, "status", json_string(r->status));
  json_object_set_new(o, "message", json_string(r->message));
  json_object_set_new(o, "method", json_string(cv_method_name(r->method)));
  if (r->nodes > 0) {
    json_object_set_new(o, "elements", json_integer(r->elements));
    json_object_set_new(o, "degree", json_integer(r->degree));
    json_object_set_new(o, "nodes", json_integer(r->nodes));
    if (r->has_degrees && r->degrees) { /* --tol: the degree of each element, in order */
      json_t *d = json_array();
      for (int e = 0; e < r->elements; e++) json_array_append_new(d, json_integer(r->degrees[e]));
      json_object_set_new(o, "degrees", d);
    }
  }
  if (r->has_interval && isfinite(r->interval[0]) && isfinite(r->interval[1])) {
    json_t *iv = json_array(); /* a moving end: the solved [a, b] */
    json_array_append_new(iv, json_real(r->interval[0]));
    json_array_append_new(iv, json_real(r->interval[1]));
    json_object_set_new(o, "interval", iv);
  }
  a = json_array();
  for (int i = 0; i < s->n; i++) json_array_append_new(a, json_string(s->unknowns[i]));
  json_object_set_new(o, "unknowns", a);
  int periodic = 0;
  for (int i = 0; i < s->n; i++) periodic |= s->bc[i].periodic;
  if (periodic) { /* periodic paths: the period and the symmetries calcvar fixed (PB-2) */
    set_real(o, "period", s->b - s->a);
    json_t *pin = json_array();
    if (scene_pins_shift(s)) json_array_append_new(pin, json_string("shift"));
    json_object_set_new(o, "pinned", pin);
  }
  if (r->has_action) set_real(o, "action", r->action);
  if (r->has_gradient_norm) set_real(o, "gradient_norm", r->gradient_norm);
  if (r->has_residual_floor) { /* additions (theory N-3a): the floor and the ratio to it */
    set_real(o, "residual_floor", r->residual_floor);
    set_real(o, "residual_over_floor", r->gradient_norm / r->residual_floor);
  }
  json_object_set_new(o, "iterations", json_integer(r->iterations));
  if (r->has_time) set_real(o, "time_s", r->time_s);
  if (r->has_morse) {
    json_object_set_new(o, "morse_index", json_integer(r->morse));
    json_object_set_new(o, "stationary_kind", json_string(r->kind));
  }
  if (r->has_err_nodal || r->has_err_action) {
    json_t *e = json_object();
    if (r->has_err_nodal) set_real(e, "max_nodal", r->err_nodal);
    if (r->has_err_action) set_real(e, "action", r->err_action);
    json_object_set_new(o, "error", e);
  }
  if (r->has_err_est) set_real(o, "error_estimate", r->err_est);
  if (r->has_energy) json_object_set_new(o, "energy", min_max(r->emin, r->emax, 1));
  json_t *mom = json_object();
  for (int i = 0; i < s->n; i++)
    if (r->has_mom[i])
      json_object_set_new(mom, s->unknowns[i], min_max(r->mom_min[i], r->mom_max[i], 0));
  if (json_object_size(mom) > 0)
    json_object_set_new(o, "momenta", mom);
  else
    json_decref(mom);
  json_t *mul = json_object();
  for (int k = 0; k < s->nints; k++)
    if (r->has_mu && r->has_mu[k]) set_real(mul, s->ints[k].name, r->mu[k]);
  if (json_object_size(mul) > 0)
    json_object_set_new(o, "multipliers", mul);
  else
    json_decref(mul);
  json_t *con = json_object(); /* inequalities: their contact intervals (OB-4) */
  for (int c = 0; r->contact && c < s->ncons; c++) {
    if (!s->cons[c].sense) continue;
    json_t *list = json_array();
    for (int k = 0; k < r->ncontact[c]; k++) {
      json_t *iv = json_array();
      json_array_append_new(iv, json_real(r->contact[c][2 * k]));
      json_array_append_new(iv, json_real(r->contact[c][2 * k + 1]));
      json_array_append_new(list, iv);
    }
    json_object_set_new(con, s->cons[c].name, list);
  }
  if (json_object_size(con) > 0)
    json_object_set_new(o, "contact", con);
  else
    json_decref(con);
  json_t *rep = json_object();
  for (int k = 0; k < s->nreports; k++)
    if (r->has_rep[k]) set_real(rep, s->reports[k].name, r->rep[k]);
  if (json_object_size(rep) > 0)
    json_object_set_new(o, "report", rep);
  else
    json_decref(rep);

  return o;
}

int cli_report_json(FILE *f, const cli_report *r) {
  json_t *o = cli_report_json_object(r);
  if (!o) return -1;
  int rc = json_dumpf(o, f, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  if (rc == 0 && fputc('\n', f) == EOF) rc = -1;
  json_decref(o);
  return rc;
}

char *cli_report_json_text(const cli_report *r) {
  json_t *o = cli_report_json_object(r);
  if (!o) return NULL;
  char *text = json_dumps(o, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
  json_decref(o);
  return text;
}
