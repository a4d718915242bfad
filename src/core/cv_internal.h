/* src/core/cv_internal.h — private structures shared by the core files.
 * SPDX-License-Identifier: MIT */
#ifndef CV_INTERNAL_H
#define CV_INTERNAL_H

#include <stddef.h>
#include "calcvar.h"
#include "cv_memory.h" /* the one allocator (tests may inject failures) */
#include "cv_table_internal.h"

/* The functions of every solve: placed together (.text.hot), so that a solve touches few
 * pages of code, the first in a process few fresh ones (docs/performance.md). */
#define CV_HOT __attribute__((hot))

/* Largest batch handed to an integrand callback (documented in calcvar.h). */
#define CV_BATCH      256
#define CV_MAX_DEGREE 8
#define CV_MAX_QUAD   32
#define CV_PI         3.14159265358979323846
/* The round-off floor of an error estimate, in units of eps times the values' size (HP-2). */
#define CV_ROUNDOFF_ULPS 256.0

typedef struct {
  cv_constraint_fn G;
  void *user;
  cv_release_fn release;
  int sense; /* 0: G = 0; +1: G >= 0; -1: G <= 0 (an obstacle, theory OB-1) */
} cv_pconstraint;

typedef struct {
  cv_integrand_fn K;
  void *user;
  cv_release_fn release;
  double c;
} cv_iconstraint;

/* A moving end of the interval (cv_problem_ends.c, cv_ends.c; theory ME-1 .. ME-4). */
enum { CV_END_FIXED = 0, CV_END_FREE = 1, CV_END_CURVE = 2 };
typedef struct {
  int kind;          /* CV_END_* */
  cv_end_curve_fn G; /* CV_END_CURVE: the curve G(x, y) = 0 */
  void *user;
  cv_release_fn release;
} cv_end_motion;

struct cv_problem {
  int n;
  cv_end_motion move[2]; /* what each end of the interval does (0 = a, 1 = b) */
  int nc, ni;            /* pointwise and integral constraints */
  cv_pconstraint *pc;
  cv_iconstraint *ic;
  double a, b;
  cv_integrand_fn F;
  void *user;
  cv_release_fn release;
  int *fixed;     /* fixed[2*k + end]: 1 fixed, 0 free (natural condition) */
  double *endval; /* endval[2*k + end] */
  cv_guess_fn guess;
  void *guess_user;
  int nnotes; /* failure notes of callbacks (cv_table_internal.h) */
  cv_note_source *notes;
  cv_smooth_fn smooth; /* jumps that can be smoothed (cv_table_internal.h, theory HC-4) */
  void *smooth_user;
  int nsmooth;
  int ntables; /* tables added by cv_problem_add_table, each with a reference */
  char **table_name;
  cv_table **table;
  /* Second derivatives (cv_problem_order2.c, theory H-1): order2[k] when y''_k enters; c1
   * when any does (then every unknown uses C^1 elements, cv_hermite.c); slopes at the
   * ends as fixed/endval are for values. NULL / 0 for a first-order problem. */
  int c1;
  int *order2, *sfixed;
  double *sendval;
};

/* Release a problem's second-order arrays (cv_problem_order2.c). */
void cv_problem_order2_free(cv_problem *p);

/* ---- reference element: GLL nodes, Gauss-Legendre rule, basis tables (cv_quadrature.c) */
typedef struct {
  int p, q;
  double xi[CV_MAX_DEGREE + 1];                /* GLL nodes on [-1, 1] */
  double wl[CV_MAX_DEGREE + 1];                /* GLL weights (= integral of each basis function) */
  double tau[CV_MAX_QUAD];                     /* Gauss points */
  double omega[CV_MAX_QUAD];                   /* Gauss weights */
  double B[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)]; /* B[k*(p+1)+l] = phi_l(tau_k) */
  double D[CV_MAX_QUAD * (CV_MAX_DEGREE + 1)]; /* D[k*(p+1)+l] = phi_l'(tau_k) on [-1,1] */
  int qs; /* points of the singular-end rules, built per element in cv_disc.c */
} cv_refelem;

/* One quadrature rule on the reference element with its basis tables. */
typedef struct {
  int q;
  const double *tau, *omega, *B, *D;
} cv_rule;

CV_HOT void cv_gauss_legendre(int q, double *t, double *w);
/* The same computed (Newton on the Legendre recurrence), for the table's test. */
void cv_gauss_legendre_compute(int q, double *t, double *w);
void cv_gauss_lobatto_compute(int p, double *xi, double *w);
CV_HOT void cv_gauss_lobatto(int p, double *xi, double *w);
/* Lagrange basis on nodes xi[0..p] at s: phi[l] and (if dphi) phi_l'(s). */
CV_HOT void cv_lagrange(int p, const double *xi, double s, double *phi, double *dphi);
CV_HOT void cv_refelem_init(cv_refelem *r, int p, int q);
/* The singular-end rule on the element touching end 0 (a) or 1 (b), qs points, for
 * degree p (1 <= p <= CV_MAX_DEGREE, 1 <= qs <= CV_MAX_QUAD); cached for the process. */
CV_HOT cv_rule cv_end_rule(int p, int qs, int end);

/* ---- mesh (cv_mesh.c) ---- */
enum { CV_MESH_UNIFORM, CV_MESH_GRADED, CV_MESH_USER };
typedef struct {
  int kind, elements, grade_end;
  double grading;
  double *t; /* user mesh on [0,1], elements+1 */
  int nbreak;
  double *breaks;
  int *degrees; /* user mesh only: degree of each of its elements (hp), or NULL */
} cv_meshspec;
/* Element boundaries on [a, b] from a spec; *xe is allocated (E+1 entries). */
CV_HOT cv_status cv_mesh_build(const cv_meshspec *m, double a, double b, int *E, double **xe,
                               char *msg, size_t len);
/* Degrees of the E elements xe[0..E] built from m (m->degrees set): an element takes the
 * degree of the user element containing its midpoint (breakpoints may have split some). */
void cv_mesh_degrees(const cv_meshspec *m, double a, double b, int E, const double *xe, int *pe);

/* ---- discretisation of one solve (cv_disc.c) ---- */
/* Unknowns of the discrete problem, node-major (theory E-2, C-3): at each node its free
 * components of y, then (with pointwise constraints, at nodes having a free component) its
 * nc multipliers; after the last node the ni integral multipliers. */
typedef struct {
  int n, p, E, nodes, ndof, nfree; /* p: the (largest) element degree */
  int nc, ni, stride, off0;        /* stride = n + nc; off0 = unknowns at node 0 */
  int nfree0, nfree1;              /* free y components at node 0 / at the last node */
  double a, b;
  double *xe;          /* element boundaries, E+1 */
  cv_refelem ref;      /* its tables are not zeroed with the rest (cv_disc.c): fix0 follows */
  int *fix0, *fix1;    /* index of each y component at node 0 / last, or -1 */
  int lam0, lamL, nu0; /* first multiplier at node 0 / last node (-1: none), integrals */
  double *mass;        /* lumped nodal weight of each unknown (theory N-3) */
  double *imass;       /* 1 / mass */
  int sing_a, sing_b;  /* integrand singular at that end: rules Q-2 on every element */
  double *srule;       /* per-element rules (tau, omega, B, D) when singular, else NULL */
  /* Variable degree (hp, theory HP-1): NULL when every element has degree p. */
  int *pe;          /* degree of each element */
  long *en;         /* first node of each element, E+1 entries (en[E] = nodes - 1) */
  cv_refelem *refs; /* reference element of each degree, refs[k] for k = 1..p */
  /* C^1 elements (cv_hermite.c, theory H-2): NULL for C^0 GLL. Then n = 2 x the problem's
   * unknowns (value and slope of each at every node, interleaved: component 2i is y_i,
   * 2i+1 is y_i'), p = r the node degree (nodes of GLL degree r) and the element degree
   * is 2r + 1. */
  struct cv_hermite *herm;
} cv_disc;

/* First node, degree and reference element of element e (constant or hp). */
static inline long cv_disc_enode(const cv_disc *d, long e) { return d->en ? d->en[e] : e * d->p; }
static inline int cv_disc_edeg(const cv_disc *d, long e) { return d->pe ? d->pe[e] : d->p; }
static inline const cv_refelem *cv_disc_eref(const cv_disc *d, long e) {
  return d->pe ? &d->refs[d->pe[e]] : &d->ref;
}
/* The element containing node j (the left one at a shared boundary node). */
long cv_disc_node_elem(const cv_disc *d, long j);

/* Build the per-element singular-end rules after sing_a/sing_b are set. */
cv_status cv_disc_build_singular_rules(cv_disc *d);

/* index of y dof g = node*n + i, or -1 when fixed */
static inline int cv_disc_fidx(const cv_disc *d, long g) {
  long node = d->n == 1 ? g : g / d->n; /* integer division is slow; n = 1 is common */
  int i = (int)(g - node * d->n);
  if (node == 0) return d->fix0[i];
  if (node == d->nodes - 1) return d->fix1[i];
  return (int)(d->off0 + (node - 1) * d->stride + i);
}
/* index of the multiplier of pointwise constraint k at a node, or -1 */
static inline int cv_disc_lidx(const cv_disc *d, long node, int k) {
  if (node == 0) return d->lam0 < 0 ? -1 : d->lam0 + k;
  if (node == d->nodes - 1) return d->lamL < 0 ? -1 : d->lamL + k;
  return (int)(d->off0 + (node - 1) * d->stride + d->n + k);
}
/* first free index of node j's block (of the next block if node j has no free unknown); the
 * blocks of nodes 0 .. nodes-1 fill 0 .. nu0-1 in order */
static inline int cv_disc_node_first(const cv_disc *d, long j) {
  return j == 0 ? 0 : (int)(d->off0 + (j - 1) * d->stride);
}
/* first unknown of element e (its first node's first unknown) */
static inline int cv_disc_elem_first(const cv_disc *d, long e) {
  return e == 0 ? 0 : (int)(d->off0 + (cv_disc_enode(d, e) - 1) * d->stride);
}

/* Sparsity pattern of the Hessian / KKT matrix (E-2, C-3): colptr (nfree + 1; may be NULL
 * to count only) and, if gof is not NULL, the y dof of each unknown or -1 - (index into
 * the multipliers). Returns the number of entries of the upper triangle; colptr is filled
 * only when that fits an int (the caller checks against INT_MAX first). */
CV_HOT long cv_disc_pattern(const cv_disc *d, int *colptr, int *gof);

/* The rule of element e (Gauss, or the singular-end rule on a flagged end element). */
cv_rule cv_disc_rule(const cv_disc *d, long e);
/* Total number of quadrature points over the mesh. */
long cv_disc_num_qpoints(const cv_disc *d);
double cv_disc_node_x(const cv_disc *d, long j);
/* All node abscissae, x[0 .. nodes-1]. */
void cv_disc_fill_nodes(const cv_disc *d, double *x);

/* ---- sparse symmetric LDL^T (cv_cholmod.c: the only file that includes CHOLMOD) ---- */
typedef struct cv_ldlt cv_ldlt;
/* The matrix of disc's pattern (cv_disc_pattern; gof filled if not NULL), upper triangle in
 * compressed columns: column c holds rows rstart(c)..c, contiguous. 32-bit indices:
 * CVAR_EINVAL with a message beyond 2^31 - 1 entries, CVAR_ENOMEM without one. */
CV_HOT cv_status cv_ldlt_new(const cv_disc *d, int *gof, cv_ldlt **out, char *msg, size_t len);
CV_HOT void cv_ldlt_free(cv_ldlt *L);
/* 1 when L (with its gof) is the matrix of disc's pattern: a new solve on the same mesh,
 * degrees, unknowns and constraints keeps the factor and its analysis. */
int cv_ldlt_matches(const cv_ldlt *L, const cv_disc *d, const int *gof);
/* Systems of up to cv_ldlt_skyline_max unknowns, and larger ones without integral
 * multipliers whose envelope has at most cv_ldlt_skyline_band entries per column, use the
 * skyline LDL^T (theory N-7), the others CHOLMOD; tests set both to compare the two. */
extern int cv_ldlt_skyline_max, cv_ldlt_skyline_band;
const int *cv_ldlt_colptr(const cv_ldlt *L); /* nfree + 1 column pointers */
double *cv_ldlt_values(cv_ldlt *L);          /* Ax, length colptr[nfree] */
/* Factor numerically (analysis happens on the first call). Returns CVAR_OK, or
 * CVAR_ESINGULAR with *minor set when a pivot is exactly zero/NaN. *neg = number of
 * negative pivots, *dmin the smallest |D(j)| / |A(j,j)|, *dmax the largest |D(j)|. */
CV_HOT cv_status cv_ldlt_factor(cv_ldlt *L, int *neg, double *dmin, double *dmax, char *msg,
                                size_t len);
/* Solve in place: x <- A^{-1} x. */
CV_HOT cv_status cv_ldlt_solve(cv_ldlt *L, double *x);
/* x <- A^{-1} (-b): as x = -b and cv_ldlt_solve, the negation fused into a pass where it can be. */
CV_HOT cv_status cv_ldlt_solve_neg(cv_ldlt *L, const double *b, double *x);
/* x <- L^{-1} x (transpose 0) or L^{-T} x (transpose 1), L unit lower triangular. */
cv_status cv_ldlt_solve_L(cv_ldlt *L, int transpose, double *x);
/* The pivots D(j) of the last factorisation. */
void cv_ldlt_diag(const cv_ldlt *L, double *D);

/* ---- assembly (cv_assemble.c) ---- */
typedef struct {
  const cv_problem *prob;
  const cv_disc *disc;
  double *buf; /* batch buffers */
  double *K;   /* element matrix, (p+1) n rows of ((p+1) n + 3) & ~3 */
  int *fl;     /* free index of each local dof, (p+1) n */
  double *x, *y, *dy;
  cv_partials out;
  int cb_status; /* last callback return value (>0 cannot evaluate, <0 abort) */
  int qv;        /* points whose rows of fit the buffer of batch_general */
  long nevals;
  double *hbuf; /* C^1 elements: their own batch buffers (cv_hermite_assemble.c), else NULL */
} cv_assembler;

CV_HOT cv_status cv_assembler_init(cv_assembler *as, const cv_problem *p, const cv_disc *d);
CV_HOT void cv_assembler_free(cv_assembler *as);
/* The elements of the batch that starts at element e0: up to CV_BATCH points of
 * consecutive elements sharing one rule and degree (HP-1), one element at a time with
 * per-element singular-end rules. Returns their count; q is the rule's points. */
static inline int cv_assembler_batch(const cv_disc *d, int e0, int q) {
  int nb = d->srule ? 1 : CV_BATCH / q, ne = d->E - e0 < nb ? (int)d->E - e0 : nb;
  if (d->pe)
    for (int k = 1; k < ne; k++)
      if (d->pe[e0 + k] != d->pe[e0]) return k;
  return ne;
}
/* x, y, y' at the quadrature points of elements e0 .. e0+ne-1 of one batch (degree of
 * e0) into the assembler's batch buffers, theory (E-3): what cv_assemble evaluates F at. */
void cv_assembler_points(cv_assembler *as, const double *Y, const cv_rule *r, int e0, int ne);
/* Set *S to the discrete integral of Fn (theory A-1), add its gradient to g (rows of the
 * y unknowns; may be NULL) and hscale times its Hessian to Ax (may be NULL; column
 * layout colptr), at nodal values Y (length nodes*n). With overwrite 0 nothing is zeroed;
 * with 1 the rows of g and columns of Ax of the mesh nodes (free indices 0 .. nu0-1) are
 * cleared batch by batch before the sums, so they end up holding this assembly alone
 * (integral-multiplier rows and columns are not touched). Returns CVAR_OK,
 * CVAR_ENONFINITE (non-finite output or > 0 from the callback), CVAR_ECALLBACK. */
CV_HOT cv_status cv_assemble(cv_assembler *as, cv_integrand_fn Fn, void *user, const double *Y,
                             double *S, double *g, const int *colptr, double *Ax, double hscale,
                             int overwrite);

/* ---- the Lagrangian system with constraints (cv_kkt.c) ---- */
typedef struct {
  const cv_problem *prob;
  const cv_disc *d;
  cv_assembler as;
  const int *colptr;
  double *xn;   /* node abscissae (pointwise constraints) */
  double *cbuf; /* batch buffers of constraint calls */
  double *gK;   /* gradient of one integral constraint */
  /* Inequalities (cv_kkt_active.c, theory OB-2): per node and constraint, 1 when the
   * node's row imposes G = 0, 0 when it imposes lambda = 0; the weights c of the
   * active-set rule. NULL without them. */
  unsigned char *active;
  double *cw;
  int frozen;    /* 1: evaluations keep the decisions (line-search trials along one step) */
  double on_tol; /* OB-2: |G| <= on_tol (relative) counts as on the obstacle at the start;
                  * 0: 1e-12 (a solved path); the NLopt engine sets its constraint tolerance */
  double gscale; /* OB-5: crossings smaller than this (1% of max |G| at the nodes) pass */
  double eps;    /* > 0: the penalised rows of the path-following (OB-3); 0: exact (OB-2) */
  double tg, tl; /* OB-2b: round-off margins of G and lambda against flipping a node */
  int all_ineq;  /* every pointwise constraint is an inequality (OB-3a's merit applies) */
  double hmax;   /* the action's largest Hessian diagonal at the last evaluation (C-4's delta) */
  size_t *chg;   /* OB-2c: node * nc + k of the decisions the last update changed */
  long nchg, chgcap;
} cv_kkt;
CV_HOT cv_status cv_kkt_init(cv_kkt *k, const cv_problem *p, const cv_disc *d, const int *colptr);
CV_HOT void cv_kkt_free(cv_kkt *k);
/* Reject pointwise constraints that fail at an end whose unknowns are all fixed. */
cv_status cv_kkt_check_ends(cv_kkt *k, const double *Y, char *msg, size_t len);
/* OB-2c: swap the rows of the nodes the last cv_kkt_update_active changed into the system
 * (G, Ax, dreg) evaluated at (Y, M) with the old set. */
cv_status cv_kkt_apply_changes(cv_kkt *k, const double *Y, const double *M, double *G, double *Ax,
                               double *dreg);
/* Inequalities (cv_kkt_active.c, theory OB-1, OB-2). 1 when the problem has any. */
int cv_kkt_has_inequalities(const cv_problem *p);
cv_status cv_kkt_active_init(cv_kkt *k);
/* Re-decide every inequality row at (Y, M) by the rule of OB-2 (constraint values only, no
 * assembly); returns how many decisions changed, or -1 when a constraint cannot be
 * evaluated there. */
long cv_kkt_update_active(cv_kkt *k, const double *Y, const double *M);
/* OB-8 (cv_contact.c): the gap kept by the free node beside each contact end, the error
 * the enriched solve cannot see; raises eta (may be NULL) of the elements around it. */
double cv_contact_gap_term(const cv_solver *s, const cv_problem *p, double *eta);
/* OB-5: 1 when the step from Y to Yt takes an inactive node that satisfies an inequality
 * (slack g > 0) further than OB_CROSS g past the obstacle: the line search shortens it, so
 * that a path does not jump across an obstacle whose constraint gradient is small inside. */
#define OB_CROSS 0.5
int cv_kkt_step_crosses(cv_kkt *k, const double *Y, const double *Yt);
/* Decide the row of inequality kc at node j from its value g, multiplier lam and the
 * weight c (OB-2): 1 active (impose G = 0), 0 inactive (impose lambda = 0). */
/* OB-3a: the penalised action's extra term and the slope correction (cv_kkt.c). */
int cv_kkt_penalty(cv_kkt *k, const double *Y, const double *M, const double *Yt, double *pen,
                   double *dslope);
/* OB-3b: a penalty stage's start set from the path's sinking (cv_kkt.c). */
long cv_kkt_stage_start(cv_kkt *k, const double *Y, double frac);
int cv_kkt_active_rule(int sense, double g, double lam, double c, double eps, int was, double tg,
                       double tl);
/* The row of an inactive node (lambda = 0): residual, diagonal. */
void cv_kkt_inactive_row(cv_kkt *k, long node, int kc, int row, double lam, double *G, double *Ax,
                         double *dreg);
/* Constraint values and dense Jacobian rows for the NLopt engine. */
cv_status cv_kkt_constraint_values(cv_kkt *k, const double *Y, double *vals, double *jac, int ld,
                                   const int *lrow, const int *var);
/* Least-squares starting multipliers from the stationarity condition at Y (C-5). */
cv_status cv_kkt_init_multipliers(cv_kkt *k, const double *Y, double *M);
/* M: multipliers, lam[node*nc + k] then nu[r]. Ax and dreg may be NULL. */
CV_HOT cv_status cv_kkt_eval(cv_kkt *k, const double *Y, const double *M, double *S, double *G,
                             double *Ax, double *dreg);

/* ---- Newton (cv_newton.c) ---- */
typedef struct {
  int iterations, morse, degenerate;
  double action, gnorm;
  char msg[640];
} cv_newton_result;

struct cv_solver {
  cv_meshspec mesh;
  int degree, nq, maxit;
  cv_method method;
  double rtol, atol;
  double *start;
  int start_len;

  /* results of the last solve */
  cv_status status;
  char msg[640];
  int n, have;
  cv_disc disc;
  double *y;    /* nodes*n */
  double *mult; /* nodes*nc multiplier field, then ni integral multipliers */
  double action, gnorm, time;
  double gfloor; /* the unknowns' part of gnorm's round-off floor (theory N-3a; cv_newton.c;
                  * cv_floor.c adds the terms' part), NaN if unknown */
  int iterations, morse, degenerate;
  double t_assemble, t_factor; /* seconds in assembly / LDL^T (bench/; from 512 unknowns) */
  double adapt_tol, err_est;   /* adaptive refinement (cv_adapt.c) */
  int adapt_max, rounds;
  /* HP-9: the next rounds start from a mesh a batch row handed on (cv_reuse_set_start),
   * laid for tails of at most cv_pilot_aim x tol; cleared when the rounds end */
  int handed_on;
  /* HP-7b: the pilot's aim (x tol) learnt from this solver's earlier rounds at tolerance
   * aim_tol (0: none yet; the rounds and the mesh handed to the next batch row use it) */
  double pilot_aim, aim_tol;
  double time_limit;        /* seconds for the rounds (HP-6); 0: none */
  int hp;                   /* 1: --tol (hp, HP-1..HP-6); 0: --adapt at a fixed degree */
  int continuation, csteps; /* automatic continuation (cv_continuation.c) */
  double smooth_w;         /* > 0: the answer is of the integrand smoothed over this width (HC-4) */
  char note[640];          /* what the solver decided on its own, prefixed to msg */
  cv_progress_fn progress; /* cv_solver_set_progress; NULL: none */
  void *progress_user;
  int near_sing[2]; /* ends found nearly singular after a solve */
  /* polish: an estimate's enriched solve (HP-2a): Newton takes a step within the tolerance
   * without evaluating the system at its end (the step is the last one and only the values
   * are used). ends_passed[k], set by the caller for the next solve: end k passed the
   * near-singular end check on an end element containing this mesh's, of no higher
   * degree (the solution being estimated, the previous round), so it is not checked again.
   * ends_ok[k]: the last solve's end k passed that check (cv_solve_mesh; cleared with the
   * results). */
  int polish, ends_passed[2], ends_ok[2];
  double search_work;       /* cv_solve_all's work limit (cv_deflation.c) */
  struct cv_pathset *paths; /* the paths of the last cv_solve_all (cv_deflation.c) */
  /* The sparse LDL^T of the Hessian pattern of `disc` (CHOLMOD common, pattern, symbolic
   * analysis) and the y dof of each unknown: made by the first Newton run on the mesh and
   * reused by the next ones on it (retries, continuation steps); dropped with the mesh. */
  struct cv_ldlt *ldlt;
  int *gof;
  /* A moving end (cv_ends.c): the fixed-interval problem of the last solve, for the calls
   * that take the problem after it (error estimate, residual floor), and the outer
   * dimension the Morse index and the free count include (0: no end moved). */
  struct cv_ends_state *ends;
  int ends_dim;
  int ends_neg; /* 1 when the reduced action decreases along the end's motion (ME-4): the
                 * Morse index is the inner one (morse) plus this */
};
CV_HOT cv_status cv_solve_mesh(cv_solver *s, const cv_problem *p);
/* One solve of p on its fixed interval: adaptive (--adapt, --tol) or on the mesh set. */
cv_status cv_solve_interval(cv_solver *s, const cv_problem *p);
/* Moving ends (cv_ends.c): does p move an end; the solve that finds the ends (ME-1..ME-4)
 * from the start's end point moved `shift` along the end's motion;
 * the problem of the last solve of s when it moved the ends of p (else p); release the
 * state. cv_problem_ends_release (cv_problem_ends.c) releases the curves' user data. */
int cv_ends_moving(const cv_problem *p);
cv_status cv_ends_run(cv_solver *s, const cv_problem *p, double shift);
/* cv_solve with a moving end's start point moved `shift` along its motion (cv_solve_all's
 * starts, cv_deflation.c); shift = 0 is cv_solve. */
cv_status cv_solve_at(cv_solver *s, const cv_problem *p, double shift);
const cv_problem *cv_ends_solved(const cv_solver *s, const cv_problem *p);
void cv_ends_state_free(cv_solver *s);
void cv_problem_ends_release(cv_problem *p);
/* At end `end` (0 = a, 1 = b) of the last solve of s on the fixed-interval problem q
 * (cv_ends_data.c, theory ME-2): the end values y, the slopes v = y', the momenta P and the
 * energy *H = sum_i v_i P_i - F (n values each), and *size = |F| + sum_i |v_i P_i|. mode 0: the momentum of a value q fixes
 * there is its reaction (the derivative of the discrete action with respect to it), of a
 * free one 0, and v solves F_y'(x, y, v) = P; mode 1: v of the end element, P = F_y'. */
cv_status cv_ends_end_data(const cv_solver *s, const cv_problem *q, int end, int mode, double *H,
                           double *P, double *y, double *v, double *size);
/* The default start at fraction t of the interval (cv_start.c): y[0 .. n-1]. */
void cv_start_line(const cv_problem *p, double t, double *y);
/* Release the solver's factor of its mesh (before the mesh changes). */
void cv_solver_drop_factor(cv_solver *s);
/* Release the last solve's mesh, nodal values and multipliers (not the factor). */
CV_HOT void cv_solver_drop_results(cv_solver *s);
/* The start of a solve (cv_start.c): cv_start_setup discretises the current mesh spec,
 * allocates the results and fills s->y with the starting values and flags singular ends;
 * cv_start_values fills Y with the given start / guess, or (line = 1) the straight line. */
CV_HOT cv_status cv_start_setup(cv_solver *s, const cv_problem *p);
CV_HOT cv_status cv_start_values(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y,
                                 int line);
/* After a solve: does the end element at end `end` (0 = a, 1 = b) under-integrate the
 * action (theory Q-3)? 0: no; CV_END_INTEGRAND: the integrand is nearly singular there;
 * CV_END_PATH: the integrand is smooth but the path bends on a scale below the element
 * (Q-3a). *rel: the relative change of the action under the singular-end rule there. */
enum { CV_END_INTEGRAND = 1, CV_END_PATH = 2 };
CV_HOT int cv_start_end_unresolved(const cv_problem *p, const cv_disc *d, const double *Y, int end,
                                   double action, double *rel);
/* The paths found by cv_solve_all (cv_deflation.c); NULL is a no-op. */
void cv_pathset_free(struct cv_pathset *ps);
cv_status cv_adapt_run(cv_solver *s, const cv_problem *p);
/* HP-9: what a failed round of cv_adapt_run knows: the caller's mesh and degree, whether
 * the round was warm-started, when the rounds began, and their Newton iterations. */
typedef struct {
  const cv_meshspec *spec0;
  int degree0, warm;
  double t0;
  long *iters;
} cv_rescue;
/* HP-9: after a round's solve failed with `first` on the mesh (E, t, deg): from the guess on
 * that mesh (when it was warm-started), then on finer uniform meshes of the caller's kind.
 * CVAR_OK with s solved and (E, t, deg) its mesh, note the sentence to prefix; else
 * `first`, with note a sentence to append to the failure (may be empty). */
cv_status cv_adapt_rescue(cv_solver *s, const cv_problem *p, const cv_rescue *r, cv_status first,
                          int *E, double **t, int **deg, char *note, size_t len);
/* ---- error estimate and hp decisions (cv_estimate.c, cv_hp.c) ---- */
/* Start s (mesh set) from `from` interpolated at its nodes. */
cv_status cv_warm_start(cv_solver *s, const cv_problem *p, const cv_solver *from);
/* HP-2, HP-3: the estimate of s's max nodal error from a warm-started solve into f on the
 * enriched mesh (est_vertex: at the element boundaries; floor_out: its round-off part; both
 * may be NULL). */
cv_status cv_estimate_enriched(const cv_solver *s, const cv_problem *p, cv_solver *f, double *est,
                               double *est_vertex, double *floor_out, char *msg, size_t len);
/* HP-4: the indicators eta, sigma, where (E entries each) of s's elements from f, the
 * enriched solve of a successful cv_estimate_enriched. */
cv_status cv_estimate_indicators(const cv_solver *s, const cv_solver *f, double *eta, double *sigma,
                                 double *where);
/* HP-7: from s's own solution, no solve: per element the decay rate sigma of its Legendre
 * coefficients and the next coefficient it predicts, tail = |a_p| e^(-sigma) (the largest
 * over the unknowns); a prediction to refine by, never an estimate. */
cv_status cv_estimate_pilot(const cv_solver *s, double *tail, double *sigma);
/* HP-7b: the pilot's aim (a multiple of tol) for s's next rounds (cv_adapt.c). */
double cv_pilot_aim(const cv_solver *s);
/* HP-4, HP-5: the next mesh (on [0, 1], *t with *Enew + 1 entries, *deg with *Enew) from
 * d with the elements cv_hp_marked refined (hp = 0: bisected at their degree; hp = 2: hp
 * and smooth neighbours may be merged, HP-8); target:
 * the tolerance, for the degree a smooth element is raised to. */
int cv_hp_marked(double eta, double sigma, double thresh, double target, int hp);
cv_status cv_hp_refine(const cv_disc *d, const double *eta, const double *sigma,
                       const double *where, double thresh, double target, int hp, int *Enew,
                       double **t, int **deg);
/* HP-7a: the pilot's mesh of degree-8 elements for a mesh of degree-8 elements with
 * predicted tails tail[e]: element e needs r_e = max(1, (tail_e / aim)^(1/9)) pieces, and
 * M = max(E + 1, ceil(sum r_e)) elements are laid so that each holds an equal share of
 * sum r_e (r_e spread evenly over element e). */
cv_status cv_hp_pilot_mesh(const cv_disc *d, const double *tail, double aim, int *Enew, double **t,
                           int **deg);
double cv_now(void);

cv_status cv_nlopt_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y);
/* Homotopy towards the problem from Y0 (theory HC-1); t in [0, 1], weight w > 0. */
typedef struct {
  double t, w;
  const double *Y0;
} cv_homotopy;
CV_HOT cv_status cv_newton_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *y, double *M,
                               const cv_homotopy *h);
/* After a failed Newton solve from Y0: continuation in t from Y0 (theory HC-2). */
cv_status cv_continuation_run(cv_solver *s, const cv_problem *p, cv_disc *d, double *Y, double *M,
                              const double *Y0);

CV_HOT void cv_disc_free(cv_disc *d);
CV_HOT cv_status cv_disc_init(cv_disc *d, const cv_problem *p, const cv_solver *s, char *msg,
                              size_t len);
void cv_set_msg(char *msg, size_t len, const char *fmt, ...) __attribute__((format(printf, 3, 4)));

/* ---- short vectors without libc or libm calls (cv_vec.c; the first solve in a process
 * binds every libc or libm symbol it calls, docs/performance.md) */
/* v[0 .. n-1] = 0 and dst[0 .. n-1] = src[0 .. n-1] (memset, memcpy beyond 4 kB). */
CV_HOT void cv_dzero(double *v, size_t n);
CV_HOT void cv_dcopy(double *restrict dst, const double *restrict src, size_t n);
/* fmax(a, b): the larger, or the one that is not NaN; inline instead of libm's call */
static inline double cv_fmax(double a, double b) { return a > b || b != b ? a : b; }
/* The same as cv_set_msg(msg, len, "converged in %d iterations", iterations). */
CV_HOT void cv_set_msg_converged(char *msg, size_t len, int iterations);

#endif /* CV_INTERNAL_H */
