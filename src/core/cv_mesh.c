/* src/core/cv_mesh.c — element boundaries: uniform, graded, user-given, with breakpoints.
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cv_internal.h"

static int cmp_double(const void *u, const void *v) {
  double a = *(const double *)u, b = *(const double *)v;
  return (a > b) - (a < b);
}

/* Reference boundaries t_0 = 0 < ... < t_E = 1 of a uniform or graded mesh, theory (M-1). */
static double graded_t(const cv_meshspec *m, int i) {
  double s = (double)i / m->elements, k = m->grading;
  if (m->kind != CV_MESH_GRADED) return s;
  if (m->grade_end == CVAR_GRADE_A) return pow(s, k);
  if (m->grade_end == CVAR_GRADE_B) return 1.0 - pow(1.0 - s, k);
  return s <= 0.5 ? 0.5 * pow(2.0 * s, k) : 1.0 - 0.5 * pow(2.0 * (1.0 - s), k);
}

cv_status cv_mesh_build(const cv_meshspec *m, double a, double b, int *Eout, double **xout,
                        char *msg, size_t len) {
  double L = b - a, *xe = NULL, *bp = NULL;
  int E = m->elements, nb = m->nbreak;
  cv_status st = CVAR_OK;
  *xout = NULL;
  if (nb > 0) {
    bp = cv_malloc((size_t)nb * sizeof *bp);
    if (!bp) return CVAR_ENOMEM;
    memcpy(bp, m->breaks, (size_t)nb * sizeof *bp);
    qsort(bp, (size_t)nb, sizeof *bp, cmp_double);
    for (int i = 0; i < nb; i++) {
      if (!(bp[i] > a && bp[i] < b)) {
        cv_set_msg(msg, len, "breakpoint %g is not inside the interval (%g, %g)", bp[i], a, b);
        st = CVAR_EINVAL;
        goto cleanup;
      }
    }
  }
  if (m->kind == CV_MESH_UNIFORM && nb > 0) {
    /* Segments between breakpoints, elements shared in proportion to length (>= 1 each). */
    int total = 0, *cnt = cv_malloc((size_t)(nb + 1) * sizeof *cnt);
    if (!cnt) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    for (int s = 0; s <= nb; s++) {
      double lo = s ? bp[s - 1] : a, hi = s < nb ? bp[s] : b;
      cnt[s] = (int)lround(E * (hi - lo) / L);
      if (cnt[s] < 1) cnt[s] = 1;
      total += cnt[s];
    }
    xe = cv_malloc((size_t)(total + 1) * sizeof *xe);
    if (!xe) {
      cv_free(cnt);
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    int e = 0;
    for (int s = 0; s <= nb; s++) {
      double lo = s ? bp[s - 1] : a, hi = s < nb ? bp[s] : b;
      for (int i = 0; i < cnt[s]; i++) xe[e++] = lo + (hi - lo) * i / cnt[s];
    }
    xe[e] = b;
    E = total;
    cv_free(cnt);
  } else {
    xe = cv_malloc(((size_t)E + (size_t)nb + 1) * sizeof *xe); /* E may be INT_MAX */
    if (!xe) {
      st = CVAR_ENOMEM;
      goto cleanup;
    }
    if (m->kind == CV_MESH_UNIFORM) /* the common case, without a call per boundary */
      for (int i = 0; i < E; i++) xe[i] = a + L * ((double)i / E);
    else
      for (int i = 0; i < E; i++)
        xe[i] = a + L * (m->kind == CV_MESH_USER ? m->t[i] : graded_t(m, i));
    /* the last boundary outside the loop: i <= E would overflow at E = INT_MAX */
    xe[E] = a + L * (m->kind == CV_MESH_UNIFORM ? 1.0
                     : m->kind == CV_MESH_USER  ? m->t[E]
                                                : graded_t(m, E));
    xe[0] = a;
    xe[E] = b;
    /* Insert each breakpoint that is not already a boundary (to 1e-13 relative). */
    for (int i = 0; i < nb; i++) {
      int j = 0;
      while (j < E && xe[j + 1] <= bp[i]) j++;
      if (fabs(xe[j] - bp[i]) <= 1e-13 * L || fabs(xe[j + 1] - bp[i]) <= 1e-13 * L) continue;
      memmove(xe + j + 2, xe + j + 1, (size_t)(E - j) * sizeof *xe);
      xe[j + 1] = bp[i];
      E++;
    }
  }
  for (int i = 0; i < E; i++) {
    if (!(xe[i + 1] > xe[i])) {
      cv_set_msg(msg, len, "mesh boundaries must increase strictly (element %d has length %g)", i,
                 xe[i + 1] - xe[i]);
      st = CVAR_EINVAL;
      goto cleanup;
    }
  }
cleanup:
  cv_free(bp);
  if (st) {
    cv_free(xe);
    return st;
  }
  *Eout = E;
  *xout = xe;
  return CVAR_OK;
}

void cv_mesh_degrees(const cv_meshspec *m, double a, double b, int E, const double *xe, int *pe) {
  int U = m->elements, u = 0;
  for (int e = 0; e < E; e++) {
    double mid = (0.5 * (xe[e] + xe[e + 1]) - a) / (b - a);
    while (u < U - 1 && m->t[u + 1] <= mid) u++;
    pe[e] = m->degrees[u];
  }
}
