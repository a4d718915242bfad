/* src/scene/cv_scene.c — the public scene loader and report (calcvar.h, "Scene files"):
 * thin handles over the loader and the report the command uses, so that a C program or the
 * Python module loads, configures and reports exactly as `calcvar solve` does.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "scene/scene.h"
#include "scene/scene_internal.h"
#include "scene/scene_report.h"

struct cv_report {
  char *json;
};

static void say(char *err, size_t errlen, const char *fmt, const char *what) {
  if (err && errlen) snprintf(err, errlen, fmt, what);
}

/* "name=value" strings into sc_set pairs pointing into one copy (*buf). */
static sc_set *split_sets(int nset, const char *const *set, char **buf, char *err, size_t errlen) {
  size_t total = 0;
  for (int i = 0; i < nset; i++) {
    if (!set[i]) {
      say(err, errlen, "%s", "--set: NULL override");
      return NULL;
    }
    total += strlen(set[i]) + 1;
  }
  sc_set *pairs = cv_calloc((size_t)nset + 1, sizeof *pairs);
  char *copy = cv_malloc(total + 1), *q = copy;
  if (!pairs || !copy) {
    cv_free(pairs);
    cv_free(copy);
    say(err, errlen, "%s", "out of memory");
    return NULL;
  }
  for (int i = 0; i < nset; i++) {
    size_t len = strlen(set[i]);
    memcpy(q, set[i], len + 1);
    char *eq = strchr(q, '=');
    if (!eq || eq == q) {
      say(err, errlen, "--set %s: expected name=value", set[i]);
      cv_free(pairs);
      cv_free(copy);
      return NULL;
    }
    *eq = '\0';
    pairs[i].name = q;
    pairs[i].value = eq + 1;
    q += len + 1;
  }
  *buf = copy;
  return pairs;
}

static cv_scene *load(const char *path, const char *text, const char *name, int nset,
                      const char *const *set, char *err, size_t errlen) {
  if (err && errlen) err[0] = '\0';
  if ((!path && !text) || nset < 0 || (nset > 0 && !set)) {
    say(err, errlen, "%s", "cv_scene_load: invalid argument");
    return NULL;
  }
  char *buf = NULL;
  sc_set *pairs = NULL;
  if (nset > 0 && !(pairs = split_sets(nset, set, &buf, err, errlen))) return NULL;
  cv_scene *sc = cv_calloc(1, sizeof *sc);
  if (!sc) {
    say(err, errlen, "%s", "out of memory");
  } else {
    sc->s = path ? scene_load_file(path, nset, pairs, err, errlen)
                 : scene_load_buffer(text, strlen(text), name ? name : "<text>", nset, pairs, err,
                                     errlen);
    if (!sc->s) {
      cv_free(sc);
      sc = NULL;
    }
  }
  cv_free(pairs);
  cv_free(buf);
  return sc;
}

cv_scene *cv_scene_load_file(const char *path, int nset, const char *const *set, char *err,
                             size_t errlen) {
  return load(path, NULL, NULL, nset, set, err, errlen);
}

cv_scene *cv_scene_load_text(const char *text, const char *name, int nset, const char *const *set,
                             char *err, size_t errlen) {
  return load(NULL, text, name, nset, set, err, errlen);
}

void cv_scene_free(cv_scene *sc) {
  if (!sc) return;
  scene_free(sc->s);
  cv_free(sc);
}

int cv_scene_get_num_unknowns(const cv_scene *sc) { return sc ? sc->s->n : 0; }

const char *cv_scene_get_unknown(const cv_scene *sc, int i) {
  return sc && i >= 0 && i < sc->s->n ? sc->s->unknowns[i] : NULL;
}

const char *cv_scene_get_title(const cv_scene *sc) {
  return sc && sc->s->title ? sc->s->title : "";
}

const char *cv_scene_get_variable(const cv_scene *sc) {
  return sc && sc->s->variable ? sc->s->variable : "x";
}

int cv_scene_get_num_constraints(const cv_scene *sc) { return sc ? sc->s->ncons : 0; }

const char *cv_scene_get_constraint(const cv_scene *sc, int k) {
  return sc && k >= 0 && k < sc->s->ncons ? sc->s->cons[k].name : NULL;
}

int cv_scene_get_num_integrals(const cv_scene *sc) { return sc ? sc->s->nints : 0; }

const char *cv_scene_get_integral(const cv_scene *sc, int k) {
  return sc && k >= 0 && k < sc->s->nints ? sc->s->ints[k].name : NULL;
}

/* Integer options must be whole numbers in range; reals finite and positive. */
static int whole(double v, double lo, double hi) {
  return isfinite(v) && v == floor(v) && v >= lo && v <= hi;
}

cv_status cv_scene_set_option(cv_scene *sc, const char *name, double value, char *err,
                              size_t errlen) {
  if (err && errlen) err[0] = '\0';
  if (!sc || !name) {
    say(err, errlen, "%s", "cv_scene_set_option: invalid argument");
    return CVAR_EINVAL;
  }
  scene *s = sc->s;
  int ok = 1;
  if (strcmp(name, "elements") == 0 && (ok = whole(value, 1, 1e9))) {
    s->elements = (int)value;
    if (!s->elements_line) s->elements_line = -1; /* given: tol starts from it */
  } else if (strcmp(name, "degree") == 0 && (ok = whole(value, 1, 8))) {
    s->degree = (int)value;
    if (!s->degree_line) s->degree_line = -1;
  } else if (strcmp(name, "max_iterations") == 0 && (ok = whole(value, 1, 1e9)))
    s->max_iterations = (int)value;
  else if (strcmp(name, "method") == 0 && (ok = whole(value, 0, CVAR_METHOD_AUGLAG)))
    s->method = (cv_method)(int)value;
  else if (strcmp(name, "tolerance") == 0 && (ok = isfinite(value) && value > 0))
    s->tolerance = value;
  else if (strcmp(name, "adapt") == 0 && (ok = isfinite(value) && value >= 0))
    s->adapt = value;
  else if (strcmp(name, "tol") == 0 && (ok = isfinite(value) && value >= 0)) {
    s->tol = value;
    scene_tol_start(s); /* the start `calcvar solve --tol` takes */
  } else if (strcmp(name, "max_nodes") == 0 && (ok = whole(value, 2, 2e8)))
    s->tol_max_nodes = (int)value;
  else if (strcmp(name, "time_limit") == 0 && (ok = isfinite(value) && value > 0))
    s->time_limit = value;
  else if (ok && strcmp(name, "elements") && strcmp(name, "degree") &&
           strcmp(name, "max_iterations") && strcmp(name, "method") && strcmp(name, "tolerance") &&
           strcmp(name, "adapt") && strcmp(name, "tol") && strcmp(name, "max_nodes") &&
           strcmp(name, "time_limit")) {
    say(err, errlen,
        "unknown option '%s' (known: elements, degree, tolerance, "
        "max_iterations, adapt, tol, max_nodes, time_limit, method)",
        name);
    return CVAR_EINVAL;
  }
  if (ok && s->tol > 0 && s->adapt > 0) {
    /* as `solve --tol` with `--adapt`: two accuracy rules at once */
    say(err, errlen, "%s",
        "tol and adapt may not be given together (tol chooses the degrees "
        "too; adapt refines at a fixed degree)");
    if (strcmp(name, "tol") == 0)
      s->tol = 0;
    else
      s->adapt = 0;
    return CVAR_EINVAL;
  }
  if (!ok) {
    if (err && errlen) snprintf(err, errlen, "%s: invalid value %g", name, value);
    return CVAR_EINVAL;
  }
  return CVAR_OK;
}

cv_problem *cv_scene_problem_new(const cv_scene *sc, char *err, size_t errlen) {
  if (!sc) {
    say(err, errlen, "%s", "cv_scene_problem_new: no scene");
    return NULL;
  }
  return scene_problem_new(sc->s, scene_method_need(sc->s->method), err, errlen);
}

cv_status cv_scene_configure_solver(const cv_scene *sc, cv_solver *s, char *err, size_t errlen) {
  if (!sc || !s) {
    say(err, errlen, "%s", "cv_scene_configure_solver: invalid argument");
    return CVAR_EINVAL;
  }
  return scene_solver_configure(sc->s, s, err, errlen);
}

cv_report *cv_report_new(cv_scene *sc, const cv_problem *p, cv_solver *s, cv_status *why) {
  cv_report *r = NULL;
  cli_report cr;
  memset(&cr, 0, sizeof cr);
  cv_status st = CVAR_ENOMEM;
  if (!sc || !p || !s) {
    st = CVAR_EINVAL;
    goto done;
  }
  if (cv_solver_get_num_nodes(s) <= 0) {
    st = CVAR_ESTATE;
    goto done;
  }
  r = cv_calloc(1, sizeof *r);
  int rounds = isfinite(cv_solver_get_error_estimate(s)); /* --adapt or --tol: 1, 2 */
  if (!r ||
      cli_report_build(&cr, sc->s, p, s, cv_solver_get_status(s),
                       rounds && sc->s->tol > 0 ? 2 : rounds) < 0 ||
      !(r->json = cli_report_json_text(&cr))) {
    cv_report_free(r);
    r = NULL;
    goto done;
  }
  st = CVAR_OK;
done:
  cli_report_free(&cr);
  if (why) *why = st;
  return r;
}

const char *cv_report_json(const cv_report *r) { return r && r->json ? r->json : ""; }

void cv_report_free(cv_report *r) {
  if (!r) return;
  free(r->json); /* from json_dumps: jansson's allocator */
  cv_free(r);
}
