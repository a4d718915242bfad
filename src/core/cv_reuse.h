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

#endif /* CV_REUSE_H */
