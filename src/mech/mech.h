/* src/mech/mech.h — what Lagrangian mechanics says about a compiled integrand: momenta,
 * Euler–Lagrange equations, Hamiltonian, conservation laws (mech_equations.c), and the
 * equilibrium with its small oscillations (mech_modes.c, mech_equilibrium.c, with the dense
 * linear algebra in mech_dense.c, the only file that calls LAPACK).
 * SPDX-License-Identifier: MIT
 *
 * Internal to the library (not installed). Works on an expression DAG and its node ids,
 * knows no scene file: src/scene builds a mech_problem from a scene and turns the
 * sentences returned here into FILE:LINE messages. Never prints, never exits: failures come
 * back as a cv_status and one sentence in err, with `at` saying which entry it is about.
 * docs/theory.md part P gives the equations, labelled (P-1)...
 */
#ifndef CV_MECH_H
#define CV_MECH_H

#include <stddef.h>

#include "calcvar.h"
#include "expr/expr.h"

/** A Lagrangian problem: F(x, y, y') and its constraints as nodes of one DAG, with slots
 * 0 = the variable x, 1..n = y_i, n+1..2n = y'_i. */
typedef struct {
  ex_dag *dag; /* derivatives are added to it */
  int n;       /* unknowns */
  ex_id F;
  int ncons;                     /* pointwise constraints G_c(x, y) = 0 */
  const ex_id *cons;             /* [ncons] */
  int nints;                     /* integral constraints int K_r(x, y, y') dx = c_r */
  const ex_id *ints;             /* [nints] */
  const char *variable;          /* names for printing and messages */
  const char *const *unknowns;   /* [n] */
  const char *const *cons_names; /* [ncons] */
  const char *const *int_names;  /* [nints] */
  const double *start;           /* [n]: Newton's start for the equilibrium (modes only) */
  double start_x;                /* the variable there (modes: L and G do not depend on it) */
  int order2; /* F (and the K_r) may read y''_i at slot 2n+1+i: a second-order Lagrangian */
} mech_problem;

/** Which entry a failure is about (for the caller's FILE:LINE). */
enum {
  MECH_AT_NONE = -1, /* the problem as a whole */
  MECH_AT_F = 0,     /* the integrand */
  MECH_AT_CONS = 1   /* MECH_AT_CONS + c: pointwise constraint c; after them the integral
                        constraints, MECH_AT_CONS + ncons + r */
};

/* ---- Equations (mech_equations.c) ----------------------------------------------------- */

/** Symbolic mechanics of F, as nodes of the problem's DAG.
 *
 * Slots extend the problem's convention (0 = variable, 1..n = y, n+1..2n = y'):
 * 2n+1..3n = y''; then one slot per pointwise constraint (its multiplier field
 * lambda_NAME), then one per integral constraint (its scalar multiplier mu_NAME).
 * names[slot] gives each slot's printed name ("th", "th'", "th''", "lambda_rod"); nslots
 * is their number.
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
  /* A second-order Lagrangian (mp->order2, theory P-14): slots y'''_i and y''''_i after
   * the multipliers' (names "y'''", "y''''"); momentum[i] is Ostrogradsky's first
   * p_i = F_y'_i - d/dx F_y''_i, momentum2[i] the second q_i = F_y''_i; H = sum_i
   * (y'_i p_i + y''_i q_i) - F; E_i = d/dx F_y' - F_y - d2/dx2 F_y'' (sign as above, by
   * the coefficient of y''''_i). momentum2 is NULL for a first-order F. */
  ex_id *momentum2;
  ex_id F; /* the integrand in these slots */
} mech_equations;

/** Build the equations. E_i = d/dx p_i - dF/dy_i (- sum_c lambda_c dG_c/dy_i
 * - sum_r mu_r (dK_r/dy_i - d/dx dK_r/dy'_i)), expanded by the chain rule
 * d/dx G = G_x + sum_j G_{y_j} y'_j + sum_j G_{y'_j} y''_j, and negated if the
 * coefficient of y_i'' comes out a negative number, so a mechanical equation reads
 * "m l^2 th'' + ... = 0". Returns CVAR_OK, or CVAR_ENOMEM with err set. */
cv_status mech_equations_new(const mech_problem *mp, mech_equations *eq, char *err, size_t errlen);
void mech_equations_free(mech_equations *eq);

/* ---- Symmetries (mech_dense.c) --------------------------------------------------------- */
/** The null directions of an m x n matrix of samples (row-major): unit vectors v with
 * R v = 0 to rtol of R's scale; V holds n values each. Returns their count or -1. */
int mech_null_directions(int n, int m, const double *R, double rtol, double *V);

/* ---- Small oscillations (mech_modes.c) ------------------------------------------------ */

typedef enum {
  MECH_MODE_STABLE = 0, /* omega2 > 0: oscillation with period 2 pi / omega */
  MECH_MODE_UNSTABLE,   /* omega2 < 0: growth rate sqrt(-omega2) */
  MECH_MODE_NEUTRAL     /* |omega2| below the threshold: free translation or rotation */
} mech_mode_kind;

/** Equilibrium and normal modes. Arrays are owned (mech_modes_free). */
typedef struct {
  int n;
  int nc;               /* pointwise constraints G_c(y) = 0 (P-13) */
  int nmodes;           /* n - nc: modes on the constraints' tangent space */
  double *equilibrium;  /* [n] */
  double *multipliers;  /* [nc]: lambda_c of L + lambda.G at the equilibrium */
  double residual;      /* max |dL/dy_i| at the equilibrium */
  int iterations;       /* Newton iterations for the equilibrium */
  double *omega2;       /* [nmodes], increasing */
  mech_mode_kind *kind; /* [nmodes] */
  double *shape;        /* [nmodes*n]: mode k is shape[k*n .. k*n + n-1], v^T M v = 1 */
  double *mass;         /* [n*n] M, row-major (symmetric) */
  double *stiffness;    /* [n*n] K = -d2(L + lambda.G)/dy dy, row-major (symmetric) */
  double gyroscopic;    /* max |G_ij| of G = C - C^T, C_ij = d2L/dy'_i dy_j; the modes of
                          K v = w2 M v ignore G (docs/theory.md (P-10)) */
  /* With G != 0, the motions of M y'' + G y' + K y = 0 (P-12): one entry per frequency,
   * ngyro <= n of them, stable (omega > 0, growth 0), unstable (growth > 0, omega >= 0)
   * or neutral (both 0); increasing omega, then increasing growth. ngyro = 0 if G = 0. */
  int ngyro;
  double *gyro_omega;        /* [n] Im lambda >= 0 */
  double *gyro_growth;       /* [n] Re lambda >= 0 */
  mech_mode_kind *gyro_kind; /* [n] */
} mech_modes;

/** |omega2| <= MECH_NEUTRAL_RTOL * max_k |omega2_k| counts as zero (neutral); when K
 * is zero every mode is neutral. */
#define MECH_NEUTRAL_RTOL 1e-9

/** Find the equilibrium from mp->start (Newton on dL/dy = 0 at y' = 0, mech_equilibrium.c),
 * form M and K there and solve K v = omega2 M v (LAPACK dsygv).
 * Returns CVAR_OK, or with a sentence in err and *at (may be NULL) the entry it is about:
 * CVAR_EINVAL    modes do not apply: F or a constraint depends on the variable, integral
 *                constraints, or as many constraints as unknowns;
 * CVAR_ENONFINITE the Lagrangian's derivatives are not finite at the start or on the way;
 * CVAR_EMAXITER  Newton found no equilibrium;
 * CVAR_ESINGULAR M = d2L/dy'dy' is not positive definite, or the constraints' gradients
 *                are dependent at the equilibrium;
 * CVAR_EDEPENDENCY a LAPACK routine failed; CVAR_ENOMEM. */
cv_status mech_modes_new(const mech_problem *mp, mech_modes *md, int *at, char *err, size_t errlen);
void mech_modes_free(mech_modes *md);

#endif /* CV_MECH_H */
