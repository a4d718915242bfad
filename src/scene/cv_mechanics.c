/* src/scene/cv_mechanics.c — the public mechanics of a scene (calcvar.h, "Mechanics"):
 * opaque handles over scene_equations_new / scene_modes_new with getters and the JSON text
 * the command writes (scene_mechanics_json.c), so a C program or the Python module gets
 * exactly what `calcvar equations --json` / `calcvar modes --json` print.
 * SPDX-License-Identifier: MIT
 * docs/theory.md part P gives the equations, labelled (P-1)...
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "calcvar.h"
#include "scene/scene_internal.h"
#include "scene/scene_mechanics.h"

struct cv_equations {
  mech_equations eq;
  scene_eq_texts t;
  char *json; /* jansson's allocator */
};

struct cv_modes {
  mech_modes md;
  char *json; /* jansson's allocator */
};

static void say(char *err, size_t errlen, const char *what) {
  if (err && errlen) snprintf(err, errlen, "%s", what);
}

cv_equations *cv_equations_new(cv_scene *sc, cv_status *why, char *err, size_t errlen) {
  char msg[SC_ERRLEN] = "";
  cv_status st = CVAR_EINVAL;
  cv_equations *e = NULL;
  if (err && errlen) err[0] = '\0';
  if (!sc || !sc->s) {
    say(err, errlen, "cv_equations_new: invalid argument");
    goto done;
  }
  st = CVAR_ENOMEM;
  if (!(e = cv_calloc(1, sizeof *e))) {
    say(err, errlen, "out of memory");
    goto done;
  }
  st = scene_equations_new(sc->s, &e->eq, msg, sizeof msg);
  if (st != CVAR_OK) {
    say(err, errlen, msg[0] ? msg : "out of memory");
    goto fail;
  }
  st = CVAR_ENOMEM;
  if (scene_eq_texts_make(&e->t, sc->s, &e->eq) < 0 ||
      !(e->json = scene_equations_json(sc->s, &e->eq, &e->t))) {
    say(err, errlen, "out of memory");
    goto fail;
  }
  st = CVAR_OK;
  goto done;
fail:
  cv_equations_free(e);
  e = NULL;
done:
  if (why) *why = st;
  return e;
}

void cv_equations_free(cv_equations *e) {
  if (!e) return;
  scene_eq_texts_free(&e->t);
  mech_equations_free(&e->eq);
  free(e->json);
  cv_free(e);
}

int cv_equations_get_num_unknowns(const cv_equations *e) { return e ? e->eq.n : 0; }

const char *cv_equations_get_momentum(const cv_equations *e, int i) {
  return e && i >= 0 && i < e->eq.n ? e->t.mom[i] : NULL;
}

const char *cv_equations_get_euler_lagrange(const cv_equations *e, int i) {
  return e && i >= 0 && i < e->eq.n ? e->t.el[i] : NULL;
}

const char *cv_equations_get_hamiltonian(const cv_equations *e) { return e ? e->t.H : NULL; }

const char *cv_equations_get_integrand(const cv_equations *e) { return e ? e->t.F : NULL; }

int cv_equations_is_cyclic(const cv_equations *e, int i) {
  return e && i >= 0 && i < e->eq.n ? e->eq.cyclic[i] != 0 : 0;
}

int cv_equations_is_autonomous(const cv_equations *e) { return e ? e->eq.autonomous != 0 : 0; }

const char *cv_equations_json(const cv_equations *e) { return e && e->json ? e->json : ""; }

cv_modes *cv_modes_new(cv_scene *sc, cv_status *why, char *err, size_t errlen) {
  char msg[SC_ERRLEN] = "";
  cv_status st = CVAR_EINVAL;
  cv_modes *m = NULL;
  if (err && errlen) err[0] = '\0';
  if (!sc || !sc->s) {
    say(err, errlen, "cv_modes_new: invalid argument");
    goto done;
  }
  st = CVAR_ENOMEM;
  if (!(m = cv_calloc(1, sizeof *m))) {
    say(err, errlen, "out of memory");
    goto done;
  }
  st = scene_modes_new(sc->s, &m->md, msg, sizeof msg);
  if (st != CVAR_OK) {
    say(err, errlen, msg[0] ? msg : cv_strerror(st));
    goto fail;
  }
  if (!(m->json = scene_modes_json(sc->s, &m->md))) {
    st = CVAR_ENOMEM;
    say(err, errlen, "out of memory");
    goto fail;
  }
  st = CVAR_OK;
  goto done;
fail:
  cv_modes_free(m);
  m = NULL;
done:
  if (why) *why = st;
  return m;
}

void cv_modes_free(cv_modes *m) {
  if (!m) return;
  mech_modes_free(&m->md);
  free(m->json);
  cv_free(m);
}

int cv_modes_get_num_unknowns(const cv_modes *m) { return m ? m->md.n : 0; }

int cv_modes_get_num_modes(const cv_modes *m) { return m ? m->md.nmodes : 0; }

int cv_modes_get_num_constraints(const cv_modes *m) { return m ? m->md.nc : 0; }

cv_status cv_modes_get_equilibrium(const cv_modes *m, double *y) {
  if (!m || !y) return CVAR_EINVAL;
  memcpy(y, m->md.equilibrium, (size_t)m->md.n * sizeof *y);
  return CVAR_OK;
}

cv_status cv_modes_get_omega2(const cv_modes *m, double *omega2) {
  if (!m || !omega2) return CVAR_EINVAL;
  memcpy(omega2, m->md.omega2, (size_t)m->md.nmodes * sizeof *omega2);
  return CVAR_OK;
}

cv_mode_kind cv_modes_get_kind(const cv_modes *m, int k) {
  if (!m || k < 0 || k >= m->md.nmodes) return CVAR_MODE_NEUTRAL;
  switch (m->md.kind[k]) {
  case MECH_MODE_STABLE: return CVAR_MODE_STABLE;
  case MECH_MODE_UNSTABLE: return CVAR_MODE_UNSTABLE;
  default: return CVAR_MODE_NEUTRAL;
  }
}

cv_status cv_modes_get_shapes(const cv_modes *m, double *shape) {
  if (!m || !shape) return CVAR_EINVAL;
  memcpy(shape, m->md.shape, (size_t)m->md.nmodes * (size_t)m->md.n * sizeof *shape);
  return CVAR_OK;
}

cv_status cv_modes_get_multipliers(const cv_modes *m, double *lambda) {
  if (!m || (!lambda && m->md.nc > 0)) return CVAR_EINVAL;
  if (m->md.nc > 0) memcpy(lambda, m->md.multipliers, (size_t)m->md.nc * sizeof *lambda);
  return CVAR_OK;
}

cv_status cv_modes_get_matrices(const cv_modes *m, double *mass, double *stiffness) {
  if (!m) return CVAR_EINVAL;
  size_t nn = (size_t)m->md.n * (size_t)m->md.n;
  if (mass) memcpy(mass, m->md.mass, nn * sizeof *mass);
  if (stiffness) memcpy(stiffness, m->md.stiffness, nn * sizeof *stiffness);
  return CVAR_OK;
}

const char *cv_modes_json(const cv_modes *m) { return m && m->json ? m->json : ""; }
