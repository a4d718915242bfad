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

#endif /* CV_SCENE_BATCH_H */
