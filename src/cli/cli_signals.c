/* src/cli/cli_signals.c — what an interrupted run leaves: nothing of its own.
 * SPDX-License-Identifier: MIT
 *
 * Every temporary file (NAME.tmp.XXXXXX beside an output, a picture's scratch file) is
 * made by cli_mkstemp, which records its name here until it is renamed into place or
 * removed. SIGINT, SIGTERM, SIGHUP and SIGQUIT remove the recorded files (unlink is
 * async-signal-safe) and then end the process by the same signal, as the shell expects
 * (exit status 128 + N). The outputs themselves are untouched: a file is renamed over its
 * target only when complete, so an interrupted run leaves every output as it was before.
 *
 * SIGPIPE is ignored, so a closed pipe is a write error like any other (EPIPE): the
 * command says so and exits 3 (docs/cli.md). Descriptors 0-2 are held open from the
 * start (on /dev/null, or /dev/full for a closed standard output, where a write fails):
 * a temporary file must never become standard output and receive another report.
 */
#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli/cli.h"

enum { MAX_TEMPS = 64 }; /* a command has a handful of outputs at once */

static char *volatile temps[MAX_TEMPS];

static void on_signal(int sig) {
  for (int k = 0; k < MAX_TEMPS; k++) {
    char *t = temps[k];
    if (t) unlink(t);
  }
  signal(sig, SIG_DFL);
  raise(sig);
}

int cli_mkstemp(char *tmpl) {
  int fd = mkstemp(tmpl);
  if (fd < 0) return -1;
  for (int k = 0; k < MAX_TEMPS; k++)
    if (!temps[k]) {
      temps[k] = tmpl;
      return fd;
    }
  return fd; /* more than MAX_TEMPS at once: still removed on every normal path */
}

void cli_temp_forget(const char *name) {
  for (int k = 0; name && k < MAX_TEMPS; k++)
    if (temps[k] == name) temps[k] = NULL;
}

/* Hold descriptor fd open: 1 when it was closed. */
static int hold(int fd, const char *dev, int flags) {
  if (fcntl(fd, F_GETFD) >= 0 || errno != EBADF) return 0;
  int got = open(dev, flags);
  if (got < 0) got = open("/dev/null", flags);
  if (got >= 0 && got != fd) { /* a lower descriptor was free too: move it */
    dup2(got, fd);
    close(got);
  }
  return 1;
}

int cli_signals_setup(void) {
  hold(STDIN_FILENO, "/dev/null", O_RDONLY);
  int out_closed = hold(STDOUT_FILENO, "/dev/full", O_WRONLY);
  hold(STDERR_FILENO, "/dev/null", O_WRONLY);
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &sa, NULL);
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  static const int sigs[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  for (size_t k = 0; k < sizeof sigs / sizeof sigs[0]; k++) {
    struct sigaction old;
    /* a signal ignored by the parent (nohup, a background job) stays ignored */
    if (sigaction(sigs[k], NULL, &old) == 0 && old.sa_handler == SIG_IGN) continue;
    sigaction(sigs[k], &sa, NULL);
  }
  return out_closed;
}
