/* src/scene/scene_mechanics.h — what Lagrangian mechanics says about a scene's integrand:
 * momenta, Euler–Lagrange equations, Hamiltonian, conservation laws (scene_mechanics.c),
 * and the equilibrium with its small oscillations (scene_modes.c).
 * SPDX-License-Identifier: MIT
 *
 * Internal to the library and the calcvar command (not installed). Never prints, never
 * exits: failures come back as a status and one sentence in err. docs/theory.md part P
 * gives the equations, labelled (P-1)...
 */
#ifndef CV_SCENE_MECHANICS_H
#define CV_SCENE_MECHANICS_H

#include <stddef.h>

#include "scene/scene.h"

/* ---- Equations (scene_mechanics.c) ------------------------------------------------- */

/** Symbolic mechanics of a scene's integrand F, as nodes of the scene's DAG.
 *
 * Slots extend the scene convention (0 = variable, 1..n = y, n+1..2n = y'):
 * 2n+1..3n = y''; then one slot per pointwise constraint (its multiplier field
 * lambda_NAME), then one per integral constraint (its scalar multiplier mu_NAME).
 * names[slot] gives each slot's printed name ("th", "th'", "th''", "lambda_rod"); nslots
 * is their number. Parameters are numbers in every expression (the scene folds them).
 *
 * Each expression has been passed through ex_collect for display. */
typedef struct {
  int n;
  int nslots;
  char **names;      /* [nslots] */
  ex_id *momentum;   /* [n]: p_i = dF/dy'_i                                     (P-3) */
  ex_id *el;         /* [n]: E_i, zero along a stationary path                    (P-4) */
  ex_id hamiltonian; /* H = sum_i y'_i p_i - F                                    (P-5) */
  int *cyclic;       /* [n]: F does not depend on y_i, so p_i is conserved         (P-7) */
  int autonomous;    /* F does not depend on the variable, so H is conserved       (P-6) */
} sc_equations;

/** Build the equations. E_i = d/dx p_i - dF/dy_i (- sum_c lambda_c dG_c/dy_i
 * - sum_r mu_r (dK_r/dy_i - d/dx dK_r/dy'_i)), expanded by the chain rule
 * d/dx G = G_x + sum_j G_{y_j} y'_j + sum_j G_{y'_j} y''_j, and negated if the
 * coefficient of y_i'' comes out a negative number, so a mechanical equation reads
 * "m l^2 th'' + ... = 0". Returns 0, or -1 (out of memory) with err set. */
int scene_equations_new(scene *s, sc_equations *eq, char *err, size_t errlen);
void scene_equations_free(sc_equations *eq);

/* ---- Small oscillations (scene_modes.c) -------------------------------------------- */

typedef enum {
  SC_MODE_STABLE = 0, /* omega2 > 0: oscillation with period 2 pi / omega */
  SC_MODE_UNSTABLE,   /* omega2 < 0: growth rate sqrt(-omega2) */
  SC_MODE_NEUTRAL     /* |omega2| below the threshold: free translation or rotation */
} sc_mode_kind;

/** Outcome of scene_modes_new (0 is success). */
enum {
  SC_MODES_OK = 0,
  SC_MODES_EXPLICIT = 1,    /* F depends on the variable: not a Lagrangian L(y, y') */
  SC_MODES_CONSTRAINED = 2, /* the scene has [constraints] or [integrals] */
  SC_MODES_NO_EQUILIBRIUM = 3, /* Newton on dL/dy = 0 did not converge */
  SC_MODES_MASS = 4,        /* M = d2L/dy'dy' is not positive definite */
  SC_MODES_NONFINITE = 5,   /* L or its derivatives are not finite at the guess */
  SC_MODES_NOMEM = 6
};

/** Equilibrium and normal modes. Arrays are owned (scene_modes_free). */
typedef struct {
  int n;
  int nc;              /* pointwise constraints G_c(y) = 0 (P-13) */
  int nmodes;          /* n - nc: modes on the constraints' tangent space */
  double *equilibrium; /* [n] */
  double *multipliers; /* [nc]: lambda_c of L + lambda.G at the equilibrium */
  double residual;     /* max |dL/dy_i| at the equilibrium */
  int iterations;      /* Newton iterations for the equilibrium */
  double *omega2;      /* [nmodes], increasing */
  sc_mode_kind *kind;  /* [nmodes] */
  double *shape;       /* [nmodes*n]: mode k is shape[k*n .. k*n + n-1], v^T M v = 1 */
  double *mass;        /* [n*n] M, row-major (symmetric) */
  double *stiffness;   /* [n*n] K = -d2(L + lambda.G)/dy dy, row-major (symmetric) */
  double gyroscopic;   /* max |G_ij| of G = C - C^T, C_ij = d2L/dy'_i dy_j; the modes of
                          K v = w2 M v ignore G (docs/theory.md (P-10)) */
  /* With G != 0, the motions of M y'' + G y' + K y = 0 (P-12): one entry per frequency,
   * ngyro <= n of them, stable (omega > 0, growth 0), unstable (growth > 0, omega >= 0)
   * or neutral (both 0); increasing omega, then increasing growth. ngyro = 0 if G = 0. */
  int ngyro;
  double *gyro_omega;      /* [n] Im lambda >= 0 */
  double *gyro_growth;     /* [n] Re lambda >= 0 */
  sc_mode_kind *gyro_kind; /* [n] */
} sc_modes;

/** |omega2| <= SC_MODES_NEUTRAL_RTOL * max_k |omega2_k| counts as zero (neutral); when K
 * is zero every mode is neutral. */
#define SC_MODES_NEUTRAL_RTOL 1e-9

/** Find the equilibrium from the guess at the start of the interval (Newton on
 * dL/dy = 0 at y' = 0), form M and K there and solve K v = omega2 M v (LAPACK dsygv).
 * Returns SC_MODES_OK or another SC_MODES_* value with err set. */
int scene_modes_new(scene *s, sc_modes *md, char *err, size_t errlen);
void scene_modes_free(sc_modes *md);

#endif /* CV_SCENE_MECHANICS_H */
