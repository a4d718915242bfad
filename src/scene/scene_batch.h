/* src/scene/scene_batch.h — the batch engine (cv_batch of calcvar.h) seen from the
 * calcvar command. SPDX-License-Identifier: MIT
 *
 * Internal (not installed). The command loads the scene itself (scene_load_file_inputs,
 * with its --set overrides), applies its solve options to the scene's fields, and hands
 * the scene over to scene_batch_new, which compiles it once.
 */
#ifndef CV_SCENE_BATCH_H
#define CV_SCENE_BATCH_H

#include "calcvar.h"
#include "scene/scene.h"

/** A batch over s (loaded with parameters as inputs); takes ownership of s, also when it
 * fails (NULL with "FILE: what is wrong" in err). */
cv_batch *scene_batch_new(scene *s, char *err, size_t errlen);
/** The scene of the batch (the values of its fields are those of the last check). */
const scene *scene_batch_scene(const cv_batch *b);

/** The problem of one row for the caller's own solver (continuation, which carries its
 * mesh and start from step to step): the batch's first worker takes the row's values
 * and a problem over its compiled clones is built, without reading or compiling the
 * scene again. *inst receives the worker's scene instance (its values are this row's
 * until the next call). Free the problem (cv_problem_free) before the next call and
 * before the batch. NULL with a sentence in err when the values are invalid. */
cv_problem *scene_batch_problem(cv_batch *b, const double *row, const scene **inst, char *err,
                                size_t errlen);

/** Work item i of a scene_batch_for_each on worker t (0 .. threads-1): the worker's
 * state (scene_batch_solve_row, scene_batch_check_row on t) is this call's alone. */
typedef int (*scene_batch_item_fn)(cv_batch *b, int t, int i, void *user);
/** fn(b, t, i, user) for i in [0, n) on the batch's threads (cv_batch_set_threads), items
 * claimed in blocks of `block` consecutive ones; returns when all are done. The command
 * reads, solves and formats its rows this way, so only reading lines and writing the
 * window stay on one thread (docs/scale-out.md). */
cv_status scene_batch_for_each(cv_batch *b, int n, int block, scene_batch_item_fn fn, void *user);
/** The block scene_batch_for_each should use for n rows (consecutive rows per thread with
 * warm starts; small blocks without). */
int scene_batch_block(const cv_batch *b, int n);
/** cv_batch_solve's work for one row, on worker t inside scene_batch_for_each; `row` is
 * the row's number (a warm start follows row - 1 solved by the same worker). */
void scene_batch_solve_row(cv_batch *b, int t, int row, const double *vals, cv_batch_result *r);
/** cv_batch_check_row on worker t (its buffers: no allocation), inside
 * scene_batch_for_each. */
cv_status scene_batch_check_row(cv_batch *b, int t, const double *row, char *err, size_t errlen);

#endif /* CV_SCENE_BATCH_H */
