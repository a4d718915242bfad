/* src/scene/scene_contact.c — the contact set of each inequality constraint of a solved
 * scene: the intervals where it is active, with their ends placed between the nodes,
 * theory (OB-4).
 * SPDX-License-Identifier: MIT */
#include <math.h>
#include <string.h>

#include "scene/scene_internal.h"
#include "scene/scene_report.h"

/* The end of a contact run between the inactive node xo (gap go > 0) and the active node
 * xa, from the gap at xo and at the next inactive node xoo (gap goo) (OB-4): a path that
 * leaves a smooth obstacle tangentially has a gap ~ C (x - x0)^2, so sqrt(gap) is linear
 * in x; its zero, kept between xo and xa. Without a usable second node: xa. */
static double contact_end(double xa, double xo, double go, double xoo, double goo) {
  if (!(go > 0) || !(goo > go) || !isfinite(xoo)) return xa;
  double so = sqrt(go), soo = sqrt(goo);
  double x0 = xo - so * (xoo - xo) / (soo - so);
  double lo = xa < xo ? xa : xo, hi = xa < xo ? xo : xa;
  return x0 < lo ? lo : x0 > hi ? hi : x0;
}

/* The gap s G of constraint c at every node into gap (sense s, so that it is >= 0 where
 * the constraint holds). */
static int node_gaps(const cli_report *r, const scene *s, int c, double *gap) {
  int n = s->n, nn = r->nodes;
  double *y = cv_malloc((size_t)n * nn * sizeof *y);
  if (!y) return -1;
  for (int j = 0; j < nn; j++)
    for (int i = 0; i < n; i++) y[(size_t)i * nn + j] = r->y[(size_t)j * n + i];
  int rc = sc_eval_exprs(s, 1, &s->cons[c].expr, nn, r->x, y, NULL, gap);
  cv_free(y);
  for (int j = 0; j < nn && rc == 0; j++) gap[j] *= s->cons[c].sense;
  return rc;
}

int cli_report_contact(cli_report *r, const scene *s) {
  int nn = r->nodes;
  if (!r->lam || nn < 2) return 0;
  r->ncontact = cv_calloc((size_t)s->ncons + 1, sizeof *r->ncontact);
  r->contact = cv_calloc((size_t)s->ncons + 1, sizeof *r->contact);
  double *gap = cv_malloc((size_t)nn * sizeof *gap);
  if (!r->ncontact || !r->contact || !gap) {
    cv_free(gap);
    return -1;
  }
  for (int c = 0; c < s->ncons; c++) {
    if (!s->cons[c].sense) continue;
    if (node_gaps(r, s, c, gap) < 0) {
      cv_free(gap);
      return -1;
    }
    /* active: a nonzero multiplier (an inactive row ends with lambda = 0 exactly), or a
     * node on the obstacle within the round-off of the values */
    const double *lam = r->lam + (size_t)c * nn;
    double *iv = cv_malloc(2 * (size_t)nn * sizeof *iv);
    if (!iv) {
      cv_free(gap);
      return -1;
    }
    r->contact[c] = iv;
    int k = 0;
    for (int j = 0; j < nn;) {
      if (lam[j] == 0.0 || !isfinite(lam[j])) {
        j++;
        continue;
      }
      int j1 = j;
      while (j1 + 1 < nn && lam[j1 + 1] != 0.0 && isfinite(lam[j1 + 1])) j1++;
      double xs = r->x[j], xe = r->x[j1];
      if (j >= 1)
        xs = contact_end(r->x[j], r->x[j - 1], gap[j - 1], j >= 2 ? r->x[j - 2] : NAN,
                         j >= 2 ? gap[j - 2] : NAN);
      if (j1 + 1 < nn)
        xe = contact_end(r->x[j1], r->x[j1 + 1], gap[j1 + 1], j1 + 2 < nn ? r->x[j1 + 2] : NAN,
                         j1 + 2 < nn ? gap[j1 + 2] : NAN);
      iv[2 * k] = xs;
      iv[2 * k + 1] = xe;
      k++;
      j = j1 + 1;
    }
    r->ncontact[c] = k;
  }
  cv_free(gap);
  return 0;
}
