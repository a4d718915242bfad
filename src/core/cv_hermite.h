/* src/core/cv_hermite.h — C^1 elements: Hermite interpolation at the GLL nodes of degree r
 * (values and slopes at r + 1 nodes of each element, degree 2r + 1), theory H-2.
 * SPDX-License-Identifier: MIT */
#ifndef CV_HERMITE_H
#define CV_HERMITE_H

#include "cv_internal.h"

#define CV_HERMITE_MAX_R 3 /* element degrees 3, 5, 7 */
#define CV_HERMITE_NB    (2 * (CV_HERMITE_MAX_R + 1))

/* The reference C^1 element on [-1, 1]: basis function t = 2l + c is the polynomial of
 * degree 2r + 1 with value (c = 0) or s-derivative (c = 1) 1 at node l and every other
 * value and s-derivative 0 at the nodes; tables at q Gauss points: B values, D first and
 * E second s-derivatives, [k*nb + t]. */
typedef struct cv_hermite {
  int r, nb, q;
  double xi[CV_HERMITE_MAX_R + 1];
  double C[CV_HERMITE_NB * CV_HERMITE_NB]; /* Legendre coefficients: phi_t = sum_k C[k*nb+t] P_k */
  double tau[CV_MAX_QUAD], omega[CV_MAX_QUAD];
  double B[CV_MAX_QUAD * CV_HERMITE_NB], D[CV_MAX_QUAD * CV_HERMITE_NB],
      E[CV_MAX_QUAD * CV_HERMITE_NB];
} cv_hermite;

/* The element of node degree r (1 .. CV_HERMITE_MAX_R) with q Gauss points. */
void cv_hermite_init(cv_hermite *h, int r, int q);
/* The nb basis functions and their first and second s-derivatives at s (any may be NULL). */
void cv_hermite_basis(const cv_hermite *h, double s, double *B, double *D, double *E);
/* The node degree r for the element degree the solver asks for (1 means 3), or -1 with a
 * sentence when it is not one of 3, 5, 7. */
int cv_hermite_node_degree(int degree, char *msg, size_t len);
/* Set up d (mesh built, d->n and d->p set by cv_disc_init) for C^1 elements: the element
 * tables. */
cv_status cv_hermite_disc_init(cv_disc *d, int nq);
/* Lumped weights of the slope unknowns (H-5), after the value weights are in place. */
void cv_hermite_scale_mass(cv_disc *d);
/* Starting values and slopes (cv_start_values for C^1 elements, theory H-9). */
cv_status cv_hermite_start_values(cv_solver *s, const cv_problem *p, const cv_disc *d, double *Y,
                                  int line);
/* y, y', y'' of every unknown (n = the problem's) on element e at reference s. */
void cv_hermite_eval_local(const cv_disc *d, const double *Y, long e, double s, double *y,
                           double *dy, double *d2y);

/* ---- the solution of a C^1 solve (cv_hermite_solution.c) ---- */
/* Nodal values (slopes = 0) or slopes (1) of s->y, node-major nodes*n. */
cv_status cv_hermite_nodal(const cv_solver *s, int slopes, double *out);
/* cv_solver_get_qpoints2 and cv_solver_eval for C^1 elements. */
cv_status cv_hermite_qpoints(const cv_solver *s, double *x, double *w, double *y, double *dy,
                             double *d2y);
cv_status cv_hermite_eval(const cv_solver *s, int m, const double *x, double *y, double *dy);

/* ---- error estimate (cv_hermite_estimate.c, theory H-7) ---- */
/* The estimate of s's max nodal error from an enriched solve into f (a fresh solver);
 * eta (may be NULL): the largest difference on each element (E entries). */
cv_status cv_hermite_estimate(const cv_solver *s, const cv_problem *p, cv_solver *f, double *est,
                              double *est_vertex, double *eta, char *msg, size_t len);
/* Start f (its mesh set) from s's solution: values and slopes at f's nodes. */
cv_status cv_hermite_warm(cv_solver *f, const cv_problem *p, const cv_solver *s);
/* H-8: the smoothness indicator of element e of s's solution, the ratio of the Legendre
 * coefficients of degrees p, p-1 to those of p-2, p-3 (of degree >= 1), the largest over
 * the unknowns: small (below e^-2) where the solution is smooth. */
double cv_hermite_smoothness(const cv_solver *s, long e);
/* --tol and --adapt for C1 elements (theory H-8). */
cv_status cv_hermite_adapt(cv_solver *s, const cv_problem *p);

/* ---- assembly (cv_hermite_assemble.c) ---- */
cv_status cv_hermite_assembler_init(cv_assembler *as);
/* cv_assemble for C^1 elements (theory H-3). */
cv_status cv_hermite_assemble(cv_assembler *as, cv_integrand_fn Fn, void *user, const double *Y,
                              double *S, double *g, const int *colptr, double *Ax, double hscale,
                              int overwrite);

#endif /* CV_HERMITE_H */
