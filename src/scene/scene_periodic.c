/* src/scene/scene_periodic.c — closed paths of a scene: when calcvar pins the shift along
 * the variable, and the phase condition that does it, theory (PB-2).
 * SPDX-License-Identifier: MIT */
#include <math.h>

#include "scene/scene_internal.h"

int scene_pins_shift(const scene *s) {
  if (scene_F_depends_on_variable(s)) return 0;
  int moves = 0;
  for (int i = 0; i < s->n; i++) {
    if (!s->bc[i].periodic) return 0;
    if (s->guess[i] < 0) continue;
    ex_id d = ex_diff(s->dag, s->guess[i], 0);
    double v;
    /* a guess whose derivative folds to the number 0 does not move */
    moves |= !(d >= 0 && ex_node_op(s->dag, d) == EX_NUM && ex_eval_const(s->dag, d, &v) == 0 &&
               v == 0.0);
  }
  return moves;
}

/* PB-2: K = sum_i y_i g_i'(x) with g the [guess]; the constraint int K dx = c holds at y = g
 * (c = sum_i int g_i g_i' dx = sum_i (g_i(b)^2 - g_i(a)^2) / 2), and its gradient along
 * the shift direction y' of a path near g is int |g'|^2 dx > 0, so it fixes the shift. */
int scene_phase_condition(const scene *s, ex_id *K, double *c) {
  ex_id sum = ex_num(s->dag, 0.0);
  double total = 0.0;
  for (int i = 0; i < s->n && sum >= 0; i++) {
    if (s->guess[i] < 0) continue;
    ex_id d = ex_diff(s->dag, s->guess[i], 0);
    ex_id yi = ex_slot(s->dag, 1 + i);
    if (d < 0 || yi < 0) return -1;
    sum = ex_binary(s->dag, EX_ADD, sum, ex_binary(s->dag, EX_MUL, yi, d));
    double ab[2] = {s->a, s->b}, g[2];
    if (sc_eval_exprs(s, 1, &s->guess[i], 2, ab, NULL, NULL, g) < 0) return -1;
    total += 0.5 * (g[1] * g[1] - g[0] * g[0]);
  }
  if (sum < 0 || !isfinite(total)) return -1;
  *K = sum;
  *c = total;
  return 0;
}
