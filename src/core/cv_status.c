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

/* "converged in N iterations" without vsnprintf: the message of every successful Newton
 * solve. The first printf-family call in a process runs through code of libc no earlier
 * call has touched (a page fault and about 1 200 instructions, docs/performance.md); the
 * messages of failures keep cv_set_msg. */
CV_HOT void cv_set_msg_converged(char *msg, size_t len, int iterations) {
  static const char head[] = "converged in ", tail[] = " iterations";
  char buf[sizeof head + 11 + sizeof tail], digits[11];
  size_t n = 0, nd = 0;
  unsigned v = iterations < 0 ? 0u - (unsigned)iterations : (unsigned)iterations;
  if (!msg || len == 0) return;
  do digits[nd++] = (char)('0' + v % 10u);
  while ((v /= 10u) != 0u);
  for (size_t i = 0; i < sizeof head - 1; i++) buf[n++] = head[i];
  if (iterations < 0) buf[n++] = '-';
  while (nd > 0) buf[n++] = digits[--nd];
  for (size_t i = 0; i < sizeof tail - 1; i++) buf[n++] = tail[i];
  if (n > len - 1) n = len - 1; /* truncated as snprintf would */
  for (size_t i = 0; i < n; i++) msg[i] = buf[i];
  msg[n] = '\0';
}
