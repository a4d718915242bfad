/* src/core/cv_status.c — status messages and names, version, message formatting.
 * SPDX-License-Identifier: MIT */
#include <stdarg.h>
#include <stdio.h>

#include "cv_internal.h"

#define MSG_ITEM(name, msg)  msg,
#define NAME_ITEM(name, msg) #name,
static const char *const messages[] = {CVAR_STATUS_LIST(MSG_ITEM)};
static const char *const names[] = {CVAR_STATUS_LIST(NAME_ITEM)};

const char *cv_strerror(cv_status s) {
  if ((int)s < 0 || s >= CVAR_NUM_STATUS) return "unknown status";
  return messages[s];
}

const char *cv_status_name(cv_status s) {
  if ((int)s < 0 || s >= CVAR_NUM_STATUS) return "CVAR_UNKNOWN";
  return names[s];
}

void cv_version(int *major, int *minor, int *patch) {
  if (major) *major = CVAR_VERSION_MAJOR;
  if (minor) *minor = CVAR_VERSION_MINOR;
  if (patch) *patch = CVAR_VERSION_PATCH;
}

void cv_set_msg(char *msg, size_t len, const char *fmt, ...) {
  if (!msg || len == 0) return;
  va_list ap;
  va_start(ap, fmt);
  vsnprintf(msg, len, fmt, ap);
  va_end(ap);
}
