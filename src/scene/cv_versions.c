/* src/scene/cv_versions.c — cv_dependency_versions: the versions of the libraries linked
 * into libcalcvar, asked of each library at run time where it can tell (`--version`).
 * SPDX-License-Identifier: MIT */
#include <cholmod.h>
#include <jansson.h>
#include <nlopt.h>
#include <stdio.h>

#include "calcvar.h"

/* LAPACK's own version query (reference LAPACK and OpenBLAS both export it). */
void ilaver_(int *major, int *minor, int *patch);

cv_status cv_dependency_versions(char *buf, size_t len) {
  if (!buf || len == 0) return CVAR_EINVAL;
  int cv[3] = {0, 0, 0}, nv[3] = {0, 0, 0}, lv[3] = {0, 0, 0};
  cholmod_version(cv);
  nlopt_version(&nv[0], &nv[1], &nv[2]);
  ilaver_(&lv[0], &lv[1], &lv[2]);
  /* inih has no version call: the one of the headers built against is not recorded */
  int k = snprintf(buf, len,
                   "CHOLMOD %d.%d.%d, NLopt %d.%d.%d, LAPACK %d.%d.%d, jansson %s, "
                   "inih",
                   cv[0], cv[1], cv[2], nv[0], nv[1], nv[2], lv[0], lv[1], lv[2],
                   jansson_version_str());
  return k >= 0 && (size_t)k < len ? CVAR_OK : CVAR_EINVAL;
}
