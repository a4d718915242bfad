/* src/core/cv_reuse.h — the mesh a solve hands to the next problem of a batch (theory HP-9).
 * Internal (not installed): the batch engine (src/scene/scene_batch_row.c) uses it.
 * SPDX-License-Identifier: MIT */
#ifndef CV_REUSE_H
#define CV_REUSE_H

#include "calcvar.h"

/** HP-9: from s's last converged --tol solve (cv_solver_set_tol), the mesh to start the
 * next problem's rounds from: s's final mesh, or, when it is finer than the tolerance needs
 * (every element of degree 8, smooth, no singular end, no breakpoint), fewer degree-8
 * elements laid by HP-7a's rule for that tolerance. *E elements, *t (*E + 1 boundaries on
 * [0, 1]) and *deg (*E degrees), and with y != NULL *y, s's solution at the nodes of that
 * mesh on s's interval (node-major, nodes x n: a warm start); the caller frees them with
 * cv_free. *coarsened: 1 when the mesh is not s's own. CVAR_ESTATE without such a solve. */
cv_status cv_reuse_mesh(const cv_solver *s, int *E, double **t, int **deg, double **y,
                        int *coarsened);

/** The nodes of the mesh (E, t, deg) as fractions of its interval, 1 + sum deg of them in
 * order (Gauss-Lobatto within each element): where the values of cv_reuse_mesh's y are. */
void cv_reuse_node_fractions(int E, const double *t, const int *deg, double *u);

/** HP-9: set s's mesh to (E, t, deg), a mesh cv_reuse_mesh handed on, as the start of the
 * next --tol rounds (cv_solver_set_mesh_hp), and tell them so: their pilot (HP-7) then
 * refines a degree-8 start only when a tail is above the aim that mesh was laid for
 * (cv_pilot_aim x tol: HP-7a's 10 tol, or what HP-7b learnt), not above tol, so that the row does not refine by one element the mesh
 * just coarsened for it. The mark lasts for the next rounds only. */
cv_status cv_reuse_set_start(cv_solver *s, int E, const double *t, const int *deg);

#endif /* CV_REUSE_H */
