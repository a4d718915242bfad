/* src/scene/scene.h — scene files (shared/SCENES.md): load, validate, build a cv_problem.
 * SPDX-License-Identifier: MIT
 *
 * Internal to the library and the calcvar command (not installed). The loader never
 * prints and never exits: every failure comes back as one sentence "FILE:LINE: what is
 * wrong" (or "FILE: what is wrong" when there is no line, e.g. a --set override) in a
 * caller buffer of errlen bytes (SC_ERRLEN is a comfortable size).
 *
 * Lifetime: a cv_problem built from a scene refers to the scene's expression DAG and
 * guess data, so free the problem before the scene.
 *
 * Slots of every expression (the convention of src/expr): 0 = the variable,
 * 1..n = the unknowns y_i, n+1..2n = their derivatives y'_i.
 */
#ifndef CV_SCENE_H
#define CV_SCENE_H

#include <stddef.h>

#include "calcvar.h"
#include "expr/expr.h"

enum { SC_ERRLEN = 1024 };
/* The largest scene file read (bytes): a scene is a page of text; the cap keeps
 * `solve /dev/zero` or a wrong file from eating the memory (docs/scenes.md). */
enum { SC_MAX_BYTES = 4 << 20 };
/* The largest table read ([tables] grids and batch tables, bytes): 1 GiB, above the 630 MB
 * grid of bench/bench_table, far below what /dev/urandom or a wrong file would fill. */
#define SC_MAX_TABLE_BYTES ((long long)1 << 30)

/** One `--set name=value` override; value is a constant expression. */
typedef struct {
  const char *name;
  const char *value;
} sc_set;

/** A named entry of [parameters], [definitions], [constraints], [integrals], [report]. */
typedef struct {
  char *name;
  int line;     /* line of the entry in the scene file */
  ex_id expr;   /* the expression (parameters: the folded number) */
  ex_id expr2;  /* [integrals]: the constant c as a node; else -1 */
  double value; /* [parameters]: the value; [integrals]: c */
  int sense;    /* [constraints]: 0 for G = 0, +1 for G >= 0, -1 for G <= 0 */
} sc_item;

/** A moving end of the interval ([ends], docs/scenes.md): free, or on the curve G = 0. */
typedef struct {
  int kind; /* 0: fixed (no line), 1: free, 2: on a curve (the core's CV_END_* values) */
  int line; /* the [ends] line, 0 when none */
  ex_id G;  /* the curve G(x, y), its dG/dx and dG/dy_i (Gy: n of them), or -1 */
  ex_id Gx;
  ex_id *Gy;
} sc_end;

/** End conditions of one unknown: fixed values or natural (free) ends. */
typedef struct {
  double value[2]; /* at a and at b; meaningful where not free */
  int free_end[2]; /* nonzero: natural boundary condition dF/dy' = 0 there */
  int line;
  ex_id expr[2]; /* parameters as inputs: the value as an expression of them, else -1 */
  int periodic;  /* 'periodic [+ D]': y(b) = y(a) + shift, both ends free (theory PB-1) */
  double shift;
} sc_boundary;

typedef struct scene {
  char *file; /* the name used in messages */
  char *title;
  char *variable; /* default "x" */
  double a, b;
  int n; /* number of unknowns */
  char **unknowns;

  ex_dag *dag; /* owns every expression below */
  ex_id F;     /* the integrand */
  int F_line;

  sc_boundary *bc; /* [n] */
  sc_end ends[2];  /* [ends]: what each end of the interval does (0 = a, 1 = b) */
  ex_id *guess;    /* [n]: expression of the variable, or -1 for the default */
  ex_id *exact;    /* [n]: expression of the variable, or -1 when not given */
  int has_exact_action;
  double exact_action;

  int nparams, ndefs, ncons, nints, nreports;
  sc_item *params, *defs, *cons, *ints, *reports;

  /* [mesh] */
  int elements; /* default 100 */
  int degree;   /* default 1 */
  int nbreak;
  double *breakpoints; /* sorted, inside (a, b) */
  double adapt;        /* 0: off */
  int adapt_line;
  double tol; /* [mesh] tol: automatic accuracy (hp), 0: off */
  int tol_line;
  int tol_max_nodes;              /* --max-nodes: cap of tol on the nodes, 0: SCENE_TOL_MAX_NODES */
  double time_limit;              /* --time-limit: seconds for the rounds of tol/adapt, 0: none */
  int elements_line, degree_line; /* 0 when not given (--tol then picks its start); -1: given
                                     by the command's flags or cv_scene_set_option */
#define SCENE_TOL_MAX_NODES      1000000 /* cap of --tol / [mesh] tol on the nodes */
#define SCENE_TOL_START_ELEMENTS 4       /* --tol's starting mesh when the scene gives none */
#define SCENE_TOL_START_DEGREE   4
  double grading; /* 0: uniform; else the exponent k >= 1 (an addition, docs/scenes.md) */
  int graded_end; /* CVAR_GRADE_A, CVAR_GRADE_B or CVAR_GRADE_BOTH */

  /* [solver] */
  cv_method method;   /* the names are the core's: cv_method_name, cv_method_from_name */
  int method_line;    /* 0 when not given */
  double tolerance;   /* default 1e-10 */
  int max_iterations; /* default 50 */

  /* Parameters as inputs (scene_load_*_inputs, docs/scale-out.md): parameter i is slot
   * 2n+1+i of every expression instead of a folded number, params[i].expr is that slot,
   * params[i].expr2 its definition (an expression of earlier parameters) and
   * params[i].value its current value. Values that are constant expressions of
   * parameters keep their expressions (a_expr, b_expr, bc[].expr, ints[].expr2,
   * exact_action_expr) so that scene_set_parameters re-evaluates them. */
  int params_as_inputs;
  ex_id a_expr, b_expr, exact_action_expr;
  int settings_line; /* a [mesh]/[solver] value that uses a parameter: its line, else 0 */
  int is_instance;   /* made by scene_instance_new: shares the rest with its scene */
  /* [plot] (an addition, docs/scenes.md): slots 0 = the variable, 1..n = the unknowns */
  int plot_path[2]; /* path = U, V: V drawn against U; -1, -1 when not given */
  int *plot_down;   /* [n + 1]: nonzero for a name drawn increasing downward */
  /* Second derivatives (scene_order2.c): y''_i is slot sc_d2_slot(s, i) of every
   * expression; order2[i] when it appears anywhere (then the problem is second order and
   * every unknown uses C^1 elements, c1 = 1); sbc[i] the slope line `y' = a, b` (line 0:
   * none, both slopes free). */
  int c1;
  int *order2;      /* [n] */
  sc_boundary *sbc; /* [n] */
} scene;

/* The slot of y''_i: after the parameters and the smoothing width. */
static inline int sc_d2_slot(const scene *s, int i) { return 2 + 2 * s->n + s->nparams + i; }

/** Load a scene file. `name` for messages is the path itself; the path "-" reads standard
 * input, named "<stdin>" in messages (read once; later loads of "-" in the process reuse
 * its text). Only regular files (and "-") of at most SC_MAX_BYTES are read. nset overrides
 * (may be 0). */
scene *scene_load_file(const char *path, int nset, const sc_set *set, char *err, size_t errlen);
/** Load a scene from memory: len bytes (NUL bytes inside are rejected), `name` is used in
 * messages (e.g. "gallery:catenary"). */
scene *scene_load_buffer(const char *text, size_t len, const char *name, int nset,
                         const sc_set *set, char *err, size_t errlen);
/** After a solve: a point x* strictly inside (a, b) where the integrand along the solution
 * grows like |x - x*|^(-alpha) with alpha >= 0.85 (the action is then infinite, theory
 * (SG-1)). Returns 1 with *xs and *alpha, 0 when there is none, -1 when out of memory. */
int scene_interior_singularity(const scene *s, cv_solver *sv, double *xs, double *alpha);
/** Its two halves, for many solves of one scene (a batch): the sub-expressions of x alone
 * that F divides by, takes the log of or raises to a negative power (*cands, cv_free it;
 * returns their number, -1 out of memory), found once; then the check along a solution. */
int scene_singular_candidates(const scene *s, ex_id **cands);
int scene_interior_singularity_of(const scene *s, cv_solver *sv, int nc, const ex_id *cands,
                                  double *xs, double *alpha);

/** The same, with the parameters as inputs of every compiled expression (see the fields
 * above): one load and one compilation serve any parameter values. */
scene *scene_load_file_inputs(const char *path, int nset, const sc_set *set, char *err,
                              size_t errlen);
scene *scene_load_buffer_inputs(const char *text, size_t len, const char *name, int nset,
                                const sc_set *set, char *err, size_t errlen);

/** Parameters as inputs only: set parameter values and re-evaluate what depends on them.
 * given[i] nonzero: parameter i takes vals[i] (as `--set` would); else its definition is
 * evaluated with the values before it. Then the interval, the end values, the [integrals]
 * constants and the exact action. Returns 0, or -1 with "FILE: what is wrong" in err (a
 * non-finite value, a >= b); the scene is then unusable until a successful call. */
int scene_set_parameters(scene *s, const unsigned char *given, const double *vals, char *err,
                         size_t errlen);

/** A copy of s that shares its expressions, names and settings but owns its parameter
 * values, interval, end values and [integrals] constants: one per thread, each set with
 * scene_set_parameters, while s stays unchanged. Only the evaluators below (which read
 * the DAG without changing it) may be used on an instance from several threads; free it
 * (scene_free) before s. NULL on allocation failure. */
scene *scene_instance_new(const scene *s);

/** Release a scene; NULL is a no-op. */
void scene_free(scene *s);

/** Derivative groups a method asks the integrand for: newton F|GRAD|HESS, the NLopt
 * minimisers F|GRAD. */
unsigned scene_method_need(cv_method m);

/** A problem for the scene's integrand, ends, guess, [constraints] and [integrals]. max_need:
 * CVAR_NEED_* bits the integrand and constraints compile. (A pointwise constraint that
 * fails at an end whose values are fixed was already rejected by the loader.) */
cv_problem *scene_problem_new(const scene *s, unsigned max_need, char *err, size_t errlen);
/** Automatic accuracy's start (s->tol > 0): the mesh of [mesh] (or of the caller's own
 * elements / degree, marked by elements_line / degree_line != 0) is only where the rounds
 * begin; where neither gave one, SCENE_TOL_START_ELEMENTS x SCENE_TOL_START_DEGREE. The
 * command (--tol) and cv_scene_set_option ("tol") both start here. */
void scene_tol_start(scene *s);
/** Apply [mesh] and [solver] to a solver (elements, degree, grading, breakpoints,
 * tolerances, maximum iterations). */
cv_status scene_solver_configure(const scene *s, cv_solver *sv, char *err, size_t errlen);

/** The scene's [ends] on a problem made by scene_problem_new (scene_ends.c): 0, or -1 with
 * "FILE:LINE: what is wrong" in err. */
int scene_problem_set_ends(const scene *s, cv_problem *p, char *err, size_t errlen);
/** Whether the scene moves an end of its interval. */
int scene_has_moving_end(const scene *s);

/** Whether F depends explicitly on the variable / on unknown i (not through y'_i). */
int scene_F_depends_on_variable(const scene *s);
/** Whether calcvar pins the shift along the variable (theory PB-2): every unknown is
 * periodic, F does not depend on the variable, and the [guess] moves (its derivative is
 * not identically zero); the phase condition is then an integral constraint after the
 * scene's [integrals] and the periodic ones. */
int scene_pins_shift(const scene *s);
/** Translations of the periodic unknowns that leave F unchanged (PB-3), described with the
 * [integrals] line that pins each into out (len bytes); returns how many. */
int scene_translations(const scene *s, char *out, size_t len);
/** Expression of the phase condition's K = sum_i y_i g_i'(x) and its value c (PB-2). */
int scene_phase_condition(const scene *s, ex_id *K, double *c);
int scene_F_depends_on_unknown(const scene *s, int i);

/* Evaluators over m points, structure of arrays like cv_solver_get_qpoints: x[k],
 * y[i*m + k], dy[i*m + k]. Each returns 0 on success, -1 on allocation failure.
 * Non-finite values are written as they come: the caller checks. */

/** exact[i*m + k] from [exact]; NaN for unknowns without an exact solution. */
int scene_eval_exact(const scene *s, int m, const double *x, double *exact);
/** The guess (the [guess] expression or the default) at m abscissae: y[i*m + k]. */
int scene_eval_guess(const scene *s, int m, const double *x, double *y);
/** K_r at m points: out[r*m + k] for each [report] entry r. */
int scene_eval_reports(scene *s, int m, const double *x, const double *y, const double *dy,
                       double *out);
/** The same with y'' (d2y[i*m + k]), for a scene with second derivatives. */
int scene_eval_reports2(scene *s, int m, const double *x, const double *y, const double *dy,
                        const double *d2y, double *out);

#endif /* CV_SCENE_H */
