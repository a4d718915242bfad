/* src/scene/scene_mechanics.h — the mechanics of a scene's integrand (src/mech) with the
 * scene's names, and failures as FILE:LINE messages.
 * SPDX-License-Identifier: MIT
 *
 * Internal to the library and the calcvar command (not installed). Never prints, never
 * exits. docs/theory.md part P gives the equations, labelled (P-1)...
 */
#ifndef CV_SCENE_MECHANICS_H
#define CV_SCENE_MECHANICS_H

#include <stddef.h>

#include "mech/mech.h"
#include "scene/scene.h"

/** The momenta, Euler–Lagrange equations and Hamiltonian of the scene's F with its
 * [constraints] and [integrals] (mech_equations_new). Returns CVAR_OK or CVAR_ENOMEM with
 * err set. */
cv_status scene_equations_new(const scene *s, mech_equations *eq, char *err, size_t errlen);

/** The equilibrium and small oscillations of the scene's Lagrangian (mech_modes_new), from
 * the guess at the start of the interval. Returns CVAR_OK or mech_modes_new's status with a
 * FILE:LINE message in err (the line of the entry at fault, when there is one). */
cv_status scene_modes_new(const scene *s, mech_modes *md, char *err, size_t errlen);

/* ---- As text and JSON (scene_mechanics_json.c) --------------------------------------- */

/** The equations printed in the scene grammar, parameters as numbers: mom[i] = p_i,
 * el[i] = E_i, H, and F itself. */
typedef struct {
  int n;
  char **mom, **el, *H, *F;
  char **mom2; /* second-order Lagrangian: Ostrogradsky's second momenta F_y'', else NULL */
} scene_eq_texts;

/** Print eq's expressions (all of them, or -1 on allocation failure; free it either way). */
int scene_eq_texts_make(scene_eq_texts *t, const scene *s, const mech_equations *eq);
void scene_eq_texts_free(scene_eq_texts *t);

/** The JSON of `calcvar equations --json` (docs/cli.md), without the final newline;
 * malloc'ed by jansson (release with free), NULL when out of memory. */
char *scene_equations_json(const scene *s, const mech_equations *eq, const scene_eq_texts *t);

/** The JSON of `calcvar modes --json`, as scene_equations_json. */
char *scene_modes_json(const scene *s, const mech_modes *md);

/** "stable", "unstable" or "neutral". */
const char *scene_mode_kind_name(mech_mode_kind k);

#endif /* CV_SCENE_MECHANICS_H */
