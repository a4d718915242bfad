/* include/calcvar.h — public C API of calcvar, direct solution of variational problems.
 * SPDX-License-Identifier: MIT */
/** \file
 * calcvar makes the functional  I[y] = int_a^b F(x, y, y') dx,  y : [a, b] -> R^n,
 * stationary by direct discretisation: y lives on a mesh of polynomial elements
 * (Gauss-Lobatto-Legendre nodes), the discrete action is integrated by Gauss-Legendre
 * quadrature, and Newton's method on the exact gradient and Hessian (sparse LDL^T,
 * CHOLMOD) finds the stationary point. See docs/theory.md for the formulas.
 *
 * Handles are opaque (cv_problem, cv_solver). Every function that can fail returns a
 * cv_status; 0 (CVAR_OK) means success and nothing else does. Constructors return NULL on
 * failure and fill an optional `why`. The library never prints and never exits. Outputs
 * go to caller-owned buffers whose lengths are documented per function.
 *
 * Thread safety: distinct handles may be used from distinct threads; one handle must not be
 * used concurrently. Callbacks are never re-entered on the same handle, and every callback
 * runs on the thread that called cv_solve. On large systems (50 000 unknowns and more) a
 * solve runs CHOLMOD's symbolic analysis of the sparse pattern on one extra thread of its
 * own, which it joins before it returns; no user code runs there.
 *
 * Array layouts (one per kind of array, the same in every call):
 *  - values at the mesh nodes are node-major: y[j*n + i] is unknown i at node j
 *    (cv_solver_get_values, cv_solver_set_start); so a node's n values are adjacent, and a
 *    C array y[nodes][n] (numpy shape (nodes, n), C order) is this layout;
 *  - one value per node (nodes, multiplier fields) is a plain array x[j], lambda[j];
 *  - values at a batch of m points are unknown-major: y[i*m + k] (the integrand, guess and
 *    constraint callbacks, cv_solver_get_qpoints, cv_solver_eval), so that each unknown's m
 *    values are adjacent for vectorised evaluation.
 *
 * Only the names declared here are exported from libcalcvar.so (CVAR_API); everything else
 * in the library is internal.
 *
 * Minimal use (the catenary, see examples/catenary.c):
 * \code
 *   cv_status why;
 *   cv_problem *p = cv_problem_new(1, -1.0, 1.0, &why);
 *   cv_problem_set_integrand(p, catenary_F, NULL);
 *   cv_problem_set_dirichlet(p, 0, 2 * cosh(0.5), 2 * cosh(0.5));
 *   cv_solver *s = cv_solver_new(&why);
 *   cv_solver_set_elements(s, 64);
 *   cv_solver_set_degree(s, 2);
 *   if (cv_solve(s, p) == CVAR_OK) {
 *     int nn = cv_solver_get_num_nodes(s);
 *     double *x = malloc(nn * sizeof *x), *y = malloc(nn * sizeof *y);
 *     cv_solver_get_nodes(s, x);
 *     cv_solver_get_values(s, y);
 *     ...
 *   }
 *   cv_solver_free(s);
 *   cv_problem_free(p);
 * \endcode
 */
#ifndef CALCVAR_H
#define CALCVAR_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Marks a declaration as part of the public ABI. The library is built with hidden
 * visibility by default (meson.build), so only names marked CVAR_API are exported from
 * libcalcvar.so; everything else stays internal. */
#if defined(__GNUC__) || defined(__clang__)
#define CVAR_API __attribute__((visibility("default")))
#else
#define CVAR_API
#endif

/** \name Version */
/**@{*/
#define CVAR_VERSION_MAJOR 0 /**< major version of this header */
#define CVAR_VERSION_MINOR 1 /**< minor version of this header */
#define CVAR_VERSION_PATCH 0 /**< patch level of this header */
/** Pack a version for `#if` tests: CVAR_VERSION_PACK(0, 1, 0). */
#define CVAR_VERSION_PACK(a, b, c) ((a)*10000 + (b)*100 + (c))
/** This header's version, packed: compare with CVAR_VERSION_PACK(a, b, c) in `#if`. */
#define CVAR_VERSION CVAR_VERSION_PACK(CVAR_VERSION_MAJOR, CVAR_VERSION_MINOR, CVAR_VERSION_PATCH)
/** The library's version, to compare with the header's. Any pointer may be NULL. */
CVAR_API void cv_version(int *major, int *minor, int *patch);
/**@}*/

/** \name Status codes
 * One X-macro list generates the enum and the message table (cv_strerror). */
/**@{*/
/** The statuses in order, each with its cv_strerror sentence; CVAR_OK is 0. */
#define CVAR_STATUS_LIST(X)                                                                        \
  X(CVAR_OK, "success")                                                                            \
  X(CVAR_EINVAL, "invalid argument")                                                               \
  X(CVAR_ENOMEM, "out of memory")                                                                  \
  X(CVAR_ECALLBACK, "a user callback reported an error")                                           \
  X(CVAR_ENONFINITE, "non-finite value in the integrand or an iterate")                            \
  X(CVAR_ESINGULAR, "singular or degenerate Hessian")                                              \
  X(CVAR_EMAXITER, "maximum number of iterations reached before convergence")                      \
  X(CVAR_ESTALL, "no further progress possible (round-off or stagnation)")                         \
  X(CVAR_EDIVERGED, "the iteration diverged")                                                      \
  X(CVAR_ENOTMIN, "the stationary point is not a minimum")                                         \
  X(CVAR_EDEPENDENCY, "failure inside a dependency (CHOLMOD, NLopt)")                              \
  X(CVAR_ESTATE, "no solution available (call cv_solve first)")                                    \
  X(CVAR_ECANCELLED, "cancelled by the progress callback")

/** Turns one CVAR_STATUS_LIST entry into an enumerator (undefined again below). */
#define CVAR_ENUM_ITEM(name, msg) name,
/** Result of every fallible call. CVAR_OK is 0; all other values are failures. The values,
 * in order, are those of CVAR_STATUS_LIST: CVAR_OK, CVAR_EINVAL, CVAR_ENOMEM, CVAR_ECALLBACK,
 * CVAR_ENONFINITE, CVAR_ESINGULAR, CVAR_EMAXITER, CVAR_ESTALL, CVAR_EDIVERGED, CVAR_ENOTMIN,
 * CVAR_EDEPENDENCY, CVAR_ESTATE, CVAR_ECANCELLED; CVAR_NUM_STATUS counts them. */
typedef enum { CVAR_STATUS_LIST(CVAR_ENUM_ITEM) CVAR_NUM_STATUS } cv_status;
#undef CVAR_ENUM_ITEM

/** A static sentence for a status; never NULL (unknown codes give "unknown status"). */
CVAR_API const char *cv_strerror(cv_status s);
/** The symbolic name of a status, e.g. "CVAR_EMAXITER"; never NULL. */
CVAR_API const char *cv_status_name(cv_status s);
/** The libraries linked into libcalcvar with their versions, as the libraries report them
 * at run time, e.g. "CHOLMOD 3.0.14, NLopt 2.7.1, LAPACK 3.11.0, jansson 2.14, inih", into
 * buf (len bytes; 160 is ample). CVAR_EINVAL when it does not fit. */
CVAR_API cv_status cv_dependency_versions(char *buf, size_t len);
/**@}*/

/** \name Integrand callbacks */
/**@{*/

/** Bits of `need`: which outputs the solver asks for in one call. */
enum {
  CVAR_NEED_F = 1u,    /**< F itself */
  CVAR_NEED_GRAD = 2u, /**< F_y and F_y' */
  CVAR_NEED_HESS = 4u, /**< F_yy, F_yy', F_y'y' */
  /** Second-order problems only (cv_problem_set_second_order): `out` is the d1 member of
   * a cv_partials2 carrying y'', and the groups asked for include the partials in y''
   * (with CVAR_NEED_GRAD Fq, with CVAR_NEED_HESS Fyq, Fpq and Fqq). A callback of a
   * first-order problem never sees this bit. */
  CVAR_NEED_Y2 = 8u
};

/** Output buffers of an integrand call at m points, structure of arrays.
 * A member is NULL exactly when its group was not asked for in `need`.
 * With n unknowns and point index k (0 <= k < m):
 *  - F[k]
 *  - Fy[i*m + k]  = dF/dy_i,   Fp[i*m + k] = dF/dy'_i             (i < n)
 *  - Fyy[(i*n + j)*m + k] = d2F/dy_i dy_j     (symmetric)
 *  - Fyp[(i*n + j)*m + k] = d2F/dy_i dy'_j    (not symmetric in general)
 *  - Fpp[(i*n + j)*m + k] = d2F/dy'_i dy'_j   (symmetric)
 * The solver fills every entry it hands over with NaN before the call, so entries the
 * callback forgets are caught as non-finite. */
typedef struct {
  double *F;   /**< F[k], length m */
  double *Fy;  /**< dF/dy_i at [i*m + k], length n*m; NULL unless CVAR_NEED_GRAD */
  double *Fp;  /**< dF/dy'_i at [i*m + k], length n*m; NULL unless CVAR_NEED_GRAD */
  double *Fyy; /**< d2F/dy_i dy_j at [(i*n + j)*m + k]; NULL unless CVAR_NEED_HESS */
  double *Fyp; /**< d2F/dy_i dy'_j at [(i*n + j)*m + k]; NULL unless CVAR_NEED_HESS */
  double *Fpp; /**< d2F/dy'_i dy'_j at [(i*n + j)*m + k]; NULL unless CVAR_NEED_HESS */
} cv_partials;

/** The outputs of a call with CVAR_NEED_Y2 (second-order problems): `out` then points to
 * the member d1 of one of these, so the callback reaches the rest by cv_partials_y2(out).
 * Members are NULL exactly when their group was not asked for, as in cv_partials.
 *  - d2y[i*m + k] = y''_i (input)
 *  - Fq[i*m + k] = dF/dy''_i                                      (with CVAR_NEED_GRAD)
 *  - Fyq[(i*n + j)*m + k] = d2F/dy_i dy''_j, Fpq[...] = d2F/dy'_i dy''_j,
 *    Fqq[(i*n + j)*m + k] = d2F/dy''_i dy''_j (symmetric)          (with CVAR_NEED_HESS) */
typedef struct {
  cv_partials d1;    /**< the first-order members, as in every call */
  const double *d2y; /**< input: y''_i at [i*m + k], length n*m */
  double *Fq;        /**< dF/dy''_i at [i*m + k]; NULL unless CVAR_NEED_GRAD */
  double *Fyq;       /**< d2F/dy_i dy''_j at [(i*n + j)*m + k]; NULL unless CVAR_NEED_HESS */
  double *Fpq;       /**< d2F/dy'_i dy''_j at [(i*n + j)*m + k]; NULL unless CVAR_NEED_HESS */
  double *Fqq;       /**< d2F/dy''_i dy''_j (symmetric); NULL unless CVAR_NEED_HESS */
} cv_partials2;
/** The second-order outputs of a call whose need has CVAR_NEED_Y2. */
static inline cv_partials2 *cv_partials_y2(cv_partials *out) { return (cv_partials2 *)(void *)out; }

/** Integrand F(x, y, y') and its partials at m points.
 * \param m     number of points (1 <= m <= 256)
 * \param x     x[k], length m
 * \param y     y[i*m + k], length n*m
 * \param dy    y'[i*m + k], length n*m
 * \param need  OR of CVAR_NEED_* bits
 * \param out   buffers to fill, see cv_partials
 * \param user  the pointer given to cv_problem_set_integrand, untouched
 * \return 0 on success; > 0 "cannot evaluate here" (e.g. outside the domain: the line
 *         search shortens the step); < 0 abort (the solve returns CVAR_ECALLBACK). */
typedef int (*cv_integrand_fn)(int m, const double *x, const double *y, const double *dy,
                               unsigned need, cv_partials *out, void *user);

/** Initial guess: fill y[i*m + k] for the m abscissae x[k]. Return 0 on success. */
typedef int (*cv_guess_fn)(int m, const double *x, double *y, void *user);
/**@}*/

/** \name Problem: what is to be made stationary */
/**@{*/
/** A variational problem: interval, unknowns, integrand, end conditions, constraints.
 * Opaque; made by cv_problem_new, released by cv_problem_free. */
typedef struct cv_problem cv_problem;

/** A new problem with n >= 1 unknown functions on [a, b], a < b, both finite.
 * Returns NULL on failure and sets *why (may be NULL) to CVAR_EINVAL or CVAR_ENOMEM.
 * End values start as fixed at 0; no integrand is set. */
CVAR_API cv_problem *cv_problem_new(int n, double a, double b, cv_status *why);
/** Release a problem; NULL is a no-op. */
CVAR_API void cv_problem_free(cv_problem *p);
/** The integrand (required before solving). `user` is passed through untouched. */
CVAR_API cv_status cv_problem_set_integrand(cv_problem *p, cv_integrand_fn F, void *user);
/** Releases user data handed to the problem (see the `_owned` setters). */
typedef void (*cv_release_fn)(void *user);
/** Like cv_problem_set_integrand, but the problem owns `user`: cv_problem_free (or the next
 * integrand set) calls release(user) when release is not NULL. On failure release(user) is
 * called before returning, so the caller never has to. */
CVAR_API cv_status cv_problem_set_integrand_owned(cv_problem *p, cv_integrand_fn F, void *user,
                                                  cv_release_fn release);
/** Fix unknown k (0 <= k < n) to ya at a and yb at b. Values must be finite. */
CVAR_API cv_status cv_problem_set_dirichlet(cv_problem *p, int k, double ya, double yb);
/** Fix unknown k at one end: end 0 is a, end 1 is b. */
CVAR_API cv_status cv_problem_set_end_value(cv_problem *p, int k, int end, double value);
/** Leave unknown k free at one end (0 = a, 1 = b): the natural boundary condition
 * dF/dy'_k = 0 holds there at the solution. */
CVAR_API cv_status cv_problem_set_free_end(cv_problem *p, int k, int end);
/** \name Moving ends (docs/moving-ends.md; theory ME-1 .. ME-6)
 * An end of the interval may itself be unknown: free, or constrained to a curve
 * G(x, y) = 0. The solve then also finds where that end lies, from the transversality
 * condition, which calcvar derives and imposes itself: the interval given to
 * cv_problem_new is where the search starts, and cv_solver_get_interval gives the solved
 * one. One end or both may move; the Morse index counts the ends' motion too, and
 * cv_solve_all searches along it. Integral constraints are allowed (their multipliers
 * enter the condition); pointwise ones are not (cv_solve returns CVAR_EINVAL with a
 * sentence). */
/**@{*/
/** An end curve at one point: *G = G(x, y), *Gx = dG/dx and Gy[i] = dG/dy_i (n values).
 * Return 0 on success, nonzero when G cannot be evaluated there. */
typedef int (*cv_end_curve_fn)(double x, const double *y, double *G, double *Gx, double *Gy,
                               void *user);
/** Make end `end` of the interval (0 = a, 1 = b) free: its position is found with the path,
 * from the condition F - sum_i y'_i dF/dy'_i = 0 there (ME-1); the end values stay as set
 * (fixed, or free with their natural condition). */
CVAR_API cv_status cv_problem_set_end_free(cv_problem *p, int end);
/** Make end `end` (0 = a, 1 = b) move along the curve G(x, y) = 0: the end point lies on it
 * and the transversality condition along the curve holds there (ME-3). The values the
 * problem leaves free at that end may move with it; G may depend on at most one of them (at
 * the start point; CVAR_EINVAL from cv_solve otherwise). */
CVAR_API cv_status cv_problem_set_end_curve(cv_problem *p, int end, cv_end_curve_fn G, void *user);
/** cv_problem_set_end_curve whose `user` the problem owns and releases as in
 * cv_problem_set_integrand_owned (also on failure). */
CVAR_API cv_status cv_problem_set_end_curve_owned(cv_problem *p, int end, cv_end_curve_fn G,
                                                  void *user, cv_release_fn release);
/** Fix end `end` again (the default): the interval's end is where cv_problem_new put it. */
CVAR_API cv_status cv_problem_set_end_fixed(cv_problem *p, int end);
/** What end `end` does: 0 fixed, 1 free, 2 on a curve; -1 for bad arguments. */
CVAR_API int cv_problem_get_end_kind(const cv_problem *p, int end);
/**@}*/
/** Second derivatives (theory H-1 .. H-6): unknown k's y'' enters the integrand (or an
 * integral constraint). The problem then uses C^1 elements (values and slopes at the
 * nodes, cubic Hermite and the odd degrees 5 and 7 by cv_solver_set_degree;
 * degree 1 means 3; an even degree is refused when solving) for all its unknowns, and every integrand callback is called with
 * CVAR_NEED_Y2 (cv_partials2). Slopes start free at both
 * ends (the natural conditions of a second-order integrand hold there at the solution). */
CVAR_API cv_status cv_problem_set_second_order(cv_problem *p, int k);
/** Whether unknown k was made second order (0 for a bad k). */
CVAR_API int cv_problem_get_second_order(const cv_problem *p, int k);
/** Fix the slope y'_k at one end (0 = a, 1 = b) of a second-order unknown k. */
CVAR_API cv_status cv_problem_set_end_slope(cv_problem *p, int k, int end, double value);
/** Leave the slope y'_k free at one end (the default). */
CVAR_API cv_status cv_problem_set_free_slope(cv_problem *p, int k, int end);
/** Initial guess (default: the straight line between the end values; with a free end,
 * the constant fixed value; with both ends free, 0). NULL restores the default. */
CVAR_API cv_status cv_problem_set_guess(cv_problem *p, cv_guess_fn g, void *user);
/** The number n of unknown functions. */
CVAR_API int cv_problem_get_num_unknowns(const cv_problem *p);
/** The interval; a or b may be NULL. */
CVAR_API void cv_problem_get_interval(const cv_problem *p, double *a, double *b);

/** The integrand as a formula string, with exact symbolic derivatives (no callback to
 * write). `variable` names the independent variable (NULL for "x"); `unknowns` is a comma
 * separated list of n names (n must equal the problem's); `F` uses the scene grammar of
 * docs/scenes.md (y' is dy/dx; y'' makes that unknown second order, as
 * cv_problem_set_second_order, in an integrand or an integral constraint). `parameters` is NULL or a comma separated list of
 * `name = constant expression`. On failure returns CVAR_EINVAL and writes a sentence to
 * err (errlen bytes, may be NULL/0). The problem owns the compiled integrand. */
CVAR_API cv_status cv_problem_set_integrand_expr(cv_problem *p, const char *variable,
                                                 const char *unknowns, const char *F,
                                                 const char *parameters, char *err, size_t errlen);

/** \name Tables: functions given as data
 * A table is the C^2 cubic spline (not-a-knot ends, tensor product in 2-D and 3-D) through
 * values on a rectilinear grid of 1, 2 or 3 coordinates (docs/theory.md TB-1 .. TB-4), with
 * exact partial derivatives. Tables are reference counted: a problem that uses one keeps
 * its own reference, so the caller may free its handle at any time. A table is immutable
 * and may be read from several threads at once. */
/**@{*/
/** A tabulated function. Opaque; made by cv_table_new, released by cv_table_free. */
typedef struct cv_table cv_table;
/** A table in dim = 1, 2 or 3 coordinates. n[k] >= 4 values along coordinate k, given in
 * coords[k][0 .. n[k]-1], strictly increasing and finite. values holds the n[0]*...*n[dim-1]
 * finite grid values, the last coordinate fastest: the value at (i0, i1, i2) is
 * values[(i0*n[1] + i1)*n[2] + i2]. Everything is copied. NULL on failure, with *why (may
 * be NULL) CVAR_EINVAL or CVAR_ENOMEM. Memory: 2^dim doubles per grid value. */
CVAR_API cv_table *cv_table_new(int dim, const int *n, const double *const *coords,
                                const double *values, cv_status *why);
/** Release the caller's reference; NULL is a no-op. */
CVAR_API void cv_table_free(cv_table *t);
/** Number of coordinates (0 for NULL). */
CVAR_API int cv_table_get_dim(const cv_table *t);
/** The grid's range [lo, hi] along coordinate k (0-based); lo or hi may be NULL. */
CVAR_API cv_status cv_table_get_range(const cv_table *t, int k, double *lo, double *hi);
/** The spline's partial derivative of orders order[k] (NULL: the value) at the point u.
 * Returns 0; or k + 1 when u[k] lies outside the grid along coordinate k (no
 * extrapolation; *value is then NaN); -1 for NULL arguments. */
CVAR_API int cv_table_eval(const cv_table *t, const double *u, const int *order, double *value);
/** Make t callable as `name(u)`, `name(u, v)` or `name(u, v, w)` (and its derivatives
 * `name.1(...)`, `name.12(...)`, docs/expressions.md) in the formulas given afterwards to
 * cv_problem_set_integrand_expr, cv_problem_add_constraint_expr and
 * cv_problem_add_integral_expr. The problem takes its own reference. The name must be an
 * identifier that is not a function, pi, or a table already added (CVAR_EINVAL). When a
 * solve fails after the path left a table's grid, cv_solver_last_error() names the table. */
CVAR_API cv_status cv_problem_add_table(cv_problem *p, const char *name, cv_table *t);
/**@}*/

/** Pointwise constraint G(x, y) = 0 (no y'), at m points: G[k], and when asked for
 * (need & CVAR_NEED_GRAD) Gy[i*m + k] = dG/dy_i, (need & CVAR_NEED_HESS)
 * Gyy[(i*n + j)*m + k] = d2G/dy_i dy_j. Gy/Gyy are NULL when not asked for. Returns as
 * cv_integrand_fn does. */
typedef int (*cv_constraint_fn)(int m, const double *x, const double *y, unsigned need, double *G,
                                double *Gy, double *Gyy, void *user);

/** Add the pointwise constraint G(x, y(x)) = 0 for all x. It is imposed at every node
 * that has a free unknown, with one multiplier per node: the discrete multiplier field
 * lambda(x) of the Lagrangian F + lambda G (theory C-1). At an end where all unknowns are
 * fixed, the constraint must already hold (cv_solve returns CVAR_EINVAL otherwise).
 * *index (may be NULL) receives the constraint's number, 0, 1, ... */
CVAR_API cv_status cv_problem_add_constraint(cv_problem *p, cv_constraint_fn G, void *user,
                                             int *index);
/** Add the integral constraint  int_a^b K(x, y, y') dx = c, with one scalar multiplier
 * mu (Lagrangian F + mu K, theory C-2). K has the integrand's signature and must supply
 * the partials asked for. *index (may be NULL) receives its number, 0, 1, ... */
CVAR_API cv_status cv_problem_add_integral(cv_problem *p, cv_integrand_fn K, void *user, double c,
                                           int *index);
/** cv_problem_add_constraint whose `user` the problem owns and
 * releases as in cv_problem_set_integrand_owned (also on failure). */
CVAR_API cv_status cv_problem_add_constraint_owned(cv_problem *p, cv_constraint_fn G, void *user,
                                                   cv_release_fn release, int *index);
/** Make pointwise constraint k (from cv_problem_add_constraint*) an inequality: sense +1
 * requires G(x, y(x)) >= 0, sense -1 requires G <= 0, 0 makes it an equality again.
 * An obstacle: its multiplier lambda(x) is zero where the constraint is not active; where
 * it is, lambda <= 0 for G >= 0 and lambda >= 0 for G <= 0, so that -lambda grad G, the
 * force of the obstacle on the path, points away from it (theory OB-1). The solve
 * determines the active set by a primal-dual active set (semismooth Newton) iteration
 * (OB-2); the Morse index is that of the problem with the final active set fixed. */
CVAR_API cv_status cv_problem_set_constraint_sense(cv_problem *p, int k, int sense);
/** The sense of pointwise constraint k (0, +1, -1), or 0 when k is out of range. */
CVAR_API int cv_problem_get_constraint_sense(const cv_problem *p, int k);
/** cv_problem_add_integral whose `user` the problem owns (see above). */
CVAR_API cv_status cv_problem_add_integral_owned(cv_problem *p, cv_integrand_fn K, void *user,
                                                 cv_release_fn release, double c, int *index);
/** The pointwise constraint G(x, y) = 0 as a formula (no callback, exact partials): the
 * arguments as cv_problem_set_integrand_expr's; G may not involve the derivatives y'.
 * On failure CVAR_EINVAL with a sentence in err. *index as cv_problem_add_constraint. */
CVAR_API cv_status cv_problem_add_constraint_expr(cv_problem *p, const char *variable,
                                                  const char *unknowns, const char *G,
                                                  const char *parameters, int *index, char *err,
                                                  size_t errlen);
/** The integral constraint int_a^b K(x, y, y') dx = c as a formula, as above. */
CVAR_API cv_status cv_problem_add_integral_expr(cv_problem *p, const char *variable,
                                                const char *unknowns, const char *K, double c,
                                                const char *parameters, int *index, char *err,
                                                size_t errlen);
/** The number of pointwise constraints added so far. */
CVAR_API int cv_problem_get_num_constraints(const cv_problem *p);
/** Make unknown k periodic: y_k(b) = y_k(a) + D (D = 0: a closed path; D = 2 pi: an
 * angle that winds once). Both end values of y_k become free and are found with the
 * path; the condition is added as the integral constraint int_a^b y_k' dx = D (theory
 * PB-1), whose number is put in *index (may be NULL): its multiplier is minus the common
 * momentum dF/dy_k' at the two ends. When every unknown is periodic and F does not depend
 * on x, the path can be shifted along x: pin that shift with a further integral
 * constraint, e.g. int y . y0' dx = int y0 . y0' dx against a reference path y0 (PB-2). */
CVAR_API cv_status cv_problem_set_periodic(cv_problem *p, int k, double D, int *index);
/** The number of integral constraints added so far. */
CVAR_API int cv_problem_get_num_integrals(const cv_problem *p);
/** Energy H = sum_i y'_i dF/dy'_i - F and momenta P_i = dF/dy'_i at m >= 0 points, from
 * the integrand's own partials (any m: the callback is called in batches), e.g. at the
 * quadrature points of a solution (cv_solver_get_qpoints): x[k], y[i*m + k], dy[i*m + k]
 * in; H[k] and P[i*m + k] out, either may be NULL. Returns CVAR_ECALLBACK or
 * CVAR_ENONFINITE when the callback returns < 0 or > 0 at some point, CVAR_ENOMEM or
 * CVAR_EINVAL; values are written as they come (the caller checks finiteness). */
CVAR_API cv_status cv_problem_eval_energy(const cv_problem *p, int m, const double *x,
                                          const double *y, const double *dy, double *H, double *P);

/** Outcome of cv_problem_check_derivatives. */
typedef struct {
  double worst;    /**< worst relative difference |analytic - FD| / max(1, |analytic|) */
  int point;       /**< point index of the worst entry */
  char which[32];  /**< e.g. "Fyp[1][0]" */
  double analytic; /**< the callback's value there */
  double fd;       /**< the central finite-difference value */
} cv_derivcheck;

/** Compare the callback's first and second partials against central finite differences
 * of F (for the first partials) and of the first partials (for the second), at m points
 * (x[k], y[i*m+k], dy[i*m+k]); 1 <= m <= 256. Fills *report with the worst entry.
 * Returns CVAR_ECALLBACK/CVAR_ENONFINITE if the callback fails at a point. */
CVAR_API cv_status cv_problem_check_derivatives(const cv_problem *p, int m, const double *x,
                                                const double *y, const double *dy,
                                                cv_derivcheck *report);
/** The same for a second-order problem (cv_problem_set_second_order), with y''[i*m+k] in
 * d2y: every first partial in (y, y', y'') against central differences of F, every second
 * partial against those of the first ones; the names are "Fq[i]", "Fyq[i][j]", ... (the
 * stored block, e.g. d2F/dy''_1 dy_0 is "Fyq[0][1]"). CVAR_EINVAL for a first-order
 * problem or more than 64 unknowns. */
CVAR_API cv_status cv_problem_check_derivatives2(const cv_problem *p, int m, const double *x,
                                                 const double *y, const double *dy,
                                                 const double *d2y, cv_derivcheck *report);
/**@}*/

/** \name Solver: discretisation, options, results */
/**@{*/
/** A solver: discretisation, options, and the results of the last cv_solve. Opaque; made
 * by cv_solver_new, released by cv_solver_free; one solver may solve many problems. */
typedef struct cv_solver cv_solver;

/** Mesh grading end for cv_solver_set_mesh_graded. */
enum { CVAR_GRADE_A = 0, CVAR_GRADE_B = 1, CVAR_GRADE_BOTH = 2 };

/** A new solver with defaults: 100 uniform elements of degree 1, p+1 Gauss points,
 * rtol = atol = 1e-10, 50 iterations. NULL on failure (*why set when why != NULL). */
CVAR_API cv_solver *cv_solver_new(cv_status *why);
/** Release a solver and its results; NULL is a no-op. */
CVAR_API void cv_solver_free(cv_solver *s);

/** Number of elements of a uniform mesh (>= 1). Replaces a user or graded mesh. */
CVAR_API cv_status cv_solver_set_elements(cv_solver *s, int elements);
/** Polynomial degree 1..8 of every element. */
CVAR_API cv_status cv_solver_set_degree(cv_solver *s, int degree);
/** Gauss-Legendre points per element, 0 for the default p+1, else 1..32. */
CVAR_API cv_status cv_solver_set_quadrature_points(cv_solver *s, int q);
/** Graded mesh: element boundaries a + (b-a) t_i^k with t_i = i/E towards end a
 * (CVAR_GRADE_A), mirrored towards b, or symmetric towards both; grading k >= 1. */
CVAR_API cv_status cv_solver_set_mesh_graded(cv_solver *s, int elements, double grading, int end);
/** A user mesh on the reference interval [0, 1]: t[0] = 0 < t[1] < ... < t[E] = 1, mapped
 * affinely onto the problem's [a, b]. The array is copied; E >= 1. */
CVAR_API cv_status cv_solver_set_mesh(cv_solver *s, int elements, const double *t);
/** A user mesh as cv_solver_set_mesh with its own degree 1..8 for each element
 * (degrees[0 .. elements-1], copied; theory HP-1). Nodes: 1 + the sum of the degrees.
 * cv_solver_set_degree and the other mesh setters return to one degree for all. */
CVAR_API cv_status cv_solver_set_mesh_hp(cv_solver *s, int elements, const double *t,
                                         const int *degrees);
/** Points in (a, b) at which the mesh must have nodes (where the integrand may jump), in
 * the problem's variable. The nearest element boundary is moved onto each breakpoint (the
 * mesh is split there when moving would tangle it). nb = 0 clears. */
CVAR_API cv_status cv_solver_set_breakpoints(cv_solver *s, int nb, const double *xb);
/** Tolerances on the Newton step, weighted as 1/(rtol |y_i| + atol * scale), where scale
 * is the largest end value magnitude (or 1). Both >= 0, not both 0; rtol >= 10 eps. */
CVAR_API cv_status cv_solver_set_tolerances(cv_solver *s, double rtol, double atol);
/** Maximum Newton iterations (>= 1). */
CVAR_API cv_status cv_solver_set_max_iterations(cv_solver *s, int maxit);

/** Engines. Newton finds any stationary point (minimum or saddle) and reports its Morse
 * index; the NLopt minimisers find minima only (docs/engines.md). */
typedef enum {
  CVAR_METHOD_NEWTON = 0, /**< Newton on the (KKT) stationarity system, sparse LDL^T */
  CVAR_METHOD_LBFGS,      /**< NLopt L-BFGS (no constraints) */
  CVAR_METHOD_TNEWTON,    /**< NLopt preconditioned truncated Newton (no constraints) */
  CVAR_METHOD_MMA,        /**< NLopt MMA (constraints as pairs of inequalities) */
  CVAR_METHOD_CCSAQ,      /**< NLopt CCSA with quadratic approximations (as MMA) */
  CVAR_METHOD_SLSQP,      /**< NLopt SLSQP (equality constraints) */
  CVAR_METHOD_AUGLAG      /**< NLopt augmented Lagrangian around L-BFGS (equality constraints) */
} cv_method;
/** "newton", "lbfgs", "tnewton", "mma", "ccsaq", "slsqp", "auglag"; NULL if out of range. */
CVAR_API const char *cv_method_name(cv_method m);
/** Parse a method name; CVAR_EINVAL if unknown. */
CVAR_API cv_status cv_method_from_name(const char *name, cv_method *m);
/** The engine of the next solve (default CVAR_METHOD_NEWTON). */
CVAR_API cv_status cv_solver_set_method(cv_solver *s, cv_method m);
/** The engine of the next solve. */
CVAR_API cv_method cv_solver_get_method(const cv_solver *s);

/** Make the discrete action of p stationary, starting from p's guess (or, after
 * cv_solver_set_start, from given nodal values). Results stay in s until the next solve.
 * Returns CVAR_OK only when converged; otherwise a failure status, with a sentence in
 * cv_solver_last_error(). On failure the results still describe the last iterate (for
 * diagnosis) but cv_solver_get_status() tells it did not converge. */
CVAR_API cv_status cv_solve(cv_solver *s, const cv_problem *p);

/** Automatic continuation (on by default; theory HC-2): when Newton from the start fails to
 * converge on an unconstrained problem, follow the homotopy from the start to the problem
 * in small steps before giving up. The message then says so. */
CVAR_API cv_status cv_solver_set_continuation(cv_solver *s, int on);
/** Continuation steps taken by the last solve (0 when Newton converged directly). */
CVAR_API int cv_solver_get_continuation_steps(const cv_solver *s);

/** Adaptive refinement at a fixed degree (theory AD-1): solve, estimate the error with the
 * enriched solve of cv_solver_estimate_error (HP-2), bisect the elements whose indicator
 * exceeds tol / 4, and repeat until the estimated max nodal error is at most tol, or the
 * mesh would exceed max_elements (then CVAR_EMAXITER with a sentence). tol = 0 turns it off
 * (default). The starting mesh is the one set by the other mesh setters. Replaces a
 * cv_solver_set_tol (the last one set wins). */
CVAR_API cv_status cv_solver_set_adapt(cv_solver *s, double tol, int max_elements);
/** Automatic accuracy (theory HP-1..HP-4): the solver chooses the mesh and the degree of
 * each element (1..8) until its estimate of the max nodal error is at most tol (> 0), or it
 * stops with CVAR_EMAXITER and a sentence saying why (the cap on unknowns, on rounds, or the
 * round-off floor) and the estimate reached. tol = 0 turns it off (default). The starting
 * mesh is the one set by the other setters. Cannot be combined with cv_solver_set_adapt
 * (the last one set wins). */
CVAR_API cv_status cv_solver_set_tol(cv_solver *s, double tol, int max_nodes);
/** A cap on the wall-clock time of the rounds of cv_solver_set_tol or cv_solver_set_adapt
 * (theory HP-6): when a round ends after `seconds` (> 0) since cv_solve began without the
 * estimate reaching tol, the rounds stop with CVAR_EMAXITER and a sentence naming the cap and
 * the estimate reached; the results are those of the last round. The round under way is
 * finished (and estimated), so a run may exceed the cap by one round. 0 turns it off
 * (default). Plain solves on a fixed mesh are not capped. */
CVAR_API cv_status cv_solver_set_time_limit(cv_solver *s, double seconds);
/** Estimated max nodal error of the last adaptive or --tol solve (NaN otherwise). */
CVAR_API double cv_solver_get_error_estimate(const cv_solver *s);
/** A-posteriori estimate of the max nodal error of the last (converged) solve on its own
 * mesh, from a warm-started solve on the p-enriched mesh (theory HP-2): CVAR_OK with *est
 * and (if est_vertex is not NULL) the max over the element boundaries alone, or an error
 * with a sentence in msg (cv_solver_last_error is not changed) when the enriched solve
 * failed or landed on another stationary path (theory HP-3): no bound then, NaN. */
CVAR_API cv_status cv_solver_estimate_error(const cv_solver *s, const cv_problem *p, double *est,
                                            double *est_vertex, char *msg, size_t len);
/** Refinement rounds of the last adaptive solve. */
CVAR_API int cv_solver_get_adapt_rounds(const cv_solver *s);

/** Start the next solve from nodal values y (node-major, length nodes*n as laid out by
 * the current mesh and degree); NULL returns to the problem's guess. Copied. */
CVAR_API cv_status cv_solver_set_start(cv_solver *s, int len, const double *y);

/** What a progress callback is told (cv_solver_set_progress). */
typedef struct {
  int kind;        /**< CVAR_PROGRESS_NEWTON after a Newton step, CVAR_PROGRESS_ROUND after
                        an adaptive round's error estimate */
  int iteration;   /**< Newton iteration of the current mesh solve, 1, 2, ... (NEWTON) */
  double residual; /**< scaled Euler-Lagrange residual (theory N-3) of the iterate the step
                        started from (NEWTON) */
  double step;     /**< weighted RMS norm of the Newton step (theory N-4); <= 1 ends the
                        iteration (NEWTON) */
  double alpha;    /**< line-search factor of the step taken, 1 for a full step (NEWTON) */
  double action;   /**< discrete action after the step (NEWTON) */
  int round;       /**< adaptive refinement round, 1, 2, ...; 0 when not adaptive */
  int elements;    /**< elements of the mesh being solved */
  double estimate; /**< estimated max nodal error after the round (ROUND); NaN otherwise */
} cv_progress;
/** Values of cv_progress.kind. */
enum { CVAR_PROGRESS_NEWTON = 0, CVAR_PROGRESS_ROUND = 1 };
/** Progress callback: return 0 to go on, nonzero to cancel the solve (cv_solve then returns
 * CVAR_ECANCELLED, and the results describe the last iterate). */
typedef int (*cv_progress_fn)(const cv_progress *info, void *user);
/** Call fn on the calling thread of cv_solve after every Newton step and every adaptive
 * round (NLopt engines report nothing); NULL turns it off. Newton runs inside automatic
 * continuation are reported like any other (their iteration count restarts); the reference
 * solves of adaptive refinement are not. */
CVAR_API cv_status cv_solver_set_progress(cv_solver *s, cv_progress_fn fn, void *user);

/** Status of the last solve (CVAR_ESTATE before any). */
CVAR_API cv_status cv_solver_get_status(const cv_solver *s);
/** One sentence about the last failure or outcome; never NULL. */
CVAR_API const char *cv_solver_last_error(const cv_solver *s);
/** Nodes of the mesh of the last solve, including both ends (0 before any solve). */
CVAR_API int cv_solver_get_num_nodes(const cv_solver *s);
/** Elements of the mesh of the last solve (breakpoints may have added some; 0 before any). */
CVAR_API int cv_solver_get_num_elements(const cv_solver *s);
/** Polynomial degree of the elements of the last solve, the largest with per-element
 * degrees (0 before any). */
CVAR_API int cv_solver_get_degree(const cv_solver *s);
/** Number of elements of the last solve; with degrees != NULL also writes the degree of
 * each element (0 before any solve). */
CVAR_API int cv_solver_get_degrees(const cv_solver *s, int *degrees);
/** The interval [a, b] of the last solve: the solved one when an end moved (a or b may be
 * NULL). CVAR_ESTATE before any solve. */
CVAR_API cv_status cv_solver_get_interval(const cv_solver *s, double *a, double *b);
/** x[j] of node j, length cv_solver_get_num_nodes(). */
CVAR_API cv_status cv_solver_get_nodes(const cv_solver *s, double *x);
/** Nodal values, node-major: y[j*n + i] is unknown i at node j; length nodes*n. */
CVAR_API cv_status cv_solver_get_values(const cv_solver *s, double *y);
/** Nodal slopes y'[j*n + i] of a second-order problem's last solve (C^1 elements: the
 * slopes are unknowns at the nodes); of a first-order one, the derivative of the
 * interpolant at the node (from the element to its left at a shared node). Length nodes*n. */
CVAR_API cv_status cv_solver_get_slopes(const cv_solver *s, double *dy);
/** Discrete action S_h at the last iterate. */
CVAR_API double cv_solver_get_action(const cv_solver *s);
/** Max-norm of the discrete Euler-Lagrange residual scaled by the lumped nodal weights
 * (theory (N-3)); mesh independent. */
CVAR_API double cv_solver_get_gradient_norm(const cv_solver *s);
/** Round-off floor of that residual at the last Newton iterate (theory (N-3a)): machine
 * epsilon times (1/m_f) (sum_j |K_fj| |x_j| + the sum of the magnitudes of the terms summed
 * into the gradient g_f), maximised over the free unknowns f, with K the Hessian (or KKT
 * matrix) and x the unknowns: how far round-off alone can move the residual. A residual
 * of up to a few times this is at round-off. p must be the problem solved; costs one
 * evaluation of the integrand's gradient at the quadrature points. CVAR_ESTATE (and NaN)
 * when the last solve was not a Newton solve that took a step (NLopt engines, no free
 * unknowns). Terms of constraints are not counted (a lower estimate of the floor then). */
CVAR_API cv_status cv_solver_residual_floor(const cv_solver *s, const cv_problem *p, double *floor);
/** Newton (or minimiser) iterations of the last solve. */
CVAR_API int cv_solver_get_num_iterations(const cv_solver *s);
/** Wall-clock seconds of the last cv_solve. */
CVAR_API double cv_solver_get_time(const cv_solver *s);
/** Number of negative pivots of the LDL^T factor of the Hessian at the last iterate (the
 * Morse index), or -1 when unknown. */
CVAR_API int cv_solver_get_morse_index(const cv_solver *s);
/** Nonzero when the Hessian at the last iterate has a (numerically) zero pivot. */
CVAR_API int cv_solver_get_degenerate(const cv_solver *s);
/** Dimension of the discrete problem: free scalar nodal values minus constraint rows (the
 * largest possible Morse index). */
CVAR_API int cv_solver_get_num_free(const cv_solver *s);

/** The contact set of inequality k in the last solve: the intervals [iv[2i], iv[2i+1]]
 * where it is active (a touching point is [x, x]), their ends placed between nodes from
 * the gap (theory OB-4). Up to cap intervals are written; *count receives how many there
 * are. CVAR_EINVAL when k is not an inequality, CVAR_ESTATE before a solve. */
CVAR_API cv_status cv_solver_get_contact(const cv_solver *s, const cv_problem *p, int k, double *iv,
                                         int cap, int *count);
/** The multiplier field of pointwise constraint k at the nodes of the last solve,
 * lambda[j], j < cv_solver_get_num_nodes(). At an end node whose unknowns are all fixed
 * (no multiplier there) the value is extrapolated from the neighbouring nodes. */
CVAR_API cv_status cv_solver_get_multiplier_field(const cv_solver *s, int k, double *lambda);
/** The scalar multiplier of integral constraint k of the last solve. */
CVAR_API cv_status cv_solver_get_multiplier(const cv_solver *s, int k, double *mu);

/** Number nq of quadrature points of the last solve's mesh (0 before any). */
CVAR_API int cv_solver_get_num_qpoints(const cv_solver *s);
/** Quadrature points of the last solve's mesh with their weights and the solution there.
 * Each output may be NULL. x, w: length nq; y, dy: n*nq, laid out y[i*nq + k] (structure of
 * arrays). Sum_k w[k] g(x[k]) is the solver's integral of g. */
CVAR_API cv_status cv_solver_get_qpoints(const cv_solver *s, double *x, double *w, double *y,
                                         double *dy);
/** cv_solver_get_qpoints with the second derivatives d2y[i*nq + k] as well, for a
 * second-order problem (for a first-order one d2y must be NULL: CVAR_EINVAL). */
CVAR_API cv_status cv_solver_get_qpoints2(const cv_solver *s, double *x, double *w, double *y,
                                          double *dy, double *d2y);
/** Evaluate the last solution (degree-p interpolant) at m abscissae in [a, b]:
 * y[i*m + k] and, if dy != NULL, y'[i*m + k]. */
CVAR_API cv_status cv_solver_eval(const cv_solver *s, int m, const double *x, double *y,
                                  double *dy);
/**@}*/

/** \name Scene files: a problem and its options from the scene format (docs/scenes.md)
 * The loader the calcvar command uses. A scene is loaded from a file or from text, with
 * optional `name=value` overrides of its [parameters]; every failure is one sentence
 * "FILE:LINE: what is wrong" in the caller's err buffer (errlen bytes; 1024 is ample).
 * A problem made from a scene refers to it: free the problem before the scene. */
/**@{*/
/** A loaded scene. Opaque; made by cv_scene_load_file or cv_scene_load_text, released by
 * cv_scene_free. */
typedef struct cv_scene cv_scene;
/** Load the scene file at path: a regular file of at most 4 MiB, or "-" for standard
 * input (read once per process; "<stdin>" in messages). set: nset strings "name=value"
 * (value a constant expression) overriding [parameters]; NULL when nset is 0. NULL on
 * failure, with the sentence in err. */
CVAR_API cv_scene *cv_scene_load_file(const char *path, int nset, const char *const *set, char *err,
                                      size_t errlen);
/** Load a scene from NUL-terminated text; name (NULL: "<text>") stands for the file in
 * messages. Otherwise as cv_scene_load_file. */
CVAR_API cv_scene *cv_scene_load_text(const char *text, const char *name, int nset,
                                      const char *const *set, char *err, size_t errlen);
/** Release a scene; NULL is a no-op. */
CVAR_API void cv_scene_free(cv_scene *sc);
/** The number of unknowns. */
CVAR_API int cv_scene_get_num_unknowns(const cv_scene *sc);
/** The name of unknown i (NULL when out of range); owned by the scene. */
CVAR_API const char *cv_scene_get_unknown(const cv_scene *sc, int i);
/** The scene's title and its variable's name; owned by the scene, never NULL. */
CVAR_API const char *cv_scene_get_title(const cv_scene *sc);
/** The name of the independent variable ("x" unless the scene says otherwise). */
CVAR_API const char *cv_scene_get_variable(const cv_scene *sc);
/** The number of the scene's [constraints] (pointwise, each with a multiplier field). */
CVAR_API int cv_scene_get_num_constraints(const cv_scene *sc);
/** The name of constraint k, in file order (its multiplier field is lambda_NAME; index k of
 * cv_solver_get_multiplier_field); NULL when out of range; owned by the scene. */
CVAR_API const char *cv_scene_get_constraint(const cv_scene *sc, int k);
/** The number of the scene's [integrals] (integral constraints, each with a multiplier). */
CVAR_API int cv_scene_get_num_integrals(const cv_scene *sc);
/** The name of integral constraint k, in file order (index k of cv_solver_get_multiplier);
 * NULL when out of range; owned by the scene. */
CVAR_API const char *cv_scene_get_integral(const cv_scene *sc, int k);
/** Override a [mesh] or [solver] setting before cv_scene_problem_new and
 * cv_scene_configure_solver, as the command's options do: "elements", "degree",
 * "tolerance", "max_iterations", "adapt", "tol" (a number; "tol" starts from the mesh
 * `calcvar solve --tol` starts from: [mesh] or the "elements" / "degree" given, else 4
 * elements of degree 4), "max_nodes" (the cap of "tol", default 10^6), "time_limit"
 * (seconds for the rounds of "tol" or "adapt"), "method" (a cv_method value).
 * CVAR_EINVAL for an unknown name or a value out of range, with a sentence in err. */
CVAR_API cv_status cv_scene_set_option(cv_scene *sc, const char *name, double value, char *err,
                                       size_t errlen);
/** A problem for the scene: integrand, ends, guess, [constraints], [integrals]. NULL on
 * failure (sentence in err). Free it (cv_problem_free) before the scene. */
CVAR_API cv_problem *cv_scene_problem_new(const cv_scene *sc, char *err, size_t errlen);
/** Apply the scene's [mesh] and [solver] (and cv_scene_set_option overrides) to a solver. */
CVAR_API cv_status cv_scene_configure_solver(const cv_scene *sc, cv_solver *s, char *err,
                                             size_t errlen);

/** The report of a solve, as `calcvar solve --json` writes it (docs/cli.md): the same keys,
 * built by the same code. Opaque; released by cv_report_free. */
typedef struct cv_report cv_report;
/** The report of the last cv_solve of s on p, a problem of sc (s is not modified). Without
 * [exact] it estimates the nodal error by a reference solve (docs/cli.md), as the command
 * does. NULL on failure (*why, may be NULL: CVAR_ESTATE before a solve, CVAR_ENOMEM). */
CVAR_API cv_report *cv_report_new(cv_scene *sc, const cv_problem *p, cv_solver *s, cv_status *why);
/** The report as JSON text (UTF-8, NUL-terminated), owned by the report. */
CVAR_API const char *cv_report_json(const cv_report *r);
/** Release a report; NULL is a no-op. */
CVAR_API void cv_report_free(cv_report *r);
/**@}*/

/** \name Mechanics of a scene: equations and small oscillations (docs/mechanics.md)
 * What `calcvar equations` and `calcvar modes` compute, for a loaded scene, with the same
 * JSON text as their `--json` (built by the same code). Each result is an opaque handle
 * that owns everything its getters return; strings are UTF-8, NUL-terminated and live
 * until the handle is freed. Both calls add nodes to the scene's expression store: do not
 * call them on one scene from two threads at once. The handles do not refer to the scene
 * once made (the scene may be freed first). */
/**@{*/
/** Momenta, Euler–Lagrange equations, Hamiltonian and conservation laws of a scene's
 * integrand F (with its [constraints] and [integrals] multipliers (P-8)), as expressions. */
typedef struct cv_equations cv_equations;
/** Derive the equations of sc (theory (P-3)..(P-7)). NULL on failure, with *why (may be
 * NULL; CVAR_EINVAL for a NULL scene, CVAR_ENOMEM) and a sentence in err (may be NULL). */
CVAR_API cv_equations *cv_equations_new(cv_scene *sc, cv_status *why, char *err, size_t errlen);
/** Release; NULL is a no-op. */
CVAR_API void cv_equations_free(cv_equations *e);
/** The number of unknowns (as the scene's, in its order). */
CVAR_API int cv_equations_get_num_unknowns(const cv_equations *e);
/** The momentum p_i = dF/dy_i' of unknown i, printed in the scene grammar with the scene's
 * names and its parameters as numbers (so it parses without the scene); NULL when i is out
 * of range. */
CVAR_API const char *cv_equations_get_momentum(const cv_equations *e, int i);
/** The left side E_i of unknown i's Euler–Lagrange equation E_i = 0, expanded with y_i''
 * (written "y''"; a multiplier field of constraint C is "lambda_C", an integral's
 * multiplier "mu_NAME"), signed so that the coefficient of y_i'' is not a negative
 * number; NULL when i is out of range. */
CVAR_API const char *cv_equations_get_euler_lagrange(const cv_equations *e, int i);
/** The Hamiltonian H = sum_i y_i' p_i - F. */
CVAR_API const char *cv_equations_get_hamiltonian(const cv_equations *e);
/** The integrand F itself, printed the same way. */
CVAR_API const char *cv_equations_get_integrand(const cv_equations *e);
/** 1 when F does not depend on y_i (p_i is conserved), else 0 (also out of range). */
CVAR_API int cv_equations_is_cyclic(const cv_equations *e, int i);
/** 1 when F does not depend on the variable (H is conserved), else 0. */
CVAR_API int cv_equations_is_autonomous(const cv_equations *e);
/** The JSON text of `calcvar equations --json` (without its final newline): keys momenta,
 * euler_lagrange, hamiltonian, cyclic, autonomous (docs/cli.md); "" for NULL. */
CVAR_API const char *cv_equations_json(const cv_equations *e);

/** The kind of a small oscillation. */
typedef enum {
  CVAR_MODE_STABLE = 0, /**< omega2 > 0: oscillation with period 2 pi / sqrt(omega2) */
  CVAR_MODE_UNSTABLE,   /**< omega2 < 0: growth rate sqrt(-omega2) */
  CVAR_MODE_NEUTRAL     /**< omega2 = 0 to round-off: a free translation or rotation */
} cv_mode_kind;
/** The equilibrium of a Lagrangian L(y, y') and its normal modes K v = omega2 M v. */
typedef struct cv_modes cv_modes;
/** Find the equilibrium dL/dy = 0 (y' = 0; on the [constraints] G(y) = 0 with their
 * multipliers) by Newton from the scene's guess at the start of the interval, and the
 * modes there (theory (P-9), (P-10), (P-12), (P-13)). NULL on failure, with *why (may be
 * NULL) and a sentence "FILE:LINE: what is wrong" in err (may be NULL): CVAR_EINVAL
 * when modes do not apply (L or a constraint depends on the variable, integral
 * constraints, as many constraints as unknowns); CVAR_ENONFINITE, CVAR_EMAXITER (no equilibrium from the
 * guess), CVAR_ESINGULAR (M not positive definite, dependent constraints), CVAR_EDEPENDENCY
 * (LAPACK), CVAR_ENOMEM. */
CVAR_API cv_modes *cv_modes_new(cv_scene *sc, cv_status *why, char *err, size_t errlen);
/** Release; NULL is a no-op. */
CVAR_API void cv_modes_free(cv_modes *m);
/** n, the number of unknowns. */
CVAR_API int cv_modes_get_num_unknowns(const cv_modes *m);
/** The number of modes: n minus the number of [constraints]. */
CVAR_API int cv_modes_get_num_modes(const cv_modes *m);
/** The number of [constraints] (multipliers). */
CVAR_API int cv_modes_get_num_constraints(const cv_modes *m);
/** The equilibrium y*[i], i < n, into the caller's array. */
CVAR_API cv_status cv_modes_get_equilibrium(const cv_modes *m, double *y);
/** omega2[k] of each mode k, increasing, into the caller's array of num_modes values. */
CVAR_API cv_status cv_modes_get_omega2(const cv_modes *m, double *omega2);
/** The kind of mode k (CVAR_MODE_NEUTRAL when k is out of range). */
CVAR_API cv_mode_kind cv_modes_get_kind(const cv_modes *m, int k);
/** The mode shapes, mode-major: shape[k*n + i] is unknown i of mode k (num_modes*n values),
 * normalised to v^T M v = 1. */
CVAR_API cv_status cv_modes_get_shapes(const cv_modes *m, double *shape);
/** The multipliers lambda_c of L + lambda.G at the equilibrium (num_constraints values;
 * lambda may be NULL when there are none). */
CVAR_API cv_status cv_modes_get_multipliers(const cv_modes *m, double *lambda);
/** M = d2L/dy'dy' and K = -d2(L + lambda.G)/dydy at the equilibrium, n*n row-major each
 * (either may be NULL). */
CVAR_API cv_status cv_modes_get_matrices(const cv_modes *m, double *mass, double *stiffness);
/** The JSON text of `calcvar modes --json` (without its final newline): keys equilibrium,
 * modes, and multipliers / gyroscopic when they apply (docs/cli.md); "" for NULL. */
CVAR_API const char *cv_modes_json(const cv_modes *m);
/**@}*/

/** @name Many parameter sets on one compiled scene (the engine of `calcvar batch`)
 * A scene file is read and compiled once, its [parameters] as inputs of the compiled
 * expressions; each row (values of some parameters) is then solved as `calcvar solve
 * SCENE --set name=value ...` would solve it, on several threads (docs/scale-out.md).
 * @{ */
/** A compiled scene and its per-thread solvers. */
typedef struct cv_batch cv_batch;

/** One solved row. outputs is the caller's: NULL, or room for cv_batch_num_outputs()
 * values (the [report] integrals, then the [integrals] multipliers), NaN where absent. */
typedef struct {
  cv_status status;       /**< CVAR_OK only when converged */
  int iterations;         /**< Newton (or minimiser) iterations */
  double time_s;          /**< wall-clock seconds of this row */
  int has_result;         /**< converged: action, morse_index, errors, outputs are set */
  double action;          /**< the discrete action */
  int morse_index;        /**< -1 when unknown (a method other than Newton) */
  double error_max_nodal; /**< against [exact]; NaN without it */
  double error_estimate;  /**< as `calcvar solve` reports it: the rounds' estimate of a
                               --tol or --adapt solve, else, without [exact], the enriched
                               solve's (theory HP-2); NaN with [exact] and no --tol, or when
                               there is no bound (the message says why, HP-3) */
  double *outputs;        /**< see above */
  int warm;               /**< 1: started from the previous row's solution */
  char message[1024];     /**< the report's sentence (a solve's message is at most 640 bytes) */
} cv_batch_result;

/** Read and compile the scene file (exit-2 kind of problems come back NULL with
 * "FILE:LINE: what is wrong" in err). */
CVAR_API cv_batch *cv_batch_new(const char *scene_path, char *err, size_t errlen);
/** Release; NULL is a no-op. */
CVAR_API void cv_batch_free(cv_batch *b);
/** The number of the scene's [parameters]. */
CVAR_API int cv_batch_num_parameters(const cv_batch *b);
/** Name of parameter i (file order), NULL when out of range. */
CVAR_API const char *cv_batch_parameter_name(const cv_batch *b, int i);
/** Result columns besides the fixed ones: [report] names, then "mu_" + integral name. */
CVAR_API int cv_batch_num_outputs(const cv_batch *b);
/** Name of output k, NULL when out of range. */
CVAR_API const char *cv_batch_output_name(const cv_batch *b, int k);
/** Which parameters a row gives, in order (default: none, i.e. the scene's values). Set
 * before the first cv_batch_solve (CVAR_EINVAL after it). */
CVAR_API cv_status cv_batch_set_columns(cv_batch *b, int ncols, const char *const *names, char *err,
                                        size_t errlen);
/** Threads (default 1; 0 = the cores available). */
CVAR_API cv_status cv_batch_set_threads(cv_batch *b, int nthreads);
/** Start each row from the previous row's solution on the same thread (default off); a
 * failed warm start is retried from the scene's guess and the row's message says so. */
CVAR_API cv_status cv_batch_set_warm_start(cv_batch *b, int on);
/** Override [mesh] elements and degree (0 keeps the scene's). */
CVAR_API cv_status cv_batch_set_mesh(cv_batch *b, int elements, int degree);
/** Check a row's values without solving: CVAR_EINVAL with a sentence when they make the
 * scene invalid (e.g. an interval with a >= b). */
CVAR_API cv_status cv_batch_check_row(cv_batch *b, const double *row, char *err, size_t errlen);
/** Solve nrows rows (row r is rows[r*ncols .. r*ncols+ncols-1]); res[r] receives row r
 * whatever order the threads took them in. Under the scene's [mesh] tol each row starts
 * its rounds from the mesh the previous converged row on its thread handed on (its final
 * mesh, or a coarser one when that is finer than tol needs; theory HP-9), verified by the
 * estimate; with warm starts on, also from that row's path. CVAR_OK when the rows were all attempted (each
 * has its own status), else an error for the whole call (e.g. CVAR_ENOMEM). */
CVAR_API cv_status cv_batch_solve(cv_batch *b, int nrows, const double *rows, cv_batch_result *res);
/**@}*/

/** \name Every stationary path: deflation (theory DF-1..DF-5) */
/**@{*/
/** How a cv_solve_all search went. */
typedef struct {
  int starts;     /**< starting points tried (the plain solve from the guess counts as one) */
  int failed;     /**< starts from which no stationary path converged */
  int duplicates; /**< starts that converged to a path already found */
  int found;      /**< distinct converged paths kept (cv_solver_get_num_solutions) */
  char stop[200]; /**< why the search stopped, one sentence */
} cv_search_info;

/** Search for up to max >= 1 distinct stationary paths of p (minima and saddles) with the
 * same ends: a plain cv_solve from the guess, then Newton on the deflated system (DF-3) from
 * the guess, the straight line and perturbations of every path found along its softest
 * Hessian directions (DF-4); every path is polished by plain Newton (adaptively when
 * cv_solver_set_adapt is on) and reported with its own Morse index. Two paths are the same
 * when their nodal values differ by at most the larger of their error estimates (adaptive
 * solves) and 1e-6 of their size (DF-5). Newton engine only (else CVAR_EINVAL).
 * Returns CVAR_OK when at least one path converged; the paths are then ordered by
 * increasing action and path 0 is selected: every getter above reads the selected path.
 * Otherwise the status and getters describe the failed plain solve. A later cv_solve
 * forgets the paths. */
CVAR_API cv_status cv_solve_all(cv_solver *s, const cv_problem *p, int max);
/** Work limit of cv_solve_all: no new start is begun once its Newton iterations (deflated
 * and polishing) since the last new path was found, or since the search began, reach factor
 * (>= 1, default 2) times the iterations of the first solve (counted as at least 8) and
 * every path has had two perturbations; each path found renews it (theory DF-4). */
CVAR_API cv_status cv_solver_set_search_work(cv_solver *s, double factor);
/** Number of distinct converged paths of the last cv_solve_all (0 otherwise). */
CVAR_API int cv_solver_get_num_solutions(const cv_solver *s);
/** Make path k (0 <= k < cv_solver_get_num_solutions) the one the getters read (nodes,
 * values, action, Morse index, multipliers, ...). CVAR_ESTATE without a cv_solve_all.
 * Selecting modifies the solver: the paths are not handles of their own, and the rule on
 * threads (one handle, one thread at a time) covers select-then-read as one use. To use
 * paths independently, copy each one's results out (the Python module reads every path,
 * with its report, into a Solution of its own). */
CVAR_API cv_status cv_solver_select_solution(cv_solver *s, int k);
/** What the last cv_solve_all tried and why it stopped. CVAR_ESTATE without one. */
CVAR_API cv_status cv_solver_get_search(const cv_solver *s, cv_search_info *info);
/**@}*/

#ifdef __cplusplus
}
#endif
#endif /* CALCVAR_H */
